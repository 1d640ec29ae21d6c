//! The recursion run on the expression graph ([`crate::graph`]): one straight-line program per kernel
//! configuration, with F^s, G^s or the coefficients of Z_n ([`crate::redshift`]) as its outputs.

use crate::dag::{coefficient_muls, Dag, Op, Value, Q};
use crate::graph::Graph;
use crate::recursion::{momentum, Mask, Recursion, RecursionStats};
use crate::spec::{Kind, Spec};
use num_traits::Zero;

/// A generated kernel: its configuration, its straight-line program and its outputs.
pub struct Program {
    /// The configuration.
    pub spec: Spec,
    /// The expression graph (only nodes reachable from the outputs are emitted).
    pub dag: Dag,
    /// `[F^s, G^s]` of the configuration, or the n + 1 coefficients of Z_n ([`Kind::Redshift`]).
    pub outputs: Vec<Value>,
    /// What the recursion did.
    pub stats: RecursionStats,
}

/// Counts of the emitted operations of a program.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct OpCounts {
    /// Multiplications (including multiplication by a constant inside linear combinations).
    pub muls: usize,
    /// Additions and subtractions.
    pub adds: usize,
    /// Reciprocals (one division each).
    pub recips: usize,
    /// Straight-line statements (live graph nodes that are not plain inputs).
    pub statements: usize,
}

impl OpCounts {
    /// All floating-point operations.
    pub fn flops(&self) -> usize {
        self.muls + self.adds + self.recips
    }
}

impl Program {
    /// Runs the recursion for `spec` on a fresh graph.
    pub fn build(spec: &Spec) -> Program {
        let mut rec = Recursion::new(spec, Graph::new(spec));
        let outputs = match spec.kind {
            Kind::Spt => {
                let (f, g) = rec.top();
                vec![f, g]
            }
            Kind::Redshift => crate::redshift::coefficients(spec, &mut rec),
        };
        let stats = rec.stats;
        Program {
            spec: spec.clone(),
            dag: rec.alg.dag,
            outputs,
            stats,
        }
    }

    /// Which graph nodes the outputs need.
    pub fn live(&self) -> Vec<bool> {
        self.dag.live(&self.outputs.iter().collect::<Vec<_>>())
    }

    /// Operation counts of the emitted code.
    pub fn op_counts(&self) -> OpCounts {
        let live = self.live();
        let mut c = OpCounts::default();
        for (op, _) in self.dag.ops().iter().zip(&live).filter(|(_, &l)| l) {
            match op {
                Op::Input(_) => continue,
                Op::Lin(terms, c0) => {
                    c.adds += terms.len() - 1 + usize::from(!c0.is_zero());
                    c.muls += coefficient_muls(terms);
                }
                Op::Mul(..) => c.muls += 1,
                Op::Recip(_) => c.recips += 1,
            }
            c.statements += 1;
        }
        c
    }

    /// Every rational constant the emitted code uses.
    pub fn constants(&self) -> Vec<Q> {
        let live = self.live();
        let mut out: Vec<Q> = Vec::new();
        let mut push = |r: &Q| {
            if !out.contains(r) {
                out.push(r.clone());
            }
        };
        for (op, _) in self.dag.ops().iter().zip(&live).filter(|(_, &l)| l) {
            if let Op::Lin(terms, c0) = op {
                terms.iter().for_each(|(r, _)| push(&r.abs_value()));
                if !c0.is_zero() {
                    push(&c0.abs_value());
                }
            }
        }
        self.outputs.iter().for_each(|o| push(&o.coef.abs_value()));
        out
    }

    /// The subsets of the arguments whose total momentum vanishes identically (never evaluated).
    pub fn zero_momentum_subsets(&self) -> Vec<Mask> {
        let n = self.spec.order();
        (1..(1u32 << n))
            .filter(|s| s.count_ones() >= 2 && momentum(&self.spec, *s).iter().all(|&c| c == 0))
            .collect()
    }
}

trait AbsValue {
    fn abs_value(&self) -> Q;
}

impl AbsValue for Q {
    fn abs_value(&self) -> Q {
        if self < &Q::zero() {
            -self.clone()
        } else {
            self.clone()
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn f2_graph_is_small() {
        let spec = Spec::free("f2", 2).unwrap();
        let p = Program::build(&spec);
        // F2 needs 1/q1², 1/q2², and a handful of products: a sanity bound, not a snapshot.
        let c = p.op_counts();
        assert_eq!(c.recips, 2);
        assert!(c.flops() < 30, "{c:?}");
    }

    #[test]
    fn propagator_drops_the_zero_momentum_subsets() {
        for x in 1..=3 {
            let spec = Spec::propagator("p", x).unwrap();
            let p = Program::build(&spec);
            // Subsets of {±q_i} holding whole pairs only: 2^x − 1 of them.
            assert_eq!(p.zero_momentum_subsets().len(), (1 << x) - 1);
            assert_eq!(p.stats.zero_momentum_subsets, (1 << x) - 1);
            // No norm that is identically zero is ever inverted: every Recip operand is a live, non-constant node.
            for op in p.dag.ops() {
                if let Op::Recip(x) = op {
                    assert!(!matches!(p.dag.ops()[*x], Op::Lin(ref t, _) if t.is_empty()));
                }
            }
        }
    }
}
