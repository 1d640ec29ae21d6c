//! The search of a galaxy fit: the bounds and start box of each parameter, several starts, the
//! Hessian errors and their check by the profile likelihood, and the 1-D profile of a parameter.
//!
//! * Bounds ([`RANGES`]): wide physical ranges (f in [0, 2], b1 in [0.05, 10], …), narrowed by a flat
//!   or log-normal prior's support; α∥, α⊥ within the plan's AP range.
//! * Starts: the request's start, then [`Search::starts`] − 1 points drawn with a seeded generator
//!   (ChaCha8, [`Search::seed`]): a parameter with a prior from its prior (a Gaussian's draws within
//!   ±2σ), the others uniformly in their start box ([`RANGES`]), all moved into the bounds. Each start
//!   is minimised ([`crate::fit::bounded`]) and the lowest minimum taken; the fit reports how many
//!   reached it to Δχ² < 0.01 and the spread of the minima.
//! * Errors: √diag(2H⁻¹), H the central-difference Hessian of −2 ln L with steps of
//!   [`HESSIAN_STEP`] times each parameter's conditional σ at the minimum. Then the likelihood checks
//!   it: the profile −2 ln L (the others re-minimised, started on the Hessian's regression line) at
//!   best ± σ_H, and the crossing of Δ = 1 found by the secant in √Δ (exact for a Gaussian likelihood,
//!   where √Δ is linear in the distance) to [`CROSSING_TOLERANCE`]. A profile point below the minimum
//!   by more than 0.01 means the starts missed the global minimum: the search restarts there.

use super::objective::Objective;
use super::{FitBasis, GalaxyFit, OwnValues, PriorShape, AP_SLOT, OWN_SLOT};
use crate::error::{Error, Result};
use crate::fit::bounded::{
    hessian_from_gradient, multistart, Minimum, Problem, ValueGradient, AGREEMENT,
    EXPECTED_DECREASE,
};
use crate::linalg::solve_spd;
pub use crate::statistic::Range;
use rand::{Rng, SeedableRng};

mod profile;
pub use profile::{profile_galaxy, GalaxyProfile, ProfileGrid, ProfilePoint};

/// The starts of a fit by default.
pub const DEFAULT_STARTS: usize = 8;

/// The Hessian's step in units of each parameter's conditional σ at the minimum.
pub const HESSIAN_STEP: f64 = 0.5;

/// The relative difference between the profile's half-width and the Hessian's σ above which the
/// profile's is the error given.
pub const PROFILE_AGREEMENT: f64 = 0.1;

/// The tolerance on √Δ(−2 ln L) at a crossing of Δ = 1 (0.5% of the interval).
pub const CROSSING_TOLERANCE: f64 = 0.005;

/// The convergence of a profile point's minimisation: Δ(−2 ln L) to 1e-4, √Δ at Δ = 1 to 5e-5.
pub const PROFILE_DECREASE: f64 = 1e-4;

/// Re-searches after a profile found a lower minimum, at most.
const RESTARTS: usize = 3;

/// Per slot ([`crate::rsd::ept::PARAM_NAMES`], then α∥, α⊥; a block's own from its
/// [`crate::statistic::Kind::ranges`]): (lower bound, upper bound, start box lower, upper, typical σ).
/// The bounds are wide physical ranges (f: the plausible range [0, 2]); the start box is where galaxy
/// samples' best fits lie (b1 1–3, |b2| ≲ 2 in velocileptors' units; counterterms tens of (Mpc/h)²,
/// shot noise ~1/n̄ ~ 10³ (Mpc/h)³).
pub const RANGES: [Range; OWN_SLOT] = [
    (0.05, 10.0, 1.0, 3.0, 0.1),
    (-50.0, 50.0, -2.0, 2.0, 1.0),
    (-50.0, 50.0, -1.0, 1.0, 1.0),
    (-50.0, 50.0, -1.0, 1.0, 1.0),
    (-1e4, 1e4, -30.0, 30.0, 10.0),
    (-1e4, 1e4, -30.0, 30.0, 10.0),
    (-1e4, 1e4, -30.0, 30.0, 10.0),
    (-1e4, 1e4, -30.0, 30.0, 10.0),
    (-1e5, 1e5, -1e3, 1e3, 300.0),
    (-1e7, 1e7, -1e4, 1e4, 3e3),
    (-1e9, 1e9, -1e5, 1e5, 3e4),
    (0.0, 2.0, 0.4, 1.0, 0.05),
    (0.5, 2.0, 0.9, 1.1, 0.03),
    (0.5, 2.0, 0.9, 1.1, 0.03),
];

/// [`RANGES`] for the slots of the DESI physical basis ([`crate::rsd::ept::physical`]): b1p = b1 σ₈(z)
/// (start box 0.6–1.8), b2p, bsp, b3p in σ₈²-scaled units, the counterterms as fractions of linear
/// theory per (h/Mpc)² (tens), the stochastic terms in units of 1/n̄ (of order one).
pub const PHYSICAL_RANGES: [Range; OWN_SLOT] = [
    (0.01, 10.0, 0.6, 1.8, 0.05),
    (-50.0, 50.0, -1.0, 1.0, 0.5),
    (-50.0, 50.0, -0.5, 0.5, 0.5),
    (-50.0, 50.0, -0.5, 0.5, 0.5),
    (-1e3, 1e3, -20.0, 20.0, 5.0),
    (-1e3, 1e3, -20.0, 20.0, 5.0),
    (-1e3, 1e3, -20.0, 20.0, 5.0),
    (0.0, 0.0, 0.0, 0.0, 1.0),
    (-1e3, 1e3, -2.0, 2.0, 0.5),
    (-1e3, 1e3, -5.0, 5.0, 1.0),
    (-1e3, 1e3, -5.0, 5.0, 1.0),
    (0.0, 2.0, 0.4, 1.0, 0.05),
    (0.5, 2.0, 0.9, 1.1, 0.03),
    (0.5, 2.0, 0.9, 1.1, 0.03),
];

/// [`PHYSICAL_RANGES`] in the DESI basis, else [`RANGES`].
pub(super) fn ranges(basis: &FitBasis) -> &'static [Range; OWN_SLOT] {
    match basis {
        FitBasis::Desi(_) => &PHYSICAL_RANGES,
        _ => &RANGES,
    }
}

/// The linear parameters in −2 ln L.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Linear {
    /// Marginalised analytically (the ln det F term).
    Marginalised,
    /// Profiled: set to their best values â, without ln det F.
    Profiled,
}

/// How a fit searches for its minimum.
#[derive(Debug, Clone, PartialEq)]
pub struct Search {
    /// Starts minimised (≥ 1; the first is the request's start).
    pub starts: usize,
    /// The seed of the starts' draws.
    pub seed: u64,
    /// Whether the Hessian errors are checked by (and the intervals found on) the profile likelihood.
    pub profile_check: bool,
    /// Marginalise or profile the linear parameters.
    pub linear: Linear,
}

impl Default for Search {
    fn default() -> Self {
        Self {
            starts: DEFAULT_STARTS,
            seed: 1,
            profile_check: true,
            linear: Linear::Marginalised,
        }
    }
}

/// The bounds (lower, upper) and typical σ of slot `i` of `objective`: its range
/// ([`Objective::range`]), α∥, α⊥ within the plan's AP range, narrowed by the slot's prior's support.
pub(super) fn bound(objective: &Objective, i: usize) -> (f64, f64, f64) {
    let (mut a, mut b, _, _, s) = objective.range(i);
    let ap = objective.plan.settings().ap_range;
    if let (true, Some((x, y))) = ((AP_SLOT..OWN_SLOT).contains(&i), ap) {
        (a, b) = (x, y);
    }
    if let Some(p) = &objective.priors[i] {
        let (x, y) = p.support();
        (a, b) = (a.max(x), b.min(y));
    }
    (a, b, s)
}

/// The bounds (lower, upper) and typical σ of the free parameters of `objective`.
fn bounds(objective: &Objective) -> (Vec<f64>, Vec<f64>, Vec<f64>) {
    let mut lo = Vec::new();
    let mut hi = Vec::new();
    let mut scale = Vec::new();
    for &i in &objective.free {
        let (a, b, s) = bound(objective, i);
        lo.push(a);
        hi.push(b);
        scale.push(s);
    }
    (lo, hi, scale)
}

/// A standard normal draw (Box–Muller) and a uniform one.
fn draws(rng: &mut rand_chacha::ChaCha8Rng) -> (f64, f64) {
    let (u1, u2): (f64, f64) = (rng.gen(), rng.gen());
    let z = (-2.0 * (1.0 - u1).ln()).sqrt() * (std::f64::consts::TAU * u2).cos();
    (z, rng.gen())
}

/// The starts: `x0`, then draws from the priors or the start box, within [lo, hi]; `params` the
/// slot and prior of each free parameter.
fn starts(space: &Space, search: &Search) -> Vec<Vec<f64>> {
    let (params, x0, lo, hi) = (&space.params, &space.x0, &space.lo, &space.hi);
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(search.seed);
    let mut all = vec![x0.to_vec()];
    while all.len() < search.starts {
        let x = params
            .iter()
            .enumerate()
            .map(|(j, &(_, prior))| {
                let (z, u) = draws(&mut rng);
                let (from, to) = space.boxes[j];
                let v = match prior {
                    Some(p) => p.draw(z.clamp(-2.0, 2.0), u),
                    None => from + (to - from) * u,
                };
                v.clamp(lo[j], hi[j])
            })
            .collect();
        all.push(x);
    }
    all
}

/// `y` (every free parameter but the i-th) with `v` put in at i.
fn insert(y: &[f64], i: usize, v: f64) -> Vec<f64> {
    let mut x = y.to_vec();
    x.insert(i, v);
    x
}

/// The minimum of `problem` with parameter i held at `v`, the others started at `guess` (full
/// length; its i-th entry ignored).
fn profile_at(problem: &Problem, sigma: &[f64], i: usize, v: f64, guess: &[f64]) -> Minimum {
    let drop = |x: &[f64]| -> Vec<f64> {
        x.iter()
            .enumerate()
            .filter(|&(j, _)| j != i)
            .map(|(_, &a)| a)
            .collect()
    };
    let g = |y: &[f64]| (problem.f)(&insert(y, i, v));
    let exact = |y: &[f64]| {
        let (value, gradient, curvature) = (problem.grad?)(&insert(y, i, v))?;
        Some((value, drop(&gradient), drop(&curvature)))
    };
    let reduced = Problem {
        f: &g,
        grad: problem.grad.map(|_| &exact as &ValueGradient),
        lo: drop(&problem.lo),
        hi: drop(&problem.hi),
        scale: drop(sigma),
        tolerance: PROFILE_DECREASE,
    };
    let m = reduced.minimise(&drop(guess));
    Minimum {
        x: insert(&m.x, i, v),
        sigma: insert(&m.sigma, i, sigma[i]),
        ..m
    }
}

/// The start of the others for the profile at x_i = `v`: on the Hessian's regression line through
/// the best fit (x_j + C_ji/C_ii Δx_i), or the best fit where the covariance is undefined.
fn regression(best: &[f64], cov: Option<&[Vec<f64>]>, i: usize, v: f64) -> Vec<f64> {
    let d = v - best[i];
    best.iter()
        .enumerate()
        .map(|(j, &b)| match cov {
            Some(c) if j != i => b + c[j][i] / c[i][i] * d,
            _ => b,
        })
        .collect()
}

/// The Gaussian errors √diag(2H⁻¹) at `best` and the covariance 2H⁻¹ (`None` if H is not positive
/// definite; the errors NaN then), and the evaluations used.
fn hessian_errors(problem: &Problem, best: &Minimum) -> (Vec<f64>, Option<Vec<Vec<f64>>>, usize) {
    let n = best.x.len();
    let count = std::cell::Cell::new(0);
    let f = |x: &[f64]| {
        count.set(count.get() + 1);
        (problem.f)(x)
    };
    let h: Vec<f64> = best.sigma.iter().map(|s| HESSIAN_STEP * s).collect();
    // from the exact gradient where the objective has one (2n gradients), else from −2 ln L
    let from_gradient = problem.grad.and_then(|grad| {
        let counted = |x: &[f64]| {
            count.set(count.get() + 1);
            grad(x)
        };
        hessian_from_gradient(&counted, &best.x, &h, &problem.lo, &problem.hi)
    });
    let hess = from_gradient.unwrap_or_else(|| {
        crate::fit::bounded::hessian(&f, &best.x, best.value, &h, &problem.lo, &problem.hi)
    });
    match solve_spd(&hess, &vec![0.0; n]) {
        Ok((_, inverse, _)) => {
            let cov: Vec<Vec<f64>> = inverse
                .iter()
                .map(|r| r.iter().map(|v| 2.0 * v).collect())
                .collect();
            let errors = (0..n).map(|i| cov[i][i].sqrt()).collect();
            (errors, Some(cov), count.get())
        }
        Err(_) => (vec![f64::NAN; n], None, count.get()),
    }
}

/// The profile crossings of Δ = 1 of every parameter: (lower, upper) per parameter and the
/// evaluations used; `Err` with a profile point that is lower than `best` by more than 0.01.
fn intervals(
    problem: &Problem,
    best: &Minimum,
    errors: &[f64],
    cov: Option<&[Vec<f64>]>,
) -> std::result::Result<(Vec<(f64, f64)>, usize), Minimum> {
    let n = best.x.len();
    let mut used = 0;
    let mut out = Vec::with_capacity(n);
    #[allow(clippy::needless_range_loop)] // i indexes the bounds, the best fit and its errors alike
    for i in 0..n {
        let start = if errors[i].is_finite() && errors[i] > 0.0 {
            errors[i]
        } else {
            best.sigma[i]
        };
        let mut ends = [f64::NAN; 2];
        for (side, end) in [-1.0, 1.0].into_iter().zip(ends.iter_mut()) {
            let bound = if side < 0.0 {
                problem.lo[i]
            } else {
                problem.hi[i]
            };
            let mut d = start;
            for _ in 0..8 {
                let v = best.x[i] + side * d;
                let at_bound = (v - bound) * side >= 0.0;
                let v = if at_bound { bound } else { v };
                let guess = regression(&best.x, cov, i, v);
                let m = profile_at(problem, &best.sigma, i, v, &guess);
                used += m.evaluations;
                let delta = m.value - best.value;
                if delta < -AGREEMENT {
                    return Err(m);
                }
                let root = delta.max(0.0).sqrt();
                if (root - 1.0).abs() < CROSSING_TOLERANCE {
                    *end = v;
                    break;
                }
                if at_bound && root < 1.0 {
                    break;
                }
                // √Δ ∝ distance for a Gaussian likelihood; at most 4× further per step.
                let reach = (v - best.x[i]).abs();
                d = reach / root.max(0.25);
            }
        }
        out.push((ends[0], ends[1]));
    }
    Ok((out, used))
}

/// The free parameters of a search: per parameter its slot and prior, its bounds and typical σ, and
/// its start (inside the bounds).
pub(super) struct Space<'p> {
    /// Per parameter: its slot and prior.
    pub(super) params: Vec<(usize, Option<&'p PriorShape>)>,
    /// Lower bounds.
    pub(super) lo: Vec<f64>,
    /// Upper bounds.
    pub(super) hi: Vec<f64>,
    /// Typical σ.
    pub(super) scale: Vec<f64>,
    /// The start.
    pub(super) x0: Vec<f64>,
    /// Per parameter, its start box (lower, upper: [`Objective::range`]).
    pub(super) boxes: Vec<(f64, f64)>,
}

/// The errors of a search's free parameters (or of a selection of them: [`Errors::select`]).
#[derive(Debug, Clone, PartialEq)]
pub(super) struct Errors {
    /// The errors given (the Hessian's, or the profile's half-width).
    pub(super) given: Vec<f64>,
    /// √diag(2H⁻¹).
    pub(super) hessian: Vec<f64>,
    /// 2H⁻¹.
    pub(super) covariance: Option<Vec<Vec<f64>>>,
    /// The profile's Δ = 1 crossings.
    pub(super) intervals: Vec<(f64, f64)>,
    /// Whether the error given is the profile's.
    pub(super) from_profile: Vec<bool>,
}

impl Errors {
    /// The errors of the parameters `indices` (their covariance the block of those rows and columns).
    pub(super) fn select(&self, indices: &[usize]) -> Self {
        Self {
            given: indices.iter().map(|&i| self.given[i]).collect(),
            hessian: indices.iter().map(|&i| self.hessian[i]).collect(),
            covariance: self.covariance.as_ref().map(|c| {
                indices
                    .iter()
                    .map(|&i| indices.iter().map(|&j| c[i][j]).collect())
                    .collect()
            }),
            intervals: indices.iter().map(|&i| self.intervals[i]).collect(),
            from_profile: indices.iter().map(|&i| self.from_profile[i]).collect(),
        }
    }
}

/// What a search found: the minimum, the errors and their profile check, the starts' agreement.
pub(super) struct Found {
    /// The minimum.
    pub(super) best: Minimum,
    /// The free parameters' errors.
    pub(super) errors: Errors,
    /// Starts minimised.
    pub(super) starts: usize,
    /// Starts that reached the minimum to [`AGREEMENT`].
    pub(super) agree: usize,
    /// The highest start's minimum minus the lowest.
    pub(super) spread: f64,
    /// Whether the profile check moved the minimum.
    pub(super) moved: bool,
    /// Objective evaluations used.
    pub(super) evaluations: usize,
    /// Whether the minimiser had the exact gradient.
    pub(super) exact_gradient: bool,
}

/// The fit of `objective` (module docs).
///
/// # Errors
/// [`Error::InvalidParameter`] for no start or no start with a finite −2 ln L; as the model's
/// evaluation.
pub(super) fn solve(objective: &Objective, search: &Search) -> Result<GalaxyFit> {
    let (lo, hi, scale) = bounds(objective);
    let mut x0: Vec<f64> = objective.free.iter().map(|&i| objective.start[i]).collect();
    for (j, v) in x0.iter_mut().enumerate() {
        *v = v.clamp(lo[j], hi[j]);
    }
    // Errors of the model at the start are the user's: reported as they are.
    objective.evaluate(&x0)?;
    let space = Space {
        params: objective
            .free
            .iter()
            .map(|&i| (i, objective.priors[i].as_ref()))
            .collect(),
        lo,
        hi,
        scale,
        x0,
        boxes: objective
            .free
            .iter()
            .map(|&i| objective.start_box(i))
            .collect(),
    };
    let exact = |x: &[f64]| objective.cost_and_gradient(x);
    let grad = objective.exact_gradient.then_some(&exact as &ValueGradient);
    let found = find(&|x: &[f64]| objective.cost(x), grad, &space, search)?;
    package(objective, &found.best.x, &found, found.errors.clone())
}

/// The [`GalaxyFit`] of `objective` at its free values `x`, with `errors` (of its free parameters)
/// and the search's report `found`.
///
/// # Errors
/// As the model's evaluation.
pub(super) fn package(
    objective: &Objective,
    x: &[f64],
    found: &Found,
    errors: Errors,
) -> Result<GalaxyFit> {
    let (minus_two_log_l, chi2, slots, marginalised_errors) = objective.evaluate(x)?;
    let (params, ap) = objective.split(&slots)?;
    Ok(GalaxyFit {
        best: params,
        ap,
        errors: errors.given,
        hessian_errors: errors.hessian,
        covariance: errors.covariance,
        intervals: errors.intervals,
        from_profile: errors.from_profile,
        marginalised_errors,
        chi2,
        minus_two_log_l,
        points: objective.points(),
        starts: found.starts,
        agree: found.agree,
        spread: found.spread,
        moved_by_profile: found.moved,
        exact_gradient: found.exact_gradient,
        evaluations: found.evaluations,
        in_basis: (!objective.basis.is_model()).then(|| std::array::from_fn(|i| slots[i])),
        block: objective.block.as_ref().and_then(|b| {
            let own = b.fit.kind().own;
            Some(OwnValues {
                names: own,
                values: slots.get(OWN_SLOT..OWN_SLOT + own.len())?.to_vec(),
            })
        }),
    })
}

/// The minimum of `cost` over `space` from the starts of `search`, its errors and their profile
/// check (module docs).
///
/// # Errors
/// [`Error::InvalidParameter`] for no start or no start with a finite −2 ln L.
pub(super) fn find(
    cost: &dyn Fn(&[f64]) -> f64,
    grad: Option<&ValueGradient>,
    space: &Space,
    search: &Search,
) -> Result<Found> {
    if search.starts == 0 {
        return Err(Error::InvalidParameter {
            name: "number of starts",
            value: 0.0,
            reason: "the fit needs at least one start",
        });
    }
    let (lo, hi) = (&space.lo, &space.hi);
    let problem = Problem {
        f: cost,
        grad,
        lo: lo.clone(),
        hi: hi.clone(),
        scale: space.scale.clone(),
        tolerance: EXPECTED_DECREASE,
    };
    let multi = multistart(&problem, &starts(space, search));
    let mut best = multi.best().clone();
    if !best.value.is_finite() {
        return Err(Error::InvalidParameter {
            name: "number of starts with a finite -2 ln L",
            value: 0.0,
            reason: "no start gave a finite likelihood (every one outside the model's domain)",
        });
    }
    let mut evaluations = multi.evaluations();
    if std::env::var_os("PT_FIT_DEBUG").is_some() {
        for m in &multi.minima {
            eprintln!(
                "start: {} evals, value {}, converged {}",
                m.evaluations, m.value, m.converged
            );
        }
    }
    let mut moved = false;
    let n = best.x.len();
    let mut restarts = 0;
    let (hessian, covariance, intervals) = loop {
        let (errors, cov, used) = hessian_errors(&problem, &best);
        evaluations += used;
        if !search.profile_check {
            break (errors, cov, vec![(f64::NAN, f64::NAN); n]);
        }
        match intervals(&problem, &best, &errors, cov.as_deref()) {
            Ok((found, used)) => {
                evaluations += used;
                break (errors, cov, found);
            }
            Err(lower) if restarts < RESTARTS => {
                restarts += 1;
                moved = true;
                best = problem.minimise(&lower.x);
                evaluations += best.evaluations + lower.evaluations;
            }
            Err(_) => break (errors, cov, vec![(f64::NAN, f64::NAN); n]),
        }
    };
    if std::env::var_os("PT_FIT_DEBUG").is_some() {
        eprintln!("total {evaluations} evals");
    }
    let mut errors = hessian.clone();
    let mut from_profile = vec![false; n];
    for j in 0..n {
        let (a, b) = intervals[j];
        let half = 0.5 * (b - a);
        if half.is_finite() && ((half / hessian[j]) - 1.0).abs() > PROFILE_AGREEMENT {
            errors[j] = half;
            from_profile[j] = true;
        }
    }
    Ok(Found {
        starts: multi.minima.len(),
        // counted against the final minimum: after a profile found a lower one, the starts that
        // reached it (possibly none)
        agree: multi
            .minima
            .iter()
            .filter(|m| m.value - best.value < AGREEMENT)
            .count(),
        spread: multi.worst_value() - best.value,
        best,
        errors: Errors {
            given: errors,
            hessian,
            covariance,
            intervals,
            from_profile,
        },
        moved,
        evaluations,
        exact_gradient: grad.is_some(),
    })
}
