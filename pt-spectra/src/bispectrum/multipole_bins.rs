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

use super::bin_rows::{
    fold, read_correction, write_correction, BinCorrection, Folded, FoldedRows, Slot, TreeNodes,
};
pub use super::bin_rows::{CHECK_TEMPLATES, DELTA_TEMPLATES};
use super::geometry::{LegendreSide, TriangleSet};
use super::ir_legs::leading_order_spectrum;
use super::multipole_basis::{setup, side_code, triples, Acc, MultipoleLoopBasis, Names};
use super::multipole_cache::Reader;
use super::multipole_tensors::{triangle_tensors, Products, TriangleTensors, F_NODES};
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
use crate::loops::basis::{after_key, cache_file_name, triple_products, Projection};
use rayon::prelude::*;
use std::borrow::Cow;
use std::sync::atomic::{AtomicUsize, Ordering};

/// A bin's node triangles and weights.
type Nodes = Vec<([f64; 3], f64)>;

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
                // each list of nodes with the effective triangle at weight −1 (its coarse tensors built once)
                let with_effective =
                    |n: usize| nodes[i][n].iter().copied().chain([(effective[i], -1.0)]);
                let eff = tensors(effective[i], &coarse)?;
                let coarse_at = |k: [f64; 3], w: f64| -> Result<Cow<TriangleTensors>> {
                    Ok(if w < 0.0 {
                        Cow::Borrowed(&eff)
                    } else {
                        Cow::Owned(tensors(k, &coarse)?)
                    })
                };
                for (k, w) in with_effective(0) {
                    let t = coarse_at(k, w)?;
                    fold(&t, w, DELTA_TEMPLATES, &mut delta);
                    fold(&t, w, CHECK_TEMPLATES, &mut small);
                    tree.push((w, k, t.tree.clone()));
                }
                for (k, w) in with_effective(1) {
                    let t = coarse_at(k, w)?;
                    fold(&t, w, CHECK_TEMPLATES, &mut fewer);
                    tree_fewer.push((w, k, t.tree.clone()));
                }
                for (k, w) in with_effective(0) {
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
        let names = Names::get();
        let (mut out, mut tree_out) = (Vec::new(), Vec::new());
        let corrections = self
            .corrections
            .iter()
            .zip(&at_effective)
            .map(|(b, m)| {
                let mut loops = |acc: &mut Acc, rows: &FoldedRows, x: &[f32], sign: f64| {
                    rows.add_to(acc, x, &fp, sign, &mut out);
                };
                let mut tree =
                    |acc: &mut Acc, nodes: &TreeNodes, leg: &dyn Fn(f64) -> f64, slot| {
                        nodes.add_to(acc, leg, &fp, slot, &mut tree_out);
                    };
                // Δ's loops once; Δ_nodes = Δ − (Δ − Δ_nodes), Δ_rule likewise; the tree level does not
                // depend on the rule
                let mut base = Acc::new(names);
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
    key.push(side_code(side));
    key.push(set.width().unwrap_or(0.0));
    key.extend(set.triangles().iter().flatten());
    key
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
