//! Bounded minimisation of a smooth objective of a few parameters (−2 ln L of a fit): a projected
//! quasi-Newton method with several starts.
//!
//! * Gradient: the objective's own exact gradient where it gives one ([`Problem::grad`], with an
//!   approximation of the diagonal curvature such as Gauss–Newton's), else central differences inside
//!   the minimiser, with a step per parameter of
//!   [`GRADIENT_STEP`] times its current error scale √(2/∂²f/∂x²) (the diagonal curvature comes free
//!   with the central differences), one-sided at a bound. For −2 ln L that is a step of 1e-3 σ: the
//!   truncation error of the gradient is ~1e-6 of its 1σ scale and the rounding error of a χ² of
//!   O(100) (~1e-14 relative) is ~1e-8 of it.
//! * Direction: BFGS (Nocedal & Wright 2006, §6.1) on the free variables, its inverse Hessian started
//!   from the diagonal curvature; the variables at a bound whose gradient points out of the box are
//!   held (the projected-gradient active set of Bertsekas 1982), and the step is projected on the box.
//! * Line search: Armijo backtracking on the projected path, halving, from the full quasi-Newton step.
//! * Convergence: when the decrease the quadratic model still expects, ½ gᵀH⁻¹g over the free
//!   variables, is below [`EXPECTED_DECREASE`] (1e-7 in −2 ln L, i.e. Δχ²), or a line search cannot
//!   improve by more than rounding; at most [`MAX_ITERATIONS`] iterations.
//! * Several starts ([`multistart`]): each start minimised, the lowest taken; the report says how
//!   many reached it to [`AGREEMENT`] (Δχ² < 0.01).

/// The gradient step in units of each parameter's current 1σ scale (module docs).
pub const GRADIENT_STEP: f64 = 1e-3;

/// Convergence: the decrease of the objective the quadratic model still expects (module docs).
pub const EXPECTED_DECREASE: f64 = 1e-7;

/// The convergence of the starts of [`multistart`] before the lowest is polished to the problem's
/// tolerance: 1e-3, ten times below [`AGREEMENT`].
pub const COARSE_DECREASE: f64 = 1e-3;

/// Starts whose coarse minimum is within this of the lowest are polished to the problem's tolerance.
pub const POLISH_WITHIN: f64 = 0.3;

/// Iterations of one minimisation at most.
pub const MAX_ITERATIONS: usize = 300;

/// Starts whose minima are within this of the lowest agree with it (Δ(−2 ln L) = Δχ²).
pub const AGREEMENT: f64 = 0.01;

/// Armijo's sufficient-decrease constant.
const ARMIJO: f64 = 1e-4;

/// An objective's value, exact gradient and an approximation of its diagonal curvature ∂²f/∂xᵢ²
/// (Gauss–Newton's, say; NaN where unknown) at a point, or `None` where it cannot give them there
/// (the minimiser then differences the objective at that point).
pub type ValueGradient<'a> = dyn Fn(&[f64]) -> Option<(f64, Vec<f64>, Vec<f64>)> + 'a;

/// A box-bounded objective of n parameters.
pub struct Problem<'a> {
    /// The objective; +∞ (or NaN) outside its domain.
    pub f: &'a dyn Fn(&[f64]) -> f64,
    /// The objective with its exact gradient, if it has one (module docs).
    pub grad: Option<&'a ValueGradient<'a>>,
    /// Lower bounds.
    pub lo: Vec<f64>,
    /// Upper bounds.
    pub hi: Vec<f64>,
    /// A typical 1σ scale of each parameter, used before the curvature is known.
    pub scale: Vec<f64>,
    /// Convergence: the decrease the quadratic model still expects ([`EXPECTED_DECREASE`] for a
    /// final minimum; a start compared with others to [`AGREEMENT`] needs ~[`COARSE_DECREASE`]).
    pub tolerance: f64,
}

/// The result of one minimisation.
#[derive(Debug, Clone, PartialEq)]
pub struct Minimum {
    /// The point.
    pub x: Vec<f64>,
    /// The objective there.
    pub value: f64,
    /// Objective evaluations used.
    pub evaluations: usize,
    /// Whether the convergence test was met (not the iteration limit).
    pub converged: bool,
    /// The 1σ scale of each parameter at the minimum, √(2/∂²f/∂x²) with the others fixed (the
    /// parameter's scale where the curvature is not positive).
    pub sigma: Vec<f64>,
}

/// Several starts minimised: every minimum, lowest first, and how many agree with the lowest.
#[derive(Debug, Clone, PartialEq)]
pub struct MultiStart {
    /// The minima, lowest first.
    pub minima: Vec<Minimum>,
    /// How many of them are within [`AGREEMENT`] of the lowest (the lowest included).
    pub agree: usize,
}

impl MultiStart {
    /// The lowest minimum.
    pub fn best(&self) -> &Minimum {
        &self.minima[0]
    }

    /// The largest value among the minima (the worst start's).
    pub fn worst_value(&self) -> f64 {
        self.minima.last().map_or(f64::NAN, |m| m.value)
    }

    /// The total evaluations of every start.
    pub fn evaluations(&self) -> usize {
        self.minima.iter().map(|m| m.evaluations).sum()
    }
}

impl Problem<'_> {
    fn clamp(&self, x: &mut [f64]) {
        for ((v, lo), hi) in x.iter_mut().zip(&self.lo).zip(&self.hi) {
            *v = v.clamp(*lo, *hi);
        }
    }

    fn value(&self, x: &[f64], count: &mut usize) -> f64 {
        *count += 1;
        let v = (self.f)(x);
        if v.is_nan() {
            f64::INFINITY
        } else {
            v
        }
    }

    /// The objective at `x` and, where the problem has an exact gradient, the gradient and the
    /// diagonal curvature there (one evaluation either way).
    #[allow(clippy::type_complexity)]
    fn trial(&self, x: &[f64], count: &mut usize) -> (f64, Option<(Vec<f64>, Vec<f64>)>) {
        if let Some(grad) = self.grad {
            if let Some((v, g, c)) = grad(x) {
                *count += 1;
                if v.is_finite() && g.iter().all(|g| g.is_finite()) {
                    return (v, Some((g, c)));
                }
                return (f64::INFINITY, None);
            }
        }
        (self.value(x, count), None)
    }

    /// The central-difference gradient and diagonal curvature at `x` (value `f0`), steps of
    /// [`GRADIENT_STEP`] × `sigma`, one-sided where a bound is nearer than the step.
    fn gradient(
        &self,
        x: &[f64],
        f0: f64,
        sigma: &[f64],
        count: &mut usize,
    ) -> (Vec<f64>, Vec<f64>) {
        let n = x.len();
        let (mut g, mut c) = (vec![0.0; n], vec![f64::NAN; n]);
        for i in 0..n {
            let h = GRADIENT_STEP * sigma[i];
            let at = |d: f64, count: &mut usize| {
                let mut y = x.to_vec();
                y[i] += d;
                self.value(&y, count)
            };
            let (up, down) = (x[i] + h <= self.hi[i], x[i] - h >= self.lo[i]);
            match (up, down) {
                (true, true) => {
                    let (a, b) = (at(h, count), at(-h, count));
                    g[i] = (a - b) / (2.0 * h);
                    c[i] = (a - 2.0 * f0 + b) / (h * h);
                }
                (true, false) => {
                    let (a, b) = (at(h, count), at(2.0 * h, count));
                    g[i] = (-3.0 * f0 + 4.0 * a - b) / (2.0 * h);
                    c[i] = (f0 - 2.0 * a + b) / (h * h);
                }
                (false, true) => {
                    let (a, b) = (at(-h, count), at(-2.0 * h, count));
                    g[i] = (3.0 * f0 - 4.0 * a + b) / (2.0 * h);
                    c[i] = (f0 - 2.0 * a + b) / (h * h);
                }
                // The box is narrower than the step: held.
                (false, false) => {}
            }
            if !g[i].is_finite() {
                g[i] = 0.0;
            }
        }
        (g, c)
    }

    /// The 1σ scales from the curvature `c` (−2 ln L: σ = √(2/c)), `old` where c is not positive.
    fn sigma_from(c: &[f64], old: &[f64]) -> Vec<f64> {
        c.iter()
            .zip(old)
            .map(|(&c, &s)| {
                if c.is_finite() && c > 0.0 {
                    // Within a factor 1e3 of the old scale: one noisy curvature cannot wreck the steps.
                    (2.0 / c).sqrt().clamp(1e-3 * s, 1e3 * s)
                } else {
                    s
                }
            })
            .collect()
    }

    /// Minimises from `x0` (moved into the box).
    pub fn minimise(&self, x0: &[f64]) -> Minimum {
        let n = x0.len();
        let mut count = 0;
        let mut x = x0.to_vec();
        self.clamp(&mut x);
        let mut sigma = self.scale.clone();
        let (mut f0, mut exact) = self.trial(&x, &mut count);
        if !f0.is_finite() {
            return Minimum {
                x,
                value: f0,
                evaluations: count,
                converged: false,
                sigma,
            };
        }
        let (mut g, c) = exact
            .take()
            .unwrap_or_else(|| self.gradient(&x, f0, &sigma, &mut count));
        sigma = Self::sigma_from(&c, &sigma);
        let diagonal = |sigma: &[f64]| -> Vec<Vec<f64>> {
            (0..n)
                .map(|i| {
                    let mut row = vec![0.0; n];
                    row[i] = 0.5 * sigma[i] * sigma[i];
                    row
                })
                .collect()
        };
        let mut inverse = diagonal(&sigma);
        let mut converged = false;
        for _ in 0..MAX_ITERATIONS {
            let held: Vec<bool> = (0..n)
                .map(|i| (x[i] <= self.lo[i] && g[i] > 0.0) || (x[i] >= self.hi[i] && g[i] < 0.0))
                .collect();
            let direction = |inverse: &[Vec<f64>]| -> Vec<f64> {
                (0..n)
                    .map(|i| {
                        if held[i] {
                            0.0
                        } else {
                            -(0..n)
                                .filter(|&j| !held[j])
                                .map(|j| inverse[i][j] * g[j])
                                .sum::<f64>()
                        }
                    })
                    .collect()
            };
            let mut d = direction(&inverse);
            let mut slope: f64 = d.iter().zip(&g).map(|(a, b)| a * b).sum();
            if slope.is_nan() || slope >= 0.0 {
                inverse = diagonal(&sigma);
                d = direction(&inverse);
                slope = d.iter().zip(&g).map(|(a, b)| a * b).sum();
            }
            // ½ gᵀH⁻¹g over the free variables: the decrease still expected.
            if slope.is_nan() || slope >= 0.0 || -0.5 * slope < self.tolerance {
                converged = true;
                break;
            }
            let mut t = 1.0;
            let (mut x_new, mut f_new);
            loop {
                x_new = x
                    .iter()
                    .zip(&d)
                    .map(|(a, b)| a + t * b)
                    .collect::<Vec<f64>>();
                self.clamp(&mut x_new);
                (f_new, exact) = self.trial(&x_new, &mut count);
                let moved: f64 = (0..n).map(|i| g[i] * (x_new[i] - x[i])).sum();
                if f_new <= f0 + ARMIJO * moved.min(0.0) && f_new.is_finite() {
                    break;
                }
                t *= 0.5;
                if t < 1e-12 {
                    break;
                }
            }
            if f_new.is_nan() || f_new >= f0 {
                // No decrease to rounding along the quasi-Newton direction.
                converged = -0.5 * slope < 1e3 * self.tolerance;
                break;
            }
            let (g_new, c) = exact
                .take()
                .unwrap_or_else(|| self.gradient(&x_new, f_new, &sigma, &mut count));
            sigma = Self::sigma_from(&c, &sigma);
            let s: Vec<f64> = x_new.iter().zip(&x).map(|(a, b)| a - b).collect();
            let y: Vec<f64> = g_new.iter().zip(&g).map(|(a, b)| a - b).collect();
            bfgs_update(&mut inverse, &s, &y);
            x = x_new;
            f0 = f_new;
            g = g_new;
        }
        Minimum {
            x,
            value: f0,
            evaluations: count,
            converged,
            sigma,
        }
    }
}

/// The BFGS update of the inverse Hessian `h` with the step `s` and gradient change `y`, skipped
/// unless the curvature condition sᵀy > 0 holds (Nocedal & Wright 2006, eq. 6.17).
fn bfgs_update(h: &mut [Vec<f64>], s: &[f64], y: &[f64]) {
    let n = s.len();
    let sy: f64 = s.iter().zip(y).map(|(a, b)| a * b).sum();
    let norm =
        s.iter().map(|v| v * v).sum::<f64>().sqrt() * y.iter().map(|v| v * v).sum::<f64>().sqrt();
    if sy.is_nan() || sy <= 1e-10 * norm {
        return;
    }
    let rho = 1.0 / sy;
    let hy: Vec<f64> = (0..n)
        .map(|i| (0..n).map(|j| h[i][j] * y[j]).sum())
        .collect();
    let yhy: f64 = y.iter().zip(&hy).map(|(a, b)| a * b).sum();
    for i in 0..n {
        for j in 0..n {
            h[i][j] += -rho * (hy[i] * s[j] + s[i] * hy[j]) + (rho * rho * yhy + rho) * s[i] * s[j];
        }
    }
}

/// Minimises `problem` from every start to [`COARSE_DECREASE`] (or the problem's tolerance if
/// looser), then those within [`POLISH_WITHIN`] of the lowest to the problem's tolerance; the minima sorted lowest first and the
/// agreement count.
pub fn multistart(problem: &Problem, starts: &[Vec<f64>]) -> MultiStart {
    let coarse = Problem {
        f: problem.f,
        grad: problem.grad,
        lo: problem.lo.clone(),
        hi: problem.hi.clone(),
        scale: problem.scale.clone(),
        tolerance: problem.tolerance.max(COARSE_DECREASE),
    };
    let mut minima: Vec<Minimum> = starts.iter().map(|s| coarse.minimise(s)).collect();
    minima.sort_by(|a, b| a.value.total_cmp(&b.value));
    // Polish every start near the lowest (a coarse minimum was seen 0.13 above its true one):
    // those decide the agreement count and which is lowest.
    let lowest = minima.first().map_or(f64::NAN, |m| m.value);
    for m in minima
        .iter_mut()
        .filter(|m| m.value - lowest < POLISH_WITHIN)
    {
        let polished = Problem {
            f: problem.f,
            grad: problem.grad,
            lo: problem.lo.clone(),
            hi: problem.hi.clone(),
            scale: m.sigma.clone(),
            tolerance: problem.tolerance,
        };
        let better = polished.minimise(&m.x);
        let evaluations = m.evaluations + better.evaluations;
        if better.value <= m.value {
            *m = better;
        }
        m.evaluations = evaluations;
    }
    minima.sort_by(|a, b| a.value.total_cmp(&b.value));
    let lowest = minima.first().map_or(f64::NAN, |m| m.value);
    let agree = minima
        .iter()
        .filter(|m| m.value - lowest < AGREEMENT)
        .count();
    MultiStart { minima, agree }
}

/// The Hessian of `f` at `x` by central differences with steps `h` (each shrunk to stay inside the
/// box [`lo`, `hi`] where it can, one-sided at a bound) and `f0` = f(x).
pub fn hessian(
    f: &dyn Fn(&[f64]) -> f64,
    x: &[f64],
    f0: f64,
    h: &[f64],
    lo: &[f64],
    hi: &[f64],
) -> Vec<Vec<f64>> {
    let n = x.len();
    let stencil = stencil(x, h, lo, hi);
    let at = |d: &[(usize, f64)]| {
        let mut y = x.to_vec();
        for &(i, v) in d {
            y[i] += v;
        }
        f(&y)
    };
    let mut hess = vec![vec![0.0; n]; n];
    for i in 0..n {
        let (a, central) = stencil[i];
        hess[i][i] = if central {
            (at(&[(i, a)]) - 2.0 * f0 + at(&[(i, -a)])) / (a * a)
        } else {
            (f0 - 2.0 * at(&[(i, a)]) + at(&[(i, 2.0 * a)])) / (a * a)
        };
        for j in 0..i {
            let (c, central_j) = stencil[j];
            let v = if central && central_j {
                (at(&[(i, a), (j, c)]) - at(&[(i, a), (j, -c)]) - at(&[(i, -a), (j, c)])
                    + at(&[(i, -a), (j, -c)]))
                    / (4.0 * a * c)
            } else {
                // One of them at a bound: the one-sided mixed difference.
                (at(&[(i, a), (j, c)]) - at(&[(i, a)]) - at(&[(j, c)]) + f0) / (a * c)
            };
            hess[i][j] = v;
            hess[j][i] = v;
        }
    }
    hess
}

/// Per parameter of `x`, the step of a difference of size `h` inside the box [`lo`, `hi`] and
/// whether it is central (±a) or one-sided (a, 2a; a < 0 backward, where a bound is nearer than
/// 0.05 h).
fn stencil(x: &[f64], h: &[f64], lo: &[f64], hi: &[f64]) -> Vec<(f64, bool)> {
    (0..x.len())
        .map(|i| {
            let (up, down) = (hi[i] - x[i], x[i] - lo[i]);
            let room = up.min(down);
            if room >= 0.05 * h[i] {
                (h[i].min(room), true)
            } else if up >= down {
                (h[i].min(0.5 * up), false)
            } else {
                (-h[i].min(0.5 * down), false)
            }
        })
        .collect()
}

/// The Hessian at `x` by differences of the exact gradient `grad` with steps `h` (central where the
/// box allows, else one-sided of second order, as [`hessian`]), symmetrised: exact for a quadratic,
/// from 2n gradients where [`hessian`] takes 2n² values. `None` where a gradient is not available.
pub fn hessian_from_gradient(
    grad: &ValueGradient,
    x: &[f64],
    h: &[f64],
    lo: &[f64],
    hi: &[f64],
) -> Option<Vec<Vec<f64>>> {
    let n = x.len();
    // the gradient where the objective is finite (a point outside the model's domain: none)
    let gradient_at = |y: &[f64]| grad(y).and_then(|(v, g, _)| v.is_finite().then_some(g));
    let at = |i: usize, d: f64| -> Option<Vec<f64>> {
        let mut y = x.to_vec();
        y[i] += d;
        gradient_at(&y)
    };
    let mut at_x: Option<Vec<f64>> = None;
    let mut columns = Vec::with_capacity(n);
    for (i, (a, central)) in stencil(x, h, lo, hi).into_iter().enumerate() {
        let column: Vec<f64> = if central {
            let (p, m) = (at(i, a)?, at(i, -a)?);
            p.iter().zip(&m).map(|(p, m)| (p - m) / (2.0 * a)).collect()
        } else {
            if at_x.is_none() {
                at_x = Some(gradient_at(x)?);
            }
            let g0 = at_x.as_ref()?;
            let (g1, g2) = (at(i, a)?, at(i, 2.0 * a)?);
            (0..n)
                .map(|j| (-3.0 * g0[j] + 4.0 * g1[j] - g2[j]) / (2.0 * a))
                .collect()
        };
        columns.push(column);
    }
    Some(
        (0..n)
            .map(|i| {
                (0..n)
                    .map(|j| 0.5 * (columns[i][j] + columns[j][i]))
                    .collect()
            })
            .collect(),
    )
}

#[cfg(test)]
mod tests;
