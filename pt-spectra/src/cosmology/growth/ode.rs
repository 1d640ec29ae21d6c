//! The growth ODE for any w0, wa (the [growth module's docs](super)): g = D/a in x = ln a, by an
//! adaptive Dormand–Prince 5(4) Runge–Kutta method over a [`Real`] T.
//!
//! The step-size controller and the accept/reject decisions see the values alone (the error
//! estimate is formed from [`Real::value`]s), so on [`Dual`](crate::dual::Dual)s the mesh in ln a is
//! a constant and the derivatives are those of the discrete solution on that mesh: exact up to the
//! ODE tolerance [`ODE_TOL`].

use super::super::background::Background;
use crate::dual::Real;

/// Scale factor at which the growth ODE starts, deep in matter domination. A start slightly off the
/// growing mode adds a decaying mode that falls as a^{−5/2} relative to the growing one, so even a
/// start error of 1e-8 (D = D′ = a with Ω_k ~ Ω_m) would be far below 1e-12 by z ~ 1e3.
const A_START: f64 = 1e-8;

/// Absolute local error per step on g = D/D_md ~ 1 and on g′ (so on f = 1 + g′/g), Dormand–Prince 5(4).
/// The accumulated global error is ~1e-11 (measured against Heath's integral by the tests).
/// Each factor 10 tighter costs a factor 10^{1/5} ≈ 1.6 in steps.
const ODE_TOL: f64 = 1e-11;

/// First trial step in ln a; the controller adapts it (steps of ~1 early, ~0.015 near a = 1).
const ODE_FIRST_STEP: f64 = 0.5;

/// Guard against a stalled step-size controller (a valid cosmology needs a few hundred steps).
const ODE_MAX_STEPS: usize = 100_000;

/// (g, g′) with g = D/a and ′ = d/d ln a.
pub(super) type State<T> = [T; 2];

impl<T: Real> Background<T> {
    /// Right-hand side of the growth ODE for (g, g′), g = D/a, in x = ln a:
    /// g″ = −(5m + 6k + (5 − 3w)d)/(2E²) g′ − (4k + 3(1 − w)d)/(2E²) g, with m, k, d the matter,
    /// curvature and dark-energy terms of E² = m + k + d and w = w(a). This is the equation of the module
    /// docs with D = a g, written so that the matter-domination terms cancel exactly (no round-off as
    /// g″ → 0 for a → 0). All three terms are multiplied by a³ to stay O(1).
    fn ode_rhs(&self, x: f64, [g, dg]: State<T>) -> State<T> {
        let a = x.exp();
        let m = self.omega_m;
        let k = self.omega_k * a;
        let d = self.omega_lambda * a.powi(3) * self.dark_energy_density_ln(a, x);
        let w = self.w_of_a(a);
        let two_e2 = (m + k + d) * 2.0;
        let damping = (m * 5.0 + k * 6.0 + (-(w * 3.0) + 5.0) * d) / two_e2;
        let source = (k * 4.0 + (-w + 1.0) * 3.0 * d) / two_e2;
        [dg, -(damping * dg) - source * g]
    }

    /// (g, g′) of the growing mode at a = [`A_START`]: D = D′ = a plus the first-order corrections for
    /// curvature and dark energy. A term E²/(Ω_m a⁻³) ⊃ ε a^p (curvature: ε = Ω_k/Ω_m, p = 1; dark
    /// energy at a → 0: ε = Ω_DE e^{−3wa}/Ω_m, p = −3(w0 + wa)) changes the growing mode to
    /// g = 1 + c ε a^p with c = −(p + 3)/(p (2p + 5)), e.g. −2/11 for Λ and −4/7 for curvature. The
    /// neglected O(ε² a^{2p}) terms change D_md by < 1e-12 unless w0 + wa > −0.3.
    fn ode_start(&self) -> State<T> {
        let terms = [
            (self.omega_k / self.omega_m, T::cst(1.0)),
            (
                self.omega_lambda * (self.wa * -3.0).exp() / self.omega_m,
                (self.w0 + self.wa) * -3.0,
            ),
        ];
        let mut state = [T::cst(1.0), T::cst(0.0)];
        for (epsilon, p) in terms {
            // a^p = e^{p ln a}: p carries the derivatives with respect to w0 and wa.
            let term = -(p + 3.0) / (p * (p * 2.0 + 5.0)) * epsilon * (p * A_START.ln()).exp();
            state[0] += term;
            state[1] += p * term;
        }
        state
    }

    /// (g, g′) at x = ln a for the two targets (in any order), integrating once from a = [`A_START`].
    /// NaN if the integration fails (E² ≤ 0 on the way, or a target below the start).
    pub(super) fn ode_states(&self, targets: [f64; 2]) -> [State<T>; 2] {
        let (lo, hi) = (targets[0].min(targets[1]), targets[0].max(targets[1]));
        let mut h = ODE_FIRST_STEP;
        let first = self.ode_integrate(A_START.ln(), lo, self.ode_start(), &mut h);
        let second = self.ode_integrate(lo, hi, first, &mut h);
        if targets[0] <= targets[1] {
            [first, second]
        } else {
            [second, first]
        }
    }

    /// Integrates the growth ODE from `x0` to `x1` ≥ `x0` starting at `y`; `h` is the step to try and is
    /// updated to the next step the controller proposes. The steps and their acceptance depend on the
    /// values alone (module docs).
    fn ode_integrate(&self, x0: f64, x1: f64, y: State<T>, h: &mut f64) -> State<T> {
        let nan = [T::cst(f64::NAN); 2];
        if x1.is_nan() || x0.is_nan() || x1 < x0 {
            return nan;
        }
        let (mut x, mut y) = (x0, y);
        let mut k1 = self.ode_rhs(x, y);
        for _ in 0..ODE_MAX_STEPS {
            if x >= x1 {
                return y;
            }
            let last = x1 - x <= *h;
            let step = if last { x1 - x } else { *h };
            let (y_new, k7, err) = dormand_prince_step(|x, y| self.ode_rhs(x, y), x, y, k1, step);
            if err.is_nan() || y_new.iter().any(|v| !v.value().is_finite()) {
                return nan;
            }
            let scale = if err == 0.0 {
                5.0
            } else {
                (0.9 * err.powf(-0.2)).clamp(0.2, 5.0)
            };
            if err <= 1.0 {
                (x, y, k1) = (if last { x1 } else { x + step }, y_new, k7);
            }
            *h = step * scale;
        }
        nan
    }
}

/// One Dormand–Prince 5(4) step (Dormand & Prince 1980; Hairer, Nørsett & Wanner, Solving ODEs I,
/// Table 5.2): the 5th-order solution, the derivative there (first stage of the next step, "FSAL"),
/// and the error estimate |y5 − y4|_∞ / [`ODE_TOL`] of the values (a plain number: it steers the
/// step size only).
#[inline]
fn dormand_prince_step<T: Real>(
    f: impl Fn(f64, State<T>) -> State<T>,
    x: f64,
    y: State<T>,
    k1: State<T>,
    h: f64,
) -> (State<T>, State<T>, f64) {
    let at = |coefs: &[f64], ks: &[State<T>]| -> State<T> {
        let mut out = y;
        for (c, k) in coefs.iter().zip(ks) {
            out[0] += k[0] * (h * c);
            out[1] += k[1] * (h * c);
        }
        out
    };
    let k2 = f(x + h / 5.0, at(&[1.0 / 5.0], &[k1]));
    let k3 = f(x + 0.3 * h, at(&[3.0 / 40.0, 9.0 / 40.0], &[k1, k2]));
    let k4 = f(
        x + 0.8 * h,
        at(&[44.0 / 45.0, -56.0 / 15.0, 32.0 / 9.0], &[k1, k2, k3]),
    );
    let a5 = [
        19372.0 / 6561.0,
        -25360.0 / 2187.0,
        64448.0 / 6561.0,
        -212.0 / 729.0,
    ];
    let k5 = f(x + 8.0 / 9.0 * h, at(&a5, &[k1, k2, k3, k4]));
    let a6 = [
        9017.0 / 3168.0,
        -355.0 / 33.0,
        46732.0 / 5247.0,
        49.0 / 176.0,
        -5103.0 / 18656.0,
    ];
    let k6 = f(x + h, at(&a6, &[k1, k2, k3, k4, k5]));
    let b = [
        35.0 / 384.0,
        0.0,
        500.0 / 1113.0,
        125.0 / 192.0,
        -2187.0 / 6784.0,
        11.0 / 84.0,
    ];
    let y5 = at(&b, &[k1, k2, k3, k4, k5, k6]);
    let k7 = f(x + h, y5);
    // e = b − b̂ (5th minus embedded 4th-order weights).
    let e = [
        71.0 / 57600.0,
        0.0,
        -71.0 / 16695.0,
        71.0 / 1920.0,
        -17253.0 / 339200.0,
        22.0 / 525.0,
        -1.0 / 40.0,
    ];
    let ks = [k1, k2, k3, k4, k5, k6, k7];
    let err = (0..2)
        .map(|i| {
            (h * e
                .iter()
                .zip(&ks)
                .map(|(c, k)| c * k[i].value())
                .sum::<f64>())
            .abs()
        })
        .fold(0.0, f64::max);
    (y5, k7, err / ODE_TOL)
}
