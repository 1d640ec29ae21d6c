//! The one-loop multipole tensors of a triangle set read or built through a [`TableStore`] (issue 50):
//! the triangles' ([`MultipoleLoopBasis`]) and the bins' ([`MultipoleBinBasis`]), and whether they
//! represent a spectrum. What the table jobs, `pt.OneLoopMultipolePlan` and the one-loop bispectrum
//! block ([`super::loop_block`]) read them with.

use super::multipole_basis::{MultipoleLoopBasis, TEMPLATES};
use super::multipole_bins::{correction_rules, MultipoleBinBasis};
use super::one_loop::OneLoopRule;
use super::one_loop_basis::BispectrumLoopSource;
use super::{LegendreSide, TriangleSet};
use crate::error::{Error, Result};
use crate::precision::TwoLoopMethod;
use crate::progress::Progress;
use crate::store::TableStore;
use std::sync::Arc;

/// The multipole tensors of `triangles` (Legendre polynomial on `side`, loop `rule`): read from `store`'s
/// cache or built (once: ~190 s per triangle and core at the default rule) and cached.
///
/// # Errors
/// A triangle that does not close (named), a bad side or rule; the store's errors.
pub fn one_loop_multipole_tensors(
    triangles: &[[f64; 3]],
    side: LegendreSide,
    rule: &OneLoopRule,
    store: &TableStore,
    progress: &dyn Progress,
) -> Result<Arc<MultipoleLoopBasis>> {
    check_triangles(triangles, side, rule)?;
    let build = |tick: &(dyn Fn(usize, usize) + Sync)| {
        MultipoleLoopBasis::build(triangles, side, rule, tick)
            .expect("triangles, side and rule checked")
    };
    let tensors = store.for_method::<MultipoleLoopBasis>(
        TwoLoopMethod::Basis,
        (triangles, side, rule),
        build,
        progress,
    )?;
    Ok(tensors.expect("method basis reads or builds"))
}

/// What the tensors' build checks, named: every triangle closes and has the Legendre side; the rule.
///
/// # Errors
/// [`Error::InvalidChoice`] naming the first bad triangle; the rule's error.
pub fn check_triangles(
    triangles: &[[f64; 3]],
    side: LegendreSide,
    rule: &OneLoopRule,
) -> Result<()> {
    for (i, &k) in triangles.iter().enumerate() {
        crate::bispectrum::one_loop::triangle_vectors(k)
            .and_then(|_| {
                crate::bispectrum::one_loop_galaxy_multipoles::legendre_side_index(&k, side)
            })
            .map_err(|e| Error::InvalidChoice {
                what: format!("triangle {} ({}, {}, {})", i + 1, k[0], k[1], k[2]),
                reason: e.to_string(),
            })?;
    }
    rule.validate()
}

/// The largest projection residual of the IR-resummed loops' spectrum P_LO = P_nw + e^{−k²Σ²} P_w on the
/// multipole tensors' templates that they represent. P_LO's residual is its damped wiggles', which no
/// 16 templates of linear spectra span (6.5e-4 to 8.1e-3 on spectra not trained on, where P's own is
/// ≤ 2e-3); the loop integrals average them out and the factors outside the integrals take P_LO's own
/// values ([`super::multipole_basis`]), so B_ℓ errs far less than the residual suggests: measured
/// (`resummed_multipole_tensors_against_direct`, 9 spectra not trained on with P_LO residuals 6.5e-4 to
/// 8.1e-3) ≤ 9.8e-4 of B₀, at most 0.01 of the stated error, and unrelated to the residual in that range
/// (8.7e-4 at 8.1e-3, 8.6e-4 at 1.6e-3). A spectrum outside the span altogether (a curved-space table:
/// 0.17, its B off by 8e-2) stays refused.
pub const IR_MAX_RESIDUAL: f64 = 1e-2;

/// Whether the multipole tensors (of triangles or bins) represent a spectrum whose projection residual on
/// their templates is `residual` (of P, or of P_LO if `resummed`): the basis source up to
/// [`crate::loops::basis::MAX_RESIDUAL`] (P) or [`IR_MAX_RESIDUAL`] (P_LO), the direct fallback above.
pub fn tensor_source(residual: f64, resummed: bool) -> BispectrumLoopSource {
    let max = if resummed {
        IR_MAX_RESIDUAL
    } else {
        crate::loops::basis::MAX_RESIDUAL
    };
    if residual <= max {
        BispectrumLoopSource::Basis {
            functions: TEMPLATES,
            residual,
        }
    } else {
        BispectrumLoopSource::Fallback {
            residual,
            max_residual: max,
        }
    }
}

/// The multipole bin tensors of the bins `set` (shells; Legendre polynomial on `side`, loop `rule`) as
/// `method` asks: basis reads or builds them (once: the effective triangles' ~190 s per bin and core at the
/// default rule, and each bin's ~64 node triangles on the correction's coarse rules, ~0.75 s each), auto
/// reads them if cached, direct none.
///
/// # Errors
/// A set of points; a bin centre that does not close (named), a bad side or rule; the store's errors.
pub fn one_loop_multipole_bin_tensors(
    set: &TriangleSet,
    side: LegendreSide,
    rule: &OneLoopRule,
    method: TwoLoopMethod,
    store: &TableStore,
    progress: &dyn Progress,
) -> Result<Option<Arc<MultipoleBinBasis>>> {
    crate::bispectrum::one_loop_bins::require_bins(set)?;
    check_triangles(set.triangles(), side, rule)?;
    let build = |tick: &(dyn Fn(usize, usize) + Sync)| {
        MultipoleBinBasis::build(set, side, rule, tick).expect("bins, side and rule checked")
    };
    store.for_method::<MultipoleBinBasis>(
        method,
        (set, side, rule, &correction_rules(rule)),
        build,
        progress,
    )
}
