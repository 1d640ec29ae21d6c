//! 1- and 2-loop SPT against an independent code: the expected outputs of cosPT (Taule & Garny's
//! Monte Carlo loop integrator, `tests/data/cospt/`, provenance and conventions there), for its input
//! spectrum interpolated as cosPT does (a natural cubic spline in linear k, P) and its integration
//! range q ∈ [1e-4, 10] h/Mpc; cosPT's outputs are in the (2π)⁻³ convention. Compared for k ≤ 2.9
//! (beyond, the two codes cut |k − q| > q_max differently). Differences are in units of σ, the two
//! codes' errors combined in quadrature.

use pt_spectra::linear::{LinearSpectrum, LogGrid};
use pt_spectra::loops::{Estimate, Pair};
use pt_spectra::precision::{Precision, TwoLoopMethod};
use pt_spectra::progress::Silent;
use pt_spectra::real::{RealModel, RealPlan};
use pt_spectra::rsd::spt2::Spt2Plan;

use crate::support::*;

/// cosPT's outputs are P/(2π)³.
const TWO_PI_CUBED: f64 = 248.050_213_442_398_6;

/// cosPT's input spectrum as cosPT reads it: a natural cubic spline in linear (k, P), tabulated on
/// 6000 log-spaced k (pt-spectra's own interpolation of the 139 rows differs by up to 1e-3).
fn cospt_spectrum() -> LinearSpectrum {
    let table = rows(&data("cospt/pk_lin.dat"));
    let (x, y): (Vec<f64>, Vec<f64>) = table.iter().map(|r| (r[0], r[1])).unzip();
    let n = x.len();
    let h: Vec<f64> = x.windows(2).map(|w| w[1] - w[0]).collect();
    // Second derivatives m with m_0 = m_{n−1} = 0 (Thomas algorithm).
    let (mut c, mut r) = (vec![0.0; n], vec![0.0; n]);
    for i in 1..n - 1 {
        let (a, b, cc) = (h[i - 1], 2.0 * (h[i - 1] + h[i]), h[i]);
        let rhs = 6.0 * ((y[i + 1] - y[i]) / h[i] - (y[i] - y[i - 1]) / h[i - 1]);
        let den = b - a * c[i - 1];
        c[i] = cc / den;
        r[i] = (rhs - a * r[i - 1]) / den;
    }
    let mut m = vec![0.0; n];
    for i in (1..n - 1).rev() {
        m[i] = r[i] - c[i] * m[i + 1];
    }
    let spline = |t: f64| {
        let t = t.clamp(x[0], x[n - 1]);
        let i = x.partition_point(|&v| v <= t).clamp(1, n - 1) - 1;
        let (p, q) = ((x[i + 1] - t) / h[i], (t - x[i]) / h[i]);
        p * y[i]
            + q * y[i + 1]
            + ((p.powi(3) - p) * m[i] + (q.powi(3) - q) * m[i + 1]) * h[i] * h[i] / 6.0
    };
    let grid = LogGrid::new(x[0], x[n - 1], 6000).unwrap();
    LinearSpectrum::from_fn(&grid, spline).unwrap()
}

fn precision(base: Precision) -> Precision {
    let mut p = base.with_q_range(1e-4, 10.0).unwrap();
    p.two_loop = TwoLoopMethod::Direct;
    p
}

/// (ours − theirs) / σ, with theirs = (value, error) in cosPT's convention.
fn pull(ours: Estimate, value: f64, error: f64) -> f64 {
    let (v, e) = (value * TWO_PI_CUBED, error * TWO_PI_CUBED);
    (ours.value - v) / ours.error.hypot(e)
}

#[test]
fn real_space_one_and_two_loop_spt_agree_with_cospt() {
    let l1 = rows(&data("cospt/L1.dat"));
    let l2 = rows(&data("cospt/L2.dat"));
    let k: Vec<f64> = l1.iter().map(|r| r[0]).filter(|&k| k < 3.0).collect();
    let p = cospt_spectrum();
    let plan = RealPlan::new(
        &k,
        RealModel::TwoLoopSpt,
        &precision(Precision::default()),
        store(),
        &Silent,
    )
    .unwrap();
    let terms = plan.terms(&p, &Silent).unwrap();
    let two_loop = &terms.two_loop.as_ref().unwrap().pairs[Pair::DeltaDelta];
    for (i, &ki) in k.iter().enumerate() {
        let p_lin = terms.one_loop.p_lin[i];
        assert!(
            (p_lin / (l1[i][1] * TWO_PI_CUBED) - 1.0).abs() < 1e-6,
            "k = {ki}"
        );
        // 1-loop: measured ≤ 4.0e-5 relative, 0.4σ.
        let one = terms.one_loop.one_loop(Pair::DeltaDelta, i);
        let theirs = l1[i][2] * TWO_PI_CUBED;
        assert!(
            (one.value / theirs - 1.0).abs() < 1e-4,
            "k = {ki}: {one:?} {theirs}"
        );
        assert!(pull(one, l1[i][2], l1[i][3]).abs() < 3.0, "k = {ki}");
        // 2-loop correction: within 1.03σ except at k = 0.0115, where both errors are ≤ 1.2e-4 of
        // it and the difference is 7.1e-4 of it (our P15 error there is smaller than at the
        // neighbouring k): hence a floor of 1e-3 of the value in σ.
        let two = two_loop.total[i];
        let (v, e) = (l2[i][2], l2[i][3]);
        let floored = Estimate::new(two.value, two.error.max(1e-3 * two.value.abs()));
        let z = pull(floored, v, e);
        assert!(
            z.abs() < 4.0,
            "k = {ki}: 2-loop {two:?} vs {}, {z:.2} sigma",
            v * TWO_PI_CUBED
        );
    }
}

#[test]
fn redshift_space_two_loop_multipoles_agree_with_cospt() {
    // k ≤ 0.2 (cosPT's errors at larger k are 2–3% of the 2-loop part), default precision. With half
    // the points at k ≤ 0.13 (the real-space rule) the 2-loop multipoles at k ≤ 0.1 came out
    // 0.7–0.9% smaller in magnitude, beyond their errors, and this test failed (mean pull +1.71 for
    // ℓ = 0): hence `rsd_points_at`.
    let l1 = rows(&data("cospt/rsd_L1.dat"));
    let l2 = rows(&data("cospt/rsd_L2.dat"));
    let k: Vec<f64> = l2.iter().map(|r| r[0]).filter(|&k| k < 0.21).collect();
    let p = cospt_spectrum();
    let plan = Spt2Plan::new(&k, &precision(Precision::default())).unwrap();
    let m = plan
        .terms(&p, &Silent)
        .unwrap()
        .multipoles(0.55, &[0, 2, 4])
        .unwrap();
    for (l, ell) in [0, 2, 4].into_iter().enumerate() {
        let col = 1 + 3 * l;
        let mut mean = 0.0;
        for (i, &ki) in k.iter().enumerate() {
            let lin = m.linear[l][i].value / (l1[i][col] * TWO_PI_CUBED);
            assert!((lin - 1.0).abs() < 1e-6, "l = {ell} k = {ki}: Kaiser");
            // 1-loop: measured ≤ 0.33σ (cosPT's Monte Carlo errors, 0.1–3%).
            let z1 = pull(m.one_loop[l][i], l1[i][col + 1], l1[i][col + 2]);
            assert!(z1.abs() < 3.0, "l = {ell} k = {ki}: 1-loop {z1:.2} sigma");
            // 2-loop: measured ≤ 0.86σ at reference precision.
            let z2 = pull(m.two_loop[l][i], l2[i][col + 1], l2[i][col + 2]);
            assert!(z2.abs() < 3.0, "l = {ell} k = {ki}: 2-loop {z2:.2} sigma");
            mean += z2 / k.len() as f64;
        }
        // No bias: the mean pull over the k (measured −0.43, −0.48, −0.21; −0.38, −0.46, −0.21 at
        // reference precision; +1.71 and +1.18 for ℓ = 0, 2 with the real-space points rule).
        assert!(mean.abs() < 1.0, "l = {ell}: mean pull {mean:.2}");
    }
}
