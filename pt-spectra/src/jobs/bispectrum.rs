//! `bispectrum`: the tree-level galaxy bispectrum multipoles B₀, B₂, B₄ at triangles or over triangle
//! bins ([`crate::bispectrum`]) as a table with its header.

use super::VERSION;
use crate::bispectrum::{
    BispectrumParams, BispectrumPlan, Fog, LegendreSide, PlanRules, Settings, TriangleSet,
};
use crate::error::Result;
use crate::estimate::Estimate;
use crate::output::{Table, BISPECTRUM, WAVENUMBER};
use crate::setup::Prepared;

/// What `bispectrum` computes beyond the linear spectrum.
#[derive(Debug, Clone)]
pub struct BispectrumRequest {
    /// The triangles or triangle bins.
    pub triangles: TriangleSet,
    /// The side of the Legendre polynomial.
    pub side: LegendreSide,
    /// The quadrature rules.
    pub rules: PlanRules,
    /// Bias, counterterm and stochastic parameters.
    pub params: BispectrumParams,
    /// The growth rate; `None` is f(z) of the cosmology.
    pub f: Option<f64>,
    /// AP scalings q∥, q⊥.
    pub q: (f64, f64),
    /// Fingers of God.
    pub fog: Fog,
    /// IR resummation of the BAO.
    pub ir: bool,
}

/// The table `k1 k2 k3 B0 B2 B4 err_B0 err_B2 err_B4` of `request` for the linear spectrum of
/// `prepared` (tracer spectrum: cold dark matter + baryons with massive neutrinos).
///
/// # Errors
/// As [`BispectrumPlan::new`], [`BispectrumPlan::terms`] and the parameters' validation.
pub fn bispectrum_table(prepared: &Prepared, request: &BispectrumRequest) -> Result<Table> {
    let f = request.f.unwrap_or(prepared.growth_rate);
    let settings = Settings {
        f,
        q_par: request.q.0,
        q_perp: request.q.1,
        fog: request.fog,
        ir: request.ir,
    };
    let plan = BispectrumPlan::new(request.triangles.clone(), request.side, request.rules)?;
    let terms = plan.terms(prepared.tracer_spectrum(), &settings)?;
    let b = terms.multipoles(&request.params)?;
    let rules = request.rules;
    let mut header = vec![
        format!(
            "pt-spectra {VERSION} bispectrum: tree-level galaxy bispectrum in redshift space, multipoles B0, B2, B4 \
             (Scoccimarro et al. 1999), z = {}",
            prepared.z
        ),
        format!(
            "B = 2 Z1 Z1 Z2 P P + cyclic + (1/n_bar)[b1 b_shot + f mu^2 (1 + p_shot)] Z1 P + cyclic + (1 + a_shot)/n_bar^2; \
             Z1 = b1 + f mu^2 - c1 k^2 mu^2; bias as velocileptors ((b2/2) delta^2 + bs s^2; CLASS-PT: bs = b_G2, \
             b2 = b2_CLASS-PT - (4/3) b_G2)"
        ),
        format!("parameters: {}", request.params.describe()),
        format!(
            "f = {f}{}; AP q_par = {}, q_perp = {} (B / (q_par^2 q_perp^4)); FoG {}; IR resummation {}",
            if request.f.is_none() { " (f(z) of the cosmology)" } else { "" },
            settings.q_par,
            settings.q_perp,
            request.fog.describe(),
            if request.ir {
                "of the BAO in every leg: P_nw + exp(-k^2 Sigma_tot^2(mu)) P_w"
            } else {
                "off"
            }
        ),
        format!(
            "Legendre polynomial on {}; orientations {} x {} (Gauss-Legendre in mu in [0, 1] x trapezoid in phi)",
            match request.side {
                LegendreSide::Largest => "the largest side (as the window-free estimator)".to_string(),
                LegendreSide::Index(a) => format!("side k{}", a + 1),
            },
            rules.n_mu,
            rules.n_phi,
        ),
        match request.triangles.width() {
            Some(w) => format!(
                "bin averages over all closed triangles of three shells of width {w} h/Mpc around k1, k2, k3 \
                 (weight k1 k2 k3, {} Gauss-Legendre nodes per shell panel)",
                rules.n_shell
            ),
            None => "at the given triangles (not averaged over bins)".into(),
        },
        "err_B*: difference from a coarser rule (one node fewer per shell panel, in mu and in phi)".into(),
    ];
    header.extend(prepared.description.iter().cloned());
    let mut t = Table::new(header);
    let tri = request.triangles.triangles();
    for (i, name) in ["k1", "k2", "k3"].iter().enumerate() {
        t.push(*name, WAVENUMBER, tri.iter().map(|t| t[i]).collect());
    }
    let column = |l: usize| -> Vec<Estimate> { b.iter().map(|b| b[l]).collect() };
    for (l, name) in ["B0", "B2", "B4"].iter().enumerate() {
        t.push(
            *name,
            BISPECTRUM,
            column(l).iter().map(|e| e.value).collect(),
        );
    }
    for (l, name) in ["err_B0", "err_B2", "err_B4"].iter().enumerate() {
        t.push(
            *name,
            BISPECTRUM,
            column(l).iter().map(|e| e.error).collect(),
        );
    }
    Ok(t)
}
