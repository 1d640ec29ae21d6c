//! The one-loop galaxy multipoles planned for a triangle set (issue 50): the multipole tensors read or built
//! once ([`crate::bispectrum::multipole_basis`]), then B₀, B₂, B₄ of a new spectrum, f and bias in
//! milliseconds, with the direct pass where the tensors do not represent the spectrum (stated). What
//! `pt.OneLoopMultipolePlan` calls.

use crate::bispectrum::bias_kernels::LoopBias;
use crate::bispectrum::multipole_basis::{MultipoleLoopBasis, TEMPLATES};
use crate::bispectrum::multipole_bins::{
    correction_rules, MultipoleBinBasis, CHECK_TEMPLATES, DELTA_TEMPLATES,
};
use crate::bispectrum::one_loop::OneLoopRule;
use crate::bispectrum::one_loop_basis::{BispectrumLoopSource, PROJECTION_FACTOR};
use crate::bispectrum::one_loop_bins::{binned_multipoles, BinnedLoopMultipoles};
use crate::bispectrum::one_loop_galaxy::OneLoopGalaxy;
use crate::bispectrum::one_loop_galaxy_multipoles::one_loop_galaxy_multipoles;
use crate::bispectrum::one_loop_ir::one_loop_galaxy_multipoles_ir;
use crate::bispectrum::{IrInputs, LegendreSide, TriangleSet};
use crate::error::{Error, Result};
use crate::linear::LinearSpectrum;
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

/// The header line of how the multipoles' loop terms were computed.
pub fn describe_source(source: &BispectrumLoopSource) -> String {
    match source {
        BispectrumLoopSource::DirectUncached => "loop terms: direct integration (method auto: no multipole \
            tensors cached for these triangles, side and rule; method basis builds them once, ~190 s per \
            triangle and core at the default rule, then ~0.07 ms per triangle with f free)"
            .into(),
        BispectrumLoopSource::Basis { residual, .. } => format!(
            "loop terms: multipole tensors on {TEMPLATES} SVD templates of the CAMB basis, f free (powers f^0 \
             to f^6), the same nodes as direct; projection residual {residual:.1e}; err_ includes \
             {PROJECTION_FACTOR} x residual x (sum of |loop terms|)"
        ),
        s => s.describe(),
    }
}

/// What the tensors' build checks, named: every triangle closes and has the Legendre side; the rule.
///
/// # Errors
/// [`Error::InvalidChoice`] naming the first bad triangle; the rule's error.
pub(super) fn check_triangles(
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

/// B₀, B₂, B₄ of every triangle of `tensors` for the spectrum `p` (resummed with `ir`), growth rate `f` and
/// `bias`, if the tensors represent the loops' spectrum (P, or P_LO with `ir`; residual ≤
/// [`crate::loops::basis::MAX_RESIDUAL`]); `None` with the reason otherwise.
///
/// # Errors
/// f outside [0, 2]; a bias coefficient that is not finite.
pub fn multipoles_from_tensors(
    tensors: &MultipoleLoopBasis,
    p: &LinearSpectrum,
    bias: &LoopBias,
    f: f64,
    ir: Option<&IrInputs>,
) -> Result<(Option<Vec<[OneLoopGalaxy; 3]>>, BispectrumLoopSource)> {
    let (polys, projected) = tensors.evaluate_projected(p, f, ir)?;
    let source = tensor_source(projected.residual);
    if !matches!(source, BispectrumLoopSource::Basis { .. }) {
        return Ok((None, source));
    }
    let rows = polys
        .iter()
        .map(|m| m.evaluate(bias))
        .collect::<Result<Vec<_>>>()?;
    Ok((Some(rows), source))
}

/// Whether the multipole tensors (of triangles or bins) represent a spectrum whose projection residual on
/// their templates is `residual`: the basis source up to [`crate::loops::basis::MAX_RESIDUAL`], the direct
/// fallback above.
fn tensor_source(residual: f64) -> BispectrumLoopSource {
    let max = crate::loops::basis::MAX_RESIDUAL;
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

/// [`multipoles_from_tensors`], or where the tensors do not represent the spectrum the direct one pass of
/// every triangle on the tensors' rule (~27 s per triangle and core at the default rule; the source says
/// so).
///
/// # Errors
/// As [`multipoles_from_tensors`]; as the direct pass.
pub fn multipole_plan_rows(
    tensors: &MultipoleLoopBasis,
    p: &LinearSpectrum,
    bias: &LoopBias,
    f: f64,
    ir: Option<&IrInputs>,
) -> Result<(Vec<[OneLoopGalaxy; 3]>, BispectrumLoopSource)> {
    let (rows, source) = multipoles_from_tensors(tensors, p, bias, f, ir)?;
    if let Some(rows) = rows {
        return Ok((rows, source));
    }
    let side = tensors.side();
    let rows = tensors
        .triangles()
        .iter()
        .map(|&k| {
            let m = match ir {
                None => one_loop_galaxy_multipoles(p, k, f, side, tensors.rule(), None),
                Some(ir) => one_loop_galaxy_multipoles_ir(p, ir, k, f, side, tensors.rule(), None),
            }?;
            m.evaluate(bias)
        })
        .collect::<Result<Vec<_>>>()?;
    Ok((rows, source))
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

/// The binned multipoles per bias monomial of the bins `set` for the spectrum `p` (resummed with `ir`) at
/// growth rate `f`: from `tensors` if given and they represent the loops' spectrum (P, or P_LO with `ir`),
/// else directly on `rule` ([`binned_multipoles`], `tick` per bin; `uncached` says why there are no
/// tensors: auto found none cached), with how the loop terms were computed.
///
/// # Errors
/// As [`MultipoleBinBasis::evaluate_projected`] and [`binned_multipoles`].
#[allow(clippy::too_many_arguments)]
pub fn binned_plan_multipoles(
    tensors: Option<&MultipoleBinBasis>,
    uncached: bool,
    p: &LinearSpectrum,
    ir: Option<&IrInputs>,
    set: &TriangleSet,
    f: f64,
    side: LegendreSide,
    rule: &OneLoopRule,
    tick: &dyn Fn(usize, usize),
) -> Result<(BinnedLoopMultipoles, BispectrumLoopSource)> {
    let source = match tensors {
        Some(t) => {
            let (binned, projected) = t.evaluate_projected(p, f, ir)?;
            let source = tensor_source(projected.residual);
            if matches!(source, BispectrumLoopSource::Basis { .. }) {
                return Ok((binned, source));
            }
            source
        }
        None if uncached => BispectrumLoopSource::DirectUncached,
        None => BispectrumLoopSource::Direct,
    };
    let binned = binned_multipoles(p, ir, set, f, side, rule, tick)?;
    Ok((binned, source))
}

/// The header line of how the binned multipoles' loop terms were computed.
pub fn describe_bin_source(source: &BispectrumLoopSource) -> String {
    match source {
        BispectrumLoopSource::Direct => "loop terms: direct integration".into(),
        BispectrumLoopSource::DirectUncached => "loop terms: direct integration (method auto: no multipole \
            bin tensors cached for these bins, side and rule; method basis builds them once, ~190 s per bin \
            and core at the default rule, then ~0.13 ms per bin with f free)"
            .into(),
        BispectrumLoopSource::Basis { residual, .. } => format!(
            "loop terms: multipole bin tensors, f free: the effective triangles' on {TEMPLATES} SVD templates \
             of the CAMB basis, the correction Delta's loops on the first {DELTA_TEMPLATES} (its error \
             estimates' on {CHECK_TEMPLATES}), the tree level's Delta exact (with IR: legs damped at \
             mu^2 = 1/3, the damping's range in err_); projection residual {residual:.1e}; err_ includes \
             {PROJECTION_FACTOR} x residual x (sum of |loop terms|)"
        ),
        s => s.describe(),
    }
}
