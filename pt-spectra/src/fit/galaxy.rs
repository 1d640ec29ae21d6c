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
//! plus the priors of the free θ (Gaussian, flat or log-normal: [`PriorShape`]). With
//! [`Linear::Profiled`] the linear parameters are profiled instead (maximised: no ln det F term).
//! The best fit minimises it over θ within bounds ([`search`]: a projected quasi-Newton method with
//! several starts drawn from the priors and the start box, [`crate::fit::bounded`]); â at the best θ is
//! the best fit of the marginalised parameters and √(F⁻¹)ᵢᵢ their errors (at fixed θ). The errors of
//! the free θ: the Gaussian ones, √diag(2H⁻¹) with H the Hessian of −2 ln L by central differences of
//! half a σ, checked by the likelihood itself: the profile of each parameter (the others
//! re-minimised) where Δ(−2 ln L) = 1 on either side ([`GalaxyFit::intervals`]); where the profile's
//! half-width and the Hessian's σ differ by more than 10% the error given is the profile's
//! ([`GalaxyFit::from_profile`]). χ² alone (without the ln det F and prior terms) is also reported.
//!
//! With `n_mocks`, C⁻¹ carries the Hartlap factor (N − p − 2)/(N − 1) of a covariance estimated
//! from N mocks (p = fitted points).
//!
//! With a distortion (`ap`), α∥ and α⊥ (`apar`, `aperp`) can be free too, on a plan built for an AP
//! range ([`crate::rsd::ept::EptSettings::ap_range`]).

use super::MultipoleData;
use crate::error::{Error, Result};
use crate::rsd::ept::{EptParams, EptPlan, EptTerms, PARAM_NAMES};
use crate::survey::observe::Observation;

mod basis;
mod block;
mod derived;
mod gradient;
pub mod joint;
mod objective;
mod priors;
mod request;
pub mod search;
pub use basis::{FitBasis, CLASSPT_NAMES};
pub use block::{BlockFit, OwnValues};
pub use derived::{derived, sound_horizon, Derived, Template};
pub use joint::{default_shared, fit_joint, DataSet, JointFit, JointLikelihood};
pub use priors::{desi_priors, Prior, PriorShape};
pub use search::{profile_galaxy, GalaxyProfile, Linear, ProfileGrid, ProfilePoint, Search};

/// The parameters that enter the model linearly and can be marginalised analytically.
pub const LINEAR: [&str; 7] = ["alpha0", "alpha2", "alpha4", "alpha6", "sn", "sn2", "sn4"];

/// The Alcock–Paczynski parameters a fit can free (with a plan built for an AP range), after the
/// model's [`PARAM_NAMES`].
pub const AP_NAMES: [&str; 2] = ["apar", "aperp"];

/// The slot of α∥ (α⊥ the next).
const AP_SLOT: usize = PARAM_NAMES.len();

/// The first slot of a block's own parameters ([`crate::statistic::Kind::own`]): the fitted
/// vector's slots are the model's parameters, then α∥, α⊥, then those of the data set's block.
const OWN_SLOT: usize = AP_SLOT + AP_NAMES.len();

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
    /// Priors (at most one per parameter; Gaussian only on marginalised ones).
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
    /// The parameter basis of `free`, `marginalise` and `priors` ([`FitBasis`]: velocileptors' (the
    /// model's), CLASS-PT's bias, or the DESI physical basis; the start is still given as the
    /// model's parameters and converted).
    pub basis: FitBasis,
}

/// The result of a fit.
#[derive(Debug, Clone, PartialEq)]
pub struct GalaxyFit {
    /// Every parameter at the best fit (the marginalised ones at â).
    pub best: EptParams,
    /// The distortion at the best fit.
    pub ap: Option<crate::rsd::ap::Distortion>,
    /// The free parameters' errors, in the order of the request: the Hessian's, or the profile's
    /// half-width where they differ by more than [`search::PROFILE_AGREEMENT`] ([`Self::from_profile`]).
    pub errors: Vec<f64>,
    /// The free parameters' Gaussian errors √diag(2H⁻¹) (NaN where H is not positive definite).
    pub hessian_errors: Vec<f64>,
    /// The covariance 2H⁻¹ of the free parameters (`None` where H is not positive definite).
    pub covariance: Option<Vec<Vec<f64>>>,
    /// The free parameters' 1σ intervals (lower, upper) where the profile −2 ln L (the others
    /// re-minimised) is 1 above the minimum; NaN on a side where it is not reached inside the bounds
    /// (or without the profile check).
    pub intervals: Vec<(f64, f64)>,
    /// Per free parameter: whether [`Self::errors`] is the profile's half-width (the Hessian's σ
    /// differs from it by more than 10%, or is undefined).
    pub from_profile: Vec<bool>,
    /// The marginalised parameters' errors √(F⁻¹)ᵢᵢ at the best θ, in the order of the request.
    pub marginalised_errors: Vec<f64>,
    /// χ² of the best fit (data only).
    pub chi2: f64,
    /// −2 ln L of the best fit (χ² + the priors + ln det F).
    pub minus_two_log_l: f64,
    /// Data points fitted.
    pub points: usize,
    /// Starts minimised.
    pub starts: usize,
    /// Starts whose minimum is within [`crate::fit::bounded::AGREEMENT`] (Δχ² 0.01) of the lowest.
    pub agree: usize,
    /// The highest of the starts' minima minus the lowest.
    pub spread: f64,
    /// Whether the profile check found a lower minimum than the starts did (then taken).
    pub moved_by_profile: bool,
    /// Whether the minimiser used the exact gradient of −2 ln L (a power spectrum without a block
    /// after it), or central differences of it.
    pub exact_gradient: bool,
    /// Objective evaluations used (every start, the Hessian and the profiles).
    pub evaluations: usize,
    /// In a basis other than the model's: every parameter at the best fit in it (the order of its
    /// [`FitBasis::names`]; [`Self::best`] holds the model's parameters they map to).
    pub in_basis: Option<[f64; 12]>,
    /// With a block after the power spectrum: its own parameters at the best fit.
    pub block: Option<OwnValues>,
}

/// The names of the model's slots in `basis`.
pub fn slot_names(basis: &FitBasis) -> &'static [&'static str; 12] {
    basis.names()
}

/// The parameters of the power spectrum's model that enter it linearly, in `basis` (and a block's
/// [`crate::statistic::Kind::linear`] with a block).
pub fn linear_names(basis: &FitBasis) -> &'static [&'static str] {
    basis.linear_names()
}

/// The slot of parameter `name` in `basis` (its model parameters, then apar, aperp, then `own`: the
/// data set's block's own parameters, which no basis changes).
pub(crate) fn slot_index(name: &str, basis: &FitBasis, own: &[&str]) -> Result<usize> {
    basis.check_name(name)?;
    let names = slot_names(basis);
    if let Some(i) = names
        .iter()
        .chain(&AP_NAMES)
        .chain(own)
        .position(|&n| n == name)
    {
        return Ok(i);
    }
    let what = format!("fit parameter `{name}`");
    Err(match crate::blocks::owner(name) {
        Some(kind) => Error::InvalidChoice {
            what,
            reason: format!(
                "is a {0} parameter, and this data set has no {0}",
                kind.name
            ),
        },
        None => Error::InvalidChoice {
            what,
            reason: format!(
                "the parameters are {} (and apar, aperp{}){}",
                names.join(", "),
                crate::blocks::AVAILABLE
                    .iter()
                    .map(|k| format!("; with a {} {}", k.name, k.own.join(", ")))
                    .collect::<String>(),
                basis.hint(name)
            ),
        },
    })
}

/// How a fit applies an observation (window, bins, ξ), for its header.
pub const OBSERVATION_IN_FITS: &str =
    "the fit applies the window and bins as one matrix (the chain \
     on unit model vectors, made once: a spline of P instead of ln|P| between the model k; on the \
     BOSS CMASS NGC fit the best fit moves by <= 2e-4 sigma, 3-5x faster)";

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
    fit_galaxy_search(plan, terms, data, request, observation, &Search::default())
}

/// [`fit_galaxy_observed`] with the minimiser's settings `search` (starts, seed, the profile check).
///
/// # Errors
/// As [`fit_galaxy`]; [`Error::InvalidParameter`] for no start.
pub fn fit_galaxy_search(
    plan: &EptPlan,
    terms: &EptTerms,
    data: &MultipoleData,
    request: &GalaxyFitRequest,
    observation: Option<&Observation>,
    search: &Search,
) -> Result<GalaxyFit> {
    let mut objective = objective::objective(plan, terms, data, request, observation, None)?;
    objective.log_det = search.linear == Linear::Marginalised;
    search::solve(&objective, search)
}

#[cfg(test)]
mod joint_tests;
#[cfg(test)]
mod search_tests;
#[cfg(test)]
pub(crate) mod tests;
