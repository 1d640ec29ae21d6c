//! `ept`: the 1-loop Eulerian model of biased tracers in redshift space with the BAO resummed
//! (Chen, Vlah, Castorina & White 2021, arXiv:2012.04636; velocileptors' `REPT`), in velocileptors'
//! parameters and conventions:
//!
//!   P(k, μ) = P_nw^{1L}(k, μ) + e^{−k²Σ²(μ)} [ (1 + k²Σ²(μ)) Z₁²P_w + P_w^{1L}(k, μ) ]
//!             + (α₀ + α₂μ² + α₄μ⁴ + α₆μ⁶) k² (P_nw + e^{−k²Σ²(μ)} P_w)
//!             + sn + sn2 k²μ² + sn4 k⁴μ⁴,
//!
//! with Z₁ = b1 + fμ², P^{1L}\[P\] = Z₁²P + the 1-loop terms of [`crate::loops::redshift`] (bias b1, b2, bs,
//! b3 as velocileptors: (b2/2)δ², bs s², b3 = 2 b3nl of FAST-PT; [`crate::bias`]), P_nw the no-wiggle
//! spectrum of velocileptors' Savitzky–Golay filter ([`crate::ir::savitzky_golay_no_wiggle`]), P_w = P − P_nw, P^{1L}_w = P^{1L}\[P\] − P^{1L}\[P_nw\], and
//!   Σ²(μ) = [1 + fμ²(2 + f)] Σ²,   Σ² = (1/6π²) ∫ dq P_nw(q) [1 − j₀(q r_BAO)],   r_BAO = 110 Mpc/h
//! (velocileptors' ½(X + Y/3) at r_BAO). Without IR resummation (`--no-ir`) P_nw = P: plain 1-loop SPT in
//! redshift space, α's times k²P.
//!
//! Counterterms α_n [(Mpc/h)²], stochastic sn [(Mpc/h)³], sn2 [(Mpc/h)⁵], sn4 [(Mpc/h)⁷].
//!
//! Map to other bases:
//! * CLASS-PT (Ivanov et al. 2019; Chudaykin et al. 2020): the biases exactly as [`crate::bias`]
//!   maps them, bs = b_G2, b2 = b2^CLASS-PT − (4/3) b_G2, b3 = −15 b_G2 − 6 b_Γ3 (the cubic parts
//!   of G₂ and Γ₃ have sig3nl's shape, which b3 multiplies). Counterterms at the level of P(k, μ):
//!   α_{2n} k²μ^{2n}P ↔ −2 c̃_{2n} f^n k²μ^{2n}P; stochastic sn = P_shot, sn2 = a2/k_NL² (k_NL = 0.45 h/Mpc);
//!   CLASS-PT's isotropic a0 (k/k_NL)² has no counterpart here.
//! * The paper's TNS (b, A_b, σ0, P_εε): b1 = b and sn = P_εε at large scales; its scale-dependent
//!   A_b and Fingers-of-God σ0 have no counterpart (the counterterms α₂, α₄ take the k²μ² leading
//!   order of the damping: α₂ = −f²σ0²b1², α₄ = −2f³σ0²b1, α₆ = −f⁴σ0² for a Gaussian D²).
//!
//! Multipoles ℓ ≤ 8: Gauss–Legendre in μ on [0, 1] ([`MU_NODES`]; the error the change from half as
//! many nodes), exact when the model is a polynomial in μ (no IR, no AP). With AP
//! ([`super::ap::Distortion`]) the terms are computed on the internal log grid and interpolated in ln k
//! (the C² cubic B-spline of [`super::ap::spline`]: the exact derivatives in α∥, α⊥ have no jumps).

use super::ap::spline::UniformSpline;
use super::ap::Distortion;
use crate::bias::BiasParams;
use crate::error::{Error, Result};
use crate::estimate::Estimate;
use crate::ir::savitzky_golay_no_wiggle;
use crate::linear::LinearSpectrum;
use crate::loops::redshift::{RedshiftPlan, RedshiftTerms};
use crate::precision::Precision;
use std::f64::consts::PI;
use std::sync::Arc;

/// Gauss–Legendre nodes of the μ integral on [0, 1].
pub const MU_NODES: usize = 24;
/// The BAO scale of Σ² [Mpc/h] (velocileptors' `rbao`): the IR resummation's one ([`crate::ir::BAO_SCALE`]).
pub const R_BAO: f64 = crate::ir::BAO_SCALE;

/// The parameter names, in velocileptors' order (then f).
pub const PARAM_NAMES: [&str; 12] = [
    "b1", "b2", "bs", "b3", "alpha0", "alpha2", "alpha4", "alpha6", "sn", "sn2", "sn4", "f",
];

/// The index of `b1` in [`PARAM_NAMES`] and [`EptParams::values`].
const B1: usize = 0;
/// The index of the growth rate `f` in [`PARAM_NAMES`] and [`EptParams::values`].
const F: usize = 11;

/// The parameters of the model (velocileptors' names and units; module docs).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct EptParams {
    /// The values in the order of [`PARAM_NAMES`].
    pub values: [f64; 12],
}

impl EptParams {
    /// Linear bias `b1`, growth rate `f`, every other parameter 0.
    pub fn new(b1: f64, f: f64) -> Self {
        let mut values = [0.0; 12];
        values[B1] = b1;
        values[F] = f;
        Self { values }
    }

    /// The growth rate f.
    pub fn f(&self) -> f64 {
        self.values[F]
    }

    /// Sets the growth rate f (unchecked: [`Self::validate`] checks it).
    pub fn set_f(&mut self, f: f64) {
        self.values[F] = f;
    }

    /// The value of parameter `name`.
    pub fn get(&self, name: &str) -> Option<f64> {
        PARAM_NAMES
            .iter()
            .position(|&n| n == name)
            .map(|i| self.values[i])
    }

    /// Sets parameter `name`.
    ///
    /// # Errors
    /// [`Error::InvalidChoice`] for a name not in [`PARAM_NAMES`]; [`Error::InvalidParameter`] for a
    /// value that is not finite.
    pub fn set(&mut self, name: &str, value: f64) -> Result<()> {
        let i = checked_param(name, value)?;
        self.values[i] = value;
        Ok(())
    }

    /// The bias b1, b2, bs, b3 ([`crate::bias`]: the model's convention is velocileptors').
    pub fn bias(&self) -> BiasParams {
        let v = &self.values;
        BiasParams {
            b1: v[B1],
            b2: v[B1 + 1],
            bs: v[B1 + 2],
            b3: v[B1 + 3],
        }
    }

    /// Sets the bias b1, b2, bs, b3.
    pub fn set_bias(&mut self, bias: &BiasParams) {
        self.values[B1..B1 + 4].copy_from_slice(&bias.values());
    }

    /// (b1, b2, bs, b3, f) for the loop terms.
    fn monomial_params(&self) -> [f64; 5] {
        let [b1, b2, bs, b3] = self.bias().values();
        [b1, b2, bs, b3, self.f()]
    }

    /// Checks the growth rate is physical (0 ≤ f ≤ 2) and every value finite.
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] naming the parameter.
    pub fn validate(&self) -> Result<()> {
        for (name, &v) in PARAM_NAMES.iter().zip(&self.values) {
            if !v.is_finite() {
                return Err(Error::InvalidParameter {
                    name,
                    value: v,
                    reason: "must be finite",
                });
            }
        }
        let f = self.f();
        let range = crate::cosmology::plausible("f").expect("f has a plausible range");
        if !range.contains(f) {
            return Err(Error::InvalidParameter {
                name: "f",
                value: f,
                reason: range.reason,
            });
        }
        Ok(())
    }
}

/// How the model is evaluated.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct EptSettings {
    /// IR resummation of the BAO (on by default).
    pub ir: bool,
    /// The Alcock–Paczynski distortion, if any.
    pub ap: Option<Distortion>,
    /// The range [lo, hi] of α∥ and α⊥ the plan must serve (fits with free AP parameters): the
    /// internal grid then covers every distortion in it ([`EptPlan::multipole_values_at`]).
    pub ap_range: Option<(f64, f64)>,
    /// The true k [h/Mpc] outside of which the loop terms are taken as 0 (the linear, counterterm
    /// and stochastic terms are kept): for an observation whose far window columns weigh nothing
    /// ([`crate::pipeline::Pipeline`] measures the range it sets and what it changes). `None`:
    /// the loops everywhere.
    pub loop_range: Option<(f64, f64)>,
}

impl Default for EptSettings {
    fn default() -> Self {
        Self {
            ir: true,
            ap: None,
            ap_range: None,
            loop_range: None,
        }
    }
}

/// The plan: the loop plan on the grid the model needs (the output k, or the AP internal grid).
#[derive(Debug, Clone)]
pub struct EptPlan {
    /// Gauss–Legendre rules on [0, 1] ([`MU_NODES`] and half as many): (μ, w, L_0…L_8(μ)).
    rules: [projection::MuRule; 2],
    /// The rule of the values-only paths ([`Self::with_value_nodes`]; the first of `rules` unless
    /// chosen).
    value_rule: projection::MuRule,
    k_out: Vec<f64>,
    grid: Vec<f64>,
    /// Whether `grid` is `k_out` itself or the AP grid the terms are interpolated on: told by how
    /// the plan was built, never by comparing lengths (an output grid may have the AP grid's length).
    grid_use: GridUse,
    /// The prefilter of the interpolant in ln k on `grid` (the cubic B-spline of [`crate::rsd::ap`]),
    /// planned once, shared with the terms.
    spline: Arc<UniformSpline>,
    settings: EptSettings,
    /// The indices of `grid` where the loop terms are computed ([`EptSettings::loop_range`]).
    loop_span: std::ops::Range<usize>,
    loops: RedshiftPlan,
    split: Option<()>,
    /// The basis tensors of the loop terms, if they come from them ([`Self::with_basis`]).
    tensors: Option<basis::Tensors>,
    /// The largest projection residual evaluated on the tensors ([`Self::with_max_residual`]).
    max_residual: f64,
}

/// What the plan's loop grid is to its output k.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum GridUse {
    /// The loop grid is the output grid: term i is at output k i.
    Output,
    /// The loop grid is the internal log grid of the Alcock–Paczynski distortions
    /// ([`Distortion::internal_grid`]): every output k is interpolated in ln k.
    Internal,
}

/// The loop terms of one linear spectrum: everything that does not depend on the parameters.
#[derive(Debug, Clone)]
pub struct EptTerms {
    grid: Vec<f64>,
    /// The plan's prefilter of the interpolant on `grid`.
    spline: Arc<UniformSpline>,
    full: RedshiftTerms,
    /// The no-wiggle terms and Σ² [(Mpc/h)²], with IR resummation.
    nw: Option<(RedshiftTerms, Estimate)>,
    /// The projection residual if the terms come from basis tensors.
    basis_residual: Option<f64>,
    /// Δ [(Mpc/h)²] if the spectrum was projected cut below the soft modes.
    basis_soft: Option<f64>,
    /// The projection residual of a spectrum the plan's tensors did not accept (integrated directly
    /// instead); `None` otherwise.
    fallback_residual: Option<f64>,
}

/// Bytes per internal k of one spectrum's `ept` terms (the redshift-space 1-loop terms of the spectrum
/// and of its no-wiggle part: ~130 estimates of 16 bytes).
const EPT_TERMS_BYTES_PER_K: f64 = 2.1e3;

impl crate::plan::Plan for EptPlan {
    type Settings<'a> = ();
    type Terms = EptTerms;

    fn describe(&self) -> String {
        format!("the ept terms on {} k", self.k_out.len())
    }

    fn method(&self) -> crate::plan::Method {
        match self.tensors {
            Some(_) => crate::plan::Method::Basis,
            None => crate::plan::Method::Direct,
        }
    }

    /// The process, the 1-loop plan on the internal grid and, with tensors, the 1-loop tensors
    /// counted at the 2-loop tensors' measured bytes per k (an upper bound: they hold fewer forms).
    fn bytes(&self) -> f64 {
        let (nk, precision) = (self.grid.len(), self.loops.precision());
        let tensors = match self.tensors {
            Some(_) => crate::loops::basis::TwoLoopBasis::memory_estimate(nk, precision),
            None => 0.0,
        };
        crate::memory::PROCESS + RedshiftPlan::memory_estimate(nk, precision) + tensors
    }

    fn terms_bytes(&self) -> f64 {
        EPT_TERMS_BYTES_PER_K * self.grid.len() as f64
    }

    fn max_memory(&self) -> Option<f64> {
        self.loops.precision().max_memory
    }

    fn terms(
        &self,
        spectrum: &LinearSpectrum,
        (): (),
        _progress: &dyn crate::progress::Progress,
    ) -> Result<EptTerms> {
        EptPlan::terms(self, spectrum)
    }
}

impl EptPlan {
    /// The plan for output wavenumbers `k` [h/Mpc].
    ///
    /// # Errors
    /// As [`RedshiftPlan::new`] and [`Distortion::internal_grid`].
    pub fn new(k: &[f64], settings: EptSettings, precision: &Precision) -> Result<Self> {
        crate::table::check_k_values("k", k)?;
        let grid_use = match (&settings.ap, settings.ap_range) {
            (None, None) => GridUse::Output,
            _ => GridUse::Internal,
        };
        let grid = match (&settings.ap, settings.ap_range) {
            (_, Some((lo, hi))) => {
                // The widest k' of the range: k/hi … k/lo (module `ap`'s grid of α∥ = hi, α⊥ = lo).
                let range = Distortion::new(hi, lo)?;
                if let Some(ap) = &settings.ap {
                    for a in [ap.apar, ap.aperp] {
                        if !(lo..=hi).contains(&a) {
                            return Err(Error::InvalidParameter {
                                name: "apar/aperp",
                                value: a,
                                reason: "must lie inside the plan's AP range",
                            });
                        }
                    }
                }
                range.internal_grid(k)?
            }
            (Some(ap), None) => ap.internal_grid(k)?,
            (None, None) => k.to_vec(),
        };
        let loop_span = range::loop_span(&grid, settings.loop_range)?;
        let loops = RedshiftPlan::new(&grid[loop_span.clone()], precision)?;
        let split = settings.ir.then_some(());
        let rules = [MU_NODES, MU_NODES / 2].map(projection::mu_rule);
        Ok(Self {
            value_rule: rules[0].clone(),
            rules,
            k_out: k.to_vec(),
            spline: Arc::new(UniformSpline::new(grid.len())),
            grid,
            grid_use,
            settings,
            loop_span,
            loops,
            split,
            tensors: None,
            max_residual: crate::loops::basis::MAX_RESIDUAL,
        })
    }

    /// The output wavenumbers [h/Mpc].
    pub fn k(&self) -> &[f64] {
        &self.k_out
    }

    /// The settings.
    pub fn settings(&self) -> EptSettings {
        self.settings
    }

    /// The loop terms of `spectrum` (and of its no-wiggle part with IR resummation).
    ///
    /// # Errors
    /// As [`savitzky_golay_no_wiggle`].
    pub fn terms(&self, spectrum: &LinearSpectrum) -> Result<EptTerms> {
        self.terms_with(spectrum, true)
    }

    /// [`Self::terms`] without error estimates on the basis path (every error NaN: not estimated),
    /// for a caller that reads the values only, as the chain step ([`crate::pipeline`]) does: the
    /// tensors of the quadrature differences, the error forms and the thinning's error
    /// interpolation are not applied (the same values to the bit). A spectrum outside the basis's
    /// span takes the direct integrals, with their errors, as [`Self::terms`].
    ///
    /// # Errors
    /// As [`Self::terms`].
    pub fn term_values(&self, spectrum: &LinearSpectrum) -> Result<EptTerms> {
        self.terms_with(spectrum, false)
    }

    fn terms_with(&self, spectrum: &LinearSpectrum, errors: bool) -> Result<EptTerms> {
        let fallback_residual = match self.terms_on_basis(spectrum, errors)? {
            Ok(terms) => return Ok(terms),
            Err(refused) => refused,
        };
        let at_grid =
            |p: &LinearSpectrum| -> Vec<f64> { self.grid.iter().map(|&k| p.eval(k)).collect() };
        let p_lin = at_grid(spectrum);
        let (full, nw) = match &self.split {
            Some(()) => {
                let p_nw = savitzky_golay_no_wiggle(spectrum)?;
                let (full, t) = self.loops.evaluate_with_no_wiggle(spectrum, &p_nw);
                let t = self.padded(t, &at_grid(&p_nw));
                (full, Some((t, sigma2(&p_nw))))
            }
            None => (self.loops.evaluate(spectrum), None),
        };
        let full = self.padded(full, &p_lin);
        Ok(EptTerms {
            grid: self.grid.clone(),
            spline: self.spline.clone(),
            full,
            nw,
            basis_residual: None,
            basis_soft: None,
            fallback_residual,
        })
    }

    /// The multipoles `ells` (even, ≤ 8) at the output k: `out[j][i]` for the j-th ℓ at the i-th k.
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] for an odd or too large ℓ or invalid parameters; as
    /// [`Self::terms`].
    pub fn multipoles(
        &self,
        terms: &EptTerms,
        params: &EptParams,
        ells: &[usize],
    ) -> Result<Vec<Vec<Estimate>>> {
        self.multipoles_at(terms, params, ells, self.settings.ap)
    }

    /// [`Self::multipoles`] with the distortion `ap` instead of the plan's (as
    /// [`Self::multipole_values_at`]).
    ///
    /// # Errors
    /// As [`Self::multipole_values_at`].
    pub fn multipoles_at(
        &self,
        terms: &EptTerms,
        params: &EptParams,
        ells: &[usize],
        ap: Option<Distortion>,
    ) -> Result<Vec<Vec<Estimate>>> {
        self.check_projection(terms, std::slice::from_ref(params), ells, ap)?;
        let model = terms.model(params);
        let volume = ap.map_or(1.0, |d| d.volume());
        let mut out = vec![Vec::with_capacity(self.k_out.len()); ells.len()];
        for (i, &k) in self.k_out.iter().enumerate() {
            let mut sums = [vec![0.0; ells.len()], vec![0.0; ells.len()]];
            let mut spread = vec![0.0; ells.len()];
            for (r, nodes) in self.rules.iter().enumerate() {
                for (mu, w, legendre) in nodes {
                    let (mu, w) = (*mu, *w);
                    let p = match &ap {
                        None if self.grid_use == GridUse::Output => model.at(i, k, mu),
                        None => model.interpolated(k, mu)?,
                        Some(ap) => {
                            let (kt, mt) = ap.true_coordinates(k, mu);
                            model.interpolated(kt, mt)?
                        }
                    };
                    for (j, &l) in ells.iter().enumerate() {
                        let c = w * (2 * l + 1) as f64 * legendre[l] * volume;
                        sums[r][j] += c * p.value;
                        if r == 0 {
                            spread[j] += c.abs() * p.error;
                        }
                    }
                }
            }
            for j in 0..ells.len() {
                let quadrature = (sums[0][j] - sums[1][j]).abs();
                out[j].push(Estimate::new(sums[0][j], spread[j] + quadrature));
            }
        }
        Ok(out)
    }

    /// The values only of [`Self::multipoles`] (the [`MU_NODES`] rule, no error estimate): the
    /// fast path of fits and chains, `out[j][i]` for the j-th ℓ at the i-th k.
    ///
    /// # Errors
    /// As [`Self::multipoles`].
    pub fn multipole_values(
        &self,
        terms: &EptTerms,
        params: &EptParams,
        ells: &[usize],
    ) -> Result<Vec<Vec<f64>>> {
        self.multipole_values_at(terms, params, ells, self.settings.ap)
    }

    /// [`Self::multipole_values`] with the distortion `ap` instead of the plan's (a plan with an
    /// [`EptSettings::ap_range`] containing it, or `ap` = the plan's own).
    ///
    /// # Errors
    /// As [`Self::multipoles`]; [`Error::InvalidChoice`] for a distortion on a plan without AP grid,
    /// [`Error::OutOfRange`] for one outside the plan's range.
    pub fn multipole_values_at(
        &self,
        terms: &EptTerms,
        params: &EptParams,
        ells: &[usize],
        ap: Option<Distortion>,
    ) -> Result<Vec<Vec<f64>>> {
        let (weights, nodes) =
            self.projection_nodes(terms, std::slice::from_ref(params), ells, ap)?;
        let model = terms.model_values(params);
        let mut out = vec![vec![0.0; self.k_out.len()]; ells.len()];
        if ap.is_none() && self.grid_use == GridUse::Output {
            for (i, &k) in self.k_out.iter().enumerate() {
                for ((mu, _, _), c) in self.value_rule.iter().zip(&weights) {
                    let p = model.value_at(i, k, *mu);
                    for (o, c) in out.iter_mut().zip(c) {
                        o[i] += c * p;
                    }
                }
            }
            return Ok(out);
        }
        // node by node in μ: the BAO damping of all k of a node in one vectorised pass
        let ln_k: Vec<f64> = self.k_out.iter().map(|k| k.ln()).collect();
        let mut damping = vec![0.0; self.k_out.len()];
        for (c, &(ln_ratio, ratio2, mt)) in weights.iter().zip(&nodes) {
            let exponent = ratio2 * model.damping_exponent(mt);
            for (d, k) in damping.iter_mut().zip(&self.k_out) {
                *d = k * k * exponent;
            }
            crate::simd::exp_in_place(&mut damping);
            for (i, (&ln_k, damping)) in ln_k.iter().zip(&damping).enumerate() {
                let (n, w) = model.interpolated_parts_ln(ln_k + ln_ratio, mt)?;
                let p = n + damping * w;
                for (o, c) in out.iter_mut().zip(c) {
                    o[i] += c * p;
                }
            }
        }
        Ok(out)
    }
}

impl EptPlan {
    /// A distortion needs a plan built with one (its AP grid) or with an AP range.
    fn check_ap(&self, ap: Option<Distortion>) -> Result<()> {
        if ap.is_some() && self.settings.ap.is_none() && self.settings.ap_range.is_none() {
            return Err(Error::InvalidChoice {
                what: "an Alcock-Paczynski distortion".into(),
                reason: "the plan was built without AP (give EptSettings::ap or ap_range)".into(),
            });
        }
        Ok(())
    }

    /// Terms must be on this plan's loop grid (compared by value: another plan's terms on a grid of
    /// the same length would be read at the wrong k).
    fn check_terms(&self, terms: &EptTerms) -> Result<()> {
        if terms.grid != self.grid {
            return Err(Error::GridMismatch {
                what: "ept terms and plan",
                expected: crate::table::describe_grid(&self.grid),
                found: crate::table::describe_grid(&terms.grid),
            });
        }
        Ok(())
    }
}

/// Σ² = (1/6π²)∫dq P_nw(q)[1 − j₀(q r_BAO)] over [1e-5, 1e3] h/Mpc: Simpson in ln q, error against
/// the half rule.
pub fn sigma2(no_wiggle: &LinearSpectrum) -> Estimate {
    let integrand = |ln_q: f64| {
        let q = ln_q.exp();
        sigma2_kernel(q) * no_wiggle.eval(q)
    };
    let (value, error) =
        crate::integrate::simpson_ln(integrand, (1e-5_f64).ln(), (1e3_f64).ln(), 2048);
    Estimate::new(value, error)
}

/// The weight of P_nw(q) in Σ² per unit ln q: q [1 − j₀(q r_BAO)] / (6π²).
fn sigma2_kernel(q: f64) -> f64 {
    let x = q * R_BAO;
    let one_minus_j0 = if x < 1e-3 {
        x * x / 6.0
    } else {
        1.0 - x.sin() / x
    };
    q * one_minus_j0 / (6.0 * PI * PI)
}

mod basis;
mod model;
pub mod physical;
mod projection;
mod range;
pub mod tangent;

/// The index of parameter `name` in [`PARAM_NAMES`], its `value` checked finite.
///
/// # Errors
/// [`Error::InvalidChoice`] for a name not in [`PARAM_NAMES`] (listing them);
/// [`Error::InvalidParameter`] for a value that is not finite.
pub fn checked_param(name: &str, value: f64) -> Result<usize> {
    let i = PARAM_NAMES
        .iter()
        .position(|&n| n == name)
        .ok_or_else(|| Error::InvalidChoice {
            what: format!("ept parameter `{name}`"),
            reason: format!("the parameters are {}", PARAM_NAMES.join(", ")),
        })?;
    if !value.is_finite() {
        return Err(Error::InvalidParameter {
            name: PARAM_NAMES[i],
            value,
            reason: "must be finite",
        });
    }
    Ok(i)
}

#[cfg(test)]
mod tests;
