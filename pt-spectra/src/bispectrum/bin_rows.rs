//! The stored parts of a bin's correction in [`super::multipole_bins`]: the folded loop rows of Δ and of
//! its error estimates, the tree level's node matrices, their fold from a node triangle's tensors, and
//! their layout in the bins' cache file.

use super::multipole_basis::{triples, Acc};
use super::multipole_cache::Reader;
use super::multipole_tensors::{Rows, TriangleTensors, F_NODES};
use crate::loops::basis::{pair_index, triple_index};
use crate::simd::{from_bf16, matvec, matvec_bf16, matvec_f32, to_bf16};
use std::collections::BTreeMap;

/// The templates Δ is kept on.
pub const DELTA_TEMPLATES: usize = 6;

/// The templates of Δ's two error estimates.
pub const CHECK_TEMPLATES: usize = 4;

/// Folded loop rows: per (term 1–4, [ℓ, key (unused, 0), monomial, power]) a packed triple on m templates.
pub(super) type Folded = BTreeMap<(usize, [u16; 4]), Vec<f64>>;

/// [`Folded`]'s rows as one matrix (a row of `len` values per key), contracted by one matrix–vector
/// product: in f32 (Δ), or in bfloat16 (`half`: the error estimates' differences, an error of an error,
/// rounded to 2^-9 of each entry).
#[derive(Debug, Clone, PartialEq, Default)]
pub(super) struct FoldedRows {
    keys: Vec<(usize, [u16; 4])>,
    values: Vec<f32>,
    half: Vec<u16>,
    len: usize,
}

impl FoldedRows {
    pub(super) fn new(folded: Folded, len: usize, bf16: bool) -> Self {
        let mut rows = Self {
            len,
            ..Self::default()
        };
        for (key, v) in folded {
            rows.keys.push(key);
            rows.push_values(v.iter().map(|&x| x as f32), bf16);
        }
        rows
    }

    fn push_values(&mut self, v: impl Iterator<Item = f32>, bf16: bool) {
        if bf16 {
            self.half.extend(v.map(to_bf16));
        } else {
            self.values.extend(v);
        }
    }

    /// The values as f32, whichever the storage.
    fn values_f32(&self) -> Vec<f32> {
        if self.half.is_empty() {
            self.values.clone()
        } else {
            self.half.iter().map(|&h| from_bf16(h)).collect()
        }
    }

    /// Adds `sign` × each row contracted with the products `x` (f32, `len`) × f^power to `acc`.
    pub(super) fn add_to(
        &self,
        acc: &mut Acc,
        x: &[f32],
        fp: &[f64; F_NODES],
        sign: f64,
        out: &mut Vec<f64>,
    ) {
        out.clear();
        out.resize(self.keys.len(), 0.0);
        if self.half.is_empty() {
            matvec_f32(&self.values, x, out);
        } else {
            matvec_bf16(&self.half, x, out);
        }
        for ((term, idx), v) in self.keys.iter().zip(out.iter()) {
            acc.add(idx, *term, sign * fp[idx[3] as usize] * v, 0.0);
        }
    }
}

/// A bin's correction: the folded loops of Δ and of its two error estimates' differences, and the tree
/// level's nodes for Δ and for Δ on one node fewer.
#[derive(Debug, Clone, PartialEq)]
pub(super) struct BinCorrection {
    pub(super) delta: FoldedRows,
    pub(super) minus_nodes: FoldedRows,
    pub(super) minus_rule: FoldedRows,
    pub(super) tree: [TreeNodes; 2],
}

/// The tree level's rows of a bin's node triangles (the effective triangle among them with weight −1) as
/// one matrix per side s whose legs multiply them: Δ_tree = Σ_n w_n P(k_n,s+1) P(k_n,s+2) M_s[row, n] for
/// the rows (ℓ, s, monomial, power) of that side, exact with the true P.
#[derive(Debug, Clone, PartialEq, Default)]
pub(super) struct TreeNodes {
    weights: Vec<f64>,
    sides: Vec<[f64; 3]>,
    /// The rows' indices, by side s (`idx[1]`) then (ℓ, monomial, power).
    keys: Vec<[u16; 4]>,
    /// Row-major, one value per node.
    values: Vec<f64>,
    /// The distinct side lengths of the nodes (a shell's few Gauss nodes recur across its triangles)
    /// and each node's sides as indices into them: the legs are evaluated once per distinct k.
    distinct: Vec<f64>,
    at: Vec<[usize; 3]>,
}

impl TreeNodes {
    /// The nodes with their weights, sides and row matrix, and the distinct sides found.
    pub(super) fn with_rows(
        weights: Vec<f64>,
        sides: Vec<[f64; 3]>,
        keys: Vec<[u16; 4]>,
        values: Vec<f64>,
    ) -> Self {
        let mut distinct: Vec<f64> = Vec::new();
        let at = sides
            .iter()
            .map(|k| {
                k.map(|v| match distinct.iter().position(|&d| d == v) {
                    Some(i) => i,
                    None => {
                        distinct.push(v);
                        distinct.len() - 1
                    }
                })
            })
            .collect();
        Self {
            weights,
            sides,
            keys,
            values,
            distinct,
            at,
        }
    }

    pub(super) fn new(nodes: Vec<(f64, [f64; 3], Rows)>) -> Self {
        let mut rows: BTreeMap<[u16; 4], Vec<f64>> = BTreeMap::new();
        for (n, (_, _, r)) in nodes.iter().enumerate() {
            for (idx, v) in r.index.iter().zip(&r.fine) {
                let key = [idx[1], idx[0], idx[2], idx[3]];
                rows.entry(key).or_insert_with(|| vec![0.0; nodes.len()])[n] += v;
            }
        }
        Self::with_rows(
            nodes.iter().map(|n| n.0).collect(),
            nodes.iter().map(|n| n.1).collect(),
            rows.keys().map(|k| [k[1], k[0], k[2], k[3]]).collect(),
            rows.into_values().flatten().collect(),
        )
    }

    /// Adds the tree level's Δ with the legs `leg(k)` to `acc` in `slot`.
    pub(super) fn add_to(
        &self,
        acc: &mut Acc,
        leg: &dyn Fn(f64) -> f64,
        fp: &[f64; F_NODES],
        slot: Slot,
        out: &mut Vec<f64>,
    ) {
        let n = self.weights.len();
        let legs_k: Vec<f64> = self.distinct.iter().map(|&k| leg(k)).collect();
        let pk: Vec<[f64; 3]> = self.at.iter().map(|a| a.map(|i| legs_k[i])).collect();
        let mut start = 0;
        for s in 0..3 {
            let rows = self.keys[start..]
                .iter()
                .take_while(|idx| idx[1] as usize == s)
                .count();
            let legs: Vec<f64> = pk
                .iter()
                .zip(&self.weights)
                .map(|(pk, w)| w * pk[(s + 1) % 3] * pk[(s + 2) % 3])
                .collect();
            out.clear();
            out.resize(rows, 0.0);
            matvec(&self.values[start * n..(start + rows) * n], &legs, out);
            for (idx, v) in self.keys[start..start + rows].iter().zip(out.iter()) {
                let v = fp[idx[3] as usize] * v;
                match slot {
                    Slot::Value => acc.add(idx, 0, v, 0.0),
                    Slot::Difference(sign) => acc.add(idx, 0, 0.0, sign * v),
                }
            }
            start += rows;
        }
    }
}

/// Where [`TreeNodes::add_to`] adds: to the values, or `sign` × to the differences (the error).
#[derive(Debug, Clone, Copy)]
pub(super) enum Slot {
    Value,
    Difference(f64),
}

/// Appends a bin's correction: each folded family (Δ, its differences on one node fewer and on the check
/// rule) as its row count r, row length, 5r keys (term, ℓ, 0, monomial, power) and r × length values (the
/// f32 or bfloat16 values, exact in f64); then the tree level's two node lists, each as its node count n,
/// row count r, per node its weight and three sides, 4r row keys (ℓ, s, monomial, power) and the r × n
/// matrix, row-major.
pub(super) fn write_correction(c: &BinCorrection, out: &mut Vec<f64>) {
    for rows in [&c.delta, &c.minus_nodes, &c.minus_rule] {
        out.extend([rows.keys.len() as f64, rows.len as f64]);
        for (term, idx) in &rows.keys {
            out.push(*term as f64);
            out.extend(idx.iter().map(|&i| f64::from(i)));
        }
        out.extend(rows.values_f32().iter().map(|&x| f64::from(x)));
    }
    for nodes in &c.tree {
        out.extend([nodes.weights.len() as f64, nodes.keys.len() as f64]);
        for (w, k) in nodes.weights.iter().zip(&nodes.sides) {
            out.push(*w);
            out.extend(k);
        }
        out.extend(nodes.keys.iter().flatten().map(|&i| f64::from(i)));
        out.extend(&nodes.values);
    }
}

/// A bin's correction as [`write_correction`] wrote it.
pub(super) fn read_correction(r: &mut Reader) -> Option<BinCorrection> {
    let mut folded = [
        (DELTA_TEMPLATES, false),
        (CHECK_TEMPLATES, true),
        (CHECK_TEMPLATES, true),
    ]
    .map(|(m, bf16)| {
        let n = r.count(1 << 24)?;
        let len = r.count(triples(m) + 1)?;
        (len == triples(m)).then_some(())?;
        let keys = r
            .indices::<5>(n)?
            .into_iter()
            .map(|k| (k[0] < 5).then(|| (usize::from(k[0]), [k[1], k[2], k[3], k[4]])))
            .collect::<Option<Vec<_>>>()?;
        let mut rows = FoldedRows {
            keys,
            len,
            ..FoldedRows::default()
        };
        rows.push_values(r.take(n * len)?.iter().map(|&x| x as f32), bf16);
        Some(rows)
    });
    let mut tree = [0, 1].map(|_| {
        let (n, rows) = (r.count(1 << 16)?, r.count(1 << 16)?);
        let nodes = r.take(4 * n)?;
        let keys = r.indices::<4>(rows)?;
        keys.iter().all(|k| k[1] < 3).then_some(())?;
        Some(TreeNodes::with_rows(
            nodes.chunks_exact(4).map(|c| c[0]).collect(),
            nodes.chunks_exact(4).map(|c| [c[1], c[2], c[3]]).collect(),
            keys,
            r.take(rows * n)?.to_vec(),
        ))
    });
    let mut take = |i: usize| folded[i].take();
    let (delta, minus_nodes, minus_rule) = (take(0)?, take(1)?, take(2)?);
    Some(BinCorrection {
        delta,
        minus_nodes,
        minus_rule,
        tree: [tree[0].take()?, tree[1].take()?],
    })
}

/// Adds `w` × the loops of one node triangle's tensors folded into packed triples on the first `mc`
/// templates (module docs) to `out`, by (term, [ℓ, 0, monomial, power]).
pub(super) fn fold(t: &TriangleTensors, w: f64, mc: usize, out: &mut Folded) {
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
