//! The ept multipoles beyond one parameter set: several sets of one f with one projection (the
//! nuisance polynomial's), their exact f-derivatives, and the exact derivatives with respect to α∥,
//! α⊥ ([`EptPlan::multipole_ap_derivatives`]).

use super::tangent::TermsTangent;
use super::{model, EptParams, EptPlan, EptTerms, GridUse, MU_NODES};
use crate::error::{Error, Result};
use crate::integrate::legendre_nodes;
use crate::rsd::ap::Distortion;
use crate::rsd::{legendre_coefficients, MAX_ELL};

impl EptPlan {
    /// This plan with an n-point Gauss–Legendre rule in μ for the values-only multipoles
    /// ([`Self::multipole_values_at`] and the batches, f-derivatives, tangents and AP derivatives
    /// built on them; [`Self::multipoles`] keeps [`MU_NODES`] and its error): a chain step whose
    /// data vector a smaller rule changes by less than its tolerance (measured at build,
    /// [`crate::pipeline`]) projects faster.
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] unless 8 ≤ n ≤ [`MU_NODES`].
    pub fn with_value_nodes(mut self, n: usize) -> Result<Self> {
        if !(8..=MU_NODES).contains(&n) {
            return Err(Error::InvalidParameter {
                name: "value_nodes",
                value: n as f64,
                reason: "the values' rule in mu takes 8 to 24 nodes",
            });
        }
        self.value_rule = mu_rule(n);
        Ok(self)
    }

    /// The number of nodes in μ of the values-only multipoles ([`Self::with_value_nodes`]).
    pub fn value_nodes(&self) -> usize {
        self.value_rule.len()
    }

    /// [`Self::multipole_values_at`] of several parameter sets of one growth rate f (e.g. the
    /// nuisance polynomial's 22 sets, [`crate::pipeline::CosmologyStep::linearise`]): the projection
    /// onto the multipoles is linear in the model's μ² polynomials on the grid, so it is made once per
    /// output k as weights on the grid points its stencils reach and applied to each set's
    /// polynomials (`out[s][j][i]`: set s, j-th ℓ, i-th k; the same numbers to rounding).
    ///
    /// # Errors
    /// As [`Self::multipole_values_at`]; [`Error::InvalidChoice`] for sets of different f.
    pub fn multipole_values_many(
        &self,
        terms: &EptTerms,
        params: &[EptParams],
        ells: &[usize],
        ap: Option<Distortion>,
    ) -> Result<Vec<Vec<Vec<f64>>>> {
        Ok(self
            .multipole_values_and_df_many(terms, params, &[], ells, ap)?
            .0)
    }

    /// [`Self::multipole_values_many`] of the sets `params`, and the exact f-derivatives of the
    /// multipoles of the sets `df` (of the same f; their μ² polynomials' and the BAO damping's, no
    /// finite differences), with one projection: `(values, d/df)`.
    ///
    /// # Errors
    /// As [`Self::multipole_values_many`].
    #[allow(clippy::type_complexity)]
    pub fn multipole_values_and_df_many(
        &self,
        terms: &EptTerms,
        params: &[EptParams],
        df: &[EptParams],
        ells: &[usize],
        ap: Option<Distortion>,
    ) -> Result<(Vec<Vec<Vec<f64>>>, Vec<Vec<Vec<f64>>>)> {
        self.project_sets(terms, params, df, None, ells, ap)
    }

    /// The projection of [`Self::multipole_values_and_df_many`] and, with `tangents`, of
    /// [`Self::multipoles_with_tangents`] (the tangents' multipoles after the f-derivatives):
    /// every set of one f, the weights made once.
    #[allow(clippy::type_complexity)]
    pub(super) fn project_sets(
        &self,
        terms: &EptTerms,
        params: &[EptParams],
        df: &[EptParams],
        tangents: Option<(&[TermsTangent], &EptParams)>,
        ells: &[usize],
        ap: Option<Distortion>,
    ) -> Result<(Vec<Vec<Vec<f64>>>, Vec<Vec<Vec<f64>>>)> {
        let all: Vec<EptParams> = params
            .iter()
            .chain(df)
            .chain(tangents.map(|(_, p)| p))
            .copied()
            .collect();
        if let Some(p) = all.iter().find(|p| p.f() != all[0].f()) {
            return Err(Error::InvalidChoice {
                what: format!("parameter sets with f = {} and {}", all[0].f(), p.f()),
                reason: "a batch of multipoles shares one growth rate (its damping)".into(),
            });
        }
        let (weights, nodes) = self.projection_nodes(terms, &all, ells, ap)?;
        let models: Vec<_> = params.iter().map(|p| terms.model_values(p)).collect();
        let df_models: Vec<_> = df.iter().map(|p| terms.model_values(p)).collect();
        let base = tangents.map(|(_, p)| terms.model_values(p));
        let mut parts: Vec<_> = df
            .iter()
            .zip(&df_models)
            .map(|(p, m)| (m, terms.parts_df(p), model::DampingTangent::F))
            .collect();
        if let (Some((tangents, params)), Some(base)) = (tangents, &base) {
            for t in tangents {
                let (d, damping) = t.model_parts(terms, params)?;
                parts.push((base, d, damping));
            }
        }
        let on_grid = ap.is_none() && self.grid_use == GridUse::Output;
        model::project_many(&models, &parts, &self.k_out, &nodes, &weights, on_grid)
    }

    /// The exact derivatives of [`Self::multipole_values_at`] with respect to α∥ and α⊥ at the
    /// distortion `ap` (of the interpolant in ln k of the true spectrum, the BAO damping and the
    /// volume factor; no finite differences): `[d/dα∥, d/dα⊥]`, each `[j][i]` as the values.
    ///
    /// # Errors
    /// As [`Self::multipole_values_at`] (the plan must have an AP grid: [`super::EptSettings::ap`] or
    /// [`super::EptSettings::ap_range`]).
    pub fn multipole_ap_derivatives(
        &self,
        terms: &EptTerms,
        params: &EptParams,
        ells: &[usize],
        ap: Distortion,
    ) -> Result<[Vec<Vec<f64>>; 2]> {
        let mut all =
            self.multipole_ap_derivatives_many(terms, std::slice::from_ref(params), ells, ap)?;
        Ok(all.remove(0))
    }

    /// [`Self::multipole_ap_derivatives`] of several parameter sets of one growth rate f, with one
    /// projection (its stencils and damping made once): one `[d/dα∥, d/dα⊥]` per set.
    ///
    /// # Errors
    /// As [`Self::multipole_values_many`].
    pub fn multipole_ap_derivatives_many(
        &self,
        terms: &EptTerms,
        params: &[EptParams],
        ells: &[usize],
        ap: Distortion,
    ) -> Result<Vec<[Vec<Vec<f64>>; 2]>> {
        if let Some(p) = params.iter().find(|p| p.f() != params[0].f()) {
            return Err(Error::InvalidChoice {
                what: format!("parameter sets with f = {} and {}", params[0].f(), p.f()),
                reason: "a batch of multipoles shares one growth rate (its damping)".into(),
            });
        }
        let (weights, nodes) = self.projection_nodes(terms, params, ells, Some(ap))?;
        let models: Vec<_> = params.iter().map(|p| terms.model_values(p)).collect();
        model::ap_derivatives_many(&models, &self.k_out, &nodes, &weights, (ap.apar, ap.aperp))
    }

    /// The checks of a projection: each parameter set, the distortion against the plan's AP grid,
    /// the terms' grid, the multipoles (even, ≤ 8).
    pub(super) fn check_projection(
        &self,
        terms: &EptTerms,
        params: &[EptParams],
        ells: &[usize],
        ap: Option<Distortion>,
    ) -> Result<()> {
        for p in params {
            p.validate()?;
        }
        self.check_ap(ap)?;
        self.check_terms(terms)?;
        crate::rsd::check_ells(ells)?;
        Ok(())
    }

    /// The checks of a projection onto the multipoles `ells` with distortion `ap`
    /// ([`Self::check_projection`]), and per μ node of the values' rule ([`Self::value_nodes`]) the
    /// weights (2ℓ + 1) w L_ℓ(μ) × the AP volume factor, and the distortion's ln(k'/k), (k'/k)² and
    /// μ' (the same at every k).
    #[allow(clippy::type_complexity)]
    pub(super) fn projection_nodes(
        &self,
        terms: &EptTerms,
        params: &[EptParams],
        ells: &[usize],
        ap: Option<Distortion>,
    ) -> Result<(Vec<Vec<f64>>, Vec<(f64, f64, f64)>)> {
        self.check_projection(terms, params, ells, ap)?;
        let volume = ap.map_or(1.0, |d| d.volume());
        let weights: Vec<Vec<f64>> = self
            .value_rule
            .iter()
            .map(|(_, w, legendre)| {
                ells.iter()
                    .map(|&l| w * (2 * l + 1) as f64 * legendre[l] * volume)
                    .collect()
            })
            .collect();
        // per μ node, the distortion's k'/k and μ' (Distortion::true_coordinates): ln(k'/k),
        // (k'/k)² and μ', the same at every k
        let nodes: Vec<(f64, f64, f64)> = self
            .value_rule
            .iter()
            .map(|(mu, _, _)| match &ap {
                None => (0.0, 1.0, *mu),
                Some(ap) => {
                    let (ratio, mt) = ap.true_coordinates(1.0, *mu);
                    (ratio.ln(), ratio * ratio, mt)
                }
            })
            .collect();
        Ok((weights, nodes))
    }
}

/// A Gauss–Legendre rule in μ on [0, 1]: (μ, w, L_0…L_8(μ)) per node.
pub(super) type MuRule = Vec<(f64, f64, [f64; MAX_ELL + 1])>;

/// The n-point Gauss–Legendre rule on [0, 1] with the Legendre polynomials at its nodes.
pub(super) fn mu_rule(n: usize) -> MuRule {
    let legendre: Vec<Vec<f64>> = (0..=MAX_ELL).map(legendre_coefficients).collect();
    let (x, w) = legendre_nodes(n);
    x.iter()
        .zip(&w)
        .map(|(&x, &w)| {
            let mu = 0.5 * (x + 1.0);
            let l =
                std::array::from_fn(|ell| legendre[ell].iter().rev().fold(0.0, |a, c| a * mu + c));
            (mu, 0.5 * w, l)
        })
        .collect()
}
