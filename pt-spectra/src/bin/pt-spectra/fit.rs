//! `pt-spectra fit`: best-fit f, σ0, A_b with Δχ² errors against measured multipoles, versus k_max.

use crate::common::{list, parse_cs2, parsed, BiasArgs, NoiseArgs};
use crate::ept::{EptArgs, RsdChoice};
use crate::input::SpectrumInput;
use crate::output::{check_outputs, write_output};
use crate::progress::Bars;
use anyhow::{bail, Context, Result};
use pt_spectra::fit::galaxy::{GalaxyFitRequest, Prior};
use pt_spectra::fit::{ContourGrid, MultipoleData, Parameter};
use pt_spectra::jobs::{fit_tables, FitOutputs, FitRequest, RsdRequest};
use pt_spectra::real::RealModel;
use pt_spectra::rsd::{Fog, RsdPlan, Sigma0};
use std::path::PathBuf;

/// Arguments of `pt-spectra fit`.
#[derive(clap::Args, Debug)]
pub struct Args {
    #[command(flatten)]
    spectrum: SpectrumInput,
    /// Measured multipoles: a table with k [h/Mpc] and, per multipole, P_l and its 1σ error [(Mpc/h)^3].
    #[arg(long, value_name = "FILE", required_unless_present = "analysis")]
    data: Option<PathBuf>,
    /// A joint fit of the galaxy model `ept` to several data sets described by a TOML analysis file
    /// (each set's data, covariance, window, z, k ranges, multipoles, free and marginalised parameters,
    /// priors; the shared parameters; docs/analysis.md). The cosmology and linear spectrum come from
    /// the options (--cosmology, --linear, …), the redshifts from the file.
    #[arg(long, value_name = "FILE.toml", conflicts_with_all = [
        "data", "covariance", "data_columns", "data_ells", "ells", "free", "marginalise", "prior",
        "n_mocks", "k_min", "k_max", "k_range_ell", "xi", "apar", "aperp", "fiducial", "starts",
        "seed", "no_profile_check", "profile_linear", "profile", "model_out", "contour", "z",
        "basis", "n_bar", "satellites", "desi_priors",
    ])]
    analysis: Option<PathBuf>,
    /// 1-based columns of the data: k, then P_l and σ_l for each of --data-ells.
    #[arg(long, value_name = "K,P,S,…", default_value = "1,2,3,4,5,6,7")]
    data_columns: String,
    /// The multipoles in the data file, in column order.
    #[arg(long, value_name = "L,L,…", default_value = "0,2,4")]
    data_ells: String,
    /// The multipoles to fit (jointly), a subset of --data-ells.
    #[arg(long, value_name = "L,L,…", default_value = "0")]
    ells: String,
    /// Optional full covariance of the fitted data vector (ℓ-major over --ells, all k of the file): a
    /// whitespace square matrix. Default: diagonal σ².
    #[arg(long, value_name = "FILE")]
    covariance: Option<PathBuf>,
    /// Real-space model: linear, 1l-spt, 2l-spt, 1l-rpt-n0..n3, 2l-rpt-n0..n3.
    #[arg(long = "real", value_name = "M", default_value = pt_spectra::jobs::defaults::FIT_REAL_MODEL, value_parser = parsed::<RealModel>)]
    real_model: RealModel,
    /// Redshift-space model: kaiser, scoccimarro or tns; or ept, the galaxy model (free, marginalised
    /// and prior parameters by velocileptors' names: b1 is --bias, then --b2 --bs --b3 --alpha0..6
    /// --sn --sn2 --sn4 as start values or fixed values).
    #[arg(long, value_name = "MODEL", default_value = pt_spectra::jobs::defaults::RSD_MODEL, value_parser = parsed::<RsdChoice>)]
    rsd: RsdChoice,
    /// Fingers of God: none, lorentzian or gaussian.
    #[arg(long, value_name = "KIND", default_value = pt_spectra::jobs::defaults::FIT_FOG, value_parser = parsed::<Fog>)]
    fog: Fog,
    /// Free parameters, comma separated: f, sigma0, ab, cs2 (the EFT counterterm of --cs2); with
    /// --rsd ept any of f, b1, b2, bs, b3, alpha0, alpha2, alpha4, alpha6, sn, sn2, sn4. Default
    /// f,sigma0 (ept: f,b1).
    #[arg(long, value_name = "P,P")]
    free: Option<String>,
    /// --rsd ept: parameters that enter linearly, marginalised analytically (of alpha0, alpha2,
    /// alpha4, alpha6, sn, sn2, sn4), comma separated.
    #[arg(long, value_name = "P,P")]
    marginalise: Option<String>,
    /// --rsd ept: the number of mocks the --covariance was estimated from: its inverse is scaled by the
    /// Hartlap factor (N − p − 2)/(N − 1), p the fitted points.
    #[arg(long, value_name = "N")]
    n_mocks: Option<usize>,
    /// --rsd ept: a prior on a free or marginalised parameter (repeat the option for several):
    /// Gaussian NAME:MEAN,SIGMA, flat NAME:flat,LO,HI (bounds the fit), or log-normal
    /// NAME:lognormal,MU,SIGMA (of ln NAME). Marginalised parameters take Gaussian priors only.
    #[arg(long, value_name = "NAME:MEAN,SIGMA|NAME:flat,LO,HI")]
    prior: Vec<String>,
    /// --rsd ept: the basis of --free, --marginalise and --prior: `velocileptors` (the model's own
    /// b1, b2, bs, b3, alpha0..6, sn, sn2, sn4), `classpt` (CLASS-PT's bias b1, b2, bG2, bGamma3, the
    /// rest velocileptors') or `desi` (the DESI DR1 physical basis b1p = b1 sigma8(z), b2p, bsp, b3p,
    /// alpha0p, alpha2p, alpha4p, sn0p, sn2p, sn4p in units of 1/n_bar; needs --n-bar;
    /// docs/reference.md). Start values stay the model's (--bias, --b2, ...).
    #[arg(long, value_name = "BASIS", default_value = "velocileptors")]
    basis: String,
    /// --basis desi: the sample's number density [(h/Mpc)^3] (the unit of sn0p, sn2p, sn4p).
    #[arg(long, value_name = "N")]
    n_bar: Option<f64>,
    /// --basis desi: satellite fraction and velocity dispersion [Mpc/h] of sn2p, sn4p (desilike's
    /// generic 0.1 and 5).
    #[arg(long, value_name = "FSAT,SIGV", value_parser = parse_pair)]
    satellites: Option<(f64, f64)>,
    /// --basis desi: add the DESI DR1 priors (b1p flat [0, 3]; b2p, bsp N(0, 5); alpha0p, alpha2p,
    /// alpha4p N(0, 12.5); sn0p N(0, 2); sn2p, sn4p N(0, 5)) to the free and marginalised parameters
    /// that have no --prior.
    #[arg(long)]
    desi_priors: bool,
    /// --rsd ept: second-order bias b2 (start or fixed value).
    #[arg(long, value_name = "B2", allow_hyphen_values = true)]
    b2: Option<f64>,
    /// --rsd ept: tidal bias bs (start or fixed value).
    #[arg(long, value_name = "BS", allow_hyphen_values = true)]
    bs: Option<f64>,
    /// --rsd ept: cubic bias b3 (start or fixed value).
    #[arg(long, value_name = "B3", allow_hyphen_values = true)]
    b3: Option<f64>,
    /// --rsd ept: Alcock–Paczynski α∥ of the measurement (needs --aperp); start value if free
    /// (`--free …,apar,aperp`, searched in [0.8, 1.25]).
    #[arg(
        long,
        value_name = "A",
        requires = "aperp",
        conflicts_with = "fiducial"
    )]
    apar: Option<f64>,
    /// --rsd ept: the fiducial cosmology the data were measured in (preset or .ini): α∥, α⊥ from
    /// its H(z), D_M(z) against --cosmology's.
    #[arg(long, value_name = "NAME|FILE")]
    fiducial: Option<String>,
    /// --rsd ept: Alcock–Paczynski α⊥ of the measurement (needs --apar).
    #[arg(long, value_name = "A", requires = "apar")]
    aperp: Option<f64>,
    #[command(flatten)]
    ept: EptArgs,
    /// Growth rate: start value if free, value if fixed. Default: f(z) of the cosmology.
    #[arg(long, value_name = "F", allow_hyphen_values = true)]
    f: Option<f64>,
    /// σ0 [Mpc/h]: start value if free, value if fixed; a number, or the theory value of eq. sigmav as
    /// in `rsd`: `lin` (P_lin) or `1l-spt` (1-loop SPT P_θθ for q ≤ 0.3 h/Mpc, P_lin above).
    #[arg(
        long,
        value_name = "S",
        default_value = pt_spectra::jobs::defaults::FIT_SIGMA0_TEXT,
        allow_hyphen_values = true,
        value_parser = parsed::<Sigma0>
    )]
    sigma0: Sigma0,
    /// EFT counterterm c_s² [(Mpc/h)²] (as `real --cs2`): start value if free, value if fixed.
    #[arg(long, value_name = "CS2", default_value_t = 0.0, allow_hyphen_values = true, value_parser = parse_cs2)]
    cs2: f64,
    #[command(flatten)]
    bias: BiasArgs,
    #[command(flatten)]
    noise: NoiseArgs,
    /// Smallest k used [h/Mpc].
    #[arg(long, value_name = "K", default_value_t = 0.0)]
    k_min: f64,
    /// k_max [h/Mpc]: one value, a list `a,b,c`, or a scan `start:end:step`.
    #[arg(long, value_name = "K", default_value = K_MAX_SCAN)]
    k_max: String,
    /// --rsd ept: a narrower range for one multipole, `L:KMIN,KMAX` [h/Mpc] (s [Mpc/h] with --xi;
    /// repeat the option for several): ℓ = L is fitted over [max(k_min, KMIN), min(k_max, KMAX)].
    #[arg(long = "k-range-ell", value_name = "L:KMIN,KMAX")]
    k_range_ell: Vec<String>,
    /// --rsd ept: the data are correlation-function multipoles ξ_ℓ(s), s [Mpc/h] in the first data
    /// column (errors and covariance likewise): the model's ξ_ℓ by FFTLog, no window (a Landy–Szalay
    /// estimate divides it out), fitted over --s-min ≤ s ≤ --s-max.
    #[arg(long)]
    xi: bool,
    /// --xi: the smallest s fitted [Mpc/h].
    #[arg(long, value_name = "S", default_value_t = 30.0, requires = "xi")]
    s_min: f64,
    /// --xi: the largest s fitted [Mpc/h]: one value, a list or a scan `start:end:step`.
    #[arg(long, value_name = "S", default_value = "150", requires = "xi")]
    s_max: String,
    /// --xi: the data are means over s bins of these edges [Mpc/h] (`a,b,c,…` or `start:end:step`):
    /// the model is averaged with the pair-count weight s².
    #[arg(long, value_name = "EDGES", requires = "xi")]
    s_edges: Option<String>,
    /// --rsd ept: starts of the minimiser (the start given, then draws from the priors or the start
    /// box); the lowest minimum is taken and the table says how many agree with it.
    #[arg(long, value_name = "N", default_value_t = pt_spectra::fit::galaxy::search::DEFAULT_STARTS)]
    starts: usize,
    /// --rsd ept: the seed of the starts' draws.
    #[arg(long, value_name = "SEED", default_value_t = 1)]
    seed: u64,
    /// --rsd ept: skip the check of the Hessian errors by the profile likelihood (faster; no
    /// <p>_lo, <p>_hi).
    #[arg(long)]
    no_profile_check: bool,
    /// --rsd ept: profile the linear (--marginalise) parameters, at their best values, instead of
    /// marginalising them (no ln det F term).
    #[arg(long)]
    profile_linear: bool,
    /// --rsd ept: write the profile likelihood of this free parameter at the (single) --k-max instead
    /// of the fit table: a row per value, the other free parameters re-minimised.
    #[arg(long, value_name = "P")]
    profile: Option<String>,
    /// --profile: values on the grid (3 to 401).
    #[arg(long, value_name = "N", default_value_t = 21, requires = "profile")]
    profile_points: usize,
    /// --profile: the grid's half-width in units of the parameter's fitted error.
    #[arg(long, value_name = "S", default_value_t = 3.0, requires = "profile")]
    profile_span: f64,
    /// Write the table to this file instead of standard output.
    #[arg(long, value_name = "FILE")]
    out: Option<PathBuf>,
    /// Write the best-fit model multipoles of every k_max to this file: `k`, the fitted data
    /// `P<l>_data err_P<l>_data`, the no-wiggle reference `P<l>_nw` (not with ept) and `P<l>_kmax<K>`
    /// (the model curves of the paper's figures, windowed with ept's --window; `plot multipoles`
    /// draws them).
    #[arg(long, value_name = "FILE")]
    model_out: Option<PathBuf>,
    /// Two free parameters, e.g. `f,sigma0`, `f,ab` or `f,cs2`: write their Δχ² surface at every k_max to
    /// --contour-out, the other free parameters re-minimised at each point (`plot contour` draws the
    /// Δχ² = 2.3 and 6.17 contours).
    #[arg(long, value_name = "P1,P2", requires = "contour_out")]
    contour: Option<String>,
    /// The file of the --contour surface: `k_max i j <P1> <P2> chi2 delta_chi2 <other free>`, a row per
    /// grid point (i, j).
    #[arg(long, value_name = "FILE", requires = "contour")]
    contour_out: Option<PathBuf>,
    /// Grid points per axis of the --contour surface (3 to 401).
    #[arg(long, value_name = "N", default_value_t = 41)]
    contour_points: usize,
    /// Half-width of each --contour axis in units of the Δχ² = 2.3 ellipse's semi-axis along it (the grid
    /// follows the ellipse's principal axes, which resolves degenerate planes such as f–A_b).
    #[arg(long, value_name = "S", default_value_t = 2.5)]
    contour_span: f64,
}

/// The default scan of --k-max.
const K_MAX_SCAN: &str = "0.05:0.25:0.01";

/// The path of --data (required unless --analysis is given).
fn data_path(args: &Args) -> Result<&std::path::Path> {
    args.data
        .as_deref()
        .ok_or_else(|| anyhow::anyhow!("fit needs --data FILE (or --analysis FILE.toml)"))
}

/// The data of --data (the multipoles of --ells) and --covariance, and the fitted ells.
fn read_data(args: &Args) -> Result<(MultipoleData, Vec<usize>)> {
    let data_ells: Vec<usize> = list(&args.data_ells, "--data-ells")?;
    let ells: Vec<usize> = list(&args.ells, "--ells")?;
    let cols: Vec<usize> = list(&args.data_columns, "--data-columns")?;
    let layout = pt_spectra::fit::DataLayout::new(&data_ells, Some(&cols))
        .map_err(|e| anyhow::anyhow!("--data-columns/--data-ells: {e}"))?;
    let mut data = layout
        .read(data_path(args)?, &ells)
        .map_err(|e| anyhow::anyhow!("--ells/--data: {e}"))?;
    if let Some(path) = &args.covariance {
        data = layout.read_covariance(data, path).context("--covariance")?;
    }
    Ok((data, ells))
}

/// `fit --rsd ept`: the galaxy model's fits with marginalisation and priors.
fn run_ept(args: &Args) -> Result<()> {
    let refused = [
        ("--real", args.real_model != RealModel::OneLoopSpt),
        ("--fog", args.fog != Fog::Lorentzian),
        ("--cs2", args.cs2 != 0.0),
        ("--amplitude", args.bias.amplitude != 1.0),
        (
            "--shot-noise/--number-density/--noise-file (use --sn)",
            args.noise.is_set(),
        ),
        ("--contour (use --profile)", args.contour.is_some()),
    ];
    if let Some((flag, _)) = refused.iter().find(|(_, given)| *given) {
        bail!("{flag} is not an option of fit --rsd ept");
    }
    if args.xi {
        for (flag, given) in [
            ("--k-max (use --s-max)", args.k_max != K_MAX_SCAN),
            ("--k-min (use --s-min)", args.k_min != 0.0),
            ("--window (xi has none)", args.ept.has_window()),
            ("--k-edges/--box (use --s-edges)", args.ept.has_bins()),
        ] {
            if given {
                bail!("{flag} is not an option of fit --xi");
            }
        }
    }
    let (data, ells) = read_data(args)?;
    let b1 = match args.bias.bias()? {
        pt_spectra::halo::Bias::Constant(b) => b,
        pt_spectra::halo::Bias::Table(_) => bail!("--rsd ept takes a constant --bias (b1)"),
    };
    let loaded = args.spectrum.load()?;
    let mut start =
        pt_spectra::rsd::ept::EptParams::new(b1, args.f.unwrap_or(loaded.prepared.growth_rate));
    for (name, value) in [("b2", args.b2), ("bs", args.bs), ("b3", args.b3)]
        .into_iter()
        .chain(args.ept.values())
    {
        if let Some(v) = value {
            start.set(name, v)?;
        }
    }
    let names = |s: Option<&str>, default: &str| -> Vec<String> {
        s.unwrap_or(default)
            .split(',')
            .map(|n| n.trim().to_string())
            .filter(|n| !n.is_empty())
            .collect()
    };
    let mut priors = args
        .prior
        .iter()
        .map(|text| parse_prior(text))
        .collect::<Result<Vec<_>>>()?;
    let (window, bins) = args.ept.observation()?;
    let spec = pt_spectra::jobs::ObservationSpec {
        window,
        bins,
        xi: args.xi,
        ap: crate::common::ap_spec(args.apar, args.aperp, args.fiducial.as_deref())?,
        s_edges: args
            .s_edges
            .as_deref()
            .map(|t| crate::ept::edges(t, "--s-edges"))
            .transpose()?,
    };
    let distortion = spec
        .ap
        .distortion(&loaded.prepared.cosmology.cosmology, loaded.prepared.z)?;
    let free = names(args.free.as_deref(), "f,b1");
    let free_ap = pt_spectra::rsd::ap::ApSpec::check_free(distortion.as_ref(), &free)?;
    let marginalise = names(args.marginalise.as_deref(), "");
    let basis = fit_basis(args, loaded.prepared.spectrum.sigma8())?;
    if args.desi_priors {
        pt_spectra::jobs::add_desi_priors(&mut priors, &free, &marginalise);
    }
    let request = GalaxyFitRequest {
        start,
        ap: distortion,
        free,
        marginalise,
        priors,
        ells,
        k_min: if args.xi { args.s_min } else { args.k_min },
        k_max: 0.0,
        ell_ranges: args
            .k_range_ell
            .iter()
            .map(|t| parse_ell_range(t))
            .collect::<Result<_>>()?,
        n_mocks: args.n_mocks,
        basis,
    };
    let observation = spec
        .build(&request.ells, &data.k)
        .context("--xi/--s-edges/--window/--k-edges")?;
    let model_k = observation
        .as_ref()
        .map_or(data.k.as_slice(), |o| o.k_model());
    let plan = pt_spectra::jobs::ept_plan(
        model_k,
        !args.ept.no_ir(),
        distortion,
        free_ap,
        &loaded.precision,
        &loaded.store,
        &Bars::default(),
    )?;
    let terms = plan.terms(loaded.prepared.tracer_spectrum())?;
    let mut header = vec![format!(
        "pt-spectra {} fit: ept (velocileptors' REPT conventions{}) to {}",
        pt_spectra::jobs::VERSION,
        if args.ept.no_ir() {
            ", no IR resummation"
        } else {
            ", IR resummed"
        },
        data_path(args)?.display()
    )];
    header.extend(pt_spectra::jobs::describe_inputs(
        &loaded.prepared,
        &loaded.precision,
    ));
    let maxima = k_max_values(if args.xi { &args.s_max } else { &args.k_max })?;
    // --s-max at or below --s-min: named as separations (it was reported as an invalid k_max).
    if let Some(s_max) = maxima.iter().find(|&&s| args.xi && s <= args.s_min) {
        bail!(
            "--s-max {s_max} Mpc/h must exceed --s-min {} Mpc/h (the fitted s range is empty)",
            args.s_min
        );
    }
    let context = pt_spectra::jobs::FitContext {
        observation: observation.as_ref(),
        search: search(args)?,
        template: Some(pt_spectra::fit::galaxy::Template {
            sigma8_z: loaded.prepared.spectrum.sigma8(),
            z: loaded.prepared.z,
            cosmology: Some(loaded.prepared.cosmology.cosmology),
        }),
        header,
    };
    if let Some(name) = &args.profile {
        let [k_max] = maxima[..] else {
            bail!(
                "--profile needs one --k-max (or --s-max), not {}",
                maxima.len()
            );
        };
        let mut r = request.clone();
        r.k_max = k_max;
        let grid = pt_spectra::fit::galaxy::ProfileGrid {
            points: args.profile_points,
            span: args.profile_span,
        };
        let table =
            pt_spectra::jobs::ept_profile_table(&plan, &terms, &data, &r, &context, name, &grid)?;
        return write_output(args.out.as_ref(), &table);
    }
    let (table, fits) =
        pt_spectra::jobs::ept_fit_table(&plan, &terms, &data, &request, &maxima, &context)?;
    if let Some(path) = &args.model_out {
        let model = pt_spectra::jobs::ept_model_table(
            &plan, &terms, &data, &request, &fits, &maxima, &context,
        )?;
        write_output(Some(path), &model)?;
    }
    write_output(args.out.as_ref(), &table)
}

/// The minimiser's settings of --starts, --seed, --no-profile-check, --profile-linear.
fn search(args: &Args) -> Result<pt_spectra::fit::galaxy::Search> {
    if args.starts == 0 {
        bail!("--starts 0: the fit needs at least one start");
    }
    Ok(pt_spectra::fit::galaxy::Search {
        starts: args.starts,
        seed: args.seed,
        profile_check: !args.no_profile_check,
        linear: if args.profile_linear {
            pt_spectra::fit::galaxy::Linear::Profiled
        } else {
            pt_spectra::fit::galaxy::Linear::Marginalised
        },
    })
}

/// L:KMIN,KMAX of --k-range-ell.
fn parse_ell_range(text: &str) -> Result<(usize, f64, f64)> {
    let parse = || -> Option<(usize, f64, f64)> {
        let (l, range) = text.split_once(':')?;
        let (a, b) = range.split_once(',')?;
        Some((
            l.trim().parse().ok()?,
            a.trim().parse().ok()?,
            b.trim().parse().ok()?,
        ))
    };
    parse().ok_or_else(|| anyhow::anyhow!("--k-range-ell {text}: expected L:KMIN,KMAX"))
}

/// The parameter basis of the options ([`pt_spectra::jobs::fit_basis`]) at σ₈(z) `sigma8`.
fn fit_basis(args: &Args, sigma8: f64) -> Result<pt_spectra::fit::galaxy::FitBasis> {
    Ok(pt_spectra::jobs::fit_basis(
        &args.basis,
        sigma8,
        args.n_bar,
        args.satellites,
        args.desi_priors,
    )?)
}

/// `A,B` as two numbers.
fn parse_pair(text: &str) -> std::result::Result<(f64, f64), String> {
    let parts: Vec<&str> = text.split(',').map(str::trim).collect();
    match parts[..] {
        [a, b] => match (a.parse(), b.parse()) {
            (Ok(a), Ok(b)) => Ok((a, b)),
            _ => Err(format!("`{text}`: expected two numbers A,B")),
        },
        _ => Err(format!("`{text}`: expected two numbers A,B")),
    }
}

fn parse_prior(text: &str) -> Result<Prior> {
    Prior::parse(text).map_err(|e| anyhow::anyhow!("--prior: {e}"))
}

/// `a:b:step` (inclusive, to rounding), a list, or one value.
fn k_max_values(s: &str) -> Result<Vec<f64>> {
    let parts: Vec<&str> = s.split(':').collect();
    let v = match parts[..] {
        [a, b, step] => {
            let (a, b, step): (f64, f64, f64) =
                (a.trim().parse()?, b.trim().parse()?, step.trim().parse()?);
            if !(a.is_finite() && b >= a && step > 0.0) {
                bail!("--k-max {s}: needs start <= end and step > 0");
            }
            let n = ((b - a) / step + 1e-9).floor() as usize;
            (0..=n).map(|i| a + step * i as f64).collect()
        }
        [_] => list(s, "--k-max")?,
        _ => bail!("--k-max {s}: expected K, a list K,K,… or start:end:step"),
    };
    if let Some(bad) = v.iter().find(|k| !(k.is_finite() && **k > 0.0)) {
        bail!("--k-max/--s-max: {bad} is not positive");
    }
    Ok(v)
}

/// Runs the subcommand.
pub fn run(args: &Args) -> Result<()> {
    if let Some(path) = &args.analysis {
        return crate::analysis::run(path, &args.spectrum, args.rsd, args.out.as_deref());
    }
    let mut inputs = args.spectrum.files();
    inputs.push(("--data", Some(data_path(args)?)));
    inputs.push(("--covariance", args.covariance.as_deref()));
    inputs.extend(args.bias.files());
    inputs.extend(args.noise.files());
    let outputs = [
        ("--out", args.out.as_deref()),
        ("--model-out", args.model_out.as_deref()),
        ("--contour-out", args.contour_out.as_deref()),
    ];
    check_outputs(&outputs, &inputs)?;
    if args.rsd == RsdChoice::Ept {
        return run_ept(args);
    }
    let RsdChoice::Paper(rsd) = args.rsd else {
        unreachable!("ept returned above")
    };
    let paper_only_refused = [
        ("--marginalise", args.marginalise.is_some()),
        ("--xi", args.xi),
        ("--k-range-ell", !args.k_range_ell.is_empty()),
        (
            "--window/--k-edges/--box (fit --rsd ept takes them)",
            args.ept.has_window() || args.ept.has_bins(),
        ),
        ("--prior", !args.prior.is_empty()),
        (
            "--basis/--n-bar/--satellites/--desi-priors",
            args.basis != "velocileptors"
                || args.n_bar.is_some()
                || args.satellites.is_some()
                || args.desi_priors,
        ),
        ("--n-mocks", args.n_mocks.is_some()),
        ("--profile", args.profile.is_some()),
        (
            "--starts/--seed/--no-profile-check/--profile-linear",
            args.starts != pt_spectra::fit::galaxy::search::DEFAULT_STARTS
                || args.seed != 1
                || args.no_profile_check
                || args.profile_linear,
        ),
        (
            "--b2/--bs/--b3",
            args.b2.is_some() || args.bs.is_some() || args.b3.is_some(),
        ),
        (
            "--apar/--aperp/--fiducial",
            args.apar.is_some() || args.fiducial.is_some(),
        ),
    ];
    if let Some(flag) = args
        .ept
        .given()
        .first()
        .copied()
        .or_else(|| paper_only_refused.iter().find(|(_, g)| *g).map(|(f, _)| *f))
    {
        bail!("{flag} is an option of --rsd ept, not of --rsd {rsd}");
    }
    let free: Vec<Parameter> = args
        .free
        .as_deref()
        .unwrap_or("f,sigma0")
        .split(',')
        .map(str::parse)
        .collect::<Result<_, _>>()?;
    let (data, ells) = read_data(args)?;
    let request = FitRequest {
        model: RsdRequest {
            rsd,
            f: args.f,
            bias: args.bias.bias()?,
            amplitude: args.bias.amplitude,
            fog: args.fog,
            sigma0: args.sigma0,
            noise: args.noise.noise()?,
            ells,
            terms: false,
            no_wiggle: false,
            cs2: args.cs2,
            galaxy: None,
            ap: None,
        },
        free,
        k_min: args.k_min,
        k_max: k_max_values(&args.k_max)?,
        data_name: data_path(args)?.display().to_string(),
    };
    for (name, v) in [("--amplitude", args.bias.amplitude)]
        .into_iter()
        .chain(args.f.map(|f| ("--f", f)))
    {
        if !v.is_finite() {
            bail!("{name} {v}: must be finite");
        }
    }
    let loaded = args.spectrum.load()?;
    let bars = Bars::default();
    let (precision, store) = (&loaded.precision, &loaded.store);
    let outputs = FitOutputs {
        model: args.model_out.is_some(),
        contour: match &args.contour {
            None => None,
            Some(text) => Some(contour_grid(text, args, &request.free)?),
        },
    };
    let plan = RsdPlan::new(&data.k, args.real_model, rsd, precision, store, &bars)?;
    let tables = fit_tables(&plan, data, &request, outputs, &loaded.prepared, &bars)?;
    for (path, table) in [
        (args.model_out.as_ref(), tables.model.as_ref()),
        (args.contour_out.as_ref(), tables.contour.as_ref()),
    ] {
        if let (Some(path), Some(table)) = (path, table) {
            write_output(Some(path), table)?;
        }
    }
    write_output(args.out.as_ref(), &tables.fit)
}

/// The grid of `--contour P1,P2`: two different parameters among the free ones.
fn contour_grid(text: &str, args: &Args, free: &[Parameter]) -> Result<ContourGrid> {
    let pair: Vec<Parameter> = text
        .split(',')
        .map(str::parse)
        .collect::<Result<_, _>>()
        .with_context(|| format!("--contour {text}"))?;
    let [x, y] = pair[..] else {
        bail!("--contour {text}: expected two parameters P1,P2, e.g. f,sigma0");
    };
    let (points, span) = (args.contour_points, args.contour_span);
    ContourGrid::new(x, y, points, span, free).map_err(|e| match e {
        // "contour P1,P2: …" names the option's value already.
        pt_spectra::error::Error::InvalidChoice { .. } => anyhow::anyhow!("--{e}"),
        e => anyhow::Error::new(e)
            .context(format!("--contour-points {points} --contour-span {span}")),
    })
}
