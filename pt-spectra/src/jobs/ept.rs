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
    /// A distortion replacing the plan's (on a plan built with an AP range, [`ept_plan`]'s
    /// `free_ap`); `None`: the plan's own.
    pub ap: Option<Distortion>,
}

/// The range of α∥, α⊥ of fits that free them: [`AP_FIT_RANGE`].0 … .1.
pub const AP_FIT_RANGE: (f64, f64) = (0.8, 1.25);

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
    if params.values[11].is_nan() {
        params.values[11] = prepared.growth_rate;
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
    header.push(if settings.ir {
        "IR resummation: no-wiggle P by velocileptors' Savitzky-Golay filter (quartic, ln 7 in ln k), \
         wiggles damped by exp(-k^2 Sigma^2 (1 + f (2 + f) mu^2)), Sigma^2 = (1/6pi^2) int P_nw (1 - \
         j0(q 110 Mpc/h)) dq, (1 + k^2 Sigma^2(mu)) on the linear wiggles; --no-ir for plain SPT"
            .into()
    } else {
        "no IR resummation (--no-ir): plain 1-loop SPT in redshift space".into()
    });
    if let Some(d) = ap {
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
    header.extend(terms.describe_source());
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

/// `fit --rsd ept`: one best fit per k_max of `request` (its k_max replaced), a row each: `k_max
/// points chi2 minus_2_ln_L` and, per parameter, its best value and (free or marginalised) `err_<p>`.
///
/// # Errors
/// As [`crate::fit::galaxy::fit_galaxy`].
pub fn ept_fit_table(
    plan: &EptPlan,
    terms: &EptTerms,
    data: &crate::fit::MultipoleData,
    request: &crate::fit::galaxy::GalaxyFitRequest,
    k_max: &[f64],
    header: Vec<String>,
    observation: Option<&crate::survey::observe::Observation>,
) -> Result<Table> {
    use crate::fit::galaxy::fit_galaxy_observed;
    let mut fits = Vec::with_capacity(k_max.len());
    for &k in k_max {
        let mut r = request.clone();
        r.k_max = k;
        fits.push(fit_galaxy_observed(plan, terms, data, &r, observation)?);
    }
    let mut header = header;
    header.extend(terms.describe_source());
    if let Some(o) = observation {
        header.extend(o.description().iter().cloned());
    }
    if let Some(d) = request.ap {
        header.push(format!(
            "Alcock-Paczynski: the data measured with apar = {}, aperp = {}{}",
            d.apar,
            d.aperp,
            if request.free.iter().any(|n| n == "apar" || n == "aperp") {
                format!(
                    " (start values; free ones searched in [{}, {}])",
                    AP_FIT_RANGE.0, AP_FIT_RANGE.1
                )
            } else {
                String::new()
            }
        ));
    }
    let xi = observation.is_some_and(crate::survey::observe::Observation::is_xi);
    let (var, unit_of_var) = if xi { ("s", "Mpc/h") } else { ("k", "h/Mpc") };
    let ranges: String = request
        .ell_ranges
        .iter()
        .map(|(l, a, b)| format!(" (l = {l}: within [{a}, {b}] {unit_of_var})"))
        .collect();
    header.push(format!(
        "fit of ept to {} multipoles {:?} for {var} in [{}, {var}_max] {unit_of_var}{ranges}: free {} (Gaussian errors from the \
         Hessian of -2 ln L), marginalised analytically {} (errors sqrt((F^-1)_ii) at the best fit), \
         priors {}; -2 ln L = chi2 + priors + ln det F",
        if xi { "correlation-function" } else { "power-spectrum" },
        request.ells,
        request.k_min,
        request.free.join(","),
        if request.marginalise.is_empty() {
            "none".to_string()
        } else {
            request.marginalise.join(",")
        },
        if request.priors.is_empty() {
            "none".to_string()
        } else {
            request
                .priors
                .iter()
                .map(|p| format!("{}: N({}, {}^2)", p.name, p.mean, p.sigma))
                .collect::<Vec<_>>()
                .join(", ")
        }
    ));
    let mut t = Table::new(header);
    if xi {
        t.push("s_max", "Mpc/h", k_max.to_vec());
    } else {
        t.push("k_max", WAVENUMBER, k_max.to_vec());
    }
    t.push(
        "points",
        "1",
        fits.iter().map(|f| f.points as f64).collect(),
    );
    t.push("chi2", "1", fits.iter().map(|f| f.chi2).collect());
    t.push(
        "minus_2_ln_L",
        "1",
        fits.iter().map(|f| f.minus_two_log_l).collect(),
    );
    let ap_names: &[&str] = if request.ap.is_some() {
        &crate::fit::galaxy::AP_NAMES
    } else {
        &[]
    };
    let value = |i: usize, f: &crate::fit::galaxy::GalaxyFit| match (i.checked_sub(12), f.ap) {
        (None, _) => f.best.values[i],
        (Some(0), Some(d)) => d.apar,
        (Some(_), Some(d)) => d.aperp,
        (Some(_), None) => f64::NAN,
    };
    for (i, name) in PARAM_NAMES.iter().chain(ap_names).enumerate() {
        t.push(
            *name,
            unit(name),
            fits.iter().map(|f| value(i, f)).collect(),
        );
        let err = |f: &crate::fit::galaxy::GalaxyFit| {
            if let Some(j) = request.free.iter().position(|n| n == name) {
                Some(f.errors[j])
            } else {
                request
                    .marginalise
                    .iter()
                    .position(|n| n == name)
                    .map(|j| f.marginalised_errors[j])
            }
        };
        if fits.first().and_then(err).is_some() {
            let values: Vec<f64> = fits.iter().map(|f| err(f).unwrap_or(f64::NAN)).collect();
            t.push_undefined_as(
                format!("err_{name}"),
                unit(name),
                values,
                "NaN where the Hessian of -2 ln L is not positive definite",
            );
        }
    }
    Ok(t)
}

/// The unit of an ept parameter.
fn unit(name: &str) -> &'static str {
    match name {
        "alpha0" | "alpha2" | "alpha4" | "alpha6" => "(Mpc/h)^2",
        "sn" => "(Mpc/h)^3",
        "sn2" => "(Mpc/h)^5",
        "sn4" => "(Mpc/h)^7",
        _ => "1",
    }
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
