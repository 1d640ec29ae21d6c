//! Several evaluations at once: the kernels in SIMD lanes, [`F64x2`] (two `f64`, one SSE2 register) and
//! [`F64x4`] (four, two registers).
//!
//! A loop integrand that needs the same kernel at several configurations (e.g. the four antithetic images
//! of a quasi-Monte-Carlo point, or the four random shifts of an angular rule) evaluates them together:
//! the straight-line generated code then runs each statement on all lanes at once (packed SSE2 operations
//! from the `wide` crate, since this crate forbids the `unsafe` of `std::arch`), and the divisions, the
//! slowest statements, overlap. Each lane gives exactly the result of the direct `f64` program
//! (`generated::name::<f64>`; for P17 the single `f64` call instead runs the paired program, one evaluation
//! in two lanes, equal to it to rounding: see `kernelgen_core::pairing`).
//!
//! The `_x4` functions take four configurations: the smaller kernels in one call of [`F64x4`], the P17
//! kernel in two calls of [`F64x2`]. [`F64x2`] is a SIMD vector to rustc, so each statement stays an SSA
//! value in registers, as with `f64`; [`F64x4`], two vectors, is an aggregate, so each statement is a stack
//! slot that LLVM's SROA takes apart again, superlinearly in the function's length. For the 4,485
//! statements of `propagator_7` that took ~35 s to compile (with a `[f64; 4]` lane type before), and the
//! code moved every lane through memory: two calls of [`F64x2`] compile in seconds and run 1.5–1.8× faster per
//! configuration. For the few hundred statements of the others, one call of four lanes is the faster.

use crate::{generated, PairScalar, Scalar};
use std::ops::{Add, Div, Mul, Neg, Sub};
use wide::{f64x2, f64x4, CmpEq};

/// Two `f64` lanes, operated on lane by lane (one packed SSE2 instruction per operation on x86_64).
#[derive(Clone, Copy, Debug, Default)]
pub struct F64x2(pub f64x2);

impl F64x2 {
    /// The lanes `[a, b]`.
    #[inline(always)]
    pub fn new(lanes: [f64; 2]) -> Self {
        Self(f64x2::from(lanes))
    }

    /// All lanes equal to `x`.
    #[inline(always)]
    pub fn splat(x: f64) -> Self {
        Self(f64x2::splat(x))
    }

    /// The two lanes.
    #[inline(always)]
    pub fn to_array(self) -> [f64; 2] {
        self.0.to_array()
    }
}

/// Lane-wise equality of the values (as `f64`: 0.0 == −0.0, NaN ≠ NaN).
impl PartialEq for F64x2 {
    fn eq(&self, other: &Self) -> bool {
        self.to_array() == other.to_array()
    }
}

macro_rules! lanewise {
    ($($trait:ident $method:ident $op:tt),*) => {$(
        impl $trait for F64x2 {
            type Output = Self;
            #[inline(always)]
            fn $method(self, rhs: Self) -> Self {
                Self(self.0 $op rhs.0)
            }
        }
    )*};
}

lanewise!(Add add +, Sub sub -, Mul mul *, Div div /);

macro_rules! lanewise4 {
    ($($trait:ident $method:ident $op:tt),*) => {$(
        impl $trait for F64x4 {
            type Output = Self;
            #[inline(always)]
            fn $method(self, rhs: Self) -> Self {
                Self(self.0 $op rhs.0)
            }
        }
    )*};
}

impl Neg for F64x2 {
    type Output = Self;
    #[inline(always)]
    fn neg(self) -> Self {
        Self(-self.0)
    }
}

impl PairScalar for F64x2 {
    type Lane = f64;
    #[inline(always)]
    fn pair(a: f64, b: f64) -> Self {
        Self::new([a, b])
    }
    #[inline(always)]
    fn swap(self) -> Self {
        let [a, b] = self.to_array();
        Self::new([b, a])
    }
    #[inline(always)]
    fn lane(self, i: usize) -> f64 {
        self.to_array()[i]
    }
}

impl Scalar for F64x2 {
    #[inline(always)]
    fn from_ratio(num: i64, den: i64) -> Self {
        Self::splat(num as f64 / den as f64)
    }
    /// 1/x in each lane, and +0 where the lane is ±0 (as `f64::safe_recip`).
    #[inline(always)]
    fn safe_recip(&self) -> Self {
        let zero = f64x2::splat(0.0);
        let recip = f64x2::splat(1.0) / self.0;
        Self(self.0.cmp_eq(zero).blend(zero, recip))
    }
    /// True if every lane is exactly zero.
    #[inline(always)]
    fn is_zero(&self) -> bool {
        self.to_array() == [0.0; 2]
    }
}

/// Four `f64` lanes, operated on lane by lane (two packed SSE2 instructions per operation on x86_64).
#[derive(Clone, Copy, Debug, Default)]
pub struct F64x4(pub f64x4);

impl F64x4 {
    /// All lanes equal to `x`.
    #[inline(always)]
    pub fn splat(x: f64) -> Self {
        Self(f64x4::splat(x))
    }

    /// The four lanes.
    #[inline(always)]
    pub fn to_array(self) -> [f64; 4] {
        self.0.to_array()
    }
}

/// Lane-wise equality of the values (as `f64`: 0.0 == −0.0, NaN ≠ NaN).
impl PartialEq for F64x4 {
    fn eq(&self, other: &Self) -> bool {
        self.to_array() == other.to_array()
    }
}

lanewise4!(Add add +, Sub sub -, Mul mul *, Div div /);

impl Neg for F64x4 {
    type Output = Self;
    #[inline(always)]
    fn neg(self) -> Self {
        Self(-self.0)
    }
}

impl Scalar for F64x4 {
    #[inline(always)]
    fn from_ratio(num: i64, den: i64) -> Self {
        Self::splat(num as f64 / den as f64)
    }
    /// 1/x in each lane, and +0 where the lane is ±0 (as `f64::safe_recip`).
    #[inline(always)]
    fn safe_recip(&self) -> Self {
        let zero = f64x4::splat(0.0);
        let recip = f64x4::splat(1.0) / self.0;
        Self(self.0.cmp_eq(zero).blend(zero, recip))
    }
    /// True if every lane is exactly zero.
    #[inline(always)]
    fn is_zero(&self) -> bool {
        self.to_array() == [0.0; 4]
    }
}

/// Evaluates `kernel` at four Gram rows in one call of four lanes.
#[inline(always)]
fn four_lanes<const N: usize>(
    g: &[[f64; N]; 4],
    kernel: fn(&[F64x4; N]) -> [F64x4; 2],
) -> [[f64; 2]; 4] {
    let lanes = std::array::from_fn(|i| F64x4(f64x4::from([g[0][i], g[1][i], g[2][i], g[3][i]])));
    let [f, g] = kernel(&lanes).map(F64x4::to_array);
    std::array::from_fn(|l| [f[l], g[l]])
}

/// Evaluates `kernel` at four Gram rows in two calls of two lanes.
#[inline(always)]
fn two_by_two<const N: usize>(
    g: &[[f64; N]; 4],
    kernel: fn(&[F64x2; N]) -> [F64x2; 2],
) -> [[f64; 2]; 4] {
    let pair = |a: usize| {
        let [f, g] = kernel(&std::array::from_fn(|i| F64x2::new([g[a][i], g[a + 1][i]])));
        let (f, g) = (f.to_array(), g.to_array());
        [[f[0], g[0]], [f[1], g[1]]]
    };
    let ([a, b], [c, d]) = (pair(0), pair(2));
    [a, b, c, d]
}

macro_rules! four_at_once {
    ($($(#[$doc:meta])* $name:ident = $how:ident($kernel:ident): $n:literal;)*) => {$(
        $(#[$doc])*
        ///
        /// Four Gram rows in, four `[F^s, G^s]` out; each equals the single `f64` evaluation.
        pub fn $name(g: &[[f64; $n]; 4]) -> [[f64; 2]; 4] {
            $how(g, generated::$kernel)
        }
    )*};
}

four_at_once! {
    /// [`crate::mode_coupling_3`] at four configurations.
    mode_coupling_3_x4 = four_lanes(mode_coupling_3): 6;
    /// [`crate::mode_coupling_4`] at four configurations.
    mode_coupling_4_x4 = four_lanes(mode_coupling_4): 6;
    /// [`crate::propagator_5`] at four configurations.
    propagator_5_x4 = four_lanes(propagator_5): 6;
    /// [`crate::propagator_7`] at four configurations.
    propagator_7_x4 = two_by_two(propagator_7): 10;
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn safe_recip_is_the_f64_one_in_every_lane() {
        let x = [0.0, -0.0, 2.0, -4.0];
        let bits = |v: [f64; 4]| v.map(f64::to_bits);
        let expected = bits(x.map(|x| x.safe_recip()));
        assert_eq!(
            bits(F64x4(f64x4::from(x)).safe_recip().to_array()),
            expected
        );
        let pairs =
            [F64x2::new([x[0], x[1]]), F64x2::new([x[2], x[3]])].map(|p| p.safe_recip().to_array());
        assert_eq!(
            bits([pairs[0][0], pairs[0][1], pairs[1][0], pairs[1][1]]),
            expected
        );
        assert!(F64x2::splat(0.0).is_zero() && !F64x4::splat(1.0).is_zero());
    }

    #[test]
    fn every_lane_is_the_scalar_kernel_bit_for_bit() {
        let g: [[f64; 6]; 4] = [
            [1.0, 0.3, -0.2, 0.25, 0.05, 0.5],
            [0.16, -0.04, 0.03, 0.02, -0.01, 0.03],
            [2.0, 0.7, 0.1, 0.9, -0.3, 1.4],
            [1.0, 1.0, 0.0, 1.0, 0.0, 1e-4],
        ];
        let (m3, m4) = (mode_coupling_3_x4(&g), mode_coupling_4_x4(&g));
        // Gram matrices of (k, q1, q2, q3) for the P17 kernel.
        let g7: [[f64; 10]; 4] = std::array::from_fn(|l| {
            let a = l as f64;
            let v = [
                [0.0, 0.0, 1.0],
                [0.3 + 0.1 * a, -0.2, 0.5],
                [-0.4, 0.7 * a, 0.1],
                [0.2, 0.1, -0.9 + a],
            ];
            let g = crate::gram(&v);
            g.try_into().unwrap()
        });
        let (p5, p7) = (propagator_5_x4(&g), propagator_7_x4(&g7));
        for l in 0..4 {
            assert_eq!(m3[l], crate::mode_coupling_3(&g[l]), "lane {l}");
            assert_eq!(m4[l], crate::mode_coupling_4(&g[l]), "lane {l}");
            assert_eq!(p5[l], crate::propagator_5(&g[l]), "lane {l}");
            // The lanes run the direct program; the single f64 call runs the paired one (equal to rounding).
            assert_eq!(p7[l], generated::propagator_7::<f64>(&g7[l]), "lane {l}");
            let single = crate::propagator_7(&g7[l]);
            for i in 0..2 {
                assert!(
                    (single[i] - p7[l][i]).abs() <= 1e-13 * p7[l][i].abs().max(1.0),
                    "lane {l}"
                );
            }
        }
    }
}
