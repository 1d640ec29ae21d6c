//! The isotropic dilation of the one-loop galaxy bispectrum (what the one-loop block's Alcock–Paczynski
//! effect rests on, issue 50): a triangle of sides s k sees, with the linear spectrum P, what the triangle of
//! sides k sees with P(s ·) (`LinearSpectrum::dilated`), times s³ for the loops (∫d³q), s^d for a
//! counterterm shape with k^d (`REDSHIFT_COUNTERTERM_K_POWERS`), 1 for the tree level; the IR resummation's
//! Σ², δΣ² times s² (`IrInputs::dilated`), the loop rule's cut-offs times s.

use pt_spectra::bispectrum::bias_kernels::LoopBias;
use pt_spectra::bispectrum::galaxy_counterterms_rsd::{
    redshift_counterterm_shapes, REDSHIFT_COUNTERTERMS, REDSHIFT_COUNTERTERM_K_POWERS,
};
use pt_spectra::bispectrum::one_loop::OneLoopRule;
use pt_spectra::bispectrum::one_loop_galaxy_multipoles::one_loop_galaxy_multipoles;
use pt_spectra::bispectrum::one_loop_ir::one_loop_galaxy_multipoles_ir;
use pt_spectra::bispectrum::one_loop_rsd::Orientation;
use pt_spectra::bispectrum::{IrInputs, LegendreSide};
use pt_spectra::ir::WiggleSplit;
use pt_spectra::linear::LinearSpectrum;

/// P(s k) is the spectrum at s k (1e-12: the same spline moved), and refused for s ≤ 0.
#[test]
fn a_dilated_spectrum_is_the_spectrum_at_dilated_k() {
    let p = LinearSpectrum::gm2012(0.5).unwrap();
    for s in [0.9, 1.0 / 1.07, 1.12] {
        let d = p.dilated(s).unwrap();
        for k in [1e-4, 0.01, 0.0637, 0.1, 0.23, 1.0, 5.0, 40.0] {
            let (got, want) = (d.eval(k), p.eval(s * k));
            assert!(
                (got - want).abs() <= 1e-12 * want,
                "s = {s}, k = {k}: {got} vs {want}"
            );
        }
    }
    for s in [0.0, -1.0, f64::NAN] {
        let e = p.dilated(s).unwrap_err().to_string();
        assert!(e.contains("dilation"), "{e}");
    }
}

/// Every counterterm and stochastic shape at the sides s k with P equals s^d times the shape at k with
/// P(s ·), d from the shape's units (2 for ct_*, 0 for st_*), to 1e-12; the powers are not all one
/// number (the test would pass with a wrong uniform d otherwise only if s^d were 1).
#[test]
fn the_counterterm_shapes_scale_with_their_powers_of_k() {
    let p = LinearSpectrum::gm2012(0.5).unwrap();
    let bias = LoopBias::from_values([2.1, 0.6, -0.3, 0.4, 0.5, -0.2, 0.35, 0.3, -0.4, 0.25, 0.6]);
    let o = Orientation {
        mu1: 0.37,
        phi: 1.3,
    };
    for s in [1.0 / 1.08, 1.1] {
        let d = p.dilated(s).unwrap();
        for k in [[0.05, 0.07, 0.1], [0.02, 0.1, 0.11], [0.08, 0.08, 0.08]] {
            let at_sk =
                redshift_counterterm_shapes(&p, k.map(|x| s * x), &bias, (0.72, o)).unwrap();
            let at_k = redshift_counterterm_shapes(&d, k, &bias, (0.72, o)).unwrap();
            for i in 0..REDSHIFT_COUNTERTERMS.len() {
                let want = s.powi(REDSHIFT_COUNTERTERM_K_POWERS[i]) * at_k[i];
                assert!(
                    (at_sk[i] - want).abs() <= 1e-12 * want.abs(),
                    "{} at {k:?}, s = {s}: {} vs {want}",
                    REDSHIFT_COUNTERTERMS[i],
                    at_sk[i]
                );
            }
        }
    }
    for (name, d) in REDSHIFT_COUNTERTERMS
        .iter()
        .zip(REDSHIFT_COUNTERTERM_K_POWERS)
    {
        assert_eq!(d, if name.starts_with("ct_") { 2 } else { 0 }, "{name}");
    }
}

/// B₀, B₂, B₄ of the one-loop galaxy bispectrum at the sides s k with P, the loop rule's cut-offs times s,
/// equal the tree level plus s³ times the loops at k with P(s ·) (every node of the rule moves with the sides;
/// measured 8e-8 of B₀, the rounding of the UV subtractions, whose kernel limits at q = 1e3 k_max cancel
/// many digits; bound 1e-6), without and with the IR resummation (Σ², δΣ² times s²); the loops differ from
/// the undilated ones by ≫ that (the test can fail).
#[test]
fn the_one_loop_multipoles_of_dilated_sides_are_those_of_the_dilated_spectrum() {
    let p = LinearSpectrum::gm2012(0.5).unwrap();
    let ir = IrInputs::split(&p, &WiggleSplit::new().unwrap(), 1e-4).unwrap();
    let bias = LoopBias::from_values([2.1, 0.6, -0.3, 0.4, 0.5, -0.2, 0.35, 0.3, -0.4, 0.25, 0.6]);
    let rule = OneLoopRule {
        radial: 3,
        mu: 3,
        phi: 3,
        ..OneLoopRule::default()
    };
    let k = [0.05, 0.07, 0.1];
    let s = 1.0 / 1.06;
    let scaled_rule = OneLoopRule {
        q_min: rule.q_min * s,
        q_max: rule.q_max * s,
        ..rule
    };
    let (f, side, orient) = (0.74, LegendreSide::Largest, Some((3, 5)));
    let d = p.dilated(s).unwrap();
    let ir_d = ir.dilated(s).unwrap();
    for with_ir in [false, true] {
        let (at_sk, at_k, undilated) = if with_ir {
            let m = |p, ir, k, rule| {
                one_loop_galaxy_multipoles_ir(p, ir, k, f, side, rule, orient).unwrap()
            };
            (
                m(&p, &ir, k.map(|x| s * x), &scaled_rule),
                m(&d, &ir_d, k, &rule),
                m(&p, &ir, k, &rule),
            )
        } else {
            let m = |p, k, rule| one_loop_galaxy_multipoles(p, k, f, side, rule, orient).unwrap();
            (
                m(&p, k.map(|x| s * x), &scaled_rule),
                m(&d, k, &rule),
                m(&p, k, &rule),
            )
        };
        let (a, b, u) = (
            at_sk.evaluate(&bias).unwrap(),
            at_k.evaluate(&bias).unwrap(),
            undilated.evaluate(&bias).unwrap(),
        );
        let b0 = a[0].total().value.abs();
        for l in 0..3 {
            let want = b[l].tree.value + s.powi(3) * b[l].loop_correction().value;
            let got = a[l].total().value;
            assert!(
                (got - want).abs() <= 1e-6 * b0,
                "IR {with_ir}, l = {}: {got} vs {want}",
                2 * l
            );
        }
        let change = (a[0].loop_correction().value - u[0].loop_correction().value).abs();
        assert!(
            change > 1e-3 * b0,
            "IR {with_ir}: the dilation changes the loops by {change}"
        );
    }
}

/// B_ℓ of the loops under an anisotropic distortion, by brute force: each orientation n̂ of the observed
/// triangle maps its sides to the true frame (k∥/α∥, k⊥/α⊥), and the loop correction of the true triangle at
/// the true orientation of n̂ (one orientation of the direct path) is weighted by (2ℓ + 1) L_ℓ(n̂·k̂_a) of
/// the observed side a and the volume 1/(α∥²α⊥⁴), on the folded product rule `orient` in n̂.
fn loops_by_orientation(
    p: &LinearSpectrum,
    k: [f64; 3],
    (q_par, q_perp): (f64, f64),
    (f, bias): (f64, &LoopBias),
    rule: &OneLoopRule,
    orient: (usize, usize),
) -> [f64; 3] {
    use pt_spectra::bispectrum::one_loop::triangle_vectors;
    use pt_spectra::bispectrum::one_loop_galaxy_multipoles::{
        legendre_024, legendre_side_index, orientation_nodes,
    };
    use pt_spectra::bispectrum::one_loop_galaxy_poly::one_loop_galaxy_polynomial;
    let dot = |a: [f64; 3], b: [f64; 3]| a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
    let unit = |a: [f64; 3]| {
        let n = dot(a, a).sqrt();
        a.map(|x| x / n)
    };
    let kv = triangle_vectors(k).unwrap();
    let a = legendre_side_index(&k, LegendreSide::Largest).unwrap();
    let volume = 1.0 / (q_par * q_par * q_perp.powi(4));
    let mut out = [0.0; 3];
    for (o, w) in orientation_nodes(orient.0, orient.1) {
        let n = o.line_of_sight().unwrap();
        let to_true = |v: [f64; 3]| {
            let par = dot(v, n);
            std::array::from_fn(|i| (v[i] - par * n[i]) / q_perp + par * n[i] / q_par)
        };
        let t: [[f64; 3]; 3] = kv.map(to_true);
        let sides = t.map(|v| dot(v, v).sqrt());
        // n̂ in the true triangle's frame: k₁ along z, k₂ in the x–z plane (x > 0)
        let ez = unit(t[0]);
        let ex = unit(std::array::from_fn(|i| t[1][i] - dot(t[1], ez) * ez[i]));
        let ey = [
            ez[1] * ex[2] - ez[2] * ex[1],
            ez[2] * ex[0] - ez[0] * ex[2],
            ez[0] * ex[1] - ez[1] * ex[0],
        ];
        let true_o = Orientation {
            mu1: dot(n, ez).clamp(-1.0, 1.0),
            phi: dot(n, ey).atan2(dot(n, ex)),
        };
        let b = one_loop_galaxy_polynomial(p, sides, Some((f, true_o)), rule)
            .unwrap()
            .evaluate(bias)
            .unwrap()
            .loop_correction()
            .value;
        let legendre = legendre_024(dot(n, unit(kv[a])));
        for l in 0..3 {
            out[l] += w * (4 * l + 1) as f64 * legendre[l] * volume * b;
        }
    }
    out
}

/// What the one-loop block neglects of AP (its loops exact under the isotropic dilation α = (α∥α⊥²)^{1/3},
/// the anisotropic rest on the tree level only), against the loops by brute force over the orientations:
/// at the Nseries α = (1.0546, 1.0451) and at a strong anisotropy (1.1, 0.95), for triangles from squeezed
/// to equilateral. The brute force at 6 × 11 orientations is checked against 5 × 9; the dilated
/// loops (the block's) and the undistorted ones times the volume (the former block's) are compared with
/// it, relative to B₀ (tree + loops). Measured (gm2012 z = 0.5, f = 0.76, velocileptors' (2, 0.4, −0.3),
/// loops 7–18% of B₀, brute force on 8 × 14 within 4e-6 of 6 × 11): at the Nseries α the block's worst error 3.8e-4 of
/// B₀ (B₂ of (0.05, 0.07, 0.1)), the former's 6.8e-3; at (1.1, 0.95) 5.4e-3 and 5.8e-3 (nearly no
/// isotropic part: the anisotropic rest is what remains). Asserted: the block's error ≤ the former's, and
/// at the Nseries α ≤ 1/4 of it and ≤ 1e-3 of B₀.
#[test]
#[ignore = "a measurement, ~1 min: cargo test --release -p pt-spectra-tests --test suite -- --ignored anisotropic"]
fn the_anisotropic_rest_of_ap_on_the_loops_is_small() {
    let p = LinearSpectrum::gm2012(0.5).unwrap();
    let bias = LoopBias::from_velocileptors(2.0, 0.4, -0.3);
    let f = 0.76;
    let rule = OneLoopRule {
        radial: 3,
        mu: 6,
        phi: 4,
        ..OneLoopRule::default()
    };
    for q in [(1.0546f64, 1.0451f64), (1.1, 0.95)] {
        let alpha = (q.0 * q.1 * q.1).cbrt();
        let true_rule = OneLoopRule {
            q_min: rule.q_min / alpha,
            q_max: rule.q_max / alpha,
            ..rule
        };
        let (mut worst_block, mut worst_former) = (0.0f64, 0.0f64);
        for k in [
            [0.02, 0.07, 0.08],
            [0.045, 0.055, 0.065],
            [0.07, 0.07, 0.07],
            [0.05, 0.07, 0.1],
        ] {
            let brute = loops_by_orientation(&p, k, q, (f, &bias), &true_rule, (6, 11));
            let coarse = loops_by_orientation(&p, k, q, (f, &bias), &true_rule, (5, 9));
            let multipoles = |k: [f64; 3], rule: &OneLoopRule| {
                one_loop_galaxy_multipoles(&p, k, f, LegendreSide::Largest, rule, None)
                    .unwrap()
                    .evaluate(&bias)
                    .unwrap()
            };
            let volume = 1.0 / (q.0 * q.0 * q.1.powi(4));
            let dilated = multipoles(k.map(|x| x / alpha), &true_rule);
            let undistorted = multipoles(k, &rule);
            let b0 = volume * dilated[0].total().value.abs();
            for l in 0..3 {
                let block = volume * dilated[l].loop_correction().value;
                let former = volume * undistorted[l].loop_correction().value;
                let (e_block, e_former) = ((block - brute[l]) / b0, (former - brute[l]) / b0);
                eprintln!(
                    "alpha {q:?} k {k:?} B{}: loops/B0 {:.3e}, brute force 8x14 vs 6x11 {:.1e}, block {:.2e}, \
                     former {:.2e}",
                    2 * l,
                    brute[l] / b0,
                    (brute[l] - coarse[l]) / b0,
                    e_block,
                    e_former
                );
                worst_block = worst_block.max(e_block.abs());
                worst_former = worst_former.max(e_former.abs());
            }
        }
        eprintln!("alpha {q:?}: worst block {worst_block:.2e}, former {worst_former:.2e} of B0");
        // nearly isotropic: the block's error a fraction of the former one's; strongly anisotropic (α_iso
        // = 0.998): about the former one's, no larger
        assert!(worst_block <= worst_former, "{q:?}");
        if q.0 < 1.06 {
            assert!(
                worst_block <= 0.25 * worst_former && worst_block <= 1e-3,
                "{q:?}"
            );
        }
    }
}
