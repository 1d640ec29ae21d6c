//! Derived parameters of a galaxy fit: fσ8, σ8(z), α_iso, α_AP, D_M/D_H and D_V/r_d, with errors
//! propagated linearly from the free parameters' errors and the correlations of their covariance.
//!
//! With the template cosmology (the linear spectrum's, its distances D_M^t, D_H^t = c/H^t(z)) and the
//! measurement's distortion at the start α∥⁰ = H^fid/H^t, α⊥⁰ = D_M^t/D_M^fid, the fitted α∥, α⊥
//! (relative to the fiducial the data were measured in) give D_H = α∥ D_H^fid = (α∥/α∥⁰) D_H^t and
//! D_M = (α⊥/α⊥⁰) D_M^t; D_V = (z D_M² D_H)^{1/3}; the BAO of the template scale with its r_d, so
//! D_V/r_d = D_V/r_d^t. α_iso = α∥^{1/3} α⊥^{2/3} and α_AP = α∥/α⊥ (the fiducial's coordinates).
//! r_d^t: the fitting formula of Aubourg et al. 2015 (eq. 16; 0.02% of CAMB for standard N_eff),
//! r_d = 55.154 exp[−72.3 (ω_ν + 0.0006)²] / (ω_cb^0.25351 ω_b^0.12807) Mpc.

use super::{GalaxyFit, GalaxyFitRequest};
use crate::cosmology::{Cosmology, EV_PER_OMEGA_NU, HUBBLE_DISTANCE_MPC_H};

/// What the derived parameters need besides the fit: the template.
#[derive(Debug, Clone, PartialEq)]
pub struct Template {
    /// σ8 of the template's linear matter spectrum at the fit redshift.
    pub sigma8_z: f64,
    /// The fit redshift.
    pub z: f64,
    /// The template cosmology (distances and r_d), if known.
    pub cosmology: Option<Cosmology>,
}

/// A derived parameter.
#[derive(Debug, Clone, PartialEq)]
pub struct Derived {
    /// Its column name (`fsigma8`, `sigma8_z`, `alpha_iso`, `alpha_ap`, `DM_over_DH`, `DV_over_rd`).
    pub name: &'static str,
    /// Its value.
    pub value: f64,
    /// Its 1σ error (0 where every parameter it depends on is fixed).
    pub error: f64,
}

/// The sound horizon at the drag epoch r_d [Mpc/h] of `c` (Aubourg et al. 2015, eq. 16; module docs).
pub fn sound_horizon(c: &Cosmology) -> f64 {
    let h2 = c.h * c.h;
    let omega_nu = c.m_nu / EV_PER_OMEGA_NU;
    let omega_cb = c.omega_m * h2 - omega_nu;
    55.154 * (-72.3 * (omega_nu + 0.0006).powi(2)).exp()
        / (omega_cb.powf(0.25351) * c.omega_b_h2.powf(0.12807))
        * c.h
}

/// The derived parameters of `fit` (of `request`) with `template`: fσ8 and σ8(z) always; with a
/// distortion α_iso, α_AP, and with the template cosmology D_M/D_H and D_V/r_d.
pub fn derived(fit: &GalaxyFit, request: &GalaxyFitRequest, template: &Template) -> Vec<Derived> {
    // The free parameters' covariance with the given errors on its diagonal (the profile's where the
    // likelihood is not Gaussian) and the Hessian's correlations.
    let position = |name: &str| request.free.iter().position(|n| n == name);
    let cov = |a: usize, b: usize| -> f64 {
        let (ea, eb) = (fit.errors[a], fit.errors[b]);
        if a == b {
            return ea * eb;
        }
        match &fit.covariance {
            Some(c) => c[a][b] / (c[a][a] * c[b][b]).sqrt() * ea * eb,
            None => 0.0,
        }
    };
    // σ of a function of (f, α∥, α⊥) with gradient `g`.
    let error = |g: [f64; 3]| -> f64 {
        let ids: Vec<(Option<usize>, f64)> = ["f", "apar", "aperp"]
            .iter()
            .map(|n| position(n))
            .zip(g)
            .collect();
        let mut v = 0.0;
        for &(a, ga) in &ids {
            for &(b, gb) in &ids {
                if let (Some(a), Some(b)) = (a, b) {
                    v += ga * gb * cov(a, b);
                }
            }
        }
        v.max(0.0).sqrt()
    };
    let f = fit.best.f();
    let s8 = template.sigma8_z;
    let mut out = vec![
        Derived {
            name: "fsigma8",
            value: f * s8,
            error: error([s8, 0.0, 0.0]),
        },
        Derived {
            name: "sigma8_z",
            value: s8,
            error: 0.0,
        },
    ];
    let (Some(d), Some(d0)) = (fit.ap, request.ap) else {
        return out;
    };
    let (a, p) = (d.apar, d.aperp);
    let iso = a.powf(1.0 / 3.0) * p.powf(2.0 / 3.0);
    let iso_gradient = [0.0, iso / (3.0 * a), 2.0 * iso / (3.0 * p)];
    out.push(Derived {
        name: "alpha_iso",
        value: iso,
        error: error(iso_gradient),
    });
    out.push(Derived {
        name: "alpha_ap",
        value: a / p,
        error: error([0.0, 1.0 / p, -a / (p * p)]),
    });
    if let Some(c) = &template.cosmology {
        let z = template.z;
        let d_h = HUBBLE_DISTANCE_MPC_H * 100.0 / c.hubble(z) * a / d0.apar;
        let d_m = c.transverse_comoving_distance(z) * p / d0.aperp;
        let ratio = d_m / d_h;
        out.push(Derived {
            name: "DM_over_DH",
            value: ratio,
            error: error([0.0, -ratio / a, ratio / p]),
        });
        let d_v = (z * d_m * d_m * d_h).cbrt() / sound_horizon(c);
        out.push(Derived {
            name: "DV_over_rd",
            value: d_v,
            error: error(iso_gradient.map(|g| g * d_v / iso)),
        });
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    /// r_d of Planck 2018 (TT,TE,EE+lowE+lensing: ω_b = 0.02237, ω_c = 0.1200, h = 0.6736, one
    /// neutrino of 0.06 eV): 147.09 ± 0.26 Mpc published (Planck 2018 VI, table 2; CAMB's r_drag),
    /// which the formula gives to its stated 0.02% (+ the rounding of the published parameters).
    #[test]
    fn sound_horizon_of_planck_2018() {
        let mut c = Cosmology::planck2018();
        c.h = 0.6736;
        c.omega_b_h2 = 0.02237;
        c.m_nu = 0.06;
        c.omega_m = (0.1200 + 0.02237 + 0.06 / EV_PER_OMEGA_NU) / (0.6736 * 0.6736);
        let r_d = sound_horizon(&c) / c.h;
        assert!((r_d / 147.09 - 1.0).abs() < 1e-3, "{r_d}");
    }
}
