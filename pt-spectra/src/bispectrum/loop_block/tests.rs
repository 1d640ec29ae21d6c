//! The one-loop bispectrum block against its parts computed independently: the tensors' loops at the bias
//! of the exact map, and the direct counterterm shapes.

use super::*;
use crate::bispectrum::galaxy_counterterms_rsd::{
    redshift_counterterm_multipoles, REDSHIFT_COUNTERTERMS,
};
use crate::statistic::{OptionValue, Options};

const TRIANGLES: [[f64; 3]; 2] = [[0.05, 0.07, 0.1], [0.04, 0.04, 0.06]];

fn rule() -> OneLoopRule {
    OneLoopRule {
        radial: 2,
        mu: 2,
        phi: 2,
        ..OneLoopRule::default()
    }
}

/// B₀, B₂, B₄ of the one-loop galaxy bispectrum of the sides `k` by the direct one pass on `rule`.
fn direct_multipoles(
    p: &LinearSpectrum,
    k: [f64; 3],
    f: f64,
    rule: &OneLoopRule,
    bias: &LoopBias,
) -> [OneLoopGalaxy; 3] {
    crate::bispectrum::one_loop_galaxy_multipoles::one_loop_galaxy_multipoles(
        p,
        k,
        f,
        LegendreSide::Largest,
        rule,
        None,
    )
    .unwrap()
    .evaluate(bias)
    .unwrap()
}

/// The pipeline face's options for `TRIANGLES` on `rule()` in `dir`.
fn options(dir: &std::path::Path, ells: &[i64]) -> Options {
    let list = |v: &[f64]| OptionValue::List(v.iter().map(|&x| OptionValue::Number(x)).collect());
    Options {
        entries: vec![
            (
                "triangles".into(),
                OptionValue::List(TRIANGLES.iter().map(|t| list(t)).collect()),
            ),
            (
                "rule".into(),
                OptionValue::List(vec![OptionValue::Integer(2); 3]),
            ),
            (
                "ells".into(),
                OptionValue::List(ells.iter().map(|&l| OptionValue::Integer(l)).collect()),
            ),
            (
                "cache_dir".into(),
                OptionValue::Text(dir.display().to_string()),
            ),
        ],
        ..Options::default()
    }
}

/// The block from the pipeline face reads the tensors a table job cached (refusing before they are), and
/// its entries are the tensors' loops at the exact bias map plus Σ c_s × the direct counterterm
/// multipoles (1e-10); every own parameter enters linearly (the fit marginalises all of them); under an
/// isotropic AP dilation the block is the direct multipoles of the true sides (the loops to the tensors'
/// accuracy, the counterterms to 1e-10), and an anisotropic one adds the tree-level block's change from the
/// isotropic part.
#[test]
fn the_block_is_its_parts_and_linear_in_its_own_parameters() {
    assert_eq!(&LOOP_NAMES[LOOP_BIASES.len()..], &REDSHIFT_COUNTERTERMS[..]);
    assert_eq!(LOOP_NAMES[..LOOP_BIASES.len()], LOOP_BIASES);
    let dir = std::env::temp_dir().join(format!("pt-loop-block-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    let spec = (faces::FACES.pipeline)(&options(&dir, &[0, 2]))
        .unwrap()
        .unwrap();
    let e = spec.plan().unwrap_err().to_string();
    assert!(
        e.contains("not cached") && e.contains("--two-loop basis"),
        "{e}"
    );
    let store = TableStore::new(&dir);
    let set = TriangleSet::points(TRIANGLES.to_vec()).unwrap();
    let tensors = super::super::loop_tensors::one_loop_multipole_tensors(
        set.triangles(),
        LegendreSide::Largest,
        &rule(),
        &store,
        &Silent,
    )
    .unwrap();
    let block = spec.plan().unwrap();
    assert_eq!(block.len(), 4);
    assert!(block.entry(3).contains("B2"), "{}", block.entry(3));
    let p = LinearSpectrum::gm2012(0.5).unwrap();
    let prepared = block.prepare(&p, false).unwrap();
    let f = 0.74;
    let terms = block.terms(&p, &prepared, f, (1.0, 1.0)).unwrap();
    let shared = Shared {
        b1: 2.1,
        b2: -0.4,
        bs: 0.3,
    };
    let own: Vec<f64> = (0..LOOP_NAMES.len())
        .map(|i| 0.3 * (i as f64 - 7.0) * if i < 5 { 0.3 } else { 20.0 })
        .collect();
    let got = terms.values(shared, &own).unwrap();
    // the parts: the exact map of velocileptors' b1, b2, bs and CLASS-PT's b_Gamma3
    let mut bias = LoopBias::from_class_pt(2.1, -0.4 + 0.4, 0.3, own[0]);
    (bias.b3, bias.g2x, bias.g3, bias.g21x) = (own[1], own[2], own[3], own[4]);
    let loops = tensors.evaluate(&p, f).unwrap();
    for (j, (&l, t)) in [0usize, 1]
        .iter()
        .flat_map(|l| TRIANGLES.iter().enumerate().map(move |t| (l, t)))
        .enumerate()
    {
        let (i, k) = t;
        let row = loops[i].evaluate(&bias).unwrap();
        let shapes =
            redshift_counterterm_multipoles(&p, *k, &bias, f, LegendreSide::Largest).unwrap();
        let ct: f64 = own[5..].iter().zip(&shapes[l]).map(|(c, s)| c * s).sum();
        let want = row[l].total().value + ct;
        assert!(
            (got[j] - want).abs() <= 1e-10 * want.abs().max(row[0].total().value.abs()),
            "entry {j}: {} vs {want}",
            got[j]
        );
    }
    // linear in every own parameter: v(2 e_i) - v(0) = 2 (v(e_i) - v(0))
    let zero = terms.values(shared, &[0.0; 25]).unwrap();
    for i in 0..LOOP_NAMES.len() {
        let at = |x: f64| {
            let mut v = [0.0; 25];
            v[i] = x;
            terms.values(shared, &v).unwrap()
        };
        let (one, two) = (at(1.0), at(2.0));
        let scale = one
            .iter()
            .zip(&zero)
            .map(|(a, b)| (a - b).abs())
            .fold(0.0, f64::max);
        assert!(scale > 0.0, "{} does not enter", LOOP_NAMES[i]);
        for ((o, t), z) in one.iter().zip(&two).zip(&zero) {
            assert!(
                ((t - z) - 2.0 * (o - z)).abs() <= 1e-9 * (scale + z.abs()),
                "{} is not linear",
                LOOP_NAMES[i]
            );
        }
    }
    // a selection of the planned triangles: their rows of the whole block
    let second = LoopBispectrumBlock {
        triangles: set.clone(),
        side: LegendreSide::Largest,
        rule: rule(),
        ells: vec![0, 2],
        cache_dir: Some(dir.clone()),
        fitted: Some(vec![1]),
    }
    .plan()
    .unwrap();
    assert_eq!(second.len(), 2);
    let prepared_second = second.prepare(&p, false).unwrap();
    let picked = second
        .terms(&p, &prepared_second, f, (1.0, 1.0))
        .unwrap()
        .values(shared, &own)
        .unwrap();
    assert_eq!(picked, vec![got[1], got[3]]);
    // AP, isotropic: every term exact (the counterterms to 1e-10, the tree and loops to the tensors'
    // accuracy), against the direct multipoles of the true sides k/α (the loop rule's cut-offs with them):
    // measured ≤ 7.9e-5 of B₀ at α = 1.08, where the former approximation (loops undistorted, times the
    // volume) was 5.2e-3 to 9.8e-3 off
    let alpha: f64 = 1.08;
    let volume = alpha.powi(-6);
    let dilated = block.terms(&p, &prepared, f, (alpha, alpha)).unwrap();
    let no_ct: Vec<f64> = own[..5].iter().copied().chain([0.0; 20]).collect();
    let (iso, iso_no_ct) = (
        dilated.values(shared, &own).unwrap(),
        dilated.values(shared, &no_ct).unwrap(),
    );
    let true_rule = OneLoopRule {
        q_min: rule().q_min / alpha,
        q_max: rule().q_max / alpha,
        ..rule()
    };
    for (j, (&l, (i, k))) in [0usize, 1]
        .iter()
        .flat_map(|l| TRIANGLES.iter().enumerate().map(move |t| (l, t)))
        .enumerate()
    {
        let k_true = k.map(|x| x / alpha);
        let shapes =
            redshift_counterterm_multipoles(&p, k_true, &bias, f, LegendreSide::Largest).unwrap();
        let ct: f64 = own[5..].iter().zip(&shapes[l]).map(|(c, s)| c * s).sum();
        assert!(
            (iso[j] - iso_no_ct[j] - volume * ct).abs() <= 1e-10 * (volume * ct).abs(),
            "counterterms under AP, entry {j}"
        );
        let direct = direct_multipoles(&p, k_true, f, &true_rule, &bias);
        let want = volume * direct[l].total().value;
        let b0 = volume * direct[0].total().value;
        // the former approximation: the loops undistorted, the tree exact
        let row = loops[i].evaluate(&bias).unwrap();
        let former =
            volume * direct[l].tree.value + volume * (row[l].total().value - row[l].tree.value);
        assert!(
            (iso_no_ct[j] - want).abs() <= 5e-4 * b0.abs(),
            "isotropic AP, entry {j}: {} vs {want}",
            iso_no_ct[j]
        );
        assert!((former - want).abs() > 2e-3 * b0.abs(), "entry {j}");
    }
    // anisotropic: the isotropic part's block plus the tree's change from (α_iso, α_iso) to (α∥, α⊥), the
    // tree-level block's
    let (q_par, q_perp): (f64, f64) = (1.03, 0.98);
    let alpha = (q_par * q_perp * q_perp).cbrt();
    let tree_block = crate::bispectrum::block::BispectrumBlock {
        ells: vec![0, 2],
        ..crate::bispectrum::block::BispectrumBlock::monopole(set.clone())
    }
    .plan()
    .unwrap();
    let tree_prepared = tree_block.prepare(&p, false).unwrap();
    let tree_at = |q: (f64, f64)| {
        tree_block
            .terms(&p, &tree_prepared, f, q)
            .unwrap()
            .values(shared, &[0.0, 0.0, 0.0, 0.0])
            .unwrap()
    };
    let (tree_q, tree_iso) = (tree_at((q_par, q_perp)), tree_at((alpha, alpha)));
    let at_q = block
        .terms(&p, &prepared, f, (q_par, q_perp))
        .unwrap()
        .values(shared, &own)
        .unwrap();
    let at_iso = block
        .terms(&p, &prepared, f, (alpha, alpha))
        .unwrap()
        .values(shared, &own)
        .unwrap();
    let mut st_1 = own.clone();
    st_1[11] += 1e6;
    let with_st_1 = block
        .terms(&p, &prepared, f, (q_par, q_perp))
        .unwrap()
        .values(shared, &st_1)
        .unwrap();
    let volume = 1.0 / (q_par * q_par * q_perp.powi(4));
    for (j, &l) in [0usize, 0, 1, 1].iter().enumerate() {
        let want = at_iso[j] + (tree_q[j] - tree_iso[j]);
        assert!(
            (at_q[j] - want).abs() <= 1e-10 * want.abs(),
            "AP entry {j}: {} vs {want}",
            at_q[j]
        );
        let st = if l == 0 { 1e6 * volume } else { 0.0 };
        assert!(
            (with_st_1[j] - at_q[j] - st).abs() <= 1e-6 * want.abs(),
            "st_1 at entry {j}"
        );
        // the anisotropy matters at this size: the tree's change is ≥ 1e-3 of B
        assert!(
            (tree_q[j] - tree_iso[j]).abs() > 1e-3 * want.abs(),
            "entry {j}"
        );
    }
    let _ = std::fs::remove_dir_all(&dir);
}

/// An analysis file's `[dataset.one_loop_bispectrum]`: the fitted triangles' block on the table's rule,
/// the entries of the file; a bad rule and a key of the tree-level block are refused, named.
#[test]
fn the_analysis_face_reads_the_measurement_and_the_rule() {
    let dir = std::env::temp_dir().join(format!("pt-loop-face-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let data = dir.join("bk.dat");
    std::fs::write(
        &data,
        "# k1 k2 k3 B0 B2\n0.05 0.07 0.1 1e9 2e8\n0.04 0.04 0.06 2e9 3e8\n0.1 0.12 0.2 1e8 1e7\n",
    )
    .unwrap();
    let cov = dir.join("cov.dat");
    std::fs::write(&cov, "1\n").unwrap();
    let text = |k: &str, v: &str| (k.to_string(), OptionValue::Text(v.into()));
    let ints = |k: &str, v: &[i64]| {
        (
            k.to_string(),
            OptionValue::List(v.iter().map(|&x| OptionValue::Integer(x)).collect()),
        )
    };
    let mut o = Options {
        entries: vec![
            text("data", "bk.dat"),
            ints("data_ells", &[0, 2]),
            ints("ells", &[0, 2]),
            ("k_max".into(), OptionValue::Number(0.15)),
            text("covariance", "cov.dat"),
            ints("rule", &[2, 2, 2]),
            text("cache_dir", &dir.display().to_string()),
        ],
        base: Some(dir.clone()),
        ..Options::default()
    };
    let face = faces::FACES.analysis.unwrap();
    (face.check)(&o).unwrap();
    let m = (face.measure)(&o).unwrap();
    // the two triangles within k_max, multipole then triangle, among the file's 2 x 3 entries
    assert_eq!(m.fitted, vec![0, 1, 3, 4]);
    assert_eq!(m.columns.len(), 2);
    // its tensors are the file's three triangles', of which it fits two
    let e = m.spec.plan().unwrap_err().to_string();
    assert!(e.contains("3 triangles") && e.contains("2 x 2 x 2"), "{e}");
    o.entries.push(ints("rule", &[2, 2]));
    o.entries.remove(5);
    let e = (face.check)(&o).unwrap_err().to_string();
    assert!(e.contains("rule"), "{e}");
    o.entries.pop();
    o.entries.push(("n_bar".into(), OptionValue::Number(3e-4)));
    let e = (face.check)(&o).unwrap_err().to_string();
    assert!(e.contains("n_bar") && e.contains("unknown key"), "{e}");
    let _ = std::fs::remove_dir_all(&dir);
}

/// CAMB tables in `tests/data/` that the basis was not trained on.
const HELD_OUT: [&str; 5] = [
    "linear_pk_camb_heldout_0.dat",
    "linear_pk_camb_heldout_1.dat",
    "linear_pk_camb_heldout_2.dat",
    "linear_pk_planck2018_z1.0.dat",
    "linear_pk_planck2018_z0.0.dat",
];

/// The spectra of the tables `names` in `tests/data/`.
fn tables(names: &[&str]) -> Vec<LinearSpectrum> {
    let data = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/data/");
    names
        .iter()
        .map(|f| LinearSpectrum::from_file(format!("{data}{f}")).unwrap())
        .collect()
}

/// The multipole tensors of [`TRIANGLES`] on [`rule`], built into a new store in the temporary directory
/// named `tag` (and the process), which the caller removes.
fn tensors_in(
    tag: &str,
) -> (
    std::path::PathBuf,
    Arc<super::super::multipole_basis::MultipoleLoopBasis>,
) {
    let dir = std::env::temp_dir().join(format!("{tag}-{}", std::process::id()));
    let tensors = super::super::loop_tensors::one_loop_multipole_tensors(
        &TRIANGLES,
        LegendreSide::Largest,
        &rule(),
        &TableStore::new(&dir),
        &Silent,
    )
    .unwrap();
    (dir, tensors)
}

/// The loops of the dilated spectrum P(k/α) from the tensors, times α⁻³, against the direct loops of the
/// true sides k/α (the rule's cut-offs with them), for five spectra (four CAMB tables not trained on) and
/// α from 0.9 to 1.1: the dilated spectrum's projection residual grows with |α − 1| (to 1.1e-2, beyond the
/// templates' MAX_RESIDUAL: the block's [`DILATED_MAX_RESIDUAL`]), and the loops' error with it, measured
/// ≤ 0.4 × the residual of B₀; the former approximation (the loops of P at k) was 3e-3 to 4e-2 off, and
/// the dilation is ≥ 2× better in every case.
#[test]
fn the_dilated_loops_are_the_loops_of_the_true_sides() {
    let (dir, tensors) = tensors_in("pt-loop-dilated");
    let mut spectra = vec![LinearSpectrum::gm2012(0.5).unwrap()];
    spectra.extend(tables(&HELD_OUT[..4]));
    let bias = LoopBias::from_velocileptors(2.0, 0.4, -0.3);
    let f = 0.76;
    let mut largest = 0.0f64;
    for p in &spectra {
        let (undistorted, _) = tensors.evaluate_projected(p, f, None).unwrap();
        for alpha in [0.9f64, 0.95, 1.05, 1.1] {
            let s = 1.0 / alpha;
            let (rows, projection) = tensors
                .evaluate_projected(&p.dilated(s).unwrap(), f, None)
                .unwrap();
            largest = largest.max(projection.residual);
            assert!(projection.residual < DILATED_MAX_RESIDUAL, "{}", p.origin());
            let true_rule = OneLoopRule {
                q_min: rule().q_min * s,
                q_max: rule().q_max * s,
                ..rule()
            };
            let (mut error, mut former) = (0.0f64, 0.0f64);
            for (i, k) in TRIANGLES.iter().enumerate() {
                let direct = direct_multipoles(p, k.map(|x| x * s), f, &true_rule, &bias);
                let (dilated, plain) = (
                    rows[i].evaluate(&bias).unwrap(),
                    undistorted[i].evaluate(&bias).unwrap(),
                );
                let b0 = direct[0].total().value.abs();
                for l in 0..3 {
                    let want = direct[l].loop_correction().value;
                    let got = s.powi(3) * dilated[l].loop_correction().value;
                    error = error.max((got - want).abs() / b0);
                    former = former.max((plain[l].loop_correction().value - want).abs() / b0);
                }
            }
            assert!(
                error <= 0.5 * projection.residual + 1e-4 && error <= 0.5 * former,
                "{} at alpha = {alpha}: {error:.2e} of B0 (residual {:.1e}, former {former:.1e})",
                p.origin(),
                projection.residual
            );
        }
    }
    // the test reaches beyond the templates' limit
    assert!(largest > crate::loops::basis::MAX_RESIDUAL, "{largest}");
    let _ = std::fs::remove_dir_all(&dir);
}

/// With IR the block contracts P_LO, whose residual on the templates is its damped wiggles' (not P's): on
/// the embedded tables at z = 0 and 0.5, five CAMB tables not trained on and four emulated spectra (Ω_m 0.26
/// to 0.38, z = 0 to 1), P_LO at α = 1 lies within `IR_MAX_RESIDUAL` (measured ≤ 4.9e-3; P's own limit,
/// 2e-3, refused six of them, so the block refused IR on them) and dilated within `DILATED_MAX_RESIDUAL` for
/// α = 0.9 … 1.1 (measured ≤ 1.7e-2, as P's own dilation: 1.2e-2).
#[test]
fn the_resummed_spectra_are_represented_at_and_around_alpha_one() {
    use super::super::loop_tensors::IR_MAX_RESIDUAL;
    let (dir, tensors) = tensors_in("pt-loop-dilated-ir");
    let mut spectra = vec![
        LinearSpectrum::gm2012(0.5).unwrap(),
        LinearSpectrum::gm2012(0.0).unwrap(),
    ];
    spectra.extend(tables(&HELD_OUT));
    let emulator = crate::emulator::LinearEmulator::embedded().unwrap();
    for (om, z) in [(0.26, 0.0), (0.31, 0.5), (0.38, 1.0), (0.3, 0.3)] {
        let c = crate::cosmology::Cosmology::flat(om, 0.68, 0.0224, 0.965, 0.8).unwrap();
        let e = emulator.spectra(&c, z).unwrap();
        spectra.push(LinearSpectrum::from_nodes(e.k.clone(), e.p_cb.clone()).unwrap());
    }
    let split = crate::ir::WiggleSplit::new().unwrap();
    let q_min = crate::precision::Precision::default().q_min;
    let mut above_p_limit = 0;
    for (i, p) in spectra.iter().enumerate() {
        let ir = IrInputs::split(p, &split, q_min).unwrap();
        for alpha in [0.9f64, 0.95, 1.0, 1.05, 1.1] {
            let s = 1.0 / alpha;
            let (p, ir) = (p.dilated(s).unwrap(), ir.dilated(s).unwrap());
            let lo = super::super::ir_legs::leading_order_spectrum(&p, &ir).unwrap();
            let r = tensors.project(&lo).1.residual;
            let limit = if alpha == 1.0 {
                above_p_limit += usize::from(r > crate::loops::basis::MAX_RESIDUAL);
                IR_MAX_RESIDUAL
            } else {
                DILATED_MAX_RESIDUAL
            };
            assert!(r <= limit, "spectrum {i} at alpha = {alpha}: {r:.1e}");
        }
    }
    assert!(above_p_limit >= 3, "{above_p_limit}");
    let _ = std::fs::remove_dir_all(&dir);
}

/// The block's units and ranges follow from each name (module docs of `galaxy_counterterms_rsd`): the
/// biases dimensionless, ct_* in (Mpc/h)² (k² shapes), st_p* in (Mpc/h)³ (× P), st_1 in (Mpc/h)⁶; one
/// entry per name.
#[test]
fn the_units_and_ranges_follow_from_the_names() {
    assert_eq!(KIND.units.len(), KIND.own.len());
    assert_eq!(KIND.ranges.len(), KIND.own.len());
    for ((name, unit), range) in KIND.own.iter().zip(KIND.units).zip(KIND.ranges) {
        let (want, want_range) = if LOOP_BIASES.contains(name) {
            ("1", BIAS_RANGE)
        } else if name.starts_with("ct_") {
            ("(Mpc/h)^2", CT_RANGE)
        } else if name.starts_with("st_p") {
            ("(Mpc/h)^3", ST_P_RANGE)
        } else if *name == "st_1" {
            ("(Mpc/h)^6", ST_1_RANGE)
        } else {
            panic!("{name}: no rule for its unit");
        };
        assert_eq!(*unit, want, "{name}");
        assert_eq!(*range, want_range, "{name}");
    }
}
