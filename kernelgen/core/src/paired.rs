//! The lane-pair form of a program (the types [`crate::pairing`] builds, [`crate::modp`] checks and
//! [`crate::emit`] writes out), and the involutions of a kernel's arguments it is built under.

use crate::dag::{coefficient_muls, Q};
use crate::program::OpCounts;
use crate::recursion::RecursionStats;
use crate::spec::Spec;
use num_traits::Zero;

/// A signed permutation of the basis vectors: e_a ↦ sign\[a\] · e_perm\[a\], with σ² = 1.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Involution {
    /// Image index of each basis vector.
    pub perm: Vec<usize>,
    /// Sign of each image (±1).
    pub sign: Vec<i64>,
}

impl Involution {
    /// Where each Gram input goes: (σg)ᵢ = ±g_j as (j, negated).
    pub fn on_inputs(&self, spec: &Spec) -> Vec<(usize, bool)> {
        let nb = spec.basis.len();
        let mut out = vec![(0, false); spec.n_inputs()];
        for a in 0..nb {
            for b in a..nb {
                let j = spec.gram_index(self.perm[a], self.perm[b]);
                out[spec.gram_index(a, b)] = (j, self.sign[a] * self.sign[b] < 0);
            }
        }
        out
    }

    /// Every involution of the basis that maps the argument list onto itself (as a multiset) and acts on
    /// the Gram inputs non-trivially.
    pub fn candidates(spec: &Spec) -> Vec<Involution> {
        let nb = spec.basis.len();
        let mut out = Vec::new();
        for perm in permutations(nb) {
            if (0..nb).any(|a| perm[perm[a]] != a) {
                continue;
            }
            for bits in 0..(1u32 << nb) {
                let sign: Vec<i64> = (0..nb)
                    .map(|a| if bits & (1 << a) != 0 { -1 } else { 1 })
                    .collect();
                if (0..nb).any(|a| sign[a] * sign[perm[a]] != 1) {
                    continue;
                }
                let inv = Involution {
                    perm: perm.clone(),
                    sign,
                };
                let trivial = inv
                    .on_inputs(spec)
                    .iter()
                    .enumerate()
                    .all(|(i, &(j, neg))| i == j && !neg);
                if !trivial && inv.preserves_arguments(spec) {
                    out.push(inv);
                }
            }
        }
        out
    }

    fn image(&self, arg: &[i64]) -> Vec<i64> {
        let mut v = vec![0; arg.len()];
        for (a, &c) in arg.iter().enumerate() {
            v[self.perm[a]] += self.sign[a] * c;
        }
        v
    }

    fn preserves_arguments(&self, spec: &Spec) -> bool {
        let mut args = spec.args.clone();
        let mut images: Vec<Vec<i64>> = args.iter().map(|a| self.image(a)).collect();
        args.sort();
        images.sort();
        args == images
    }

    /// `q1 → q2, q2 → q1, q3 → −q3`: the non-trivial part of the map.
    pub fn describe(&self, spec: &Spec) -> String {
        (0..spec.basis.len())
            .filter(|&a| self.perm[a] != a || self.sign[a] != 1)
            .map(|a| {
                let sign = if self.sign[a] < 0 { "−" } else { "" };
                format!("{} → {sign}{}", spec.basis[a], spec.basis[self.perm[a]])
            })
            .collect::<Vec<_>>()
            .join(", ")
    }
}

fn permutations(n: usize) -> Vec<Vec<usize>> {
    if n == 0 {
        return vec![Vec::new()];
    }
    let mut out = Vec::new();
    for p in permutations(n - 1) {
        for pos in 0..=p.len() {
            let mut q = p.clone();
            q.insert(pos, n - 1);
            out.push(q);
        }
    }
    out
}

/// A lane pair of the paired program (an index into [`Paired::ops`]).
pub type Var = usize;

/// One statement of the paired program; statement i defines the pair `y{i}`.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum PairOp {
    /// (g_i, ±g_j).
    Input {
        /// Lane 0's input.
        i: usize,
        /// Lane 1's input (the mirror of i).
        j: usize,
        /// Lane 1 is −g_j.
        negated: bool,
    },
    /// Σ cᵢ yᵢ + Σ dⱼ swap(yⱼ) + c0, the swapped terms summed first and swapped once.
    Lin {
        /// Terms taken as they are.
        direct: Vec<(Q, Var)>,
        /// Terms taken swapped.
        swapped: Vec<(Q, Var)>,
        /// Constant.
        c0: Q,
    },
    /// a · b, or a · swap(b).
    Mul {
        /// First factor.
        a: Var,
        /// Second factor.
        b: Var,
        /// Take b swapped.
        swap_b: bool,
    },
    /// 1/a lane by lane (0 at an exact 0).
    Recip(Var),
}

/// A scalar of the paired program: `coef`, times a lane of a pair if `var` is set.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Output {
    /// Exact multiplier.
    pub coef: Q,
    /// The pair and the lane holding the value, if not a constant.
    pub var: Option<(Var, usize)>,
}

/// How much the paired program costs.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct PairCounts {
    /// Packed statements.
    pub statements: usize,
    /// Lane swaps: one per pair used swapped in products (once however often), one per sum with swapped
    /// terms.
    pub swaps: usize,
    /// Nodes of the direct program that cost nothing: mirror images of paired ones.
    pub mirrored: usize,
    /// Nodes equal to an earlier node up to a constant (merged).
    pub merged: usize,
    /// Statements of the direct program.
    pub direct: usize,
}

/// A program evaluated in lane pairs under an involution.
pub struct Paired {
    /// The configuration.
    pub spec: Spec,
    /// The symmetry used.
    pub involution: Involution,
    /// Statements in evaluation order.
    pub ops: Vec<PairOp>,
    /// F^s.
    pub f: Output,
    /// G^s.
    pub g: Output,
    /// Costs.
    pub counts: PairCounts,
    /// What the recursion of the direct program did.
    pub stats: RecursionStats,
}

impl Paired {
    /// Operation counts of the emitted code (each packed operation counted once; swaps not included).
    pub fn op_counts(&self) -> OpCounts {
        let mut c = OpCounts::default();
        for op in &self.ops {
            match op {
                PairOp::Input { .. } => {}
                PairOp::Mul { .. } => c.muls += 1,
                PairOp::Recip(_) => c.recips += 1,
                PairOp::Lin {
                    direct,
                    swapped,
                    c0,
                } => {
                    let leaves = direct.len() + swapped.len() + usize::from(!c0.is_zero());
                    c.adds += leaves.saturating_sub(1);
                    c.muls += coefficient_muls(direct) + coefficient_muls(swapped);
                }
            }
            c.statements += 1;
        }
        c
    }
}
