//! The symmetrised F_n/G_n recursion over subsets of the arguments (science.md, "Kernels").
//!
//! For a subset S of the arguments with m = |S| ≥ 2 and total momentum k_S,
//!
//! ```text
//! F^s(S) = Σ_{A ⊂ S, A ≠ ∅, S} G^s(A) [(2m+1) α(k_S,k_A) F^s(S∖A) + 2β(k_S,k_A,k_{S∖A}) G^s(S∖A)] / ((2m+3)(m−1) C(m,|A|))
//! G^s(S) = Σ_{A ⊂ S, A ≠ ∅, S} G^s(A) [3 α(k_S,k_A) F^s(S∖A) + 2m β(k_S,k_A,k_{S∖A}) G^s(S∖A)] / ((2m+3)(m−1) C(m,|A|))
//! ```
//!
//! Pairing A with B = S∖A, both brackets are combinations of the same two sums
//! U = Σ w (α_SA G_A F_B + α_SB G_B F_A) and V = Σ w 2β G_A G_B over unordered splits {A, B}, with
//! w = 1/((2m+3)(m−1)C(m,|A|)): F^s(S) = (2m+1)U + 2V and G^s(S) = 3U + 2mV. This is O(3^n) work instead of
//! the n! permutations of the definition. With Ĝ_A = G_A/k_A² (one division per sub-kernel, not per split),
//! α_SA G_A = (k_S·k_A) Ĝ_A and 2β G_A G_B = k_S² (k_A·k_B) Ĝ_A Ĝ_B, so
//! U = Σ w [(k_S·k_A) Ĝ_A F_B + (k_S·k_B) Ĝ_B F_A] and V = k_S² Σ w (k_A·k_B) Ĝ_A Ĝ_B.
//!
//! Zero momentum: a subset S with k_S = 0 and |S| ≥ 2 has F^s(S) = G^s(S) = 0 (the symmetrised kernels
//! vanish like k_S²), and every split term that carries such a factor is exactly zero in the limit (G_A ~ k_A²
//! beats α ~ 1/k_A and β ~ 1/k_A), so those terms are dropped and 0·∞ is never formed.
//!
//! The recursion is written once, over an [`Algebra`]: the code generator runs it on the expression graph,
//! and the angle-averaged vertices ν_n, μ_n run it in exact rationals with α → 1 and β → 1/3.

use crate::dag::{q, Q};
use crate::spec::Spec;
use num_integer::binomial;
use std::collections::HashMap;

/// A subset of the arguments, as a bitmask (bit i = argument i).
pub type Mask = u32;

/// The operations the recursion needs from whatever it computes in.
pub trait Algebra {
    /// A computed quantity.
    type V: Clone;
    /// The exact constant r.
    fn constant(&mut self, r: Q) -> Self::V;
    /// True if v is zero exactly (known at generation time).
    fn is_zero(&self, v: &Self::V) -> bool;
    /// a · b.
    fn mul(&mut self, a: &Self::V, b: &Self::V) -> Self::V;
    /// Σ r_i v_i.
    fn lin(&mut self, terms: &[(Q, Self::V)]) -> Self::V;
    /// k_S² for the subset `s`.
    fn norm(&mut self, s: Mask) -> Self::V;
    /// k_S·k_A for the subset `s` and its part `a`.
    fn total_dot(&mut self, s: Mask, a: Mask) -> Self::V;
    /// k_A·k_B for disjoint subsets `a` and `b`.
    fn pair_dot(&mut self, a: Mask, b: Mask) -> Self::V;
    /// Ĝ_A = G^s(A)/k_A², given G^s(A) = `g`.
    fn over_norm(&mut self, a: Mask, g: &Self::V) -> Self::V;
}

/// Counts that describe how much work the recursion did (reported in generated docs and tests).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct RecursionStats {
    /// Distinct sub-kernels evaluated (subsets up to equal multisets of arguments and a global sign).
    pub subkernels: usize,
    /// Subsets with zero total momentum, dropped with F^s = G^s = 0.
    pub zero_momentum_subsets: usize,
    /// Unordered splits {A, B} visited.
    pub splits: usize,
    /// Split terms (α or β products) that are identically zero and were never built.
    pub dropped_terms: usize,
}

/// The recursion for one configuration, memoised by sub-kernel.
pub struct Recursion<'s, A: Algebra> {
    spec: &'s Spec,
    /// The algebra the recursion computes in.
    pub alg: A,
    memo: HashMap<Vec<Vec<i64>>, Sub<A::V>>,
    /// Work counters.
    pub stats: RecursionStats,
}

/// A sub-kernel: F^s(S), G^s(S) and Ĝ(S) = G^s(S)/k_S².
#[derive(Clone, Debug)]
pub struct Sub<V> {
    /// F^s(S).
    pub f: V,
    /// G^s(S).
    pub g: V,
    /// G^s(S)/k_S² (zero where G^s(S) is).
    pub g_hat: V,
}

/// Total momentum of a subset as coefficients over the basis.
pub fn momentum(spec: &Spec, s: Mask) -> Vec<i64> {
    let mut c = vec![0; spec.basis.len()];
    for (i, arg) in spec.args.iter().enumerate() {
        if s & (1 << i) != 0 {
            c.iter_mut().zip(arg).for_each(|(x, a)| *x += a);
        }
    }
    c
}

/// Canonical key of a subset: its multiset of arguments, up to a global sign (kernels depend only on dot
/// products, so both give the same value).
fn canonical_key(spec: &Spec, s: Mask) -> Vec<Vec<i64>> {
    let members = |sign: i64| {
        let mut v: Vec<Vec<i64>> = (0..spec.args.len())
            .filter(|i| s & (1 << i) != 0)
            .map(|i| spec.args[i].iter().map(|c| sign * c).collect())
            .collect();
        v.sort();
        v
    };
    members(1).min(members(-1))
}

impl<'s, A: Algebra> Recursion<'s, A> {
    /// A recursion over `spec` computing in `alg`.
    pub fn new(spec: &'s Spec, alg: A) -> Self {
        Recursion {
            spec,
            alg,
            memo: HashMap::new(),
            stats: RecursionStats::default(),
        }
    }

    /// (F^s, G^s) of the whole argument list.
    pub fn top(&mut self) -> (A::V, A::V) {
        let all = (1u32 << self.spec.order()) - 1;
        let sub = self.kernel(all);
        (sub.f, sub.g)
    }

    /// The sub-kernel of the subset `s` of the arguments.
    pub fn kernel(&mut self, s: Mask) -> Sub<A::V> {
        let key = canonical_key(self.spec, s);
        if let Some(v) = self.memo.get(&key) {
            return v.clone();
        }
        let (f, g) = if s.count_ones() == 1 {
            let one = self.alg.constant(q(1, 1));
            (one.clone(), one)
        } else if momentum(self.spec, s).iter().all(|&c| c == 0) {
            self.stats.zero_momentum_subsets += 1;
            let zero = self.alg.constant(q(0, 1));
            (zero.clone(), zero)
        } else {
            self.stats.subkernels += 1;
            self.split_sum(s)
        };
        let g_hat = if self.alg.is_zero(&g) {
            g.clone()
        } else {
            self.alg.over_norm(s, &g)
        };
        let sub = Sub { f, g, g_hat };
        self.memo.insert(key, sub.clone());
        sub
    }

    fn split_sum(&mut self, s: Mask) -> (A::V, A::V) {
        let m = s.count_ones() as i64;
        let lowest = s & s.wrapping_neg();
        let (mut u_terms, mut v_terms) = (Vec::new(), Vec::new());
        // Every unordered split {A, B} once: A holds the lowest argument of S.
        let rest = s ^ lowest;
        let mut sub = rest;
        loop {
            let a = lowest | sub;
            if a != s {
                let b = s ^ a;
                self.stats.splits += 1;
                let w = q(
                    1,
                    (2 * m + 3) * (m - 1) * binomial(m, a.count_ones() as i64),
                );
                self.split_terms(s, a, b, &w, &mut u_terms, &mut v_terms);
            }
            if sub == 0 {
                break;
            }
            sub = (sub - 1) & rest;
        }
        let u = self.alg.lin(&u_terms);
        let v_sum = self.alg.lin(&v_terms);
        let v = if self.alg.is_zero(&v_sum) {
            v_sum
        } else {
            let ns = self.alg.norm(s);
            self.alg.mul(&v_sum, &ns)
        };
        let f = self
            .alg
            .lin(&[(q(2 * m + 1, 1), u.clone()), (q(2, 1), v.clone())]);
        let g = self.alg.lin(&[(q(3, 1), u), (q(2 * m, 1), v)]);
        (f, g)
    }

    /// Adds w (k_S·k_A) Ĝ_A F_B + w (k_S·k_B) Ĝ_B F_A to U and w (k_A·k_B) Ĝ_A Ĝ_B to V, skipping every
    /// product that is identically zero.
    fn split_terms(
        &mut self,
        s: Mask,
        a: Mask,
        b: Mask,
        w: &Q,
        u: &mut Vec<(Q, A::V)>,
        v: &mut Vec<(Q, A::V)>,
    ) {
        let sa = self.kernel(a);
        let sb = self.kernel(b);
        for (part, this, other) in [(a, &sa, &sb), (b, &sb, &sa)] {
            if self.alg.is_zero(&this.g_hat) || self.alg.is_zero(&other.f) {
                self.stats.dropped_terms += 1;
                continue;
            }
            let dot = self.alg.total_dot(s, part);
            let t = self.alg.mul(&dot, &this.g_hat);
            let t = self.alg.mul(&t, &other.f);
            u.push((w.clone(), t));
        }
        if self.alg.is_zero(&sa.g_hat) || self.alg.is_zero(&sb.g_hat) {
            self.stats.dropped_terms += 1;
        } else {
            let dot = self.alg.pair_dot(a, b);
            let t = self.alg.mul(&sa.g_hat, &sb.g_hat);
            let t = self.alg.mul(&t, &dot);
            v.push((w.clone(), t));
        }
    }
}

/// The recursion in exact rationals with α → 1 and β → 1/3: the kernels averaged over independent isotropic
/// directions of their arguments (Bernardeau 1992), which depend on the order only.
pub struct AngleAveraged;

impl Algebra for AngleAveraged {
    type V = Q;
    fn constant(&mut self, r: Q) -> Q {
        r
    }
    fn is_zero(&self, v: &Q) -> bool {
        num_traits::Zero::is_zero(v)
    }
    fn mul(&mut self, a: &Q, b: &Q) -> Q {
        a * b
    }
    fn lin(&mut self, terms: &[(Q, Q)]) -> Q {
        terms.iter().map(|(r, v)| r * v).sum()
    }
    // α → 1 and 2β → 2/3, realised as k_S·k_A → 1, k_A² → 1, k_S² → 1 and k_A·k_B → 2/3.
    fn norm(&mut self, _s: Mask) -> Q {
        q(1, 1)
    }
    fn total_dot(&mut self, _s: Mask, _a: Mask) -> Q {
        q(1, 1)
    }
    fn pair_dot(&mut self, _a: Mask, _b: Mask) -> Q {
        q(2, 3)
    }
    fn over_norm(&mut self, _a: Mask, g: &Q) -> Q {
        g.clone()
    }
}

/// The angle-averaged vertices (ν_n, μ_n) = n! (⟨F_n^s⟩, ⟨G_n^s⟩), exact, from the generator's own recursion.
pub fn vertices(n: usize) -> (Q, Q) {
    let spec = Spec::free("vertex", n).expect("1 <= n <= 7");
    let mut rec = Recursion::new(&spec, AngleAveraged);
    let (f, g) = rec.top();
    let factorial = q((1..=n as i64).product(), 1);
    (f * &factorial, g * factorial)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn vertices_match_bernardeau_1994() {
        let expected = [
            (2, q(34, 21), q(26, 21)),
            (3, q(682, 189), q(142, 63)),
            (4, q(446440, 43659), q(236872, 43659)),
            (5, q(8546480, 243243), q(27674320, 1702701)),
            (6, q(1690382480, 11918907), q(694579280, 11918907)),
            (7, q(6672944960, 10149867), q(2090034880, 8588349)),
        ];
        for (n, nu, mu) in expected {
            assert_eq!(vertices(n), (nu, mu), "n = {n}");
        }
    }

    #[test]
    fn first_order_vertex_is_one() {
        assert_eq!(vertices(1), (q(1, 1), q(1, 1)));
    }

    #[test]
    fn every_unordered_split_is_visited_once() {
        // Unordered splits of an m-set into two non-empty parts: 2^(m−1) − 1.
        let spec = Spec::free("f", 5).unwrap();
        let mut rec = Recursion::new(&spec, AngleAveraged);
        rec.top();
        let expected: usize = (2..=5)
            .map(|m| binomial(5usize, m) * ((1 << (m - 1)) - 1))
            .sum();
        assert_eq!(rec.stats.splits, expected);
    }
}
