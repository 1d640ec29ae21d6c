//! The bispectrum block of a data vector (issue 49, items 4 and 5): the tree-level galaxy bispectrum
//! multipoles of a triangle set beside the power spectrum's, from the same linear spectrum, growth
//! rate, Alcock–Paczynski distortion and IR setting, sharing b1, b2, bs with the galaxy model and
//! adding its own counterterm and stochastic parameters ([`BISPECTRUM_NAMES`]); used by the pipeline
//! ([`crate::pipeline`]) and the galaxy fits ([`crate::fit::galaxy`]).
//!
//! The block's terms are computed once per growth rate and distortion: the IR damping makes B depend
//! on f beyond a polynomial, so another `f` needs new terms (the pipeline's
//! `step_at_growth_rate`); a parameter step is then a contraction (microseconds).
//!
//! Its Gaussian covariance in a forecast (the monopole of triangle bins of shells) is the variance of
//! Scoccimarro, Sefusatti & Zaldarriaga (2004).

use super::{
    BispectrumParams, BispectrumPlan, BispectrumTerms, Fog, IrInputs, LegendreSide, PlanRules,
    Settings, TriangleSet, ELLS,
};
use crate::error::{Error, Result};
use crate::linear::LinearSpectrum;
use crate::statistic::{foreign, Block, Kind, Prepared, Shared, Spec, Survey, Terms};
use std::f64::consts::PI;

mod faces;

/// The parameters of the bispectrum block besides the shared b1, b2, bs (velocileptors' convention):
/// the counterterm c1 [(Mpc/h)²] and the stochastic amplitudes of [`BispectrumParams`].
pub const BISPECTRUM_NAMES: [&str; 4] = ["c1", "b_shot", "p_shot", "a_shot"];

/// The bispectrum parameters that enter B linearly (affinely): the objective marginalises them as
/// it does the power spectrum's counterterms.
pub const BISPECTRUM_LINEAR: [&str; 3] = ["b_shot", "p_shot", "a_shot"];

/// The bispectrum's own parameters in a forecast with B0 (c1 [(Mpc/h)²], the stochastic amplitudes in
/// units of 1/n̄; fiducial 0, 1 (Poisson), 0, 0): free by default, p_shot fixed.
pub const BISPECTRUM_FREE: [&str; 3] = ["c1", "b_shot", "a_shot"];

/// The bispectrum's [`Kind`]: [`BISPECTRUM_NAMES`], not given c1 = 0, Poisson b_shot = 1, p_shot =
/// a_shot = 0 (as [`BispectrumParams::default`]); in a fit c1 within ±10³ (Mpc/h)² (start box ±10), the
/// stochastic amplitudes within ±20 (of order one in units of 1/n̄).
pub const KIND: Kind = Kind {
    name: "bispectrum",
    own: &BISPECTRUM_NAMES,
    defaults: &[0.0, 1.0, 0.0, 0.0],
    units: &["(Mpc/h)^2", "1", "1", "1"],
    linear: &BISPECTRUM_LINEAR,
    ranges: &[
        (-1e3, 1e3, -10.0, 10.0, 3.0),
        (-20.0, 20.0, 0.0, 2.0, 0.3),
        (-20.0, 20.0, -1.0, 1.0, 0.3),
        (-20.0, 20.0, -1.0, 1.0, 0.3),
    ],
    forecast_free: &BISPECTRUM_FREE,
    faces: faces::FACES,
};

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

impl Spec for BispectrumBlock {
    fn plan(&self) -> Result<Box<dyn Block>> {
        Ok(Box::new(PlannedBispectrum::new(self.clone())?))
    }
}

/// The indices into [`ELLS`] of the multipoles `ells` of a block.
///
/// # Errors
/// [`Error::InvalidChoice`] for multipoles that are not an increasing subset of 0, 2, 4.
pub(super) fn ell_indices(ells: &[usize]) -> Result<Vec<usize>> {
    let bad = |reason: &str| Error::InvalidChoice {
        what: format!("bispectrum multipoles {ells:?}"),
        reason: reason.into(),
    };
    if ells.is_empty() || ells.windows(2).any(|w| w[0] >= w[1]) {
        return Err(bad("give at least one, in increasing order"));
    }
    ells.iter()
        .map(|l| ELLS.iter().position(|e| e == l))
        .collect::<Option<Vec<usize>>>()
        .ok_or_else(|| bad("valid: 0, 2, 4"))
}

/// Entry `j` of a bispectrum block of the multipoles `ells` (indices into [`ELLS`]) at `triangles`
/// (multipole, then triangle) in words, its multipole named after `prefix` (e.g. "one-loop ").
pub(super) fn entry_words(
    prefix: &str,
    ells: &[usize],
    triangles: &[[f64; 3]],
    j: usize,
) -> String {
    let n = triangles.len().max(1);
    match (ells.get(j / n), triangles.get(j % n)) {
        (Some(&l), Some(t)) => format!(
            "{prefix}B{} of the triangle ({}, {}, {}) h/Mpc",
            ELLS[l], t[0], t[1], t[2]
        ),
        _ => format!("{prefix}bispectrum entry {}", j + 1),
    }
}

/// The block planned: the bispectrum plan and where each multipole sits in [`ELLS`].
#[derive(Debug, Clone)]
struct PlannedBispectrum {
    plan: BispectrumPlan,
    /// Indices into [`ELLS`] of the block's multipoles.
    ells: Vec<usize>,
    fog: Fog,
    n_bar: f64,
    /// One line for a header.
    description: String,
}

impl PlannedBispectrum {
    /// Plans `block`.
    ///
    /// # Errors
    /// [`Error::InvalidChoice`] for multipoles that are not an increasing subset of 0, 2, 4, or a bad
    /// n̄; as [`BispectrumPlan::new`].
    fn new(block: BispectrumBlock) -> Result<Self> {
        let description = format!(
            "bispectrum: B_l for l in {:?} of {} triangles, tree level (Legendre side {:?}, {:?}, \
             FoG {:?}, n_bar {} (h/Mpc)^3), b1, b2, bs shared with the power spectrum",
            block.ells,
            block.triangles.len(),
            block.side,
            block.rules,
            block.fog,
            block.n_bar
        );
        let ells = ell_indices(&block.ells)?;
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
            description,
        })
    }
}

impl Block for PlannedBispectrum {
    fn kind(&self) -> &'static Kind {
        &KIND
    }

    /// Multipoles × triangles.
    fn len(&self) -> usize {
        self.ells.len() * self.plan.triangles().len()
    }

    /// Entry `j` (multipole, then triangle), e.g. "B2 of the triangle (0.015, 0.025, 0.035) h/Mpc".
    fn entry(&self, j: usize) -> String {
        entry_words("", &self.ells, self.plan.triangles().triangles(), j)
    }

    fn describe(&self) -> String {
        self.description.clone()
    }

    /// The IR resummation's inputs of `spectrum` ([`BispectrumPlan::ir_inputs`]; `None` without).
    fn prepare(&self, spectrum: &LinearSpectrum, ir: bool) -> Result<Prepared> {
        let inputs: Option<IrInputs> = if ir {
            Some(self.plan.ir_inputs(spectrum)?)
        } else {
            None
        };
        Ok(std::sync::Arc::new(inputs))
    }

    /// [`BispectrumPlan::terms_with_ir`] with the prepared IR inputs, [`BispectrumPlan::terms`]
    /// without (the same numbers as `terms` with IR: it makes those inputs first).
    fn terms(
        &self,
        spectrum: &LinearSpectrum,
        prepared: &Prepared,
        f: f64,
        (q_par, q_perp): (f64, f64),
    ) -> Result<Box<dyn Terms>> {
        let ir = prepared
            .downcast_ref::<Option<IrInputs>>()
            .ok_or_else(|| foreign(&KIND))?;
        let settings = Settings {
            f,
            q_par,
            q_perp,
            fog: self.fog,
            ir: ir.is_some(),
        };
        let terms = match ir {
            Some(ir) => self.plan.terms_with_ir(spectrum, &settings, ir)?,
            None => self.plan.terms(spectrum, &settings)?,
        };
        Ok(Box::new(BlockTerms {
            terms,
            ells: self.ells.clone(),
            n_bar: self.n_bar,
        }))
    }

    /// The Gaussian variance of the monopole of each triangle bin (Scoccimarro, Sefusatti &
    /// Zaldarriaga 2004; Sefusatti et al. 2006, arXiv:astro-ph/0604505): ΔB² = s₁₂₃ k_f³ Π_i [P(k_i) +
    /// 1/n̄] / V_B, k_f³ = (2π)³/V, V_B the volume of the bin's closed triangles
    /// ([`triangle_bin_volume`]), s₁₂₃ = 6, 2, 1 for equilateral, isosceles and other bins; P the
    /// monopole (the redshift-space variance to leading order in the multipoles).
    fn gaussian_variances(&self, survey: &Survey) -> Result<Vec<f64>> {
        if self.ells != [0] {
            return Err(Error::InvalidChoice {
                what: "the Gaussian covariance of bispectrum multipoles other than B0".into(),
                reason: "only the monopole's variance is implemented".into(),
            });
        }
        let k_f3 = (2.0 * PI).powi(3) / survey.volume;
        let power = survey.power;
        Ok(self
            .plan
            .triangles()
            .triangles()
            .iter()
            .map(|t| {
                let equal = |a: f64, b: f64| (a - b).abs() < 1e-9 * a;
                let s = match (equal(t[0], t[1]), equal(t[1], t[2]), equal(t[0], t[2])) {
                    (true, true, _) => 6.0,
                    (false, false, false) => 1.0,
                    _ => 2.0,
                };
                s * k_f3 * power(t[0]) * power(t[1]) * power(t[2])
                    / triangle_bin_volume(*t, survey.dk)
            })
            .collect())
    }
}

/// The volume of the closed triangles of a bin of shells of width `dk` centred on `k`,
/// ∫d³q₁d³q₂ over q₁, q₂, |q₁ + q₂| in the shells ≈ 8π² k₁k₂k₃ Δk³ (thin shells).
pub fn triangle_bin_volume(k: [f64; 3], dk: f64) -> f64 {
    8.0 * PI * PI * k[0] * k[1] * k[2] * dk.powi(3)
}

/// The block's terms at one (spectrum, f, distortion).
struct BlockTerms {
    terms: BispectrumTerms,
    ells: Vec<usize>,
    n_bar: f64,
}

impl Terms for BlockTerms {
    /// The entries (multipole, then triangle) at b1, b2, bs and [`BISPECTRUM_NAMES`] (n̄ the block's).
    fn values(&self, shared: Shared, own: &[f64]) -> Result<Vec<f64>> {
        let &[c1, b_shot, p_shot, a_shot] = own else {
            return Err(Error::InvalidChoice {
                what: format!("{} own bispectrum parameters", own.len()),
                reason: format!("they are {}", BISPECTRUM_NAMES.join(", ")),
            });
        };
        let b = BispectrumParams {
            b1: shared.b1,
            b2: shared.b2,
            bs: shared.bs,
            c1,
            b_shot,
            p_shot,
            a_shot,
            n_bar: self.n_bar,
        };
        let m = self.terms.multipoles(&b)?;
        Ok(self
            .ells
            .iter()
            .flat_map(|&l| m.iter().map(move |row| row[l].value))
            .collect())
    }
}
