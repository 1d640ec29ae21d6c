//! The chain-step `Pipeline` (issue 47) against the path it replaces: the ept plan's terms, its
//! multipoles with the AP distortion, and the observation (BOSS CMASS NGC window, 38 k); with a
//! bispectrum block, against the bispectrum plan on the same spectrum.

use pt_spectra::bispectrum::block::BispectrumBlock;
use pt_spectra::bispectrum::{BispectrumParams, BispectrumPlan, Fog, Settings, TriangleSet};
use pt_spectra::cosmology::Cosmology;
use pt_spectra::jobs::ept_plan;
use pt_spectra::pipeline::loop_range::LOOP_RANGE_TOLERANCE;
use pt_spectra::pipeline::mu_rule::MU_RULE_TOLERANCE;
use pt_spectra::pipeline::{
    Pipeline, PipelineSettings, TermsSource, JACOBIAN_NAMES, NUISANCE_NAMES, PIPELINE_MAX_RESIDUAL,
};
use pt_spectra::precision::{Precision, TwoLoopMethod};
use pt_spectra::progress::Silent;
use pt_spectra::rsd::ap::Distortion;
use pt_spectra::rsd::ept::{EptParams, MU_NODES};
use pt_spectra::setup::{prepare, LinearSource, NamedCosmology, Request};
use pt_spectra::store::TableStore;
use pt_spectra::survey::observe::{Observation, Window};
use pt_spectra::survey::{Mixing, WindowFormat};
use std::sync::OnceLock;

pub(crate) const Z: f64 = 0.57;
/// The observation matrix against the window's own steps: 3.9e-8 of the largest element measured
/// (the window's transform is linear up to its tail treatment, rounding aside), plus the loop range's
/// change (≤ 1e-5 of a multipole's largest value, 1.6e-6 of P4's measured); the brief's bound.
const ROUNDING: f64 = 1e-6;

pub(crate) fn observation() -> Observation {
    let path = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../examples/data/boss_dr12_cmass_ngc/window_BOSS_CMASS_NGC_z057.dat"
    );
    let window = Window::read(path.as_ref(), Mixing::Wilson, &WindowFormat::header()).unwrap();
    let k: Vec<f64> = (0..38)
        .map(|i| 0.015 * (0.38f64 / 0.015).powf(i as f64 / 37.0))
        .collect();
    Observation::new(&[0, 2, 4], &k, Some(window), None).unwrap()
}

pub(crate) fn precision() -> Precision {
    let mut p = Precision::preset("fast").unwrap();
    p.two_loop = TwoLoopMethod::Basis;
    p
}

pub(crate) fn store() -> TableStore {
    TableStore::new(concat!(env!("CARGO_TARGET_TMPDIR"), "/pipeline-store"))
}

pub(crate) fn fiducial() -> Cosmology {
    Cosmology::flat(0.31, 0.676, 0.022, 0.97, 0.80).unwrap()
}

fn truth() -> Cosmology {
    Cosmology::flat(0.295, 0.69, 0.0226, 0.955, 0.83).unwrap()
}

pub(crate) fn pipeline() -> &'static Pipeline {
    static P: OnceLock<Pipeline> = OnceLock::new();
    P.get_or_init(|| {
        let settings = PipelineSettings::ept(Z, Some(fiducial()));
        Pipeline::new(observation(), settings, &precision(), &store(), &Silent).unwrap()
    })
}

pub(crate) const PARAMS: [(&str, f64); 8] = [
    ("b1", 2.1),
    ("b2", -0.4),
    ("bs", 0.3),
    ("b3", 0.2),
    ("alpha0", 12.0),
    ("alpha2", -20.0),
    ("sn", 1500.0),
    ("sn2", -800.0),
];

pub(crate) fn max_abs(v: &[f64]) -> f64 {
    v.iter().fold(0.0, |a, x| a.max(x.abs()))
}

fn assert_close(a: &[f64], b: &[f64], tol: f64, what: &str) {
    assert_eq!(a.len(), b.len(), "{what}");
    let scale = max_abs(b);
    let worst = a
        .iter()
        .zip(b)
        .map(|(x, y)| (x - y).abs() / scale)
        .fold(0.0, f64::max);
    assert!(worst <= tol, "{what}: worst {worst:e} > {tol:e}");
}

/// The existing path: the prepared emulated spectrum, the plan on the AP range, its multipoles at
/// the distortion of the cosmology, then the observation's own steps.
/// The ept plan of the observation's model k with IR and the AP range, on the basis (24 μ nodes).
fn observation_plan(obs: &Observation) -> pt_spectra::rsd::ept::EptPlan {
    ept_plan(
        obs.k_model(),
        true,
        None,
        true,
        &precision(),
        &store(),
        &Silent,
    )
    .unwrap()
}

/// [`PARAMS`] at growth rate f.
fn params_at(f: f64) -> EptParams {
    let mut p = EptParams::new(0.0, f);
    for (n, v) in PARAMS {
        p.set(n, v).unwrap();
    }
    p
}

fn chain(max_residual: f64, c: &Cosmology) -> (Vec<f64>, Option<f64>) {
    let obs = observation();
    let prepared = prepare(Request {
        source: LinearSource::Emulator,
        cosmology: Some(NamedCosmology {
            name: "test".into(),
            cosmology: *c,
        }),
        z: Z,
    })
    .unwrap();
    let plan = observation_plan(&obs)
        .with_max_residual(max_residual)
        .unwrap();
    let terms = plan.terms(prepared.tracer_spectrum()).unwrap();
    let p = params_at(prepared.growth_rate);
    let ap = Distortion::from_cosmologies(c, &fiducial(), Z).unwrap();
    let m = plan
        .multipole_values_at(&terms, &p, obs.model_ells(), Some(ap))
        .unwrap();
    let d = obs.apply_values(&m).unwrap().concat();
    (d, terms.basis_residual())
}

#[test]
fn the_pipeline_equals_the_chain_of_plan_multipoles_and_observation() {
    let pl = pipeline();
    assert_eq!(pl.len(), 3 * 38);
    let (expected, residual) = chain(PIPELINE_MAX_RESIDUAL, &truth());
    // The emulated spectrum projects on the basis within the limit (loops::basis::MAX_RESIDUAL, the
    // pipeline's too; the plans' old 3e-4 sent it to the direct integrals).
    let residual = residual.expect("an emulated spectrum is evaluated on the basis");
    assert!(
        residual > 0.0 && residual <= PIPELINE_MAX_RESIDUAL,
        "{residual}"
    );
    let got = pl.evaluate(&truth(), &PARAMS).unwrap();
    assert_close(&got, &expected, ROUNDING, "pipeline vs chain");
    let step = pl.step(&pl.prepare(&truth()).unwrap()).unwrap();
    assert_eq!(step.source, TermsSource::Basis { residual });
}

#[test]
fn outside_the_span_the_pipeline_falls_back_to_direct_and_says_so() {
    let mut settings = PipelineSettings::ept(Z, Some(fiducial()));
    settings.max_residual = 1e-6;
    let pl = Pipeline::new(observation(), settings, &precision(), &store(), &Silent).unwrap();
    let step = pl.step(&pl.prepare(&truth()).unwrap()).unwrap();
    let TermsSource::DirectFallback { residual } = step.source else {
        panic!("{:?}", step.source);
    };
    assert!(residual > 1e-6, "{residual}");
    assert!(step.source.describe(1e-6).contains("fallback"));
    let direct = step.data_vector(&PARAMS).unwrap();
    let (expected, r) = chain(1e-6, &truth());
    assert!(r.is_none());
    assert_close(&direct, &expected, ROUNDING, "fallback vs direct chain");
    // The basis and the direct integrals agree within the projection error (≲ residual × terms).
    let basis = pipeline().evaluate(&truth(), &PARAMS).unwrap();
    assert_close(&basis, &direct, PIPELINE_MAX_RESIDUAL, "basis vs direct");
}

#[test]
fn the_nuisance_polynomial_and_its_jacobian_are_exact() {
    let pl = pipeline();
    let step = pl.step(&pl.prepare(&truth()).unwrap()).unwrap();
    let lin = step.linearise_with_df(None).unwrap();
    assert_eq!(lin.names(), &JACOBIAN_NAMES);
    assert_eq!(step.linearise(None).unwrap().names(), &NUISANCE_NAMES);
    let sets: [&[(&str, f64)]; 3] = [
        &PARAMS,
        &[
            ("b1", 1.3),
            ("b3", -1.1),
            ("alpha4", 3.0),
            ("alpha6", 1.5),
            ("sn4", 40.0),
        ],
        &[("b2", 2.0), ("bs", -1.7)],
    ];
    for set in sets {
        let direct = step.data_vector(set).unwrap();
        assert_close(&lin.data_vector(set).unwrap(), &direct, 1e-9, "polynomial");
        // Fourth-order central differences of the full step (exact for a quadratic up to rounding).
        let jac = lin.jacobian(set).unwrap();
        for (n, column) in NUISANCE_NAMES.iter().zip(&jac) {
            let base = set.iter().find(|(m, _)| m == n).map_or(0.0, |p| p.1);
            let h = 0.5 * base.abs().max(1.0);
            let at = |x: f64| {
                let mut s: Vec<(&str, f64)> = set.iter().filter(|(m, _)| m != n).copied().collect();
                s.push((n, x));
                step.data_vector(&s).unwrap()
            };
            let (p1, m1, p2, m2) = (
                at(base + h),
                at(base - h),
                at(base + 2.0 * h),
                at(base - 2.0 * h),
            );
            let fd: Vec<f64> = (0..p1.len())
                .map(|r| (8.0 * (p1[r] - m1[r]) - (p2[r] - m2[r])) / (12.0 * h))
                .collect();
            assert_close(column, &fd, 1e-6, n);
        }
        // ∂/∂f (not a polynomial: the BAO damping's exponential): against fourth-order central
        // differences of the full step with step control (h and h/2 agree to 1e-8 of the largest
        // element before the comparison)
        assert_eq!(jac.len(), JACOBIAN_NAMES.len());
        assert_eq!(JACOBIAN_NAMES[NUISANCE_NAMES.len()], "f");
        let f0 = step.growth_rate;
        let at = |x: f64| {
            let mut s: Vec<(&str, f64)> = set.to_vec();
            s.push(("f", x));
            step.data_vector(&s).unwrap()
        };
        let fd = |h: f64| -> Vec<f64> {
            let (p1, m1, p2, m2) = (at(f0 + h), at(f0 - h), at(f0 + 2.0 * h), at(f0 - 2.0 * h));
            (0..p1.len())
                .map(|r| (8.0 * (p1[r] - m1[r]) - (p2[r] - m2[r])) / (12.0 * h))
                .collect()
        };
        let (coarse, fine) = (fd(2e-3 * f0), fd(1e-3 * f0));
        assert_close(&coarse, &fine, 1e-8, "f: step control");
        assert_close(&jac[NUISANCE_NAMES.len()], &fine, 1e-6, "f");
        // the step's Jacobian: the same rows, its f row from the one set
        let (values, rows) = step.jacobian(set).unwrap();
        assert_close(&values, &direct, 1e-9, "step: values");
        assert_eq!(rows.len(), JACOBIAN_NAMES.len());
        for (a, b) in rows.iter().zip(&jac) {
            assert_close(a, b, 1e-9, "step: rows");
        }
    }
}

#[test]
fn bad_parameter_names_are_refused_naming_the_valid_ones() {
    let pl = pipeline();
    let err = pl
        .evaluate(&truth(), &[("b1", 2.0), ("c0", 1.0)])
        .unwrap_err()
        .to_string();
    assert!(
        err.contains("c0") && err.contains("alpha0") && err.contains("sn4"),
        "{err}"
    );
    let step = pl.step(&pl.prepare(&truth()).unwrap()).unwrap();
    let lin = step.linearise(None).unwrap();
    let err = lin.data_vector(&[("bias", 2.0)]).unwrap_err().to_string();
    assert!(err.contains("bias") && err.contains("b1"), "{err}");
    let err = lin.data_vector(&[("f", 0.3)]).unwrap_err().to_string();
    assert!(err.contains("linearised"), "{err}");
}

#[test]
fn a_batch_gives_the_single_calls() {
    let pl = pipeline();
    let other = Cosmology::flat(0.32, 0.66, 0.0221, 0.975, 0.78).unwrap();
    let sets = vec![
        (truth(), PARAMS.to_vec()),
        (other, vec![("b1", 1.8), ("sn", 300.0)]),
    ];
    let batch = pl.evaluate_batch(&sets).unwrap();
    assert_eq!(batch[0], pl.evaluate(&truth(), &PARAMS).unwrap());
    assert_eq!(
        batch[1],
        pl.evaluate(&other, &[("b1", 1.8), ("sn", 300.0)]).unwrap()
    );
    assert_ne!(batch[0], batch[1]);
}

/// Four bins of width 0.01 h/Mpc (Nseries-like), B0 and B2, Lorentzian FoG, n̄ = 3e-4.
fn bispectrum_block() -> BispectrumBlock {
    let bins = vec![
        [0.015, 0.025, 0.035],
        [0.035, 0.035, 0.055],
        [0.045, 0.055, 0.065],
        [0.055, 0.065, 0.075],
    ];
    BispectrumBlock {
        ells: vec![0, 2],
        fog: Fog::Lorentzian { sigma: 4.0 },
        n_bar: 3e-4,
        ..BispectrumBlock::monopole(TriangleSet::shells(bins, 0.01).unwrap())
    }
}

#[test]
fn a_bispectrum_block_follows_the_power_spectrum_with_the_same_spectrum_f_and_distortion() {
    let mut settings = PipelineSettings::ept(Z, Some(fiducial()));
    settings.blocks = vec![std::sync::Arc::new(bispectrum_block())];
    let pl = Pipeline::new(observation(), settings, &precision(), &store(), &Silent).unwrap();
    assert_eq!((pl.len(), pl.power_len()), (3 * 38 + 2 * 4, 3 * 38));
    let b_params = [("c1", 2.0), ("b_shot", 0.9), ("a_shot", 0.1)];
    let params: Vec<(&str, f64)> = PARAMS.iter().chain(&b_params).copied().collect();
    let prepared = pl.prepare(&truth()).unwrap();
    let got = pl.step(&prepared).unwrap().data_vector(&params).unwrap();
    // the power spectrum part is the pipeline without the block
    let p_only = pipeline().evaluate(&truth(), &PARAMS).unwrap();
    assert_eq!(&got[..pl.power_len()], &p_only[..]);
    // the block: the bispectrum plan on the same spectrum at f(z), the cosmology's distortion, IR
    let ap = Distortion::from_cosmologies(&truth(), &fiducial(), Z).unwrap();
    assert!((ap.apar - 1.0).abs() > 1e-3, "the test needs a distortion");
    let block = bispectrum_block();
    let direct = |f: f64| {
        BispectrumPlan::new(block.triangles.clone(), block.side, block.rules)
            .unwrap()
            .terms(
                prepared.tracer_spectrum(),
                &Settings {
                    f,
                    q_par: ap.apar,
                    q_perp: ap.aperp,
                    fog: block.fog,
                    ir: true,
                },
            )
            .unwrap()
            .multipoles(&BispectrumParams {
                b1: 2.1,
                b2: -0.4,
                bs: 0.3,
                c1: 2.0,
                b_shot: 0.9,
                p_shot: 0.0,
                a_shot: 0.1,
                n_bar: 3e-4,
            })
            .unwrap()
    };
    let flat = |m: Vec<[pt_spectra::estimate::Estimate; 3]>| -> Vec<f64> {
        [0, 1]
            .iter()
            .flat_map(|&l| m.iter().map(move |r| r[l].value).collect::<Vec<_>>())
            .collect()
    };
    assert_close(
        &got[pl.power_len()..],
        &flat(direct(prepared.growth_rate)),
        1e-12,
        "block vs bispectrum plan",
    );
    // another f: refused on the step at f(z), given by a step at that f
    let f = prepared.growth_rate + 0.05;
    let mut with_f = params.clone();
    with_f.push(("f", f));
    let step = pl.step(&prepared).unwrap();
    let err = step.data_vector(&with_f).unwrap_err().to_string();
    assert!(err.contains("step_at_growth_rate"), "{err}");
    let at_f = pl
        .step_at_growth_rate(&prepared, f)
        .unwrap()
        .data_vector(&with_f)
        .unwrap();
    assert_close(&at_f[pl.power_len()..], &flat(direct(f)), 1e-12, "at f");
    // the nuisance polynomial is the power spectrum's: refused with a block
    assert!(step.linearise(None).is_err());
    assert!(pl.parameters().contains(&"b_shot"));
    // without a block a bispectrum name is refused, saying why
    let err = pipeline()
        .evaluate(&truth(), &[("b1", 2.0), ("c1", 1.0)])
        .unwrap_err()
        .to_string();
    assert!(err.contains("no bispectrum block"), "{err}");
}

#[test]
fn the_loop_range_is_measured_at_build_and_changes_the_data_vector_by_little() {
    // The BOSS window reaches k = 1e-4 … 4 h/Mpc; the data 0.015 … 0.38. The pipeline computes the
    // loops on about 3e-3 … 0.6 (true k) only: the build measured what this changes on its reference
    // (≤ 1e-5 of each multipole's largest value), and at another cosmology and parameters the change
    // against a pipeline with the loops everywhere stays at that level (1.6e-6 measured).
    let pl = pipeline();
    let ((lo, hi), change) = pl.loop_range().expect("a restricted loop range");
    assert!(change <= LOOP_RANGE_TOLERANCE, "{change}");
    let k_model = observation().k_model().to_vec();
    assert!(lo > k_model[0] && lo < 0.015 && hi > 0.38 && hi < k_model[k_model.len() - 1]);
    assert!(pl.describe_loop_range().contains("loop terms on true k in"));
    let settings = PipelineSettings {
        restrict_loops: false,
        ..PipelineSettings::ept(Z, Some(fiducial()))
    };
    let everywhere =
        Pipeline::new(observation(), settings, &precision(), &store(), &Silent).unwrap();
    assert!(everywhere.loop_range().is_none());
    let a = pl.evaluate(&truth(), &PARAMS).unwrap();
    let b = everywhere.evaluate(&truth(), &PARAMS).unwrap();
    for block in 0..3 {
        let r = block * 38..(block + 1) * 38;
        let scale = max_abs(&b[r.clone()]);
        let worst = r.map(|i| (a[i] - b[i]).abs() / scale).fold(0.0, f64::max);
        assert!(
            worst <= 3.0 * LOOP_RANGE_TOLERANCE,
            "ℓ = {}: {worst:e}",
            2 * block
        );
    }
}

/// The step's multipoles use a smaller rule in μ than the plans' 24 points, chosen at build by its
/// change of the reference data vector at the corners of the AP range (≤ 1e-5 of each multipole's
/// largest value). At another spectrum, other parameters and a strong distortion, the 24- and the
/// chosen rule's data vectors stay within twice that (measured 16 nodes: 4.2e-7 at (1.2, 0.85)).
#[test]
fn the_mu_rule_is_measured_at_build_and_changes_the_data_vector_by_little() {
    let pl = pipeline();
    let (n, change) = pl.mu_rule().expect("a smaller rule in mu");
    assert!(n < MU_NODES && change <= MU_RULE_TOLERANCE, "{n} {change}");
    assert!(pl
        .describe_mu_rule()
        .starts_with(&format!("multipoles: {n}-point")));
    let obs = observation();
    let plan = observation_plan(&obs);
    let fewer = plan.clone().with_value_nodes(n).unwrap();
    assert_eq!((plan.value_nodes(), fewer.value_nodes()), (MU_NODES, n));
    let prepared = pl.prepare(&truth()).unwrap();
    let terms = plan.terms(prepared.tracer_spectrum()).unwrap();
    let p = params_at(0.9);
    let ap = Some(Distortion::new(1.2, 0.85).unwrap());
    let data = |plan: &pt_spectra::rsd::ept::EptPlan| {
        let m = plan
            .multipole_values_at(&terms, &p, obs.model_ells(), ap)
            .unwrap();
        obs.apply_values(&m).unwrap().concat()
    };
    let (a, b) = (data(&plan), data(&fewer));
    let mut worst: f64 = 0.0;
    for block in 0..3 {
        let r = block * 38..(block + 1) * 38;
        let scale = max_abs(&a[r.clone()]);
        worst = r.fold(worst, |w, i| w.max((a[i] - b[i]).abs() / scale));
    }
    assert!(worst > 0.0 && worst <= 2.0 * MU_RULE_TOLERANCE, "{worst:e}");
    assert!(plan.clone().with_value_nodes(4).is_err());
}

/// The exact derivatives with respect to f, α∥, α⊥ of the windowed data vector against fourth-order
/// central differences of steps at those values (step control: h and 2h agree first), to 1e-9 of
/// each column's largest element: the interpolant in ln k' is a C² cubic B-spline, so the
/// differences see no kinks where k' crosses its grid nodes (measured: steps ≤ 6.2e-11 apart, the
/// exact derivatives ≤ 5.1e-11 from the h = 1e-5 differences; with the four-point Lagrange
/// interpolant before it, 3.9e-7 and 6.2e-8 for α∥).
#[test]
fn the_template_jacobian_is_the_differences_of_steps() {
    let pl = pipeline();
    let prepared = pl.prepare(&truth()).unwrap();
    let step = pl.step(&prepared).unwrap();
    let ap = step.ap.unwrap();
    let exact = step.template_jacobian(&PARAMS).unwrap();
    let at = |f: f64, apar: f64, aperp: f64| {
        let d = Distortion::new(apar, aperp).unwrap();
        pl.step_with(prepared.tracer_spectrum(), f, Some(d))
            .unwrap()
            .data_vector(&PARAMS)
            .unwrap()
    };
    let x0 = [step.growth_rate, ap.apar, ap.aperp];
    for (which, exact) in exact.iter().enumerate() {
        let value = |x: f64| {
            let mut v = x0;
            v[which] = x;
            at(v[0], v[1], v[2])
        };
        let fd = |h: f64| -> Vec<f64> {
            let (p1, m1, p2, m2) = (
                value(x0[which] + h),
                value(x0[which] - h),
                value(x0[which] + 2.0 * h),
                value(x0[which] - 2.0 * h),
            );
            (0..p1.len())
                .map(|r| (8.0 * (p1[r] - m1[r]) - (p2[r] - m2[r])) / (12.0 * h))
                .collect()
        };
        let (fine, coarse) = (fd(1e-5), fd(2e-5));
        assert_close(
            &coarse,
            &fine,
            1e-9,
            [
                "f: step control",
                "apar: step control",
                "aperp: step control",
            ][which],
        );
        assert_close(exact, &fine, 1e-9, ["f", "apar", "aperp"][which]);
    }
}
