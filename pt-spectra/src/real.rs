//! Real-space models of the matter spectra P_δδ, P_δθ and P_θθ (Gil-Marín et al. 2012,
//! arXiv:1209.3771, section 2.1).
//!
//! | name        | P_XY                                                  |
//! |-------------|-------------------------------------------------------|
//! | `linear`    | P_lin                                                 |
//! | `1l-spt`    | P_lin + P22_XY + 2 P13_XY (1-loop SPT)                |
//! | `1l-rpt-n0` | [P_lin + P22_XY] N0², N0 = exp(−k²σ_v²/2)             |
//! | `1l-rpt-n1` | [P_lin + P22_XY] N_X N_Y, N_δ,θ = exp(P13_δδ,θθ/P_lin) |
//! | `1l-rpt-n2` | [P_lin + P22_XY] N_X N_Y, N from P13 and P15 (eq. theory_N2) |
//! | `2l-spt`    | P_lin + P22 + 2P13 + (2P15 + 2P24 + P33) (2-loop SPT)  |
//! | `2l-rpt-n0`, `2l-rpt-n1`, `2l-rpt-n2` | [P_lin + P22_XY + P33^{2L}_XY] N_X N_Y |
//! | `1l-rpt-n3`, `2l-rpt-n3` | as the N2 models, with N3 from P13, P15 and P17 (eq. N3) |
//!
//! Every value carries an error estimate propagated from the loop integrals ([`crate::loops`]).

use crate::error::{Error, Result};
use crate::linear::LinearSpectrum;
use crate::loops::{Estimate, OneLoopPlan, OneLoopTerms, Pair};
use crate::precision::Precision;
use crate::resum::{self, Propagator};
use std::fmt;
use std::str::FromStr;
use std::sync::{Arc, Mutex};

/// A real-space model, named as on the command line.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[non_exhaustive]
pub enum RealModel {
    /// Linear theory.
    Linear,
    /// 1-loop standard perturbation theory.
    OneLoopSpt,
    /// 1-loop RPT with the propagator N0.
    OneLoopRptN0,
    /// 1-loop RPT with the propagator N1.
    OneLoopRptN1,
    /// 1-loop RPT with the 2-loop propagator N2.
    OneLoopRptN2,
    /// 2-loop standard perturbation theory.
    TwoLoopSpt,
    /// 2-loop RPT with N0.
    TwoLoopRptN0,
    /// 2-loop RPT with N1.
    TwoLoopRptN1,
    /// 2-loop RPT with N2 (the paper's best model).
    TwoLoopRptN2,
    /// 1-loop RPT with the 3-loop propagator N3.
    OneLoopRptN3,
    /// 2-loop RPT with N3.
    TwoLoopRptN3,
}

/// The accepted model names, for messages.
const MODEL_NAMES: &str = "linear, 1l-spt, 1l-rpt-n0, 1l-rpt-n1, 1l-rpt-n2, 1l-rpt-n3, 2l-spt, \
                           2l-rpt-n0, 2l-rpt-n1, 2l-rpt-n2, 2l-rpt-n3";

impl RealModel {
    /// Every model.
    pub const ALL: [RealModel; 11] = [
        RealModel::Linear,
        RealModel::OneLoopSpt,
        RealModel::OneLoopRptN0,
        RealModel::OneLoopRptN1,
        RealModel::OneLoopRptN2,
        RealModel::TwoLoopSpt,
        RealModel::TwoLoopRptN0,
        RealModel::TwoLoopRptN1,
        RealModel::TwoLoopRptN2,
        RealModel::OneLoopRptN3,
        RealModel::TwoLoopRptN3,
    ];

    /// The model's name (`linear`, `1l-spt`, `1l-rpt-n0`, `1l-rpt-n1`).
    pub fn name(self) -> &'static str {
        match self {
            RealModel::Linear => "linear",
            RealModel::OneLoopSpt => "1l-spt",
            RealModel::OneLoopRptN0 => "1l-rpt-n0",
            RealModel::OneLoopRptN1 => "1l-rpt-n1",
            RealModel::OneLoopRptN2 => "1l-rpt-n2",
            RealModel::TwoLoopSpt => "2l-spt",
            RealModel::TwoLoopRptN0 => "2l-rpt-n0",
            RealModel::TwoLoopRptN1 => "2l-rpt-n1",
            RealModel::TwoLoopRptN2 => "2l-rpt-n2",
            RealModel::OneLoopRptN3 => "1l-rpt-n3",
            RealModel::TwoLoopRptN3 => "2l-rpt-n3",
        }
    }

    /// The RPT propagator of the model, if it has one.
    pub fn propagator(self) -> Option<Propagator> {
        match self {
            RealModel::OneLoopRptN0 => Some(Propagator::N0),
            RealModel::OneLoopRptN1 => Some(Propagator::N1),
            RealModel::OneLoopRptN2 | RealModel::TwoLoopRptN2 => Some(Propagator::N2),
            RealModel::TwoLoopRptN0 => Some(Propagator::N0),
            RealModel::TwoLoopRptN1 => Some(Propagator::N1),
            RealModel::OneLoopRptN3 | RealModel::TwoLoopRptN3 => Some(Propagator::N3),
            RealModel::Linear | RealModel::OneLoopSpt | RealModel::TwoLoopSpt => None,
        }
    }

    /// Whether the model needs the 2-loop propagator term P15 ([`crate::loops::add_p15`]).
    pub fn needs_p15(self) -> bool {
        matches!(self.propagator(), Some(Propagator::N2 | Propagator::N3)) || self.needs_two_loop()
    }

    /// Whether the model needs the 3-loop propagator term P17 ([`crate::loops::add_p17`]).
    pub fn needs_p17(self) -> bool {
        self.propagator() == Some(Propagator::N3)
    }

    /// Whether the model needs the 2-loop terms ([`crate::loops::add_two_loop`]).
    pub fn needs_two_loop(self) -> bool {
        matches!(
            self,
            RealModel::TwoLoopSpt
                | RealModel::TwoLoopRptN0
                | RealModel::TwoLoopRptN1
                | RealModel::TwoLoopRptN2
                | RealModel::TwoLoopRptN3
        )
    }
}

impl fmt::Display for RealModel {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

impl FromStr for RealModel {
    type Err = Error;

    /// Parses a model name, ignoring ASCII case.
    ///
    /// # Errors
    /// [`Error::UnknownModel`] naming the accepted models.
    fn from_str(s: &str) -> Result<Self> {
        RealModel::ALL
            .into_iter()
            .find(|m| m.name().eq_ignore_ascii_case(s.trim()))
            .ok_or_else(|| Error::UnknownModel {
                name: s.to_string(),
                available: MODEL_NAMES,
            })
    }
}

/// Real-space spectra of one model on a k grid, in (Mpc/h)^3.
#[derive(Debug, Clone, PartialEq)]
pub struct RealSpectra {
    /// The model.
    pub model: RealModel,
    /// Wavenumbers [h/Mpc].
    pub k: Vec<f64>,
    /// The linear spectrum.
    pub p_lin: Vec<f64>,
    /// P_δδ, P_δθ, P_θθ at each k, in that order.
    pub spectra: [Vec<Estimate>; 3],
    /// For RPT models, the factors N_X N_Y multiplying [P_lin + P22] for δδ, δθ, θθ.
    pub factors: Option<[Vec<Estimate>; 3]>,
}

impl RealSpectra {
    /// The spectrum of `pair`.
    pub fn pair(&self, pair: Pair) -> &[Estimate] {
        &self.spectra[pair_index(pair)]
    }
}

fn pair_index(pair: Pair) -> usize {
    match pair {
        Pair::DeltaDelta => 0,
        Pair::DeltaTheta => 1,
        Pair::ThetaTheta => 2,
    }
}

/// The spectra of `model` from precomputed loop `terms`.
///
/// # Errors
/// [`Error::InvalidParameter`] if the model needs P15 and `terms` have none.
pub fn from_terms(model: RealModel, terms: &OneLoopTerms) -> Result<RealSpectra> {
    if model.needs_p15() && terms.dd.p15.len() != terms.k.len() {
        return Err(Error::InvalidParameter {
            name: "number of P15 values",
            value: terms.dd.p15.len() as f64,
            reason: "the model needs P15 at every k (loops::add_p15)",
        });
    }
    if model.needs_p17() && terms.dd.p17.len() != terms.k.len() {
        return Err(Error::InvalidParameter {
            name: "number of P17 values",
            value: terms.dd.p17.len() as f64,
            reason: "the model needs P17 at every k (loops::add_p17)",
        });
    }
    if model.needs_two_loop() && terms.dd.two_loop.len() != terms.k.len() {
        return Err(Error::InvalidParameter {
            name: "number of 2-loop values",
            value: terms.dd.two_loop.len() as f64,
            reason: "the model needs the 2-loop terms at every k (loops::add_two_loop)",
        });
    }
    let n = terms.k.len();
    let mut spectra: [Vec<Estimate>; 3] = Default::default();
    let mut factors = None;
    match model.propagator() {
        None => {
            for (j, pair) in Pair::ALL.into_iter().enumerate() {
                let t = terms.pair(pair);
                spectra[j] = (0..n)
                    .map(|i| {
                        let lin = terms.p_lin[i];
                        match model {
                            RealModel::Linear => Estimate::new(lin, 0.0),
                            RealModel::TwoLoopSpt => {
                                let (l, m) = (t.one_loop(i), t.two_loop[i]);
                                Estimate::new(lin + l.value + m.value, l.error + m.error)
                            }
                            _ => {
                                let l = t.one_loop(i);
                                Estimate::new(lin + l.value, l.error)
                            }
                        }
                    })
                    .collect();
            }
        }
        Some(kind) => {
            let props = resum::propagators(kind, terms);
            let mut f: [Vec<Estimate>; 3] = Default::default();
            for i in 0..n {
                for (j, fi) in resum::factors(&props, i).into_iter().enumerate() {
                    f[j].push(fi);
                }
            }
            for (j, pair) in Pair::ALL.into_iter().enumerate() {
                spectra[j] = (0..n)
                    .map(|i| resum::rpt(terms, &props, pair, i, model.needs_two_loop()))
                    .collect();
            }
            factors = Some(f);
        }
    }
    Ok(RealSpectra {
        model,
        k: terms.k.clone(),
        p_lin: terms.p_lin.clone(),
        spectra,
        factors,
    })
}

/// The 1-loop plan for `k` and `precision`: the one of the previous call if they are the same.
fn plan_for(k: &[f64], precision: &Precision) -> Result<Arc<OneLoopPlan>> {
    static LAST: Mutex<Option<Arc<OneLoopPlan>>> = Mutex::new(None);
    let same = |plan: &OneLoopPlan| plan.k() == k && plan.precision() == precision;
    if let Some(plan) = LAST.lock().ok().and_then(|last| last.clone()) {
        if same(&plan) {
            return Ok(plan);
        }
    }
    let plan = Arc::new(OneLoopPlan::new(k, precision)?);
    if let Ok(mut last) = LAST.lock() {
        *last = Some(Arc::clone(&plan));
    }
    Ok(plan)
}

/// The spectra of `model` for `spectrum` at wavenumbers `k` [h/Mpc], with the loop terms they were
/// built from (computed in parallel over k; also for `linear`, so that they can be reported). Models
/// with N2 also compute P15 (building the angular table on first use, see [`crate::loops::P15Table`]).
///
/// The 1-loop plan (the cosmology-independent quadrature weights, [`OneLoopPlan`]) of the previous call
/// is kept and reused when `k` and `precision` are the same, so a loop over spectra on one grid (a fit,
/// an MCMC chain) builds it once.
///
/// # Errors
/// As [`OneLoopPlan::new`].
///
/// ```
/// use pt_spectra::{linear::LinearSpectrum, precision::Precision, real::{real_space, RealModel}};
/// let p = LinearSpectrum::gm2012(0.0)?;
/// let (spt, _) = real_space("1l-spt".parse()?, &p, &[0.1], &Precision::fast())?;
/// let (n1, _) = real_space(RealModel::OneLoopRptN1, &p, &[0.1], &Precision::fast())?;
/// // At k = 0.1 h/Mpc, z = 0 the two agree to a few per cent and exceed P_lin.
/// let (a, b) = (spt.spectra[0][0].value, n1.spectra[0][0].value);
/// assert!(a > spt.p_lin[0] && (a / b - 1.0).abs() < 0.05);
/// # Ok::<(), pt_spectra::error::Error>(())
/// ```
pub fn real_space(
    model: RealModel,
    spectrum: &LinearSpectrum,
    k: &[f64],
    precision: &Precision,
) -> Result<(RealSpectra, OneLoopTerms)> {
    let mut terms = plan_for(k, precision)?.par_evaluate(spectrum);
    if model.needs_two_loop() {
        crate::loops::add_two_loop(&mut terms, spectrum, precision, &|_, _| {}, &|_, _| {});
    } else if model.needs_p15() {
        crate::loops::add_p15(&mut terms, spectrum, precision, &|_, _| {});
    }
    if model.needs_p17() {
        crate::loops::add_p17(&mut terms, spectrum, precision, &|_, _| {});
    }
    Ok((from_terms(model, &terms)?, terms))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn model_names_round_trip_and_unknown_names_are_listed() {
        for m in RealModel::ALL {
            assert_eq!(m.name().parse::<RealModel>().unwrap(), m);
        }
        assert_eq!(
            "1L-SPT".parse::<RealModel>().unwrap(),
            RealModel::OneLoopSpt
        );
        let e = "3l-spt".parse::<RealModel>().unwrap_err().to_string();
        assert!(e.contains("3l-spt") && e.contains("1l-rpt-n2"), "{e}");
    }

    #[test]
    fn the_reused_plan_is_the_plan_of_the_grid_and_precision_asked_for() {
        let p = LinearSpectrum::gm2012(0.0).unwrap();
        let fresh =
            |k: &[f64], precision: &Precision| OneLoopPlan::new(k, precision).unwrap().evaluate(&p);
        let (a, b) = ([0.05, 0.1], [0.05, 0.2]);
        for (k, precision) in [
            (&a[..], Precision::fast()),
            (&a[..], Precision::fast()),
            (&b[..], Precision::fast()),
            (&b[..], Precision::default()),
            (&a[..], Precision::default()),
        ] {
            let (_, terms) = real_space(RealModel::OneLoopSpt, &p, k, &precision).unwrap();
            assert_eq!(terms, fresh(k, &precision), "{k:?}");
        }
    }

    #[test]
    fn rpt_n1_expands_to_spt_and_linear_is_p_lin() {
        let p = LinearSpectrum::gm2012(1.0).unwrap();
        let k = [0.02, 0.05];
        let (lin, terms) = real_space(RealModel::Linear, &p, &k, &Precision::fast()).unwrap();
        let spt = from_terms(RealModel::OneLoopSpt, &terms).unwrap();
        let n1 = from_terms(RealModel::OneLoopRptN1, &terms).unwrap();
        assert!(from_terms(RealModel::OneLoopRptN2, &terms).is_err());
        for (i, &ki) in k.iter().enumerate() {
            assert_eq!(lin.spectra[0][i].value, terms.p_lin[i]);
            for j in 0..3 {
                // N1² = 1 + 2x + 2x² + O(x³), x = P13/P: the models differ by 2P13(P13 + P22)/P
                // at second order, with third-order terms of size ~ 2x²(|P13| + |P22|).
                let (a, b) = (spt.spectra[j][i].value, n1.spectra[j][i].value);
                let t = terms.pair(Pair::ALL[j]);
                let (p22, p13, lin) = (t.p22[i].value, t.p13[i].value, terms.p_lin[i]);
                let second = 2.0 * p13 * (p13 + p22) / lin;
                let third = 2.0 * (p13 / lin).powi(2) * (p13.abs() + p22.abs());
                assert!(
                    (b - a - second).abs() < third,
                    "k={ki} j={j}: {a} {b} {second}"
                );
            }
        }
    }
}
