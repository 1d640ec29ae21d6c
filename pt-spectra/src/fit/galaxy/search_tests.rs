//! The search of a galaxy fit on real data (BOSS DR12 CMASS NGC P0, P2 and their MD-Patchy
//! covariance, `examples/data/boss_dr12_cmass_ngc`, no window), where the Nelder–Mead search that
//! came before stopped in local minima 1.0–3.4 above the global one and gave errors on f that grew
//! with k_max (issue 48); and its profiles, priors and derived parameters on model data.

use super::*;
use crate::fit::bounded::AGREEMENT;
use crate::linear::LogGrid;
use crate::precision::Precision;
use crate::rsd::ept::EptSettings;
use crate::setup::{prepare, LinearSource, Request};

/// Rows of the whitespace table at `path` (lines starting with `#` skipped).
fn rows(path: &std::path::Path) -> Vec<Vec<f64>> {
    std::fs::read_to_string(path)
        .unwrap()
        .lines()
        .filter(|l| !l.trim().is_empty() && !l.starts_with('#'))
        .map(|l| l.split_whitespace().map(|v| v.parse().unwrap()).collect())
        .collect()
}

/// BOSS DR12 CMASS NGC P0, P2 (58 k each) with the covariance block of ℓ = 0, 2, the ept plan on
/// its k (IR resummed, fast precision), the gm2012 template at z = 0.57, and the request of
/// `examples/boss_cmass_fit.py` without window and AP (free f, b1, b2, bs; α0, α2, sn, sn2
/// marginalised; its priors; 2048 mocks).
fn boss() -> (EptPlan, EptTerms, MultipoleData, GalaxyFitRequest) {
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../examples/data/boss_dr12_cmass_ngc");
    let d = rows(&dir.join("ps1D_highzNGC.dat"));
    let c = rows(&dir.join("Cov_highzNGC.dat"));
    let n = 58;
    let k: Vec<f64> = d[..n].iter().map(|r| r[0]).collect();
    let values: Vec<Vec<f64>> = (0..2)
        .map(|l| d[l * n..(l + 1) * n].iter().map(|r| r[1]).collect())
        .collect();
    let sigma: Vec<Vec<f64>> = (0..2)
        .map(|l| (0..n).map(|i| c[l * n + i][l * n + i].sqrt()).collect())
        .collect();
    let cov: Vec<Vec<f64>> = (0..2 * n)
        .map(|i| (0..2 * n).map(|j| 0.5 * (c[i][j] + c[j][i])).collect())
        .collect();
    let data = MultipoleData::from_arrays(k.clone(), &[0, 2], values, sigma, "BOSS NGC")
        .unwrap()
        .with_covariance(cov)
        .unwrap();
    let plan = EptPlan::new(
        &k,
        EptSettings {
            ir: true,
            ap: None,
            ap_range: None,
            loop_range: None,
        },
        &Precision::fast(),
    )
    .unwrap();
    let prepared = prepare(Request {
        source: LinearSource::Embedded,
        cosmology: None,
        z: 0.57,
    })
    .unwrap();
    let terms = plan.terms(prepared.tracer_spectrum()).unwrap();
    let priors = [
        ("b2", 5.0),
        ("bs", 5.0),
        ("alpha0", 100.0),
        ("alpha2", 100.0),
        ("sn", 3000.0),
        ("sn2", 1e5),
    ]
    .map(|(name, sigma)| Prior::gaussian(name, 0.0, sigma))
    .to_vec();
    let request = GalaxyFitRequest {
        start: EptParams::new(2.0, prepared.growth_rate),
        ap: None,
        free: ["f", "b1", "b2", "bs"].map(String::from).to_vec(),
        marginalise: ["alpha0", "alpha2", "sn", "sn2"].map(String::from).to_vec(),
        priors,
        ells: vec![0, 2],
        k_min: 0.01,
        k_max: 0.18,
        ell_ranges: vec![],
        n_mocks: Some(2048),
        basis: FitBasis::Velocileptors,
    };
    (plan, terms, data, request)
}

/// The reported minimum is the lowest of 8 single-start minimisations from spread starts to
/// Δχ² < 0.01, some of which stop in a local minimum more than 1 above it; the error given follows the 10% rule between the Hessian and the profile.
#[test]
fn boss_minimum_is_the_lowest_of_eight_starts() {
    let (plan, terms, data, request) = boss();
    let fit = fit_galaxy(&plan, &terms, &data, &request).unwrap();
    assert_eq!(fit.starts, 8);
    assert!(fit.agree >= 1 && fit.agree <= 8);
    let one = Search {
        starts: 1,
        profile_check: false,
        ..Search::default()
    };
    let mut single = Vec::new();
    for (f, b1, b2, bs) in [
        (0.6, 2.0, 1.0, 0.0),
        (0.9, 1.8, 0.0, 3.0),
        (0.5, 2.2, 2.0, 2.0),
        (0.75, 2.0, -3.0, -2.0),
        (0.7, 1.5, 0.0, 0.0),
        (0.8, 2.5, -1.0, 1.0),
        (0.65, 2.1, 3.0, -3.0),
        (0.85, 1.9, -2.0, 2.5),
    ] {
        let mut r = request.clone();
        for (name, v) in [("f", f), ("b1", b1), ("b2", b2), ("bs", bs)] {
            r.start.set(name, v).unwrap();
        }
        let m = fit_galaxy_search(&plan, &terms, &data, &r, None, &one).unwrap();
        single.push(m.minus_two_log_l);
    }
    let lowest = single.iter().copied().fold(f64::INFINITY, f64::min);
    assert!(
        fit.minus_two_log_l < lowest + AGREEMENT,
        "{} vs the single starts {single:?}",
        fit.minus_two_log_l
    );
    // Some starts end in a local minimum (measured 24.54 against 22.16: with the exact gradient the
    // 2nd, 4th and 7th, with central differences the 1st): one start alone is not enough.
    assert!(
        single.iter().any(|&v| v > fit.minus_two_log_l + 1.0),
        "{single:?}"
    );
    for j in 0..request.free.len() {
        let (lo, hi) = fit.intervals[j];
        let half = 0.5 * (hi - lo);
        assert!(half.is_finite() && half > 0.0, "{:?}", fit.intervals);
        if fit.from_profile[j] {
            assert_eq!(fit.errors[j], half);
            assert!((half / fit.hessian_errors[j] - 1.0).abs() > search::PROFILE_AGREEMENT);
        } else {
            assert_eq!(fit.errors[j], fit.hessian_errors[j]);
            assert!((half / fit.hessian_errors[j] - 1.0).abs() <= search::PROFILE_AGREEMENT);
        }
        let x = fit.best.get(&request.free[j]).unwrap();
        assert!(lo < x && x < hi, "{lo} {x} {hi}");
    }
}

/// Nested data (the same multipoles to a larger k_max): the error on f never grows by more than the
/// minimiser's noise (1%); with the old search it grew from 0.081 to 0.095 between k_max = 0.16 and
/// 0.18. The Δ = 1 interval of f narrows too.
#[test]
fn boss_errors_do_not_grow_on_nested_data() {
    let (plan, terms, data, request) = boss();
    let mut previous: Option<(f64, f64)> = None;
    for k_max in [0.12, 0.14, 0.16, 0.18, 0.2] {
        let mut r = request.clone();
        r.k_max = k_max;
        let fit = fit_galaxy(&plan, &terms, &data, &r).unwrap();
        let (lo, hi) = fit.intervals[0];
        let now = (fit.errors[0], hi - lo);
        if let Some((error, width)) = previous {
            assert!(
                now.0 <= 1.01 * error,
                "k_max {k_max}: σ(f) {} after {error}",
                now.0
            );
            assert!(
                now.1 <= 1.01 * width,
                "k_max {k_max}: width {} after {width}",
                now.1
            );
        }
        previous = Some(now);
    }
}

/// Model data (no noise, 1% errors): the likelihood of f, b1 is close to Gaussian, so the Hessian's
/// σ is the profile's half-width to 10% and is the error given; the profile's grid passes through the
/// minimum, never below it, and crosses Δ = 1 where the fit's interval says (to the grid's linear
/// interpolation) and Δ = 4 at about twice the distance.
#[test]
fn profile_of_f_agrees_with_the_fit() {
    let (plan, terms, truth, data) = super::tests::setup();
    let mut start = truth;
    start.set("f", 0.7).unwrap();
    start.set("b1", 1.9).unwrap();
    let request = GalaxyFitRequest {
        start,
        ap: None,
        free: vec!["f".into(), "b1".into()],
        marginalise: vec!["alpha0".into(), "alpha2".into(), "sn".into()],
        priors: vec![],
        ells: vec![0, 2],
        k_min: 0.0,
        k_max: 0.15,
        ell_ranges: vec![],
        n_mocks: None,
        basis: FitBasis::Velocileptors,
    };
    let grid = ProfileGrid {
        points: 9,
        span: 2.0,
    };
    let profile = profile_galaxy(
        &plan,
        &terms,
        &data,
        &request,
        None,
        &Search::default(),
        "f",
        &grid,
    )
    .unwrap();
    let fit = &profile.fit;
    assert_eq!(fit.from_profile, vec![false, false]);
    assert_eq!(fit.errors, fit.hessian_errors);
    let delta: Vec<f64> = profile
        .points
        .iter()
        .map(|p| p.minus_two_log_l - fit.minus_two_log_l)
        .collect();
    assert!(delta[4].abs() < 1e-3, "{delta:?}");
    assert!(delta.iter().all(|&d| d > -1e-3), "{delta:?}");
    // ±1σ at points 2 and 6 (span 2 over 9 points), ±2σ at the ends.
    for j in [2, 6] {
        assert!((delta[j] - 1.0).abs() < 0.2, "{delta:?}");
    }
    for j in [0, 8] {
        assert!((delta[j] / 4.0 - 1.0).abs() < 0.2, "{delta:?}");
    }
    // Where the grid's Δ crosses 1, linearly interpolated, against the fit's interval.
    let (lo, hi) = fit.intervals[0];
    let cross = |a: usize, b: usize| {
        let (x0, x1) = (profile.points[a].value, profile.points[b].value);
        x0 + (1.0 - delta[a]) / (delta[b] - delta[a]) * (x1 - x0)
    };
    let width = hi - lo;
    assert!(
        (cross(2, 3) - lo).abs() < 0.05 * width,
        "{} {lo}",
        cross(2, 3)
    );
    assert!(
        (cross(6, 5) - hi).abs() < 0.05 * width,
        "{} {hi}",
        cross(6, 5)
    );
    // Every point's other parameters were re-minimised: b1 moves along the f–b1 degeneracy.
    let b1: Vec<f64> = profile.points.iter().map(|p| p.best.values[0]).collect();
    assert!(b1.windows(2).all(|w| w[0] != w[1]), "{b1:?}");
    // A fixed or unknown parameter has no profile.
    for name in ["b2", "nonsense"] {
        assert!(profile_galaxy(
            &plan,
            &terms,
            &data,
            &request,
            None,
            &Search::default(),
            name,
            &grid
        )
        .is_err());
    }
}

/// A flat prior bounds the fit (truth f = 0.75 outside [0.5, 0.7]: the best f is the bound and its
/// interval is open there); a log-normal prior adds its −2 ln p to −2 ln L.
#[test]
fn flat_and_log_normal_priors() {
    let (plan, terms, truth, data) = super::tests::setup();
    let request = GalaxyFitRequest {
        start: truth,
        ap: None,
        free: vec!["f".into(), "b1".into()],
        marginalise: vec![],
        priors: vec![Prior::parse("f:flat,0.5,0.7").unwrap()],
        ells: vec![0, 2],
        k_min: 0.0,
        k_max: 0.15,
        ell_ranges: vec![],
        n_mocks: None,
        basis: FitBasis::Velocileptors,
    };
    let fit = fit_galaxy(&plan, &terms, &data, &request).unwrap();
    assert_eq!(fit.best.get("f").unwrap(), 0.7);
    assert!(fit.intervals[0].1.is_nan(), "{:?}", fit.intervals);
    // Log-normal on b1 centred on the truth: the fit stays at the truth (χ² = 0) and −2 ln L is the
    // prior's value there, ((ln 2 − ln 2)/σ)² + 2 ln 2.
    let mut ln = request;
    ln.priors = vec![Prior::parse(&format!("b1:lognormal,{},0.1", 2f64.ln())).unwrap()];
    let fit = fit_galaxy(&plan, &terms, &data, &ln).unwrap();
    assert!(fit.chi2 < 1e-3, "{}", fit.chi2);
    // The prior pulls b1 below 2 (the mode of the log-normal density is e^(μ − σ²)); χ² pulls back.
    let want = 2.0 * 2f64.ln();
    assert!(
        fit.minus_two_log_l <= want + 1e-9 && fit.minus_two_log_l > want - 0.05,
        "{} {want}",
        fit.minus_two_log_l
    );
    // A flat prior on a marginalised parameter is refused (the marginalisation is Gaussian).
    let mut bad = ln;
    bad.marginalise = vec!["sn".into()];
    bad.priors = vec![Prior::parse("sn:flat,0,1000").unwrap()];
    let e = fit_galaxy(&plan, &terms, &data, &bad)
        .unwrap_err()
        .to_string();
    assert!(e.contains("sn") && e.contains("Gaussian"), "{e}");
}

/// The derived parameters from their definitions: fσ8 = f σ8(z) with error σ8 σ(f); α_iso, α_AP
/// from the fitted α's; D_M/D_H from the template's distances (α⁰ = 1); D_V/r_d with Aubourg's r_d.
#[test]
fn derived_parameters_from_their_definitions() {
    let k = LogGrid::new(0.02, 0.2, 24).unwrap().points();
    let settings = EptSettings {
        ir: false,
        ap: Some(crate::rsd::ap::Distortion::new(1.0, 1.0).unwrap()),
        ap_range: Some((0.8, 1.25)),
        loop_range: None,
    };
    let plan = EptPlan::new(&k, settings, &Precision::fast()).unwrap();
    let spectrum = crate::linear::LinearSpectrum::gm2012(0.5).unwrap();
    let terms = plan.terms(&spectrum).unwrap();
    let truth = crate::rsd::ap::Distortion::new(1.03, 0.98).unwrap();
    let params = EptParams::new(2.0, 0.75);
    let m = plan
        .multipole_values_at(&terms, &params, &[0, 2], Some(truth))
        .unwrap();
    let sigma: Vec<Vec<f64>> = (0..2)
        .map(|_| m[0].iter().map(|p| 0.01 * p).collect())
        .collect();
    let data = MultipoleData::from_arrays(k, &[0, 2], m, sigma, "model").unwrap();
    let request = GalaxyFitRequest {
        start: EptParams::new(1.9, 0.7),
        ap: Some(crate::rsd::ap::Distortion::new(1.0, 1.0).unwrap()),
        free: ["f", "b1", "apar", "aperp"].map(String::from).to_vec(),
        marginalise: vec![],
        priors: vec![],
        ells: vec![0, 2],
        k_min: 0.0,
        k_max: 0.2,
        ell_ranges: vec![],
        n_mocks: None,
        basis: FitBasis::Velocileptors,
    };
    let search = Search {
        starts: 2,
        ..Search::default()
    };
    let fit = fit_galaxy_search(&plan, &terms, &data, &request, None, &search).unwrap();
    let c = crate::cosmology::Cosmology::gm2012();
    let template = Template {
        sigma8_z: spectrum.sigma8(),
        z: 0.5,
        cosmology: Some(c),
    };
    let d = derived(&fit, &request, &template);
    let get = |n: &str| d.iter().find(|x| x.name == n).unwrap();
    let (f, a, p) = (
        fit.best.get("f").unwrap(),
        fit.ap.unwrap().apar,
        fit.ap.unwrap().aperp,
    );
    assert!(
        (a - 1.03).abs() < 1e-3 && (p - 0.98).abs() < 1e-3,
        "{a} {p}"
    );
    assert_eq!(get("fsigma8").value, f * spectrum.sigma8());
    assert!((get("fsigma8").error - spectrum.sigma8() * fit.errors[0]).abs() < 1e-15);
    assert!((get("alpha_iso").value - (a * p * p).cbrt()).abs() < 1e-14);
    assert!((get("alpha_ap").value - a / p).abs() < 1e-15);
    let d_h = 2997.92458 / (c.hubble(0.5) / 100.0);
    let d_m = c.transverse_comoving_distance(0.5);
    let ratio = d_m * p / (d_h * a);
    assert!((get("DM_over_DH").value / ratio - 1.0).abs() < 1e-12);
    let d_v = (0.5 * d_m * d_m * d_h).cbrt() * (a * p * p).cbrt() / sound_horizon(&c);
    assert!((get("DV_over_rd").value / d_v - 1.0).abs() < 1e-12);
    // α_AP's error from the covariance of α∥, α⊥ written out.
    let cov = fit.covariance.as_ref().unwrap();
    let e = &fit.errors;
    let rho = cov[2][3] / (cov[2][2] * cov[3][3]).sqrt();
    let (ga, gp) = (1.0 / p, -a / (p * p));
    let want =
        (ga * ga * e[2] * e[2] + gp * gp * e[3] * e[3] + 2.0 * ga * gp * rho * e[2] * e[3]).sqrt();
    assert!((get("alpha_ap").error / want - 1.0).abs() < 1e-12);
}
