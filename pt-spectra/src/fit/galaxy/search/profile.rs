//! The profile likelihood of one free parameter of a galaxy fit: the others re-minimised on a grid
//! around the best fit.

use super::{bounds, profile_at, solve, Linear, Search, RANGES};
use crate::error::{Error, Result};
use crate::fit::bounded::{Minimum, Problem, EXPECTED_DECREASE};
use crate::fit::galaxy::{slot_index, GalaxyFit, GalaxyFitRequest, MultipoleData, Observation};
use crate::rsd::ept::{EptParams, EptPlan, EptTerms, PARAM_NAMES};

/// The grid of a profile: `points` values over ± `span` times the fitted error around the best fit.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ProfileGrid {
    /// Values (≥ 3).
    pub points: usize,
    /// The half-width in units of the fitted error (> 0).
    pub span: f64,
}

/// One point of a profile.
#[derive(Debug, Clone, PartialEq)]
pub struct ProfilePoint {
    /// The profiled parameter's value.
    pub value: f64,
    /// −2 ln L with the others re-minimised.
    pub minus_two_log_l: f64,
    /// χ² there.
    pub chi2: f64,
    /// Every parameter there (the marginalised ones at â).
    pub best: EptParams,
    /// The distortion there.
    pub ap: Option<crate::rsd::ap::Distortion>,
    /// In a basis other than the model's: every parameter there in it ([`GalaxyFit::in_basis`]).
    pub in_basis: Option<[f64; 12]>,
}

/// The profile likelihood of one free parameter.
#[derive(Debug, Clone, PartialEq)]
pub struct GalaxyProfile {
    /// The parameter.
    pub name: String,
    /// The best fit (with the Δ = 1 interval of every free parameter).
    pub fit: GalaxyFit,
    /// The profile, in increasing value.
    pub points: Vec<ProfilePoint>,
}

/// The profile of the free parameter `name` of `request` on `grid` around the best fit: at each
/// value the other free parameters re-minimised (started from the neighbouring point's), the linear
/// ones marginalised or profiled as `search` says. Δ(−2 ln L) = 1 bounds the 68.3% interval
/// ([`GalaxyFit::intervals`]), 4 the 95.4% one.
///
/// # Errors
/// [`Error::InvalidChoice`] if `name` is not free; [`Error::InvalidParameter`] for a grid of fewer
/// than 3 or more than 401 points or a span that is not finite and positive; as
/// [`crate::fit::galaxy::fit_galaxy_search`].
#[allow(clippy::too_many_arguments)]
pub fn profile_galaxy(
    plan: &EptPlan,
    terms: &EptTerms,
    data: &MultipoleData,
    request: &GalaxyFitRequest,
    observation: Option<&Observation>,
    search: &Search,
    name: &str,
    grid: &ProfileGrid,
) -> Result<GalaxyProfile> {
    let slot = slot_index(name, &request.basis, &[])?;
    if !(3..=401).contains(&grid.points) {
        return Err(Error::InvalidParameter {
            name: "profile grid points",
            value: grid.points as f64,
            reason: "must be between 3 and 401",
        });
    }
    if !(grid.span.is_finite() && grid.span > 0.0) {
        return Err(Error::InvalidParameter {
            name: "profile span (in fitted errors)",
            value: grid.span,
            reason: "must be finite and positive",
        });
    }
    let mut objective =
        crate::fit::galaxy::objective::objective(plan, terms, data, request, observation, None)?;
    objective.log_det = search.linear == Linear::Marginalised;
    let Some(i) = objective.free.iter().position(|&s| s == slot) else {
        return Err(Error::InvalidChoice {
            what: format!("the profile of {name}"),
            reason: format!(
                "{name} is not free (free: {}): only a free parameter has a profile",
                request.free.join(", ")
            ),
        });
    };
    let fit = solve(&objective, search)?;
    let (lo, hi, _) = bounds(&objective);
    let f = |x: &[f64]| objective.cost(x);
    let exact = |x: &[f64]| objective.cost_and_gradient(x);
    let problem = Problem {
        f: &f,
        grad: objective
            .exact_gradient
            .then_some(&exact as &crate::fit::bounded::ValueGradient),
        lo,
        hi,
        scale: vec![],
        tolerance: EXPECTED_DECREASE,
    };
    let value_of = |s: usize| match s.checked_sub(PARAM_NAMES.len()) {
        None => fit.in_basis.map_or(fit.best.values[s], |v| v[s]),
        Some(0) => fit.ap.map_or(f64::NAN, |d| d.apar),
        Some(_) => fit.ap.map_or(f64::NAN, |d| d.aperp),
    };
    let best: Vec<f64> = objective.free.iter().map(|&s| value_of(s)).collect();
    let sigma: Vec<f64> = fit
        .errors
        .iter()
        .zip(objective.free.iter())
        .map(|(&e, &s)| {
            if e.is_finite() && e > 0.0 {
                e
            } else {
                RANGES[s].4
            }
        })
        .collect();
    let n = grid.points;
    let values: Vec<f64> = (0..n)
        .map(|j| best[i] + grid.span * sigma[i] * (2.0 * j as f64 / (n - 1) as f64 - 1.0))
        .map(|v| v.clamp(problem.lo[i], problem.hi[i]))
        .collect();
    // From the centre outwards, each point started from its inner neighbour's optimum.
    let mut found: Vec<Option<Minimum>> = vec![None; n];
    let centre = values
        .iter()
        .enumerate()
        .min_by(|a, b| (a.1 - best[i]).abs().total_cmp(&(b.1 - best[i]).abs()))
        .map_or(0, |(j, _)| j);
    let order: Vec<usize> = (centre..n).chain((0..centre).rev()).collect();
    for j in order {
        let guess = if j >= centre && j > centre {
            found[j - 1].as_ref().map_or(best.clone(), |m| m.x.clone())
        } else if j < centre {
            found[j + 1].as_ref().map_or(best.clone(), |m| m.x.clone())
        } else {
            best.clone()
        };
        found[j] = Some(profile_at(&problem, &sigma, i, values[j], &guess));
    }
    let mut points = Vec::with_capacity(n);
    for m in found.into_iter().flatten() {
        let (total, chi2, slots, _) = objective.evaluate(&m.x)?;
        let (params, ap) = objective.split(&slots)?;
        points.push(ProfilePoint {
            value: m.x[i],
            minus_two_log_l: total,
            chi2,
            best: params,
            ap,
            in_basis: (!objective.basis.is_model()).then(|| std::array::from_fn(|k| slots[k])),
        });
    }
    Ok(GalaxyProfile {
        name: name.to_string(),
        fit,
        points,
    })
}
