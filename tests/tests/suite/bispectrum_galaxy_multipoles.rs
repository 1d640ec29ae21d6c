//! The multipoles B₀, B₂, B₄ of the one-loop galaxy bispectrum (issue 50,
//! `bispectrum::one_loop_galaxy_multipoles`): the tree level against the tree-level code's multipoles, f = 0
//! against real space, the one pass against the one-orientation polynomials averaged over an unfolded
//! orientation rule written out here.

use pt_spectra::bispectrum::bias_kernels::LoopBias;
use pt_spectra::bispectrum::one_loop::OneLoopRule;
use pt_spectra::bispectrum::one_loop_galaxy_multipoles::one_loop_galaxy_multipoles;
use pt_spectra::bispectrum::one_loop_galaxy_poly::one_loop_galaxy_polynomial;
use pt_spectra::bispectrum::one_loop_rsd::Orientation;
use pt_spectra::bispectrum::{
    BispectrumParams, BispectrumPlan, Fog, LegendreSide, PlanRules, Settings, TriangleSet,
};
use pt_spectra::linear::LinearSpectrum;
use std::time::Instant;

fn tiny() -> OneLoopRule {
    OneLoopRule {
        radial: 2,
        mu: 2,
        phi: 2,
        ..OneLoopRule::default()
    }
}

fn small() -> OneLoopRule {
    OneLoopRule {
        radial: 4,
        mu: 8,
        phi: 6,
        ..OneLoopRule::default()
    }
}

fn biases() -> [LoopBias; 2] {
    [
        LoopBias::from_values([1.8, 0.6, -0.3, 0.4, 0.5, -0.2, 0.35, 0.3, -0.4, 0.25, 0.6]),
        LoopBias::from_velocileptors(2.1, -0.4, 0.3),
    ]
}

/// The tree level of B₀, B₂, B₄ equals the tree-level code's multipoles (`BispectrumPlan`, its own
/// orientation rule, velocileptors' bias, no stochastic terms) to 1e-10, for the largest side and side 1, at
/// four triangles (squeezed to folded), f = 0.7.
#[test]
fn the_tree_level_multipoles_are_the_tree_level_codes() {
    let p = LinearSpectrum::gm2012_z0();
    let triangles = vec![
        [0.02, 0.1, 0.11],
        [0.1, 0.1, 0.1],
        [0.05, 0.08, 0.12],
        [0.06, 0.06, 0.12],
    ];
    let f = 0.7;
    let (b1, b2, bs) = (2.1, -0.4, 0.3);
    let params = BispectrumParams {
        b1,
        b2,
        bs,
        b_shot: 0.0,
        p_shot: -1.0,
        a_shot: -1.0,
        ..BispectrumParams::default()
    };
    let settings = Settings {
        f,
        q_par: 1.0,
        q_perp: 1.0,
        fog: Fog::None,
        ir: false,
    };
    for side in [LegendreSide::Largest, LegendreSide::Index(0)] {
        let set = TriangleSet::points(triangles.clone()).unwrap();
        let plan = BispectrumPlan::new(set, side, PlanRules::default()).unwrap();
        let tree = plan
            .terms(&p, &settings)
            .unwrap()
            .multipoles(&params)
            .unwrap();
        for (t, want) in triangles.iter().zip(&tree) {
            let m = one_loop_galaxy_multipoles(&p, *t, f, side, &tiny(), None).unwrap();
            let got = m
                .evaluate(&LoopBias::from_velocileptors(b1, b2, bs))
                .unwrap();
            let scale = want[0].value.abs();
            for l in 0..3 {
                let d = (got[l].tree.value - want[l].value).abs();
                assert!(
                    d <= 1e-10 * scale,
                    "{t:?} {side:?} l = {}: {} vs {} ({:e})",
                    2 * l,
                    got[l].tree.value,
                    want[l].value,
                    d / scale
                );
            }
        }
    }
}

/// At f = 0 the monopole is the real-space one-loop B and B₂, B₄ vanish (1e-13 of the bare terms' scale),
/// at two triangles and two biases. The loop nodes are the same (the off-plane rule's φ nodes are the in-plane
/// rule's and their mirror images): B₂₂₂, B₃₂₁ᴵ, B₃₂₁ᴵᴵ agree to ≤ 1.8e-13 of the bare scale, B₄₁₁ to 1.3e-9
/// (bound 1e-8; its UV constant c₄, taken at q = 10³ k where the kernel's terms cancel to 1e-6 of themselves,
/// carries round-off that the two node orders sum differently, and c₄σ² is ~100 times B₄₁₁), the errors to
/// 7.5e-12 (bound 1e-10). Bad input is refused.
#[test]
fn at_f_zero_the_monopole_is_real_space_and_the_rest_vanish() {
    let p = LinearSpectrum::gm2012_z0();
    for k in [[0.05, 0.08, 0.1], [0.02, 0.1, 0.11]] {
        let m =
            one_loop_galaxy_multipoles(&p, k, 0.0, LegendreSide::Largest, &tiny(), None).unwrap();
        let real = one_loop_galaxy_polynomial(&p, k, None, &tiny()).unwrap();
        for bias in biases() {
            let r = real.evaluate(&bias).unwrap();
            let [b0, b2, b4] = m.evaluate(&bias).unwrap();
            let scale = [r.tree, r.b222, r.b321_i, r.bare_b321_ii(), r.bare_b411()]
                .iter()
                .fold(0.0_f64, |s, t| s.max(t.value.abs()));
            let pairs = [
                (b0.tree, r.tree),
                (b0.b222, r.b222),
                (b0.b321_i, r.b321_i),
                (b0.b321_ii, r.b321_ii),
                (b0.b411, r.b411),
            ];
            for (i, (a, b)) in pairs.iter().enumerate() {
                assert!(
                    (a.value - b.value).abs() <= 1e-8 * scale,
                    "{k:?} term {i}: {} vs {}",
                    a.value,
                    b.value
                );
                assert!(
                    (a.error - b.error).abs() <= 1e-10 * scale,
                    "{k:?} error {i}"
                );
            }
            for b in [b2, b4] {
                assert!(
                    b.total().value.abs() <= 1e-13 * scale,
                    "{k:?}: {:?}",
                    b.total()
                );
            }
        }
    }
    let p = LinearSpectrum::gm2012_z0();
    let k = [0.05, 0.08, 0.1];
    assert!(one_loop_galaxy_multipoles(&p, k, 2.5, LegendreSide::Largest, &tiny(), None).is_err());
    assert!(one_loop_galaxy_multipoles(
        &p,
        [0.1, 0.1, 0.3],
        0.5,
        LegendreSide::Largest,
        &tiny(),
        None
    )
    .is_err());
    assert!(one_loop_galaxy_multipoles(&p, k, 0.5, LegendreSide::Index(3), &tiny(), None).is_err());
    assert!(
        one_loop_galaxy_multipoles(&p, k, 0.5, LegendreSide::Largest, &tiny(), Some((0, 3)))
            .is_err()
    );
}

/// L₀, L₂, L₄.
fn legendre(x: f64) -> [f64; 3] {
    [
        1.0,
        0.5 * (3.0 * x * x - 1.0),
        (35.0 * x.powi(4) - 30.0 * x * x + 3.0) / 8.0,
    ]
}

/// The one pass equals the one-orientation polynomials (`one_loop_galaxy_polynomial`) averaged with the
/// unfolded product rule written out here (Gauss–Legendre in μ₁ on [−1, 1] with 12 nodes, trapezoid in φ on
/// [0, 2π) with 20: another rule, exact for the same degree) at three triangles, f = 0.7, every term of B₀,
/// B₂, B₄ and its error at two biases to 1e-9 of the bare scale; the folded rule of 6 × 11 nodes gives the
/// same to 1e-11. Both are exact for B(n̂) L_ℓ, so they agree to round-off: the test checks the fold, the
/// weights and the Legendre side. 240 orientations at a small loop rule: slow checks.
#[test]
#[ignore = "slow exhaustive check (about 1.5 min): `cargo test --release --workspace -- --ignored`"]
fn the_one_pass_equals_the_average_of_single_orientations() {
    let p = LinearSpectrum::gm2012_z0();
    let f = 0.7;
    let rule = small();
    let (n_mu, n_phi) = (12, 20);
    let (x, w) = gauss_legendre(n_mu);
    for (k, side) in [
        ([0.05, 0.08, 0.1], LegendreSide::Largest),
        ([0.1, 0.1, 0.1], LegendreSide::Index(1)),
        ([0.02, 0.1, 0.11], LegendreSide::Index(0)),
    ] {
        let a = match side {
            LegendreSide::Index(a) => a,
            LegendreSide::Largest => 2,
        };
        let start = Instant::now();
        let m = one_loop_galaxy_multipoles(&p, k, f, side, &rule, None).unwrap();
        let t_pass = start.elapsed().as_secs_f64();
        let other = one_loop_galaxy_multipoles(&p, k, f, side, &rule, Some((6, 11))).unwrap();
        // the side a's direction in the triangle's frame (k₁ along z, k₂ in the x–z plane)
        let c12 = (k[2] * k[2] - k[0] * k[0] - k[1] * k[1]) / (2.0 * k[0] * k[1]);
        let s12 = (1.0 - c12 * c12).sqrt();
        let v = [
            [0.0, 0.0, k[0]],
            [k[1] * s12, 0.0, k[1] * c12],
            [-k[1] * s12, 0.0, -k[0] - k[1] * c12],
        ];
        let ka: Vec<f64> = v[a].iter().map(|c| c / k[a]).collect();
        let start = Instant::now();
        let mut sums = vec![[[0.0; 2]; 5]; 3 * biases().len()];
        for (mu, wm) in x.iter().zip(&w) {
            for j in 0..n_phi {
                let phi = 2.0 * std::f64::consts::PI * j as f64 / n_phi as f64;
                let s = (1.0 - mu * mu).sqrt();
                let n = [s * phi.cos(), s * phi.sin(), *mu];
                let l = legendre(n[0] * ka[0] + n[1] * ka[1] + n[2] * ka[2]);
                let weight = wm / (2.0 * n_phi as f64);
                let one = one_loop_galaxy_polynomial(
                    &p,
                    k,
                    Some((f, Orientation { mu1: *mu, phi })),
                    &rule,
                )
                .unwrap();
                for (ib, bias) in biases().iter().enumerate() {
                    let b = one.evaluate(bias).unwrap();
                    let t = [b.tree, b.b222, b.b321_i, b.b321_ii, b.b411];
                    // signed errors: fine − coarse, recovered from the polynomial's differences
                    let d = [&one.tree, &one.b222, &one.b321_i, &one.b321_ii, &one.b411]
                        .map(|term| signed_difference(term, bias));
                    for ell in 0..3 {
                        let c = weight * (4 * ell + 1) as f64 * l[ell];
                        for i in 0..5 {
                            sums[3 * ib + ell][i][0] += c * t[i].value;
                            sums[3 * ib + ell][i][1] += c * d[i];
                        }
                    }
                }
            }
        }
        let t_average = start.elapsed().as_secs_f64();
        for (ib, bias) in biases().iter().enumerate() {
            let got = m.evaluate(bias).unwrap();
            let again = other.evaluate(bias).unwrap();
            let scale = got[0]
                .bare_b411()
                .value
                .abs()
                .max(got[0].bare_b321_ii().value.abs());
            for ell in 0..3 {
                let g = &got[ell];
                let h = &again[ell];
                let terms = [g.tree, g.b222, g.b321_i, g.b321_ii, g.b411];
                let terms_h = [h.tree, h.b222, h.b321_i, h.b321_ii, h.b411];
                for i in 0..5 {
                    let [value, diff] = sums[3 * ib + ell][i];
                    assert!(
                        (terms[i].value - value).abs() <= 1e-9 * scale,
                        "{k:?} bias {ib} l {} term {i}: {} vs {}",
                        2 * ell,
                        terms[i].value,
                        value
                    );
                    assert!(
                        (terms[i].error - diff.abs()).abs() <= 1e-9 * scale,
                        "{k:?} error l {} term {i}",
                        2 * ell
                    );
                    assert!(
                        (terms[i].value - terms_h[i].value).abs() <= 1e-11 * scale,
                        "{k:?} 6 x 11 l {} term {i}",
                        2 * ell
                    );
                }
            }
        }
        eprintln!(
            "{k:?}: one pass {t_pass:.2} s, {} single orientations {t_average:.1} s",
            n_mu * n_phi
        );
    }
}

/// Σ monomial × (fine − coarse) of a term at `bias` (the signed error).
fn signed_difference(
    term: &pt_spectra::bispectrum::one_loop_galaxy_poly::TermPolynomial,
    bias: &LoopBias,
) -> f64 {
    let mut x = [1.0; 12];
    x[1..].copy_from_slice(&bias.values());
    term.monomials
        .iter()
        .zip(&term.differences)
        .map(|(m, d)| d * m.iter().map(|&i| x[i as usize]).product::<f64>())
        .sum()
}

/// Gauss–Legendre nodes and weights on [−1, 1] (Newton on the recurrence; written here, not the crate's).
fn gauss_legendre(n: usize) -> (Vec<f64>, Vec<f64>) {
    let (mut x, mut w) = (Vec::new(), Vec::new());
    for i in 0..n {
        let mut z = (std::f64::consts::PI * (i as f64 + 0.75) / (n as f64 + 0.5)).cos();
        for _ in 0..100 {
            let (mut p0, mut p1) = (1.0, z);
            for j in 2..=n {
                let p2 = ((2 * j - 1) as f64 * z * p1 - (j - 1) as f64 * p0) / j as f64;
                p0 = p1;
                p1 = p2;
            }
            let dp = n as f64 * (z * p1 - p0) / (z * z - 1.0);
            let dz = p1 / dp;
            z -= dz;
            if dz.abs() < 1e-16 {
                let (mut p0, mut p1) = (1.0, z);
                for j in 2..=n {
                    let p2 = ((2 * j - 1) as f64 * z * p1 - (j - 1) as f64 * p0) / j as f64;
                    p0 = p1;
                    p1 = p2;
                }
                let dp = n as f64 * (z * p1 - p0) / (z * z - 1.0);
                x.push(z);
                w.push(2.0 / ((1.0 - z * z) * dp * dp));
                break;
            }
        }
    }
    (x, w)
}
