//! Four evaluations at once: the kernels in [`F64x4`], four independent `f64` lanes.
//!
//! A loop integrand that needs the same kernel at several configurations (e.g. the four antithetic images
//! of a quasi-Monte-Carlo point) evaluates them together: the straight-line generated code then runs each
//! statement on four lanes, which the compiler maps to SIMD instructions (two SSE2 or one AVX operation),
//! and the divisions, the slowest statements, overlap. Each lane gives exactly the `f64` result.

use crate::{generated, Scalar};
use std::ops::{Add, Div, Mul, Neg, Sub};

/// Four `f64` lanes, operated on lane by lane.
#[derive(Clone, Copy, Debug, PartialEq, Default)]
pub struct F64x4(pub [f64; 4]);

impl F64x4 {
    /// All four lanes equal to `x`.
    #[inline(always)]
    pub const fn splat(x: f64) -> Self {
        Self([x; 4])
    }
}

macro_rules! lanewise {
    ($($trait:ident $method:ident $op:tt),*) => {$(
        impl $trait for F64x4 {
            type Output = Self;
            #[inline(always)]
            fn $method(self, rhs: Self) -> Self {
                let (a, b) = (self.0, rhs.0);
                Self([a[0] $op b[0], a[1] $op b[1], a[2] $op b[2], a[3] $op b[3]])
            }
        }
    )*};
}

lanewise!(Add add +, Sub sub -, Mul mul *, Div div /);

impl Neg for F64x4 {
    type Output = Self;
    #[inline(always)]
    fn neg(self) -> Self {
        Self(self.0.map(|x| -x))
    }
}

impl Scalar for F64x4 {
    #[inline(always)]
    fn from_ratio(num: i64, den: i64) -> Self {
        Self::splat(num as f64 / den as f64)
    }
    #[inline(always)]
    fn safe_recip(&self) -> Self {
        Self(self.0.map(|x| if x == 0.0 { 0.0 } else { 1.0 / x }))
    }
    /// True if every lane is exactly zero.
    #[inline(always)]
    fn is_zero(&self) -> bool {
        self.0 == [0.0; 4]
    }
}

/// Transposes four Gram rows into lanes.
#[inline(always)]
fn lanes<const N: usize>(g: &[[f64; N]; 4]) -> [F64x4; N] {
    std::array::from_fn(|i| F64x4([g[0][i], g[1][i], g[2][i], g[3][i]]))
}

/// Transposes lanes back into four `[F^s, G^s]`.
#[inline(always)]
fn rows(v: [F64x4; 2]) -> [[f64; 2]; 4] {
    std::array::from_fn(|l| [v[0].0[l], v[1].0[l]])
}

macro_rules! four_at_once {
    ($($(#[$doc:meta])* $name:ident = $kernel:ident: $n:literal;)*) => {$(
        $(#[$doc])*
        ///
        /// Four Gram rows in, four `[F^s, G^s]` out; each equals the single `f64` evaluation.
        pub fn $name(g: &[[f64; $n]; 4]) -> [[f64; 2]; 4] {
            rows(generated::$kernel(&lanes(g)))
        }
    )*};
}

four_at_once! {
    /// [`crate::mode_coupling_3`] at four configurations.
    mode_coupling_3_x4 = mode_coupling_3: 6;
    /// [`crate::mode_coupling_4`] at four configurations.
    mode_coupling_4_x4 = mode_coupling_4: 6;
    /// [`crate::propagator_5`] at four configurations.
    propagator_5_x4 = propagator_5: 6;
    /// [`crate::propagator_7`] at four configurations.
    propagator_7_x4 = propagator_7: 10;
}

#[cfg(test)]
mod tests {
    use super::*;

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
            assert_eq!(p7[l], crate::propagator_7(&g7[l]), "lane {l}");
        }
    }
}
