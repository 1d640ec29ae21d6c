use super::*;

fn c(re: f64, im: f64) -> C64 {
    C64::new(re, im)
}

/// a ≡ b modulo 2πi, to `tol` absolute.
fn close_mod_2pi(a: C64, b: C64, tol: f64) -> bool {
    let d = a - b;
    let turns = (d.im / (2.0 * PI)).round();
    (d.re.abs() < tol) && (d.im - 2.0 * PI * turns).abs() < tol
}

#[test]
fn ln_gamma_of_real_arguments() {
    let half = ln_gamma(c(0.5, 0.0));
    assert!((half.re - PI.sqrt().ln()).abs() < 3e-15 && half.im == 0.0);
    let mut ln_factorial = 0.0f64;
    for n in 1..=30 {
        let got = ln_gamma(c(n as f64, 0.0));
        let tol = 5e-16 * ln_factorial.abs().max(4.0);
        assert!((got.re - ln_factorial).abs() < tol, "Γ({n}): {got}");
        assert_eq!(got.im, 0.0);
        ln_factorial += (n as f64).ln();
    }
    // Γ(−1/2) = −2√π (reflection): the imaginary part is π modulo 2π.
    let got = ln_gamma(c(-0.5, 0.0)).exp();
    assert!(
        (got.re + 2.0 * PI.sqrt()).abs() < 2e-14 && got.im.abs() < 1e-14,
        "{got}"
    );
}

#[test]
fn ln_gamma_of_complex_arguments() {
    // Γ(1 + i) (Abramowitz & Stegun table 6.7; 16 digits).
    let g = ln_gamma(c(1.0, 1.0)).exp();
    assert!((g - c(0.498_015_668_118_356, -0.154_949_828_301_811)).norm() < 2e-15);
    for y in [0.1, 1.0, 10.0, 100.0, 300.0] {
        // |Γ(1/2 + iy)|² = π/cosh(πy),  ln cosh(πy) = πy + ln(1 + e^{−2πy}) − ln 2.
        let ln_cosh = PI * y + (-2.0 * PI * y).exp().ln_1p() - LN_2;
        let expected = PI.ln() - ln_cosh;
        let got = 2.0 * ln_gamma(c(0.5, y)).re;
        assert!(
            (got - expected).abs() < 1e-13 * expected.abs().max(1.0),
            "y={y}: {got}"
        );
        // |Γ(iy)|² = π/(y sinh(πy)), through the reflection formula.
        let ln_sinh = PI * y + (-(-2.0 * PI * y).exp()).ln_1p() - LN_2;
        let expected = PI.ln() - y.ln() - ln_sinh;
        let got = 2.0 * ln_gamma(c(0.0, y)).re;
        assert!(
            (got - expected).abs() < 1e-13 * expected.abs().max(1.0),
            "iy={y}: {got}"
        );
    }
    // Recurrence Γ(z + 1) = zΓ(z) and conjugation, on both sides of Re z = 1/2 and the shift at 10.
    for z in [
        c(0.3, 7.0),
        c(-2.7, 0.4),
        c(9.6, -3.0),
        c(0.75, 250.0),
        c(-4.5, -60.0),
    ] {
        let (a, b) = (ln_gamma(z + 1.0), ln_gamma(z) + z.ln());
        assert!(
            close_mod_2pi(a, b, 1e-12 * b.norm().max(1.0)),
            "z={z}: {a} vs {b}"
        );
        assert!(close_mod_2pi(ln_gamma(z.conj()), ln_gamma(z).conj(), 1e-13));
    }
}

#[test]
fn mellin_transforms_of_j_ell_are_known() {
    // U_0(1) = ∫ j0(t) dt = π/2, and U_ℓ(z)U_ℓ(3 − z) = π/2 (the two directions are inverses).
    assert!((ln_mellin(0, c(1.0, 0.0)).exp().re - PI / 2.0).abs() < 1e-14);
    for ell in 0..=MAX_ELL {
        for z in [c(1.5, 0.0), c(0.5, 3.0), c(1.2, -80.0)] {
            let product = (ln_mellin(ell, z) + ln_mellin(ell, 3.0 - z)).exp();
            assert!((product - c(PI / 2.0, 0.0)).norm() < 1e-12, "ℓ={ell} z={z}");
        }
    }
}

#[test]
fn plans_have_reciprocal_low_ringing_grids_and_invert_each_other() {
    let n = 256;
    for ell in [0, 3, 8] {
        let fwd = HankelPlan::new(1e-4, 10.0, n, ell, Direction::PkToXi, 1.5).unwrap();
        let (x, y) = (fwd.input_grid(), fwd.output_grid());
        assert!((fwd.kappa().ln()).abs() <= 0.5 * (1e5f64).ln() / (n - 1) as f64 + 1e-12);
        for j in 0..n {
            assert!((x[j] * y[n - 1 - j] / fwd.kappa() - 1.0).abs() < 1e-12);
        }
        // u_{N/2} is real (low ringing).
        assert!(fwd.u[n / 2].im.abs() < 1e-10 * fwd.u[n / 2].norm());
        let back = HankelPlan::new(y[0], y[n - 1], n, ell, Direction::XiToPk, 1.5).unwrap();
        let p: Vec<f64> = x
            .iter()
            .map(|k| k.powi(2) * (-k * k * 100.0).exp())
            .collect();
        let again = back.transform(&fwd.transform(&p).unwrap()).unwrap();
        let peak = p.iter().fold(0.0f64, |a, v| a.max(v.abs()));
        let worst = again
            .iter()
            .zip(&p)
            .fold(0.0f64, |w, (a, b)| w.max((a - b).abs()));
        println!(
            "ℓ = {ell}: round trip on the plans' grids to {:.1e} of the peak",
            worst / peak
        );
        assert!(worst < 1e-10 * peak, "ℓ={ell}: {worst:e}");
    }
}

#[test]
fn a_power_law_with_the_matching_bias_is_exact() {
    // P = k^{−1.5}, ℓ = 0: ξ = U_0(3/2) s^{−3/2}/(2π²), U_0(3/2) = √(π/2); P k^{3−q} is constant for q = 3/2.
    let plan = HankelPlan::new(1e-3, 1e3, 64, 0, Direction::PkToXi, 1.5).unwrap();
    let p: Vec<f64> = plan.input_grid().iter().map(|k| k.powf(-1.5)).collect();
    let xi = plan.transform(&p).unwrap();
    for (s, v) in plan.output_grid().iter().zip(xi) {
        let expected = (PI / 2.0).sqrt() / (2.0 * PI * PI) * s.powf(-1.5);
        assert!((v / expected - 1.0).abs() < 1e-13, "s={s}");
    }
}

fn grid(n: usize) -> (Vec<f64>, Vec<f64>) {
    let k: Vec<f64> = (0..n).map(|i| 1e-3 * 1.5f64.powi(i as i32)).collect();
    let p = k.iter().map(|k| (-k * k).exp()).collect();
    (k, p)
}

#[test]
fn bad_input_is_an_error() {
    let (k, p) = grid(20);
    let s = [10.0, 50.0];
    assert!(xi_from_pk(&k, &p, 2, &s).is_ok());
    let err = |r: Result<Vec<f64>>| r.unwrap_err();
    assert!(matches!(
        err(xi_from_pk(&k, &p[1..], 0, &s)),
        Error::LengthMismatch {
            left: 20,
            right: 19,
            ..
        }
    ));
    assert!(matches!(
        err(xi_from_pk(&k[..15], &p[..15], 0, &s)),
        Error::TooFewPoints { found: 15, .. }
    ));
    let e = err(xi_from_pk(&k, &p, 9, &s));
    assert!(
        matches!(e, Error::InvalidParameter { value, .. } if value == 9.0),
        "{e}"
    );
    let mut bad = p.clone();
    bad[4] = f64::NAN;
    assert!(matches!(
        err(xi_from_pk(&k, &bad, 0, &s)),
        Error::InvalidValue { line: 5, .. }
    ));
    bad[4] = f64::INFINITY;
    assert!(matches!(
        err(pk_from_xi(&k, &bad, 0, &s)),
        Error::InvalidValue { line: 5, .. }
    ));
    for (i, v) in [(0, 0.0), (3, -1.0), (7, f64::INFINITY)] {
        let mut bad = k.clone();
        bad[i] = v;
        let e = err(xi_from_pk(&bad, &p, 0, &s));
        assert!(
            matches!(e, Error::InvalidK { line, .. } if line == i + 1),
            "{e}"
        );
        let e = err(pk_from_xi(&bad, &p, 0, &s));
        assert!(
            matches!(e, Error::InvalidValue { line, .. } if line == i + 1),
            "{e}"
        );
    }
    let mut bad = k.clone();
    bad[6] = bad[5];
    let e = err(xi_from_pk(&bad, &p, 0, &s));
    assert!(matches!(e, Error::NonIncreasingK { line: 7, .. }), "{e}");
    let e = err(pk_from_xi(&bad, &p, 0, &s));
    assert!(matches!(e, Error::InvalidValue { line: 7, .. }), "{e}");
    // Outputs outside the reciprocal range [κ/x_max, κ/x_min] (here about [1/2217, 1000]).
    let e = err(xi_from_pk(&k, &p, 0, &[10.0, 2000.0]));
    assert!(
        matches!(e, Error::InvalidChoice { .. }) && e.to_string().contains("s = 2000 Mpc/h"),
        "{e}"
    );
    let e = err(pk_from_xi(&k, &p, 0, &[1e-4]));
    assert!(matches!(e, Error::OutOfRange { .. }), "{e}");
    assert!(matches!(
        err(xi_from_pk(&k, &p, 0, &[-1.0])),
        Error::InvalidValue { .. }
    ));
    assert!(matches!(
        err(pk_from_xi(&k, &p, 0, &[f64::NAN])),
        Error::InvalidK { .. }
    ));
    // Options and plans.
    let options = |o: HankelOptions| err(xi_from_pk_with(&k, &p, 0, &s, &o));
    let d = HankelOptions::default();
    for o in [
        HankelOptions { q: 2.0, ..d },
        HankelOptions { q: f64::NAN, ..d },
        HankelOptions {
            points_per_decade: 5.0,
            ..d
        },
        HankelOptions {
            points_per_decade: 1e9,
            ..d
        },
        HankelOptions {
            pad_decades: -1.0,
            ..d
        },
        HankelOptions {
            k_damp: Some(0.0),
            ..d
        },
    ] {
        assert!(
            matches!(options(o), Error::InvalidParameter { .. }),
            "{o:?}"
        );
    }
    let plan = |lo, hi, n, ell, q| HankelPlan::new(lo, hi, n, ell, Direction::PkToXi, q);
    for r in [
        plan(1.0, 1.0, 64, 0, 1.5),
        plan(0.0, 1.0, 64, 0, 1.5),
        plan(1.0, f64::INFINITY, 64, 0, 1.5),
        plan(1.0, 2.0, 15, 0, 1.5),
        plan(1.0, 2.0, 64, 9, 1.5),
        plan(1.0, 2.0, 64, 0, 0.0),
        plan(1.0, 2.0, 64, 2, -2.0),
    ] {
        assert!(matches!(r, Err(Error::InvalidParameter { .. })), "{r:?}");
    }
    let plan = plan(1.0, 2.0, 64, 2, -1.9).unwrap();
    assert!(matches!(
        plan.transform(&[1.0; 63]),
        Err(Error::LengthMismatch { .. })
    ));
    let mut f = [1.0; 64];
    f[63] = f64::NAN;
    assert!(matches!(
        plan.transform(&f),
        Err(Error::InvalidValue { line: 64, .. })
    ));
}
