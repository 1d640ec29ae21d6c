//! Fits of the growth rate f, the FoG dispersion σ0, the bias amplitude A_b and the EFT counterterm c_s²
//! to measured multipoles (Gil-Marín et al. 2012, sections 4.2–4.5; c_s²: [`crate::real::counterterm`](mod@crate::real::counterterm)).
//!
//! * χ² = Σ_ℓ Σ_{k ≤ k_max} [(P_ℓ,data − P_ℓ,model)/σ_ℓ]² (diagonal, as the paper), or
//!   (d − m)ᵀ C⁻¹ (d − m) with a full covariance of the data vector (ℓ-major: all k of the first ℓ, …).
//! * The model ([`MultipoleModel`]) holds everything that does not depend on (f, σ0, A_b, c_s²): the
//!   real-space spectra, P_lin and the TNS coefficients per k. A new parameter point costs one polynomial
//!   per k (the counterterm, linear in c_s² and P_lin, is added to the three real-space spectra there) and
//!   a 32-point μ quadrature with FoG: no loop integral is ever recomputed.
//! * The best fit minimises χ² over the free parameters with Nelder–Mead (the `argmin` crate). The 1σ
//!   interval of each free parameter is where its profile χ² (minimised over the other free parameters,
//!   1-D Brent) crosses χ²_min + Δχ², Δχ² = 1, 2.3, 3.53, 4.72 for 1 to 4 free parameters: found on the
//!   contour by bracketing and bisection, never from a quadratic approximation.
//! * σ0 enters only through σ0², so it is fitted as is and reported as |σ0|.
//! * [`contour`]: Δχ² = χ² − χ²_min on a grid of two free parameters around the best fit, the other free
//!   parameter re-minimised at every point: the f–σ0 and f–A_b planes whose Δχ² = 2.3 contour gives the
//!   paper's two-parameter errors ([`CONTOUR_LEVELS`]).

use crate::error::{Error, Result};
use crate::loops::{Estimate, Pair, TnsCoefficients, TnsTerms};
use crate::real::{counterterm, RealSpectra};
use crate::rsd::{Fog, MultipoleRule, RsdModel};
use minimise::{Residuals, Window};
use std::fmt;
use std::str::FromStr;

pub mod bounded;
mod contour;
pub mod covariance;
mod data;
pub mod galaxy;
mod layout;
mod minimise;
pub use contour::{contour, Contour, ContourGrid, CONTOUR_LEVELS};
pub use data::MultipoleData;
pub use layout::DataLayout;

/// A parameter that can be fitted.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Parameter {
    /// The growth rate f.
    F,
    /// The FoG dispersion σ0 [Mpc/h] (z = 0 value; σ = σ0 D(z) f).
    Sigma0,
    /// The bias amplitude A_b (b → A_b b).
    Amplitude,
    /// The EFT counterterm c_s² [(Mpc/h)²] ([`crate::real::counterterm`](mod@crate::real::counterterm)).
    Cs2,
}

impl Parameter {
    /// The unit of the parameter's values.
    pub fn unit(self) -> &'static str {
        match self {
            Parameter::Sigma0 => "Mpc/h",
            Parameter::Cs2 => "(Mpc/h)^2",
            Parameter::F | Parameter::Amplitude => "1",
        }
    }

    /// The name, as on the command line: `f`, `sigma0`, `ab`, `cs2`.
    pub fn name(self) -> &'static str {
        match self {
            Parameter::F => "f",
            Parameter::Sigma0 => "sigma0",
            Parameter::Amplitude => "ab",
            Parameter::Cs2 => "cs2",
        }
    }
}

impl fmt::Display for Parameter {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

impl FromStr for Parameter {
    type Err = Error;

    fn from_str(s: &str) -> Result<Self> {
        match s.trim().to_ascii_lowercase().as_str() {
            "f" => Ok(Parameter::F),
            "sigma0" | "s0" => Ok(Parameter::Sigma0),
            "ab" | "a_b" | "amplitude" => Ok(Parameter::Amplitude),
            "cs2" | "c_s2" => Ok(Parameter::Cs2),
            _ => Err(Error::UnknownName {
                what: "fit parameter",
                name: s.to_string(),
                available: "f, sigma0, ab, cs2",
            }),
        }
    }
}

/// A point in parameter space.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Params {
    /// Growth rate f.
    pub f: f64,
    /// σ0 [Mpc/h].
    pub sigma0: f64,
    /// Bias amplitude A_b.
    pub amplitude: f64,
    /// EFT counterterm c_s² [(Mpc/h)²], added to the model's real-space spectra (0: none).
    pub cs2: f64,
}

impl Params {
    /// The value of `p`.
    pub fn get(&self, p: Parameter) -> f64 {
        match p {
            Parameter::F => self.f,
            Parameter::Sigma0 => self.sigma0,
            Parameter::Amplitude => self.amplitude,
            Parameter::Cs2 => self.cs2,
        }
    }

    fn set(&mut self, p: Parameter, v: f64) {
        match p {
            Parameter::F => self.f = v,
            Parameter::Sigma0 => self.sigma0 = v,
            Parameter::Amplitude => self.amplitude = v,
            Parameter::Cs2 => self.cs2 = v,
        }
    }
}

/// The multipoles of one RSD model as a function of (f, σ0, A_b, c_s²) on a fixed k grid.
#[derive(Debug, Clone)]
pub struct MultipoleModel {
    k: Vec<f64>,
    p_lin: Vec<f64>,
    rsd: RsdModel,
    fog: Fog,
    growth_factor: f64,
    bias: Vec<f64>,
    spectra: Vec<[Estimate; 3]>,
    tns: Option<Vec<TnsCoefficients>>,
    rule: MultipoleRule,
}

impl MultipoleModel {
    /// The model at the k of `real` (and `tns`, needed for [`RsdModel::Tns`]), with b(k) before A_b in
    /// `bias`, FoG `fog`, the growth factor D(z) of the damping scale σ = σ0 D f, and multipoles `ells`.
    /// The counterterm of [`Params::cs2`] is added to the spectra of `real` (on top of any they hold).
    ///
    /// # Errors
    /// [`Error::LengthMismatch`] if `bias` is not on the k of `real`, [`Error::GridMismatch`] if `tns` is
    /// on other k (compared point by point), [`Error::MissingTerm`] for TNS without `tns`,
    /// [`Error::InvalidParameter`] for a bad ℓ.
    pub fn new(
        real: &RealSpectra,
        tns: Option<&TnsTerms>,
        rsd: RsdModel,
        fog: Fog,
        growth_factor: f64,
        bias: Vec<f64>,
        ells: &[usize],
    ) -> Result<Self> {
        let n = real.k.len();
        if bias.len() != n {
            return Err(Error::LengthMismatch {
                what: "bias and k",
                left: bias.len(),
                right: n,
            });
        }
        let tns = match (rsd.needs_tns(), tns) {
            (true, None) => {
                return Err(Error::MissingTerm {
                    term: "the TNS A and B coefficients",
                    needed_by: "the tns model".into(),
                    hint: " (TnsPlan, or an RsdPlan)",
                })
            }
            // By value: TNS terms of another grid of the same length would be read at the wrong k.
            (true, Some(t))
                if !crate::table::same_k(&t.k, &real.k) || t.coefficients.len() != n =>
            {
                return Err(Error::GridMismatch {
                    what: "TNS terms and real-space spectra",
                    expected: crate::table::describe_grid(&real.k),
                    found: crate::table::describe_grid(&t.k),
                })
            }
            (true, Some(t)) => Some(t.coefficients.clone()),
            (false, _) => None,
        };
        Ok(Self {
            k: real.k.clone(),
            p_lin: real.p_lin.clone(),
            rsd,
            fog,
            growth_factor,
            bias,
            spectra: (0..n)
                .map(|i| [real.spectra.dd[i], real.spectra.dt[i], real.spectra.tt[i]])
                .collect(),
            tns,
            rule: MultipoleRule::new(ells)?,
        })
    }

    /// The wavenumbers [h/Mpc].
    pub fn k(&self) -> &[f64] {
        &self.k
    }

    /// The multipole orders.
    pub fn ells(&self) -> &[usize] {
        self.rule.ells()
    }

    /// P_ℓ at k indices `range` for `params`, written ℓ-major into `out` (length n_ℓ · range.len()).
    pub fn multipoles_into(&self, params: &Params, range: std::ops::Range<usize>, out: &mut [f64]) {
        let n = range.len();
        let mut row = [0.0; crate::rsd::MAX_ELL / 2 + 1];
        let sigma = params.sigma0 * self.growth_factor * params.f;
        for (c, i) in range.enumerate() {
            let b = params.amplitude * self.bias[i];
            let mut spectra = self.spectra[i];
            if params.cs2 != 0.0 {
                for (e, pair) in spectra.iter_mut().zip(Pair::ALL) {
                    e.value += counterterm(pair, params.cs2, self.k[i], self.p_lin[i]);
                }
            }
            let parts = self
                .rsd
                .parts(b, params.f, spectra, self.tns.as_ref().map(|t| &t[i]))
                .expect("TNS coefficients are present when needed");
            let poly = parts.total();
            let ells = self.rule.ells().len();
            self.rule
                .evaluate_values(&poly.value, self.fog, self.k[i] * sigma, &mut row[..ells]);
            for j in 0..ells {
                out[j * n + c] = row[j];
            }
        }
    }

    /// P_ℓ(k) for `params`: `result[j][i]` for the j-th ℓ.
    pub fn multipoles(&self, params: &Params) -> Vec<Vec<f64>> {
        let n = self.k.len();
        let mut out = vec![0.0; n * self.ells().len()];
        self.multipoles_into(params, 0..n, &mut out);
        out.chunks(n).map(<[f64]>::to_vec).collect()
    }
}

/// What to fit.
#[derive(Debug, Clone, PartialEq)]
pub struct FitSettings {
    /// The free parameters (1 to 4, no repeats).
    pub free: Vec<Parameter>,
    /// Starting values of the free parameters and the values of the fixed ones.
    pub start: Params,
    /// Smallest k used [h/Mpc].
    pub k_min: f64,
}

/// The best fit at one k_max.
#[derive(Debug, Clone, PartialEq)]
pub struct FitResult {
    /// k_max [h/Mpc].
    pub k_max: f64,
    /// Number of data points used (n_ℓ × n_k).
    pub points: usize,
    /// Best-fit parameters (fixed ones at their given values).
    pub best: Params,
    /// χ² at the best fit.
    pub chi2: f64,
    /// Degrees of freedom, points − free parameters.
    pub dof: usize,
    /// For each free parameter, the 1σ interval (lower, upper) from the Δχ² contour (NaN if the profile
    /// does not reach χ²_min + Δχ² within 50 times the starting step).
    pub intervals: Vec<(Parameter, f64, f64)>,
}

/// Δχ² of the 1σ (68.3%) region for n free parameters (the χ² quantiles of Press et al., Numerical
/// Recipes, §15.6).
pub fn delta_chi2(n: usize) -> f64 {
    match n {
        1 => 1.0,
        2 => 2.30,
        3 => 3.53,
        _ => 4.72,
    }
}

/// Checks that `free` names 1 to 4 distinct parameters and that `model` is on the grid and ells of
/// `data`.
fn check(model: &MultipoleModel, data: &MultipoleData, free: &[Parameter]) -> Result<()> {
    let names = || free.iter().map(|p| p.name()).collect::<Vec<_>>().join(",");
    if let Some(i) = (1..free.len()).find(|&i| free[..i].contains(&free[i])) {
        return Err(Error::InvalidChoice {
            what: format!("free parameters {}", names()),
            reason: format!("{} is named twice", free[i].name()),
        });
    }
    if free.is_empty() || free.len() > 4 {
        return Err(Error::InvalidChoice {
            what: format!("free parameters `{}`", names()),
            reason: "name 1 to 4 of f, sigma0, ab, cs2".into(),
        });
    }
    let describe = |k: &[f64]| match (k.first(), k.last()) {
        (Some(a), Some(b)) => format!("{} k in [{a:e}, {b:e}] h/Mpc", k.len()),
        _ => "no k".into(),
    };
    if model.k() != data.k.as_slice() {
        return Err(Error::GridMismatch {
            what: "the fit's model and data",
            expected: describe(&data.k),
            found: describe(model.k()),
        });
    }
    if model.ells() != data.ells.as_slice() {
        return Err(Error::InvalidChoice {
            what: format!("the model's multipoles {:?}", model.ells()),
            reason: format!("must be the data's {:?}, in order", data.ells),
        });
    }
    Ok(())
}

/// χ² of `model` at `params` against `data` over k ∈ [k_min, k_max] (as [`fit`] minimises it).
///
/// # Errors
/// As [`fit`] with one free parameter.
pub fn chi2(
    model: &MultipoleModel,
    data: &MultipoleData,
    params: &Params,
    k_min: f64,
    k_max: f64,
) -> Result<f64> {
    check(model, data, &[Parameter::F])?;
    Ok(Residuals::new(model, data, k_min, k_max, 0)?.chi2(params))
}

/// Fits `model` to `data` using k ∈ [k_min, k_max], for each `k_max`.
///
/// # Errors
/// [`Error::InvalidParameter`] for no or repeated free parameters, a model grid that is not the data grid,
/// ells that differ, fewer data points than free parameters, or a covariance window that is not
/// positive definite.
pub fn fit(
    model: &MultipoleModel,
    data: &MultipoleData,
    settings: &FitSettings,
    k_max: &[f64],
) -> Result<Vec<FitResult>> {
    let free = &settings.free;
    check(model, data, free)?;
    let dchi2 = delta_chi2(free.len());
    let mut results = Vec::with_capacity(k_max.len());
    for &km in k_max {
        let residuals = Residuals::new(model, data, settings.k_min, km, free.len())?;
        let points = residuals.points();
        let window = Window {
            residuals: &residuals,
            base: settings.start,
            free: free.clone(),
        };
        let x0: Vec<f64> = free.iter().map(|&p| settings.start.get(p)).collect();
        let steps = minimise::steps(free, &x0);
        let (x, _) = minimise::minimise(&window, &x0, &steps);
        // Restart once from the optimum: Nelder–Mead can stall on a ridge.
        let (x, chi2) = minimise::minimise(&window, &x, &steps);
        let mut best = window.params(&x);
        // χ² depends on σ0² only.
        best.sigma0 = best.sigma0.abs();
        let intervals = free
            .iter()
            .enumerate()
            .map(|(i, &p)| {
                let profile = |v: f64| window.profile(&[(p, v)], &best, &steps).0;
                let centre = best.get(p);
                let target = chi2 + dchi2;
                let crossing = |direction: f64| -> f64 {
                    let step = direction * steps[i] * 0.2;
                    let (mut inside, mut outside) = (centre, centre + step);
                    let mut tries = 0;
                    while profile(outside) < target {
                        inside = outside;
                        outside = centre + (outside - centre) * 2.0;
                        tries += 1;
                        if tries > 12 {
                            return f64::NAN;
                        }
                    }
                    for _ in 0..40 {
                        let mid = 0.5 * (inside + outside);
                        if profile(mid) < target {
                            inside = mid;
                        } else {
                            outside = mid;
                        }
                        if (outside - inside).abs() < 1e-7 * centre.abs().max(1e-3) {
                            break;
                        }
                    }
                    0.5 * (inside + outside)
                };
                let (lo, hi) = (crossing(-1.0), crossing(1.0));
                // A σ0 interval reaching below 0 contains 0 (χ² is even in σ0).
                if p == Parameter::Sigma0 && lo < 0.0 {
                    (p, 0.0, hi)
                } else {
                    (p, lo, hi)
                }
            })
            .collect();
        results.push(FitResult {
            k_max: km,
            points,
            best,
            chi2,
            dof: points - free.len(),
            intervals,
        });
    }
    Ok(results)
}
