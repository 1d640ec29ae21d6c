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
//! in [`num_rational::BigRational`]. The F_S, G_S come from the generated kernels; a subset with exactly
//! zero total momentum contributes its limit, zero (F_S, G_S ∝ k_S²).
//!
//! [`brute_force_redshift`] is the oracle: the same expansion with the *unsymmetrised* kernels of
//! [`crate::reference`] on consecutive blocks of an ordering, averaged over all n! orderings (no subsets,
//! no set partitions, no factorial weights).

use crate::reference::{unsymmetrised, ReferenceError};
use crate::{dot, kernels, one, zero, Evaluate, KernelError, Scalar, MAX_ORDER};

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

/// Z_n(q_1, …, q_n; f, n̂) for n = 1..=[`MAX_REDSHIFT_ORDER`] (module docs): `f` the growth rate, `los`
/// the line of sight (any non-zero vector; only its direction enters).
///
/// # Errors
/// [`KernelError::Order`] for n outside 1..=5, [`KernelError::ZeroVector`] for a zero argument (index
/// from 1), [`KernelError::ZeroLineOfSight`].
pub fn redshift_kernel<T: Evaluate>(q: &[[T; 3]], f: &T, los: &[T; 3]) -> Result<T, KernelError> {
    check(q, los)?;
    let n = q.len();
    let full = (1usize << n) - 1;
    let k = total(q);
    // D and U of every non-empty subset (F_S, G_S from the generated kernels, which, like `pieces`,
    // give the limit of a subset with zero total momentum)
    let mut d = vec![zero::<T>(); full + 1];
    let mut u = vec![zero::<T>(); full + 1];
    for mask in 1..=full {
        let members: Vec<[T; 3]> = (0..n)
            .filter(|i| mask >> i & 1 == 1)
            .map(|i| q[i].clone())
            .collect();
        [d[mask], u[mask]] = pieces(f, los, &k, &total(&members), kernels(&members)?);
    }
    // E(R): the blocks B containing the lowest member of R, then the rest
    let mut e = vec![zero::<T>(); full + 1];
    e[0] = one();
    for r in 1..=full {
        let low = r & r.wrapping_neg();
        let rest = r ^ low;
        let mut sum = zero::<T>();
        let mut sub = rest;
        loop {
            let block = sub | low;
            let size = block.count_ones() as usize;
            sum = sum + factorial::<T>(size) * u[block].clone() * e[r ^ block].clone();
            if sub == 0 {
                break;
            }
            sub = (sub - 1) & rest;
        }
        e[r] = sum;
    }
    let mut z = zero::<T>();
    for s0 in 1..=full {
        let size = s0.count_ones() as usize;
        z = z + factorial::<T>(size) * d[s0].clone() * e[full ^ s0].clone();
    }
    Ok(z / factorial::<T>(n))
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
