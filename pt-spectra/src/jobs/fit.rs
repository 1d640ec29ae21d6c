//! `pt-spectra fit`: best fits versus k_max, with the best-fit model multipoles and Δχ² surfaces the
//! paper's figures show.

use super::rsd::{describe_sigma0, no_wiggle_multipoles, RsdRequest};
use super::{counterterm_line, describe_inputs, VERSION};
use crate::error::{Error, Result};
use crate::fit::{
    contour, delta_chi2, fit, ContourGrid, FitResult, FitSettings, MultipoleData, MultipoleModel,
    Parameter, Params, CONTOUR_LEVELS,
};
use crate::output::{Table, POWER, WAVENUMBER};
use crate::progress::Progress;
use crate::rsd::{dispersion_theory, DispersionInput, Fog, RsdPlan, DISPERSION_Q_CUT};
use crate::setup::Prepared;

/// What `fit` fits, besides the redshift-space settings.
#[derive(Debug, Clone, PartialEq)]
pub struct FitRequest {
    /// The model: RSD model, f (start or fixed value), bias, amplitude (start or fixed), FoG, σ0
    /// (start or fixed value: a number or a theory value), noise (subtracted from the measured
    /// monopole), ells (the fitted multipoles).
    pub model: RsdRequest,
    /// The free parameters.
    pub free: Vec<Parameter>,
    /// Smallest k used [h/Mpc].
    pub k_min: f64,
    /// The k_max [h/Mpc] of each fit.
    pub k_max: Vec<f64>,
    /// A description of the data for the header (e.g. its file name).
    pub data_name: String,
}

/// The tables `fit` can write besides the fit table.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct FitOutputs {
    /// The best-fit model multipoles at every k_max ([`FitTables::model`]).
    pub model: bool,
    /// The Δχ² surface of two free parameters at every k_max ([`FitTables::contour`]).
    pub contour: Option<ContourGrid>,
}

/// The tables of [`fit_tables`].
#[derive(Debug, Clone, PartialEq)]
pub struct FitTables {
    /// The best fits versus k_max (as [`fit_table`]).
    pub fit: Table,
    /// `k`, the fitted data `P<l>_data err_P<l>_data` (noise subtracted), the no-wiggle reference
    /// `P<l>_nw` (at the start f and A_b), and the best-fit model `P<l>_kmax<K>` of each k_max over the
    /// whole data grid.
    pub model: Option<Table>,
    /// `k_max i j <x> <y> chi2 delta_chi2 <other>`: the Δχ² surface, a row per grid point (i, j).
    pub contour: Option<Table>,
}

/// `pt-spectra fit`: the best fit and Δχ² intervals at each k_max of `request` to `data` (its
/// multipoles those of `request.model.ells`, on the grid of `plan`). With FoG, the columns
/// `sigma0_lin sigma0_1l` give the theory σ0 of eq. sigmav (linear and 1-loop SPT P_θθ).
///
/// # Errors
/// As [`fit_tables`].
pub fn fit_table(
    plan: &RsdPlan,
    data: MultipoleData,
    request: &FitRequest,
    prepared: &Prepared,
    progress: &dyn Progress,
) -> Result<Table> {
    Ok(fit_tables(
        plan,
        data,
        request,
        FitOutputs::default(),
        prepared,
        progress,
    )?
    .fit)
}

/// [`fit_table`] and the `outputs` asked for: the best-fit model multipoles and Δχ² surfaces.
///
/// # Errors
/// [`Error::InvalidParameter`] for non-finite start values; as [`fit`], [`contour`],
/// [`MultipoleModel::new`], [`RsdPlan::evaluate`], [`crate::rsd::Sigma0::resolve`] and (with the
/// model table) [`Prepared::no_wiggle`].
pub fn fit_tables(
    plan: &RsdPlan,
    mut data: MultipoleData,
    request: &FitRequest,
    outputs: FitOutputs,
    prepared: &Prepared,
    progress: &dyn Progress,
) -> Result<FitTables> {
    let m = &request.model;
    let precision = plan.real().precision();
    let growth = prepared.growth_factor;
    let sigma0 = m
        .sigma0
        .resolve(prepared.tracer_spectrum(), growth, precision)?;
    let f0 = m.f.unwrap_or(prepared.growth_rate);
    super::rsd::check_growth_rate(f0)?;
    let fields = [
        ("f", f0),
        ("sigma0", sigma0),
        ("A_b", m.amplitude),
        ("cs2", m.cs2),
    ];
    for (name, v) in fields {
        if !v.is_finite() {
            let reason = "must be finite";
            return Err(Error::InvalidParameter {
                name,
                value: v,
                reason,
            });
        }
    }
    if let (Some(p_eps), Some(j)) = (
        m.noise.values(&data.k)?,
        data.ells.iter().position(|&l| l == 0),
    ) {
        for (v, e) in data.values[j].iter_mut().zip(p_eps) {
            *v -= e;
        }
    }
    let b = m.bias.values(&data.k, 1.0)?;
    let (spectra, tns) = plan.evaluate(prepared.tracer_spectrum(), progress)?;
    let model = MultipoleModel::new(
        &spectra,
        tns.as_ref(),
        m.rsd,
        m.fog,
        growth,
        b.clone(),
        &m.ells,
    )?;
    let settings = FitSettings {
        free: request.free.clone(),
        start: Params {
            f: f0,
            sigma0,
            amplitude: m.amplitude,
            cs2: m.cs2,
        },
        k_min: request.k_min,
    };
    let results = fit(&model, &data, &settings, &request.k_max)?;
    let names = |v: &[String]| v.join(",");
    let free: Vec<String> = request.free.iter().map(|p| p.to_string()).collect();
    let ells: Vec<String> = m.ells.iter().map(|l| l.to_string()).collect();
    let mut header = vec![format!(
        "pt-spectra {VERSION} fit: {} with real-space {}, FoG {:?}, z = {}, ells {}, free {}; data {}",
        m.rsd,
        plan.real().model(),
        m.fog,
        prepared.z,
        names(&ells),
        names(&free),
        request.data_name
    )];
    header.extend(describe_inputs(prepared, precision));
    let with_cs2 = m.cs2 != 0.0 || request.free.contains(&Parameter::Cs2);
    header.push(format!(
        "chi2 = {} ; errors: where the profile chi2 reaches chi2_min + {} ({} free); fixed: f = {f0}, \
         sigma0 = {sigma0}{}, ab = {}{}",
        if data.covariance.is_some() {
            "(d-m)^T C^-1 (d-m)"
        } else {
            "sum ((d-m)/sigma)^2"
        },
        delta_chi2(request.free.len()),
        request.free.len(),
        describe_sigma0(m.sigma0),
        m.amplitude,
        if with_cs2 {
            format!(", cs2 = {} (Mpc/h)^2", m.cs2)
        } else {
            String::new()
        }
    ));
    if with_cs2 {
        header.push(counterterm_line(m.cs2).replacen("cs2 = ", "cs2 (fixed or start) = ", 1));
    }
    let theory = if m.fog == Fog::None {
        None
    } else {
        header.push(format!(
            "sigma0_lin, sigma0_1l: the theory sigma0 = sigma(z)/D(z) of eq. sigmav, sigma^2 = \
             (1/6pi^2) int P_tt dq, with P_lin and with 1-loop SPT P_tt (for q <= {DISPERSION_Q_CUT} \
             h/Mpc, P_lin above)"
        ));
        let value = |input| -> Result<f64> {
            Ok(dispersion_theory(prepared.tracer_spectrum(), input, precision)?.value / growth)
        };
        Some([
            value(DispersionInput::Linear)?,
            value(DispersionInput::OneLoopSpt)?,
        ])
    };
    let mut fit_out = fit_results_table(&results, header.clone());
    if let Some([lin, one]) = theory {
        fit_out.push("sigma0_lin", "Mpc/h", vec![lin; results.len()]);
        fit_out.push("sigma0_1l", "Mpc/h", vec![one; results.len()]);
    }
    let model_out = if outputs.model {
        let nw = no_wiggle_multipoles(
            &data.k,
            &m.bias.values(&data.k, m.amplitude)?,
            f0,
            &m.ells,
            &prepared.no_wiggle()?,
        )?;
        Some(model_table(&model, &data, &results, nw, header.clone()))
    } else {
        None
    };
    let contour_out = match outputs.contour {
        None => None,
        Some(grid) => {
            let surfaces = results
                .iter()
                .map(|r| contour(&model, &data, &settings, r, &grid))
                .collect::<Result<Vec<_>>>()?;
            let mut h = header;
            h.push(format!(
                "delta_chi2 = chi2 - chi2_min on a {0} x {0} grid (i, j) of ({1}, {2}) along the principal \
                 axes of the delta_chi2 = {4} ellipse at the best fit, over +- {3} times its semi-axes (or \
                 along {1} and {2} over +- {3} times their 1-sigma half-widths where the ellipse is not \
                 defined), the other free parameters re-minimised at each point; levels {4} and {5} \
                 bound the 68.3% and 95.4% regions of two parameters; chi2 is even in sigma0",
                grid.points, grid.x, grid.y, grid.span, CONTOUR_LEVELS[0], CONTOUR_LEVELS[1]
            ));
            Some(super::contour_table(&surfaces, &request.free, h))
        }
    };
    Ok(FitTables {
        fit: fit_out,
        model: model_out,
        contour: contour_out,
    })
}

/// `k_max` as a column-name suffix: at most 4 decimals, no trailing zeros (0.15 → `0.15`).
fn k_max_name(k_max: f64) -> String {
    let s = format!("{k_max:.4}");
    s.trim_end_matches('0').trim_end_matches('.').to_string()
}

/// The table of [`FitTables::model`].
fn model_table(
    model: &MultipoleModel,
    data: &MultipoleData,
    results: &[FitResult],
    nw: Vec<Vec<f64>>,
    mut header: Vec<String>,
) -> Table {
    header.push(
        "P<l>_data, err_P<l>_data: the fitted data (noise subtracted from the monopole); P<l>_nw: \
         linear Kaiser multipoles of the Eisenstein & Hu no-wiggle spectrum at the start f and A_b; \
         P<l>_kmax<K>: the best-fit model of the fit up to k_max = K, on every k"
            .into(),
    );
    for r in results {
        let best: Vec<String> = r
            .intervals
            .iter()
            .map(|&(p, _, _)| format!("{p} = {:.6}", r.best.get(p)))
            .collect();
        header.push(format!(
            "k_max = {}: {}, chi2 = {:.4} for {} dof",
            k_max_name(r.k_max),
            best.join(", "),
            r.chi2,
            r.dof
        ));
    }
    let mut t = Table::new(header);
    t.push("k", WAVENUMBER, data.k.clone());
    for (j, l) in data.ells.iter().enumerate() {
        t.push(format!("P{l}_data"), POWER, data.values[j].clone());
        t.push(format!("err_P{l}_data"), POWER, data.sigma[j].clone());
    }
    for (l, p) in data.ells.iter().zip(nw) {
        t.push(format!("P{l}_nw"), POWER, p);
    }
    let mut used = std::collections::HashSet::new();
    for r in results {
        // Two k_max equal to 4 decimals keep their full values in the names.
        let mut suffix = k_max_name(r.k_max);
        if !used.insert(suffix.clone()) {
            suffix = format!("{}", r.k_max);
        }
        for (l, p) in data.ells.iter().zip(model.multipoles(&r.best)) {
            t.push(format!("P{l}_kmax{suffix}"), POWER, p);
        }
    }
    t
}

/// The results of a fit versus k_max as a table with `header` lines: `k_max points`, for each free
/// parameter `p p_lo p_hi` (best fit and 1σ interval), then `chi2 dof chi2_dof`.
fn fit_results_table(results: &[crate::fit::FitResult], header: Vec<String>) -> Table {
    let mut t = Table::new(header);
    let column = |f: &dyn Fn(&crate::fit::FitResult) -> f64| results.iter().map(f).collect();
    t.push("k_max", WAVENUMBER, column(&|r| r.k_max));
    t.push("points", "1", column(&|r| r.points as f64));
    if let Some(first) = results.first() {
        for (j, (p, _, _)) in first.intervals.iter().enumerate() {
            let unit = p.unit();
            t.push(p.name(), unit, column(&|r| r.best.get(r.intervals[j].0)));
            let unbounded = "no delta chi2 = 1 crossing found on that side within 2^12 times the \
                             initial step (the parameter is unconstrained there)";
            t.push_undefined_as(
                format!("{p}_lo"),
                unit,
                column(&|r| r.intervals[j].1),
                unbounded,
            );
            t.push_undefined_as(
                format!("{p}_hi"),
                unit,
                column(&|r| r.intervals[j].2),
                unbounded,
            );
        }
    }
    t.push("chi2", "1", column(&|r| r.chi2));
    t.push("dof", "1", column(&|r| r.dof as f64));
    t.push("chi2_dof", "1", column(&|r| r.chi2 / r.dof as f64));
    t
}
