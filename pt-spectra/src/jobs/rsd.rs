//! `pt-spectra rsd`: redshift-space multipoles, with the halo signal-to-noise and the no-wiggle
//! reference of the paper's figures.

use super::{counterterm_line, describe_inputs, VERSION};
use crate::bias::{BiasConvention, BiasParams};
use crate::error::{Error, Result};
use crate::halo::{crossings, Bias, Noise};
use crate::linear::LinearSpectrum;
use crate::loops::bias::BiasTerms;
use crate::loops::TnsTerms;
use crate::output::{MethodNote, Table, POWER};
use crate::precision::Precision;
use crate::progress::Progress;
use crate::real::RealSpectra;
use crate::rsd::{
    fog_sigma, multipoles, DispersionInput, Fog, GalaxyTerms, MultipoleRule, Observed, RsdModel,
    RsdPlan, RsdSettings, Sigma0, DISPERSION_Q_CUT,
};
use crate::setup::Prepared;

/// Signal-to-noise levels whose crossings are reported (the paper's table_noise).
pub const SN_LEVELS: [f64; 3] = [1.0, 0.5, 0.1];

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
    /// Whether to add the no-wiggle reference `P<l>_nw` ([`no_wiggle_multipoles`]).
    pub no_wiggle: bool,
    /// The EFT counterterm c_s² [(Mpc/h)²] added to the real-space spectra ([`crate::real::counterterm`](mod@crate::real::counterterm);
    /// 0: none); in `fit` its start value if free, else its value.
    pub cs2: f64,
    /// The nonlinear galaxy bias b2, bs, b3 of the Scoccimarro and TNS models (the plan needs
    /// [`RsdPlan::with_bias_terms`]; b1 is the constant bias); `None`: linear bias.
    pub galaxy: Option<NonlinearBias>,
    /// The Alcock–Paczynski projection onto observed k ([`crate::rsd::ap`]): the plan must then be
    /// on [`Distortion::internal_grid`](crate::rsd::ap::Distortion::internal_grid) of those k.
    pub ap: Option<Observed>,
}

/// The nonlinear galaxy bias of an [`RsdRequest`], in velocileptors' convention as every model
/// takes it ([`crate::bias`]: (b2/2)δ², bs s², b3 = 2 b3nl), and the convention the user wrote it in
/// (for the header). The Scoccimarro and TNS models evaluate FAST-PT's expansion with the mapped
/// values ([`crate::rsd::GalaxyTerms`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct NonlinearBias {
    /// Second-order local bias b2.
    pub b2: f64,
    /// Tidal bias bs (bs s²).
    pub bs: f64,
    /// Cubic bias b3 (b1 b3 sig3nl in P_gg).
    pub b3: f64,
    /// The convention the values were given in.
    pub given: BiasConvention,
}

impl NonlinearBias {
    /// The bias of `b2`, `third` and `fourth` written in `convention` (bs and b3, b_G2 and b_Γ3, …:
    /// [`BiasConvention::names`]).
    pub fn new(convention: BiasConvention, b2: f64, third: f64, fourth: f64) -> Self {
        let b = BiasParams::from_convention(convention, [0.0, b2, third, fourth]);
        Self {
            b2: b.b2,
            bs: b.bs,
            b3: b.b3,
            given: convention,
        }
    }

    /// The bias with linear bias `b1`.
    pub fn with_b1(&self, b1: f64) -> BiasParams {
        BiasParams {
            b1,
            b2: self.b2,
            bs: self.bs,
            b3: self.b3,
        }
    }
}

impl RsdRequest {
    /// Checks the nonlinear bias against the model and the bias before any plan is built.
    ///
    /// # Errors
    /// [`Error::InvalidChoice`] for nonlinear bias with the Kaiser model or a b(k) table;
    /// [`Error::InvalidParameter`] for a bias that is not finite.
    pub fn validate_galaxy(&self) -> Result<()> {
        let Some(g) = self.galaxy else {
            return Ok(());
        };
        if self.rsd == RsdModel::Kaiser {
            return Err(Error::InvalidChoice {
                what: "nonlinear bias with the kaiser model".into(),
                reason: "Kaiser is linear in the bias: use scoccimarro or tns".into(),
            });
        }
        if !matches!(self.bias, Bias::Constant(_)) {
            return Err(Error::InvalidChoice {
                what: "nonlinear bias with a b(k) table".into(),
                reason: "the bias expansion has a constant b1: give it with --bias".into(),
            });
        }
        super::check_finite(&[("b2", g.b2), ("bs", g.bs), ("b3", g.b3)])
    }

    /// A description of the bias for headers.
    pub fn describe_bias(&self) -> String {
        match &self.bias {
            Bias::Constant(b) => format!("b = {b}"),
            Bias::Table(t) => format!("b(k) from {}", t.origin()),
        }
    }
}

/// How a σ0 was obtained, for headers: empty for a number, else the equation and its input.
pub fn describe_sigma0(sigma0: Sigma0) -> String {
    match sigma0 {
        Sigma0::Value(_) => String::new(),
        Sigma0::Theory(DispersionInput::Linear) => {
            " (theory: eq. sigmav, sigma^2 = (1/6pi^2) int P_lin dq, sigma0 = sigma(z)/D(z))".into()
        }
        Sigma0::Theory(DispersionInput::OneLoopSpt) => format!(
            " (theory: eq. sigmav, sigma^2 = (1/6pi^2) int P_tt dq with 1-loop SPT P_tt for q <= \
             {DISPERSION_Q_CUT} h/Mpc and P_lin above, where 1-loop P_tt turns negative; sigma0 = \
             sigma(z)/D(z))"
        ),
    }
}

/// The linear Kaiser multipoles of the no-wiggle spectrum `p_nw` with bias `bias` (amplitude included)
/// and growth rate f, without FoG: `P<l>_nw`, the smooth reference by which the paper divides
/// multipoles (its "non-wiggle linear prediction"), P_0,nw = (b² + 2bf/3 + f²/5) P_nw, P_2,nw =
/// (4bf/3 + 4f²/7) P_nw, P_4,nw = 8f²/35 P_nw. `result[j][i]` for the j-th ℓ at k_i.
///
/// # Errors
/// [`Error::LengthMismatch`] for a bias not on `k`; [`Error::InvalidParameter`] for a bad ℓ.
pub fn no_wiggle_multipoles(
    k: &[f64],
    bias: &[f64],
    f: f64,
    ells: &[usize],
    p_nw: &LinearSpectrum,
) -> Result<Vec<Vec<f64>>> {
    if bias.len() != k.len() {
        return Err(Error::LengthMismatch {
            what: "bias and k",
            left: bias.len(),
            right: k.len(),
        });
    }
    let rule = MultipoleRule::new(ells)?;
    let mut out = vec![Vec::with_capacity(k.len()); ells.len()];
    for (&ki, &b) in k.iter().zip(bias) {
        let c = RsdModel::Kaiser.coefficients(b, f, [p_nw.eval(ki); 3]);
        for (o, p) in out.iter_mut().zip(rule.evaluate(&c, Fog::None, 0.0)) {
            o.push(p.value);
        }
    }
    Ok(out)
}

/// `pt-spectra rsd`: the multipoles of `request` for the prepared linear spectrum, from the loop
/// terms of `plan`. With a noise: the columns `P_eps SN SN_s`, SN = P_hh/P_εε = (A_b b)² P_δδ/P_εε in
/// real space (the paper's signal-to-noise, P_δδ of the real-space model) and SN_s = P0/P_εε, and the
/// k where each falls to [`SN_LEVELS`] in the header.
///
/// # Errors
/// As [`RsdPlan::evaluate`], [`multipoles`], [`Bias::values`], [`Noise::values`],
/// [`Sigma0::resolve`] and (with `no_wiggle`) [`Prepared::no_wiggle`]; [`Error::InvalidParameter`] for
/// a non-finite f or c_s².
pub fn rsd_table(
    plan: &RsdPlan,
    request: &RsdRequest,
    prepared: &Prepared,
    progress: &dyn Progress,
) -> Result<Table> {
    let (spectra, tns) = plan.evaluate(prepared.tracer_spectrum(), progress)?;
    let bias_terms = match request.galaxy {
        None => None,
        Some(_) => Some(
            plan.bias_terms(prepared.tracer_spectrum())
                .ok_or(Error::MissingTerm {
                    term: "the bias terms",
                    needed_by: "the nonlinear galaxy bias".into(),
                    hint: " (RsdPlan::with_bias_terms)",
                })?,
        ),
    };
    rsd_table_with_bias_terms(
        &spectra,
        tns.as_ref(),
        bias_terms,
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
    tns: Option<&TnsTerms>,
    precision: &Precision,
    request: &RsdRequest,
    prepared: &Prepared,
) -> Result<Table> {
    rsd_table_with_bias_terms(spectra, tns, None, precision, request, prepared)
}

/// [`rsd_table_from_terms`] with the theory σ0 of the spectrum kept in `memo` between calls
/// ([`crate::rsd::Dispersions`], one per spectrum and precision): the steps of a chain with
/// `sigma0 = lin` or `1l-spt` then integrate it once.
///
/// # Errors
/// As [`rsd_table`].
pub fn rsd_table_from_terms_memo(
    spectra: &RealSpectra,
    tns: Option<&TnsTerms>,
    precision: &Precision,
    request: &RsdRequest,
    prepared: &Prepared,
    memo: &crate::rsd::Dispersions,
) -> Result<Table> {
    rsd_table_memo(spectra, tns, None, precision, request, prepared, memo)
}

/// [`rsd_table_from_terms`] with the bias terms of the spectrum, which a request with nonlinear bias
/// ([`RsdRequest::galaxy`]) needs.
///
/// # Errors
/// As [`rsd_table_from_terms`]; [`Error::MissingTerm`] for nonlinear bias without `bias_terms`,
/// [`Error::InvalidChoice`] for it with a b(k) table or the Kaiser model.
pub fn rsd_table_with_bias_terms(
    spectra: &RealSpectra,
    tns: Option<&TnsTerms>,
    bias_terms: Option<BiasTerms>,
    precision: &Precision,
    request: &RsdRequest,
    prepared: &Prepared,
) -> Result<Table> {
    let memo = crate::rsd::Dispersions::default();
    rsd_table_memo(
        spectra, tns, bias_terms, precision, request, prepared, &memo,
    )
}

/// The body of the tables above, the theory σ0 kept in `memo`.
fn rsd_table_memo(
    spectra: &RealSpectra,
    tns: Option<&TnsTerms>,
    bias_terms: Option<BiasTerms>,
    precision: &Precision,
    request: &RsdRequest,
    prepared: &Prepared,
    memo: &crate::rsd::Dispersions,
) -> Result<Table> {
    let k = &spectra.k;
    let f = request.f.unwrap_or(prepared.growth_rate);
    check_growth_rate(f)?;
    let growth = prepared.growth_factor;
    let sigma0 =
        request
            .sigma0
            .resolve_with(prepared.tracer_spectrum(), growth, precision, memo)?;
    let sigma = fog_sigma(sigma0, growth, f);
    let bias = request.bias.values(k, request.amplitude)?;
    request.validate_galaxy()?;
    let galaxy = match (request.galaxy, bias_terms) {
        (None, _) => None,
        (Some(_), None) => {
            return Err(Error::MissingTerm {
                term: "the bias terms",
                needed_by: "the nonlinear galaxy bias".into(),
                hint: " (RsdPlan::with_bias_terms)",
            })
        }
        (Some(g), Some(terms)) => {
            let [_, b2, bs, b3nl] = g.with_b1(0.0).in_convention(BiasConvention::FastPt);
            Some(GalaxyTerms {
                b2,
                bs,
                b3nl,
                terms,
            })
        }
    };
    let settings = RsdSettings {
        model: request.rsd,
        f,
        bias: bias.clone(),
        fog: request.fog,
        sigma,
        noise: request.noise.values(k)?,
        ells: request.ells.clone(),
        parts: request.terms,
        cs2: request.cs2,
        galaxy,
        ap: request.ap.clone(),
    };
    let m = multipoles(spectra, tns, &settings)?;
    let (rsd, fog) = (request.rsd, request.fog);
    let mut header = vec![format!(
        "pt-spectra {VERSION} rsd: {rsd} with real-space {}, z = {}, f = {f}, {} times A_b = {}, \
         FoG {fog:?} with sigma0 = {sigma0} Mpc/h{} (sigma = sigma0 D(z) f = {sigma:.6} Mpc/h)",
        spectra.model,
        prepared.z,
        request.describe_bias(),
        request.amplitude,
        describe_sigma0(request.sigma0),
    )];
    header.extend(describe_inputs(prepared, precision));
    if request.cs2 != 0.0 {
        header.push(counterterm_line(request.cs2));
    }
    header.extend(spectra.terms.one_loop_source.map(|s| s.describe()));
    if rsd.needs_tns() {
        header.push(
            "TNS A and B at leading order (linear P, tree-level bispectrum), A = b^3 A(f/b), \
             B = b^4 B(f/b)"
                .into(),
        );
        if let Some(tns) = tns.filter(|t| t.basis_residual.is_some()) {
            header.push(format!(
                "TNS A and B: basis tensors, the same quadrature nodes as direct; projection \
                 residual {:.1e}; errors include the projection error (2 x residual x the \
                 magnitudes of each coefficient's parts){}",
                tns.basis_residual.unwrap_or_default(),
                crate::loops::basis::soft::describe(tns.basis_soft)
            ));
        }
    }
    if let Some(g) = request.galaxy {
        let [_, b2, bs, b3nl] = g.with_b1(0.0).in_convention(BiasConvention::FastPt);
        header.push(g.with_b1(0.0).describe_nonlinear(g.given));
        header.push(format!(
            "nonlinear galaxy bias (Beutler et al. 2017) in FAST-PT's convention: b1 = A_b b, b2 = {}, \
             bs = {}, b3nl = {}; P^s = P_gg + 2 f mu^2 P_gt + f^2 mu^4 P_tt (+ A, B of b1), P_gg = b1^2 P_dd + b1 b2 Pd1d2 \
             + 1/4 b2^2 Pd2d2 + b1 bs Pd1s2 + 1/2 b2 bs Pd2s2 + 1/4 bs^2 Ps2s2 + 2 b1 b3nl sig3nl, P_gt \
             = b1 P_dt + 1/2 b2 Pt1d2 + 1/2 bs Pt1s2 + b3nl sig3nl (FAST-PT's bias terms, no constant \
             subtracted: the k -> 0 constant 1/4 b2^2 Pd2d2 + ... acts as a shot noise)",
            b2, bs, b3nl
        ));
    }
    header.push(
        "P_l = (2l+1) int_0^1 dmu P^s(k,mu) L_l(mu) of the noise-free model (the paper's P^s_hh = \
         <d_h d_h> - P_eps); err_P_l bounds the numerical error (loop integrals and mu quadrature)"
            .into(),
    );
    if let (Some(sn), Some(sn_s)) = (&m.signal_to_noise, &m.signal_to_noise_s) {
        header.push(crossing_line(
            "signal-to-noise SN = P_hh/P_eps = b^2 P_dd/P_eps (real space, as the paper)",
            k,
            sn,
        ));
        header.push(crossing_line(
            "redshift-space ratio SN_s = P0/P_eps",
            k,
            sn_s,
        ));
    }
    if request.no_wiggle {
        header.push(
            "P<l>_nw: linear Kaiser multipoles of the Eisenstein & Hu no-wiggle spectrum (same b(k) \
             and f, no FoG), the reference the paper divides multipoles by"
                .into(),
        );
    }
    if let Some(ap) = &request.ap {
        let (d, grid) = (ap.distortion, &spectra.k);
        header.push(format!(
            "Alcock-Paczynski: apar = {}, aperp = {}; observed P_l(k) = (2l+1) int_0^1 dmu L_l(mu) \
             P^s(k', mu')/(apar aperp^2), k' = (k/aperp) sqrt(1 + mu^2 (F^-2 - 1)), mu' = mu/(F sqrt(1 + \
             mu^2 (F^-2 - 1))), F = apar/aperp; the model on {} k in [{:.6e}, {:.6e}] h/Mpc \
             (a cubic B-spline in ln k), {}-point Gauss-Legendre in mu (error from half as many); \
             wide-angle terms neglected",
            d.apar,
            d.aperp,
            grid.len(),
            grid[0],
            grid[grid.len() - 1],
            crate::rsd::ap::MU_NODES
        ));
    }
    let mut t = super::rsd_multipoles_table(&m, header);
    let model = spectra.model;
    t.methods = spectra
        .terms
        .methods(model.needs_two_loop(), model.needs_ir());
    if rsd.needs_tns() {
        let basis = tns.is_some_and(|t| t.basis_residual.is_some());
        t.methods.push(MethodNote::new(
            "TNS A and B",
            if basis { "basis" } else { "direct" },
        ));
    }
    if request.no_wiggle {
        let (k, bias) = match &request.ap {
            None => (k.clone(), bias.clone()),
            Some(ap) => (ap.k.clone(), request.bias.values(&ap.k, request.amplitude)?),
        };
        let nw = no_wiggle_multipoles(&k, &bias, f, &request.ells, &prepared.no_wiggle()?)?;
        for (l, p) in request.ells.iter().zip(nw) {
            t.push(format!("P{l}_nw"), POWER, p);
        }
    }
    Ok(t)
}

/// Where `sn` falls to each of [`SN_LEVELS`]: `<what> falls to 1 at k = …; …`.
fn crossing_line(what: &str, k: &[f64], sn: &[f64]) -> String {
    let mut text = format!("{what} falls to");
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

pub use crate::cosmology::check_growth_rate;

/// `rsd --xi`: the correlation-function multipoles ξ_ℓ(s) of a multipole table `t` (columns `k`,
/// `P<l>`, `err_P<l>` for each of `ells`) at `s` [Mpc/h], by FFTLog ([`crate::hankel::xi_from_pk`]:
/// the multipoles on the table's k, extended beyond its ends by power laws). `err_xi<l>` bounds the
/// error that the multipoles' errors carry, ∫ k²/(2π²) err_P_l(k) |j_l(ks)| dk ≤ ∫ k²/(2π²) err_P_l dk
/// (trapezoid on the table's k), plus 1e-6 of max |ξ_l| for the transform.
///
/// # Errors
/// [`Error::MissingTerm`] if a column is missing; as [`crate::hankel::xi_from_pk`].
pub fn xi_table(t: &Table, ells: &[usize], s: &[f64]) -> Result<Table> {
    let column = |name: &str| {
        t.column(name).ok_or(Error::MissingTerm {
            term: "a multipole column",
            needed_by: format!("the correlation function ({name})"),
            hint: "",
        })
    };
    let k = column("k")?;
    let mut header = t.header.clone();
    header.push(format!(
        "correlation-function multipoles xi_l(s) = i^l int k^2 dk/(2 pi^2) P_l(k) j_l(ks) by FFTLog \
         (Hamilton 2000) of the P_l on {} k in [{:e}, {:e}] h/Mpc, extended by power laws beyond them; \
         err_xi_l = int k^2/(2 pi^2) err_P_l dk + 1e-6 max|xi_l| (a bound; the transform itself: \
         <= 1e-6 on the tests' analytic pairs)",
        k.len(),
        k[0],
        k[k.len() - 1]
    ));
    let mut out = Table::new(header);
    out.push("s", "Mpc/h", s.to_vec());
    let mut errors = Vec::with_capacity(ells.len());
    for &l in ells {
        let (p, e) = (column(&format!("P{l}"))?, column(&format!("err_P{l}"))?);
        let xi = crate::hankel::xi_from_pk(k, p, l, s)?;
        let bound: f64 = k
            .windows(2)
            .zip(e.windows(2))
            .map(|(k, e)| 0.5 * (k[1] - k[0]) * (k[0] * k[0] * e[0] + k[1] * k[1] * e[1]))
            .sum::<f64>()
            / (2.0 * std::f64::consts::PI.powi(2));
        let largest = xi.iter().fold(0.0_f64, |m, v| m.max(v.abs()));
        errors.push(vec![bound + 1e-6 * largest; s.len()]);
        out.push(format!("xi{l}"), "1", xi);
    }
    for (&l, e) in ells.iter().zip(errors) {
        out.push(format!("err_xi{l}"), "1", e);
    }
    Ok(out)
}
