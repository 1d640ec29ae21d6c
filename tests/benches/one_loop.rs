//! All 1-loop SPT terms (P22, P13 of δδ, δθ, θθ, and σ_v², each with its error estimate) on log-spaced
//! k grids in [0.001, 1] h/Mpc, for the embedded gm2012 z = 0 CAMB spectrum, after it is loaded.
//!
//! * `evaluate/…`: [`OneLoopPlan::evaluate`], sequential on the calling thread (one core);
//! * `par_evaluate/…`: the same over rayon's pool (all cores; `RAYON_NUM_THREADS` sets the count);
//! * `plan/…`: building the cosmology-independent plan once per k grid (uses rayon's pool);
//! * `basis (1 core)/…`: the 1-loop SPT spectra with all terms through the 1-loop basis tensors
//!   ([`RealPlan`] with method basis), from a CAMB table's (k, P) arrays: the spectrum's spline, its
//!   lattice samples and projection, the contractions and the assembly, on the calling thread.
//!
//! Run with `cargo bench --bench one_loop`; for one core everywhere, `RAYON_NUM_THREADS=1`.

// `criterion_group!` defines an undocumented function.
#![allow(missing_docs)]

use criterion::{black_box, criterion_group, criterion_main, BenchmarkId, Criterion};
use pt_spectra::linear::{LinearSpectrum, LogGrid};
use pt_spectra::loops::OneLoopPlan;
use pt_spectra::precision::{Precision, TwoLoopMethod};
use pt_spectra::progress::Silent;
use pt_spectra::real::{RealModel, RealPlan};
use pt_spectra::store::TableStore;
use std::time::Duration;

fn grid(n: usize) -> Vec<f64> {
    LogGrid::new(1e-3, 1.0, n).expect("valid grid").points()
}

fn presets() -> [(&'static str, Precision); 2] {
    [
        ("default", Precision::default()),
        ("fast", Precision::fast()),
    ]
}

fn evaluate(c: &mut Criterion) {
    let p = LinearSpectrum::gm2012(0.0).expect("embedded spectrum");
    let mut group = c.benchmark_group("evaluate (1 core)");
    group.measurement_time(Duration::from_secs(5));
    for (name, precision) in presets() {
        for n in [100, 1000] {
            let plan = OneLoopPlan::new(&grid(n), &precision).expect("valid plan");
            group.bench_with_input(BenchmarkId::new(name, n), &plan, |b, plan| {
                b.iter(|| plan.evaluate(black_box(&p)))
            });
        }
    }
    group.finish();
}

fn par_evaluate(c: &mut Criterion) {
    let p = LinearSpectrum::gm2012(0.0).expect("embedded spectrum");
    let mut group = c.benchmark_group("par_evaluate (rayon)");
    group.measurement_time(Duration::from_secs(5));
    for n in [100, 1000] {
        let plan = OneLoopPlan::new(&grid(n), &Precision::default()).expect("valid plan");
        group.bench_with_input(BenchmarkId::new("default", n), &plan, |b, plan| {
            b.iter(|| plan.par_evaluate(black_box(&p)))
        });
    }
    group.finish();
}

fn plan(c: &mut Criterion) {
    let mut group = c.benchmark_group("plan (rayon)");
    group.sample_size(10);
    for (name, precision) in presets() {
        let k = grid(100);
        group.bench_with_input(BenchmarkId::new(name, 100), &k, |b, k| {
            b.iter(|| OneLoopPlan::new(black_box(k), &precision).expect("valid plan"))
        });
    }
    group.finish();
}

fn basis(c: &mut Criterion) {
    let table = LinearSpectrum::from_file(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../pt-spectra/tests/data/linear_pk_camb_heldout_1.dat"
    ))
    .expect("test table");
    let (k_in, p_in) = table.nodes();
    let (k_in, p_in) = (k_in.to_vec(), p_in.to_vec());
    let store = TableStore::in_memory();
    let mut group = c.benchmark_group("basis (1 core)");
    group.measurement_time(Duration::from_secs(5));
    for (name, mut precision) in presets() {
        precision.two_loop = TwoLoopMethod::Basis;
        let plan = RealPlan::new(
            &grid(100),
            RealModel::OneLoopSpt,
            &precision,
            &store,
            &Silent,
        )
        .expect("valid plan");
        group.bench_with_input(BenchmarkId::new(name, 100), &plan, |b, plan| {
            b.iter(|| {
                let p = LinearSpectrum::from_nodes(k_in.clone(), p_in.clone()).expect("valid");
                plan.evaluate(black_box(&p), &Silent).expect("evaluates")
            })
        });
    }
    group.finish();
}

criterion_group!(benches, evaluate, par_evaluate, plan, basis);
criterion_main!(benches);
