//! [`Lanes`]: N independent f64 evaluations in one pass of the generated code (SIMD-friendly batching).
//!
//! The generated kernels are generic over [`Scalar`], so running them on `Lanes<N>` evaluates N points at
//! once with element-wise arithmetic that the compiler turns into vector instructions. Integrators that
//! evaluate a kernel on many points use this for throughput; each lane gives bit-for-bit the f64 result.

use crate::Scalar;
use std::ops::{Add, Div, Mul, Neg, Sub};

/// N f64 values operated on element-wise.
#[derive(Clone, Copy, Debug, PartialEq)]
#[repr(align(64))]
pub struct Lanes<const N: usize>(pub [f64; N]);

impl<const N: usize> Lanes<N> {
    /// Every lane set to `x`.
    #[inline(always)]
    pub fn splat(x: f64) -> Self {
        Lanes([x; N])
    }

    #[inline(always)]
    fn zip(self, o: Self, f: impl Fn(f64, f64) -> f64) -> Self {
        let mut r = [0.0; N];
        for i in 0..N {
            r[i] = f(self.0[i], o.0[i]);
        }
        Lanes(r)
    }
}

macro_rules! lane_op {
    ($tr:ident, $m:ident, $op:tt) => {
        impl<const N: usize> $tr for Lanes<N> {
            type Output = Self;
            #[inline(always)]
            fn $m(self, o: Self) -> Self {
                self.zip(o, |a, b| a $op b)
            }
        }
    };
}
lane_op!(Add, add, +);
lane_op!(Sub, sub, -);
lane_op!(Mul, mul, *);
lane_op!(Div, div, /);

impl<const N: usize> Neg for Lanes<N> {
    type Output = Self;
    #[inline(always)]
    fn neg(self) -> Self {
        Lanes(self.0.map(|x| -x))
    }
}

impl<const N: usize> Scalar for Lanes<N> {
    #[inline(always)]
    fn from_ratio(num: i64, den: i64) -> Self {
        Lanes::splat(num as f64 / den as f64)
    }
    #[inline(always)]
    fn safe_recip(&self) -> Self {
        Lanes(self.0.map(|x| if x == 0.0 { 0.0 } else { 1.0 / x }))
    }
    #[inline(always)]
    fn is_zero(&self) -> bool {
        self.0.iter().all(|&x| x == 0.0)
    }
}
