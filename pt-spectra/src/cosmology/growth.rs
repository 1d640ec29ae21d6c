//! Background expansion E(a) and linear growth D, f (formulas and references in the [module docs](super)).
//!
//! Two paths give the growing mode, normalised to a deep in matter domination ("D_md"):
//! * ΛCDM (w0 = −1, wa = 0, any curvature): Heath's (1977) integral, exact up to the quadrature error.
//! * Otherwise: the growth ODE in x = ln a for g = D/a, integrated by an adaptive Dormand–Prince 5(4)
//!   Runge–Kutta method from a = 1e-8 (g = 1, g′ = 0, i.e. D = D′ = a, plus first-order
//!   corrections, see `ode.rs`) with a local error tolerance of 1e-11 per step: 200–300 steps
//!   and a few tens of µs per call, about as for Heath's integral. The tests check it against Heath's
//!   integral to ≤ 1e-8 (measured ~1e-11).
//!
//! Everything is written once, as methods of [`Background<T>`] over a [`Real`] T; the [`Cosmology`]
//! methods call them on [`Cosmology::background`] (`f64`, the values alone). On the [`Background`] of
//! [`Dual`](crate::dual::Dual)s that [`Cosmology::seeded`] gives, every result carries its exact
//! derivatives with respect to the sampled parameters
//! ([`DERIVATIVE_NAMES`](super::background::DERIVATIVE_NAMES)):
//! * Heath's integral: the derivative of the Simpson sum on its fixed nodes in u = √a, i.e. the
//!   integral of the integrand's derivative to the same quadrature error.
//! * The ODE: the step-size controller and the accept/reject decisions use the values alone (the
//!   error estimate's [`value`](Real::value)), so the mesh in ln a is a constant for the derivative,
//!   which is then that of the discrete Runge–Kutta solution on its mesh (the same scheme applied to
//!   the variational equations): exact up to the ODE tolerance. The tests find it equal to
//!   Richardson-extrapolated finite differences of the `f64` path to ≤ 1e-7 of its scale.
//! * The cosmological-constant shortcuts (Heath's integral, ρ_DE = 1) hold at w0 = −1, wa = 0 only,
//!   so they are taken only where both are also [constants](Real::is_constant): a [`Background`]
//!   seeded in w0 and wa takes the general formula and the ODE even at w0 = −1, wa = 0 (the ODE
//!   agrees with Heath's integral to ~1e-11) and keeps the derivatives with respect to w0 and wa.

mod ode;

use super::background::Background;
use super::Cosmology;
use crate::dual::Real;

/// Simpson intervals of the growth integral (integrand smooth in u = √a, so the error is ~1e-13).
const GROWTH_INTERVALS: usize = 1024;

/// How the growing mode is computed.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum Method {
    /// Heath's integral (valid for w0 = −1, wa = 0 only).
    Heath,
    /// The growth ODE (any w0, wa).
    Ode,
}

impl<T: Real> Background<T> {
    /// True for a constant cosmological constant: w0 = −1 and wa = 0, both without derivatives (module
    /// docs), where Heath's integral is exact and ρ_DE = 1.
    pub fn is_lambda(&self) -> bool {
        self.w0.value() == -1.0
            && self.wa.value() == 0.0
            && self.w0.is_constant()
            && self.wa.is_constant()
    }

    /// The dark-energy equation of state w(a) = w0 + wa (1 − a) (Chevallier & Polarski 2001; Linder 2003).
    pub fn w_of_a(&self, a: f64) -> T {
        self.w0 + self.wa * (1.0 - a)
    }

    /// Dark-energy density relative to today, ρ_DE(a)/ρ_DE(1) = a^{−3(1+w0+wa)} exp(−3 wa (1 − a)).
    pub fn dark_energy_density(&self, a: f64) -> T {
        if self.is_lambda() {
            return T::cst(1.0);
        }
        self.dark_energy_density_ln(a, a.ln())
    }

    /// [`dark_energy_density`](Self::dark_energy_density) given both a and ln a (saves a logarithm),
    /// without the shortcut for Λ.
    fn dark_energy_density_ln(&self, a: f64, ln_a: f64) -> T {
        ((self.w0 + 1.0 + self.wa) * -3.0 * ln_a - self.wa * 3.0 * (1.0 - a)).exp()
    }

    /// (aE)² = Ω_m/a + Ω_k + Ω_DE a² ρ_DE(a)/ρ_DE(1).
    pub fn a2e2(&self, a: f64) -> T {
        self.omega_m / a + self.omega_k + self.omega_lambda * a * a * self.dark_energy_density(a)
    }

    /// E(a) = H(a)/H0 = (Ω_m a⁻³ + Ω_k a⁻² + Ω_DE a^{−3(1+w0+wa)} e^{−3wa(1−a)})^½ (radiation neglected).
    ///
    /// NaN where E² < 0 (only possible for a > 1 in a valid closed model) or unless a > 0.
    pub fn e_of_a(&self, a: f64) -> T {
        if a.is_nan() || a <= 0.0 {
            return T::cst(f64::NAN);
        }
        self.a2e2(a).sqrt() / a
    }

    /// E(z) = H(z)/H0, [`e_of_a`](Self::e_of_a) at a = 1/(1+z).
    pub fn e_of_z(&self, z: f64) -> T {
        self.e_of_a(1.0 / (1.0 + z))
    }

    /// Ω_m(z) = Ω_m (1+z)³ / E²(z).
    pub fn omega_m_of_z(&self, z: f64) -> T {
        self.omega_m * (1.0 + z).powi(3) / self.e_of_z(z).powi(2)
    }

    /// Linear growth factor D(z), normalised to D(0) = 1 (NaN unless z is finite and > −1).
    pub fn growth_factor(&self, z: f64) -> T {
        scale_factor(z).map_or(T::cst(f64::NAN), |a| {
            self.normalised_growth(a, self.method())
        })
    }

    /// Linear growth rate f(z) = d ln D / d ln a (NaN unless z is finite and > −1).
    pub fn growth_rate(&self, z: f64) -> T {
        scale_factor(z).map_or(T::cst(f64::NAN), |a| self.rate(a, self.method()))
    }

    /// D(z)/D(0) and f(z) together, from one integral at z (and one at z = 0). NaN unless z is
    /// finite and > −1.
    pub fn growth_factor_and_rate(&self, z: f64) -> (T, T) {
        let Some(a) = scale_factor(z) else {
            return (T::cst(f64::NAN), T::cst(f64::NAN));
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
                (s_a[0] * a / s_1[0], s_a[1] / s_a[0] + 1.0)
            }
        }
    }

    /// The growing mode normalised to D = a deep in matter domination, D_md(z), and f(z), from one
    /// integration. NaN unless z is finite and > −1.
    pub fn growth_md_and_rate(&self, z: f64) -> (T, T) {
        let Some(a) = scale_factor(z) else {
            return (T::cst(f64::NAN), T::cst(f64::NAN));
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
                (s[0] * a, s[1] / s[0] + 1.0)
            }
        }
    }

    /// The method of the growth functions: Heath's integral for a constant cosmological constant
    /// ([`is_lambda`](Self::is_lambda)), the ODE otherwise.
    pub(super) fn method(&self) -> Method {
        if self.is_lambda() {
            Method::Heath
        } else {
            Method::Ode
        }
    }

    /// D(a)/D(1).
    pub(super) fn normalised_growth(&self, a: f64, method: Method) -> T {
        match method {
            Method::Heath => self.heath_d_md(a) / self.heath_d_md(1.0),
            Method::Ode => {
                let [s_a, s_1] = self.ode_states([a.ln(), 0.0]);
                s_a[0] * a / s_1[0]
            }
        }
    }

    /// f(a) = d ln D/d ln a.
    pub(super) fn rate(&self, a: f64, method: Method) -> T {
        match method {
            Method::Heath => self.heath_rate(a),
            Method::Ode => {
                let [s, _] = self.ode_states([a.ln(), a.ln()]);
                s[1] / s[0] + 1.0
            }
        }
    }

    /// The growing mode normalised to D_md = a deep in matter domination, at a.
    pub(super) fn growth_md(&self, a: f64, method: Method) -> T {
        match method {
            Method::Heath => self.heath_d_md(a),
            Method::Ode => self.ode_states([a.ln(), a.ln()])[0][0] * a,
        }
    }

    /// I(a) = ∫_0^a da′/(a′E)³ = ∫_0^√a 2u⁴ / (Ω_m + Ω_k u² + Ω_Λ u⁶)^{3/2} du (Λ only), by
    /// Simpson's rule with [`GROWTH_INTERVALS`] intervals.
    fn growth_integral(&self, a: f64) -> T {
        let (om, ok, ol) = (self.omega_m, self.omega_k, self.omega_lambda);
        let integrand = |u: f64| {
            let u2 = u * u;
            // x^{3/2} as x √x: the same number to rounding, a quarter of pow's time (the integral
            // has 1,025 nodes and the chain step evaluates it several times)
            let x = om + ok * u2 + ol * u2 * u2 * u2;
            T::cst(2.0 * u2 * u2) / (x * x.sqrt())
        };
        crate::linear::simpson(integrand, 0.0, a.sqrt(), GROWTH_INTERVALS).0
    }

    /// Heath's growing mode (5Ω_m/2) E(a) I(a), equal to a deep in matter domination (Λ only).
    fn heath_d_md(&self, a: f64) -> T {
        self.heath_d_md_of(a, self.growth_integral(a))
    }

    /// [`heath_d_md`](Self::heath_d_md) given the integral I(a).
    fn heath_d_md_of(&self, a: f64, integral: T) -> T {
        self.omega_m * 2.5 * self.a2e2(a).sqrt() / a * integral
    }

    /// f = −(3Ω_m a⁻³ + 2Ω_k a⁻²)/(2E²) + 1/(a²E³ I(a)) (Λ only).
    fn heath_rate(&self, a: f64) -> T {
        self.heath_rate_of(a, self.growth_integral(a))
    }

    /// [`heath_rate`](Self::heath_rate) given the integral I(a).
    fn heath_rate_of(&self, a: f64, integral: T) -> T {
        let e2 = self.a2e2(a) / (a * a);
        let dln_e = -(self.omega_m * 3.0 / a.powi(3) + self.omega_k * 2.0 / (a * a)) / (e2 * 2.0);
        dln_e + (e2.powf(1.5) * (a * a) * integral).recip()
    }
}

impl Cosmology {
    /// The dark-energy equation of state w(a) = w0 + wa (1 − a) (Chevallier & Polarski 2001; Linder 2003).
    pub fn w_of_a(&self, a: f64) -> f64 {
        self.background().w_of_a(a)
    }

    /// (aE)² = Ω_m/a + Ω_k + Ω_DE a² ρ_DE(a)/ρ_DE(1) (the tests').
    #[cfg(test)]
    pub(super) fn a2e2(&self, a: f64) -> f64 {
        self.background().a2e2(a)
    }

    /// E(a) = H(a)/H0 = (Ω_m a⁻³ + Ω_k a⁻² + Ω_DE a^{−3(1+w0+wa)} e^{−3wa(1−a)})^½ (radiation neglected).
    ///
    /// NaN where E² < 0 (only possible for a > 1 in a valid closed model) or unless a > 0.
    pub fn e_of_a(&self, a: f64) -> f64 {
        self.background().e_of_a(a)
    }

    /// E(z) = H(z)/H0, [`e_of_a`](Self::e_of_a) at a = 1/(1+z).
    pub fn e_of_z(&self, z: f64) -> f64 {
        self.background().e_of_z(z)
    }

    /// Ω_m(z) = Ω_m (1+z)³ / E²(z).
    pub fn omega_m_of_z(&self, z: f64) -> f64 {
        self.background().omega_m_of_z(z)
    }

    /// Linear growth factor D(z), normalised to D(0) = 1.
    ///
    /// Heath's integral for a cosmological constant, the growth ODE otherwise (see the module docs).
    /// Returns NaN unless z is finite and > −1.
    pub fn growth_factor(&self, z: f64) -> f64 {
        self.background().growth_factor(z)
    }

    /// Linear growth rate f(z) = d ln D / d ln a.
    ///
    /// Heath's integral for a cosmological constant, the growth ODE otherwise (see the module docs).
    /// Returns NaN unless z is finite and > −1.
    pub fn growth_rate(&self, z: f64) -> f64 {
        self.background().growth_rate(z)
    }

    /// D(z)/D(0) and f(z) together: [`growth_factor`](Self::growth_factor) and
    /// [`growth_rate`](Self::growth_rate) from one integral at z (and one at z = 0), where calling
    /// both costs three. NaN unless z is finite and > −1.
    pub fn growth_factor_and_rate(&self, z: f64) -> (f64, f64) {
        self.background().growth_factor_and_rate(z)
    }

    /// The growing mode normalised to D = a deep in matter domination, D_md(z), and f(z), from one
    /// integration (Heath's integral for a cosmological constant, the ODE otherwise). NaN unless z is
    /// finite and > −1.
    pub fn growth_md_and_rate(&self, z: f64) -> (f64, f64) {
        self.background().growth_md_and_rate(z)
    }

    /// The method that [`growth_factor`](Self::growth_factor) and [`growth_rate`](Self::growth_rate) use.
    pub(super) fn method(&self) -> Method {
        self.background().method()
    }

    /// D(a)/D(1) by `method` (the tests').
    #[cfg(test)]
    pub(super) fn normalised_growth(&self, a: f64, method: Method) -> f64 {
        self.background().normalised_growth(a, method)
    }

    /// f(a) = d ln D/d ln a by `method` (the tests').
    #[cfg(test)]
    pub(super) fn rate(&self, a: f64, method: Method) -> f64 {
        self.background().rate(a, method)
    }

    /// The growing mode normalised to D_md = a deep in matter domination, at a.
    pub(super) fn growth_md(&self, a: f64, method: Method) -> f64 {
        self.background().growth_md(a, method)
    }
}

/// The scale factor a = 1/(1+z) for finite z > −1.
pub(super) fn scale_factor(z: f64) -> Option<f64> {
    (z.is_finite() && z > -1.0).then(|| 1.0 / (1.0 + z))
}

#[cfg(test)]
mod tests;
