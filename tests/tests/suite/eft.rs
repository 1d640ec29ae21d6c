//! The 2-loop EFT models (`2l-eft`, `2l-eft-ir`): the counterterm templates against their closed
//! forms, the set against what it must do (absorb the cut-off dependence of the loops), and the
//! linear fit.

use pt_spectra::linear::{LinearSpectrum, LogGrid};
use pt_spectra::loops::Pair;
use pt_spectra::precision::{Precision, TwoLoopMethod};
use pt_spectra::progress::Silent;
use pt_spectra::real::{
    fit_counterterms, Counterterm, Counterterms, RealModel, RealPlan, RealSpectra,
};

use crate::support;

/// The spectra of `model`, with the cached tables of the tests ([`support::store`]).
fn spectra(model: RealModel, p: &LinearSpectrum, k: &[f64], precision: &Precision) -> RealSpectra {
    RealPlan::new(k, model, precision, support::store(), &Silent)
        .unwrap()
        .evaluate(p, &Silent)
        .unwrap()
}

fn direct(q_max: f64) -> Precision {
    let mut p = Precision::default().with_q_range(1e-5, q_max).unwrap();
    p.two_loop = TwoLoopMethod::Direct;
    p
}

#[test]
fn the_templates_are_their_closed_forms_and_add_linearly() {
    let p = LinearSpectrum::gm2012(0.5).unwrap();
    let k = [0.05, 0.12, 0.2];
    let base = spectra(RealModel::TwoLoopEft, &p, &k, &Precision::fast());
    let ct = Counterterms {
        cs2: 1.3,
        cs2_1loop: -0.4,
        c4: 2.5,
    };
    let with = base.clone().with_counterterms(&ct).unwrap();
    assert_eq!(with.counterterms, ct);
    let t = &base.terms.one_loop;
    for (i, &ki) in k.iter().enumerate() {
        let (lin, k2, k4) = (t.p_lin[i], ki * ki, ki.powi(4));
        let one = |pair| t.one_loop(pair, i).value;
        let (dd, dt, tt) = (
            one(Pair::DeltaDelta),
            one(Pair::DeltaTheta),
            one(Pair::ThetaTheta),
        );
        // T_dd = −2 kᵐ S_dd, T_dt = −kᵐ (n S_dd + 2 S_dt), T_tt = −2 kᵐ (n S_dt + S_tt).
        let want = [
            (
                Counterterm::Cs2,
                [-2.0 * k2 * lin, -4.0 * k2 * lin, -6.0 * k2 * lin],
            ),
            (
                Counterterm::Cs2OneLoop,
                [
                    -2.0 * k2 * dd,
                    -k2 * (2.0 * dd + 2.0 * dt),
                    -2.0 * k2 * (2.0 * dt + tt),
                ],
            ),
            (
                Counterterm::C4,
                [-2.0 * k4 * lin, -6.0 * k4 * lin, -10.0 * k4 * lin],
            ),
        ];
        for (c, values) in want {
            let template = base.counterterm_template(c);
            for (pair, v) in Pair::ALL.into_iter().zip(values) {
                let got = template[pair][i].value;
                assert!(
                    (got - v).abs() <= 1e-13 * v.abs(),
                    "{c} {pair:?} k={ki}: {got} {v}"
                );
            }
        }
        for (j, pair) in Pair::ALL.into_iter().enumerate() {
            let shift = with.spectra[pair][i].value - base.spectra[pair][i].value;
            let sum: f64 = want_sum(&want_values(&base, i), &ct)[j];
            assert!(
                (shift - sum).abs() <= 1e-12 * base.spectra[pair][i].value,
                "{pair:?}"
            );
            assert!((with.counterterm(pair)[i] - sum).abs() <= 1e-12 * sum.abs());
        }
        // The 1-loop insertion carries the error of P_1loop; P_lin's are exact.
        let e = |s: &RealSpectra| s.spectra.dd[i].error;
        let added = 2.0 * k2 * ct.cs2_1loop.abs() * t.one_loop(Pair::DeltaDelta, i).error;
        assert!((e(&with) - e(&base) - added).abs() <= 1e-9 * e(&base).max(added));
    }
}

/// The templates of every counterterm and pair at k index `i`.
fn want_values(s: &RealSpectra, i: usize) -> Vec<[f64; 3]> {
    Counterterm::ALL
        .iter()
        .map(|&c| {
            let t = s.counterterm_template(c);
            [t.dd[i].value, t.dt[i].value, t.tt[i].value]
        })
        .collect()
}

/// Σ_X X T_X for each pair.
fn want_sum(templates: &[[f64; 3]], ct: &Counterterms) -> [f64; 3] {
    let mut sum = [0.0; 3];
    for (c, t) in Counterterm::ALL.iter().zip(templates) {
        for j in 0..3 {
            sum[j] += ct.get(*c) * t[j];
        }
    }
    sum
}

#[test]
fn the_set_absorbs_the_cut_off_dependence_of_two_loop_spt_and_cs2_alone_does_not() {
    // 2-loop SPT with the loops cut at q_max = 2 h/Mpc and at 10³ h/Mpc differ by UV physics that
    // the counterterms stand for: 12% of P_lin at k = 0.3 at z = 0. The set must absorb it to the
    // integration error of the 2-loop terms (~2.5e-4 of P_lin); c_s² alone leaves ~3e-3 (the
    // single-hard 2-loop limit has another shape).
    let p = LinearSpectrum::gm2012(0.0).unwrap();
    let k = LogGrid::new(0.02, 0.3, 12).unwrap().points();
    let full = spectra(RealModel::TwoLoopEft, &p, &k, &direct(1e3));
    let cut = spectra(RealModel::TwoLoopEft, &p, &k, &direct(2.0));
    let data: Vec<f64> = full.spectra.dd.iter().map(|e| e.value).collect();
    let sigma: Vec<f64> = cut.p_lin.iter().map(|p| 1e-3 * p).collect();
    let (values, errors) = fit_counterterms(&cut, &data, &sigma, 0.31).unwrap();
    let fitted = cut.clone().with_counterterms(&values).unwrap();
    let residual = |s: &RealSpectra| -> f64 {
        (0..k.len())
            .map(|i| ((data[i] - s.spectra.dd[i].value) / s.p_lin[i]).abs())
            .fold(0.0, f64::max)
    };
    let before = residual(&cut);
    let after = residual(&fitted);
    // c_s² alone, by weighted least squares.
    let t = cut.counterterm_template(Counterterm::Cs2).dd;
    let (mut num, mut den) = (0.0, 0.0);
    for i in 0..k.len() {
        let w = 1.0 / (sigma[i] * sigma[i]);
        num += w * t[i].value * (data[i] - cut.spectra.dd[i].value);
        den += w * t[i].value * t[i].value;
    }
    let cs2_only = residual(&cut.clone().with_counterterm(num / den).unwrap());
    assert!(before > 0.08, "the cut-off must matter: {before:e}");
    assert!(after < 6e-4, "the set leaves {after:e} of P_lin");
    assert!(
        cs2_only > 4.0 * after,
        "c_s² alone: {cs2_only:e}, the set {after:e}"
    );
    // Lowering q_max removes UV power that is negative: the c_s² that replaces it is positive (the
    // sign of the EFT literature), well determined for these σ.
    assert!(
        values.cs2 > 0.5 && errors.cs2 < 0.05 * values.cs2,
        "{values:?} {errors:?}"
    );
}

#[test]
fn a_fit_recovers_injected_counterterms_and_refuses_what_it_cannot_fit() {
    let p = LinearSpectrum::gm2012(1.0).unwrap();
    let k = LogGrid::new(0.03, 0.3, 8).unwrap().points();
    let base = spectra(RealModel::TwoLoopEftIr, &p, &k, &Precision::fast());
    let ct = Counterterms {
        cs2: 0.8,
        cs2_1loop: 1.7,
        c4: -3.0,
    };
    let data: Vec<f64> = base
        .clone()
        .with_counterterms(&ct)
        .unwrap()
        .spectra
        .dd
        .iter()
        .map(|e| e.value)
        .collect();
    let sigma = vec![1.0; k.len()];
    let (got, _) = fit_counterterms(&base, &data, &sigma, 1.0).unwrap();
    for c in Counterterm::ALL {
        assert!(
            (got.get(c) - ct.get(c)).abs() < 1e-6 * ct.get(c).abs(),
            "{c}: {got:?}"
        );
    }
    // Too few points, a non-EFT model, σ ≤ 0, fitted counterterms already in.
    assert!(fit_counterterms(&base, &data, &sigma, 0.05).is_err());
    let spt = RealSpectra::from_terms(RealModel::TwoLoopSpt, base.terms.clone()).unwrap();
    assert!(fit_counterterms(&spt, &data, &sigma, 1.0).is_err());
    assert!(fit_counterterms(&base, &data, &vec![0.0; k.len()], 1.0).is_err());
    let with = base.clone().with_counterterms(&ct).unwrap();
    assert!(fit_counterterms(&with, &data, &sigma, 1.0).is_err());
}

#[test]
fn the_ir_templates_damp_the_wiggles_and_neutrinos_scale_the_density_template() {
    let p = LinearSpectrum::gm2012(0.0).unwrap();
    let k = [0.05, 0.1, 0.2];
    let s = spectra(RealModel::TwoLoopEftIr, &p, &k, &Precision::fast());
    let ir = s.terms.ir.as_deref().unwrap();
    let t = s.counterterm_template(Counterterm::Cs2);
    for (i, &ki) in k.iter().enumerate() {
        let (p_lin, p_nw) = (s.p_lin[i], ir.no_wiggle.one_loop.p_lin[i]);
        let d = (-ki * ki * ir.sigma2.value).exp();
        let want = -2.0 * ki * ki * (p_nw + d * (p_lin - p_nw));
        assert!((t.dd[i].value - want).abs() < 1e-12 * want.abs(), "k={ki}");
    }
    // With massive neutrinos the density template is f_cb² that of cold matter.
    let f_cb = 0.99;
    let p_m: Vec<f64> = s.p_lin.iter().map(|p| 1.01 * p).collect();
    let nu = s.clone().with_massive_neutrinos(&p_m, f_cb).unwrap();
    for c in Counterterm::ALL {
        let (a, b) = (s.counterterm_template(c), nu.counterterm_template(c));
        for i in 0..k.len() {
            assert!(
                (b.dd[i].value - f_cb * f_cb * a.dd[i].value).abs() < 1e-12 * a.dd[i].value.abs()
            );
            assert_eq!(a.tt[i], b.tt[i]);
        }
    }
}

#[test]
fn counterterms_parse_and_belong_to_the_eft_models() {
    let ct = Counterterms::from_assignments(["cs2=1", "CS2_1LOOP = -0.5", "c4=2e-1"]).unwrap();
    assert_eq!(
        ct,
        Counterterms {
            cs2: 1.0,
            cs2_1loop: -0.5,
            c4: 0.2
        }
    );
    for bad in ["cs2", "cs3=1", "c4=nan", "c4=inf", "c4=x"] {
        assert!(Counterterms::from_assignments([bad]).is_err(), "{bad}");
    }
    let e = Counterterms::from_assignments(["c4=1", "c4=2"])
        .unwrap_err()
        .to_string();
    assert!(e.contains("twice"), "{e}");
    assert!(ct.check(RealModel::TwoLoopEft).is_ok());
    let e = ct.check(RealModel::TwoLoopSpt).unwrap_err().to_string();
    assert!(e.contains("cs2_1loop") && e.contains("2l-eft"), "{e}");
    assert!(Counterterms::cs2(1.0).check(RealModel::OneLoopSpt).is_ok());
    assert!(Counterterms::cs2(1.0).with_cs2(2.0).is_err());
    assert_eq!(Counterterms::cs2(1.0).with_cs2(0.0).unwrap().cs2, 1.0);
    assert!(RealModel::TwoLoopEftIr.needs_ir() && RealModel::TwoLoopEft.needs_two_loop());
}
