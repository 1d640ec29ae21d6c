//! Fits on one core, for the embedded gm2012 z = 0 spectrum on 50 log-spaced k in [0.01, 0.3] h/Mpc
//! with TNS + 1L-SPT and Lorentzian FoG (all loop terms computed once, outside the timing):
//!
//! * `model/evaluate`: P_0, P_2, P_4 at a new (f, σ0, A_b) — one χ² step; `model/evaluate-cs2` the
//!   same with the EFT counterterm c_s² ≠ 0;
//! * `fit/scan-20`: a 20-point k_max scan (0.06 … 0.3) of a 2-parameter (f, σ0) fit on the three
//!   multipoles, with the Δχ² = 2.3 errors of both parameters.
//!
//! Run with `cargo bench --bench fit`.

// `criterion_group!` defines an undocumented function.
#![allow(missing_docs)]

use criterion::{black_box, criterion_group, criterion_main, Criterion};
use pt_spectra::fit::{fit, FitSettings, MultipoleData, MultipoleModel, Parameter, Params};
use pt_spectra::linear::{LinearSpectrum, LogGrid};
use pt_spectra::loops::TnsPlan;
use pt_spectra::precision::Precision;
use pt_spectra::real::{real_space, RealModel};
use pt_spectra::rsd::{Fog, RsdModel};
use pt_spectra::store::TableStore;

fn setup() -> (MultipoleModel, MultipoleData) {
    let p = LinearSpectrum::gm2012(0.0).expect("embedded spectrum");
    let k = LogGrid::new(0.01, 0.3, 50).expect("valid grid").points();
    let real = real_space(
        RealModel::OneLoopSpt,
        &p,
        &k,
        &Precision::default(),
        &TableStore::in_memory(),
    )
    .expect("valid");
    let tns = TnsPlan::new(&k, &Precision::default())
        .expect("valid")
        .evaluate(&p);
    let model = MultipoleModel::new(
        &real,
        Some(&tns),
        RsdModel::Tns,
        Fog::Lorentzian,
        1.0,
        vec![1.0; k.len()],
        &[0, 2, 4],
    )
    .expect("valid model");
    let m = model.multipoles(&Params {
        f: 0.483,
        sigma0: 4.0,
        amplitude: 1.0,
        cs2: 0.0,
    });
    let mut text = String::new();
    for (i, &ki) in k.iter().enumerate() {
        let s = 0.01 * m[0][i];
        text += &format!("{ki} {} {s} {} {s} {} {s}\n", m[0][i], m[1][i], m[2][i]);
    }
    let data = MultipoleData::parse(&text, "mock", 0, &[(0, 1, 2), (2, 3, 4), (4, 5, 6)])
        .expect("valid data");
    (model, data)
}

fn benches(c: &mut Criterion) {
    let (model, data) = setup();
    let n = model.k().len();
    let mut out = vec![0.0; 3 * n];
    let mut group = c.benchmark_group("model");
    group.bench_function("evaluate", |b| {
        let mut f = 0.45;
        b.iter(|| {
            f += 1e-9;
            model.multipoles_into(
                black_box(&Params {
                    f,
                    sigma0: 4.0,
                    amplitude: 1.0,
                    cs2: 0.0,
                }),
                0..n,
                &mut out,
            );
            out[0]
        })
    });
    // The same with the EFT counterterm: three more multiply-adds per k.
    group.bench_function("evaluate-cs2", |b| {
        let mut f = 0.45;
        b.iter(|| {
            f += 1e-9;
            model.multipoles_into(
                black_box(&Params {
                    f,
                    sigma0: 4.0,
                    amplitude: 1.0,
                    cs2: 1.0,
                }),
                0..n,
                &mut out,
            );
            out[0]
        })
    });
    group.finish();
    let settings = FitSettings {
        free: vec![Parameter::F, Parameter::Sigma0],
        start: Params {
            f: 0.55,
            sigma0: 3.0,
            amplitude: 1.0,
            cs2: 0.0,
        },
        k_min: 0.0,
    };
    let k_max: Vec<f64> = (0..20).map(|i| 0.06 + 0.24 * i as f64 / 19.0).collect();
    let mut group = c.benchmark_group("fit");
    group.sample_size(10);
    group.bench_function("scan-20", |b| {
        b.iter(|| fit(&model, black_box(&data), &settings, &k_max).expect("fits"))
    });
    group.finish();
}

criterion_group!(fits, benches);
criterion_main!(fits);
