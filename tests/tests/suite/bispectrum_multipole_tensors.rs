//! The one-loop galaxy multipole tensors (16 SVD templates, f free) against the direct one pass of the
//! true spectrum, on spectra not in the training set (issue 50: ≤ 1e-3 of direct). The comparison is node
//! for node (the same coarse rule on both paths), so it measures what the templates' projection leaves:
//! `-- --ignored --nocapture`, ~2 min on one core, prints the table of docs/bispectrum.md.

use pt_spectra::bispectrum::bias_kernels::LoopBias;
use pt_spectra::bispectrum::multipole_basis::MultipoleLoopBasis;
use pt_spectra::bispectrum::one_loop::OneLoopRule;
use pt_spectra::bispectrum::one_loop_galaxy_multipoles::one_loop_galaxy_multipoles;
use pt_spectra::bispectrum::LegendreSide;

use super::bispectrum_basis_truncation::spectra;

/// From the squeezed to the equilateral in the Nseries range (0.015–0.075 h/Mpc) and one beyond it.
const TRIANGLES: [[f64; 3]; 4] = [
    [0.015, 0.075, 0.075],
    [0.035, 0.055, 0.065],
    [0.065, 0.065, 0.065],
    [0.1, 0.15, 0.2],
];

/// B_ℓ (tree + one loop, two biases, f = 0.5 and 0.9) from the tensors against the direct pass of P, each
/// difference relative to |B₀| of its case: ≤ 1e-3 on every represented spectrum (projection residual ≤
/// `MAX_RESIDUAL`), and within the tensors' stated error (which carries 3 ε Σ|loop terms|).
#[test]
#[ignore = "2 min: the accuracy of the multipole tensors (run with --ignored)"]
fn multipole_tensors_against_direct_on_spectra_not_trained_on() {
    let rule = OneLoopRule {
        radial: 4,
        mu: 8,
        phi: 6,
        ..OneLoopRule::default()
    };
    let basis =
        MultipoleLoopBasis::build(&TRIANGLES, LegendreSide::Largest, &rule, &|_, _| {}).unwrap();
    let biases = [
        LoopBias::from_velocileptors(2.0, 0.3, -0.2),
        LoopBias::from_class_pt(1.6, -0.5, -0.3, 0.2),
    ];
    let mut worst = 0.0f64;
    println!("spectrum                                   residual   worst |ΔB_l|/|B0|   worst |ΔB_l|/error");
    for (name, p) in spectra() {
        let (_, projection) = basis.project(&p);
        let represented = projection.residual <= pt_spectra::loops::basis::MAX_RESIDUAL;
        let (mut rel, mut of_error) = (0.0f64, 0.0f64);
        for f in [0.5, 0.9] {
            let fast = basis.evaluate(&p, f).unwrap();
            for (t, &k) in TRIANGLES.iter().enumerate() {
                let direct =
                    one_loop_galaxy_multipoles(&p, k, f, LegendreSide::Largest, &rule, None)
                        .unwrap();
                for bias in &biases {
                    let a = fast[t].evaluate(bias).unwrap();
                    let b = direct.evaluate(bias).unwrap();
                    let b0 = b[0].total().value.abs();
                    for ell in 0..3 {
                        let (x, y) = (a[ell].total(), b[ell].total());
                        let d = (x.value - y.value).abs();
                        rel = rel.max(d / b0);
                        of_error = of_error.max(d / x.error);
                    }
                }
            }
        }
        println!(
            "{name:<42} {:9.2e} {rel:12.2e} {of_error:16.2}{}",
            projection.residual,
            if represented {
                ""
            } else {
                "   (not represented)"
            }
        );
        if represented {
            worst = worst.max(rel);
            assert!(
                of_error <= 1.0,
                "{name}: the difference exceeds the stated error ({of_error})"
            );
        }
    }
    assert!(worst <= 1e-3, "worst {worst}");
}

/// The same with the IR resummation (the loops on P_LO, whose residual on the templates is larger; the
/// factors outside the integrals P_LO's own values): prints the worst |ΔB_ℓ|/|B₀| and |ΔB_ℓ|/error per
/// spectrum; every difference of a spectrum the tensors represent (P_LO's residual ≤ `IR_MAX_RESIDUAL`,
/// every one but the curved table) within the stated error and ≤ 1e-3 of B₀ (measured 9.8e-4 at most;
/// with the projection's values at the sides it was 3.1e-3).
#[test]
#[ignore = "1 min: the accuracy of the resummed multipole tensors (run with --ignored)"]
fn resummed_multipole_tensors_against_direct() {
    use pt_spectra::bispectrum::one_loop_ir::one_loop_galaxy_multipoles_ir;
    use pt_spectra::bispectrum::IrInputs;
    let rule = OneLoopRule {
        radial: 3,
        mu: 6,
        phi: 4,
        ..OneLoopRule::default()
    };
    let basis =
        MultipoleLoopBasis::build(&TRIANGLES, LegendreSide::Largest, &rule, &|_, _| {}).unwrap();
    let bias = LoopBias::from_velocileptors(2.0, 0.3, -0.2);
    let split = pt_spectra::ir::WiggleSplit::new().unwrap();
    let q_min = pt_spectra::precision::Precision::default().q_min;
    let f = 0.7;
    for (name, p) in spectra() {
        let Ok(ir) = IrInputs::split(&p, &split, q_min) else {
            continue;
        };
        let (fast, projection) = basis.evaluate_projected(&p, f, Some(&ir)).unwrap();
        let residual = projection.residual;
        let (mut rel, mut of_error) = (0.0f64, 0.0f64);
        for (t, &k) in TRIANGLES.iter().enumerate() {
            let direct =
                one_loop_galaxy_multipoles_ir(&p, &ir, k, f, LegendreSide::Largest, &rule, None)
                    .unwrap();
            let a = fast[t].evaluate(&bias).unwrap();
            let b = direct.evaluate(&bias).unwrap();
            let b0 = b[0].total().value.abs();
            for ell in 0..3 {
                let (x, y) = (a[ell].total(), b[ell].total());
                let d = (x.value - y.value).abs();
                rel = rel.max(d / b0);
                of_error = of_error.max(d / x.error);
            }
        }
        println!("IR {name:<42} {residual:9.2e} {rel:12.2e} {of_error:16.2}");
        if residual <= pt_spectra::bispectrum::loop_tensors::IR_MAX_RESIDUAL {
            assert!(
                of_error <= 1.0,
                "{name}: the difference exceeds the stated error ({of_error})"
            );
            assert!(rel <= 1e-3, "{name}: {rel} of B0");
        }
    }
}

/// The bins from tensors (`MultipoleBinBasis`: the effective triangle's tensors plus the folded correction)
/// against the direct bins (`binned_multipoles`, the same rules) on spectra not in the training set: one
/// Nseries-like bin of width 0.01 h/Mpc, f = 0.7, without and with IR (P_LO's residual under
/// `IR_MAX_RESIDUAL`); every |ΔB_ℓ| ≤ 1e-3 of |B₀| and within the
/// stated error (the issue's ≤ 1e-3 of direct for the binned multipoles). Prints the table of
/// docs/bispectrum.md.
#[test]
#[ignore = "2 min: the accuracy of the multipole bin tensors (run with --ignored)"]
fn multipole_bins_against_direct_bins_on_spectra_not_trained_on() {
    use pt_spectra::bispectrum::loop_tensors::tensor_source;
    use pt_spectra::bispectrum::multipole_bins::MultipoleBinBasis;
    use pt_spectra::bispectrum::one_loop_basis::BispectrumLoopSource;
    use pt_spectra::bispectrum::one_loop_bins::binned_multipoles;
    use pt_spectra::bispectrum::TriangleSet;
    let rule = OneLoopRule {
        radial: 2,
        mu: 4,
        phi: 3,
        ..OneLoopRule::default()
    };
    let set = TriangleSet::shells(vec![[0.035, 0.055, 0.065]], 0.01).unwrap();
    let bins = MultipoleBinBasis::build(&set, LegendreSide::Largest, &rule, &|_, _| {}).unwrap();
    let bias = LoopBias::from_class_pt(1.8, -0.4, -0.3, 0.2);
    let f = 0.7;
    let names = [
        "planck2018_z0.0.dat",
        "camb_heldout_0.dat",
        "camb_w0wa_z1.0.dat",
    ];
    println!(
        "bins: spectrum                          residual   worst |ΔB_l|/|B0|   worst |ΔB_l|/error"
    );
    let split = pt_spectra::ir::WiggleSplit::new().unwrap();
    let q_min = pt_spectra::precision::Precision::default().q_min;
    for (name, p) in spectra()
        .into_iter()
        .filter(|(n, _)| names.contains(&n.as_str()))
    {
        let ir = pt_spectra::bispectrum::IrInputs::split(&p, &split, q_min).unwrap();
        for ir in [None, Some(&ir)] {
            let (fast, projection) = bins.evaluate_projected(&p, f, ir).unwrap();
            let direct =
                binned_multipoles(&p, ir, &set, f, LegendreSide::Largest, &rule, &|_, _| {})
                    .unwrap();
            let (a, b) = (
                fast.evaluate(&bias).unwrap(),
                direct.evaluate(&bias).unwrap(),
            );
            let b0 = b[0][0].total().value.abs();
            let (mut rel, mut of_error) = (0.0f64, 0.0f64);
            for ell in 0..3 {
                let (x, y) = (a[0][ell].total(), b[0][ell].total());
                let d = (x.value - y.value).abs();
                rel = rel.max(d / b0);
                of_error = of_error.max(d / x.error);
            }
            let tag = if ir.is_some() { "IR " } else { "" };
            println!(
                "bins: {tag}{name:<34} {:9.2e} {rel:12.2e} {of_error:16.2}",
                projection.residual
            );
            let source = tensor_source(projection.residual, ir.is_some());
            assert!(matches!(source, BispectrumLoopSource::Basis { .. }));
            assert!(rel <= 1e-3, "{tag}{name}: {rel} of B0");
            assert!(
                of_error <= 1.0,
                "{tag}{name}: beyond the stated error ({of_error})"
            );
        }
    }
}
