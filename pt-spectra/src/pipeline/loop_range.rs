//! The k range where a pipeline computes the loop terms ([`crate::rsd::ept::EptSettings::loop_range`]).
//!
//! A survey window needs the model from k ≈ 1e-4 to several h/Mpc, but weighs the columns far from the
//! measured k by 1e-3 (large scales, where the loops are ~1e-3 of the linear spectrum) to 1e-6 (small
//! scales): the loop terms there change the data vector by far less than any error, yet took half of
//! a step's time (the AP grid of the loops grows with the decades covered). The range is chosen at
//! build time by measurement: the reference data vector (the embedded gm2012 spectrum at the
//! pipeline's z, b1 = 2, f = f(z), AP at the fiducial) with the loops everywhere is compared with the
//! loops inside each candidate range only, and the narrowest candidate whose largest change is at most
//! [`LOOP_RANGE_TOLERANCE`] of the largest |value| of its multipole's block is taken. The candidates are
//! the measured k span widened by factors 1/16 … 1/2 below and 2 … 1.25 above, in observed
//! k, then divided by the AP range's extremes (the loops are in true k). The measured change is kept
//! ([`super::Pipeline::loop_range`]) and stated.

use super::apply_matrix;
use crate::error::Result;
use crate::linear::LinearSpectrum;
use crate::precision::Precision;
use crate::rsd::ap::Distortion;
use crate::rsd::ept::{EptParams, EptPlan, EptSettings, EptTerms};
use crate::survey::observe::Observation;

/// The largest change of the reference data vector the loop range may cause, relative to the
/// largest |value| of the multipole's block: 1e-5 (a thousandth of a percent-level error bar).
pub const LOOP_RANGE_TOLERANCE: f64 = 1e-5;

/// The lower ends tried: the smallest measured k times these (widest first).
const LOW_FACTORS: [f64; 4] = [1.0 / 16.0, 1.0 / 8.0, 1.0 / 4.0, 1.0 / 2.0];

/// The upper ends tried: the largest measured k times these (widest first).
const HIGH_FACTORS: [f64; 3] = [2.0, 1.5, 1.25];

/// The chosen range, for the observation's `matrix` ([`super::Pipeline::observation_matrix`]), in true k [h/Mpc] and its measured change of the reference data vector
/// (relative, as [`LOOP_RANGE_TOLERANCE`]); `None` if no candidate is narrower than the model's grid
/// or none passes.
pub(super) fn choose(
    observation: &Observation,
    matrix: &[f64],
    reference: &Reference,
    settings: &EptSettings,
) -> Result<Option<((f64, f64), f64)>> {
    let k_out = observation.k_out();
    let k_model = observation.k_model();
    if observation.is_xi() || k_out.is_empty() || k_model.is_empty() {
        return Ok(None);
    }
    let data_lo = k_out.iter().copied().fold(f64::INFINITY, f64::min);
    let data_hi = k_out.iter().copied().fold(0.0, f64::max);
    let (model_lo, model_hi) = (k_model[0], k_model[k_model.len() - 1]);
    // observed k to true k: the loops must cover k/α for every α of the plan's AP range
    let (a_lo, a_hi) = settings.ap_range.unwrap_or((1.0, 1.0));
    let data = |lo: Option<f64>, hi: Option<f64>| -> Result<Vec<f64>> {
        let cut = reference.terms.with_loops_only_in(
            lo.map_or(0.0, |l| l / a_hi),
            hi.map_or(f64::INFINITY, |h| h / a_lo),
        );
        reference.data_vector(&cut, matrix, observation.model_ells(), reference.identity)
    };
    let full = data(None, None)?;
    let change = relative_change(&full, observation.ells().len());
    // the lower end with the loops to the top, then the upper end with that lower end
    let (mut lo, mut hi, mut measured) = (None, None, 0.0);
    for factor in LOW_FACTORS {
        let candidate = data_lo * factor;
        if candidate <= model_lo {
            continue;
        }
        let c = change(&data(Some(candidate), None)?);
        if c > LOOP_RANGE_TOLERANCE {
            break;
        }
        (lo, measured) = (Some(candidate), c);
    }
    for factor in HIGH_FACTORS {
        let candidate = data_hi * factor;
        if candidate >= model_hi {
            continue;
        }
        let c = change(&data(lo, Some(candidate))?);
        if c > LOOP_RANGE_TOLERANCE {
            break;
        }
        (hi, measured) = (Some(candidate), c);
    }
    if lo.is_none() && hi.is_none() {
        return Ok(None);
    }
    let range = (
        lo.map_or(f64::MIN_POSITIVE, |l| l / a_hi),
        hi.map_or(f64::MAX, |h| h / a_lo),
    );
    Ok(Some((range, measured)))
}

/// The reference of the build-time measurements ([module docs](self), [`super::mu_rule`]): the
/// embedded gm2012 spectrum at z, its terms at the fast precision (the measurements need the
/// loops' size, not their last digit), b1 = 2 and f = f(z).
pub(super) struct Reference {
    pub(super) plan: EptPlan,
    pub(super) terms: EptTerms,
    pub(super) params: EptParams,
    /// The identity distortion with an AP range, else none.
    pub(super) identity: Option<Distortion>,
}

impl Reference {
    pub(super) fn new(k_model: &[f64], settings: &EptSettings, z: f64) -> Result<Self> {
        let plan = EptPlan::new(k_model, *settings, &Precision::fast())?;
        let terms = plan.terms(&reference_spectrum(z)?)?;
        let f = crate::cosmology::Cosmology::gm2012().growth_rate(z);
        let identity = settings
            .ap_range
            .map(|_| Distortion::new(1.0, 1.0))
            .transpose()?;
        Ok(Self {
            plan,
            terms,
            params: EptParams::new(2.0, f),
            identity,
        })
    }

    /// The data vector of `terms` (the reference's, or changed) through the observation `matrix`
    /// with the distortion `ap`.
    pub(super) fn data_vector(
        &self,
        terms: &EptTerms,
        matrix: &[f64],
        ells: &[usize],
        ap: Option<Distortion>,
    ) -> Result<Vec<f64>> {
        Ok(apply_matrix(
            matrix,
            &self
                .plan
                .multipole_values_at(terms, &self.params, ells, ap)?,
        ))
    }
}

/// The largest change of a data vector from `full` (of `n_ells` output multipoles' blocks), each row
/// relative to the largest |value| of its block.
pub(super) fn relative_change(full: &[f64], n_ells: usize) -> impl Fn(&[f64]) -> f64 + '_ {
    let block = full.len() / n_ells.max(1);
    let scale: Vec<f64> = full
        .chunks(block.max(1))
        .flat_map(|b| {
            let m = b.iter().fold(0.0_f64, |m, v| m.max(v.abs()));
            std::iter::repeat_n(m, b.len())
        })
        .collect();
    move |d: &[f64]| -> f64 {
        d.iter()
            .zip(full)
            .zip(&scale)
            .map(|((a, b), s)| (a - b).abs() / s)
            .fold(0.0, f64::max)
    }
}

/// The embedded gm2012 spectrum at z (rescaled by its growth from the nearest table).
fn reference_spectrum(z: f64) -> Result<LinearSpectrum> {
    let prepared = crate::setup::prepare_with_emulator(
        crate::setup::Request {
            source: crate::setup::LinearSource::Embedded,
            cosmology: None,
            z,
        },
        None,
    )?;
    Ok(prepared.tracer_spectrum().clone())
}
