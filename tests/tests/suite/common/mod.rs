//! Helpers shared by the kernel tests: exact rationals, vectors, random configurations, quadrature.
#![allow(dead_code)]

use num_bigint::BigInt;
use num_rational::BigRational;
use num_traits::{Signed, ToPrimitive};
use rand::Rng;

/// Exact rational.
pub type Q = BigRational;

/// n/d.
pub fn q(n: i64, d: i64) -> Q {
    Q::new(BigInt::from(n), BigInt::from(d))
}

/// 10^-e as an exact rational.
pub fn ten_to_minus(e: u32) -> Q {
    Q::new(BigInt::from(1), BigInt::from(10).pow(e))
}

/// An exact 3-vector from integers over a common denominator.
pub fn v(x: i64, y: i64, z: i64, d: i64) -> [Q; 3] {
    [q(x, d), q(y, d), q(z, d)]
}

/// −a.
pub fn neg(a: &[Q; 3]) -> [Q; 3] {
    [-a[0].clone(), -a[1].clone(), -a[2].clone()]
}

/// a + b.
pub fn add(a: &[Q; 3], b: &[Q; 3]) -> [Q; 3] {
    [&a[0] + &b[0], &a[1] + &b[1], &a[2] + &b[2]]
}

/// s·a.
pub fn scale(s: &Q, a: &[Q; 3]) -> [Q; 3] {
    [s * &a[0], s * &a[1], s * &a[2]]
}

/// Exact dot product.
pub fn dot(a: &[Q; 3], b: &[Q; 3]) -> Q {
    &a[0] * &b[0] + &a[1] * &b[1] + &a[2] * &b[2]
}

/// To f64.
pub fn f(x: &Q) -> f64 {
    x.to_f64().expect("finite")
}

/// |a − b| / max(|b|, tiny), exactly, then as f64.
pub fn rel_diff(a: &Q, b: &Q) -> f64 {
    let d = (a - b).abs();
    if b.abs() < ten_to_minus(300) {
        return f(&d);
    }
    f(&(d / b.abs()))
}

/// A random non-zero vector with dyadic components (exactly representable in f64): numerators in
/// [−8, 8], denominator 4.
pub fn random_dyadic(rng: &mut impl Rng) -> [Q; 3] {
    loop {
        let c = [
            rng.gen_range(-8..=8),
            rng.gen_range(-8..=8),
            rng.gen_range(-8..=8),
        ];
        if c != [0, 0, 0] {
            return v(c[0], c[1], c[2], 4);
        }
    }
}

/// The same vector in f64.
pub fn to_f64(a: &[Q; 3]) -> [f64; 3] {
    [f(&a[0]), f(&a[1]), f(&a[2])]
}

/// Gauss–Legendre nodes and weights on [−1, 1] (Newton iteration on P_n).
pub fn gauss_legendre(n: usize) -> Vec<(f64, f64)> {
    (0..n)
        .map(|i| {
            let mut x = (std::f64::consts::PI * (i as f64 + 0.75) / (n as f64 + 0.5)).cos();
            for _ in 0..100 {
                let (mut p0, mut p1) = (1.0, x);
                for k in 2..=n {
                    let p2 = ((2 * k - 1) as f64 * x * p1 - (k - 1) as f64 * p0) / k as f64;
                    p0 = p1;
                    p1 = p2;
                }
                let dp = n as f64 * (x * p1 - p0) / (x * x - 1.0);
                let dx = p1 / dp;
                x -= dx;
                if dx.abs() < 1e-16 {
                    let w = 2.0 / ((1.0 - x * x) * dp * dp);
                    return (x, w);
                }
            }
            panic!("Gauss-Legendre did not converge");
        })
        .collect()
}
