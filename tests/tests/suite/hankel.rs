//! FFTLog Hankel transforms (`pt_spectra::hankel`) against closed forms and direct quadrature.
//!
//! Conventions (module docs): ξ_ℓ = σ_ℓ ∫ k² dk/(2π²) P_ℓ j_ℓ(ks), P_ℓ = 4π σ_ℓ ∫ s² ds ξ_ℓ j_ℓ(ks), with
//! σ_ℓ = (−1)^⌊ℓ/2⌋ (= i^ℓ for even ℓ; for odd ℓ the real p_ℓ = iP_ℓ is transformed).

use pt_spectra::hankel::{
    pk_from_xi, xi_from_pk, xi_from_pk_with, Direction, HankelOptions, HankelPlan, MAX_ELL,
};
use pt_spectra::linear::LinearSpectrum;
use std::f64::consts::PI;

fn sign(ell: usize) -> f64 {
    if (ell / 2).is_multiple_of(2) {
        1.0
    } else {
        -1.0
    }
}

/// n log-spaced points from a to b.
fn logspace(a: f64, b: f64, n: usize) -> Vec<f64> {
    (0..n)
        .map(|i| a * (b / a).powf(i as f64 / (n - 1) as f64))
        .collect()
}

/// The largest |got − expected| over max |expected|.
fn worst(got: &[f64], expected: &[f64]) -> f64 {
    let peak = expected.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    let diff = got
        .iter()
        .zip(expected)
        .fold(0.0f64, |m, (a, b)| m.max((a - b).abs()));
    diff / peak
}

/// P_ℓ = k^ℓ e^{−k²R²/2}  ⇔  ξ_ℓ = σ_ℓ √(π/2) s^ℓ e^{−s²/(2R²)} / (2π² R^{2ℓ+3}), since
/// ∫_0^∞ k^{ℓ+2} e^{−k²R²/2} j_ℓ(ks) dk = √(π/2) s^ℓ e^{−s²/(2R²)}/R^{2ℓ+3} (from
/// ∫ e^{−ak²} k^{ν+1} J_ν(bk) dk = b^ν e^{−b²/4a}/(2a)^{ν+1}, ν = ℓ + 1/2).
fn gaussian_pk(ell: usize, r: f64, k: f64) -> f64 {
    k.powi(ell as i32) * (-0.5 * k * k * r * r).exp()
}

fn gaussian_xi(ell: usize, r: f64, s: f64) -> f64 {
    sign(ell) * (PI / 2.0).sqrt() / (2.0 * PI * PI)
        * s.powi(ell as i32)
        * (-0.5 * s * s / (r * r)).exp()
        / r.powi(2 * ell as i32 + 3)
}

/// A non-uniform k grid [h/Mpc]: 40 log-spaced points 1e-4..0.01, then steps of 0.002 up to 0.4.
fn mixed_k_grid() -> Vec<f64> {
    let mut k = logspace(1e-4, 0.01, 40);
    k.extend((1..=195).map(|i| 0.01 + 0.002 * i as f64));
    k
}

#[test]
fn gaussian_pairs_for_every_ell() {
    let s: Vec<f64> = (10..=200).map(f64::from).collect();
    let k_grid = mixed_k_grid();
    for r in [25.0, 50.0] {
        for ell in 0..=MAX_ELL {
            let expected: Vec<f64> = s.iter().map(|&s| gaussian_xi(ell, r, s)).collect();
            // The bare plan on a log-uniform grid (no extension: k^{3−q}P = k^{1.5+ℓ}e^{−k²R²/2} is
            // negligible at its ends), read at its own output points.
            let plan = HankelPlan::new(1e-7, 10.0, 2048, ell, Direction::PkToXi, 1.5).unwrap();
            let p: Vec<f64> = plan
                .input_grid()
                .iter()
                .map(|&k| gaussian_pk(ell, r, k))
                .collect();
            let xi = plan.transform(&p).unwrap();
            let (grid_s, grid_xi): (Vec<f64>, Vec<f64>) = plan
                .output_grid()
                .into_iter()
                .zip(xi)
                .filter(|(s, _)| (10.0..=200.0).contains(s))
                .unzip();
            let exact: Vec<f64> = grid_s.iter().map(|&s| gaussian_xi(ell, r, s)).collect();
            let bare = worst(&grid_xi, &exact);
            // The convenience function on the non-uniform grid (resampling, extension, interpolation).
            let p: Vec<f64> = k_grid.iter().map(|&k| gaussian_pk(ell, r, k)).collect();
            let convenient = worst(&xi_from_pk(&k_grid, &p, ell, &s).unwrap(), &expected);
            // And back: ξ_ℓ on 0.5 ≤ s ≤ 1000 Mpc/h in steps of 0.5 to P_ℓ on 1e-3 ≤ k ≤ 0.2 h/Mpc.
            let s_in: Vec<f64> = (1..=2000).map(|i| 0.5 * i as f64).collect();
            let xi_in: Vec<f64> = s_in.iter().map(|&s| gaussian_xi(ell, r, s)).collect();
            let k_out = logspace(1e-3, 0.2, 200);
            let p_exact: Vec<f64> = k_out.iter().map(|&k| gaussian_pk(ell, r, k)).collect();
            let back = worst(&pk_from_xi(&s_in, &xi_in, ell, &k_out).unwrap(), &p_exact);
            println!(
                "Gaussian R = {r} Mpc/h, ℓ = {ell}: worst |Δξ|/max|ξ| over 10..200 Mpc/h: plan {bare:.1e}, \
                 xi_from_pk {convenient:.1e}; pk_from_xi |ΔP|/max|P| {back:.1e}"
            );
            assert!(
                bare < 1e-5 && convenient < 1e-5 && back < 1e-5,
                "R={r} ℓ={ell}"
            );
        }
    }
}

#[test]
fn power_laws_match_their_gamma_function_constants() {
    // P = k^n ⇒ ξ_ℓ = σ_ℓ U_ℓ(3 + n) s^{−3−n}/(2π²), U_ℓ(z) = √π 2^{z−2} Γ((ℓ+z)/2)/Γ((ℓ+3−z)/2):
    // U_ℓ(3/2) = √(π/2) for every ℓ, U_0(1) = π/2, U_0(1.8) = √π 2^{−0.2} Γ(0.9)/Γ(0.6).
    let k = logspace(1e-4, 100.0, 300);
    let s: Vec<f64> = logspace(1.0, 1000.0, 50);
    let gamma_09_over_06 = 1.068_628_702_119_319 / 1.489_192_248_812_817;
    let mut cases: Vec<(usize, f64, f64)> = (0..=MAX_ELL)
        .map(|ell| (ell, -1.5, sign(ell) * (PI / 2.0).sqrt()))
        .collect();
    cases.push((0, -2.0, PI / 2.0));
    cases.push((0, -1.2, PI.sqrt() * 2f64.powf(-0.2) * gamma_09_over_06));
    for (ell, n, u) in cases {
        let p: Vec<f64> = k.iter().map(|k| k.powf(n)).collect();
        let options = HankelOptions {
            q: 3.0 + n,
            ..HankelOptions::default()
        };
        let xi = xi_from_pk_with(&k, &p, ell, &s, &options).unwrap();
        let expected: Vec<f64> = s
            .iter()
            .map(|s| u * s.powf(-3.0 - n) / (2.0 * PI * PI))
            .collect();
        let rel = xi
            .iter()
            .zip(&expected)
            .fold(0.0f64, |m, (a, b)| m.max((a / b - 1.0).abs()));
        println!("P = k^{n}, ℓ = {ell}: worst relative error of ξ over 1..1000 Mpc/h {rel:.1e}");
        assert!(rel < 1e-9, "n={n} ℓ={ell}: {rel:e}");
    }
}

/// j_0 and j_2, with their series where the closed forms cancel.
fn j(ell: usize, x: f64) -> f64 {
    let x2 = x * x;
    match (ell, x < 0.1) {
        (0, true) => 1.0 - x2 / 6.0 + x2 * x2 / 120.0,
        (0, false) => x.sin() / x,
        (_, true) => x2 / 15.0 - x2 * x2 / 210.0 + x2 * x2 * x2 / 7560.0,
        (_, false) => (3.0 / x2 - 1.0) * x.sin() / x - 3.0 * x.cos() / x2,
    }
}

#[test]
fn realistic_spectrum_against_direct_quadrature() {
    // ξ_ℓ of P_lin(k) e^{−k²} (gm2012, z = 0), by Simpson's rule on 0 ≤ k ≤ 8 h/Mpc with 400000 steps
    // (the oscillation of j_ℓ(ks) at s = 200 Mpc/h has 60 steps per period).
    let lin = LinearSpectrum::gm2012(0.0).unwrap();
    let (k, p) = lin.nodes();
    let s = [
        10.0, 20.0, 35.0, 50.0, 75.0, 100.0, 105.0, 110.0, 150.0, 200.0,
    ];
    let options = HankelOptions {
        k_damp: Some(1.0),
        ..HankelOptions::default()
    };
    let steps = 400_000;
    let h = 8.0 / steps as f64;
    let integrand: Vec<f64> = (0..=steps)
        .map(|i| {
            let k = h * i as f64;
            let w = if i == 0 || i == steps {
                1.0
            } else if i % 2 == 1 {
                4.0
            } else {
                2.0
            };
            w * h / 3.0 * k * k * lin.eval(k) * (-k * k).exp() / (2.0 * PI * PI)
        })
        .collect();
    for ell in [0, 2] {
        let fftlog = xi_from_pk_with(k, p, ell, &s, &options).unwrap();
        let direct: Vec<f64> = s
            .iter()
            .map(|&s| {
                let sum: f64 = integrand
                    .iter()
                    .enumerate()
                    .map(|(i, w)| w * j(ell, h * i as f64 * s))
                    .sum();
                sign(ell) * sum
            })
            .collect();
        let err = worst(&fftlog, &direct);
        println!("gm2012 P e^(-k²), ℓ = {ell}: |Δξ|/max|ξ| against quadrature {err:.1e}");
        assert!(err < 1e-5, "ℓ={ell}: {err:e}\n{fftlog:?}\n{direct:?}");
    }
}

#[test]
fn round_trip_of_the_linear_spectrum() {
    let lin = LinearSpectrum::gm2012(0.0).unwrap();
    let (k, p) = lin.nodes();
    // ξ on the range reciprocal to 1e-4 ≤ k ≤ 50 h/Mpc, 200 points per decade, and back.
    let s = logspace(0.021, 9.5e3, 1131);
    let k_out = logspace(0.01, 0.3, 100);
    let p_exact: Vec<f64> = k_out.iter().map(|&k| lin.eval(k)).collect();
    for ell in [0, 2, 4] {
        let xi = xi_from_pk(k, p, ell, &s).unwrap();
        let back = pk_from_xi(&s, &xi, ell, &k_out).unwrap();
        let rel = back
            .iter()
            .zip(&p_exact)
            .fold(0.0f64, |m, (a, b)| m.max((a / b - 1.0).abs()));
        println!("gm2012 round trip P -> xi_{ell} -> P: worst relative error over 0.01..0.3 h/Mpc {rel:.1e}");
        assert!(rel < 1e-4, "ℓ={ell}: {rel:e}");
    }
}

#[test]
fn timing_of_one_transform() {
    let plan = HankelPlan::new(1e-4, 100.0, 1024, 2, Direction::PkToXi, 1.5).unwrap();
    let lin = LinearSpectrum::gm2012(0.0).unwrap();
    let p: Vec<f64> = plan.input_grid().iter().map(|&k| lin.eval(k)).collect();
    let start = std::time::Instant::now();
    let reps = 1000;
    let mut total = 0.0;
    for _ in 0..reps {
        total += plan.transform(&p).unwrap()[512];
    }
    let per = start.elapsed().as_secs_f64() / reps as f64;
    let start = std::time::Instant::now();
    let build = HankelPlan::new(1e-4, 100.0, 1024, 2, Direction::PkToXi, 1.5).unwrap();
    let plan_time = start.elapsed().as_secs_f64();
    let (k, pk) = lin.nodes();
    let s: Vec<f64> = (10..=200).map(f64::from).collect();
    let start = std::time::Instant::now();
    let xi = xi_from_pk(k, pk, 0, &s).unwrap();
    let convenience = start.elapsed().as_secs_f64();
    println!(
        "N = 1024: transform {:.1} µs, plan {:.1} µs; xi_from_pk on the 1200-point gm2012 table {:.2} ms",
        per * 1e6,
        plan_time * 1e6,
        convenience * 1e3
    );
    assert!(total.is_finite() && build.ell() == 2 && xi.len() == s.len());
}
