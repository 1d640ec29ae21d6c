//! The Sugiyama et al. (2019, arXiv:1803.02132) multipoles B_{ℓ₁ℓ₂L}(k₁, k₂) of the tree-level
//! bispectrum: the tripolar-harmonic expansion in the directions of k₁, k₂ and the line of sight, with
//! the angle between k₁ and k₂ integrated:
//!
//! ```text
//! B_{ℓ₁ℓ₂L}(k₁, k₂) = H N ∫ d²k̂₁/(4π) ∫ d²k̂₂/(4π) S_{ℓ₁ℓ₂L}(k̂₁, k̂₂, n̂) B(k₁, k₂, k₃ = −k₁ − k₂; n̂)
//!                   = (1/8π) ∫_{−1}^{1} dx ∫_{−1}^{1} dμ₁ ∫_0^{2π} dφ  w_{ℓ₁ℓ₂L} B,
//! ```
//!
//! H = (ℓ₁ ℓ₂ L; 0 0 0), N = (2ℓ₁+1)(2ℓ₂+1)(2L+1), S the tripolar harmonic, x = k̂₁·k̂₂, μ₁ = k̂₁·n̂, φ
//! the azimuth of k̂₂ about k̂₁ (μ₂ = μ₁x + √(1−μ₁²)√(1−x²) cos φ), with the weights
//! w = 1 (000), 3x (110), 5L₂(μ₁) (202), 5L₂(μ₂) (022), 3(3μ₁μ₂ − x) (112), 5L₂(x) (220)
//! (tests/data/bispectrum/DEFINITIONS.md (e); FolpsD's normalisation, `renormalize=True`, except its
//! B112, whose azimuthal coefficient is 2√3 instead of the tripolar 3).
//!
//! Quadrature: x through k₃ ∈ [|k₁ − k₂|, k₁ + k₂] (dx = k₃dk₃/(k₁k₂)) on Gauss–Legendre panels
//! clustered quadratically at the lower end (for k₁ = k₂, k₃ → 0 where P(k₃) is not analytic); μ₁ ∈
//! [0, 1] Gauss–Legendre and φ ∈ (0, π) midpoints (B and every weight are even in n̂ and in φ), exact
//! for the polynomial part (degree ≤ 10 in n̂) without damping. Every value carries the difference from
//! [`SugiyamaRules::coarse`] as its error. AP, FoG, IR and the parameters as the Scoccimarro multipoles
//! ([`crate::bispectrum`]): the sides, x and μ's are the observed ones.

use super::observed::{accumulate, observed_slots};
use super::resum::IrInputs;
use super::terms::{contract, SLOTS};
use super::{BispectrumParams, Settings};
use crate::error::{Error, Result};
use crate::estimate::Estimate;
use crate::integrate::legendre_nodes;
use crate::ir::WiggleSplit;
use crate::linear::LinearSpectrum;
use crate::precision::Precision;
use std::f64::consts::PI;

/// The multipoles ℓ₁ℓ₂L the plan computes, in this order.
pub const SUGIYAMA_MULTIPOLES: [&str; 6] = ["000", "110", "202", "022", "112", "220"];

/// Quadrature orders of a [`SugiyamaPlan`].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct SugiyamaRules {
    /// Panels in k₃ (quadratically clustered at |k₁ − k₂|).
    pub n_panels: usize,
    /// Gauss–Legendre nodes per k₃ panel.
    pub n_k3: usize,
    /// Gauss–Legendre nodes in μ₁ ∈ [0, 1].
    pub n_mu: usize,
    /// Midpoint nodes in φ ∈ (0, π).
    pub n_phi: usize,
}

impl Default for SugiyamaRules {
    /// 16 × 8 nodes in k₃, 8 × 8 orientations (exact for the polynomial part without damping).
    fn default() -> Self {
        Self {
            n_panels: 16,
            n_k3: 8,
            n_mu: 8,
            n_phi: 8,
        }
    }
}

impl SugiyamaRules {
    /// The rule of the error estimate: half the panels (at least one), two nodes fewer per panel, one
    /// fewer in μ₁ and φ (7 × 7 is still exact for the polynomial part).
    pub fn coarse(&self) -> Self {
        Self {
            n_panels: (self.n_panels / 2).max(1),
            n_k3: self.n_k3.saturating_sub(2).max(1),
            n_mu: self.n_mu.saturating_sub(1).max(1),
            n_phi: self.n_phi.saturating_sub(1).max(1),
        }
    }
}

/// One node in k₃ of a pair: k₃, x = k̂₁·k̂₂, √(1 − x²) and the weight of (1/2)dx.
#[derive(Debug, Clone, Copy)]
struct Leg {
    k3: f64,
    x: f64,
    sin_x: f64,
    weight: f64,
}

/// One orientation node: μ₁, √(1 − μ₁²), cos φ and the weight (summing to 1 over the rule).
#[derive(Debug, Clone, Copy)]
struct Orientation {
    mu1: f64,
    sin1: f64,
    cos_phi: f64,
    weight: f64,
}

/// The nodes of one rule: per pair its k₃ nodes, and the orientations shared by all pairs.
#[derive(Debug, Clone)]
struct Nodes {
    legs: Vec<Vec<Leg>>,
    orientations: Vec<Orientation>,
}

impl Nodes {
    fn new(pairs: &[[f64; 2]], r: SugiyamaRules) -> Self {
        let (xk, wk) = legendre_nodes(r.n_k3);
        let legs = pairs
            .iter()
            .map(|&[k1, k2]| {
                let (lo, hi) = ((k1 - k2).abs(), k1 + k2);
                let edge = |i: usize| lo + (hi - lo) * (i as f64 / r.n_panels as f64).powi(2);
                (0..r.n_panels)
                    .flat_map(|i| {
                        let (a, b) = (edge(i), edge(i + 1));
                        let (mid, half) = (0.5 * (a + b), 0.5 * (b - a));
                        xk.iter().zip(&wk).map(move |(&t, &w)| {
                            let k3 = mid + half * t;
                            let x =
                                ((k3 * k3 - k1 * k1 - k2 * k2) / (2.0 * k1 * k2)).clamp(-1.0, 1.0);
                            Leg {
                                k3,
                                x,
                                sin_x: (1.0 - x * x).max(0.0).sqrt(),
                                weight: 0.5 * half * w * k3 / (k1 * k2),
                            }
                        })
                    })
                    .collect()
            })
            .collect();
        let (xm, wm) = legendre_nodes(r.n_mu);
        let mut orientations = Vec::with_capacity(r.n_mu * r.n_phi);
        for (&t, &w) in xm.iter().zip(&wm) {
            let mu1 = 0.5 * (1.0 + t);
            for m in 0..r.n_phi {
                orientations.push(Orientation {
                    mu1,
                    sin1: (1.0 - mu1 * mu1).max(0.0).sqrt(),
                    cos_phi: (PI * (m as f64 + 0.5) / r.n_phi as f64).cos(),
                    weight: 0.5 * w / r.n_phi as f64,
                });
            }
        }
        Self { legs, orientations }
    }
}

/// The Sugiyama multipoles planned for a set of (k₁, k₂) pairs: the nodes, once;
/// [`terms`](Self::terms) per linear spectrum.
#[derive(Debug, Clone)]
pub struct SugiyamaPlan {
    pairs: Vec<[f64; 2]>,
    rules: SugiyamaRules,
    fine: Nodes,
    coarse: Nodes,
    split: WiggleSplit,
    q_min: f64,
}

impl SugiyamaPlan {
    /// Plans the pairs (k₁, k₂) [h/Mpc].
    ///
    /// # Errors
    /// [`Error::InvalidValue`] naming the row (1-based) of a k that is not finite and > 0;
    /// [`Error::InvalidChoice`] for no pairs or a rule with no node; as [`WiggleSplit::new`].
    pub fn new(pairs: Vec<[f64; 2]>, rules: SugiyamaRules) -> Result<Self> {
        if pairs.is_empty() {
            return Err(Error::InvalidChoice {
                what: "Sugiyama pairs".into(),
                reason: "give at least one pair (k1, k2)".into(),
            });
        }
        if [rules.n_panels, rules.n_k3, rules.n_mu, rules.n_phi].contains(&0) {
            return Err(Error::InvalidChoice {
                what: format!("{rules:?}"),
                reason: "every quadrature rule needs at least one node".into(),
            });
        }
        for (row, pair) in pairs.iter().enumerate() {
            if let Some(&k) = pair.iter().find(|k| !(k.is_finite() && **k > 0.0)) {
                return Err(Error::InvalidValue {
                    origin: "Sugiyama pairs".into(),
                    line: row + 1,
                    name: "k",
                    value: k,
                    reason: "k1 and k2 must be finite and > 0 [h/Mpc]",
                });
            }
        }
        Ok(Self {
            fine: Nodes::new(&pairs, rules),
            coarse: Nodes::new(&pairs, rules.coarse()),
            split: WiggleSplit::new()?,
            q_min: Precision::default().q_min,
            pairs,
            rules,
        })
    }

    /// The pairs (k₁, k₂) [h/Mpc].
    pub fn pairs(&self) -> &[[f64; 2]] {
        &self.pairs
    }

    /// The quadrature rules.
    pub fn rules(&self) -> SugiyamaRules {
        self.rules
    }

    /// The coefficients of every parameter monomial of the six multipoles at every pair for `spectrum`
    /// (at the redshift of the prediction) with `settings` (IR from the project's wiggle split).
    ///
    /// # Errors
    /// As [`Settings::validate`] and the no-wiggle split.
    pub fn terms(&self, spectrum: &LinearSpectrum, settings: &Settings) -> Result<SugiyamaTerms> {
        settings.validate()?;
        let ir = if settings.ir {
            Some(IrInputs::split(spectrum, &self.split, self.q_min)?)
        } else {
            None
        };
        Ok(self.sum_all(spectrum, settings, ir.as_ref()))
    }

    /// As [`terms`](Self::terms) with the IR resummation's inputs given (`settings.ir` must be true).
    ///
    /// # Errors
    /// As [`terms`](Self::terms); [`Error::InvalidChoice`] if `settings.ir` is false.
    pub fn terms_with_ir(
        &self,
        spectrum: &LinearSpectrum,
        settings: &Settings,
        ir: &IrInputs,
    ) -> Result<SugiyamaTerms> {
        settings.validate()?;
        settings.require_ir()?;
        Ok(self.sum_all(spectrum, settings, Some(ir)))
    }

    fn sum_all(
        &self,
        spectrum: &LinearSpectrum,
        settings: &Settings,
        ir: Option<&IrInputs>,
    ) -> SugiyamaTerms {
        let eval = Evaluator {
            spectrum,
            settings,
            ir,
        };
        let sum = |nodes: &Nodes| -> Vec<[[f64; SLOTS]; 6]> {
            self.pairs
                .iter()
                .zip(&nodes.legs)
                .map(|(&pair, legs)| eval.pair(pair, legs, &nodes.orientations))
                .collect()
        };
        SugiyamaTerms {
            fine: sum(&self.fine),
            coarse: sum(&self.coarse),
            pairs: self.pairs.clone(),
        }
    }
}

/// The spectrum, settings and IR inputs of one evaluation.
struct Evaluator<'a> {
    spectrum: &'a LinearSpectrum,
    settings: &'a Settings,
    ir: Option<&'a IrInputs>,
}

impl Evaluator<'_> {
    /// (P, P_nw) at true k (P_nw = P without resummation).
    fn legs(&self, k: f64) -> (f64, f64) {
        let p = self.spectrum.eval(k);
        (p, self.ir.map_or(p, |ir| ir.no_wiggle.eval(k)))
    }

    /// The accumulated slots of the six multipoles of one pair.
    fn pair(
        &self,
        [k1, k2]: [f64; 2],
        legs: &[Leg],
        orientations: &[Orientation],
    ) -> [[f64; SLOTS]; 6] {
        let s = self.settings;
        // without anisotropic AP the true sides are k/q at every orientation: P interpolated per leg
        let fixed =
            (s.q_par == s.q_perp).then(|| [self.legs(k1 / s.q_par), self.legs(k2 / s.q_par)]);
        let mut acc = [[0.0; SLOTS]; 6];
        for leg in legs {
            let d12 = k1 * k2 * leg.x;
            let dots = [d12, -(d12 + k2 * k2), -(k1 * k1 + d12)];
            let cached = fixed.map(|[a, b]| [a, b, self.legs(leg.k3 / s.q_par)]);
            let power = |i: usize, k: f64, mu: f64| {
                let (p, p_nw) = cached.map_or_else(|| self.legs(k), |c| c[i]);
                self.ir.map_or(p, |ir| ir.resum(p, p_nw, k, mu, s.f))
            };
            for o in orientations {
                let mu2 = o.mu1 * leg.x + o.sin1 * leg.sin_x * o.cos_phi;
                let par = [k1 * o.mu1, k2 * mu2, -(k1 * o.mu1 + k2 * mu2)];
                let slots = observed_slots([k1, k2, leg.k3], dots, par, s, power);
                let w = leg.weight * o.weight;
                let l2 = |t: f64| 2.5 * (3.0 * t * t - 1.0);
                let weights = [
                    w,
                    3.0 * leg.x * w,
                    l2(o.mu1) * w,
                    l2(mu2) * w,
                    3.0 * (3.0 * o.mu1 * mu2 - leg.x) * w,
                    l2(leg.x) * w,
                ];
                accumulate(&mut acc, weights, &slots);
            }
        }
        acc
    }
}

/// The monomial coefficients of the six Sugiyama multipoles of one spectrum at every pair (fine and
/// coarse rules): [`multipoles`](Self::multipoles) per parameter step.
#[derive(Debug, Clone)]
pub struct SugiyamaTerms {
    fine: Vec<[[f64; SLOTS]; 6]>,
    coarse: Vec<[[f64; SLOTS]; 6]>,
    pairs: Vec<[f64; 2]>,
}

impl SugiyamaTerms {
    /// The pairs (k₁, k₂) [h/Mpc].
    pub fn pairs(&self) -> &[[f64; 2]] {
        &self.pairs
    }

    /// B000, B110, B202, B022, B112, B220 [(Mpc/h)⁶] ([`SUGIYAMA_MULTIPOLES`]) at every pair, each with
    /// the difference from the coarse rule as its error.
    ///
    /// # Errors
    /// As [`BispectrumParams::validate`].
    pub fn multipoles(&self, params: &BispectrumParams) -> Result<Vec<[Estimate; 6]>> {
        params.validate()?;
        Ok(self
            .fine
            .iter()
            .zip(&self.coarse)
            .map(|(fine, coarse)| {
                [0, 1, 2, 3, 4, 5].map(|m| {
                    let v = contract(&fine[m], params);
                    let c = contract(&coarse[m], params);
                    Estimate::new(v, (v - c).abs())
                })
            })
            .collect())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bispectrum::Fog;

    fn real_space() -> Settings {
        Settings {
            f: 0.0,
            q_par: 1.0,
            q_perp: 1.0,
            fog: Fog::None,
            ir: false,
        }
    }

    #[test]
    fn in_real_space_only_the_l_zero_multipoles_remain() {
        // f = 0: B does not depend on n̂, and the L = 2 weights average to zero over it exactly
        let plan =
            SugiyamaPlan::new(vec![[0.05, 0.05], [0.03, 0.11]], SugiyamaRules::default()).unwrap();
        let spectrum = LinearSpectrum::gm2012_z0();
        let params = BispectrumParams {
            b1: 1.7,
            b2: 0.4,
            bs: -0.2,
            ..BispectrumParams::default()
        };
        let b = plan
            .terms(&spectrum, &real_space())
            .unwrap()
            .multipoles(&params)
            .unwrap();
        for b in &b {
            for m in [2, 3, 4] {
                assert!(
                    b[m].value.abs() <= 1e-12 * b[0].value.abs(),
                    "{m}: {:?}",
                    b[m]
                );
            }
            assert!(b[0].value > 0.0 && b[0].error <= 1e-4 * b[0].value);
        }
    }

    #[test]
    fn bad_pairs_and_rules_are_errors() {
        let rules = SugiyamaRules::default();
        assert!(matches!(
            SugiyamaPlan::new(vec![[0.05, 0.05], [0.03, -0.1]], rules),
            Err(Error::InvalidValue { line: 2, .. })
        ));
        assert!(SugiyamaPlan::new(vec![], rules).is_err());
        let none = SugiyamaRules { n_mu: 0, ..rules };
        assert!(SugiyamaPlan::new(vec![[0.05, 0.05]], none).is_err());
        let plan = SugiyamaPlan::new(vec![[0.05, 0.05]], rules).unwrap();
        let ir = IrInputs::new(LinearSpectrum::gm2012_z0(), 20.0, 5.0).unwrap();
        assert!(plan
            .terms_with_ir(&LinearSpectrum::gm2012_z0(), &real_space(), &ir)
            .is_err());
        assert!(IrInputs::new(LinearSpectrum::gm2012_z0(), f64::NAN, 5.0).is_err());
    }
}
