//! Redshift space, for the embedded gm2012 z = 0 spectrum on 50 log-spaced k in [0.01, 0.3] h/Mpc:
//!
//! * `tns/evaluate`: the TNS A and B coefficients of μ^{2n} f^m ([`TnsPlan::evaluate`], one core);
//! * `tns/plan`: building the cosmology-independent TNS plan (rayon's pool);
//! * `tns/new spectrum through the basis`: the whole TNS model of a new CAMB table's (k, P) arrays on
//!   the 1- and TNS basis tensors ([`RsdPlan`] with method basis, 1L-SPT): the spline, the projection,
//!   the real-space terms, A and B, and P_0, P_2, P_4 with Lorentzian FoG (one core);
//! * `multipoles/…`: P_0, P_2, P_4 of the TNS model at one (f, σ0, b) from the precomputed real-space
//!   spectra and TNS coefficients: what a fit pays per step, undamped (exact) and with Lorentzian FoG
//!   (32-point Gauss–Legendre plus the 16-point error estimate).
//!
//! * `bias/evaluate`: the 1-loop bias terms Pd1d2 … sig3nl, Pt1d2, Pt1s2 of a new spectrum
//!   ([`BiasPlan::evaluate`], rayon's pool; `RAYON_NUM_THREADS=1` for one core);
//! * `ap/observed`: P_0, P_2, P_4 of TNS with Lorentzian FoG observed with α∥ = 1.03, α⊥ = 0.98
//!   ([`multipoles`] with the Alcock–Paczynski projection from its internal grid), per step of a fit.
//!
//! * `ept/terms`: the galaxy model's loop terms of a new linear spectrum with IR resummation (the
//!   no-wiggle filter, the terms of P and P_nw, Σ²) on 50 k ([`EptPlan::terms`], rayon's pool;
//!   `RAYON_NUM_THREADS=1` for one core), at the default and the fast precision (both within
//!   2.7e-4 of velocileptors' REPT, tests/tests/suite/ept.rs);
//! * `ept/new spectrum through the basis`: a new CAMB table's arrays to P_0, P_2, P_4 with the loop
//!   terms from the basis tensors (the spline, the no-wiggle filter, both projections, the
//!   contractions, one parameter step; one core);
//! * `ept/step`: P_0, P_2, P_4 from those terms at new parameters (one nuisance step of a chain,
//!   [`EptPlan::multipole_values`]), without and with AP (α∥ = 1.03, α⊥ = 0.98), and with the error
//!   estimates ([`EptPlan::multipoles`]).
//!
//! * `survey/…`: what a survey likelihood pays for a new linear spectrum: `ept` (IR on, precision fast)
//!   on the model k of a window and bins ([`Observation`]: Q_ℓ(s) of a 300 Mpc/h sphere on 128 s points,
//!   Wilson mixing, P_0, P_2, P_4 averaged over 48 bins of 0.005 h/Mpc), the loop terms, P_0 … P_8 on
//!   that grid and the window and bins; and the window and bins alone (one core).
//!
//! * `two_loop_rsd/spt2 …`, `two_loop_rsd/eft2 …`: a new CAMB table's arrays to the 2-loop matter
//!   multipoles P_0, P_2, P_4 in redshift space on 40 log-spaced k in [0.005, 0.4] with the 1- and
//!   2-loop terms from the basis tensors (precision fast; the tensors read from the cache of
//!   `PT_SPECTRA_CACHE`, or built once outside the timing, a few minutes): the spline, the projection,
//!   the contractions and the multipoles; `eft2` with IR resummation (the no-wiggle split and both
//!   spectra's contractions). Rayon's pool; `RAYON_NUM_THREADS=1` for one core.
//!
//! Run with `cargo bench --bench rsd`.

// `criterion_group!` defines an undocumented function.
#![allow(missing_docs)]

use criterion::{black_box, criterion_group, criterion_main, BenchmarkId, Criterion};
use pt_spectra::linear::{LinearSpectrum, LogGrid};
use pt_spectra::loops::bias::BiasPlan;
use pt_spectra::loops::{TnsPlan, TnsTerms};
use pt_spectra::precision::{Precision, TwoLoopMethod};
use pt_spectra::progress::Silent;
use pt_spectra::real::{real_space, RealModel, RealSpectra};
use pt_spectra::rsd::ap::Distortion;
use pt_spectra::rsd::ept::{EptParams, EptPlan, EptSettings};
use pt_spectra::rsd::RsdPlan;
use pt_spectra::rsd::{Fog, MultipoleRule, Observed, RsdModel, RsdSettings};
use pt_spectra::store::TableStore;
use pt_spectra::survey::observe::{Bins, Observation, Window};
use pt_spectra::survey::{Mixing, WindowMultipoles};
use std::time::Duration;

fn grid() -> Vec<f64> {
    LogGrid::new(0.01, 0.3, 50).expect("valid grid").points()
}

fn tns(c: &mut Criterion) {
    let p = LinearSpectrum::gm2012(0.0).expect("embedded spectrum");
    let k = grid();
    let mut group = c.benchmark_group("tns");
    group.measurement_time(Duration::from_secs(5));
    let plan = TnsPlan::new(&k, &Precision::default()).expect("valid plan");
    group.bench_function(BenchmarkId::new("evaluate (1 core)", 50), |b| {
        b.iter(|| plan.evaluate(black_box(&p)))
    });
    let table = LinearSpectrum::from_file(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../pt-spectra/tests/data/linear_pk_camb_heldout_1.dat"
    ))
    .expect("test table");
    let (k_in, p_in) = table.nodes();
    let (k_in, p_in) = (k_in.to_vec(), p_in.to_vec());
    let mut precision = Precision::default();
    precision.two_loop = TwoLoopMethod::Basis;
    let store = TableStore::in_memory();
    let rsd = RsdPlan::new(
        &k,
        RealModel::OneLoopSpt,
        RsdModel::Tns,
        &precision,
        &store,
        &Silent,
    )
    .expect("valid plan");
    let rule = MultipoleRule::new(&[0, 2, 4]).expect("valid ells");
    group.bench_function(
        BenchmarkId::new("new spectrum through the basis", 50),
        |b| {
            b.iter(|| {
                let p = LinearSpectrum::from_nodes(k_in.clone(), p_in.clone()).expect("valid");
                let (real, tns) = rsd.evaluate(black_box(&p), &Silent).expect("evaluates");
                let tns = tns.expect("TNS terms");
                multipoles(&rule, &real, &tns, (0.6, 3.5, 2.0), Fog::Lorentzian)
            })
        },
    );
    group.sample_size(10);
    group.bench_function(BenchmarkId::new("plan (rayon)", 50), |b| {
        b.iter(|| TnsPlan::new(black_box(&k), &Precision::default()).expect("valid plan"))
    });
    group.finish();
}

/// P_0, P_2, P_4 at (f, σ, b) for every k: the sum a fit evaluates per step.
fn multipoles(
    rule: &MultipoleRule,
    real: &RealSpectra,
    tns: &TnsTerms,
    (f, k_sigma, b): (f64, f64, f64),
    fog: Fog,
) -> f64 {
    let mut sum = 0.0;
    for (i, &k) in real.k.iter().enumerate() {
        let s = [real.spectra.dd[i], real.spectra.dt[i], real.spectra.tt[i]];
        let parts = RsdModel::Tns
            .parts(b, f, s, Some(&tns.coefficients[i]))
            .expect("TNS coefficients given");
        let p = rule.evaluate_polynomial(&parts.total(), fog, k * k_sigma);
        sum += p[0].value + p[1].value + p[2].value;
    }
    sum
}

fn rsd_multipoles(c: &mut Criterion) {
    let p = LinearSpectrum::gm2012(0.0).expect("embedded spectrum");
    let k = grid();
    let store = TableStore::in_memory();
    let real = real_space(
        RealModel::OneLoopRptN1,
        &p,
        &k,
        &Precision::default(),
        &store,
    )
    .expect("k valid");
    let tns = TnsPlan::new(&k, &Precision::default())
        .expect("valid plan")
        .evaluate(&p);
    let rule = MultipoleRule::new(&[0, 2, 4]).expect("valid ells");
    let mut group = c.benchmark_group("multipoles (50 k, l = 0, 2, 4)");
    for (name, fog) in [("undamped", Fog::None), ("lorentzian", Fog::Lorentzian)] {
        group.bench_function(name, |b| {
            b.iter(|| multipoles(&rule, &real, &tns, black_box((0.483, 3.5, 1.0)), fog))
        });
    }
    group.finish();
}

fn bias_and_ap(c: &mut Criterion) {
    let p = LinearSpectrum::gm2012(0.0).expect("embedded spectrum");
    let k = grid();
    let mut group = c.benchmark_group("bias");
    let plan = BiasPlan::new(&k, &Precision::default()).expect("valid plan");
    group.bench_function(BenchmarkId::new("evaluate", 50), |b| {
        b.iter(|| plan.evaluate(black_box(&p)))
    });
    group.finish();
    let distortion = Distortion::new(1.03, 0.98).expect("valid alphas");
    let internal = distortion.internal_grid(&k).expect("valid grid");
    let store = TableStore::in_memory();
    let real = real_space(
        RealModel::OneLoopSpt,
        &p,
        &internal,
        &Precision::default(),
        &store,
    )
    .expect("k valid");
    let tns = TnsPlan::new(&internal, &Precision::default())
        .expect("valid plan")
        .evaluate(&p);
    let settings = RsdSettings {
        model: RsdModel::Tns,
        f: 0.483,
        bias: vec![2.0; internal.len()],
        fog: Fog::Lorentzian,
        sigma: 3.5,
        noise: None,
        ells: vec![0, 2, 4],
        parts: false,
        cs2: 0.0,
        galaxy: None,
        ap: Some(Observed {
            distortion,
            k: k.clone(),
        }),
    };
    let mut group = c.benchmark_group("ap");
    group.bench_function(
        BenchmarkId::new("observed (50 k, l = 0, 2, 4)", internal.len()),
        |b| b.iter(|| pt_spectra::rsd::multipoles(&real, Some(&tns), black_box(&settings))),
    );
    group.finish();
}

/// The galaxy model: a new spectrum's terms, and one parameter step.
fn ept(c: &mut Criterion) {
    let p = LinearSpectrum::gm2012(0.0).expect("embedded spectrum");
    let k = grid();
    let mut group = c.benchmark_group("ept");
    let plan = EptPlan::new(&k, EptSettings::default(), &Precision::default()).expect("valid plan");
    group.bench_function(BenchmarkId::new("terms (IR)", 50), |b| {
        b.iter(|| plan.terms(black_box(&p)).expect("valid spectrum"))
    });
    let fast = EptPlan::new(&k, EptSettings::default(), &Precision::fast()).expect("valid plan");
    group.bench_function(BenchmarkId::new("terms (IR, precision fast)", 50), |b| {
        b.iter(|| fast.terms(black_box(&p)).expect("valid spectrum"))
    });
    // A new CAMB table's arrays through the basis tensors (method basis, built once here).
    let table = LinearSpectrum::from_file(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../pt-spectra/tests/data/linear_pk_camb_heldout_1.dat"
    ))
    .expect("test table");
    let (k_in, p_in) = (table.nodes().0.to_vec(), table.nodes().1.to_vec());
    let mut basis_precision = Precision::default();
    basis_precision.two_loop = TwoLoopMethod::Basis;
    let on_basis = EptPlan::new(&k, EptSettings::default(), &basis_precision)
        .expect("valid plan")
        .with_basis(&TableStore::in_memory(), &Silent)
        .expect("tensors");
    let mut params = EptParams::new(2.0, 0.48);
    for (name, v) in [("b2", 0.3), ("bs", -0.2), ("alpha0", 5.0), ("sn", 800.0)] {
        params.set(name, v).expect("known name");
    }
    group.bench_function(
        BenchmarkId::new("new spectrum through the basis (IR, l = 0, 2, 4)", 50),
        |b| {
            b.iter(|| {
                let p = LinearSpectrum::from_nodes(k_in.clone(), p_in.clone()).expect("valid");
                let terms = on_basis.terms(black_box(&p)).expect("valid spectrum");
                on_basis.multipole_values(&terms, &params, &[0, 2, 4])
            })
        },
    );
    let terms = plan.terms(&p).expect("valid spectrum");
    for (name, v) in [("b2", 0.3), ("bs", -0.2), ("alpha0", 5.0), ("sn", 800.0)] {
        params.set(name, v).expect("known name");
    }
    group.bench_function(BenchmarkId::new("step (IR, l = 0, 2, 4)", 50), |b| {
        b.iter(|| plan.multipole_values(&terms, black_box(&params), &[0, 2, 4]))
    });
    group.bench_function(
        BenchmarkId::new("step with errors (IR, l = 0, 2, 4)", 50),
        |b| b.iter(|| plan.multipoles(&terms, black_box(&params), &[0, 2, 4])),
    );
    let ap = EptSettings {
        ir: true,
        ap: Some(Distortion::new(1.03, 0.98).expect("valid alphas")),
        ap_range: None,
        loop_range: None,
    };
    let plan = EptPlan::new(&k, ap, &Precision::default()).expect("valid plan");
    let terms = plan.terms(&p).expect("valid spectrum");
    group.bench_function(BenchmarkId::new("step (IR + AP, l = 0, 2, 4)", 50), |b| {
        b.iter(|| plan.multipole_values(&terms, black_box(&params), &[0, 2, 4]))
    });
    group.finish();
}

/// The 2-loop redshift-space multipoles of a new spectrum through the basis tensors (module docs).
fn two_loop_rsd(c: &mut Criterion) {
    use pt_spectra::rsd::eft2::{Eft2Plan, RsdCounterterms};
    use pt_spectra::rsd::spt2::Spt2Plan;
    let k = LogGrid::new(0.005, 0.4, 40).expect("valid grid").points();
    let table = LinearSpectrum::from_file(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../pt-spectra/tests/data/linear_pk_camb_heldout_1.dat"
    ))
    .expect("test table");
    let (k_in, p_in) = (table.nodes().0.to_vec(), table.nodes().1.to_vec());
    let mut precision = Precision::fast();
    precision.two_loop = TwoLoopMethod::Basis;
    let store = TableStore::from_env();
    let spt2 = Spt2Plan::new(&k, &precision)
        .expect("valid plan")
        .with_basis(&store, &Silent)
        .expect("tensors");
    let eft2 = Eft2Plan::new(&k, true, &precision)
        .expect("valid plan")
        .with_basis(&store, &Silent)
        .expect("tensors");
    let ct = RsdCounterterms::from_assignments(&["c0=2", "c2_1loop=-1"]).expect("valid");
    let mut group = c.benchmark_group("two_loop_rsd");
    group.sample_size(20);
    group.bench_function(
        BenchmarkId::new("spt2 new spectrum through the basis", 40),
        |b| {
            b.iter(|| {
                let p = LinearSpectrum::from_nodes(k_in.clone(), p_in.clone()).expect("valid");
                let terms = spt2.terms(black_box(&p), &Silent).expect("valid spectrum");
                assert!(terms.source.contains("basis"));
                terms.multipoles(0.7, &[0, 2, 4]).expect("valid")
            })
        },
    );
    group.bench_function(
        BenchmarkId::new("eft2 new spectrum through the basis (IR)", 40),
        |b| {
            b.iter(|| {
                let p = LinearSpectrum::from_nodes(k_in.clone(), p_in.clone()).expect("valid");
                let terms = eft2.terms(black_box(&p), &Silent).expect("valid spectrum");
                terms.multipoles(0.7, &[0, 2, 4], &ct).expect("valid")
            })
        },
    );
    group.finish();
}

/// A windowed, binned `ept` evaluation for a new linear spectrum (module docs).
fn survey(c: &mut Criterion) {
    let p = LinearSpectrum::gm2012(0.0).expect("embedded spectrum");
    let r = 300.0;
    let s: Vec<f64> = (0..128)
        .map(|i| 0.01 * (2.0 * r / 0.01f64).powf(f64::from(i) / 127.0))
        .collect();
    let q0 = s
        .iter()
        .map(|&s| 1.0 - 0.75 * s / r + (s / r).powi(3) / 16.0)
        .collect();
    let window = WindowMultipoles::from_columns(s, vec![0], vec![q0]).expect("valid window");
    let edges: Vec<f64> = (0..=48).map(|i| 0.005 * f64::from(i)).collect();
    let observation = Observation::new(
        &[0, 2, 4],
        &[],
        Some(Window::Multipoles(window, Mixing::Wilson)),
        Some(Bins::Edges(edges)),
    )
    .expect("valid observation");
    let k = observation.k_model().to_vec();
    let plan = EptPlan::new(&k, EptSettings::default(), &Precision::fast()).expect("valid plan");
    let mut params = EptParams::new(2.0, 0.48);
    for (name, v) in [("b2", 0.3), ("bs", -0.2), ("alpha0", 5.0), ("sn", 800.0)] {
        params.set(name, v).expect("known name");
    }
    let mut group = c.benchmark_group("survey");
    group.bench_function(
        BenchmarkId::new("ept windowed binned (48 bins, 128 s), model k", k.len()),
        |b| {
            b.iter(|| {
                let terms = plan.terms(black_box(&p)).expect("valid spectrum");
                let model = plan
                    .multipole_values(&terms, &params, observation.model_ells())
                    .expect("valid parameters");
                observation.apply(&model).expect("valid model")
            })
        },
    );
    let terms = plan.terms(&p).expect("valid spectrum");
    let model = plan
        .multipole_values(&terms, &params, observation.model_ells())
        .expect("valid parameters");
    group.bench_function(
        BenchmarkId::new("window and bins alone", observation.k_out().len()),
        |b| b.iter(|| observation.apply(black_box(&model)).expect("valid model")),
    );
    group.finish();
}

criterion_group!(
    benches,
    tns,
    rsd_multipoles,
    bias_and_ap,
    ept,
    survey,
    two_loop_rsd
);
criterion_main!(benches);
