//! The galaxy model's loop terms from basis tensors ([`RedshiftBasis`]): a new spectrum's terms as
//! contractions with its projection (and, with IR resummation, its no-wiggle part's projection on a
//! basis of no-wiggle spectra) instead of the plan's integrals.

use super::{sigma2, EptPlan, EptTerms};
use crate::error::Result;
use crate::ir::savitzky_golay_no_wiggle;
use crate::linear::LinearSpectrum;
use crate::loops::basis::training::{camb_basis, transformed_basis};
use crate::loops::basis::{
    LinearBasis, Projection, RedshiftBasis, SpectrumFamily, BASIS_SIZE, MAX_RESIDUAL,
};
use crate::precision::TwoLoopMethod;
use crate::progress::Progress;
use crate::store::TableStore;
use std::sync::Arc;

/// The tensors of the linear spectrum's terms and, with IR resummation, of the no-wiggle terms.
#[derive(Debug, Clone)]
pub(super) struct Tensors {
    linear: Arc<RedshiftBasis>,
    no_wiggle: Option<Arc<RedshiftBasis>>,
}

impl EptPlan {
    /// This plan with the basis tensors of its loop terms ([`RedshiftBasis`]) as the precision's
    /// method says ([`crate::precision::TwoLoopMethod`]: `basis` reads or builds them in `store`,
    /// seconds, `auto` uses them if cached, `direct` never).
    ///
    /// # Errors
    /// As [`TableStore::redshift_basis`].
    pub fn with_basis(mut self, store: &TableStore, progress: &dyn Progress) -> Result<Self> {
        let precision = self.loops.precision().clone();
        let lattice = self.loops.rules().0.lattice.clone();
        let ir = self.split.is_some();
        let linear_basis = || camb_basis(lattice.clone(), BASIS_SIZE);
        let no_wiggle_basis = || {
            transformed_basis(&lattice, BASIS_SIZE, &|p| {
                savitzky_golay_no_wiggle(p).unwrap_or_else(|_| p.clone())
            })
        };
        let get = |family, basis: &dyn Fn() -> LinearBasis| -> Result<_> {
            Ok(match precision.two_loop {
                TwoLoopMethod::Basis => {
                    Some(store.redshift_basis(&self.loops, family, basis, progress)?)
                }
                TwoLoopMethod::Auto => {
                    store.cached_redshift_basis(&self.grid, &precision, family, progress)
                }
                TwoLoopMethod::Direct => None,
            })
        };
        let linear = get(SpectrumFamily::Linear, &linear_basis)?;
        let no_wiggle = if ir {
            get(SpectrumFamily::NoWiggle, &no_wiggle_basis)?
        } else {
            None
        };
        self.tensors = match (linear, no_wiggle, ir) {
            (Some(linear), no_wiggle, false) | (Some(linear), no_wiggle @ Some(_), true) => {
                Some(Tensors { linear, no_wiggle })
            }
            _ => None,
        };
        Ok(self)
    }

    /// Whether the loop terms come from basis tensors (for spectra the bases represent).
    pub fn has_basis(&self) -> bool {
        self.tensors.is_some()
    }

    /// The loop terms from the basis tensors, or `None` without tensors or for a spectrum (or its
    /// no-wiggle part) its basis does not represent well enough.
    pub(super) fn terms_on_basis(&self, spectrum: &LinearSpectrum) -> Result<Option<EptTerms>> {
        let Some(tensors) = &self.tensors else {
            return Ok(None);
        };
        let accepted = |tensors: &RedshiftBasis, p: &LinearSpectrum| -> Option<Projection> {
            let basis = tensors.basis();
            let projection = basis.project(&basis.sample(p));
            (projection.residual <= MAX_RESIDUAL).then_some(projection)
        };
        let Some(projection) = accepted(&tensors.linear, spectrum) else {
            return Ok(None);
        };
        let on_grid = |p: &LinearSpectrum| self.grid.iter().map(|&k| p.eval(k)).collect::<Vec<_>>();
        let p_lin = on_grid(spectrum);
        let mut residual = (projection.residual, None);
        let (full, nw) = match (&self.split, &tensors.no_wiggle) {
            (Some(()), Some(nw_tensors)) => {
                let p_nw = savitzky_golay_no_wiggle(spectrum)?;
                let Some(projection_nw) = accepted(nw_tensors, &p_nw) else {
                    return Ok(None);
                };
                residual.1 = Some(projection_nw.residual);
                let (full, t) = tensors.linear.evaluate_with_no_wiggle(
                    &self.loops,
                    (&p_lin, &projection),
                    nw_tensors,
                    (&on_grid(&p_nw), &projection_nw),
                );
                (full, Some((t, sigma2(&p_nw))))
            }
            _ => (
                tensors.linear.evaluate(&self.loops, &p_lin, &projection),
                None,
            ),
        };
        Ok(Some(EptTerms {
            grid: self.grid.clone(),
            full,
            nw,
            basis_residual: Some(residual),
        }))
    }
}

impl EptTerms {
    /// One header line if the terms come from basis tensors: the projection residuals.
    pub fn describe_source(&self) -> Option<String> {
        let (full, nw) = self.basis_residual?;
        let nw = nw.map_or(String::new(), |r| {
            format!(", of the no-wiggle spectrum {r:.1e}")
        });
        Some(format!(
            "loop terms: basis tensors on the same quadrature nodes as direct; projection residual \
             {full:.1e}{nw}; errors include the projection error (2 x residual x |term| for the \
             P22-type terms, residual x P int |w| P for the others)"
        ))
    }
}
