//! The survey window (`pt_spectra::survey::window`) against independent computations:
//!
//! * a uniform sphere of radius R, whose window multipoles are Q0(s) = 1 − 3s/4R + s³/16R³ (s < 2R),
//!   against the direct convolution in k space, P̂_ℓ(k) = ∫ d³k'/(2π)³ G(|k − k'|) P(k', μ') with
//!   G(q) = |W̃(q)|²/V = V [3 j1(qR)/(qR)]², reduced by the addition theorem to
//!   P̂_ℓ(k) = (1/4π²) ∫ dk' k'² P_ℓ(k') (1/kk') ∫_{|k−k'|}^{k+k'} dq q G(q) L_ℓ((k² + k'² − q²)/2kk'),
//!   both integrals by Gauss–Legendre panels (no Hankel transform);
//! * a BOSS-format Q_ℓ file (an ellipsoidal survey's Q0, Q2, Q4 on the BOSS s grid) against
//!   `tests/data/make_window_reference.py`, which applies the same formulae with numpy by direct
//!   quadrature (ξ_ℓ by a k integral, P̂_ℓ by an s integral).

use crate::support;

use pt_spectra::estimate::Estimate;
use pt_spectra::integrate::GaussLegendre;
use pt_spectra::linear::LinearSpectrum;
use pt_spectra::survey::window::BOSS_ROWS;
use pt_spectra::survey::{
    legendre, BinAverage, Mixing, WindowFormat, WindowMultipoles, WindowPlan,
};
use std::f64::consts::PI;
use std::time::Instant;

/// Kaiser multipole factors of (1 + βμ²)²: 1 + 2β/3 + β²/5, 4β/3 + 4β²/7, 8β²/35.
fn kaiser(beta: f64) -> [f64; 3] {
    [
        1.0 + 2.0 * beta / 3.0 + beta * beta / 5.0,
        4.0 * beta / 3.0 + 4.0 * beta * beta / 7.0,
        8.0 * beta * beta / 35.0,
    ]
}

/// The sphere's Q0 on `n` log-spaced s from 0.01 Mpc/h to 2R.
fn sphere_window(r: f64, n: usize) -> WindowMultipoles {
    let s: Vec<f64> = (0..n)
        .map(|i| 0.01 * (2.0 * r / 0.01f64).powf(i as f64 / (n - 1) as f64))
        .collect();
    let q0 = s
        .iter()
        .map(|&s| (1.0 - 0.75 * s / r + (s / r).powi(3) / 16.0).max(0.0))
        .collect();
    WindowMultipoles::from_columns(s, vec![0], vec![q0]).unwrap()
}

/// 3 j1(x)/x, with its series at small x.
fn top_hat(x: f64) -> f64 {
    if x < 1e-2 {
        1.0 - x * x / 10.0 + x.powi(4) / 280.0
    } else {
        3.0 * (x.sin() - x * x.cos()) / x.powi(3)
    }
}

/// The direct convolution of P_ℓ (ℓ = 0, 2, 4 with factors `c`) × `p` with the sphere's kernel at `k`.
fn direct_sphere(p: &LinearSpectrum, c: [f64; 3], r: f64, k: f64) -> [f64; 3] {
    direct_sphere_fn(|k| p.eval(k), c, r, k)
}

fn direct_sphere_fn(p: impl Fn(f64) -> f64, c: [f64; 3], r: f64, k: f64) -> [f64; 3] {
    let gl = GaussLegendre::new(10);
    let volume = 4.0 * PI * r.powi(3) / 3.0;
    let g = |q: f64| volume * top_hat(q * r).powi(2);
    let width = 0.5 / r;
    // g_ℓ(k, k') for ℓ = 0, 2, 4.
    let kernel = |kp: f64| -> [f64; 3] {
        let (lo, hi) = ((k - kp).abs(), k + kp);
        let panels = ((hi - lo) / width).ceil().max(1.0) as usize;
        let h = (hi - lo) / panels as f64;
        let mut sum = [0.0; 3];
        for i in 0..panels {
            for (q, w) in gl.on(lo + h * i as f64, lo + h * (i + 1) as f64) {
                let mu = ((k * k + kp * kp - q * q) / (2.0 * k * kp)).clamp(-1.0, 1.0);
                let f = w * q * g(q);
                for (ell, s) in sum.iter_mut().enumerate() {
                    *s += f * legendre(2 * ell, mu);
                }
            }
        }
        sum.map(|s| s / (k * kp))
    };
    // k' panels: width 0.5/R within 150/R of k (an edge at k), then growing by 10% to 100 h/Mpc.
    let near = 150.0 / r;
    let mut edges = vec![];
    let mut x = (k - near).max(0.0);
    let start = ((k - x) / width).ceil() as usize;
    x = k - start as f64 * width;
    edges.push(x.max(0.0));
    while x < k + near {
        x += width;
        edges.push(x);
    }
    while x < 100.0 {
        x *= 1.1;
        edges.push(x);
    }
    let mut out = [0.0; 3];
    for e in edges.windows(2) {
        for (kp, w) in gl.on(e[0], e[1]) {
            let gk = kernel(kp);
            let pk = p(kp) * kp * kp * w;
            for ell in 0..3 {
                out[ell] += c[ell] * pk * gk[ell];
            }
        }
    }
    out.map(|v| v / (4.0 * PI * PI))
}

fn model(plan: &WindowPlan, p: &LinearSpectrum, c: [f64; 3]) -> Vec<Vec<f64>> {
    c.iter()
        .map(|c| plan.k_theory().iter().map(|&k| c * p.eval(k)).collect())
        .collect()
}

#[test]
fn sphere_window_matches_the_direct_convolution() {
    let p = LinearSpectrum::gm2012(0.0).unwrap();
    let c = kaiser(0.5);
    let k_out = [0.005, 0.01, 0.02, 0.05, 0.1, 0.15, 0.2, 0.3];
    for r in [100.0, 300.0] {
        let window = sphere_window(r, 256);
        let plan = WindowPlan::new(&[0, 2, 4], &k_out, &window, Mixing::Wilson).unwrap();
        let out = plan.apply(&model(&plan, &p, c)).unwrap();
        let (mut worst, mut effect) = ([0.0f64; 3], 0.0f64);
        for (j, &k) in k_out.iter().enumerate() {
            let d = direct_sphere(&p, c, r, k);
            effect = effect.max((d[0] / (c[0] * p.eval(k)) - 1.0).abs());
            for ell in 0..3 {
                let e: Estimate = out[ell][j];
                worst[ell] = worst[ell].max((e.value - d[ell]).abs() / d[0]);
            }
        }
        println!(
            "sphere R = {r} Mpc/h (window changes P0 by up to {effect:.0e}): |P̂_ℓ − direct|/P̂0 ≤ \
             {:.1e}, {:.1e}, {:.1e} (ℓ = 0, 2, 4); {} model points, {} FFTLog points",
            worst[0],
            worst[1],
            worst[2],
            plan.k_theory().len(),
            plan.fft_points()
        );
        assert!(worst.iter().all(|&w| w < 1e-4), "R = {r}: {worst:?}");
    }
}

/// A Gaussian P = A e^{−k²σ²/2}, whose ξ = A (2πσ²)^{−3/2} e^{−s²/2σ²} is known: the sphere's P̂0 by
/// the plan, by the direct convolution and by configuration-space quadrature of ξ Q0 j0.
#[test]
fn gaussian_through_a_sphere_three_ways() {
    let (a, sigma) = (1e4, 5.0);
    let pk = |k: f64| a * (-0.5 * k * k * sigma * sigma).exp();
    let xi =
        |s: f64| a * (2.0 * PI * sigma * sigma).powf(-1.5) * (-0.5 * s * s / (sigma * sigma)).exp();
    let gl = GaussLegendre::new(10);
    let k_out = [0.01, 0.1, 0.2, 0.3];
    for r in [100.0, 300.0] {
        let window = sphere_window(r, 256);
        let plan = WindowPlan::new(&[0], &k_out, &window, Mixing::Wilson).unwrap();
        let m = vec![plan.k_theory().iter().map(|&k| pk(k)).collect::<Vec<_>>()];
        let out = plan.apply(&m).unwrap();
        for (j, &k) in k_out.iter().enumerate() {
            let direct = direct_sphere_fn(pk, [1.0, 0.0, 0.0], r, k)[0];
            let edges: Vec<f64> = (0..=2000).map(|i| 2.0 * r * i as f64 / 2000.0).collect();
            let (config, _) = gl.integrate_panels(
                |s| {
                    let x = k * s;
                    let j0 = if x < 1e-8 { 1.0 } else { x.sin() / x };
                    4.0 * PI * s * s * xi(s) * (1.0 - 0.75 * s / r + (s / r).powi(3) / 16.0) * j0
                },
                &edges,
            );
            assert!(
                (direct - config).abs() < 1e-7 * config,
                "R {r} k {k}: {direct} {config}"
            );
            let e = out[0][j];
            assert!(
                (e.value - config).abs() < 1e-6 * config,
                "R {r} k {k}: {e:?} {config}"
            );
        }
    }
}

/// Plan and per-call cost of the windowed, binned P0, P2, P4 at 48 bins through a 128-point BOSS-format
/// window (the Kaiser model on the plan's grid is cheap; a perturbative model costs its own time per k).
#[test]
fn windowed_binned_evaluation_is_fast() {
    let path = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/data/window_boss_ellipsoid.dat"
    );
    let window =
        WindowMultipoles::from_file(path, &WindowFormat::boss(BOSS_ROWS).unwrap()).unwrap();
    let edges: Vec<f64> = (0..=48).map(|i| 0.005 * i as f64).collect();
    let p = LinearSpectrum::gm2012(0.0).unwrap();
    let t0 = Instant::now();
    let bins = BinAverage::new(&edges).unwrap();
    let plan = WindowPlan::new(&[0, 2, 4], bins.k_theory(), &window, Mixing::Wilson).unwrap();
    let t_plan = t0.elapsed();
    let reps = 50;
    let (mut t_model, mut t_window) = (std::time::Duration::ZERO, std::time::Duration::ZERO);
    for _ in 0..reps {
        let t = Instant::now();
        let m = model(&plan, &p, kaiser(0.5));
        t_model += t.elapsed();
        let t = Instant::now();
        let windowed = plan.apply(&m).unwrap();
        let binned: Vec<Vec<Estimate>> = windowed
            .iter()
            .map(|w| bins.apply_estimates(w).unwrap())
            .collect();
        t_window += t.elapsed();
        assert_eq!(binned.len(), 3);
        assert!(binned.iter().all(|b| b.len() == 48));
    }
    let (t_model, t_window) = (t_model / reps, t_window / reps);
    println!(
        "48 bins × ℓ = 0, 2, 4 through 128 s points: plan {t_plan:?}; per call: window + bins \
         {t_window:?}, Kaiser model on {} k {t_model:?}; {} FFTLog points",
        plan.k_theory().len(),
        plan.fft_points()
    );
    // Generous bounds (debug-free release builds on a loaded machine).
    assert!(t_window.as_secs_f64() < 0.02, "{t_window:?}");
    assert!(t_plan.as_secs_f64() < 1.0, "{t_plan:?}");
}

#[test]
fn boss_format_window_matches_the_python_reference() {
    let path = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/data/window_boss_ellipsoid.dat"
    );
    let window =
        WindowMultipoles::from_file(path, &WindowFormat::boss(BOSS_ROWS).unwrap()).unwrap();
    assert_eq!(window.ells(), &[0, 2, 4]);
    assert!((window.s()[127] - 1000.0).abs() < 1e-9);
    assert!(window.normalisation_warning().is_none());
    let rows = support::rows(&support::data("window_boss_reference.dat"));
    let k: Vec<f64> = rows.iter().map(|r| r[0]).collect();
    let p = LinearSpectrum::gm2012(0.0).unwrap();
    let c = kaiser(0.5);
    // The two mixings differ (by 1e-3 of P0 at the lowest k): the comparison tells them apart.
    assert!((rows[0][1] / rows[0][4] - 1.0).abs() > 5e-4);
    for (mixing, col) in [(Mixing::Wilson, 1), (Mixing::ClassPtBoss, 4)] {
        let plan = WindowPlan::new(&[0, 2, 4], &k, &window, mixing).unwrap();
        let m: Vec<Vec<f64>> = c
            .iter()
            .map(|c| {
                plan.k_theory()
                    .iter()
                    .map(|&q| c * p.eval(q) * (-q * q).exp())
                    .collect()
            })
            .collect();
        let out = plan.apply(&m).unwrap();
        let mut worst = [0.0f64; 3];
        for (i, r) in rows.iter().enumerate() {
            for ell in 0..3 {
                let d = (out[ell][i].value - r[col + ell]).abs() / r[col];
                worst[ell] = worst[ell].max(d);
            }
        }
        println!(
            "BOSS-format window, {mixing:?}: |P̂_ℓ − numpy|/P̂0 ≤ {:.1e}, {:.1e}, {:.1e} (ℓ = 0, 2, 4)",
            worst[0], worst[1], worst[2]
        );
        assert!(worst.iter().all(|&w| w < 1e-4), "{mixing:?}: {worst:?}");
    }
}
