//! The plan (nodes of a triangle set, once), the terms of one linear spectrum (the bispectrum's
//! coefficients of its parameter monomials, once per spectrum, f, AP and FoG) and their contraction
//! with the parameters (per step, microseconds).

use super::geometry::{orientations, LegendreSide, MuGroup, Shape, TriangleSet};
use super::lanes::Blocks;
use super::observed::{accumulate, add_observed_slots};
pub(super) use super::observed::{tree_slots, SLOTS};
use super::resum::IrInputs;
use super::sampled::Sampled;
use super::{BispectrumParams, Settings};
use crate::error::Result;
use crate::estimate::Estimate;
use crate::ir::WiggleSplit;
use crate::linear::LinearSpectrum;
use crate::precision::Precision;
use rayon::prelude::*;

/// Quadrature orders of a plan: Gauss–Legendre nodes per shell (bins), in μ of the Legendre side and
/// trapezoid nodes in the azimuth. The error estimate is the difference from [`PlanRules::coarse`].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct PlanRules {
    /// Nodes per shell of a bin (k₁, k₂, and k₃ on its closed part).
    pub n_shell: usize,
    /// Nodes in μ_a ∈ [0, 1]: the positive half of the 2n_mu-point Gauss–Legendre rule on [−1, 1].
    pub n_mu: usize,
    /// Trapezoid nodes in the azimuth.
    pub n_phi: usize,
    /// The effective-triangle shortcut: each bin evaluated at one triangle, its mean sides over the
    /// bin's closed triangles (weight k₁k₂k₃), instead of averaged over them. The error estimate is
    /// then the difference from the bin average of the coarse rule, so it states the shortcut's error.
    pub effective: bool,
}

impl Default for PlanRules {
    /// 3 per shell panel, 5 × 5 orientations (μ_a ∈ [0, 1], φ ∈ (0, π)): exact for the polynomial part
    /// (degree ≤ 12 in μ_a, ≤ 8 in cos φ; the μ_a rule to degree 19, the coarse rule's to 15) without
    /// damping. On the 62 Nseries bins with IR, AP (q∥ = 1.04, q⊥ = 0.97) and a Lorentzian FoG of
    /// σ = 4 Mpc/h, 5 × 5 differs from 7 × 5 by less than 1e-6 of B₀ and from 16 × 16 (with 10 per
    /// shell panel) by 2.2e-4 of B₀, all of it the bin average's (3 per shell panel).
    fn default() -> Self {
        Self {
            n_shell: 3,
            n_mu: 5,
            n_phi: 5,
            effective: false,
        }
    }
}

impl PlanRules {
    /// The rule of the error estimate: one node fewer per shell panel, in μ_a and in φ (the difference
    /// bounds the bin-average error, which dominates, and the orientation error of the damping and AP;
    /// below 5 × 5 it includes the orientation rule's error on the polynomial part as well). With the
    /// effective-triangle shortcut, the same triangle with one node fewer in μ_a and in φ.
    pub fn coarse(&self) -> Self {
        Self {
            n_shell: if self.effective {
                self.n_shell
            } else {
                (self.n_shell.saturating_sub(1)).max(1)
            },
            n_mu: (self.n_mu.saturating_sub(1)).max(1),
            n_phi: (self.n_phi.saturating_sub(1)).max(1),
            effective: self.effective,
        }
    }
}

/// The growth rate and linear bias of the reference prediction on which the effective-triangle
/// shortcut's error is measured when a plan is made (the embedded gm2012 spectrum at z = 0.5, IR
/// resummed, no AP, no FoG, b₂ = b_s = 0, no shot noise).
const SHORTCUT_REFERENCE: (f64, f64) = (0.72, 2.0);

/// The tree-level bispectrum planned for one set of triangles: every node of its orientation and bin
/// averages, made once; [`terms`](Self::terms) per linear spectrum.
#[derive(Debug, Clone)]
pub struct BispectrumPlan {
    set: TriangleSet,
    side: LegendreSide,
    rules: PlanRules,
    fine: Vec<Vec<Shape>>,
    coarse: Vec<Vec<Shape>>,
    /// The nodes of `fine` and `coarse` laid out four μ-groups at a time.
    fine_blocks: Blocks,
    coarse_blocks: Blocks,
    split: WiggleSplit,
    q_min: f64,
    /// Shortest and longest side of every node [h/Mpc] (the range the spectrum is sampled over).
    k_range: [f64; 2],
    /// With the effective-triangle shortcut: its relative error per bin and ℓ, measured when the plan
    /// is made (empty otherwise).
    shortcut: Vec<[f64; 3]>,
}

impl BispectrumPlan {
    /// Plans `set` with the Legendre polynomial on `side`.
    ///
    /// # Errors
    /// As [`WiggleSplit::new`]; [`crate::error::Error::InvalidChoice`] for a rule with no node or a
    /// side index above 2.
    pub fn new(set: TriangleSet, side: LegendreSide, rules: PlanRules) -> Result<Self> {
        if rules.n_shell == 0 || rules.n_mu == 0 || rules.n_phi == 0 {
            return Err(crate::error::Error::InvalidChoice {
                what: format!("{rules:?}"),
                reason: "every quadrature rule needs at least one node".into(),
            });
        }
        if let LegendreSide::Index(a) = side {
            if a > 2 {
                return Err(crate::error::Error::InvalidChoice {
                    what: format!("Legendre side = {a}"),
                    reason: "a triangle has sides 0, 1, 2 (or 'largest')".into(),
                });
            }
        }
        let nodes = |r: PlanRules| -> Vec<Vec<Shape>> {
            (0..set.len())
                .map(|i| {
                    let a = set.legendre_index(i, side);
                    let mut shapes = set.shapes(i, r.n_shell);
                    if r.effective && shapes.len() > 1 {
                        let mean = shapes.iter().fold([0.0; 3], |m, (k, w)| {
                            [m[0] + w * k[0], m[1] + w * k[1], m[2] + w * k[2]]
                        });
                        shapes = vec![(mean, 1.0)];
                    }
                    shapes
                        .into_iter()
                        .map(|(k, w)| {
                            let sq = k.map(|k| k * k);
                            let dots = [0, 1, 2]
                                .map(|i| 0.5 * (sq[(i + 2) % 3] - sq[i] - sq[(i + 1) % 3]));
                            let groups = orientations(k, a, r.n_mu, r.n_phi)
                                .chunks(r.n_phi)
                                .map(|chunk| MuGroup {
                                    par: chunk.iter().map(|o| [o[0], o[1], o[2]]).collect(),
                                    lambda: [chunk[0][3] * w, chunk[0][4] * w, chunk[0][5] * w],
                                })
                                .collect();
                            Shape {
                                k,
                                side: a,
                                dots,
                                groups,
                            }
                        })
                        .collect()
                })
                .collect()
        };
        let (fine, coarse) = (nodes(rules), nodes(rules.coarse()));
        let k_range = fine
            .iter()
            .chain(&coarse)
            .flatten()
            .flat_map(|shape| shape.k)
            .fold([f64::INFINITY, 0.0_f64], |[lo, hi], k| {
                [lo.min(k), hi.max(k)]
            });
        let mut plan = Self {
            fine_blocks: Blocks::new(&fine),
            coarse_blocks: Blocks::new(&coarse),
            fine,
            coarse,
            k_range,
            split: WiggleSplit::new()?,
            q_min: Precision::default().q_min,
            set,
            side,
            rules,
            shortcut: Vec::new(),
        };
        if rules.effective && set_has_bins(&plan.set) {
            plan.shortcut = plan.measure_shortcut()?;
        }
        Ok(plan)
    }

    /// The effective-triangle shortcut's relative error per bin and ℓ (|B_ℓ(mean triangle) − B_ℓ(bin
    /// average)| / |B₀(bin average)|) on the reference prediction [`SHORTCUT_REFERENCE`].
    fn measure_shortcut(&self) -> Result<Vec<[f64; 3]>> {
        let (f, b1) = SHORTCUT_REFERENCE;
        let spectrum = LinearSpectrum::gm2012(0.5)?;
        let settings = Settings {
            f,
            q_par: 1.0,
            q_perp: 1.0,
            fog: super::Fog::None,
            ir: true,
        };
        let params = BispectrumParams {
            b1,
            ..BispectrumParams::default()
        };
        let average = Self::new(
            self.set.clone(),
            self.side,
            PlanRules {
                effective: false,
                ..self.rules
            },
        )?;
        let exact = average.terms(&spectrum, &settings)?.multipoles(&params)?;
        let mut shortcut = self.terms(&spectrum, &settings)?;
        shortcut.shortcut.clear();
        let approx = shortcut.multipoles(&params)?;
        Ok(exact
            .iter()
            .zip(&approx)
            .map(|(e, a)| [0, 1, 2].map(|l| (a[l].value - e[l].value).abs() / e[0].value.abs()))
            .collect())
    }

    /// The triangles.
    pub fn triangles(&self) -> &TriangleSet {
        &self.set
    }

    /// The Legendre side.
    pub fn side(&self) -> LegendreSide {
        self.side
    }

    /// The quadrature rules.
    pub fn rules(&self) -> PlanRules {
        self.rules
    }

    /// The coefficients of every parameter monomial of B₀, B₂, B₄ at every triangle for `spectrum`
    /// (the linear spectrum at the redshift of the prediction) with `settings`.
    ///
    /// # Errors
    /// As [`Settings::validate`] and the no-wiggle split.
    pub fn terms(&self, spectrum: &LinearSpectrum, settings: &Settings) -> Result<BispectrumTerms> {
        settings.validate()?;
        let ir = if settings.ir {
            Some(self.ir_inputs(spectrum)?)
        } else {
            None
        };
        self.terms_resummed(spectrum, settings, ir.as_ref(), false)
    }

    /// The IR resummation's inputs of `spectrum` with this plan's no-wiggle split (what
    /// [`terms`](Self::terms) makes; they depend on the spectrum alone, not on f or AP, so a caller
    /// evaluating many f or α of one spectrum makes them once and passes them to
    /// [`terms_with_ir`](Self::terms_with_ir)).
    ///
    /// # Errors
    /// As the no-wiggle split.
    pub fn ir_inputs(&self, spectrum: &LinearSpectrum) -> Result<IrInputs> {
        IrInputs::split(spectrum, &self.split, self.q_min)
    }

    /// As [`terms`](Self::terms), with the IR resummation's no-wiggle spectrum and Σ², δΣ² given
    /// (`settings.ir` must be true), e.g. to compare with another code's split.
    ///
    /// # Errors
    /// As [`terms`](Self::terms); [`crate::error::Error::InvalidChoice`] if `settings.ir` is false.
    pub fn terms_with_ir(
        &self,
        spectrum: &LinearSpectrum,
        settings: &Settings,
        ir: &IrInputs,
    ) -> Result<BispectrumTerms> {
        settings.validate()?;
        settings.require_ir()?;
        self.terms_resummed(spectrum, settings, Some(ir), false)
    }

    /// The terms with IR resummation from `ir` (none for `None`): the nodes four μ-groups at a time
    /// ([`Blocks::sums`]) where the processor has AVX2 and FMA, else (or with `per_node`) node by node.
    pub(super) fn terms_resummed(
        &self,
        spectrum: &LinearSpectrum,
        settings: &Settings,
        ir: Option<&IrInputs>,
        per_node: bool,
    ) -> Result<BispectrumTerms> {
        // P and P_nw (P_nw = P without IR resummation) sampled once over every true side a node can
        // have: k/q with q between q∥ and q⊥
        let (q_lo, q_hi) = (
            settings.q_par.min(settings.q_perp),
            settings.q_par.max(settings.q_perp),
        );
        let table = Sampled::new(
            spectrum,
            ir.map(|ir| &ir.no_wiggle),
            self.k_range[0] / q_hi,
            self.k_range[1] / q_lo,
        )?;
        let sum = |shapes: &[Vec<Shape>], blocks: &Blocks| {
            (!per_node)
                .then(|| blocks.sums(&table, settings, ir))
                .flatten()
                .unwrap_or_else(|| per_node_sums(shapes, &table, settings, ir))
        };
        Ok(BispectrumTerms {
            fine: sum(&self.fine, &self.fine_blocks),
            coarse: sum(&self.coarse, &self.coarse_blocks),
            interpolation: table.relative_error,
            shortcut: self.shortcut.clone(),
            triangles: self.set.triangles().to_vec(),
        })
    }
}

/// The slots of every triangle of `shapes` node by node ([`add_observed_slots`]), the Z₁Z₁Z₂ part
/// symmetrised as [`Blocks::sums`] makes it (S_αβ + S_βα in slot (α, β), α ≤ β; slot (β, α) 0).
fn per_node_sums(
    shapes: &[Vec<Shape>],
    table: &Sampled,
    settings: &Settings,
    ir: Option<&IrInputs>,
) -> Vec<[[f64; SLOTS]; 3]> {
    // the resummed P at k, μ from (P, P_nw)
    let resummed = |(p, p_nw): (f64, f64), k: f64, mu: f64| -> f64 {
        ir.map_or(p, |ir| ir.resum(p, p_nw, k, mu, settings.f))
    };
    // Without an anisotropic distortion the true sides k/q do not depend on the orientation:
    // the spectra are looked up once per shape, not once per orientation.
    let isotropic = settings.q_par == settings.q_perp;
    // triangles in parallel (rayon; RAYON_NUM_THREADS=1 for one core)
    shapes
        .par_iter()
        .map(|triangle| {
            let mut acc = [[0.0; SLOTS]; 3];
            for shape in triangle {
                let cached = isotropic.then(|| shape.k.map(|k| table.eval(k / settings.q_par)));
                let power = |i: usize, k: f64, mu: f64| {
                    resummed(cached.map_or_else(|| table.eval(k), |c| c[i]), k, mu)
                };
                for group in &shape.groups {
                    // the Legendre side's power once per group: its k and μ do not depend on
                    // the azimuth
                    let side = std::cell::Cell::new(None);
                    let power = |i: usize, k: f64, mu: f64| {
                        if i != shape.side {
                            return power(i, k, mu);
                        }
                        if let Some(p) = side.get() {
                            return p;
                        }
                        let p = power(i, k, mu);
                        side.set(Some(p));
                        p
                    };
                    // the azimuths first (λ depends on μ only), then ℓ
                    let mut azimuths = [0.0; SLOTS];
                    for par in &group.par {
                        add_observed_slots(
                            &mut azimuths,
                            shape.k,
                            shape.dots,
                            *par,
                            settings,
                            power,
                        );
                    }
                    accumulate(&mut acc, group.lambda, &azimuths);
                }
            }
            acc.map(|mut slots| {
                symmetrise(&mut slots);
                slots
            })
        })
        .collect()
}

/// S_αβ + S_βα in slot (α, β) of Z₁Z₁Z₂, α < β, and 0 in slot (β, α) (the contraction with u_α u_β
/// is the same).
pub(super) fn symmetrise(slots: &mut [f64; SLOTS]) {
    for al in 0..3 {
        for be in al + 1..3 {
            for g in 0..4 {
                let (upper, lower) = ((al * 3 + be) * 4 + g, (be * 3 + al) * 4 + g);
                slots[upper] += slots[lower];
                slots[lower] = 0.0;
            }
        }
    }
}

/// The contraction of slots with the parameters.
pub(super) fn contract(slots: &[f64; SLOTS], b: &BispectrumParams) -> f64 {
    let u = [1.0, b.b1, b.c1];
    let v = [1.0, b.b1, b.b2, b.bs];
    let mut total = 0.0;
    for al in 0..3 {
        for be in 0..3 {
            let uu = u[al] * u[be];
            let base = (al * 3 + be) * 4;
            total += uu * (0..4).map(|g| v[g] * slots[base + g]).sum::<f64>();
        }
    }
    let inv_n = 1.0 / b.n_bar;
    let (mut shot_b, mut shot_p) = (0.0, 0.0);
    for be in 0..3 {
        shot_b += u[be] * slots[36 + be];
        shot_p += u[be] * slots[39 + be];
    }
    total
        + inv_n * (b.b_shot * b.b1 * shot_b + (1.0 + b.p_shot) * shot_p)
        + (1.0 + b.a_shot) * inv_n * inv_n * slots[42]
}

/// B at one configuration, unaveraged: sides `sides` (closing, [h/Mpc]), line of sight `los` (any
/// length), linear power `p` at the three sides, growth rate `f`, no IR resummation, FoG or AP.
pub fn tree_level_at(
    sides: [[f64; 3]; 3],
    los: [f64; 3],
    p: [f64; 3],
    f: f64,
    params: &BispectrumParams,
) -> f64 {
    use crate::vec3::dot;
    let n = dot(&los, &los).sqrt();
    let k = sides.map(|s| dot(&s, &s).sqrt());
    let dots = [0, 1, 2].map(|i| dot(&sides[i], &sides[(i + 1) % 3]));
    let par = sides.map(|s| dot(&s, &los) / n);
    contract(&tree_slots(k, dots, par, p, f), params)
}

/// The monomial coefficients of B₀, B₂, B₄ of one spectrum at every triangle (fine and coarse rules):
/// [`multipoles`](Self::multipoles) per parameter step.
#[derive(Debug, Clone)]
pub struct BispectrumTerms {
    fine: Vec<[[f64; SLOTS]; 3]>,
    coarse: Vec<[[f64; SLOTS]; 3]>,
    /// Relative error of the sampled spectrum (B is quadratic in it).
    interpolation: f64,
    /// The effective-triangle shortcut's relative error per bin and ℓ (empty without it).
    shortcut: Vec<[f64; 3]>,
    triangles: Vec<[f64; 3]>,
}

impl BispectrumTerms {
    /// Terms of exact sums (no quadrature: the coarse rule is the rule itself, errors are zero).
    pub(super) fn exact(slots: Vec<[[f64; SLOTS]; 3]>, triangles: Vec<[f64; 3]>) -> Self {
        Self {
            fine: slots.clone(),
            coarse: slots,
            interpolation: 0.0,
            shortcut: Vec::new(),
            triangles,
        }
    }

    /// The slots of the fine and the coarse rule.
    #[cfg(test)]
    pub(super) fn slots(&self) -> [&[[[f64; SLOTS]; 3]]; 2] {
        [&self.fine, &self.coarse]
    }

    /// The triangles (bin centres) [h/Mpc].
    pub fn triangles(&self) -> &[[f64; 3]] {
        &self.triangles
    }

    /// B₀, B₂, B₄ [(Mpc/h)⁶] at every triangle, each with the difference from the coarse rule plus
    /// twice the measured relative error of the sampled spectrum as its error; with the
    /// effective-triangle shortcut, plus twice its error measured on the reference prediction (relative
    /// to B₀; [`PlanRules::effective`]).
    ///
    /// # Errors
    /// As [`BispectrumParams::validate`].
    pub fn multipoles(&self, params: &BispectrumParams) -> Result<Vec<[Estimate; 3]>> {
        params.validate()?;
        Ok(self
            .fine
            .iter()
            .zip(&self.coarse)
            .enumerate()
            .map(|(i, (fine, coarse))| {
                let b0 = contract(&fine[0], params).abs();
                [0, 1, 2].map(|l| {
                    let v = contract(&fine[l], params);
                    let c = contract(&coarse[l], params);
                    let shortcut = self.shortcut.get(i).map_or(0.0, |s| 2.0 * s[l] * b0);
                    Estimate::new(
                        v,
                        (v - c).abs() + 2.0 * self.interpolation * v.abs() + shortcut,
                    )
                })
            })
            .collect())
    }
}

/// Whether `set` holds bins (shells), where the effective-triangle shortcut differs from the average.
fn set_has_bins(set: &TriangleSet) -> bool {
    set.width().is_some()
}
