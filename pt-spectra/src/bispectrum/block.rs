//! The bispectrum block of a data vector (issue 49, items 4 and 5): the tree-level galaxy bispectrum
//! multipoles of a triangle set beside the power spectrum's, from the same linear spectrum, growth
//! rate, Alcock–Paczynski distortion and IR setting, sharing b1, b2, bs with the galaxy model and
//! adding its own counterterm and stochastic parameters ([`BISPECTRUM_NAMES`]); used by the pipeline
//! ([`crate::pipeline`]) and the galaxy fits ([`crate::fit::galaxy`]).
//!
//! The block's terms are computed once per growth rate and distortion: the IR damping makes B depend
//! on f beyond a polynomial, so another `f` needs new terms (the pipeline's
//! `step_at_growth_rate`); a parameter step is then a contraction (microseconds).

use super::{
    BispectrumParams, BispectrumPlan, BispectrumTerms, Fog, LegendreSide, PlanRules, Settings,
    TriangleSet, ELLS,
};
use crate::error::{Error, Result};
use crate::linear::LinearSpectrum;

/// The parameters of the bispectrum block besides the shared b1, b2, bs (velocileptors' convention):
/// the counterterm c1 [(Mpc/h)²] and the stochastic amplitudes of [`BispectrumParams`].
pub const BISPECTRUM_NAMES: [&str; 4] = ["c1", "b_shot", "p_shot", "a_shot"];

/// What the bispectrum block is built from.
#[derive(Debug, Clone)]
pub struct BispectrumBlock {
    /// The triangles (bins of shells, or points) in the order of the data vector.
    pub triangles: TriangleSet,
    /// The side that carries the Legendre polynomial.
    pub side: LegendreSide,
    /// The quadrature rules.
    pub rules: PlanRules,
    /// The multipoles in the data vector: a subset of 0, 2, 4, increasing.
    pub ells: Vec<usize>,
    /// Fingers of God.
    pub fog: Fog,
    /// The mean density n̄ [(h/Mpc)³] of the stochastic terms (infinite: none).
    pub n_bar: f64,
}

impl BispectrumBlock {
    /// B₀ of `triangles` with the Legendre polynomial on the largest side, default rules, no FoG and
    /// no stochastic terms.
    pub fn monopole(triangles: TriangleSet) -> Self {
        Self {
            triangles,
            side: LegendreSide::Largest,
            rules: PlanRules::default(),
            ells: vec![0],
            fog: Fog::None,
            n_bar: f64::INFINITY,
        }
    }
}

/// The block planned: the bispectrum plan and where each multipole sits in [`ELLS`].
#[derive(Debug, Clone)]
pub(crate) struct PlannedBispectrum {
    plan: BispectrumPlan,
    /// Indices into [`ELLS`] of the block's multipoles.
    ells: Vec<usize>,
    fog: Fog,
    n_bar: f64,
}

impl PlannedBispectrum {
    /// Plans `block`.
    ///
    /// # Errors
    /// [`Error::InvalidChoice`] for multipoles that are not an increasing subset of 0, 2, 4, or a bad
    /// n̄; as [`BispectrumPlan::new`].
    pub(crate) fn new(block: BispectrumBlock) -> Result<Self> {
        let bad = |reason: &str| Error::InvalidChoice {
            what: format!("bispectrum multipoles {:?}", block.ells),
            reason: reason.into(),
        };
        if block.ells.is_empty() || block.ells.windows(2).any(|w| w[0] >= w[1]) {
            return Err(bad("give at least one, in increasing order"));
        }
        let ells = block
            .ells
            .iter()
            .map(|l| ELLS.iter().position(|e| e == l))
            .collect::<Option<Vec<usize>>>()
            .ok_or_else(|| bad("valid: 0, 2, 4"))?;
        if block.n_bar.is_nan() || block.n_bar <= 0.0 {
            return Err(Error::InvalidChoice {
                what: format!("n_bar = {}", block.n_bar),
                reason: "the mean density must be > 0 [(h/Mpc)^3] (infinite: no stochastic terms)"
                    .into(),
            });
        }
        Ok(Self {
            plan: BispectrumPlan::new(block.triangles, block.side, block.rules)?,
            ells,
            fog: block.fog,
            n_bar: block.n_bar,
        })
    }

    /// The number of entries: multipoles × triangles.
    pub(crate) fn len(&self) -> usize {
        self.ells.len() * self.plan.triangles().len()
    }

    /// Entry `j` (multipole, then triangle) in words, e.g. "B2 of the triangle (0.015, 0.025, 0.035)
    /// h/Mpc" (for messages).
    pub(crate) fn entry(&self, j: usize) -> String {
        let triangles = self.plan.triangles().triangles();
        let n = triangles.len().max(1);
        match (self.ells.get(j / n), triangles.get(j % n)) {
            (Some(&l), Some(t)) => format!(
                "B{} of the triangle ({}, {}, {}) h/Mpc",
                ELLS[l], t[0], t[1], t[2]
            ),
            _ => format!("bispectrum entry {}", j + 1),
        }
    }

    /// The terms of `spectrum` at growth rate `f` with the distortion `ap` = (α∥, α⊥) (none: 1).
    ///
    /// # Errors
    /// As [`BispectrumPlan::terms`].
    pub(crate) fn terms(
        &self,
        spectrum: &LinearSpectrum,
        f: f64,
        ap: Option<(f64, f64)>,
        ir: bool,
    ) -> Result<BispectrumTerms> {
        let (q_par, q_perp) = ap.unwrap_or((1.0, 1.0));
        self.plan.terms(
            spectrum,
            &Settings {
                f,
                q_par,
                q_perp,
                fog: self.fog,
                ir,
            },
        )
    }

    /// The IR resummation's inputs of `spectrum` ([`BispectrumPlan::ir_inputs`]).
    ///
    /// # Errors
    /// As [`BispectrumPlan::ir_inputs`].
    pub(crate) fn ir_inputs(&self, spectrum: &LinearSpectrum) -> Result<super::IrInputs> {
        self.plan.ir_inputs(spectrum)
    }

    /// [`Self::terms`] with the IR inputs given (`None`: no resummation).
    ///
    /// # Errors
    /// As [`BispectrumPlan::terms_with_ir`].
    pub(crate) fn terms_resummed(
        &self,
        spectrum: &LinearSpectrum,
        f: f64,
        (q_par, q_perp): (f64, f64),
        ir: Option<&super::IrInputs>,
    ) -> Result<BispectrumTerms> {
        let settings = Settings {
            f,
            q_par,
            q_perp,
            fog: self.fog,
            ir: ir.is_some(),
        };
        match ir {
            Some(ir) => self.plan.terms_with_ir(spectrum, &settings, ir),
            None => self.plan.terms(spectrum, &settings),
        }
    }

    /// The block's entries (multipole, then triangle) at the parameters `b` (its n̄ set here).
    ///
    /// # Errors
    /// As [`BispectrumTerms::multipoles`].
    pub(crate) fn values(&self, terms: &BispectrumTerms, b: BispectrumParams) -> Result<Vec<f64>> {
        let b = BispectrumParams {
            n_bar: self.n_bar,
            ..b
        };
        let m = terms.multipoles(&b)?;
        Ok(self
            .ells
            .iter()
            .flat_map(|&l| m.iter().map(move |row| row[l].value))
            .collect())
    }
}

/// The bispectrum's parameters of `params`: b1, b2, bs (shared; 0 when not given, as the galaxy
/// model's) and [`BISPECTRUM_NAMES`] (not given: c1 = 0, Poisson b_shot = 1, p_shot = a_shot = 0, as
/// [`BispectrumParams::default`]); other names are the galaxy model's and are skipped here.
pub(crate) fn bispectrum_params(params: &[(&str, f64)]) -> BispectrumParams {
    let mut b = BispectrumParams {
        b1: 0.0,
        ..BispectrumParams::default()
    };
    for &(name, v) in params {
        match name {
            "b1" => b.b1 = v,
            "b2" => b.b2 = v,
            "bs" => b.bs = v,
            "c1" => b.c1 = v,
            "b_shot" => b.b_shot = v,
            "p_shot" => b.p_shot = v,
            "a_shot" => b.a_shot = v,
            _ => {}
        }
    }
    b
}
