//! Time per evaluation of the generated kernels (F and G together, f64, the P17 kernel in lane pairs and,
//! for comparison, without; and four configurations per call, two at a time in `F64x2` lanes), and of the brute-force n!-permutation reference for comparison. Fixed
//! inputs; one core.

// `criterion_group!` defines an undocumented function.
#![allow(missing_docs)]

use criterion::{black_box, criterion_group, criterion_main, BenchmarkId, Criterion};
use pt_kernels::{general_from_gram, gram, reference};
use pt_kernels::{
    mode_coupling_2, mode_coupling_3, mode_coupling_3_x4, mode_coupling_4, mode_coupling_4_x4,
    propagator_3, propagator_5, propagator_5_x4, propagator_7, propagator_7_x4,
};
use std::time::Duration;

/// Seven fixed, generic vectors (h/Mpc).
fn vectors() -> Vec<[f64; 3]> {
    (0..7)
        .map(|i| {
            let a = i as f64;
            [(1.3 * a).sin() + 0.1, (0.7 * a + 1.0).cos(), 0.3 + 0.1 * a]
        })
        .collect()
}

fn general(c: &mut Criterion) {
    let v = vectors();
    let mut group = c.benchmark_group("general F_n^s,G_n^s");
    for n in 2..=7usize {
        let g = gram(&v[..n]);
        group.bench_with_input(BenchmarkId::from_parameter(n), &g, |b, g| {
            b.iter(|| general_from_gram(n, black_box(g)).unwrap())
        });
    }
    group.finish();
}

fn specialised(c: &mut Criterion) {
    let v = vectors();
    let g2: [f64; 3] = gram(&v[..2]).try_into().unwrap();
    let g3: [f64; 6] = gram(&v[..3]).try_into().unwrap();
    let g4: [f64; 10] = gram(&v[..4]).try_into().unwrap();
    let mut group = c.benchmark_group("specialised");
    group.bench_function("propagator_3 (P13)", |b| {
        b.iter(|| propagator_3(black_box(&g2)))
    });
    group.bench_function("propagator_5 (P15)", |b| {
        b.iter(|| propagator_5(black_box(&g3)))
    });
    group.bench_function("propagator_7 (P17)", |b| {
        b.iter(|| propagator_7(black_box(&g4)))
    });
    // The same kernel without the lane pairs (the direct program in plain f64), for comparison.
    group.bench_function("propagator_7 direct (P17, unpaired)", |b| {
        b.iter(|| pt_kernels::generated::propagator_7::<f64>(black_box(&g4)))
    });
    group.bench_function("mode_coupling_2 (P22)", |b| {
        b.iter(|| mode_coupling_2(black_box(&g2)))
    });
    group.bench_function("mode_coupling_3 (P33)", |b| {
        b.iter(|| mode_coupling_3(black_box(&g3)))
    });
    group.bench_function("mode_coupling_4 (P24)", |b| {
        b.iter(|| mode_coupling_4(black_box(&g3)))
    });
    group.finish();
    // Four configurations per call, two F64x2 lanes at a time (the 2-loop integrand's four images).
    let g3x4: [[f64; 6]; 4] = std::array::from_fn(|l| {
        let w: Vec<[f64; 3]> = v[l..l + 3].to_vec();
        gram(&w).try_into().unwrap()
    });
    let mut group = c.benchmark_group("four lanes");
    group.bench_function("mode_coupling_3_x4 (4 × P33)", |b| {
        b.iter(|| mode_coupling_3_x4(black_box(&g3x4)))
    });
    group.bench_function("mode_coupling_4_x4 (4 × P24)", |b| {
        b.iter(|| mode_coupling_4_x4(black_box(&g3x4)))
    });
    let g4x4: [[f64; 10]; 4] = std::array::from_fn(|l| {
        let w: Vec<[f64; 3]> = v[l..l + 4].to_vec();
        gram(&w).try_into().unwrap()
    });
    group.bench_function("propagator_5_x4 (4 × P15)", |b| {
        b.iter(|| propagator_5_x4(black_box(&g3x4)))
    });
    group.bench_function("propagator_7_x4 (4 × P17)", |b| {
        b.iter(|| propagator_7_x4(black_box(&g4x4)))
    });
    group.finish();
}

fn brute_force(c: &mut Criterion) {
    let v = vectors();
    let mut group = c.benchmark_group("brute force reference");
    group.sample_size(10);
    for n in 2..=7usize {
        group.bench_with_input(BenchmarkId::from_parameter(n), &v[..n], |b, q| {
            b.iter(|| reference::brute_force(black_box(q)).unwrap())
        });
    }
    group.finish();
}

criterion_group! {
    name = benches;
    config = Criterion::default().warm_up_time(Duration::from_millis(500)).measurement_time(Duration::from_secs(2));
    targets = general, specialised, brute_force
}
criterion_main!(benches);
