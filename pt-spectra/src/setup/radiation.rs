//! The radiation the growth neglects ([`crate::cosmology`]: D(z) and f(z) of matter and dark energy
//! only), bounded where a spectrum is rescaled by [D(z)/D(z_input)]².
//!
//! In matter domination with radiation the growing mode is D ∝ a + (2/3) a_eq (Meszaros 1974), with
//! a_eq = Ω_r/Ω_m, where the growth here has D ∝ a. The rescaling factor [D(z)/D(z_input)]² is then off
//! by about (4/3) (Ω_r/Ω_m) |z − z_input|: 4.2e-4 per unit of z for gm2012 (Ω_r = 8.5e-5 with three
//! massless neutrinos), so 4.2% at z = 100, where CAMB was measured 3–4% away (issue 45). Near z ~ 1
//! the estimate is a bound rather than a value: CAMB's Planck 2018 spectrum at z = 1 is 1.7e-4 from the
//! z = 0 one rescaled, against 3.9e-4 estimated.

use crate::cosmology::Cosmology;
use crate::error::{Error, Result};

/// Estimated error of a rescaled spectrum above which the header and stderr warn: the 1e-3 the
/// growth is otherwise good to against CAMB (z ≳ 2.4 from z_input = 0 for gm2012).
pub const WARN_ABOVE: f64 = 1e-3;

/// Estimated error above which a rescaling is refused: a spectrum 1% off in amplitude is a wrong
/// number, not a caveat (z ≳ 24 from z_input = 0 for gm2012).
pub const REFUSE_ABOVE: f64 = 1e-2;

/// The estimated relative error of P rescaled by [D(z)/D(z_input)]² in cosmology `c`:
/// (4/3) (Ω_r/Ω_m) |z − z_input| (module docs).
pub fn rescaling_error(c: &Cosmology, z_input: f64, z: f64) -> f64 {
    4.0 / 3.0 * c.omega_radiation() / c.omega_m * (z - z_input).abs()
}

/// Checks the rescaling of `what` (a spectrum's description) from `z_input` to `z` in `c`: the
/// header's note on the radiation neglected, and a warning above [`WARN_ABOVE`].
///
/// # Errors
/// [`Error::InvalidParameter`] naming z above [`REFUSE_ABOVE`], with the largest z allowed.
pub(crate) fn check_rescaling(
    c: &Cosmology,
    what: &str,
    z_input: f64,
    z: f64,
) -> Result<(String, Option<String>)> {
    let error = rescaling_error(c, z_input, z);
    let reach = |bound: f64| bound / rescaling_error(c, 0.0, 1.0);
    if error > REFUSE_ABOVE {
        return Err(Error::InvalidChoice {
            what: format!("z = {z} for {what} given at z_input = {z_input}"),
            reason: format!(
                "the growth here neglects radiation, which puts [D(z)/D(z_input)]^2 about {error:.1e} \
                 off (Meszaros: (4/3) Omega_r/Omega_m |z - z_input|); more than {REFUSE_ABOVE:e} \
                 beyond |z - z_input| = {:.1} in this cosmology: give a linear spectrum computed at \
                 z by a Boltzmann code (with z_input = z)",
                reach(REFUSE_ABOVE)
            ),
        });
    }
    let note = format!(
        "radiation neglected in the growth: the rescaled P is about {error:.1e} off at most \
         ((4/3) Omega_r/Omega_m |z - z_input|)"
    );
    let warning = (error > WARN_ABOVE).then(|| {
        format!(
            "{what} is rescaled from z_input = {z_input} to z = {z} by a growth without radiation: \
             about {error:.1e} off (more than {WARN_ABOVE:e} beyond |z - z_input| = {:.1}); a \
             spectrum computed at z avoids it",
            reach(WARN_ABOVE)
        )
    });
    Ok((note, warning))
}

/// Checks D(z) and f(z) of `c` asked for at `z` (Python's `pt.growth`): the growth neglects
/// radiation, so D(z)/D(0) is about half of [`rescaling_error`] off (D² is rescaling_error off): a
/// warning above [`WARN_ABOVE`] for D², returned, and a refusal above [`REFUSE_ABOVE`]
/// (`pt.growth(1e6)` returned D = 1.3e-6, ~200 times below the growth with radiation, silently).
///
/// # Errors
/// [`Error::InvalidChoice`] naming z above [`REFUSE_ABOVE`], with the largest z allowed.
pub fn check_growth(c: &Cosmology, z: f64) -> Result<Option<String>> {
    check_rescaling(c, "the growth D(z), f(z) (relative to z = 0)", 0.0, z).map(|(_, w)| w)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Issue 45: the growth far in z (radiation neglected) is refused, warned about in between.
    #[test]
    fn the_growth_far_in_z_is_refused_or_warned_about() {
        let c = Cosmology::gm2012();
        assert!(check_growth(&c, 1.0).unwrap().is_none());
        assert!(check_growth(&c, 5.0)
            .unwrap()
            .unwrap()
            .contains("radiation"));
        let e = check_growth(&c, 1e6).unwrap_err().to_string();
        assert!(e.contains("z = 1000000") && e.contains("radiation"), "{e}");
    }

    /// gm2012: Ω_r h² = 2.47e-5 (photons, T = 2.7255 K) × 1.6918 (3.046 massless neutrinos) =
    /// 4.18e-5, so Ω_r/Ω_m = 4.18e-5/(0.49 × 0.27) = 3.16e-4 and 4.2e-4 per unit of z: 4.2% at
    /// z = 100 (CAMB: 3–4%), the warning from |Δz| = 2.4, the refusal from 24.
    #[test]
    fn the_bound_is_the_meszaros_offset() {
        let c = Cosmology::gm2012();
        let per_z = rescaling_error(&c, 0.0, 1.0);
        assert!((per_z / 4.21e-4 - 1.0).abs() < 0.01, "{per_z:e}");
        assert!((rescaling_error(&c, 1.0, 101.0) - 100.0 * per_z).abs() < 1e-15);
        let (note, warning) = check_rescaling(&c, "P", 0.0, 2.0).unwrap();
        assert!(note.contains("8.4e-4"), "{note}");
        assert!(warning.is_none());
        let (_, warning) = check_rescaling(&c, "P", 0.0, 3.0).unwrap();
        let warning = warning.unwrap();
        assert!(
            warning.contains("1.3e-3") && warning.contains("|z - z_input| = 2.4"),
            "{warning}"
        );
        let e = check_rescaling(&c, "P", 0.0, 100.0)
            .unwrap_err()
            .to_string();
        assert!(
            e.starts_with("z = 100 for P given at z_input = 0:")
                && e.contains("4.2e-2")
                && e.contains("|z - z_input| = 23.7"),
            "{e}"
        );
    }
}
