//! The exact derivative of the ept multipoles along a direction δP of the linear spectrum (the
//! cosmological Jacobian of [`crate::pipeline`] composes it with the emulator's dP/dθ).
//!
//! On the basis path the loop terms are a polynomial of degree 2 in the spectrum's lattice samples s
//! and its values p on the plan's grid: T(s, p) = L(s, p) + Q(s, p), with the projection
//! coefficients c = ⟨φ, ωs⟩ linear in s, the no-wiggle spectrum and Σ² linear forms of s and c, and
//! the terms linear (P_lin, the counterterms' k²P) or bilinear (P22-, P13-type) in them. For such a
//! polynomial the tangent DT\[δs\] = L(δs) + 2Q(s, δs) is written out
//! ([`crate::loops::basis::RedshiftBasis::evaluate_tangents`]: the tensors applied to the symmetric
//! products c_a δc_b + δc_a c_b, the product rule on P_lin × linear forms). The multipoles are affine
//! in the terms at fixed Σ², f and parameters, so the model of the tangent terms without its
//! constant (the stochastic terms) is the model's tangent; Σ² enters the resummation's polynomial
//! (1 + k²Σ²[1 + f(2 + f)μ²]) Z₁² P_w and the damping e^{−k'²Σ²[…]}, whose derivatives are written
//! out (the model's `DampingTangent::Sigma2`).
//!
//! The direct integrals (the fallback when a spectrum does not project on the basis) are not
//! written this way: a tangent there is refused with an error naming the residual.

use super::model::{DampingTangent, PartsDf};
use super::{EptParams, EptPlan, EptTerms};
use crate::error::{Error, Result};
use crate::estimate::Estimate;
use crate::linear::LinearSpectrum;
use crate::rsd::ap::Distortion;

/// The tangent of the loop terms of a spectrum along one direction ([module docs](self)).
#[derive(Debug, Clone)]
pub struct TermsTangent {
    /// dT: the terms' tangent (values; the spectrum's own Σ² in place of dΣ², so that the model's
    /// resummation polynomial is the spectrum's: the damping's change is `d_sigma2`).
    tangent: EptTerms,
    /// dΣ² [(Mpc/h)²] along the direction.
    d_sigma2: f64,
}

impl TermsTangent {
    /// dΣ² along the direction [(Mpc/h)²] (0 without IR resummation).
    pub fn d_sigma2(&self) -> f64 {
        self.d_sigma2
    }

    /// The model's tangent at `params` as the projection takes it: the μ² polynomials of the
    /// tangent terms (the model is affine in the terms: without its constant, the stochastic terms,
    /// the model of the tangent terms is the tangent of the model) with Σ²'s change in the
    /// resummation polynomial, and the damping's change through dΣ².
    pub(super) fn model_parts(
        &self,
        terms: &EptTerms,
        params: &EptParams,
    ) -> Result<(PartsDf, DampingTangent)> {
        let mut linear = *params;
        for name in ["sn", "sn2", "sn4"] {
            linear.set(name, 0.0)?;
        }
        let mut d: PartsDf = self
            .tangent
            .model_values(&linear)
            .parts()
            .iter()
            .map(|(n, w)| (n.0, w.0))
            .collect();
        terms.add_parts_dsigma2(params, self.d_sigma2, &mut d);
        Ok((d, DampingTangent::Sigma2(self.d_sigma2)))
    }
}

impl EptPlan {
    /// The wavenumbers [h/Mpc] at which a direction δP of the linear spectrum is needed by
    /// [`Self::terms_tangents`]: the basis lattice and the plan's grid (`None` without basis tensors).
    pub fn tangent_nodes(&self) -> Option<(Vec<f64>, &[f64])> {
        let lattice = self.linear_basis()?.lattice();
        let k = (0..lattice.len).map(|j| lattice.x(j).exp()).collect();
        Some((k, &self.grid))
    }

    /// The tangents of the loop terms of `spectrum` along the directions `directions`, each its
    /// values (on the lattice, on the grid) at [`Self::tangent_nodes`] ([module docs](self)); the
    /// tensors are read once for all directions.
    ///
    /// # Errors
    /// [`Error::InvalidChoice`] without basis tensors, for a spectrum the basis does not represent
    /// within [`Self::max_residual`] (the direct integrals have no exact tangent), or for directions
    /// of the wrong lengths.
    pub fn terms_tangents(
        &self,
        spectrum: &LinearSpectrum,
        directions: &[(Vec<f64>, Vec<f64>)],
    ) -> Result<Vec<TermsTangent>> {
        let refuse = |reason: String| Error::InvalidChoice {
            what: "the derivative of the ept loop terms along a direction of the linear spectrum"
                .into(),
            reason,
        };
        let Some(tensors) = &self.tensors else {
            return Err(refuse(
                "it needs the basis tensors (the direct integrals have no exact derivative)".into(),
            ));
        };
        let basis = tensors.linear.basis();
        let samples = basis.sample(spectrum);
        if let Some((l, g)) = directions
            .iter()
            .find(|(l, g)| l.len() != samples.len() || g.len() != self.grid.len())
        {
            return Err(refuse(format!(
                "a direction has {} lattice and {} grid values where the plan has {} and {}",
                l.len(),
                g.len(),
                samples.len(),
                self.grid.len()
            )));
        }
        let projection = basis.project(&samples);
        let residual = projection.residual;
        if residual.is_nan() || residual > self.max_residual {
            return Err(refuse(format!(
                "the spectrum projects on the basis with residual {residual:.1e} > {:.1e}: its \
                 terms come from the direct integrals, which have no exact derivative",
                self.max_residual
            )));
        }
        let p_lin: Vec<f64> = self.grid.iter().map(|&k| spectrum.eval(k)).collect();
        let c = &projection.coefficients;
        let on_lattice: Vec<&[f64]> = directions.iter().map(|(l, _)| l.as_slice()).collect();
        let dcs = basis.coefficients_many(&on_lattice);
        let dc_refs: Vec<&[f64]> = dcs.iter().map(Vec::as_slice).collect();
        let span = self.loop_span.clone();
        let d_grid: Vec<&[f64]> = directions.iter().map(|(_, g)| &g[span.clone()]).collect();
        // with IR resummation: P_nw, Σ² and their tangents (linear forms of the samples and c)
        let no_wiggle = match (&self.split, &tensors.no_wiggle) {
            (Some(()), Some((nw_tensors, forms))) => {
                let (p_nw, sigma2) = forms.evaluate(&samples, c, 0.0);
                let d: Vec<(Vec<f64>, Estimate)> = directions
                    .iter()
                    .zip(&dcs)
                    .map(|((l, _), dc)| forms.evaluate(l, dc, 0.0))
                    .collect();
                Some((nw_tensors, p_nw, sigma2.value, d))
            }
            _ => None,
        };
        let dp_nw: Vec<&[f64]> = no_wiggle
            .iter()
            .flat_map(|(_, _, _, d)| d.iter().map(|(dp, _)| &dp[span.clone()]))
            .collect();
        let terms = tensors.linear.evaluate_tangents(
            &self.loops,
            (&p_lin[span.clone()], &d_grid),
            no_wiggle
                .as_ref()
                .map(|(t, p_nw, _, _)| (t.as_ref(), &p_nw[span.clone()], dp_nw.as_slice())),
            (c, &dc_refs),
        );
        Ok(terms
            .into_iter()
            .enumerate()
            .map(|(j, (full, nw))| {
                let (nw, d_sigma2) = match (nw, &no_wiggle) {
                    (Some(t), Some((_, _, sigma2, d))) => (
                        Some((self.padded(t, &d[j].0), Estimate::new(*sigma2, 0.0))),
                        d[j].1.value,
                    ),
                    _ => (None, 0.0),
                };
                TermsTangent {
                    tangent: EptTerms {
                        grid: self.grid.clone(),
                        spline: self.spline.clone(),
                        full: self.padded(full, &directions[j].1),
                        nw,
                        basis_residual: Some(residual),
                        basis_soft: None,
                        fallback_residual: None,
                    },
                    d_sigma2,
                }
            })
            .collect())
    }

    /// The tangents of the multipoles `ells` at the output k of the terms `terms` (of the spectrum
    /// the `tangents` were made from, [`Self::terms_tangents`]) with parameters `params` and
    /// distortion `ap`: one `[j][i]` per tangent, exact ([module docs](self)).
    ///
    /// # Errors
    /// As [`Self::multipole_values_many`].
    pub fn multipole_tangents(
        &self,
        terms: &EptTerms,
        tangents: &[TermsTangent],
        params: &EptParams,
        ells: &[usize],
        ap: Option<Distortion>,
    ) -> Result<Vec<Vec<Vec<f64>>>> {
        Ok(self
            .multipoles_with_tangents(terms, &[], &[], (tangents, params), ells, ap)?
            .tangents)
    }

    /// In one projection (its stencils, damping and weights made once per output k,
    /// [`Self::multipole_values_and_df_many`]): the multipoles of the parameter sets `values`, the
    /// exact f-derivatives of those of the sets `df` and the tangents of those of `params` along
    /// `tangents` ([`Self::multipole_tangents`]); every set of one f. The chain step's Jacobian
    /// needs all three of one spectrum, and the weights cost more than applying them.
    ///
    /// # Errors
    /// As [`Self::multipole_values_and_df_many`].
    pub fn multipoles_with_tangents(
        &self,
        terms: &EptTerms,
        values: &[EptParams],
        df: &[EptParams],
        (tangents, params): (&[TermsTangent], &EptParams),
        ells: &[usize],
        ap: Option<Distortion>,
    ) -> Result<ProjectedTangents> {
        let (values, mut derivatives) =
            self.project_sets(terms, values, df, Some((tangents, params)), ells, ap)?;
        let tangents = derivatives.split_off(df.len());
        Ok(ProjectedTangents {
            values,
            df: derivatives,
            tangents,
        })
    }
}

/// The multipoles of [`EptPlan::multipoles_with_tangents`], each `[j][i]` (j-th ℓ, i-th output k).
#[derive(Debug, Clone)]
pub struct ProjectedTangents {
    /// Of each set of `values`.
    pub values: Vec<Vec<Vec<f64>>>,
    /// The f-derivatives of each set of `df`.
    pub df: Vec<Vec<Vec<f64>>>,
    /// The tangents along each direction.
    pub tangents: Vec<Vec<Vec<f64>>>,
}

#[cfg(test)]
mod tests {
    use super::super::{EptParams, EptPlan, EptSettings};
    use crate::linear::LinearSpectrum;
    use crate::precision::{Precision, TwoLoopMethod};
    use crate::rsd::ap::Distortion;

    /// Along δ ln P = t ln(k/0.05) (the n_s direction: the spline of ln P and its power-law tails
    /// reproduce a line in ln k exactly, so P_t = P (k/0.05)^t node by node is the spectrum moved
    /// exactly along δP = P ln(k/0.05)), the multipoles' tangents equal a 6th-order central
    /// difference (steps 0.05) of the multipoles of P_t, with and without IR and AP, to 1e-6 of the
    /// largest tangent (the bound). A direction of the wrong length and a plan without basis
    /// are refused.
    #[test]
    fn multipole_tangents_equal_high_order_differences() {
        let k: Vec<f64> = (0..12).map(|i| 0.02 * 1.2_f64.powi(i)).collect();
        let dir = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/data/");
        let p = LinearSpectrum::from_file(format!("{dir}linear_pk_camb_heldout_2.dat")).unwrap();
        let moved = |t: f64| {
            let (nk, np) = p.nodes();
            let np = nk
                .iter()
                .zip(np)
                .map(|(k, p)| p * (k / 0.05).powf(t))
                .collect();
            LinearSpectrum::from_nodes(nk.to_vec(), np).unwrap()
        };
        let store = crate::store::TableStore::in_memory();
        let mut params = EptParams::new(1.9, 0.7);
        for (name, v) in [("b2", 0.4), ("bs", -0.3), ("alpha2", 12.0), ("sn", 900.0)] {
            params.set(name, v).unwrap();
        }
        let ells = [0, 2, 4];
        for (ir, ap) in [
            (true, Some(Distortion::new(1.03, 0.96).unwrap())),
            (true, None),
            (false, Some(Distortion::new(0.97, 1.02).unwrap())),
        ] {
            let settings = EptSettings {
                ir,
                ap: None,
                ap_range: ap.map(|_| (0.9, 1.1)),
                loop_range: None,
            };
            let mut precision = Precision::fast();
            precision.two_loop = TwoLoopMethod::Basis;
            let plan = EptPlan::new(&k, settings, &precision)
                .unwrap()
                .with_basis(&store, &crate::progress::Silent)
                .unwrap()
                .with_max_residual(2e-3)
                .unwrap();
            let values = |t: f64| {
                let s = moved(t);
                let terms = plan.terms(&s).unwrap();
                assert!(terms.basis_residual().is_some());
                plan.multipole_values_at(&terms, &params, &ells, ap)
                    .unwrap()
            };
            let terms = plan.terms(&p).unwrap();
            let (lattice, grid) = plan.tangent_nodes().unwrap();
            let direction = |k: &[f64]| -> Vec<f64> {
                k.iter().map(|&k| p.eval(k) * (k / 0.05).ln()).collect()
            };
            let tangent = plan
                .terms_tangents(&p, &[(direction(&lattice), direction(grid))])
                .unwrap()
                .remove(0);
            assert_eq!(tangent.d_sigma2() == 0.0, !ir);
            let exact = plan
                .multipole_tangents(&terms, &[tangent], &params, &ells, ap)
                .unwrap()
                .remove(0);
            // 6th-order central difference (error ~ h⁶ D⁽⁷⁾/140)
            let h = 0.05;
            let at: Vec<_> = [-3.0, -2.0, -1.0, 1.0, 2.0, 3.0]
                .iter()
                .map(|s| values(s * h))
                .collect();
            let c = [-1.0, 9.0, -45.0, 45.0, -9.0, 1.0];
            let scale = exact.iter().flatten().fold(0.0_f64, |m, v| m.max(v.abs()));
            for (j, e) in exact.iter().enumerate() {
                for (i, e) in e.iter().enumerate() {
                    let fd: f64 =
                        c.iter().zip(&at).map(|(c, v)| c * v[j][i]).sum::<f64>() / (60.0 * h);
                    assert!(
                        (e - fd).abs() < 1e-6 * scale,
                        "ir {ir} ap {ap:?} ell {} k {}: {e} {fd}",
                        ells[j],
                        k[i]
                    );
                }
            }
            assert!(plan
                .terms_tangents(&p, &[(direction(&lattice[1..]), direction(grid))])
                .is_err());
        }
        let no_basis = EptPlan::new(&k, EptSettings::default(), &Precision::fast()).unwrap();
        assert!(no_basis.terms_tangents(&p, &[(vec![], vec![])]).is_err());
    }
}
