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
use super::Pipeline;
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

impl Pipeline {
    /// The nodes of the rule in μ of the multipoles and the change of the reference data vector
    /// they measured at build time, relative to each multipole's largest |value| at the worst
    /// distortion ([`MU_RULE_TOLERANCE`]); `None` if the step keeps
    /// [`crate::rsd::ept::MU_NODES`].
    pub fn mu_rule(&self) -> Option<(usize, f64)> {
        self.mu_rule
    }

    /// One line for a header, a `meta` entry or a log: the rule in μ of the multipoles
    /// ([module docs](self)).
    pub fn describe_mu_rule(&self) -> String {
        let at = if self.settings.fiducial.is_some() {
            "at the worst of the identity and the AP range's corners"
        } else {
            "without AP"
        };
        match self.mu_rule {
            Some((n, change)) => format!(
                "multipoles: {n}-point Gauss-Legendre rule in mu (measured at build: the reference \
                 data vector changes from the {}-point rule's by {change:.1e} of each multipole's \
                 largest value {at}, <= {:.0e})",
                crate::rsd::ept::MU_NODES,
                MU_RULE_TOLERANCE
            ),
            None => format!(
                "multipoles: {}-point Gauss-Legendre rule in mu",
                crate::rsd::ept::MU_NODES
            ),
        }
    }
}
