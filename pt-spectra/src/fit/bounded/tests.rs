//! Tests of the bounded minimiser and the Hessians.

use super::*;

/// A quadratic with a known minimum inside the box is found to its rounding; a bound that cuts
/// it off holds the minimum on the bound (the constrained minimum of a quadratic, exactly).
#[test]
fn quadratic_minimum_inside_and_on_a_bound() {
    // f = (x−1)² + 10 (y + 2)² + (x−1)(y+2): minimum at (1, −2), value 3.
    let f = |v: &[f64]| {
        let (a, b) = (v[0] - 1.0, v[1] + 2.0);
        a * a + 10.0 * b * b + a * b + 3.0
    };
    let p = Problem {
        f: &f,
        grad: None,
        lo: vec![-10.0, -10.0],
        hi: vec![10.0, 10.0],
        scale: vec![1.0, 1.0],
        tolerance: EXPECTED_DECREASE,
    };
    let m = p.minimise(&[7.0, 5.0]);
    assert!(m.converged);
    assert!(
        (m.x[0] - 1.0).abs() < 1e-4 && (m.x[1] + 2.0).abs() < 1e-4,
        "{m:?}"
    );
    assert!((m.value - 3.0).abs() < 1e-7, "{m:?}");
    // y ≥ −1: on the bound, x minimises a² + a(1) → a = −½, value 3 + 10 + ... = 3 + 10 − ¼.
    let q = Problem {
        lo: vec![-10.0, -1.0],
        ..p
    };
    let m = q.minimise(&[7.0, 5.0]);
    assert_eq!(m.x[1], -1.0);
    // Converged to an expected decrease of 1e-7: |Δx| ≲ √(1e-7) here.
    assert!((m.x[0] - 0.5).abs() < 1e-3, "{m:?}");
    assert!((m.value - (13.0 - 0.25)).abs() < 1e-7, "{m:?}");
}

/// Rosenbrock's valley (curved, badly scaled) from the classic start (−1.2, 1): the minimum (1, 1).
#[test]
fn rosenbrock() {
    let f = |v: &[f64]| 100.0 * (v[1] - v[0] * v[0]).powi(2) + (1.0 - v[0]).powi(2);
    let p = Problem {
        f: &f,
        grad: None,
        lo: vec![-5.0, -5.0],
        hi: vec![5.0, 5.0],
        scale: vec![0.1, 0.1],
        tolerance: EXPECTED_DECREASE,
    };
    let m = p.minimise(&[-1.2, 1.0]);
    assert!(m.value < 1e-6, "{m:?}");
    assert!((m.x[0] - 1.0).abs() < 2e-3, "{m:?}");
}

/// With the exact gradient (and no curvature: NaN) the same minima are found, inside and on a
/// bound, in fewer evaluations than with central differences.
#[test]
fn exact_gradients_find_the_same_minima_in_fewer_evaluations() {
    let f = |v: &[f64]| 100.0 * (v[1] - v[0] * v[0]).powi(2) + (1.0 - v[0]).powi(2);
    let grad = |v: &[f64]| {
        let r = v[1] - v[0] * v[0];
        Some((
            f(v),
            vec![-400.0 * r * v[0] - 2.0 * (1.0 - v[0]), 200.0 * r],
            vec![f64::NAN; 2],
        ))
    };
    for lo in [-5.0, 1.2] {
        let differences = Problem {
            f: &f,
            grad: None,
            lo: vec![-5.0, lo],
            hi: vec![5.0, 5.0],
            scale: vec![0.1, 0.1],
            tolerance: EXPECTED_DECREASE,
        };
        let exact = Problem {
            grad: Some(&grad),
            lo: vec![-5.0, lo],
            hi: vec![5.0, 5.0],
            scale: vec![0.1, 0.1],
            ..differences
        };
        let (a, b) = (
            differences.minimise(&[-1.2, 1.3]),
            exact.minimise(&[-1.2, 1.3]),
        );
        assert!(
            b.converged && (a.value - b.value).abs() < 1e-6,
            "{a:?} {b:?}"
        );
        assert!((a.x[0] - b.x[0]).abs() < 3e-3, "{a:?} {b:?}");
        assert!(b.evaluations < a.evaluations, "{a:?} {b:?}");
    }
}

/// Two valleys: the start near the higher one stays there, the multistart takes the lower one
/// and counts the starts that reached it.
#[test]
fn several_starts_find_the_lower_of_two_minima() {
    // f = (x² − 1)² + 0.3 x: minima near x = −1.04 (lower) and x = 0.96.
    let f = |v: &[f64]| (v[0] * v[0] - 1.0).powi(2) + 0.3 * v[0];
    let p = Problem {
        f: &f,
        grad: None,
        lo: vec![-3.0],
        hi: vec![3.0],
        scale: vec![0.1],
        tolerance: EXPECTED_DECREASE,
    };
    let single = p.minimise(&[0.8]);
    assert!(single.x[0] > 0.5, "{single:?}");
    let m = multistart(&p, &[vec![0.8], vec![-2.0], vec![2.5], vec![-0.5]]);
    assert!(m.best().x[0] < -1.0, "{:?}", m.best());
    // x* solves 4x³ − 4x + 0.3 = 0.
    let x = m.best().x[0];
    assert!((4.0 * x * x * x - 4.0 * x + 0.3).abs() < 1e-3, "{x}");
    assert_eq!(m.agree, 2, "{m:?}");
}

/// The Hessian from differences of the exact gradient of a quadratic is exact to rounding, also
/// at a bound.
#[test]
fn hessian_from_the_gradient_of_a_quadratic() {
    let grad = |v: &[f64]| {
        Some((
            0.0,
            vec![4.0 * v[0] + 3.0 * v[1], 3.0 * v[0] + 10.0 * v[1]],
            vec![f64::NAN; 2],
        ))
    };
    for (x, lo) in [([0.3, -0.2], [-1.0, -1.0]), ([0.3, -0.2], [0.3, -1.0])] {
        let h = hessian_from_gradient(&grad, &x, &[1e-2, 1e-2], &lo, &[1.0, 1.0]).unwrap();
        for (got, want) in [
            (h[0][0], 4.0),
            (h[0][1], 3.0),
            (h[1][0], 3.0),
            (h[1][1], 10.0),
        ] {
            assert!((got - want).abs() < 1e-9, "{h:?}");
        }
    }
    assert!(hessian_from_gradient(&|_: &[f64]| None, &[0.0], &[1e-2], &[-1.0], &[1.0]).is_none());
    // a point outside the objective's domain (+∞) gives no Hessian, not one of its zero gradient
    let outside = |_: &[f64]| Some((f64::INFINITY, vec![0.0], vec![f64::NAN]));
    assert!(hessian_from_gradient(&outside, &[0.0], &[1e-2], &[-1.0], &[1.0]).is_none());
}

/// The central-difference Hessian of a quadratic is exact to rounding, also at a bound.
#[test]
fn hessian_of_a_quadratic() {
    let f = |v: &[f64]| 2.0 * v[0] * v[0] + 3.0 * v[0] * v[1] + 5.0 * v[1] * v[1];
    for (x, lo) in [([0.3, -0.2], [-1.0, -1.0]), ([0.3, -0.2], [0.3, -1.0])] {
        let h = hessian(&f, &x, f(&x), &[1e-2, 1e-2], &lo, &[1.0, 1.0]);
        for (got, want) in [(h[0][0], 4.0), (h[0][1], 3.0), (h[1][1], 10.0)] {
            assert!((got - want).abs() < 1e-6, "{h:?}");
        }
    }
}
