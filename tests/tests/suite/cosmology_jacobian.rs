//! The exact derivatives of the chain step with respect to the sampled cosmological parameters
//! (issue 47: `Pipeline::cosmology_jacobian`, through the emulator, the growth, the loop terms on
//! the basis, IR resummation, AP, the window and bins) against high-order finite differences of the
//! data vector with step control, at cosmologies the emulator was not trained on.

use super::pipeline::{max_abs, observation, pipeline, precision, store, PARAMS, Z};
use pt_spectra::pipeline::{Pipeline, PipelineSettings};
use pt_spectra::progress::Silent;
use std::sync::OnceLock;

/// The pipeline of [`pipeline`] without the AP distortion (no fiducial: the model on the output k).
fn without_ap() -> &'static Pipeline {
    static P: OnceLock<Pipeline> = OnceLock::new();
    P.get_or_init(|| {
        let settings = PipelineSettings::ept(Z, None);
        Pipeline::new(observation(), settings, &precision(), &store(), &Silent).unwrap()
    })
}
use pt_spectra::cosmology::background::{DERIVATIVE_NAMES, N_DERIVATIVES};
use pt_spectra::cosmology::{Amplitude, Cosmology, Neutrinos, EV_PER_OMEGA_NU};

/// The cosmology of the sampled parameters θ = (h, ω_b, ω_cdm, ln10¹⁰A_s, n_s, Σm_ν, w0, wa), flat.
fn cosmology(t: &[f64; N_DERIVATIVES]) -> Cosmology {
    let [h, omega_b, omega_cdm, ln_a, n_s, m_nu, w0, wa] = *t;
    let omega_m = (omega_b + omega_cdm + m_nu / EV_PER_OMEGA_NU) / (h * h);
    let mut c = Cosmology::planck2018();
    c.omega_m = omega_m;
    c.omega_lambda = 1.0 - omega_m;
    c.h = h;
    c.omega_b_h2 = omega_b;
    c.n_s = n_s;
    c.amplitude = Amplitude::As {
        a_s: ln_a.exp() * 1e-10,
        k_pivot: 0.05,
    };
    c.w0 = w0;
    c.wa = wa;
    c.m_nu = m_nu;
    c.neutrinos = Neutrinos::ThreeDegenerate;
    c
}

/// Steps per parameter: the largest of the control's four (6th-order central differences at h … h/8
/// reach ±3h).
const STEPS: [f64; N_DERIVATIVES] = [2e-4, 1.2e-5, 8e-5, 1.6e-3, 5e-4, 3e-4, 2e-4, 3e-4];

/// dD/dθ_j by 6th-order central differences with step control: of the steps h/2, h/4, h/8, the
/// estimate whose difference from the next coarser one is smallest, and that difference.
fn differences(
    d: &dyn Fn(&[f64; N_DERIVATIVES]) -> Vec<f64>,
    t: [f64; 8],
    j: usize,
) -> (Vec<f64>, f64) {
    let c = [-1.0, 9.0, -45.0, 0.0, 45.0, -9.0, 1.0];
    let at = |h: f64| -> Vec<f64> {
        let mut sum: Vec<f64> = Vec::new();
        for (s, c) in (-3..=3).zip(c) {
            if c == 0.0 {
                continue;
            }
            let mut u = t;
            u[j] += f64::from(s) * h;
            let v = d(&u);
            sum.resize(v.len(), 0.0);
            sum.iter_mut().zip(&v).for_each(|(a, v)| *a += c * v);
        }
        sum.iter().map(|v| v / (60.0 * h)).collect()
    };
    let estimates: Vec<Vec<f64>> = (0..4).map(|i| at(STEPS[j] / f64::from(1 << i))).collect();
    let change = |a: &[f64], b: &[f64]| {
        a.iter()
            .zip(b)
            .fold(0.0_f64, |m, (a, b)| m.max((a - b).abs()))
    };
    (0..3)
        .map(|i| {
            (
                estimates[i + 1].clone(),
                change(&estimates[i], &estimates[i + 1]),
            )
        })
        .min_by(|a, b| a.1.total_cmp(&b.1))
        .expect("three pairs")
}

/// At a ΛCDM and a w0–wa cosmology with massive neutrinos (neither a training node), and with f
/// given (then f's dependence is not in the cosmological columns), every column agrees with the
/// finite-difference estimate within 1e-6 of its largest element, with and without AP (measured
/// ≤ 1.6e-8 without AP, ≤ 7.3e-8 with, w0 ≤ 4.1e-8: the AP projection's interpolant in ln k′ is a
/// cubic B-spline, C², so differences that straddle its cell edges see no derivative jumps; with
/// the four-point Lagrange interpolant it replaced, w0 was 1.3e-6 off, docs/architecture.md); the
/// data vector is `evaluate`'s.
#[test]
fn cosmological_derivatives_equal_high_order_differences() {
    let lcdm = [0.68, 0.0224, 0.12, 3.04, 0.965, 0.06, -1.0, 0.0];
    let w0wa = [0.685, 0.0230, 0.115, 2.95, 0.975, 0.15, -0.9, -0.3];
    let with_f: Vec<(&str, f64)> = PARAMS.iter().copied().chain([("f", 0.74)]).collect();
    for (pl, with_ap, t, params) in [
        (without_ap(), false, w0wa, &PARAMS[..]),
        (pipeline(), true, lcdm, &PARAMS[..]),
        (pipeline(), true, w0wa, &PARAMS[..]),
        (pipeline(), true, w0wa, &with_f[..]),
    ] {
        let c = cosmology(&t);
        let jac = pl.cosmology_jacobian(&c, params).unwrap();
        let value = pl.evaluate(&c, params).unwrap();
        assert_eq!(jac.data_vector, value);
        assert_eq!(jac.names(), &DERIVATIVE_NAMES);
        let given_f = params.len() > PARAMS.len();
        assert_eq!(jac.growth_rate.d.iter().all(|&d| d == 0.0), given_f);
        let d = |u: &[f64; N_DERIVATIVES]| pl.evaluate(&cosmology(u), params).unwrap();
        for (j, name) in DERIVATIVE_NAMES.iter().enumerate() {
            let (fd, control) = differences(&d, t, j);
            let scale = max_abs(&fd);
            let worst = jac.cosmological[j]
                .iter()
                .zip(&fd)
                .fold(0.0_f64, |m, (a, b)| m.max((a - b).abs()))
                / scale;
            assert!(
                worst < 1e-6,
                "{name} at {t:?} (AP {with_ap}): {worst:e} (the differences' own change {:e})",
                control / scale
            );
        }
    }
}

/// σ8-normalised cosmologies and pipelines with a bispectrum block are refused with errors that
/// say what to do.
#[test]
fn the_cosmological_jacobian_refuses_what_it_cannot_differentiate() {
    let pl = pipeline();
    let sigma8 = Cosmology::flat(0.3, 0.68, 0.0224, 0.965, 0.8).unwrap();
    let e = pl
        .cosmology_jacobian(&sigma8, &PARAMS)
        .unwrap_err()
        .to_string();
    assert!(e.contains("sigma8") && e.contains("A_s"), "{e}");
}

/// The full Jacobian is the cosmological one and the step's nuisance rows (the nuisance parameters,
/// then f), from one step: the same numbers as the two calls made apart.
#[test]
fn the_full_jacobian_is_both_jacobians_of_one_step() {
    let pl = pipeline();
    let c = cosmology(&[0.68, 0.0224, 0.12, 3.04, 0.965, 0.06, -1.0, 0.0]);
    let (cosmological, nuisance) = pl.full_jacobian(&c, &PARAMS).unwrap();
    let alone = pl.cosmology_jacobian(&c, &PARAMS).unwrap();
    assert_eq!(cosmological.data_vector, alone.data_vector);
    assert_eq!(cosmological.cosmological, alone.cosmological);
    let step = pl.step(&pl.prepare(&c).unwrap()).unwrap();
    let (_, rows) = step.jacobian(&PARAMS).unwrap();
    assert_eq!(nuisance.len(), pt_spectra::pipeline::JACOBIAN_NAMES.len());
    assert_eq!(nuisance, rows);
}

/// The columns asked of `full_jacobian_of` (any subset, any order) are the full Jacobian's columns to
/// the bit, with the same data vector and nuisance rows; a name that is not sampled, or one given twice,
/// is refused by name.
#[test]
fn the_columns_asked_for_are_those_of_the_full_jacobian() {
    let pl = pipeline();
    let c = cosmology(&[0.69, 0.0223, 0.118, 3.05, 0.96, 0.1, -0.95, 0.05]);
    let (all, all_rows) = pl.full_jacobian(&c, &PARAMS).unwrap();
    assert_eq!(all.names(), &DERIVATIVE_NAMES);
    for asked in [
        vec!["h", "omega_b", "omega_cdm", "ln10^{10}A_s", "n_s"],
        vec!["wa", "h"],
        vec![],
    ] {
        let (some, rows) = pl.full_jacobian_of(&c, &PARAMS, &asked).unwrap();
        assert_eq!(some.names(), asked.as_slice());
        assert_eq!(some.data_vector, all.data_vector);
        assert_eq!(rows, all_rows);
        for (name, column) in asked.iter().zip(&some.cosmological) {
            let j = DERIVATIVE_NAMES.iter().position(|n| n == name).unwrap();
            assert_eq!(column, &all.cosmological[j], "{name}");
        }
        let alone = pl.cosmology_jacobian_of(&c, &PARAMS, &asked).unwrap();
        assert_eq!(alone.cosmological, some.cosmological);
    }
    for (asked, says) in [
        (vec!["h", "sigma8"], "`sigma8`: not a sampled parameter"),
        (vec!["h", "n_s", "h"], "`h`: asked for twice"),
    ] {
        let e = pl
            .full_jacobian_of(&c, &PARAMS, &asked)
            .unwrap_err()
            .to_string();
        assert!(e.contains(says), "{e}");
    }
}
