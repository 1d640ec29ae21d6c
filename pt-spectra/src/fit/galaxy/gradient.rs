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
//! r = d − m₀ − Σ âₐTₐ. The model's derivatives are exact:
//! * f, α∥, α⊥: those of the projection ([`crate::rsd::ept::EptPlan::multipole_values_and_df_many`],
//!   [`crate::rsd::ept::EptPlan::multipole_ap_derivatives_many`]), at the point and at each template's
//!   set, so ∂Tₐ/∂θ is their difference;
//! * the polynomial parameters (biases, counterterms, stochastic terms held free): the model is at
//!   most quadratic in each, so ∂m/∂θⱼ = [m(θ + eⱼ) − m(θ − eⱼ)]/2 exactly (checked when the
//!   objective is made, as is ∂Tₐ/∂θⱼ = 0: the templates do not multiply them).
//!
//! The curvature handed to the minimiser with it is Gauss–Newton's, 2(|Jⱼ|² − (TᵀJⱼ)ᵀF⁻¹(TᵀJⱼ)) plus
//! the prior's, with Jⱼ the column above: the diagonal of the profiled χ²'s Hessian without the
//! model's second derivatives.
//!
//! Not covered (the minimiser differences the objective there, and the output says so): the DESI
//! physical basis (its map mixes the counterterms with b₁ and f), a bispectrum beside the power
//! spectrum, and a model that fails the checks above.

use super::objective::Objective;
use super::{AP_SLOT, SLOTS};
use crate::error::Result;
use crate::linalg::dot;
use crate::rsd::ept::{EptParams, PARAM_NAMES};

/// The slot of the growth rate f.
const F_SLOT: usize = PARAM_NAMES.len() - 1;

/// The relative size, against the model, of a third difference (or of a template's change) that
/// counts as none: rounding of the model's sums.
const EXACTNESS_TOLERANCE: f64 = 1e-9;

/// What the gradient needs to know of one free parameter.
#[derive(Clone, Copy)]
enum Kind {
    /// A polynomial parameter: its index among the ± sets.
    Polynomial(usize),
    /// The growth rate.
    Growth,
    /// α∥ (0) or α⊥ (1).
    Distortion(usize),
}

impl Objective<'_> {
    /// Whether [`Self::value_and_gradient`] is exact for this objective (module docs): the
    /// velocileptors basis, no bispectrum, the model at most quadratic in each free polynomial
    /// parameter and the templates independent of them, both checked at the start.
    pub(super) fn check_exact_gradient(&self) -> Result<bool> {
        if self.basis.is_some() || self.bispectrum.is_some() {
            return Ok(false);
        }
        let mut v = self.start;
        for &i in &self.marg {
            v[i] = 0.0;
        }
        let polynomial: Vec<usize> = self.free.iter().copied().filter(|&j| j < F_SLOT).collect();
        let m = self.model(&v)?;
        let scale = m
            .iter()
            .fold(0.0f64, |s, x| s.max(x.abs()))
            .max(f64::MIN_POSITIVE);
        for &j in &polynomial {
            let at = |d: f64| {
                let mut w = v;
                w[j] += d;
                self.model(&w)
            };
            let (a, b, c) = (at(2.0)?, at(1.0)?, at(-1.0)?);
            let third = (0..m.len()).map(|i| a[i] - 3.0 * b[i] + 3.0 * m[i] - c[i]);
            if third.fold(0.0f64, |s, x| s.max(x.abs())) > EXACTNESS_TOLERANCE * scale {
                return Ok(false);
            }
        }
        if self.marg.is_empty() || polynomial.is_empty() {
            return Ok(true);
        }
        let templates = |v: &[f64; SLOTS]| -> Result<Vec<Vec<f64>>> {
            let m0 = self.model(v)?;
            self.marg
                .iter()
                .map(|&a| {
                    let mut w = *v;
                    w[a] = 1.0;
                    Ok(self
                        .model(&w)?
                        .iter()
                        .zip(&m0)
                        .map(|(x, y)| x - y)
                        .collect())
                })
                .collect()
        };
        let t0 = templates(&v)?;
        let mut w = v;
        for (n, &j) in polynomial.iter().enumerate() {
            w[j] += 0.37 - 0.11 * n as f64;
        }
        let t1 = templates(&w)?;
        let t_scale = t0.iter().flatten().fold(0.0f64, |s, x| s.max(x.abs()));
        Ok(t0
            .iter()
            .flatten()
            .zip(t1.iter().flatten())
            .all(|(a, b)| (a - b).abs() <= EXACTNESS_TOLERANCE * t_scale))
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
        let (p, ap) = self.split(&v)?;
        let kinds: Vec<Kind> = {
            let mut n = 0;
            self.free
                .iter()
                .map(|&j| match j {
                    F_SLOT => Kind::Growth,
                    j if j >= AP_SLOT => Kind::Distortion(j - AP_SLOT),
                    _ => {
                        n += 1;
                        Kind::Polynomial(n - 1)
                    }
                })
                .collect()
        };
        // The sets: the point, each template's (aₐ = 1), then ± 1 in each polynomial parameter.
        let nm = self.marg.len();
        let mut sets = vec![p];
        for &a in &self.marg {
            let mut q = p;
            q.values[a] = 1.0;
            sets.push(q);
        }
        for (&j, _) in self
            .free
            .iter()
            .zip(&kinds)
            .filter(|(_, k)| matches!(k, Kind::Polynomial(_)))
        {
            for d in [1.0, -1.0] {
                let mut q: EptParams = p;
                q.values[j] += d;
                sets.push(q);
            }
        }
        let with_growth = kinds.iter().any(|k| matches!(k, Kind::Growth));
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
            Some(d) if kinds.iter().any(|k| matches!(k, Kind::Distortion(_))) => self
                .plan
                .multipole_ap_derivatives_many(self.terms, &sets[..=nm], ells, d)?
                .into_iter()
                .map(|[a, b]| Ok([observe(a)?, observe(b)?]))
                .collect::<Result<_>>()?,
            _ => Vec::new(),
        };
        let m0 = &w[0];
        let diff =
            |a: &[f64], b: &[f64]| -> Vec<f64> { a.iter().zip(b).map(|(x, y)| x - y).collect() };
        let templates: Vec<Vec<f64>> = (1..=nm).map(|a| diff(&w[a], m0)).collect();
        let marginal = self.marginalise(&mut v, m0, &templates)?;
        let n = self.free.len();
        let (mut gradient, mut curvature) = (vec![0.0; n], vec![0.0; n]);
        for (col, (&j, kind)) in self.free.iter().zip(&kinds).enumerate() {
            // ∂m₀/∂θ and ∂Tₐ/∂θ
            let (dm0, dt): (Vec<f64>, Vec<Vec<f64>>) = match *kind {
                Kind::Polynomial(q) => {
                    let (up, down) = (&w[1 + nm + 2 * q], &w[2 + nm + 2 * q]);
                    (
                        up.iter().zip(down).map(|(a, b)| 0.5 * (a - b)).collect(),
                        Vec::new(),
                    )
                }
                Kind::Growth => (
                    df[0].clone(),
                    (1..=nm).map(|a| diff(&df[a], &df[0])).collect(),
                ),
                Kind::Distortion(c) => (
                    da[0][c].clone(),
                    (1..=nm).map(|a| diff(&da[a][c], &da[0][c])).collect(),
                ),
            };
            // J = ∂m/∂θ at â
            let mut jac = dm0;
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
    use super::super::{GalaxyFitRequest, Prior, PriorShape};
    use crate::fit::MultipoleData;
    use crate::linear::{LinearSpectrum, LogGrid};
    use crate::precision::Precision;
    use crate::rsd::ap::Distortion;
    use crate::rsd::ept::{EptParams, EptPlan, EptSettings};

    /// The exact gradient of −2 ln L (free f, b1, b2, bs, α∥, α⊥ and α₄, a log-normal prior on b1;
    /// α₀, α₂, sn marginalised with Gaussian priors, ln det F included) against fourth-order central
    /// differences of the objective, away from the minimum; the Gauss–Newton curvature is positive.
    #[test]
    fn gradient_matches_differences_of_the_objective() {
        let k = LogGrid::new(0.02, 0.2, 20).unwrap().points();
        let settings = EptSettings {
            ir: true,
            ap: Some(Distortion::new(1.0, 1.0).unwrap()),
            ap_range: Some((0.8, 1.25)),
            loop_range: None,
        };
        let plan = EptPlan::new(&k, settings, &Precision::fast()).unwrap();
        let terms = plan.terms(&LinearSpectrum::gm2012(0.5).unwrap()).unwrap();
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
        let m = plan
            .multipole_values_at(&terms, &truth, &[0, 2, 4], Some(d))
            .unwrap();
        let sigma: Vec<Vec<f64>> = (0..3)
            .map(|_| m[0].iter().map(|p| 0.02 * p).collect())
            .collect();
        let data = MultipoleData::from_arrays(k, &[0, 2, 4], m, sigma, "model").unwrap();
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
            basis: None,
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
        // The physical basis has no exact gradient here (the minimiser differences it).
        let basis = crate::rsd::ept::physical::PhysicalBasis::new(0.6, 3e-4, 0.1, 5.0).unwrap();
        let physical = GalaxyFitRequest {
            free: ["f", "b1p"].map(String::from).to_vec(),
            marginalise: vec![],
            priors: vec![],
            basis: Some(basis),
            ..request
        };
        let o = objective(&plan, &terms, &data, &physical, None, None).unwrap();
        assert!(!o.exact_gradient && o.value_and_gradient(&[0.7, 1.1]).unwrap().is_none());
    }
}
