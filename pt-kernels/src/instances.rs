//! The generated kernels compiled once, here, for `f64` and for exact [`BigRational`].
//!
//! The functions in [`crate::generated`] are generic, and in an optimised build Rust compiles a generic
//! function anew in every crate that calls it. For kernels of up to ~9,000 straight-line statements that
//! costs seconds to a minute per crate and kernel, and for `BigRational`, whose arithmetic LLVM inlines
//! into every statement, ten minutes and ~10 GB each. [`Evaluate`] fixes both: its impls for `f64` and
//! `BigRational` are ordinary functions of this crate, so every kernel is compiled exactly once, and exact
//! arithmetic runs through `Exact`, a `Copy` handle to a `BigRational` on a per-thread tape whose
//! operations are outlined calls (same values; big-integer arithmetic dwarfs a call), a body LLVM
//! optimises quickly. (The generated functions require `T: Copy`, which `Exact` is and `BigRational` is
//! not: see `kernelgen_core::emit` for why.)

use crate::generated;
use crate::{F64x2, KernelError, Scalar};
use num_rational::BigRational;
use std::ops::{Add, Div, Mul, Neg, Sub};

/// Scalar types for which every generated kernel is compiled in this crate: `f64` and `BigRational`.
///
/// Each method is the generated function of the same name in [`crate::generated`] (see there for the
/// input layout: the upper triangle of the basis Gram matrix), returning `[F^s, G^s]`.
pub trait Evaluate: Scalar {
    /// `[F_n^s, G_n^s]` of n = 1..=7 free vectors from their Gram matrix (n(n+1)/2 entries).
    ///
    /// # Errors
    /// [`KernelError::Order`] if n is outside 1..=7 or `g` does not have n(n+1)/2 entries.
    fn general(n: usize, g: &[Self]) -> Result<[Self; 2], KernelError>;
    /// The coefficients `[Z^(0), …, Z^(n)]` of the redshift-space kernel Z_n = Σ_m f^m Z^(m), n = 1..=5,
    /// from the Gram matrix of (q_1, …, q_n, line of sight) ((n+1)(n+2)/2 entries; see
    /// [`generated::redshift_5`] for the order).
    ///
    /// # Errors
    /// [`KernelError::Order`] if n is outside 1..=5 or `g` has the wrong length.
    fn redshift(n: usize, g: &[Self]) -> Result<Vec<Self>, KernelError>;
    /// F_3^s(k, q, −q) from [k·k, k·q, q·q].
    fn propagator_3(g: &[Self; 3]) -> [Self; 2];
    /// F_5^s(k, q1, −q1, q2, −q2) from [k·k, k·q1, k·q2, q1·q1, q1·q2, q2·q2].
    fn propagator_5(g: &[Self; 6]) -> [Self; 2];
    /// F_7^s(k, q1, −q1, q2, −q2, q3, −q3) from the 10 Gram entries of (k, q1, q2, q3).
    fn propagator_7(g: &[Self; 10]) -> [Self; 2];
    /// F_2^s(q, k − q) from [k·k, k·q, q·q].
    fn mode_coupling_2(g: &[Self; 3]) -> [Self; 2];
    /// F_3^s(q1, q2, k − q1 − q2) from the 6 Gram entries of (k, q1, q2).
    fn mode_coupling_3(g: &[Self; 6]) -> [Self; 2];
    /// F_4^s(q1, k − q1, q2, −q2) from the 6 Gram entries of (k, q1, q2).
    fn mode_coupling_4(g: &[Self; 6]) -> [Self; 2];
    /// The vectors as [`kernels`](crate::kernels) evaluates them: the kernels are homogeneous of
    /// degree 0, so any common factor may be taken out. Exact types keep them; `f64` scales them by
    /// the power of two that brings the largest component to [1, 2), so that the dot products of tiny
    /// (1e-170) or huge (1e170) vectors neither underflow nor overflow, and the scaling itself is exact
    /// (unless it would flush a component below the normal range: then they are kept as they are).
    fn normalised(q: &[[Self; 3]]) -> Vec<[Self; 3]> {
        q.to_vec()
    }
}

/// Calls the generated general kernel of order n with a slice of the right length.
fn general_dispatch<T: Scalar + Copy>(n: usize, g: &[T]) -> Result<[T; 2], KernelError> {
    fn call<T: Scalar + Copy, const N: usize>(g: &[T], f: fn(&[T; N]) -> [T; 2]) -> [T; 2] {
        f(g.try_into().expect("length checked by the caller"))
    }
    if g.len() != n * (n + 1) / 2 {
        return Err(KernelError::Order(n));
    }
    use generated::*;
    Ok(match n {
        1 => call(g, general_1),
        2 => call(g, general_2),
        3 => call(g, general_3),
        4 => call(g, general_4),
        5 => call(g, general_5),
        6 => call(g, general_6),
        7 => call(g, general_7),
        _ => return Err(KernelError::Order(n)),
    })
}

/// Calls the generated redshift-space kernel of order n with a slice of the right length.
fn redshift_dispatch<T: Scalar + Copy>(n: usize, g: &[T]) -> Result<Vec<T>, KernelError> {
    fn call<T: Scalar + Copy, const N: usize, const M: usize>(
        g: &[T],
        f: fn(&[T; N]) -> [T; M],
    ) -> Vec<T> {
        f(g.try_into().expect("length checked by the caller")).to_vec()
    }
    if g.len() != (n + 1) * (n + 2) / 2 {
        return Err(KernelError::Order(n));
    }
    use generated::*;
    Ok(match n {
        1 => call(g, redshift_1),
        2 => call(g, redshift_2),
        3 => call(g, redshift_3),
        4 => call(g, redshift_4),
        5 => call(g, redshift_5),
        _ => return Err(KernelError::Order(n)),
    })
}

impl Evaluate for f64 {
    fn normalised(q: &[[f64; 3]]) -> Vec<[f64; 3]> {
        let largest = q.iter().flatten().fold(0.0_f64, |m, c| m.max(c.abs()));
        if !(largest.is_finite() && largest > 0.0) {
            return q.to_vec();
        }
        // 2^-e with e the binary exponent of the largest component, applied in two exact steps
        // (2^±1074 is not representable in one factor).
        let e = largest.log2().floor() as i32;
        let (a, b) = (e / 2, e - e / 2);
        let scale = |v: f64| v * 2f64.powi(-a) * 2f64.powi(-b);
        let scaled: Vec<[f64; 3]> = q.iter().map(|v| v.map(scale)).collect();
        // A component flushed to zero (or to the subnormal range) would change the configuration,
        // e.g. turn a tiny partial sum of momenta into an exact zero: keep the vectors as they are, so
        // that the overflow is reported rather than a different configuration evaluated.
        let flushed = q
            .iter()
            .flatten()
            .zip(scaled.iter().flatten())
            .any(|(&c, &s)| c != 0.0 && !s.is_normal());
        if flushed {
            q.to_vec()
        } else {
            scaled
        }
    }
    fn general(n: usize, g: &[f64]) -> Result<[f64; 2], KernelError> {
        general_dispatch(n, g)
    }
    fn redshift(n: usize, g: &[f64]) -> Result<Vec<f64>, KernelError> {
        redshift_dispatch(n, g)
    }
    fn propagator_3(g: &[f64; 3]) -> [f64; 2] {
        generated::propagator_3(g)
    }
    fn propagator_5(g: &[f64; 6]) -> [f64; 2] {
        generated::propagator_5(g)
    }
    /// In one call of [`F64x2`] lane pairs, lane 1 running the mirror image (see
    /// [`generated::propagator_7_paired`]): equal to the direct program to rounding.
    fn propagator_7(g: &[f64; 10]) -> [f64; 2] {
        generated::propagator_7_paired::<F64x2>(g)
    }
    fn mode_coupling_2(g: &[f64; 3]) -> [f64; 2] {
        generated::mode_coupling_2(g)
    }
    fn mode_coupling_3(g: &[f64; 6]) -> [f64; 2] {
        generated::mode_coupling_3(g)
    }
    fn mode_coupling_4(g: &[f64; 6]) -> [f64; 2] {
        generated::mode_coupling_4(g)
    }
}

/// Runs a generated function in [`Exact`] arithmetic on `BigRational` inputs.
fn exact<const N: usize>(
    g: &[BigRational; N],
    f: fn(&[Exact; N]) -> [Exact; 2],
) -> [BigRational; 2] {
    tape::record(|| f(&g.clone().map(Exact::new)).map(Exact::value))
}

impl Evaluate for BigRational {
    fn general(n: usize, g: &[BigRational]) -> Result<[BigRational; 2], KernelError> {
        tape::record(|| {
            let g: Vec<Exact> = g.iter().cloned().map(Exact::new).collect();
            Ok(general_dispatch(n, &g)?.map(Exact::value))
        })
    }
    fn redshift(n: usize, g: &[BigRational]) -> Result<Vec<BigRational>, KernelError> {
        tape::record(|| {
            let g: Vec<Exact> = g.iter().cloned().map(Exact::new).collect();
            Ok(redshift_dispatch(n, &g)?
                .into_iter()
                .map(Exact::value)
                .collect())
        })
    }
    fn propagator_3(g: &[BigRational; 3]) -> [BigRational; 2] {
        exact(g, generated::propagator_3)
    }
    fn propagator_5(g: &[BigRational; 6]) -> [BigRational; 2] {
        exact(g, generated::propagator_5)
    }
    fn propagator_7(g: &[BigRational; 10]) -> [BigRational; 2] {
        exact(g, generated::propagator_7)
    }
    fn mode_coupling_2(g: &[BigRational; 3]) -> [BigRational; 2] {
        exact(g, generated::mode_coupling_2)
    }
    fn mode_coupling_3(g: &[BigRational; 6]) -> [BigRational; 2] {
        exact(g, generated::mode_coupling_3)
    }
    fn mode_coupling_4(g: &[BigRational; 6]) -> [BigRational; 2] {
        exact(g, generated::mode_coupling_4)
    }
}

/// An exact rational held on a per-thread tape: the scalar the `BigRational` instances run in.
///
/// The handle is `Copy` and every operation is an outlined call that appends its result to the tape, so
/// a generated kernel instantiated with it is a flat sequence of calls: no inlined big-integer code, no
/// drop glue and no unwinding clean-up per statement, which is what made the direct `BigRational`
/// instantiation take minutes to compile. The tape is truncated when the evaluation that filled it ends.
#[derive(Clone, Copy)]
pub(crate) struct Exact(usize);

mod tape {
    use super::Exact;
    use num_rational::BigRational;
    use std::cell::RefCell;

    thread_local! {
        static TAPE: RefCell<Vec<BigRational>> = const { RefCell::new(Vec::new()) };
    }

    /// Runs `f`, then drops every value it put on this thread's tape.
    pub(super) fn record<R>(f: impl FnOnce() -> R) -> R {
        let start = TAPE.with(|t| t.borrow().len());
        // Truncate even if `f` panics, so that a failed evaluation leaves the tape as it was.
        struct Reset(usize);
        impl Drop for Reset {
            fn drop(&mut self) {
                TAPE.with(|t| t.borrow_mut().truncate(self.0));
            }
        }
        let _reset = Reset(start);
        f()
    }

    pub(super) fn push(value: BigRational) -> Exact {
        TAPE.with(|t| {
            let mut t = t.borrow_mut();
            t.push(value);
            Exact(t.len() - 1)
        })
    }

    pub(super) fn with<R>(f: impl FnOnce(&[BigRational]) -> R) -> R {
        TAPE.with(|t| f(&t.borrow()))
    }
}

impl Exact {
    #[inline(never)]
    fn new(value: BigRational) -> Self {
        tape::push(value)
    }

    #[inline(never)]
    fn value(self) -> BigRational {
        tape::with(|t| t[self.0].clone())
    }
}

impl PartialEq for Exact {
    fn eq(&self, other: &Self) -> bool {
        tape::with(|t| t[self.0] == t[other.0])
    }
}

impl std::fmt::Debug for Exact {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        tape::with(|t| write!(f, "{}", t[self.0]))
    }
}

macro_rules! outlined_binary {
    ($($trait:ident $method:ident),*) => {$(
        impl $trait for Exact {
            type Output = Exact;
            #[inline(never)]
            fn $method(self, rhs: Exact) -> Exact {
                let value = tape::with(|t| (&t[self.0]).$method(&t[rhs.0]));
                tape::push(value)
            }
        }
    )*};
}
outlined_binary!(Add add, Sub sub, Mul mul, Div div);

impl Neg for Exact {
    type Output = Exact;
    #[inline(never)]
    fn neg(self) -> Exact {
        let value = tape::with(|t| -&t[self.0]);
        tape::push(value)
    }
}

impl Scalar for Exact {
    #[inline(never)]
    fn from_ratio(num: i64, den: i64) -> Self {
        tape::push(BigRational::from_ratio(num, den))
    }
    #[inline(never)]
    fn safe_recip(&self) -> Self {
        let value = tape::with(|t| t[self.0].safe_recip());
        tape::push(value)
    }
    #[inline(never)]
    fn is_zero(&self) -> bool {
        tape::with(|t| Scalar::is_zero(&t[self.0]))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use num_traits::ToPrimitive;

    #[test]
    fn exact_and_f64_instances_agree_on_f2() {
        // F_2^s, G_2^s of q1 = (1,0,0), q2 = (1,1,0): q1² = 1, q1·q2 = 1, q2² = 2.
        let q = |n, d| BigRational::from_ratio(n, d);
        let [f, g] = BigRational::general(2, &[q(1, 1), q(1, 1), q(2, 1)]).unwrap();
        // μ = 1/√2, k1/k2 + k2/k1 = 3/√2: F = 5/7 + 3/4 + 1/7 = 45/28, G = 3/7 + 3/4 + 2/7 = 41/28.
        assert_eq!((f, g), (q(45, 28), q(41, 28)));
        let [ff, gf] = f64::general(2, &[1.0, 1.0, 2.0]).unwrap();
        assert!((ff - 45.0 / 28.0).abs() < 1e-15 && (gf - 41.0 / 28.0).abs() < 1e-15);
        assert_eq!(f64::general(3, &[1.0]), Err(KernelError::Order(3)));
    }

    #[test]
    fn paired_p17_is_the_direct_program_exactly() {
        use crate::Lanes2;
        // Gram matrices of (k, q1, q2, q3) with small integer components, generic and degenerate
        // (q2 = q1, and q3 = k, where the mirror image of a sub-kernel can coincide with another one).
        let vectors: [[[i64; 3]; 4]; 3] = [
            [[0, 0, 2], [1, -2, 1], [-1, 3, 2], [2, 1, -3]],
            [[0, 0, 1], [1, 1, 0], [1, 1, 0], [0, 2, 1]],
            [[1, 0, 1], [0, 3, -1], [2, -1, 1], [1, 0, 1]],
        ];
        for v in vectors {
            let g: Vec<BigRational> =
                crate::gram(&v.map(|x| x.map(|c| BigRational::from_ratio(c, 1))));
            let g: [BigRational; 10] = g.try_into().unwrap();
            let direct = BigRational::propagator_7(&g);
            let paired = tape::record(|| {
                generated::propagator_7_paired::<Lanes2<Exact>>(&g.clone().map(Exact::new))
                    .map(Exact::value)
            });
            assert_eq!(paired, direct, "{v:?}");
            let gf = g.clone().map(|x| x.to_f64().unwrap());
            let (fast, reference) = (f64::propagator_7(&gf), generated::propagator_7::<f64>(&gf));
            let d = direct.map(|x| x.to_f64().unwrap());
            for i in 0..2 {
                assert!(
                    (fast[i] - d[i]).abs() <= 1e-12 * d[i].abs().max(1.0),
                    "{v:?}: {fast:?} vs {d:?}"
                );
                assert!((reference[i] - d[i]).abs() <= 1e-12 * d[i].abs().max(1.0));
            }
        }
    }
}
