//! Fits of the galaxy model `ept` ([`crate::rsd::ept`]) to measured multipoles: any parameter free,
//! Gaussian priors, and analytic marginalisation of the parameters that enter linearly (counterterms
//! α_n and stochastic terms sn, sn2, sn4), as CLASS-PT, PyBird and desilike do.
//!
//! With the data vector d (ℓ-major over the fitted multipoles, k_min ≤ k ≤ k_max), its covariance C,
//! the model m(θ, a) = m₀(θ) + Σᵢ aᵢ Tᵢ(θ) linear in the marginalised a (Tᵢ = ∂m/∂aᵢ, exact: the model is
//! linear in them) and Gaussian priors a ~ N(μ, S) (S diagonal; a parameter without a prior has a flat
//! one, S⁻¹ = 0), the marginal likelihood is, up to a constant,
//!   −2 ln L(θ) = χ²(θ, â) + (â − μ)ᵀS⁻¹(â − μ) + ln det F,   F = TᵀC⁻¹T + S⁻¹,
//!   â = F⁻¹[TᵀC⁻¹(d − m₀) + S⁻¹μ],
//! plus the Gaussian priors of the free θ. The best fit minimises it over θ (Nelder–Mead, restarted
//! once from its own best point); â at the best θ is the best fit of the marginalised parameters and
//! √(F⁻¹)ᵢᵢ their errors (at fixed θ). The errors of the free θ are Gaussian: the square roots of the
//! diagonal of the inverse Hessian of −½ × (−2 ln L), by central differences — stated as such in the
//! output. χ² alone (without the ln det F and prior terms) is also reported.
//!
//! With `n_mocks`, C⁻¹ carries the Hartlap factor (N − p − 2)/(N − 1) of a covariance estimated
//! from N mocks (p = fitted points).
//!
//! With a distortion (`ap`), α∥ and α⊥ (`apar`, `aperp`) can be free too, on a plan built for an AP
//! range ([`crate::rsd::ept::EptSettings::ap_range`]).

use super::MultipoleData;
use crate::error::{Error, Result};
use crate::linalg::{cholesky, dot, invert_lower, solve_spd};
use crate::rsd::ept::{EptParams, EptPlan, EptTerms, PARAM_NAMES};
use crate::survey::observe::Observation;
use crate::table::{describe_grid, same_k};
use argmin::core::{CostFunction, Executor, State};
use argmin::solver::neldermead::NelderMead;

/// The parameters that enter the model linearly and can be marginalised analytically.
pub const LINEAR: [&str; 7] = ["alpha0", "alpha2", "alpha4", "alpha6", "sn", "sn2", "sn4"];

/// The Alcock–Paczynski parameters a fit can free (with a plan built for an AP range), after the
/// model's [`PARAM_NAMES`].
pub const AP_NAMES: [&str; 2] = ["apar", "aperp"];

/// Slots of the fitted vector: the model's parameters, then α∥, α⊥.
const SLOTS: usize = PARAM_NAMES.len() + AP_NAMES.len();

/// A Gaussian prior on a parameter.
#[derive(Debug, Clone, PartialEq)]
pub struct Prior {
    /// The parameter's name (one of [`PARAM_NAMES`]).
    pub name: String,
    /// Its mean.
    pub mean: f64,
    /// Its standard deviation (> 0).
    pub sigma: f64,
}

/// What to fit.
#[derive(Debug, Clone, PartialEq)]
pub struct GalaxyFitRequest {
    /// Start values of the free parameters and values of the fixed ones.
    pub start: EptParams,
    /// The distortion of the measurement (start values if apar, aperp are free), if any.
    pub ap: Option<crate::rsd::ap::Distortion>,
    /// The free parameters (minimised).
    pub free: Vec<String>,
    /// The linear parameters marginalised analytically (a subset of [`LINEAR`]).
    pub marginalise: Vec<String>,
    /// Gaussian priors.
    pub priors: Vec<Prior>,
    /// The fitted multipoles (a subset of the data's).
    pub ells: Vec<usize>,
    /// The fitted range [h/Mpc].
    pub k_min: f64,
    /// The fitted range [h/Mpc].
    pub k_max: f64,
    /// Per-multipole ranges (ℓ, k_min, k_max) [h/Mpc] that narrow [k_min, k_max] for that ℓ: the
    /// points of ℓ are those in [max(k_min, k_min_ℓ), min(k_max, k_max_ℓ)] (e.g. P4 to 0.1 h/Mpc while
    /// P0 and P2 go to k_max). For ξ_ℓ data the ranges are in s [Mpc/h].
    pub ell_ranges: Vec<(usize, f64, f64)>,
    /// The number of mocks the covariance was estimated from: C⁻¹ is scaled by the Hartlap factor
    /// (N − p − 2)/(N − 1), p the number of fitted points (Hartlap, Simon & Schneider 2007).
    pub n_mocks: Option<usize>,
}

/// The result of a fit.
#[derive(Debug, Clone, PartialEq)]
pub struct GalaxyFit {
    /// Every parameter at the best fit (the marginalised ones at â).
    pub best: EptParams,
    /// The distortion at the best fit.
    pub ap: Option<crate::rsd::ap::Distortion>,
    /// The free parameters' Gaussian errors, in the order of the request.
    pub errors: Vec<f64>,
    /// The marginalised parameters' errors √(F⁻¹)ᵢᵢ at the best θ, in the order of the request.
    pub marginalised_errors: Vec<f64>,
    /// χ² of the best fit (data only).
    pub chi2: f64,
    /// −2 ln L of the best fit (χ² + the priors + ln det F).
    pub minus_two_log_l: f64,
    /// Data points fitted.
    pub points: usize,
}

fn index(name: &str) -> Result<usize> {
    PARAM_NAMES
        .iter()
        .chain(&AP_NAMES)
        .position(|&n| n == name)
        .ok_or_else(|| Error::InvalidChoice {
            what: format!("fit parameter `{name}`"),
            reason: format!(
                "the ept parameters are {} (and apar, aperp)",
                PARAM_NAMES.join(", ")
            ),
        })
}

/// The objective of one request on one data window.
struct Objective<'a> {
    plan: &'a EptPlan,
    terms: &'a EptTerms,
    /// The window and bins between the model and the data, if any.
    observation: Option<&'a Observation>,
    /// Every slot's start or fixed value (the model's parameters, α∥, α⊥).
    start: [f64; SLOTS],
    /// Whether the measurement has a distortion.
    has_ap: bool,
    ells: Vec<usize>,
    free: Vec<usize>,
    marg: Vec<usize>,
    /// Per parameter: (mean, 1/σ²) of its prior, if any.
    priors: Vec<Option<(f64, f64)>>,
    /// Per fitted ℓ (in the order of `ells`), the k indices of its fitted points.
    window: Vec<Vec<usize>>,
    /// L⁻¹ of the Cholesky factor of the window's covariance.
    whiten: Vec<Vec<f64>>,
    /// L⁻¹ d.
    data: Vec<f64>,
}

impl Objective<'_> {
    fn slots(&self, x: &[f64]) -> [f64; SLOTS] {
        let mut v = self.start;
        for (&i, &value) in self.free.iter().zip(x) {
            v[i] = value;
        }
        v
    }

    fn split(&self, v: &[f64; SLOTS]) -> Result<(EptParams, Option<crate::rsd::ap::Distortion>)> {
        let n = PARAM_NAMES.len();
        let mut p = EptParams::new(0.0, 0.0);
        p.values.copy_from_slice(&v[..n]);
        let ap = if self.has_ap {
            Some(crate::rsd::ap::Distortion::new(v[n], v[n + 1])?)
        } else {
            None
        };
        Ok((p, ap))
    }

    /// The whitened model at `p` with distortion `ap` (L⁻¹ m).
    fn model(&self, p: &EptParams, ap: Option<crate::rsd::ap::Distortion>) -> Result<Vec<f64>> {
        let m = match self.observation {
            None => self
                .plan
                .multipole_values_at(self.terms, p, &self.ells, ap)?,
            Some(o) => {
                let model = self
                    .plan
                    .multipole_values_at(self.terms, p, o.model_ells(), ap)?;
                o.apply_values(&model)?
            }
        };
        let raw: Vec<f64> = m
            .iter()
            .zip(&self.window)
            .flat_map(|(l, window)| window.iter().map(move |&i| l[i]))
            .collect();
        Ok(self
            .whiten
            .iter()
            .map(|row| row.iter().zip(&raw).map(|(a, b)| a * b).sum())
            .collect())
    }

    /// (−2 ln L, χ², the slots with â, the errors of â) at the free values `x`.
    fn evaluate(&self, x: &[f64]) -> Result<(f64, f64, [f64; SLOTS], Vec<f64>)> {
        let mut v = self.slots(x);
        let (mut p, ap) = self.split(&v)?;
        for &i in &self.marg {
            p.values[i] = 0.0;
        }
        let m0 = self.model(&p, ap)?;
        let templates: Vec<Vec<f64>> = self
            .marg
            .iter()
            .map(|&i| {
                let mut q = p;
                q.values[i] = 1.0;
                self.model(&q, ap)
                    .map(|m| m.iter().zip(&m0).map(|(a, b)| a - b).collect())
            })
            .collect::<Result<_>>()?;
        let r0: Vec<f64> = self.data.iter().zip(&m0).map(|(d, m)| d - m).collect();
        let n = self.marg.len();
        let mut f = vec![vec![0.0; n]; n];
        let mut b = vec![0.0; n];
        for a in 0..n {
            let (mean, precision) = self.priors[self.marg[a]].unwrap_or((0.0, 0.0));
            b[a] = dot(&templates[a], &r0) + precision * mean;
            for c in 0..n {
                f[a][c] = dot(&templates[a], &templates[c]);
            }
            f[a][a] += precision;
        }
        let (ahat, inverse, log_det) = solve_spd(&f, &b)?;
        let mut chi2 = 0.0;
        for (j, r) in r0.iter().enumerate() {
            let fit: f64 = (0..n).map(|a| ahat[a] * templates[a][j]).sum();
            chi2 += (r - fit).powi(2);
        }
        let mut total = chi2 + log_det;
        for (a, &i) in self.marg.iter().enumerate() {
            v[i] = ahat[a];
            if let Some((mean, precision)) = self.priors[i] {
                total += precision * (ahat[a] - mean).powi(2);
            }
        }
        for &i in &self.free {
            if let Some((mean, precision)) = self.priors[i] {
                total += precision * (v[i] - mean).powi(2);
            }
        }
        let errors = (0..n).map(|a| inverse[a][a].sqrt()).collect();
        Ok((total, chi2, v, errors))
    }
}

impl CostFunction for &Objective<'_> {
    type Param = Vec<f64>;
    type Output = f64;

    fn cost(&self, x: &Vec<f64>) -> std::result::Result<f64, argmin::core::Error> {
        // Outside the model's domain (e.g. f < 0) the cost is infinite.
        Ok(self.evaluate(x).map_or(f64::INFINITY, |e| e.0))
    }
}

/// The free and marginalised parameter indices, and per parameter its prior (mean, 1/σ²).
type Validated = (Vec<usize>, Vec<usize>, Vec<Option<(f64, f64)>>);

/// Checks the request's names and values.
fn validate(request: &GalaxyFitRequest) -> Result<Validated> {
    let free = request
        .free
        .iter()
        .map(|n| index(n))
        .collect::<Result<Vec<_>>>()?;
    let mut marg = Vec::new();
    for name in &request.marginalise {
        if !LINEAR.contains(&name.as_str()) {
            return Err(Error::InvalidChoice {
                what: format!("--marginalise {name}"),
                reason: format!(
                    "only parameters that enter linearly can be marginalised: {}",
                    LINEAR.join(", ")
                ),
            });
        }
        marg.push(index(name)?);
    }
    let mut seen = std::collections::HashSet::new();
    for name in request.free.iter().chain(&request.marginalise) {
        if !seen.insert(name.as_str()) {
            return Err(Error::InvalidChoice {
                what: format!("fit parameter `{name}`"),
                reason: "is listed twice (free and marginalised are exclusive)".into(),
            });
        }
    }
    if free.is_empty() {
        return Err(Error::InvalidChoice {
            what: "--free".into(),
            reason: "name at least one free parameter".into(),
        });
    }
    for &(l, lo, hi) in &request.ell_ranges {
        if !request.ells.contains(&l) {
            return Err(Error::InvalidChoice {
                what: format!("the k range of multipole {l}"),
                reason: format!("{l} is not a fitted multipole ({:?})", request.ells),
            });
        }
        if !(lo.is_finite() && hi.is_finite() && lo < hi) {
            return Err(Error::InvalidParameter {
                name: "per-multipole k_max [h/Mpc]",
                value: hi,
                reason: "a multipole's range needs finite k_min < k_max",
            });
        }
    }
    let mut priors = vec![None; SLOTS];
    for p in &request.priors {
        let i = index(&p.name)?;
        if !(p.sigma > 0.0 && p.sigma.is_finite()) {
            return Err(Error::InvalidParameter {
                name: "prior sigma",
                value: p.sigma,
                reason: "a Gaussian prior needs 0 < sigma < infinity",
            });
        }
        if !p.mean.is_finite() {
            return Err(Error::InvalidParameter {
                name: "prior mean",
                value: p.mean,
                reason: "must be finite",
            });
        }
        if !free.contains(&i) && !marg.contains(&i) {
            return Err(Error::InvalidChoice {
                what: format!("the prior on {}", p.name),
                reason: format!(
                    "{} is fixed, and a prior acts only on a free or marginalised parameter \
                     (free: {}; marginalised: {})",
                    p.name,
                    request.free.join(", "),
                    if request.marginalise.is_empty() {
                        "none".to_string()
                    } else {
                        request.marginalise.join(", ")
                    }
                ),
            });
        }
        if priors[i].is_some() {
            return Err(Error::InvalidChoice {
                what: format!("the prior on {}", p.name),
                reason: "is given twice".into(),
            });
        }
        priors[i] = Some((p.mean, 1.0 / (p.sigma * p.sigma)));
    }
    Ok((free, marg, priors))
}

/// The best fit of `request` to `data`, whose k must be the plan's output k.
///
/// # Errors
/// [`Error::InvalidChoice`] for unknown, repeated or non-linear marginalised names;
/// [`Error::InvalidParameter`] for a prior with σ ≤ 0, a window with too few points, a covariance that
/// is not positive definite, degenerate marginalised templates; [`Error::GridMismatch`] if the data's
/// k are not the plan's.
pub fn fit_galaxy(
    plan: &EptPlan,
    terms: &EptTerms,
    data: &MultipoleData,
    request: &GalaxyFitRequest,
) -> Result<GalaxyFit> {
    fit_galaxy_observed(plan, terms, data, request, None)
}

/// [`fit_galaxy`] with the model taken through a window and bins (`observation`, made for the
/// request's multipoles; the plan on its model k, the data on its output k, row for row).
///
/// # Errors
/// As [`fit_galaxy`]; [`Error::InvalidChoice`] if the observation's output does not match the data.
pub fn fit_galaxy_observed(
    plan: &EptPlan,
    terms: &EptTerms,
    data: &MultipoleData,
    request: &GalaxyFitRequest,
    observation: Option<&Observation>,
) -> Result<GalaxyFit> {
    let (free, marg, priors) = validate(request)?;
    if request.ap.is_none() && free.iter().any(|&i| i >= PARAM_NAMES.len()) {
        return Err(Error::InvalidChoice {
            what: "free apar/aperp".into(),
            reason: "the fit needs a distortion to start from (the measurement's AP)".into(),
        });
    }
    let k = match observation {
        None => plan.k(),
        Some(o) => {
            if plan.k() != o.k_model() || !same_k(o.k_out(), &data.k) || o.ells() != request.ells {
                return Err(Error::InvalidChoice {
                    what: "the fit's window and bins".into(),
                    reason: format!(
                        "the plan must be on their model k and their output ({}, l {:?}) on the \
                         data's ({}, l {:?})",
                        describe_grid(o.k_out()),
                        o.ells(),
                        describe_grid(&data.k),
                        request.ells
                    ),
                });
            }
            data.k.as_slice()
        }
    };
    if observation.is_none() && !same_k(k, &data.k) {
        return Err(Error::InvalidChoice {
            what: "the fit's model grid".into(),
            reason: "the plan must be built on the data's k".into(),
        });
    }
    let mut rows = Vec::new();
    for &l in &request.ells {
        let j = data
            .ells
            .iter()
            .position(|&d| d == l)
            .ok_or(Error::InvalidParameter {
                name: "fitted multipole ell",
                value: l as f64,
                reason: "is not in the data",
            })?;
        rows.push(j);
    }
    let mut window = Vec::with_capacity(rows.len());
    for &l in &request.ells {
        let (mut lo, mut hi) = (request.k_min, request.k_max);
        for &(_, a, b) in request.ell_ranges.iter().filter(|r| r.0 == l) {
            lo = lo.max(a);
            hi = hi.min(b);
        }
        window.push(
            (0..k.len())
                .filter(|&i| (lo..=hi).contains(&k[i]))
                .collect::<Vec<usize>>(),
        );
    }
    let points: usize = window.iter().map(Vec::len).sum();
    if points <= free.len() + marg.len() {
        return Err(Error::InvalidParameter {
            name: "k_max [h/Mpc]",
            value: request.k_max,
            reason: "the fitted window holds no more points than parameters",
        });
    }
    // The window's covariance: the data's full covariance (ℓ-major over the data's ells), or σ².
    let position = |r: usize, i: usize| r * k.len() + i;
    // The fitted points (data row, k index), ℓ-major.
    let fitted: Vec<(usize, usize)> = rows
        .iter()
        .zip(&window)
        .flat_map(|(&r, w)| w.iter().map(move |&i| (r, i)))
        .collect();
    let cov: Vec<Vec<f64>> = fitted
        .iter()
        .map(|&(r, i)| {
            fitted
                .iter()
                .map(|&(s, j)| match &data.covariance {
                    Some(c) => c[position(r, i)][position(s, j)],
                    None if (r, i) == (s, j) => data.sigma[r][i].powi(2),
                    None => 0.0,
                })
                .collect()
        })
        .collect();
    let mut cov = cov;
    if let Some(n) = request.n_mocks {
        if n < points + 3 {
            return Err(Error::InvalidParameter {
                name: "number of mocks",
                value: n as f64,
                reason: "the Hartlap factor needs more mocks than fitted points + 2",
            });
        }
        // C⁻¹ → h C⁻¹ is C → C/h.
        let h = (n - points - 2) as f64 / (n - 1) as f64;
        for row in cov.iter_mut() {
            for v in row.iter_mut() {
                *v /= h;
            }
        }
    }
    let l = cholesky(&cov).ok_or_else(|| Error::InvalidChoice {
        what: format!("the covariance of the {points} fitted points"),
        reason: "is not positive definite".into(),
    })?;
    let whiten = invert_lower(&l);
    let raw: Vec<f64> = fitted.iter().map(|&(r, i)| data.values[r][i]).collect();
    let data_vector = whiten.iter().map(|row| dot(row, &raw)).collect();
    let mut start = [0.0; SLOTS];
    start[..PARAM_NAMES.len()].copy_from_slice(&request.start.values);
    if let Some(d) = request.ap {
        start[PARAM_NAMES.len()] = d.apar;
        start[PARAM_NAMES.len() + 1] = d.aperp;
    }
    let objective = Objective {
        plan,
        terms,
        observation,
        start,
        has_ap: request.ap.is_some(),
        ells: request.ells.clone(),
        free: free.clone(),
        marg: marg.clone(),
        priors,
        window,
        whiten,
        data: data_vector,
    };
    let x0: Vec<f64> = free.iter().map(|&i| start[i]).collect();
    objective.evaluate(&x0)?;
    let mut best = x0;
    for _ in 0..2 {
        best = minimise(&objective, &best);
    }
    let (minus_two_log_l, chi2, slots, marginalised_errors) = objective.evaluate(&best)?;
    let (params, ap) = objective.split(&slots)?;
    let errors = hessian_errors(&objective, &best, minus_two_log_l);
    Ok(GalaxyFit {
        best: params,
        ap,
        errors,
        marginalised_errors,
        chi2,
        minus_two_log_l,
        points,
    })
}

/// Nelder–Mead from `x0` with a simplex of scale-aware steps.
fn minimise(objective: &Objective<'_>, x0: &[f64]) -> Vec<f64> {
    let mut simplex = vec![x0.to_vec()];
    for i in 0..x0.len() {
        let mut x = x0.to_vec();
        x[i] += 0.05 * x[i].abs().max(1.0);
        simplex.push(x);
    }
    let solver = NelderMead::new(simplex)
        .with_sd_tolerance(1e-8)
        .expect("valid tolerance");
    match Executor::new(objective, solver)
        .configure(|s| s.max_iters(3000))
        .run()
    {
        Ok(r) => r
            .state()
            .get_best_param()
            .cloned()
            .unwrap_or_else(|| x0.to_vec()),
        Err(_) => x0.to_vec(),
    }
}

/// Gaussian errors of the free parameters: √diag of 2 H⁻¹, H the Hessian of −2 ln L by central
/// differences (steps 1e-3 of max(|value|, 1)); NaN where H is not positive definite.
fn hessian_errors(objective: &Objective<'_>, x: &[f64], f0: f64) -> Vec<f64> {
    let n = x.len();
    // Steps of 1e-3 of the value, at least 1e-3: a parameter near 0 (bs, b3) would otherwise get a
    // step at the level of the minimiser's tolerance, and a Hessian of noise.
    let h: Vec<f64> = x.iter().map(|v| 1e-3 * v.abs().max(1.0)).collect();
    let f = |dx: &[(usize, f64)]| {
        let mut y = x.to_vec();
        for &(i, d) in dx {
            y[i] += d;
        }
        objective.evaluate(&y).map_or(f64::NAN, |e| e.0)
    };
    let mut hess = vec![vec![0.0; n]; n];
    for i in 0..n {
        hess[i][i] = (f(&[(i, h[i])]) - 2.0 * f0 + f(&[(i, -h[i])])) / (h[i] * h[i]);
        for j in 0..i {
            let v = (f(&[(i, h[i]), (j, h[j])])
                - f(&[(i, h[i]), (j, -h[j])])
                - f(&[(i, -h[i]), (j, h[j])])
                + f(&[(i, -h[i]), (j, -h[j])]))
                / (4.0 * h[i] * h[j]);
            hess[i][j] = v;
            hess[j][i] = v;
        }
    }
    match solve_spd(&hess, &vec![0.0; n]) {
        Ok((_, inverse, _)) => (0..n).map(|i| (2.0 * inverse[i][i]).sqrt()).collect(),
        Err(_) => vec![f64::NAN; n],
    }
}

#[cfg(test)]
mod tests;
