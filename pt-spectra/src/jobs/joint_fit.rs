//! `fit --analysis FILE`: the joint fit of the galaxy model `ept` to several data sets
//! ([`crate::fit::galaxy::joint`]), from an analysis (the parsed file, [`Analysis`]), as a table with
//! a row per data set.

use super::ept_fit::{row_columns, Row};
use super::ObservationSpec;
use crate::error::{Error, Result};
use crate::fit::galaxy::search::{CROSSING_TOLERANCE, HESSIAN_STEP};
use crate::fit::galaxy::{
    default_shared, fit_joint, BlockFit, DataSet, GalaxyFitRequest, JointFit, Linear, Prior,
    Search, Template,
};
use crate::fit::{DataLayout, MultipoleData};
use crate::output::Table;
use crate::precision::Precision;
use crate::rsd::ap::ApSpec;
use crate::rsd::ept::{EptParams, EptPlan, EptTerms};
use crate::setup::Prepared;
use crate::store::TableStore;
use crate::survey::observe::{Bins, Observation, Window};
use std::path::PathBuf;

/// The start of b1 when a data set gives none (the middle of the start box, [`crate::fit::galaxy::search::RANGES`]).
pub const DEFAULT_B1: f64 = 2.0;

/// One data set of an analysis (paths already resolved against the analysis file's directory).
#[derive(Debug, Clone, PartialEq)]
pub struct SetSpec {
    /// Its label (unique; names its own parameters).
    pub label: String,
    /// Its redshift.
    pub z: f64,
    /// Its tracer (empty: not stated).
    pub tracer: String,
    /// The multipoles file: k, then P_ℓ and σ_ℓ per multipole of `data_ells`.
    pub data: PathBuf,
    /// The multipoles in the data file, in column order.
    pub data_ells: Vec<usize>,
    /// 1-based columns of k, then P_ℓ, σ_ℓ (default 1, 2, 3, …).
    pub data_columns: Option<Vec<usize>>,
    /// The covariance file, if any (else diagonal σ²).
    pub covariance: Option<PathBuf>,
    /// The mocks the covariance was estimated from (the Hartlap factor).
    pub n_mocks: Option<usize>,
    /// The fitted multipoles.
    pub ells: Vec<usize>,
    /// The fitted range [h/Mpc].
    pub k_min: f64,
    /// The fitted range [h/Mpc].
    pub k_max: f64,
    /// Per-multipole ranges (ℓ, k_min, k_max) [h/Mpc].
    pub ell_ranges: Vec<(usize, f64, f64)>,
    /// The free parameters.
    pub free: Vec<String>,
    /// The marginalised parameters.
    pub marginalise: Vec<String>,
    /// The priors.
    pub priors: Vec<Prior>,
    /// Start (or fixed) values by name; b1 defaults to [`DEFAULT_B1`], f to f(z) of the cosmology.
    pub start: Vec<(String, f64)>,
    /// The measurement's distortion (α∥, α⊥), if given.
    pub ap: Option<(f64, f64)>,
    /// The fiducial cosmology of the measurement (preset or .ini), for the distortion, if given.
    pub fiducial: Option<String>,
    /// The window file, if any.
    pub window: Option<PathBuf>,
    /// The window file's layout ([`crate::survey::WindowFormat::parse`]).
    pub window_format: String,
    /// The window's mixing: `wilson` or `classpt-boss`.
    pub window_mixing: String,
    /// k bin edges [h/Mpc], if any.
    pub k_edges: Option<Vec<f64>>,
    /// The parameter basis: `velocileptors` or `desi` ([`super::fit_basis`]).
    pub basis: String,
    /// The number density of the `desi` basis [(h/Mpc)³].
    pub n_bar: Option<f64>,
    /// The satellites (f_sat, σ_v [Mpc/h]) of the `desi` basis.
    pub satellites: Option<(f64, f64)>,
    /// Whether the DESI DR1 priors are added ([`super::add_desi_priors`]).
    pub desi_priors: bool,
    /// The side of the periodic box [Mpc/h] whose modes are averaged in the bins, if any.
    pub box_side: Option<f64>,
    /// IR resummation.
    pub ir: bool,
    /// The block beside the power spectrum, with their joint covariance (then `covariance` is not
    /// given), if any: its kind's name and its table (`[dataset.<kind name>]`).
    pub block: Option<(&'static str, crate::statistic::Options)>,
}

/// A joint analysis: its data sets, the shared parameters and the search.
#[derive(Debug, Clone, PartialEq)]
pub struct Analysis {
    /// The file it was read from (for the header and the errors).
    pub origin: String,
    /// The shared parameters; `None`: [`default_shared`].
    pub shared: Option<Vec<String>>,
    /// The minimiser's settings.
    pub search: Search,
    /// The data sets.
    pub sets: Vec<SetSpec>,
}

/// What the analysis needs from the face: the spectrum at a redshift, the loop settings, the cache.
pub struct Inputs<'a> {
    /// The prepared spectrum and growth at z (the face's cosmology and linear spectrum).
    pub prepare: &'a dyn Fn(f64) -> Result<Prepared>,
    /// The loop-integral settings.
    pub precision: &'a Precision,
    /// The angular-table cache.
    pub store: &'a TableStore,
    /// Progress of the plans.
    pub progress: &'a dyn crate::progress::Progress,
}

/// An error of data set `label` of `origin`.
fn in_set(origin: &str, label: &str, e: impl std::fmt::Display) -> Error {
    Error::InvalidChoice {
        what: format!("{origin}: data set `{label}`"),
        reason: e.to_string(),
    }
}

/// What one data set loads: its data, observation, plan, terms, request and template.
pub(super) struct Loaded {
    data: MultipoleData,
    observation: Option<Observation>,
    plan: EptPlan,
    terms: EptTerms,
    request: GalaxyFitRequest,
    pub(super) template: Template,
    pub(super) description: Vec<String>,
    /// Its block after the power spectrum, if any.
    block: Option<BlockFit>,
}

/// The data sets of `analysis` on their `loaded` data.
pub(super) fn data_sets<'a>(analysis: &Analysis, loaded: &'a [Loaded]) -> Vec<DataSet<'a>> {
    analysis
        .sets
        .iter()
        .zip(loaded)
        .map(|(s, l)| DataSet {
            label: s.label.clone(),
            z: s.z,
            tracer: s.tracer.clone(),
            plan: &l.plan,
            terms: &l.terms,
            data: &l.data,
            request: l.request.clone(),
            observation: l.observation.as_ref(),
            block: l.block.as_ref(),
        })
        .collect()
}

/// The shared parameters of `analysis` (declared, or [`default_shared`] of `sets`) and how they
/// were chosen.
pub(super) fn shared_of(analysis: &Analysis, sets: &[DataSet]) -> (Vec<String>, &'static str) {
    match &analysis.shared {
        Some(v) => (v.clone(), "declared in the analysis file"),
        None => (
            default_shared(sets),
            "the default: f, apar, aperp (those free in every set) when every set has the same z \
             and tracer, none otherwise",
        ),
    }
}

/// Loads data set `s` of `analysis`.
pub(super) fn load(s: &SetSpec, origin: &str, inputs: &Inputs) -> Result<Loaded> {
    let err = |e: Error| in_set(origin, &s.label, e);
    let prepared = (inputs.prepare)(s.z).map_err(err)?;
    let layout = DataLayout::new(&s.data_ells, s.data_columns.as_deref()).map_err(err)?;
    let mut data = layout.read(&s.data, &s.ells).map_err(err)?;
    if let Some(path) = &s.covariance {
        if let Some((name, _)) = &s.block {
            return Err(err(Error::InvalidChoice {
                what: format!("covariance with a {name}"),
                reason: format!(
                    "the power spectrum's covariance is the joint one's block: give only \
                     {name}.covariance"
                ),
            }));
        }
        data = layout.read_covariance(data, path).map_err(err)?;
    }
    // the block after the power spectrum and its header line
    let mut block = None;
    if let Some((name, options)) = &s.block {
        let kind = crate::blocks::by_name(name).map_err(err)?;
        let (with_cov, fit, line) = super::joint_block::load_block(
            kind,
            options,
            &layout,
            &s.data,
            data,
            prepared.tracer_spectrum(),
            s.ir,
        )
        .map_err(err)?;
        data = with_cov;
        block = Some((fit, line));
    }
    let mixing = match s.window_mixing.as_str() {
        "wilson" => crate::survey::Mixing::Wilson,
        "classpt-boss" => crate::survey::Mixing::ClassPtBoss,
        other => {
            return Err(err(Error::InvalidChoice {
                what: format!("window_mixing = \"{other}\""),
                reason: "expected wilson or classpt-boss".into(),
            }))
        }
    };
    let window = match &s.window {
        Some(path) => {
            let format = crate::survey::WindowFormat::parse(&s.window_format).map_err(err)?;
            Some(Window::read(path, mixing, &format).map_err(err)?)
        }
        None => None,
    };
    let fiducial = s
        .fiducial
        .as_deref()
        .map(|name| crate::setup::NamedCosmology::parse(name).map(|c| c.0.cosmology))
        .transpose()
        .map_err(err)?;
    let spec = ObservationSpec {
        window,
        bins: Bins::of(s.k_edges.clone(), s.box_side).map_err(err)?,
        ap: ApSpec::from_options(s.ap.map(|a| a.0), s.ap.map(|a| a.1), fiducial).map_err(err)?,
        ..ObservationSpec::default()
    };
    let cosmology = prepared.cosmology.cosmology;
    let ap = spec.ap.distortion(&cosmology, s.z).map_err(err)?;
    let free_ap = ApSpec::check_free(ap.as_ref(), &s.free).map_err(err)?;
    let observation = spec.build(&s.ells, &data.k).map_err(err)?;
    let model_k = observation
        .as_ref()
        .map_or(data.k.as_slice(), |o| o.k_model());
    let plan = super::ept_plan(
        model_k,
        s.ir,
        ap,
        free_ap,
        inputs.precision,
        inputs.store,
        inputs.progress,
    )
    .map_err(err)?;
    let terms = plan.terms(prepared.tracer_spectrum()).map_err(err)?;
    let mut start = EptParams::new(DEFAULT_B1, prepared.growth_rate);
    for (name, v) in &s.start {
        match name.as_str() {
            b if crate::blocks::owner(b).is_some() => match block.take() {
                Some((fit, line)) => block = Some((fit.with_start(b, *v).map_err(err)?, line)),
                None => {
                    let kind = crate::blocks::owner(b).map_or("", |k| k.name);
                    return Err(err(Error::InvalidChoice {
                        what: format!("start.{name}"),
                        reason: format!("is a {kind} parameter, and this data set has no {kind}"),
                    }));
                }
            },
            "apar" | "aperp" => {
                return Err(err(Error::InvalidChoice {
                    what: format!("start.{name}"),
                    reason: "the distortion's start is the data set's apar, aperp (or fiducial)"
                        .into(),
                }))
            }
            _ => start.set(name, *v).map_err(err)?,
        }
    }
    let basis = super::fit_basis(
        &s.basis,
        prepared.spectrum.sigma8(),
        s.n_bar,
        s.satellites,
        s.desi_priors,
    )
    .map_err(err)?;
    let mut priors = s.priors.clone();
    if s.desi_priors {
        super::add_desi_priors(&mut priors, &s.free, &s.marginalise);
    }
    let request = GalaxyFitRequest {
        start,
        ap,
        free: s.free.clone(),
        marginalise: s.marginalise.clone(),
        priors,
        ells: s.ells.clone(),
        k_min: s.k_min,
        k_max: s.k_max,
        ell_ranges: s.ell_ranges.clone(),
        n_mocks: s.n_mocks,
        basis,
    };
    let mut description =
        vec![format!(
        "data set {}: {} (z = {}, tracer {}{}{}), multipoles {:?} for k in [{}, {}] h/Mpc{}; free \
         {}, marginalised {}, priors {}; start {}",
        s.label,
        s.data.display(),
        s.z,
        if s.tracer.is_empty() { "not stated" } else { &s.tracer },
        s.covariance
            .as_ref()
            .map_or(", diagonal errors".into(), |c| format!(
                ", covariance {}",
                c.display()
            )),
        s.n_mocks
            .map_or(String::new(), |n| format!(" from {n} mocks (Hartlap)")),
        s.ells,
        s.k_min,
        s.k_max,
        s.ell_ranges
            .iter()
            .map(|(l, a, b)| format!(" (l = {l}: within [{a}, {b}])"))
            .collect::<String>(),
        s.free.join(","),
        list_or_none(&s.marginalise),
        list_or_none(
            &request
                .priors
                .iter()
                .map(|p| format!("{}: {}", p.name, p.shape))
                .collect::<Vec<_>>()
        ),
        describe_start(&request),
    )];
    if let Some(line) = request.basis.describe() {
        description.push(format!("data set {}: {line}", s.label));
    }
    if let Some((_, line)) = &block {
        description.push(format!("data set {}: {line}", s.label));
    }
    if let Some(d) = ap {
        description.push(format!(
            "data set {}: measured with apar = {}, aperp = {}",
            s.label, d.apar, d.aperp
        ));
    }
    if let Some(o) = &observation {
        description.extend(
            o.description()
                .iter()
                .chain([&crate::fit::galaxy::OBSERVATION_IN_FITS.to_string()])
                .map(|l| format!("data set {}: {l}", s.label)),
        );
    }
    description.extend(
        prepared
            .description
            .iter()
            .map(|l| format!("data set {}: {l}", s.label)),
    );
    let template = Template {
        sigma8_z: prepared.spectrum.sigma8(),
        z: s.z,
        cosmology: Some(cosmology),
    };
    Ok(Loaded {
        data,
        observation,
        plan,
        terms,
        request,
        template,
        description,
        block: block.map(|b| b.0),
    })
}

/// `a,b,c` or `none`.
fn list_or_none(v: &[String]) -> String {
    if v.is_empty() {
        "none".into()
    } else {
        v.join(", ")
    }
}

/// The start values of the free parameters of `request`.
fn describe_start(request: &GalaxyFitRequest) -> String {
    request
        .free
        .iter()
        .filter_map(|n| request.start.get(n).map(|v| format!("{n} = {v}")))
        .collect::<Vec<_>>()
        .join(", ")
}

/// The joint fit of `analysis`: a row per data set (`set` its 1-based number, `z`, then the columns
/// of [`super::ept_fit_table`] for that set at the joint best fit: a shared parameter has the same
/// value and error in every row). The header states every data set, the sharing and the search.
///
/// # Errors
/// As [`fit_joint`]; each data set's loading errors name the analysis file and the set.
pub fn joint_fit_table(
    analysis: &Analysis,
    inputs: &Inputs,
    header: Vec<String>,
) -> Result<(Table, JointFit)> {
    let origin = &analysis.origin;
    let loaded = analysis
        .sets
        .iter()
        .map(|s| load(s, origin, inputs))
        .collect::<Result<Vec<_>>>()?;
    let sets = data_sets(analysis, &loaded);
    let (shared, sharing) = shared_of(analysis, &sets);
    let fit = fit_joint(&sets, &shared, &analysis.search).map_err(|e| Error::InvalidChoice {
        what: origin.clone(),
        reason: e.to_string(),
    })?;
    let mut h = header;
    h.push(format!(
        "joint fit of ept to {} data set(s) of {origin}: -2 ln L = the sum of the sets' (independent \
         covariances; each set's linear parameters {} with its own ln det F); shared parameters ({sharing}): {}; \
         every other free parameter is fitted per set; joint free parameters: {}",
        sets.len(),
        if analysis.search.linear == Linear::Profiled {
            "profiled"
        } else {
            "marginalised analytically"
        },
        list_or_none(&shared),
        fit.names.join(", ")
    ));
    for l in &loaded {
        h.extend(l.terms.describe_source());
        h.extend(l.description.iter().cloned());
    }
    h.push(format!(
        "joint: points {}, chi2 {}, -2 ln L {} (the sums over the sets; each row's chi2 and \
         minus_2_ln_L are its set's term)",
        fit.points, fit.chi2, fit.minus_two_log_l
    ));
    h.push(format!(
        "minimiser: bounded quasi-Newton ({}) from {} starts (seed {}), the lowest minimum taken; \
         errors sqrt(diag 2 H^-1) of the joint -2 ln L (differences of its gradient, steps of \
         {HESSIAN_STEP} sigma){}",
        super::ept_fit::gradient_source(fit.sets.iter().map(|f| f.exact_gradient)),
        analysis.search.starts,
        analysis.search.seed,
        if analysis.search.profile_check {
            format!(
                ", checked by the profile likelihood (the half-width where they differ by more \
                 than 10%, sqrt(delta) to {CROSSING_TOLERANCE})"
            )
        } else {
            ", not checked by the profile likelihood".into()
        }
    ));
    h.push(
        "derived (per set): fsigma8 = f sigma8_z with the set's sigma8_z, alpha_iso, alpha_ap, \
         DM_over_DH, DV_over_rd with a distortion; errors propagated with the joint Hessian's \
         correlations"
            .into(),
    );
    let mut t = Table::new(h);
    t.push("set", "1", (1..=sets.len()).map(|i| i as f64).collect());
    t.push("z", "1", analysis.sets.iter().map(|s| s.z).collect());
    let rows: Vec<Row> = fit
        .sets
        .iter()
        .zip(&loaded)
        .map(|(f, l)| Row {
            fit: f,
            request: &l.request,
            template: Some(&l.template),
        })
        .collect();
    row_columns(&mut t, &rows);
    Ok((t, fit))
}
