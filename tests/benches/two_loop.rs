//! The 2-loop propagator term P15 of δδ, δθ, θθ (with error estimates) from the angular table, for the
//! embedded gm2012 z = 0 spectrum, and the N2 propagator built from it:
//!
//! * `p15/evaluate/100`: P15 on 100 log-spaced k in [0.005, 0.4] h/Mpc (rayon's pool);
//! * `n2/1l-rpt-n2/100`: the whole 1L-RPT-N2 model on the same grid through `RealPlan::evaluate`, as a
//!   fit or an MCMC step calls it (the plan built once): 1-loop terms, P15, N2;
//! * `n2/with-plan/100`: the same on a new grid, building the plan as well (the angular table already
//!   loaded in the store);
//! * `p17/evaluate/40`: P17 (for N3) on 40 log-spaced k in [0.005, 0.4] from its angular table;
//! * `two_loop/set/40`: every 2-loop term (P15, P24, P33, the total) of δδ, δθ, θθ with errors on 40
//!   log-spaced k in [0.005, 0.4] at the default precision (after the 1-loop terms);
//! * `gamma2/plan/40`, `gamma2/evaluate/40`: RegPT's vertex terms P24 and PΓ2 on the same grid: the
//!   cosmology-independent weights (once per grid), and a spectrum on them (per cosmology).
//!
//! * `two_loop/basis/40`: the same 2-loop set for a new spectrum from the basis tensors (with its 1-loop
//!   terms; run with `RAYON_NUM_THREADS=1` for one core);
//! * `new spectrum through the basis/2l-spt/40`, `…/2l-regpt/40`: the whole model from a new CAMB
//!   table's (k, P) arrays through `RealPlan::evaluate` with method basis (the spline, the
//!   projection, the 1- and 2-loop contractions, and for RegPT the vertex Γ2 as linear forms on the
//!   basis), as the Python timing script measures it.
//!
//! The angular table is read from its cache (or built once, outside the timing). Run with
//! `cargo bench --bench two_loop`.

// `criterion_group!` defines an undocumented function.
#![allow(missing_docs)]

use criterion::{black_box, criterion_group, criterion_main, Criterion};
use pt_spectra::linear::{LinearSpectrum, LogGrid};
use pt_spectra::loops::basis::{SpectrumFamily, TwoLoopBasis};
use pt_spectra::loops::{p15_terms, two_loop_correction, Gamma2Plan, OneLoopPlan};
use pt_spectra::precision::Precision;
use pt_spectra::progress::Silent;
use pt_spectra::real::{RealModel, RealPlan};
use pt_spectra::store::TableStore;

fn p15(c: &mut Criterion) {
    let p = LinearSpectrum::gm2012(0.0).expect("embedded spectrum");
    let k = LogGrid::new(0.005, 0.4, 100).expect("valid grid").points();
    let precision = Precision::default();
    let store = TableStore::from_env();
    let table = store.p15(&Silent).expect("table");
    let mut group = c.benchmark_group("p15");
    group.bench_function("evaluate/100", |b| {
        b.iter(|| {
            table.evaluate(
                black_box(&k),
                &p,
                (precision.q_min, precision.q_max),
                precision.lattice_step,
            )
        })
    });
    group.finish();
    let table17 = store.p17(&Silent).expect("table");
    let k40 = LogGrid::new(0.005, 0.4, 40).expect("valid grid").points();
    let mut group = c.benchmark_group("p17");
    group.sample_size(20);
    group.bench_function("evaluate/40", |b| {
        b.iter(|| {
            table17.evaluate(
                black_box(&k40),
                &p,
                (precision.q_min, precision.q_max),
                precision.lattice_step,
            )
        })
    });
    group.finish();
    let mut group = c.benchmark_group("n2");
    group.sample_size(20);
    // As a fit or an MCMC loop calls it: the plan is built once.
    let model = RealModel::OneLoopRptN2;
    let plan = RealPlan::new(&k, model, &precision, &store, &Silent).expect("valid");
    group.bench_function("1l-rpt-n2/100", |b| {
        b.iter(|| plan.evaluate(black_box(&p), &Silent).expect("valid"))
    });
    // A first call on a new grid: the plan is built too.
    group.bench_function("with-plan/100", |b| {
        b.iter(|| {
            let plan =
                RealPlan::new(black_box(&k), model, &precision, &store, &Silent).expect("valid");
            plan.evaluate(&p, &Silent).expect("valid")
        })
    });
    group.finish();
}

fn two_loop(c: &mut Criterion) {
    let p = LinearSpectrum::gm2012(0.0).expect("embedded spectrum");
    let k = LogGrid::new(0.005, 0.4, 40).expect("valid grid").points();
    let precision = Precision::default();
    let one = OneLoopPlan::new(&k, &precision)
        .expect("valid")
        .par_evaluate(&p);
    let table = TableStore::from_env().p15(&Silent).expect("table");
    let mut group = c.benchmark_group("two_loop");
    group.sample_size(10);
    group.bench_function("set/40", |b| {
        b.iter(|| {
            let p15 = p15_terms(&table, &k, black_box(&p), &precision);
            two_loop_correction(&one, &p15, &table, &p, &precision, &|_, _| {})
        })
    });
    group.finish();
    let range = (precision.q_min, precision.q_max);
    let mut group = c.benchmark_group("gamma2");
    group.sample_size(10);
    group.bench_function("plan/40", |b| {
        b.iter(|| Gamma2Plan::new(black_box(&k), range, precision.lattice_step))
    });
    let plan = Gamma2Plan::new(&k, range, precision.lattice_step);
    group.bench_function("evaluate/40", |b| b.iter(|| plan.evaluate(black_box(&p))));
    group.finish();
}

/// The 2-loop set of a new spectrum from the basis tensors (`two_loop/basis/40`): the 1-loop terms
/// (one core), the projection and the contractions, for the CAMB Planck 2018 table (not a training
/// spectrum). The tensors of the grid are built on first use (minutes) and cached. Before timing, the
/// largest relative difference of the 2-loop correction from the direct integral for k ≤ 0.3 is
/// printed, for that table and the held-out CAMB tables of `tests/data`.
fn basis(c: &mut Criterion) {
    let k = LogGrid::new(0.005, 0.4, 40).expect("valid grid").points();
    let precision = Precision::default();
    let store = TableStore::from_env();
    let table = store.p15(&Silent).expect("table");
    let key = (&k[..], &precision, SpectrumFamily::Linear);
    let tensors = store
        .tensors::<TwoLoopBasis>(
            key,
            |tick| TwoLoopBasis::build_linear(&k, &precision, &table, tick),
            &Silent,
        )
        .expect("tensors");
    let plan = OneLoopPlan::new(&k, &precision).expect("valid");
    let data = |name: &str| {
        let path = format!(
            "{}/../pt-spectra/tests/data/{name}",
            env!("CARGO_MANIFEST_DIR")
        );
        LinearSpectrum::from_file(&path).expect("test table")
    };
    let planck = data("linear_pk_planck2018_z0.0.dat");
    for name in [
        "linear_pk_planck2018_z0.0.dat",
        "linear_pk_planck2018_z1.0.dat",
        "linear_pk_camb_heldout_0.dat",
        "linear_pk_camb_heldout_1.dat",
        "linear_pk_camb_heldout_2.dat",
    ] {
        let p = data(name);
        let one = plan.par_evaluate(&p);
        let Ok(basis) = tensors.evaluate(&p, &one) else {
            println!("{name}: outside the basis");
            continue;
        };
        let p15 = p15_terms(&table, &k, &p, &precision);
        // Direct at the same (fixed) points as the tensors, and as it runs by default (refined where
        // an error exceeds 1e-3 of the correction, so with other points at those k).
        let mut fixed = precision.clone();
        fixed.two_loop_tolerance = 0.0;
        let worst = |precision: &Precision| {
            let direct = two_loop_correction(&one, &p15, &table, &p, precision, &|_, _| {});
            (0..k.len())
                .filter(|&i| k[i] <= 0.3)
                .flat_map(|i| {
                    pt_spectra::loops::Pair::ALL.map(|pair| {
                        let (b, d) = (
                            basis.correction.pairs[pair].total[i],
                            direct.pairs[pair].total[i],
                        );
                        ((b.value / d.value - 1.0).abs(), k[i], pair, d.value)
                    })
                })
                .fold(
                    (0.0, 0.0, pt_spectra::loops::Pair::DeltaDelta, 0.0),
                    |a, b| {
                        if b.0 > a.0 {
                            b
                        } else {
                            a
                        }
                    },
                )
        };
        println!(
            "{name}: projection residual {:.1e}; for k <= 0.3 the 2-loop correction is within {:.1e} \
             of direct at the same points, {:.1e} of refined direct",
            basis.projection.residual,
            worst(&fixed).0,
            worst(&precision).0
        );
        println!("   {:?}", worst(&fixed));
    }
    let mut group = c.benchmark_group("two_loop");
    group.bench_function("basis/40", |b| {
        b.iter(|| {
            let one = plan.evaluate(black_box(&planck));
            tensors.evaluate(&planck, &one).expect("inside the basis")
        })
    });
    group.finish();
}

/// 2L-SPT and 2L-RegPT of a new spectrum through `RealPlan` with the basis (module docs).
fn models(c: &mut Criterion) {
    use pt_spectra::precision::TwoLoopMethod;
    let k = LogGrid::new(0.005, 0.4, 40).expect("valid grid").points();
    let mut precision = Precision::default();
    precision.two_loop = TwoLoopMethod::Basis;
    let store = TableStore::from_env();
    let table = LinearSpectrum::from_file(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../pt-spectra/tests/data/linear_pk_camb_heldout_1.dat"
    ))
    .expect("test table");
    let (k_in, p_in) = (table.nodes().0.to_vec(), table.nodes().1.to_vec());
    let mut group = c.benchmark_group("new spectrum through the basis");
    for (name, model) in [
        ("2l-spt/40", RealModel::TwoLoopSpt),
        ("2l-regpt/40", RealModel::TwoLoopRegPt),
    ] {
        let plan = RealPlan::new(&k, model, &precision, &store, &Silent).expect("valid plan");
        group.bench_function(name, |b| {
            b.iter(|| {
                let p = LinearSpectrum::from_nodes(k_in.clone(), p_in.clone()).expect("valid");
                plan.evaluate(black_box(&p), &Silent).expect("evaluates")
            })
        });
    }
    group.finish();
}

criterion_group!(benches, p15, two_loop, basis, models);
criterion_main!(benches);
