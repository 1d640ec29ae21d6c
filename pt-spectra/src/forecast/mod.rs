//! Fisher forecasts of galaxy redshift surveys with the galaxy model `ept` (issue 47, part 5).
//!
//! Units: k in h/Mpc, P in (Mpc/h)³, volumes in (Mpc/h)³, n̄ in (h/Mpc)³.
//!
//! A survey is a list of redshift bins ([`SurveyBin`]: z, volume, n̄, the k range and width of the
//! measured shells, the multipoles, the fiducial nuisance parameters). Each bin's data vector is the
//! window-free P_ℓ of the [`crate::pipeline::Pipeline`] at the shells' centres, and its covariance the
//! Gaussian one with shot noise (Grieb et al. 2016, arXiv:1509.04293, eq. 15): for a shell of N_k
//! modes, N_k = V (4π/3)(k_hi³ − k_lo³)/(2π)³,
//!
//! ```text
//! C_ℓℓ'(k) = (2ℓ + 1)(2ℓ' + 1)/N_k ∫_{−1}^{1} dμ L_ℓ(μ) L_ℓ'(μ) [P(k, μ) + 1/n̄]²,
//! ```
//!
//! with P(k, μ) = Σ_{ℓ ≤ 8} P_ℓ(k) L_ℓ(μ) of the fiducial model (diagonal in k: no window, no
//! super-sample or non-Gaussian terms). The Fisher matrix is F = Σ_bins Σ_k J_kᵀ C_k⁻¹ J_k plus the
//! inverse variances of Gaussian priors; the forecast errors are √(F⁻¹)ᵢᵢ (every other parameter
//! marginalised).
//!
//! **Parameters.** [`Parameters::Template`]: per bin f, α∥, α⊥ (the compressed parameters of BAO and
//! RSD analyses; σ(fσ8) = σ8(z) σ(f) with σ8(z) of the fiducial) and the bin's free nuisance
//! parameters. [`Parameters::Cosmology`]: the cosmological parameters [`COSMOLOGY_NAMES`] shared by
//! all bins (through the emulator, with the AP distortion of each cosmology against the fiducial),
//! and each bin's free nuisance parameters.
//!
//! **Derivatives.** The nuisance parameters': exact (the data vector is a polynomial in them,
//! [`crate::pipeline::Linearised::jacobian`]). f, α∥, α⊥ and the cosmological parameters of the
//! power spectrum alone: exact ([`crate::pipeline::CosmologyStep::template_jacobian`],
//! [`crate::pipeline::Pipeline::cosmology_jacobian`]). With a block after the power spectrum
//! ([`SurveyBin::with_block`], a registered [`crate::statistic::Kind`] with a
//! [`crate::statistic::SurveyFace`]; its Gaussian variance from the block,
//! [`crate::statistic::Block::gaussian_variances`]), f, α∥, α⊥, the cosmological parameters and the
//! nuisance parameters: central differences at steps h and h/2 combined by Richardson
//! extrapolation, (4D(h/2) − D(h))/3, whose error, |D(h/2) − D(h)|/3, is reported relative to each
//! derivative's largest element ([`Forecast::derivative_error`]).

mod covariance;
mod kaiser;
mod parameters;
mod survey_bin;
#[cfg(test)]
mod tests;

use crate::cosmology::background::DERIVATIVE_NAMES;
use crate::cosmology::Cosmology;
use crate::error::{Error, Result};
use crate::pipeline::{Pipeline, NUISANCE_NAMES};
use crate::precision::Precision;
use crate::progress::Progress;
use crate::rsd::ap::Distortion;
use crate::store::TableStore;
use crate::survey::observe::Observation;
pub use covariance::gaussian_covariance;
pub use kaiser::{fisher_kaiser, kaiser_fisher, KaiserBin, KaiserForecast, KaiserTracer};
use parameters::{check_cosmology, cosmology_value, with_cosmology_value};
pub use survey_bin::SurveyBin;

/// The cosmological parameters a forecast can vary: ω_cdm, ω_b, h, ln(10¹⁰A_s), n_s (flat, the
/// fiducial's neutrinos and dark energy kept).
pub const COSMOLOGY_NAMES: [&str; 5] = ["omega_cdm", "omega_b", "h", "logA", "n_s"];

/// The template parameters of each bin.
pub const TEMPLATE_NAMES: [&str; 3] = ["f", "apar", "aperp"];

/// The nuisance parameters free by default: b1, b2, bs, the counterterms α0, α2 and the constant
/// stochastic term sn (the others fixed at their fiducial values).
pub const DEFAULT_FREE_NUISANCE: [&str; 6] = ["b1", "b2", "bs", "alpha0", "alpha2", "sn"];

/// Relative steps of the finite differences (h; the extrapolation also uses h/2): of the parameter's
/// value for the cosmological ones and f, absolute for α∥, α⊥.
const STEP: f64 = 0.01;

/// What a forecast varies.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Parameters {
    /// f, α∥, α⊥ per bin and the bins' nuisance parameters.
    Template,
    /// [`COSMOLOGY_NAMES`] shared and the bins' nuisance parameters.
    Cosmology,
}

/// The result of a forecast.
#[derive(Debug, Clone, PartialEq)]
pub struct Forecast {
    /// The parameters, in the order of the matrices: with [`Parameters::Template`], per bin
    /// `f_i`, `apar_i`, `aperp_i` then its free nuisance parameters `name_i`; with
    /// [`Parameters::Cosmology`], [`COSMOLOGY_NAMES`] then each bin's free nuisance parameters.
    pub names: Vec<String>,
    /// Their fiducial values.
    pub fiducial: Vec<f64>,
    /// The Fisher matrix (priors included).
    pub fisher: Vec<Vec<f64>>,
    /// Its inverse: the forecast covariance.
    pub covariance: Vec<Vec<f64>>,
    /// √(covariance)ᵢᵢ.
    pub sigma: Vec<f64>,
    /// Per bin, σ(fσ8) = σ8(z) σ(f) and fσ8 of the fiducial (template parameters; NaN otherwise).
    pub fsigma8: Vec<(f64, f64)>,
    /// The largest error of a finite-difference derivative relative to its largest element.
    pub derivative_error: f64,
    /// The number of data points (multipoles × shells over the bins).
    pub points: usize,
}

/// The Fisher forecast of `bins` in the `fiducial` cosmology (flat, A_s-normalised; the emulator's
/// linear spectrum), varying `parameters`, with Gaussian `priors` (name, σ) on the shared cosmological
/// parameters (e.g. a BBN prior on `omega_b`: without one, ω_b, h and the shape trade off and σ(h) is
/// of order 0.3 for a BOSS-like survey).
///
/// # Errors
/// [`Error::InvalidChoice`] naming a bin's bad value, a prior on an unknown parameter, a non-flat or
/// σ8-normalised fiducial with [`Parameters::Cosmology`], or a Fisher matrix that is not positive
/// definite; as [`Pipeline::new`] and the emulator (a fiducial outside its prior).
pub fn fisher(
    bins: &[SurveyBin],
    fiducial: &Cosmology,
    parameters: Parameters,
    priors: &[(String, f64)],
    store: &TableStore,
    progress: &dyn Progress,
) -> Result<Forecast> {
    if bins.is_empty() {
        return Err(Error::InvalidChoice {
            what: "survey".into(),
            reason: "no redshift bin given".into(),
        });
    }
    for (i, b) in bins.iter().enumerate() {
        b.validate(i)?;
    }
    if parameters == Parameters::Cosmology {
        check_cosmology(fiducial)?;
    }
    let mut precision = Precision::preset("fast")?;
    precision.two_loop = crate::precision::TwoLoopMethod::Basis;
    // per bin: its names, fiducial values, data Jacobian rows (per parameter, the data vector's
    // derivative), the block of shared parameters, and the covariance per shell
    let mut names: Vec<String> = Vec::new();
    let mut values: Vec<f64> = Vec::new();
    if parameters == Parameters::Cosmology {
        names.extend(COSMOLOGY_NAMES.iter().map(|s| s.to_string()));
        values.extend(COSMOLOGY_NAMES.iter().map(|n| cosmology_value(fiducial, n)));
    }
    let mut blocks = Vec::new();
    let mut fsigma8 = Vec::new();
    let mut worst = 0.0_f64;
    let mut points = 0;
    for (i, bin) in bins.iter().enumerate() {
        progress.note(&format!(
            "forecast: redshift bin {} of {} (z = {})",
            i + 1,
            bins.len(),
            bin.z
        ));
        let shells = bin.shells();
        let k: Vec<f64> = shells.iter().map(|s| s.0).collect();
        let observation = Observation::new(&[0, 2, 4, 6, 8], &k, None, None)?;
        let settings = bin.pipeline_settings(fiducial)?;
        let pipeline = Pipeline::new(observation, settings, &precision, store, progress)?;
        let prepared = pipeline.prepare(fiducial)?;
        let step = pipeline.step(&prepared)?;
        let nuisance: Vec<(&str, f64)> =
            bin.nuisance.iter().map(|(n, v)| (n.as_str(), *v)).collect();
        let all = step.data_vector(&nuisance)?;
        // the measured multipoles' rows of the ℓ = 0 … 8 data vector
        let rows: Vec<usize> = bin
            .ells
            .iter()
            .flat_map(|&l| {
                let n_k = k.len();
                (0..n_k).map(move |j| (l / 2) * n_k + j)
            })
            .collect();
        // and with blocks, their rows after the power spectrum's ℓ = 0 … 8
        let n_p = 5 * k.len();
        let rows: Vec<usize> = rows.into_iter().chain(n_p..all.len()).collect();
        let select = |d: &[f64]| -> Vec<f64> { rows.iter().map(|&r| d[r]).collect() };
        let with_b = pipeline.has_blocks();
        let mut jacobian: Vec<Vec<f64>> = Vec::new();
        let f0 = step.growth_rate;
        let ap0 = step.ap.unwrap_or(Distortion::new(1.0, 1.0)?);
        // the measured data vector of a step at growth rate f and distortion ap
        let step_at = |f: f64, ap: Distortion| -> Result<Vec<f64>> {
            let s = pipeline.step_with(prepared.tracer_spectrum(), f, Some(ap))?;
            Ok(select(&s.data_vector(&nuisance)?))
        };
        match parameters {
            Parameters::Template if !with_b => {
                // the power spectrum alone: exact derivatives (of the μ² polynomials, the BAO
                // damping, the interpolant in ln k', the volume factor)
                jacobian.extend(step.template_jacobian(&nuisance)?.map(|d| select(&d)));
                for (n, v) in TEMPLATE_NAMES.iter().zip([f0, ap0.apar, ap0.aperp]) {
                    names.push(format!("{n}_{}", i + 1));
                    values.push(v);
                }
                let s8 = prepared.spectrum.sigma8();
                fsigma8.push((s8, f0 * s8));
            }
            Parameters::Template => {
                // f: the data vector at f ± h (the power spectrum's terms do not depend on f; the
                // blocks' do beyond a polynomial: a step at that f)
                let with_f = |f: f64| -> Result<Vec<f64>> {
                    if with_b {
                        return step_at(f, ap0);
                    }
                    let mut p = nuisance.clone();
                    p.push(("f", f));
                    Ok(select(&step.data_vector(&p)?))
                };
                let (d, e) = richardson(f0, STEP * f0, with_f)?;
                worst = worst.max(e);
                jacobian.push(d);
                for which in 0..2 {
                    let base = if which == 0 { ap0.apar } else { ap0.aperp };
                    let with_alpha = |a: f64| -> Result<Vec<f64>> {
                        let ap = if which == 0 {
                            Distortion::new(a, ap0.aperp)?
                        } else {
                            Distortion::new(ap0.apar, a)?
                        };
                        step_at(f0, ap)
                    };
                    let (d, e) = richardson(base, STEP, with_alpha)?;
                    worst = worst.max(e);
                    jacobian.push(d);
                }
                for (n, v) in TEMPLATE_NAMES.iter().zip([f0, ap0.apar, ap0.aperp]) {
                    names.push(format!("{n}_{}", i + 1));
                    values.push(v);
                }
                let s8 = prepared.spectrum.sigma8();
                fsigma8.push((s8, f0 * s8));
            }
            Parameters::Cosmology if !with_b => {
                // the power spectrum alone: exact (Pipeline::cosmology_jacobian), logA being
                // ln10^{10}A_s
                let exact = pipeline.cosmology_jacobian(fiducial, &nuisance)?;
                for name in COSMOLOGY_NAMES {
                    let sampled = if name == "logA" { "ln10^{10}A_s" } else { name };
                    let j = DERIVATIVE_NAMES
                        .iter()
                        .position(|n| *n == sampled)
                        .expect("the forecast's names are sampled parameters");
                    jacobian.push(select(&exact.cosmological[j]));
                }
                fsigma8.push((f64::NAN, f64::NAN));
            }
            Parameters::Cosmology => {
                for name in COSMOLOGY_NAMES {
                    let x0 = cosmology_value(fiducial, name);
                    let at = |x: f64| -> Result<Vec<f64>> {
                        let c = with_cosmology_value(fiducial, name, x)?;
                        Ok(select(&pipeline.evaluate(&c, &nuisance)?))
                    };
                    let (d, e) = richardson(x0, STEP * x0.abs(), at)?;
                    worst = worst.max(e);
                    jacobian.push(d);
                }
                fsigma8.push((f64::NAN, f64::NAN));
            }
        }
        // the free nuisance parameters: exact (P alone: the linearised polynomial; with blocks (B0
        // is quartic in them), Richardson-extrapolated central differences, exact for a polynomial
        // of degree ≤ 4 up to rounding)
        let exact = if with_b {
            None
        } else {
            Some(step.linearise(None)?.jacobian(&nuisance)?)
        };
        for name in &bin.free {
            // unset: 0, but a block's own default (the bispectrum's Poisson b_shot)
            let default = pipeline
                .blocks()
                .iter()
                .find_map(|b| b.kind().index(name).map(|i| b.kind().defaults[i]))
                .unwrap_or(0.0);
            let x0 = nuisance
                .iter()
                .find(|(n, _)| n == name)
                .map_or(default, |p| p.1);
            let d = match &exact {
                Some(j) => {
                    let at = NUISANCE_NAMES
                        .iter()
                        .position(|n| n == name)
                        .expect("validated");
                    select(&j[at])
                }
                None => {
                    let at = |x: f64| -> Result<Vec<f64>> {
                        let mut p: Vec<(&str, f64)> = nuisance
                            .iter()
                            .filter(|(n, _)| n != name)
                            .copied()
                            .collect();
                        p.push((name.as_str(), x));
                        Ok(select(&step.data_vector(&p)?))
                    };
                    richardson(x0, STEP * x0.abs().max(1.0), at)?.0
                }
            };
            jacobian.push(d);
            names.push(format!("{name}_{}", i + 1));
            values.push(x0);
        }
        let covariances = covariance::shell_covariances(&all, &shells, bin)?;
        let b_variance = covariance::block_variances(pipeline.blocks(), &all[..k.len()], bin)?;
        points += rows.len();
        blocks.push((jacobian, covariances, b_variance, bin.ells.len(), k.len()));
    }
    let n = names.len();
    let mut fisher = vec![vec![0.0; n]; n];
    let shared = if parameters == Parameters::Cosmology {
        COSMOLOGY_NAMES.len()
    } else {
        0
    };
    let mut offset = shared;
    for (b, (jacobian, covariances, b_variance, n_ell, n_k)) in blocks.iter().enumerate() {
        // the columns of this bin's parameters in the global matrix
        let own = jacobian.len() - shared;
        let index: Vec<usize> = (0..shared).chain(offset..offset + own).collect();
        covariance::add_fisher(&mut fisher, &index, jacobian, covariances, *n_ell, *n_k);
        covariance::add_block_fisher(&mut fisher, &index, jacobian, b_variance, n_ell * n_k);
        for (name, sigma) in &bins[b].priors {
            let at = names
                .iter()
                .position(|n| *n == format!("{name}_{}", b + 1))
                .expect("a prior's parameter is free");
            fisher[at][at] += 1.0 / (sigma * sigma);
        }
        offset += own;
    }
    for (name, sigma) in priors {
        let at = names
            .iter()
            .position(|n| n == name)
            .filter(|_| COSMOLOGY_NAMES.contains(&name.as_str()))
            .ok_or_else(|| Error::InvalidChoice {
                what: format!("prior on `{name}`"),
                reason: format!(
                    "the shared priors are on the varied cosmological parameters ({}); a bin's \
                     nuisance priors go in its SurveyBin::priors",
                    if parameters == Parameters::Cosmology {
                        COSMOLOGY_NAMES.join(", ")
                    } else {
                        "none with template parameters".into()
                    }
                ),
            })?;
        if !(sigma.is_finite() && *sigma > 0.0) {
            return Err(Error::InvalidChoice {
                what: format!("prior on `{name}` (sigma {sigma})"),
                reason: "sigma must be finite and > 0".into(),
            });
        }
        fisher[at][at] += 1.0 / (sigma * sigma);
    }
    let covariance = invert_spd(&fisher).ok_or_else(|| Error::InvalidChoice {
        what: "the Fisher matrix".into(),
        reason: "it is not positive definite: some parameters are degenerate with the data and \
                 priors given (fix or put a prior on a nuisance parameter)"
            .into(),
    })?;
    let sigma: Vec<f64> = (0..n).map(|i| covariance[i][i].sqrt()).collect();
    let fsigma8 = fsigma8
        .iter()
        .enumerate()
        .map(|(b, &(s8, fs8))| {
            let at = names.iter().position(|n| *n == format!("f_{}", b + 1));
            at.map_or((f64::NAN, f64::NAN), |i| (s8 * sigma[i], fs8))
        })
        .collect();
    Ok(Forecast {
        names,
        fiducial: values,
        fisher,
        covariance,
        sigma,
        fsigma8,
        derivative_error: worst,
        points,
    })
}

/// The Richardson-extrapolated central difference of `g` at `x` with steps h and h/2, and its error
/// relative to the largest element: ((4D(h/2) − D(h))/3, |D(h/2) − D(h)|/3 / max|·|).
fn richardson(x: f64, h: f64, g: impl Fn(f64) -> Result<Vec<f64>>) -> Result<(Vec<f64>, f64)> {
    let central = |h: f64| -> Result<Vec<f64>> {
        let (a, b) = (g(x + h)?, g(x - h)?);
        Ok(a.iter().zip(&b).map(|(a, b)| (a - b) / (2.0 * h)).collect())
    };
    let (d1, d2) = (central(h)?, central(0.5 * h)?);
    let d: Vec<f64> = d1
        .iter()
        .zip(&d2)
        .map(|(a, b)| (4.0 * b - a) / 3.0)
        .collect();
    let scale = d.iter().fold(0.0_f64, |m, v| m.max(v.abs()));
    let error = d1
        .iter()
        .zip(&d2)
        .fold(0.0_f64, |m, (a, b)| m.max((b - a).abs() / 3.0));
    Ok((d, if scale > 0.0 { error / scale } else { 0.0 }))
}

/// The inverse of a symmetric positive-definite matrix ([`crate::linalg::solve_spd`]), or `None`.
fn invert_spd(a: &[Vec<f64>]) -> Option<Vec<Vec<f64>>> {
    crate::linalg::solve_spd(a, &vec![0.0; a.len()])
        .ok()
        .map(|(_, inverse, _)| inverse)
}
