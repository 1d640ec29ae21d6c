//! The redshift-space kernels Z_n of SPT (Scoccimarro, Couchman & Frieman 1999, eqs. 6–8) on the expression
//! graph, as polynomials in the growth rate f.
//!
//! Mapping the density to redshift space and symmetrising gives, over the subsets S of the arguments with
//! total momentum k_S and F_S = F^s(S), Ĝ_S = G^s(S)/k_S² from the [recursion](crate::recursion), the line of
//! sight n̂ (any length) and k the total momentum,
//!
//! ```text
//! Z_n = (1/n!) Σ_{S_0 ≠ ∅} |S_0|! [F_{S_0} + f (n̂·k_{S_0})² Ĝ_{S_0}/(n̂·n̂)] E(complement of S_0),
//! E(R) = Σ over set partitions {B} of R of Π_B |B|! f (n̂·k)(n̂·k_B) Ĝ_B/(n̂·n̂),   E(∅) = 1.
//! ```
//!
//! A partition into p blocks carries f^p, so with W_B = (n̂·k_B) Ĝ_B and Ẽ_p(R) the sum over the partitions
//! of R into p blocks of Π |B|! W_B (built block by block: the block holding the lowest member of R, then
//! the rest), the coefficient of f^m is
//!
//! ```text
//! Z^(m) = (1/n!) [ x^m Σ_{S_0} |S_0|! F_{S_0} Ẽ_m(R) + x^(m−1)/(n̂·n̂) Σ_{S_0} |S_0|! (n̂·k_{S_0})² Ĝ_{S_0} Ẽ_{m−1}(R) ],
//! x = (n̂·k)/(n̂·n̂),   R = complement of S_0.
//! ```
//!
//! Every factor is rational in the Gram matrix of (q_1, …, q_n, n̂), so the generated code is exact; Z^(0) is
//! F_n^s. The only reciprocals beyond the recursion's 1/k_S² is 1/(n̂·n̂).

use crate::dag::{q, Value, Q};
use crate::graph::Graph;
use crate::recursion::{Mask, Recursion};
use crate::spec::Spec;
use num_traits::{One, Zero};

fn factorial(n: u32) -> i64 {
    (1..=i64::from(n)).product()
}

/// `[Z^(0), …, Z^(n)]` of a [`crate::spec::Kind::Redshift`] configuration (module docs).
pub fn coefficients(spec: &Spec, rec: &mut Recursion<'_, Graph<'_>>) -> Vec<Value> {
    let n = spec.order();
    let los = spec
        .line_of_sight()
        .expect("a redshift configuration has a line of sight");
    let all: Mask = (1 << n) - 1;
    let zero = || Value::constant(Q::zero());
    // F_S, Ĝ_S and n̂·k_S of every non-empty subset
    let mut f_s = vec![zero(); all as usize + 1];
    let mut g_hat = vec![zero(); all as usize + 1];
    for s in 1..=all {
        let sub = rec.kernel(s);
        f_s[s as usize] = sub.f;
        g_hat[s as usize] = sub.g_hat;
    }
    let g = &mut rec.alg;
    let los_dot: Vec<Value> = (0..=all)
        .map(|s| if s == 0 { zero() } else { g.basis_dot(s, los) })
        .collect();
    let w: Vec<Value> = (0..=all as usize)
        .map(|s| g.dag.mul(&los_dot[s], &g_hat[s]))
        .collect();
    // Ẽ_p(R), p = 0..=|R|
    let mut e = vec![vec![zero(); all as usize + 1]; n + 1];
    e[0][0] = Value::constant(Q::one());
    for r in 1..=all {
        let low = r & r.wrapping_neg();
        let rest = r ^ low;
        for p in 1..=r.count_ones() as usize {
            let mut terms = Vec::new();
            let mut sub = rest;
            loop {
                let block = sub | low;
                let t = g
                    .dag
                    .mul(&w[block as usize], &e[p - 1][(r ^ block) as usize]);
                terms.push((q(factorial(block.count_ones()), 1), t));
                if sub == 0 {
                    break;
                }
                sub = (sub - 1) & rest;
            }
            e[p][r as usize] = g.dag.lin(&terms);
        }
    }
    let nn = g.input(los, los);
    let inv_nn = g.dag.recip(&nn);
    let x = g.dag.mul(&los_dot[all as usize], &inv_nn);
    let weight = |s0: Mask| q(factorial(s0.count_ones()), factorial(n as u32));
    let mut x_power = Value::constant(Q::one()); // x^(m−1) at step m
    let mut out = Vec::with_capacity(n + 1);
    for m in 0..=n {
        let mut a_terms = Vec::new();
        let mut b_terms = Vec::new();
        for s0 in 1..=all {
            let r = (all ^ s0) as usize;
            a_terms.push((weight(s0), g.dag.mul(&f_s[s0 as usize], &e[m][r])));
            if m >= 1 {
                let d = g.dag.mul(&los_dot[s0 as usize], &w[s0 as usize]);
                b_terms.push((weight(s0), g.dag.mul(&d, &e[m - 1][r])));
            }
        }
        let a = g.dag.lin(&a_terms);
        let z = if m == 0 {
            a
        } else {
            let b = g.dag.lin(&b_terms);
            let b = g.dag.mul(&b, &inv_nn);
            let xa = g.dag.mul(&x, &a);
            let sum = g.dag.lin(&[(q(1, 1), xa), (q(1, 1), b)]);
            let z = g.dag.mul(&x_power, &sum);
            x_power = g.dag.mul(&x_power, &x);
            z
        };
        out.push(z);
    }
    out
}

#[cfg(test)]
mod tests {
    use crate::modp::{evaluate, Fp};
    use crate::{Program, Spec};

    fn at(program: &Program, g: &[Fp]) -> Vec<Fp> {
        let v = evaluate(&program.dag, g);
        program
            .outputs
            .iter()
            .map(|o| {
                let c = Fp::from_q(&o.coef);
                o.node.map_or(c, |id| c * v[id])
            })
            .collect()
    }

    #[test]
    fn z1_is_one_plus_f_mu_squared() {
        // q1 = (1, 2, 2), n̂ = (0, 0, 1): q1² = 9, q1·n̂ = 2, n̂² = 1, so Z_1 = 1 + f·4/9.
        let p = Program::build(&Spec::redshift("z1", 1).unwrap());
        let g = [9, 2, 1].map(Fp::new);
        let z = at(&p, &g);
        assert_eq!(z.len(), 2);
        assert_eq!(z[0].to_small_rational(), Some(crate::dag::q(1, 1)));
        assert_eq!(z[1].to_small_rational(), Some(crate::dag::q(4, 9)));
    }

    #[test]
    fn the_f_free_part_is_f_n_and_the_top_power_is_the_linear_velocity_term() {
        // Z^(0) = F_2^s; with a unit n̂, Z^(2) = (n̂·k)/2 [μ1/q1 μ2² + μ2/q2 μ1²] (SCF99 eq. 21).
        let z2 = Program::build(&Spec::redshift("z2", 2).unwrap());
        let f2 = Program::build(&Spec::free("f2", 2).unwrap());
        // q1 = (1, 0, 1), q2 = (0, 1, 2), n̂ = (0, 0, 1)
        let g = [2, 2, 1, 5, 2, 1].map(Fp::new);
        let z = at(&z2, &g);
        let f = at(&f2, &[2, 2, 5].map(Fp::new));
        assert_eq!(z[0], f[0]);
        // n̂·k = 3, μ1/q1 = 1/2, μ1² = 1/2, μ2/q2 = 2/5, μ2² = 4/5: 3/2 (2/5 + 1/5) = 9/10
        assert_eq!(z[2].to_small_rational(), Some(crate::dag::q(9, 10)));
    }
}
