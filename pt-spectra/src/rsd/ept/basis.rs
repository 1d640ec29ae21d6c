//! The galaxy model's loop terms from basis tensors ([`RedshiftBasis`]): a new spectrum's terms as
//! contractions with its projection instead of the plan's integrals.
//!
//! With IR resummation nothing else is per spectrum either: the no-wiggle filter is linear in P on
//! the lattice ([`crate::savgol::no_wiggle_samples`]), so with P ≈ Σ c_a φ_a the no-wiggle spectrum is
//! Σ c_a S[φ_a] with the filtered functions S[φ_a] made once per plan. Its terms are contractions of
//! the same c with the tensors of S[φ_a] ([`RedshiftFamily::FilteredNoWiggle`]), Σ² is a linear form in c
//! (Simpson's rule on the lattice, its error the difference from the half-resolution rule), and
//! P_nw(k) at the output k, which the model uses directly, a fixed linear form of the spectrum's own
//! lattice samples (the filter's taps composed with the lattice interpolation), not of the
//! projection.

use super::{sigma2_kernel, EptPlan, EptTerms};
use crate::error::Result;
use crate::linear::LinearSpectrum;
use crate::loops::basis::training::camb_basis;
use crate::loops::basis::{LinearBasis, Projection, RedshiftBasis, RedshiftFamily, BASIS_SIZE};
use crate::loops::Estimate;
use crate::output::MethodNote;
use crate::progress::Progress;
use crate::store::TableStore;
use std::sync::Arc;

/// The tensors of the linear spectrum's terms and, with IR resummation, of the no-wiggle terms and
/// the forms of the no-wiggle spectrum.
#[derive(Debug, Clone)]
pub(super) struct Tensors {
    pub(super) linear: Arc<RedshiftBasis>,
    pub(super) no_wiggle: Option<(Arc<RedshiftBasis>, NoWiggleForms)>,
}

/// The no-wiggle spectrum of a spectrum with coefficients c as linear forms in c.
#[derive(Debug, Clone)]
pub(super) struct NoWiggleForms {
    /// Per output k: P_nw(k) as weights over the lattice samples from a first index.
    at_k: Vec<(usize, Vec<f64>)>,
    /// Σ² on the lattice (Simpson), and its difference from the half-resolution rule.
    sigma2: [Vec<f64>; 2],
}

impl NoWiggleForms {
    fn new(basis: &LinearBasis, grid: &[f64]) -> Self {
        let lattice = basis.lattice();
        let n = basis.len();
        let step = lattice.step;
        let filtered = basis.transformed_rows(&|f| crate::savgol::no_wiggle_samples(f, step));
        let at_k = grid
            .iter()
            .map(|&k| {
                let (b, t) = lattice.stencil((k.ln() - lattice.x0) / step);
                let l = crate::integrate::lagrange4(t);
                let rows: Vec<_> = (0..4)
                    .map(|s| crate::savgol::no_wiggle_weights(lattice.len, step, b + s))
                    .collect();
                let first = rows.iter().map(|r| r.0).min().unwrap_or(0);
                let last = rows.iter().map(|r| r.0 + r.1.len()).max().unwrap_or(0);
                let mut w = vec![0.0; last - first];
                for (ls, (start, row)) in l.iter().zip(&rows) {
                    for (i, v) in row.iter().enumerate() {
                        w[start + i - first] += ls * v;
                    }
                }
                (first, w)
            })
            .collect();
        // Σ² = ∫ d ln q (weight) P_nw(q), as sigma2 integrates it.
        let integrand: Vec<f64> = (0..lattice.len)
            .map(|j| sigma2_kernel(lattice.x(j).exp()))
            .collect();
        let form = |stride: usize| {
            let weights = simpson_weights(lattice.len.div_ceil(stride), step * stride as f64);
            let mut form = vec![0.0; n];
            for (i, w) in weights.iter().enumerate() {
                let j = i * stride;
                let row = &filtered[j * n..(j + 1) * n];
                form.iter_mut()
                    .zip(row)
                    .for_each(|(f, r)| *f += w * integrand[j] * r);
            }
            form
        };
        let (fine, coarse) = (form(1), form(2));
        let diff = fine.iter().zip(&coarse).map(|(f, c)| f - c).collect();
        Self {
            at_k,
            sigma2: [fine, diff],
        }
    }

    /// P_nw at the output k of the spectrum with lattice samples `samples` and coefficients `c`, and
    /// Σ² with its error (quadrature, and `eps` of it for the projection).
    pub(super) fn evaluate(&self, samples: &[f64], c: &[f64], eps: f64) -> (Vec<f64>, Estimate) {
        let dot = crate::simd::dot;
        let p_nw = self
            .at_k
            .iter()
            .map(|(first, w)| dot(w, &samples[*first..first + w.len()]))
            .collect();
        let sigma2 = dot(&self.sigma2[0], c);
        let error = dot(&self.sigma2[1], c).abs() + eps * sigma2.abs();
        (p_nw, Estimate::new(sigma2, error))
    }
}

/// Composite Simpson weights for `len` points spaced `h` (the last interval by the trapezoid rule if
/// their number is odd).
fn simpson_weights(len: usize, h: f64) -> Vec<f64> {
    let mut w = vec![0.0; len];
    if len < 2 {
        return w;
    }
    let even = if (len - 1).is_multiple_of(2) {
        len
    } else {
        len - 1
    };
    for i in (0..even.saturating_sub(1)).step_by(2) {
        w[i] += h / 3.0;
        w[i + 1] += 4.0 * h / 3.0;
        w[i + 2] += h / 3.0;
    }
    if even < len {
        w[len - 2] += h / 2.0;
        w[len - 1] += h / 2.0;
    }
    w
}

impl EptPlan {
    /// This plan with the basis tensors of its loop terms ([`RedshiftBasis`]) as the precision's
    /// method says ([`crate::precision::TwoLoopMethod`]: `basis` reads or builds them in `store`,
    /// seconds, `auto` uses them if cached, `direct` never).
    ///
    /// # Errors
    /// As [`TableStore::for_method`].
    pub fn with_basis(mut self, store: &TableStore, progress: &dyn Progress) -> Result<Self> {
        let precision = self.loops.precision().clone();
        let lattice = self.loops.rules().0.lattice.clone();
        let ir = self.split.is_some();
        let linear_basis = || camb_basis(lattice.clone(), BASIS_SIZE);
        let get = |family| -> Result<_> {
            let build = |tick: &(dyn Fn(usize, usize) + Sync)| {
                RedshiftBasis::build(&self.loops, family, linear_basis(), tick)
            };
            let key = (self.loop_grid(), &precision, family);
            store.for_method::<RedshiftBasis>(precision.two_loop, key, build, progress)
        };
        let linear = get(RedshiftFamily::Linear)?;
        let no_wiggle = if ir {
            get(RedshiftFamily::FilteredNoWiggle)?
        } else {
            None
        };
        self.tensors = match (linear, no_wiggle, ir) {
            (Some(linear), None, false) => Some(Tensors {
                linear,
                no_wiggle: None,
            }),
            (Some(linear), Some(nw), true) => {
                let forms = NoWiggleForms::new(linear.basis(), &self.grid);
                Some(Tensors {
                    linear,
                    no_wiggle: Some((nw, forms)),
                })
            }
            _ => None,
        };
        Ok(self)
    }

    /// This plan accepting spectra that project on the basis with a smoothed residual up to
    /// `max_residual` (default [`crate::loops::basis::MAX_RESIDUAL`]); the terms' errors include the projection error
    /// ([`EptTerms::describe_source`]) whatever the residual.
    ///
    /// # Errors
    /// [`crate::error::Error::InvalidParameter`] unless 0 < `max_residual` < 0.1.
    pub fn with_max_residual(mut self, max_residual: f64) -> Result<Self> {
        if !(max_residual > 0.0 && max_residual < 0.1) {
            return Err(crate::error::Error::InvalidParameter {
                name: "max_residual",
                value: max_residual,
                reason: "the largest projection residual must lie in (0, 0.1)",
            });
        }
        self.max_residual = max_residual;
        Ok(self)
    }

    /// The largest projection residual evaluated on the tensors ([`Self::with_max_residual`]).
    pub fn max_residual(&self) -> f64 {
        self.max_residual
    }

    /// Whether the loop terms come from basis tensors (for spectra the bases represent).
    pub fn has_basis(&self) -> bool {
        self.tensors.is_some()
    }

    /// The projection of `spectrum` on the linear basis of the tensors (`None` without tensors):
    /// its coefficients and residual, whether or not [`Self::terms`] accepts it
    /// ([`crate::loops::basis::MAX_RESIDUAL`]).
    pub fn basis_projection(&self, spectrum: &LinearSpectrum) -> Option<Projection> {
        let basis = self.tensors.as_ref()?.linear.basis();
        let samples = basis.sample(spectrum);
        Some(basis.project_spectrum_sampled(spectrum, &samples, self.max_residual))
    }

    /// The linear basis the spectra are projected on, if the loop terms come from basis tensors.
    pub fn linear_basis(&self) -> Option<&LinearBasis> {
        Some(self.tensors.as_ref()?.linear.basis())
    }

    /// The loop terms from the basis tensors (`Ok`), or why not (`Err`): `None` without tensors, the
    /// projection residual of a spectrum the basis does not represent well enough.
    pub(super) fn terms_on_basis(
        &self,
        spectrum: &LinearSpectrum,
        errors: bool,
    ) -> Result<std::result::Result<EptTerms, Option<f64>>> {
        let Some(tensors) = &self.tensors else {
            return Ok(Err(None));
        };
        let basis = tensors.linear.basis();
        let samples = basis.sample(spectrum);
        let projection = basis.project_spectrum_sampled(spectrum, &samples, self.max_residual);
        if projection.residual.is_nan() || projection.residual > self.max_residual {
            return Ok(Err(Some(projection.residual)));
        }
        // P_lin and P_nw on the whole grid; the loop terms on the loop grid, padded
        let p_lin: Vec<f64> = self.grid.iter().map(|&k| spectrum.eval(k)).collect();
        Ok(Ok(self.terms_of_samples(
            tensors,
            &samples,
            p_lin,
            &projection,
            errors,
        )))
    }

    /// The loop terms of a spectrum given by its lattice `samples`, its values `p_lin` on the
    /// plan's grid and its `projection` on the basis: a polynomial of degree 2 in (samples, p_lin)
    /// when `projection` is theirs without the soft-mode cut (its coefficients are linear in the
    /// samples), which [`super::tangent`] relies on.
    pub(super) fn terms_of_samples(
        &self,
        tensors: &Tensors,
        samples: &[f64],
        p_lin: Vec<f64>,
        projection: &Projection,
        errors: bool,
    ) -> EptTerms {
        let span = self.loop_span.clone();
        let c = &projection.coefficients;
        let (full, nw) = match (&self.split, &tensors.no_wiggle) {
            (Some(()), Some((nw_tensors, forms))) => {
                let (p_nw, sigma2) = forms.evaluate(samples, c, projection.residual);
                let (full, t) = if errors {
                    tensors.linear.evaluate_with_no_wiggle(
                        &self.loops,
                        (&p_lin[span.clone()], projection),
                        nw_tensors,
                        (&p_nw[span], projection),
                    )
                } else {
                    let (full, t) = tensors.linear.evaluate_values(
                        &self.loops,
                        (&p_lin[span.clone()], c),
                        Some((nw_tensors, &p_nw[span])),
                    );
                    (full, t.expect("asked for"))
                };
                let sigma2 = if errors {
                    sigma2
                } else {
                    Estimate::new(sigma2.value, f64::NAN)
                };
                (full, Some((self.padded(t, &p_nw), sigma2)))
            }
            _ if errors => (
                tensors
                    .linear
                    .evaluate(&self.loops, &p_lin[span], projection),
                None,
            ),
            _ => (
                tensors
                    .linear
                    .evaluate_values(&self.loops, (&p_lin[span], c), None)
                    .0,
                None,
            ),
        };
        let full = self.padded(full, &p_lin);
        EptTerms {
            grid: self.grid.clone(),
            spline: self.spline.clone(),
            full,
            nw,
            basis_residual: Some(projection.residual),
            basis_soft: projection.soft_delta(),
            fallback_residual: None,
        }
    }
}

impl EptTerms {
    /// The projection residual if the terms come from basis tensors (`None`: the direct integrals).
    pub fn basis_residual(&self) -> Option<f64> {
        self.basis_residual
    }

    /// How the loop terms were computed: from the tensors, directly, or directly because the plan's
    /// tensors did not accept the spectrum ([`Self::describe_source`] with the figures).
    pub fn method_note(&self) -> MethodNote {
        let method = match (self.basis_residual, self.fallback_residual) {
            (Some(_), _) => "basis",
            (None, Some(_)) => crate::output::FALLBACK_RESIDUAL,
            (None, None) => "direct",
        };
        MethodNote::new("loop terms", method)
    }

    /// One header line if the terms come from basis tensors (the projection residuals) or were
    /// integrated directly because the tensors did not accept the spectrum (its residual).
    pub fn describe_source(&self) -> Option<String> {
        if let Some(residual) = self.fallback_residual {
            return Some(format!(
                "loop terms: direct integration, since the spectrum's projection residual on the \
                 basis, {residual:.1e}, exceeds the plan's limit (a spectrum unlike the CAMB tables \
                 of the basis)"
            ));
        }
        let residual = self.basis_residual?;
        Some(format!(
            "loop terms: basis tensors on the same quadrature nodes as direct (no-wiggle terms: the \
             tensors of the filtered basis functions); projection residual {residual:.1e}; errors \
             include the projection error (2 x residual x |term| for the \
             P22-type terms, residual x P int |w| P for the others){}",
            crate::loops::basis::soft::describe(self.basis_soft)
        ))
    }
}

#[cfg(test)]
mod tests {
    use super::simpson_weights;

    #[test]
    fn simpson_weights_integrate_cubics_exactly_and_lines_with_a_trapezoid_end() {
        // 11 points (10 intervals): exact for x³ on [0, 1]; 12 points: the last interval by the
        // trapezoid rule, still exact for straight lines.
        let w = simpson_weights(11, 0.1);
        let cubic: f64 = w
            .iter()
            .enumerate()
            .map(|(i, w)| w * (0.1 * i as f64).powi(3))
            .sum();
        assert!((cubic - 0.25).abs() < 1e-15, "{cubic}");
        let w = simpson_weights(12, 0.1);
        let line: f64 = w
            .iter()
            .enumerate()
            .map(|(i, w)| w * (1.0 + 0.1 * i as f64))
            .sum();
        assert!((line - (1.1 + 1.1 * 1.1 / 2.0)).abs() < 1e-14, "{line}");
        assert!(simpson_weights(1, 0.1).iter().all(|&v| v == 0.0));
    }
}
