//! The 2-loop terms from basis tensors (`loops::basis`) against the direct integrals on the same
//! quasi-Monte-Carlo points, for CAMB spectra that are not in the training set: Planck 2018 at z = 0
//! and 1, the gm2012 spectrum, three held-out cosmologies of the prior (one at z = 0.5; w0 from
//! −1.12 to −1.00), a flat w0–wa one and two curved ones (Ω_k = ±0.01, projected cut below the soft
//! modes with the 1-loop terms' soft modes taken out: module `soft`). Their 2-loop corrections must agree to 1e-3 of the correction and within the
//! reported errors; an Eisenstein–Hu spectrum (outside the span of CAMB spectra) must be refused.
//!
//! The tensors are built once here with 2^11 points per shift (the comparison is point for point, so
//! fewer points test the same thing) and read back from their cache file.

use pt_spectra::cosmology::{Cosmology, TransferKind};
use pt_spectra::linear::{LinearSpectrum, LogGrid};
use pt_spectra::loops::basis::{SpectrumFamily, TwoLoopBasis, MAX_RESIDUAL};
use pt_spectra::loops::{p15_terms, two_loop_correction, Estimate, OneLoopPlan, Pair};
use pt_spectra::precision::Precision;
use pt_spectra::progress::Silent;
use pt_spectra::store::TableStore;

use crate::support::*;

/// The basis estimate `a` within `rel` of `scale` (the direct `b`'s size, or the correction's) from
/// the direct `b` and within its own error: both use the same points, so the difference is the
/// response to the projection residual (and for curved spectra to the soft modes), which a's error
/// includes.
fn close(what: &str, a: Estimate, b: Estimate, rel: f64, scale: f64) {
    let d = (a.value - b.value).abs();
    assert!(
        d <= rel * scale,
        "{what}: {} vs {} (rel {:.2e} of {scale:.3e})",
        a.value,
        b.value,
        d / scale
    );
    assert!(
        d <= a.error,
        "{what}: difference {d:.3e} exceeds the error {:.3e}",
        a.error
    );
}

#[test]
fn basis_two_loop_terms_match_the_direct_integrals() {
    let mut precision = Precision::default();
    precision.two_loop_points = 1 << 11;
    precision.two_loop_tolerance = 0.0;
    let k = LogGrid::new(0.01, 0.3, 8).unwrap().points();
    let table = store().p15(&Silent).unwrap();
    let dir = std::path::Path::new(env!("CARGO_TARGET_TMPDIR")).join("two_loop_basis");
    let _ = std::fs::remove_dir_all(&dir);
    let linear = SpectrumFamily::Linear;
    let tensors = TableStore::new(&dir)
        .tensors::<TwoLoopBasis>(
            (&k[..], &precision, linear),
            |tick| TwoLoopBasis::build_linear(&k, &precision, &table, tick),
            &Silent,
        )
        .unwrap();
    // Read back from the file by a new store: the same tensors.
    let again = TableStore::new(&dir)
        .cached::<TwoLoopBasis>((&k[..], &precision, linear), &Silent)
        .unwrap();
    assert!(*again == *tensors, "the cache file reads back the tensors");
    assert!(TableStore::new(&dir)
        .cached::<TwoLoopBasis>((&k[1..], &precision, linear), &Silent)
        .is_none());
    let plan = OneLoopPlan::new(&k, &precision).unwrap();
    let camb = |name: &str| LinearSpectrum::parse(&data(name), name, Default::default()).unwrap();
    let mut spectra = vec![
        ("planck2018 z=0", camb("linear_pk_planck2018_z0.0.dat")),
        ("planck2018 z=1", camb("linear_pk_planck2018_z1.0.dat")),
        ("gm2012 z=0", LinearSpectrum::gm2012(0.0).unwrap()),
    ];
    for i in 0..3 {
        let name = format!("linear_pk_camb_heldout_{i}.dat");
        spectra.push(("held-out", camb(&name)));
    }
    spectra.push(("flat w0-wa z=1", camb("linear_pk_camb_w0wa_z1.0.dat")));
    // Curved ones (Ω_k = ±0.01), projected cut below the soft modes (`loops::basis::soft`).
    spectra.push((
        "curved w0-wa z=0.5",
        camb("linear_pk_camb_curved_wa_z0.5.dat"),
    ));
    spectra.push(("closed z=0", camb("linear_pk_camb_closed_z0.0.dat")));
    let mut worst: f64 = 0.0;
    for (name, p) in &spectra {
        let one_loop = plan.par_evaluate(p);
        let basis = tensors
            .evaluate(p, &one_loop)
            .unwrap_or_else(|proj| panic!("{name}: projection residual {:.2e}", proj.residual));
        assert!(basis.projection.residual <= MAX_RESIDUAL);
        let p15 = p15_terms(&table, &k, p, &precision);
        let direct = two_loop_correction(&one_loop, &p15, &table, p, &precision, &|_, _| {});
        for pair in Pair::ALL {
            let (b, d) = (&basis.correction.pairs[pair], &direct.pairs[pair]);
            for i in 0..k.len() {
                let at = format!("{name} {pair:?} k = {:.3}", k[i]);
                // The 2-loop terms within 1e-3 of themselves; for the curved spectra within 1e-3
                // of the correction (the bar): alone they respond to the soft modes (P15 of
                // the curved one by 2.2e-3 of itself where it crosses zero, 4e-5 of the correction).
                let total = d.total[i].value.abs();
                let scale = |t: Estimate| match name.starts_with("c") {
                    true => t.value.abs().max(total),
                    false => t.value.abs(),
                };
                close(&format!("{at} total"), b.total[i], d.total[i], 1e-3, total);
                let p15 = (basis.p15[pair][i], p15[pair][i]);
                close(&format!("{at} P15"), p15.0, p15.1, 1e-3, scale(p15.1));
                let p33 = (b.p33_2l[i], d.p33_2l[i]);
                close(&format!("{at} P33irr"), p33.0, p33.1, 1e-3, scale(p33.1));
                close(
                    &format!("{at} P24"),
                    b.p24[i],
                    d.p24[i],
                    1e-3,
                    scale(d.p24[i]),
                );
                worst = worst.max((b.total[i].value / d.total[i].value - 1.0).abs());
            }
        }
    }
    eprintln!("largest relative difference of the 2-loop correction: {worst:.2e}");
    // An Eisenstein–Hu spectrum is not in the span of CAMB spectra: refused, with its residual.
    let eh = Cosmology::planck2018()
        .eisenstein_hu_spectrum(TransferKind::Wiggle, 0.0, &LogGrid::default())
        .unwrap();
    let refused = tensors.evaluate(&eh, &plan.par_evaluate(&eh)).unwrap_err();
    assert!(refused.residual > MAX_RESIDUAL, "{}", refused.residual);
}

#[test]
fn auto_says_when_it_integrates_directly_for_want_of_tensors() {
    use pt_spectra::loops::TwoLoopSource;
    use pt_spectra::precision::TwoLoopMethod;
    use pt_spectra::real::{RealModel, RealPlan};
    // A grid no test builds tensors for, so the cache never holds them.
    let k = [0.0123, 0.0456];
    let p = LinearSpectrum::gm2012(0.0).unwrap();
    let source = |method| {
        let mut precision = Precision::fast();
        precision.two_loop = method;
        let plan = RealPlan::new(&k, RealModel::TwoLoopSpt, &precision, store(), &Silent).unwrap();
        plan.evaluate(&p, &Silent)
            .unwrap()
            .terms
            .two_loop_source
            .unwrap()
    };
    let auto = source(TwoLoopMethod::Auto);
    assert_eq!(auto, TwoLoopSource::DirectUncached);
    assert!(auto
        .describe()
        .contains("no basis tensors are cached for this k grid"));
    assert_eq!(source(TwoLoopMethod::Direct), TwoLoopSource::Direct);
    assert_eq!(
        TwoLoopSource::Direct.describe(),
        "2-loop terms: direct integration"
    );
}
