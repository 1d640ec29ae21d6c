//! `fit --rsd ept`: the best fits of the galaxy model versus k_max, and the profile likelihood of a
//! parameter, as tables.

use super::ept::AP_FIT_RANGE;
use crate::error::{Error, Result};
use crate::fit::bounded::{AGREEMENT, EXPECTED_DECREASE};
use crate::fit::galaxy::search::{CROSSING_TOLERANCE, HESSIAN_STEP, PROFILE_AGREEMENT};
use crate::fit::galaxy::{
    derived, fit_galaxy_search, profile_galaxy, slot_names, Derived, FitBasis, GalaxyFit,
    GalaxyFitRequest, Linear, Prior, ProfileGrid, Search, Template,
};
use crate::fit::MultipoleData;
use crate::output::{Table, WAVENUMBER};
use crate::rsd::ept::physical::{PhysicalBasis, DEFAULT_F_SAT, DEFAULT_SIGMA_V};
use crate::rsd::ept::{EptPlan, EptTerms, PARAM_NAMES};
use crate::survey::observe::Observation;

/// What a fit's table needs besides the plan, data and request.
#[derive(Clone)]
pub struct FitContext<'a> {
    /// The window and bins between the model and the data, if any.
    pub observation: Option<&'a Observation>,
    /// How the minimum is searched for.
    pub search: Search,
    /// The template of the derived parameters (fσ8, …); `None`: no derived columns.
    pub template: Option<Template>,
    /// The caller's header lines (the command, the inputs).
    pub header: Vec<String>,
}

/// The parameter basis of a fit by name: `velocileptors` (the model's own), `classpt` (CLASS-PT's
/// bias b1, b2, bG2, bGamma3: [`FitBasis::ClassPt`]) or `desi` (the DESI DR1 physical basis at
/// σ₈(z) `sigma8` of the template, number density `n_bar` [(h/Mpc)³], satellites (f_sat, σ_v
/// [Mpc/h]), default desilike's 0.1 and 5). `desi_priors`: whether the DESI priors are asked for
/// (only in that basis).
///
/// # Errors
/// [`Error::InvalidChoice`] for another name, `desi` without `n_bar`, or `n_bar`, satellites or
/// the DESI priors with another basis; as [`PhysicalBasis::new`].
pub fn fit_basis(
    name: &str,
    sigma8: f64,
    n_bar: Option<f64>,
    satellites: Option<(f64, f64)>,
    desi_priors: bool,
) -> Result<FitBasis> {
    let bad = |reason: &str| Error::InvalidChoice {
        what: format!("parameter basis `{name}`"),
        reason: reason.into(),
    };
    match name {
        "velocileptors" | "classpt" => {
            if n_bar.is_some() || satellites.is_some() || desi_priors {
                return Err(bad(
                    "n_bar (--n-bar), the satellites (--satellites) and the DESI priors \
                     (--desi-priors) belong to the basis desi",
                ));
            }
            Ok(if name == "classpt" {
                FitBasis::ClassPt
            } else {
                FitBasis::Velocileptors
            })
        }
        "desi" => {
            let n_bar = n_bar.ok_or_else(|| {
                bad("the basis desi needs n_bar (--n-bar): the unit 1/n_bar of sn0p, sn2p, sn4p")
            })?;
            let (f_sat, sigma_v) = satellites.unwrap_or((DEFAULT_F_SAT, DEFAULT_SIGMA_V));
            Ok(FitBasis::Desi(PhysicalBasis::new(
                sigma8, n_bar, f_sat, sigma_v,
            )?))
        }
        _ => Err(bad("valid: velocileptors, classpt, desi")),
    }
}

/// Adds the DESI DR1 priors ([`crate::fit::galaxy::desi_priors`]) of the `free` and `marginalise`d
/// parameters that have none in `priors`.
pub fn add_desi_priors(priors: &mut Vec<Prior>, free: &[String], marginalise: &[String]) {
    for p in crate::fit::galaxy::desi_priors() {
        let used = free.contains(&p.name) || marginalise.contains(&p.name);
        if used && !priors.iter().any(|q| q.name == p.name) {
            priors.push(p);
        }
    }
}

/// The header lines of the search and the errors.
fn search_lines(
    request: &GalaxyFitRequest,
    fits: &[GalaxyFit],
    context: &FitContext,
) -> Vec<String> {
    let s = &context.search;
    let mut lines = vec![format!(
        "minimiser: bounded quasi-Newton (BFGS, {}) from {} starts (the \
         start given, then draws from the priors or the start box, seed {}), converged to an \
         expected decrease < {EXPECTED_DECREASE:e}; the lowest minimum is taken; starts_agree: the \
         starts within {AGREEMENT} of it in -2 ln L, starts_spread: the highest start's minimum minus \
         the lowest",
        gradient_source(fits.iter().map(|f| f.exact_gradient)),
        s.starts,
        s.seed
    )];
    lines.push(if s.profile_check {
        format!(
            "errors of the free parameters: err_<p>_hessian = sqrt(diag 2 H^-1), H the Hessian of -2 ln \
             L by central differences (of its exact gradient where the minimiser has it, else of -2 ln L) \
             of {HESSIAN_STEP} conditional sigma; <p>_lo, <p>_hi: where the \
             profile -2 ln L (the others re-minimised) is 1 above the minimum (sqrt(delta) to \
             {CROSSING_TOLERANCE}); err_<p> is the Hessian's unless the profile's half-width differs \
             from it by more than {:.0}% (err_<p>_from_profile = 1: then the half-width)",
            100.0 * PROFILE_AGREEMENT
        )
    } else {
        "errors of the free parameters: sqrt(diag 2 H^-1) (Gaussian; the profile check is off)".into()
    });
    if s.linear == Linear::Profiled {
        lines.push(
            "linear parameters profiled (at their best values, no ln det F term), not marginalised"
                .into(),
        );
    }
    if let Some(t) = &context.template {
        lines.push(format!(
            "derived: fsigma8 = f sigma8_z, sigma8_z = {} (the template's linear matter spectrum at z = \
             {}); errors propagated linearly with the Hessian's correlations{}",
            t.sigma8_z,
            t.z,
            if request.ap.is_some() {
                "; alpha_iso = apar^(1/3) aperp^(2/3), alpha_ap = apar/aperp (relative to the \
                 fiducial the data were measured in); DM_over_DH = D_M/D_H and DV_over_rd = D_V/r_d \
                 from the template's distances times the fitted alphas over their start values, \
                 r_d of the template by Aubourg et al. 2015 eq. 16"
            } else {
                " (no distortion: no alpha or distance columns)"
            }
        ));
    }
    lines
}

/// `fit --rsd ept`: one best fit per k_max of `request` (its k_max replaced), a row each: `k_max
/// points chi2 minus_2_ln_L starts starts_agree starts_spread`; per parameter its best value and (free
/// or marginalised) `err_<p>`; per free parameter `err_<p>_hessian <p>_lo <p>_hi
/// err_<p>_from_profile`; the derived parameters and their errors ([`crate::fit::galaxy::derived`]).
///
/// Returns the table and the fits.
///
/// # Errors
/// As [`crate::fit::galaxy::fit_galaxy_search`].
pub fn ept_fit_table(
    plan: &EptPlan,
    terms: &EptTerms,
    data: &MultipoleData,
    request: &GalaxyFitRequest,
    k_max: &[f64],
    context: &FitContext,
) -> Result<(Table, Vec<GalaxyFit>)> {
    let mut fits = Vec::with_capacity(k_max.len());
    for &k in k_max {
        let mut r = request.clone();
        r.k_max = k;
        fits.push(fit_galaxy_search(
            plan,
            terms,
            data,
            &r,
            context.observation,
            &context.search,
        )?);
    }
    let mut t = Table::new(fit_header(terms, request, &fits, context));
    if context.observation.is_some_and(Observation::is_xi) {
        t.push("s_max", "Mpc/h", k_max.to_vec());
    } else {
        t.push("k_max", WAVENUMBER, k_max.to_vec());
    }
    fit_columns(&mut t, &fits, request, context);
    Ok((t, fits))
}

/// `fit --rsd ept --model-out`: `k`, the data `P<l>_data err_P<l>_data` and the best-fit model
/// `P<l>_kmax<K>` of each fit (of [`ept_fit_table`], at `k_max`; the marginalised parameters at â;
/// through the observation, if any) on every k of the data.
///
/// # Errors
/// As [`EptPlan::multipole_values_at`] and [`Observation::apply_values`].
pub fn ept_model_table(
    plan: &EptPlan,
    terms: &EptTerms,
    data: &MultipoleData,
    request: &GalaxyFitRequest,
    fits: &[GalaxyFit],
    k_max: &[f64],
    context: &FitContext,
) -> Result<Table> {
    let mut header = fit_header(terms, request, fits, context);
    header.push(
        "P<l>_data, err_P<l>_data: the data (sqrt of the covariance's diagonal); P<l>_kmax<K>: the \
         best-fit model of the fit up to k_max = K (marginalised parameters at their best values), \
         through the window and bins if any, on every k"
            .into(),
    );
    let mut t = Table::new(header);
    t.push("k", WAVENUMBER, data.k.clone());
    for &l in &request.ells {
        if let Some(j) = data.ells.iter().position(|&d| d == l) {
            t.push(
                format!("P{l}_data"),
                crate::output::POWER,
                data.values[j].clone(),
            );
            t.push(
                format!("err_P{l}_data"),
                crate::output::POWER,
                data.sigma[j].clone(),
            );
        }
    }
    for (fit, &k) in fits.iter().zip(k_max) {
        let m = match context.observation {
            None => plan.multipole_values_at(terms, &fit.best, &request.ells, fit.ap)?,
            Some(o) => {
                let model = plan.multipole_values_at(terms, &fit.best, o.model_ells(), fit.ap)?;
                o.apply_values(&model)?
            }
        };
        let suffix = format!("{k:.4}");
        let suffix = suffix.trim_end_matches('0').trim_end_matches('.');
        for (l, p) in request.ells.iter().zip(m) {
            t.push(format!("P{l}_kmax{suffix}"), crate::output::POWER, p);
        }
    }
    Ok(t)
}

/// The header of a fit's table: the caller's lines, the terms' source, the observation, the AP,
/// the fitted data, the search and the errors.
fn fit_header(
    terms: &EptTerms,
    request: &GalaxyFitRequest,
    fits: &[GalaxyFit],
    context: &FitContext,
) -> Vec<String> {
    let observation = context.observation;
    let mut header = context.header.clone();
    header.extend(terms.describe_source());
    if let Some(o) = observation {
        header.extend(o.description().iter().cloned());
        header.push(crate::fit::galaxy::OBSERVATION_IN_FITS.into());
    }
    let xi = observation.is_some_and(Observation::is_xi);
    header.extend(request.basis.describe());
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
    let (var, unit_of_var) = if xi { ("s", "Mpc/h") } else { ("k", "h/Mpc") };
    let ranges: String = request
        .ell_ranges
        .iter()
        .map(|(l, a, b)| format!(" (l = {l}: within [{a}, {b}] {unit_of_var})"))
        .collect();
    header.push(format!(
        "fit of ept to {} multipoles {:?} for {var} in [{}, {var}_max] {unit_of_var}{ranges}: free {}, marginalised analytically {} (errors sqrt((F^-1)_ii) at the best fit), \
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
                .map(|p| format!("{}: {}", p.name, p.shape))
                .collect::<Vec<_>>()
                .join(", ")
        }
    ));
    header.extend(search_lines(request, fits, context));
    header
}

/// The header's words for fits without their exact gradient: those with a block (e.g. "… with a
/// bispectrum", the registered kinds' names).
static NO_EXACT_GRADIENT: std::sync::LazyLock<String> = std::sync::LazyLock::new(|| {
    format!(
        "central-difference gradients (no exact gradient with a {})",
        crate::blocks::names().join(" or a ")
    )
});

/// How the minimiser's gradients of the fits `exact` (one per fit) were made, for a header.
pub(super) fn gradient_source(exact: impl Iterator<Item = bool>) -> &'static str {
    let (mut any, mut all) = (false, true);
    for e in exact {
        any |= e;
        all &= e;
    }
    match (any, all) {
        (true, true) => {
            "exact gradients: the model's derivatives in f, apar, aperp and the bias, counterterm \
             and stochastic parameters, the marginalised ones through the envelope theorem and \
             d ln det F"
        }
        (false, _) => NO_EXACT_GRADIENT.as_str(),
        (true, false) => "exact gradients for some fits, central differences for the others",
    }
}

/// One row of a fit table: a fit, its request and the template of its derived parameters.
#[derive(Clone, Copy)]
pub(super) struct Row<'a> {
    pub(super) fit: &'a GalaxyFit,
    pub(super) request: &'a GalaxyFitRequest,
    pub(super) template: Option<&'a Template>,
}

/// The columns of `fits` after the first (k_max or s_max).
fn fit_columns(
    t: &mut Table,
    fits: &[GalaxyFit],
    request: &GalaxyFitRequest,
    context: &FitContext,
) {
    let rows: Vec<Row> = fits
        .iter()
        .map(|fit| Row {
            fit,
            request,
            template: context.template.as_ref(),
        })
        .collect();
    row_columns(t, &rows);
}

/// The columns of `rows` (each its own request: a parameter free in one row and not another has
/// NaN errors in the other; a derived parameter a row does not have is NaN there).
pub(super) fn row_columns(t: &mut Table, rows: &[Row]) {
    t.push(
        "points",
        "1",
        rows.iter().map(|r| r.fit.points as f64).collect(),
    );
    t.push("chi2", "1", rows.iter().map(|r| r.fit.chi2).collect());
    t.push(
        "minus_2_ln_L",
        "1",
        rows.iter().map(|r| r.fit.minus_two_log_l).collect(),
    );
    let ap_names: &[&str] = if rows.iter().any(|r| r.request.ap.is_some()) {
        &crate::fit::galaxy::AP_NAMES
    } else {
        &[]
    };
    // In another basis its parameters (with their errors), then the model's they map to.
    let basis = rows
        .iter()
        .map(|r| r.request.basis)
        .find(|b| !b.is_model())
        .unwrap_or_default();
    let physical = matches!(basis, FitBasis::Desi(_));
    // with a block, its own parameters after the distortion's (the first row's block's)
    let b_names: &[&str] = rows
        .iter()
        .find_map(|r| r.fit.block.as_ref())
        .map_or(&[], |b| b.names);
    let value = |i: usize, f: &GalaxyFit| match (i.checked_sub(12), f.ap) {
        (Some(b), _) if b >= 2 => f
            .block
            .as_ref()
            .and_then(|v| {
                let n = b_names.get(b - 2)?;
                let j = v.names.iter().position(|m| m == n)?;
                v.values.get(j).copied()
            })
            .unwrap_or(f64::NAN),
        (None, _) if !basis.is_model() => f.in_basis.map_or(f64::NAN, |v| v[i]),
        (None, _) => f.best.values[i],
        (Some(0), Some(d)) => d.apar,
        (Some(_), Some(d)) => d.aperp,
        (Some(_), None) => f64::NAN,
    };
    let names = slot_names(&basis)
        .iter()
        .filter(|&&n| !(physical && n == "alpha6p"));
    // the columns in slot order: the model's parameters, α∥, α⊥ (if any), the block's (if any)
    let ap_slots = [12, 13];
    let b_slots = 14..14 + b_names.len();
    let model_slots = (0..12).filter(|&i| !(physical && i == 7));
    let slots = model_slots
        .chain(ap_slots.into_iter().take(ap_names.len()))
        .chain(b_slots);
    for (i, name) in slots.zip(names.chain(ap_names).chain(b_names)) {
        t.push(
            *name,
            unit(name),
            rows.iter().map(|r| value(i, r.fit)).collect(),
        );
        let free = |r: &Row| r.request.free.iter().position(|n| n == name);
        let err = |r: &Row| {
            if let Some(j) = free(r) {
                Some(r.fit.errors[j])
            } else {
                r.request
                    .marginalise
                    .iter()
                    .position(|n| n == name)
                    .map(|j| r.fit.marginalised_errors[j])
            }
        };
        if rows.iter().any(|r| err(r).is_some()) {
            let values: Vec<f64> = rows.iter().map(|r| err(r).unwrap_or(f64::NAN)).collect();
            t.push_undefined_as(
                format!("err_{name}"),
                unit(name),
                values,
                "NaN where the Hessian of -2 ln L is not positive definite and the profile has \
                 no crossing, or where the parameter is neither free nor marginalised",
            );
        }
        if rows.iter().any(|r| free(r).is_some()) {
            let js: Vec<Option<usize>> = rows.iter().map(free).collect();
            free_columns(t, rows, name, &js);
        }
    }
    if !basis.is_model() {
        // the model's parameters that differ from the basis's slot of that index; a name the basis
        // also uses (CLASS-PT's b2) gets the suffix _velocileptors
        let unit_rows = basis.jacobian(&[1.0; 12]);
        for (i, name) in PARAM_NAMES.iter().enumerate().take(11) {
            let same = (0..12).all(|j| unit_rows[i][j] == f64::from(u8::from(i == j)));
            if basis.names()[i] == *name && same {
                continue;
            }
            let column = if basis.names().contains(name) {
                format!("{name}_velocileptors")
            } else {
                (*name).to_string()
            };
            t.push(
                column,
                unit(name),
                rows.iter().map(|r| r.fit.best.values[i]).collect(),
            );
        }
    }
    let count = |g: fn(&GalaxyFit) -> f64| rows.iter().map(|r| g(r.fit)).collect();
    t.push("starts", "1", count(|f| f.starts as f64));
    t.push("starts_agree", "1", count(|f| f.agree as f64));
    t.push("starts_spread", "1", count(|f| f.spread));
    let all: Vec<Vec<Derived>> = rows
        .iter()
        .map(|r| r.template.map_or(vec![], |t| derived(r.fit, r.request, t)))
        .collect();
    let mut names: Vec<&'static str> = Vec::new();
    for d in all.iter().flatten() {
        if !names.contains(&d.name) {
            names.push(d.name);
        }
    }
    for name in names {
        let find = |d: &[Derived]| d.iter().find(|x| x.name == name).cloned();
        let of = |g: fn(&Derived) -> f64| -> Vec<f64> {
            all.iter()
                .map(|d| find(d).map_or(f64::NAN, |x| g(&x)))
                .collect()
        };
        t.push(name, "1", of(|d| d.value));
        if name != "sigma8_z" {
            t.push(format!("err_{name}"), "1", of(|d| d.error));
        }
    }
}

/// The error columns of the free parameter `name` (the `js[r]`-th free of row r, if free there).
fn free_columns(t: &mut Table, rows: &[Row], name: &str, js: &[Option<usize>]) {
    let of = |g: &dyn Fn(&GalaxyFit, usize) -> f64| -> Vec<f64> {
        rows.iter()
            .zip(js)
            .map(|(r, j)| j.map_or(f64::NAN, |j| g(r.fit, j)))
            .collect()
    };
    t.push_undefined_as(
        format!("err_{name}_hessian"),
        unit(name),
        of(&|f, j| f.hessian_errors[j]),
        "NaN where the Hessian of -2 ln L is not positive definite (or the parameter is not free)",
    );
    let none = "NaN where the profile does not reach delta = 1 inside the parameter's bounds";
    t.push_undefined_as(
        format!("{name}_lo"),
        unit(name),
        of(&|f, j| f.intervals[j].0),
        none,
    );
    t.push_undefined_as(
        format!("{name}_hi"),
        unit(name),
        of(&|f, j| f.intervals[j].1),
        none,
    );
    t.push_undefined_as(
        format!("err_{name}_from_profile"),
        "1",
        of(&|f, j| f64::from(u8::from(f.from_profile[j]))),
        "NaN where the parameter is not free",
    );
}

/// The unit of an ept parameter or a block's own ([`crate::statistic::Kind::units`]).
fn unit(name: &str) -> &'static str {
    match name {
        "alpha0" | "alpha2" | "alpha4" | "alpha6" | "alpha0p" | "alpha2p" | "alpha4p" => {
            "(Mpc/h)^2"
        }
        "sn" => "(Mpc/h)^3",
        "sn2" => "(Mpc/h)^5",
        "sn4" => "(Mpc/h)^7",
        _ => crate::blocks::owner(name)
            .and_then(|k| k.units.get(k.index(name)?).copied())
            .unwrap_or("1"),
    }
}

/// `fit --rsd ept --profile P`: the profile likelihood of the free parameter `name` at `request`'s
/// k_max on `grid`, a row per value: `<P> minus_2_ln_L delta_minus_2_ln_L chi2` and every other
/// free parameter (and marginalised one, at â) there. The header gives the best fit and the
/// Δ(−2 ln L) = 1 interval of `name` and its Hessian error.
///
/// # Errors
/// As [`crate::fit::galaxy::profile_galaxy`].
pub fn ept_profile_table(
    plan: &EptPlan,
    terms: &EptTerms,
    data: &MultipoleData,
    request: &GalaxyFitRequest,
    context: &FitContext,
    name: &str,
    grid: &ProfileGrid,
) -> Result<Table> {
    let profile = profile_galaxy(
        plan,
        terms,
        data,
        request,
        context.observation,
        &context.search,
        name,
        grid,
    )?;
    let fit = &profile.fit;
    let j = request
        .free
        .iter()
        .position(|n| n == name)
        .expect("profile_galaxy checked that the parameter is free");
    let mut header = fit_header(terms, request, std::slice::from_ref(fit), context);
    header.push(format!(
        "profile of {name} at k_max = {}: {} points over +- {} times its error around the best fit \
         {name} = {}, -2 ln L = {}; the other free parameters re-minimised at each point{}; \
         delta_minus_2_ln_L = 1 (4) bounds the 68.3% (95.4%) interval: [{}, {}] (Hessian error {})",
        request.k_max,
        grid.points,
        grid.span,
        value_of(fit, &request.basis, name),
        fit.minus_two_log_l,
        if context.search.linear == Linear::Profiled {
            ", the linear ones profiled"
        } else if request.marginalise.is_empty() {
            ""
        } else {
            ", the linear ones marginalised analytically"
        },
        fit.intervals[j].0,
        fit.intervals[j].1,
        fit.hessian_errors[j]
    ));
    let mut t = Table::new(header);
    let points = &profile.points;
    let at = |p: &crate::fit::galaxy::ProfilePoint, n: &str| match n {
        "apar" => p.ap.map_or(f64::NAN, |d| d.apar),
        "aperp" => p.ap.map_or(f64::NAN, |d| d.aperp),
        n => match (
            p.in_basis,
            request.basis.names().iter().position(|&m| m == n),
        ) {
            (Some(v), Some(i)) => v[i],
            _ => p.best.get(n).unwrap_or(f64::NAN),
        },
    };
    t.push(name, unit(name), points.iter().map(|p| p.value).collect());
    t.push(
        "minus_2_ln_L",
        "1",
        points.iter().map(|p| p.minus_two_log_l).collect(),
    );
    t.push(
        "delta_minus_2_ln_L",
        "1",
        points
            .iter()
            .map(|p| p.minus_two_log_l - fit.minus_two_log_l)
            .collect(),
    );
    t.push("chi2", "1", points.iter().map(|p| p.chi2).collect());
    for n in request
        .free
        .iter()
        .chain(&request.marginalise)
        .filter(|n| *n != name)
    {
        t.push(
            n.as_str(),
            unit(n),
            points.iter().map(|p| at(p, n)).collect(),
        );
    }
    Ok(t)
}

/// The best-fit value of the parameter `name` (α∥, α⊥ from the distortion).
fn value_of(fit: &GalaxyFit, basis: &FitBasis, name: &str) -> f64 {
    match name {
        "apar" => fit.ap.map_or(f64::NAN, |d| d.apar),
        "aperp" => fit.ap.map_or(f64::NAN, |d| d.aperp),
        n => match (fit.in_basis, basis.names().iter().position(|&m| m == n)) {
            (Some(v), Some(i)) => v[i],
            _ => fit.best.get(n).unwrap_or(f64::NAN),
        },
    }
}
