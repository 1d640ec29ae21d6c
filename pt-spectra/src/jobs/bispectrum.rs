//! `bispectrum`: the tree-level galaxy bispectrum multipoles B₀, B₂, B₄ at triangles or over triangle
//! bins, or the Sugiyama multipoles B_{ℓ₁ℓ₂L} at (k₁, k₂) pairs ([`crate::bispectrum`]), as a table with
//! its header.

use super::VERSION;
use crate::bispectrum::one_loop::{OneLoopMatter, OneLoopRule, COUNTERTERMS, PARTITION_POWER};
use crate::bispectrum::one_loop_basis::{
    BispectrumLoopSource, OneLoopMatterBasis, OneLoopMatterPlan,
};
use crate::bispectrum::one_loop_rsd::{one_loop_matter_redshift, Orientation};
use crate::bispectrum::{
    BispectrumParams, BispectrumPlan, BoxPlan, Fog, LegendreSide, PlanRules, Settings,
    SugiyamaPlan, SugiyamaRules, TriangleSet, SUGIYAMA_MULTIPOLES,
};
use crate::error::{Error, Result};
use crate::estimate::Estimate;
use crate::output::{MethodNote, Table, WAVENUMBER};

use crate::precision::TwoLoopMethod;
use crate::progress::Progress;
use crate::setup::Prepared;
use crate::store::TableStore;

/// The unit of bispectra.
pub(super) const BISPECTRUM: &str = "(Mpc/h)^6";
/// Unit of a bispectrum counterterm shape: P P k², a bispectrum per coefficient in (Mpc/h)².
pub(super) const BISPECTRUM_SHAPE: &str = "(Mpc/h)^4";

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
    /// Average the bins exactly over the discrete modes of a periodic box of this side [Mpc/h]
    /// (line of sight z) instead of continuous shells.
    pub box_size: Option<f64>,
}

/// The table `k1 k2 k3 B0 B2 B4 err_B0 err_B2 err_B4` of `request` for the linear spectrum of
/// `prepared` (tracer spectrum: cold dark matter + baryons with massive neutrinos).
///
/// # Errors
/// As [`BispectrumPlan::new`], [`BispectrumPlan::terms`] and the parameters' validation.
pub fn bispectrum_table(prepared: &Prepared, request: &BispectrumRequest) -> Result<Table> {
    let settings = settings(prepared, request.f, request.q, request.fog, request.ir);
    if request.rules.effective
        && (request.box_size.is_some() || request.triangles.width().is_none())
    {
        return Err(Error::InvalidChoice {
            what: "the effective-triangle shortcut".into(),
            reason:
                "is for bins of continuous shells (--k-edges, or --triangles with --bin-width), \
                     not for single triangles or --box"
                    .into(),
        });
    }
    let terms = match request.box_size {
        Some(l) => BoxPlan::new(request.triangles.clone(), request.side, l)?
            .terms(prepared.tracer_spectrum(), &settings)?,
        None => BispectrumPlan::new(request.triangles.clone(), request.side, request.rules)?
            .terms(prepared.tracer_spectrum(), &settings)?,
    };
    let b = terms.multipoles(&request.params)?;
    let rules = request.rules;
    let mut header = vec![format!(
        "pt-spectra {VERSION} bispectrum: tree-level galaxy bispectrum in redshift space, multipoles B0, B2, B4 \
         (Scoccimarro et al. 1999), z = {}",
        prepared.z
    )];
    header.extend(model_lines(&request.params, request.f, &settings));
    header.extend([
        format!(
            "Legendre polynomial on {}; orientations {} x {} (Gauss-Legendre in mu in [0, 1] x trapezoid in phi)",
            match request.side {
                LegendreSide::Largest => "the largest side (as the window-free estimator)".to_string(),
                LegendreSide::Index(a) => format!("side k{}", a + 1),
            },
            rules.n_mu,
            rules.n_phi,
        ),
        match (request.box_size, request.triangles.width()) {
            (Some(l), Some(w)) => format!(
                "bin averages over the discrete modes of a periodic box of side {l} Mpc/h (k_f = 2 pi/L, line of \
                 sight z): every ordered triple of modes in the three shells of width {w} h/Mpc around k1, k2, k3; \
                 exact sums, err_B* = 0 (round-off ~1e-13)"
            ),
            (_, Some(w)) if rules.effective => format!(
                "effective-triangle shortcut: each bin of width {w} h/Mpc evaluated at its mean sides over its closed \
                 triangles (weight k1 k2 k3), not averaged; err_B* includes twice the shortcut's distance from the \
                 bin average measured on the reference prediction (gm2012 z = 0.5, f = 0.72, b1 = 2, IR), relative to B0"
            ),
            (_, Some(w)) => format!(
                "bin averages over all closed triangles of three shells of width {w} h/Mpc around k1, k2, k3 \
                 (weight k1 k2 k3, {} Gauss-Legendre nodes per shell panel)",
                rules.n_shell
            ),
            (_, None) => "at the given triangles (not averaged over bins)".into(),
        },
        "err_B*: difference from a coarser rule (one node fewer per shell panel, in mu and in phi)".into(),
    ]);
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

/// The settings of a request: f defaults to f(z) of `prepared`'s cosmology.
fn settings(prepared: &Prepared, f: Option<f64>, q: (f64, f64), fog: Fog, ir: bool) -> Settings {
    Settings {
        f: f.unwrap_or(prepared.growth_rate),
        q_par: q.0,
        q_perp: q.1,
        fog,
        ir,
    }
}

/// The header lines of the model: formula, parameters, f, AP, FoG and IR.
fn model_lines(params: &BispectrumParams, f: Option<f64>, settings: &Settings) -> [String; 3] {
    [
        "B = 2 Z1 Z1 Z2 P P + cyclic + (1/n_bar)[b1 b_shot + f mu^2 (1 + p_shot)] Z1 P + cyclic + (1 + a_shot)/n_bar^2; \
         Z1 = b1 + f mu^2 - c1 k^2 mu^2; bias as velocileptors ((b2/2) delta^2 + bs s^2; CLASS-PT: bs = b_G2, \
         b2 = b2_CLASS-PT - (4/3) b_G2)"
            .to_string(),
        format!("parameters: {}", params.describe()),
        format!(
            "f = {}{}; AP q_par = {}, q_perp = {} (B / (q_par^2 q_perp^4)); FoG {}; IR resummation {}",
            settings.f,
            if f.is_none() { " (f(z) of the cosmology)" } else { "" },
            settings.q_par,
            settings.q_perp,
            settings.fog.describe(),
            if settings.ir {
                "of the BAO in every leg: P_nw + exp(-k^2 Sigma_tot^2(mu)) P_w"
            } else {
                "off"
            }
        ),
    ]
}

/// What the Sugiyama multipoles are computed for beyond the linear spectrum.
#[derive(Debug, Clone)]
pub struct SugiyamaRequest {
    /// The pairs (k₁, k₂) [h/Mpc].
    pub pairs: Vec<[f64; 2]>,
    /// The quadrature rules.
    pub rules: SugiyamaRules,
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

/// The table `k1 k2 B000 B110 B202 B022 B112 B220 err_B000 …` of `request` for the linear spectrum of
/// `prepared` (tracer spectrum).
///
/// # Errors
/// As [`SugiyamaPlan::new`], [`SugiyamaPlan::terms`] and the parameters' validation.
pub fn sugiyama_table(prepared: &Prepared, request: &SugiyamaRequest) -> Result<Table> {
    let settings = settings(prepared, request.f, request.q, request.fog, request.ir);
    let plan = SugiyamaPlan::new(request.pairs.clone(), request.rules)?;
    let b = plan
        .terms(prepared.tracer_spectrum(), &settings)?
        .multipoles(&request.params)?;
    let r = request.rules;
    let mut header = vec![format!(
        "pt-spectra {VERSION} bispectrum: tree-level galaxy bispectrum in redshift space, Sugiyama et al. (2019) \
         multipoles B_l1l2L(k1, k2) (angle between k1 and k2 integrated), z = {}",
        prepared.z
    )];
    header.extend(model_lines(&request.params, request.f, &settings));
    header.extend([
        "B_l1l2L = (1/8pi) int dx dmu1 dphi w B, x = k1^.k2^, mu1 = k1^.n^, phi the azimuth of k2 about k1; \
         w = 1 (000), 3x (110), 5 L2(mu1) (202), 5 L2(mu2) (022), 3(3 mu1 mu2 - x) (112, tripolar; FolpsD's \
         B112 has 2 sqrt3 for the azimuthal 3), 5 L2(x) (220)"
            .to_string(),
        format!(
            "quadrature: k3 = |k1 + k2| on {} Gauss-Legendre panels x {} (clustered at |k1 - k2|), mu1 {} x phi {}; \
             err_B*: difference from the coarser rule {:?}",
            r.n_panels,
            r.n_k3,
            r.n_mu,
            r.n_phi,
            r.coarse()
        ),
    ]);
    header.extend(prepared.description.iter().cloned());
    let mut t = Table::new(header);
    for (i, name) in ["k1", "k2"].iter().enumerate() {
        t.push(
            *name,
            WAVENUMBER,
            request.pairs.iter().map(|p| p[i]).collect(),
        );
    }
    let column = |m: usize| -> Vec<Estimate> { b.iter().map(|b| b[m]).collect() };
    for (m, name) in SUGIYAMA_MULTIPOLES.iter().enumerate() {
        let values = column(m).iter().map(|e| e.value).collect();
        t.push(format!("B{name}"), BISPECTRUM, values);
    }
    for (m, name) in SUGIYAMA_MULTIPOLES.iter().enumerate() {
        let errors = column(m).iter().map(|e| e.error).collect();
        t.push(format!("err_B{name}"), BISPECTRUM, errors);
    }
    Ok(t)
}

/// The one-loop matter bispectrum plan of `triangles` and `rule` whose loop terms are computed by
/// `method`: `direct`, `basis` (the tensors from `store`, built once, reporting to `progress`, and
/// cached) or `auto` (the tensors if cached, else direct); and whether `auto` found none.
///
/// # Errors
/// As [`OneLoopMatterPlan::new`] (sides that do not close, naming the triangle; a bad rule).
pub fn one_loop_bispectrum_plan(
    triangles: &[[f64; 3]],
    rule: &OneLoopRule,
    method: TwoLoopMethod,
    store: &TableStore,
    progress: &dyn Progress,
) -> Result<(OneLoopMatterPlan, bool)> {
    let plan = OneLoopMatterPlan::new(triangles.to_vec(), *rule)?;
    // the plan above has checked the triangles and the rule: the build cannot fail
    let build = |tick: &(dyn Fn(usize, usize) + Sync)| {
        OneLoopMatterBasis::build(triangles, rule, tick).expect("triangles and rule checked")
    };
    let tensors =
        store.for_method::<OneLoopMatterBasis>(method, (triangles, rule), build, progress)?;
    let uncached = method == TwoLoopMethod::Auto && tensors.is_none();
    Ok(match tensors {
        Some(t) => (plan.with_basis(t)?, false),
        None => (plan, uncached),
    })
}

/// The table `k1 k2 k3 B_tree B222 B321_I B321_II B411 B_1loop` and their `err_` columns of the one-loop
/// matter bispectrum in real space at `triangles` (points) for the all-matter linear spectrum of
/// `prepared` ([`crate::bispectrum::one_loop`]), the loop terms computed by `method`: `direct`, `basis`
/// (the tensors of [`crate::bispectrum::one_loop_basis`] from `store`, built once and cached) or `auto`
/// (the tensors if cached, else direct); direct integrals report each triangle to `progress`.
///
/// # Errors
/// As [`OneLoopMatterPlan::new`] (sides that do not close, naming the triangle; a bad rule).
pub fn one_loop_bispectrum_table(
    prepared: &Prepared,
    triangles: &[[f64; 3]],
    rule: &OneLoopRule,
    method: TwoLoopMethod,
    store: &TableStore,
    progress: &dyn Progress,
) -> Result<Table> {
    let (plan, uncached) = one_loop_bispectrum_plan(triangles, rule, method, store, progress)?;
    let (rows, mut source) = plan.evaluate_reporting(&prepared.spectrum, &|d, t| {
        progress.update(crate::bispectrum::seam::ONE_LOOP_STAGE, d, t);
    })?;
    if uncached {
        source = BispectrumLoopSource::DirectUncached;
    }
    let mut header = vec![
        format!(
            "pt-spectra {VERSION} bispectrum --loop 1: one-loop matter bispectrum in real space (SPT), z = {}",
            prepared.z
        ),
        "B_1loop = B_tree + B222 + B321_I + B321_II + B411 (Scoccimarro 1997; Sefusatti et al. 2010 eqs. 17-21), \
         exact generated kernels F2..F4; no counterterms in B_1loop: the columns shape_ct_* are the four EFT \
         counterterm shapes, B_ct = sum_c ct_c shape_ct_c with coefficients ct_c in (Mpc/h)^2 (docs/bispectrum.md)"
            .into(),
        format!(
            "loop integrals over {} <= |q| <= {} h/Mpc about each cusp (smooth partition of unity, power {}); \
             {} ln q x {} cos(theta) x {} phi nodes per panel; err_: difference from the rule with half the nodes",
            rule.q_min, rule.q_max, PARTITION_POWER, rule.radial, rule.mu, rule.phi
        ),
        source.describe(),
        "at the given triangles (not averaged over bins); linear spectrum: all matter".into(),
    ];
    if prepared.spectrum_cb.is_some() {
        header.push(
            "warning: massive neutrinos: the loops are those of the total matter spectrum as one fluid \
             (neutrino free-streaming inside the loops is not modelled)"
                .into(),
        );
    }
    header.extend(prepared.description.iter().cloned());
    let mut t = Table::new(header);
    t.methods
        .push(MethodNote::new("loop terms", source.method()));
    let terms = |b: &OneLoopMatter| [b.tree, b.b222, b.b321_i, b.b321_ii, b.b411, b.total()];
    one_loop_columns(
        &mut t,
        &rows.iter().map(|b| (b.k, terms(b))).collect::<Vec<_>>(),
    );
    for (j, name) in COUNTERTERMS.iter().enumerate() {
        t.push(
            format!("shape_{name}"),
            BISPECTRUM_SHAPE,
            rows.iter().map(|b| b.counterterm_shapes[j]).collect(),
        );
    }
    Ok(t)
}

/// The columns `k1 k2 k3 B_tree B222 B321_I B321_II B411 B_1loop` and their `err_` of one-loop terms,
/// per triangle its sides and (tree, B222, B321_I, B321_II, B411, total).
pub(super) fn one_loop_columns(t: &mut Table, rows: &[([f64; 3], [Estimate; 6])]) {
    for (i, name) in ["k1", "k2", "k3"].iter().enumerate() {
        t.push(*name, WAVENUMBER, rows.iter().map(|r| r.0[i]).collect());
    }
    let names = ["B_tree", "B222", "B321_I", "B321_II", "B411", "B_1loop"];
    for (j, name) in names.iter().enumerate() {
        t.push(
            *name,
            BISPECTRUM,
            rows.iter().map(|r| r.1[j].value).collect(),
        );
    }
    for (j, name) in names.iter().enumerate() {
        t.push(
            format!("err_{name}"),
            BISPECTRUM,
            rows.iter().map(|r| r.1[j].error).collect(),
        );
    }
}

/// The table `k1 k2 k3 B_tree B222 B321_I B321_II B411 B_1loop` and their `err_` columns of the one-loop
/// matter bispectrum in redshift space ([`crate::bispectrum::one_loop_rsd`]) at `triangles` (points)
/// at growth rate `f` (default f(z)) and `orientation` to the line of sight, for the all-matter
/// linear spectrum of `prepared`, directly, reporting each triangle to `progress`.
///
/// # Errors
/// As [`one_loop_matter_redshift`], naming the triangle.
pub fn one_loop_redshift_table(
    prepared: &Prepared,
    triangles: &[[f64; 3]],
    f: Option<f64>,
    orientation: Orientation,
    rule: &OneLoopRule,
    progress: &dyn Progress,
) -> Result<Table> {
    let f = f.unwrap_or(prepared.growth_rate);
    let mut rows = Vec::with_capacity(triangles.len());
    for (i, &k) in triangles.iter().enumerate() {
        let b =
            one_loop_matter_redshift(&prepared.spectrum, k, f, orientation, rule).map_err(|e| {
                Error::InvalidChoice {
                    what: format!("triangle {} ({}, {}, {})", i + 1, k[0], k[1], k[2]),
                    reason: e.to_string(),
                }
            })?;
        rows.push((k, [b.tree, b.b222, b.b321_i, b.b321_ii, b.b411, b.total()]));
        progress.update(
            crate::bispectrum::seam::ONE_LOOP_STAGE,
            i + 1,
            triangles.len(),
        );
    }
    let mut header = vec![
        format!(
            "pt-spectra {VERSION} bispectrum --loop 1: one-loop matter bispectrum in redshift space (SPT), z = {}, \
             f = {f}, line of sight at mu1 = {} (cosine to k1), phi = {} rad (azimuth about k1 from the \
             triangle's plane, on the side of k2)",
            prepared.z, orientation.mu1, orientation.phi
        ),
        "B_1loop = B_tree + B222 + B321_I + B321_II + B411 with the exact generated redshift-space kernels Z1..Z4 \
         (Scoccimarro, Couchman & Frieman 1999) in place of F_n and Z1 on the linear legs; no counterterms, \
         bias, IR resummation or average over orientations yet (docs/bispectrum.md)"
            .into(),
        format!(
            "loop integrals over {} <= |q| <= {} h/Mpc about each cusp (smooth partition of unity, power {}); \
             {} ln q x {} cos(theta) x {} phi nodes per half circle and panel (phi over the whole circle unless the line of \
             sight lies in the triangle's plane); err_: difference from the rule with half the nodes; \
             loop terms: direct integration",
            rule.q_min, rule.q_max, PARTITION_POWER, rule.radial, rule.mu, rule.phi
        ),
        "at the given triangles (not averaged over bins); linear spectrum: all matter".into(),
    ];
    header.extend(prepared.description.iter().cloned());
    let mut t = Table::new(header);
    t.methods.push(MethodNote::new("loop terms", "direct"));
    one_loop_columns(&mut t, &rows);
    Ok(t)
}
