//! `pt-spectra real`: real-space P_δδ, P_δθ, P_θθ of a model on a k grid, as a whitespace table.

use crate::common::{parse_cs2, parsed, GalaxyBiasArgs};
use crate::input::Input;
use crate::output::{check_outputs, write_output};
use crate::progress::Bars;
use anyhow::{bail, Context, Result};
use pt_spectra::jobs::{real_table_with_bias, BiasOutput};
use pt_spectra::loops::bias::BiasPlan;
use pt_spectra::real::{Counterterms, RealPlan, RealSelection};
use std::path::PathBuf;

/// Arguments of `pt-spectra real`.
#[derive(clap::Args, Debug)]
pub struct Args {
    #[command(flatten)]
    input: Input,
    /// Model: linear, 1l-spt, 2l-spt, 1l-rpt-n0..n3, 2l-rpt-n0..n3 (N3 builds the P17 table once),
    /// 1l-regpt, 2l-regpt (RegPT), 1l-spt-ir, 2l-spt-ir (IR-resummed BAO), 2l-eft, 2l-eft-ir
    /// (2-loop SPT + the EFT counterterms of --ct);
    /// or `all`: P_dd/P_nowiggle of every model, one column each (the paper's real-space comparison).
    #[arg(long, value_name = "M", default_value = pt_spectra::jobs::defaults::REAL_MODEL, value_parser = parsed::<RealSelection>)]
    model: RealSelection,
    /// Also print the separate loop terms, σ_v² and propagators, each with its error estimate (and,
    /// with counterterms, their sum P_ct_dd P_ct_dt P_ct_tt; for 2l-eft, 2l-eft-ir the derivatives
    /// T_dd_X T_dt_X T_tt_X of P in each counterterm X, so that P = P(0) + Σ X T_X).
    #[arg(long)]
    terms: bool,
    /// EFT counterterm c_s² [(Mpc/h)²] added to the model: P_dd − 2 c_s² k² P_lin, P_dt − 4 c_s² k²
    /// P_lin, P_tt − 6 c_s² k² P_lin (δ_ct ∝ D³, θ_ct = 3 δ_ct by mass conservation); exact.
    #[arg(long, value_name = "CS2", default_value_t = 0.0, allow_hyphen_values = true, value_parser = parse_cs2)]
    cs2: f64,
    /// EFT counterterm NAME=VALUE, repeatable: cs2 [(Mpc/h)²] (−2 cs2 k² P_lin, any model), and for
    /// 2l-eft, 2l-eft-ir cs2_1loop [(Mpc/h)²] (−2 cs2_1loop k² P_1loop) and c4 [(Mpc/h)⁴]
    /// (−2 c4 k⁴ P_lin); terms of P_dd, velocities in docs/eft.md. Default 0.
    #[arg(long = "ct", value_name = "NAME=VALUE", allow_hyphen_values = true)]
    ct: Vec<String>,
    /// Add the 1-loop bias terms Pd1d2 Pd2d2 Pd1s2 Pd2s2 Ps2s2 (FAST-PT's names and normalisation, no
    /// constant subtracted), their velocity counterparts Pt1d2 Pt1s2 and sig3nl, each with err_.
    #[arg(long)]
    bias_terms: bool,
    /// Linear galaxy bias b1: adds P_gg and P_gm (with err_) of the bias expansion on the model's P_dd,
    /// with --b2, --bs, --b3 (default 0).
    #[arg(long, value_name = "B1", allow_hyphen_values = true)]
    bias: Option<f64>,
    #[command(flatten)]
    galaxy: GalaxyBiasArgs,
    /// Write the table to this file instead of standard output.
    #[arg(long, value_name = "FILE")]
    out: Option<PathBuf>,
    /// Target relative error of the 2-loop correction of 2-loop models: where the quasi-Monte-Carlo
    /// error estimate exceeds it, points are added at that k (at most 4 times the initial ones).
    /// Default: 1e-3 with `--precision default`, 0 (fixed points) with `fast` and `reference`.
    #[arg(long, value_name = "REL", allow_hyphen_values = true)]
    two_loop_tolerance: Option<f64>,
}

/// Runs the subcommand.
pub fn run(args: &Args) -> Result<()> {
    check_outputs(&[("--out", args.out.as_deref())], &args.input.files())?;
    let (k, mut loaded) = args.input.load()?;
    if let Some(tolerance) = args.two_loop_tolerance {
        loaded.precision.two_loop_tolerance = tolerance;
        loaded
            .precision
            .validate()
            .context("invalid --two-loop-tolerance")?;
    }
    let bars = Bars::default();
    let bias = BiasOutput {
        terms: args.bias_terms,
        galaxy: args.bias.map(|b1| args.galaxy.params(b1)),
        given: args.galaxy.convention(),
    };
    if args.bias.is_none() && (args.galaxy.any() || args.galaxy.bias_convention.is_some()) {
        bail!("--b2, --bs, --b3 and --bias-convention need --bias (b1): the galaxy spectra are those of the bias expansion");
    }
    if args.bias.is_some() {
        args.galaxy.warn_if_implicit("real");
    }
    bias.validate(args.model)?;
    let counterterms = Counterterms::from_assignments(&args.ct)?.with_cs2(args.cs2)?;
    if let RealSelection::One(model) = args.model {
        counterterms.check(model)?;
        if model.is_eft() && counterterms.is_zero() {
            eprintln!(
                "warning: every counterterm of {model} is 0 (it is then 2-loop SPT): set them with \
                 --ct NAME=VALUE, or fit them with the T_ columns of --terms"
            );
        }
    }
    let plan = RealPlan::for_selection(&k, args.model, &loaded.precision, &loaded.store, &bars)?;
    let bias_plan = if bias.any() {
        Some(BiasPlan::new(&k, &loaded.precision)?)
    } else {
        None
    };
    let table = real_table_with_bias(
        &plan,
        bias_plan.as_ref(),
        args.model,
        &loaded.prepared,
        args.terms,
        &counterterms,
        bias,
        &bars,
    )?;
    write_output(args.out.as_ref(), &table)
}
