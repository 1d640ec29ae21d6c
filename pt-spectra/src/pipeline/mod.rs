//! The chain step as one object: cosmological parameters (through the emulator) or a linear
//! spectrum, and nuisance parameters by name, to the observed data vector (issue 47).
//!
//! A [`Pipeline`] is built once from the observation ([`Observation`]: window, bins or ξ, ℓ's), the
//! model (`ept`: [`crate::rsd::ept`]; other models take the place of [`Model`]), the redshift and the
//! Alcock–Paczynski fiducial. Everything that does not depend on the cosmology is done there:
//! - the loop plan and its basis tensors on one fixed k grid (with a fiducial: the internal log grid
//!   of every α∥, α⊥ in [`AP_FIT_RANGE`], [`crate::rsd::ept::EptSettings::ap_range`]), which the AP
//!   projection interpolates at the true k, μ; no plan is made per cosmology;
//! - the observation as one matrix `M` (rows: output ℓ then output k; columns: model ℓ then model k),
//!   found by applying the (linear) window and bins to unit vectors, so that the stage is one
//!   matrix–vector product and its derivative is `M` itself;
//! - the parsed emulator.
//!
//! A call ([`Pipeline::step`] then [`CosmologyStep::data_vector`]) computes the loop terms of the
//! spectrum (on the basis when it projects within [`PIPELINE_MAX_RESIDUAL`], else by the direct
//! integrals, stated in [`CosmologyStep::source`]), the multipoles with the distortion of the
//! cosmology against the fiducial, and `M` times them.
//!
//! The nuisance-only step: at fixed cosmology the data vector is a polynomial in the parameters,
//! quadratic in u = (1, b1, b2, bs, b3) and linear in the counterterms and stochastic terms
//! (α0, α2, α4, α6, sn, sn2, sn4; velocileptors' REPT), so
//! D(θ) = Σ_{i≤j} u_i u_j A_ij + Σ_c θ_c C_c. [`CosmologyStep::linearise`] finds the 22 vectors
//! A_ij, C_c from 22 evaluations (exact up to rounding: the model is that polynomial), after which
//! [`Linearised::data_vector`] and its exact Jacobian [`Linearised::jacobian`] cost a few
//! thousand multiplications.
//!
//! Derivatives, all exact (no finite differences): [`CosmologyStep::jacobian`] with respect to the
//! nuisance parameters and f ([`JACOBIAN_NAMES`]; f through the model's μ² polynomials and the BAO
//! damping), [`CosmologyStep::template_jacobian`] with respect to f, α∥, α⊥ (the AP projection's
//! interpolant, damping and volume factor), [`Pipeline::cosmology_jacobian`] with respect to the
//! sampled cosmological parameters (through the emulator, the growth, the loops, AP: [`cosmological`]).

use crate::cosmology::Cosmology;
use crate::emulator::LinearEmulator;
use crate::error::{Error, Result};
use crate::linear::LinearSpectrum;
use crate::precision::Precision;
use crate::progress::Progress;
use crate::rsd::ap::{Distortion, AP_FIT_RANGE};
use crate::rsd::ept::{EptParams, EptPlan, EptSettings, EptTerms, PARAM_NAMES};
use crate::setup::{LinearSource, NamedCosmology, Prepared, Request};
use crate::statistic::{Block, Shared, Spec, Terms};
use crate::store::TableStore;
use crate::survey::observe::{apply_matrix, Observation};
use std::sync::Arc;

pub mod cosmological;
mod linearised;
pub mod loop_range;
pub mod mu_rule;
pub use cosmological::CosmologyJacobian;
pub use linearised::{Linearised, JACOBIAN_NAMES, NUISANCE_NAMES};

/// The largest smoothed projection residual for which a [`Pipeline`] evaluates the loop terms on the
/// basis: the plans' own, [`crate::loops::basis::MAX_RESIDUAL`] (2e-3; emulated spectra project with
/// 4e-4 to 8e-4). The terms' errors include ε|T| for a residual ε, whatever it is.
pub const PIPELINE_MAX_RESIDUAL: f64 = crate::loops::basis::MAX_RESIDUAL;

/// The models of the power spectrum a [`Pipeline`] can evaluate (the place of TNS and eft2 later;
/// other statistics are blocks after it, [`crate::statistic`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Model {
    /// The 1-loop Eulerian galaxy model in redshift space ([`crate::rsd::ept`]).
    Ept,
}

/// What a [`Pipeline`] is built from besides the observation.
#[derive(Debug, Clone)]
pub struct PipelineSettings {
    /// The model.
    pub model: Model,
    /// The redshift of the observation.
    pub z: f64,
    /// The fiducial cosmology of the measurement's distances (`None`: no AP distortion).
    pub fiducial: Option<Cosmology>,
    /// IR resummation of the model.
    pub ir: bool,
    /// The largest projection residual evaluated on the basis ([`PIPELINE_MAX_RESIDUAL`]).
    pub max_residual: f64,
    /// The blocks after the power spectrum in the data vector, in its order (none: the power
    /// spectrum alone), each planned by [`Self::planned_blocks`].
    pub blocks: Vec<Arc<dyn Spec>>,
    /// Whether the loop terms are computed only where the observation weighs them, the range chosen
    /// by measurement at build time ([`loop_range`]; default true). False: everywhere.
    pub restrict_loops: bool,
}

impl PipelineSettings {
    /// The blocks after the power spectrum, planned, in the order of the data vector.
    ///
    /// # Errors
    /// As each block's planning ([`Spec::plan`]).
    pub fn planned_blocks(&self) -> crate::error::Result<Vec<Box<dyn Block>>> {
        self.blocks.iter().map(|s| s.plan()).collect()
    }

    /// `ept` at `z` with IR resummation, the AP distortion against `fiducial`, and
    /// [`PIPELINE_MAX_RESIDUAL`].
    pub fn ept(z: f64, fiducial: Option<Cosmology>) -> Self {
        Self {
            model: Model::Ept,
            z,
            fiducial,
            ir: true,
            max_residual: PIPELINE_MAX_RESIDUAL,
            blocks: Vec::new(),
            restrict_loops: true,
        }
    }
}

/// The whole chain step, planned once (module docs).
pub struct Pipeline {
    settings: PipelineSettings,
    plan: EptPlan,
    observation: Observation,
    /// The observation as a matrix, rows × columns = `rows` × `model_ells.len() · k_model.len()`.
    matrix: Vec<f64>,
    rows: usize,
    emulator: LinearEmulator,
    /// The blocks after the power spectrum, planned ([`PipelineSettings::planned_blocks`]).
    blocks: Vec<Box<dyn Block>>,
    /// The measured change of the reference data vector by the loop range, if restricted
    /// ([`loop_range`]).
    loop_truncation: Option<f64>,
    /// The nodes of the rule in μ and their measured change of the reference data vector, if fewer
    /// than [`crate::rsd::ept::MU_NODES`] ([`mu_rule`]).
    mu_rule: Option<(usize, f64)>,
}

/// Where the loop terms of one spectrum came from.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum TermsSource {
    /// The basis tensors, with the spectrum's smoothed projection residual.
    Basis {
        /// The residual.
        residual: f64,
    },
    /// The direct integrals, since the residual exceeded the pipeline's largest (or was NaN).
    DirectFallback {
        /// The residual that was refused.
        residual: f64,
    },
    /// The direct integrals (the plan has no basis tensors).
    Direct,
}

impl TermsSource {
    /// One line for a header, a `meta` entry or a warning.
    pub fn describe(&self, max_residual: f64) -> String {
        match self {
            Self::Basis { residual } => format!(
                "loop terms: basis (projection residual {residual:.1e} <= {max_residual:.1e}, \
                 which bounds their relative error by about twice itself; values only: the chain \
                 step estimates no error per step, EptPlan::terms does)"
            ),
            Self::DirectFallback { residual } => format!(
                "loop terms: direct integrals (fallback: the spectrum projects on the basis with \
                 residual {residual:.1e} > {max_residual:.1e}, outside its span; slower, same model)"
            ),
            Self::Direct => "loop terms: direct integrals (no basis tensors)".into(),
        }
    }
}

/// The cosmology-dependent part of one call: the loop terms, the growth rate and the distortion.
pub struct CosmologyStep<'a> {
    pipeline: &'a Pipeline,
    terms: EptTerms,
    /// f(z) of the spectrum's cosmology (the default of the nuisance `f`).
    pub growth_rate: f64,
    /// The AP distortion of the cosmology against the fiducial (`None` without fiducial).
    pub ap: Option<Distortion>,
    /// Where the loop terms came from.
    pub source: TermsSource,
    /// Each block's terms at [`Self::growth_rate`] and [`Self::ap`].
    blocks: Vec<Box<dyn Terms>>,
}

impl Pipeline {
    /// The pipeline of `observation` (its model ℓ's and k are what the model is evaluated on) with
    /// `settings`, the loop terms planned at `precision` with basis tensors read or built in
    /// `store` (reporting to `progress`).
    ///
    /// # Errors
    /// As [`crate::jobs::ept_plan`], [`EptPlan::with_max_residual`], [`Observation::apply_values`]
    /// and [`LinearEmulator::embedded`]; [`Error::InvalidParameter`] for a bad redshift.
    pub fn new(
        observation: Observation,
        settings: PipelineSettings,
        precision: &Precision,
        store: &TableStore,
        progress: &dyn Progress,
    ) -> Result<Self> {
        if !(settings.z.is_finite() && settings.z > -1.0) {
            return Err(Error::InvalidParameter {
                name: "z",
                value: settings.z,
                reason: "a redshift must be finite and > -1",
            });
        }
        let mut precision = precision.clone();
        if precision.two_loop == crate::precision::TwoLoopMethod::Auto {
            precision.two_loop = crate::precision::TwoLoopMethod::Basis;
        }
        let Model::Ept = settings.model;
        let ept = EptSettings {
            ir: settings.ir,
            ap: None,
            ap_range: settings.fiducial.as_ref().map(|_| AP_FIT_RANGE),
            loop_range: None,
        };
        let (matrix, rows) = observation.matrix().map(|(m, r)| (m.to_vec(), r))?;
        // the build-time measurements of what the step may skip: the loops where the observation
        // weighs little, the μ nodes a smaller rule integrates as well
        let reference = loop_range::Reference::new(observation.k_model(), &ept, settings.z)?;
        let chosen = if settings.restrict_loops {
            loop_range::choose(&observation, &matrix, &reference, &ept)?
        } else {
            None
        };
        let mu_rule = mu_rule::choose(&observation, &matrix, &reference, &ept)?;
        let mut plan = EptPlan::new(
            observation.k_model(),
            EptSettings {
                loop_range: chosen.map(|(range, _)| range),
                ..ept
            },
            &precision,
        )?
        .with_basis(store, progress)?
        .with_max_residual(settings.max_residual)?;
        if let Some((n, _)) = mu_rule {
            plan = plan.with_value_nodes(n)?;
        }
        let blocks = settings.planned_blocks()?;
        Ok(Self {
            settings,
            plan,
            observation,
            matrix,
            rows,
            emulator: LinearEmulator::embedded()?,
            blocks,
            loop_truncation: chosen.map(|(_, change)| change),
            mu_rule,
        })
    }

    /// The settings.
    pub fn settings(&self) -> &PipelineSettings {
        &self.settings
    }

    /// The observation.
    pub fn observation(&self) -> &Observation {
        &self.observation
    }

    /// The length of the data vector: output ℓ's × output k, then each block's entries.
    pub fn len(&self) -> usize {
        self.rows + self.blocks.iter().map(|b| b.len()).sum::<usize>()
    }

    /// The length of the power-spectrum part of the data vector (output ℓ's × output k).
    pub fn power_len(&self) -> usize {
        self.rows
    }

    /// Whether the data vector is empty (never for a built pipeline).
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Whether the data vector has blocks after the power spectrum.
    pub fn has_blocks(&self) -> bool {
        !self.blocks.is_empty()
    }

    /// The blocks after the power spectrum, in the data vector's order.
    pub fn blocks(&self) -> &[Box<dyn Block>] {
        &self.blocks
    }

    /// The observation's matrix (row-major, [`Self::len`] rows, model ℓ's × model k columns): the
    /// derivative of the data vector with respect to the model multipoles.
    pub fn observation_matrix(&self) -> &[f64] {
        &self.matrix
    }

    /// The true k range [h/Mpc] of the loop terms (the first and last points of their grid) and the
    /// change of the reference data vector this range measured at build time, relative to each
    /// multipole's largest |value| ([`loop_range::LOOP_RANGE_TOLERANCE`]); `None` if the loops cover the
    /// whole grid.
    pub fn loop_range(&self) -> Option<((f64, f64), f64)> {
        self.loop_truncation
            .map(|change| (self.plan.loop_k_range(), change))
    }

    /// One line for a header, a `meta` entry or a log: where the loop terms are computed.
    pub fn describe_loop_range(&self) -> String {
        match self.loop_range() {
            Some(((lo, hi), change)) => format!(
                "loop terms on true k in [{lo:.3e}, {hi:.3e}] h/Mpc only (the observation weighs \
                 the rest by little: the reference data vector changes by {change:.1e} of each \
                 multipole's largest value, <= {:.0e}); linear, counterterm and stochastic terms \
                 everywhere",
                loop_range::LOOP_RANGE_TOLERANCE
            ),
            None => "loop terms on the whole grid of the observation's model k".into(),
        }
    }

    /// Whether the loop terms can come from basis tensors.
    pub fn has_basis(&self) -> bool {
        self.plan.has_basis()
    }

    /// The prepared linear spectrum of `cosmology` at the pipeline's redshift from the emulator
    /// parsed at build time (P_cb and f_cb with massive neutrinos, as [`crate::setup::prepare`]).
    ///
    /// # Errors
    /// As [`crate::setup::prepare`] (a parameter outside the emulator's prior is named).
    pub fn prepare(&self, cosmology: &Cosmology) -> Result<Prepared> {
        self.prepare_source(
            LinearSource::Emulator,
            Some(NamedCosmology {
                name: "the pipeline's parameters".into(),
                cosmology: *cosmology,
            }),
        )
    }

    /// The prepared spectrum of any source (a table, the emulator, Eisenstein & Hu) with
    /// `cosmology` (its growth and distances), at the pipeline's redshift.
    ///
    /// # Errors
    /// As [`crate::setup::prepare`].
    pub fn prepare_source(
        &self,
        source: LinearSource,
        cosmology: Option<NamedCosmology>,
    ) -> Result<Prepared> {
        crate::setup::prepare_with_emulator(
            Request {
                source,
                cosmology,
                z: self.settings.z,
            },
            Some(&self.emulator),
        )
    }

    /// The cosmology-dependent step of a prepared spectrum: its loop terms and, with a fiducial,
    /// the distortion of its cosmology.
    ///
    /// # Errors
    /// As [`EptPlan::terms`] and [`Distortion::from_cosmologies`].
    pub fn step(&self, prepared: &Prepared) -> Result<CosmologyStep<'_>> {
        self.step_at_growth_rate(prepared, prepared.growth_rate)
    }

    /// [`Self::step`] at the growth rate `f` instead of the cosmology's f(z) (a template fit's free
    /// f; with blocks the only way to change f, on which their terms depend beyond a polynomial).
    ///
    /// # Errors
    /// As [`Self::step`].
    pub fn step_at_growth_rate(&self, prepared: &Prepared, f: f64) -> Result<CosmologyStep<'_>> {
        let ap = match &self.settings.fiducial {
            Some(fid) => Some(Distortion::from_cosmologies(
                &prepared.cosmology.cosmology,
                fid,
                self.settings.z,
            )?),
            None => None,
        };
        self.step_with(prepared.tracer_spectrum(), f, ap)
    }

    /// The step of a linear spectrum at the pipeline's redshift with growth rate `growth_rate` and
    /// distortion `ap` (given, not from a cosmology: `None` on a pipeline with a fiducial is no
    /// distortion).
    ///
    /// # Errors
    /// As [`EptPlan::terms`]; [`Error::InvalidChoice`] for a distortion without fiducial.
    pub fn step_with(
        &self,
        spectrum: &LinearSpectrum,
        growth_rate: f64,
        ap: Option<Distortion>,
    ) -> Result<CosmologyStep<'_>> {
        // values only: a step reads no error (the header states the basis's bound)
        let terms = self.plan.term_values(spectrum)?;
        let source = match (terms.basis_residual(), self.plan.has_basis()) {
            (Some(residual), _) => TermsSource::Basis { residual },
            (None, true) => TermsSource::DirectFallback {
                residual: self
                    .plan
                    .basis_projection(spectrum)
                    .map_or(f64::NAN, |p| p.residual),
            },
            (None, false) => TermsSource::Direct,
        };
        let ap = match (ap, &self.settings.fiducial) {
            (Some(a), _) => Some(a),
            (None, Some(_)) => Some(Distortion::new(1.0, 1.0)?),
            (None, None) => None,
        };
        let distortion = ap.map_or((1.0, 1.0), |d| (d.apar, d.aperp));
        let blocks = self
            .blocks
            .iter()
            .map(|b| {
                let prepared = b.prepare(spectrum, self.settings.ir)?;
                b.terms(spectrum, &prepared, growth_rate, distortion)
            })
            .collect::<Result<_>>()?;
        Ok(CosmologyStep {
            pipeline: self,
            terms,
            growth_rate,
            ap,
            source,
            blocks,
        })
    }

    /// The data vector of `cosmology` (through the emulator) with the nuisance parameters `params`
    /// by name ([`NUISANCE_NAMES`]; `f` defaults to f(z) of the cosmology).
    ///
    /// # Errors
    /// As [`Self::prepare`], [`Self::step`] and [`CosmologyStep::data_vector`].
    pub fn evaluate(&self, cosmology: &Cosmology, params: &[(&str, f64)]) -> Result<Vec<f64>> {
        let prepared = self.prepare(cosmology)?;
        self.step(&prepared)?.data_vector(params)
    }

    /// [`Self::evaluate`] for many parameter sets (one data vector each, in order).
    ///
    /// # Errors
    /// As [`Self::evaluate`], naming the set that failed.
    pub fn evaluate_batch(&self, sets: &[(Cosmology, Vec<(&str, f64)>)]) -> Result<Vec<Vec<f64>>> {
        sets.iter()
            .enumerate()
            .map(|(i, (c, p))| {
                self.evaluate(c, p).map_err(|e| Error::InvalidChoice {
                    what: format!("parameter set {i} of the batch"),
                    reason: e.to_string(),
                })
            })
            .collect()
    }

    /// `M` times the model multipoles (`model[j]`: model ℓ j on the model k).
    fn observe(&self, model: &[Vec<f64>]) -> Vec<f64> {
        apply_matrix(&self.matrix, model)
    }
}

impl CosmologyStep<'_> {
    /// The ept parameters of `params` by name, `f` defaulting to the step's growth rate.
    fn params(&self, params: &[(&str, f64)]) -> Result<EptParams> {
        let mut p = EptParams::new(0.0, self.growth_rate);
        let blocks = &self.pipeline.blocks;
        for &(name, value) in params {
            if blocks.iter().any(|b| b.kind().index(name).is_some()) {
                continue;
            }
            if let (Some(b), "f") = (blocks.first(), name) {
                if value != self.growth_rate {
                    let block = b.kind().name;
                    return Err(Error::InvalidChoice {
                        what: format!("f = {value} with a {block} block"),
                        reason: format!(
                            "the step's {block} terms are at f = {}: make the step at this f \
                             (Pipeline::step_at_growth_rate; in Python, f is passed there)",
                            self.growth_rate
                        ),
                    });
                }
            }
            p.set(name, value)
                .map_err(|e| match (crate::blocks::owner(name), e) {
                    (Some(kind), Error::InvalidChoice { what, reason }) => Error::InvalidChoice {
                        what,
                        reason: format!(
                            "{reason} ({name} is a {0} parameter: this pipeline has no {0} block)",
                            kind.name
                        ),
                    },
                    (_, e) => e,
                })?;
        }
        p.validate()?;
        Ok(p)
    }

    /// The data vector at the nuisance parameters `params` (by name; any not given is 0, `f` is
    /// f(z)): the model multipoles with the step's distortion, times the observation matrix.
    ///
    /// # Errors
    /// [`Error::InvalidChoice`] naming the valid parameters for an unknown name; as
    /// [`EptPlan::multipole_values_at`].
    pub fn data_vector(&self, params: &[(&str, f64)]) -> Result<Vec<f64>> {
        let p = self.params(params)?;
        let mut out = self.data_vector_of(&p)?;
        let shared = Shared::from_params(params);
        for (block, terms) in self.pipeline.blocks.iter().zip(&self.blocks) {
            out.extend(terms.values(shared, &block.kind().own_values(params))?);
        }
        Ok(out)
    }

    /// The power spectrum's data vectors of several parameter sets of one f.
    fn data_vectors_of(&self, params: &[EptParams]) -> Result<Vec<Vec<f64>>> {
        let pl = self.pipeline;
        let models = pl.plan.multipole_values_many(
            &self.terms,
            params,
            pl.observation.model_ells(),
            self.ap,
        )?;
        Ok(models.iter().map(|m| pl.observe(m)).collect())
    }

    /// [`Self::data_vectors_of`] of the sets `params`, and the exact f-derivatives of those of the
    /// sets `df` (one projection).
    #[allow(clippy::type_complexity)]
    fn data_vectors_and_df_of(
        &self,
        params: &[EptParams],
        df: &[EptParams],
    ) -> Result<(Vec<Vec<f64>>, Vec<Vec<f64>>)> {
        let pl = self.pipeline;
        let (models, df) = pl.plan.multipole_values_and_df_many(
            &self.terms,
            params,
            df,
            pl.observation.model_ells(),
            self.ap,
        )?;
        let observe = |m: &Vec<Vec<Vec<f64>>>| m.iter().map(|m| pl.observe(m)).collect();
        Ok((observe(&models), observe(&df)))
    }

    fn data_vector_of(&self, p: &EptParams) -> Result<Vec<f64>> {
        let pl = self.pipeline;
        let model =
            pl.plan
                .multipole_values_at(&self.terms, p, pl.observation.model_ells(), self.ap)?;
        Ok(pl.observe(&model))
    }

    /// The loop terms: their values (on the basis, their errors are NaN, not estimated: a chain step
    /// reads values only; [`EptPlan::terms`] of the same spectrum has them, and
    /// [`TermsSource::describe`] states the basis's bound).
    pub fn terms(&self) -> &EptTerms {
        &self.terms
    }

    /// Whether the step has the terms of blocks after the power spectrum.
    pub fn has_blocks(&self) -> bool {
        !self.blocks.is_empty()
    }
}

/// The names a call takes: [`PARAM_NAMES`] (`f` defaults to f(z) of the cosmology).
pub fn parameter_names() -> &'static [&'static str] {
    &PARAM_NAMES
}

impl Pipeline {
    /// The names a call of this pipeline takes: [`PARAM_NAMES`], then each block's own.
    pub fn parameters(&self) -> Vec<&'static str> {
        let mut names = PARAM_NAMES.to_vec();
        for b in &self.blocks {
            names.extend(b.kind().own);
        }
        names
    }
}
