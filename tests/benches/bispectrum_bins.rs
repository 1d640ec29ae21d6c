//! The bin averages of the one-loop galaxy multipoles B0, B2, B4 of the 62 Nseries bins from tensors
//! (issue 50: ≤ 10 ms for a new linear spectrum on one core): the effective triangles' multipole tensors
//! and each bin's folded correction, then a bias.
//!
//! The tensors are built here on 2 x 2 x 2 rules (the evaluation's cost does not depend on the rules; the
//! 62 bins take ~16 min on two cores) and cached in `$PT_SPECTRA_CACHE`; `PT_BENCH_BINS=n` takes the first
//! n bins only. Run with `RAYON_NUM_THREADS=1 cargo bench -p pt-spectra-tests --bench bispectrum_bins`.

// `criterion_group!` defines an undocumented function.
#![allow(missing_docs)]

use criterion::{criterion_group, criterion_main, Criterion};
use pt_spectra::bispectrum::bias_kernels::LoopBias;
use pt_spectra::bispectrum::multipole_bins::MultipoleBinBasis;
use pt_spectra::bispectrum::one_loop::OneLoopRule;
use pt_spectra::bispectrum::{LegendreSide, TriangleSet};
use pt_spectra::linear::LinearSpectrum;
use std::hint::black_box;

fn nseries(n: Option<usize>) -> TriangleSet {
    let text = include_str!("../data/bispectrum/nseries_triangles.txt");
    let rows: Vec<[f64; 3]> = text
        .lines()
        .filter(|l| !l.starts_with('#'))
        .map(|l| {
            let v: Vec<f64> = l.split_whitespace().map(|x| x.parse().unwrap()).collect();
            [v[0], v[1], v[2]]
        })
        .take(n.unwrap_or(usize::MAX))
        .collect();
    TriangleSet::shells(rows, 0.01).unwrap()
}

fn one_loop_multipole_bins(crit: &mut Criterion) {
    let rule = OneLoopRule {
        radial: 2,
        mu: 2,
        phi: 2,
        ..OneLoopRule::default()
    };
    let n = std::env::var("PT_BENCH_BINS")
        .ok()
        .and_then(|n| n.parse::<usize>().ok());
    let set = nseries(n);
    let start = std::time::Instant::now();
    let store = pt_spectra::store::TableStore::from_env();
    let bins = store
        .tensors::<MultipoleBinBasis>(
            (&set, LegendreSide::Largest, &rule, &[rule, rule]),
            |tick| {
                MultipoleBinBasis::build_with(
                    &set,
                    LegendreSide::Largest,
                    &rule,
                    [rule, rule],
                    tick,
                )
                .unwrap()
            },
            &pt_spectra::progress::Silent,
        )
        .unwrap();
    eprintln!(
        "multipole bin tensors of {} bins on 2 x 2 x 2 rules: {:.1} s (or read from the cache)",
        set.len(),
        start.elapsed().as_secs_f64()
    );
    let spectra: Vec<LinearSpectrum> = [0.0, 0.5, 1.0, 1.5]
        .iter()
        .map(|&z| LinearSpectrum::gm2012(z).unwrap())
        .collect();
    let bias = LoopBias::from_velocileptors(2.0, 0.3, -0.2);
    let f = |i: u32| 0.6 + 0.01 * f64::from(i % 30);
    let mut i = 0;
    crit.bench_function(
        &format!(
            "bispectrum/one-loop galaxy B0 B2 B4 of {} Nseries bins, new spectrum and f, multipole bin \
             tensors",
            set.len()
        ),
        |b| {
            b.iter(|| {
                i += 1;
                let m = bins.evaluate(&spectra[i as usize % spectra.len()], f(i)).unwrap();
                black_box(m.evaluate(&bias).unwrap())
            })
        },
    );
    let split = pt_spectra::ir::WiggleSplit::new().unwrap();
    let q_min = pt_spectra::precision::Precision::default().q_min;
    let inputs: Vec<_> = spectra
        .iter()
        .map(|p| pt_spectra::bispectrum::IrInputs::split(p, &split, q_min).unwrap())
        .collect();
    crit.bench_function(
        &format!(
            "bispectrum/one-loop galaxy B0 B2 B4 of {} Nseries bins, new spectrum and f, multipole bin \
             tensors, IR",
            set.len()
        ),
        |b| {
            b.iter(|| {
                i += 1;
                let at = i as usize % spectra.len();
                let (m, _) = bins
                    .evaluate_projected(&spectra[at], f(i), Some(&inputs[at]))
                    .unwrap();
                black_box(m.evaluate(&bias).unwrap())
            })
        },
    );
    crit.bench_function(
        &format!(
            "bispectrum/one-loop galaxy B0 B2 B4 of {} Nseries bins: the effective triangles only",
            set.len()
        ),
        |b| {
            b.iter(|| {
                i += 1;
                let p = &spectra[i as usize % spectra.len()];
                black_box(bins.effective().evaluate(p, f(i)).unwrap())
            })
        },
    );
    let start = std::time::Instant::now();
    let counterterms =
        pt_spectra::bispectrum::counterterm_plan::CountertermPlan::new(&set, LegendreSide::Largest)
            .unwrap();
    eprintln!(
        "counterterm plan of {} bins: {:.1} s",
        set.len(),
        start.elapsed().as_secs_f64()
    );
    crit.bench_function(
        &format!(
            "bispectrum/one-loop counterterm and stochastic multipoles of {} Nseries bins, new spectrum \
             and f",
            set.len()
        ),
        |b| {
            b.iter(|| {
                i += 1;
                let p = &spectra[i as usize % spectra.len()];
                black_box(counterterms.evaluate(p, f(i)).unwrap().at(&bias))
            })
        },
    );
    // the one-loop block of a data vector: a new spectrum and f (loops + counterterms), then a new bias
    let block = pt_spectra::bispectrum::loop_block::LoopBispectrumBlock {
        triangles: set.clone(),
        side: LegendreSide::Largest,
        rule,
        ells: vec![0, 2, 4],
        cache_dir: None,
        fitted: None,
    }
    .plan_with_bins(bins.clone())
    .unwrap();
    let shared = pt_spectra::statistic::Shared {
        b1: 2.0,
        b2: 0.3,
        bs: -0.2,
    };
    let own: Vec<f64> = (0..25).map(|i| 0.1 * f64::from(i)).collect();
    let prepared: Vec<_> = spectra
        .iter()
        .map(|p| block.prepare(p, false).unwrap())
        .collect();
    crit.bench_function(
        &format!(
            "bispectrum/one-loop block of {} Nseries bins (B0 B2 B4, counterterms), new spectrum and f",
            set.len()
        ),
        |b| {
            b.iter(|| {
                i += 1;
                let at = i as usize % spectra.len();
                let terms = block
                    .terms(&spectra[at], &prepared[at], f(i), (1.0, 1.0))
                    .unwrap();
                black_box(terms.values(shared, &own).unwrap())
            })
        },
    );
    let terms = block
        .terms(&spectra[0], &prepared[0], f(0), (1.0, 1.0))
        .unwrap();
    crit.bench_function(
        &format!(
            "bispectrum/one-loop block of {} Nseries bins, new bias and counterterms",
            set.len()
        ),
        |b| {
            b.iter(|| {
                i += 1;
                let s = pt_spectra::statistic::Shared {
                    b1: 2.0 + 1e-3 * f64::from(i % 50),
                    ..shared
                };
                black_box(terms.values(s, &own).unwrap())
            })
        },
    );
}

criterion_group! {
    name = benches;
    config = Criterion::default().sample_size(10);
    targets = one_loop_multipole_bins
}
criterion_main!(benches);
