//! The scalar types the generated kernels run in: `f64` (fast) and [`BigRational`] (exact).

use num_bigint::BigInt;
use num_rational::BigRational;
use num_traits::Zero;
use std::ops::{Add, Div, Mul, Neg, Sub};

/// What the generated code needs from a number type.
///
/// Implemented for `f64` and for exact [`BigRational`]; the same generated function runs in both.
pub trait Scalar:
    Clone
    + PartialEq
    + std::fmt::Debug
    + Add<Output = Self>
    + Sub<Output = Self>
    + Mul<Output = Self>
    + Div<Output = Self>
    + Neg<Output = Self>
{
    /// The rational `num/den`; exact for f64 when |num| and den are below 2^53 (the generator checks this).
    fn from_ratio(num: i64, den: i64) -> Self;
    /// `1/x`, and `0` when `x` is exactly zero: the limit every reciprocal of a subset norm needs when that
    /// subset's total momentum vanishes (its kernel factor is then exactly zero too).
    fn safe_recip(&self) -> Self;
    /// True if the value is exactly zero.
    fn is_zero(&self) -> bool;
}

impl Scalar for f64 {
    #[inline(always)]
    fn from_ratio(num: i64, den: i64) -> Self {
        num as f64 / den as f64
    }
    #[inline(always)]
    fn safe_recip(&self) -> Self {
        if *self == 0.0 {
            0.0
        } else {
            1.0 / self
        }
    }
    #[inline(always)]
    fn is_zero(&self) -> bool {
        *self == 0.0
    }
}

impl Scalar for BigRational {
    fn from_ratio(num: i64, den: i64) -> Self {
        BigRational::new(BigInt::from(num), BigInt::from(den))
    }
    fn safe_recip(&self) -> Self {
        if Zero::is_zero(self) {
            BigRational::zero()
        } else {
            self.recip()
        }
    }
    fn is_zero(&self) -> bool {
        Zero::is_zero(self)
    }
}

/// Two lanes of a scalar type, the type the paired kernels run in (see `kernelgen_core::pairing`): lane 0
/// evaluates the kernel, lane 1 its mirror image, and each statement runs on both at once.
pub trait PairScalar: Scalar + Copy {
    /// The scalar of one lane.
    type Lane: Scalar + Copy;
    /// The pair (a, b).
    fn pair(a: Self::Lane, b: Self::Lane) -> Self;
    /// (b, a) from (a, b).
    fn swap(self) -> Self;
    /// Lane `i` (0 or 1).
    fn lane(self, i: usize) -> Self::Lane;
}

/// Two lanes of any scalar, operated on one after the other: the paired kernels in exact arithmetic
/// (tests), or anywhere a packed type is not wanted.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Lanes2<S>(pub [S; 2]);

macro_rules! lanes2_binary {
    ($($trait:ident $method:ident),*) => {$(
        impl<S: Scalar + Copy> $trait for Lanes2<S> {
            type Output = Self;
            fn $method(self, rhs: Self) -> Self {
                Lanes2([self.0[0].$method(rhs.0[0]), self.0[1].$method(rhs.0[1])])
            }
        }
    )*};
}
lanes2_binary!(Add add, Sub sub, Mul mul, Div div);

impl<S: Scalar + Copy> Neg for Lanes2<S> {
    type Output = Self;
    fn neg(self) -> Self {
        Lanes2(self.0.map(|x| -x))
    }
}

impl<S: Scalar + Copy> Scalar for Lanes2<S> {
    fn from_ratio(num: i64, den: i64) -> Self {
        let x = S::from_ratio(num, den);
        Lanes2([x, x])
    }
    fn safe_recip(&self) -> Self {
        Lanes2(self.0.map(|x| x.safe_recip()))
    }
    fn is_zero(&self) -> bool {
        self.0.iter().all(S::is_zero)
    }
}

impl<S: Scalar + Copy> PairScalar for Lanes2<S> {
    type Lane = S;
    fn pair(a: S, b: S) -> Self {
        Lanes2([a, b])
    }
    fn swap(self) -> Self {
        Lanes2([self.0[1], self.0[0]])
    }
    fn lane(self, i: usize) -> S {
        self.0[i]
    }
}

/// `1` in any scalar type.
pub fn one<T: Scalar>() -> T {
    T::from_ratio(1, 1)
}

/// `0` in any scalar type.
pub fn zero<T: Scalar>() -> T {
    T::from_ratio(0, 1)
}

/// Dot product of two 3-vectors.
pub fn dot<T: Scalar>(a: &[T; 3], b: &[T; 3]) -> T {
    a[0].clone() * b[0].clone() + a[1].clone() * b[1].clone() + a[2].clone() * b[2].clone()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn safe_recip_is_the_reciprocal_away_from_zero() {
        assert_eq!(4.0f64.safe_recip(), 0.25);
        assert_eq!(0.0f64.safe_recip(), 0.0);
        let r = BigRational::from_ratio(-3, 7);
        assert_eq!(r.safe_recip(), BigRational::from_ratio(-7, 3));
        assert!(Scalar::is_zero(&BigRational::from_ratio(0, 5).safe_recip()));
        assert!(BigRational::from_ratio(1, 1) == one());
    }
}
