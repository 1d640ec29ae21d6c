//! One function per job of the command line and of the Python module, each returning the [`Table`]
//! both write: `real` ([`real_table`]), `rsd` ([`rsd_table`]) and `fit` ([`fit_table`]). The caller
//! parses its input into the typed requests here, builds the plan once per k grid ([`RealPlan`],
//! [`RsdPlan`]) and prepares the linear spectrum of each cosmology ([`crate::setup::prepare`]); the
//! job does the rest, with the header saying what was computed, with which cosmology, q range and
//! precision.
//!
//! ```
//! use pt_spectra::{jobs, precision::Precision, progress::Silent, store::TableStore};
//! use pt_spectra::real::{RealPlan, RealSelection};
//! use pt_spectra::setup::{prepare, LinearSource, Request};
//! let prepared = prepare(Request { source: LinearSource::Embedded, cosmology: None, z: 0.0 })?;
//! let selection: RealSelection = "1l-spt".parse()?;
//! let plan = RealPlan::for_selection(&[0.05, 0.1], selection, &Precision::fast(),
//!                                    &TableStore::in_memory(), &Silent)?;
//! let t = jobs::real_table(&plan, selection, &prepared, true, &Silent)?;
//! assert_eq!(t.names()[..5], ["k", "P_lin", "P_dd", "P_dt", "P_tt"]);
//! assert!(t.column("P22_dd").is_some() && t.header[0].contains("1l-spt"));
//! # Ok::<(), pt_spectra::error::Error>(())
//! ```

use crate::error::{Error, Result};
use crate::fit::{delta_chi2, fit, FitSettings, MultipoleData, MultipoleModel, Parameter, Params};
use crate::halo::{crossings, Bias, Noise};
use crate::loops::Pair;
use crate::output::{fit_table as fit_results_table, Table, POWER, WAVENUMBER};
use crate::precision::Precision;
use crate::progress::Progress;
use crate::real::{RealModel, RealPlan, RealSelection, RealSpectra};
use crate::rsd::{fog_sigma, multipoles, Fog, RsdModel, RsdPlan, RsdSettings, Sigma0};
use crate::setup::Prepared;

/// The version of pt-spectra, for table headers.
pub const VERSION: &str = env!("CARGO_PKG_VERSION");

/// Signal-to-noise levels whose crossings are reported (the paper's table_noise).
pub const SN_LEVELS: [f64; 3] = [1.0, 0.5, 0.1];

/// Header lines naming the cosmology, the input spectrum and the integration settings.
pub fn describe_inputs(prepared: &Prepared, precision: &Precision) -> Vec<String> {
    let spectrum = &prepared.spectrum;
    let (low, high) = spectrum.extrapolation_slopes();
    let mut h = prepared.description.clone();
    h.push(format!(
        "loop integrals over q in [{:e}, {:e}] h/Mpc, precision {}; the linear table covers [{:e}, \
         {:e}] h/Mpc and is extended by power laws (slopes {low:.3}, {high:.3})",
        precision.q_min,
        precision.q_max,
        precision.preset,
        spectrum.k_min(),
        spectrum.k_max(),
    ));
    h
}

/// The header line describing the 2-loop mode-coupling integration.
pub fn two_loop_line(precision: &Precision) -> String {
    let target = if precision.two_loop_tolerance > 0.0 {
        format!(
            "points added where the error exceeds {:e} of the correction",
            precision.two_loop_tolerance
        )
    } else {
        "fixed points".to_string()
    };
    format!(
        "2-loop mode coupling: randomised quasi-Monte Carlo, {} shifts x {} Sobol points at k = 0.16 \
         (scaled as k^3.5), seed {}; {target}",
        precision.two_loop_replicas, precision.two_loop_points, precision.two_loop_seed
    )
}

/// `pt-spectra real`: the spectra of the selected model (or P_dd/P_nw of every model) for the
/// prepared linear spectrum, with the loop terms if `terms`.
///
/// # Errors
/// [`Error::GridMismatch`] if the plan does not cover the selection ([`RealPlan::for_selection`]); as [`RealPlan::evaluate`]
/// and [`Prepared::no_wiggle`].
pub fn real_table(
    plan: &RealPlan,
    selection: RealSelection,
    prepared: &Prepared,
    terms: bool,
    progress: &dyn Progress,
) -> Result<Table> {
    if !plan.covers(selection) {
        return Err(Error::GridMismatch {
            what: "real-space plan and model",
            expected: format!("a plan for {}", selection.plan_model()),
            found: format!("a plan for {}", plan.model()),
        });
    }
    let precision = plan.precision();
    let spectra = plan.evaluate(&prepared.spectrum, progress)?;
    let mut header = vec![format!(
        "pt-spectra {VERSION} real: model {}, z = {}",
        match selection {
            RealSelection::One(m) => m.name(),
            RealSelection::All => "all (P_dd of each model over the no-wiggle spectrum)",
        },
        prepared.z
    )];
    header.extend(describe_inputs(prepared, precision));
    match selection {
        RealSelection::One(model) => {
            header.extend(model_header(model, &spectra, precision, terms));
            Ok(spectra.table(header, terms))
        }
        RealSelection::All => {
            header.push(two_loop_line(precision));
            header.push(
                "P_nw: Eisenstein & Hu (1998) no-wiggle fit of the cosmology, scaled to the sigma8 of \
                 the linear input; columns <model> = P_dd(model)/P_nw, err_<model> its estimated \
                 numerical error"
                    .into(),
            );
            all_models(header, &spectra, &prepared.no_wiggle()?)
        }
    }
}

/// The header lines of one model: conventions, σ_v², the 2-loop settings and the RPT factors.
fn model_header(
    model: RealModel,
    spectra: &RealSpectra,
    precision: &Precision,
    terms: bool,
) -> Vec<String> {
    let sigma_v2 = spectra.terms.one_loop.sigma_v2;
    let mut h = vec![
        "conventions: theta = -div v/(aHf); 1-loop correction = P22 + 2 P13; err_X = estimated \
         absolute numerical error of X"
            .to_string(),
        format!(
            "sigma_v2 = {:.8e} +- {:.1e} (Mpc/h)^2",
            sigma_v2.value, sigma_v2.error
        ),
    ];
    if model.needs_two_loop() {
        h.push(two_loop_line(precision));
    }
    if terms && model.propagator().is_some() {
        h.push(
            "N_dd = N_delta^2, N_dt = N_delta N_theta, N_tt = N_theta^2: the factors multiplying \
             P_lin + P22 in the RPT model"
                .into(),
        );
    }
    h
}

/// `k P_nw`, then P_dd/P_nw of every model and their errors.
fn all_models(
    header: Vec<String>,
    spectra: &RealSpectra,
    p_nw: &crate::linear::LinearSpectrum,
) -> Result<Table> {
    let nw: Vec<f64> = spectra.k.iter().map(|&k| p_nw.eval(k)).collect();
    let models = RealModel::ALL
        .iter()
        .map(|&m| RealSpectra::from_terms(m, spectra.terms.clone()))
        .collect::<Result<Vec<_>>>()?;
    let mut t = Table::new(header);
    t.push("k", WAVENUMBER, spectra.k.clone());
    t.push("P_nw", POWER, nw.clone());
    let ratio = |m: &RealSpectra, error: bool| -> Vec<f64> {
        let dd = m.pair(Pair::DeltaDelta);
        dd.iter()
            .zip(&nw)
            .map(|(e, n)| if error { e.error / n } else { e.value / n })
            .collect()
    };
    for m in &models {
        t.push(m.model.name(), "1", ratio(m, false));
    }
    for m in &models {
        t.push(format!("err_{}", m.model), "1", ratio(m, true));
    }
    Ok(t)
}

/// The redshift-space settings of `rsd` and `fit` that are not plans or data.
#[derive(Debug, Clone, PartialEq)]
pub struct RsdRequest {
    /// The RSD model.
    pub rsd: RsdModel,
    /// The growth rate; `None` for f(z) of the cosmology.
    pub f: Option<f64>,
    /// The bias b(k) before the amplitude.
    pub bias: Bias,
    /// The bias amplitude A_b.
    pub amplitude: f64,
    /// The Fingers-of-God damping.
    pub fog: Fog,
    /// Its σ0 [Mpc/h] (z = 0 value), or a theory value.
    pub sigma0: Sigma0,
    /// The stochasticity P_εε.
    pub noise: Noise,
    /// The multipoles.
    pub ells: Vec<usize>,
    /// Whether to add the multipoles of the parts.
    pub terms: bool,
}

impl RsdRequest {
    /// A description of the bias for headers.
    pub fn describe_bias(&self) -> String {
        match &self.bias {
            Bias::Constant(b) => format!("b = {b}"),
            Bias::Table(t) => format!("b(k) from {}", t.origin()),
        }
    }
}

/// `pt-spectra rsd`: the multipoles of `request` for the prepared linear spectrum, from the loop
/// terms of `plan`.
///
/// # Errors
/// As [`RsdPlan::evaluate`], [`multipoles`], [`Bias::values`], [`Noise::values`] and
/// [`Sigma0::resolve`]; [`Error::InvalidParameter`] for a non-finite f.
pub fn rsd_table(
    plan: &RsdPlan,
    request: &RsdRequest,
    prepared: &Prepared,
    progress: &dyn Progress,
) -> Result<Table> {
    let (spectra, tns) = plan.evaluate(&prepared.spectrum, progress)?;
    rsd_table_from_terms(
        &spectra,
        tns.as_ref(),
        plan.real().precision(),
        request,
        prepared,
    )
}

/// [`rsd_table`] from loop terms computed before (`spectra` and, for TNS, `tns` of the prepared
/// spectrum, with `precision`): the cheap step of a chain in which only f, the bias, σ0 or the noise
/// change.
///
/// # Errors
/// As [`rsd_table`].
pub fn rsd_table_from_terms(
    spectra: &RealSpectra,
    tns: Option<&crate::loops::TnsTerms>,
    precision: &Precision,
    request: &RsdRequest,
    prepared: &Prepared,
) -> Result<Table> {
    let k = &spectra.k;
    let f = request.f.unwrap_or(prepared.growth_rate);
    if !f.is_finite() {
        return Err(Error::InvalidParameter {
            name: "f",
            value: f,
            reason: "must be finite",
        });
    }
    let growth = prepared.growth_factor;
    let sigma0 = request
        .sigma0
        .resolve(&prepared.spectrum, growth, precision)?;
    let sigma = fog_sigma(sigma0, growth, f);
    let settings = RsdSettings {
        model: request.rsd,
        f,
        bias: request.bias.values(k, request.amplitude)?,
        fog: request.fog,
        sigma,
        noise: request.noise.values(k)?,
        ells: request.ells.clone(),
        parts: request.terms,
    };
    let m = multipoles(spectra, tns, &settings)?;
    let (rsd, fog) = (request.rsd, request.fog);
    let mut header = vec![format!(
        "pt-spectra {VERSION} rsd: {rsd} with real-space {}, z = {}, f = {f}, {} times A_b = {}, \
         FoG {fog:?} with sigma0 = {sigma0} Mpc/h (sigma = sigma0 D(z) f = {sigma:.6} Mpc/h)",
        spectra.model,
        prepared.z,
        request.describe_bias(),
        request.amplitude,
    )];
    header.extend(describe_inputs(prepared, precision));
    if rsd.needs_tns() {
        header.push(
            "TNS A and B at leading order (linear P, tree-level bispectrum), A = b^3 A(f/b), \
             B = b^4 B(f/b)"
                .into(),
        );
    }
    header.push(
        "P_l = (2l+1) int_0^1 dmu P^s(k,mu) L_l(mu), noise-subtracted; err_P_l bounds the numerical \
         error (loop integrals and mu quadrature)"
            .into(),
    );
    if let Some(sn) = &m.signal_to_noise {
        header.push(crossing_line(k, sn));
    }
    Ok(m.table(header))
}

/// Where the signal-to-noise falls to each of [`SN_LEVELS`].
fn crossing_line(k: &[f64], sn: &[f64]) -> String {
    let mut text = "signal-to-noise SN = P0/P_eps falls to".to_string();
    for (level, c) in SN_LEVELS.iter().zip(crossings(k, sn, &SN_LEVELS)) {
        match c {
            Some(kc) => text += &format!(" {level} at k = {kc:.4}"),
            None if sn[0] < *level => text += &format!(" {level}: below it at every k"),
            None => text += &format!(" {level}: not within the k range"),
        }
        text.push(';');
    }
    text
}

/// What `fit` fits, besides the redshift-space settings.
#[derive(Debug, Clone, PartialEq)]
pub struct FitRequest {
    /// The model: RSD model, f (start or fixed value), bias, amplitude (start or fixed), FoG, σ0
    /// (start or fixed value: a number), noise (subtracted from the measured monopole), ells (the
    /// fitted multipoles).
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

/// `pt-spectra fit`: the best fit and Δχ² intervals at each k_max of `request` to `data` (its
/// multipoles those of `request.model.ells`, on the grid of `plan`).
///
/// # Errors
/// [`Error::InvalidParameter`] for a σ0 that is a theory value, non-finite start values; as
/// [`fit`], [`MultipoleModel::new`] and [`RsdPlan::evaluate`].
pub fn fit_table(
    plan: &RsdPlan,
    mut data: MultipoleData,
    request: &FitRequest,
    prepared: &Prepared,
    progress: &dyn Progress,
) -> Result<Table> {
    let m = &request.model;
    let Sigma0::Value(sigma0) = m.sigma0 else {
        return Err(Error::InvalidParameter {
            name: "sigma0 of a fit",
            value: f64::NAN,
            reason: "must be a number (its start or fixed value)",
        });
    };
    let f0 = m.f.unwrap_or(prepared.growth_rate);
    for (name, v) in [("f", f0), ("sigma0", sigma0), ("A_b", m.amplitude)] {
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
    let (spectra, tns) = plan.evaluate(&prepared.spectrum, progress)?;
    let model = MultipoleModel::new(
        &spectra,
        tns.as_ref(),
        m.rsd,
        m.fog,
        prepared.growth_factor,
        b,
        &m.ells,
    )?;
    let settings = FitSettings {
        free: request.free.clone(),
        start: Params {
            f: f0,
            sigma0,
            amplitude: m.amplitude,
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
    header.extend(describe_inputs(prepared, plan.real().precision()));
    header.push(format!(
        "chi2 = {} ; errors: where the profile chi2 reaches chi2_min + {} ({} free); fixed: f = {f0}, \
         sigma0 = {sigma0}, ab = {}",
        if data.covariance.is_some() {
            "(d-m)^T C^-1 (d-m)"
        } else {
            "sum ((d-m)/sigma)^2"
        },
        delta_chi2(request.free.len()),
        request.free.len(),
        m.amplitude
    ));
    Ok(fit_results_table(&results, header))
}
