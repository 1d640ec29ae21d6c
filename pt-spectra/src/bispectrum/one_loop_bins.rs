//! The multipoles of the one-loop galaxy bispectrum averaged over triangle bins (issue 50), by the
//! effective-triangle shortcut for the loops and the exact bin average for the tree level.
//!
//! A direct one-loop evaluation costs ~30 s per triangle ([`super::one_loop_galaxy_multipoles`]), a bin
//! average over its closed triangles tens of them. So, per bin of three shells (the tree level's
//! [`TriangleSet`] bins, [`super::BispectrumPlan`]):
//!
//! ```text
//! B_ℓ,bin = B_ℓ(k_eff) + [T_ℓ,bin − T_ℓ(k_eff)],
//! ```
//!
//! B_ℓ(k_eff) the one-loop multipoles (tree level and loops, per bias monomial, IR-resummed or not) at the
//! bin's effective triangle k_eff (its mean sides over the closed triangles, weight k₁k₂k₃: the tree-level
//! plan's [`super::PlanRules::effective`] triangle), with the Legendre polynomial on the bin's side; T the
//! tree-level code's multipoles (velocileptors' b1, b2, bs of the bias; its IR resummation when on), T_ℓ,bin
//! its exact bin average (the default shell rule) and T_ℓ(k_eff) its value at k_eff. The tree level is thus
//! averaged over the bin (up to the difference between the two IR prescriptions' trees, B_tree's (1 + x)
//! legs, taken at k_eff: a product of two small effects), the loops are taken at k_eff.
//!
//! **The shortcut's error** (added to each loop term's error, every ℓ): with ε = max_ℓ |T_ℓ,bin −
//! T_ℓ(k_eff)| / |T₀,bin| the tree level's own shortcut error at this bias (relative to its B₀, the largest
//! over ℓ = 0, 2, 4: it measures the bin's size and shape against B's variation across it), each loop term X
//! gets [`LOOP_SHORTCUT_FACTOR`] × ε × |X₀(k_eff)|. The loops' binning error is their curvature across the
//! bin, as the tree level's is, but they are steeper in k; the factor was measured against the loops
//! averaged over the bins' closed triangles (docs/bispectrum.md; `bispectrum_galaxy_bins` in the slow
//! checks).

use super::bias_kernels::LoopBias;
use super::geometry::{LegendreSide, TriangleSet};
use super::one_loop::OneLoopRule;
use super::one_loop_galaxy::OneLoopGalaxy;
use super::one_loop_galaxy_multipoles::{galaxy_multipoles, GalaxyLoopMultipoles};
use super::resum::IrInputs;
use super::terms::{BispectrumPlan, BispectrumTerms, PlanRules};
use super::{BispectrumParams, Fog, Settings};
use crate::error::{Error, Result};
use crate::estimate::Estimate;
use crate::linear::LinearSpectrum;

/// The factor of the loops' shortcut error over the tree level's relative one (module docs): on five
/// Nseries bins (lowest, squeezed, isosceles, scalene, equilateral) × two biases × ℓ = 0, 2, 4 the loops'
/// binning error was at most about half of this × ε Σ|X₀| (docs/bispectrum.md).
pub const LOOP_SHORTCUT_FACTOR: f64 = 8.0;

/// The binned one-loop multipoles of a triangle set (module docs): per bin the loops at its effective
/// triangle per bias monomial, and the tree-level code's terms over the bins and at the effective
/// triangles, contracted with the bias at [`evaluate`](Self::evaluate).
#[derive(Debug, Clone)]
pub struct BinnedLoopMultipoles {
    /// Per bin, the effective triangle [h/Mpc].
    pub effective: Vec<[f64; 3]>,
    /// Per bin, the one-loop multipoles at the effective triangle.
    pub loops: Vec<GalaxyLoopMultipoles>,
    tree_bins: BispectrumTerms,
    tree_effective: BispectrumTerms,
}

impl BinnedLoopMultipoles {
    /// B₀, B₂, B₄ of every bin at the coefficients `bias` (module docs): the tree level corrected to the bin
    /// average (its error the tree-level plan's), the loop terms at the effective triangle with the
    /// shortcut's error added.
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] for a coefficient that is not finite.
    pub fn evaluate(&self, bias: &LoopBias) -> Result<Vec<[OneLoopGalaxy; 3]>> {
        let params = tree_params(bias);
        let bins = self.tree_bins.multipoles(&params)?;
        let at = self.tree_effective.multipoles(&params)?;
        self.loops
            .iter()
            .zip(bins.iter().zip(&at))
            .map(|(m, (bin, at))| {
                let mut ells = m.evaluate(bias)?;
                let monopoles = [
                    ells[0].b222.value,
                    ells[0].b321_i.value,
                    ells[0].b321_ii.value,
                    ells[0].b411.value,
                ];
                // the tree level's shortcut error relative to its B₀, the largest over ℓ
                let epsilon = (0..3)
                    .map(|l| (bin[l].value - at[l].value).abs() / bin[0].value.abs())
                    .fold(0.0, f64::max);
                for (l, b) in ells.iter_mut().enumerate() {
                    let shift = bin[l].value - at[l].value;
                    b.tree = Estimate::new(b.tree.value + shift, b.tree.error + bin[l].error);
                    let terms = [&mut b.b222, &mut b.b321_i, &mut b.b321_ii, &mut b.b411];
                    for (t, x0) in terms.into_iter().zip(monopoles) {
                        t.error += LOOP_SHORTCUT_FACTOR * epsilon * x0.abs();
                    }
                }
                Ok(ells)
            })
            .collect()
    }
}

/// The tree-level code's parameters of `bias` (velocileptors' b2 = b2^ESS − (4/3) g2, bs = g2), no
/// stochastic terms.
fn tree_params(bias: &LoopBias) -> BispectrumParams {
    let v = bias.values();
    BispectrumParams {
        b1: v[0],
        b2: v[1] - 4.0 / 3.0 * v[2],
        bs: v[2],
        b_shot: 0.0,
        p_shot: -1.0,
        a_shot: -1.0,
        ..BispectrumParams::default()
    }
}

/// The effective triangle of bin `i` of `set`: its mean sides over the closed triangles (weight k₁k₂k₃) on
/// the tree-level plan's default shell rule (the triangle [`PlanRules::effective`] evaluates).
pub fn effective_triangle(set: &TriangleSet, i: usize) -> [f64; 3] {
    set.shapes(i, PlanRules::default().n_shell)
        .iter()
        .fold([0.0; 3], |m, (k, w)| {
            [m[0] + w * k[0], m[1] + w * k[1], m[2] + w * k[2]]
        })
}

/// The binned one-loop multipoles of the bins `set` (shells; module docs) at growth rate `f`, the Legendre
/// polynomial on `side` (each bin's, as the tree level's), for the linear spectrum `p`, resummed with `ir`
/// if given, with the loop `rule`; `tick(done, total)` after each bin.
///
/// # Errors
/// [`Error::InvalidChoice`] for a set of points (no bins); as
/// [`super::one_loop_galaxy_multipoles::one_loop_galaxy_multipoles`] at an effective triangle, naming the
/// bin; as [`BispectrumPlan::new`].
pub fn binned_multipoles(
    p: &LinearSpectrum,
    ir: Option<&IrInputs>,
    set: &TriangleSet,
    f: f64,
    side: LegendreSide,
    rule: &OneLoopRule,
    tick: &dyn Fn(usize, usize),
) -> Result<BinnedLoopMultipoles> {
    if set.width().is_none() {
        return Err(Error::InvalidChoice {
            what: "a triangle set of points".into(),
            reason: "bin averages need bins (shells of a width)".into(),
        });
    }
    let settings = Settings {
        f,
        q_par: 1.0,
        q_perp: 1.0,
        fog: Fog::None,
        ir: ir.is_some(),
    };
    settings.validate()?;
    let plan = |effective: bool| {
        let rules = PlanRules {
            effective,
            ..PlanRules::default()
        };
        BispectrumPlan::new(set.clone(), side, rules)
    };
    let (bins, at) = (plan(false)?, plan(true)?);
    let terms = |plan: &BispectrumPlan| match ir {
        None => plan.terms(p, &settings),
        Some(ir) => plan.terms_with_ir(p, &settings, ir),
    };
    let (tree_bins, tree_effective) = (terms(&bins)?, terms(&at)?);
    let mut effective = Vec::with_capacity(set.len());
    let mut loops = Vec::with_capacity(set.len());
    for i in 0..set.len() {
        let k = effective_triangle(set, i);
        let a = LegendreSide::Index(set.legendre_index(i, side));
        let m =
            galaxy_multipoles(p, ir, k, f, a, rule, None).map_err(|e| Error::InvalidChoice {
                what: format!(
                    "bin {} (centres {:?}, effective triangle {k:?})",
                    i + 1,
                    set.triangles()[i]
                ),
                reason: e.to_string(),
            })?;
        effective.push(k);
        loops.push(m);
        tick(i + 1, set.len());
    }
    Ok(BinnedLoopMultipoles {
        effective,
        loops,
        tree_bins,
        tree_effective,
    })
}
