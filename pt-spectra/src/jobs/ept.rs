//! `rsd --rsd ept`: the multipoles of the galaxy model ([`crate::rsd::ept`]) as a table.

use super::{describe_inputs, VERSION};
use crate::bias::BiasConvention;
use crate::error::Result;
use crate::output::{Table, POWER, WAVENUMBER};
use crate::precision::Precision;
use crate::rsd::ap::Distortion;
use crate::rsd::ept::{EptParams, EptPlan, EptTerms, PARAM_NAMES};
use crate::setup::Prepared;

/// What `rsd --rsd ept` computes besides the plan: the parameters (f NaN: f(z) of the cosmology)
/// and the multipoles.
#[derive(Debug, Clone, PartialEq)]
pub struct EptRequest {
    /// The model's parameters; a NaN f means f(z) of the cosmology.
    pub params: EptParams,
    /// Multipoles to compute (even, ≤ 8).
    pub ells: Vec<usize>,
    /// A distortion replacing the plan's (on a plan built with an AP range, [`ept_plan`]'s
    /// `free_ap`); `None`: the plan's own.
    pub ap: Option<Distortion>,
    /// The convention the user wrote the bias in (the header then gives it as written too); the
    /// params are velocileptors' ([`crate::bias`]).
    pub bias_given: BiasConvention,
}

pub use crate::rsd::ap::AP_FIT_RANGE;

/// The plan of a request on the output `k`, with IR resummation `ir`, the distortion `ap`, and with
/// `free_ap` the internal grid of every α∥, α⊥ in `AP_FIT_RANGE` (0.8 … 1.25).
///
/// The loop terms come from basis tensors as `precision.two_loop` says ([`EptPlan::with_basis`]:
/// `basis` reads or builds them in `store`, reporting to `progress`; `auto` uses cached ones).
///
/// # Errors
/// As [`EptPlan::new`] and [`EptPlan::with_basis`].
pub fn ept_plan(
    k: &[f64],
    ir: bool,
    ap: Option<Distortion>,
    free_ap: bool,
    precision: &Precision,
    store: &crate::store::TableStore,
    progress: &dyn crate::progress::Progress,
) -> Result<EptPlan> {
    EptPlan::new(
        k,
        crate::rsd::ept::EptSettings {
            ir,
            ap,
            ap_range: free_ap.then_some(AP_FIT_RANGE),
            loop_range: None,
        },
        precision,
    )?
    .with_basis(store, progress)
}

/// The multipole table of `request` on the prepared spectrum: columns `k P<l>… err_P<l>…`.
///
/// # Errors
/// As [`EptPlan::terms`] and [`ept_table_from_terms`].
pub fn ept_table(
    plan: &EptPlan,
    request: &EptRequest,
    prepared: &Prepared,
    precision: &Precision,
) -> Result<Table> {
    let terms = plan.terms(prepared.tracer_spectrum())?;
    ept_table_from_terms(plan, &terms, request, prepared, precision)
}

/// [`ept_table`] from terms computed before: the cheap step when only parameters change.
///
/// # Errors
/// As [`EptPlan::multipoles`].
pub fn ept_table_from_terms(
    plan: &EptPlan,
    terms: &EptTerms,
    request: &EptRequest,
    prepared: &Prepared,
    precision: &Precision,
) -> Result<Table> {
    let mut params = request.params;
    if params.f().is_nan() {
        params.set_f(prepared.growth_rate);
    }
    let settings = plan.settings();
    let ap = request.ap.or(settings.ap);
    let m = plan.multipoles_at(terms, &params, &request.ells, ap)?;
    let values: Vec<String> = PARAM_NAMES
        .iter()
        .zip(params.values)
        .map(|(n, v)| format!("{n} = {v}"))
        .collect();
    let mut header = vec![
        format!(
            "pt-spectra {VERSION} rsd: ept (1-loop Eulerian galaxy model in redshift space, velocileptors' \
             REPT conventions), z = {}, {}",
            prepared.z,
            values.join(", ")
        ),
        "P(k,mu) = 1-loop SPT of b1 delta + (b2/2) delta^2 + bs s^2 + b3 O3 (b3 = 2 b3nl of FAST-PT) in \
         redshift space + (alpha0 + alpha2 mu^2 + alpha4 mu^4 + alpha6 mu^6) k^2 P_lin + sn + sn2 k^2 \
         mu^2 + sn4 k^4 mu^4; k->0 constants of the b2, bs terms not subtracted"
            .into(),
    ];
    if request.bias_given != BiasConvention::Velocileptors {
        header.push(params.bias().describe(request.bias_given));
    }
    header.push(if settings.ir {
        format!(
            "IR resummation: no-wiggle P by velocileptors' Savitzky-Golay filter (quartic, ln 7 in ln k), \
             wiggles damped by exp(-k^2 Sigma^2 (1 + f (2 + f) mu^2)), Sigma^2 = (1/6pi^2) int P_nw (1 - \
             j0(q {} Mpc/h)) dq, (1 + k^2 Sigma^2(mu)) on the linear wiggles; --no-ir for plain SPT",
            crate::rsd::ept::R_BAO
        )
    } else {
        "no IR resummation (--no-ir): plain 1-loop SPT in redshift space".into()
    });
    if let Some(d) = ap {
        header.push(format!(
            "Alcock-Paczynski: apar = {}, aperp = {}; the model on the log grid of the AP projection \
             (a cubic B-spline in ln k), {}-point Gauss-Legendre in mu (error from half as many); \
             wide-angle terms neglected",
            d.apar,
            d.aperp,
            crate::rsd::ept::MU_NODES
        ));
    }
    header.extend(describe_inputs(prepared, precision));
    header.extend(terms.describe_source());
    let mut t = Table::new(header);
    t.methods.push(terms.method_note());
    t.push("k", WAVENUMBER, plan.k().to_vec());
    for (l, p) in request.ells.iter().zip(&m) {
        t.push(format!("P{l}"), POWER, p.iter().map(|e| e.value).collect());
    }
    for (l, p) in request.ells.iter().zip(&m) {
        t.push(
            format!("err_P{l}"),
            POWER,
            p.iter().map(|e| e.error).collect(),
        );
    }
    Ok(t)
}

/// [`ept_table_from_terms`] through a window and bins (`observation`; the plan built on its
/// [`Observation::k_model`](crate::survey::observe::Observation::k_model)): columns `k P<l>… err_P<l>…` at
/// the observation's output k. The model's own error estimates are carried through the chain (applied
/// to it as to the values, in absolute value) and added to the chain's.
///
/// # Errors
/// As [`EptPlan::multipoles`] and [`crate::survey::observe::Observation::apply`];
/// [`crate::error::Error::InvalidChoice`] if the plan is not on the observation's model k.
pub fn ept_observed_table(
    plan: &EptPlan,
    terms: &EptTerms,
    request: &EptRequest,
    prepared: &Prepared,
    precision: &Precision,
    observation: &crate::survey::observe::Observation,
) -> Result<Table> {
    if plan.k() != observation.k_model() {
        return Err(crate::error::Error::InvalidChoice {
            what: "the ept plan of a windowed or binned table".into(),
            reason: "must be built on the observation's model k".into(),
        });
    }
    let mut model_request = request.clone();
    model_request.ells = observation.model_ells().to_vec();
    let model = ept_table_from_terms(plan, terms, &model_request, prepared, precision)?;
    super::observed_table(&model, observation)
}
