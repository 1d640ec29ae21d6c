//! Fits of the power spectrum with the bispectrum beside it, on model data: the truth recovered,
//! the bispectrum tightening f and b2, the cross-covariance entering the likelihood as it must, and
//! the refusals.

use crate::bispectrum::block::BispectrumBlock;
use crate::bispectrum::{Fog, LegendreSide, PlanRules, TriangleSet};
use crate::fit::galaxy::tests::setup;
use crate::fit::galaxy::{
    fit_joint, BlockFit, DataSet, FitBasis, GalaxyFitRequest, JointFit, JointLikelihood, Linear,
    Search,
};
use crate::fit::MultipoleData;
use crate::linear::LinearSpectrum;
use crate::rsd::ept::{EptParams, EptPlan, EptTerms};
use crate::statistic::{Shared, Spec};

type BispectrumFit = BlockFit;

/// Number density of the model data's stochastic terms [(h/Mpc)³].
const N_BAR: f64 = 3e-4;

/// Ten triangles from squeezed to equilateral, 0.02 ≤ k ≤ 0.1 h/Mpc, at points.
fn triangles() -> TriangleSet {
    TriangleSet::points(vec![
        [0.03, 0.03, 0.03],
        [0.05, 0.05, 0.05],
        [0.08, 0.08, 0.08],
        [0.1, 0.1, 0.1],
        [0.04, 0.05, 0.06],
        [0.06, 0.08, 0.1],
        [0.02, 0.08, 0.09],
        [0.05, 0.1, 0.1],
        [0.03, 0.06, 0.08],
        [0.07, 0.07, 0.1],
    ])
    .unwrap()
}

fn block() -> BispectrumBlock {
    BispectrumBlock {
        triangles: triangles(),
        side: LegendreSide::Largest,
        rules: PlanRules::default(),
        ells: vec![0, 2],
        fog: Fog::None,
        n_bar: N_BAR,
    }
}

/// The power spectrum of `setup` with its diagonal covariance, and the bispectrum B0, B2 of the
/// truth (b1, b2, bs, f of the power spectrum's truth; c1 = 5, b_shot = 1.2) with σ = 2% of |B0|
/// and, with `cross`, a correlation of `cross` between P0 at the first k and every B entry.
fn data(cross: f64) -> (EptPlan, EptTerms, EptParams, MultipoleData, BispectrumFit) {
    let (plan, terms, truth, mut data) = setup();
    let n_p: usize = data.values.iter().map(Vec::len).sum();
    let sigma_p: Vec<f64> = data.sigma.iter().flatten().copied().collect();
    data.covariance = Some(
        (0..n_p)
            .map(|i| {
                (0..n_p)
                    .map(|j| if i == j { sigma_p[i].powi(2) } else { 0.0 })
                    .collect()
            })
            .collect(),
    );
    let spectrum = LinearSpectrum::gm2012(0.5).unwrap();
    let model = BispectrumFit::new(
        &block(),
        spectrum.clone(),
        false,
        vec![0.0; 20],
        vec![vec![0.0; 20]; n_p],
        diagonal(&[1.0; 20]),
    )
    .unwrap()
    .with_start("c1", 5.0)
    .unwrap()
    .with_start("b_shot", 1.2)
    .unwrap();
    let values = bispectrum_of(&model, &truth);
    let sigma_b: Vec<f64> = (0..20).map(|j| 0.02 * values[j % 10].abs()).collect();
    let mut c = vec![vec![0.0; 20]; n_p];
    for j in 0..20 {
        c[0][j] = cross * sigma_p[0] * sigma_b[j];
    }
    let fit = BispectrumFit::new(
        &block(),
        spectrum,
        false,
        values,
        c,
        diagonal(&sigma_b.iter().map(|s| s * s).collect::<Vec<_>>()),
    )
    .unwrap()
    .with_start("c1", 5.0)
    .unwrap()
    .with_start("b_shot", 1.2)
    .unwrap();
    (plan, terms, truth, data, fit)
}

fn diagonal(v: &[f64]) -> Vec<Vec<f64>> {
    (0..v.len())
        .map(|i| {
            (0..v.len())
                .map(|j| if i == j { v[i] } else { 0.0 })
                .collect()
        })
        .collect()
}

/// B of `fit`'s block at `truth` and `fit`'s start values of its own parameters.
fn bispectrum_of(fit: &BispectrumFit, truth: &EptParams) -> Vec<f64> {
    let spectrum = LinearSpectrum::gm2012(0.5).unwrap();
    let block = block().plan().unwrap();
    let prepared = block.prepare(&spectrum, false).unwrap();
    let terms = block
        .terms(&spectrum, &prepared, truth.f(), (1.0, 1.0))
        .unwrap();
    let bias = truth.bias();
    let shared = Shared {
        b1: bias.b1,
        b2: bias.b2,
        bs: bias.bs,
    };
    terms.values(shared, fit.start()).unwrap()
}

fn request(truth: &EptParams, marginalise: &[&str]) -> GalaxyFitRequest {
    let mut start = *truth;
    start.set("f", 0.65).unwrap();
    start.set("b1", 1.9).unwrap();
    start.set("b2", 0.0).unwrap();
    GalaxyFitRequest {
        start,
        ap: None,
        free: vec!["f".into(), "b1".into(), "b2".into(), "c1".into()],
        marginalise: marginalise.iter().map(|s| s.to_string()).collect(),
        priors: vec![],
        ells: vec![0, 2],
        k_min: 0.0,
        k_max: 0.2,
        ell_ranges: vec![],
        n_mocks: None,
        basis: FitBasis::Velocileptors,
    }
}

fn set<'a>(
    plan: &'a EptPlan,
    terms: &'a EptTerms,
    data: &'a MultipoleData,
    request: &GalaxyFitRequest,
    bispectrum: Option<&'a BispectrumFit>,
) -> DataSet<'a> {
    DataSet {
        label: "pb".into(),
        z: 0.5,
        tracer: String::new(),
        plan,
        terms,
        data,
        request: request.clone(),
        observation: None,
        block: bispectrum,
    }
}

fn quick() -> Search {
    Search {
        starts: 2,
        profile_check: false,
        ..Search::default()
    }
}

/// Noise-free P + B of a known truth: f, b1, b2, c1 free, the counterterms, the power spectrum's
/// shot noise and b_shot marginalised: the truth recovered (b_shot to 1e-3 at â), χ² ≈ 0, and σ(f),
/// σ(b2) smaller than from the power spectrum alone.
#[test]
fn the_truth_is_recovered_and_the_bispectrum_tightens_f_and_b2() {
    let (plan, terms, truth, data, b) = data(0.0);
    let mut r = request(&truth, &["alpha0", "alpha2", "sn", "b_shot"]);
    r.start.set("c1", 0.0).ok(); // not a galaxy-model name: the bispectrum's start is its own
    let b = b.with_start("c1", 0.0).unwrap();
    let pb = fit_joint(&[set(&plan, &terms, &data, &r, Some(&b))], &[], &quick()).unwrap();
    let fit = &pb.sets[0];
    assert!(fit.chi2 < 1e-3, "{}", fit.chi2);
    for (name, want) in [("f", truth.f()), ("b1", 2.0), ("b2", -0.4)] {
        let got = fit.best.get(name).unwrap();
        assert!((got - want).abs() < 1e-3, "{name}: {got} vs {want}");
    }
    let own = fit.block.as_ref().unwrap().values.clone();
    assert!((own[0] - 5.0).abs() < 0.05, "c1 {own:?}");
    assert!((own[1] - 1.2).abs() < 1e-3, "b_shot {own:?}");
    // the power spectrum alone: no bispectrum parameter, wider errors
    let mut rp = request(&truth, &["alpha0", "alpha2", "sn"]);
    rp.free.retain(|n| n != "c1");
    let p = fit_joint(&[set(&plan, &terms, &data, &rp, None)], &[], &quick()).unwrap();
    // (the minimiser differences −2 ln L with a bispectrum, has its exact gradient without)
    assert!(!fit.exact_gradient && p.sets[0].exact_gradient);
    let err = |f: &JointFit, n: &str| {
        let at = f.names.iter().position(|x| x.split('[').next() == Some(n));
        f.errors[at.unwrap()]
    };
    for n in ["f", "b1", "b2"] {
        eprintln!("sigma({n}): {} with B, {} without", err(&pb, n), err(&p, n));
    }
    // measured: σ(f) 0.00634 against 0.00669, σ(b1) 0.0126 against 0.0160, σ(b2) 0.042 against
    // 0.64 (ten triangles at 2%, c1 free, b_shot
    // marginalised)
    assert!(err(&pb, "f") < 0.97 * err(&p, "f"));
    assert!(err(&pb, "b2") < 0.5 * err(&p, "b2"));
    // the whole table: the bispectrum's own parameters in the fit
    assert_eq!(fit.points, 48 + 20);
}

/// The cross-covariance enters −2 ln L as it must: P0 at the first k one σ off and B exact, so
/// that χ² = (C⁻¹)₀₀ σ²; with a correlation ρ between that point and each of the 20 B entries (and
/// no other), the block [[1, ρuᵀ], [ρu, I]] (u all ones) gives (C⁻¹)₀₀ = 1/(1 − 20ρ²).
#[test]
fn the_cross_covariance_enters_the_likelihood() {
    let chi2_at_truth = |rho: f64| {
        let (plan, terms, truth, mut data, b) = data(rho);
        data.values[0][0] += data.sigma[0][0];
        let mut r = request(&truth, &[]);
        r.free = vec!["b2".into()];
        r.start = truth;
        let sets = [set(&plan, &terms, &data, &r, Some(&b))];
        // no prior, no marginalised parameter, no ln det: −2 ln L is χ²
        let o = JointLikelihood::new(&sets, &[], Linear::Profiled).unwrap();
        o.minus_two_log_l(&[truth.get("b2").unwrap()]).unwrap()
    };
    let uncorrelated = chi2_at_truth(0.0);
    assert!((uncorrelated - 1.0).abs() < 1e-9, "{uncorrelated}");
    for rho in [0.1, 0.2] {
        let correlated = chi2_at_truth(rho);
        let want = 1.0 / (1.0 - 20.0 * rho * rho);
        assert!(
            (correlated - want).abs() < 1e-9 * want,
            "{rho}: {correlated} vs {want}"
        );
    }
}

/// Refused: a bispectrum parameter without a bispectrum; a bispectrum with diagonal power-spectrum
/// errors; data of the wrong size.
#[test]
fn refusals_name_the_problem() {
    let (plan, terms, truth, data, b) = data(0.0);
    let r = request(&truth, &[]);
    let e = fit_joint(&[set(&plan, &terms, &data, &r, None)], &[], &quick())
        .unwrap_err()
        .to_string();
    assert!(e.contains("c1") && e.contains("no bispectrum"), "{e}");
    let mut diagonal_p = data.clone();
    diagonal_p.covariance = None;
    let e = fit_joint(
        &[set(&plan, &terms, &diagonal_p, &r, Some(&b))],
        &[],
        &quick(),
    )
    .unwrap_err()
    .to_string();
    assert!(e.contains("joint covariance"), "{e}");
    let spectrum = LinearSpectrum::gm2012(0.5).unwrap();
    let e = BispectrumFit::new(
        &block(),
        spectrum,
        false,
        vec![1.0; 19],
        vec![],
        diagonal(&[1.0; 20]),
    )
    .unwrap_err()
    .to_string();
    assert!(e.contains("20 fitted entries"), "{e}");
}
