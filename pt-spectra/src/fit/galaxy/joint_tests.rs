//! Joint fits against single fits whose likelihood they must equal, and on model data with two
//! truths.

use super::tests::setup;
use super::*;

/// Model multipoles ℓ = 0, 2, 4 of `truth` on the plan's k with σ = 1% of P0, times
/// (1 + `wiggle` sin(7i + ℓ)) (a fixed pattern standing for noise).
fn model_data(plan: &EptPlan, terms: &EptTerms, truth: &EptParams, wiggle: f64) -> MultipoleData {
    let m = plan.multipoles(terms, truth, &[0, 2, 4]).unwrap();
    let values: Vec<Vec<f64>> = m
        .iter()
        .enumerate()
        .map(|(l, row)| {
            row.iter()
                .enumerate()
                .map(|(i, e)| e.value * (1.0 + wiggle * (7.0 * i as f64 + l as f64).sin()))
                .collect()
        })
        .collect();
    let sigma: Vec<Vec<f64>> = (0..3)
        .map(|_| m[0].iter().map(|p| 0.01 * p.value).collect())
        .collect();
    MultipoleData::from_arrays(plan.k().to_vec(), &[0, 2, 4], values, sigma, "model").unwrap()
}

/// The request: free f, b1, b2 (started off the truth), α0 and sn marginalised, a prior on b2.
fn request(truth: &EptParams) -> GalaxyFitRequest {
    let mut start = *truth;
    start.set("f", 0.65).unwrap();
    start.set("b1", 1.9).unwrap();
    start.set("b2", 0.0).unwrap();
    GalaxyFitRequest {
        start,
        ap: None,
        free: vec!["f".into(), "b1".into(), "b2".into()],
        marginalise: vec!["alpha0".into(), "sn".into()],
        priors: vec![Prior::gaussian("b2", 0.0, 2.0)],
        ells: vec![0, 2],
        k_min: 0.0,
        k_max: 0.2,
        ell_ranges: vec![],
        n_mocks: None,
        basis: FitBasis::Velocileptors,
    }
}

fn set<'a>(
    label: &str,
    plan: &'a EptPlan,
    terms: &'a EptTerms,
    data: &'a MultipoleData,
    request: &GalaxyFitRequest,
) -> DataSet<'a> {
    DataSet {
        label: label.into(),
        z: 0.5,
        tracer: String::new(),
        plan,
        terms,
        data,
        request: request.clone(),
        observation: None,
        block: None,
    }
}

/// One data set: the joint fit is the single fit, field for field (same objective, bounds, starts,
/// minimiser), with no parameter shared and with f declared shared.
#[test]
fn one_set_is_the_single_fit() {
    let (plan, terms, truth, _) = setup();
    let data = model_data(&plan, &terms, &truth, 0.01);
    let r = request(&truth);
    let search = Search::default();
    let single = fit_galaxy_search(&plan, &terms, &data, &r, None, &search).unwrap();
    for shared in [vec![], vec!["f".to_string()]] {
        let joint = fit_joint(&[set("a", &plan, &terms, &data, &r)], &shared, &search).unwrap();
        assert_eq!(joint.sets[0], single);
        assert_eq!(joint.minus_two_log_l, single.minus_two_log_l);
        assert_eq!(joint.errors, single.errors);
    }
}

/// Two copies of one data set (covariance C each) with every free parameter shared and the linear
/// ones profiled are one copy with C/2 (module docs of [`super::joint`]): the same best fit and the
/// same errors on the shared parameters to the minimiser's tolerance (Δ(−2 ln L) 1e-7, i.e. ~5e-4 σ),
/// and −2 ln L the same; the prior on the shared b2 counts once in both.
#[test]
fn two_copies_are_one_copy_with_half_the_covariance() {
    let (plan, terms, truth, _) = setup();
    let data = model_data(&plan, &terms, &truth, 0.01);
    let mut half = data.clone();
    for row in half.sigma.iter_mut() {
        for s in row.iter_mut() {
            *s /= 2f64.sqrt();
        }
    }
    let r = request(&truth);
    let search = Search {
        linear: Linear::Profiled,
        ..Search::default()
    };
    let one = fit_galaxy_search(&plan, &terms, &half, &r, None, &search).unwrap();
    let shared: Vec<String> = r.free.clone();
    let joint = fit_joint(
        &[
            set("a", &plan, &terms, &data, &r),
            set("b", &plan, &terms, &data, &r),
        ],
        &shared,
        &search,
    )
    .unwrap();
    assert_eq!(joint.names, shared);
    for (j, name) in shared.iter().enumerate() {
        let (got, want) = (
            joint.sets[0].best.get(name).unwrap(),
            one.best.get(name).unwrap(),
        );
        assert!(
            (got - want).abs() < 2e-3 * one.errors[j],
            "{name}: {got} vs {want} (σ {})",
            one.errors[j]
        );
        assert_eq!(joint.sets[1].best.get(name), joint.sets[0].best.get(name));
        let e = joint.errors[j] / one.errors[j] - 1.0;
        assert!(
            e.abs() < 2e-3,
            "{name}: σ {} vs {}",
            joint.errors[j],
            one.errors[j]
        );
    }
    assert!(
        (joint.minus_two_log_l - one.minus_two_log_l).abs() < 1e-5,
        "{} vs {}",
        joint.minus_two_log_l,
        one.minus_two_log_l
    );
    assert!((joint.chi2 - one.chi2).abs() < 1e-5);
}

/// Two noise-free data sets with b1 = 1.8 and 2.2 and the same f: the joint fit with f shared and
/// b1, b2 per set recovers both b1 and f (to 5% of their errors), χ² ≈ 0.
#[test]
fn recovers_two_biases_and_the_shared_growth_rate() {
    let (plan, terms, mut truth, _) = setup();
    truth.set("b1", 1.8).unwrap();
    let low = model_data(&plan, &terms, &truth, 0.0);
    let mut truth_high = truth;
    truth_high.set("b1", 2.2).unwrap();
    let high = model_data(&plan, &terms, &truth_high, 0.0);
    let r = request(&truth);
    let search = Search {
        profile_check: false,
        ..Search::default()
    };
    let sets = [
        set("low", &plan, &terms, &low, &r),
        set("high", &plan, &terms, &high, &r),
    ];
    assert_eq!(default_shared(&sets), vec!["f".to_string()]);
    // Another redshift or another tracer: nothing shared by default.
    let mut other = sets.clone();
    other[1].z = 0.8;
    assert!(default_shared(&other).is_empty());
    other[1].z = 0.5;
    other[1].tracer = "ELG".into();
    assert!(default_shared(&other).is_empty());
    let joint = fit_joint(&sets, &default_shared(&sets), &search).unwrap();
    assert_eq!(
        joint.names,
        ["f", "b1[low]", "b2[low]", "b1[high]", "b2[high]"]
    );
    let want = [0.75, 1.8, -0.4, 2.2, -0.4];
    for (j, name) in joint.names.iter().enumerate() {
        let s = usize::from(j > 2);
        let base = name.split('[').next().unwrap();
        let got = joint.sets[s].best.get(base).unwrap();
        assert!(
            (got - want[j]).abs() < 0.05 * joint.errors[j],
            "{name}: {got} vs {} (σ {})",
            want[j],
            joint.errors[j]
        );
    }
    assert!(joint.chi2 < 1e-2, "{}", joint.chi2);
    // The shared f has one error, the same in both sets' fits.
    assert_eq!(joint.sets[0].errors[0], joint.sets[1].errors[0]);
    assert_eq!(joint.sets[0].errors[0], joint.errors[0]);
}

/// Every sharing rule broken is an error naming the parameter (or label) and the rule.
#[test]
fn sharing_rules_are_checked() {
    let (plan, terms, truth, _) = setup();
    let data = model_data(&plan, &terms, &truth, 0.0);
    let r = request(&truth);
    let mut fixed_f = r.clone();
    fixed_f.free.retain(|n| n != "f");
    let mut other_prior = r.clone();
    other_prior.priors = vec![Prior::gaussian("b2", 0.0, 3.0)];
    let search = Search {
        starts: 1,
        profile_check: false,
        ..Search::default()
    };
    let two = |a: &GalaxyFitRequest, b: &GalaxyFitRequest, shared: &[&str], label: &str| {
        let shared: Vec<String> = shared.iter().map(|s| s.to_string()).collect();
        fit_joint(
            &[
                set("a", &plan, &terms, &data, a),
                set(label, &plan, &terms, &data, b),
            ],
            &shared,
            &search,
        )
        .unwrap_err()
        .to_string()
    };
    let e = two(&r, &fixed_f, &["f"], "b");
    assert!(
        e.contains("`f`") && e.contains("not free in data set `b`"),
        "{e}"
    );
    let e = two(&r, &r, &["sn"], "b");
    assert!(e.contains("`sn`") && e.contains("marginalised"), "{e}");
    let e = two(&r, &r, &["apar"], "b");
    assert!(e.contains("no data set has it free"), "{e}");
    let e = two(&r, &r, &["bogus"], "b");
    assert!(e.contains("bogus"), "{e}");
    let e = two(&r, &other_prior, &["b2"], "b");
    assert!(e.contains("`b2`") && e.contains("one prior"), "{e}");
    let e = two(&r, &r, &["f"], "a");
    assert!(e.contains("label `a`") && e.contains("twice"), "{e}");
    let e = fit_joint(&[], &[], &search).unwrap_err().to_string();
    assert!(e.contains("at least one data set"), "{e}");
}

/// The likelihood a sampler calls is the fit's: at the joint best fit its value is the fit's
/// −2 ln L; its gradient matches differences of it; a value outside the bounds is refused.
#[test]
fn the_joint_likelihood_is_what_the_fit_minimises() {
    let (plan, terms, truth, _) = setup();
    let (d1, d2) = (
        model_data(&plan, &terms, &truth, 0.01),
        model_data(&plan, &terms, &truth, -0.01),
    );
    let r = request(&truth);
    let sets = [
        set("a", &plan, &terms, &d1, &r),
        set("b", &plan, &terms, &d2, &r),
    ];
    let shared = vec!["f".to_string()];
    let fit = fit_joint(&sets, &shared, &Search::default()).unwrap();
    let like = JointLikelihood::new(&sets, &shared, Linear::Marginalised).unwrap();
    assert_eq!(like.names, fit.names);
    assert!(like.exact_gradient());
    let best: Vec<f64> = like
        .names
        .iter()
        .map(|n| {
            let (name, s) = match n.split_once('[') {
                Some((name, label)) => (name, usize::from(label.starts_with('b'))),
                None => (n.as_str(), 0),
            };
            fit.sets[s].best.get(name).unwrap()
        })
        .collect();
    let v = like.minus_two_log_l(&best).unwrap();
    assert!(
        (v - fit.minus_two_log_l).abs() < 1e-9 * v.abs(),
        "{v} vs {}",
        fit.minus_two_log_l
    );
    let x: Vec<f64> = best.iter().map(|b| b * 1.02).collect();
    let (value, g) = like.value_and_gradient(&x).unwrap().unwrap();
    let direct = like.minus_two_log_l(&x).unwrap();
    assert!(
        (value - direct).abs() < 1e-9 * direct,
        "{value} vs {direct}"
    );
    for j in 0..x.len() {
        let h = 1e-4 * x[j].abs().max(1.0);
        let at = |d: f64| {
            let mut y = x.clone();
            y[j] += d;
            like.minus_two_log_l(&y).unwrap()
        };
        let fd = (8.0 * (at(h) - at(-h)) - (at(2.0 * h) - at(-2.0 * h))) / (12.0 * h);
        assert!(
            (g[j] - fd).abs() < 1e-5 * fd.abs().max(1.0),
            "{}: {} vs {fd}",
            like.names[j],
            g[j]
        );
    }
    let mut out = best.clone();
    out[0] = like.upper[0] + 1.0;
    let e = like.minus_two_log_l(&out).unwrap_err().to_string();
    assert!(e.contains("outside the likelihood's range"), "{e}");
    assert!(like.minus_two_log_l(&best[1..]).is_err());
}
