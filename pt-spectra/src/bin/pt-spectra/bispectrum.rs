//! `pt-spectra bispectrum`: the tree-level galaxy bispectrum multipoles B0, B2, B4 in redshift space at
//! triangles or averaged over the triangle bins of a measurement, or the Sugiyama multipoles
//! B_l1l2L(k1, k2) at pairs (`--basis sugiyama --pairs FILE`); with `--loop 1` the one-loop matter
//! bispectrum in real space at triangles.

use crate::input::SpectrumInput;
use crate::output::{check_outputs, write_output};
use anyhow::{bail, Context, Result};
use pt_spectra::bispectrum::one_loop::OneLoopRule;
use pt_spectra::bispectrum::{
    BispectrumParams, Fog, LegendreSide, PlanRules, SugiyamaRules, TriangleSet,
};
use pt_spectra::jobs::{
    bispectrum_table, one_loop_bispectrum_table, sugiyama_table, BispectrumRequest, SugiyamaRequest,
};
use pt_spectra::table::DataColumns;
use std::path::PathBuf;

/// Arguments of `pt-spectra bispectrum`.
#[derive(clap::Args, Debug)]
pub struct Args {
    #[command(flatten)]
    spectrum: SpectrumInput,
    /// Multipole basis: scoccimarro (B0, B2, B4 at triangles or bins) or sugiyama (B000, B110, B202,
    /// B022, B112, B220 at the (k1, k2) pairs of --pairs).
    #[arg(long, default_value = "scoccimarro")]
    basis: String,
    /// With --basis sugiyama: the pairs from the first two columns k1 k2 [h/Mpc] of this file
    /// ('#' comments).
    #[arg(long, value_name = "FILE", conflicts_with_all = ["triangles", "k_edges", "bin_width"])]
    pairs: Option<PathBuf>,
    /// Triangles from the first three columns k1 k2 k3 [h/Mpc] of this file ('#' comments), e.g. the
    /// k1 k2 k3 columns of a measurement.
    #[arg(long, value_name = "FILE", conflicts_with = "k_edges")]
    triangles: Option<PathBuf>,
    /// With --triangles: average over all closed triangles of three shells of this width [h/Mpc]
    /// centred on k1, k2, k3 (what a measurement's bins are); without it the triangles are points.
    #[arg(long, value_name = "DK", requires = "triangles")]
    bin_width: Option<f64>,
    /// All bins k1 <= k2 <= k3 of uniform shells between these edges [h/Mpc] whose centres close a
    /// triangle, averaged over their closed triangles: `a,b,c,…` or `start:end:step`.
    #[arg(long, value_name = "EDGES")]
    k_edges: Option<String>,
    /// Average the bins exactly over the discrete modes of a periodic box of side L [Mpc/h] (line of
    /// sight z; the FFT box estimator) instead of continuous shells; needs bins.
    #[arg(long = "box", value_name = "L", allow_hyphen_values = true)]
    box_size: Option<f64>,
    /// The effective-triangle shortcut: each bin at its mean sides (weight k1 k2 k3) instead of the
    /// bin average, about 10x faster; err_B* then includes the shortcut's error. Needs bins.
    #[arg(long)]
    effective: bool,
    /// Side whose cosine with the line of sight the Legendre polynomial takes: largest (the largest bin,
    /// as the window-free estimator), 1, 2 or 3.
    #[arg(long, value_name = "SIDE", default_value = "largest")]
    legendre_side: String,
    /// Linear bias b1.
    #[arg(long, default_value_t = 1.0, allow_hyphen_values = true)]
    b1: f64,
    /// Quadratic bias b2 ((b2/2) delta^2, velocileptors).
    #[arg(long, default_value_t = 0.0, allow_hyphen_values = true)]
    b2: f64,
    /// Tidal bias bs (bs s^2, velocileptors; CLASS-PT's b_G2 = bs).
    #[arg(long, default_value_t = 0.0, allow_hyphen_values = true)]
    bs: f64,
    /// The convention --b2 and --bs are written in: velocileptors (the default, as every command),
    /// fastpt (FAST-PT's (bs/2) s^2) or classpt (CLASS-PT's b2 and b_G2); docs/reference.md, "Bias
    /// conventions". The header gives both.
    #[arg(long, value_name = "NAME", value_parser = crate::common::parsed::<pt_spectra::bias::BiasConvention>)]
    bias_convention: Option<pt_spectra::bias::BiasConvention>,
    /// Counterterm c1 [(Mpc/h)^2]: Z1 -> Z1 - c1 k^2 mu^2.
    #[arg(long, default_value_t = 0.0, allow_hyphen_values = true)]
    c1: f64,
    /// Number density n_bar [(h/Mpc)^3] of the stochastic terms (none without it).
    #[arg(long, value_name = "N", allow_hyphen_values = true)]
    n_bar: Option<f64>,
    /// B_shot of (1/n_bar) b1 B_shot Z1 P (Poisson: 1).
    #[arg(
        long,
        default_value_t = 1.0,
        allow_hyphen_values = true,
        requires = "n_bar"
    )]
    b_shot: f64,
    /// P_shot of (1/n_bar)(1 + P_shot) f mu^2 Z1 P (Poisson: 0).
    #[arg(
        long,
        default_value_t = 0.0,
        allow_hyphen_values = true,
        requires = "n_bar"
    )]
    p_shot: f64,
    /// A_shot of (1 + A_shot)/n_bar^2 (Poisson: 0).
    #[arg(
        long,
        default_value_t = 0.0,
        allow_hyphen_values = true,
        requires = "n_bar"
    )]
    a_shot: f64,
    /// Growth rate f (default: f(z) of the cosmology).
    #[arg(long, allow_hyphen_values = true)]
    f: Option<f64>,
    /// AP scaling q_par = alpha_par (observed in a fiducial cosmology).
    #[arg(long, default_value_t = 1.0, allow_hyphen_values = true)]
    q_par: f64,
    /// AP scaling q_perp = alpha_perp.
    #[arg(long, default_value_t = 1.0, allow_hyphen_values = true)]
    q_perp: f64,
    /// Fingers of God: none, lorentzian or gaussian, with --sigma-fog.
    #[arg(long, default_value = "none")]
    fog: String,
    /// sigma_B of the Fingers of God [Mpc/h].
    #[arg(long, default_value_t = 0.0, allow_hyphen_values = true)]
    sigma_fog: f64,
    /// Switch off the IR resummation of the BAO in every leg (tree level) and, with --loop 1, of the
    /// one-loop galaxy bispectrum (any bias option, or --multipoles): on by default, B_tree with
    /// P_nw + e^-x (1 + x) P_w per leg and the loops on P_nw + e^(-q^2 Sigma^2) P_w (the matter tables
    /// of --loop 1 without a bias option are plain SPT, not resummed).
    #[arg(long)]
    no_ir: bool,
    /// Loop order: 0 (the tree-level galaxy model in redshift space) or 1 (the one-loop bispectrum,
    /// SPT: B_tree, B222, B321_I, B321_II, B411 at the points of --triangles, of matter or, with
    /// --b1/--b2/--bs/--b-gamma3/--loop-bias, of galaxies; real space, one orientation with --mu1, or
    /// the multipoles with --multipoles; the counterterm shapes as columns in real space and with
    /// --multipoles; bins with --multipoles; in real space --two-loop basis
    /// makes it ~10 us (matter) or ~0.15 ms (galaxies) per triangle after a one-off ~0.7 s (4 s) per
    /// triangle and core). The galaxy bispectrum's BAO are IR-resummed unless --no-ir.
    #[arg(long = "loop", value_name = "N", default_value_t = 0)]
    loop_order: u32,
    /// --loop 1 in redshift space: the cosine between k1 and the line of sight (with --f, default
    /// f(z); the matter or galaxy bispectrum at this one orientation, directly).
    #[arg(
        long,
        value_name = "MU1",
        allow_hyphen_values = true,
        requires = "triangles"
    )]
    mu1: Option<f64>,
    /// --loop 1 with --mu1: the azimuth of the line of sight about k1 from the triangle's plane, on
    /// the side of k2 [rad] (default 0: in the plane).
    #[arg(long, value_name = "PHI", allow_hyphen_values = true, requires = "mu1")]
    phi_los: Option<f64>,
    /// --loop 1: the multipoles B0, B2, B4 of the one-loop galaxy (or, without bias options, matter)
    /// bispectrum in redshift space at the points of --triangles (with --f, default f(z), and
    /// --legendre-side), all orientations in one pass over the loop nodes (the orientation rule exact),
    /// with the multipoles of the redshift-space counterterm and stochastic shapes; direct, ~6 times one
    /// orientation's cost (~35 s per triangle on 2 cores). With bins (--bin-width or --k-edges): each
    /// bin at its effective triangle (mean sides) plus the departure of the bin average from it on a
    /// coarse loop rule (exact for the tree level), its error in err_; ~33 s per bin on one core
    /// (docs/bispectrum.md). --two-loop basis: from the multipole tensors (of the triangles, or of the
    /// bins), f free, ~0.1-0.15 ms per triangle or bin after a one-off ~190 s per triangle and core at
    /// the default rule (cached; auto uses them if cached).
    #[arg(long, conflicts_with = "mu1")]
    multipoles: bool,
    /// --loop 1: CLASS-PT's b_Gamma3 (Gamma3 = G2(Phi_g) - G2(Phi_v)), with --b1, --b2, --bs.
    #[arg(long, default_value_t = 0.0, allow_hyphen_values = true)]
    b_gamma3: f64,
    /// --loop 1: fourth-order bias coefficients of Eggemeier, Scoccimarro & Smith (2019) by name,
    /// NAME=VALUE[,NAME=VALUE...] with NAME one of b3, g2x, g3, g21, g21x, g211, g22, g31, each in
    /// place of the value mapped from --bs and --b-gamma3 (docs/bispectrum.md).
    #[arg(long, value_name = "NAME=VALUE,...", allow_hyphen_values = true)]
    loop_bias: Option<String>,
    /// Write the table to this file instead of standard output.
    #[arg(long, value_name = "FILE")]
    out: Option<PathBuf>,
}

/// The options that the one-loop bispectrum does not take, set away from their defaults.
fn galaxy_options_given(args: &Args) -> Vec<&'static str> {
    let mut given = Vec::new();
    let mut flag = |set: bool, name: &'static str| {
        if set {
            given.push(name);
        }
    };
    flag(args.basis != "scoccimarro", "--basis");
    flag(args.pairs.is_some(), "--pairs");
    flag(args.bin_width.is_some(), "--bin-width");
    flag(args.k_edges.is_some(), "--k-edges");
    flag(args.box_size.is_some(), "--box");
    flag(args.effective, "--effective");
    flag(args.legendre_side != "largest", "--legendre-side");
    flag(args.c1 != 0.0, "--c1");
    flag(args.n_bar.is_some(), "--n-bar");
    flag(args.f.is_some(), "--f");
    flag(args.q_par != 1.0 || args.q_perp != 1.0, "--q-par/--q-perp");
    flag(args.fog != "none", "--fog");
    flag(args.sigma_fog != 0.0, "--sigma-fog");
    flag(args.no_ir, "--no-ir");
    given
}

/// `--loop 1`: the one-loop matter bispectrum at the triangles of --triangles.
fn one_loop(args: &Args) -> Result<pt_spectra::output::Table> {
    let redshift = args.mu1.is_some() || args.multipoles;
    let given: Vec<&str> = galaxy_options_given(args)
        .into_iter()
        .filter(|&o| !(redshift && o == "--f"))
        .filter(|&o| !(args.multipoles && o == "--legendre-side"))
        .filter(|&o| o != "--no-ir")
        .filter(|&o| !(args.multipoles && (o == "--bin-width" || o == "--k-edges")))
        .collect();
    if !given.is_empty() {
        bail!(
            "--loop 1 is the one-loop bispectrum at single triangles (bins: with --multipoles); it does not \
             take {} (counterterms, stochastic terms, FoG and AP of the one-loop bispectrum are not built yet)",
            given.join(", ")
        );
    }
    if args.multipoles && (args.bin_width.is_some() || args.k_edges.is_some()) {
        return binned_multipoles(args);
    }
    let Some(path) = &args.triangles else {
        bail!("--loop 1 needs --triangles FILE (columns k1 k2 k3 [h/Mpc])");
    };
    let t = DataColumns::read(path, &[0, 1, 2]).context("--triangles")?;
    let rows: Vec<[f64; 3]> = (0..t.columns[0].len())
        .map(|i| [t.columns[0][i], t.columns[1][i], t.columns[2][i]])
        .collect();
    let loaded = args.spectrum.load()?;
    let bars = crate::progress::Bars::default();
    if args.multipoles {
        let bias = galaxy_bias(args)?
            .unwrap_or_else(pt_spectra::bispectrum::bias_kernels::LoopBias::matter);
        return pt_spectra::jobs::one_loop_galaxy_multipoles_table(
            &loaded.prepared,
            &rows,
            &bias,
            args.f,
            LegendreSide::by_name(&args.legendre_side).context("--legendre-side")?,
            !args.no_ir,
            &OneLoopRule::default(),
            (loaded.precision.two_loop, &loaded.store),
            &bars,
        )
        .with_context(|| format!("--triangles {}", path.display()));
    }
    if let Some(bias) = galaxy_bias(args)? {
        let redshift = args.mu1.map(|mu1| {
            let phi = args.phi_los.unwrap_or(0.0);
            (
                args.f,
                pt_spectra::bispectrum::one_loop_rsd::Orientation { mu1, phi },
            )
        });
        return pt_spectra::jobs::one_loop_galaxy_table(
            &loaded.prepared,
            &rows,
            &bias,
            redshift,
            !args.no_ir,
            &OneLoopRule::default(),
            loaded.precision.two_loop,
            &loaded.store,
            &bars,
        )
        .with_context(|| format!("--triangles {}", path.display()));
    }
    if let Some(mu1) = args.mu1 {
        if loaded.precision.two_loop == pt_spectra::precision::TwoLoopMethod::Basis {
            bail!(
                "--two-loop basis: the one-loop bispectrum's tensors are built for real space only"
            );
        }
        let orientation = pt_spectra::bispectrum::one_loop_rsd::Orientation {
            mu1,
            phi: args.phi_los.unwrap_or(0.0),
        };
        return pt_spectra::jobs::one_loop_redshift_table(
            &loaded.prepared,
            &rows,
            args.f,
            orientation,
            &OneLoopRule::default(),
            &bars,
        )
        .with_context(|| format!("--triangles {}", path.display()));
    }
    one_loop_bispectrum_table(
        &loaded.prepared,
        &rows,
        &OneLoopRule::default(),
        loaded.precision.two_loop,
        &loaded.store,
        &bars,
    )
    .with_context(|| format!("--triangles {}", path.display()))
}

/// `--loop 1 --multipoles` with bins (`--triangles FILE --bin-width DK` or `--k-edges`): the loops at each
/// bin's effective triangle, the tree level averaged over the bin.
fn binned_multipoles(args: &Args) -> Result<pt_spectra::output::Table> {
    let set = triangles(args)?;
    let loaded = args.spectrum.load()?;
    let bias =
        galaxy_bias(args)?.unwrap_or_else(pt_spectra::bispectrum::bias_kernels::LoopBias::matter);
    pt_spectra::jobs::one_loop_galaxy_binned_multipoles_table(
        &loaded.prepared,
        &set,
        &bias,
        args.f,
        LegendreSide::by_name(&args.legendre_side).context("--legendre-side")?,
        !args.no_ir,
        &OneLoopRule::default(),
        (loaded.precision.two_loop, &loaded.store),
        &crate::progress::Bars::default(),
    )
    .context("--loop 1 --multipoles with bins")
}

/// `--loop 1`'s galaxy bias, if any bias option is given (else the matter bispectrum).
fn galaxy_bias(args: &Args) -> Result<Option<pt_spectra::bispectrum::bias_kernels::LoopBias>> {
    let overrides = match &args.loop_bias {
        None => Vec::new(),
        Some(list) => {
            list.split(',')
                .map(|item| {
                    let (name, value) = item
                        .split_once('=')
                        .with_context(|| format!("--loop-bias {item:?}: expected NAME=VALUE"))?;
                    let value: f64 = value.trim().parse().with_context(|| {
                        format!("--loop-bias {item:?}: the value is not a number")
                    })?;
                    Ok((name.trim().to_string(), value))
                })
                .collect::<Result<Vec<_>>>()?
        }
    };
    let matter = args.b1 == 1.0
        && args.b2 == 0.0
        && args.bs == 0.0
        && args.b_gamma3 == 0.0
        && args.bias_convention.is_none()
        && overrides.is_empty();
    if matter {
        return Ok(None);
    }
    let convention = args.bias_convention.unwrap_or_default();
    let bias =
        pt_spectra::bias::BiasParams::from_convention(convention, [args.b1, args.b2, args.bs, 0.0]);
    Ok(Some(pt_spectra::jobs::loop_bias(
        &bias,
        args.b_gamma3,
        &overrides,
    )?))
}

/// The triangle set of the options.
fn triangles(args: &Args) -> Result<TriangleSet> {
    if let Some(path) = &args.triangles {
        let t = DataColumns::read(path, &[0, 1, 2]).context("--triangles")?;
        let rows: Vec<[f64; 3]> = (0..t.columns[0].len())
            .map(|i| [t.columns[0][i], t.columns[1][i], t.columns[2][i]])
            .collect();
        let set = match args.bin_width {
            Some(w) => TriangleSet::shells(rows, w),
            None => {
                eprintln!(
                    "warning: --triangles without --bin-width: B at the triangles themselves; a measurement's \
                     bins need --bin-width (their shell width) to be averaged over"
                );
                TriangleSet::points(rows)
            }
        };
        return set.with_context(|| format!("--triangles {}", path.display()));
    }
    match &args.k_edges {
        Some(text) => {
            let edges = crate::ept::edges(text, "--k-edges")?;
            TriangleSet::from_edges(&edges).context("--k-edges")
        }
        None => bail!("give the triangles: --triangles FILE (k1 k2 k3 [h/Mpc]) or --k-edges EDGES"),
    }
}

/// The pairs of `--pairs`.
fn pairs(path: &std::path::Path) -> Result<Vec<[f64; 2]>> {
    let t = DataColumns::read(path, &[0, 1]).context("--pairs")?;
    Ok((0..t.columns[0].len())
        .map(|i| [t.columns[0][i], t.columns[1][i]])
        .collect())
}

/// Runs the subcommand.
pub fn run(args: &Args) -> Result<()> {
    let mut inputs = args.spectrum.files();
    inputs.push(("--triangles", args.triangles.as_deref()));
    inputs.push(("--pairs", args.pairs.as_deref()));
    check_outputs(&[("--out", args.out.as_deref())], &inputs)?;
    let convention = args.bias_convention.unwrap_or_default();
    // the cubic slot does not enter the tree level: given as 0 in the convention
    let bias =
        pt_spectra::bias::BiasParams::from_convention(convention, [args.b1, args.b2, args.bs, 0.0]);
    let params = BispectrumParams {
        b1: bias.b1,
        b2: bias.b2,
        bs: bias.bs,
        c1: args.c1,
        b_shot: args.b_shot,
        p_shot: args.p_shot,
        a_shot: args.a_shot,
        n_bar: args.n_bar.unwrap_or(f64::INFINITY),
    };
    let fog = Fog::by_name(&args.fog, args.sigma_fog)?;
    match args.loop_order {
        0 if args.multipoles => {
            bail!("--multipoles is for --loop 1 (the tree level always gives B0, B2, B4)")
        }
        0 if args.mu1.is_some() => {
            bail!("--mu1 is the orientation of the one-loop matter bispectrum: give --loop 1 (the tree \
                   level averages over orientations: B0, B2, B4)")
        }
        0 if args.b_gamma3 != 0.0 || args.loop_bias.is_some() => {
            bail!("--b-gamma3 and --loop-bias are the one-loop bispectrum's bias: give --loop 1 (the \
                   tree level takes --b1, --b2, --bs)")
        }
        0 => {}
        1 => return write_output(args.out.as_ref(), &one_loop(args)?),
        n => bail!(
            "--loop {n}: valid: 0 (tree level), 1 (one-loop matter or galaxies, real space, or redshift \
             space at one orientation with --mu1)"
        ),
    }
    let table = match args.basis.to_ascii_lowercase().as_str() {
        "scoccimarro" => {
            if args.pairs.is_some() {
                bail!("--pairs is for --basis sugiyama; the Scoccimarro multipoles take --triangles or --k-edges");
            }
            let request = BispectrumRequest {
                triangles: triangles(args)?,
                side: LegendreSide::by_name(&args.legendre_side).context("--legendre-side")?,
                rules: PlanRules {
                    effective: args.effective,
                    ..PlanRules::default()
                },
                params,
                f: args.f,
                q: (args.q_par, args.q_perp),
                fog,
                ir: !args.no_ir,
                box_size: args.box_size,
            };
            let loaded = args.spectrum.load()?;
            bispectrum_table(&loaded.prepared, &request)?
        }
        "sugiyama" => {
            let Some(path) = &args.pairs else {
                bail!("--basis sugiyama needs --pairs FILE (columns k1 k2 [h/Mpc])");
            };
            if args.box_size.is_some() {
                bail!("--box is for the Scoccimarro multipoles of triangle bins");
            }
            if args.legendre_side != "largest" {
                bail!("--legendre-side is for --basis scoccimarro (the Sugiyama multipoles have no Legendre side)");
            }
            let request = SugiyamaRequest {
                pairs: pairs(path)?,
                rules: SugiyamaRules::default(),
                params,
                f: args.f,
                q: (args.q_par, args.q_perp),
                fog,
                ir: !args.no_ir,
            };
            let loaded = args.spectrum.load()?;
            sugiyama_table(&loaded.prepared, &request)
                .with_context(|| format!("--pairs {}", path.display()))?
        }
        other => bail!("--basis {other}: valid: scoccimarro, sugiyama"),
    };
    let mut table = table;
    if convention != pt_spectra::bias::BiasConvention::Velocileptors {
        table.header.push(bias.describe(convention));
    }
    write_output(args.out.as_ref(), &table)
}
