//! Background distances for the Alcock–Paczynski effect: H(z), the comoving distance D_C(z), the
//! transverse comoving distance D_M(z) and D_A(z) = D_M/(1 + z), with radiation.
//!
//! E²(z) = Ω_r(1+z)⁴ + Ω_m(1+z)³ + Ω_k(1+z)² + (Ω_DE − Ω_r) ρ_DE(z)/ρ_DE(0): the radiation of the CMB
//! photons (T_CMB = [`T_CMB`]) and of [`N_EFF`] massless neutrinos, Ω_r h² = 4.18e-5, is taken from the
//! dark energy so that E(0) = 1 with the cosmology's Ω_m and Ω_k, as CAMB and CLASS close the budget.
//! With massive neutrinos (`m_nu > 0`) the three degenerate species are matter, part of Ω_m, and the
//! photons are the only radiation: at z ≤ 3 CAMB's H and D_M are then matched to 2e-5. (The growth,
//! `crate::cosmology::growth`, neglects radiation: its effect on D(z) is ~1e-4 and is
//! common to the models.) Without radiation H(z = 3) would be off by 5.7e-4 and D_M by 2.5e-4; with it,
//! the tests find CAMB's H and D_M to ≤ 1e-7. Distances are in Mpc/h and H in h km/s/Mpc, the units
//! in which an AP analysis compares two cosmologies (k in h/Mpc of each).
//!
//! Written once, as methods of [`Background<T>`] over a [`Real`] T, which the [`Cosmology`] methods
//! call on [`Cosmology::background`]; on [`Cosmology::seeded`] they give the exact derivatives with
//! respect to the sampled parameters (the quadrature's nodes are fixed, so the derivative of D_C is
//! the same Gauss–Legendre sum of the derivative of 1/E). The neutrinos' switch between radiation
//! and matter is taken on the value of Σm_ν: at Σm_ν = 0 the derivative with respect to Σm_ν is that
//! of the massless branch (all neutrinos radiation), the only one defined there.

use super::background::Background;
use super::Cosmology;
use crate::dual::Real;
use crate::integrate::GaussLegendre;

/// The 16-point Gauss–Legendre rule of each panel of the comoving distance's integral (its nodes
/// are constants: made once per process, not at every distance of a chain step).
static PANEL_RULE: std::sync::LazyLock<GaussLegendre> =
    std::sync::LazyLock::new(|| GaussLegendre::new(16));

/// The CMB temperature today \[K\] (Fixsen 2009).
pub const T_CMB: f64 = 2.7255;
/// The effective number of neutrino species, all massless.
pub const N_EFF: f64 = 3.046;
/// c / (100 km/s) \[Mpc\]: the Hubble distance c/H0 in Mpc/h.
pub const HUBBLE_DISTANCE: f64 = 2_997.924_58;

/// The photon density Ω_γ h² at [`T_CMB`]: (π²/15) (k_B T)⁴/(ħ³c⁵) / ρ_crit,100 with
/// ρ_crit,100 = 3 (100 km/s/Mpc)²/(8πG).
fn omega_gamma_h2() -> f64 {
    let (k_b, hbar, c, g): (f64, f64, f64, f64) = (
        1.380_649e-23,
        1.054_571_817e-34,
        299_792_458.0,
        6.674_30e-11,
    );
    let mpc = 3.085_677_581_491_367e22;
    let rho_gamma =
        std::f64::consts::PI.powi(2) / 15.0 * (k_b * T_CMB).powi(4) / (hbar.powi(3) * c.powi(5));
    let h100 = 1e5 / mpc;
    let rho_crit = 3.0 * h100 * h100 / (8.0 * std::f64::consts::PI * g);
    rho_gamma / rho_crit
}

impl<T: Real> Background<T> {
    /// The radiation density Ω_r = Ω_γ (1 + (7/8)(4/11)^{4/3} N_eff) of photons at [`T_CMB`] and
    /// [`N_EFF`] massless neutrinos; Ω_γ alone with massive neutrinos (module docs; the switch is
    /// taken on the value of Σm_ν).
    pub fn omega_radiation(&self) -> T {
        let neutrinos = if self.m_nu.value() > 0.0 {
            1.0
        } else {
            1.0 + 7.0 / 8.0 * (4.0_f64 / 11.0).powf(4.0 / 3.0) * N_EFF
        };
        T::cst(omega_gamma_h2() * neutrinos) / (self.h * self.h)
    }

    /// E(z) = H(z)/H0 with radiation (module docs).
    pub fn e_of_z_with_radiation(&self, z: f64) -> T {
        self.e_with_radiation(z, self.omega_radiation())
    }

    /// [`e_of_z_with_radiation`](Self::e_of_z_with_radiation) given Ω_r (computed once per
    /// distance).
    fn e_with_radiation(&self, z: f64, o_r: T) -> T {
        let a = 1.0 / (1.0 + z);
        let x = 1.0 + z;
        let de = self.omega_lambda - o_r;
        let rho_de = self.dark_energy_density(a);
        (o_r * x.powi(4) + self.omega_m * x.powi(3) + self.omega_k * x * x + de * rho_de).sqrt()
    }

    /// H(z) [h km/s/Mpc] = 100 E(z).
    pub fn hubble(&self, z: f64) -> T {
        self.e_of_z_with_radiation(z) * 100.0
    }

    /// The line-of-sight comoving distance D_C(z) = (c/H0) ∫_0^z dz'/E(z') [Mpc/h] (Gauss–Legendre,
    /// 16 nodes on panels of at most 0.05 in z: ≲ 1e-13 relative); 0 unless z is finite and > 0.
    pub fn comoving_distance(&self, z: f64) -> T {
        if !(z.is_finite() && z > 0.0) {
            return T::cst(0.0);
        }
        let o_r = self.omega_radiation();
        let panels = ((z / 0.05).ceil() as usize).max(1);
        let rule = &*PANEL_RULE;
        let width = z / panels as f64;
        let mut integral = T::cst(0.0);
        for i in 0..panels {
            let (a, b) = (i as f64 * width, (i + 1) as f64 * width);
            let mut panel = T::cst(0.0);
            for (x, w) in rule.on(a, b) {
                panel += T::cst(w) / self.e_with_radiation(x, o_r);
            }
            integral += panel;
        }
        integral * HUBBLE_DISTANCE
    }

    /// The transverse comoving distance D_M(z) [Mpc/h] (= D_C flat; sinh or sin of √|Ω_k| D_C H0/c
    /// curved).
    pub fn transverse_comoving_distance(&self, z: f64) -> T {
        let d = self.comoving_distance(z);
        let ok = self.omega_k;
        if ok.value().abs() < 1e-12 {
            return d;
        }
        if ok.value() > 0.0 {
            let s = ok.sqrt() / HUBBLE_DISTANCE;
            (s * d).sinh() / s
        } else {
            let s = (-ok).sqrt() / HUBBLE_DISTANCE;
            (s * d).sin() / s
        }
    }

    /// The angular-diameter distance D_A(z) = D_M(z)/(1 + z) [Mpc/h].
    pub fn angular_diameter_distance(&self, z: f64) -> T {
        self.transverse_comoving_distance(z) / (1.0 + z)
    }
}

impl Cosmology {
    /// The radiation density Ω_r = Ω_γ (1 + (7/8)(4/11)^{4/3} N_eff) of photons at [`T_CMB`] and
    /// [`N_EFF`] massless neutrinos; Ω_γ alone with massive neutrinos (module docs).
    pub fn omega_radiation(&self) -> f64 {
        self.background().omega_radiation()
    }

    /// E(z) = H(z)/H0 with radiation (module docs).
    pub fn e_of_z_with_radiation(&self, z: f64) -> f64 {
        self.background().e_of_z_with_radiation(z)
    }

    /// H(z) [h km/s/Mpc] = 100 E(z).
    pub fn hubble(&self, z: f64) -> f64 {
        self.background().hubble(z)
    }

    /// The line-of-sight comoving distance D_C(z) = (c/H0) ∫_0^z dz'/E(z') [Mpc/h] (Gauss–Legendre,
    /// 16 nodes on panels of at most 0.05 in z: ≲ 1e-13 relative).
    pub fn comoving_distance(&self, z: f64) -> f64 {
        self.background().comoving_distance(z)
    }

    /// The transverse comoving distance D_M(z) [Mpc/h] (= D_C flat; sinh or sin of √|Ω_k| D_C H0/c
    /// curved).
    pub fn transverse_comoving_distance(&self, z: f64) -> f64 {
        self.background().transverse_comoving_distance(z)
    }

    /// The angular-diameter distance D_A(z) = D_M(z)/(1 + z) [Mpc/h].
    pub fn angular_diameter_distance(&self, z: f64) -> f64 {
        self.background().angular_diameter_distance(z)
    }
}

#[cfg(test)]
mod tests;
