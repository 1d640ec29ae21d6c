//! The chain step of issue 47 on one core: the BOSS CMASS NGC windowed `ept` data vector (P0, P2,
//! P4 at 38 k from 0.015 to 0.38 h/Mpc through the Q_ℓ window, AP against a fiducial), basis
//! tensors cached, planned once ([`Pipeline`]):
//!
//! * `pipeline/emulator`: a new cosmology at every call (emulator → loop terms → AP multipoles →
//!   window matrix); `pipeline/cosmology-jacobian` with the exact derivatives in the eight sampled
//!   cosmological parameters, `pipeline/full-jacobian` with the nuisance rows of the same step too;
//! * `pipeline/table`: the same from a given linear table (the embedded gm2012 CAMB spectrum);
//! * `pipeline/terms`, `pipeline/multipoles`: the two cosmology-dependent stages alone;
//! * `pipeline/linearise`: a cosmology's data vector as a polynomial in the nuisance parameters
//!   (what a new cosmology's nuisance Jacobian costs beyond the step), and `pipeline/jacobian` the
//!   step's full exact Jacobian (the nuisance parameters and f) with the data vector;
//! * `pipeline/nuisance`: the nuisance-only step on a linearised cosmology, and
//!   `pipeline/nuisance-jacobian` its exact Jacobian.
//!
//! Run with `cargo bench -p pt-spectra-tests --bench pipeline` (set RAYON_NUM_THREADS=1 for one core).

// `criterion_group!` defines an undocumented function.
#![allow(missing_docs)]

use criterion::{black_box, criterion_group, criterion_main, Criterion};
use pt_spectra::cosmology::Cosmology;
use pt_spectra::linear::LinearSpectrum;
use pt_spectra::pipeline::{Pipeline, PipelineSettings};
use pt_spectra::precision::{Precision, TwoLoopMethod};
use pt_spectra::progress::Silent;
use pt_spectra::store::TableStore;
use pt_spectra::survey::observe::{Observation, Window};
use pt_spectra::survey::{Mixing, WindowFormat};

const Z: f64 = 0.57;
const PARAMS: [(&str, f64); 6] = [
    ("b1", 2.1),
    ("b2", -0.4),
    ("bs", 0.3),
    ("alpha0", 12.0),
    ("alpha2", -20.0),
    ("sn", 1500.0),
];

fn pipeline() -> Pipeline {
    let path = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../examples/data/boss_dr12_cmass_ngc/window_BOSS_CMASS_NGC_z057.dat"
    );
    let window = Window::read(path.as_ref(), Mixing::Wilson, &WindowFormat::header()).unwrap();
    let k: Vec<f64> = (0..38)
        .map(|i| 0.015 * (0.38f64 / 0.015).powf(i as f64 / 37.0))
        .collect();
    let obs = Observation::new(&[0, 2, 4], &k, Some(window), None).unwrap();
    let mut precision = Precision::default();
    precision.two_loop = TwoLoopMethod::Basis;
    let store = TableStore::new(concat!(env!("CARGO_TARGET_TMPDIR"), "/pipeline-store"));
    let fiducial = Cosmology::flat(0.31, 0.676, 0.022, 0.97, 0.80).unwrap();
    let settings = PipelineSettings::ept(Z, Some(fiducial));
    Pipeline::new(obs, settings, &precision, &store, &Silent).unwrap()
}

/// The `j`-th of 97 cosmologies along Ω_m, A_s-normalised (what the cosmological derivatives take).
fn a_s_cosmology(j: usize) -> Cosmology {
    let om = 0.28 + 0.04 * ((j % 97) as f64 / 97.0);
    Cosmology::flat(om, 0.69, 0.0224, 0.965, 0.81)
        .unwrap()
        .with_amplitude(pt_spectra::cosmology::Amplitude::a_s(2.1e-9))
        .unwrap()
}

fn benches(c: &mut Criterion) {
    let pl = pipeline();
    let mut i = 0usize;
    let mut cosmology = || {
        i += 1;
        let om = 0.28 + 0.04 * ((i % 97) as f64 / 97.0);
        Cosmology::flat(om, 0.69, 0.0224, 0.965, 0.81).unwrap()
    };
    c.bench_function("pipeline/emulator", |b| {
        b.iter(|| black_box(pl.evaluate(&cosmology(), &PARAMS).unwrap()))
    });
    // the exact derivatives with respect to the eight sampled cosmological parameters (A_s-normalised)
    let mut j = 0usize;
    c.bench_function("pipeline/cosmology-jacobian", |b| {
        b.iter(|| {
            j += 1;
            let c = a_s_cosmology(j);
            black_box(
                pl.cosmology_jacobian(&c, &PARAMS)
                    .unwrap()
                    .cosmological
                    .len(),
            )
        })
    });
    // the same with the nuisance rows of the same step (a sampler's whole Jacobian)
    let mut j = 0usize;
    c.bench_function("pipeline/full-jacobian", |b| {
        b.iter(|| {
            j += 1;
            let c = a_s_cosmology(j);
            black_box(pl.full_jacobian(&c, &PARAMS).unwrap().1.len())
        })
    });
    let named = pt_spectra::setup::NamedCosmology::gm2012();
    // The embedded CAMB table at z = 0.5, scaled to the pipeline's z by the cosmology's growth.
    let table = LinearSpectrum::gm2012(0.5).unwrap();
    c.bench_function("pipeline/table", |b| {
        b.iter(|| {
            let prepared = pl
                .prepare_source(
                    pt_spectra::setup::LinearSource::Table {
                        spectrum: Box::new(table.clone()),
                        z_input: 0.5,
                    },
                    Some(named.clone()),
                )
                .unwrap();
            black_box(pl.step(&prepared).unwrap().data_vector(&PARAMS).unwrap())
        })
    });
    let prepared = pl.prepare(&cosmology()).unwrap();
    c.bench_function("pipeline/terms", |b| {
        b.iter(|| black_box(pl.step(&prepared).unwrap().growth_rate))
    });
    let step = pl.step(&prepared).unwrap();
    c.bench_function("pipeline/multipoles", |b| {
        b.iter(|| black_box(step.data_vector(&PARAMS).unwrap()))
    });
    c.bench_function("pipeline/linearise", |b| {
        b.iter(|| black_box(step.linearise(None).unwrap().f()))
    });
    c.bench_function("pipeline/jacobian", |b| {
        b.iter(|| black_box(step.jacobian(&PARAMS).unwrap().1.len()))
    });
    let lin = step.linearise(None).unwrap();
    c.bench_function("pipeline/nuisance", |b| {
        b.iter(|| black_box(lin.data_vector(&PARAMS).unwrap()))
    });
    c.bench_function("pipeline/nuisance-jacobian", |b| {
        b.iter(|| black_box(lin.jacobian(&PARAMS).unwrap()))
    });
}

criterion_group! {
    name = pipeline_benches;
    config = Criterion::default().sample_size(20);
    targets = benches
}
criterion_main!(pipeline_benches);
