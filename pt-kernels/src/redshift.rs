//! The redshift-space kernels Z_n of standard perturbation theory (Scoccimarro, Couchman & Frieman 1999,
//! arXiv:astro-ph/9808305, eqs. 6–8): the matter density in redshift space to order n,
//! δ_s(k) = Σ_n ∫ Z_n(q_1, …, q_n) δ_L(q_1)…δ_L(q_n), k = q_1 + … + q_n, from the mapping
//!
//! ```text
//! δ_s(k) = Σ_{m≥0} (f k μ)^m / m! [ (δ + f μ² θ) (μ/k θ)^m ](k),
//! ```
//!
//! with μ = n̂·k/k along the line of sight n̂ and θ the velocity divergence in units of −aHf (θ_1 = δ_1).
//! Expanding every factor to its order and symmetrising gives, for the subsets S of the arguments with
//! k_S = Σ_{i∈S} q_i, μ_S = n̂·k_S/k_S, F_S = F^s_{|S|}(q_S), G_S = G^s_{|S|}(q_S),
//!
//! ```text
//! Z_n = (1/n!) Σ_{S_0 ≠ ∅} |S_0|! D(S_0) E(complement of S_0),
//! D(S) = F_S + f μ_S² G_S,   U(S) = f (k μ) (μ_S/k_S) G_S,
//! E(R) = Σ over set partitions {B} of R of Π_B |B|! U(B),   E(∅) = 1:
//! ```
//!
//! Z_1 = 1 + fμ², Z_2 = F_2 + fμ²G_2 + (fμk/2)[μ_1/q_1 (1 + fμ_2²) + μ_2/q_2 (1 + fμ_1²)], and Z_n = F_n at
//! f = 0. Everything is rational in the dot products: (kμ)(μ_S/k_S) = (n̂·k)(n̂·k_S)/(n̂·n̂ k_S²) and
//! μ_S² = (n̂·k_S)²/(n̂·n̂ k_S²), so the line of sight need not be a unit vector and the kernels are exact
//! in [`num_rational::BigRational`]; a subset with exactly zero total momentum contributes its limit, zero
//! (F_S, G_S ∝ k_S²).
//!
//! [`redshift_coefficients`] and [`redshift_kernel`] run straight-line code that `kernelgen` emits from this
//! expansion (with the F_S, G_S recursion inlined and every rational constant folded) as the coefficients of
//! f^0 … f^n, from the Gram matrix of (q_1, …, q_n, n̂): like F_n and G_n, it runs in `f64` and exactly.
//!
//! [`brute_force_redshift`] is the oracle: the same expansion with the *unsymmetrised* kernels of
//! [`crate::reference`] on consecutive blocks of an ordering, averaged over all n! orderings (no subsets,
//! no set partitions, no factorial weights).

use crate::reference::{unsymmetrised, ReferenceError};
use crate::{dot, gram, one, zero, Evaluate, KernelError, Scalar, MAX_ORDER};

/// Largest order of the redshift-space kernels.
pub const MAX_REDSHIFT_ORDER: usize = 5;

/// Σ v over `vectors`.
fn total<T: Scalar>(vectors: &[[T; 3]]) -> [T; 3] {
    vectors.iter().fold([zero::<T>(), zero(), zero()], |a, v| {
        [
            a[0].clone() + v[0].clone(),
            a[1].clone() + v[1].clone(),
            a[2].clone() + v[2].clone(),
        ]
    })
}

fn factorial<T: Scalar>(n: usize) -> T {
    T::from_ratio((1..=n as i64).product(), 1)
}

/// The pieces of a subset: D(S) = F_S + fμ_S²G_S and U(S) = f(kμ)(μ_S/k_S)G_S.
fn pieces<T: Scalar>(f: &T, los: &[T; 3], k: &[T; 3], k_s: &[T; 3], fg: [T; 2]) -> [T; 2] {
    let [f_s, g_s] = fg;
    let norm = dot(k_s, k_s);
    if norm.is_zero() {
        // F_S, G_S vanish like k_S² and μ_S/k_S grows like 1/k_S: the limit is zero
        return [zero(), zero()];
    }
    let nn = dot(los, los);
    let (nk, ns) = (dot(los, k), dot(los, k_s));
    let d = f_s + f.clone() * ns.clone() * ns.clone() / (nn.clone() * norm.clone()) * g_s.clone();
    let u = f.clone() * nk * ns / (nn * norm) * g_s;
    [d, u]
}

fn check<T: Scalar>(q: &[[T; 3]], los: &[T; 3]) -> Result<(), KernelError> {
    if q.is_empty() || q.len() > MAX_REDSHIFT_ORDER {
        return Err(KernelError::Order(q.len()));
    }
    if let Some(i) = q.iter().position(|v| v.iter().all(Scalar::is_zero)) {
        return Err(KernelError::ZeroVector(i + 1));
    }
    if los.iter().all(Scalar::is_zero) {
        return Err(KernelError::ZeroLineOfSight);
    }
    Ok(())
}

/// The coefficients `[Z^(0), …, Z^(n)]` of Z_n(q_1, …, q_n; f, n̂) = Σ_m f^m Z^(m), n = 1..=[`MAX_REDSHIFT_ORDER`]
/// (module docs), from the generated straight-line code ([`crate::generated::redshift_5`] and its
/// siblings): `los` is the line of sight (any non-zero vector; only its direction enters). Z^(0) = F_n^s.
///
/// In `f64` the q's and the line of sight are each scaled by a power of two first (the kernels are
/// homogeneous of degree 0 in both), as [`crate::kernels`] does.
///
/// # Errors
/// [`KernelError::Order`] for n outside 1..=5, [`KernelError::ZeroVector`] for a zero argument (index
/// from 1), [`KernelError::ZeroLineOfSight`].
pub fn redshift_coefficients<T: Evaluate>(
    q: &[[T; 3]],
    los: &[T; 3],
) -> Result<Vec<T>, KernelError> {
    check(q, los)?;
    let mut vectors = T::normalised(q);
    vectors.extend(T::normalised(std::slice::from_ref(los)));
    T::redshift(q.len(), &gram(&vectors))
}

/// Z_n(q_1, …, q_n; f, n̂) for n = 1..=[`MAX_REDSHIFT_ORDER`]: [`redshift_coefficients`] summed in f.
///
/// # Errors
/// As [`redshift_coefficients`].
pub fn redshift_kernel<T: Evaluate>(q: &[[T; 3]], f: &T, los: &[T; 3]) -> Result<T, KernelError> {
    let c = redshift_coefficients(q, los)?;
    Ok(c.iter()
        .rev()
        .fold(zero::<T>(), |acc, c| acc * f.clone() + c.clone()))
}

/// The oracle of [`redshift_kernel`]: for every ordering of the arguments, every composition
/// n = n_0 + … + n_m cuts it into consecutive blocks, which contribute (1/m!) D(block_0) Π_j U(block_j)
/// with the unsymmetrised F, G of [`unsymmetrised`] on each block; the average over the n! orderings.
///
/// # Errors
/// As [`crate::reference::brute_force`]: a block summing to zero momentum is singular for the
/// unsymmetrised kernels.
pub fn brute_force_redshift<T: Scalar>(
    q: &[[T; 3]],
    f: &T,
    los: &[T; 3],
) -> Result<T, ReferenceError> {
    check(q, los)?;
    let n = q.len();
    let k = total(q);
    let mut sum = zero::<T>();
    let mut count = 0i64;
    for order in orderings(n) {
        let block = |range: std::ops::Range<usize>| -> Result<[T; 2], ReferenceError> {
            let members: Vec<[T; 3]> = order[range].iter().map(|&i| q[i].clone()).collect();
            let k_s = total(&members);
            if dot(&k_s, &k_s).is_zero() {
                return Err(ReferenceError::ZeroMomentumRun);
            }
            Ok(pieces(f, los, &k, &k_s, unsymmetrised(&members)?))
        };
        for parts in compositions(n) {
            let m = parts.len() - 1;
            let mut start = 0;
            let mut product = one::<T>();
            for (j, &len) in parts.iter().enumerate() {
                let [d, u] = block(start..start + len)?;
                product = product * if j == 0 { d } else { u };
                start += len;
            }
            sum = sum + product / factorial::<T>(m);
        }
        count += 1;
    }
    Ok(sum / T::from_ratio(count, 1))
}

/// Every ordering of 0..n.
fn orderings(n: usize) -> Vec<Vec<usize>> {
    if n == 0 {
        return vec![Vec::new()];
    }
    let mut out = Vec::new();
    for rest in orderings(n - 1) {
        for at in 0..=rest.len() {
            let mut o = rest.clone();
            o.insert(at, n - 1);
            out.push(o);
        }
    }
    out
}

/// Every composition of n into positive parts.
fn compositions(n: usize) -> Vec<Vec<usize>> {
    if n == 0 {
        return vec![Vec::new()];
    }
    (1..=n)
        .flat_map(|first| {
            compositions(n - first).into_iter().map(move |mut rest| {
                rest.insert(0, first);
                rest
            })
        })
        .collect()
}

const _: () = assert!(MAX_REDSHIFT_ORDER <= MAX_ORDER);
