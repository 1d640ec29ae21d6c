//! The linear-spectrum emulator: P_m, P_cb and f_cb(k) of a new cosmology at one redshift, from its
//! parameters (issue 27: ≤ 100 µs per cosmology). Each iteration takes a different cosmology of the
//! prior (Σm_ν, w0, wa and h varied), so that nothing is reused between calls.

// `criterion_group!` defines an undocumented function.
#![allow(missing_docs)]

use criterion::{criterion_group, criterion_main, Criterion};
use pt_spectra::cosmology::{Amplitude, Cosmology};
use pt_spectra::emulator::LinearEmulator;
use std::hint::black_box;

fn cosmologies() -> Vec<Cosmology> {
    (0..64)
        .map(|i| {
            let t = f64::from(i) / 64.0;
            let mut c = Cosmology::planck2018()
                .with_neutrinos(0.05 + 0.4 * t)
                .unwrap()
                .with_dark_energy(-1.2 + 0.4 * t, 0.3 - 0.6 * t)
                .unwrap();
            c.h = 0.63 + 0.08 * t;
            c.amplitude = Amplitude::a_s(2.1e-9 * (1.0 + 0.1 * t));
            c.validate().unwrap();
            c
        })
        .collect()
}

fn emulator(crit: &mut Criterion) {
    let emulator = LinearEmulator::embedded().unwrap();
    let all = cosmologies();
    let mut i = 0;
    crit.bench_function(
        "emulator/P_m, P_cb, f_cb of a new cosmology (w0-wa, m_nu)",
        |b| {
            b.iter(|| {
                i = (i + 1) % all.len();
                black_box(emulator.spectra(&all[i], 0.8).unwrap())
            })
        },
    );
    let lambda: Vec<Cosmology> = all
        .iter()
        .map(|c| c.with_dark_energy(-1.0, 0.0).unwrap())
        .collect();
    crit.bench_function(
        "emulator/P_m, P_cb, f_cb of a new cosmology (Lambda, m_nu)",
        |b| {
            b.iter(|| {
                i = (i + 1) % lambda.len();
                black_box(emulator.spectra(&lambda[i], 0.8).unwrap())
            })
        },
    );
    // σ8-normalised: A_s found from σ8 at z = 0 (the shape at z = 0 without its s-derivative)
    let sigma8: Vec<Cosmology> = all
        .iter()
        .map(|c| c.with_amplitude(Amplitude::Sigma8(0.8)).unwrap())
        .collect();
    crit.bench_function(
        "emulator/P_m, P_cb, f_cb of a new sigma8-normalised cosmology (w0-wa, m_nu)",
        |b| {
            b.iter(|| {
                i = (i + 1) % sigma8.len();
                black_box(emulator.spectra(&sigma8[i], 0.8).unwrap())
            })
        },
    );
}

criterion_group!(benches, emulator);
criterion_main!(benches);
