//! `pt-spectra real`: real-space P_δδ, P_δθ, P_θθ of a model on a k grid, as a whitespace table.

use crate::input::Input;
use crate::progress::Bars;
use anyhow::{Context, Result};
use pt_spectra::loops::Pair;
use pt_spectra::output::{Table, POWER, WAVENUMBER};
use pt_spectra::precision::Precision;
use pt_spectra::real::{RealModel, RealPlan, RealSpectra};
use std::io::Write;
use std::path::PathBuf;

/// A model name, or `all`.
#[derive(Clone, Copy, Debug)]
pub enum ModelChoice {
    /// One model.
    One(RealModel),
    /// Every model, as P_dd/P_nw.
    All,
}

fn parse_model(s: &str) -> std::result::Result<ModelChoice, String> {
    if s.trim().eq_ignore_ascii_case("all") {
        return Ok(ModelChoice::All);
    }
    s.parse()
        .map(ModelChoice::One)
        .map_err(|e: pt_spectra::error::Error| e.to_string())
}

/// Arguments of `pt-spectra real`.
#[derive(clap::Args, Debug)]
pub struct Args {
    #[command(flatten)]
    input: Input,
    /// Model: linear, 1l-spt, 2l-spt, 1l-rpt-n0..n3 or 2l-rpt-n0..n3 (N3 builds the P17 table once);
    /// or `all`: P_dd/P_nowiggle of every model, one column each (the paper's real-space comparison).
    #[arg(long, value_name = "M", default_value = "1l-spt", value_parser = parse_model)]
    model: ModelChoice,
    /// Also print the separate loop terms, σ_v² and propagators, each with its error estimate.
    #[arg(long)]
    terms: bool,
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
    let (k, mut loaded) = args.input.load()?;
    if let Some(tolerance) = args.two_loop_tolerance {
        loaded.precision.two_loop_tolerance = tolerance;
        loaded
            .precision
            .validate()
            .context("invalid --two-loop-tolerance")?;
    }
    // Every model's terms are a subset of 2l-rpt-n3's.
    let model = match args.model {
        ModelChoice::One(m) => m,
        ModelChoice::All => RealModel::TwoLoopRptN3,
    };
    let bars = Bars::default();
    let plan = RealPlan::new(&k, model, &loaded.precision, &loaded.store, &bars)?;
    let spectra = plan.evaluate(&loaded.prepared.spectrum, &bars)?;
    let mut header = vec![format!(
        "pt-spectra {} real: model {}, z = {}",
        env!("CARGO_PKG_VERSION"),
        match args.model {
            ModelChoice::One(m) => m.name(),
            ModelChoice::All => "all (P_dd of each model over the no-wiggle spectrum)",
        },
        args.input.z()
    )];
    header.extend(loaded.describe());
    let table = match args.model {
        ModelChoice::One(model) => {
            header.extend(model_header(model, &spectra, &loaded.precision, args.terms));
            spectra.table(header, args.terms)
        }
        ModelChoice::All => {
            header.push(two_loop_line(&loaded.precision));
            header.push(
                "P_nw: Eisenstein & Hu (1998) no-wiggle fit of the cosmology, scaled to the sigma8 of the \
                 linear input; columns <model> = P_dd(model)/P_nw, err_<model> its estimated numerical \
                 error"
                    .into(),
            );
            let p_nw = loaded.prepared.no_wiggle()?;
            all_models(header, &spectra, &p_nw)?
        }
    };
    write_output(args.out.as_ref(), &table.to_text())
}

/// `k P_nw`, then P_dd/P_nw of every model and their errors.
fn all_models(
    header: Vec<String>,
    spectra: &RealSpectra,
    p_nw: &pt_spectra::linear::LinearSpectrum,
) -> Result<Table> {
    let nw: Vec<f64> = spectra.k.iter().map(|&k| p_nw.eval(k)).collect();
    let models = RealModel::ALL
        .iter()
        .map(|&m| RealSpectra::from_terms(m, spectra.terms.clone()))
        .collect::<Result<Vec<_>, _>>()?;
    let mut t = Table::new(header);
    t.push("k", WAVENUMBER, spectra.k.clone());
    t.push("P_nw", POWER, nw.clone());
    let ratio = |m: &RealSpectra, error: bool| -> Vec<f64> {
        let dd = m.pair(Pair::DeltaDelta);
        dd.iter()
            .zip(&nw)
            .map(|(e, n)| if error { e.error / n } else { e.value / n })
            .collect()
    };
    for m in &models {
        t.push(m.model.name(), "1", ratio(m, false));
    }
    for m in &models {
        t.push(format!("err_{}", m.model), "1", ratio(m, true));
    }
    Ok(t)
}

/// Writes `text` to `out`, or to standard output.
pub fn write_output(out: Option<&PathBuf>, text: &str) -> Result<()> {
    match out {
        Some(path) => std::fs::write(path, text)
            .with_context(|| format!("cannot write `{}`", path.display()))?,
        None => std::io::stdout().write_all(text.as_bytes())?,
    }
    Ok(())
}

/// The header line describing the 2-loop mode-coupling integration.
pub fn two_loop_line(precision: &Precision) -> String {
    let target = if precision.two_loop_tolerance > 0.0 {
        format!(
            "points added where the error exceeds {:e} of the correction",
            precision.two_loop_tolerance
        )
    } else {
        "fixed points".to_string()
    };
    format!(
        "2-loop mode coupling: randomised quasi-Monte Carlo, {} shifts x {} Sobol points at k = 0.16 \
         (scaled as k^3.5), seed {}; {target}",
        precision.two_loop_replicas, precision.two_loop_points, precision.two_loop_seed
    )
}

/// The header lines of one model: conventions, σ_v², the 2-loop settings and the RPT factors.
fn model_header(
    model: RealModel,
    spectra: &RealSpectra,
    precision: &Precision,
    terms: bool,
) -> Vec<String> {
    let sigma_v2 = spectra.terms.one_loop.sigma_v2;
    let mut h = vec![
        "conventions: theta = -div v/(aHf); 1-loop correction = P22 + 2 P13; err_X = estimated absolute \
         numerical error of X"
            .to_string(),
        format!(
            "sigma_v2 = {:.8e} +- {:.1e} (Mpc/h)^2",
            sigma_v2.value, sigma_v2.error
        ),
    ];
    if model.needs_two_loop() {
        h.push(two_loop_line(precision));
    }
    if terms && model.propagator().is_some() {
        h.push(
            "N_dd = N_delta^2, N_dt = N_delta N_theta, N_tt = N_theta^2: the factors multiplying \
             P_lin + P22 in the RPT model"
                .into(),
        );
    }
    h
}

#[cfg(test)]
mod tests {
    use super::*;
    use pt_spectra::linear::LinearSpectrum;
    use pt_spectra::progress::Silent;
    use pt_spectra::store::TableStore;

    #[test]
    fn every_row_has_one_value_per_named_column() {
        let p = LinearSpectrum::gm2012(0.0).unwrap();
        let store = TableStore::in_memory();
        let plan = RealPlan::new(
            &[0.05, 0.1],
            RealModel::OneLoopRptN1,
            &Precision::fast(),
            &store,
            &Silent,
        )
        .unwrap();
        let terms = plan.evaluate(&p, &Silent).unwrap().terms;
        for model in RealModel::ALL {
            for with_terms in [false, true] {
                let Ok(spectra) = RealSpectra::from_terms(model, terms.clone()) else {
                    continue;
                };
                let text = spectra.table(vec![], with_terms).to_text();
                let names = text.lines().find(|l| l.starts_with("# k")).unwrap();
                let n = names.split_whitespace().count() - 1;
                for line in text.lines().filter(|l| !l.starts_with('#')) {
                    assert_eq!(line.split_whitespace().count(), n, "{model} {with_terms}");
                }
            }
        }
    }
}
