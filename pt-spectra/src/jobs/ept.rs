//! `rsd --rsd ept`: the multipoles of the galaxy model ([`crate::rsd::ept`]) as a table.

use super::{describe_inputs, VERSION};
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
}

/// The plan of a request on the output `k`, with IR resummation `ir` and the distortion `ap`.
///
/// # Errors
/// As [`EptPlan::new`].
pub fn ept_plan(
    k: &[f64],
    ir: bool,
    ap: Option<Distortion>,
    precision: &Precision,
) -> Result<EptPlan> {
    EptPlan::new(k, crate::rsd::ept::EptSettings { ir, ap }, precision)
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
    let terms = plan.terms(&prepared.spectrum)?;
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
    if params.values[11].is_nan() {
        params.values[11] = prepared.growth_rate;
    }
    let m = plan.multipoles(terms, &params, &request.ells)?;
    let settings = plan.settings();
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
    header.push(if settings.ir {
        "IR resummation: no-wiggle P by velocileptors' Savitzky-Golay filter (quartic, ln 7 in ln k), \
         wiggles damped by exp(-k^2 Sigma^2 (1 + f (2 + f) mu^2)), Sigma^2 = (1/6pi^2) int P_nw (1 - \
         j0(q 110 Mpc/h)) dq, (1 + k^2 Sigma^2(mu)) on the linear wiggles; --no-ir for plain SPT"
            .into()
    } else {
        "no IR resummation (--no-ir): plain 1-loop SPT in redshift space".into()
    });
    if let Some(d) = settings.ap {
        header.push(format!(
            "Alcock-Paczynski: apar = {}, aperp = {}; the model on the log grid of the AP projection \
             (interpolated cubically in ln k), {}-point Gauss-Legendre in mu (error from half as many); \
             wide-angle terms neglected",
            d.apar,
            d.aperp,
            crate::rsd::ept::MU_NODES
        ));
    }
    header.extend(describe_inputs(prepared, precision));
    let mut t = Table::new(header);
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
