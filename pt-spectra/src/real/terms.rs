//! The loop terms each real-space model is made of, one type per model family ([`ModelTerms`]),
//! taken from what a plan computed ([`LoopTerms`], which holds the terms of every model the plan
//! covers) in the one place that names a missing term ([`ModelTerms::of`]).

use super::RealModel;
use crate::error::{Error, Result};
use crate::loops::{Estimate, IrTerms, LoopTerms, OneLoopTerms, TwoLoopCorrection};
use crate::resum::{Propagator, PropagatorTerms, RegPtTwoLoop};

/// The terms of one model, by family.
#[derive(Debug, Clone, Copy)]
pub enum ModelTerms<'a> {
    /// `linear`, `1l-spt`, `2l-spt`, `2l-eft`: P_lin (+ the 1-loop terms unless `linear`) + the 2-loop
    /// correction if any.
    Spt {
        /// P_lin, P22, P13.
        one_loop: &'a OneLoopTerms,
        /// Linear theory: P_lin alone.
        linear: bool,
        /// The 2-loop correction of the 2-loop models.
        two_loop: Option<&'a TwoLoopCorrection>,
    },
    /// The RPT models: [P_lin + P22 (+ P33^{2L})] N_X N_Y.
    Rpt {
        /// P_lin, P22, P13, σ_v².
        one_loop: &'a OneLoopTerms,
        /// The propagator and the terms it is made of.
        propagator: PropagatorTerms<'a>,
        /// The 2-loop correction of the 2-loop models.
        two_loop: Option<&'a TwoLoopCorrection>,
    },
    /// `1l-regpt`.
    RegPtOneLoop {
        /// P_lin, P22, P13.
        one_loop: &'a OneLoopTerms,
        /// σ_d²(k).
        sigma_d2: &'a [Estimate],
    },
    /// `2l-regpt`.
    RegPtTwoLoop(RegPtTwoLoop<'a>),
    /// The IR-resummed models `1l-spt-ir`, `2l-spt-ir`, `2l-eft-ir`.
    Ir {
        /// P_lin, P22, P13.
        one_loop: &'a OneLoopTerms,
        /// Σ² and the no-wiggle spectrum's terms.
        ir: &'a IrTerms,
        /// The 2-loop corrections of the spectrum and of its no-wiggle part (2-loop models).
        two_loop: Option<(&'a TwoLoopCorrection, &'a TwoLoopCorrection)>,
    },
}

impl<'a> ModelTerms<'a> {
    /// The terms `model` is made of, from `terms`.
    ///
    /// # Errors
    /// [`Error::MissingTerm`] naming the term and the model if `terms` lack one the model needs.
    pub fn of(model: RealModel, terms: &'a LoopTerms) -> Result<Self> {
        let needed_by = format!("model {model}");
        let needed_by = &needed_by as &dyn std::fmt::Display;
        let one_loop = &terms.one_loop;
        let two_loop = if model.needs_two_loop() {
            Some(terms.two_loop(needed_by)?)
        } else {
            None
        };
        Ok(match model.propagator() {
            Some(kind) => Self::Rpt {
                one_loop,
                propagator: match kind {
                    Propagator::N0 => PropagatorTerms::N0,
                    Propagator::N1 => PropagatorTerms::N1,
                    Propagator::N2 => PropagatorTerms::N2 {
                        p15: terms.p15(needed_by)?,
                    },
                    Propagator::N3 => PropagatorTerms::N3 {
                        p15: terms.p15(needed_by)?,
                        p17: terms.p17(needed_by)?,
                    },
                },
                two_loop,
            },
            None if model.needs_ir() => {
                let ir = terms.ir.as_deref().ok_or_else(|| Error::MissingTerm {
                    term: "the no-wiggle loop terms",
                    needed_by: needed_by.to_string(),
                    hint: " (compute the terms with a RealPlan)",
                })?;
                let two_loop = match two_loop {
                    Some(two) => Some((two, ir.no_wiggle.two_loop(needed_by)?)),
                    None => None,
                };
                Self::Ir {
                    one_loop,
                    ir,
                    two_loop,
                }
            }
            None if model == RealModel::OneLoopRegPt => Self::RegPtOneLoop {
                one_loop,
                sigma_d2: terms.sigma_d2(needed_by)?,
            },
            None if model == RealModel::TwoLoopRegPt => Self::RegPtTwoLoop(RegPtTwoLoop {
                one_loop,
                sigma_d2: terms.sigma_d2(needed_by)?,
                p15: terms.p15(needed_by)?,
                two_loop: terms.two_loop(needed_by)?,
                gamma2: terms.gamma2(needed_by)?,
            }),
            None => Self::Spt {
                one_loop,
                linear: model == RealModel::Linear,
                two_loop,
            },
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::linear::LinearSpectrum;
    use crate::precision::Precision;
    use crate::progress::Silent;
    use crate::real::RealPlan;
    use crate::store::TableStore;

    /// The terms of a 1-loop SPT plan make every model that needs nothing else (with its family's
    /// type) and refuse each other model, naming the term it lacks and the model.
    #[test]
    fn a_model_takes_its_family_s_terms_and_names_what_is_missing() {
        let (p, store) = (
            LinearSpectrum::gm2012(0.0).unwrap(),
            TableStore::in_memory(),
        );
        let plan = RealPlan::new(
            &[0.05, 0.1],
            RealModel::OneLoopSpt,
            &Precision::fast(),
            &store,
            &Silent,
        )
        .unwrap();
        let terms = plan.terms(&p, &Silent).unwrap();
        for model in RealModel::ALL {
            let missing = match model {
                RealModel::Linear
                | RealModel::OneLoopSpt
                | RealModel::OneLoopRptN0
                | RealModel::OneLoopRptN1
                | RealModel::OneLoopRegPt => None,
                RealModel::OneLoopRptN2 | RealModel::OneLoopRptN3 => Some("P15"),
                RealModel::OneLoopSptIr => Some("no-wiggle"),
                _ => Some("2-loop"),
            };
            match (ModelTerms::of(model, &terms), missing) {
                (Ok(view), None) => {
                    let family_fits = match view {
                        ModelTerms::Spt { linear, .. } => {
                            matches!(model, RealModel::Linear | RealModel::OneLoopSpt)
                                && linear == (model == RealModel::Linear)
                        }
                        ModelTerms::Rpt { propagator, .. } => matches!(
                            (model, propagator),
                            (RealModel::OneLoopRptN0, PropagatorTerms::N0)
                                | (RealModel::OneLoopRptN1, PropagatorTerms::N1)
                        ),
                        ModelTerms::RegPtOneLoop { .. } => model == RealModel::OneLoopRegPt,
                        _ => false,
                    };
                    assert!(family_fits, "{model}: {view:?}");
                }
                (Err(e), Some(term)) => {
                    let e = e.to_string();
                    assert!(
                        e.contains(term) && e.contains(&format!("model {model}")),
                        "{e}"
                    );
                }
                (result, _) => panic!("{model}: {result:?}"),
            }
        }
    }
}
