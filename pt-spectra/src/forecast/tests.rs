use super::*;
use crate::progress::Silent;
use std::f64::consts::PI;

fn store() -> TableStore {
    TableStore::new(std::env::temp_dir().join("pt-spectra-forecast-tests"))
}

/// The template forecast of `bins` in Planck 2018, no shared priors.
fn template(bins: &[SurveyBin]) -> Forecast {
    fisher(
        bins,
        &Cosmology::planck2018(),
        Parameters::Template,
        &[],
        &store(),
        &Silent,
    )
    .unwrap()
}

/// [P(k, μ) + 1/n̄]² of the Kaiser model P(k, μ) = (b + fμ²)²P as coefficients of μ⁰ … μ⁸.
fn kaiser_noise_squared(b: f64, f: f64, p: f64, n_bar: f64) -> [f64; 5] {
    let (a0, a1, a2) = (b * b * p + 1.0 / n_bar, 2.0 * b * f * p, f * f * p);
    [
        a0 * a0,
        2.0 * a0 * a1,
        a1 * a1 + 2.0 * a0 * a2,
        2.0 * a1 * a2,
        a2 * a2,
    ]
}

/// The Kaiser model's Fisher matrix of (b1, f) from P0, P2 with the Gaussian covariance, in closed
/// form: P_ℓ and their derivatives are polynomials in b, f times P_lin, and the covariance's μ
/// integrals are exact moments of μ (written here independently of the module's quadrature).
fn kaiser_fisher(
    b: f64,
    f: f64,
    shells: &[(f64, f64, f64, f64)],
    volume: f64,
    n_bar: f64,
) -> [[f64; 2]; 2] {
    // ∫_{-1}^{1} μ^{2n} dμ = 2/(2n + 1)
    let m = |n: i32| 2.0 / (2.0 * f64::from(n) + 1.0);
    let l2 = |x: [f64; 5]| -> [f64; 5] {
        // coefficients of μ^0, μ^2, … of L2(μ) times a polynomial in μ² (degree ≤ 2 in, ≤ 3 out)
        let mut out = [0.0; 5];
        for (n, c) in x.iter().enumerate().take(4) {
            out[n] -= 0.5 * c;
            out[n + 1] += 1.5 * c;
        }
        out
    };
    let integral = |x: [f64; 5]| -> f64 { (0..5).map(|n| x[n] * m(n as i32)).sum() };
    let mut fisher = [[0.0; 2]; 2];
    for &(_, lo, hi, p) in shells {
        let modes = volume * 4.0 * PI / 3.0 * (hi.powi(3) - lo.powi(3)) / (2.0 * PI).powi(3);
        let sq = kaiser_noise_squared(b, f, p, n_bar);
        // L0 L0 = 1, L0 L2 = L2, L2 L2 = (9μ⁴ − 6μ² + 1)/4: times sq, truncated at μ⁸
        let c00 = integral(sq) / modes;
        let c02 = 5.0 * integral(l2(sq)) / modes;
        let l22 = |x: [f64; 5]| -> f64 {
            let mut t = 0.0;
            for (n, xn) in x.iter().enumerate() {
                let n = n as i32;
                t += xn * (0.25 * m(n) - 1.5 * m(n + 1) + 2.25 * m(n + 2));
            }
            t
        };
        let c22 = 25.0 * l22(sq) / modes;
        // dP0/db = (2b + 2f/3) P, dP0/df = (2b/3 + 2f/5) P; dP2/db = (4f/3) P, dP2/df = (4b/3 + 8f/7) P
        let d = [
            [(2.0 * b + 2.0 * f / 3.0) * p, 4.0 * f / 3.0 * p],
            [
                (2.0 * b / 3.0 + 2.0 * f / 5.0) * p,
                (4.0 * b / 3.0 + 8.0 * f / 7.0) * p,
            ],
        ];
        let det = c00 * c22 - c02 * c02;
        let inv = [[c22 / det, -c02 / det], [-c02 / det, c00 / det]];
        for i in 0..2 {
            for j in 0..2 {
                let mut s = 0.0;
                for a in 0..2 {
                    for bb in 0..2 {
                        s += d[i][a] * inv[a][bb] * d[j][bb];
                    }
                }
                fisher[i][j] += s;
            }
        }
    }
    fisher
}

#[test]
fn on_large_scales_the_forecast_is_the_kaiser_fisher_matrix() {
    // k ≤ 0.04 h/Mpc: ept is Kaiser to ≲ 1% (loops ∝ k², no FoG); (b1, f) free, α's fixed by tight
    // priors being absent — the template has them free, so compare the (b1, f) block of the inverse of
    // the Kaiser matrix with α's marginalised is not possible in closed form: fix them instead by
    // comparing the Fisher matrix itself (its b1, f block)
    let fiducial = Cosmology::planck2018();
    let mut bin = SurveyBin::new(0.5, 2e9, 3e-4, 0.02, 2.0);
    bin.k_min = 0.004;
    bin.dk = 0.002;
    bin.free = vec!["b1".into()];
    let got = template(std::slice::from_ref(&bin));
    let (f_at, b_at) = (
        got.names.iter().position(|n| n == "f_1").unwrap(),
        got.names.iter().position(|n| n == "b1_1").unwrap(),
    );
    // the model's linear spectrum at the shells, from the emulator
    let e = crate::emulator::LinearEmulator::embedded().unwrap();
    let s = e.spectra(&fiducial, 0.5).unwrap();
    let cb = s.cb().unwrap();
    let f = got.fiducial[f_at];
    let shells: Vec<(f64, f64, f64, f64)> = bin
        .shells()
        .iter()
        .map(|&(k, lo, hi)| (k, lo, hi, cb.eval(k)))
        .collect();
    let want = kaiser_fisher(2.0, f, &shells, bin.volume, bin.n_bar);
    // the loops' f-dependence (−(kμf)²σ_v² terms) is ~2% of dP/df at k = 0.02: 3.5% of F_ff measured
    // (10% at k_max = 0.04); b1's derivative is Kaiser's to 1e-3
    let pairs = [
        (b_at, b_at, 0, 0, 0.01),
        (f_at, f_at, 1, 1, 0.05),
        (b_at, f_at, 0, 1, 0.03),
    ];
    for (i, j, a, b, tol) in pairs {
        let r = got.fisher[i][j] / want[a][b] - 1.0;
        assert!(
            r.abs() < tol,
            "F[{}][{}]: {} vs {} ({r:+.2e})",
            got.names[i],
            got.names[j],
            got.fisher[i][j],
            want[a][b]
        );
    }
    assert!(got.derivative_error < 1e-4, "{}", got.derivative_error);
}

#[test]
fn errors_scale_as_one_over_the_square_root_of_the_volume_and_priors_shrink_them() {
    let bin = SurveyBin::new(0.6, 1e9, 4e-4, 0.15, 2.0);
    let one = template(std::slice::from_ref(&bin));
    let mut big = bin.clone();
    big.volume *= 4.0;
    let four = template(&[big]);
    for (a, b) in one.sigma.iter().zip(&four.sigma) {
        assert!((a / b - 2.0).abs() < 1e-9, "{a} {b}");
    }
    // σ(fσ8) = σ8(z) σ(f), a few percent of fσ8 for a BOSS-like bin
    let (s, fs8) = one.fsigma8[0];
    assert!(s > 0.01 * fs8 && s < 0.2 * fs8, "{s} {fs8}");
    // two identical bins: errors of the shared-nothing template parameters unchanged per bin
    let two = template(&[bin.clone(), bin.clone()]);
    assert_eq!(two.names.len(), 2 * one.names.len());
    assert!((two.sigma[0] / one.sigma[0] - 1.0).abs() < 1e-12);
    // a prior on b2 lowers σ(f)
    let mut with_prior = bin.clone();
    with_prior.priors = vec![("b2".into(), 0.1)];
    let p = template(&[with_prior]);
    assert!(p.sigma[0] < one.sigma[0]);
}

#[test]
fn cosmological_forecasts_share_the_parameters_and_bad_input_is_named() {
    let fiducial = Cosmology::planck2018();
    let bins = [
        SurveyBin::new(0.5, 2e9, 3e-4, 0.15, 2.0),
        SurveyBin::new(1.0, 4e9, 2e-4, 0.15, 1.6),
    ];
    let bbn = [("omega_b".to_string(), 0.00037)];
    let got = fisher(
        &bins,
        &fiducial,
        Parameters::Cosmology,
        &bbn,
        &store(),
        &Silent,
    )
    .unwrap();
    assert_eq!(
        &got.names[..5],
        COSMOLOGY_NAMES.map(String::from).as_slice()
    );
    assert_eq!(got.names.len(), 5 + 2 * DEFAULT_FREE_NUISANCE.len());
    assert!(got.sigma.iter().all(|s| s.is_finite() && *s > 0.0));
    assert!(got.derivative_error < 1e-3, "{}", got.derivative_error);
    // with a BBN prior on ω_b, h is measured through the shape and AP to a few percent; without it
    // ω_b, h and the shape trade off
    assert!(got.sigma[2] < 0.05 * fiducial.h, "{}", got.sigma[2]);
    assert!(got.sigma[1] < 0.00037);
    let free = fisher(
        &bins,
        &fiducial,
        Parameters::Cosmology,
        &[],
        &store(),
        &Silent,
    )
    .unwrap();
    assert!(
        free.sigma[2] > 2.0 * got.sigma[2],
        "{} {}",
        free.sigma[2],
        got.sigma[2]
    );
    let e = fisher(
        &bins,
        &fiducial,
        Parameters::Template,
        &bbn,
        &store(),
        &Silent,
    )
    .unwrap_err();
    assert!(e.to_string().contains("omega_b"), "{e}");
    let refused = |bad: SurveyBin| -> String {
        fisher(
            &[bad],
            &fiducial,
            Parameters::Template,
            &[],
            &store(),
            &Silent,
        )
        .unwrap_err()
        .to_string()
    };
    let mut bad = bins[0].clone();
    bad.volume = -1.0;
    let e = refused(bad);
    assert!(e.contains("survey bin 1") && e.contains("volume"), "{e}");
    let mut bad = bins[0].clone();
    bad.free.push("b9".into());
    let e = refused(bad);
    assert!(e.contains("b9"), "{e}");
    // a block's survey number outside the shells, and a block not registered
    for kind in crate::blocks::AVAILABLE {
        if let Some(face) = kind.faces.survey {
            let mut bad = bins[0].clone();
            bad.blocks.push((kind.name, 0.3));
            assert!(refused(bad).contains(face.key));
        }
    }
    let mut bad = bins[0].clone();
    bad.blocks.push(("trispectrum", 0.1));
    let e = refused(bad);
    assert!(
        e.contains("trispectrum") && e.contains("the blocks are"),
        "{e}"
    );
    let sigma8 = Cosmology::gm2012();
    let e = fisher(
        &bins,
        &sigma8,
        Parameters::Cosmology,
        &[],
        &store(),
        &Silent,
    )
    .unwrap_err();
    assert!(e.to_string().contains("A_s"), "{e}");
}

#[test]
fn the_gaussian_covariance_is_the_closed_form_of_kaiser_multipoles() {
    // P(k, μ) = (b + fμ²)² P: P0, P2, P4 = (b² + 2bf/3 + f²/5, 4bf/3 + 4f²/7, 8f²/35) P; the module's
    // quadrature against the exact moments of μ (one shell)
    let (b, f, p, n_bar, modes) = (1.8, 0.7, 2.0e4, 2e-4, 1234.0);
    let ell = [
        (b * b + 2.0 * b * f / 3.0 + f * f / 5.0) * p,
        (4.0 * b * f / 3.0 + 4.0 * f * f / 7.0) * p,
        8.0 * f * f / 35.0 * p,
        0.0,
        0.0,
    ];
    let c = gaussian_covariance(&[0, 2, 4], &ell, n_bar, modes);
    let m = |n: usize| 2.0 / (2.0 * n as f64 + 1.0);
    let sq = kaiser_noise_squared(b, f, p, n_bar);
    // L0 = 1, L2 = (3μ² − 1)/2, L4 = (35μ⁴ − 30μ² + 3)/8 as coefficients of μ^0, μ^2, μ^4
    let legendre = [
        [1.0, 0.0, 0.0],
        [-0.5, 1.5, 0.0],
        [3.0 / 8.0, -30.0 / 8.0, 35.0 / 8.0],
    ];
    for (a, la) in legendre.iter().enumerate() {
        for (bb, lb) in legendre.iter().enumerate() {
            let mut s = 0.0;
            for (i, x) in la.iter().enumerate() {
                for (j, y) in lb.iter().enumerate() {
                    for (n, q) in sq.iter().enumerate() {
                        s += x * y * q * m(i + j + n);
                    }
                }
            }
            let want = ((4 * a + 1) * (4 * bb + 1)) as f64 * s / modes;
            let got = c[a * 3 + bb];
            assert!(
                (got - want).abs() <= 1e-12 * c[0].abs(),
                "C[{a}][{bb}]: {got} vs {want}"
            );
        }
    }
}

// ---- the linear-Kaiser forecast (kaiser.rs) ----

/// ∫_0^1 μ^{2m} dμ/(b + fμ²)² for m = 0, 1, 2 in closed form (arctan), independently of the
/// module's quadrature.
fn kaiser_mu_moments(b: f64, f: f64) -> [f64; 3] {
    let j = (f / b).sqrt().atan() / (b * f).sqrt(); // ∫ dμ/(b + fμ²)
    let i0 = 1.0 / (2.0 * b * (b + f)) + j / (2.0 * b); // ∫ dμ/(b + fμ²)²
    let i1 = (j - b * i0) / f; // ∫ μ² dμ/(b + fμ²)²
    let k1 = (1.0 - b * j) / f; // ∫ μ² dμ/(b + fμ²)
    let i2 = (k1 - b * i1) / f; // ∫ μ⁴ dμ/(b + fμ²)²
    [i0, i1, i2]
}

#[test]
fn the_kaiser_fisher_matrix_is_the_closed_form_one_without_shot_noise() {
    // one tracer, n̄ → ∞: Tr[C⁻¹∂C]² = 4 u_a u_b/(b + fμ²)², independent of P, so
    // F = V/(4π²) (k_max³ − k_min³)/3 · 4 ∫ [μ⁰, μ², μ⁴] dμ/(b + fμ²)²
    let (b, f, v, k0, k1) = (1.7, 0.8, 3e9, 0.002, 0.13);
    let tracers = [KaiserTracer { n_bar: 1e12, b1: b }];
    let p = |k: f64| 2e4 * (k / 0.05).powf(-1.3) * (1.0 + 0.05 * (100.0 * k).sin());
    let got = crate::forecast::kaiser_fisher(&tracers, f, &p, v, k0, k1);
    let [i0, i1, i2] = kaiser_mu_moments(b, f);
    let pre = v / (4.0 * PI * PI) * (k1.powi(3) - k0.powi(3)) / 3.0 * 4.0;
    // parameters (f, b): F_ff ∝ ∫μ⁴, F_fb ∝ ∫μ², F_bb ∝ ∫1
    for (got, want) in [
        (got[0][0], pre * i2),
        (got[0][1], pre * i1),
        (got[1][1], pre * i0),
    ] {
        assert!((got / want - 1.0).abs() < 1e-9, "{got} vs {want}");
    }
    assert_eq!(got[0][1], got[1][0]);
}

#[test]
fn the_kaiser_fisher_matrix_with_shot_noise_is_the_single_tracer_integral() {
    // one tracer with noise: F_ab = V/(4π²) ∫k²dk ∫dμ ∂_aP ∂_bP/(P + 1/n̄)², by a dense trapezoid here
    let (b, f, n, v) = (1.4, 0.7, 2e-4, 1e9);
    let p = |k: f64| 3e4 * k / (1.0 + (k / 0.02).powi(2)) / 0.02;
    let got =
        crate::forecast::kaiser_fisher(&[KaiserTracer { n_bar: n, b1: b }], f, &p, v, 0.01, 0.2);
    let (nk, nm) = (4000, 2000);
    let mut want = [[0.0; 2]; 2];
    for i in 0..=nk {
        let k = 0.01 + 0.19 * i as f64 / nk as f64;
        let wk = if i == 0 || i == nk { 0.5 } else { 1.0 } * 0.19 / nk as f64;
        for j in 0..=nm {
            let mu = j as f64 / nm as f64;
            let wm = if j == 0 || j == nm { 0.5 } else { 1.0 } / nm as f64;
            let a = b + f * mu * mu;
            let ps = a * a * p(k);
            let d = [2.0 * a * mu * mu * p(k), 2.0 * a * p(k)];
            for x in 0..2 {
                for y in 0..2 {
                    want[x][y] += wk * wm * k * k * v / (4.0 * PI * PI) * d[x] * d[y]
                        / (ps + 1.0 / n).powi(2);
                }
            }
        }
    }
    for x in 0..2 {
        for y in 0..2 {
            assert!(
                (got[x][y] / want[x][y] - 1.0).abs() < 1e-5,
                "{x}{y}: {} vs {}",
                got[x][y],
                want[x][y]
            );
        }
    }
}

#[test]
fn two_tracers_of_equal_bias_measure_f_as_one_of_their_summed_density() {
    // equal biases: the difference field carries no information on f or the common bias, so σ(f)
    // equals that of one tracer with n̄₁ + n̄₂ (b₁, b₂ free against b free)
    let p = |k: f64| 2e4 * (k / 0.05).powf(-1.2);
    let inv_ff = |fisher: Vec<Vec<f64>>| {
        let n = fisher.len();
        crate::linalg::solve_spd(&fisher, &vec![0.0; n]).unwrap().1[0][0]
    };
    let two = [
        KaiserTracer {
            n_bar: 1e-4,
            b1: 1.5,
        },
        KaiserTracer {
            n_bar: 3e-4,
            b1: 1.5,
        },
    ];
    let one = [KaiserTracer {
        n_bar: 4e-4,
        b1: 1.5,
    }];
    let s2 = inv_ff(crate::forecast::kaiser_fisher(
        &two, 0.8, &p, 1e9, 0.005, 0.15,
    ));
    let s1 = inv_ff(crate::forecast::kaiser_fisher(
        &one, 0.8, &p, 1e9, 0.005, 0.15,
    ));
    assert!((s2 / s1 - 1.0).abs() < 1e-9, "{s2} vs {s1}");
    // unequal biases: the second tracer adds information (multi-tracer), never removes it
    let unequal = [
        KaiserTracer {
            n_bar: 1e-4,
            b1: 1.2,
        },
        KaiserTracer {
            n_bar: 3e-4,
            b1: 2.0,
        },
    ];
    let alone = [KaiserTracer {
        n_bar: 3e-4,
        b1: 2.0,
    }];
    assert!(
        inv_ff(crate::forecast::kaiser_fisher(
            &unequal, 0.8, &p, 1e9, 0.005, 0.15
        )) < inv_ff(crate::forecast::kaiser_fisher(
            &alone, 0.8, &p, 1e9, 0.005, 0.15
        ))
    );
}

/// The bins of the DESI FDR (arXiv:1611.00036) Tables 2.3 and 2.5 (`tests/data/desi_fdr_fsigma8.txt`):
/// (sample, z, bins of the forecast at k_max, published σ(fσ8)/fσ8 at k_max = 0.1 and 0.2 [%]).
pub(super) fn desi_fdr_bins(
    fiducial: &Cosmology,
    k_max: f64,
) -> Vec<(String, f64, KaiserBin, f64, f64)> {
    let text = include_str!("../../tests/data/desi_fdr_fsigma8.txt");
    let area = 14000.0 * (PI / 180.0).powi(2);
    let growth_at = |z: f64| fiducial.growth_factor(z);
    text.lines()
        .filter(|l| !l.starts_with('#') && !l.trim().is_empty())
        .map(|l| {
            let c: Vec<&str> = l.split_whitespace().collect();
            let x: Vec<f64> = c[1..].iter().map(|s| s.parse().unwrap()).collect();
            let z = x[0];
            let (lo, hi) = (z - 0.05, z + 0.05);
            let volume = area / 3.0
                * (fiducial.comoving_distance(hi).powi(3) - fiducial.comoving_distance(lo).powi(3));
            let d = growth_at(z);
            let tracers: Vec<KaiserTracer> = [(x[1], 0.84), (x[2], 1.7), (x[3], 1.2), (x[4], 1.34)]
                .iter()
                .filter(|(n, _)| *n > 0.0)
                .map(|&(dndz, bd)| KaiserTracer {
                    n_bar: dndz * 0.1 * 14000.0 / volume,
                    b1: bd / d,
                })
                .collect();
            let bin = KaiserBin {
                z,
                volume,
                k_min: 0.001,
                k_max,
                tracers,
            };
            (c[0].to_string(), z, bin, x[5], x[6])
        })
        .collect()
}

#[test]
fn the_desi_fdr_table_2_3_fsigma8_forecast_is_reproduced_within_ten_percent_at_k_max_0_1() {
    // DESI FDR Table 2.3 (ELG + LRG + QSO, multi-tracer, 0.6 < z < 1.9), k_max = 0.1 h/Mpc, the
    // like-for-like case (linear scales, the FDR's method): every bin's σ(fσ8)/fσ8 within 10% of the
    // published one (measured 0.94 … 1.04 with Planck 2018, docs/forecast.md). Where the FDR's numbers
    // include information loss beyond linear Kaiser (k_max = 0.2; the BGS of Table 2.5 at z < 0.5) ours
    // are smaller; those ratios are only guarded here (measured: main 0.86 … 0.92 at 0.2; BGS 0.87 …
    // 0.93 at 0.1 and 0.73 … 0.79 at 0.2)
    let fiducial = Cosmology::planck2018();
    for k_max in [0.1, 0.2] {
        let rows = desi_fdr_bins(&fiducial, k_max);
        let bins: Vec<KaiserBin> = rows.iter().map(|r| r.2.clone()).collect();
        let got = fisher_kaiser(&bins, &fiducial).unwrap();
        for (row, &(s, fs8)) in rows.iter().zip(&got.fsigma8) {
            let published = if k_max == 0.1 { row.3 } else { row.4 };
            let ratio = 100.0 * s / fs8 / published;
            let (lo, hi) = match (row.0.as_str(), k_max == 0.1) {
                ("main", true) => (0.9, 1.1),
                ("main", false) => (0.85, 0.97),
                (_, true) => (0.85, 0.96),
                (_, false) => (0.7, 0.82),
            };
            assert!(
                ratio > lo && ratio < hi,
                "{} z = {}, k_max = {k_max}: {:.2}% against {published}% (ratio {ratio:.3})",
                row.0,
                row.1,
                100.0 * s / fs8
            );
        }
    }
}
