//! Eisenstein & Hu (1998) transfer functions (see the [module docs](super)).

use super::{Cosmology, T_CMB_K};
use crate::error::Result;
use std::f64::consts::E;

/// Which Eisenstein & Hu (1998) transfer function to use.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum TransferKind {
    /// The full fit with baryon acoustic oscillations (EH98 §3).
    Wiggle,
    /// The smooth "no-wiggle" fit with the BAO removed (EH98 §4.2, eqs. 26–31).
    NoWiggle,
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
    use crate::linear::LogGrid;

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
