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
//! their differences from Δ on the first [`CHECK_TEMPLATES`] (in bfloat16: an error's estimate). The tree
//! level's Δ is exact: the node triangles' tree rows (numbers per power of f) with the true P at their sides,
//! one matrix per side.

use super::geometry::{LegendreSide, TriangleSet};
use super::ir_legs::leading_order_spectrum;
use super::multipole_basis::{setup, triples, Acc, MultipoleLoopBasis, Names};
use super::multipole_cache::Reader;
use super::multipole_tensors::{triangle_tensors, Products, Rows, TriangleTensors, F_NODES};
use super::one_loop::OneLoopRule;
use super::one_loop_bins::{
    check_rule, correction_rule, effective_triangle, require_bins, BinnedLoopMultipoles,
    CORRECTION_NODES,
};
use super::one_loop_galaxy_poly::GalaxyLoopPolynomial;
use super::resum::IrInputs;
use crate::error::Result;
use crate::ir::sigma2_total;
use crate::linear::LinearSpectrum;
use crate::loops::basis::{
    after_key, cache_file_name, pair_index, triple_index, triple_products, Projection,
};
use crate::simd::{from_bf16, matvec, matvec_bf16, matvec_f32, to_bf16};
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

/// [`Folded`]'s rows as one matrix (a row of `len` values per key), contracted by one matrix–vector
/// product: in f32 (Δ), or in bfloat16 (`half`: the error estimates' differences, an error of an error,
/// rounded to 2^-9 of each entry).
#[derive(Debug, Clone, PartialEq, Default)]
struct FoldedRows {
    keys: Vec<(usize, [u16; 4])>,
    values: Vec<f32>,
    half: Vec<u16>,
    len: usize,
}

impl FoldedRows {
    fn new(folded: Folded, len: usize, bf16: bool) -> Self {
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
    fn add_to(&self, acc: &mut Acc, x: &[f32], fp: &[f64; F_NODES], sign: f64, out: &mut Vec<f64>) {
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
struct BinCorrection {
    delta: FoldedRows,
    minus_nodes: FoldedRows,
    minus_rule: FoldedRows,
    tree: [TreeNodes; 2],
}

/// The tree level's rows of a bin's node triangles (the effective triangle among them with weight −1) as
/// one matrix per side s whose legs multiply them: Δ_tree = Σ_n w_n P(k_n,s+1) P(k_n,s+2) M_s[row, n] for
/// the rows (ℓ, s, monomial, power) of that side, exact with the true P.
#[derive(Debug, Clone, PartialEq, Default)]
struct TreeNodes {
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
    fn with_rows(
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

    fn new(nodes: Vec<(f64, [f64; 3], Rows)>) -> Self {
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
    fn add_to(
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

/// The one-loop galaxy multipoles of a set of bins from tensors (module docs).
#[derive(Debug, Clone, PartialEq)]
pub struct MultipoleBinBasis {
    set: TriangleSet,
    /// The correction's rules: coarse and check.
    rules: [OneLoopRule; 2],
    /// The tensors at the bins' effective triangles.
    main: MultipoleLoopBasis,
    corrections: Vec<BinCorrection>,
}

impl MultipoleBinBasis {
    /// Builds the tensors of the bins `set` (shells) with the Legendre polynomial on `side` (each bin's,
    /// as the tree level's), the loop `rule` at the effective triangles; `progress(done, total)` per bin.
    ///
    /// # Errors
    /// [`crate::error::Error::InvalidChoice`] for a set of points; as [`MultipoleLoopBasis::build`].
    pub fn build(
        set: &TriangleSet,
        side: LegendreSide,
        rule: &OneLoopRule,
        progress: &(dyn Fn(usize, usize) + Sync),
    ) -> Result<Self> {
        Self::build_with(set, side, rule, correction_rules(rule), progress)
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
        let Layout {
            effective,
            indices,
            nodes,
            k_max,
        } = Layout::of(set, side)?;
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
                let minus = |x: &Folded| -> FoldedRows {
                    let d = small
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
                        .collect();
                    FoldedRows::new(d, triples(CHECK_TEMPLATES), true)
                };
                let c = BinCorrection {
                    minus_nodes: minus(&fewer),
                    minus_rule: minus(&checked),
                    delta: FoldedRows::new(delta, triples(DELTA_TEMPLATES), false),
                    tree: [TreeNodes::new(tree), TreeNodes::new(tree_fewer)],
                };
                progress(done.fetch_add(1, Ordering::Relaxed) + 1, set.len());
                Ok(c)
            })
            .collect::<Result<Vec<_>>>()?;
        Ok(Self {
            set: set.clone(),
            rules: [coarse, check],
            main,
            corrections,
        })
    }

    /// The cache file name of the tensors of the bins `set`, `side`, `rule` and the correction's `rules`
    /// (and of the present kernels).
    pub fn file_name(
        set: &TriangleSet,
        side: LegendreSide,
        rule: &OneLoopRule,
        rules: &[OneLoopRule; 2],
    ) -> String {
        cache_file_name(
            "bispectrum-multipole-bins",
            VERSION,
            &key(set, side, rule, rules),
        )
    }

    /// The cache file's values: the key, the effective triangles' tensors (their count, then
    /// [`MultipoleLoopBasis::to_f64s`]), per bin its correction ([`write_correction`]).
    pub(crate) fn to_f64s(&self) -> Vec<f64> {
        let mut v = key(&self.set, self.main.side(), self.main.rule(), &self.rules);
        v.insert(0, v.len() as f64);
        let main = self.main.to_f64s();
        v.push(main.len() as f64);
        v.extend(main);
        for c in &self.corrections {
            write_correction(c, &mut v);
        }
        v
    }

    /// The tensors of the bins `set`, `side`, `rule` and `rules` from their file's values, or `None` if the
    /// file was made for other settings or does not fit them.
    pub(crate) fn from_f64s(
        values: &[f64],
        set: &TriangleSet,
        side: LegendreSide,
        rule: &OneLoopRule,
        rules: &[OneLoopRule; 2],
    ) -> Option<Self> {
        let rest = after_key(values, &key(set, side, rule, rules))?;
        let layout = Layout::of(set, side).ok()?;
        let mut r = Reader { values: rest };
        let n = r.count(usize::MAX)?;
        let main = MultipoleLoopBasis::from_f64s_at(
            r.take(n)?,
            &layout.effective,
            side,
            rule,
            layout.k_max,
        )?;
        let corrections = (0..set.len())
            .map(|_| read_correction(&mut r))
            .collect::<Option<Vec<_>>>()?;
        r.values.is_empty().then(|| Self {
            set: set.clone(),
            rules: *rules,
            main,
            corrections,
        })
    }

    /// The triangle bins.
    pub fn set(&self) -> &TriangleSet {
        &self.set
    }

    /// The tensors at the bins' effective triangles.
    pub fn effective(&self) -> &MultipoleLoopBasis {
        &self.main
    }

    /// The binned multipoles per bias monomial for the spectrum `p` at growth rate `f` (no IR resummation):
    /// [`BinnedLoopMultipoles::evaluate`] then gives B₀, B₂, B₄ of every bin at a bias with the errors of
    /// [`super::one_loop_bins`].
    ///
    /// # Errors
    /// As [`MultipoleLoopBasis::evaluate`].
    pub fn evaluate(&self, p: &LinearSpectrum, f: f64) -> Result<BinnedLoopMultipoles> {
        Ok(self.evaluate_projected(p, f, None)?.0)
    }

    /// [`evaluate`](Self::evaluate), or with `ir` the IR resummation of [`super::one_loop_ir`]: the
    /// effective triangles as [`MultipoleLoopBasis::evaluate_ir`], Δ's loops on P_LO's projection, and the
    /// tree level's Δ on the legs P_nw + e^{−x}(1 + x) P_w with x = k²Σ²_tot(μ) at μ² = 1/3 for every
    /// orientation (the direct bins damp each orientation's legs), with |Δ_tree(μ = 0) − Δ_tree(μ = 1)|, the
    /// whole range of the damping, added to its error (measured: the direct Δ_tree within 2e-5 of B₀ and
    /// within it). Returns the projection of the loops' spectrum on the templates too.
    ///
    /// # Errors
    /// As [`MultipoleLoopBasis::evaluate_ir`].
    pub fn evaluate_projected(
        &self,
        p: &LinearSpectrum,
        f: f64,
        ir: Option<&IrInputs>,
    ) -> Result<(BinnedLoopMultipoles, Projection)> {
        crate::cosmology::check_growth_rate(f)?;
        let resummed = ir.map(|ir| leading_order_spectrum(p, ir)).transpose()?;
        let loops_p = resummed.as_ref().unwrap_or(p);
        let (c, projection) = self.main.project(loops_p);
        let at_effective =
            self.main
                .contract(&c, projection.residual, loops_p, f, ir.map(|ir| (p, ir)));
        let single = |v: Vec<f64>| -> Vec<f32> { v.iter().map(|&x| x as f32).collect() };
        let c3 = single(triple_products(&c[..DELTA_TEMPLATES]));
        let c3_check = single(triple_products(&c[..CHECK_TEMPLATES]));
        let fp: [f64; F_NODES] = std::array::from_fn(|i| f.powi(i as i32));
        // the tree level's legs damped as along μ (with IR)
        let leg = |mu: f64| {
            move |k: f64| match ir {
                None => p.eval(k),
                Some(ir) => {
                    let x = k * k * sigma2_total(ir.sigma2, ir.delta_sigma2, f, mu);
                    let nw = ir.no_wiggle.eval(k);
                    nw + (-x).exp() * (1.0 + x) * (p.eval(k) - nw)
                }
            }
        };
        let (damped, weakest, strongest) = (leg(MEAN_MU), leg(0.0), leg(1.0));
        let names = Names::new();
        let mut out = Vec::new();
        let corrections = self
            .corrections
            .iter()
            .zip(&at_effective)
            .map(|(b, m)| {
                let mut loops = |acc: &mut Acc, rows: &FoldedRows, x: &[f32], sign: f64| {
                    rows.add_to(acc, x, &fp, sign, &mut out);
                };
                let mut tree_out = Vec::new();
                let mut tree =
                    |acc: &mut Acc, nodes: &TreeNodes, leg: &dyn Fn(f64) -> f64, slot| {
                        nodes.add_to(acc, leg, &fp, slot, &mut tree_out);
                    };
                // Δ's loops once; Δ_nodes = Δ − (Δ − Δ_nodes), Δ_rule likewise; the tree level does not
                // depend on the rule
                let mut base = Acc::new(&names);
                loops(&mut base, &b.delta, &c3, 1.0);
                let mut delta = base.clone();
                tree(&mut delta, &b.tree[0], &damped, Slot::Value);
                if ir.is_some() {
                    tree(&mut delta, &b.tree[0], &weakest, Slot::Difference(1.0));
                    tree(&mut delta, &b.tree[0], &strongest, Slot::Difference(-1.0));
                }
                let mut checked = delta.clone();
                loops(&mut checked, &b.minus_rule, &c3_check, -1.0);
                let mut fewer = base;
                loops(&mut fewer, &b.minus_nodes, &c3_check, -1.0);
                tree(&mut fewer, &b.tree[1], &damped, Slot::Value);
                let ells = |acc: &Acc| -> [GalaxyLoopPolynomial; 3] {
                    std::array::from_fn(|l| acc.polynomial(l, m.k, 0.0))
                };
                [ells(&delta), ells(&fewer), ells(&checked)]
            })
            .collect();
        let binned = BinnedLoopMultipoles {
            effective: self.main.triangles().to_vec(),
            at_effective,
            corrections,
        };
        Ok((binned, projection))
    }
}

/// The line of sight's μ at which the tree level's Δ damps its legs with IR: μ² = 1/3, the mean over
/// orientations.
const MEAN_MU: f64 = 0.577_350_269_189_625_8;

/// Where [`TreeNodes::add_to`] adds: to the values, or `sign` × to the differences (the error).
#[derive(Debug, Clone, Copy)]
enum Slot {
    Value,
    Difference(f64),
}

/// The correction's rules [coarse, check] for the main `rule` ([`super::one_loop_bins`]'s): the cache key's
/// `rules` of a default build.
pub fn correction_rules(rule: &OneLoopRule) -> [OneLoopRule; 2] {
    [correction_rule(rule), check_rule(rule)]
}

/// Version of the layout, part of the cache file name.
const VERSION: u32 = 1;

/// The settings that make the bins' tensors (their cache key): the layout's version, the templates of Δ and
/// of its errors, the nodes per shell panel, the rule, the correction's rules, the Legendre side (−1 for the
/// largest), the width and the bins' centres (the effective triangles' tensors carry their own key).
fn key(
    set: &TriangleSet,
    side: LegendreSide,
    rule: &OneLoopRule,
    rules: &[OneLoopRule; 2],
) -> Vec<f64> {
    let mut key = vec![
        f64::from(VERSION),
        DELTA_TEMPLATES as f64,
        CHECK_TEMPLATES as f64,
        CORRECTION_NODES as f64,
    ];
    for r in std::iter::once(rule).chain(rules) {
        key.extend([r.radial as f64, r.mu as f64, r.phi as f64, r.q_min, r.q_max]);
    }
    key.push(match side {
        LegendreSide::Largest => -1.0,
        LegendreSide::Index(a) => a as f64,
    });
    key.push(set.width().unwrap_or(0.0));
    key.extend(set.triangles().iter().flatten());
    key
}

/// Appends a bin's correction: each folded family (Δ, its differences on one node fewer and on the check
/// rule) as its row count r, row length, 5r keys (term, ℓ, 0, monomial, power) and r × length values; then
/// the tree level's two node lists as their count and per node its weight, sides and tree rows.
fn write_correction(c: &BinCorrection, out: &mut Vec<f64>) {
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
fn read_correction(r: &mut Reader) -> Option<BinCorrection> {
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

/// Where a set's bins are evaluated: the effective triangles, the Legendre side's index, the nodes of Δ and
/// of Δ on one node fewer per shell panel, and the largest side (the basis's lattice reaches it).
struct Layout {
    effective: Vec<[f64; 3]>,
    indices: Vec<usize>,
    nodes: Vec<[Nodes; 2]>,
    k_max: f64,
}

impl Layout {
    fn of(set: &TriangleSet, side: LegendreSide) -> Result<Self> {
        require_bins(set)?;
        let bins = 0..set.len();
        let effective: Vec<[f64; 3]> = bins.clone().map(|i| effective_triangle(set, i)).collect();
        let indices = bins.clone().map(|i| set.legendre_index(i, side)).collect();
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
        Ok(Self {
            effective,
            indices,
            nodes,
            k_max,
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
