use super::*;
use crate::cosmology::background::DERIVATIVE_NAMES;
use crate::cosmology::finite_difference::{sampled, with_sampled, VALUE_TOL};
use crate::cosmology::Amplitude;
use crate::emulator::RATIO_TAPER;
use crate::setup::{prepare_with_emulator, LinearSource, NamedCosmology, Request};

/// The agreement asked of the derivatives with the finite differences, relative to each derivative's
/// largest |value| over the tested k (issue 47).
const FD_TOL: f64 = 1e-6;

/// Wavenumbers [h/Mpc] at which P(k) is differentiated: below the nodes (k_min ≈ 1.1e-4 for
/// r_d ≈ 100 Mpc/h), across them, and above them (k_max ≈ 8.8).
const KS: [f64; 17] = [
    2e-5, 1e-4, 1e-3, 3e-3, 0.01, 0.02, 0.05, 0.1, 0.15, 0.2, 0.3, 0.5, 1.0, 2.0, 5.0, 20.0, 100.0,
];

/// A cosmology of the emulator's prior that is not a training node: h = 0.69, ω_b = 0.0223,
/// ω_cdm = 0.118, A_s = 2.1e-9, n_s = 0.965 with Σm_ν [eV], w0, wa.
fn cosmology(m_nu: f64, w0: f64, wa: f64) -> Cosmology {
    let ln_10_a_s = (1e10 * 2.1e-9_f64).ln();
    let p = [0.69, 0.0223, 0.118, ln_10_a_s, 0.965, m_nu, w0, wa];
    let c = with_sampled(&Cosmology::planck2018(), p);
    c.validate().unwrap();
    c
}

/// The tested cosmologies: Λ with Σm_ν = 0.06; w0–wa with 0.15; massless; and Σm_ν = 0.003, where
/// the massless head is tapered in.
fn cosmologies() -> [(&'static str, Cosmology); 4] {
    [
        ("m_nu = 0.06, Lambda", cosmology(0.06, -1.0, 0.0)),
        (
            "m_nu = 0.15, w0 = -0.9, wa = -0.2",
            cosmology(0.15, -0.9, -0.2),
        ),
        ("m_nu = 0, Lambda", cosmology(0.0, -1.0, 0.0)),
        (
            "m_nu = 0.003, w0 = -1.05, wa = 0.1",
            cosmology(0.003, -1.05, 0.1),
        ),
    ]
}

/// What the pipeline takes from the emulator ([`prepare_with_emulator`]): the tracer spectrum at
/// `ks`, then the growth rate.
fn pipeline(emulator: &LinearEmulator, cosmology: Cosmology, z: f64, ks: &[f64]) -> Vec<f64> {
    let request = Request {
        source: LinearSource::Emulator,
        cosmology: Some(NamedCosmology {
            name: "tested".into(),
            cosmology,
        }),
        z,
    };
    let p = prepare_with_emulator(request, Some(emulator)).unwrap();
    let mut out: Vec<f64> = ks.iter().map(|&k| p.tracer_spectrum().eval(k)).collect();
    out.push(p.growth_rate);
    out
}

/// `cosmology` with its sampled parameter `j` ([`DERIVATIVE_NAMES`]) moved by `delta`, the others
/// held ([`with_sampled`]: Ω_m = (ω_b + ω_cdm + Σm_ν/93.14 eV)/h², Ω_DE = 1 − Ω_m − Ω_k,
/// A_s = e^{ln(10¹⁰A_s)}/10¹⁰).
fn moved(cosmology: &Cosmology, j: usize, delta: f64) -> Cosmology {
    let mut v = sampled(cosmology);
    v[j] += delta;
    with_sampled(cosmology, v)
}

/// The derivative at 0 of each component of `f` by Ridders' method: the differences (central, or
/// forward if `one_sided`) at steps `delta`, `delta`/1.4, … (ten), extrapolated to step 0 in a
/// Neville tableau (the error in powers of the step squared for central differences, of the step
/// for forward ones); per component the entry whose estimated error (the change from its neighbours)
/// is smallest, until the tableau's diagonal departs from it by twice that (noise). Returns
/// (derivative, estimated error) per component.
fn ridders(f: impl Fn(f64) -> Vec<f64>, delta: f64, one_sided: bool) -> Vec<(f64, f64)> {
    const SHRINK: f64 = 1.4;
    const LEVELS: usize = 10;
    const SAFE: f64 = 2.0;
    let at_zero = one_sided.then(|| f(0.0));
    let difference = |h: f64| -> Vec<f64> {
        let up = f(h);
        let (down, width) = match &at_zero {
            Some(f0) => (f0.clone(), h),
            None => (f(-h), 2.0 * h),
        };
        up.iter().zip(&down).map(|(u, d)| (u - d) / width).collect()
    };
    let power = if one_sided { SHRINK } else { SHRINK * SHRINK };
    let mut previous = vec![difference(delta)];
    let n = previous[0].len();
    let mut best = vec![(f64::NAN, f64::INFINITY); n];
    let mut done = vec![false; n];
    let mut h = delta;
    for level in 1..LEVELS {
        h /= SHRINK;
        let mut row = vec![difference(h)];
        let mut factor = power;
        for j in 1..=level {
            let next: Vec<f64> = (0..n)
                .map(|c| (row[j - 1][c] * factor - previous[j - 1][c]) / (factor - 1.0))
                .collect();
            factor *= if one_sided { SHRINK } else { SHRINK * SHRINK };
            for c in (0..n).filter(|&c| !done[c]) {
                let error = (next[c] - row[j - 1][c])
                    .abs()
                    .max((next[c] - previous[j - 1][c]).abs());
                if error <= best[c].1 {
                    best[c] = (next[c], error);
                }
            }
            row.push(next);
        }
        for c in 0..n {
            done[c] |= (row[level][c] - previous[level - 1][c]).abs() >= SAFE * best[c].1;
        }
        previous = row;
    }
    best
}

/// The first step of each parameter's differences (the smallest is 20 times smaller): for h, ω_b,
/// ω_cdm, which move r_d and so the nodes across a fixed k, small enough that the nodes move by
/// ≲ 3e-3 in ln k (the interpolant is a cubic spline: its third derivative jumps at the nodes).
const STEPS: [f64; N_DERIVATIVES] = [0.002, 4e-4, 2e-3, 0.1, 0.02, 0.01, 0.02, 0.04];

/// Σm_ν's first step where the massless head is tapered in (Σm_ν < 0.005; at Σm_ν = 0 too, stepping
/// forward): the steps stay inside, away from the taper's kink.
const TAPER_STEP: f64 = 1e-3;

/// The derivatives of the tracer spectrum at fixed k (inside, below and above the nodes) and of the
/// growth rate, for each of the eight parameters, agree with Richardson-extrapolated differences of
/// the whole f64 path (setup with the emulator) to [`FD_TOL`] of each derivative's largest value
/// over the k, at four cosmologies and two redshifts. At Σm_ν = 0 the Σm_ν derivative of P is
/// one-sided (forward differences: Σm_ν ≥ 0), and that of f is not tested: f jumps there from the
/// background's f to the emulated f_cb(0.1) (module docs).
#[test]
fn derivatives_agree_with_richardson_differences_of_the_pipeline() {
    let emulator = LinearEmulator::embedded().unwrap();
    // worst |Δ| / max |derivative| per parameter, over cosmologies and redshifts: of P, of f
    let mut worst = [[0.0f64; 2]; N_DERIVATIVES];
    for (name, c) in cosmologies() {
        for z in [0.5, 1.0] {
            let tangent = emulator.tracer_tangent(&c, z).unwrap();
            let exact = tangent.eval_many(&KS);
            let f = tangent.growth_rate();
            for j in 0..N_DERIVATIVES {
                let massless = c.m_nu == 0.0 && j == 5;
                let step = if j == 5 && c.m_nu < RATIO_TAPER {
                    TAPER_STEP
                } else {
                    STEPS[j]
                };
                let fd = ridders(
                    |d| pipeline(&emulator, moved(&c, j, d), z, &KS),
                    step,
                    massless,
                );
                let scale = fd[..KS.len()].iter().map(|v| v.0.abs()).fold(0.0, f64::max);
                for (i, (e, (d, _))) in exact.iter().zip(&fd).enumerate() {
                    let rel = (e.d[j] - d).abs() / scale;
                    worst[j][0] = worst[j][0].max(rel);
                    assert!(
                        rel <= FD_TOL,
                        "{name}, z = {z}, d/d{}, k = {}: {} vs {d} ({rel:.1e} of {scale:.3e})",
                        DERIVATIVE_NAMES[j],
                        KS[i],
                        e.d[j]
                    );
                }
                if massless {
                    continue;
                }
                let (d, _) = fd[KS.len()];
                let rel = (f.d[j] - d).abs() / d.abs().max(1e-12);
                worst[j][1] = worst[j][1].max(rel);
                assert!(
                    rel <= FD_TOL,
                    "{name}, z = {z}, df/d{}: {} vs {d} ({rel:.1e})",
                    DERIVATIVE_NAMES[j],
                    f.d[j]
                );
            }
        }
    }
    for (name, [p, f]) in DERIVATIVE_NAMES.iter().zip(worst) {
        eprintln!("d/d{name}: P(k) {p:.1e}, f {f:.1e}");
    }
}

/// The spectrum is the pipeline's tracer spectrum bit for bit, and the growth rate's value its f.
#[test]
fn spectrum_and_growth_rate_are_those_of_prepare() {
    let emulator = LinearEmulator::embedded().unwrap();
    for (name, c) in cosmologies() {
        for z in [0.5, 1.0] {
            let t = emulator.tracer_tangent(&c, z).unwrap();
            let request = Request {
                source: LinearSource::Emulator,
                cosmology: Some(NamedCosmology {
                    name: name.into(),
                    cosmology: c,
                }),
                z,
            };
            let p = prepare_with_emulator(request, Some(&emulator)).unwrap();
            assert_eq!(t.spectrum().nodes(), p.tracer_spectrum().nodes(), "{name}");
            for k in KS {
                assert_eq!(t.eval(k).v, p.tracer_spectrum().eval(k), "{name}, k = {k}");
            }
            assert_eq!(t.growth_rate().v, p.growth_rate, "{name}");
        }
    }
}

/// P ∝ A_s (k h/k_pivot)^{n_s − 1} at fixed k, with nothing else depending on them (r_d neither):
/// ∂ ln P/∂ ln(10¹⁰A_s) = 1 and ∂ ln P/∂n_s = ln(k h/k_pivot) exactly, in the tails too (the tail
/// slopes are fitted to the nodes' ln P, linear in ln k here); f does not depend on them.
#[test]
fn amplitude_and_tilt_derivatives_are_exact() {
    let emulator = LinearEmulator::embedded().unwrap();
    for (name, c) in cosmologies() {
        let t = emulator.tracer_tangent(&c, 0.5).unwrap();
        for (k, p) in KS.iter().zip(t.eval_many(&KS)) {
            let tilt = (k * c.h / Amplitude::DEFAULT_K_PIVOT).ln();
            assert!((p.d[3] / p.v - 1.0).abs() < 1e-12, "{name}, k = {k}");
            assert!((p.d[4] / p.v - tilt).abs() < 1e-10, "{name}, k = {k}");
        }
        assert_eq!(t.growth_rate().d[3..5], [0.0, 0.0], "{name}");
    }
}

/// The one implementation over `T`: its values on [`CosmoDual`] are those on f64, to [`VALUE_TOL`]
/// (rounding, and the growth ODE that the duals take at w0 = −1, wa = 0 against Heath's integral).
#[test]
fn the_computation_on_duals_has_the_values_of_that_on_f64() {
    let emulator = LinearEmulator::embedded().unwrap();
    for (name, c) in cosmologies() {
        let values = emulator.nodes(&c, &c.background(), 0.7).unwrap();
        let duals = emulator.nodes(&c, &c.seeded().unwrap(), 0.7).unwrap();
        let close = |a: &[f64], b: &[CosmoDual]| {
            a.iter()
                .zip(b)
                .all(|(a, b)| (a - b.v).abs() <= VALUE_TOL * a.abs().max(1.0))
        };
        assert!(close(&values.ln_p_cb, &duals.ln_p_cb), "{name}");
        assert!(close(&values.ln_ratio, &duals.ln_ratio), "{name}");
        assert!(close(&values.f_cb, &duals.f_cb), "{name}");
        assert!(close(&[values.ln_r_d], &[duals.ln_r_d]), "{name}");
        assert_eq!(values.k, duals.k, "{name}");
    }
}

/// A cosmology normalised by σ8, or outside the prior, is an error naming why.
#[test]
fn sigma8_and_parameters_outside_the_prior_are_errors() {
    let emulator = LinearEmulator::embedded().unwrap();
    let e = emulator
        .tracer_tangent(&Cosmology::gm2012(), 0.5)
        .unwrap_err();
    assert!(e.to_string().contains("sigma8"), "{e}");
    let far = cosmology(0.6, -1.0, 0.0);
    let e = emulator.tracer_tangent(&far, 0.5).unwrap_err();
    assert!(e.to_string().contains("m_nu = 0.6"), "{e}");
    let e = emulator
        .tracer_tangent(&cosmology(0.06, -1.0, 0.0), 3.5)
        .unwrap_err();
    assert!(e.to_string().contains("z = 3.5"), "{e}");
}
