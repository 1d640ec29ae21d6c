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
//! | `1l-regpt`, `2l-regpt` | RegPT (Taruya et al. 2012), [`crate::resum::regpt_one_loop`], `crate::resum::regpt_two_loop` |
//! | `1l-spt-ir`, `2l-spt-ir` | SPT with IR-resummed BAO ([`crate::ir`]) |
//! | `2l-eft`, `2l-eft-ir` | 2-loop SPT (IR-resummed) + the EFT counterterms cs2, cs2_1loop, c4 ([`eft`]) |
//!
//! Every value carries an error estimate propagated from the loop integrals ([`crate::loops`]).
//! Any model takes the EFT counterterm −(2, 4, 6) c_s² k² P_lin of δδ, δθ, θθ
//! ([`RealSpectra::with_counterterm`], module [`counterterm`](mod@counterterm): the pair factors
//! and their assumptions).

use crate::error::{Error, Result};
use crate::loops::{ByPair, Estimate, LoopTerms, Pair};
use crate::resum::{self, Propagator};
use std::fmt;
use std::str::FromStr;

pub mod counterterm;
pub mod eft;
mod plan;
mod terms;
pub use counterterm::{check_cs2, counterterm, counterterm_factor};
pub use eft::{fit_counterterms, Counterterm, Counterterms};
pub use plan::{real_space, RealPlan};
pub use terms::ModelTerms;

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
    /// 1-loop RegPT (Taruya, Bernardeau, Nishimichi & Codis 2012): regularised propagators with
    /// σ_d² at the running cut-off k/2 ([`crate::resum::regpt_one_loop`]).
    OneLoopRegPt,
    /// 2-loop RegPT: regularised propagators to two loops, P24 and PΓ2 from the 1-loop vertex Γ2
    /// (`crate::resum::regpt_two_loop`).
    TwoLoopRegPt,
    /// 1-loop SPT with the BAO wiggles IR-resummed ([`crate::ir`]).
    OneLoopSptIr,
    /// 2-loop SPT with the BAO wiggles IR-resummed ([`crate::ir`]).
    TwoLoopSptIr,
    /// 2-loop SPT with the EFT counterterms to that order ([`eft`]).
    TwoLoopEft,
    /// 2-loop SPT with IR-resummed BAO and the EFT counterterms ([`eft`]).
    TwoLoopEftIr,
}

/// The accepted model names, for messages.
const MODEL_NAMES: &str = "linear, 1l-spt, 1l-rpt-n0, 1l-rpt-n1, 1l-rpt-n2, 1l-rpt-n3, 2l-spt, \
                           2l-rpt-n0, 2l-rpt-n1, 2l-rpt-n2, 2l-rpt-n3, 1l-regpt, 2l-regpt, 1l-spt-ir, \
                           2l-spt-ir, 2l-eft, 2l-eft-ir";

impl RealModel {
    /// Every model.
    pub const ALL: [RealModel; 17] = [
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
        RealModel::OneLoopRegPt,
        RealModel::TwoLoopRegPt,
        RealModel::OneLoopSptIr,
        RealModel::TwoLoopSptIr,
        RealModel::TwoLoopEft,
        RealModel::TwoLoopEftIr,
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
            RealModel::OneLoopRegPt => "1l-regpt",
            RealModel::TwoLoopRegPt => "2l-regpt",
            RealModel::OneLoopSptIr => "1l-spt-ir",
            RealModel::TwoLoopSptIr => "2l-spt-ir",
            RealModel::TwoLoopEft => "2l-eft",
            RealModel::TwoLoopEftIr => "2l-eft-ir",
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
            RealModel::Linear
            | RealModel::OneLoopSpt
            | RealModel::TwoLoopSpt
            | RealModel::OneLoopRegPt
            | RealModel::TwoLoopRegPt
            | RealModel::OneLoopSptIr
            | RealModel::TwoLoopSptIr
            | RealModel::TwoLoopEft
            | RealModel::TwoLoopEftIr => None,
        }
    }

    /// Whether the model needs the 2-loop propagator term P15 ([`crate::loops::p15_terms`]).
    pub fn needs_p15(self) -> bool {
        matches!(self.propagator(), Some(Propagator::N2 | Propagator::N3)) || self.needs_two_loop()
    }

    /// Whether the model needs the 3-loop propagator term P17 ([`crate::loops::p17_terms`]).
    pub fn needs_p17(self) -> bool {
        self.propagator() == Some(Propagator::N3)
    }

    /// Whether the model needs the 2-loop terms ([`crate::loops::two_loop_correction`]).
    pub fn needs_two_loop(self) -> bool {
        matches!(
            self,
            RealModel::TwoLoopSpt
                | RealModel::TwoLoopRptN0
                | RealModel::TwoLoopRptN1
                | RealModel::TwoLoopRptN2
                | RealModel::TwoLoopRptN3
                | RealModel::TwoLoopSptIr
                | RealModel::TwoLoopRegPt
                | RealModel::TwoLoopEft
                | RealModel::TwoLoopEftIr
        )
    }

    /// Whether the model needs RegPT's vertex terms P24 and PΓ2 ([`crate::loops::Gamma2Plan`]).
    pub fn needs_gamma2(self) -> bool {
        self == RealModel::TwoLoopRegPt
    }

    /// Whether the model resums the BAO ([`crate::ir`]): its terms include those of the no-wiggle
    /// spectrum.
    pub fn needs_ir(self) -> bool {
        matches!(
            self,
            RealModel::OneLoopSptIr | RealModel::TwoLoopSptIr | RealModel::TwoLoopEftIr
        )
    }

    /// Whether the model is an EFT model, with the counterterms cs2, cs2_1loop, c4 ([`eft`]).
    pub fn is_eft(self) -> bool {
        matches!(self, RealModel::TwoLoopEft | RealModel::TwoLoopEftIr)
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
    /// [`Error::UnknownName`] naming the accepted models.
    fn from_str(s: &str) -> Result<Self> {
        RealModel::ALL
            .into_iter()
            .find(|m| m.name().eq_ignore_ascii_case(s.trim()))
            .ok_or_else(|| Error::UnknownName {
                what: "real-space model",
                name: s.to_string(),
                available: MODEL_NAMES,
            })
    }
}

/// What `real` computes: one model, or P_dd of every model over the no-wiggle spectrum (`all`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum RealSelection {
    /// One model.
    One(RealModel),
    /// Every model (the paper's real-space comparison).
    All,
}

impl RealSelection {
    /// The model whose plan computes what the selection needs (`all`: 2l-rpt-n3, whose terms include
    /// every model's).
    pub fn plan_model(self) -> RealModel {
        match self {
            RealSelection::One(m) => m,
            RealSelection::All => RealModel::TwoLoopRptN3,
        }
    }
}

impl FromStr for RealSelection {
    type Err = Error;

    /// A model name or `all`.
    fn from_str(s: &str) -> Result<Self> {
        if s.trim().eq_ignore_ascii_case("all") {
            return Ok(RealSelection::All);
        }
        s.parse().map(RealSelection::One)
    }
}

/// Real-space spectra of one model on a k grid, in (Mpc/h)^3, with the loop terms they were made of.
#[derive(Debug, Clone, PartialEq)]
pub struct RealSpectra {
    /// The model.
    pub model: RealModel,
    /// Wavenumbers [h/Mpc].
    pub k: Vec<f64>,
    /// The linear spectrum.
    pub p_lin: Vec<f64>,
    /// P_δδ, P_δθ, P_θθ at each k.
    pub spectra: ByPair<Vec<Estimate>>,
    /// For RPT models, the factors N_X N_Y multiplying [P_lin + P22 (+ P33^{2L})].
    pub factors: Option<ByPair<Vec<Estimate>>>,
    /// The loop terms (every term the model needs is there; others may be too).
    pub terms: LoopTerms,
    /// The EFT counterterms included in `spectra` (all 0: none;
    /// [`with_counterterms`](Self::with_counterterms)).
    pub counterterms: Counterterms,
    /// With massive neutrinos, f_cb = 1 − ω_ν/ω_m of [`with_massive_neutrinos`](Self::with_massive_neutrinos):
    /// P_δδ is then that of all matter, and its counterterms are f_cb² times those of cold matter.
    pub cold_fraction: Option<f64>,
}

impl RealSpectra {
    /// Massive neutrinos, by the usual prescription (Saito, Takada & Taruya 2008; Castorina et al.
    /// 2015): these spectra, computed from the linear spectrum of cold dark matter + baryons P_cb,
    /// become for all matter P_δδ,m = P_m,lin + f_cb² (P_δδ,cb − P_cb,lin), with `p_m_lin` = P_m,lin at
    /// the same k and f_cb = 1 − ω_ν/ω_m: neutrinos stay linear, and so does their cross-spectrum with
    /// cold matter. P_δθ and P_θθ stay those of cold dark matter + baryons (the velocities that
    /// galaxies follow). `p_lin` becomes P_m,lin.
    ///
    /// # Errors
    /// [`Error::LengthMismatch`] unless `p_m_lin` has one value per k.
    pub fn with_massive_neutrinos(mut self, p_m_lin: &[f64], f_cb: f64) -> Result<Self> {
        if p_m_lin.len() != self.k.len() {
            return Err(Error::LengthMismatch {
                what: "k and P_m,lin",
                left: self.k.len(),
                right: p_m_lin.len(),
            });
        }
        let dd = &mut self.spectra[Pair::DeltaDelta];
        for ((v, &p_cb), &p_m) in dd.iter_mut().zip(&self.p_lin).zip(p_m_lin) {
            *v = (*v + (-p_cb)) * (f_cb * f_cb) + p_m;
        }
        self.p_lin = p_m_lin.to_vec();
        self.cold_fraction = Some(self.cold_fraction.unwrap_or(1.0) * f_cb);
        Ok(self)
    }

    /// The spectrum of `pair`.
    pub fn pair(&self, pair: Pair) -> &[Estimate] {
        &self.spectra[pair]
    }

    /// The spectra of `model` from precomputed loop `terms`.
    ///
    /// # Errors
    /// [`Error::MissingTerm`] if the model needs a term that `terms` do not have.
    pub fn from_terms(model: RealModel, terms: LoopTerms) -> Result<Self> {
        let t = &terms.one_loop;
        let n = t.k.len();
        let each = |f: &dyn Fn(Pair, usize) -> Estimate| {
            ByPair::from_fn(|pair| (0..n).map(|i| f(pair, i)).collect())
        };
        let (spectra, factors) = match ModelTerms::of(model, &terms)? {
            ModelTerms::Ir {
                one_loop,
                ir,
                two_loop,
            } => (
                each(&|pair, i| crate::ir::resummed(one_loop, ir, two_loop, pair, i)),
                None,
            ),
            ModelTerms::RegPtOneLoop { one_loop, sigma_d2 } => (
                each(&|pair, i| resum::regpt_one_loop(one_loop, pair, i, sigma_d2[i])),
                None,
            ),
            ModelTerms::RegPtTwoLoop(regpt) => (each(&|pair, i| regpt.spectrum(pair, i)), None),
            ModelTerms::Spt {
                one_loop,
                linear,
                two_loop,
            } => {
                let spectra = each(&|pair, i| {
                    let lin = Estimate::exact(one_loop.p_lin[i]);
                    match (linear, two_loop) {
                        (true, _) => lin,
                        (false, Some(two)) => {
                            lin + one_loop.one_loop(pair, i) + two.pairs[pair].total[i]
                        }
                        (false, None) => lin + one_loop.one_loop(pair, i),
                    }
                });
                (spectra, None)
            }
            ModelTerms::Rpt {
                one_loop,
                propagator,
                two_loop,
            } => {
                let props = resum::propagators(propagator, one_loop);
                let factors = each(&|pair, i| resum::factors(&props, i)[pair]);
                let spectra = each(&|pair, i| resum::rpt(one_loop, two_loop, &props, pair, i));
                (spectra, Some(factors))
            }
        };
        Ok(Self {
            model,
            k: t.k.clone(),
            p_lin: t.p_lin.clone(),
            spectra,
            factors,
            terms,
            counterterms: Counterterms::default(),
            cold_fraction: None,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::plan::CHUNKED_GRID;
    use super::*;
    use crate::linear::LinearSpectrum;
    use crate::loops::OneLoopPlan;
    use crate::precision::Precision;
    use crate::progress::Silent;
    use crate::store::TableStore;

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
    fn a_plan_gives_the_terms_of_a_fresh_1_loop_plan_and_chunks_change_nothing() {
        let p = LinearSpectrum::gm2012(0.0).unwrap();
        let store = TableStore::in_memory();
        let k: Vec<f64> = (0..CHUNKED_GRID + 100)
            .map(|i| 1e-3 * (1.0 + i as f64 * 1e-3))
            .collect();
        for (k, precision) in [(&k[..3], Precision::fast()), (&k[..], Precision::fast())] {
            let plan =
                RealPlan::new(k, RealModel::OneLoopSpt, &precision, &store, &Silent).unwrap();
            let terms = plan.terms(&p, &Silent).unwrap();
            assert_eq!(
                terms.one_loop,
                OneLoopPlan::new(k, &precision).unwrap().evaluate(&p)
            );
            assert!(terms.p15.is_none() && terms.two_loop.is_none());
        }
    }

    #[test]
    fn every_row_has_one_value_per_named_column() {
        let p = LinearSpectrum::gm2012(0.0).unwrap();
        let store = TableStore::in_memory();
        let plan = RealPlan::new(
            &[0.05, 0.1],
            RealModel::OneLoopRptN1,
            &Precision::fast(),
            &store,
            &Silent,
        )
        .unwrap();
        let terms = plan.evaluate(&p, &Silent).unwrap().terms;
        for model in RealModel::ALL {
            for with_terms in [false, true] {
                let Ok(spectra) = RealSpectra::from_terms(model, terms.clone()) else {
                    continue;
                };
                let t = crate::jobs::real_spectra_table(&spectra, vec![], with_terms);
                assert!(t.columns.iter().all(|c| c.values.len() == 2), "{model}");
                let text = t.to_text();
                let names = text.lines().find(|l| l.starts_with("# k")).unwrap();
                let n = names.split_whitespace().count() - 1;
                assert_eq!(n, t.columns.len());
                for line in text.lines().filter(|l| !l.starts_with('#')) {
                    assert_eq!(line.split_whitespace().count(), n, "{model} {with_terms}");
                }
            }
        }
    }

    #[test]
    fn rpt_n1_expands_to_spt_and_linear_is_p_lin() {
        let p = LinearSpectrum::gm2012(1.0).unwrap();
        let k = [0.02, 0.05];
        let store = TableStore::in_memory();
        let lin = real_space(RealModel::Linear, &p, &k, &Precision::fast(), &store).unwrap();
        let terms = lin.terms.clone();
        let spt = RealSpectra::from_terms(RealModel::OneLoopSpt, terms.clone()).unwrap();
        let n1 = RealSpectra::from_terms(RealModel::OneLoopRptN1, terms.clone()).unwrap();
        let e = RealSpectra::from_terms(RealModel::OneLoopRptN2, terms.clone()).unwrap_err();
        assert!(e.to_string().contains("model 1l-rpt-n2 needs P15"), "{e}");
        let t = &terms.one_loop;
        for (i, &ki) in k.iter().enumerate() {
            assert_eq!(lin.spectra.dd[i].value, t.p_lin[i]);
            for pair in Pair::ALL {
                // N1² = 1 + 2x + 2x² + O(x³), x = P13/P: the models differ by 2P13(P13 + P22)/P
                // at second order, with third-order terms of size ~ 2x²(|P13| + |P22|).
                let (a, b) = (spt.spectra[pair][i].value, n1.spectra[pair][i].value);
                let (p22, p13, lin) = (t.p22[pair][i].value, t.p13[pair][i].value, t.p_lin[i]);
                let second = 2.0 * p13 * (p13 + p22) / lin;
                let third = 2.0 * (p13 / lin).powi(2) * (p13.abs() + p22.abs());
                assert!(
                    (b - a - second).abs() < third,
                    "k={ki} {pair:?}: {a} {b} {second}"
                );
            }
        }
    }
}
