//! A hash-consed expression graph with exact rational coefficients.
//!
//! Every quantity the recursion builds is a [`Value`]: an exact rational constant times a node of the graph
//! (or a bare constant). Constants are therefore folded as the graph is built, equal sub-expressions are
//! shared (hash-consing), and anything known to be zero at generation time simply never becomes a node.
//! Nodes are created after their operands, so creation order is a valid evaluation order.

use num_bigint::BigInt;
use num_rational::BigRational;
use num_traits::{One, Signed, Zero};
use std::collections::HashMap;

/// Exact rational used for every coefficient.
pub type Q = BigRational;

/// Index of a node in the graph.
pub type NodeId = usize;

/// One operation of the straight-line program.
#[derive(Clone, Debug, PartialEq, Eq, Hash)]
pub enum Op {
    /// The i-th input (a Gram-matrix entry).
    Input(usize),
    /// Σ c_i · x_i + c_0, with the first c_i equal to 1 (normalised for sharing).
    Lin(Vec<(Q, NodeId)>, Q),
    /// x · y, operands ordered.
    Mul(NodeId, NodeId),
    /// 1/x, and 0 where x is exactly 0 (the limit every use of it needs; see the recursion).
    Recip(NodeId),
}

/// `coef × node`, or the constant `coef` when `node` is `None`.
#[derive(Clone, Debug, PartialEq, Eq, Hash)]
pub struct Value {
    /// Exact multiplier.
    pub coef: Q,
    /// The node multiplied, if any.
    pub node: Option<NodeId>,
}

impl Value {
    /// The constant r.
    pub fn constant(r: Q) -> Self {
        Value {
            coef: r,
            node: None,
        }
    }

    /// True if the value is exactly zero.
    pub fn is_zero(&self) -> bool {
        self.coef.is_zero()
    }

    /// The value as a constant, if it is one.
    pub fn as_constant(&self) -> Option<&Q> {
        self.node.is_none().then_some(&self.coef)
    }

    /// r × self.
    pub fn scaled(&self, r: &Q) -> Self {
        if r.is_zero() {
            return Value::constant(Q::zero());
        }
        Value {
            coef: &self.coef * r,
            node: self.node,
        }
    }
}

/// The expression graph.
#[derive(Default, Debug)]
pub struct Dag {
    ops: Vec<Op>,
    index: HashMap<Op, NodeId>,
}

impl Dag {
    /// An empty graph.
    pub fn new() -> Self {
        Self::default()
    }

    /// All nodes in creation (= evaluation) order.
    pub fn ops(&self) -> &[Op] {
        &self.ops
    }

    fn intern(&mut self, op: Op) -> NodeId {
        if let Some(&id) = self.index.get(&op) {
            return id;
        }
        let id = self.ops.len();
        self.ops.push(op.clone());
        self.index.insert(op, id);
        id
    }

    /// The i-th input.
    pub fn input(&mut self, i: usize) -> Value {
        let id = self.intern(Op::Input(i));
        Value {
            coef: Q::one(),
            node: Some(id),
        }
    }

    /// Σ r_i · v_i, with like terms merged, zeros dropped and the result normalised for sharing.
    pub fn lin(&mut self, terms: &[(Q, Value)]) -> Value {
        let mut constant = Q::zero();
        let mut merged: Vec<(Q, NodeId)> = Vec::new();
        for (r, v) in terms {
            let c = r * &v.coef;
            if c.is_zero() {
                continue;
            }
            match v.node {
                None => constant += c,
                Some(id) => match merged.iter_mut().find(|(_, n)| *n == id) {
                    Some(slot) => slot.0 += c,
                    None => merged.push((c, id)),
                },
            }
        }
        merged.retain(|(c, _)| !c.is_zero());
        merged.sort_by_key(|&(_, id)| id);
        match merged.len() {
            0 => Value::constant(constant),
            1 if constant.is_zero() => {
                let (c, id) = merged.pop().expect("one term");
                Value {
                    coef: c,
                    node: Some(id),
                }
            }
            _ => {
                let lead = merged[0].0.clone();
                let normalised: Vec<(Q, NodeId)> =
                    merged.into_iter().map(|(c, id)| (c / &lead, id)).collect();
                let id = self.intern(Op::Lin(normalised, constant / &lead));
                Value {
                    coef: lead,
                    node: Some(id),
                }
            }
        }
    }

    /// a · b.
    pub fn mul(&mut self, a: &Value, b: &Value) -> Value {
        let coef = &a.coef * &b.coef;
        if coef.is_zero() {
            return Value::constant(Q::zero());
        }
        let node = match (a.node, b.node) {
            (None, n) | (n, None) => n,
            (Some(x), Some(y)) => Some(self.intern(Op::Mul(x.min(y), x.max(y)))),
        };
        Value { coef, node }
    }

    /// The product of several values.
    pub fn product(&mut self, factors: &[&Value]) -> Value {
        let mut acc = Value::constant(Q::one());
        for f in factors {
            acc = self.mul(&acc, f);
        }
        acc
    }

    /// 1/a (a must not be the constant zero).
    pub fn recip(&mut self, a: &Value) -> Value {
        assert!(!a.is_zero(), "reciprocal of an exact zero requested");
        match a.node {
            None => Value::constant(a.coef.recip()),
            Some(x) => {
                let id = self.intern(Op::Recip(x));
                Value {
                    coef: a.coef.recip(),
                    node: Some(id),
                }
            }
        }
    }

    /// Nodes reachable from `roots`, as a mask over node ids.
    pub fn live(&self, roots: &[&Value]) -> Vec<bool> {
        let mut live = vec![false; self.ops.len()];
        for r in roots {
            if let Some(id) = r.node {
                live[id] = true;
            }
        }
        for id in (0..self.ops.len()).rev() {
            if !live[id] {
                continue;
            }
            match &self.ops[id] {
                Op::Input(_) => {}
                Op::Lin(terms, _) => terms.iter().for_each(|&(_, t)| live[t] = true),
                Op::Mul(x, y) => {
                    live[*x] = true;
                    live[*y] = true;
                }
                Op::Recip(x) => live[*x] = true,
            }
        }
        live
    }
}

/// The integer pair (numerator, denominator) of an exact rational, if both fit in i64.
pub fn as_i64_pair(r: &Q) -> Option<(i64, i64)> {
    let n: i64 = r.numer().try_into().ok()?;
    let d: i64 = r.denom().try_into().ok()?;
    Some((n, d))
}

/// True if |numerator| and denominator are both below 2^53, so that `n as f64 / d as f64` is correctly rounded.
pub fn exact_in_f64(r: &Q) -> bool {
    let bound = BigInt::from(1u64 << 53);
    r.numer().abs() < bound && r.denom().abs() < bound
}

/// The rational n/d.
pub fn q(n: i64, d: i64) -> Q {
    Q::new(BigInt::from(n), BigInt::from(d))
}

/// Multiplications of a linear combination as emitted: one per distinct |coefficient| other than 1.
pub fn coefficient_muls(terms: &[(Q, NodeId)]) -> usize {
    group_by_magnitude(terms)
        .iter()
        .filter(|(m, _)| !m.is_one())
        .count()
}

/// Terms of a linear combination grouped by the magnitude of their coefficient, each with its sign.
pub fn group_by_magnitude(terms: &[(Q, NodeId)]) -> Vec<(Q, Vec<(bool, NodeId)>)> {
    let mut groups: Vec<(Q, Vec<(bool, NodeId)>)> = Vec::new();
    for (c, id) in terms {
        let mag = c.abs();
        let entry = (c.is_negative(), *id);
        match groups.iter_mut().find(|(m, _)| *m == mag) {
            Some((_, g)) => g.push(entry),
            None => groups.push((mag, vec![entry])),
        }
    }
    groups
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn constants_fold_and_zeros_vanish() {
        let mut dag = Dag::new();
        let x = dag.input(0);
        let two = Value::constant(q(2, 1));
        let y = dag.mul(&x, &two);
        assert_eq!(y.node, x.node);
        assert_eq!(y.coef, q(2, 1));
        let zero = dag.lin(&[(q(1, 1), y.clone()), (q(-2, 1), x.clone())]);
        assert!(zero.is_zero() && zero.node.is_none());
        assert!(dag.mul(&zero, &x).is_zero());
    }

    #[test]
    fn equal_expressions_share_one_node() {
        let mut dag = Dag::new();
        let a = dag.input(0);
        let b = dag.input(1);
        let s1 = dag.lin(&[(q(1, 1), a.clone()), (q(3, 1), b.clone())]);
        let s2 = dag.lin(&[(q(2, 1), a.clone()), (q(6, 1), b.clone())]);
        assert_eq!(s1.node, s2.node);
        assert_eq!(s2.coef, q(2, 1));
        let p1 = dag.mul(&a, &b);
        let p2 = dag.mul(&b, &a);
        assert_eq!(p1, p2);
        assert_eq!(dag.ops().len(), 4);
    }

    #[test]
    fn dead_nodes_are_not_live() {
        let mut dag = Dag::new();
        let a = dag.input(0);
        let b = dag.input(1);
        let _unused = dag.mul(&a, &b);
        let r = dag.recip(&a);
        let live = dag.live(&[&r]);
        assert_eq!(live, vec![true, false, false, true]);
    }

    #[test]
    fn f64_exactness_bound() {
        assert!(exact_in_f64(&q(1219, 1470)));
        assert!(!exact_in_f64(&Q::new(
            BigInt::from(1u64 << 53),
            BigInt::from(3)
        )));
    }
}
