//! The exact gradient of a galaxy fit's −2 ln L (the linear parameters marginalised), for the
//! minimiser ([`crate::fit::bounded::Problem::grad`]).
//!
//! With the whitened model m(θ, a) = m₀(θ) + Σₐ aₐTₐ(θ) affine in the marginalised parameters a,
//! F = TᵀT + P (P their prior precisions) and â = F⁻¹[Tᵀ(d − m₀) + Pā], the objective is
//! Φ(θ) = min_a [|d − m|² + (a − ā)ᵀP(a − ā)] + ln det F + priors(θ). At the minimum over a the
//! envelope theorem gives
//!
//! ```text
//! ∂Φ/∂θⱼ = −2 rᵀ(∂m₀/∂θⱼ + Σₐ âₐ ∂Tₐ/∂θⱼ) + 2 Σₐ꜀ (F⁻¹)ₐ꜀ T꜀ᵀ ∂Tₐ/∂θⱼ + ∂priors/∂θⱼ,
//! ```
//!
//! r = d − m₀ − Σ âₐTₐ. The model's derivatives are exact. With p(v) the model's parameters of the
//! slots v (the fit's basis maps them, [`super::FitBasis::jacobian`];
//! the identity in velocileptors' basis) and Mᵢ = ∂m/∂pᵢ:
//! * the polynomial parameters (biases, counterterms, stochastic terms): the model is at most
//!   quadratic in each, so Mᵢ = [m(p + eᵢ) − m(p − eᵢ)]/2 exactly; and Mᵢ does not depend on the
//!   linear ones (no product of a bias with a counterterm or stochastic term), so one Mᵢ at the point
//!   serves every template's set (both checked when the objective is made);
//! * f, α∥, α⊥: the projection's exact derivatives ([`crate::rsd::ept::EptPlan::multipole_values_and_df_many`],
//!   [`crate::rsd::ept::EptPlan::multipole_ap_derivatives_many`]) at the point and at each template's set;
//! * ∂m/∂vⱼ = Σᵢ Mᵢ ∂pᵢ/∂vⱼ (+ ∂m/∂f for f) at each set, and ∂Tₐ/∂vⱼ the difference of a template's
//!   set and the point.
//!
//! The curvature handed to the minimiser with it is Gauss–Newton's, 2(|Jⱼ|² − (TᵀJⱼ)ᵀF⁻¹(TᵀJⱼ)) plus
//! the prior's, with Jⱼ the column above: the diagonal of the profiled χ²'s Hessian without the
//! model's second derivatives.
//!
//! Not covered (the minimiser differences the objective there, and the output says so): a block
//! after the power spectrum ([`crate::statistic`]), and a model that fails the checks above.

use super::objective::Objective;
use super::AP_SLOT;
use crate::error::Result;
use crate::linalg::dot;
use crate::rsd::ap::Distortion;
use crate::rsd::ept::{EptParams, PARAM_NAMES};

/// The slot (and model parameter index) of the growth rate f.
const F_SLOT: usize = PARAM_NAMES.len() - 1;

/// The model's parameters that enter linearly: counterterms and stochastic terms.
const LINEAR: std::ops::Range<usize> = 4..F_SLOT;

/// The relative size, against the model, of a third or mixed difference that counts as none:
/// rounding of the model's sums.
const EXACTNESS_TOLERANCE: f64 = 1e-9;

/// ∂p/∂v of a parameter basis: row i a model parameter, column j a slot (both in [`PARAM_NAMES`]'
/// order).
type Jacobian = [[f64; F_SLOT + 1]; F_SLOT + 1];

impl Objective<'_> {
    /// ∂p/∂v at the slots `v`: the basis's Jacobian (the identity in the model's).
    fn basis_jacobian(&self, v: &[f64]) -> Jacobian {
        let mut u = [0.0; F_SLOT + 1];
        u.copy_from_slice(&v[..=F_SLOT]);
        self.basis.jacobian(&u)
    }

    /// The whitened power-spectrum points of each parameter set of `sets` (one f) at `ap`.
    fn models_of(&self, sets: &[EptParams], ap: Option<Distortion>) -> Result<Vec<Vec<f64>>> {
        self.plan
            .multipole_values_many(self.terms, sets, self.plan_ells(), ap)?
            .into_iter()
            .map(|m| Ok(self.whitened(&self.fitted_points(m)?)))
            .collect()
    }

    /// Whether [`Self::value_and_gradient`] is exact for this objective (module docs): no
    /// block, the model at most quadratic in each polynomial parameter and none of their
    /// derivatives changed by the linear ones, checked at the start.
    pub(super) fn check_exact_gradient(&self) -> Result<bool> {
        if self.has_block() {
            return Ok(false);
        }
        let mut v = self.start.clone();
        for &i in &self.marg {
            v[i] = 0.0;
        }
        let (p, ap) = self.split(&v)?;
        let shift = |p: &EptParams, i: usize, d: f64| {
            let mut q = *p;
            q.values[i] += d;
            q
        };
        let mut shifted = p;
        for k in LINEAR {
            shifted.values[k] += 0.3 + 0.1 * k as f64;
        }
        // per polynomial parameter: p + 2eᵢ, p + eᵢ, p − eᵢ, then shifted + eᵢ; p and shifted last
        let mut sets = Vec::new();
        for i in 0..F_SLOT {
            sets.extend([
                shift(&p, i, 2.0),
                shift(&p, i, 1.0),
                shift(&p, i, -1.0),
                shift(&shifted, i, 1.0),
            ]);
        }
        sets.extend([p, shifted]);
        let m = self.models_of(&sets, ap)?;
        let (m0, s0) = (&m[4 * F_SLOT], &m[4 * F_SLOT + 1]);
        let scale = m0.iter().fold(f64::MIN_POSITIVE, |s, x| s.max(x.abs()));
        Ok((0..F_SLOT).all(|i| {
            let [a, b, c, d] = [&m[4 * i], &m[4 * i + 1], &m[4 * i + 2], &m[4 * i + 3]];
            let third = |n: usize| a[n] - 3.0 * b[n] + 3.0 * m0[n] - c[n];
            let mixed = |n: usize| (d[n] - s0[n]) - (b[n] - m0[n]);
            let none = |e: &dyn Fn(usize) -> f64| {
                (0..m0.len()).all(|n| e(n).abs() <= EXACTNESS_TOLERANCE * scale)
            };
            none(&third) && none(&mixed)
        }))
    }

    /// −2 ln L, its exact gradient in the free values `x` and the Gauss–Newton diagonal curvature
    /// (module docs); `Ok(None)` if the objective has no exact gradient.
    ///
    /// # Errors
    /// As the model's evaluation.
    #[allow(clippy::type_complexity)]
    pub(super) fn value_and_gradient(
        &self,
        x: &[f64],
    ) -> Result<Option<(f64, Vec<f64>, Vec<f64>)>> {
        if !self.exact_gradient {
            return Ok(None);
        }
        let mut v = self.slots(x);
        for &i in &self.marg {
            v[i] = 0.0;
        }
        // The base sets: the point, then each template's (its slot at 1).
        let nm = self.marg.len();
        let mut base = vec![v.clone()];
        for &a in &self.marg {
            let mut w = v.clone();
            w[a] = 1.0;
            base.push(w);
        }
        let jacobians: Vec<Jacobian> = base.iter().map(|w| self.basis_jacobian(w)).collect();
        let mut sets = Vec::with_capacity(nm + 1);
        let mut ap = None;
        for w in &base {
            let (p, d) = self.split(w)?;
            sets.push(p);
            ap = d;
        }
        let p = sets[0];
        // The polynomial parameters a free slot reaches, and ± 1 in each at the point.
        let model_slots: Vec<usize> = self.free.iter().copied().filter(|&j| j <= F_SLOT).collect();
        let reached: Vec<usize> = (0..F_SLOT)
            .filter(|&i| {
                model_slots
                    .iter()
                    .any(|&j| jacobians.iter().any(|jac| jac[i][j] != 0.0))
            })
            .collect();
        for &i in &reached {
            for d in [1.0, -1.0] {
                let mut q = p;
                q.values[i] += d;
                sets.push(q);
            }
        }
        let with_growth = self.free.contains(&F_SLOT);
        let with_ap = self.free.iter().any(|&j| j >= AP_SLOT);
        let ells = self.plan_ells();
        let (values, df) = self.plan.multipole_values_and_df_many(
            self.terms,
            &sets,
            if with_growth { &sets[..=nm] } else { &[] },
            ells,
            ap,
        )?;
        let observe =
            |m: Vec<Vec<f64>>| -> Result<Vec<f64>> { Ok(self.whitened(&self.fitted_points(m)?)) };
        let w: Vec<Vec<f64>> = values.into_iter().map(observe).collect::<Result<_>>()?;
        let df: Vec<Vec<f64>> = df.into_iter().map(observe).collect::<Result<_>>()?;
        let da: Vec<[Vec<f64>; 2]> = match ap {
            Some(d) if with_ap => self
                .plan
                .multipole_ap_derivatives_many(self.terms, &sets[..=nm], ells, d)?
                .into_iter()
                .map(|[a, b]| Ok([observe(a)?, observe(b)?]))
                .collect::<Result<_>>()?,
            _ => Vec::new(),
        };
        // Mᵢ = ∂m/∂pᵢ of the reached parameters
        let derivative: Vec<Vec<f64>> = (0..reached.len())
            .map(|r| {
                let (up, down) = (&w[nm + 1 + 2 * r], &w[nm + 2 + 2 * r]);
                up.iter().zip(down).map(|(a, b)| 0.5 * (a - b)).collect()
            })
            .collect();
        let m0 = &w[0];
        let diff =
            |a: &[f64], b: &[f64]| -> Vec<f64> { a.iter().zip(b).map(|(x, y)| x - y).collect() };
        let templates: Vec<Vec<f64>> = (1..=nm).map(|a| diff(&w[a], m0)).collect();
        let marginal = self.marginalise(&mut v, m0, &templates)?;
        let n = self.free.len();
        let (mut gradient, mut curvature) = (vec![0.0; n], vec![0.0; n]);
        for (col, &j) in self.free.iter().enumerate() {
            // ∂m/∂vⱼ at each base set
            let at: Vec<Vec<f64>> = if j <= F_SLOT {
                (0..=nm)
                    .map(|s| {
                        let mut d = if j == F_SLOT {
                            df[s].clone()
                        } else {
                            vec![0.0; m0.len()]
                        };
                        for (r, &i) in reached.iter().enumerate() {
                            let c = jacobians[s][i][j];
                            if c != 0.0 {
                                d.iter_mut()
                                    .zip(&derivative[r])
                                    .for_each(|(x, y)| *x += c * y);
                            }
                        }
                        d
                    })
                    .collect()
            } else {
                da.iter().map(|d| d[j - AP_SLOT].clone()).collect()
            };
            // ∂Tₐ/∂vⱼ, and J = ∂m/∂vⱼ at â
            let dt: Vec<Vec<f64>> = (1..=nm).map(|a| diff(&at[a], &at[0])).collect();
            let mut jac = at[0].clone();
            for (t, a) in dt.iter().zip(&marginal.ahat) {
                jac.iter_mut().zip(t).for_each(|(x, y)| *x += a * y);
            }
            let mut g = -2.0 * dot(&marginal.residual, &jac);
            if self.log_det {
                for (a, t) in dt.iter().enumerate() {
                    for (c, tc) in templates.iter().enumerate() {
                        g += 2.0 * marginal.inverse[a][c] * dot(tc, t);
                    }
                }
            }
            let tj: Vec<f64> = templates.iter().map(|t| dot(t, &jac)).collect();
            let projected: f64 = (0..nm)
                .map(|a| {
                    (0..nm)
                        .map(|c| tj[a] * marginal.inverse[a][c] * tj[c])
                        .sum::<f64>()
                })
                .sum();
            let mut c = 2.0 * (dot(&jac, &jac) - projected);
            if let Some(prior) = &self.priors[j] {
                let (d1, d2) = prior.minus_two_log_derivatives(v[j]);
                g += d1;
                c += d2;
            }
            gradient[col] = g;
            curvature[col] = c;
        }
        Ok(Some((marginal.total, gradient, curvature)))
    }
}

#[cfg(test)]
mod tests {
    use super::super::objective::objective;
    use super::super::{FitBasis, GalaxyFitRequest, Prior, PriorShape};
    use crate::rsd::ap::Distortion;
    use crate::rsd::ept::EptParams;

    /// The exact gradient of −2 ln L (free f, b1, b2, bs, α∥, α⊥ and α₄, a log-normal prior on b1;
    /// α₀, α₂, sn marginalised with Gaussian priors, ln det F included) against fourth-order central
    /// differences of the objective, away from the minimum; the Gauss–Newton curvature is positive.
    #[test]
    fn gradient_matches_differences_of_the_objective() {
        let mut truth = EptParams::new(2.0, 0.75);
        for (n, v) in [
            ("b2", -0.4),
            ("alpha0", 8.0),
            ("alpha2", -6.0),
            ("sn", 900.0),
        ] {
            truth.set(n, v).unwrap();
        }
        let d = Distortion::new(1.03, 0.98).unwrap();
        let (plan, terms, data) = super::super::tests::ap_setup(20, &truth, d, 0.02);
        let mut priors: Vec<Prior> = [("alpha0", 30.0), ("alpha2", 30.0), ("sn", 2000.0)]
            .map(|(n, s)| Prior::gaussian(n, 0.0, s))
            .to_vec();
        priors.push(Prior {
            name: "b1".into(),
            shape: PriorShape::LogNormal {
                mu: 0.6,
                sigma: 0.3,
            },
        });
        let request = GalaxyFitRequest {
            start: EptParams::new(1.9, 0.7),
            ap: Some(Distortion::new(1.0, 1.0).unwrap()),
            free: ["f", "b1", "b2", "bs", "apar", "aperp", "alpha4"]
                .map(String::from)
                .to_vec(),
            marginalise: ["alpha0", "alpha2", "sn"].map(String::from).to_vec(),
            priors,
            ells: vec![0, 2, 4],
            k_min: 0.0,
            k_max: 0.2,
            ell_ranges: vec![],
            n_mocks: None,
            basis: FitBasis::Velocileptors,
        };
        let o = objective(&plan, &terms, &data, &request, None, None).unwrap();
        assert!(o.exact_gradient);
        let x = [0.71, 1.93, -0.2, 0.15, 1.02, 0.99, 3.0];
        let (value, g, c) = o.value_and_gradient(&x).unwrap().unwrap();
        assert!((value - o.cost(&x)).abs() < 1e-9 * value.abs(), "{value}");
        let steps = [1e-3, 1e-3, 1e-2, 1e-2, 1e-4, 1e-4, 1e-1];
        for (i, h) in steps.into_iter().enumerate() {
            let at = |d: f64| {
                let mut y = x;
                y[i] += d;
                o.cost(&y)
            };
            let fd = (8.0 * (at(h) - at(-h)) - (at(2.0 * h) - at(-2.0 * h))) / (12.0 * h);
            let curvature = (at(h) - 2.0 * value + at(-h)) / (h * h);
            assert!(
                (g[i] - fd).abs() < 1e-5 * g[i].abs().max(1.0),
                "{}: exact {} differences {fd}",
                request.free[i],
                g[i]
            );
            // Away from the minimum the model's second derivatives count as well: Gauss–Newton's
            // is a positive scale, not the curvature.
            assert!(
                c[i] > 0.0 && c[i].is_finite() && curvature.is_finite(),
                "{}: Gauss-Newton {} differences {curvature}",
                request.free[i],
                c[i]
            );
        }
        // The CLASS-PT bias basis: b2, bG2, bGamma3 mix into b2, bs, b3 linearly.
        let class_pt = GalaxyFitRequest {
            free: ["f", "b1", "b2", "bG2", "bGamma3"]
                .map(String::from)
                .to_vec(),
            basis: FitBasis::ClassPt,
            ..request.clone()
        };
        let o = objective(&plan, &terms, &data, &class_pt, None, None).unwrap();
        assert_exact_gradient(&o, &[0.72, 1.9, 0.3, -0.2, 0.1], &[1e-3; 5], &class_pt.free);
        // The physical basis: the same check through its map (b1p, f and the counterterms mix).
        let basis = crate::rsd::ept::physical::PhysicalBasis::new(0.6, 3e-4, 0.1, 5.0).unwrap();
        let physical = GalaxyFitRequest {
            free: ["f", "b1p", "b2p", "apar", "aperp"]
                .map(String::from)
                .to_vec(),
            marginalise: ["alpha0p", "alpha2p", "alpha4p", "sn0p", "sn2p"]
                .map(String::from)
                .to_vec(),
            priors: [("alpha0p", 12.5), ("alpha2p", 12.5), ("sn0p", 2.0)]
                .map(|(n, s)| Prior::gaussian(n, 0.0, s))
                .to_vec(),
            basis: FitBasis::Desi(basis),
            ..request
        };
        let o = objective(&plan, &terms, &data, &physical, None, None).unwrap();
        assert_exact_gradient(
            &o,
            &[0.72, 1.15, 0.3, 1.02, 0.99],
            &[1e-3, 1e-3, 1e-2, 1e-4, 1e-4],
            &physical.free,
        );
    }

    /// The objective has an exact gradient, and at `x` it and the value match fourth-order central
    /// differences of −2 ln L (steps `h`) to 1e-5.
    fn assert_exact_gradient(o: &super::Objective, x: &[f64], h: &[f64], names: &[String]) {
        assert!(o.exact_gradient);
        let (value, g, _) = o.value_and_gradient(x).unwrap().unwrap();
        assert!((value - o.cost(x)).abs() < 1e-9 * value.abs(), "{value}");
        for (i, &h) in h.iter().enumerate() {
            let at = |d: f64| {
                let mut y = x.to_vec();
                y[i] += d;
                o.cost(&y)
            };
            let fd = (8.0 * (at(h) - at(-h)) - (at(2.0 * h) - at(-2.0 * h))) / (12.0 * h);
            assert!(
                (g[i] - fd).abs() < 1e-5 * g[i].abs().max(1.0),
                "{}: exact {} differences {fd}",
                names[i],
                g[i]
            );
        }
    }
}
