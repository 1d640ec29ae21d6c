//! Redshift space: the Kaiser and Scoccimarro models, Fingers-of-God damping and Legendre multipoles.
//!
//! Gil-Marín et al. (2012, arXiv:1209.3771), section 2.2. Every model is a polynomial in μ² whose
//! coefficients are built once per k from the real-space spectra, so a new (f, b, σ0) costs no integral:
//! * Kaiser (eq. kaiser_eq, whose printed (b + f²μ)² is a typo): P^s = (b + fμ²)² P_δδ;
//! * Scoccimarro (eq. SC): P^s = b² P_δδ + 2bfμ² P_δθ + f²μ⁴ P_θθ;
//! * TNS (eq. taruya_eq): Scoccimarro + A(k, μ; f, b) + B(k, μ; f, b), the leading-order correction terms of
//!   Taruya, Nishimichi & Saito (2010) from [`crate::loops::TnsPlan`], A = b³A(f/b), B = b⁴B(f/b);
//! * Fingers of God (eq. fog_changing): P^s → P^s D²_FoG(kμσ), σ = σ0 D(z) f(z) as the paper writes it
//!   (eq. lorentzian): D_Lor = 1/(1 + ½ x²), D_Gau = exp(−½ x²), x = kμσ;
//! * multipoles (eq. real_Ps): P_ℓ = (2ℓ+1)∫_0^1 dμ P^s(k, μ) L_ℓ(μ), ℓ even ≤ [`MAX_ELL`].
//!
//! Without damping the multipoles are exact finite sums (∫_0^1 μ^{2n} L_ℓ dμ in closed form). With damping
//! they use a Gauss–Legendre rule on [0, 1] whose error estimate is the change from the half-size rule.
//! (The upward recursion for ∫μ^{2n}/(1 + a²μ²) is unstable at small a; quadrature is not.)
//!
//! Units: k in h/Mpc, σ in Mpc/h, P in (Mpc/h)^3.

use crate::error::{Error, Result};
use crate::integrate::legendre_nodes;
use crate::loops::{Estimate, Pair, TnsCoefficients};
use std::fmt;
use std::str::FromStr;

pub mod ap;
pub mod eft2;
pub mod ept;
mod multipoles;
mod sigma0;
pub mod spt2;
pub use multipoles::{multipoles, GalaxyTerms, Observed, RsdMultipoles, RsdPlan, RsdSettings};
pub use sigma0::{Dispersions, Sigma0};

/// Largest multipole order ℓ supported.
pub const MAX_ELL: usize = 8;

/// Checks every ℓ of `ells` is even and at most [`MAX_ELL`] (the one check of the multipoles that
/// the redshift-space models, AP and the galaxy model take).
///
/// # Errors
/// [`Error::InvalidParameter`] naming the first ℓ that is odd or above [`MAX_ELL`].
pub fn check_ells(ells: &[usize]) -> Result<()> {
    match ells.iter().find(|&&l| l % 2 == 1 || l > MAX_ELL) {
        Some(&bad) => Err(Error::InvalidParameter {
            name: "multipole ell",
            value: bad as f64,
            reason: "must be even and at most 8",
        }),
        None => Ok(()),
    }
}
/// Largest power n of μ^{2n} in a model polynomial (μ⁸: the TNS B term).
pub const MAX_MU_POWER: usize = 4;
/// Gauss–Legendre nodes on μ ∈ [0, 1] for damped multipoles: exact for the polynomial part up to
/// μ^{2·MAX_MU_POWER + MAX_ELL} with room to spare; the damping is analytic on [0, 1], with poles (Lorentzian)
/// at |μ| = √2/(kσ), so for kσ ≲ 5 the rule converges to ≲ 1e-10.
const FOG_NODES: usize = 32;

/// A redshift-space model, named as on the command line.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[non_exhaustive]
pub enum RsdModel {
    /// (b + fμ²)² P_δδ.
    Kaiser,
    /// b² P_δδ + 2bfμ² P_δθ + f²μ⁴ P_θθ.
    Scoccimarro,
    /// Scoccimarro + A + B (Taruya, Nishimichi & Saito 2010).
    Tns,
}

impl RsdModel {
    /// Every model.
    pub const ALL: [RsdModel; 3] = [RsdModel::Kaiser, RsdModel::Scoccimarro, RsdModel::Tns];

    /// The model's name.
    pub fn name(self) -> &'static str {
        match self {
            RsdModel::Kaiser => "kaiser",
            RsdModel::Scoccimarro => "scoccimarro",
            RsdModel::Tns => "tns",
        }
    }

    /// Whether the model needs the TNS coefficients.
    pub fn needs_tns(self) -> bool {
        self == RsdModel::Tns
    }

    /// The coefficients of μ⁰, μ², μ⁴ at one k, from the real-space spectra and b, f (for TNS: its
    /// Scoccimarro part).
    ///
    /// ```
    /// use pt_spectra::rsd::RsdModel;
    /// // With P_δθ = P_θθ = P_δδ (linear theory) the two models agree.
    /// let k = RsdModel::Kaiser.coefficients(2.0, 0.5, [100.0, 100.0, 100.0]);
    /// assert_eq!(k, RsdModel::Scoccimarro.coefficients(2.0, 0.5, [100.0; 3]));
    /// assert_eq!(k, [400.0, 200.0, 25.0]);
    /// ```
    pub fn coefficients(self, b: f64, f: f64, [p_dd, p_dt, p_tt]: [f64; 3]) -> [f64; 3] {
        match self {
            RsdModel::Kaiser => [b * b * p_dd, 2.0 * b * f * p_dd, f * f * p_dd],
            RsdModel::Scoccimarro | RsdModel::Tns => {
                [b * b * p_dd, 2.0 * b * f * p_dt, f * f * p_tt]
            }
        }
    }

    /// P^s(k, μ) at one k before damping, by part, from the real-space spectra [P_δδ, P_δθ, P_θθ] (with
    /// their errors), the bias b, the growth rate f and, for TNS, the coefficients of A and B.
    ///
    /// # Errors
    /// [`Error::MissingTerm`] if the model is TNS and `tns` is `None`.
    pub fn parts(
        self,
        b: f64,
        f: f64,
        spectra: [Estimate; 3],
        tns: Option<&TnsCoefficients>,
    ) -> Result<Parts> {
        let value = self.coefficients(b, f, spectra.map(|e| e.value));
        let error = self.coefficients(b.abs(), f.abs(), spectra.map(|e| e.error));
        self.with_tns(MuPolynomial::from_low(value, error), b, f, tns)
    }

    /// As [`parts`](Self::parts) for galaxies with nonlinear bias (Beutler et al. 2017): from the
    /// galaxy spectra [P_gg, P_gθ, P_θθ] ([`crate::loops::bias`]), P^s = P_gg + 2fμ² P_gθ + f²μ⁴ P_θθ
    /// (+ b1³ A(f/b1) + b1⁴ B(f/b1) for TNS, with b1 = `b`).
    ///
    /// # Errors
    /// [`Error::InvalidChoice`] for Kaiser (linear by definition); as [`parts`](Self::parts).
    pub fn galaxy_parts(
        self,
        b: f64,
        f: f64,
        [gg, gt, tt]: [Estimate; 3],
        tns: Option<&TnsCoefficients>,
    ) -> Result<Parts> {
        if self == RsdModel::Kaiser {
            return Err(Error::InvalidChoice {
                what: "nonlinear bias with the kaiser model".into(),
                reason: "Kaiser is linear in the bias: use scoccimarro or tns".into(),
            });
        }
        let value = [gg.value, 2.0 * f * gt.value, f * f * tt.value];
        let error = [gg.error, 2.0 * f.abs() * gt.error, f * f * tt.error];
        self.with_tns(MuPolynomial::from_low(value, error), b, f, tns)
    }

    /// The parts with `base` and, for TNS, the A and B terms of bias `b`.
    fn with_tns(
        self,
        base: MuPolynomial,
        b: f64,
        f: f64,
        tns: Option<&TnsCoefficients>,
    ) -> Result<Parts> {
        let mut parts = Parts {
            base,
            ..Parts::default()
        };
        if self.needs_tns() {
            let c = tns.ok_or(Error::MissingTerm {
                term: "the TNS A and B coefficients",
                needed_by: "the tns model".into(),
                hint: " (TnsPlan, or an RsdPlan)",
            })?;
            let ((av, ae), (bv, be)) = (c.a_polynomial(f, b), c.b_polynomial(f, b));
            parts.a = MuPolynomial {
                value: av,
                error: ae,
            };
            parts.b = MuPolynomial {
                value: bv,
                error: be,
            };
        }
        Ok(parts)
    }
}

/// A polynomial Σ_n c_n μ^{2n} (n ≤ [`MAX_MU_POWER`]) with bounds on the errors of its coefficients.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct MuPolynomial {
    /// c_n, the coefficient of μ^{2n}.
    pub value: [f64; MAX_MU_POWER + 1],
    /// Bounds on the errors of c_n (≥ 0).
    pub error: [f64; MAX_MU_POWER + 1],
}

impl MuPolynomial {
    fn from_low(value: [f64; 3], error: [f64; 3]) -> Self {
        let mut p = Self::default();
        p.value[..3].copy_from_slice(&value);
        p.error[..3].copy_from_slice(&error);
        p
    }

    /// The sum of two polynomials, errors added.
    pub fn add(&self, other: &Self) -> Self {
        Self {
            value: std::array::from_fn(|n| self.value[n] + other.value[n]),
            error: std::array::from_fn(|n| self.error[n] + other.error[n]),
        }
    }

    /// The value at μ.
    pub fn at(&self, mu: f64) -> f64 {
        let m2 = mu * mu;
        self.value.iter().rev().fold(0.0, |acc, c| acc * m2 + c)
    }
}

/// The parts of P^s(k, μ) before damping: the Kaiser or Scoccimarro part, and the TNS A and B terms
/// (zero for the other models).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Parts {
    /// Kaiser or Scoccimarro part.
    pub base: MuPolynomial,
    /// The TNS A term.
    pub a: MuPolynomial,
    /// The TNS B term.
    pub b: MuPolynomial,
}

impl Parts {
    /// base + A + B.
    pub fn total(&self) -> MuPolynomial {
        self.base.add(&self.a).add(&self.b)
    }
}

impl fmt::Display for RsdModel {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

impl FromStr for RsdModel {
    type Err = Error;

    /// Parses a model name, ignoring ASCII case.
    ///
    /// # Errors
    /// [`Error::UnknownName`] naming the accepted models.
    fn from_str(s: &str) -> Result<Self> {
        RsdModel::ALL
            .into_iter()
            .find(|m| m.name().eq_ignore_ascii_case(s.trim()))
            .ok_or_else(|| Error::UnknownName {
                what: "RSD model",
                name: s.to_string(),
                available: "kaiser, scoccimarro, tns",
            })
    }
}

/// Fingers-of-God damping D_FoG(x), x = kμσ; the spectrum is multiplied by D².
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
pub enum Fog {
    /// No damping, D = 1.
    #[default]
    None,
    /// D = 1/(1 + x²/2).
    Lorentzian,
    /// D = exp(−x²/2).
    Gaussian,
}

impl Fog {
    /// D²(x), the factor applied to P^s.
    ///
    /// ```
    /// use pt_spectra::rsd::Fog;
    /// assert_eq!(Fog::Lorentzian.damping_squared(2.0), 1.0 / 9.0);
    /// assert_eq!(Fog::Gaussian.damping_squared(0.0), 1.0);
    /// ```
    pub fn damping_squared(self, x: f64) -> f64 {
        match self {
            Fog::None => 1.0,
            Fog::Lorentzian => {
                let d = 1.0 / (1.0 + 0.5 * x * x);
                d * d
            }
            Fog::Gaussian => (-x * x).exp(),
        }
    }
}

impl FromStr for Fog {
    type Err = Error;

    /// `none`, `lorentzian` or `gaussian` (ASCII case ignored).
    ///
    /// # Errors
    /// [`Error::UnknownName`] naming the accepted choices.
    fn from_str(s: &str) -> Result<Self> {
        match s.trim().to_ascii_lowercase().as_str() {
            "none" => Ok(Fog::None),
            "lorentzian" => Ok(Fog::Lorentzian),
            "gaussian" => Ok(Fog::Gaussian),
            _ => Err(Error::UnknownName {
                what: "Fingers-of-God damping",
                name: s.to_string(),
                available: "none, lorentzian, gaussian",
            }),
        }
    }
}

/// The velocity-dispersion scale of the damping, σ(z) = σ0 D(z) f(z) [Mpc/h], as eq. lorentzian of the
/// paper writes it (σ0 is the z = 0 value; D(0) = 1).
pub fn fog_sigma(sigma0: f64, growth_factor: f64, growth_rate: f64) -> f64 {
    sigma0 * growth_factor * growth_rate
}

/// Which P_θθ enters the theory value of the velocity dispersion (eq. sigmav).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum DispersionInput {
    /// P_θθ = P_lin.
    Linear,
    /// P_θθ of 1-loop SPT up to [`DISPERSION_Q_CUT`], P_lin beyond.
    OneLoopSpt,
}

/// Above this q [h/Mpc] the theory dispersion uses P_lin even for 1-loop input: 1-loop SPT P_θθ turns
/// negative at q ≈ 0.5–1 h/Mpc (z = 0), where it means nothing. The q > 0.3 h/Mpc tail carries 9% of the
/// linear σ² at z = 0 (σ = 6.078 Mpc/h with linear input, 5.802 with 1-loop input).
pub const DISPERSION_Q_CUT: f64 = 0.3;

/// The theory value of the FoG dispersion, eq. sigmav of the paper: σ²(z) = (4π/3)∫dq/(2π)³ P_θθ(q, z)
/// = (1/6π²)∫P_θθ dq [(Mpc/h)²], over the loop range [q_min, q_max] of `precision`, for the linear
/// `spectrum` at redshift z. Returns σ [Mpc/h] with an error estimate (Simpson against the half-size rule
/// plus the propagated loop errors). σ0 = σ/D(z) (eq. lorentzian: σ(z) = σ0 D(z)).
///
/// # Errors
/// As [`crate::loops::OneLoopPlan::new`].
pub fn dispersion_theory(
    spectrum: &crate::linear::LinearSpectrum,
    input: DispersionInput,
    precision: &crate::precision::Precision,
) -> Result<Estimate> {
    // Simpson in ln q on [q_min, q_cut] (P_θθ of the input) and [q_cut, q_max] (P_lin), N intervals each.
    const N: usize = 400;
    // Composite Simpson with step h, and its error estimate |S_h − S_2h|/15.
    fn simpson(h: f64, y: &[f64]) -> f64 {
        let n = y.len() - 1;
        let inner: f64 = (1..n)
            .map(|i| if i % 2 == 1 { 4.0 * y[i] } else { 2.0 * y[i] })
            .sum();
        (y[0] + inner + y[n]) * h / 3.0
    }
    let integrate = |x: &[f64], y: &[f64]| -> (f64, f64) {
        let h = (x[x.len() - 1].ln() - x[0].ln()) / N as f64;
        let fine = simpson(h, y);
        let coarse = simpson(2.0 * h, &y.iter().step_by(2).copied().collect::<Vec<_>>());
        (fine, (fine - coarse).abs() / 15.0)
    };
    let grid = |a: f64, b: f64| -> Vec<f64> {
        (0..=N)
            .map(|i| (a.ln() + (b.ln() - a.ln()) * i as f64 / N as f64).exp())
            .collect()
    };
    let cut = DISPERSION_Q_CUT.clamp(precision.q_min, precision.q_max);
    let low = grid(precision.q_min * (1.0 + 1e-9), cut * (1.0 - 1e-9));
    let (p_tt, loop_error): (Vec<f64>, f64) = match input {
        DispersionInput::Linear => (low.iter().map(|&q| spectrum.eval(q)).collect(), 0.0),
        DispersionInput::OneLoopSpt => {
            let terms = crate::loops::OneLoopPlan::new(&low, precision)?.evaluate(spectrum);
            let corrections: Vec<Estimate> = (0..low.len())
                .map(|i| terms.one_loop(Pair::ThetaTheta, i))
                .collect();
            let p = (0..low.len())
                .map(|i| terms.p_lin[i] + corrections[i].value)
                .collect();
            // Σ err · q Δln q bounds the propagated error of the integral.
            let h = (cut / precision.q_min).ln() / N as f64;
            let e = corrections
                .iter()
                .zip(&low)
                .map(|(c, q)| c.error * q * h)
                .sum();
            (p, e)
        }
    };
    let y: Vec<f64> = low.iter().zip(&p_tt).map(|(q, p)| q * p).collect();
    let (a, ea) = integrate(&low, &y);
    let high = grid(cut, precision.q_max);
    let y: Vec<f64> = high.iter().map(|&q| q * spectrum.eval(q)).collect();
    let (b, eb) = integrate(&high, &y);
    let norm = 1.0 / (6.0 * std::f64::consts::PI.powi(2));
    let sigma2 = (a + b) * norm;
    let error2 = (ea + eb + loop_error) * norm;
    let sigma = sigma2.max(0.0).sqrt();
    Ok(Estimate::new(
        sigma,
        0.5 * error2 / sigma.max(f64::MIN_POSITIVE),
    ))
}

/// Coefficients of L_ℓ(μ) in powers of μ: `legendre_coefficients(ℓ)[j]` multiplies μ^j.
/// Exact in f64 for ℓ ≤ 8 (dyadic rationals with small numerators).
pub(crate) fn legendre_coefficients(ell: usize) -> Vec<f64> {
    // (j+1) L_{j+1} = (2j+1) μ L_j − j L_{j−1}
    let mut prev = vec![1.0];
    if ell == 0 {
        return prev;
    }
    let mut cur = vec![0.0, 1.0];
    for j in 1..ell {
        let mut next = vec![0.0; j + 2];
        for (i, c) in cur.iter().enumerate() {
            next[i + 1] += (2 * j + 1) as f64 * c;
        }
        for (i, c) in prev.iter().enumerate() {
            next[i] -= j as f64 * c;
        }
        next.iter_mut().for_each(|c| *c /= (j + 1) as f64);
        prev = cur;
        cur = next;
    }
    cur
}

/// (2ℓ+1)∫_0^1 μ^{2n} L_ℓ(μ) dμ, exactly (as an f64 sum of exact rationals).
pub(crate) fn polynomial_moment(ell: usize, n: usize) -> f64 {
    let c = legendre_coefficients(ell);
    let integral: f64 = c
        .iter()
        .enumerate()
        .map(|(j, cj)| cj / (2 * n + j + 1) as f64)
        .sum();
    (2 * ell + 1) as f64 * integral
}

/// A precomputed rule for the multipoles P_ℓ of polynomials Σ_n c_n μ^{2n} (n ≤ [`MAX_MU_POWER`]),
/// optionally damped: built once for a list of ℓ, then each evaluation is a few dot products.
#[derive(Debug, Clone)]
pub struct MultipoleRule {
    ells: Vec<usize>,
    /// (2ℓ+1)∫_0^1 μ^{2n} L_ℓ: `exact[l][n]`.
    exact: Vec<[f64; MAX_MU_POWER + 1]>,
    fine: Quadrature,
    coarse: Quadrature,
}

/// Gauss–Legendre nodes μ_i on [0, 1] and the weights (2ℓ+1) w_i L_ℓ(μ_i) μ_i^{2n}.
#[derive(Debug, Clone)]
struct Quadrature {
    mu: Vec<f64>,
    /// `weights[l][n][i]`.
    weights: Vec<[Vec<f64>; MAX_MU_POWER + 1]>,
}

impl Quadrature {
    fn new(ells: &[usize], n: usize) -> Self {
        let (x, w) = legendre_nodes(n);
        let mu: Vec<f64> = x.iter().map(|x| 0.5 * (x + 1.0)).collect();
        let weights = ells
            .iter()
            .map(|&ell| {
                let c = legendre_coefficients(ell);
                let l_of = |m: f64| c.iter().rev().fold(0.0, |acc, cj| acc * m + cj);
                std::array::from_fn(|p| {
                    mu.iter()
                        .zip(&w)
                        .map(|(&m, &wi)| {
                            (2 * ell + 1) as f64 * 0.5 * wi * l_of(m) * m.powi(2 * p as i32)
                        })
                        .collect()
                })
            })
            .collect();
        Self { mu, weights }
    }

    /// P_ℓ for every ℓ of the rule, with damping D²(a μ).
    fn evaluate(&self, coeffs: &[f64], fog: Fog, a: f64, out: &mut [f64]) {
        let damping: Vec<f64> = self
            .mu
            .iter()
            .map(|&m| fog.damping_squared(a * m))
            .collect();
        for (l, w) in self.weights.iter().enumerate() {
            out[l] = coeffs
                .iter()
                .zip(w)
                .map(|(c, wn)| c * wn.iter().zip(&damping).map(|(x, d)| x * d).sum::<f64>())
                .sum();
        }
    }
}

impl MultipoleRule {
    /// The rule for multipoles `ells` (even, ≤ [`MAX_ELL`]).
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] for an empty list or an odd or too large ℓ.
    pub fn new(ells: &[usize]) -> Result<Self> {
        if ells.is_empty() {
            return Err(Error::InvalidParameter {
                name: "number of multipoles",
                value: 0.0,
                reason: "must be at least 1",
            });
        }
        check_ells(ells)?;
        Ok(Self {
            ells: ells.to_vec(),
            exact: ells
                .iter()
                .map(|&l| std::array::from_fn(|n| polynomial_moment(l, n)))
                .collect(),
            fine: Quadrature::new(ells, FOG_NODES),
            coarse: Quadrature::new(ells, FOG_NODES / 2),
        })
    }

    /// The multipole orders of the rule.
    pub fn ells(&self) -> &[usize] {
        &self.ells
    }

    /// P_ℓ(k) for each ℓ of the rule, of P^s = D²(kμσ) Σ_n c_n μ^{2n} with `coeffs[n]` = c_n
    /// (at most [`MAX_MU_POWER`] + 1 of them), at `k_sigma` = kσ. Undamped: exact, error 0. Damped:
    /// 32-point Gauss–Legendre, error = change from the 16-point rule.
    ///
    /// ```
    /// use pt_spectra::rsd::{Fog, MultipoleRule};
    /// let rule = MultipoleRule::new(&[0, 2, 4])?;
    /// // Linear Kaiser, b = 1, f = 1/2, P = 1: P0 = 1 + f/1.5 + f²/5.
    /// let p = rule.evaluate(&[1.0, 1.0, 0.25], Fog::None, 0.0);
    /// assert!((p[0].value - (1.0 + 1.0 / 3.0 + 0.05)).abs() < 1e-15);
    /// # Ok::<(), pt_spectra::error::Error>(())
    /// ```
    ///
    /// # Panics
    /// If `coeffs` has more than [`MAX_MU_POWER`] + 1 entries.
    pub fn evaluate(&self, coeffs: &[f64], fog: Fog, k_sigma: f64) -> Vec<Estimate> {
        assert!(coeffs.len() <= MAX_MU_POWER + 1, "at most μ^8 is supported");
        if fog == Fog::None || k_sigma == 0.0 {
            return self
                .exact
                .iter()
                .map(|e| Estimate::new(coeffs.iter().zip(e).map(|(c, m)| c * m).sum(), 0.0))
                .collect();
        }
        let n = self.ells.len();
        let (mut fine, mut coarse) = (vec![0.0; n], vec![0.0; n]);
        self.fine.evaluate(coeffs, fog, k_sigma, &mut fine);
        self.coarse.evaluate(coeffs, fog, k_sigma, &mut coarse);
        fine.iter()
            .zip(&coarse)
            .map(|(&a, &b)| Estimate::new(a, (a - b).abs()))
            .collect()
    }
}

impl MultipoleRule {
    /// The values only of [`evaluate`](Self::evaluate) (no error estimate, no allocation), written to
    /// `out[i]` for the i-th ℓ of the rule: the fast path of fits.
    ///
    /// # Panics
    /// If `coeffs` has more than [`MAX_MU_POWER`] + 1 entries or `out` is shorter than the ℓ list.
    pub fn evaluate_values(&self, coeffs: &[f64], fog: Fog, k_sigma: f64, out: &mut [f64]) {
        assert!(coeffs.len() <= MAX_MU_POWER + 1, "at most μ^8 is supported");
        if fog == Fog::None || k_sigma == 0.0 {
            for (o, e) in out.iter_mut().zip(&self.exact) {
                *o = coeffs.iter().zip(e).map(|(c, m)| c * m).sum();
            }
            return;
        }
        let q = &self.fine;
        let mut damping = [0.0; FOG_NODES];
        for (d, &m) in damping.iter_mut().zip(&q.mu) {
            *d = fog.damping_squared(k_sigma * m);
        }
        for (o, w) in out.iter_mut().zip(&q.weights) {
            *o = coeffs
                .iter()
                .zip(w)
                .map(|(c, wn)| c * wn.iter().zip(&damping).map(|(x, d)| x * d).sum::<f64>())
                .sum();
        }
    }

    /// The multipoles of D²(kμσ) · `poly`, with the coefficient errors propagated: |L_ℓ| ≤ 1 and
    /// 0 ≤ μ^{2n} D² ≤ 1 on [0, 1], so an error δc_n moves P_ℓ by at most (2ℓ+1) δc_n.
    pub fn evaluate_polynomial(
        &self,
        poly: &MuPolynomial,
        fog: Fog,
        k_sigma: f64,
    ) -> Vec<Estimate> {
        let spread: f64 = poly.error.iter().sum();
        let mut p = self.evaluate(&poly.value, fog, k_sigma);
        for (e, &l) in p.iter_mut().zip(&self.ells) {
            e.error += (2 * l + 1) as f64 * spread;
        }
        p
    }
}

#[cfg(test)]
mod tests;
