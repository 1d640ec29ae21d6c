//! One function per job of the command line and of the Python module, each returning the [`Table`]
//! both write: `real` ([`real_table`]), `rsd` ([`rsd_table`]), `fit` ([`fit_table`]; with the model
//! multipoles and Δχ² surfaces, [`fit_tables`]) and `halo` ([`halo_table`]). The caller
//! parses its input into the typed requests here, builds the plan once per k grid ([`RealPlan`],
//! [`crate::rsd::RsdPlan`]) and prepares the linear spectrum of each cosmology ([`crate::setup::prepare`]); the
//! job does the rest, with the header saying what was computed, with which cosmology, q range and
//! precision.
//!
//! ```
//! use pt_spectra::{jobs, precision::Precision, progress::Silent, store::TableStore};
//! use pt_spectra::real::{Counterterms, RealPlan, RealSelection};
//! use pt_spectra::setup::{prepare, LinearSource, Request};
//! let prepared = prepare(Request { source: LinearSource::Embedded, cosmology: None, z: 0.0 })?;
//! let selection: RealSelection = "1l-spt".parse()?;
//! let plan = RealPlan::for_selection(&[0.05, 0.1], selection, &Precision::fast(),
//!                                    &TableStore::in_memory(), &Silent)?;
//! let none = Counterterms::default();
//! let t = jobs::real_table(&plan, selection, &prepared, true, &none, &Silent)?;
//! assert_eq!(t.names()[..5], ["k", "P_lin", "P_dd", "P_dt", "P_tt"]);
//! assert!(t.column("P22_dd").is_some() && t.header[0].contains("1l-spt"));
//! // With the EFT counterterm c_s² = 1 (Mpc/h)²: P_dd − 2 k² P_lin, stated in the header.
//! let c = jobs::real_table(&plan, selection, &prepared, true, &Counterterms::cs2(1.0), &Silent)?;
//! let (p, q, p_lin) = (t.column("P_dd").unwrap(), c.column("P_dd").unwrap(), t.column("P_lin").unwrap());
//! assert!((q[1] - p[1] + 2.0 * 0.1 * 0.1 * p_lin[1]).abs() < 1e-9 * p[1]);
//! assert!(c.header.iter().any(|h| h.contains("cs2 = 1")) && c.column("P_ct_tt").is_some());
//! # Ok::<(), pt_spectra::error::Error>(())
//! ```

use crate::error::{Error, Result};
use crate::loops::bias::BiasPlan;
use crate::loops::Pair;
use crate::output::{Table, POWER, WAVENUMBER};
use crate::precision::Precision;
use crate::progress::Progress;
pub use crate::real::counterterm::counterterm_line;
use crate::real::{Counterterms, RealModel, RealPlan, RealSelection, RealSpectra};
use crate::setup::Prepared;

/// The TOML analysis file of a joint fit (feature `analysis`).
#[cfg(feature = "analysis")]
pub mod analysis;
#[cfg(feature = "analysis")]
mod analysis_likelihood;
mod batch;
mod bias;
mod bispectrum;
mod bispectrum_galaxy;
mod bispectrum_galaxy_bins;
mod bispectrum_multipole_plan;
pub mod defaults;
mod ept;
mod ept_fit;
mod fit;
mod forecast;
mod halo;
mod joint_block;
mod joint_fit;
mod observe;
mod report;
mod rsd;
mod spt2;
#[cfg(feature = "analysis")]
pub use analysis_likelihood::AnalysisLikelihood;
pub use batch::{batch_memory, real_batch, BatchColumns, BatchMemory, BatchRows};
pub use bias::BiasOutput;
pub use bispectrum::{
    bispectrum_table, one_loop_bispectrum_plan, one_loop_bispectrum_table, one_loop_redshift_table,
    sugiyama_table, BispectrumRequest, SugiyamaRequest,
};
pub use bispectrum_galaxy::{
    loop_bias, one_loop_galaxy_multipoles_table, one_loop_galaxy_table, one_loop_ir_inputs,
    LOOP_BIAS_NAMES,
};
pub use bispectrum_galaxy_bins::one_loop_galaxy_binned_multipoles_table;
pub use bispectrum_multipole_plan::{
    binned_plan_multipoles, describe_bin_source, describe_source as describe_multipole_source,
    multipole_plan_rows, multipoles_from_tensors, one_loop_multipole_bin_tensors,
    one_loop_multipole_tensors,
};
pub use ept::{
    ept_observed_table, ept_plan, ept_table, ept_table_from_terms, EptRequest, AP_FIT_RANGE,
};
pub use ept_fit::{
    add_desi_priors, ept_fit_table, ept_model_table, ept_profile_table, fit_basis, FitContext,
};
pub use fit::{fit_table, fit_tables, FitOutputs, FitRequest, FitTables};
pub use forecast::{forecast_table, parse_bin};
pub use halo::{halo_table, HaloRequest};
pub use joint_fit::{joint_fit_table, Analysis, Inputs, SetSpec, DEFAULT_B1};
pub use observe::{observed_table, ApSpec, ObservationSpec};
pub use report::{contour_table, push_spectrum_errors, real_spectra_table, rsd_multipoles_table};
pub use rsd::{
    describe_sigma0, no_wiggle_multipoles, rsd_table, rsd_table_from_terms,
    rsd_table_from_terms_memo, rsd_table_with_bias_terms, xi_table, NonlinearBias, RsdRequest,
    SN_LEVELS,
};
pub use spt2::{eft2_table, spt2_table};

/// The version of pt-spectra, for table headers.
pub const VERSION: &str = env!("CARGO_PKG_VERSION");

/// Each `(name, value)` finite.
///
/// # Errors
/// [`Error::InvalidParameter`] naming the first that is not.
pub(crate) fn check_finite(parameters: &[(&'static str, f64)]) -> Result<()> {
    match parameters.iter().find(|(_, v)| !v.is_finite()) {
        Some(&(name, value)) => Err(Error::InvalidParameter {
            name,
            value,
            reason: "must be finite",
        }),
        None => Ok(()),
    }
}

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
        precision.label(),
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
/// prepared linear spectrum (each with its error `err_P_xx`, the last columns without `terms`), with the
/// loop terms if `terms`, and the EFT `counterterms` added (c_s²
/// to every model, [`crate::real::counterterm`](mod@crate::real::counterterm); the 2-loop set to
/// `2l-eft`, `2l-eft-ir`, [`crate::real::eft`]). The header states them; with `terms`, the columns
/// `P_ct_dd P_ct_dt P_ct_tt` give their sum and, for the EFT models, `T_dd_X T_dt_X T_tt_X` the
/// derivatives ∂P/∂X of each parameter X.
///
/// # Errors
/// [`Error::PlanMismatch`] if the plan does not cover the selection ([`RealPlan::for_selection`]); as [`RealPlan::evaluate`],
/// [`RealSpectra::with_counterterm`] and [`Prepared::no_wiggle`].
pub fn real_table(
    plan: &RealPlan,
    selection: RealSelection,
    prepared: &Prepared,
    terms: bool,
    counterterms: &Counterterms,
    progress: &dyn Progress,
) -> Result<Table> {
    real_table_with_bias(
        plan,
        None,
        selection,
        prepared,
        terms,
        counterterms,
        BiasOutput::default(),
        progress,
    )
}

/// [`real_table`] with the galaxy bias expansion of `bias` (its terms from `bias_plan`, on the
/// plan's k): the bias terms as columns (`Pd1d2 err_Pd1d2 …`), and P_gg, P_gm of the model's P_δδ
/// ([`crate::loops::bias`]). Without either in `bias`, exactly [`real_table`].
///
/// # Errors
/// As [`real_table`]; [`Error::InvalidChoice`] for bias output with `--model all`;
/// [`Error::MissingTerm`] without a `bias_plan`, [`Error::GridMismatch`] if it is for other k.
#[allow(clippy::too_many_arguments)]
pub fn real_table_with_bias(
    plan: &RealPlan,
    bias_plan: Option<&BiasPlan>,
    selection: RealSelection,
    prepared: &Prepared,
    terms: bool,
    counterterms: &Counterterms,
    bias: BiasOutput,
    progress: &dyn Progress,
) -> Result<Table> {
    let bias_terms = bias::terms(plan, bias_plan, selection, prepared, bias)?;
    if !plan.covers(selection) {
        return Err(Error::PlanMismatch {
            expected: format!("model {}", selection.plan_model()),
            found: format!("model {}", plan.model()),
            hint: " (RealPlan::for_selection)",
        });
    }
    // `all` takes c_s² alone, as the non-EFT models do.
    counterterms.check(match selection {
        RealSelection::One(model) => model,
        RealSelection::All => RealModel::Linear,
    })?;
    let precision = plan.precision();
    let spectra = match &prepared.spectrum_cb {
        Some(cb) => {
            let spectra = plan.evaluate(cb, progress)?;
            let p_m: Vec<f64> = spectra
                .k
                .iter()
                .map(|&k| prepared.spectrum.eval(k))
                .collect();
            spectra.with_massive_neutrinos(&p_m, prepared.cold_fraction())?
        }
        None => plan.evaluate(&prepared.spectrum, progress)?,
    };
    let mut header = vec![format!(
        "pt-spectra {VERSION} real: model {}, z = {}",
        match selection {
            RealSelection::One(m) => m.name(),
            RealSelection::All => "all (P_dd of each model over the no-wiggle spectrum)",
        },
        prepared.z
    )];
    header.extend(describe_inputs(prepared, precision));
    if prepared.spectrum_cb.is_some() {
        header.push(format!(
            "massive neutrinos: loops of P_cb; P_dd of all matter = P_lin + f_cb^2 (P_dd,cb - P_cb) \
             (neutrinos linear), f_cb = 1 - omega_nu/omega_m = {:.6}; P_dt, P_tt of cold dark matter + \
             baryons; P_lin is the linear P_m, P_cb the linear P of cold dark matter + baryons",
            prepared.cold_fraction()
        ));
    }
    match selection {
        RealSelection::One(model) => {
            header.extend(counterterms.describe(model));
            header.extend(model_header(model, &spectra, precision, terms));
            let spectra = spectra.with_counterterms(counterterms)?;
            let mut t = real_spectra_table(&spectra, header, terms);
            t.methods = spectra
                .terms
                .methods(model.needs_two_loop(), model.needs_ir());
            if let Some(cb) = &prepared.spectrum_cb {
                t.push(
                    "P_cb",
                    POWER,
                    spectra.k.iter().map(|&k| cb.eval(k)).collect(),
                );
            }
            if terms && !counterterms.is_zero() {
                for pair in Pair::ALL {
                    let name = format!("P_ct_{}", pair.suffix());
                    t.push(name, POWER, spectra.counterterm(pair));
                }
            }
            if let Some(b) = bias_terms {
                bias::push_columns(&mut t, &spectra, &b, bias);
            }
            if !terms {
                // every number with its error (the `--terms` table has them after the spectra)
                push_spectrum_errors(&mut t, &spectra);
            }
            Ok(t)
        }
        RealSelection::All => {
            header.push(two_loop_line(precision));
            header.extend(spectra.terms.two_loop_source.map(|s| s.describe()));
            header.extend(spectra.terms.one_loop_source.map(|s| s.describe()));
            header.push(
                "P_nw: Eisenstein & Hu (1998) no-wiggle fit of the cosmology, scaled to the sigma8 of \
                 the linear input; columns <model> = P_dd(model)/P_nw, err_<model> its estimated \
                 numerical error"
                    .into(),
            );
            header.extend(counterterms.describe(RealModel::Linear));
            let mut t = all_models(header, &spectra, counterterms.cs2, &prepared.no_wiggle()?)?;
            t.methods = spectra.terms.methods(true, true);
            Ok(t)
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
        h.extend(spectra.terms.two_loop_source.map(|s| s.describe()));
    }
    h.extend(spectra.terms.one_loop_source.map(|s| s.describe()));
    if let (Some(ir), true) = (&spectra.terms.ir, model.needs_ir()) {
        let source = ir.no_wiggle.one_loop_source.map_or_else(
            || "1-loop terms: direct integration".to_string(),
            |s| s.describe(),
        );
        h.push(format!("no-wiggle spectrum: {source}"));
        if model.needs_two_loop() {
            let two = ir.no_wiggle.two_loop_source.map(|s| s.describe());
            h.extend(two.map(|s| format!("no-wiggle spectrum: {s}")));
        }
    }
    if matches!(model, RealModel::OneLoopRegPt | RealModel::TwoLoopRegPt) {
        h.push(
            "RegPT (Taruya et al. 2012): x = k^2 sigma_d2/2, sigma_d2 = (1/6pi^2) int_qmin^(k/2) P dq; \
             1-loop: e^-2x [(1+x+G1_X)(1+x+G1_Y) P_lin + P22], G1_X = P13_XX/P_lin"
                .into(),
        );
    }
    if model.needs_gamma2() {
        h.push(
            "2-loop RegPT: e^-2x [A_X A_Y P_lin + P22 (1+x)^2 + P24_Gamma2 (1+x) + PGamma2 + P33_2L], \
             A_X = 1+x+x^2/2+G1_X(1+x)+P15_XX/P_lin; P24_Gamma2 = 2 int [X2 Gamma2_Y + Gamma2_X Y2] P P \
             (= 2 P24), PGamma2 = 2 int Gamma2_X Gamma2_Y P P, Gamma2 = 6 int F4(k1,k2,p,-p) P(p): \
             Gauss-Legendre quadrature, error = difference from a coarser layout"
                .into(),
        );
        let residual = spectra.terms.gamma2.as_ref().and_then(|g| g.basis_residual);
        h.extend(residual.map(|r| {
            format!(
                "Gamma2: linear forms on the basis functions (the same nodes), projection residual \
                 {r:.1e}; errors add its response, 2 x residual x sum |w| P"
            )
        }));
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

/// `k P_nw`, then P_dd/P_nw of every model but the EFT ones (2-loop SPT until fitted) and their errors.
fn all_models(
    header: Vec<String>,
    spectra: &RealSpectra,
    cs2: f64,
    p_nw: &crate::linear::LinearSpectrum,
) -> Result<Table> {
    let nw: Vec<f64> = spectra.k.iter().map(|&k| p_nw.eval(k)).collect();
    // The EFT models are 2-loop SPT until their counterterms are fitted: not repeated here.
    let models = RealModel::ALL
        .iter()
        .filter(|m| !m.is_eft())
        .map(|&m| RealSpectra::from_terms(m, spectra.terms.clone())?.with_counterterm(cs2))
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
