// Index loops mirror the formulae's subscripts.
#![allow(clippy::needless_range_loop)]

use super::*;
use crate::linear::{LinearSpectrum, LogGrid};
use crate::precision::Precision;
use crate::rsd::ept::EptSettings;

pub(crate) fn setup() -> (EptPlan, EptTerms, EptParams, MultipoleData) {
    let k = LogGrid::new(0.02, 0.2, 24).unwrap().points();
    let plan = EptPlan::new(
        &k,
        EptSettings {
            ir: false,
            ap: None,
            ap_range: None,
            loop_range: None,
        },
        &Precision::fast(),
    )
    .unwrap();
    let terms = plan.terms(&LinearSpectrum::gm2012(0.5).unwrap()).unwrap();
    let mut truth = EptParams::new(2.0, 0.75);
    for (n, v) in [
        ("b2", -0.4),
        ("bs", 0.2),
        ("alpha0", 8.0),
        ("alpha2", -6.0),
        ("sn", 900.0),
    ] {
        truth.set(n, v).unwrap();
    }
    let m = plan.multipoles(&terms, &truth, &[0, 2, 4]).unwrap();
    let values: Vec<Vec<f64>> = m
        .iter()
        .map(|l| l.iter().map(|e| e.value).collect())
        .collect();
    let sigma: Vec<Vec<f64>> = (0..3)
        .map(|_| values[0].iter().map(|p| 0.01 * p).collect())
        .collect();
    let data = MultipoleData::from_arrays(k, &[0, 2, 4], values, sigma, "model").unwrap();
    (plan, terms, truth, data)
}

/// Noise-free data made by the model: the fit recovers the free and the marginalised parameters.
#[test]
fn recovers_the_truth_with_marginalised_counterterms() {
    let (plan, terms, truth, data) = setup();
    let mut start = truth;
    start.set("f", 0.65).unwrap();
    start.set("b1", 1.8).unwrap();
    start.set("b2", 0.0).unwrap();
    let request = GalaxyFitRequest {
        start,
        ap: None,
        free: vec!["f".into(), "b1".into(), "b2".into()],
        marginalise: vec!["alpha0".into(), "alpha2".into(), "sn".into()],
        priors: vec![],
        ells: vec![0, 2, 4],
        k_min: 0.0,
        k_max: 0.2,
        ell_ranges: vec![],
        n_mocks: None,
        basis: FitBasis::Velocileptors,
    };
    let fit = fit_galaxy(&plan, &terms, &data, &request).unwrap();
    // ln det F is nearly flat in θ, so the maximum of the marginal likelihood sits within a small
    // fraction of σ of χ² = 0.
    for (i, name) in ["f", "b1", "b2", "alpha0", "alpha2", "sn"]
        .iter()
        .enumerate()
    {
        let (got, want) = (fit.best.get(name).unwrap(), truth.get(name).unwrap());
        let sigma = match i {
            0..=2 => fit.errors[i],
            _ => fit.marginalised_errors[i - 3],
        };
        assert!(sigma > 0.0 && sigma.is_finite(), "{name}: σ {sigma}");
        assert!(
            (got - want).abs() < 0.05 * sigma,
            "{name}: {got} vs {want} (σ {sigma})"
        );
    }
    assert!(fit.chi2 < 1e-2, "{}", fit.chi2);
}

/// −2 ln L of one marginalised parameter with a prior against a direct quadrature of
/// ∫ exp(−½[χ²(a) + prior]) da: −2 ln of the integral = (−2 ln L) − ln 2π.
#[test]
fn analytic_marginalisation_is_the_integral() {
    let (plan, terms, truth, data) = setup();
    let mut start = truth;
    start.set("alpha0", 0.0).unwrap();
    let prior = Prior::gaussian("alpha0", 3.0, 10.0);
    let request = GalaxyFitRequest {
        start,
        ap: None,
        free: vec!["f".into()],
        marginalise: vec!["alpha0".into()],
        priors: vec![prior.clone()],
        ells: vec![0, 2],
        k_min: 0.0,
        k_max: 0.15,
        ell_ranges: vec![],
        n_mocks: None,
        basis: FitBasis::Velocileptors,
    };
    let fit = fit_galaxy(&plan, &terms, &data, &request).unwrap();
    // χ² at fixed a (alpha0 fixed, nothing marginalised) on a grid, integrated by Simpson.
    let chi2_at = |a: f64| {
        let mut p = start;
        p.set("f", fit.best.get("f").unwrap()).unwrap();
        p.set("alpha0", a).unwrap();
        let m = plan.multipoles(&terms, &p, &[0, 2]).unwrap();
        let mut c = 0.0;
        for l in 0..2 {
            for (i, &k) in data.k.iter().enumerate() {
                if k <= 0.15 {
                    c += ((data.values[l][i] - m[l][i].value) / data.sigma[l][i]).powi(2);
                }
            }
        }
        c + prior.shape.minus_two_log(a)
    };
    let (lo, hi, n) = (
        fit.best.get("alpha0").unwrap() - 8.0 * fit.marginalised_errors[0],
        fit.best.get("alpha0").unwrap() + 8.0 * fit.marginalised_errors[0],
        400,
    );
    let h = (hi - lo) / n as f64;
    let c0 = chi2_at(fit.best.get("alpha0").unwrap());
    let integral: f64 = (0..=n)
        .map(|j| {
            let w = if j == 0 || j == n {
                1.0
            } else if j % 2 == 1 {
                4.0
            } else {
                2.0
            };
            w * (-0.5 * (chi2_at(lo + h * j as f64) - c0)).exp()
        })
        .sum::<f64>()
        * h
        / 3.0;
    let direct = c0 - 2.0 * integral.ln();
    let analytic = fit.minus_two_log_l - (2.0 * std::f64::consts::PI).ln();
    assert!(
        (direct - analytic).abs() < 1e-6 * analytic.abs().max(1.0),
        "{direct} vs {analytic}"
    );
}

#[test]
fn bad_requests_are_named() {
    let (plan, terms, truth, data) = setup();
    let base = GalaxyFitRequest {
        start: truth,
        ap: None,
        free: vec!["f".into()],
        marginalise: vec![],
        priors: vec![],
        ells: vec![0],
        k_min: 0.0,
        k_max: 0.2,
        ell_ranges: vec![],
        n_mocks: None,
        basis: FitBasis::Velocileptors,
    };
    let err = |r: GalaxyFitRequest| {
        fit_galaxy(&plan, &terms, &data, &r)
            .unwrap_err()
            .to_string()
    };
    let mut r = base.clone();
    r.free = vec!["fsigma8".into()];
    assert!(err(r).contains("fsigma8"));
    let mut r = base.clone();
    r.marginalise = vec!["b2".into()];
    assert!(err(r).contains("b2"));
    let mut r = base.clone();
    r.priors = vec![Prior::gaussian("b1", 2.0, 0.0)];
    assert!(err(r).contains("sigma"));
    let mut r = base.clone();
    r.marginalise = vec!["f".into()];
    assert!(err(r).contains("linearly"));
    let mut r = base;
    r.ells = vec![6];
    assert!(err(r).contains("ell"));
}

/// A plan on `nk` k in [0.02, 0.2] with IR and an AP range [0.8, 1.25], its terms of the gm2012
/// spectrum at z = 0.5, and noise-free P0, P2, P4 of `truth` at the distortion `d` with errors
/// `relative` × P0.
pub(super) fn ap_setup(
    nk: usize,
    truth: &EptParams,
    d: crate::rsd::ap::Distortion,
    relative: f64,
) -> (EptPlan, EptTerms, MultipoleData) {
    let k = LogGrid::new(0.02, 0.2, nk).unwrap().points();
    let settings = EptSettings {
        ir: true,
        ap: Some(crate::rsd::ap::Distortion::new(1.0, 1.0).unwrap()),
        ap_range: Some((0.8, 1.25)),
        loop_range: None,
    };
    let plan = EptPlan::new(&k, settings, &Precision::fast()).unwrap();
    let terms = plan.terms(&LinearSpectrum::gm2012(0.5).unwrap()).unwrap();
    let m = plan
        .multipole_values_at(&terms, truth, &[0, 2, 4], Some(d))
        .unwrap();
    let sigma: Vec<Vec<f64>> = (0..3)
        .map(|_| m[0].iter().map(|p| relative * p).collect())
        .collect();
    let data = MultipoleData::from_arrays(k, &[0, 2, 4], m, sigma, "model").unwrap();
    (plan, terms, data)
}

/// Free α∥, α⊥ on a plan built for an AP range: the injected distortion is recovered.
#[test]
fn recovers_the_distortion() {
    let truth = crate::rsd::ap::Distortion::new(1.04, 0.97).unwrap();
    let mut params = EptParams::new(2.0, 0.75);
    params.set("sn", 900.0).unwrap();
    let (plan, terms, data) = ap_setup(24, &params, truth, 0.005);
    let request = GalaxyFitRequest {
        start: EptParams::new(1.9, 0.7),
        ap: Some(crate::rsd::ap::Distortion::new(1.0, 1.0).unwrap()),
        free: ["f", "b1", "apar", "aperp"].map(String::from).to_vec(),
        marginalise: vec!["sn".into()],
        priors: vec![],
        ells: vec![0, 2, 4],
        k_min: 0.0,
        k_max: 0.2,
        ell_ranges: vec![],
        n_mocks: None,
        basis: FitBasis::Velocileptors,
    };
    let fit = fit_galaxy(&plan, &terms, &data, &request).unwrap();
    let ap = fit.ap.unwrap();
    for (got, want, err) in [
        (ap.apar, 1.04, fit.errors[2]),
        (ap.aperp, 0.97, fit.errors[3]),
        (fit.best.get("f").unwrap(), 0.75, fit.errors[0]),
    ] {
        assert!((got - want).abs() < 0.05 * err, "{got} vs {want} ± {err}");
    }
    // Free AP without a distortion to start from is refused.
    let mut bad = request;
    bad.ap = None;
    assert!(fit_galaxy(&plan, &terms, &data, &bad)
        .unwrap_err()
        .to_string()
        .contains("apar"));
}

/// The Hartlap factor scales χ² by (N − p − 2)/(N − 1); too few mocks are refused.
#[test]
fn hartlap_factor_scales_chi2() {
    let (plan, terms, truth, data) = setup();
    let mut start = truth;
    start.set("b1", 2.1).unwrap();
    let base = GalaxyFitRequest {
        start,
        ap: None,
        free: vec!["f".into()],
        marginalise: vec![],
        priors: vec![],
        ells: vec![0],
        k_min: 0.0,
        k_max: 0.2,
        ell_ranges: vec![],
        n_mocks: None,
        basis: FitBasis::Velocileptors,
    };
    let plain = fit_galaxy(&plan, &terms, &data, &base).unwrap();
    let mut with = base.clone();
    with.n_mocks = Some(100);
    let scaled = fit_galaxy(&plan, &terms, &data, &with).unwrap();
    let h = (100 - plain.points - 2) as f64 / 99.0;
    assert!(
        (scaled.chi2 / plain.chi2 - h).abs() < 1e-3 * h,
        "{} {} {h}",
        scaled.chi2,
        plain.chi2
    );
    with.n_mocks = Some(plain.points + 2);
    assert!(fit_galaxy(&plan, &terms, &data, &with)
        .unwrap_err()
        .to_string()
        .contains("mocks"));
}

/// A prior on a parameter that is neither free nor marginalised would be listed and ignored: it is
/// refused, naming the parameter and the free ones; a second prior on one parameter likewise.
#[test]
fn priors_on_fixed_parameters_are_refused() {
    let (plan, terms, truth, data) = setup();
    let request = GalaxyFitRequest {
        start: truth,
        ap: None,
        free: vec!["f".into(), "b1".into()],
        marginalise: vec!["sn".into()],
        priors: vec![Prior::gaussian("b2", 0.0, 1.0)],
        ells: vec![0, 2],
        k_min: 0.0,
        k_max: 0.2,
        ell_ranges: vec![],
        n_mocks: None,
        basis: FitBasis::Velocileptors,
    };
    let e = fit_galaxy(&plan, &terms, &data, &request)
        .unwrap_err()
        .to_string();
    assert_eq!(
        e,
        "the prior on b2: b2 is fixed, and a prior acts only on a free or marginalised parameter \
         (free: f, b1; marginalised: sn)"
    );
    let mut twice = request.clone();
    twice.priors = vec![Prior::gaussian("sn", 0.0, 1e3); 2];
    let e = fit_galaxy(&plan, &terms, &data, &twice).unwrap_err();
    assert_eq!(e.to_string(), "the prior on sn: is given twice");
    let mut ok = request;
    ok.priors[0].name = "b1".into();
    assert!(fit_galaxy(&plan, &terms, &data, &ok).is_ok());
}

/// An observation whose output has as many k as the data but other values is refused (it was taken
/// for the data's grid by its length), and the message reads as one sentence.
#[test]
fn an_observation_on_other_k_of_the_same_length_is_refused() {
    let (_, _, truth, data) = setup();
    let edges = LogGrid::new(0.05, 0.3, data.k.len() + 1).unwrap().points();
    let observation = Observation::new(
        &[0, 2],
        &data.k,
        None,
        Some(crate::survey::observe::Bins::Edges(edges)),
    )
    .unwrap();
    assert_eq!(observation.k_out().len(), data.k.len());
    let settings = EptSettings {
        ir: false,
        ap: None,
        ap_range: None,
        loop_range: None,
    };
    let plan = EptPlan::new(observation.k_model(), settings, &Precision::fast()).unwrap();
    let terms = plan.terms(&LinearSpectrum::gm2012(0.5).unwrap()).unwrap();
    let request = GalaxyFitRequest {
        start: truth,
        ap: None,
        free: vec!["f".into()],
        marginalise: vec![],
        priors: vec![],
        ells: vec![0, 2],
        k_min: 0.0,
        k_max: 0.2,
        ell_ranges: vec![],
        n_mocks: None,
        basis: FitBasis::Velocileptors,
    };
    let e = fit_galaxy_observed(&plan, &terms, &data, &request, Some(&observation))
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("output (24 k in [0.0")
            && e.contains("on the data's (24 k in [0.02, 0.2] h/Mpc"),
        "{e}"
    );
    assert!(!e.contains("  "), "stray spaces: {e:?}");
}

mod physical {
    //! Fits in the DESI physical basis ([`crate::rsd::ept::physical`]).
    use super::*;
    use crate::fit::galaxy::search::{Linear, Search};
    use crate::rsd::ept::physical::PhysicalBasis;

    fn basis() -> PhysicalBasis {
        PhysicalBasis::new(0.62, 3e-4, 0.1, 5.0).unwrap()
    }

    fn request(free: &[&str], marginalise: &[&str], start: EptParams) -> GalaxyFitRequest {
        GalaxyFitRequest {
            start,
            ap: None,
            free: free.iter().map(|s| s.to_string()).collect(),
            marginalise: marginalise.iter().map(|s| s.to_string()).collect(),
            priors: vec![],
            ells: vec![0, 2, 4],
            k_min: 0.0,
            k_max: 0.2,
            ell_ranges: vec![],
            n_mocks: None,
            basis: FitBasis::Velocileptors,
        }
    }

    /// Free b1, b2, bs, f and a profiled sn are a one-to-one map of b1p, b2p, bsp, f and sn0p: the
    /// same minimum of −2 ln L (without priors and ln det F, a change of variables leaves it), the same
    /// best fit and the same error on f, which both bases share.
    #[test]
    fn the_physical_basis_is_a_change_of_variables() {
        let (plan, terms, truth, data) = setup();
        let mut start = truth;
        for (n, v) in [("f", 0.68), ("b1", 1.9), ("alpha0", 0.0), ("alpha2", 0.0)] {
            start.set(n, v).unwrap();
        }
        let search = Search {
            starts: 3,
            linear: Linear::Profiled,
            ..Search::default()
        };
        let vel = request(&["f", "b1", "b2", "bs"], &["sn"], start);
        let mut phys = request(&["f", "b1p", "b2p", "bsp"], &["sn0p"], start);
        phys.basis = FitBasis::Desi(basis());
        let a = fit_galaxy_search(&plan, &terms, &data, &vel, None, &search).unwrap();
        let b = fit_galaxy_search(&plan, &terms, &data, &phys, None, &search).unwrap();
        assert!(
            (a.minus_two_log_l - b.minus_two_log_l).abs() < 1e-6 * a.minus_two_log_l.max(1.0),
            "{} vs {}",
            a.minus_two_log_l,
            b.minus_two_log_l
        );
        for (j, name) in ["f", "b1", "b2", "bs"].iter().enumerate() {
            let (x, y) = (a.best.get(name).unwrap(), b.best.get(name).unwrap());
            assert!(
                (x - y).abs() < 0.01 * a.errors[j],
                "{name}: {x} vs {y} (σ {})",
                a.errors[j]
            );
        }
        let (x, y) = (a.best.get("sn").unwrap(), b.best.get("sn").unwrap());
        assert!(
            (x - y).abs() < 0.01 * a.marginalised_errors[0],
            "sn: {x} vs {y}"
        );
        assert!(
            (a.errors[0] / b.errors[0] - 1.0).abs() < 0.01,
            "{:?} vs {:?}",
            a.errors,
            b.errors
        );
        let physical = b.in_basis.expect("the physical values are reported");
        assert!((physical[0] - b.best.get("b1").unwrap() * 0.62).abs() < 1e-12);
        assert!((physical[8] - b.best.get("sn").unwrap() * 3e-4).abs() < 1e-12);
        assert!(a.in_basis.is_none());
    }

    /// The CLASS-PT bias basis is a linear change of variables of b2, bs, b3: the same minimum, the
    /// same best fit, and the reported bG2, bGamma3 map back to it ([`crate::bias`]).
    #[test]
    fn the_class_pt_basis_is_a_change_of_variables() {
        let (plan, terms, truth, data) = setup();
        let mut start = truth;
        for (n, v) in [("f", 0.68), ("b1", 1.9), ("alpha0", 0.0), ("alpha2", 0.0)] {
            start.set(n, v).unwrap();
        }
        let search = Search {
            starts: 3,
            linear: Linear::Profiled,
            ..Search::default()
        };
        let vel = request(&["f", "b1", "b2", "bs", "b3"], &["sn"], start);
        let mut cpt = request(&["f", "b1", "b2", "bG2", "bGamma3"], &["sn"], start);
        cpt.basis = FitBasis::ClassPt;
        let a = fit_galaxy_search(&plan, &terms, &data, &vel, None, &search).unwrap();
        let b = fit_galaxy_search(&plan, &terms, &data, &cpt, None, &search).unwrap();
        assert!(a.exact_gradient && b.exact_gradient);
        assert!(
            (a.minus_two_log_l - b.minus_two_log_l).abs() < 1e-6 * a.minus_two_log_l.max(1.0),
            "{} vs {}",
            a.minus_two_log_l,
            b.minus_two_log_l
        );
        for (j, name) in ["f", "b1", "b2", "bs", "b3"].iter().enumerate() {
            let (x, y) = (a.best.get(name).unwrap(), b.best.get(name).unwrap());
            assert!((x - y).abs() < 0.02 * a.errors[j], "{name}: {x} vs {y}");
        }
        let v = b.in_basis.expect("the basis's values are reported");
        let mapped = crate::bias::BiasParams::from_convention(
            crate::bias::BiasConvention::ClassPt,
            [v[0], v[1], v[2], v[3]],
        );
        for (i, name) in ["b1", "b2", "bs", "b3"].iter().enumerate() {
            let want = b.best.get(name).unwrap();
            assert!(
                (mapped.values()[i] - want).abs() < 1e-12 * want.abs().max(1.0),
                "{name}"
            );
        }
        // the error of f, a parameter both bases share, is the same
        assert!(
            (a.errors[0] / b.errors[0] - 1.0).abs() < 0.01,
            "{:?} vs {:?}",
            a.errors,
            b.errors
        );
        let e = fit_galaxy_search(
            &plan,
            &terms,
            &data,
            &GalaxyFitRequest {
                free: vec!["bs".into()],
                ..cpt.clone()
            },
            None,
            &search,
        )
        .unwrap_err()
        .to_string();
        assert!(e.contains("bG2 and bGamma3"), "{e}");
    }

    /// Data made in the physical basis (counterterms α₀p, α₂p, α₄p and sn0p, hence α₆ = f²α₄p) are
    /// recovered by a fit in it: exactly (0.01σ) with the linear ones profiled and no priors, and
    /// within 0.3σ with them marginalised under the DESI DR1 priors (centred on 0, not on the truth,
    /// and with ln det F, which depends on b1p and f in this basis: the projection effects of the
    /// DESI analyses).
    #[test]
    fn recovers_the_truth_in_the_physical_basis_with_desi_priors() {
        let (plan, terms, _, _) = setup();
        let truth = [
            1.24, -0.1, 0.05, 0.0, 2.0, -3.0, 1.0, 0.0, 0.3, 0.0, 0.0, 0.75,
        ];
        let model = basis().to_ept(&truth);
        let m = plan.multipoles(&terms, &model, &[0, 2, 4]).unwrap();
        let values: Vec<Vec<f64>> = m
            .iter()
            .map(|l| l.iter().map(|e| e.value).collect())
            .collect();
        let sigma: Vec<Vec<f64>> = (0..3)
            .map(|_| values[0].iter().map(|p| 0.01 * p).collect())
            .collect();
        let data =
            MultipoleData::from_arrays(plan.k().to_vec(), &[0, 2, 4], values, sigma, "model")
                .unwrap();
        let mut start = model;
        start.set("f", 0.65).unwrap();
        start.set("b1", 1.8).unwrap();
        let free = ["f", "b1p", "b2p", "bsp"];
        let marg = ["alpha0p", "alpha2p", "alpha4p", "sn0p"];
        let mut r = request(&free, &marg, start);
        r.basis = FitBasis::Desi(basis());
        r.priors = desi_priors()
            .into_iter()
            .filter(|p| free.contains(&p.name.as_str()) || marg.contains(&p.name.as_str()))
            .collect();
        let profiled = Search {
            starts: 3,
            linear: Linear::Profiled,
            ..Search::default()
        };
        let exact = GalaxyFitRequest {
            priors: vec![],
            ..r.clone()
        };
        // χ² of the marginalised fit: the priors and ln det F move its maximum off χ² = 0 (0.018 here).
        for (request, search, tolerance, chi2) in [
            (&exact, &profiled, 0.01, 1e-4),
            (&r, &Search::default(), 0.3, 0.1),
        ] {
            let fit = fit_galaxy_search(&plan, &terms, &data, request, None, search).unwrap();
            let got = fit.in_basis.unwrap();
            for (j, &slot) in [11, 0, 1, 2].iter().enumerate() {
                let sigma = fit.errors[j];
                assert!(
                    (got[slot] - truth[slot]).abs() < tolerance * sigma,
                    "{}: {} vs {} (σ {sigma})",
                    free[j],
                    got[slot],
                    truth[slot]
                );
            }
            assert!(fit.chi2 < chi2, "{}", fit.chi2);
        }
    }

    /// The profile of b1p in the physical basis runs through the best fit (its lowest point at the
    /// fitted b1p, Δ(−2 ln L) = 0 there) and reports the physical values at each point.
    #[test]
    fn profiles_in_the_physical_basis_start_from_its_best_fit() {
        let (plan, terms, truth, data) = setup();
        let mut r = request(&["f", "b1p", "b2p"], &["sn0p"], truth);
        r.basis = FitBasis::Desi(basis());
        let search = Search {
            starts: 2,
            profile_check: false,
            ..Search::default()
        };
        let grid = ProfileGrid {
            points: 5,
            span: 2.0,
        };
        let p = profile_galaxy(&plan, &terms, &data, &r, None, &search, "b1p", &grid).unwrap();
        let best = p.fit.in_basis.unwrap()[0];
        let low = p
            .points
            .iter()
            .min_by(|a, b| a.minus_two_log_l.total_cmp(&b.minus_two_log_l))
            .unwrap();
        assert!(
            (low.value - best).abs() < 1e-9 * best,
            "{} vs {best}",
            low.value
        );
        assert!((low.minus_two_log_l - p.fit.minus_two_log_l).abs() < 1e-6);
        for point in &p.points {
            let v = point.in_basis.unwrap();
            assert!((v[0] - point.value).abs() < 1e-12 * point.value);
            assert!((point.best.get("b1").unwrap() - point.value / 0.62).abs() < 1e-12);
        }
    }

    /// Names of the other basis, and alpha6p (not a parameter of the physical basis), are refused by
    /// name.
    #[test]
    fn names_of_the_other_basis_are_refused_with_a_hint() {
        let (plan, terms, truth, data) = setup();
        let mut r = request(&["f", "b1"], &[], truth);
        r.basis = FitBasis::Desi(basis());
        let e = fit_galaxy(&plan, &terms, &data, &r)
            .unwrap_err()
            .to_string();
        assert!(e.contains("velocileptors name"), "{e}");
        let r = request(&["f", "b1p"], &[], truth);
        let e = fit_galaxy(&plan, &terms, &data, &r)
            .unwrap_err()
            .to_string();
        assert!(e.contains("DESI physical"), "{e}");
        let mut r = request(&["f", "alpha6p"], &[], truth);
        r.basis = FitBasis::Desi(basis());
        let e = fit_galaxy(&plan, &terms, &data, &r)
            .unwrap_err()
            .to_string();
        assert!(e.contains("alpha4p"), "{e}");
        let mut r = request(&["f"], &["alpha0"], truth);
        r.basis = FitBasis::Desi(basis());
        let e = fit_galaxy(&plan, &terms, &data, &r)
            .unwrap_err()
            .to_string();
        assert!(e.contains("alpha0p"), "{e}");
    }
}
