//! The one place the kernel generator runs.
//!
//! Every function here is `name<T: Scalar + Copy>(g: &[T; N]) -> [T; 2]`: it takes the Gram matrix of its basis
//! vectors (upper triangle, row-major; the order is in `NAME_INFO.inputs` and in each function's docs)
//! and returns `[F^s, G^s]`; the `redshift_n` functions return the n + 1 coefficients of Z_n in f
//! (`[T; n + 1]`). Nothing here is hand-written: the bodies are flattened straight-line code emitted by `kernelgen` from the symmetrised subset recursion, with exact rational coefficients. The
//! `_paired` functions take the Gram matrix as lane scalars and run in a [`PairScalar`] (see there).
#![allow(clippy::all, clippy::pedantic, unused_parens, missing_docs)]

use crate::{KernelInfo, PairScalar, Scalar};

kernelgen::kernels! {
    scalar = Scalar;
    info = KernelInfo;
    pair = PairScalar;

    /// F_1^s = G_1^s = 1.
    general_1 = free(1);
    /// F_2^s, G_2^s of two free vectors.
    general_2 = free(2);
    /// F_3^s, G_3^s of three free vectors.
    general_3 = free(3);
    /// F_4^s, G_4^s of four free vectors.
    general_4 = free(4);
    /// F_5^s, G_5^s of five free vectors.
    general_5 = free(5);
    /// F_6^s, G_6^s of six free vectors.
    general_6 = free(6);
    /// F_7^s, G_7^s of seven free vectors.
    general_7 = free(7);

    /// The P13 propagator kernel F_3^s(k, q, −q).
    propagator_3 = propagator(1);
    /// The P15 propagator kernel F_5^s(k, q1, −q1, q2, −q2).
    propagator_5 = propagator(2);
    /// The P17 propagator kernel F_7^s(k, q1, −q1, q2, −q2, q3, −q3).
    propagator_7 = propagator(3);
    /// The P17 propagator kernel in lane pairs: one evaluation, lane 1 running the mirror image of lane 0
    /// under a symmetry of the arguments (`pt_kernels::propagator_7` for `f64` runs it in [`crate::F64x2`]).
    propagator_7_paired = propagator(3) paired;

    /// Z_1(q1; f, los) = 1 + f μ1², as `[1, μ1²]`.
    redshift_1 = redshift(1);
    /// Z_2(q1, q2; f, los) as its coefficients in f.
    redshift_2 = redshift(2);
    /// Z_3(q1, q2, q3; f, los) as its coefficients in f.
    redshift_3 = redshift(3);
    /// Z_4(q1, …, q4; f, los) as its coefficients in f.
    redshift_4 = redshift(4);
    /// Z_5(q1, …, q5; f, los) as its coefficients in f.
    redshift_5 = redshift(5);

    /// The P22 mode-coupling kernel F_2^s(q, k − q).
    mode_coupling_2 = basis(k, q) args(q, k - q);
    /// The P33 mode-coupling kernel F_3^s(q1, q2, k − q1 − q2).
    mode_coupling_3 = basis(k, q1, q2) args(q1, q2, k - q1 - q2);
    /// The P24 mode-coupling kernel F_4^s(q1, k − q1, q2, −q2).
    mode_coupling_4 = basis(k, q1, q2) args(q1, k - q1, q2, -q2);
}
