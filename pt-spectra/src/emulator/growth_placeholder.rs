//! TEMPORARY PLACEHOLDER, to be deleted when branch `cosmo-bg` (the growth over [`Real`]) is merged:
//! the growth of a [`Background`] from [`Cosmology`]'s f64 growth, its derivatives by fourth-order
//! central differences in Ω_m, Ω_DE, w0 and wa (to ~1e-8, not exact), chained to the parameters'
//! derivatives. The signatures are those `cosmo-bg` provides.

use crate::cosmology::background::Background;
use crate::cosmology::{Amplitude, Cosmology};
use crate::dual::Real;

impl<T: Real> Background<T> {
    /// PLACEHOLDER: (D_md(z), f(z)), derivatives by differences.
    pub fn growth_md_and_rate(&self, z: f64) -> (T, T) {
        self.placeholder_growth(|c| c.growth_md_and_rate(z))
    }

    /// PLACEHOLDER: (D(z)/D(0), f(z)), derivatives by differences.
    pub fn growth_factor_and_rate(&self, z: f64) -> (T, T) {
        self.placeholder_growth(|c| c.growth_factor_and_rate(z))
    }

    /// `growth` of the values, with the chain rule through Ω_m, Ω_DE, w0, wa (none for f64).
    fn placeholder_growth(&self, growth: impl Fn(&Cosmology) -> (f64, f64)) -> (T, T) {
        let c = Cosmology {
            omega_m: self.omega_m.value(),
            omega_lambda: self.omega_lambda.value(),
            h: self.h.value(),
            omega_b_h2: self.omega_b_h2.value(),
            n_s: self.n_s.value(),
            amplitude: Amplitude::Sigma8(0.8),
            w0: self.w0.value(),
            wa: self.wa.value(),
            m_nu: self.m_nu.value(),
            neutrinos: self.neutrinos,
        };
        let (d, f) = growth(&c);
        let (mut d_t, mut f_t) = (T::cst(d), T::cst(f));
        if std::any::type_name::<T>() == "f64" {
            return (d_t, f_t);
        }
        let inputs = [self.omega_m, self.omega_lambda, self.w0, self.wa];
        for (p, x) in inputs.into_iter().enumerate() {
            let at = |delta: f64| {
                let mut m = c;
                match p {
                    0 => m.omega_m += delta,
                    1 => m.omega_lambda += delta,
                    2 => m.w0 += delta,
                    _ => m.wa += delta,
                }
                growth(&m)
            };
            let h = 1e-3;
            let (a, b, e, g) = (at(2.0 * h), at(h), at(-h), at(-2.0 * h));
            let partial =
                |s: fn((f64, f64)) -> f64| (-s(a) + 8.0 * s(b) - 8.0 * s(e) + s(g)) / (12.0 * h);
            let dx = x - x.value();
            d_t += dx * partial(|v| v.0);
            f_t += dx * partial(|v| v.1);
        }
        (d_t, f_t)
    }
}
