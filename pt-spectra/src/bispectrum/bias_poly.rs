//! Polynomials in the growth rate f and the second-order bias coefficients b1, b2, g2 of
//! [`super::bias_kernels::LoopBias`], with `f64` coefficients: the counterterm and stochastic shapes of
//! the one-loop galaxy bispectrum written once ([`super::galaxy_counterterms_rsd`]'s `pair_parts`) and
//! evaluated either at numbers or as such polynomials, so that a plan ([`super::counterterm_plan`]) holds
//! them once per triangle and a new f or bias is a contraction.

use std::ops::{Add, Mul, Sub};

/// The variables, in the order of a monomial's exponents.
pub const VARIABLES: [&str; 4] = ["f", "b1", "b2", "g2"];

/// The arithmetic the shapes need of their coefficients: `f64`, or [`Poly`].
pub trait Ring:
    Clone
    + Add<Output = Self>
    + Sub<Output = Self>
    + Mul<Output = Self>
    + Mul<f64, Output = Self>
    + From<f64>
{
}

impl<T> Ring for T where
    T: Clone
        + Add<Output = T>
        + Sub<Output = T>
        + Mul<Output = T>
        + Mul<f64, Output = T>
        + From<f64>
{
}

/// Σ c x^e over monomials e = (exponents of f, b1, b2, g2), sorted by exponents, no zero coefficient.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Poly {
    terms: Vec<([u8; 4], f64)>,
}

impl Poly {
    /// The variable `i` of [`VARIABLES`].
    pub fn var(i: usize) -> Self {
        let mut e = [0; 4];
        e[i] = 1;
        Self {
            terms: vec![(e, 1.0)],
        }
    }

    /// Σ c x^e from terms in any order (merged, zeros dropped).
    pub fn from_terms(mut terms: Vec<([u8; 4], f64)>) -> Self {
        terms.sort_by_key(|t| t.0);
        let mut out: Vec<([u8; 4], f64)> = Vec::with_capacity(terms.len());
        for (e, c) in terms {
            match out.last_mut() {
                Some(last) if last.0 == e => last.1 += c,
                _ => out.push((e, c)),
            }
        }
        out.retain(|t| t.1 != 0.0);
        Self { terms: out }
    }

    /// The monomials' exponents and coefficients.
    pub fn terms(&self) -> &[([u8; 4], f64)] {
        &self.terms
    }

    /// The value at x = (f, b1, b2, g2).
    pub fn eval(&self, x: [f64; 4]) -> f64 {
        self.terms
            .iter()
            .map(|(e, c)| {
                c * e
                    .iter()
                    .zip(x)
                    .map(|(&n, x)| x.powi(i32::from(n)))
                    .product::<f64>()
            })
            .sum()
    }
}

impl From<f64> for Poly {
    fn from(c: f64) -> Self {
        Self::from_terms(vec![([0; 4], c)])
    }
}

impl Add for Poly {
    type Output = Self;
    fn add(mut self, other: Self) -> Self {
        self.terms.extend(other.terms);
        Self::from_terms(self.terms)
    }
}

impl Sub for Poly {
    type Output = Self;
    fn sub(self, other: Self) -> Self {
        self + other * -1.0
    }
}

impl Mul<f64> for Poly {
    type Output = Self;
    fn mul(mut self, c: f64) -> Self {
        self.terms.iter_mut().for_each(|t| t.1 *= c);
        self.terms.retain(|t| t.1 != 0.0);
        self
    }
}

impl Mul for Poly {
    type Output = Self;
    fn mul(self, other: Self) -> Self {
        let mut terms = Vec::with_capacity(self.terms.len() * other.terms.len());
        for (a, x) in &self.terms {
            for (b, y) in &other.terms {
                terms.push((std::array::from_fn(|i| a[i] + b[i]), x * y));
            }
        }
        Self::from_terms(terms)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn arithmetic_is_that_of_the_values() {
        let (f, b1) = (Poly::var(0), Poly::var(1));
        let p = (f.clone() * 2.0 + b1.clone()) * (b1.clone() - Poly::from(0.5)) * f.clone();
        let x = [0.7, 1.9, -0.3, 0.4];
        let want = (2.0 * 0.7 + 1.9) * (1.9 - 0.5) * 0.7;
        assert!((p.eval(x) - want).abs() < 1e-14, "{} {want}", p.eval(x));
        assert_eq!(p.terms().len(), 4);
        assert_eq!((p.clone() - p).terms().len(), 0);
    }
}
