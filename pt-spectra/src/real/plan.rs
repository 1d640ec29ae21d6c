//! [`RealPlan`]: a real-space model prepared for one k grid, evaluated for any linear spectrum.

use super::{RealModel, RealSelection, RealSpectra};
use crate::error::Result;
use crate::linear::LinearSpectrum;
use crate::loops::basis::training::{camb_basis, transformed_basis};
use crate::loops::basis::{
    LinearBasis, OneLoopBasis, Projection, SpectrumFamily, TwoLoopBasis, BASIS_SIZE, MAX_RESIDUAL,
};
use crate::loops::lattice::Lattice;
use crate::loops::{
    self, ByPair, Estimate, Gamma2Basis, Gamma2Plan, LoopTerms, OneLoopPlan, OneLoopTerms,
};
use crate::loops::{OneLoopSource, P15Table, P17Table, TwoLoopCorrection, TwoLoopSource};
use crate::precision::{Precision, TwoLoopMethod};
use crate::progress::{stage_callback, Progress, Silent, Stage};
use crate::resum;
use crate::store::TableStore;
use std::sync::Arc;

mod seam;

/// Above this many k values the 1-loop plan is built and evaluated in chunks, reporting
/// [`Stage::OneLoop`] progress after each.
pub(super) const CHUNKED_GRID: usize = 2048;
/// k values per chunk.
const CHUNK: usize = 512;

/// A real-space model prepared for one k grid: the 1-loop quadrature weights and the angular tables the
/// model needs, all independent of the cosmology. [`evaluate`](Self::evaluate) then computes the
/// spectra of any linear spectrum, as often as needed (a fit, a chain, a batch of cosmologies).
///
/// ```
/// use pt_spectra::{linear::LinearSpectrum, loops::Pair, precision::Precision, progress::Silent};
/// use pt_spectra::{real::{RealModel, RealPlan}, store::TableStore};
/// let store = TableStore::in_memory();
/// let plan = RealPlan::new(&[0.05, 0.1], RealModel::OneLoopSpt, &Precision::fast(), &store, &Silent)?;
/// for z in [0.0, 1.0] {
///     let s = plan.evaluate(&LinearSpectrum::gm2012(z)?, &Silent)?;
///     // At k = 0.1 h/Mpc the 1-loop P_δδ exceeds P_lin by a few per cent.
///     let ratio = s.pair(Pair::DeltaDelta)[1].value / s.p_lin[1];
///     assert!(ratio > 1.0 && ratio < 1.1, "{ratio}");
/// }
/// # Ok::<(), pt_spectra::error::Error>(())
/// ```
#[derive(Debug, Clone)]
pub struct RealPlan {
    k: Vec<f64>,
    model: RealModel,
    precision: Precision,
    one_loop: Vec<OneLoopPlan>,
    p15: Option<Arc<P15Table>>,
    p17: Option<Arc<P17Table>>,
    /// The wiggle split if [`terms`](Self::terms) also computes the no-wiggle terms of the
    /// IR-resummed models (its reference spectrum built once, here).
    ir: Option<crate::ir::WiggleSplit>,
    /// RegPT's vertex weights (2-loop RegPT, and `all`).
    gamma2: Option<Gamma2Plan>,
    /// Its inner integrals as linear forms on the 1-loop tensors' basis, if the plan has them.
    gamma2_basis: Option<Gamma2Basis>,
    /// The 2-loop basis tensors, if the 2-loop terms come from them ([`TwoLoopMethod`]).
    basis: Option<Arc<TwoLoopBasis>>,
    /// For the IR-resummed 2-loop models, the 2-loop tensors of the no-wiggle spectra.
    basis_nw: Option<Arc<TwoLoopBasis>>,
    /// The 1-loop basis tensors, if the 1-loop terms come from them ([`TwoLoopMethod`]).
    one_loop_basis: Option<Arc<OneLoopBasis>>,
    /// For the IR-resummed models, the 1-loop tensors of the no-wiggle spectra (on a basis of the
    /// training spectra's no-wiggle parts), if the 1-loop terms come from tensors.
    one_loop_basis_nw: Option<Arc<OneLoopBasis>>,
}

impl RealPlan {
    /// The plan of what `selection` needs: its model's, and for `all` every model's terms (the IR
    /// resummation included).
    ///
    /// # Errors
    /// As [`new`](Self::new).
    pub fn for_selection(
        k: &[f64],
        selection: RealSelection,
        precision: &Precision,
        store: &TableStore,
        progress: &dyn Progress,
    ) -> Result<Self> {
        if selection == RealSelection::All {
            precision.validate()?;
            crate::memory::check(
                Self::memory_estimate(k.len(), RealModel::TwoLoopRegPt, precision),
                precision,
                &format!("the plan of every model on {} k", k.len()),
            )?;
        }
        let mut plan = Self::new(k, selection.plan_model(), precision, store, progress)?;
        if selection == RealSelection::All {
            if plan.ir.is_none() {
                plan.ir = Some(crate::ir::WiggleSplit::new()?);
            }
            if plan.gamma2.is_none() {
                plan.gamma2 = Some(gamma2_plan(k, precision, progress));
            }
        }
        Ok(plan)
    }

    /// The estimated peak memory of the plan of `model` on `nk` wavenumbers with `precision` \[bytes\]:
    /// the process, the 1-loop plan and what the model adds (the P15 and P17 tables, RegPT's Γ2
    /// weights, the 2-loop basis tensors), each plan's own estimate. [`new`](Self::new) checks it
    /// against the limit before it allocates.
    pub fn memory_estimate(nk: usize, model: RealModel, precision: &Precision) -> f64 {
        let mut bytes = crate::memory::PROCESS + OneLoopPlan::memory_estimate(nk, precision);
        if model.needs_p15() {
            bytes += P15Table::MEMORY;
        }
        if model.needs_p17() {
            bytes += P17Table::MEMORY;
        }
        if model.needs_gamma2() {
            bytes += Gamma2Plan::memory_estimate(nk);
        }
        if model.needs_two_loop() {
            bytes += TwoLoopBasis::memory_estimate(nk, precision);
        }
        bytes
    }

    /// Whether the plan computes every model's terms (those of `real --model all`).
    pub fn covers(&self, selection: RealSelection) -> bool {
        self.model == selection.plan_model()
            && ((self.ir.is_some() && self.gamma2.is_some()) || selection != RealSelection::All)
    }

    /// The plan of `model` on the wavenumbers `k` [h/Mpc] with `precision`; the angular tables the
    /// model needs (P15 for N2, N3 and 2-loop models, P17 for N3) come from `store`, built there on
    /// first use (reported to `progress`). For 2-loop models, `precision.two_loop` says whether the
    /// 2-loop terms come from basis tensors (read from `store`, or for [`TwoLoopMethod::Basis`]
    /// built there: minutes, once per grid) or from direct integrals.
    ///
    /// # Errors
    /// As [`OneLoopPlan::new`] and [`TableStore::p15`].
    pub fn new(
        k: &[f64],
        model: RealModel,
        precision: &Precision,
        store: &TableStore,
        progress: &dyn Progress,
    ) -> Result<Self> {
        precision.validate()?;
        // The whole grid (the chunks below are checked one by one).
        crate::table::check_k_values("k", k)?;
        crate::memory::check(
            Self::memory_estimate(k.len(), model, precision),
            precision,
            &format!("the {} plan on {} k", model.name(), k.len()),
        )?;
        let one_loop = if k.len() < CHUNKED_GRID {
            vec![OneLoopPlan::new(k, precision)?]
        } else {
            let mut plans = Vec::new();
            for (i, chunk) in k.chunks(CHUNK).enumerate() {
                plans.push(OneLoopPlan::new(chunk, precision)?);
                progress.update(Stage::OneLoop, ((i + 1) * CHUNK).min(k.len()), 2 * k.len());
            }
            plans
        };
        let p15 = if model.needs_p15() {
            Some(store.p15(progress)?)
        } else {
            None
        };
        let p17 = if model.needs_p17() {
            Some(store.p17(progress)?)
        } else {
            None
        };
        let split = if model.needs_ir() {
            Some(crate::ir::WiggleSplit::new()?)
        } else {
            None
        };
        // The basis of the no-wiggle parts of the training spectra, on `lattice`.
        let no_wiggle_basis = |lattice: &Lattice| -> Option<LinearBasis> {
            let split = split.as_ref()?;
            Some(transformed_basis(
                lattice,
                BASIS_SIZE,
                &|p: &LinearSpectrum| split.no_wiggle(p).unwrap_or_else(|_| p.clone()),
            ))
        };
        let method = precision.two_loop;
        let basis_nw = match &p15 {
            Some(table) if model.needs_two_loop() && model.needs_ir() => {
                let nw = SpectrumFamily::NoWiggle;
                let build = |tick: &(dyn Fn(usize, usize) + Sync)| {
                    let lattice = TwoLoopBasis::lattice(precision);
                    let basis = no_wiggle_basis(&lattice).expect("an IR model has a split");
                    TwoLoopBasis::build(k, precision, table, nw, basis, tick)
                };
                store.for_method::<TwoLoopBasis>(method, (k, precision, nw), build, progress)?
            }
            _ => None,
        };
        let basis = match &p15 {
            Some(table) if model.needs_two_loop() => {
                let linear = SpectrumFamily::Linear;
                let build = |tick: &(dyn Fn(usize, usize) + Sync)| {
                    TwoLoopBasis::build_linear(k, precision, table, tick)
                };
                store.for_method::<TwoLoopBasis>(method, (k, precision, linear), build, progress)?
            }
            _ => None,
        };
        // The 1-loop tensors (one chunk only): built with the 2-loop ones by method basis, used by
        // auto when cached.
        let tensors = |family: SpectrumFamily| -> Result<Option<Arc<OneLoopBasis>>> {
            let [plan] = one_loop.as_slice() else {
                return Ok(None);
            };
            let build = |tick: &(dyn Fn(usize, usize) + Sync)| {
                let lattice = plan.rules().0.lattice.clone();
                let basis = match family {
                    SpectrumFamily::NoWiggle => {
                        no_wiggle_basis(&lattice).expect("only IR models ask for it")
                    }
                    SpectrumFamily::Linear => camb_basis(lattice.clone(), BASIS_SIZE),
                };
                OneLoopBasis::build(plan, family, basis, tick)
            };
            let key = (plan.k(), plan.precision(), family);
            store.for_method::<OneLoopBasis>(method, key, build, progress)
        };
        let one_loop_basis = tensors(SpectrumFamily::Linear)?;
        let one_loop_basis_nw = match (&one_loop_basis, &split) {
            (Some(_), Some(_)) => tensors(SpectrumFamily::NoWiggle)?,
            _ => None,
        };
        let gamma2 = model
            .needs_gamma2()
            .then(|| gamma2_plan(k, precision, progress));
        let gamma2_basis = match (&gamma2, &one_loop_basis) {
            (Some(plan), Some(tensors)) => plan.on_basis(tensors.basis()),
            _ => None,
        };
        Ok(Self {
            k: k.to_vec(),
            model,
            precision: precision.clone(),
            one_loop_basis,
            one_loop_basis_nw,
            one_loop,
            p15,
            p17,
            ir: split,
            gamma2,
            gamma2_basis,
            basis,
            basis_nw,
        })
    }

    /// The wavenumbers [h/Mpc].
    pub fn k(&self) -> &[f64] {
        &self.k
    }

    /// The model.
    pub fn model(&self) -> RealModel {
        self.model
    }

    /// The settings of the loop integrals.
    pub fn precision(&self) -> &Precision {
        &self.precision
    }

    /// Every loop term the model needs, for the linear `spectrum` (at the output redshift), in
    /// parallel over k; the 2-loop points are reported to `progress` ([`Stage::TwoLoopPoints`]).
    /// IR-resummed models also get the terms of the no-wiggle spectrum ([`crate::ir`]).
    ///
    /// # Errors
    /// As [`crate::ir::no_wiggle`].
    pub fn terms(&self, spectrum: &LinearSpectrum, progress: &dyn Progress) -> Result<LoopTerms> {
        self.terms_projected(spectrum, None, progress)
    }

    /// The projection of `spectrum` on the plan's basis, if the plan has 1-loop basis tensors (for
    /// other plans on the same grid and precision to share: [`crate::rsd::RsdPlan`]).
    pub fn project(&self, spectrum: &LinearSpectrum) -> Option<Projection> {
        let basis = self.one_loop_basis.as_ref()?.basis();
        Some(basis.project_spectrum(spectrum, MAX_RESIDUAL))
    }

    /// As [`terms`](Self::terms) with the spectrum's `projection` from [`project`](Self::project)
    /// already made (`None`: made here if needed).
    ///
    /// # Errors
    /// As [`terms`](Self::terms).
    pub fn terms_projected(
        &self,
        spectrum: &LinearSpectrum,
        projection: Option<Projection>,
        progress: &dyn Progress,
    ) -> Result<LoopTerms> {
        let tensors = (self.one_loop_basis.as_ref(), self.basis.as_ref());
        let mut terms = self.loop_terms(spectrum, projection, tensors, progress);
        if let Some(split) = &self.ir {
            let nw = split.no_wiggle(spectrum)?;
            terms.ir = Some(Box::new(loops::IrTerms {
                sigma2: crate::ir::sigma2_bao(&nw, self.precision.q_min),
                no_wiggle: self.loop_terms(
                    &nw,
                    None,
                    (self.one_loop_basis_nw.as_ref(), self.basis_nw.as_ref()),
                    progress,
                ),
            }));
        }
        Ok(terms)
    }

    /// The loop terms of `spectrum`, from `tensors` (the plan's 1- and 2-loop tensors of linear or
    /// of no-wiggle spectra) where given and the spectrum projects on their basis well enough.
    fn loop_terms(
        &self,
        spectrum: &LinearSpectrum,
        projection: Option<Projection>,
        (tensors, two_loop_tensors): (Option<&Arc<OneLoopBasis>>, Option<&Arc<TwoLoopBasis>>),
        progress: &dyn Progress,
    ) -> LoopTerms {
        let (k, precision) = (&self.k, &self.precision);
        let (one_loop, sigma_d2, one_loop_source, projection) =
            match self.one_loop_on_basis(tensors, spectrum, projection, progress) {
                Ok((terms, projection)) => {
                    let source = OneLoopSource::Basis {
                        functions: projection.coefficients.len(),
                        residual: projection.residual,
                        soft: projection.soft_delta(),
                    };
                    (terms.terms, terms.sigma_d2, Some(source), Some(projection))
                }
                Err(source) => (
                    self.one_loop_direct(spectrum, progress),
                    resum::sigma_d2(spectrum, k, precision),
                    source,
                    None,
                ),
            };
        let p17 = self
            .p17
            .as_ref()
            .map(|table| loops::p17_terms(table, k, spectrum, precision));
        // A projection on the no-wiggle basis is no use to the 2-loop tensors (of linear spectra).
        let linear = tensors.is_some_and(|t| {
            self.one_loop_basis
                .as_ref()
                .is_some_and(|b| Arc::ptr_eq(t, b))
        });
        let projection = projection.filter(|_| linear);
        let gamma2 = self.gamma2.as_ref().map(|plan| {
            let on_basis = self.gamma2_basis.as_ref().zip(projection.as_ref());
            on_basis
                .and_then(|(forms, projection)| forms.evaluate(plan, spectrum, projection))
                .unwrap_or_else(|| plan.evaluate(spectrum))
        });
        let (p15, two_loop, two_loop_source) =
            self.two_loop_terms(two_loop_tensors, spectrum, &one_loop, projection, progress);
        LoopTerms {
            one_loop,
            p15,
            p17,
            two_loop,
            sigma_d2: Some(sigma_d2),
            ir: None,
            gamma2,
            two_loop_source,
            one_loop_source,
        }
    }

    /// The 1-loop terms and σ_d² from the basis tensors with the spectrum's projection, or, if the
    /// plan has none or the spectrum does not project well enough, `Err` with what to report
    /// (noted to `progress`).
    fn one_loop_on_basis(
        &self,
        tensors: Option<&Arc<OneLoopBasis>>,
        spectrum: &LinearSpectrum,
        projection: Option<Projection>,
        progress: &dyn Progress,
    ) -> std::result::Result<(loops::basis::BasisOneLoop, Projection), Option<OneLoopSource>> {
        let Some(tensors) = tensors else {
            return Err(None);
        };
        let basis = tensors.basis();
        let projection =
            projection.unwrap_or_else(|| basis.project_spectrum(spectrum, MAX_RESIDUAL));
        // A NaN residual (a spectrum with non-positive values) is refused too.
        if projection.residual.is_nan() || projection.residual > MAX_RESIDUAL {
            let source = OneLoopSource::Fallback {
                residual: projection.residual,
                max_residual: MAX_RESIDUAL,
            };
            progress.note(&source.describe());
            return Err(Some(source));
        }
        let p_lin: Vec<f64> = self.k.iter().map(|&k| spectrum.eval(k)).collect();
        Ok((tensors.evaluate(&p_lin, &projection), projection))
    }

    /// The 1-loop terms from the plan's quadrature (in chunks on long grids).
    fn one_loop_direct(&self, spectrum: &LinearSpectrum, progress: &dyn Progress) -> OneLoopTerms {
        let mut one_loop: Option<OneLoopTerms> = None;
        for (i, plan) in self.one_loop.iter().enumerate() {
            let part = plan.par_evaluate(spectrum);
            match one_loop.as_mut() {
                None => one_loop = Some(part),
                Some(all) => all.append(part),
            }
            if self.one_loop.len() > 1 {
                let done = self.k.len() + ((i + 1) * CHUNK).min(self.k.len());
                progress.update(Stage::OneLoop, done, 2 * self.k.len());
            }
        }
        one_loop.expect("a plan has at least one chunk")
    }

    /// P15 and, for 2-loop models, the 2-loop terms: from the basis tensors if the plan has them and
    /// the spectrum projects well enough, else directly (with a note to `progress` if the basis was
    /// passed over).
    fn two_loop_terms(
        &self,
        tensors: Option<&Arc<TwoLoopBasis>>,
        spectrum: &LinearSpectrum,
        one_loop: &OneLoopTerms,
        projection: Option<Projection>,
        progress: &dyn Progress,
    ) -> (
        Option<ByPair<Vec<Estimate>>>,
        Option<TwoLoopCorrection>,
        Option<TwoLoopSource>,
    ) {
        let (k, precision) = (&self.k, &self.precision);
        let Some(table) = &self.p15 else {
            return (None, None, None);
        };
        let mut source = match precision.two_loop {
            TwoLoopMethod::Auto => TwoLoopSource::DirectUncached,
            _ => TwoLoopSource::Direct,
        };
        if let Some(basis) = tensors {
            // The projection made for the 1-loop tensors if it is on the same basis (accepted there
            // with the same limit), else the 2-loop basis's own.
            let shared = projection.filter(|_| {
                self.one_loop_basis
                    .as_ref()
                    .is_some_and(|b| b.basis() == basis.basis())
                    && basis.max_residual() >= MAX_RESIDUAL
            });
            let result = match shared {
                Some(projection) => Ok(basis.evaluate_projected(spectrum, projection, one_loop)),
                None => basis.evaluate(spectrum, one_loop),
            };
            match result {
                Ok(terms) => {
                    let source = TwoLoopSource::Basis {
                        functions: basis.basis().len(),
                        residual: terms.projection.residual,
                        pointwise: terms.projection.pointwise,
                        soft: terms.projection.soft_delta(),
                    };
                    return (Some(terms.p15), Some(terms.correction), Some(source));
                }
                Err(projection) => {
                    source = TwoLoopSource::Fallback {
                        residual: projection.residual,
                        max_residual: basis.max_residual(),
                    };
                    progress.note(&source.describe());
                }
            }
        }
        let p15 = loops::p15_terms(table, k, spectrum, precision);
        if !self.model.needs_two_loop() {
            return (Some(p15), None, None);
        }
        let points = stage_callback(progress, Stage::TwoLoopPoints);
        let two_loop =
            loops::two_loop_correction(one_loop, &p15, table, spectrum, precision, &points);
        (Some(p15), Some(two_loop), Some(source))
    }

    /// The model's spectra for the linear `spectrum` (at the output redshift).
    ///
    /// # Errors
    /// None in practice: the plan computes every term its model needs (a [`crate::error::Error::MissingTerm`]
    /// would be a bug).
    pub fn evaluate(
        &self,
        spectrum: &LinearSpectrum,
        progress: &dyn Progress,
    ) -> Result<RealSpectra> {
        RealSpectra::from_terms(self.model, self.terms(spectrum, progress)?)
    }

    /// As [`evaluate`](Self::evaluate) with the spectrum's `projection` already made.
    ///
    /// # Errors
    /// As [`evaluate`](Self::evaluate).
    pub fn evaluate_projected(
        &self,
        spectrum: &LinearSpectrum,
        projection: Option<Projection>,
        progress: &dyn Progress,
    ) -> Result<RealSpectra> {
        RealSpectra::from_terms(
            self.model,
            self.terms_projected(spectrum, projection, progress)?,
        )
    }
}

impl RealPlan {
    /// The model's spectra for each of `spectra` (each at the output redshift), spread over
    /// rayon's threads one spectrum per task: a batch of cosmologies. The results are those of
    /// [`evaluate`](Self::evaluate), in order. Memory: the plan once, and per spectrum its
    /// [`RealSpectra`] (values and errors of every term: at most 1 kB per k),
    /// checked against the plan's limit before any is evaluated.
    ///
    /// # Errors
    /// [`crate::error::Error::MemoryLimit`] with the estimate and the limit if the results do not
    /// fit; per spectrum as [`evaluate`](Self::evaluate).
    pub fn evaluate_batch(&self, spectra: &[LinearSpectrum]) -> Result<Vec<Result<RealSpectra>>> {
        use rayon::prelude::*;
        let nk = self.k.len();
        let plan = Self::memory_estimate(nk, self.model, &self.precision);
        let results = SPECTRA_BYTES_PER_K * nk as f64 * spectra.len() as f64;
        crate::memory::check(
            plan + results,
            &self.precision,
            &format!(
                "a batch of {} spectra on {nk} k (the {} plan {}, the results {})",
                spectra.len(),
                self.model.name(),
                crate::memory::size(plan),
                crate::memory::size(results)
            ),
        )?;
        Ok(spectra
            .par_iter()
            .map(|s| self.evaluate(s, &Silent))
            .collect())
    }
}

/// Bytes per k of one [`RealSpectra`] with every term: at most ~40 estimates (value and error,
/// 16 bytes each) per k, and its vectors' overhead.
const SPECTRA_BYTES_PER_K: f64 = 1e3;

/// RegPT's vertex weights on `k` (seconds on long grids: reported as [`Stage::Gamma2Weights`]).
fn gamma2_plan(k: &[f64], precision: &Precision, progress: &dyn Progress) -> Gamma2Plan {
    Gamma2Plan::with_progress(
        k,
        (precision.q_min, precision.q_max),
        precision.lattice_step,
        &stage_callback(progress, Stage::Gamma2Weights),
    )
}

/// The spectra of `model` for `spectrum` at wavenumbers `k` [h/Mpc]: a [`RealPlan`] built and
/// evaluated once. Build the plan yourself to evaluate several spectra on one grid.
///
/// # Errors
/// As [`RealPlan::new`].
///
/// ```
/// use pt_spectra::{linear::LinearSpectrum, loops::Pair, precision::Precision, store::TableStore};
/// use pt_spectra::real::{real_space, RealModel};
/// let (p, store) = (LinearSpectrum::gm2012(0.0)?, TableStore::in_memory());
/// let spt = real_space("1l-spt".parse()?, &p, &[0.1], &Precision::fast(), &store)?;
/// let n1 = real_space(RealModel::OneLoopRptN1, &p, &[0.1], &Precision::fast(), &store)?;
/// // At k = 0.1 h/Mpc, z = 0 the two agree to a few per cent and exceed P_lin.
/// let (a, b) = (spt.pair(Pair::DeltaDelta)[0].value, n1.pair(Pair::DeltaDelta)[0].value);
/// assert!(a > spt.p_lin[0] && (a / b - 1.0).abs() < 0.05);
/// # Ok::<(), pt_spectra::error::Error>(())
/// ```
pub fn real_space(
    model: RealModel,
    spectrum: &LinearSpectrum,
    k: &[f64],
    precision: &Precision,
    store: &TableStore,
) -> Result<RealSpectra> {
    RealPlan::new(k, model, precision, store, &Silent)?.evaluate(spectrum, &Silent)
}
