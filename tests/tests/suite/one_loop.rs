//! 1-loop SPT terms against FAST-PT, analytic limits, self-convergence, and the RPT propagators.
//!
//! Reference tables: `tests/data/fastpt_1loop_*` (provenance in `tests/data/README.md`). Their `_std`
//! columns hold P22 and 2·P13 in the paper's normalisation and were checked against brute-force quadrature
//! to ≤ 1.1e-5 relative, so agreement much below that is not expected.

use pt_kernels::mode_coupling_2;
use pt_spectra::cosmology::Cosmology;
use pt_spectra::integrate::GaussLegendre;
use pt_spectra::linear::{LinearSpectrum, LogGrid};
use pt_spectra::loops::{Estimate, OneLoopPlan, OneLoopTerms, Pair};
use pt_spectra::precision::Precision;
use std::f64::consts::PI;

use crate::support::*;

/// Required agreement with FAST-PT per term, 0.01 ≤ k ≤ 0.5 h/Mpc (the target).
const FASTPT_TOL: f64 = 1e-4;
/// Measured agreement is ≲ 1e-5 (the reference's own accuracy); a regression beyond this is a bug.
const FASTPT_MEASURED: f64 = 2e-5;
/// σ_v² against the FAST-PT header: same range 1e-5..1e3 h/Mpc, different extrapolation and quadrature.
const SIGMA_V2_TOL: f64 = 1e-6;
/// Analytic limits: the corrections are O(r²) with r = q/k or k/q ≲ 5e-3 here.
const LIMIT_TOL: f64 = 1e-4;
/// Growth against CAMB (which includes radiation and neutrinos in the background).
const GROWTH_TOL: f64 = 1e-3;

/// The value after `key` (e.g. `growth_rate_f(z)=`) in a header.
fn header_value(text: &str, key: &str) -> f64 {
    let start = text.find(key).unwrap_or_else(|| panic!("no {key}")) + key.len();
    let rest = &text[start..];
    let end = rest
        .find(|c: char| c.is_whitespace() || c == ',')
        .unwrap_or(rest.len());
    rest[..end].parse().unwrap()
}

/// Columns (P22, 2·P13) per pair in the reference files.
struct Reference {
    k: Vec<f64>,
    /// [dd, dt, tt] × (P22, 2·P13).
    terms: Vec<[[f64; 2]; 3]>,
    sigma_v2: f64,
}

fn reference(z: &str, k_range: (f64, f64)) -> Reference {
    let dd_text = data(&format!("fastpt_1loop_gm2012_z{z}.dat"));
    let (dd, dt) = (
        rows(&dd_text),
        rows(&data(&format!("fastpt_1loop_dt_tt_gm2012_z{z}.dat"))),
    );
    let keep: Vec<usize> = (0..dd.len())
        .filter(|&i| dd[i][0] >= k_range.0 && dd[i][0] <= k_range.1)
        .collect();
    assert!(keep.iter().all(|&i| dd[i][0] == dt[i][0]));
    Reference {
        k: keep.iter().map(|&i| dd[i][0]).collect(),
        terms: keep
            .iter()
            .map(|&i| {
                [
                    [dd[i][7], dd[i][8]],
                    [dt[i][2], dt[i][3]],
                    [dt[i][6], dt[i][7]],
                ]
            })
            .collect(),
        sigma_v2: header_value(&dd_text, "(trapezoid in ln q) = "),
    }
}

fn ours(terms: &OneLoopTerms, pair: Pair, i: usize) -> [Estimate; 2] {
    let p13 = terms.p13[pair][i];
    [
        terms.p22[pair][i],
        Estimate::new(2.0 * p13.value, 2.0 * p13.error),
    ]
}

#[test]
fn p22_and_p13_match_fastpt_for_dd_dt_tt() {
    for (z, zf) in [("0.0", 0.0), ("1.0", 1.0)] {
        let r = reference(z, (0.01, 0.5));
        assert!(r.k.len() > 300);
        let terms = OneLoopPlan::new(&r.k, &Precision::default())
            .unwrap()
            .par_evaluate(&LinearSpectrum::gm2012(zf).unwrap());
        assert!(
            (terms.sigma_v2.value / r.sigma_v2 - 1.0).abs() < SIGMA_V2_TOL,
            "z={z}"
        );
        let mut worst = [[0.0f64; 2]; 3];
        for i in 0..r.k.len() {
            for (j, pair) in Pair::ALL.into_iter().enumerate() {
                for (c, ours) in ours(&terms, pair, i).into_iter().enumerate() {
                    let rel = (ours.value / r.terms[i][j][c] - 1.0).abs();
                    worst[j][c] = worst[j][c].max(rel);
                    assert!(
                        rel < FASTPT_TOL,
                        "z={z} k={} {pair:?} term {c}: {rel:e}",
                        r.k[i]
                    );
                }
            }
        }
        let shown: Vec<String> = worst.iter().flatten().map(|w| format!("{w:.1e}")).collect();
        println!(
            "z={z}: max |ours/FAST-PT − 1|, dd/dt/tt × P22/2P13: {}",
            shown.join(" ")
        );
        assert!(
            worst.iter().flatten().all(|&w| w < FASTPT_MEASURED),
            "{worst:?}"
        );
    }
}

/// A spectrum with all its power in a log-normal bump around `q0` [h/Mpc] (width `s` in ln q), tabulated
/// far beyond the integration range so that no extrapolation enters.
fn bump(q0: f64, s: f64) -> LinearSpectrum {
    let grid = LogGrid::new(1e-7, 1e5, 6000).unwrap();
    LinearSpectrum::from_fn(&grid, |q| {
        let x = (q / q0).ln() / s;
        1e4 * (-0.5 * x * x).exp() + 1e-300
    })
    .unwrap()
}

#[test]
fn infrared_limit_two_p13_is_minus_k2_sigma_v2_p() {
    let p = bump(1e-3, 0.4);
    let k = [3.0, 10.0];
    let terms = OneLoopPlan::new(&k, &Precision::default())
        .unwrap()
        .evaluate(&p);
    let sv = terms.sigma_v2.value;
    for (i, &ki) in k.iter().enumerate() {
        for pair in Pair::ALL {
            let ratio = 2.0 * terms.p13[pair][i].value / (terms.p_lin[i] * ki * ki * sv);
            assert!((ratio + 1.0).abs() < LIMIT_TOL, "k={ki} {pair:?}: {ratio}");
        }
    }
}

/// (1/2π²) ∫ dq P²/q², by Gauss–Legendre panels in ln q, directly on the spectrum.
fn p_squared_over_q4(p: &LinearSpectrum) -> f64 {
    let gl = GaussLegendre::new(20);
    let edges: Vec<f64> = (0..=80).map(|i| -5.0 + 0.125 * f64::from(i)).collect();
    let (v, _) = gl.integrate_panels(
        |x| {
            let q = x.exp();
            p.eval(q).powi(2) / q
        },
        &edges,
    );
    v / (2.0 * PI * PI)
}

#[test]
fn ultraviolet_limits_of_p13_and_p22() {
    let p = bump(10.0, 0.3);
    let k = [1e-3, 3e-3];
    let precision = Precision::reference();
    let terms = OneLoopPlan::new(&k, &precision).unwrap().evaluate(&p);
    let sv = terms.sigma_v2.value;
    let i4 = p_squared_over_q4(&p);
    let p13_limit = [61.0 / 105.0, 25.0 / 21.0, 9.0 / 5.0];
    let p22_limit = [9.0 / 98.0, 19.0 / 294.0, 61.0 / 490.0];
    for (i, &ki) in k.iter().enumerate() {
        for (j, pair) in Pair::ALL.into_iter().enumerate() {
            let ratio = 2.0 * terms.p13[pair][i].value / (terms.p_lin[i] * ki * ki * sv);
            assert!(
                (ratio + p13_limit[j]).abs() < LIMIT_TOL,
                "k={ki} {pair:?} P13: {ratio}"
            );
            let c = terms.p22[pair][i].value / (ki.powi(4) * i4);
            assert!(
                (c / p22_limit[j] - 1.0).abs() < LIMIT_TOL,
                "k={ki} {pair:?} P22: {c}"
            );
        }
    }
}

/// P22 at one k by direct quadrature in (ln q, μ) with the generated kernels and `LinearSpectrum::eval`
/// (no lattice, different variables and panels): an independent check of the plan. Uses the q ↔ k − q
/// symmetry (the half p ≥ q, i.e. μ ≤ k/2q, counted twice), which removes the p → 0 singularity.
fn brute_force_p22(p: &LinearSpectrum, k: f64) -> [f64; 3] {
    let (gl_q, gl_mu) = (GaussLegendre::new(16), GaussLegendre::new(24));
    let mut edges: Vec<f64> = (0..=460)
        .map(|i| (1e-5f64).ln() + 0.04 * f64::from(i))
        .collect();
    edges.push((0.5 * k).ln());
    edges.sort_by(f64::total_cmp);
    let mut sum = [0.0; 3];
    for e in edges.windows(2) {
        for (x, wx) in gl_q.on(e[0], e[1]) {
            let q = x.exp();
            let mu_hi = (0.5 * k / q).min(1.0);
            let mu_lo = ((k * k + q * q - 1e6) / (2.0 * k * q)).max(-1.0); // |k − q| ≤ 1e3
            for m in 0..8 {
                let a = mu_lo + (mu_hi - mu_lo) * f64::from(m) / 8.0;
                let b = mu_lo + (mu_hi - mu_lo) * f64::from(m + 1) / 8.0;
                for (mu, wm) in gl_mu.on(a, b) {
                    let pp = (k * k + q * q - 2.0 * k * q * mu).sqrt();
                    let [f, g] = mode_coupling_2(&[k * k, k * q * mu, q * q]);
                    // 2 × (1/(2π)³) × 2π q³ dln q dμ, times 2 for the half domain.
                    let w = 2.0 * wx * wm * q.powi(3) * p.eval(q) * p.eval(pp) / (2.0 * PI * PI);
                    sum[0] += w * f * f;
                    sum[1] += w * f * g;
                    sum[2] += w * g * g;
                }
            }
        }
    }
    sum
}

#[test]
fn p22_matches_independent_brute_force_quadrature() {
    let p = LinearSpectrum::gm2012(0.0).unwrap();
    let k = [0.02, 0.1, 0.3];
    let terms = OneLoopPlan::new(&k, &Precision::default())
        .unwrap()
        .evaluate(&p);
    for (i, &ki) in k.iter().enumerate() {
        let brute = brute_force_p22(&p, ki);
        for (j, pair) in Pair::ALL.into_iter().enumerate() {
            let ours = terms.p22[pair][i].value;
            let rel = (ours / brute[j] - 1.0).abs();
            println!(
                "k={ki} {pair:?}: ours/brute − 1 = {:.1e}",
                ours / brute[j] - 1.0
            );
            assert!(
                rel < 3e-6,
                "k={ki} {pair:?}: ours {ours} brute {} ({rel:e})",
                brute[j]
            );
        }
    }
}

#[test]
fn doubling_the_resolution_changes_results_by_less_than_the_reported_error() {
    let p = LinearSpectrum::gm2012(0.0).unwrap();
    let k = LogGrid::new(1e-3, 1.0, 40).unwrap().points();
    for (coarse, fine) in [
        (Precision::default(), Precision::reference()),
        (Precision::fast(), Precision::default()),
    ] {
        let a = OneLoopPlan::new(&k, &coarse).unwrap().evaluate(&p);
        let b = OneLoopPlan::new(&k, &fine).unwrap().evaluate(&p);
        let check = |x: Estimate, y: Estimate, what: &str| {
            assert!(
                (x.value - y.value).abs() <= x.error,
                "{what}: {x:?} vs {y:?}"
            );
            // The estimates are useful: well below the 1e-4 accuracy target.
            assert!(x.error <= 3e-4 * x.value.abs(), "{what}: {x:?}");
        };
        check(a.sigma_v2, b.sigma_v2, "sigma_v2");
        for (i, ki) in k.iter().enumerate() {
            for pair in Pair::ALL {
                check(
                    a.p22[pair][i],
                    b.p22[pair][i],
                    &format!("P22 {pair:?} k={ki}"),
                );
                check(
                    a.p13[pair][i],
                    b.p13[pair][i],
                    &format!("P13 {pair:?} k={ki}"),
                );
            }
        }
    }
}

#[test]
fn parallel_and_sequential_evaluation_are_identical() {
    let p = LinearSpectrum::gm2012(0.5).unwrap();
    let k = LogGrid::new(1e-3, 1.0, 50).unwrap().points();
    let plan = OneLoopPlan::new(&k, &Precision::fast()).unwrap();
    assert_eq!(plan.evaluate(&p), plan.par_evaluate(&p));
}

#[test]
fn growth_matches_camb_values_in_the_reference_headers() {
    let c = Cosmology::gm2012();
    for z in ["0.0", "1.0"] {
        let text = data(&format!("fastpt_1loop_gm2012_z{z}.dat"));
        let zf: f64 = z.parse().unwrap();
        let f = header_value(&text, "growth_rate_f(z)=");
        let d = header_value(&text, "sigma8(z)=") / 0.8;
        assert!(
            (c.growth_rate(zf) / f - 1.0).abs() < GROWTH_TOL,
            "f at z={z}"
        );
        assert!(
            (c.growth_factor(zf) / d - 1.0).abs() < GROWTH_TOL,
            "D at z={z}"
        );
    }
}

#[test]
fn loop_terms_scale_as_the_growth_factor() {
    // P22 ∝ D⁴ and P13 ∝ D⁴ at fixed shape: rescaling the input by D² must scale them by D⁴ exactly
    // (the plan is linear/bilinear in the samples).
    let p0 = LinearSpectrum::gm2012(0.0).unwrap();
    let p1 = p0.scaled(0.25).unwrap();
    let k = [0.05, 0.2];
    let plan = OneLoopPlan::new(&k, &Precision::fast()).unwrap();
    let (a, b) = (plan.evaluate(&p0), plan.evaluate(&p1));
    for i in 0..k.len() {
        for pair in Pair::ALL {
            assert!((b.p22[pair][i].value / a.p22[pair][i].value - 0.0625).abs() < 1e-12);
            assert!((b.p13[pair][i].value / a.p13[pair][i].value - 0.0625).abs() < 1e-12);
        }
    }
}
