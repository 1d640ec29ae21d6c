//! The library's redshift-space entry point: multipoles from real-space spectra, an RSD model, f,
//! bias, Fingers of God and noise ([`multipoles`]), and the plan that computes the loop terms they
//! need once per k grid ([`RsdPlan`]).

use super::ap::{observed_multipoles, Distortion};
use super::{Fog, MuPolynomial, MultipoleRule, Parts, RsdModel};
use crate::error::{Error, Result};
use crate::estimate::Estimate;
use crate::linear::LinearSpectrum;
use crate::loops::basis::{TnsBasis, MAX_RESIDUAL};
use crate::loops::bias::{BiasPlan, BiasTerms, GalaxyBias};
use crate::loops::{Pair, TnsPlan, TnsTerms};
use crate::precision::Precision;
use crate::progress::Progress;
use crate::real::{counterterm, RealModel, RealPlan, RealSpectra};
use crate::store::TableStore;
use crate::table::describe_grid;

/// What turns real-space spectra into redshift-space multipoles.
#[derive(Debug, Clone, PartialEq)]
pub struct RsdSettings {
    /// Kaiser, Scoccimarro or TNS.
    pub model: RsdModel,
    /// The growth rate f.
    pub f: f64,
    /// The bias b(k) at each k, amplitude A_b included.
    pub bias: Vec<f64>,
    /// The Fingers-of-God damping.
    pub fog: Fog,
    /// Its scale σ = σ0 D(z) f [Mpc/h] ([`super::fog_sigma`]).
    pub sigma: f64,
    /// The stochasticity P_εε [(Mpc/h)^3] at each k, if any. The models are of the noise-subtracted
    /// spectrum P^s_hh = ⟨δ_h δ_h⟩ − P_εε (which P_εε, μ-independent, changes only in the monopole), so
    /// P_εε is neither added to nor subtracted from them: it is reported with the signal-to-noise.
    pub noise: Option<Vec<f64>>,
    /// The multipoles ℓ (even, ≤ 8).
    pub ells: Vec<usize>,
    /// Whether to also compute the multipoles of each part (Kaiser/Scoccimarro, A, B).
    pub parts: bool,
    /// The EFT counterterm c_s² [(Mpc/h)²] added to the real-space P_δδ, P_δθ, P_θθ before the RSD
    /// model (−2, −4, −6 c_s² k² P_lin, [`crate::real::counterterm`](mod@crate::real::counterterm); on top of any the spectra
    /// include); 0 for none.
    pub cs2: f64,
    /// The nonlinear galaxy bias of the Scoccimarro and TNS models (Beutler et al. 2017), if any:
    /// P_δδ, P_δθ then enter through P_gg, P_gθ of the bias expansion, with b1 = the bias above.
    pub galaxy: Option<GalaxyTerms>,
    /// The Alcock–Paczynski projection, if any: the real-space spectra are then on the internal grid
    /// of [`Distortion::internal_grid`] and the multipoles on the observed grid of [`Observed`].
    pub ap: Option<Observed>,
}

/// Multipoles observed in a fiducial cosmology: the distortion and the observed k [h/Mpc].
#[derive(Debug, Clone, PartialEq)]
pub struct Observed {
    /// α∥ and α⊥.
    pub distortion: Distortion,
    /// The observed wavenumbers [h/Mpc].
    pub k: Vec<f64>,
}

/// The nonlinear bias of galaxies in the Scoccimarro and TNS models (the BOSS DR12 model of Beutler
/// et al. 2017, arXiv:1607.03150, in FAST-PT's normalisation of the bias terms): b2, bs = b_s², b3nl
/// and the bias terms of the spectrum on the grid. b1 is [`RsdSettings::bias`] at each k.
#[derive(Debug, Clone, PartialEq)]
pub struct GalaxyTerms {
    /// Second-order local bias b2.
    pub b2: f64,
    /// Tidal bias b_s².
    pub bs: f64,
    /// Non-local cubic bias b3nl.
    pub b3nl: f64,
    /// The bias terms on the grid of the real-space spectra.
    pub terms: BiasTerms,
}

/// Redshift-space multipoles on a k grid [(Mpc/h)^3].
#[derive(Debug, Clone, PartialEq)]
pub struct RsdMultipoles {
    /// Wavenumbers [h/Mpc].
    pub k: Vec<f64>,
    /// The multipole orders.
    pub ells: Vec<usize>,
    /// P_ℓ(k): `total[j][i]` for the j-th ℓ at the i-th k, with its error (loop integrals and μ
    /// quadrature).
    pub total: Vec<Vec<Estimate>>,
    /// With [`RsdSettings::parts`]: the multipoles of the Kaiser/Scoccimarro part, of the TNS A term
    /// and of the TNS B term, each indexed as `total`.
    pub parts: Option<[Vec<Vec<Estimate>>; 3]>,
    /// P_εε at each k, if a noise was given.
    pub noise: Option<Vec<f64>>,
    /// The paper's signal-to-noise P_hh/P_εε in real space at each k, P_hh = b² P_δδ (b with its
    /// amplitude, P_δδ of the real-space model), if a noise was given.
    pub signal_to_noise: Option<Vec<f64>>,
    /// The redshift-space ratio P0/P_εε at each k, if a noise was given.
    pub signal_to_noise_s: Option<Vec<f64>>,
}

/// The multipoles of `settings.model` applied to the real-space spectra `real` (with `tns`, the TNS
/// A and B coefficients on the same grid, for [`RsdModel::Tns`]).
///
/// # Errors
/// [`Error::GridMismatch`] if the bias, noise or TNS terms are not on the grid of `real`;
/// [`Error::MissingTerm`] for TNS without `tns`; [`Error::InvalidParameter`] for a non-finite f or
/// c_s², σ < 0, or a bad ℓ.
///
/// ```
/// use pt_spectra::{linear::LinearSpectrum, precision::Precision, store::TableStore};
/// use pt_spectra::real::{real_space, RealModel};
/// use pt_spectra::rsd::{multipoles, Fog, RsdModel, RsdSettings};
/// let p = LinearSpectrum::gm2012(0.0)?;
/// let real = real_space(RealModel::Linear, &p, &[0.05], &Precision::fast(), &TableStore::in_memory())?;
/// let settings = RsdSettings {
///     model: RsdModel::Kaiser, f: 0.5, bias: vec![2.0], fog: Fog::None, sigma: 0.0, noise: None,
///     ells: vec![0, 2], parts: false, cs2: 0.0, galaxy: None, ap: None,
/// };
/// let m = multipoles(&real, None, &settings)?;
/// // Linear Kaiser: P0 = (b² + 2bf/3 + f²/5) P_lin.
/// let expected = (4.0 + 2.0 / 3.0 + 0.05) * real.p_lin[0];
/// assert!((m.total[0][0].value / expected - 1.0).abs() < 1e-14);
/// # Ok::<(), pt_spectra::error::Error>(())
/// ```
pub fn multipoles(
    real: &RealSpectra,
    tns: Option<&TnsTerms>,
    settings: &RsdSettings,
) -> Result<RsdMultipoles> {
    let k = &real.k;
    check_grid("bias and real-space spectra", k, settings.bias.len())?;
    if let Some(noise) = &settings.noise {
        check_grid("noise and real-space spectra", k, noise.len())?;
    }
    if let Some(g) = &settings.galaxy {
        check_grid("bias terms and real-space spectra", k, g.terms.k.len())?;
        if g.terms.k != *k {
            return Err(Error::GridMismatch {
                what: "bias terms and real-space spectra",
                expected: describe_grid(k),
                found: describe_grid(&g.terms.k),
            });
        }
    }
    let tns = match (settings.model.needs_tns(), tns) {
        (false, _) => None,
        (true, None) => {
            return Err(Error::MissingTerm {
                term: "the TNS A and B coefficients",
                needed_by: "the tns model".into(),
                hint: " (TnsPlan, or an RsdPlan)",
            })
        }
        (true, Some(t)) if t.k != *k => {
            return Err(Error::GridMismatch {
                what: "TNS terms and real-space spectra",
                expected: describe_grid(k),
                found: describe_grid(&t.k),
            })
        }
        (true, Some(t)) => Some(t),
    };
    if !settings.f.is_finite() {
        return Err(invalid("f", settings.f, "must be finite"));
    }
    crate::real::check_cs2(settings.cs2)?;
    if !(settings.sigma.is_finite() && settings.sigma >= 0.0) {
        let reason = "must be finite and non-negative";
        return Err(invalid("FoG sigma [Mpc/h]", settings.sigma, reason));
    }
    let rule = MultipoleRule::new(&settings.ells)?;
    let model = model_parts(real, tns, settings)?;
    if let Some(ap) = &settings.ap {
        return observed(real, &model, settings, ap);
    }
    let monopole = MultipoleRule::new(&[0])?;
    let n_ell = settings.ells.len();
    let empty = || vec![Vec::with_capacity(k.len()); n_ell];
    let mut total = empty();
    let mut parts = settings.parts.then(|| [empty(), empty(), empty()]);
    let mut signal_to_noise = settings.noise.as_ref().map(|_| Vec::with_capacity(k.len()));
    let mut signal_to_noise_s = signal_to_noise.clone();
    for (i, (&ki, (p, p_real))) in k.iter().zip(&model).enumerate() {
        let x = ki * settings.sigma;
        let sum = p.total();
        push(&mut total, rule.evaluate_polynomial(&sum, settings.fog, x));
        if let Some(parts) = parts.as_mut() {
            for (out, part) in parts.iter_mut().zip([p.base, p.a, p.b]) {
                push(out, rule.evaluate_polynomial(&part, settings.fog, x));
            }
        }
        if let (Some(sn), Some(sn_s), Some(noise)) = (
            signal_to_noise.as_mut(),
            signal_to_noise_s.as_mut(),
            &settings.noise,
        ) {
            sn.push(p_real / noise[i]);
            let p0 = monopole.evaluate_polynomial(&sum, settings.fog, x)[0].value;
            sn_s.push(p0 / noise[i]);
        }
    }
    Ok(RsdMultipoles {
        k: k.clone(),
        ells: settings.ells.clone(),
        total,
        parts,
        noise: settings.noise.clone(),
        signal_to_noise,
        signal_to_noise_s,
    })
}

/// P^s(k, μ) before damping at every k of `real`, by part, with the real-space spectrum of the
/// signal-to-noise (b² P_δδ, or P_gg with nonlinear bias). The inputs are checked by [`multipoles`].
fn model_parts(
    real: &RealSpectra,
    tns: Option<&TnsTerms>,
    settings: &RsdSettings,
) -> Result<Vec<(Parts, f64)>> {
    let mut out = Vec::with_capacity(real.k.len());
    for (i, &ki) in real.k.iter().enumerate() {
        let mut s = Pair::ALL.map(|p| real.spectra[p][i]);
        if settings.cs2 != 0.0 {
            for (e, pair) in s.iter_mut().zip(Pair::ALL) {
                e.value += counterterm(pair, settings.cs2, ki, real.p_lin[i]);
            }
        }
        let coefficients = tns.map(|t| &t.coefficients[i]);
        let mut p_real = settings.bias[i] * settings.bias[i] * s[0].value;
        let p = match &settings.galaxy {
            None => settings
                .model
                .parts(settings.bias[i], settings.f, s, coefficients)?,
            Some(g) => {
                let bias = GalaxyBias {
                    b1: settings.bias[i],
                    b2: g.b2,
                    bs: g.bs,
                    b3nl: g.b3nl,
                };
                let [gg, _] = bias.spectra(i, s[0], &g.terms);
                let gt = bias.velocity(i, s[1], &g.terms);
                p_real = gg.value;
                settings.model.galaxy_parts(
                    settings.bias[i],
                    settings.f,
                    [gg, gt, s[2]],
                    coefficients,
                )?
            }
        };
        out.push((p, p_real));
    }
    Ok(out)
}

/// The multipoles observed in a fiducial cosmology ([`super::ap`]): `model` on the grid of `real`
/// projected onto the observed grid of `ap`.
fn observed(
    real: &RealSpectra,
    model: &[(Parts, f64)],
    settings: &RsdSettings,
    ap: &Observed,
) -> Result<RsdMultipoles> {
    if settings.noise.is_some() {
        return Err(Error::InvalidChoice {
            what: "a noise with the Alcock-Paczynski projection".into(),
            reason: "the signal-to-noise columns are of real space; run without the noise (it \
                     does not change the multipoles)"
                .into(),
        });
    }
    let project = |part: &dyn Fn(&Parts) -> MuPolynomial| {
        let polys: Vec<MuPolynomial> = model.iter().map(|(p, _)| part(p)).collect();
        observed_multipoles(
            &real.k,
            &polys,
            settings.fog,
            settings.sigma,
            &ap.distortion,
            &settings.ells,
            &ap.k,
        )
    };
    let total = project(&|p: &Parts| p.total())?;
    let parts = if settings.parts {
        Some([
            project(&|p: &Parts| p.base)?,
            project(&|p: &Parts| p.a)?,
            project(&|p: &Parts| p.b)?,
        ])
    } else {
        None
    };
    Ok(RsdMultipoles {
        k: ap.k.clone(),
        ells: settings.ells.clone(),
        total,
        parts,
        noise: None,
        signal_to_noise: None,
        signal_to_noise_s: None,
    })
}

fn push(out: &mut [Vec<Estimate>], values: Vec<Estimate>) {
    for (o, v) in out.iter_mut().zip(values) {
        o.push(v);
    }
}

fn invalid(name: &'static str, value: f64, reason: &'static str) -> Error {
    Error::InvalidParameter {
        name,
        value,
        reason,
    }
}

/// `n` values must sit on the grid `k`.
fn check_grid(what: &'static str, k: &[f64], n: usize) -> Result<()> {
    if n == k.len() {
        return Ok(());
    }
    Err(Error::GridMismatch {
        what,
        expected: describe_grid(k),
        found: format!("{n} values"),
    })
}

/// The loop terms a redshift-space model needs on one k grid, planned once: the real-space plan and,
/// for TNS, the plan of the A and B terms.
#[derive(Debug, Clone)]
pub struct RsdPlan {
    real: RealPlan,
    tns: Option<TnsPlan>,
    /// The TNS basis tensors, if the A and B terms come from them (as the real plan's 1-loop terms:
    /// [`crate::precision::TwoLoopMethod`]).
    tns_basis: Option<std::sync::Arc<TnsBasis>>,
    /// The bias terms' plan, for nonlinear galaxy bias ([`with_bias_terms`](Self::with_bias_terms)).
    bias: Option<BiasPlan>,
}

impl crate::plan::Plan for RsdPlan {
    type Settings<'a> = ();
    type Terms = (RealSpectra, Option<TnsTerms>);

    fn describe(&self) -> String {
        let tns = if self.tns.is_some() { " + TNS" } else { "" };
        format!("{}{tns}", crate::plan::Plan::describe(&self.real))
    }

    fn method(&self) -> crate::plan::Method {
        crate::plan::Plan::method(&self.real)
    }

    fn bytes(&self) -> f64 {
        let tns = self.tns.as_ref().map_or(0.0, |t| {
            TnsPlan::memory_estimate(t.k().len(), t.precision())
        });
        let bias = self.bias.as_ref().map_or(0.0, |b| {
            BiasPlan::memory_estimate(b.k().len(), b.precision())
        });
        crate::plan::Plan::bytes(&self.real) + tns + bias
    }

    fn terms_bytes(&self) -> f64 {
        let tns = self
            .tns
            .as_ref()
            .map_or(0.0, crate::plan::Plan::terms_bytes);
        crate::plan::Plan::terms_bytes(&self.real) + tns
    }

    fn max_memory(&self) -> Option<f64> {
        self.real.precision().max_memory
    }

    fn terms(
        &self,
        spectrum: &LinearSpectrum,
        (): (),
        progress: &dyn Progress,
    ) -> Result<(RealSpectra, Option<TnsTerms>)> {
        self.evaluate(spectrum, progress)
    }
}

impl RsdPlan {
    /// The plan of real-space `real_model` with RSD model `rsd` on wavenumbers `k` [h/Mpc].
    ///
    /// # Errors
    /// As [`RealPlan::new`] and [`TnsPlan::new`].
    pub fn new(
        k: &[f64],
        real_model: RealModel,
        rsd: RsdModel,
        precision: &Precision,
        store: &TableStore,
        progress: &dyn Progress,
    ) -> Result<Self> {
        if rsd.needs_tns() {
            precision.validate()?;
            crate::memory::check(
                RealPlan::memory_estimate(k.len(), real_model, precision)
                    + TnsPlan::memory_estimate(k.len(), precision),
                precision,
                &format!("the {} + TNS plan on {} k", real_model.name(), k.len()),
            )?;
        }
        let real = RealPlan::new(k, real_model, precision, store, progress)?;
        let tns = if rsd.needs_tns() {
            Some(TnsPlan::new(k, precision)?)
        } else {
            None
        };
        let tns_basis = match &tns {
            Some(plan) => store.for_method::<TnsBasis>(
                precision.two_loop,
                (plan.k(), plan.precision()),
                |tick| TnsBasis::build(plan, tick),
                progress,
            )?,
            None => None,
        };
        Ok(Self {
            real,
            tns,
            tns_basis,
            bias: None,
        })
    }

    /// This plan with the bias terms' plan too (for [`GalaxyTerms`]); a no-op if it has it.
    ///
    /// # Errors
    /// As [`BiasPlan::new`].
    pub fn with_bias_terms(mut self) -> Result<Self> {
        if self.bias.is_none() {
            self.bias = Some(BiasPlan::new(self.real.k(), self.real.precision())?);
        }
        Ok(self)
    }

    /// The bias terms of `spectrum`, if the plan has their plan.
    pub fn bias_terms(&self, spectrum: &LinearSpectrum) -> Option<BiasTerms> {
        self.bias.as_ref().map(|plan| plan.evaluate(spectrum))
    }

    /// The real-space plan.
    pub fn real(&self) -> &RealPlan {
        &self.real
    }

    /// The real-space spectra and (for TNS) the A and B coefficients of the linear `spectrum`.
    ///
    /// # Errors
    /// As [`RealPlan::evaluate`].
    pub fn evaluate(
        &self,
        spectrum: &LinearSpectrum,
        progress: &dyn Progress,
    ) -> Result<(RealSpectra, Option<TnsTerms>)> {
        // One projection on the basis for the real-space and the TNS tensors (the same basis: both
        // are built from the shipped training set on the plan's lattice).
        let projection = self.real.project(spectrum);
        let tns = self.tns.as_ref().map(|plan| {
            let on_basis = self.tns_basis.as_ref().and_then(|tensors| {
                let basis = tensors.basis();
                let projection = match &projection {
                    Some(p) => p.clone(),
                    None => basis.project_spectrum(spectrum, MAX_RESIDUAL),
                };
                if projection.residual.is_nan() || projection.residual > MAX_RESIDUAL {
                    progress.note(&format!(
                        "TNS A and B: direct integration, since the spectrum's projection residual \
                         on the basis, {:.1e}, exceeds {MAX_RESIDUAL:.1e}",
                        projection.residual
                    ));
                    return None;
                }
                let p_lin: Vec<f64> = plan.k().iter().map(|&k| spectrum.eval(k)).collect();
                Some(tensors.evaluate(&p_lin, &projection))
            });
            on_basis.unwrap_or_else(|| plan.par_evaluate(spectrum))
        });
        let real = self
            .real
            .evaluate_projected(spectrum, projection, progress)?;
        Ok((real, tns))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn grids_that_do_not_match_are_errors_naming_them() {
        let p = LinearSpectrum::gm2012(0.0).unwrap();
        let store = TableStore::in_memory();
        let real = crate::real::real_space(
            RealModel::Linear,
            &p,
            &[0.05, 0.1],
            &Precision::fast(),
            &store,
        )
        .unwrap();
        let mut settings = RsdSettings {
            model: RsdModel::Tns,
            f: 0.5,
            bias: vec![1.0; 3],
            fog: Fog::None,
            sigma: 0.0,
            noise: None,
            ells: vec![0],
            parts: false,
            cs2: 0.0,
            galaxy: None,
            ap: None,
        };
        let e = multipoles(&real, None, &settings).unwrap_err().to_string();
        assert!(
            e.contains("bias") && e.contains("3 values") && e.contains("2 k in"),
            "{e}"
        );
        settings.bias = vec![1.0; 2];
        let e = multipoles(&real, None, &settings).unwrap_err().to_string();
        assert!(e.contains("TNS A and B"), "{e}");
        let other = TnsPlan::new(&[0.05, 0.2], &Precision::fast())
            .unwrap()
            .evaluate(&p);
        let e = multipoles(&real, Some(&other), &settings)
            .unwrap_err()
            .to_string();
        assert!(e.contains("TNS terms") && e.contains("0.2]"), "{e}");
    }

    #[test]
    fn signal_to_noise_is_the_real_space_halo_spectrum_over_the_noise() {
        // Linear input: SN = b² P_lin/P_εε exactly, and the redshift-space ratio SN_s = P0/P_εε is
        // larger by (b² + 2bf/3 + f²/5)/b² (13% for b = 2.6, f = 0.48).
        let p = LinearSpectrum::gm2012(0.0).unwrap();
        let k = [0.02, 0.1, 0.2];
        let real = crate::real::real_space(
            RealModel::Linear,
            &p,
            &k,
            &Precision::fast(),
            &TableStore::in_memory(),
        )
        .unwrap();
        let (b, f) = (2.6, 0.48);
        let noise = vec![3.0e4, 2.5e4, 2.0e4];
        let settings = RsdSettings {
            model: RsdModel::Kaiser,
            f,
            bias: vec![b; 3],
            fog: Fog::None,
            sigma: 0.0,
            noise: Some(noise.clone()),
            ells: vec![0, 2],
            parts: false,
            cs2: 0.0,
            galaxy: None,
            ap: None,
        };
        let m = multipoles(&real, None, &settings).unwrap();
        let (sn, sn_s) = (
            m.signal_to_noise.clone().unwrap(),
            m.signal_to_noise_s.clone().unwrap(),
        );
        for i in 0..3 {
            let want = b * b * p.eval(k[i]) / noise[i];
            assert!((sn[i] / want - 1.0).abs() < 1e-12, "{} {want}", sn[i]);
            let kaiser = (b * b + 2.0 * b * f / 3.0 + f * f / 5.0) / (b * b);
            assert!((sn_s[i] / sn[i] / kaiser - 1.0).abs() < 1e-12);
        }
        assert!(crate::jobs::rsd_multipoles_table(&m, vec![])
            .names()
            .ends_with(&["P_eps", "SN", "SN_s", "err_P0", "err_P2"]));
    }
}
