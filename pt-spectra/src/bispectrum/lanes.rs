//! The bin and orientation averages of the tree-level slots with four μ-groups of a triangle side by
//! side in the four f64 lanes of AVX2 (x86-64 with AVX2 and FMA, detected at run time; elsewhere
//! [`Blocks::sums`] declines and the per-node sum of [`super::observed`] runs).
//!
//! Everything that does not depend on the spectrum, f, AP, FoG or IR is laid out when the plan is made
//! ([`Blocks::new`]): per block of four μ-groups the squared observed sides kᵢ², the dot products and
//! the Legendre side's line-of-sight component (one per group: it does not depend on the azimuth),
//! the weights λ_ℓ = (2ℓ + 1)L_ℓ(μ) × node weight; per azimuth the other two sides' line-of-sight
//! components. The sides are rotated cyclically so that the Legendre side is side 0 (B sums over the
//! cyclic pairs and is invariant), so its power and damping are made once per group.
//!
//! Per node the slots are those of [`super::observed::observed_slots`] with the Z₁Z₁Z₂ part
//! symmetrised in (α, β): the contraction with u_α u_β (u = (1, b₁, c₁)) sees only S_αβ + S_βα, which
//! is accumulated in slot (α, β), α ≤ β, and slot (β, α) left 0 (24 sums of three pairs per node,
//! not 36). The spectrum is read from [`Sampled`]'s cubic rows, one division per node gives 1/k₁, 1/k₂
//! and the Lorentzian FoG's 1/D² (1/(k₁k₂D²) times the other two factors), and the resummation's
//! e^{−k²Σ²_tot} is `x86::exp` (within two units in the last place of the library's). The kernel is in
//! `x86`.

use super::geometry::Shape;
use super::observed::SLOTS;
use super::resum::IrInputs;
use super::sampled::Sampled;
use super::{Fog, Settings};
use std::ops::Range;

/// Lanes per vector.
const L: usize = 4;

/// The plan-time constants of four μ-groups (lanes), sides rotated so that side 0 is the Legendre
/// side.
#[derive(Debug, Clone, Copy)]
struct Block {
    /// kᵢ² of the observed sides [(h/Mpc)²].
    k2: [[f64; L]; 3],
    /// k₀·k₁, k₁·k₂, k₂·k₀ (observed).
    dots: [[f64; L]; 3],
    /// Line-of-sight component of side 0 (every azimuth of the group).
    par0: [f64; L],
    /// (2ℓ + 1)L_ℓ(μ) × weight, ℓ = 0, 2, 4 (0 in a lane that pads a triangle's last block).
    lambda: [[f64; L]; 3],
}

/// Every node of one rule's averages in blocks of four μ-groups.
#[derive(Debug, Clone)]
pub(super) struct Blocks {
    blocks: Vec<Block>,
    /// Line-of-sight components of sides 1 and 2 at azimuth m of block b: `par[b n_φ + m]`.
    par: Vec<[[f64; L]; 2]>,
    n_phi: usize,
    /// The blocks of each triangle.
    triangles: Vec<Range<usize>>,
}

impl Blocks {
    /// The blocks of the shapes of each triangle (every μ-group with the same number of azimuths).
    pub(super) fn new(triangles: &[Vec<Shape>]) -> Self {
        let n_phi = triangles
            .first()
            .and_then(|t| t.first())
            .and_then(|s| s.groups.first())
            .map_or(0, |g| g.par.len());
        let mut out = Self {
            blocks: Vec::new(),
            par: Vec::new(),
            n_phi,
            triangles: Vec::with_capacity(triangles.len()),
        };
        for triangle in triangles {
            let start = out.blocks.len();
            let groups: Vec<_> = triangle
                .iter()
                .flat_map(|shape| shape.groups.iter().map(move |g| (shape, g)))
                .collect();
            for chunk in groups.chunks(L) {
                // a lane past the chunk repeats its last group with no weight
                let lane = |l: usize| chunk[l.min(chunk.len() - 1)];
                let side = |l: usize, n: usize| (lane(l).0.side + n) % 3;
                let mut block = Block {
                    k2: [[0.0; L]; 3],
                    dots: [[0.0; L]; 3],
                    par0: [0.0; L],
                    lambda: [[0.0; L]; 3],
                };
                for l in 0..L {
                    let (shape, group) = lane(l);
                    assert_eq!(group.par.len(), n_phi, "μ-groups of unequal azimuths");
                    for n in 0..3 {
                        let k = shape.k[side(l, n)];
                        block.k2[n][l] = k * k;
                        block.dots[n][l] = shape.dots[side(l, n)];
                        if l < chunk.len() {
                            block.lambda[n][l] = group.lambda[n];
                        }
                    }
                    block.par0[l] = group.par[0][side(l, 0)];
                }
                for m in 0..n_phi {
                    out.par.push(
                        [1, 2].map(|n| std::array::from_fn(|l| lane(l).1.par[m][side(l, n)])),
                    );
                }
                out.blocks.push(block);
            }
            out.triangles.push(start..out.blocks.len());
        }
        out
    }

    /// The slots of ℓ = 0, 2, 4 of every triangle, Z₁Z₁Z₂ part symmetrised (module docs), or `None`
    /// where the processor has no AVX2 and FMA. Triangles in parallel (rayon).
    pub(super) fn sums(
        &self,
        table: &Sampled,
        s: &Settings,
        ir: Option<&IrInputs>,
    ) -> Option<Vec<[[f64; SLOTS]; 3]>> {
        #[cfg(target_arch = "x86_64")]
        if let Some(simd) = pulp::x86::V3::try_new() {
            use rayon::prelude::*;
            let c = x86::Consts::new(table, s, ir);
            return Some(
                self.triangles
                    .par_iter()
                    .map(|r| {
                        simd.vectorize(x86::Triangle {
                            simd,
                            blocks: self,
                            range: r.clone(),
                            c: &c,
                        })
                    })
                    .collect(),
            );
        }
        let _ = (table, s, ir);
        None
    }
}

#[cfg(target_arch = "x86_64")]
mod x86;

#[cfg(test)]
mod tests {
    use super::super::terms::BispectrumPlan;
    use super::super::{Fog, LegendreSide, PlanRules, Settings, TriangleSet};
    use crate::linear::LinearSpectrum;

    /// The blocks' sums against the node-by-node sums of `observed_slots` on a few bins (an
    /// isosceles, a squeezed and an open one), with anisotropic AP, IR and either FoG, and without.
    #[test]
    fn lanes_equal_the_node_by_node_sums() {
        #[cfg(target_arch = "x86_64")]
        if pulp::x86::V3::try_new().is_none() {
            return; // the lanes decline: both are the node-by-node sums
        }
        let set = TriangleSet::shells(
            vec![
                [0.05, 0.05, 0.05],
                [0.02, 0.1, 0.11],
                [0.04, 0.07, 0.1],
                [0.06, 0.06, 0.11],
            ],
            0.01,
        )
        .unwrap();
        let plan = BispectrumPlan::new(set, LegendreSide::Largest, PlanRules::default()).unwrap();
        let spectrum = LinearSpectrum::gm2012(0.5).unwrap();
        let ir = plan.ir_inputs(&spectrum).unwrap();
        let params = super::super::tests::galaxy();
        let cases = [
            (1.04, 0.97, Fog::Lorentzian { sigma: 4.0 }, true),
            (0.98, 1.03, Fog::Gaussian { sigma: 3.0 }, true),
            (1.02, 1.02, Fog::None, false),
        ];
        for (q_par, q_perp, fog, with_ir) in cases {
            let s = Settings {
                f: 0.76,
                q_par,
                q_perp,
                fog,
                ir: with_ir,
            };
            let ir = with_ir.then_some(&ir);
            let lanes = plan.terms_resummed(&spectrum, &s, ir, false).unwrap();
            let nodes = plan.terms_resummed(&spectrum, &s, ir, true).unwrap();
            for (a, b) in lanes.slots().iter().zip(nodes.slots()) {
                for t in 0..a.len() {
                    for slot in 0..a[t][0].len() {
                        // relative to the slot's largest |B_ℓ| (one ℓ may cancel)
                        let scale = (0..3).map(|l| b[t][l][slot].abs()).fold(0.0, f64::max);
                        for l in 0..3 {
                            let (x, y) = (a[t][l][slot], b[t][l][slot]);
                            assert!(
                                (x - y).abs() <= 1e-12 * scale,
                                "{s:?}: triangle {t} ℓ index {l} slot {slot}: {x} vs {y}"
                            );
                        }
                    }
                }
            }
            let (a, b) = (
                lanes.multipoles(&params).unwrap(),
                nodes.multipoles(&params).unwrap(),
            );
            for (a, b) in a.iter().zip(&b) {
                for l in 0..3 {
                    assert!((a[l].value - b[l].value).abs() <= 1e-12 * b[0].value.abs());
                    assert!((a[l].error - b[l].error).abs() <= 1e-12 * b[0].value.abs());
                }
            }
        }
    }

    /// The vectorised exponential against the library's to two units in the last place.
    #[cfg(target_arch = "x86_64")]
    #[test]
    fn the_vectorised_exponential_is_the_librarys_to_rounding() {
        let Some(simd) = pulp::x86::V3::try_new() else {
            return;
        };
        struct Exp(pulp::x86::V3, [f64; 4]);
        impl pulp::NullaryFnOnce for Exp {
            type Output = [f64; 4];
            #[inline(always)]
            fn call(self) -> [f64; 4] {
                super::x86::exp(super::x86::X::load(self.0, self.1)).lanes()
            }
        }
        for i in 0..20_000 {
            let x: [f64; 4] =
                std::array::from_fn(|l| -700.0 + 1400.0 * (4 * i + l) as f64 / 80_000.0);
            let got = simd.vectorize(Exp(simd, x));
            for (g, x) in got.iter().zip(x) {
                let want = x.exp();
                assert!(
                    (g / want - 1.0).abs() <= 4.5e-16,
                    "exp({x}) = {g}, not {want}"
                );
            }
        }
        for x in [
            0.0,
            -1e-300,
            1e-17,
            -0.5 * std::f64::consts::LN_2,
            0.346_573_590_279_972_7,
        ] {
            let got = simd.vectorize(Exp(simd, [x; 4]))[0];
            assert!((got / x.exp() - 1.0).abs() <= 4.5e-16, "exp({x}) = {got}");
        }
    }
}
