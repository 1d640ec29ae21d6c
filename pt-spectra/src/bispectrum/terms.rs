//! The plan (nodes of a triangle set, once), the terms of one linear spectrum (the bispectrum's
//! coefficients of its parameter monomials, once per spectrum, f, AP and FoG) and their contraction
//! with the parameters (per step, microseconds).

use super::geometry::{orientations, LegendreSide, TriangleSet};
use super::{BispectrumParams, Settings};
use crate::error::Result;
use crate::estimate::Estimate;
use crate::ir::{delta_sigma2_bao, sigma2_bao, sigma2_total, WiggleSplit};
use crate::linear::LinearSpectrum;
use crate::precision::Precision;

/// Quadrature orders of a plan: Gauss–Legendre nodes per shell (bins), in μ of the Legendre side and
/// trapezoid nodes in the azimuth. The error estimate is the difference from [`PlanRules::coarse`].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct PlanRules {
    /// Nodes per shell of a bin (k₁, k₂, and k₃ on its closed part).
    pub n_shell: usize,
    /// Gauss–Legendre nodes in μ_a.
    pub n_mu: usize,
    /// Trapezoid nodes in the azimuth.
    pub n_phi: usize,
}

impl Default for PlanRules {
    /// 3 per shell panel, 8 × 8 orientations (μ_a ∈ [0, 1], φ ∈ (0, π)): exact for the polynomial part
    /// (degree ≤ 12 in μ_a and cos φ) without damping.
    fn default() -> Self {
        Self {
            n_shell: 3,
            n_mu: 8,
            n_phi: 8,
        }
    }
}

impl PlanRules {
    /// The rule of the error estimate: one node fewer per shell panel, in μ_a and in φ (7 × 7 is still
    /// exact for the polynomial part, so the difference measures the damping, AP and bin-average errors).
    pub fn coarse(&self) -> Self {
        Self {
            n_shell: (self.n_shell.saturating_sub(1)).max(1),
            n_mu: (self.n_mu.saturating_sub(1)).max(1),
            n_phi: (self.n_phi.saturating_sub(1)).max(1),
        }
    }
}

/// Number of monomial slots per triangle and ℓ: 36 of Z₁Z₁Z₂ (3 × 3 × 4), 3 + 3 of the 1/n̄ terms, 1 of
/// the 1/n̄² term.
const SLOTS: usize = 43;

/// One shape of a triangle or bin in the observed (fiducial) frame: sides, their dot products (k₀·k₁,
/// k₁·k₂, k₂·k₀) and the orientation nodes of its average.
#[derive(Debug, Clone)]
struct Shape {
    k: [f64; 3],
    dots: [f64; 3],
    orientations: Vec<Orientation>,
}

/// One orientation of a shape: the sides' line-of-sight components and the (2ℓ + 1)L_ℓ × weight of
/// ℓ = 0, 2, 4 (the shape's bin weight included).
#[derive(Debug, Clone, Copy)]
struct Orientation {
    par: [f64; 3],
    lambda: [f64; 3],
}

/// The tree-level bispectrum planned for one set of triangles: every node of its orientation and bin
/// averages, made once; [`terms`](Self::terms) per linear spectrum.
#[derive(Debug, Clone)]
pub struct BispectrumPlan {
    set: TriangleSet,
    side: LegendreSide,
    rules: PlanRules,
    fine: Vec<Vec<Shape>>,
    coarse: Vec<Vec<Shape>>,
    split: WiggleSplit,
    q_min: f64,
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
                    set.shapes(i, r.n_shell)
                        .into_iter()
                        .map(|(k, w)| {
                            let sq = k.map(|k| k * k);
                            let dots = [0, 1, 2]
                                .map(|i| 0.5 * (sq[(i + 2) % 3] - sq[i] - sq[(i + 1) % 3]));
                            let orientations = orientations(k, a, r.n_mu, r.n_phi)
                                .into_iter()
                                .map(|o| Orientation {
                                    par: [o[0], o[1], o[2]],
                                    lambda: [o[3] * w, o[4] * w, o[5] * w],
                                })
                                .collect();
                            Shape {
                                k,
                                dots,
                                orientations,
                            }
                        })
                        .collect()
                })
                .collect()
        };
        Ok(Self {
            fine: nodes(rules),
            coarse: nodes(rules.coarse()),
            split: WiggleSplit::new()?,
            q_min: Precision::default().q_min,
            set,
            side,
            rules,
        })
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
            let nw = self.split.no_wiggle(spectrum)?;
            let s2 = sigma2_bao(&nw, self.q_min);
            let ds2 = delta_sigma2_bao(&nw, self.q_min);
            Some((nw, s2.value, ds2.value))
        } else {
            None
        };
        // P and P_nw at k (P_nw = P without IR resummation), and the resummed P at k, μ from them.
        let legs = |k: f64| -> (f64, f64) {
            let p = spectrum.eval(k);
            (p, ir.as_ref().map_or(p, |(nw, _, _)| nw.eval(k)))
        };
        let resummed = |(p, p_nw): (f64, f64), k: f64, mu: f64| -> f64 {
            match &ir {
                None => p,
                Some((_, s2, ds2)) => {
                    let x = k * k * sigma2_total(*s2, *ds2, settings.f, mu);
                    p_nw + (-x).exp() * (p - p_nw)
                }
            }
        };
        // Without an anisotropic distortion the true sides k/q do not depend on the orientation:
        // the spectra are interpolated once per shape, not once per orientation.
        let isotropic = settings.q_par == settings.q_perp;
        let sum = |shapes: &Vec<Vec<Shape>>| -> Vec<[[f64; SLOTS]; 3]> {
            shapes
                .iter()
                .map(|triangle| {
                    let mut acc = [[0.0; SLOTS]; 3];
                    for shape in triangle {
                        let cached = isotropic.then(|| shape.k.map(|k| legs(k / settings.q_par)));
                        let power = |i: usize, k: f64, mu: f64| {
                            resummed(cached.map_or_else(|| legs(k), |c| c[i]), k, mu)
                        };
                        for o in &shape.orientations {
                            let (slots, weight) = node_slots(shape, o, settings, &power);
                            for (l, acc) in acc.iter_mut().enumerate() {
                                let g = weight * o.lambda[l];
                                for (a, s) in acc.iter_mut().zip(&slots) {
                                    *a += g * s;
                                }
                            }
                        }
                    }
                    acc
                })
                .collect()
        };
        Ok(BispectrumTerms {
            fine: sum(&self.fine),
            coarse: sum(&self.coarse),
            triangles: self.set.triangles().to_vec(),
        })
    }
}

/// The monomial slots of one orientation of a shape (in the true frame after AP) and its overall weight
/// (the AP volume factor; the FoG factor is already in the slots it damps). `power(i, k, μ)` is the
/// (resummed) linear power of side i at its true k, μ.
fn node_slots(
    shape: &Shape,
    o: &Orientation,
    s: &Settings,
    power: &dyn Fn(usize, f64, f64) -> f64,
) -> ([f64; SLOTS], f64) {
    let (qp2, qt2) = (s.q_par * s.q_par, s.q_perp * s.q_perp);
    let par = o.par.map(|p| p / s.q_par);
    let k2: [f64; 3] = [0, 1, 2].map(|i| {
        let perp2 = (shape.k[i] * shape.k[i] - o.par[i] * o.par[i]).max(0.0);
        par[i] * par[i] + perp2 / qt2
    });
    let k = k2.map(f64::sqrt);
    let mu = [0, 1, 2].map(|i| par[i] / k[i]);
    let dots = [0, 1, 2].map(|i| {
        let j = (i + 1) % 3;
        let pp = o.par[i] * o.par[j];
        pp / qp2 + (shape.dots[i] - pp) / qt2
    });
    let p = [0, 1, 2].map(|i| power(i, k[i], mu[i]));
    let fog = s.fog.factor(par.iter().map(|p| p * p).sum());
    let mut slots = tree_slots(k, dots, par, p, s.f);
    for v in &mut slots[..SLOTS - 1] {
        *v *= fog;
    }
    (slots, 1.0 / (qp2 * qt2 * qt2))
}

/// The slots of B at one configuration with true sides of lengths `k`, dot products `dots`, line-of-sight
/// components `par` and linear power `p` (see the module docs of [`crate::bispectrum`]):
/// Z₁ = u·a with u = (1, b₁, c₁), a = (fμ², 1, −k²μ²); Z₂ = v·c with v = (1, b₁, b₂, b_s).
fn tree_slots(k: [f64; 3], dots: [f64; 3], par: [f64; 3], p: [f64; 3], f: f64) -> [f64; SLOTS] {
    let mu = [0, 1, 2].map(|i| par[i] / k[i]);
    let a: [[f64; 3]; 3] = [0, 1, 2].map(|i| [f * mu[i] * mu[i], 1.0, -par[i] * par[i]]);
    let mut out = [0.0; SLOTS];
    for i in 0..3 {
        let (j, l) = ((i + 1) % 3, (i + 2) % 3);
        let cos = dots[i] / (k[i] * k[j]);
        let ratio = k[i] / k[j] + k[j] / k[i];
        let f2 = 5.0 / 7.0 + 0.5 * cos * ratio + 2.0 / 7.0 * cos * cos;
        let g2 = 3.0 / 7.0 + 0.5 * cos * ratio + 4.0 / 7.0 * cos * cos;
        let k_par = par[i] + par[j]; // n̂·(kᵢ + kⱼ) = −n̂·k_l
        let mu12_sq = k_par * k_par / (k[l] * k[l]);
        let c = [
            f * mu12_sq * g2
                + 0.5
                    * f
                    * f
                    * k_par
                    * (mu[i] * mu[j] * mu[j] / k[i] + mu[j] * mu[i] * mu[i] / k[j]),
            f2 + 0.5 * f * k_par * (mu[i] / k[i] + mu[j] / k[j]),
            0.5,
            cos * cos - 1.0 / 3.0,
        ];
        let pp = 2.0 * p[i] * p[j];
        for al in 0..3 {
            for be in 0..3 {
                let ab = pp * a[i][al] * a[j][be];
                for (g, cg) in c.iter().enumerate() {
                    out[(al * 3 + be) * 4 + g] += ab * cg;
                }
            }
        }
        for be in 0..3 {
            out[36 + be] += p[i] * a[i][be];
            out[39 + be] += p[i] * a[i][0] * a[i][be];
        }
    }
    out[42] = 1.0;
    out
}

/// The contraction of slots with the parameters.
fn contract(slots: &[f64; SLOTS], b: &BispectrumParams) -> f64 {
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
    let dot = |a: &[f64; 3], b: &[f64; 3]| a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
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
    triangles: Vec<[f64; 3]>,
}

impl BispectrumTerms {
    /// The triangles (bin centres) [h/Mpc].
    pub fn triangles(&self) -> &[[f64; 3]] {
        &self.triangles
    }

    /// B₀, B₂, B₄ [(Mpc/h)⁶] at every triangle, each with the difference from the coarse rule as its
    /// error.
    ///
    /// # Errors
    /// As [`BispectrumParams::validate`].
    pub fn multipoles(&self, params: &BispectrumParams) -> Result<Vec<[Estimate; 3]>> {
        params.validate()?;
        Ok(self
            .fine
            .iter()
            .zip(&self.coarse)
            .map(|(fine, coarse)| {
                [0, 1, 2].map(|l| {
                    let v = contract(&fine[l], params);
                    let c = contract(&coarse[l], params);
                    Estimate::new(v, (v - c).abs())
                })
            })
            .collect())
    }
}
