//! The standard-perturbation-theory kernels F_n^s and G_n^s for n ≤ 7, generated at build time.
//!
//! The density and velocity-divergence kernels of SPT (Goroff et al. 1986; Gil-Marín et al. 2012,
//! arXiv:1209.3771, appendix A) are produced by the `kernelgen` macro as flattened straight-line code whose
//! rational coefficients were folded in exactly at generation time; the n! symmetrisation never runs at run
//! time. Every generated function is generic over a `Copy` [`Scalar`], so it runs in `f64` (fast), in
//! [`F64x2`] lanes and in exact [`num_rational::BigRational`] arithmetic (verification; through a `Copy`
//! handle, see [`Evaluate`]) alike.
//!
//! * [`kernels`]: `[F_n^s, G_n^s](q_1, …, q_n)` of free 3-vectors, n = 1..=7, any scalar type;
//! * [`propagator_3`], [`propagator_5`], [`propagator_7`] (P13, P15, P17: F_{2x+1}^s(k, q1, −q1, …)) and
//!   [`mode_coupling_2`], [`mode_coupling_3`], [`mode_coupling_4`] (P22, P33, P24): the specialised kernels
//!   of the loop integrals, taking the scalar invariants k², k·q_i, q_i·q_j an integrator has;
//!   [`mode_coupling_3_x4`], [`mode_coupling_4_x4`], [`propagator_5_x4`], [`propagator_7_x4`] evaluate four
//!   configurations at once ([`F64x4`], [`F64x2`] lanes);
//! * [`generated`]: the raw generic functions behind all of these. Prefer the wrappers above: they call
//!   instances compiled once in this crate for `f64` and `BigRational` ([`Evaluate`]), whereas a direct
//!   call instantiates a kernel of up to ~9,000 statements anew in the calling crate;
//! * [`reference`](mod@reference): a slow, obviously correct evaluator (the unsymmetrised recursion averaged over all n!
//!   permutations), the oracle the generated code is tested against.
//!
//! ```
//! use pt_kernels::{kernels, propagator_3};
//! // F_2^s and G_2^s of two perpendicular unit vectors: 5/7 + 2/7·0 and 3/7.
//! let [f2, g2] = kernels(&[[1.0, 0.0, 0.0], [0.0, 1.0, 0.0]]).unwrap();
//! assert!((f2 - 5.0 / 7.0).abs() < 1e-15 && (g2 - 3.0 / 7.0).abs() < 1e-15);
//! // The P13 kernel from invariants [k·k, k·q, q·q].
//! let [f3, _g3] = propagator_3(&[1.0, 0.3, 0.25]);
//! assert!(f3.is_finite());
//! ```

pub mod exact;
pub mod generated;
mod instances;
mod lanes;
pub mod redshift;
pub mod reference;
mod scalar;

pub use instances::Evaluate;
pub use lanes::{
    mode_coupling_3_x4, mode_coupling_4_x4, propagator_5_x4, propagator_7_x4, F64x2, F64x4,
};

pub use scalar::{dot, one, zero, Lanes2, PairScalar, Scalar};

/// Largest kernel order generated.
pub const MAX_ORDER: usize = 7;

/// How a generated kernel was made (one constant per generated function, `NAME_INFO`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct KernelInfo {
    /// Function name.
    pub name: &'static str,
    /// Kernel order n.
    pub order: usize,
    /// The arguments as combinations of the basis vectors, e.g. `["k", "q1", "-q1"]`.
    pub arguments: &'static [&'static str],
    /// The inputs, e.g. `["k.k", "k.q1", "q1.q1"]`.
    pub inputs: &'static [&'static str],
    /// Straight-line statements emitted.
    pub statements: usize,
    /// Multiplications per evaluation.
    pub multiplications: usize,
    /// Additions and subtractions per evaluation.
    pub additions: usize,
    /// Reciprocals (divisions) per evaluation.
    pub reciprocals: usize,
    /// Distinct sub-kernels the recursion built.
    pub subkernels: usize,
    /// Subsets with identically zero momentum, removed at generation time.
    pub zero_momentum_subsets: usize,
    /// Subset splits the recursion visited.
    pub splits: usize,
    /// Generator name and version.
    pub generator: &'static str,
}

/// Why a kernel cannot be evaluated.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
#[non_exhaustive]
pub enum KernelError {
    /// No argument, or more than [`MAX_ORDER`].
    #[error("kernel order n = {0} is not supported: n must be between 1 and {MAX_ORDER}")]
    Order(usize),
    /// An argument is the zero vector, where the kernels have a pole.
    #[error("argument q{0} is the zero vector; the kernels are singular there")]
    ZeroVector(usize),
    /// The line of sight of a redshift-space kernel is the zero vector.
    #[error("the line of sight is the zero vector: it needs a direction")]
    ZeroLineOfSight,
}

/// The metadata of the general kernel of order n (1..=7).
pub fn general_info(n: usize) -> Option<&'static KernelInfo> {
    use generated::*;
    [
        &GENERAL_1_INFO,
        &GENERAL_2_INFO,
        &GENERAL_3_INFO,
        &GENERAL_4_INFO,
        &GENERAL_5_INFO,
        &GENERAL_6_INFO,
        &GENERAL_7_INFO,
    ]
    .get(n.wrapping_sub(1))
    .copied()
}

/// The metadata of every generated kernel.
pub fn all_info() -> Vec<&'static KernelInfo> {
    use generated::*;
    let mut v: Vec<&'static KernelInfo> = (1..=MAX_ORDER).filter_map(general_info).collect();
    v.extend([
        &PROPAGATOR_3_INFO,
        &PROPAGATOR_5_INFO,
        &PROPAGATOR_7_INFO,
        &PROPAGATOR_7_PAIRED_INFO,
        &MODE_COUPLING_2_INFO,
        &MODE_COUPLING_3_INFO,
        &MODE_COUPLING_4_INFO,
        &REDSHIFT_1_INFO,
        &REDSHIFT_2_INFO,
        &REDSHIFT_3_INFO,
        &REDSHIFT_4_INFO,
        &REDSHIFT_5_INFO,
    ]);
    v
}

/// The Gram matrix of `vectors` (upper triangle, row-major): the input layout of every generated function.
pub fn gram<T: Scalar>(vectors: &[[T; 3]]) -> Vec<T> {
    let mut g = Vec::with_capacity(vectors.len() * (vectors.len() + 1) / 2);
    for (a, va) in vectors.iter().enumerate() {
        for vb in &vectors[a..] {
            g.push(dot(va, vb));
        }
    }
    g
}

/// `[F_n^s, G_n^s]` from the Gram matrix of n free vectors (layout of [`gram`]), n = 1..=7.
///
/// Subsets of the arguments whose momenta sum exactly to zero give the kernels' limit (zero contribution),
/// never NaN.
///
/// # Errors
/// [`KernelError::Order`] if n is outside 1..=7 or `g` does not have n(n+1)/2 entries.
pub fn general_from_gram<T: Evaluate>(n: usize, g: &[T]) -> Result<[T; 2], KernelError> {
    T::general(n, g)
}

/// `[F_n^s, G_n^s](q_1, …, q_n)` of n = 1..=7 free 3-vectors (k in h/Mpc; the kernels are dimensionless).
///
/// The kernels are homogeneous of degree 0: the vectors are first scaled by one common factor
/// ([`Evaluate::normalised`]), so that in `f64` vectors of any size in the floating-point range give
/// the same value as vectors of order one (a component below 2^-1022 times the largest is lost).
///
/// # Errors
/// n outside 1..=7, or a zero vector. Subsets summing exactly to zero momentum are fine.
pub fn kernels<T: Evaluate>(q: &[[T; 3]]) -> Result<[T; 2], KernelError> {
    if q.is_empty() || q.len() > MAX_ORDER {
        return Err(KernelError::Order(q.len()));
    }
    if let Some(i) = q.iter().position(|v| v.iter().all(Scalar::is_zero)) {
        return Err(KernelError::ZeroVector(i + 1));
    }
    general_from_gram(q.len(), &gram(&T::normalised(q)))
}

macro_rules! specialised {
    ($($(#[$doc:meta])* $name:ident: $n:literal;)*) => {$(
        $(#[$doc])*
        ///
        /// Returns `[F^s, G^s]`; the generated code, compiled once in this crate for `f64` and `BigRational`.
        pub fn $name<T: Evaluate>(g: &[T; $n]) -> [T; 2] {
            T::$name(g)
        }
    )*};
}

specialised! {
    /// The P13 propagator kernel F_3^s(k, q, −q) from [k·k, k·q, q·q].
    propagator_3: 3;
    /// The P15 propagator kernel F_5^s(k, q1, −q1, q2, −q2) from [k·k, k·q1, k·q2, q1·q1, q1·q2, q2·q2].
    propagator_5: 6;
    /// The P17 propagator kernel F_7^s(k, q1, −q1, q2, −q2, q3, −q3) from the Gram matrix of (k, q1, q2, q3).
    propagator_7: 10;
    /// The P22 mode-coupling kernel F_2^s(q, k − q) from [k·k, k·q, q·q].
    mode_coupling_2: 3;
    /// The P33 mode-coupling kernel F_3^s(q1, q2, k − q1 − q2) from the Gram matrix of (k, q1, q2).
    mode_coupling_3: 6;
    /// The P24 mode-coupling kernel F_4^s(q1, k − q1, q2, −q2) from the Gram matrix of (k, q1, q2).
    mode_coupling_4: 6;
}

#[cfg(test)]
mod tests {
    use super::*;

    /// F_2^s(q1, q2) of orthogonal unit vectors is 5/7 and G_2^s 3/7 exactly: the same at any scale of
    /// the vectors, down to the subnormal range and up to the top of f64.
    #[test]
    fn kernels_of_tiny_and_huge_vectors_are_those_of_unit_vectors() {
        for s in [1e-320, 1e-170, 1e-100, 1.0, 1e100, 1e170, 1e300] {
            let [f, g] = kernels(&[[s, 0.0, 0.0], [0.0, s, 0.0]]).unwrap();
            let exact = [5.0 / 7.0, 3.0 / 7.0];
            assert!(
                (f - exact[0]).abs() < 1e-15 && (g - exact[1]).abs() < 1e-15,
                "scale {s}"
            );
        }
        // A general configuration: scaling all vectors by a power of ten changes at most rounding.
        let q = [[0.3, -0.1, 0.2], [0.05, 0.4, -0.3], [-0.2, 0.1, 0.15]];
        let reference = kernels(&q).unwrap();
        for s in [1e-200, 1e-150, 1e150, 1e200] {
            let scaled: Vec<[f64; 3]> = q.iter().map(|v| v.map(|c| c * s)).collect();
            let value = kernels(&scaled).unwrap();
            for (a, b) in value.iter().zip(&reference) {
                assert!((a - b).abs() <= 1e-13 * b.abs(), "scale {s}: {a} vs {b}");
            }
        }
    }
}

/// Length ratio of the vectors above which [`cancellation_note`] warns.
pub const CANCELLATION_RATIO: f64 = 1e3;

/// A warning for `f64` vectors whose lengths differ by more than [`CANCELLATION_RATIO`]: the kernels'
/// Gram-matrix form then cancels large terms, and the `f64` result loses digits (F_2^s of orthogonal
/// vectors is 3e-11 off at length ratio 1e3, 2e-9 at 1e4, 3e-8 at 1e5, 35% at 1e9); exact rationals
/// do not.
pub fn cancellation_note(q: &[[f64; 3]]) -> Option<String> {
    let lengths: Vec<f64> = q
        .iter()
        .map(|v| v.iter().map(|c| c.abs()).fold(0.0, f64::max))
        .collect();
    let (min, max) = lengths
        .iter()
        .fold((f64::INFINITY, 0.0_f64), |(a, b), &l| (a.min(l), b.max(l)));
    let ratio = max / min;
    (min > 0.0 && ratio > CANCELLATION_RATIO).then(|| {
        format!(
            "the vectors' lengths differ by a factor {ratio:.1e}: in f64 the kernel loses digits to \
             cancellation (F_2 of orthogonal vectors: 2e-9 off at 1e4, 3e-8 at 1e5, 35% at 1e9); exact rational arithmetic (--exact, exact=True) has no such loss"
        )
    })
}

#[cfg(test)]
mod cancellation_tests {
    use super::*;

    #[test]
    fn unequal_lengths_are_noted_and_the_figures_quoted_hold() {
        assert!(cancellation_note(&[[1.0, 0.0, 0.0], [0.0, 1e-3, 0.0]]).is_none());
        let note = cancellation_note(&[[1.0, 0.0, 0.0], [0.0, 1e-5, 0.0]]).unwrap();
        assert!(note.contains("1.0e5"), "{note}");
        // The errors the note quotes, within a factor of a few.
        for (ratio, quoted) in [(1e4, 2e-9), (1e5, 3e-8)] {
            let [f, _] = kernels(&[[1.0 / ratio, 0.0, 0.0], [0.0, 1.0, 0.0]]).unwrap();
            let error = (f - 5.0 / 7.0).abs() / (5.0 / 7.0);
            assert!(error < 5.0 * quoted, "ratio {ratio}: {error:e}");
        }
    }
}
