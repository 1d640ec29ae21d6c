//! [`Estimate`]: a computed value with a bound on its numerical error, and its arithmetic.
//!
//! Errors propagate linearly (first order, worst case): δ(a ± b) = δa + δb, δ(ab) = |b|δa + |a|δb,
//! δ(ca) = |c|δa. They are bounds on integration and quadrature errors, which are not independent from
//! one term to the next (the same lattice and rules serve every term), so they add rather than add in
//! quadrature.
//!
//! ```
//! use pt_spectra::estimate::Estimate;
//! let (a, b) = (Estimate::new(2.0, 0.1), Estimate::new(-3.0, 0.2));
//! assert_eq!(a + b, Estimate::new(-1.0, 0.1 + 0.2));
//! assert_eq!(a * b, Estimate::new(-6.0, 2.0 * 0.2 + 3.0 * 0.1));
//! assert_eq!(2.0 * b, Estimate::new(-6.0, 0.4));
//! assert_eq!(a + 1.0, Estimate::new(3.0, 0.1)); // an exact number adds no error
//! ```

use std::iter::Sum;
use std::ops::{Add, AddAssign, Div, Mul, Neg, Sub};

/// A computed value with an estimate of its numerical error (same units).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Estimate {
    /// The value.
    pub value: f64,
    /// The estimated absolute numerical error (≥ 0).
    pub error: f64,
}

impl Estimate {
    /// A value with its error estimate.
    pub const fn new(value: f64, error: f64) -> Self {
        Self { value, error }
    }

    /// An exact value (error 0).
    pub const fn exact(value: f64) -> Self {
        Self { value, error: 0.0 }
    }

    /// The mean of two estimates, errors averaged: the δθ propagator terms are the means of the δδ and
    /// θθ ones (P1n_δθ = (P1n_δδ + P1n_θθ)/2).
    pub fn mean(a: Self, b: Self) -> Self {
        0.5 * (a + b)
    }

    /// The error relative to |value| (∞ if the value is 0 and the error is not).
    pub fn relative_error(&self) -> f64 {
        if self.error == 0.0 {
            0.0
        } else {
            self.error / self.value.abs()
        }
    }

    /// The estimate with the smaller error (the first if they are equal).
    pub fn more_precise(self, other: Self) -> Self {
        if other.error < self.error {
            other
        } else {
            self
        }
    }
}

impl From<f64> for Estimate {
    fn from(value: f64) -> Self {
        Self::exact(value)
    }
}

impl Add for Estimate {
    type Output = Self;
    fn add(self, rhs: Self) -> Self {
        Self::new(self.value + rhs.value, self.error + rhs.error)
    }
}

impl Add<f64> for Estimate {
    type Output = Self;
    fn add(self, rhs: f64) -> Self {
        Self::new(self.value + rhs, self.error)
    }
}

impl Add<Estimate> for f64 {
    type Output = Estimate;
    fn add(self, rhs: Estimate) -> Estimate {
        rhs + self
    }
}

impl AddAssign for Estimate {
    fn add_assign(&mut self, rhs: Self) {
        *self = *self + rhs;
    }
}

impl Sub for Estimate {
    type Output = Self;
    fn sub(self, rhs: Self) -> Self {
        Self::new(self.value - rhs.value, self.error + rhs.error)
    }
}

impl Neg for Estimate {
    type Output = Self;
    fn neg(self) -> Self {
        Self::new(-self.value, self.error)
    }
}

impl Mul for Estimate {
    type Output = Self;
    /// δ(ab) = |a|δb + |b|δa.
    fn mul(self, rhs: Self) -> Self {
        Self::new(
            self.value * rhs.value,
            self.value.abs() * rhs.error + rhs.value.abs() * self.error,
        )
    }
}

impl Mul<f64> for Estimate {
    type Output = Self;
    fn mul(self, rhs: f64) -> Self {
        Self::new(self.value * rhs, self.error * rhs.abs())
    }
}

impl Mul<Estimate> for f64 {
    type Output = Estimate;
    fn mul(self, rhs: Estimate) -> Estimate {
        rhs * self
    }
}

impl Div<f64> for Estimate {
    type Output = Self;
    fn div(self, rhs: f64) -> Self {
        Self::new(self.value / rhs, self.error / rhs.abs())
    }
}

impl Sum for Estimate {
    fn sum<I: Iterator<Item = Self>>(iter: I) -> Self {
        iter.fold(Self::default(), Add::add)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn errors_add_linearly_and_scale_with_the_absolute_factor() {
        let (a, b) = (Estimate::new(2.0, 0.1), Estimate::new(-3.0, 0.2));
        assert_eq!(a - b, Estimate::new(5.0, 0.1 + 0.2));
        assert_eq!(-a, Estimate::new(-2.0, 0.1));
        assert_eq!(a * -2.0, Estimate::new(-4.0, 0.2));
        assert_eq!([a, b, a].into_iter().sum::<Estimate>(), a + b + a);
        assert_eq!(Estimate::mean(a, b), Estimate::new(-0.5, 0.5 * (0.1 + 0.2)));
        assert_eq!(a.more_precise(b), a);
        assert_eq!(b.more_precise(a), a);
        // The product's error is the first-order change under the worst-case shifts.
        let worst = (2.1_f64 * -3.2 - a.value * b.value).abs();
        assert!(((a * b).error - worst).abs() < 0.1 * 0.2 + 1e-15);
    }
}
