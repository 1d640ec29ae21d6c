//! The tree-level bispectrum (issue 49: the 62 bin-averaged Nseries triangles, B0, B2, B4, for a new
//! linear spectrum ≤ 0.2 ms; a parameter step ≤ 20 µs): the terms of a new spectrum (f, AP, FoG and IR
//! resummation as a fit varies them) and the contraction with new bias and stochastic parameters.
//!
//! The one-loop matter bispectrum (issue 50) through its basis tensors and directly; a parameter step of the
//! one-loop galaxy bispectrum per bias monomial.
//!
//! Run with `RAYON_NUM_THREADS=1 cargo bench -p pt-spectra-tests --bench bispectrum` for one core (the
//! terms are computed triangle by triangle in parallel otherwise).

// `criterion_group!` defines an undocumented function.
#![allow(missing_docs)]

use criterion::{criterion_group, criterion_main, Criterion};
use pt_spectra::bispectrum::{
    BispectrumParams, BispectrumPlan, Fog, LegendreSide, PlanRules, Settings, TriangleSet,
};
use pt_spectra::linear::LinearSpectrum;
use std::hint::black_box;

fn nseries() -> TriangleSet {
    let text = include_str!("../data/bispectrum/nseries_triangles.txt");
    let rows: Vec<[f64; 3]> = text
        .lines()
        .filter(|l| !l.starts_with('#'))
        .map(|l| {
            let v: Vec<f64> = l.split_whitespace().map(|x| x.parse().unwrap()).collect();
            [v[0], v[1], v[2]]
        })
        .collect();
    TriangleSet::shells(rows, 0.01).unwrap()
}

fn bispectrum(crit: &mut Criterion) {
    let plan = BispectrumPlan::new(nseries(), LegendreSide::Largest, PlanRules::default()).unwrap();
    let p = LinearSpectrum::gm2012(0.5).unwrap();
    let mut i = 0u32;
    let settings = |i: u32| Settings {
        f: 0.7 + 1e-3 * f64::from(i % 50),
        q_par: 1.0 + 1e-3 * f64::from(i % 7),
        q_perp: 1.0 - 1e-3 * f64::from(i % 5),
        fog: Fog::Lorentzian { sigma: 3.0 },
        ir: true,
    };
    crit.bench_function(
        "bispectrum/terms of 62 Nseries bins, B0 B2 B4, new f and AP, IR",
        |b| {
            b.iter(|| {
                i += 1;
                black_box(plan.terms(&p, &settings(i)).unwrap())
            })
        },
    );
    // the two parts of a new spectrum: its IR inputs (the no-wiggle split and Σ², δΣ², which a
    // P + B pipeline could share with the power spectrum) and the bin and orientation averages
    crit.bench_function(
        "bispectrum/IR inputs of a new spectrum (split, Σ², δΣ²)",
        |b| b.iter(|| black_box(plan.ir_inputs(&p).unwrap())),
    );
    let ir = plan.ir_inputs(&p).unwrap();
    crit.bench_function(
        "bispectrum/terms of 62 Nseries bins with given IR inputs, new f and AP",
        |b| {
            b.iter(|| {
                i += 1;
                black_box(plan.terms_with_ir(&p, &settings(i), &ir).unwrap())
            })
        },
    );
    let terms = plan.terms(&p, &settings(0)).unwrap();
    crit.bench_function(
        "bispectrum/parameter step (b1, b2, bs, c1, shot) of 62 bins",
        |b| {
            b.iter(|| {
                i += 1;
                let params = BispectrumParams {
                    b1: 2.0 + 1e-3 * f64::from(i % 100),
                    b2: 0.3,
                    bs: -0.2,
                    c1: 1.0,
                    b_shot: 0.9,
                    p_shot: 0.1,
                    a_shot: 0.0,
                    n_bar: 3e-4,
                };
                black_box(terms.multipoles(&params).unwrap())
            })
        },
    );
}

/// The one-loop matter bispectrum (issue 50: ≤ 10 ms per new spectrum through the basis) at the 62
/// Nseries triangles (their centres: the bins' averages are not built for the one-loop terms yet),
/// the default rule, through the basis tensors (built once, cached in `$PT_SPECTRA_CACHE`), and one
/// triangle directly for comparison.
fn one_loop(crit: &mut Criterion) {
    use pt_spectra::bispectrum::one_loop::{one_loop_matter, OneLoopRule};
    use pt_spectra::bispectrum::one_loop_basis::{OneLoopMatterBasis, OneLoopMatterPlan};
    let triangles: Vec<[f64; 3]> = nseries().triangles().to_vec();
    let rule = OneLoopRule::default();
    let store = pt_spectra::store::TableStore::from_env();
    let start = std::time::Instant::now();
    let tensors = store
        .tensors::<OneLoopMatterBasis>(
            (&triangles, &rule),
            |tick| OneLoopMatterBasis::build(&triangles, &rule, tick).unwrap(),
            &pt_spectra::progress::Silent,
        )
        .unwrap();
    eprintln!(
        "one-loop bispectrum tensors of {} triangles: {:.1} s (or read from the cache)",
        triangles.len(),
        start.elapsed().as_secs_f64()
    );
    let plan = OneLoopMatterPlan::new(triangles, rule)
        .unwrap()
        .with_basis(tensors)
        .unwrap();
    let spectra: Vec<LinearSpectrum> = [0.0, 0.5, 1.0, 1.5]
        .iter()
        .map(|&z| LinearSpectrum::gm2012(z).unwrap())
        .collect();
    let mut i = 0;
    crit.bench_function(
        "bispectrum/one-loop matter B of 62 Nseries triangles, new spectrum, basis",
        |b| {
            b.iter(|| {
                i += 1;
                black_box(plan.evaluate(&spectra[i % spectra.len()]).unwrap())
            })
        },
    );
    crit.bench_function(
        "bispectrum/one-loop matter B of one triangle, direct",
        |b| b.iter(|| black_box(one_loop_matter(&spectra[0], [0.1, 0.1, 0.1], &rule).unwrap())),
    );
}

/// A parameter step of the one-loop galaxy bispectrum per bias monomial (issue 50): the terms of the 62
/// Nseries triangles (their centres) at a new set of the 11 bias coefficients, real space and redshift space
/// at one orientation, from the polynomials (built here on a cheap rule: the number of monomials, and so the
/// cost of a step, does not depend on the rule).
fn one_loop_galaxy_step(crit: &mut Criterion) {
    use pt_spectra::bispectrum::bias_kernels::LoopBias;
    use pt_spectra::bispectrum::one_loop::OneLoopRule;
    use pt_spectra::bispectrum::one_loop_galaxy_poly::one_loop_galaxy_polynomial;
    use pt_spectra::bispectrum::one_loop_rsd::Orientation;
    let rule = OneLoopRule {
        radial: 2,
        mu: 4,
        phi: 4,
        ..OneLoopRule::default()
    };
    let p = LinearSpectrum::gm2012(0.5).unwrap();
    let o = Orientation { mu1: 0.4, phi: 0.7 };
    for (name, redshift) in [("real space", None), ("redshift space", Some((0.7, o)))] {
        let polys: Vec<_> = nseries()
            .triangles()
            .iter()
            .map(|&k| one_loop_galaxy_polynomial(&p, k, redshift, &rule).unwrap())
            .collect();
        let mut i = 0;
        crit.bench_function(
            &format!("bispectrum/one-loop galaxy B of 62 Nseries triangles, new bias, {name}"),
            |b| {
                b.iter(|| {
                    i += 1;
                    let bias = LoopBias::from_values([
                        1.8 + 1e-6 * i as f64,
                        0.6,
                        -0.3,
                        0.4,
                        0.5,
                        -0.2,
                        0.35,
                        0.3,
                        -0.4,
                        0.25,
                        0.6,
                    ]);
                    let terms: Vec<_> = polys.iter().map(|t| t.evaluate(&bias).unwrap()).collect();
                    black_box(terms)
                })
            },
        );
    }
}

/// The real-space one-loop galaxy polynomials of the 62 Nseries triangles for a new linear spectrum from the
/// basis tensors per monomial (built here on a cheap rule: the contraction's cost does not depend on the
/// rule; the build time of one triangle at the default rule is printed).
fn one_loop_galaxy_basis(crit: &mut Criterion) {
    use pt_spectra::bispectrum::one_loop::OneLoopRule;
    use pt_spectra::bispectrum::one_loop_galaxy_basis::GalaxyLoopBasis;
    let start = std::time::Instant::now();
    GalaxyLoopBasis::build(&[[0.1, 0.1, 0.1]], &OneLoopRule::default(), &|_, _| {}).unwrap();
    eprintln!(
        "galaxy tensors of one triangle at the default rule: {:.1} s",
        start.elapsed().as_secs_f64()
    );
    let rule = OneLoopRule {
        radial: 2,
        mu: 4,
        phi: 4,
        ..OneLoopRule::default()
    };
    let basis = GalaxyLoopBasis::build(nseries().triangles(), &rule, &|_, _| {}).unwrap();
    let spectra: Vec<LinearSpectrum> = [0.0, 0.5, 1.0, 1.5]
        .iter()
        .map(|&z| LinearSpectrum::gm2012(z).unwrap())
        .collect();
    let mut i = 0;
    crit.bench_function(
        "bispectrum/one-loop galaxy polynomials of 62 Nseries triangles, new spectrum, basis, real space",
        |b| {
            b.iter(|| {
                i += 1;
                black_box(basis.evaluate(&spectra[i % spectra.len()]))
            })
        },
    );
    // On the first n functions (docs/bispectrum.md: 24 give <= 1e-3 of B): the contraction reads the
    // tensors' entries below n only.
    for n in [24, 16] {
        crit.bench_function(
            &format!(
                "bispectrum/one-loop galaxy polynomials of 62 Nseries triangles, new spectrum, basis, \
                 real space, first {n} functions"
            ),
            |b| {
                b.iter(|| {
                    i += 1;
                    let p = &spectra[i % spectra.len()];
                    black_box(basis.evaluate_projected(p, &basis.project_first(p, n)))
                })
            },
        );
    }
}

/// The one-loop galaxy multipoles B0, B2, B4 of the 62 Nseries triangles in redshift space per bias monomial
/// for a new linear spectrum and growth rate from the multipole tensors (16 templates, f free; built here on
/// a cheap rule: the contraction's cost does not depend on the rule; one triangle at the default rule takes
/// 193 s on one core, docs/bispectrum.md).
fn one_loop_multipole_basis(crit: &mut Criterion) {
    use pt_spectra::bispectrum::multipole_basis::MultipoleLoopBasis;
    use pt_spectra::bispectrum::one_loop::OneLoopRule;
    let rule = OneLoopRule {
        radial: 2,
        mu: 4,
        phi: 4,
        ..OneLoopRule::default()
    };
    let triangles = nseries().triangles().to_vec();
    let basis =
        MultipoleLoopBasis::build(&triangles, LegendreSide::Largest, &rule, &|_, _| {}).unwrap();
    eprintln!(
        "multipole tensors of 62 triangles: {} values",
        basis.values()
    );
    let spectra: Vec<LinearSpectrum> = [0.0, 0.5, 1.0, 1.5]
        .iter()
        .map(|&z| LinearSpectrum::gm2012(z).unwrap())
        .collect();
    let mut i = 0;
    crit.bench_function(
        "bispectrum/one-loop galaxy B0 B2 B4 of 62 Nseries triangles, new spectrum and f, multipole tensors",
        |b| {
            b.iter(|| {
                i += 1;
                let f = 0.6 + 0.01 * f64::from(i % 30);
                black_box(basis.evaluate(&spectra[i as usize % spectra.len()], f).unwrap())
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
        "bispectrum/one-loop galaxy B0 B2 B4 of 62 Nseries triangles, new spectrum and f, multipole tensors, IR",
        |b| {
            b.iter(|| {
                i += 1;
                let f = 0.6 + 0.01 * f64::from(i % 30);
                let at = i as usize % spectra.len();
                black_box(basis.evaluate_ir(&spectra[at], &inputs[at], f).unwrap())
            })
        },
    );
}

criterion_group! {
    name = benches;
    config = Criterion::default().sample_size(10);
    targets = bispectrum, one_loop, one_loop_galaxy_step, one_loop_galaxy_basis, one_loop_multipole_basis
}
criterion_main!(benches);
