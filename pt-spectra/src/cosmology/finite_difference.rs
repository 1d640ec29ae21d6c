//! Test support (compiled for the tests only): finite-difference derivatives of the `f64`
//! cosmology with respect to the sampled parameters [`DERIVATIVE_NAMES`], the reference against
//! which the tests of the growth, the distances and the Alcock–Paczynski parameters check the exact
//! [`Dual`](crate::dual::Dual) derivatives of [`Cosmology::seeded`].
//!
//! A derivative is a Richardson extrapolation of central differences over the steps δ, δ/2, δ/4
//! (error O(δ⁶); forward differences, O(δ³), where a parameter sits on the boundary Σm_ν = 0), for
//! each of the base steps δ of [`BASE_STEPS`], keeping per output the one whose estimated error
//! |R₂ − R₁| is the smallest.

use super::background::{Background, CosmoDual, DERIVATIVE_NAMES, N_DERIVATIVES};
use super::{Amplitude, Cosmology, EV_PER_OMEGA_NU};
use crate::dual::Real;

/// Largest |dual − finite difference| of a derivative relative to its scale, the largest
/// |derivative| of the quantity over [`REDSHIFTS`] (the ODE's global error, ~1e-11, over the
/// smallest finite-difference step, ~1e-4 of a parameter's scale, is ~1e-7 at worst).
pub(crate) const DERIVATIVE_TOL: f64 = 1e-7;

/// Largest relative |dual value − `f64` value|: the same formulas up to rounding, or the ODE (which
/// the duals take even at w0 = −1, wa = 0) against Heath's integral (~1e-11).
pub(crate) const VALUE_TOL: f64 = 1e-9;

/// The redshifts at which the derivatives are compared.
pub(crate) const REDSHIFTS: [f64; 3] = [0.5, 1.0, 2.0];

/// The scale of each sampled parameter ([`DERIVATIVE_NAMES`]) of which the steps are fractions. Σm_ν
/// enters through ω_ν = Σm_ν/93.14 eV, so the quantities vary on a scale of eVs.
const PARAMETER_SCALES: [f64; N_DERIVATIVES] = [0.7, 0.02, 0.1, 3.0, 1.0, 1.0, 1.0, 1.0];

/// The base steps δ as fractions of [`PARAMETER_SCALES`] (each with δ/2 and δ/4).
const BASE_STEPS: [f64; 4] = [3e-2, 1e-2, 3e-3, 1e-3];

/// The index of Σm_ν in [`DERIVATIVE_NAMES`].
const M_NU: usize = 5;

/// The sampled parameters of `c` in the order of [`DERIVATIVE_NAMES`]: h, ω_b, ω_cdm,
/// ln(10¹⁰A_s), n_s, Σm_ν [eV], w0, wa.
///
/// # Panics
/// For a cosmology normalised by σ8.
pub(crate) fn sampled(c: &Cosmology) -> [f64; N_DERIVATIVES] {
    let Amplitude::As { a_s, .. } = c.amplitude else {
        panic!("the derivative tests need a cosmology normalised by A_s")
    };
    let omega_cdm = c.omega_m * c.h * c.h - c.omega_b_h2 - c.omega_nu();
    [
        c.h,
        c.omega_b_h2,
        omega_cdm,
        (1e10 * a_s).ln(),
        c.n_s,
        c.m_nu,
        c.w0,
        c.wa,
    ]
}

/// `c` with the sampled parameters `p` ([`sampled`]), Ω_k, the pivot and the neutrino species held:
/// Ω_m = (ω_b + ω_cdm + Σm_ν/93.14 eV)/h², Ω_DE = 1 − Ω_m − Ω_k, A_s = e^{ln(10¹⁰A_s)}/10¹⁰.
///
/// # Panics
/// For a cosmology normalised by σ8.
pub(crate) fn with_sampled(c: &Cosmology, p: [f64; N_DERIVATIVES]) -> Cosmology {
    let [h, omega_b, omega_cdm, ln_a_s, n_s, m_nu, w0, wa] = p;
    let Amplitude::As { k_pivot, .. } = c.amplitude else {
        panic!("the derivative tests need a cosmology normalised by A_s")
    };
    let omega_m = (omega_b + omega_cdm + m_nu / EV_PER_OMEGA_NU) / (h * h);
    Cosmology {
        omega_m,
        omega_lambda: 1.0 - omega_m - c.omega_k(),
        h,
        omega_b_h2: omega_b,
        n_s,
        amplitude: Amplitude::As {
            a_s: ln_a_s.exp() / 1e10,
            k_pivot,
        },
        w0,
        wa,
        m_nu,
        neutrinos: c.neutrinos,
    }
}

/// The cosmologies of the derivative tests: ΛCDM (Planck 2018 with Σm_ν = 0.06 eV), w0 = −0.9,
/// wa = −0.3 with Σm_ν = 0.1 eV, open (Ω_k = 0.02) and closed (Ω_k = −0.02, with w0 = −1.1,
/// wa = 0.2) ΛCDM, and Planck 2018 itself, Σm_ν = 0 exactly.
pub(crate) fn derivative_cosmologies() -> [(&'static str, Cosmology); 5] {
    let planck = Cosmology::planck2018();
    let lcdm = planck.with_neutrinos(0.06).unwrap();
    let curved = |omega_k: f64| {
        let c = Cosmology {
            omega_lambda: lcdm.omega_lambda - omega_k,
            ..lcdm
        };
        c.validate().unwrap();
        c
    };
    [
        ("LCDM, m_nu 0.06", lcdm),
        (
            "w0 -0.9, wa -0.3, m_nu 0.1",
            planck
                .with_neutrinos(0.1)
                .unwrap()
                .with_dark_energy(-0.9, -0.3)
                .unwrap(),
        ),
        ("open LCDM, Omega_k 0.02", curved(0.02)),
        (
            "closed, Omega_k -0.02, w0 -1.1, wa 0.2",
            curved(-0.02).with_dark_energy(-1.1, 0.2).unwrap(),
        ),
        ("LCDM, m_nu 0 exactly", planck),
    ]
}

/// The derivative of each output of `f` with respect to the sampled parameter `j` of `c` (module
/// docs), one-sided (forward) if `one_sided`.
fn finite_difference(
    c: &Cosmology,
    j: usize,
    one_sided: bool,
    f: &impl Fn(&Cosmology) -> Vec<f64>,
) -> Vec<f64> {
    let p0 = sampled(c);
    let at = |delta: f64| {
        let mut p = p0;
        p[j] += delta;
        f(&with_sampled(c, p))
    };
    let centre = one_sided.then(|| at(0.0));
    let difference = |delta: f64| -> Vec<f64> {
        let plus = at(delta);
        let (minus, width) = match &centre {
            Some(centre) => (centre.clone(), delta),
            None => (at(-delta), 2.0 * delta),
        };
        plus.iter()
            .zip(&minus)
            .map(|(a, b)| (a - b) / width)
            .collect()
    };
    // The leading error terms fall by 2^p per halving: p = 2, 4 (central), 1, 2 (forward).
    let (k1, k2) = if one_sided { (2.0, 4.0) } else { (4.0, 16.0) };
    let mut best: Vec<(f64, f64)> = Vec::new();
    for step in BASE_STEPS {
        let delta = step * PARAMETER_SCALES[j];
        let d = [
            difference(delta),
            difference(delta / 2.0),
            difference(delta / 4.0),
        ];
        best.resize(d[0].len(), (f64::NAN, f64::INFINITY));
        for (i, best) in best.iter_mut().enumerate() {
            let r1 = (k1 * d[1][i] - d[0][i]) / (k1 - 1.0);
            let r1_half = (k1 * d[2][i] - d[1][i]) / (k1 - 1.0);
            let r2 = (k2 * r1_half - r1) / (k2 - 1.0);
            let error = (r2 - r1_half).abs();
            if error < best.1 {
                *best = (r2, error);
            }
        }
    }
    best.into_iter().map(|(d, _)| d).collect()
}

/// Checks the dual derivatives of the quantities `names` of `c` against finite differences, for
/// every sampled parameter at every one of [`REDSHIFTS`]: `dual(b, z)` and `value(c, z)` give the
/// quantities at z from the seeded background and from a cosmology. The dual values must equal the
/// `f64` ones to [`VALUE_TOL`], and each derivative the finite difference to [`DERIVATIVE_TOL`] of its
/// scale. At Σm_ν = 0 the Σm_ν derivative is one-sided from above, or skipped if `neutrino_switch`
/// (quantities with radiation, whose neutrinos turn from radiation into matter at Σm_ν > 0, so that
/// the derivative from above is not that of the massless model). Returns the worst relative
/// difference of each quantity.
pub(crate) fn check_derivatives(
    label: &str,
    c: &Cosmology,
    names: &[&str],
    dual: impl Fn(&Background<CosmoDual>, f64) -> Vec<CosmoDual>,
    value: impl Fn(&Cosmology, f64) -> Vec<f64>,
    neutrino_switch: bool,
) -> Vec<f64> {
    let n = names.len();
    let all = |c: &Cosmology| -> Vec<f64> { REDSHIFTS.iter().flat_map(|&z| value(c, z)).collect() };
    let seeded = c.seeded().unwrap();
    let duals: Vec<CosmoDual> = REDSHIFTS.iter().flat_map(|&z| dual(&seeded, z)).collect();
    for (i, (d, v)) in duals.iter().zip(all(c)).enumerate() {
        let difference = (d.value() / v - 1.0).abs();
        let (q, z) = (names[i % n], REDSHIFTS[i / n]);
        assert!(
            difference <= VALUE_TOL,
            "{label}: {q}({z}) dual {} vs f64 {v}",
            d.value()
        );
    }
    let mut worst = vec![(0.0_f64, ""); n];
    let mut failures = Vec::new();
    for (j, parameter) in DERIVATIVE_NAMES.iter().enumerate() {
        let boundary = j == M_NU && c.m_nu == 0.0;
        if boundary && neutrino_switch {
            continue;
        }
        let fd = finite_difference(c, j, boundary, &all);
        for (q, name) in names.iter().enumerate() {
            let pairs: Vec<(f64, f64)> = (0..REDSHIFTS.len())
                .map(|iz| (duals[iz * n + q].d[j], fd[iz * n + q]))
                .collect();
            let scale = pairs
                .iter()
                .fold(0.0_f64, |s, (d, f)| s.max(d.abs()).max(f.abs()));
            for (iz, (d, f)) in pairs.iter().enumerate() {
                let difference = if scale == 0.0 {
                    0.0
                } else {
                    (d - f).abs() / scale
                };
                if difference.is_nan() || difference > DERIVATIVE_TOL {
                    failures.push(format!(
                        "{label}: d{name}({})/d{parameter} dual {d:e}, finite difference {f:e} \
                         (scale {scale:e}): {difference:.1e}",
                        REDSHIFTS[iz]
                    ));
                }
                if difference > worst[q].0 {
                    worst[q] = (difference, parameter);
                }
            }
        }
    }
    for (name, (w, parameter)) in names.iter().zip(&worst) {
        println!("{label}: d{name}: worst |dual - finite difference|/scale {w:.1e} ({parameter})");
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
    worst.into_iter().map(|(w, _)| w).collect()
}
