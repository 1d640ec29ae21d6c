//! The recursion's algebra on the expression graph: subset norms and dot products as exact linear forms
//! in the Gram-matrix inputs.
//!
//! Every subset norm k_S² and every dot product k_A·k_B is a linear form in the Gram-matrix inputs that is
//! known exactly here, so forms that coincide are computed once, forms that vanish are constant zeros, and
//! a dot product costs two additions of norms already at hand: k_A·k_B = (k_{A∪B}² − k_A² − k_B²)/2.

use crate::dag::{q, Dag, Value, Q};
use crate::recursion::{momentum, Algebra, Mask};
use crate::spec::Spec;
use num_traits::Zero;
use std::collections::HashMap;

/// The recursion's algebra over the expression graph of one configuration.
pub struct Graph<'s> {
    spec: &'s Spec,
    /// The graph being built.
    pub dag: Dag,
    /// Gram-form → value of every norm and dot product built so far.
    forms: HashMap<Vec<i64>, Value>,
}

impl<'s> Graph<'s> {
    pub(crate) fn new(spec: &'s Spec) -> Self {
        Graph {
            spec,
            dag: Dag::new(),
            forms: HashMap::new(),
        }
    }

    /// The Gram form of (Σ_a c1_a e_a)·(Σ_b c2_b e_b): its coefficient on each input.
    fn form(&self, c1: &[i64], c2: &[i64]) -> Vec<i64> {
        let mut f = vec![0; self.spec.n_inputs()];
        for (a, x) in c1.iter().enumerate() {
            for (b, y) in c2.iter().enumerate() {
                f[self.spec.gram_index(a, b)] += x * y;
            }
        }
        f
    }

    /// k_S² as a linear combination of the inputs.
    fn norm(&mut self, s: Mask) -> Value {
        let c = momentum(self.spec, s);
        let f = self.form(&c, &c);
        if let Some(v) = self.forms.get(&f) {
            return v.clone();
        }
        let terms: Vec<(Q, Value)> = f
            .iter()
            .enumerate()
            .filter(|(_, &x)| x != 0)
            .map(|(i, &x)| (q(x, 1), self.dag.input(i)))
            .collect::<Vec<_>>();
        let v = self.dag.lin(&terms);
        self.forms.insert(f, v.clone());
        v
    }

    /// The value of a Gram form, memoised; `build` makes it from norms the first time.
    fn form_value(&mut self, f: Vec<i64>, build: impl FnOnce(&mut Self) -> Value) -> Value {
        if f.iter().all(|&x| x == 0) {
            return Value::constant(Q::zero());
        }
        if let Some(v) = self.forms.get(&f) {
            return v.clone();
        }
        let v = build(self);
        self.forms.insert(f, v.clone());
        v
    }

    /// k_S·e_b, the dot product of a subset's momentum with basis vector `b`: a linear form in the inputs.
    pub fn basis_dot(&mut self, s: Mask, b: usize) -> Value {
        let mut unit = vec![0; self.spec.basis.len()];
        unit[b] = 1;
        let f = self.form(&momentum(self.spec, s), &unit);
        self.form_value(f.clone(), |g| {
            let terms: Vec<(Q, Value)> = f
                .iter()
                .enumerate()
                .filter(|(_, &x)| x != 0)
                .map(|(i, &x)| (q(x, 1), g.dag.input(i)))
                .collect();
            g.dag.lin(&terms)
        })
    }

    /// e_a·e_b, one input.
    pub fn input(&mut self, a: usize, b: usize) -> Value {
        let i = self.spec.gram_index(a, b);
        self.dag.input(i)
    }

    /// (k_X² + k_Y² − k_Z²)/2 from three subset norms: a dot product in two additions.
    fn half_sum(&mut self, x: Mask, y: Mask, z: Mask) -> Value {
        let (x, y, z) = (self.norm(x), self.norm(y), self.norm(z));
        self.dag.lin(&[(q(1, 2), x), (q(1, 2), y), (q(-1, 2), z)])
    }
}

impl Algebra for Graph<'_> {
    type V = Value;
    fn constant(&mut self, r: Q) -> Value {
        Value::constant(r)
    }
    fn is_zero(&self, v: &Value) -> bool {
        v.is_zero()
    }
    fn mul(&mut self, a: &Value, b: &Value) -> Value {
        self.dag.mul(a, b)
    }
    fn lin(&mut self, terms: &[(Q, Value)]) -> Value {
        self.dag.lin(terms)
    }
    fn norm(&mut self, s: Mask) -> Value {
        Graph::norm(self, s)
    }
    fn total_dot(&mut self, s: Mask, a: Mask) -> Value {
        // k_S·k_A = (k_S² + k_A² − k_B²)/2 with B = S∖A
        let f = self.form(&momentum(self.spec, s), &momentum(self.spec, a));
        self.form_value(f, |g| g.half_sum(s, a, s ^ a))
    }
    fn pair_dot(&mut self, a: Mask, b: Mask) -> Value {
        // k_A·k_B = (k_{A∪B}² − k_A² − k_B²)/2
        let f = self.form(&momentum(self.spec, a), &momentum(self.spec, b));
        self.form_value(f, |g| {
            let (s, na, nb) = (g.norm(a | b), g.norm(a), g.norm(b));
            g.dag.lin(&[(q(1, 2), s), (q(-1, 2), na), (q(-1, 2), nb)])
        })
    }
    fn over_norm(&mut self, a: Mask, g: &Value) -> Value {
        let n = self.norm(a);
        let inv = self.dag.recip(&n);
        self.dag.mul(g, &inv)
    }
}
