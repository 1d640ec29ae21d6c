//! Background expansion E(a) and linear growth D, f (formulas and references in the [module docs](super)).
//!
//! Two paths give the growing mode, normalised to a deep in matter domination ("D_md"):
//! * ΛCDM (w0 = −1, wa = 0, any curvature): Heath's (1977) integral, exact up to the quadrature error.
//! * Otherwise: the growth ODE in x = ln a for g = D/a, integrated by an adaptive Dormand–Prince 5(4)
//!   Runge–Kutta method from a = [`A_START`] (g = 1, g′ = 0, i.e. D = D′ = a, plus first-order
//!   corrections, see `ode_start`) with a local error tolerance of [`ODE_TOL`] per step: 200–300 steps
//!   and a few tens of µs per call, about as for Heath's integral. The tests check it against Heath's
//!   integral to ≤ 1e-8 (measured ~1e-11).

use super::Cosmology;

/// Simpson intervals of the growth integral (integrand smooth in u = √a, so the error is ~1e-13).
const GROWTH_INTERVALS: usize = 1024;

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
type State = [f64; 2];

/// How the growing mode is computed.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum Method {
    /// Heath's integral (valid for w0 = −1, wa = 0 only).
    Heath,
    /// The growth ODE (any w0, wa).
    Ode,
}

impl Cosmology {
    /// True for a cosmological constant (w0 = −1, wa = 0), where Heath's integral is exact.
    pub(super) fn is_lambda(&self) -> bool {
        self.w0 == -1.0 && self.wa == 0.0
    }

    /// The dark-energy equation of state w(a) = w0 + wa (1 − a) (Chevallier & Polarski 2001; Linder 2003).
    pub fn w_of_a(&self, a: f64) -> f64 {
        self.w0 + self.wa * (1.0 - a)
    }

    /// Dark-energy density relative to today, ρ_DE(a)/ρ_DE(1) = a^{−3(1+w0+wa)} exp(−3 wa (1 − a)).
    fn dark_energy_density(&self, a: f64) -> f64 {
        if self.is_lambda() {
            return 1.0;
        }
        self.dark_energy_density_ln(a, a.ln())
    }

    /// [`dark_energy_density`](Self::dark_energy_density) given both a and ln a (saves a logarithm).
    fn dark_energy_density_ln(&self, a: f64, ln_a: f64) -> f64 {
        (-3.0 * (1.0 + self.w0 + self.wa) * ln_a - 3.0 * self.wa * (1.0 - a)).exp()
    }

    /// (aE)² = Ω_m/a + Ω_k + Ω_DE a² ρ_DE(a)/ρ_DE(1).
    pub(super) fn a2e2(&self, a: f64) -> f64 {
        self.omega_m / a + self.omega_k() + self.omega_lambda * a * a * self.dark_energy_density(a)
    }

    /// E(a) = H(a)/H0 = (Ω_m a⁻³ + Ω_k a⁻² + Ω_DE a^{−3(1+w0+wa)} e^{−3wa(1−a)})^½ (radiation neglected).
    ///
    /// NaN where E² < 0 (only possible for a > 1 in a valid closed model) or unless a > 0.
    pub fn e_of_a(&self, a: f64) -> f64 {
        if a.is_nan() || a <= 0.0 {
            return f64::NAN;
        }
        self.a2e2(a).sqrt() / a
    }

    /// E(z) = H(z)/H0, [`e_of_a`](Self::e_of_a) at a = 1/(1+z).
    pub fn e_of_z(&self, z: f64) -> f64 {
        self.e_of_a(1.0 / (1.0 + z))
    }

    /// Ω_m(z) = Ω_m (1+z)³ / E²(z).
    pub fn omega_m_of_z(&self, z: f64) -> f64 {
        self.omega_m * (1.0 + z).powi(3) / self.e_of_z(z).powi(2)
    }

    /// Linear growth factor D(z), normalised to D(0) = 1.
    ///
    /// Heath's integral for a cosmological constant, the growth ODE otherwise (see the module docs).
    /// Returns NaN unless z is finite and > −1.
    pub fn growth_factor(&self, z: f64) -> f64 {
        scale_factor(z).map_or(f64::NAN, |a| self.normalised_growth(a, self.method()))
    }

    /// Linear growth rate f(z) = d ln D / d ln a.
    ///
    /// Heath's integral for a cosmological constant, the growth ODE otherwise (see the module docs).
    /// Returns NaN unless z is finite and > −1.
    pub fn growth_rate(&self, z: f64) -> f64 {
        scale_factor(z).map_or(f64::NAN, |a| self.rate(a, self.method()))
    }

    /// D(z)/D(0) and f(z) together: [`growth_factor`](Self::growth_factor) and
    /// [`growth_rate`](Self::growth_rate) from one integral at z (and one at z = 0), where calling
    /// both costs three. NaN unless z is finite and > −1.
    pub fn growth_factor_and_rate(&self, z: f64) -> (f64, f64) {
        let Some(a) = scale_factor(z) else {
            return (f64::NAN, f64::NAN);
        };
        match self.method() {
            Method::Heath => {
                let integral = self.growth_integral(a);
                // At z = 0 the normalisation is the same integral (the same value, once).
                let today = if a == 1.0 {
                    self.heath_d_md_of(1.0, integral)
                } else {
                    self.heath_d_md(1.0)
                };
                (
                    self.heath_d_md_of(a, integral) / today,
                    self.heath_rate_of(a, integral),
                )
            }
            Method::Ode => {
                let [s_a, s_1] = self.ode_states([a.ln(), 0.0]);
                (a * s_a[0] / s_1[0], 1.0 + s_a[1] / s_a[0])
            }
        }
    }

    /// The growing mode normalised to D = a deep in matter domination, D_md(z), and f(z), from one
    /// integration (Heath's integral for a cosmological constant, the ODE otherwise). NaN unless z is
    /// finite and > −1.
    pub fn growth_md_and_rate(&self, z: f64) -> (f64, f64) {
        let Some(a) = scale_factor(z) else {
            return (f64::NAN, f64::NAN);
        };
        match self.method() {
            Method::Heath => {
                let integral = self.growth_integral(a);
                (
                    self.heath_d_md_of(a, integral),
                    self.heath_rate_of(a, integral),
                )
            }
            Method::Ode => {
                let [s, _] = self.ode_states([a.ln(), a.ln()]);
                (a * s[0], 1.0 + s[1] / s[0])
            }
        }
    }

    /// The method that [`growth_factor`](Self::growth_factor) and [`growth_rate`](Self::growth_rate) use.
    pub(super) fn method(&self) -> Method {
        if self.is_lambda() {
            Method::Heath
        } else {
            Method::Ode
        }
    }

    /// D(a)/D(1).
    pub(super) fn normalised_growth(&self, a: f64, method: Method) -> f64 {
        match method {
            Method::Heath => self.heath_d_md(a) / self.heath_d_md(1.0),
            Method::Ode => {
                let [s_a, s_1] = self.ode_states([a.ln(), 0.0]);
                a * s_a[0] / s_1[0]
            }
        }
    }

    /// f(a) = d ln D/d ln a.
    pub(super) fn rate(&self, a: f64, method: Method) -> f64 {
        match method {
            Method::Heath => self.heath_rate(a),
            Method::Ode => {
                let [s, _] = self.ode_states([a.ln(), a.ln()]);
                1.0 + s[1] / s[0]
            }
        }
    }

    /// The growing mode normalised to D_md = a deep in matter domination, at a.
    pub(super) fn growth_md(&self, a: f64, method: Method) -> f64 {
        match method {
            Method::Heath => self.heath_d_md(a),
            Method::Ode => a * self.ode_states([a.ln(), a.ln()])[0][0],
        }
    }

    /// I(a) = ∫_0^a da′/(a′E)³ = ∫_0^√a 2u⁴ / (Ω_m + Ω_k u² + Ω_Λ u⁶)^{3/2} du (Λ only).
    fn growth_integral(&self, a: f64) -> f64 {
        let (om, ok, ol) = (self.omega_m, self.omega_k(), self.omega_lambda);
        let integrand = |u: f64| {
            let u2 = u * u;
            2.0 * u2 * u2 / (om + ok * u2 + ol * u2 * u2 * u2).powf(1.5)
        };
        crate::linear::simpson(integrand, 0.0, a.sqrt(), GROWTH_INTERVALS).0
    }

    /// Heath's growing mode (5Ω_m/2) E(a) I(a), equal to a deep in matter domination (Λ only).
    fn heath_d_md(&self, a: f64) -> f64 {
        self.heath_d_md_of(a, self.growth_integral(a))
    }

    /// [`heath_d_md`](Self::heath_d_md) given the integral I(a).
    fn heath_d_md_of(&self, a: f64, integral: f64) -> f64 {
        2.5 * self.omega_m * self.a2e2(a).sqrt() / a * integral
    }

    /// f = −(3Ω_m a⁻³ + 2Ω_k a⁻²)/(2E²) + 1/(a²E³ I(a)) (Λ only).
    fn heath_rate(&self, a: f64) -> f64 {
        self.heath_rate_of(a, self.growth_integral(a))
    }

    /// [`heath_rate`](Self::heath_rate) given the integral I(a).
    fn heath_rate_of(&self, a: f64, integral: f64) -> f64 {
        let e2 = self.a2e2(a) / (a * a);
        let dln_e = -(3.0 * self.omega_m / a.powi(3) + 2.0 * self.omega_k() / (a * a)) / (2.0 * e2);
        dln_e + 1.0 / (a * a * e2.powf(1.5) * integral)
    }

    /// Right-hand side of the growth ODE for (g, g′), g = D/a, in x = ln a:
    /// g″ = −(5m + 6k + (5 − 3w)d)/(2E²) g′ − (4k + 3(1 − w)d)/(2E²) g, with m, k, d the matter,
    /// curvature and dark-energy terms of E² = m + k + d and w = w(a). This is the equation of the module
    /// docs with D = a g, written so that the matter-domination terms cancel exactly (no round-off as
    /// g″ → 0 for a → 0). All three terms are multiplied by a³ to stay O(1).
    fn ode_rhs(&self, x: f64, [g, dg]: State) -> State {
        let a = x.exp();
        let m = self.omega_m;
        let k = self.omega_k() * a;
        let d = self.omega_lambda * a.powi(3) * self.dark_energy_density_ln(a, x);
        let w = self.w_of_a(a);
        let two_e2 = 2.0 * (m + k + d);
        let damping = (5.0 * m + 6.0 * k + (5.0 - 3.0 * w) * d) / two_e2;
        let source = (4.0 * k + 3.0 * (1.0 - w) * d) / two_e2;
        [dg, -damping * dg - source * g]
    }

    /// (g, g′) of the growing mode at a = [`A_START`]: D = D′ = a plus the first-order corrections for
    /// curvature and dark energy. A term E²/(Ω_m a⁻³) ⊃ ε a^p (curvature: ε = Ω_k/Ω_m, p = 1; dark
    /// energy at a → 0: ε = Ω_DE e^{−3wa}/Ω_m, p = −3(w0 + wa)) changes the growing mode to
    /// g = 1 + c ε a^p with c = −(p + 3)/(p (2p + 5)), e.g. −2/11 for Λ and −4/7 for curvature. The
    /// neglected O(ε² a^{2p}) terms change D_md by < 1e-12 unless w0 + wa > −0.3.
    fn ode_start(&self) -> State {
        let terms = [
            (self.omega_k() / self.omega_m, 1.0),
            (
                self.omega_lambda * (-3.0 * self.wa).exp() / self.omega_m,
                -3.0 * (self.w0 + self.wa),
            ),
        ];
        let mut state = [1.0, 0.0];
        for (epsilon, p) in terms {
            let term = -(p + 3.0) / (p * (2.0 * p + 5.0)) * epsilon * A_START.powf(p);
            state[0] += term;
            state[1] += p * term;
        }
        state
    }

    /// (g, g′) at x = ln a for the two targets (in any order), integrating once from a = [`A_START`].
    /// NaN if the integration fails (E² ≤ 0 on the way, or a target below the start).
    fn ode_states(&self, targets: [f64; 2]) -> [State; 2] {
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
    /// updated to the next step the controller proposes.
    fn ode_integrate(&self, x0: f64, x1: f64, y: State, h: &mut f64) -> State {
        const NAN: State = [f64::NAN; 2];
        if x1.is_nan() || x0.is_nan() || x1 < x0 {
            return NAN;
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
            if err.is_nan() || y_new.iter().any(|v| !v.is_finite()) {
                return NAN;
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
        NAN
    }
}

/// One Dormand–Prince 5(4) step (Dormand & Prince 1980; Hairer, Nørsett & Wanner, Solving ODEs I,
/// Table 5.2): the 5th-order solution, the derivative there (first stage of the next step, "FSAL"),
/// and the error estimate |y5 − y4|_∞ / [`ODE_TOL`].
fn dormand_prince_step(
    f: impl Fn(f64, State) -> State,
    x: f64,
    y: State,
    k1: State,
    h: f64,
) -> (State, State, f64) {
    let at = |coefs: &[f64], ks: &[State]| -> State {
        let mut out = y;
        for (c, k) in coefs.iter().zip(ks) {
            out[0] += h * c * k[0];
            out[1] += h * c * k[1];
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
        .map(|i| (h * e.iter().zip(&ks).map(|(c, k)| c * k[i]).sum::<f64>()).abs())
        .fold(0.0, f64::max);
    (y5, k7, err / ODE_TOL)
}

/// The scale factor a = 1/(1+z) for finite z > −1.
pub(super) fn scale_factor(z: f64) -> Option<f64> {
    (z.is_finite() && z > -1.0).then(|| 1.0 / (1.0 + z))
}

#[cfg(test)]
mod tests;
