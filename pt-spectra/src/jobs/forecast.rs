//! The table of a Fisher forecast ([`crate::forecast`]): `pt-spectra fisher`.

use super::VERSION;
use crate::error::Result;
use crate::forecast::{fisher, Forecast, Parameters, SurveyBin, COSMOLOGY_NAMES};
use crate::output::Table;
use crate::progress::Progress;
use crate::setup::NamedCosmology;
use crate::store::TableStore;

/// Parses a bin given as `z=0.57,volume=2.6e9,n_bar=3e-4,k_max=0.15,b1=2` (and optionally k_min,
/// dk, a block's survey key (e.g. b_k_max) and nuisance values by name: [`SurveyBin::from_values`]); `ells` and `free` apply to
/// it.
///
/// # Errors
/// [`crate::error::Error::InvalidChoice`] naming a key that is missing, unknown or not a number.
pub fn parse_bin(text: &str, ells: &[usize], free: &[String]) -> Result<SurveyBin> {
    let bad = |reason: String| crate::error::Error::InvalidChoice {
        what: format!("survey bin `{text}`"),
        reason,
    };
    let mut pairs = Vec::new();
    for item in text.split(',').map(str::trim).filter(|s| !s.is_empty()) {
        let (key, value) = item
            .split_once('=')
            .ok_or_else(|| bad(format!("`{item}` is not KEY=VALUE")))?;
        let value: f64 = value
            .trim()
            .parse()
            .map_err(|_| bad(format!("{key} = `{value}` is not a number")))?;
        pairs.push((key.trim().to_string(), value));
    }
    let mut bin = SurveyBin::from_values(&format!("survey bin `{text}`"), &pairs)?;
    bin.ells = ells.to_vec();
    if !free.is_empty() {
        bin.free = free.to_vec();
        for (name, _) in &bin.blocks {
            let kind = crate::blocks::by_name(name)?;
            bin.free
                .extend(kind.forecast_free.iter().map(|s| s.to_string()));
        }
    }
    Ok(bin)
}

/// The forecast of `bins` in `fiducial` as a table: with template parameters one row per bin (z,
/// fsigma8, sigma_fsigma8, sigma_f, sigma_apar, sigma_aperp and the correlations corr_f_apar,
/// corr_f_aperp, corr_apar_aperp), with cosmological ones one row of the
/// fiducial values and errors of [`COSMOLOGY_NAMES`]; the header states the survey, the model, the
/// covariance, the free parameters, the priors and the derivatives' error.
///
/// # Errors
/// As [`fisher`].
pub fn forecast_table(
    bins: &[SurveyBin],
    fiducial: &NamedCosmology,
    parameters: Parameters,
    priors: &[(String, f64)],
    store: &TableStore,
    progress: &dyn Progress,
) -> Result<(Table, Forecast)> {
    let f = fisher(
        bins,
        &fiducial.cosmology,
        parameters,
        priors,
        store,
        progress,
    )?;
    let mut header = vec![
        format!(
            "pt-spectra {VERSION} fisher: Fisher forecast of window-free P_ell with the galaxy model ept \
             (velocileptors' REPT, IR resummed, fast precision, basis tensors), fiducial cosmology {} \
             (linear spectrum from the emulator; AP against it)",
            fiducial.name
        ),
        "covariance: Gaussian with shot noise, diagonal in k (Grieb et al. 2016 eq. 15; no window, \
         no super-sample or trispectrum terms), from the fiducial P(k, mu) of l <= 8"
            .into(),
    ];
    // the registered blocks' own defaults other than 0 (e.g. "; b_shot 1"), and their names
    let other_defaults: String = crate::blocks::AVAILABLE
        .iter()
        .flat_map(|k| k.own.iter().zip(k.defaults))
        .filter(|(_, &v)| v != 0.0)
        .map(|(n, v)| format!("; {n} {v}"))
        .collect();
    let blocks_named = crate::blocks::names()
        .iter()
        .map(|n| format!("the {n}"))
        .collect::<Vec<_>>()
        .join(", ");
    for (i, b) in bins.iter().enumerate() {
        let fixed: Vec<String> = b
            .nuisance
            .iter()
            .map(|(n, v)| format!("{n} = {v}"))
            .collect();
        header.push(format!(
                        "bin {}: z = {}, V = {:e} (Mpc/h)^3, n_bar = {:e} (h/Mpc)^3, shells of {} h/Mpc from {} to \
             {} h/Mpc, multipoles {:?}{}; fiducial {} (others 0{}); free nuisance {} \
             (marginalised){}",
            i + 1,
            b.z,
            b.volume,
            b.n_bar,
            b.dk,
            b.k_min,
            b.k_max,
                        b.ells,
            b.block_notes(),
            fixed.join(", "),
            other_defaults,
            b.free.join(", "),
            if b.priors.is_empty() {
                String::new()
            } else {
                format!(
                    ", Gaussian priors {}",
                    b.priors
                        .iter()
                        .map(|(n, s)| format!("{n}: {s}"))
                        .collect::<Vec<_>>()
                        .join(", ")
                )
            }
        ));
    }
    header.push(format!(
        "parameters: {}; derivatives of the nuisance parameters exact, of f, apar, aperp and the \
         cosmological parameters exact for the power spectrum alone (through the emulator, growth, \
         loops and AP), with {} by Richardson-extrapolated central differences (largest \
         error {:.1e} of a derivative's largest element); {} data points",
        match parameters {
            Parameters::Template =>
                "f, apar, aperp per bin (sigma(fsigma8) = sigma8(z) sigma(f))".to_string(),
            Parameters::Cosmology => format!(
                "{} shared{}",
                COSMOLOGY_NAMES.join(", "),
                if priors.is_empty() {
                    " (no priors: without a BBN prior on omega_b, h is poorly measured)".to_string()
                } else {
                    format!(
                        ", Gaussian priors {}",
                        priors
                            .iter()
                            .map(|(n, s)| format!("{n}: {s}"))
                            .collect::<Vec<_>>()
                            .join(", ")
                    )
                }
            ),
        },
        blocks_named,
        f.derivative_error,
        f.points
    ));
    let mut table = Table::new(header);
    let sigma_of = |name: &str| {
        f.names
            .iter()
            .position(|n| n == name)
            .map_or(f64::NAN, |i| f.sigma[i])
    };
    match parameters {
        Parameters::Template => {
            table.push("z", "", bins.iter().map(|b| b.z).collect());
            table.push("fsigma8", "", f.fsigma8.iter().map(|p| p.1).collect());
            table.push("sigma_fsigma8", "", f.fsigma8.iter().map(|p| p.0).collect());
            for name in ["f", "apar", "aperp"] {
                table.push(
                    format!("sigma_{name}"),
                    "",
                    (1..=bins.len())
                        .map(|i| sigma_of(&format!("{name}_{i}")))
                        .collect(),
                );
            }
            // the correlations of f (so of fσ8: σ8(z) is fixed), α∥, α⊥ within each bin (for the
            // ellipses of `pt-spectra plot ellipses`)
            let at = |name: &str| f.names.iter().position(|n| n == name);
            let corr = |a: &str, b: &str, i: usize| match (
                at(&format!("{a}_{i}")),
                at(&format!("{b}_{i}")),
            ) {
                (Some(p), Some(q)) => f.covariance[p][q] / (f.sigma[p] * f.sigma[q]),
                _ => f64::NAN,
            };
            for (a, b) in [("f", "apar"), ("f", "aperp"), ("apar", "aperp")] {
                table.push(
                    format!("corr_{a}_{b}"),
                    "",
                    (1..=bins.len()).map(|i| corr(a, b, i)).collect(),
                );
            }
        }
        Parameters::Cosmology => {
            for (i, name) in COSMOLOGY_NAMES.iter().enumerate() {
                table.push(*name, "", vec![f.fiducial[i]]);
                table.push(format!("sigma_{name}"), "", vec![f.sigma[i]]);
            }
        }
    }
    Ok((table, f))
}
