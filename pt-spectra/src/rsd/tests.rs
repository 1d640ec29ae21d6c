//! Tests of the redshift-space models: Legendre coefficients, multipole rules, Fingers of God.

use super::*;

#[test]
fn legendre_coefficients_are_the_textbook_ones() {
    assert_eq!(legendre_coefficients(2), vec![-0.5, 0.0, 1.5]);
    assert_eq!(
        legendre_coefficients(4),
        vec![3.0 / 8.0, 0.0, -30.0 / 8.0, 0.0, 35.0 / 8.0]
    );
    // L_ℓ(1) = 1 for every ℓ
    for l in 0..=MAX_ELL {
        assert!((legendre_coefficients(l).iter().sum::<f64>() - 1.0).abs() < 1e-14);
    }
}

#[test]
fn linear_kaiser_multipoles_are_exact() {
    // P0 = P(b² + 2bf/3 + f²/5), P2 = P(4bf/3 + 4f²/7), P4 = P·8f²/35 (science.md).
    let rule = MultipoleRule::new(&[0, 2, 4, 6]).unwrap();
    for (b, f, p) in [(1.0, 0.483135, 2.0e4), (2.5, 0.852382, 3.1e3)] {
        let c = RsdModel::Kaiser.coefficients(b, f, [p; 3]);
        let m = rule.evaluate(&c, Fog::None, 0.0);
        let expected = [
            p * (b * b + 2.0 * b * f / 3.0 + f * f / 5.0),
            p * (4.0 * b * f / 3.0 + 4.0 * f * f / 7.0),
            p * 8.0 * f * f / 35.0,
            0.0,
        ];
        for (got, want) in m.iter().zip(expected) {
            assert!((got.value - want).abs() <= 1e-14 * p, "{got:?} {want}");
        }
    }
}

#[test]
fn damped_multipoles_match_closed_forms_and_tend_to_the_undamped_ones() {
    let rule = MultipoleRule::new(&[0, 2]).unwrap();
    // Gaussian, c = [1]: P0 = ∫_0^1 exp(−a²μ²) dμ = √π erf(a)/(2a); a = 1: 0.746824132812427.
    let p = rule.evaluate(&[1.0], Fog::Gaussian, 1.0);
    assert!((p[0].value - 0.746_824_132_812_427).abs() < 1e-13, "{p:?}");
    assert!(p[0].error < 1e-10);
    // Lorentzian², c = [1]: ∫_0^1 dμ/(1 + μ²/2)² = [μ/(2(1+μ²/2)) + atan(μ/√2)/√2]_0^1 at a = 1.
    let exact = 1.0 / 3.0 + (1.0 / 2f64.sqrt()).atan() / 2f64.sqrt();
    let p = rule.evaluate(&[1.0], Fog::Lorentzian, 1.0);
    assert!((p[0].value - exact).abs() < 1e-13, "{} {exact}", p[0].value);
    // σ → 0: the damped rule tends to the exact undamped moments.
    let c = [1.0, 0.7, 0.2];
    let undamped = rule.evaluate(&c, Fog::None, 0.0);
    for fog in [Fog::Lorentzian, Fog::Gaussian] {
        let damped = rule.evaluate(&c, fog, 1e-6);
        for (d, u) in damped.iter().zip(&undamped) {
            assert!((d.value - u.value).abs() < 1e-11, "{fog:?}");
        }
    }
}

/// The memo of `Sigma0::resolve_with` holds each theory value after its first use and gives what
/// `resolve` integrates, divided by the growth factor of each call.
#[test]
fn theory_sigma0_is_computed_once_per_spectrum() {
    use crate::linear::LinearSpectrum;
    use crate::precision::Precision;
    let p = LinearSpectrum::gm2012(0.0).unwrap();
    let precision = Precision::fast();
    let memo = Dispersions::default();
    assert_eq!(memo.computed(), (None, None));
    let s = Sigma0::Theory(DispersionInput::OneLoopSpt);
    let first = s.resolve_with(&p, 1.0, &precision, &memo).unwrap();
    let (lin, one) = memo.computed();
    assert!(lin.is_none() && one == Some(first));
    assert_eq!(first, s.resolve(&p, 1.0, &precision).unwrap());
    let half = s.resolve_with(&p, 0.5, &precision, &memo).unwrap();
    assert!((half - 2.0 * first).abs() < 1e-12 * first);
    let lin = Sigma0::Theory(DispersionInput::Linear)
        .resolve_with(&p, 1.0, &precision, &memo)
        .unwrap();
    assert_eq!(memo.computed(), (Some(lin), Some(first)));
    assert_eq!(
        Sigma0::Value(3.0)
            .resolve_with(&p, 0.5, &precision, &memo)
            .unwrap(),
        3.0
    );
}

#[test]
fn linear_theory_dispersion_is_sigma_v() {
    use crate::linear::LinearSpectrum;
    use crate::precision::Precision;
    let p = LinearSpectrum::gm2012(0.0).unwrap();
    let precision = Precision::fast();
    let lin = dispersion_theory(&p, DispersionInput::Linear, &precision).unwrap();
    // σ_v² of the FAST-PT header over the same range [1e-5, 1e3] h/Mpc: 36.9474495 (Mpc/h)².
    assert!(
        (lin.value.powi(2) / 36.947_449_5 - 1.0).abs() < 1e-6,
        "{lin:?}"
    );
    assert!(lin.error < 1e-6 * lin.value);
    let one = dispersion_theory(&p, DispersionInput::OneLoopSpt, &precision).unwrap();
    // The 1-loop correction to P_θθ is negative on average at z = 0 and of order 10% of σ².
    assert!(
        one.value < lin.value && one.value > 0.8 * lin.value,
        "{one:?}"
    );
}

#[test]
fn bad_multipoles_and_names_are_refused() {
    assert!(MultipoleRule::new(&[0, 3]).is_err());
    assert!(MultipoleRule::new(&[10]).is_err());
    assert!(MultipoleRule::new(&[]).is_err());
    assert!("tns-x".parse::<RsdModel>().is_err());
    assert_eq!("Kaiser".parse::<RsdModel>().unwrap(), RsdModel::Kaiser);
    assert_eq!("gaussian".parse::<Fog>().unwrap(), Fog::Gaussian);
    assert!("cauchy"
        .parse::<Fog>()
        .unwrap_err()
        .to_string()
        .contains("lorentzian"));
}
