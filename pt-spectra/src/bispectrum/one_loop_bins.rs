//! The multipoles of the one-loop galaxy bispectrum averaged over triangle bins (issue 50): the one-loop
//! multipoles at the bin's effective triangle, corrected to the bin average on a coarse loop rule.
//!
//! A direct one-loop evaluation costs ~27 s per triangle on one core
//! ([`super::one_loop_galaxy_multipoles`]), a bin average tens of triangles. The bin average's departure
//! from the effective triangle is smooth in the triangle, and so is a coarse loop rule's quadrature error,
//! so the departure is taken on a coarse rule. Per bin of three shells (the tree level's [`TriangleSet`]
//! bins) and per bias monomial:
//!
//! ```text
//! B_ℓ,bin = B_ℓ(k_eff; rule) + Δ_ℓ,     Δ_ℓ = Σ_n w_n B_ℓ(k_n; coarse) − B_ℓ(k_eff; coarse),
//! ```
//!
//! k_eff the bin's effective triangle (its mean sides over the closed triangles, weight k₁k₂k₃: the
//! tree level's [`super::PlanRules::effective`] triangle), (k_n, w_n) the bin's closed triangles on
//! [`CORRECTION_NODES`] Gauss–Legendre nodes per shell panel (the tree level's bin rule), `coarse` the loop
//! rule [`correction_rule`] (3 × 4 × 3 nodes per panel: a ninth of a second per triangle), the Legendre
//! polynomial on the bin's side. The tree level does not depend on the loop rule, so its Δ is the exact
//! bin average's (on the same nodes as the tree-level plan's; with the IR resummation's (1 + x) legs).
//!
//! **Errors**: each term's error at k_eff (the loop rule's), plus for the loop terms
//! 2 (|Δ − Δ_nodes| + |Δ − Δ_rule|), Δ_nodes the correction on one node fewer per shell panel and Δ_rule on
//! the loop rule of 2 × 2 × 2 nodes per panel; for the tree level |Δ − Δ_nodes| (as the tree-level plan's
//! bin error). Measured against the loops averaged over the bins' nodes on a finer rule in the slow checks
//! (`bispectrum_galaxy_bins`; docs/bispectrum.md).

use super::bias_kernels::LoopBias;
use super::geometry::{LegendreSide, TriangleSet};
use super::one_loop::OneLoopRule;
use super::one_loop_galaxy::OneLoopGalaxy;
use super::one_loop_galaxy_multipoles::{combine, galaxy_multipoles, GalaxyLoopMultipoles};
use super::one_loop_galaxy_poly::GalaxyLoopPolynomial;
use super::resum::IrInputs;
use crate::error::{Error, Result};
use crate::estimate::Estimate;
use crate::linear::LinearSpectrum;

/// Nodes per shell panel of the bin average of the correction (the tree-level plan's default).
pub const CORRECTION_NODES: usize = 3;

/// The coarse loop rule of the correction: 3 × 4 × 3 nodes per panel over the main rule's q range.
pub fn correction_rule(rule: &OneLoopRule) -> OneLoopRule {
    OneLoopRule {
        radial: 3,
        mu: 4,
        phi: 3,
        ..*rule
    }
}

/// The rule of the correction's rule check: 2 × 2 × 2 nodes per panel.
pub(super) fn check_rule(rule: &OneLoopRule) -> OneLoopRule {
    OneLoopRule {
        radial: 2,
        mu: 2,
        phi: 2,
        ..*rule
    }
}

/// The binned one-loop multipoles of a triangle set (module docs), per bias monomial;
/// [`evaluate`](Self::evaluate) contracts them with a bias.
#[derive(Debug, Clone)]
pub struct BinnedLoopMultipoles {
    /// Per bin, the effective triangle [h/Mpc].
    pub effective: Vec<[f64; 3]>,
    /// Per bin, the one-loop multipoles at the effective triangle on the main rule.
    pub at_effective: Vec<GalaxyLoopMultipoles>,
    /// Per bin, the correction Δ to the bin average (module docs), the same on one node fewer per shell
    /// panel and on the check rule, each for ℓ = 0, 2, 4.
    pub corrections: Vec<[[GalaxyLoopPolynomial; 3]; 3]>,
}

impl BinnedLoopMultipoles {
    /// B₀, B₂, B₄ of every bin at the coefficients `bias` (module docs): each term at the effective triangle
    /// plus its correction, the errors as the module docs say (the renormalisation's subtracted amounts
    /// `uv_b321_ii`, `uv_b411` are the effective triangle's).
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] for a coefficient that is not finite.
    pub fn evaluate(&self, bias: &LoopBias) -> Result<Vec<[OneLoopGalaxy; 3]>> {
        let value = |p: &GalaxyLoopPolynomial| p.evaluate(bias);
        self.at_effective
            .iter()
            .zip(&self.corrections)
            .map(|(m, c)| {
                let mut ells = m.evaluate(bias)?;
                let [main, nodes, rule] = c;
                // the tree level's Δ is exact but for a stated approximation's bound (the tensors'
                // resummed legs, `multipole_bins`: the damping's anisotropy also moves the monopole's
                // wiggles into B₂, B₄, so every ℓ carries the monopole's bound too)
                let monopole_bound = value(&main[0])?.tree.error;
                for (l, b) in ells.iter_mut().enumerate() {
                    let (d, dn, dr) = (value(&main[l])?, value(&nodes[l])?, value(&rule[l])?);
                    let term = |x: &OneLoopGalaxy| {
                        [
                            x.tree.value,
                            x.b222.value,
                            x.b321_i.value,
                            x.b321_ii.value,
                            x.b411.value,
                        ]
                    };
                    let tree_error = if l == 0 {
                        monopole_bound
                    } else {
                        d.tree.error + monopole_bound
                    };
                    let (d, dn, dr) = (term(&d), term(&dn), term(&dr));
                    let terms = [
                        &mut b.tree,
                        &mut b.b222,
                        &mut b.b321_i,
                        &mut b.b321_ii,
                        &mut b.b411,
                    ];
                    for (j, t) in terms.into_iter().enumerate() {
                        let error = if j == 0 {
                            (d[0] - dn[0]).abs() + tree_error
                        } else {
                            2.0 * ((d[j] - dn[j]).abs() + (d[j] - dr[j]).abs())
                        };
                        *t = Estimate::new(t.value + d[j], t.error + error);
                    }
                }
                Ok(ells)
            })
            .collect()
    }
}

/// The effective triangle of bin `i` of `set`: its mean sides over the closed triangles (weight k₁k₂k₃) on
/// the tree-level plan's default shell rule (the triangle [`super::PlanRules::effective`] evaluates).
pub fn effective_triangle(set: &TriangleSet, i: usize) -> [f64; 3] {
    set.shapes(i, CORRECTION_NODES)
        .iter()
        .fold([0.0; 3], |m, (k, w)| {
            [m[0] + w * k[0], m[1] + w * k[1], m[2] + w * k[2]]
        })
}

/// That `set` is bins (shells of a width), as bin averages need.
///
/// # Errors
/// [`Error::InvalidChoice`] for a set of points.
pub fn require_bins(set: &TriangleSet) -> Result<()> {
    match set.width() {
        Some(_) => Ok(()),
        None => Err(Error::InvalidChoice {
            what: "a triangle set of points".into(),
            reason: "bin averages need bins (shells of a width)".into(),
        }),
    }
}

/// Σ_n w_n M_ℓ(k_n) − M_ℓ(k_eff) on `rule` with `n` nodes per shell panel of bin `i` (module docs).
#[allow(clippy::too_many_arguments)]
fn correction(
    p: &LinearSpectrum,
    ir: Option<&IrInputs>,
    set: &TriangleSet,
    i: usize,
    k_eff: [f64; 3],
    f: f64,
    side: LegendreSide,
    rule: &OneLoopRule,
    n: usize,
) -> Result<[GalaxyLoopPolynomial; 3]> {
    let nodes = set.shapes(i, n);
    let mut polys: Vec<GalaxyLoopMultipoles> = Vec::with_capacity(nodes.len() + 1);
    let mut weights = Vec::with_capacity(nodes.len() + 1);
    for (k, w) in nodes.iter().copied().chain([(k_eff, -1.0)]) {
        polys.push(galaxy_multipoles(p, ir, k, f, side, rule, None)?);
        weights.push(w);
    }
    Ok(std::array::from_fn(|l| {
        let ells: Vec<GalaxyLoopPolynomial> = polys.iter().map(|m| m.ells[l].clone()).collect();
        combine(&ells, &weights)
    }))
}

/// The binned one-loop multipoles of the bins `set` (shells; module docs) at growth rate `f`, the Legendre
/// polynomial on `side` (each bin's, as the tree level's), for the linear spectrum `p`, resummed with `ir`
/// if given, with the loop `rule` at the effective triangles; `tick(done, total)` after each bin.
///
/// # Errors
/// [`Error::InvalidChoice`] for a set of points (no bins); as
/// [`super::one_loop_galaxy_multipoles::one_loop_galaxy_multipoles`], naming the bin.
pub fn binned_multipoles(
    p: &LinearSpectrum,
    ir: Option<&IrInputs>,
    set: &TriangleSet,
    f: f64,
    side: LegendreSide,
    rule: &OneLoopRule,
    tick: &dyn Fn(usize, usize),
) -> Result<BinnedLoopMultipoles> {
    require_bins(set)?;
    let (coarse, check) = (correction_rule(rule), check_rule(rule));
    let mut effective = Vec::with_capacity(set.len());
    let mut at_effective = Vec::with_capacity(set.len());
    let mut corrections = Vec::with_capacity(set.len());
    for i in 0..set.len() {
        let k = effective_triangle(set, i);
        let a = LegendreSide::Index(set.legendre_index(i, side));
        let named = |e: Error| Error::InvalidChoice {
            what: format!(
                "bin {} (centres {:?}, effective triangle {k:?})",
                i + 1,
                set.triangles()[i]
            ),
            reason: e.to_string(),
        };
        let m = galaxy_multipoles(p, ir, k, f, a, rule, None).map_err(named)?;
        let n = CORRECTION_NODES;
        let c = [
            correction(p, ir, set, i, k, f, a, &coarse, n),
            correction(p, ir, set, i, k, f, a, &coarse, n - 1),
            correction(p, ir, set, i, k, f, a, &check, n),
        ];
        let [c0, c1, c2] = c;
        corrections.push([c0.map_err(named)?, c1.map_err(named)?, c2.map_err(named)?]);
        effective.push(k);
        at_effective.push(m);
        tick(i + 1, set.len());
    }
    Ok(BinnedLoopMultipoles {
        effective,
        at_effective,
        corrections,
    })
}
