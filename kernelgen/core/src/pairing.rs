//! One evaluation in two SIMD lanes: a kernel and its mirror image under a symmetry of its arguments.
//!
//! A kernel whose argument list is mapped onto itself by an involution σ of the basis (a signed permutation
//! with σ² = 1, e.g. q1 ↔ q2, q3 → −q3 for F_7^s(k, ±q1, ±q2, ±q3)) is unchanged by σ, but its
//! sub-expressions are not: a node n of the graph and its image n∘σ (n evaluated at the mirrored Gram
//! matrix σg) are, most of the time, two different nodes of the same graph. Evaluating every node as the
//! lane pair P(n) = (n(g), n(σg)) therefore computes both in one packed operation:
//!
//! - P(x·y) = P(x)·P(y), P(1/x) = 1/P(x), P(Σ cᵢxᵢ) = Σ cᵢP(xᵢ), and P(gᵢ) = (gᵢ, ±g_j) for the inputs;
//! - if n∘σ = c·m for a node m already paired, then P(n) = c·swap(P(m)) costs nothing;
//! - a node equal to an earlier one up to a constant costs nothing either (the graph is hash-consed by
//!   structure; this also merges what is equal by value).
//!
//! Each pair is stored in one orientation (P(n) or swap(P(n))), chosen so that operands mostly agree; a
//! product of operands in opposite orientations costs one swap, a sum one swap per node. Identities are
//! found by exact evaluation at random points modulo 2^61 − 1 ([`crate::modp`]), and every paired program is
//! checked against the direct one at two fresh points before it is used. For the P17 kernel the best of its
//! 19 involutions (q1 → −q1, q2 → −q3, q3 → −q2) leaves 2,267 packed statements and 680 swaps where the
//! direct program has 4,485 statements; the kernel's value is lane 0 of its output pair.

use crate::dag::{NodeId, Op, Q};
use crate::modp::{evaluate, evaluate_direct, evaluate_paired, Fp, Stream};
pub use crate::paired::{Involution, Output, PairCounts, PairOp, Paired, Var};
use crate::program::Program;
use num_traits::{One, Zero};
use std::collections::HashMap;
use std::ops::{Mul, Neg};

/// P(n) = scale × y (or × swap(y)); `var` None means the constant `scale`.
#[derive(Clone, Debug)]
struct Ref {
    scale: Q,
    var: Option<Var>,
    swapped: bool,
}

impl Ref {
    fn constant(c: Q) -> Ref {
        Ref {
            scale: c,
            var: None,
            swapped: false,
        }
    }
}

/// Node values at three random points, and at their mirror images under one involution, for exact
/// identity tests. The points and the values there do not depend on the involution: made once per program.
struct Samples {
    points: [Vec<Fp>; 3],
    at: [Vec<Fp>; 3],
}

/// The node values at a program's sample points after mirroring them under an involution.
struct Mirrored([Vec<Fp>; 3]);

impl Samples {
    fn new(program: &Program) -> Samples {
        let n = program.spec.n_inputs();
        let mut stream = Stream::new(0x5eed_0f17);
        let points: [Vec<Fp>; 3] =
            std::array::from_fn(|_| (0..n).map(|_| stream.next_fp()).collect());
        let at = points.clone().map(|p| evaluate(&program.dag, &p));
        Samples { points, at }
    }

    fn mirrored(&self, program: &Program, inv: &Involution) -> Mirrored {
        let map = inv.on_inputs(&program.spec);
        Mirrored(self.points.clone().map(|p| {
            let mirror: Vec<Fp> = map
                .iter()
                .map(|&(j, neg)| if neg { p[j].neg() } else { p[j] })
                .collect();
            evaluate(&program.dag, &mirror)
        }))
    }

    /// Shape of a value triple up to a constant factor: (v₂/v₁, v₃/v₁), if v₁ ≠ 0.
    fn shape(v: [Fp; 3]) -> Option<(Fp, Fp)> {
        (v[0] != Fp::new(0)).then(|| (v[1].mul(v[0].recip()), v[2].mul(v[0].recip())))
    }

    fn values(&self, id: NodeId) -> [Fp; 3] {
        std::array::from_fn(|p| self.at[p][id])
    }
}

impl Mirrored {
    fn values(&self, id: NodeId) -> [Fp; 3] {
        std::array::from_fn(|p| self.0[p][id])
    }
}

/// Pairs `program` under `inv` (see the module docs), checked against the direct program at two fresh
/// random points; `None` if the check fails (an identity wrongly assumed, which no test has seen).
pub fn pair(program: &Program, inv: &Involution) -> Option<Paired> {
    pair_at(program, inv, &Samples::new(program))
}

fn pair_at(program: &Program, inv: &Involution, samples: &Samples) -> Option<Paired> {
    let mirrored = samples.mirrored(program, inv);
    let live = program.live();
    let inputs = inv.on_inputs(&program.spec);
    // Shape → first live node with that shape.
    let mut index: HashMap<(Fp, Fp), NodeId> = HashMap::new();
    let mut refs: Vec<Option<Ref>> = vec![None; program.dag.ops().len()];
    let mut b = Builder::default();
    // The node m with values proportional to `v`, and the factor c with v = c·m, if m is already paired.
    let find = |index: &HashMap<(Fp, Fp), NodeId>, refs: &[Option<Ref>], v: [Fp; 3]| {
        let m = *index.get(&Samples::shape(v)?)?;
        let c = v[0].mul(samples.at[0][m].recip()).to_small_rational()?;
        refs[m].as_ref().map(|r| (r.clone(), c))
    };
    for (id, op) in program.dag.ops().iter().enumerate() {
        if !live[id] {
            continue;
        }
        let own = samples.values(id);
        let shape = Samples::shape(own);
        if let Some((r, c)) = find(&index, &refs, own) {
            b.counts.merged += 1;
            refs[id] = Some(Ref {
                scale: c * r.scale,
                ..r
            });
            continue;
        }
        if let Some((r, c)) = find(&index, &refs, mirrored.values(id)) {
            // n(σg) = c·m(g), so P(n) = c·swap(P(m)).
            b.counts.mirrored += 1;
            refs[id] = Some(Ref {
                scale: c * r.scale,
                var: r.var,
                swapped: !r.swapped,
            });
        } else {
            let get = |x: &NodeId| refs[*x].clone().expect("operands come first");
            refs[id] = Some(match op {
                Op::Input(i) => {
                    let (j, negated) = inputs[*i];
                    b.push_ref(PairOp::Input { i: *i, j, negated }, Q::one(), false)
                }
                Op::Mul(x, y) => b.mul(get(x), get(y)),
                Op::Recip(x) => b.recip(get(x)),
                Op::Lin(terms, c0) => {
                    let terms: Vec<(Q, Ref)> =
                        terms.iter().map(|(c, x)| (c.clone(), get(x))).collect();
                    b.lin(&terms, c0)
                }
            });
        }
        if let Some(s) = shape {
            index.entry(s).or_insert(id);
        }
    }
    let output = |v: &crate::dag::Value| match v.node {
        None => Output {
            coef: v.coef.clone(),
            var: None,
        },
        Some(id) => {
            let r = refs[id].clone().expect("outputs are live");
            Output {
                coef: &v.coef * &r.scale,
                var: r.var.map(|y| (y, usize::from(r.swapped))),
            }
        }
    };
    let (f, g) = (output(&program.outputs[0]), output(&program.outputs[1]));
    b.counts.statements = b.ops.len();
    b.counts.direct = program.op_counts().statements;
    let paired = Paired {
        spec: program.spec.clone(),
        involution: inv.clone(),
        ops: b.ops,
        f,
        g,
        counts: b.counts,
        stats: program.stats,
    };
    let mut stream = Stream::new(0x000c_4ec4);
    let n = program.spec.n_inputs();
    (0..2)
        .map(|_| (0..n).map(|_| stream.next_fp()).collect::<Vec<Fp>>())
        .all(|g| evaluate_paired(&paired, &g) == evaluate_direct(program, &g))
        .then_some(paired)
}

/// The cheapest pairing of `program` over every involution of its arguments, if it has any: fewest
/// statements, a swap counted as half of one (a swap is one short register instruction, a statement often
/// a load or store besides its arithmetic; weighting them equally chose a program 8% slower).
pub fn best_pairing(program: &Program) -> Option<Paired> {
    let samples = Samples::new(program);
    Involution::candidates(&program.spec)
        .iter()
        .filter_map(|inv| pair_at(program, inv, &samples))
        .min_by_key(|p| 2 * p.counts.statements + p.counts.swaps)
}

#[derive(Default)]
struct Builder {
    ops: Vec<PairOp>,
    counts: PairCounts,
    /// Pairs used swapped in a product (the compiler swaps each once, however often it is used).
    swapped_factors: std::collections::HashSet<Var>,
}

impl Builder {
    fn push_ref(&mut self, op: PairOp, scale: Q, swapped: bool) -> Ref {
        self.ops.push(op);
        Ref {
            scale,
            var: Some(self.ops.len() - 1),
            swapped,
        }
    }

    fn mul(&mut self, x: Ref, y: Ref) -> Ref {
        let scale = &x.scale * &y.scale;
        match (x.var, y.var) {
            (None, _) => Ref { scale, ..y },
            (_, None) => Ref { scale, ..x },
            (Some(a), Some(b)) => {
                let swap_b = x.swapped != y.swapped;
                if swap_b && self.swapped_factors.insert(b) {
                    self.counts.swaps += 1;
                }
                self.push_ref(PairOp::Mul { a, b, swap_b }, scale, x.swapped)
            }
        }
    }

    fn recip(&mut self, x: Ref) -> Ref {
        match x.var {
            None if x.scale.is_zero() => Ref::constant(Q::zero()),
            None => Ref::constant(x.scale.recip()),
            Some(a) => self.push_ref(PairOp::Recip(a), x.scale.recip(), x.swapped),
        }
    }

    fn lin(&mut self, terms: &[(Q, Ref)], c0: &Q) -> Ref {
        // Merge like terms (same pair, same orientation) and fold constants.
        let mut c0 = c0.clone();
        let mut merged: Vec<(Q, Var, bool)> = Vec::new();
        for (c, r) in terms {
            let c = c * &r.scale;
            match r.var {
                None => c0 += c,
                Some(y) => match merged.iter_mut().find(|t| t.1 == y && t.2 == r.swapped) {
                    Some(t) => t.0 += c,
                    None => merged.push((c, y, r.swapped)),
                },
            }
        }
        merged.retain(|t| !t.0.is_zero());
        if merged.is_empty() {
            return Ref::constant(c0);
        }
        if merged.len() == 1 && c0.is_zero() {
            let (c, y, swapped) = merged.pop().expect("one term");
            return Ref {
                scale: c,
                var: Some(y),
                swapped,
            };
        }
        // Orientation of the majority; the lead coefficient factored out as the scale.
        let n_swapped = merged.iter().filter(|t| t.2).count();
        let swapped = 2 * n_swapped > merged.len();
        let lead = merged[0].0.clone();
        let (mut direct, mut other) = (Vec::new(), Vec::new());
        for (c, y, s) in merged {
            let t = (c / &lead, y);
            if s == swapped {
                direct.push(t);
            } else {
                other.push(t);
            }
        }
        self.counts.swaps += usize::from(!other.is_empty());
        let op = PairOp::Lin {
            direct,
            swapped: other,
            c0: c0 / &lead,
        };
        self.push_ref(op, lead, swapped)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::spec::Spec;

    #[test]
    fn propagator_involutions_are_the_signed_pair_permutations() {
        // k stays (the arguments hold k, not −k). The q's are permuted by the identity or one of three
        // transpositions, with signs such that σ² = 1: 8 + 3·4 maps, less the identity.
        let spec = Spec::propagator("p", 3).unwrap();
        let c = Involution::candidates(&spec);
        assert_eq!(c.len(), 19);
        let swap12 = c
            .iter()
            .find(|i| i.perm == [0, 2, 1, 3] && i.sign == [1, 1, 1, -1])
            .unwrap();
        assert_eq!(swap12.describe(&spec), "q1 → q2, q2 → q1, q3 → −q3");
        // A configuration without a symmetry has no candidates.
        let mc = Spec::new(
            "m",
            vec!["k".into(), "q1".into(), "q2".into()],
            vec![vec![0, 1, 0], vec![0, 0, 1], vec![1, -1, -1], vec![1, 1, 0]],
        )
        .unwrap();
        assert!(Involution::candidates(&mc).is_empty());
    }

    #[test]
    fn paired_programs_equal_the_direct_ones_at_random_points() {
        for x in 1..=3 {
            let program = Program::build(&Spec::propagator("p", x).unwrap());
            let mut stream = Stream::new(99);
            for inv in Involution::candidates(&program.spec) {
                let paired = pair(&program, &inv).expect("checked");
                for _ in 0..3 {
                    let g: Vec<Fp> = (0..program.spec.n_inputs())
                        .map(|_| stream.next_fp())
                        .collect();
                    assert_eq!(
                        evaluate_paired(&paired, &g),
                        evaluate_direct(&program, &g),
                        "x = {x}, {}",
                        inv.describe(&program.spec)
                    );
                }
            }
        }
    }

    #[test]
    fn pairing_halves_the_p17_program() {
        let program = Program::build(&Spec::propagator("p17", 3).unwrap());
        let direct = program.op_counts().statements;
        let best = best_pairing(&program).unwrap();
        let cost = best.counts.statements + best.counts.swaps;
        assert!(2 * cost < 4 * direct / 3, "{:?} vs {direct}", best.counts);
        assert!(best.counts.mirrored > direct / 3, "{:?}", best.counts);
    }
}
