//! The IR-resummed SPT models (`1l-spt-ir`, `2l-spt-ir`): limits against SPT.

use pt_spectra::cosmology::{Cosmology, TransferKind};
use pt_spectra::linear::{LinearSpectrum, LogGrid};
use pt_spectra::loops::Pair;
use pt_spectra::precision::Precision;
use pt_spectra::progress::Silent;
use pt_spectra::real::{RealModel, RealPlan, RealSpectra};
use pt_spectra::store::TableStore;

use crate::support;

fn spectra(model: RealModel, p: &LinearSpectrum, k: &[f64]) -> RealSpectra {
    let store = TableStore::in_memory();
    RealPlan::new(k, model, &Precision::fast(), &store, &Silent)
        .unwrap()
        .evaluate(p, &Silent)
        .unwrap()
}

#[test]
fn without_wiggles_the_resummation_is_spt() {
    // The Eisenstein & Hu no-wiggle spectrum has no BAO to resum: P_w is the filter's residue
    // (≲ 1e-3 of P) and 1L-SPT-IR equals 1L-SPT to that level at every k.
    let p = Cosmology::gm2012()
        .eisenstein_hu_spectrum(TransferKind::NoWiggle, 0.0, &LogGrid::default())
        .unwrap();
    let k = LogGrid::new(0.01, 0.3, 12).unwrap().points();
    let (ir, spt) = (
        spectra(RealModel::OneLoopSptIr, &p, &k),
        spectra(RealModel::OneLoopSpt, &p, &k),
    );
    for pair in Pair::ALL {
        for (i, ki) in k.iter().enumerate() {
            let rel = ir.spectra[pair][i].value / spt.spectra[pair][i].value - 1.0;
            assert!(rel.abs() < 2e-3, "k = {ki} {pair:?}: {rel:e}");
        }
    }
}

#[test]
fn on_large_scales_the_resummation_is_spt_and_it_damps_the_wiggles() {
    let p = LinearSpectrum::gm2012(0.0).unwrap();
    let mut k = vec![0.005];
    k.extend(LogGrid::new(0.12, 0.3, 40).unwrap().points());
    let (ir, spt) = (
        spectra(RealModel::OneLoopSptIr, &p, &k),
        spectra(RealModel::OneLoopSpt, &p, &k),
    );
    let terms = ir.terms.ir.as_ref().unwrap();
    // k²Σ² ≪ 1 at k = 0.005: the resummed and plain spectra agree to O((k²Σ²)²).
    let rel = ir.spectra.dd[0].value / spt.spectra.dd[0].value - 1.0;
    assert!(rel.abs() < 1e-4, "{rel:e}");
    // The BAO of the resummed spectrum (its difference from the no-wiggle 1-loop spectrum) are those
    // of linear theory damped by ≈ e^{-k²Σ²} (the 1-loop wiggle term −k²Σ²P_w + … of SPT, which
    // overshoots at k²Σ² ≳ 1, is resummed into the exponential).
    let nw = &terms.no_wiggle.one_loop;
    let rms = |f: &dyn Fn(usize) -> f64| {
        let sum: f64 = (1..k.len()).map(|i| f(i).powi(2)).sum();
        (sum / (k.len() - 1) as f64).sqrt()
    };
    let smooth = |i: usize| nw.p_lin[i] + nw.one_loop(Pair::DeltaDelta, i).value;
    let w_ir = rms(&|i| ir.spectra.dd[i].value / smooth(i) - 1.0);
    let w_damped = rms(&|i| {
        let x = k[i] * k[i] * terms.sigma2.value;
        (-x).exp() * (ir.p_lin[i] - nw.p_lin[i]) / smooth(i)
    });
    let w_lin = rms(&|i| ir.p_lin[i] / nw.p_lin[i] - 1.0);
    println!(
        "Sigma^2 = {:.2} (Mpc/h)^2; rms BAO for 0.12 <= k <= 0.3: linear {w_lin:.2e}, \
         1L-SPT-IR {w_ir:.2e}, e^(-k^2 Sigma^2) P_w {w_damped:.2e}",
        terms.sigma2.value
    );
    assert!(w_ir < 0.6 * w_lin, "{w_ir} {w_lin}");
    assert!((w_ir / w_damped - 1.0).abs() < 0.3, "{w_ir} {w_damped}");
}

/// `model`'s spectra of the held-out CAMB tables `names` (not in the training set), through basis
/// tensors (from `store`) and directly, otherwise with `precision`.
fn basis_and_direct<'a>(
    model: RealModel,
    k: &[f64],
    precision: &Precision,
    store: &TableStore,
    names: [&'a str; 2],
) -> Vec<(&'a str, RealSpectra, RealSpectra)> {
    use pt_spectra::precision::TwoLoopMethod;
    let plan = |method| {
        let mut precision = precision.clone();
        precision.two_loop = method;
        RealPlan::new(k, model, &precision, store, &Silent).unwrap()
    };
    let (basis, direct) = (plan(TwoLoopMethod::Basis), plan(TwoLoopMethod::Direct));
    let dir = concat!(env!("CARGO_MANIFEST_DIR"), "/../pt-spectra/tests/data/");
    names
        .into_iter()
        .map(|name| {
            let p = LinearSpectrum::from_file(format!("{dir}{name}")).unwrap();
            let evaluate = |plan: &RealPlan| plan.evaluate(&p, &Silent).unwrap();
            (name, evaluate(&basis), evaluate(&direct))
        })
        .collect()
}

/// Every pair of the basis result `a` within `tolerance(i, direct value)` of the direct `b` at each
/// k index i, and within its own error.
fn assert_close(
    name: &str,
    a: &RealSpectra,
    b: &RealSpectra,
    tolerance: impl Fn(usize, f64) -> f64,
) {
    for pair in Pair::ALL {
        for (i, ki) in a.k.iter().enumerate() {
            let (x, y) = (a.spectra[pair][i], b.spectra[pair][i]);
            let d = (x.value - y.value).abs();
            assert!(
                d < tolerance(i, y.value),
                "{name} {pair:?} k={ki}: {x:?} {y:?}"
            );
            assert!(
                d <= x.error,
                "{name} {pair:?} k={ki}: {d:e} > {:e}",
                x.error
            );
        }
    }
}

#[test]
fn the_no_wiggle_terms_come_from_their_own_basis_and_match_the_direct_integrals() {
    // 1l-spt-ir through basis tensors: the linear spectrum on the CAMB basis, its no-wiggle part on a
    // basis of the training spectra's no-wiggle parts. Held-out CAMB spectra (not in the training
    // set) must give the direct result to 1e-4 of each spectrum and within the reported errors, with
    // the source saying the no-wiggle terms came from tensors.
    use pt_spectra::loops::OneLoopSource;
    let k = LogGrid::new(0.01, 0.3, 20).unwrap().points();
    let store = TableStore::in_memory();
    let names = [
        "linear_pk_camb_heldout_0.dat",
        "linear_pk_camb_heldout_2.dat",
    ];
    let model = RealModel::OneLoopSptIr;
    for (name, a, b) in basis_and_direct(model, &k, &Precision::fast(), &store, names) {
        let source = |s: &RealSpectra| s.terms.ir.as_deref().unwrap().no_wiggle.one_loop_source;
        assert!(
            matches!(source(&a), Some(OneLoopSource::Basis { .. })),
            "{name}: {:?}",
            source(&a)
        );
        assert!(source(&b).is_none());
        assert_close(name, &a, &b, |_, y| 1e-4 * y.abs());
    }
}

#[test]
fn two_loop_no_wiggle_terms_come_from_their_own_basis_too() {
    // 2l-spt-ir through basis tensors: the 2-loop terms of the no-wiggle spectrum from tensors on the
    // no-wiggle basis (built here with 2^11 points per shift, on the same points as direct). Held-out
    // CAMB spectra give the direct result to 1e-4 of P_lin and within the reported errors.
    use pt_spectra::loops::TwoLoopSource;
    let k = LogGrid::new(0.02, 0.3, 6).unwrap().points();
    let mut precision = Precision::fast();
    precision.two_loop_points = 2048;
    let names = [
        "linear_pk_camb_heldout_1.dat",
        "linear_pk_camb_heldout_2.dat",
    ];
    let model = RealModel::TwoLoopSptIr;
    for (name, a, b) in basis_and_direct(model, &k, &precision, support::store(), names) {
        let source = a.terms.ir.as_deref().unwrap().no_wiggle.two_loop_source;
        assert!(
            matches!(source, Some(TwoLoopSource::Basis { .. })),
            "{name}: {source:?}"
        );
        // Of P_lin: at k = 0.3 2-loop SPT's P_dt, P_tt are small remainders (P_tt < 0).
        assert_close(name, &a, &b, |i, _| 1e-4 * a.p_lin[i]);
    }
}
