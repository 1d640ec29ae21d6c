//! The slow, obviously correct reference: the kernels exactly as the paper defines them.
//!
//! [`unsymmetrised`] is eqs. (kernelF, kernelG) of Gil-Marín et al. (2012) for an ordered argument list, and
//! [`brute_force`] averages it over all n! orderings (eq. sym_kernels). Nothing is shared with the generator:
//! no subsets, no pairing of splits, no precomputed coefficients. Ordered sub-sequences that recur across
//! permutations are memoised, which changes the cost (about e·n! sub-kernels instead of n!·n³) but not what
//! is computed. It is the oracle of the tests, in f64 or exactly in [`num_rational::BigRational`].

use crate::{dot, one, zero, KernelError, Scalar, MAX_ORDER};
use std::collections::HashMap;

/// Why the reference cannot evaluate a configuration.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
#[non_exhaustive]
pub enum ReferenceError {
    /// Bad order or a zero argument.
    #[error(transparent)]
    Kernel(#[from] KernelError),
    /// A contiguous run of arguments sums to exactly zero momentum in some ordering: the unsymmetrised
    /// kernels are 0·∞ there (only the symmetrised sum has a limit). Move the configuration off the
    /// singular point (e.g. −q → −q + εd) to use the reference.
    #[error(
        "a run of arguments sums to zero momentum; the unsymmetrised recursion is singular there"
    )]
    ZeroMomentumRun,
}

fn add<T: Scalar>(a: &[T; 3], b: &[T; 3]) -> [T; 3] {
    [
        a[0].clone() + b[0].clone(),
        a[1].clone() + b[1].clone(),
        a[2].clone() + b[2].clone(),
    ]
}

/// α(k, k1) = k·k1/k1².
fn alpha<T: Scalar>(k: &[T; 3], k1: &[T; 3]) -> T {
    dot(k, k1) / dot(k1, k1)
}

/// β(k, k1, k2) = k² (k1·k2) / (2 k1² k2²).
fn beta<T: Scalar>(k: &[T; 3], k1: &[T; 3], k2: &[T; 3]) -> T {
    dot(k, k) * dot(k1, k2) / (T::from_ratio(2, 1) * dot(k1, k1) * dot(k2, k2))
}

struct Unsymmetrised<'a, T: Scalar> {
    q: &'a [[T; 3]],
    memo: HashMap<Vec<u8>, [T; 2]>,
}

impl<T: Scalar> Unsymmetrised<'_, T> {
    fn total(&self, seq: &[u8]) -> [T; 3] {
        seq.iter().fold([zero(), zero(), zero()], |acc, &i| {
            add(&acc, &self.q[i as usize])
        })
    }

    /// [F_n, G_n](q_seq[0], …, q_seq[n−1]), eqs. (kernelF, kernelG).
    fn eval(&mut self, seq: &[u8]) -> Result<[T; 2], ReferenceError> {
        if seq.len() == 1 {
            return Ok([one(), one()]);
        }
        if let Some(v) = self.memo.get(seq) {
            return Ok(v.clone());
        }
        let n = seq.len() as i64;
        let k = self.total(seq);
        let (mut f, mut g) = (zero::<T>(), zero::<T>());
        for m in 1..seq.len() {
            let (left, right) = seq.split_at(m);
            let (k1, k2) = (self.total(left), self.total(right));
            if dot(&k1, &k1).is_zero() || dot(&k2, &k2).is_zero() {
                return Err(ReferenceError::ZeroMomentumRun);
            }
            let [_, gm] = self.eval(left)?;
            let [fr, gr] = self.eval(right)?;
            let (a, b) = (alpha(&k, &k1), beta(&k, &k1, &k2));
            let c = |x: i64| T::from_ratio(x, 1);
            f = f + gm.clone()
                * (c(2 * n + 1) * a.clone() * fr.clone() + c(2) * b.clone() * gr.clone());
            g = g + gm * (c(3) * a * fr + c(2 * n) * b * gr);
        }
        let norm = T::from_ratio(1, (2 * n + 3) * (n - 1));
        let v = [f * norm.clone(), g * norm];
        self.memo.insert(seq.to_vec(), v.clone());
        Ok(v)
    }
}

fn check<T: Scalar>(q: &[[T; 3]]) -> Result<(), KernelError> {
    if q.is_empty() || q.len() > MAX_ORDER {
        return Err(KernelError::Order(q.len()));
    }
    match q.iter().position(|v| v.iter().all(Scalar::is_zero)) {
        Some(i) => Err(KernelError::ZeroVector(i + 1)),
        None => Ok(()),
    }
}

/// The unsymmetrised `[F_n, G_n](q_1, …, q_n)` in the given order.
pub fn unsymmetrised<T: Scalar>(q: &[[T; 3]]) -> Result<[T; 2], ReferenceError> {
    check(q)?;
    let seq: Vec<u8> = (0..q.len() as u8).collect();
    Unsymmetrised {
        q,
        memo: HashMap::new(),
    }
    .eval(&seq)
}

/// All permutations of 0..n (Heap's algorithm).
fn permutations(n: usize) -> Vec<Vec<u8>> {
    fn heap(k: usize, a: &mut Vec<u8>, out: &mut Vec<Vec<u8>>) {
        if k <= 1 {
            out.push(a.clone());
            return;
        }
        heap(k - 1, a, out);
        for i in 0..k - 1 {
            if k.is_multiple_of(2) {
                a.swap(i, k - 1);
            } else {
                a.swap(0, k - 1);
            }
            heap(k - 1, a, out);
        }
    }
    let mut out = Vec::new();
    heap(n, &mut (0..n as u8).collect(), &mut out);
    out
}

/// `[F_n^s, G_n^s]` by brute force: the unsymmetrised kernels averaged over all n! orderings.
pub fn brute_force<T: Scalar>(q: &[[T; 3]]) -> Result<[T; 2], ReferenceError> {
    check(q)?;
    let mut u = Unsymmetrised {
        q,
        memo: HashMap::new(),
    };
    let perms = permutations(q.len());
    let (mut f, mut g) = (zero::<T>(), zero::<T>());
    for p in &perms {
        let [pf, pg] = u.eval(p)?;
        f = f + pf;
        g = g + pg;
    }
    let inv = T::from_ratio(1, perms.len() as i64);
    Ok([f * inv.clone(), g * inv])
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn permutations_are_all_distinct() {
        let p = permutations(5);
        assert_eq!(p.len(), 120);
        let set: std::collections::HashSet<_> = p.into_iter().collect();
        assert_eq!(set.len(), 120);
    }

    #[test]
    fn unsymmetrised_f2_is_the_textbook_expression() {
        // F_2(q1, q2) = 5/7 α(k, q1) + 2/7 β(k, q1, q2) for q1 = (1,0,0), q2 = (0,2,0):
        // k = (1,2,0), α = 1, β = 5·0/(2·1·4) = 0 → 5/7; G_2 = 3/7 α + 4/7 β = 3/7.
        let [f, g] = unsymmetrised(&[[1.0, 0.0, 0.0], [0.0, 2.0, 0.0]]).unwrap();
        assert!((f - 5.0 / 7.0).abs() < 1e-15 && (g - 3.0 / 7.0).abs() < 1e-15);
    }

    #[test]
    fn zero_momentum_runs_are_reported() {
        let q = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, -1.0, 0.0]];
        assert_eq!(brute_force(&q), Err(ReferenceError::ZeroMomentumRun));
    }
}
