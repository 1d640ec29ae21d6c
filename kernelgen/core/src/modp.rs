//! Arithmetic modulo the Mersenne prime p = 2^61 − 1: exact identity tests on the expression graph.
//!
//! Two nodes of the graph that are equal as rational functions of the inputs (up to a constant factor) take
//! equal values (up to that factor) at a random point modulo p; two that differ agree there with probability
//! below (degree)/p ≈ 1e-16 per point (Schwartz–Zippel), and [`crate::pairing`] asks for agreement at three
//! points. No rounding is involved, so the test is exact in the sense that matters: a match is an identity
//! with overwhelming probability, and the generated code is checked against the direct program in exact
//! rationals by the tests of the crates that use it. [`evaluate_direct`] and [`evaluate_paired`] run a
//! program and its lane-pair form this way, to check one against the other.

use crate::dag::{Dag, Op, Q};
use crate::paired::{Output, PairOp, Paired, Var};
use crate::program::Program;
use num_bigint::BigInt;
use num_integer::Integer;
use num_traits::Signed;
use std::ops::{Add, Mul, Neg, Sub};

/// The modulus 2^61 − 1.
pub const P: u64 = (1 << 61) - 1;

/// An element of the field Z/pZ.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct Fp(u64);

impl Fp {
    /// The residue of `x`.
    pub fn new(x: u64) -> Self {
        Fp(x % P)
    }

    /// 1/a, and 0 for a = 0 (as the generated code's `safe_recip`).
    pub fn recip(self) -> Fp {
        let (mut base, mut e, mut r) = (self, P - 2, Fp(1));
        while e > 0 {
            if e & 1 == 1 {
                r = r.mul(base);
            }
            base = base.mul(base);
            e >>= 1;
        }
        r
    }

    /// The residue of an exact rational (its denominator is never a multiple of p here).
    pub fn from_q(r: &Q) -> Fp {
        let m = BigInt::from(P);
        let residue = |x: &BigInt| -> Fp {
            let v = x.mod_floor(&m);
            Fp(u64::try_from(v).expect("reduced below p"))
        };
        residue(r.numer()).mul(residue(r.denom()).recip())
    }

    /// The rational n/d with |n|, d < 2^20 whose residue is `self`, if there is one (unique when it exists;
    /// a residue drawn at random has one with probability ~1e-6, so a hit is not a coincidence).
    pub fn to_small_rational(self) -> Option<Q> {
        // Extended Euclid on (p, a), stopped at the first remainder below the bound (Wang's reconstruction).
        let bound: i128 = 1 << 20;
        let (mut r0, mut r1) = (P as i128, self.0 as i128);
        let (mut t0, mut t1) = (0i128, 1i128);
        while r1 >= bound {
            let q = r0 / r1;
            (r0, r1) = (r1, r0 - q * r1);
            (t0, t1) = (t1, t0 - q * t1);
        }
        if t1 == 0 || t1.abs() >= bound {
            return None;
        }
        let r = Q::new(BigInt::from(r1), BigInt::from(t1));
        (Fp::from_q(&r) == self && r.numer().abs() < BigInt::from(bound)).then_some(r)
    }
}

impl Add for Fp {
    type Output = Fp;
    fn add(self, b: Fp) -> Fp {
        Fp((self.0 + b.0) % P)
    }
}

impl Sub for Fp {
    type Output = Fp;
    fn sub(self, b: Fp) -> Fp {
        Fp((self.0 + P - b.0) % P)
    }
}

impl Neg for Fp {
    type Output = Fp;
    fn neg(self) -> Fp {
        Fp((P - self.0) % P)
    }
}

impl Mul for Fp {
    type Output = Fp;
    fn mul(self, b: Fp) -> Fp {
        Fp(((self.0 as u128 * b.0 as u128) % P as u128) as u64)
    }
}

/// The value of every node of `dag` at the given inputs (zero for nodes whose inputs are missing).
pub fn evaluate(dag: &Dag, inputs: &[Fp]) -> Vec<Fp> {
    let mut v: Vec<Fp> = Vec::with_capacity(dag.ops().len());
    for op in dag.ops() {
        let x = match op {
            Op::Input(i) => inputs[*i],
            Op::Lin(terms, c0) => terms.iter().fold(Fp::from_q(c0), |acc, (c, t)| {
                acc.add(Fp::from_q(c).mul(v[*t]))
            }),
            Op::Mul(a, b) => v[*a].mul(v[*b]),
            Op::Recip(a) => v[*a].recip(),
        };
        v.push(x);
    }
    v
}

/// (F, G) of the direct program modulo p at `g`.
pub fn evaluate_direct(program: &Program, g: &[Fp]) -> (Fp, Fp) {
    let v = evaluate(&program.dag, g);
    let out = |x: &crate::dag::Value| {
        let c = Fp::from_q(&x.coef);
        x.node.map_or(c, |id| c.mul(v[id]))
    };
    (out(&program.outputs[0]), out(&program.outputs[1]))
}

/// Evaluates the paired program modulo p at `g` (both lanes), for tests: returns (F, G).
pub fn evaluate_paired(p: &Paired, g: &[Fp]) -> (Fp, Fp) {
    let mut y: Vec<[Fp; 2]> = Vec::with_capacity(p.ops.len());
    let swap = |v: [Fp; 2]| [v[1], v[0]];
    for op in &p.ops {
        let v = match op {
            PairOp::Input { i, j, negated } => [g[*i], if *negated { g[*j].neg() } else { g[*j] }],
            PairOp::Mul { a, b, swap_b } => {
                let bv = if *swap_b { swap(y[*b]) } else { y[*b] };
                [y[*a][0].mul(bv[0]), y[*a][1].mul(bv[1])]
            }
            PairOp::Recip(a) => y[*a].map(Fp::recip),
            PairOp::Lin {
                direct,
                swapped,
                c0,
            } => {
                let sum = |terms: &[(Q, Var)], lane: usize, swap_it: bool| {
                    terms.iter().fold(Fp::new(0), |acc, (c, v)| {
                        let val = if swap_it { swap(y[*v]) } else { y[*v] };
                        acc.add(Fp::from_q(c).mul(val[lane]))
                    })
                };
                std::array::from_fn(|l| {
                    Fp::from_q(c0)
                        .add(sum(direct, l, false))
                        .add(sum(swapped, l, true))
                })
            }
        };
        y.push(v);
    }
    let out = |o: &Output| {
        let c = Fp::from_q(&o.coef);
        match o.var {
            None => c,
            Some((v, lane)) => c.mul(y[v][lane]),
        }
    };
    (out(&p.f), out(&p.g))
}

/// A deterministic stream of field elements (SplitMix64), so that generated code is reproducible.
pub struct Stream(u64);

impl Stream {
    /// A stream from a seed.
    pub fn new(seed: u64) -> Self {
        Stream(seed)
    }

    /// The next element.
    pub fn next_fp(&mut self) -> Fp {
        self.0 = self.0.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        Fp::new(z ^ (z >> 31))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::dag::q;

    #[test]
    fn field_arithmetic_and_inverse() {
        let a = Fp::new(123_456_789);
        assert_eq!(a.mul(a.recip()), Fp::new(1));
        assert_eq!(a.sub(a), Fp::new(0));
        assert_eq!(a.add(a.neg()), Fp::new(0));
        assert_eq!(Fp::new(0).recip(), Fp::new(0));
        assert_eq!(Fp::new(P + 5), Fp::new(5));
    }

    #[test]
    fn small_rationals_are_recovered_from_their_residues() {
        for r in [q(1, 1), q(-1, 1), q(7, 5), q(-1219, 1470), q(1, 2), q(0, 1)] {
            assert_eq!(Fp::from_q(&r).to_small_rational(), Some(r.clone()), "{r}");
        }
        // About 2^41 of the 2^61 residues have a preimage with |n|, d < 2^20: of 1,000 pseudo-random ones
        // none does, nor does the residue of 1/2^40 (≡ 2^21, as 2^61 ≡ 1).
        let mut s = Stream::new(7);
        assert!((0..1000).all(|_| s.next_fp().to_small_rational().is_none()));
        assert_eq!(Fp::from_q(&q(1, 1 << 40)).to_small_rational(), None);
        assert_eq!(
            Fp::from_q(&q(1, 1 << 19)).to_small_rational(),
            Some(q(1, 1 << 19))
        );
    }

    #[test]
    fn evaluation_follows_the_graph() {
        let mut dag = Dag::new();
        let x = dag.input(0);
        let y = dag.input(1);
        let s = dag.lin(&[(q(1, 1), x.clone()), (q(2, 1), y.clone())]);
        let m = dag.mul(&s, &x);
        let r = dag.recip(&m);
        let v = evaluate(&dag, &[Fp::new(3), Fp::new(5)]);
        // (3 + 10)·3 = 39 (the Lin node holds the normalised sum, coefficient 1 on x).
        assert_eq!(v[s.node.unwrap()], Fp::new(13));
        assert_eq!(v[m.node.unwrap()], Fp::new(39));
        assert_eq!(v[r.node.unwrap()], Fp::new(39).recip());
    }
}
