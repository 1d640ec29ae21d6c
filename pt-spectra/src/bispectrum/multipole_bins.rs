//! The bin averages of the one-loop galaxy multipoles from tensors (issue 50): [`super::one_loop_bins`]'s
//! effective triangle plus coarse-rule correction, with both parts contractions of precomputed tensors.
//!
//! B_ℓ,bin = B_ℓ(k_eff; rule) + Δ_ℓ, Δ_ℓ = Σ_n w_n B_ℓ(k_n; coarse) − B_ℓ(k_eff; coarse). The first term is
//! [`MultipoleLoopBasis`] at the effective triangles. The loops of Δ are cubic in the templates'
//! coefficients once the factors at the sides are written as contractions too (P̂(k_a) = t(k_a)·c, σ² = s·c):
//!
//! ```text
//! B₂₂₂:          T_abc c_a c_b c_c
//! B₃₂₁ᴵ:         t_a(k_s) M_bc c_a c_b c_c
//! B₃₂₁ᴵᴵ, B₄₁₁:  t_a(k_u) t_b(k_v) (J − U s)_c c_a c_b c_c
//! ```
//!
//! so each node triangle's tensors fold into one packed triple per (ℓ, term, monomial, power of f), and the
//! weighted sum over the bin's nodes is one such row. Δ is ≤ 6.3e-3 of B₀ on the Nseries bins, so it is kept
//! on the first [`DELTA_TEMPLATES`] templates (their truncation leaves ~1e-2 of Δ, ~1e-4 of B₀), and its two
//! error estimates (Δ on one node fewer per shell panel, Δ on the check rule; [`super::one_loop_bins`]) as
//! their differences from Δ on the first [`CHECK_TEMPLATES`]. The tree level's Δ is exact: each node
//! triangle's tree rows (numbers per power of f) with the true P at its sides.

use super::geometry::{LegendreSide, TriangleSet};
use super::multipole_basis::{setup, triples, Acc, MultipoleLoopBasis, Names};
use super::multipole_tensors::{triangle_tensors, Products, Rows, TriangleTensors, F_NODES};
use super::one_loop::OneLoopRule;
use super::one_loop_bins::{
    check_rule, correction_rule, effective_triangle, BinnedLoopMultipoles, CORRECTION_NODES,
};
use super::one_loop_galaxy_poly::GalaxyLoopPolynomial;
use crate::error::{Error, Result};
use crate::linear::LinearSpectrum;
use crate::loops::basis::{pair_index, triple_index, triple_products};
use crate::simd::dot;
use rayon::prelude::*;
use std::collections::BTreeMap;
use std::sync::atomic::{AtomicUsize, Ordering};

/// The templates Δ is kept on.
pub const DELTA_TEMPLATES: usize = 6;

/// The templates of Δ's two error estimates.
pub const CHECK_TEMPLATES: usize = 4;

/// Folded loop rows: per (term 1–4, [ℓ, key (unused, 0), monomial, power]) a packed triple on m templates.
type Folded = BTreeMap<(usize, [u16; 4]), Vec<f64>>;

/// A bin's node triangles and weights.
type Nodes = Vec<([f64; 3], f64)>;

/// [`Folded`]'s rows as a list.
type FoldedRows = Vec<((usize, [u16; 4]), Vec<f64>)>;

/// A bin's correction: the folded loops of Δ and of its two error estimates' differences, and the tree
/// level's nodes (weight, sides, tree rows) for Δ and for Δ on one node fewer.
#[derive(Debug, Clone, PartialEq)]
struct BinCorrection {
    delta: FoldedRows,
    minus_nodes: FoldedRows,
    minus_rule: FoldedRows,
    tree: [Vec<(f64, [f64; 3], Rows)>; 2],
}

/// The one-loop galaxy multipoles of a set of bins from tensors (module docs).
#[derive(Debug, Clone, PartialEq)]
pub struct MultipoleBinBasis {
    /// The tensors at the bins' effective triangles.
    main: MultipoleLoopBasis,
    corrections: Vec<BinCorrection>,
}

impl MultipoleBinBasis {
    /// Builds the tensors of the bins `set` (shells) with the Legendre polynomial on `side` (each bin's,
    /// as the tree level's), the loop `rule` at the effective triangles; `progress(done, total)` per bin.
    ///
    /// # Errors
    /// [`Error::InvalidChoice`] for a set of points; as [`MultipoleLoopBasis::build`].
    pub fn build(
        set: &TriangleSet,
        side: LegendreSide,
        rule: &OneLoopRule,
        progress: &(dyn Fn(usize, usize) + Sync),
    ) -> Result<Self> {
        Self::build_with(
            set,
            side,
            rule,
            [correction_rule(rule), check_rule(rule)],
            progress,
        )
    }

    /// [`build`](Self::build) with the correction's rules [coarse, check] given (those of
    /// [`super::one_loop_bins`] by default; other rules for benchmarks of the evaluation, whose cost does not
    /// depend on them).
    ///
    /// # Errors
    /// As [`build`](Self::build).
    pub fn build_with(
        set: &TriangleSet,
        side: LegendreSide,
        rule: &OneLoopRule,
        [coarse, check]: [OneLoopRule; 2],
        progress: &(dyn Fn(usize, usize) + Sync),
    ) -> Result<Self> {
        if set.width().is_none() {
            return Err(Error::InvalidChoice {
                what: "a triangle set of points".into(),
                reason: "bin averages need bins (shells of a width)".into(),
            });
        }
        let bins = 0..set.len();
        let effective: Vec<[f64; 3]> = bins.clone().map(|i| effective_triangle(set, i)).collect();
        let indices: Vec<usize> = bins.clone().map(|i| set.legendre_index(i, side)).collect();
        let nodes: Vec<[Nodes; 2]> = bins
            .map(|i| {
                [
                    set.shapes(i, CORRECTION_NODES),
                    set.shapes(i, CORRECTION_NODES - 1),
                ]
            })
            .collect();
        let k_max = nodes
            .iter()
            .flatten()
            .flatten()
            .flat_map(|(k, _)| *k)
            .chain(effective.iter().flatten().copied())
            .fold(0.0, f64::max);
        let main =
            MultipoleLoopBasis::build_at(&effective, side, &indices, rule, k_max, &|_, _| {})?;
        let products = Products::new();
        let phi = |x: f64, out: &mut [f64]| main.phi(x, out);
        let m = super::multipole_basis::TEMPLATES;
        let done = AtomicUsize::new(0);
        let corrections = (0..set.len())
            .into_par_iter()
            .map(|i| {
                let a = indices[i];
                let tensors = |k: [f64; 3], r: &OneLoopRule| -> Result<TriangleTensors> {
                    Ok(triangle_tensors(&setup(k, a, &phi, m, &products)?, r))
                };
                // Δ on the coarse rule with n and n − 1 nodes per shell panel, and on the check rule; each
                // node triangle's tensors built once and folded on both template counts where needed
                let (mut delta, mut small, mut fewer, mut checked) =
                    (Folded::new(), Folded::new(), Folded::new(), Folded::new());
                let (mut tree, mut tree_fewer) = (Vec::new(), Vec::new());
                let eff = tensors(effective[i], &coarse)?;
                for &(k, w) in nodes[i][0].iter().chain([&(effective[i], -1.0)]) {
                    let t = if w < 0.0 {
                        eff.clone()
                    } else {
                        tensors(k, &coarse)?
                    };
                    fold(&t, w, DELTA_TEMPLATES, &mut delta);
                    fold(&t, w, CHECK_TEMPLATES, &mut small);
                    tree.push((w, k, t.tree));
                }
                for &(k, w) in nodes[i][1].iter().chain([&(effective[i], -1.0)]) {
                    let t = if w < 0.0 {
                        eff.clone()
                    } else {
                        tensors(k, &coarse)?
                    };
                    fold(&t, w, CHECK_TEMPLATES, &mut fewer);
                    tree_fewer.push((w, k, t.tree));
                }
                for &(k, w) in nodes[i][0].iter().chain([&(effective[i], -1.0)]) {
                    fold(&tensors(k, &check)?, w, CHECK_TEMPLATES, &mut checked);
                }
                let minus = |x: &Folded| -> Vec<_> {
                    small
                        .iter()
                        .map(|(key, v)| {
                            let o = x.get(key);
                            let d = v
                                .iter()
                                .enumerate()
                                .map(|(j, a)| a - o.map_or(0.0, |o| o[j]))
                                .collect();
                            (*key, d)
                        })
                        .collect()
                };
                let c = BinCorrection {
                    minus_nodes: minus(&fewer),
                    minus_rule: minus(&checked),
                    delta: delta.into_iter().collect(),
                    tree: [tree, tree_fewer],
                };
                progress(done.fetch_add(1, Ordering::Relaxed) + 1, set.len());
                Ok(c)
            })
            .collect::<Result<Vec<_>>>()?;
        Ok(Self { main, corrections })
    }

    /// The binned multipoles per bias monomial for the spectrum `p` at growth rate `f` (no IR resummation):
    /// [`BinnedLoopMultipoles::evaluate`] then gives B₀, B₂, B₄ of every bin at a bias with the errors of
    /// [`super::one_loop_bins`].
    ///
    /// # Errors
    /// As [`MultipoleLoopBasis::evaluate`].
    pub fn evaluate(&self, p: &LinearSpectrum, f: f64) -> Result<BinnedLoopMultipoles> {
        let at_effective = self.main.evaluate(p, f)?;
        let (c, _) = self.main.project(p);
        let c3 = triple_products(&c[..DELTA_TEMPLATES]);
        let c3_check = triple_products(&c[..CHECK_TEMPLATES]);
        let fp: [f64; F_NODES] = std::array::from_fn(|i| f.powi(i as i32));
        let names = Names::new();
        let corrections = self
            .corrections
            .iter()
            .zip(&at_effective)
            .map(|(b, m)| {
                let loops = |acc: &mut Acc, rows: &FoldedRows, x: &[f64], sign: f64| {
                    for ((term, idx), v) in rows {
                        acc.add(idx, *term, sign * fp[idx[3] as usize] * dot(v, x), 0.0);
                    }
                };
                let tree = |acc: &mut Acc, nodes: &[(f64, [f64; 3], Rows)]| {
                    for (w, k, rows) in nodes {
                        let pk = k.map(|v| p.eval(v));
                        for (idx, value) in rows.index.iter().zip(&rows.fine) {
                            let s = idx[1] as usize;
                            let legs = pk[(s + 1) % 3] * pk[(s + 2) % 3];
                            acc.add(idx, 0, w * fp[idx[3] as usize] * legs * value, 0.0);
                        }
                    }
                };
                // Δ's loops once; Δ_nodes = Δ − (Δ − Δ_nodes), Δ_rule likewise; the tree level does not
                // depend on the rule
                let mut base = Acc::new(&names);
                loops(&mut base, &b.delta, &c3, 1.0);
                let mut delta = base.clone();
                tree(&mut delta, &b.tree[0]);
                let mut checked = delta.clone();
                loops(&mut checked, &b.minus_rule, &c3_check, -1.0);
                let mut fewer = base;
                loops(&mut fewer, &b.minus_nodes, &c3_check, -1.0);
                tree(&mut fewer, &b.tree[1]);
                let ells = |acc: &Acc| -> [GalaxyLoopPolynomial; 3] {
                    std::array::from_fn(|l| acc.polynomial(l, m.k, 0.0))
                };
                [ells(&delta), ells(&fewer), ells(&checked)]
            })
            .collect();
        Ok(BinnedLoopMultipoles {
            effective: self.main.triangles().to_vec(),
            at_effective,
            corrections,
        })
    }
}

/// Adds `w` × the loops of one node triangle's tensors folded into packed triples on the first `mc`
/// templates (module docs) to `out`, by (term, [ℓ, 0, monomial, power]).
fn fold(t: &TriangleTensors, w: f64, mc: usize, out: &mut Folded) {
    let m = t.sigma[0].len();
    let side = |a: usize| &t.sides[a * m..a * m + mc];
    let mut put = |term: usize, idx: &[u16; 4], f: &dyn Fn(&mut [f64])| {
        let key = (term, [idx[0], 0, idx[2], idx[3]]);
        let row = out.entry(key).or_insert_with(|| vec![0.0; triples(mc)]);
        f(row);
    };
    let tm = triples(m);
    for (idx, row) in t.b222.index.iter().zip(t.b222.fine.chunks_exact(tm)) {
        put(1, idx, &|r| {
            r.iter_mut().zip(row).for_each(|(r, x)| *r += w * x)
        });
    }
    let pm = m * (m + 1) / 2;
    for (idx, row) in t.b321.index.iter().zip(t.b321.fine.chunks_exact(pm)) {
        let phi = side(idx[1] as usize);
        put(2, idx, &|r| {
            for c in 0..mc {
                for b in 0..=c {
                    let x = w * row[pair_index(b, c)];
                    for (a, pa) in phi.iter().enumerate() {
                        let mut s = [a, b, c];
                        s.sort_unstable();
                        r[triple_index(s[0], s[1], s[2])] += x * pa;
                    }
                }
            }
        });
    }
    for (term, family) in [(3, &t.j), (4, &t.l)] {
        for ((idx, row), u) in family
            .index
            .iter()
            .zip(family.fine.chunks_exact(m))
            .zip(&family.uv)
        {
            let s = idx[1] as usize;
            let (x, y) = (side((s + 1) % 3), side((s + 2) % 3));
            // (J − U s)·c with σ² = s·c on the rule
            let z: Vec<f64> = row
                .iter()
                .zip(&t.sigma[0])
                .map(|(j, s)| j - u * s)
                .collect();
            put(term, idx, &|r| {
                for (a, xa) in x.iter().enumerate() {
                    for (b, yb) in y.iter().enumerate() {
                        for (c, zc) in z[..mc].iter().enumerate() {
                            let mut s = [a, b, c];
                            s.sort_unstable();
                            r[triple_index(s[0], s[1], s[2])] += w * xa * yb * zc;
                        }
                    }
                }
            });
        }
    }
}
