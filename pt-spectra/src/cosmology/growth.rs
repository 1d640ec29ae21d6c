//! Linear growth D(z) and f(z): Heath's (1977) integral (see the [module docs](super)).

use super::Cosmology;

/// Simpson intervals of the growth integral (integrand smooth in u = √a, so the error is ~1e-13).
const GROWTH_INTERVALS: usize = 1024;

impl Cosmology {
    /// (aE)² = Ω_m/a + Ω_k + Ω_Λ a².
    pub(super) fn a2e2(&self, a: f64) -> f64 {
        self.omega_m / a + self.omega_k() + self.omega_lambda * a * a
    }

    /// E(z) = H(z)/H0 = (Ω_m (1+z)³ + Ω_k (1+z)² + Ω_Λ)^½ (radiation neglected).
    pub fn e_of_z(&self, z: f64) -> f64 {
        let a = 1.0 / (1.0 + z);
        self.a2e2(a).sqrt() / a
    }

    /// Ω_m(z) = Ω_m (1+z)³ / E²(z).
    pub fn omega_m_of_z(&self, z: f64) -> f64 {
        self.omega_m * (1.0 + z).powi(3) / self.e_of_z(z).powi(2)
    }

    /// I(a) = ∫_0^a da′/(a′E)³ = ∫_0^√a 2u⁴ / (Ω_m + Ω_k u² + Ω_Λ u⁶)^{3/2} du.
    fn growth_integral(&self, a: f64) -> f64 {
        let (om, ok, ol) = (self.omega_m, self.omega_k(), self.omega_lambda);
        let integrand = |u: f64| {
            let u2 = u * u;
            2.0 * u2 * u2 / (om + ok * u2 + ol * u2 * u2 * u2).powf(1.5)
        };
        crate::linear::simpson(integrand, 0.0, a.sqrt(), GROWTH_INTERVALS).0
    }

    /// Unnormalised growing mode (5Ω_m/2) E(a) I(a), equal to a deep in matter domination.
    fn growth_unnormalised(&self, a: f64) -> f64 {
        2.5 * self.omega_m * self.a2e2(a).sqrt() / a * self.growth_integral(a)
    }

    /// Linear growth factor D(z), normalised to D(0) = 1 (Heath integral, see the module docs).
    ///
    /// Returns NaN unless z is finite and > −1.
    pub fn growth_factor(&self, z: f64) -> f64 {
        let Some(a) = scale_factor(z) else {
            return f64::NAN;
        };
        self.growth_unnormalised(a) / self.growth_unnormalised(1.0)
    }

    /// Linear growth rate f(z) = d ln D / d ln a = −(3Ω_m a⁻³ + 2Ω_k a⁻²)/(2E²) + 1/(a²E³ I(a)).
    ///
    /// Returns NaN unless z is finite and > −1.
    pub fn growth_rate(&self, z: f64) -> f64 {
        let Some(a) = scale_factor(z) else {
            return f64::NAN;
        };
        let e2 = self.a2e2(a) / (a * a);
        let dln_e = -(3.0 * self.omega_m / a.powi(3) + 2.0 * self.omega_k() / (a * a)) / (2.0 * e2);
        dln_e + 1.0 / (a * a * e2.powf(1.5) * self.growth_integral(a))
    }
}

/// The scale factor a = 1/(1+z) for finite z > −1.
fn scale_factor(z: f64) -> Option<f64> {
    (z.is_finite() && z > -1.0).then(|| 1.0 / (1.0 + z))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// CAMB 2.0.5 values from the headers of `data/linear_pk_gm2012_z*.dat`: (z, σ8(z), f(z)).
    const CAMB: [(f64, f64, f64); 4] = [
        (0.0, 0.800000, 0.483135),
        (0.5, 0.625851, 0.723472),
        (1.0, 0.498294, 0.852382),
        (1.5, 0.408845, 0.916082),
    ];
    /// CAMB includes radiation and scale-dependent baryon effects that the ΛCDM growth integral neglects.
    const CAMB_GROWTH_TOL: f64 = 1e-3;
    /// Simpson error of the growth integral (≈ 1.5e-12 in EdS, where the integrand is 2u⁴).
    const QUADRATURE_TOL: f64 = 1e-10;
    /// Truncation error h²f'''/6 of a centred difference with h = 1e-4 in ln a.
    const FINITE_DIFFERENCE_TOL: f64 = 1e-7;

    #[test]
    fn growth_matches_camb() {
        let c = Cosmology::gm2012();
        for (z, s8, f_camb) in CAMB {
            let d_camb = s8 / 0.8;
            let (d, f) = (c.growth_factor(z), c.growth_rate(z));
            println!(
                "z = {z}: D = {d:.6} (CAMB {d_camb:.6}, {:+.1e}), f = {f:.6} (CAMB {f_camb}, {:+.1e})",
                d / d_camb - 1.0,
                f / f_camb - 1.0
            );
            assert!((d / d_camb - 1.0).abs() < CAMB_GROWTH_TOL, "D({z}) = {d}");
            assert!((f / f_camb - 1.0).abs() < CAMB_GROWTH_TOL, "f({z}) = {f}");
        }
    }

    /// Flat ΛCDM closed form D ∝ a ₂F₁(1/3, 1; 11/6; −a³Ω_Λ/Ω_m), evaluated after the Pfaff
    /// transformation ₂F₁(a,b;c;x) = (1−x)^−b ₂F₁(c−a, b; c; x/(x−1)), whose series converges for x < 0.
    fn growth_hypergeometric(omega_m: f64, a: f64) -> f64 {
        let x = -a.powi(3) * (1.0 - omega_m) / omega_m;
        let w = x / (x - 1.0);
        let (mut term, mut sum) = (1.0, 1.0);
        for n in 0..2000 {
            let n = f64::from(n);
            term *= (1.5 + n) / (11.0 / 6.0 + n) * w;
            sum += term;
        }
        a * sum / (1.0 - x)
    }

    #[test]
    fn growth_matches_hypergeometric_closed_form() {
        for om in [0.27, 0.5, 0.05] {
            let c = Cosmology::flat(om, 0.7, 0.02, 0.96, 0.8).unwrap();
            for z in [0.0, 0.3, 1.0, 3.0, 20.0] {
                let a = 1.0 / (1.0 + z);
                let exact = growth_hypergeometric(om, a) / growth_hypergeometric(om, 1.0);
                assert!(
                    (c.growth_factor(z) / exact - 1.0).abs() < QUADRATURE_TOL,
                    "om {om} z {z}"
                );
                // f against a centred finite difference of the closed form in ln a.
                let h = 1e-4;
                let lnd = |la: f64| growth_hypergeometric(om, la.exp()).ln();
                let f_fd = (lnd(a.ln() + h) - lnd(a.ln() - h)) / (2.0 * h);
                assert!(
                    (c.growth_rate(z) / f_fd - 1.0).abs() < FINITE_DIFFERENCE_TOL,
                    "om {om} z {z}"
                );
            }
        }
    }

    #[test]
    fn einstein_de_sitter_and_open_limits() {
        let eds = Cosmology::new(1.0, 0.0, 0.7, 0.02, 1.0, 0.8).unwrap();
        for z in [0.0, 0.5, 2.0, 10.0] {
            let (d, f) = (eds.growth_factor(z), eds.growth_rate(z));
            println!(
                "EdS z = {z}: D(1+z) - 1 = {:.1e}, f - 1 = {:.1e}",
                d * (1.0 + z) - 1.0,
                f - 1.0
            );
            assert!((d * (1.0 + z) - 1.0).abs() < QUADRATURE_TOL);
            assert!((f - 1.0).abs() < QUADRATURE_TOL);
        }
        // Open, Λ = 0: f(z=0) ≈ Ω_m^0.6 (Peebles 1980) to ~1%.
        let open = Cosmology::new(0.3, 0.0, 0.7, 0.02, 1.0, 0.8).unwrap();
        assert!((open.growth_rate(0.0) / 0.3f64.powf(0.6) - 1.0).abs() < 0.02);
        assert!(eds.growth_factor(-1.0).is_nan() && eds.growth_rate(f64::NAN).is_nan());
    }
}
