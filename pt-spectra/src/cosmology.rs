//! ΛCDM background, exact linear growth, and Eisenstein & Hu (1998) linear spectra.
//!
//! * Growth (radiation neglected, matter + curvature + Λ): the growing mode is Heath's (1977) integral
//!   D(a) ∝ E(a) ∫_0^a da′ / (a′E(a′))³, E = H/H0 = (Ω_m a⁻³ + Ω_k a⁻² + Ω_Λ)^½, normalised to D(z=0) = 1,
//!   and f = d ln D/d ln a = −(3Ω_m a⁻³ + 2Ω_k a⁻²)/(2E²) + 1/(a²E³ I(a)) with I the integral. The integral
//!   is done in u = √a, where the integrand 2u⁴/(Ω_m + Ω_k u² + Ω_Λ u⁶)^{3/2} is smooth, by Simpson's rule
//!   (relative error < 1e-12). Not a fitting formula.
//! * Transfer functions: Eisenstein & Hu (1998, ApJ 496, 605; astro-ph/9709112), the full fit with baryon
//!   acoustic oscillations (their §3, eqs. 2–24) and the smooth "no-wiggle" fit (§4.2, eqs. 26–31), with
//!   T_CMB = [`T_CMB_K`]. [`Cosmology::eisenstein_hu_spectrum`] turns them into P(k) = A k^{n_s} T²(k)
//!   normalised to σ8, as a [`LinearSpectrum`].
//!
//! Units: k in h/Mpc, P in (Mpc/h)^3, lengths in Mpc/h unless stated otherwise.

use crate::error::{Error, Result};
use crate::linear::{LinearSpectrum, LogGrid};
use std::f64::consts::E;

/// CMB temperature in K used by the Eisenstein & Hu transfer functions (the CAMB default).
pub const T_CMB_K: f64 = 2.7255;

/// Simpson intervals of the growth integral (integrand smooth in u = √a, so the error is ~1e-13).
const GROWTH_INTERVALS: usize = 1024;

/// Cosmological parameters of a ΛCDM model (massless neutrinos, radiation neglected in the growth).
///
/// Ω_k = 1 − Ω_m − Ω_Λ; the paper's models are flat. After changing fields, call
/// [`validate`](Self::validate).
#[derive(Debug, Clone, Copy, PartialEq)]
#[non_exhaustive]
pub struct Cosmology {
    /// Total matter density today Ω_m (CDM + baryons).
    pub omega_m: f64,
    /// Cosmological-constant density today Ω_Λ.
    pub omega_lambda: f64,
    /// Dimensionless Hubble constant h = H0 / (100 km/s/Mpc).
    pub h: f64,
    /// Physical baryon density Ω_b h².
    pub omega_b_h2: f64,
    /// Primordial spectral index n_s.
    pub n_s: f64,
    /// RMS linear density fluctuation in spheres of 8 Mpc/h at z = 0.
    pub sigma8: f64,
}

impl Default for Cosmology {
    /// [`Cosmology::gm2012`].
    fn default() -> Self {
        Self::gm2012()
    }
}

/// Which Eisenstein & Hu (1998) transfer function to use.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum TransferKind {
    /// The full fit with baryon acoustic oscillations (EH98 §3).
    Wiggle,
    /// The smooth "no-wiggle" fit with the BAO removed (EH98 §4.2, eqs. 26–31).
    NoWiggle,
}

impl Cosmology {
    /// The cosmology of Gil-Marín et al. (2012, arXiv:1209.3771): Ω_m = 0.27, Ω_Λ = 0.73, h = 0.7,
    /// Ω_b h² = 0.023, n_s = 0.95, σ8 = 0.8.
    pub const fn gm2012() -> Self {
        Self {
            omega_m: 0.27,
            omega_lambda: 0.73,
            h: 0.7,
            omega_b_h2: 0.023,
            n_s: 0.95,
            sigma8: 0.8,
        }
    }

    /// A validated cosmology.
    ///
    /// # Errors
    /// As [`validate`](Self::validate).
    pub fn new(
        omega_m: f64,
        omega_lambda: f64,
        h: f64,
        omega_b_h2: f64,
        n_s: f64,
        sigma8: f64,
    ) -> Result<Self> {
        let c = Self {
            omega_m,
            omega_lambda,
            h,
            omega_b_h2,
            n_s,
            sigma8,
        };
        c.validate()?;
        Ok(c)
    }

    /// A flat cosmology, Ω_Λ = 1 − Ω_m.
    ///
    /// # Errors
    /// As [`validate`](Self::validate).
    pub fn flat(omega_m: f64, h: f64, omega_b_h2: f64, n_s: f64, sigma8: f64) -> Result<Self> {
        Self::new(omega_m, 1.0 - omega_m, h, omega_b_h2, n_s, sigma8)
    }

    /// Checks the parameters.
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] unless all are finite, Ω_m > 0, Ω_Λ ≥ 0, h > 0,
    /// 0 < Ω_b h² < Ω_m h², σ8 > 0, and E²(a) > 0 for all 0 < a ≤ 1 (no bounce).
    pub fn validate(&self) -> Result<()> {
        let bad = |name, value, reason| {
            Err(Error::InvalidParameter {
                name,
                value,
                reason,
            })
        };
        let positive = "must be finite and positive";
        for (name, v) in [
            ("Omega_m", self.omega_m),
            ("h", self.h),
            ("sigma8", self.sigma8),
        ] {
            if !(v.is_finite() && v > 0.0) {
                return bad(name, v, positive);
            }
        }
        if !(self.omega_lambda.is_finite() && self.omega_lambda >= 0.0) {
            return bad(
                "Omega_Lambda",
                self.omega_lambda,
                "must be finite and non-negative",
            );
        }
        if !(self.omega_b_h2 > 0.0 && self.omega_b_h2 < self.omega_m * self.h * self.h) {
            return bad(
                "Omega_b h^2",
                self.omega_b_h2,
                "must be positive and below Omega_m h^2",
            );
        }
        if !self.n_s.is_finite() {
            return bad("n_s", self.n_s, "must be finite");
        }
        if (1..=1000).any(|i| self.a2e2(f64::from(i) / 1000.0) <= 0.0) {
            return bad(
                "Omega_k",
                self.omega_k(),
                "H^2 vanishes for some a <= 1 (bouncing model)",
            );
        }
        Ok(())
    }

    /// Curvature density Ω_k = 1 − Ω_m − Ω_Λ.
    pub fn omega_k(&self) -> f64 {
        1.0 - self.omega_m - self.omega_lambda
    }

    /// (aE)² = Ω_m/a + Ω_k + Ω_Λ a².
    fn a2e2(&self, a: f64) -> f64 {
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

    /// `spectrum`, given at redshift `z_in`, rescaled to redshift `z`: P × [D(z)/D(z_in)]².
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] if a redshift is not finite or ≤ −1.
    pub fn rescale(&self, spectrum: &LinearSpectrum, z_in: f64, z: f64) -> Result<LinearSpectrum> {
        for (name, v) in [("z_in", z_in), ("z", z)] {
            if !(v.is_finite() && v > -1.0) {
                let reason = "redshift must be finite and > -1";
                return Err(Error::InvalidParameter {
                    name,
                    value: v,
                    reason,
                });
            }
        }
        spectrum.scaled((self.growth_factor(z) / self.growth_factor(z_in)).powi(2))
    }

    /// Eisenstein & Hu (1998) linear spectrum P(k, z) = A k^{n_s} T²(k) D²(z) on `grid`, with A set so that
    /// σ(8 Mpc/h) = `self.sigma8` at z = 0 (top hat, [`LinearSpectrum::sigma_r`]).
    ///
    /// [`TransferKind::NoWiggle`] gives the smooth spectrum by which BAO features are divided out
    /// (P_lin/P_nw); with the same σ8 it matches the broadband of the [`TransferKind::Wiggle`] one.
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] for an invalid cosmology or redshift.
    ///
    /// ```
    /// use pt_spectra::{cosmology::{Cosmology, TransferKind}, linear::LogGrid};
    /// let p = Cosmology::gm2012().eisenstein_hu_spectrum(TransferKind::NoWiggle, 0.0, &LogGrid::default())?;
    /// assert!((p.sigma8() - 0.8).abs() < 1e-9);
    /// # Ok::<(), pt_spectra::error::Error>(())
    /// ```
    pub fn eisenstein_hu_spectrum(
        &self,
        kind: TransferKind,
        z: f64,
        grid: &LogGrid,
    ) -> Result<LinearSpectrum> {
        let eh = EisensteinHu::new(self)?;
        let shape =
            LinearSpectrum::from_fn(grid, |k| k.powf(self.n_s) * eh.transfer(kind, k).powi(2))?;
        let sigma = shape.sigma_r(8.0)?.0;
        let normalised = shape.scaled((self.sigma8 / sigma).powi(2))?;
        self.rescale(&normalised, 0.0, z)
    }
}

/// The scale factor a = 1/(1+z) for finite z > −1.
fn scale_factor(z: f64) -> Option<f64> {
    (z.is_finite() && z > -1.0).then(|| 1.0 / (1.0 + z))
}

/// Precomputed Eisenstein & Hu (1998, astro-ph/9709112) transfer-function parameters for one cosmology.
///
/// Internally k is in 1/Mpc and lengths in Mpc as in the paper; the public methods take k in h/Mpc.
#[derive(Debug, Clone, Copy)]
pub struct EisensteinHu {
    h: f64,
    omhh: f64,
    f_baryon: f64,
    theta2: f64,
    k_equality: f64,
    sound_horizon: f64,
    k_silk: f64,
    alpha_c: f64,
    beta_c: f64,
    alpha_b: f64,
    beta_b: f64,
    beta_node: f64,
    /// Approximate sound horizon of eq. 26 [Mpc], for the no-wiggle fit.
    s_approx: f64,
    alpha_gamma: f64,
}

impl EisensteinHu {
    /// Computes the fit parameters (EH98 eqs. 2–14, 21–24, 26, 31).
    ///
    /// # Errors
    /// As [`Cosmology::validate`].
    pub fn new(c: &Cosmology) -> Result<Self> {
        c.validate()?;
        let (omhh, obhh) = (c.omega_m * c.h * c.h, c.omega_b_h2);
        let f_baryon = obhh / omhh;
        let theta = T_CMB_K / 2.7;
        let theta2 = theta * theta;
        let z_equality = 2.50e4 * omhh / (theta2 * theta2);
        let k_equality = 0.0746 * omhh / theta2;
        let b1 = 0.313 * omhh.powf(-0.419) * (1.0 + 0.607 * omhh.powf(0.674));
        let b2 = 0.238 * omhh.powf(0.223);
        let z_drag = 1291.0 * omhh.powf(0.251) / (1.0 + 0.659 * omhh.powf(0.828))
            * (1.0 + b1 * obhh.powf(b2));
        let r_of = |z: f64| 31.5 * obhh / (theta2 * theta2) * (1000.0 / z);
        let (r_drag, r_equality) = (r_of(z_drag), r_of(z_equality));
        let sound_horizon = 2.0 / (3.0 * k_equality)
            * (6.0 / r_equality).sqrt()
            * (((1.0 + r_drag).sqrt() + (r_drag + r_equality).sqrt()) / (1.0 + r_equality.sqrt()))
                .ln();
        let k_silk = 1.6 * obhh.powf(0.52) * omhh.powf(0.73) * (1.0 + (10.4 * omhh).powf(-0.95));
        let a1 = (46.9 * omhh).powf(0.670) * (1.0 + (32.1 * omhh).powf(-0.532));
        let a2 = (12.0 * omhh).powf(0.424) * (1.0 + (45.0 * omhh).powf(-0.582));
        let alpha_c = a1.powf(-f_baryon) * a2.powf(-f_baryon.powi(3));
        let bc1 = 0.944 / (1.0 + (458.0 * omhh).powf(-0.708));
        let bc2 = (0.395 * omhh).powf(-0.0266);
        let beta_c = 1.0 / (1.0 + bc1 * ((1.0 - f_baryon).powf(bc2) - 1.0));
        let y = z_equality / (1.0 + z_drag);
        let sy = (1.0 + y).sqrt();
        let g = y * (-6.0 * sy + (2.0 + 3.0 * y) * ((sy + 1.0) / (sy - 1.0)).ln());
        let alpha_b = 2.07 * k_equality * sound_horizon * (1.0 + r_drag).powf(-0.75) * g;
        let beta_b = 0.5 + f_baryon + (3.0 - 2.0 * f_baryon) * ((17.2 * omhh).powi(2) + 1.0).sqrt();
        let beta_node = 8.41 * omhh.powf(0.435);
        let s_approx = 44.5 * (9.83 / omhh).ln() / (1.0 + 10.0 * obhh.powf(0.75)).sqrt();
        let alpha_gamma = 1.0 - 0.328 * (431.0 * omhh).ln() * f_baryon
            + 0.38 * (22.3 * omhh).ln() * f_baryon * f_baryon;
        Ok(Self {
            h: c.h,
            omhh,
            f_baryon,
            theta2,
            k_equality,
            sound_horizon,
            k_silk,
            alpha_c,
            beta_c,
            alpha_b,
            beta_b,
            beta_node,
            s_approx,
            alpha_gamma,
        })
    }

    /// Sound horizon at the drag epoch, EH98 eq. 6, in Mpc/h.
    pub fn sound_horizon(&self) -> f64 {
        self.sound_horizon * self.h
    }

    /// T(k) of the requested kind, k in h/Mpc.
    pub fn transfer(&self, kind: TransferKind, k: f64) -> f64 {
        match kind {
            TransferKind::Wiggle => self.transfer_wiggle(k),
            TransferKind::NoWiggle => self.transfer_no_wiggle(k),
        }
    }

    /// Full transfer function with BAO, T = f_b T_b + (1 − f_b) T_c (EH98 eqs. 16–24), k in h/Mpc.
    pub fn transfer_wiggle(&self, k_h: f64) -> f64 {
        let k = k_h * self.h;
        let q = k / (13.41 * self.k_equality);
        let ks = k * self.sound_horizon;
        let t0 = |alpha: f64, beta: f64| {
            let l = (E + 1.8 * beta * q).ln();
            let c = 14.2 / alpha + 386.0 / (1.0 + 69.9 * q.powf(1.08));
            l / (l + c * q * q)
        };
        let f = 1.0 / (1.0 + (ks / 5.4).powi(4));
        let t_c = f * t0(1.0, self.beta_c) + (1.0 - f) * t0(self.alpha_c, self.beta_c);
        let s_tilde = self.sound_horizon / (1.0 + (self.beta_node / ks).powi(3)).cbrt();
        let x = k * s_tilde;
        let j0 = if x.abs() < 1e-6 { 1.0 } else { x.sin() / x };
        let t_b = j0
            * (t0(1.0, 1.0) / (1.0 + (ks / 5.2).powi(2))
                + self.alpha_b / (1.0 + (self.beta_b / ks).powi(3))
                    * (-(k / self.k_silk).powf(1.4)).exp());
        self.f_baryon * t_b + (1.0 - self.f_baryon) * t_c
    }

    /// Smooth no-wiggle transfer function T_0(q) with Γ_eff (EH98 eqs. 26–31), k in h/Mpc.
    pub fn transfer_no_wiggle(&self, k_h: f64) -> f64 {
        let k = k_h * self.h;
        let a = self.alpha_gamma;
        let gamma_eff = self.omhh * (a + (1.0 - a) / (1.0 + (0.43 * k * self.s_approx).powi(4)));
        let q = k * self.theta2 / gamma_eff;
        let l0 = (2.0 * E + 1.8 * q).ln();
        let c0 = 14.2 + 731.0 / (1.0 + 62.5 * q);
        l0 / (l0 + c0 * q * q)
    }
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

    #[test]
    fn rescaling_follows_growth_squared() {
        let c = Cosmology::gm2012();
        let p0 = LinearSpectrum::gm2012_z0();
        let p1 = c.rescale(&p0, 0.0, 1.0).unwrap();
        let camb1 = LinearSpectrum::gm2012(1.0).unwrap();
        for k in [1e-3, 0.05, 0.2] {
            assert!(
                (p1.eval(k) / camb1.eval(k) - 1.0).abs() < 2.0 * CAMB_GROWTH_TOL,
                "k {k}"
            );
        }
        assert!(c.rescale(&p0, -1.0, 0.0).is_err());
    }

    #[test]
    fn invalid_cosmologies_are_rejected() {
        assert!(Cosmology::gm2012().validate().is_ok());
        assert!(Cosmology::flat(-0.1, 0.7, 0.02, 0.96, 0.8).is_err());
        assert!(Cosmology::flat(0.3, 0.7, 0.5, 0.96, 0.8).is_err());
        assert!(Cosmology::flat(0.3, f64::NAN, 0.02, 0.96, 0.8).is_err());
        assert!(Cosmology::new(0.1, 3.0, 0.7, 0.002, 0.96, 0.8).is_err()); // bounce
        let e = Cosmology::flat(0.3, 0.7, 0.02, 0.96, -0.8).unwrap_err();
        assert!(e.to_string().contains("sigma8 = -0.8"), "{e}");
    }

    fn ratios(kind: TransferKind) -> (LinearSpectrum, LinearSpectrum) {
        let c = Cosmology::gm2012();
        let eh = c
            .eisenstein_hu_spectrum(kind, 0.0, &LogGrid::default())
            .unwrap();
        (eh, LinearSpectrum::gm2012_z0())
    }

    #[test]
    fn eisenstein_hu_broadband_matches_camb() {
        let (nw, camb) = ratios(TransferKind::NoWiggle);
        let (w, _) = ratios(TransferKind::Wiggle);
        assert!((nw.sigma8() - 0.8).abs() < 1e-9 && (w.sigma8() - 0.8).abs() < 1e-9);
        let (mut worst_nw, mut worst_w) = (0.0_f64, 0.0_f64);
        for k in LogGrid::new(0.01, 0.3, 100).unwrap().points() {
            worst_nw = worst_nw.max((nw.eval(k) / camb.eval(k) - 1.0).abs());
            worst_w = worst_w.max((w.eval(k) / camb.eval(k) - 1.0).abs());
        }
        println!("max |P_EH/P_CAMB - 1| on 0.01-0.3: no-wiggle {worst_nw:.4}, wiggle {worst_w:.4}");
        assert!(worst_nw < 0.08, "{worst_nw}");
        assert!(worst_w < 0.05, "{worst_w}");
    }

    #[test]
    fn eisenstein_hu_wiggles_sit_at_the_bao_scale() {
        let c = Cosmology::gm2012();
        let eh = EisensteinHu::new(&c).unwrap();
        // EH98 eq. 6 sound horizon for this cosmology: ≈ 106 Mpc/h (CAMB r_drag ≈ 151 Mpc ≈ 106 Mpc/h).
        let s = eh.sound_horizon();
        assert!((s - 106.0).abs() < 3.0, "s = {s}");
        let ks = LogGrid::new(0.04, 0.35, 2000).unwrap().points();
        let r: Vec<f64> = ks
            .iter()
            .map(|&k| (eh.transfer_wiggle(k) / eh.transfer_no_wiggle(k)).powi(2))
            .collect();
        let maxima: Vec<f64> = (1..r.len() - 1)
            .filter(|&i| r[i] > r[i - 1] && r[i] > r[i + 1])
            .map(|i| ks[i])
            .collect();
        println!("wiggle/no-wiggle maxima at k = {maxima:.4?}");
        assert!(maxima.len() >= 4, "{maxima:?}");
        assert!(
            (maxima[0] - 0.07).abs() < 0.01 && (maxima[1] - 0.13).abs() < 0.01,
            "{maxima:?}"
        );
        // Successive maxima are spaced by ≈ 2π/s.
        let spacing = (maxima[3] - maxima[1]) / 2.0;
        assert!(
            (spacing * s / (2.0 * std::f64::consts::PI) - 1.0).abs() < 0.1,
            "{spacing}"
        );
    }
}
