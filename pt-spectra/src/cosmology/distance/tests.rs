use super::*;
use crate::cosmology::finite_difference::{check_derivatives, derivative_cosmologies};

/// The exact (dual) derivatives of E(z) with radiation, H(z) and D_M(z) with respect to the eight
/// sampled parameters against Richardson-extrapolated finite differences of the `f64` path, at ΛCDM,
/// w0–wa, open (sinh), closed (sin) and massless-neutrino cosmologies (`finite_difference`). At
/// Σm_ν = 0 the Σm_ν derivative is not checked: a finite difference from above crosses the
/// neutrinos' switch from radiation to matter (module docs), a jump in Ω_r.
#[test]
fn dual_distance_derivatives_match_finite_differences() {
    for (label, c) in derivative_cosmologies() {
        check_derivatives(
            label,
            &c,
            &["E_r", "H", "D_M", "D_A"],
            |b, z| {
                vec![
                    b.e_of_z_with_radiation(z),
                    b.hubble(z),
                    b.transverse_comoving_distance(z),
                    b.angular_diameter_distance(z),
                ]
            },
            |c, z| {
                vec![
                    c.e_of_z_with_radiation(z),
                    c.hubble(z),
                    c.transverse_comoving_distance(z),
                    c.angular_diameter_distance(z),
                ]
            },
            true,
        );
    }
}

/// Ω_r ∝ 1/h², and only h carries a derivative (Σm_ν switches it by its value alone).
#[test]
fn radiation_density_derivative() {
    let c = Cosmology::planck2018().with_neutrinos(0.06).unwrap();
    let o_r = c.seeded().unwrap().omega_radiation();
    assert!((o_r.v / c.omega_radiation() - 1.0).abs() < 1e-15);
    assert!((o_r.d[0] / (-2.0 * c.omega_radiation() / c.h) - 1.0).abs() < 1e-14);
    assert!(o_r.d[1..].iter().all(|&d| d == 0.0));
}
