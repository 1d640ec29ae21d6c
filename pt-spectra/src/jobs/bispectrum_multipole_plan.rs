//! The one-loop galaxy multipoles planned for a triangle set (issue 50): the multipole tensors read or built
//! once ([`crate::bispectrum::multipole_basis`]), then B₀, B₂, B₄ of a new spectrum, f and bias in
//! milliseconds, with the direct pass where the tensors do not represent the spectrum (stated). What
//! `pt.OneLoopMultipolePlan` calls.

use crate::bispectrum::bias_kernels::LoopBias;
pub use crate::bispectrum::loop_tensors::{
    check_triangles, one_loop_multipole_bin_tensors, one_loop_multipole_tensors, tensor_source,
};
use crate::bispectrum::multipole_basis::{MultipoleLoopBasis, TEMPLATES};
use crate::bispectrum::multipole_bins::{MultipoleBinBasis, CHECK_TEMPLATES, DELTA_TEMPLATES};
use crate::bispectrum::one_loop::OneLoopRule;
use crate::bispectrum::one_loop_basis::{BispectrumLoopSource, PROJECTION_FACTOR};
use crate::bispectrum::one_loop_bins::{binned_multipoles, BinnedLoopMultipoles};
use crate::bispectrum::one_loop_galaxy::OneLoopGalaxy;
use crate::bispectrum::one_loop_galaxy_multipoles::one_loop_galaxy_multipoles;
use crate::bispectrum::one_loop_ir::one_loop_galaxy_multipoles_ir;
use crate::bispectrum::{IrInputs, LegendreSide, TriangleSet};
use crate::error::Result;
use crate::linear::LinearSpectrum;

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

/// B₀, B₂, B₄ of every triangle of `tensors` for the spectrum `p` (resummed with `ir`), growth rate `f` and
/// `bias`, if the tensors represent the loops' spectrum (P, or P_LO with `ir`: [`tensor_source`]); `None`
/// with the reason otherwise.
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
    let source = tensor_source(projected.residual, ir.is_some());
    if !matches!(source, BispectrumLoopSource::Basis { .. }) {
        return Ok((None, source));
    }
    let rows = polys
        .iter()
        .map(|m| m.evaluate(bias))
        .collect::<Result<Vec<_>>>()?;
    Ok((Some(rows), source))
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
            let source = tensor_source(projected.residual, ir.is_some());
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
