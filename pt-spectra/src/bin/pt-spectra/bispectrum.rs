//! `pt-spectra bispectrum`: the tree-level galaxy bispectrum multipoles B0, B2, B4 in redshift space at
//! triangles or averaged over the triangle bins of a measurement.

use crate::input::SpectrumInput;
use crate::output::{check_outputs, write_output};
use anyhow::{bail, Context, Result};
use pt_spectra::bispectrum::{BispectrumParams, Fog, LegendreSide, PlanRules, TriangleSet};
use pt_spectra::jobs::{bispectrum_table, BispectrumRequest};
use pt_spectra::table::Table;
use std::path::PathBuf;

/// Arguments of `pt-spectra bispectrum`.
#[derive(clap::Args, Debug)]
pub struct Args {
    #[command(flatten)]
    spectrum: SpectrumInput,
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
    /// Switch off the IR resummation of the BAO in every leg.
    #[arg(long)]
    no_ir: bool,
    /// Write the table to this file instead of standard output.
    #[arg(long, value_name = "FILE")]
    out: Option<PathBuf>,
}

/// The triangle set of the options.
fn triangles(args: &Args) -> Result<TriangleSet> {
    if let Some(path) = &args.triangles {
        let t = Table::read(path, &[0, 1, 2]).context("--triangles")?;
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

/// Runs the subcommand.
pub fn run(args: &Args) -> Result<()> {
    let mut inputs = args.spectrum.files();
    inputs.push(("--triangles", args.triangles.as_deref()));
    check_outputs(&[("--out", args.out.as_deref())], &inputs)?;
    let side = LegendreSide::by_name(&args.legendre_side).context("--legendre-side")?;
    let params = BispectrumParams {
        b1: args.b1,
        b2: args.b2,
        bs: args.bs,
        c1: args.c1,
        b_shot: args.b_shot,
        p_shot: args.p_shot,
        a_shot: args.a_shot,
        n_bar: args.n_bar.unwrap_or(f64::INFINITY),
    };
    let request = BispectrumRequest {
        triangles: triangles(args)?,
        side,
        rules: PlanRules::default(),
        params,
        f: args.f,
        q: (args.q_par, args.q_perp),
        fog: Fog::by_name(&args.fog, args.sigma_fog)?,
        ir: !args.no_ir,
    };
    let loaded = args.spectrum.load()?;
    let table = bispectrum_table(&loaded.prepared, &request)?;
    write_output(args.out.as_ref(), &table)
}
