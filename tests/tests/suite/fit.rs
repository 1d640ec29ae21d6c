//! End-to-end fits: mock multipoles made by an independent route (closed-form linear Kaiser with a known
//! f plus Gaussian noise) are fitted back, and a mock from a model the fit does not use shows a bias.

use pt_spectra::fit::{
    delta_chi2, fit, FitSettings, MultipoleData, MultipoleModel, Parameter, Params,
};
use pt_spectra::linear::{LinearSpectrum, LogGrid};
use pt_spectra::loops::TnsPlan;
use pt_spectra::precision::Precision;
use pt_spectra::real::{real_space, RealModel};
use pt_spectra::rsd::{Fog, RsdModel};
use pt_spectra::store::TableStore;
use rand::{Rng, SeedableRng};

const F_TRUE: f64 = 0.483135;

/// Standard normal deviates (Box–Muller).
fn normal(rng: &mut rand_chacha::ChaCha8Rng) -> f64 {
    let (u, v): (f64, f64) = (rng.gen::<f64>().max(1e-300), rng.gen());
    (-2.0 * u.ln()).sqrt() * (2.0 * std::f64::consts::PI * v).cos()
}

/// Linear Kaiser multipoles from the closed forms (science.md), 1% errors of P0 on every ℓ, noise.
fn kaiser_mock(k: &[f64], b: f64, seed: u64) -> MultipoleData {
    let p = LinearSpectrum::gm2012(0.0).unwrap();
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed);
    let f = F_TRUE;
    let exact: Vec<[f64; 3]> = k
        .iter()
        .map(|&k| {
            let pl = p.eval(k);
            [
                pl * (b * b + 2.0 * b * f / 3.0 + f * f / 5.0),
                pl * (4.0 * b * f / 3.0 + 4.0 * f * f / 7.0),
                pl * 8.0 * f * f / 35.0,
            ]
        })
        .collect();
    let sigma: Vec<f64> = exact.iter().map(|e| 0.01 * e[0]).collect();
    let mut text = String::from("# k P0 s0 P2 s2 P4 s4\n");
    for (i, &ki) in k.iter().enumerate() {
        text += &format!("{ki}");
        for e in exact[i] {
            text += &format!(" {} {}", e + sigma[i] * normal(&mut rng), sigma[i]);
        }
        text.push('\n');
    }
    MultipoleData::parse(&text, "mock", 0, &[(0, 1, 2), (2, 3, 4), (4, 5, 6)]).unwrap()
}

/// Linear Kaiser, no FoG, bias `b`, for the multipoles `ells`.
fn linear_kaiser_model(k: &[f64], b: f64, ells: &[usize]) -> MultipoleModel {
    let p = LinearSpectrum::gm2012(0.0).unwrap();
    let real = real_space(
        RealModel::Linear,
        &p,
        k,
        &Precision::fast(),
        &TableStore::in_memory(),
    )
    .unwrap();
    MultipoleModel::new(
        &real,
        None,
        RsdModel::Kaiser,
        Fog::None,
        1.0,
        vec![b; k.len()],
        ells,
    )
    .unwrap()
}

/// TNS with 1-loop SPT spectra and Lorentzian FoG, bias `b`, for ℓ = 0, 2, 4.
fn tns_model(k: &[f64], b: f64) -> MultipoleModel {
    let p = LinearSpectrum::gm2012(0.0).unwrap();
    let real = real_space(
        RealModel::OneLoopSpt,
        &p,
        k,
        &Precision::fast(),
        &TableStore::in_memory(),
    )
    .unwrap();
    let tns = TnsPlan::new(k, &Precision::fast()).unwrap().evaluate(&p);
    MultipoleModel::new(
        &real,
        Some(&tns),
        RsdModel::Tns,
        Fog::Lorentzian,
        1.0,
        vec![b; k.len()],
        &[0, 2, 4],
    )
    .unwrap()
}

/// TNS terms of another k grid of the same length are refused (they were taken for the spectra's
/// grid by their length, and read at the wrong k).
#[test]
fn tns_terms_of_other_k_are_refused() {
    let k = LogGrid::new(0.01, 0.3, 12).unwrap().points();
    let other = LogGrid::new(0.02, 0.3, 12).unwrap().points();
    let p = LinearSpectrum::gm2012(0.0).unwrap();
    let real = real_space(
        RealModel::OneLoopSpt,
        &p,
        &k,
        &Precision::fast(),
        &TableStore::in_memory(),
    )
    .unwrap();
    let model = |k_tns: &[f64]| {
        let tns = TnsPlan::new(k_tns, &Precision::fast())
            .unwrap()
            .evaluate(&p);
        MultipoleModel::new(
            &real,
            Some(&tns),
            RsdModel::Tns,
            Fog::Lorentzian,
            1.0,
            vec![2.0; k.len()],
            &[0, 2],
        )
    };
    assert!(model(&k).is_ok());
    let e = model(&other).unwrap_err().to_string();
    assert!(
        e.contains("TNS terms and real-space spectra") && e.contains("12 k in [0.02, 0.3"),
        "{e}"
    );
}

#[test]
fn fit_recovers_f_from_an_independent_kaiser_mock() {
    let k = LogGrid::new(0.01, 0.3, 40).unwrap().points();
    let model = linear_kaiser_model(&k, 1.0, &[0, 2, 4]);
    let mut inside = 0;
    for seed in 0..6 {
        let data = kaiser_mock(&k, 1.0, seed);
        let settings = FitSettings {
            free: vec![Parameter::F],
            start: Params {
                f: 0.6,
                sigma0: 0.0,
                amplitude: 1.0,
                cs2: 0.0,
            },
            k_min: 0.0,
        };
        let r = &fit(&model, &data, &settings, &[0.2, 0.3]).unwrap()[1];
        let (_, lo, hi) = r.intervals[0];
        assert!(lo < r.best.f && r.best.f < hi, "{r:?}");
        let sigma = 0.5 * (hi - lo);
        // The fit is right: within 3σ every time, within 1σ about 68% of the time, χ²/dof ≈ 1.
        assert!(
            (r.best.f - F_TRUE).abs() < 3.0 * sigma,
            "seed {seed}: {r:?}"
        );
        assert!(sigma < 0.01, "{sigma}");
        let reduced = r.chi2 / r.dof as f64;
        assert!(
            (0.5..1.7).contains(&reduced),
            "seed {seed}: χ²/dof = {reduced}"
        );
        inside += usize::from((r.best.f - F_TRUE).abs() < sigma);
    }
    assert!(inside >= 2, "{inside} of 6 within 1σ");
}

#[test]
fn two_parameter_errors_lie_on_the_delta_chi2_contour() {
    // f and A_b with b = 2: the profile at the interval ends is χ²_min + 2.3, found by bisection.
    let k = LogGrid::new(0.01, 0.25, 30).unwrap().points();
    let model = linear_kaiser_model(&k, 2.0, &[0, 2, 4]);
    let data = kaiser_mock(&k, 2.0, 42);
    let settings = FitSettings {
        free: vec![Parameter::F, Parameter::Amplitude],
        start: Params {
            f: 0.4,
            sigma0: 0.0,
            amplitude: 1.1,
            cs2: 0.0,
        },
        k_min: 0.0,
    };
    let r = &fit(&model, &data, &settings, &[0.25]).unwrap()[0];
    assert!(
        (r.best.f - F_TRUE).abs() < 3.0 * 0.5 * (r.intervals[0].2 - r.intervals[0].1),
        "{r:?}"
    );
    assert!(
        (r.best.amplitude - 1.0).abs() < 3.0 * 0.5 * (r.intervals[1].2 - r.intervals[1].1),
        "{r:?}"
    );
    // Cross-check one end independently: scan A_b on a fine grid at f = upper end; the minimum over
    // A_b of χ² must be χ²_min + Δχ² there.
    let (_, _, f_hi) = r.intervals[0];
    let chi2 = |f: f64, a: f64| -> f64 {
        let m = model.multipoles(&Params {
            f,
            sigma0: 0.0,
            amplitude: a,
            cs2: 0.0,
        });
        (0..3)
            .map(|j| {
                (0..k.len())
                    .map(|i| ((data.values[j][i] - m[j][i]) / data.sigma[j][i]).powi(2))
                    .sum::<f64>()
            })
            .sum()
    };
    let best_a = (0..4001)
        .map(|i| 0.9 + 0.2 * i as f64 / 4000.0)
        .map(|a| chi2(f_hi, a))
        .fold(f64::INFINITY, f64::min);
    assert!(
        (best_a - r.chi2 - delta_chi2(2)).abs() < 0.02,
        "{best_a} vs {} + 2.3",
        r.chi2
    );
}

#[test]
fn a_wrong_model_shows_a_bias() {
    // Mock: TNS with 1-loop SPT spectra and Lorentzian FoG (σ0 = 4 Mpc/h), fitted with linear Kaiser.
    let k = LogGrid::new(0.01, 0.2, 30).unwrap().points();
    let truth = tns_model(&k, 1.0);
    let m = truth.multipoles(&Params {
        f: F_TRUE,
        sigma0: 4.0,
        amplitude: 1.0,
        cs2: 0.0,
    });
    let mut text = String::new();
    for (i, &ki) in k.iter().enumerate() {
        // 0.2% of P0: errors as small as the paper's 160 simulation boxes.
        let s = 0.002 * m[0][i];
        text += &format!("{ki} {} {s} {} {s} {} {s}\n", m[0][i], m[1][i], m[2][i]);
    }
    let data =
        MultipoleData::parse(&text, "tns mock", 0, &[(0, 1, 2), (2, 3, 4), (4, 5, 6)]).unwrap();
    let settings = FitSettings {
        free: vec![Parameter::F],
        start: Params {
            f: 0.5,
            sigma0: 0.0,
            amplitude: 1.0,
            cs2: 0.0,
        },
        k_min: 0.0,
    };
    // The quadrupole alone, as the paper fits each multipole: FoG damping pulls f low.
    let quadrupole = MultipoleData::parse(&text, "tns mock", 0, &[(2, 3, 4)]).unwrap();
    let kaiser = linear_kaiser_model(&k, 1.0, &[2]);
    let wrong = &fit(&kaiser, &quadrupole, &settings, &[0.2]).unwrap()[0];
    let sigma = 0.5 * (wrong.intervals[0].2 - wrong.intervals[0].1);
    println!("wrong model, quadrupole: {wrong:?}");
    assert!(
        (wrong.best.f - F_TRUE).abs() > 5.0 * sigma,
        "no bias: {wrong:?}"
    );
    assert!(wrong.chi2 / wrong.dof as f64 > 5.0, "{wrong:?}");
    // All three multipoles: χ² rejects the model.
    let joint = &fit(
        &linear_kaiser_model(&k, 1.0, &[0, 2, 4]),
        &data,
        &settings,
        &[0.2],
    )
    .unwrap()[0];
    assert!(joint.chi2 / joint.dof as f64 > 5.0, "{joint:?}");
    // The right model with f and σ0 free recovers both.
    let settings = FitSettings {
        free: vec![Parameter::F, Parameter::Sigma0],
        start: Params {
            f: 0.55,
            sigma0: 3.0,
            amplitude: 1.0,
            cs2: 0.0,
        },
        k_min: 0.0,
    };
    let right = &fit(&truth, &data, &settings, &[0.2]).unwrap()[0];
    assert!((right.best.f - F_TRUE).abs() < 1e-4, "{right:?}");
    assert!((right.best.sigma0 - 4.0).abs() < 1e-2, "{right:?}");
}

#[test]
fn bad_data_are_refused_with_the_line() {
    let cols = [(0, 1, 2)];
    for (text, needle) in [
        ("0.1 100 1\n0.2 90 0\n", "sigma_l"),
        ("0.1 100 1\n0.2 nan 1\n", "P_l"),
        ("0.1 100 1\n0.05 90 1\n", "increasing"),
        ("0.1 100\n", "column 3 was requested"),
    ] {
        let e = MultipoleData::parse(text, "d.dat", 0, &cols)
            .unwrap_err()
            .to_string();
        assert!(e.contains("d.dat:") && e.contains(needle), "{e}");
    }
}

#[test]
fn full_covariance_generalises_the_diagonal_chi2() {
    let k = LogGrid::new(0.01, 0.2, 20).unwrap().points();
    let model = linear_kaiser_model(&k, 1.0, &[0, 2, 4]);
    let data = kaiser_mock(&k, 1.0, 7);
    let settings = FitSettings {
        free: vec![Parameter::F],
        start: Params {
            f: 0.5,
            sigma0: 0.0,
            amplitude: 1.0,
            cs2: 0.0,
        },
        k_min: 0.0,
    };
    let diagonal = &fit(&model, &data, &settings, &[0.2]).unwrap()[0];
    // The same errors as a diagonal covariance: the same fit.
    let sigma: Vec<f64> = data.sigma.iter().flatten().copied().collect();
    let n = sigma.len();
    let diag: Vec<Vec<f64>> = (0..n)
        .map(|i| {
            (0..n)
                .map(|j| if i == j { sigma[i] * sigma[i] } else { 0.0 })
                .collect()
        })
        .collect();
    let same = &fit(
        &model,
        &data.clone().with_covariance(diag).unwrap(),
        &settings,
        &[0.2],
    )
    .unwrap()[0];
    assert!(
        (same.chi2 - diagonal.chi2).abs() < 1e-9 * diagonal.chi2,
        "{same:?} {diagonal:?}"
    );
    assert!((same.best.f - diagonal.best.f).abs() < 1e-9);
    // Fully correlated errors between P0 and P2 at each k (ρ = 0.9) change χ² and the interval.
    let mut corr = vec![vec![0.0; n]; n];
    let nk = k.len();
    for i in 0..n {
        corr[i][i] = sigma[i] * sigma[i];
    }
    for i in 0..nk {
        let (a, b) = (i, nk + i);
        corr[a][b] = 0.9 * sigma[a] * sigma[b];
        corr[b][a] = corr[a][b];
    }
    let correlated = &fit(
        &model,
        &data.clone().with_covariance(corr).unwrap(),
        &settings,
        &[0.2],
    )
    .unwrap()[0];
    assert!(
        (correlated.chi2 - diagonal.chi2).abs() > 1e-3 * diagonal.chi2,
        "{correlated:?}"
    );
    let width = |r: &pt_spectra::fit::FitResult| r.intervals[0].2 - r.intervals[0].1;
    assert!(
        (width(correlated) / width(diagonal) - 1.0).abs() > 0.01,
        "{correlated:?} {diagonal:?}"
    );
    // An asymmetric or wrongly sized matrix is refused.
    assert!(data.clone().with_covariance(vec![vec![1.0; 3]; 3]).is_err());
}

#[test]
fn three_free_parameters_are_recovered_with_bracketing_intervals() {
    // Noiseless TNS + 1L-SPT + Lorentzian mock with b = 1.5: f, σ0 and A_b free (Δχ² = 3.53).
    let k = LogGrid::new(0.02, 0.2, 20).unwrap().points();
    let model = tns_model(&k, 1.5);
    let truth = Params {
        f: F_TRUE,
        sigma0: 4.0,
        amplitude: 1.0,
        cs2: 0.0,
    };
    let m = model.multipoles(&truth);
    let mut text = String::new();
    for (i, &ki) in k.iter().enumerate() {
        let s = 0.005 * m[0][i];
        text += &format!("{ki} {} {s} {} {s} {} {s}\n", m[0][i], m[1][i], m[2][i]);
    }
    let data = MultipoleData::parse(&text, "mock", 0, &[(0, 1, 2), (2, 3, 4), (4, 5, 6)]).unwrap();
    let settings = FitSettings {
        free: vec![Parameter::F, Parameter::Sigma0, Parameter::Amplitude],
        start: Params {
            f: 0.55,
            sigma0: 3.0,
            amplitude: 0.95,
            cs2: 0.0,
        },
        k_min: 0.0,
    };
    let r = &fit(&model, &data, &settings, &[0.2]).unwrap()[0];
    assert!(r.chi2 < 1e-6, "{r:?}");
    for &(param, lo, hi) in &r.intervals {
        let (best, want) = (r.best.get(param), truth.get(param));
        assert!(
            (best - want).abs() < 1e-3 * want,
            "{param}: {best} vs {want}"
        );
        assert!(lo < best && best < hi, "{param}: [{lo}, {hi}]");
    }
}

/// Scoccimarro multipoles of linear spectra with the EFT counterterm, from the closed forms computed
/// here: P_dd = P(1 − 2x), P_dt = P(1 − 4x), P_tt = P(1 − 6x), x = c_s² k², and
/// P0 = b²P_dd + 2bf P_dt/3 + f² P_tt/5, P2 = 4bf P_dt/3 + 4f² P_tt/7, P4 = 8f² P_tt/35; no noise,
/// errors 0.5% of P0.
fn scoccimarro_counterterm_mock(k: &[f64], b: f64, f: f64, cs2: f64) -> MultipoleData {
    let p = LinearSpectrum::gm2012(0.0).unwrap();
    let mut text = String::new();
    for &ki in k {
        let (pl, x) = (p.eval(ki), cs2 * ki * ki);
        let (dd, dt, tt) = (
            pl * (1.0 - 2.0 * x),
            pl * (1.0 - 4.0 * x),
            pl * (1.0 - 6.0 * x),
        );
        let m = [
            b * b * dd + 2.0 * b * f * dt / 3.0 + f * f * tt / 5.0,
            4.0 * b * f * dt / 3.0 + 4.0 * f * f * tt / 7.0,
            8.0 * f * f * tt / 35.0,
        ];
        let s = 0.005 * m[0];
        text += &format!(
            "{ki:e} {:e} {s:e} {:e} {s:e} {:e} {s:e}\n",
            m[0], m[1], m[2]
        );
    }
    MultipoleData::parse(&text, "mock", 0, &[(0, 1, 2), (2, 3, 4), (4, 5, 6)]).unwrap()
}

#[test]
fn fit_recovers_an_injected_counterterm_with_f_and_the_amplitude() {
    let k = LogGrid::new(0.01, 0.25, 30).unwrap().points();
    let (b, cs2) = (1.5, 2.0);
    let data = scoccimarro_counterterm_mock(&k, b, F_TRUE, cs2);
    let p = LinearSpectrum::gm2012(0.0).unwrap();
    let real = real_space(
        RealModel::Linear,
        &p,
        &k,
        &Precision::fast(),
        &TableStore::in_memory(),
    )
    .unwrap();
    let model = MultipoleModel::new(
        &real,
        None,
        RsdModel::Scoccimarro,
        Fog::None,
        1.0,
        vec![b; k.len()],
        &[0, 2, 4],
    )
    .unwrap();
    let free = vec![Parameter::F, Parameter::Amplitude, Parameter::Cs2];
    let start = Params {
        f: 0.55,
        sigma0: 0.0,
        amplitude: 1.1,
        cs2: 0.0,
    };
    let settings = FitSettings {
        free: free.clone(),
        start,
        k_min: 0.0,
    };
    let r = &fit(&model, &data, &settings, &[0.25]).unwrap()[0];
    println!("{r:?}");
    // The mock's 10 printed digits limit the recovery to ~1e-9 relative.
    assert!((r.best.f - F_TRUE).abs() < 1e-6, "{r:?}");
    assert!((r.best.amplitude - 1.0).abs() < 1e-6, "{r:?}");
    assert!((r.best.cs2 - cs2).abs() < 1e-5, "{r:?}");
    assert!(r.chi2 < 1e-6, "{r:?}");
    // The c_s² interval ends: with c_s² held there and f, A_b re-minimised by a separate fit, χ² is
    // χ²_min + 3.53 (three free parameters).
    let (_, lo, hi) = r.intervals[2];
    assert!(lo < cs2 && cs2 < hi && hi - lo < 1.0, "{r:?}");
    for end in [lo, hi] {
        let held = FitSettings {
            free: vec![Parameter::F, Parameter::Amplitude],
            start: Params { cs2: end, ..r.best },
            k_min: 0.0,
        };
        let at = &fit(&model, &data, &held, &[0.25]).unwrap()[0];
        // Measured: 3.53002 and 3.53001.
        assert!(
            (at.chi2 - r.chi2 - delta_chi2(3)).abs() < 1e-3,
            "c_s² = {end}: χ² = {} vs {} + 3.53",
            at.chi2,
            r.chi2
        );
    }
}

#[test]
fn four_free_parameters_recover_a_tns_mock_with_a_counterterm() {
    // The mock is the model itself at (f, σ0, A_b, c_s²) = (0.483135, 4, 1, 1.2): the four-parameter
    // path (Δχ² = 4.72) finds it from a start away from it.
    let k = LogGrid::new(0.01, 0.2, 30).unwrap().points();
    let model = tns_model(&k, 1.3);
    let truth = Params {
        f: F_TRUE,
        sigma0: 4.0,
        amplitude: 1.0,
        cs2: 1.2,
    };
    let m = model.multipoles(&truth);
    let mut text = String::new();
    for (i, &ki) in k.iter().enumerate() {
        let s = 0.002 * m[0][i];
        text += &format!("{ki} {} {s} {} {s} {} {s}\n", m[0][i], m[1][i], m[2][i]);
    }
    let data = MultipoleData::parse(&text, "mock", 0, &[(0, 1, 2), (2, 3, 4), (4, 5, 6)]).unwrap();
    let settings = FitSettings {
        free: vec![
            Parameter::F,
            Parameter::Sigma0,
            Parameter::Amplitude,
            Parameter::Cs2,
        ],
        start: Params {
            f: 0.55,
            sigma0: 3.0,
            amplitude: 1.05,
            cs2: 0.0,
        },
        k_min: 0.0,
    };
    let r = &fit(&model, &data, &settings, &[0.2]).unwrap()[0];
    println!("{r:?}");
    for p in settings.free.iter().copied() {
        // Measured: ≤ 1.2e-7 (the intervals are 1e-3 to 0.07 wide).
        assert!((r.best.get(p) - truth.get(p)).abs() < 1e-5, "{p}: {r:?}");
    }
    assert_eq!(r.dof, 3 * k.len() - 4);
    assert!(r
        .intervals
        .iter()
        .all(|&(_, lo, hi)| lo < hi && hi.is_finite()));
}

/// The BOSS DR12 CMASS SGC covariance (MD-Patchy, via PyBird; `examples/data/boss_dr12_cmass_sgc/`):
/// its few-mode first bins (k < 0.005 h/Mpc) make the ℓ = 0, 2 block nearly singular as a whole
/// (correlation condition number 2.0e7 by numpy), which the whole-matrix check refuses
/// naming a point below k = 0.005; read as a fit's file it is accepted, and the points a fit of
/// 0.01 ≤ k ≤ 0.2 inverts pass the fit's check (condition number 8.4e2 by numpy).
#[test]
fn a_real_covariance_nearly_singular_only_in_unfitted_bins_is_fitted() {
    use pt_spectra::fit::covariance::{check_conditioning, validate_whole};
    let folder = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../examples/data/boss_dr12_cmass_sgc"
    );
    let numbers = |name: &str| -> Vec<Vec<f64>> {
        std::fs::read_to_string(format!("{folder}/{name}"))
            .unwrap()
            .lines()
            .filter(|l| !l.starts_with('#') && !l.trim().is_empty())
            .map(|l| l.split_whitespace().map(|x| x.parse().unwrap()).collect())
            .collect()
    };
    let (p, cov) = (numbers("ps1D_highzSGC.dat"), numbers("Cov_highzSGC.dat"));
    let n_k = 58;
    let k: Vec<f64> = p[..n_k].iter().map(|r| r[0]).collect();
    let values: Vec<Vec<f64>> = (0..2)
        .map(|l| p[l * n_k..(l + 1) * n_k].iter().map(|r| r[1]).collect())
        .collect();
    let c: Vec<Vec<f64>> = cov[..2 * n_k]
        .iter()
        .map(|r| r[..2 * n_k].to_vec())
        .collect();
    let e = validate_whole(c.clone(), &values, "Cov_highzSGC.dat", &[])
        .unwrap_err()
        .to_string();
    assert!(e.contains("condition number"), "{e}");
    let below: Vec<usize> = (0..n_k).filter(|&i| k[i] < 0.005).collect();
    assert!(
        below
            .iter()
            .any(|&i| e.contains(&format!("point {} of block", i + 1))),
        "{e}"
    );
    let sigma = values
        .iter()
        .map(|v| v.iter().map(|x| 0.1 * x.abs()).collect())
        .collect();
    let data = MultipoleData::from_arrays(k.clone(), &[0, 2], values, sigma, "ps1D_highzSGC.dat")
        .unwrap()
        .with_covariance(c.clone())
        .unwrap();
    let c = data.covariance.unwrap();
    let ids: Vec<usize> = (0..2)
        .flat_map(|l| {
            (0..n_k)
                .filter(|&i| (0.01..=0.2).contains(&k[i]))
                .map(move |i| l * n_k + i)
        })
        .collect();
    let sub: Vec<Vec<f64>> = ids
        .iter()
        .map(|&a| ids.iter().map(|&b| c[a][b]).collect())
        .collect();
    check_conditioning(&sub, "the fitted points", &|i| i.to_string()).unwrap();
}
