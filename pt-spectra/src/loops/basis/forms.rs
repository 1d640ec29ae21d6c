//! The bilinear and linear forms on the basis of a node set of the 2-D loop integrals ([`PairNodes`]):
//! what turns a plan's quadrature of a spectrum's lattice samples into contractions with the
//! spectrum's coefficients.
//!
//! A node set at k index i integrates Σ_outer P̃(q_o) Σ_inner w_m P̃(p_j), with P̃ the lattice
//! interpolant of the samples. With P̃ = Σ_a c_a φ̃_a this is Σ_{a,b} c_a c_b T^m_ab, T^m_ab =
//! Σ_outer φ̃_a(q_o) Σ_inner w_m φ̃_b(p_j) ([`pair_forms`]); kernels that multiply P(k) rather than
//! P(q) or P(p) leave linear forms ([`NodeForms::inner`]: Σ_outer Σ_inner w φ̃(p), and
//! [`NodeForms::outer`]: Σ_outer φ̃(q) Σ_inner w).

use super::{pair_index, triple_index, triples};
use crate::integrate::lagrange4;
use crate::loops::lattice::Lattice;
use crate::loops::p22::PairNodes;
use std::ops::Range;

/// The basis functions' samples on a lattice, row by row: `rows[j * stride + a]` = φ_a(q_j).
pub(crate) struct Rows<'a> {
    pub rows: &'a [f64],
    pub stride: usize,
    pub lattice: &'a Lattice,
}

impl Rows<'_> {
    /// The interpolants of all functions at the stencil (first point `b`, Lagrange weights `l`).
    fn stencil(&self, b: usize, l: [f64; 4], out: &mut [f64]) {
        out.iter_mut().for_each(|o| *o = 0.0);
        let n = self.stride;
        for (m, lm) in l.iter().enumerate() {
            for (o, p) in out.iter_mut().zip(&self.rows[(b + m) * n..(b + m + 1) * n]) {
                *o += lm * p;
            }
        }
    }

    /// The interpolants of all functions at fractional lattice index `u`.
    pub fn at(&self, u: f64, out: &mut [f64]) {
        let (b, t) = self.lattice.stencil(u);
        self.stencil(b, lagrange4(t), out);
    }
}

/// The forms of one k: symmetric bilinear forms (pairs a ≤ b of the first n functions) and linear
/// forms (length `stride`).
pub(crate) struct NodeForms {
    /// One per bilinear weight.
    pub pairs: Vec<Vec<f64>>,
    /// Σ_outer Σ_inner w φ̃(p), one per weight of the `inner` range.
    pub inner: Vec<Vec<f64>>,
    /// Σ_outer φ̃(q) Σ_inner w, one per weight of the `outer` range.
    pub outer: Vec<Vec<f64>>,
}

/// The forms of node set `nodes` at k index `i`: bilinear ones for the weights `bilinear` on the first
/// `n` functions, linear ones for the weights `inner` and `outer`.
pub(crate) fn pair_forms<const M: usize>(
    nodes: &PairNodes<M>,
    i: usize,
    rows: &Rows<'_>,
    n: usize,
    bilinear: Range<usize>,
    inner: Range<usize>,
    outer: Range<usize>,
) -> NodeForms {
    let stride = rows.stride;
    let nb = bilinear.len();
    let (mut start, outer_nodes) = nodes.ranges(i);
    let mut full = vec![vec![0.0; n * n]; nb];
    let mut lin_inner = vec![vec![0.0; stride]; inner.len()];
    let mut lin_outer = vec![vec![0.0; stride]; outer.len()];
    let (mut phi_q, mut phi_p) = (vec![0.0; stride], vec![0.0; stride]);
    let mut acc = vec![vec![0.0; n]; nb];
    for o in outer_nodes {
        let end = nodes.outer_end[o] as usize;
        acc.iter_mut()
            .for_each(|a| a.iter_mut().for_each(|v| *v = 0.0));
        let mut weight_sums = vec![0.0; outer.len()];
        for j in start..end {
            let w = &nodes.inner_w[j];
            rows.stencil(
                nodes.inner_b[j] as usize,
                nodes.inner_l[j].map(f64::from),
                &mut phi_p,
            );
            for (a, m) in acc.iter_mut().zip(bilinear.clone()) {
                let w = f64::from(w[m]);
                a.iter_mut().zip(&phi_p[..n]).for_each(|(a, p)| *a += w * p);
            }
            for (l, m) in lin_inner.iter_mut().zip(inner.clone()) {
                let w = f64::from(w[m]);
                l.iter_mut().zip(&phi_p).for_each(|(l, p)| *l += w * p);
            }
            for (s, m) in weight_sums.iter_mut().zip(outer.clone()) {
                *s += f64::from(w[m]);
            }
        }
        rows.at(nodes.outer_u[o], &mut phi_q);
        for (t, a) in full.iter_mut().zip(&acc) {
            for (row, q) in t.chunks_exact_mut(n).zip(&phi_q[..n]) {
                row.iter_mut().zip(a).for_each(|(t, a)| *t += q * a);
            }
        }
        for (l, s) in lin_outer.iter_mut().zip(&weight_sums) {
            l.iter_mut().zip(&phi_q).for_each(|(l, q)| *l += s * q);
        }
        start = end;
    }
    let pairs = full
        .into_iter()
        .map(|t| {
            let mut sym = vec![0.0; n * (n + 1) / 2];
            for b in 0..n {
                for a in 0..b {
                    sym[pair_index(a, b)] = t[a * n + b] + t[b * n + a];
                }
                sym[pair_index(b, b)] = t[b * n + b];
            }
            sym
        })
        .collect();
    NodeForms {
        pairs,
        inner: lin_inner,
        outer: lin_outer,
    }
}

/// Σ_j w_j φ_a(q_j) for every a.
pub(crate) fn linear_form(weights: &[f64], rows: &Rows<'_>) -> Vec<f64> {
    let n = rows.stride;
    let mut out = vec![0.0; n];
    for (w, row) in weights.iter().zip(rows.rows.chunks_exact(n)) {
        out.iter_mut().zip(row).for_each(|(o, p)| *o += w * p);
    }
    out
}

pub(crate) use crate::simd::{dot32, dot_f32};

/// The products c_a c_b on the pairs a ≤ b in f64 (for the short error rows, [`dot32`]) and in f32
/// (for the long rows of the values, [`dot_f32`]).
pub(crate) fn pair_products_both(c: &[f64]) -> (Vec<f64>, Vec<f32>) {
    let s2 = pair_products(c);
    let single = s2.iter().map(|&v| v as f32).collect();
    (s2, single)
}

/// The products c_a c_b on the pairs a ≤ b.
pub(crate) fn pair_products(c: &[f64]) -> Vec<f64> {
    let n = c.len();
    let mut s2 = vec![0.0; n * (n + 1) / 2];
    for b in 0..n {
        for a in 0..=b {
            s2[pair_index(a, b)] = c[a] * c[b];
        }
    }
    s2
}

/// The basis functions on a plan's fine lattice and on its half-resolution lattice (every other
/// point), as the plans sample a spectrum.
pub(crate) struct RuleRows {
    fine: Vec<f64>,
    coarse: Vec<f64>,
    n: usize,
}

impl RuleRows {
    pub fn new(basis: &super::LinearBasis) -> Self {
        let rows = |stride: usize| {
            (0..basis.lattice().len)
                .step_by(stride)
                .flat_map(|j| basis.row(j).iter().copied())
                .collect()
        };
        Self {
            fine: rows(1),
            coarse: rows(2),
            n: basis.len(),
        }
    }

    /// Functions given by row on the fine lattice (`rows[j * n + a]`, e.g.
    /// [`super::LinearBasis::transformed_rows`]).
    pub fn from_rows(rows: Vec<f64>, n: usize) -> Self {
        let coarse = rows.chunks_exact(n).step_by(2).flatten().copied().collect();
        Self {
            fine: rows,
            coarse,
            n,
        }
    }

    /// The rows on the fine `lattice` and on the half-resolution `coarse` one.
    pub fn on<'a>(&'a self, fine: &'a Lattice, coarse: &'a Lattice) -> (Rows<'a>, Rows<'a>) {
        let rows = |rows: &'a [f64], lattice| Rows {
            rows,
            stride: self.n,
            lattice,
        };
        (rows(&self.fine, fine), rows(&self.coarse, coarse))
    }
}

/// `make(i)` for every k index i < `nk` in parallel, in order, counting them to `progress`.
pub(crate) fn per_k<T: Send>(
    nk: usize,
    progress: &(dyn Fn(usize, usize) + Sync),
    make: impl Fn(usize) -> T + Sync,
) -> Vec<T> {
    use rayon::prelude::*;
    let done = std::sync::atomic::AtomicUsize::new(0);
    (0..nk)
        .into_par_iter()
        .map(|i| {
            let t = make(i);
            progress(
                done.fetch_add(1, std::sync::atomic::Ordering::Relaxed) + 1,
                nk,
            );
            t
        })
        .collect()
}

/// The fine-rule bilinear forms in f32, and fine minus half-resolution on the pairs the latter was
/// made on (the first n_err functions, whose pairs come first in the symmetric storage).
pub(crate) fn fine_and_diff(fine: &[Vec<f64>], coarse: &[Vec<f64>]) -> (Vec<f32>, Vec<f32>) {
    let mut pairs = Vec::new();
    let mut diff = Vec::new();
    for (f, c) in fine.iter().zip(coarse) {
        pairs.extend(f.iter().map(|&v| v as f32));
        diff.extend(f.iter().zip(c).map(|(f, c)| (f - c) as f32));
    }
    (pairs, diff)
}

/// The per-k parts of three tensors, each concatenated over k.
pub(crate) fn concat<A, B, C>(per_k: Vec<(Vec<A>, Vec<B>, Vec<C>)>) -> (Vec<A>, Vec<B>, Vec<C>) {
    let (mut a, mut b, mut c) = (Vec::new(), Vec::new(), Vec::new());
    for (x, y, z) in per_k {
        a.extend(x);
        b.extend(y);
        c.extend(z);
    }
    (a, b, c)
}

/// The coefficients up to the last non-zero one (those after it contribute nothing).
pub(crate) fn leading(c: &[f64]) -> &[f64] {
    &c[..c.iter().rposition(|&x| x != 0.0).map_or(0, |i| i + 1)]
}

/// The symmetric form of a full n³ tensor on the triples a ≤ b ≤ c (at [`triple_index`]): Σ over
/// the distinct permutations, so that Σ_{a≤b≤c} packed c_a c_b c_c = Σ_{abc} T_abc c_a c_b c_c.
pub(crate) fn pack_triples(t: &[f64], n: usize) -> Vec<f64> {
    let at = |a: usize, b: usize, c: usize| t[(a * n + b) * n + c];
    let mut out = vec![0.0; triples(n)];
    for c in 0..n {
        for b in 0..=c {
            for a in 0..=b {
                let all = at(a, b, c)
                    + at(a, c, b)
                    + at(b, a, c)
                    + at(b, c, a)
                    + at(c, a, b)
                    + at(c, b, a);
                // Each distinct permutation appears 6 / (number of distinct ones) times in `all`.
                let repeats = match (a == b, b == c) {
                    (true, true) => 6.0,
                    (false, false) if a != c => 1.0,
                    _ => 2.0,
                };
                out[triple_index(a, b, c)] = all / repeats;
            }
        }
    }
    out
}

/// The symmetric form of an n × n matrix on the pairs a ≤ b (at [`pair_index`]).
pub(crate) fn pack_pairs(m: &[f64], n: usize) -> Vec<f64> {
    let mut out = vec![0.0; n * (n + 1) / 2];
    for b in 0..n {
        for a in 0..=b {
            out[pair_index(a, b)] = if a == b {
                m[a * n + a]
            } else {
                m[a * n + b] + m[b * n + a]
            };
        }
    }
    out
}
