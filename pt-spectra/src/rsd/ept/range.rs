//! Loop terms on part of the grid ([`super::EptSettings::loop_range`]): the loop plan covers the grid
//! points inside the range only, and its terms are padded to the whole grid with zeros, the linear
//! spectrum (and its no-wiggle part) being known everywhere. An observation whose window reaches
//! k = 1e-4 … 4 h/Mpc but weighs the columns beyond the fitted scales by 1e-6 then pays for the loops
//! where they matter only ([`crate::pipeline::Pipeline`] chooses the range and states what it changes).

use super::{EptPlan, EptTerms};
use crate::error::{Error, Result};
use crate::estimate::Estimate;
use crate::loops::redshift::{RedshiftTerm, RedshiftTerms};
use std::ops::Range;

/// The indices of `grid` inside `range` [h/Mpc] (all of them for `None`).
///
/// # Errors
/// [`Error::InvalidChoice`] for a range that is not 0 < lo < hi < ∞ or holds fewer than 4 grid points
/// (the interpolation stencil).
pub(super) fn loop_span(grid: &[f64], range: Option<(f64, f64)>) -> Result<Range<usize>> {
    let Some((lo, hi)) = range else {
        return Ok(0..grid.len());
    };
    if !(lo > 0.0 && hi > lo && hi.is_finite()) {
        return Err(Error::InvalidChoice {
            what: format!("loop range [{lo}, {hi}] h/Mpc"),
            reason: "needs 0 < lo < hi < infinity".into(),
        });
    }
    let first = grid.partition_point(|&k| k < lo);
    let end = grid.partition_point(|&k| k <= hi);
    if end < first + 4 {
        return Err(Error::InvalidChoice {
            what: format!("loop range [{lo}, {hi}] h/Mpc"),
            reason: format!(
                "holds {} of the plan's grid points (from {:.3e} to {:.3e} h/Mpc); at least 4 are needed",
                end.saturating_sub(first),
                grid[0],
                grid[grid.len() - 1]
            ),
        });
    }
    Ok(first..end)
}

impl EptPlan {
    /// The grid points of the loop terms ([`super::EptSettings::loop_range`]).
    pub(super) fn loop_grid(&self) -> &[f64] {
        &self.grid[self.loop_span.clone()]
    }

    /// The loop range actually covered [h/Mpc]: the first and last grid points of the loop terms.
    pub fn loop_k_range(&self) -> (f64, f64) {
        let g = self.loop_grid();
        (g[0], g[g.len() - 1])
    }

    /// `terms` on the loop grid padded to the whole grid: the linear spectrum `p_lin` at every grid
    /// point, the loop terms 0 (exactly, error 0) outside the loop grid.
    pub(super) fn padded(&self, terms: RedshiftTerms, p_lin: &[f64]) -> RedshiftTerms {
        let span = self.loop_span.clone();
        if span.len() == self.grid.len() {
            return terms;
        }
        let zero = Estimate::new(0.0, 0.0);
        let pad = |values: Vec<Estimate>| -> Vec<Estimate> {
            let mut out = Vec::with_capacity(self.grid.len());
            out.resize(span.start, zero);
            out.extend(values);
            out.resize(self.grid.len(), zero);
            out
        };
        RedshiftTerms {
            k: self.grid.clone(),
            p_lin: p_lin.to_vec(),
            terms: terms
                .terms
                .into_iter()
                .map(|t| RedshiftTerm {
                    values: pad(t.values),
                    ..t
                })
                .collect(),
            sigma_v2: terms.sigma_v2,
        }
    }
}

impl EptTerms {
    /// These terms with the loop terms set to 0 outside [lo, hi] [h/Mpc] (as a plan with that
    /// [`super::EptSettings::loop_range`] computes them: the loop integrals of one k do not depend on
    /// the other k), to measure what a loop range changes without a plan per range.
    pub fn with_loops_only_in(&self, lo: f64, hi: f64) -> EptTerms {
        let zero = Estimate::new(0.0, 0.0);
        let cut = |t: &RedshiftTerms| RedshiftTerms {
            terms: t
                .terms
                .iter()
                .map(|term| RedshiftTerm {
                    values: term
                        .values
                        .iter()
                        .zip(&self.grid)
                        .map(|(v, &k)| if (lo..=hi).contains(&k) { *v } else { zero })
                        .collect(),
                    ..term.clone()
                })
                .collect(),
            ..t.clone()
        };
        EptTerms {
            grid: self.grid.clone(),
            spline: self.spline.clone(),
            full: cut(&self.full),
            nw: self.nw.as_ref().map(|(t, s)| (cut(t), *s)),
            basis_residual: self.basis_residual,
            basis_soft: self.basis_soft,
            fallback_residual: self.fallback_residual,
        }
    }
}
