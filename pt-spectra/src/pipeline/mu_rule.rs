//! The rule in μ of the chain step's multipoles ([`crate::rsd::ept::EptPlan::with_value_nodes`]).
//!
//! The AP projection evaluates the model at every output k and μ node; with [`MU_NODES`] nodes it was
//! a quarter of a step. The integrand (the distorted k', μ' and the BAO damping) is smooth in μ, so a
//! smaller Gauss–Legendre rule gives the same multipoles to far below any error where the distortion
//! is mild; the difference grows towards the anisotropic corners of the AP range. The rule is chosen
//! at build time by measurement: the reference data vector of [`super::loop_range`] (the embedded
//! gm2012 spectrum at z, b1 = 2, f = f(z)) is made at the identity and, with an AP range (lo, hi), at
//! its corners (α∥, α⊥) = (lo, hi) and (hi, lo), with each candidate rule and with [`MU_NODES`]; the
//! smallest candidate whose largest change is at most [`MU_RULE_TOLERANCE`] of its multipole block's
//! largest |value| (at the same distortion) is taken, and the change is kept and stated.

use super::loop_range::{relative_change, Reference};
use crate::error::Result;
use crate::rsd::ap::Distortion;
use crate::rsd::ept::{EptSettings, MU_NODES};
use crate::survey::observe::{apply_matrix, Observation};

/// The largest change of the reference data vector the μ rule may cause, relative to the largest
/// |value| of the multipole's block, at the worst distortion measured: 1e-5, as the loop range's.
pub const MU_RULE_TOLERANCE: f64 = 1e-5;

/// The rules tried, smallest first.
const CANDIDATES: [usize; 3] = [12, 16, 20];

/// The chosen number of nodes and its measured change ([module docs](self)); `None` if no candidate
/// passes (the plan keeps [`MU_NODES`]).
pub(super) fn choose(
    observation: &Observation,
    matrix: &[f64],
    reference: &Reference,
    settings: &EptSettings,
) -> Result<Option<(usize, f64)>> {
    let mut distortions = vec![reference.identity];
    if let Some((lo, hi)) = settings.ap_range {
        distortions.push(Some(Distortion::new(lo, hi)?));
        distortions.push(Some(Distortion::new(hi, lo)?));
    }
    let ells = observation.model_ells();
    let n_ells = observation.ells().len();
    let data = |plan: &crate::rsd::ept::EptPlan, ap| -> Result<Vec<f64>> {
        Ok(apply_matrix(
            matrix,
            &plan.multipole_values_at(&reference.terms, &reference.params, ells, ap)?,
        ))
    };
    let full: Vec<Vec<f64>> = distortions
        .iter()
        .map(|&ap| data(&reference.plan, ap))
        .collect::<Result<_>>()?;
    for n in CANDIDATES.into_iter().filter(|&n| n < MU_NODES) {
        let plan = reference.plan.clone().with_value_nodes(n)?;
        let mut worst: f64 = 0.0;
        for (&ap, full) in distortions.iter().zip(&full) {
            worst = worst.max(relative_change(full, n_ells)(&data(&plan, ap)?));
        }
        if worst <= MU_RULE_TOLERANCE {
            return Ok(Some((n, worst)));
        }
    }
    Ok(None)
}
