//! Hankel transforms of multipoles by FFTLog (Hamilton 2000, MNRAS 312, 257, astro-ph/9905191):
//! power-spectrum multipoles P_ℓ(k) [(Mpc/h)^3, k in h/Mpc] to correlation-function multipoles ξ_ℓ(s)
//! [dimensionless, s in Mpc/h] and back,
//!   ξ_ℓ(s) = i^ℓ ∫ k² dk/(2π²) P_ℓ(k) j_ℓ(ks),   P_ℓ(k) = 4π (−i)^ℓ ∫ s² ds ξ_ℓ(s) j_ℓ(ks),
//! for 0 ≤ ℓ ≤ [`MAX_ELL`]. For even ℓ, i^ℓ = (−i)^ℓ = (−1)^(ℓ/2). For odd ℓ a real ξ_ℓ has an imaginary
//! P_ℓ = −i p_ℓ: the functions take and return the real p_ℓ = i P_ℓ, so that for every ℓ the real arrays
//! are related by the sign (−1)^⌊ℓ/2⌋ in place of i^ℓ and (−i)^ℓ.
//!
//! Method. Both directions are G(y) = ∫_0^∞ F(x) j_ℓ(xy) dx/x with F = x³f. On N log-uniform points
//! x_j = x_0 e^{jΔ}, the biased samples a_j = x_j^{−q} F(x_j) are expanded by an FFT as a trigonometric
//! polynomial in ln x, Σ_m c_m e^{iω_m ln(x/x_0)}, ω_m = 2πm/(NΔ), −N/2 < m ≤ N/2. Each term is a power
//! law with the exact transform y^{−q−iω} U_ℓ(q + iω), where
//!   U_ℓ(z) = ∫_0^∞ t^{z−1} j_ℓ(t) dt = √π 2^{z−2} Γ((ℓ + z)/2) / Γ((ℓ + 3 − z)/2),   −ℓ < Re z < 2,
//! so on y_n = y_0 e^{nΔ}: y_n^q G(y_n) = Σ_m c_m u_m e^{−2πimn/N}, u_m = U_ℓ(q + iω_m)(x_0y_0)^{−iω_m}: bias,
//! FFT, multiply by u_m, FFT back (a forward FFT read in place of the inverse one read backwards), unbias.
//! The Nyquist term keeps Re u only. κ = x_c y_c (the product of the grids' geometric centres, k_c s_c)
//! is the value nearest 1 (within a factor e^{±Δ/2}) that makes u_{N/2} real, Hamilton's "low-ringing"
//! choice; the output grid is y_n = κ/x_{N−1−n}. The Gamma functions come from a complex ln Γ (Stirling
//! series with recurrence and reflection, ≲ 1e-14). With q = 1.5 in both directions the two transforms
//! on reciprocal grids are exact inverses (U_ℓ(z)U_ℓ(3 − z) = π/2).
//!
//! Errors of FFTLog come from the ends: the periodic a_j jumps where the grid wraps around (ringing) and
//! the function is cut where the grid ends (aliasing). The convenience functions [`xi_from_pk`] and
//! [`pk_from_xi`] therefore (see [`HankelOptions`], whose defaults are given there)
//! 1. resample the input on a log-uniform grid by a not-a-knot cubic spline, of ln|f| against ln x where
//!    f keeps one sign and has no zero, of f itself against ln x otherwise (multipoles ℓ ≥ 2 change sign);
//! 2. extend it on both ends by `pad_decades`, each end with the power law fitted by least squares to
//!    ln|f| of the last [`FIT_POINTS`] input points and passing through the end point, or with zeros
//!    where those points change sign or vanish, or where the power law would make the biased x^{3−q}f
//!    grow away from the grid (it would wrap around onto the other end: the tail of ξ at the largest s
//!    is often ringing noise with a steep rising fit);
//! 3. for P → ξ only and if asked for, multiply by exp(−(k/k_damp)²);
//! 4. transform, and interpolate the output at the points asked for by a cubic spline of the value
//!    against ln y. The output is given only over the range reciprocal to the input,
//!    min(1, κ)/x_max ≤ y ≤ max(1, κ)/x_min (κ = k_c s_c ≈ 1, [`HankelPlan::kappa`]).

use crate::error::{Error, Result};
use crate::linear::spline::LogSpline;
use checks::{
    check_ell, check_finite, check_grid, check_options, check_point, invalid, out_of_range,
};
use gamma::ln_gamma;
use rustfft::num_complex::Complex;
use rustfft::{Fft, FftPlanner};
use std::f64::consts::{LN_10, LN_2, PI};
use std::sync::Arc;

type C64 = Complex<f64>;

/// The largest multipole transformed.
pub const MAX_ELL: usize = 8;
/// The fewest points of an input grid.
pub const MIN_POINTS: usize = 16;
/// The number of end points to which the extrapolating power laws are fitted.
pub const FIT_POINTS: usize = 4;
/// The most points of a transform (2^22: 64 MiB per complex buffer).
const MAX_POINTS: usize = 1 << 22;

/// Which way a transform goes.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Direction {
    /// P_ℓ(k) [(Mpc/h)^3] on k [h/Mpc] to ξ_ℓ(s) on s [Mpc/h].
    PkToXi,
    /// ξ_ℓ(s) on s [Mpc/h] to P_ℓ(k) [(Mpc/h)^3] on k [h/Mpc].
    XiToPk,
}

impl Direction {
    /// Names of the input variable, the input values and the output variable, with units.
    fn names(self) -> [&'static str; 3] {
        match self {
            Self::PkToXi => ["k [h/Mpc]", "P_ell [(Mpc/h)^3]", "s [Mpc/h]"],
            Self::XiToPk => ["s [Mpc/h]", "xi_ell", "k [h/Mpc]"],
        }
    }
}

/// An FFTLog transform of one ℓ and direction on one log-uniform input grid, with the coefficients u_m
/// computed once (see the module docs). Output grid: [`output_grid`](Self::output_grid).
#[derive(Clone)]
pub struct HankelPlan {
    ell: usize,
    direction: Direction,
    q: f64,
    /// ln x_0, ln y_0 and the step Δ of ln x and ln y.
    ln_x0: f64,
    ln_y0: f64,
    step: f64,
    /// u_m (times the prefactor and 1/N), in FFT order.
    u: Vec<C64>,
    fft: Arc<dyn Fft<f64>>,
}

impl std::fmt::Debug for HankelPlan {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("HankelPlan")
            .field("ell", &self.ell)
            .field("direction", &self.direction)
            .field("q", &self.q)
            .field("n", &self.u.len())
            .field("x_min", &self.ln_x0.exp())
            .field("y_min", &self.ln_y0.exp())
            .finish()
    }
}

impl HankelPlan {
    /// The plan of multipole `ell` in `direction` on the `n` log-uniform input points from `x_min` to
    /// `x_max` (both included; k [h/Mpc] for [`Direction::PkToXi`], s [Mpc/h] for the other), with the
    /// bias exponent `q` (1.5 suits both directions; see [`HankelOptions::q`]).
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] unless `ell` ≤ [`MAX_ELL`], [`MIN_POINTS`] ≤ `n` ≤ 2^22,
    /// 0 < `x_min` < `x_max` < ∞ and −ℓ < `q` < 2 (where U_ℓ(q) converges).
    pub fn new(
        x_min: f64,
        x_max: f64,
        n: usize,
        ell: usize,
        direction: Direction,
        q: f64,
    ) -> Result<Self> {
        check_ell(ell)?;
        if !(MIN_POINTS..=MAX_POINTS).contains(&n) {
            let reason = "must be at least 16 and at most 2^22";
            return Err(invalid("n (grid points)", n as f64, reason));
        }
        let name = direction.names()[0];
        for x in [x_min, x_max] {
            if !(x.is_finite() && x > 0.0) {
                return Err(invalid(name, x, "must be a finite positive number"));
            }
        }
        if x_max <= x_min {
            return Err(invalid(name, x_max, "the grid's end must exceed its start"));
        }
        if !(q > -(ell as f64) && q < 2.0) {
            return Err(invalid("q (bias exponent)", q, "must satisfy -ell < q < 2"));
        }
        let step = (x_max / x_min).ln() / (n - 1) as f64;
        let ln_x0 = x_min.ln();
        // Low ringing: Im ln U(q + iπ/Δ) − (π/Δ) ln(x_0y_0) ∈ πℤ, ln(x_0y_0) nearest −(n−1)Δ (κ = 1).
        let theta = ln_mellin(ell, C64::new(q, PI / step)).im;
        let j = (theta / PI + (n - 1) as f64).round();
        let ln_x0y0 = step * (theta / PI - j);
        let norm = match direction {
            Direction::PkToXi => 1.0 / (2.0 * PI * PI),
            Direction::XiToPk => 4.0 * PI,
        } * sign(ell)
            / n as f64;
        let u = (0..n)
            .map(|i| {
                let m = if i <= n / 2 {
                    i as f64
                } else {
                    i as f64 - n as f64
                };
                let omega = 2.0 * PI * m / (n as f64 * step);
                let z = C64::new(q, omega);
                (ln_mellin(ell, z) - C64::new(0.0, omega * ln_x0y0)).exp() * norm
            })
            .collect();
        Ok(Self {
            ell,
            direction,
            q,
            ln_x0,
            ln_y0: ln_x0y0 - ln_x0,
            step,
            u,
            fft: FftPlanner::new().plan_fft_forward(n),
        })
    }

    /// The multipole ℓ.
    pub fn ell(&self) -> usize {
        self.ell
    }

    /// The direction.
    pub fn direction(&self) -> Direction {
        self.direction
    }

    /// The input grid x_j = x_min e^{jΔ} (k [h/Mpc] or s [Mpc/h]).
    pub fn input_grid(&self) -> Vec<f64> {
        self.grid(self.ln_x0)
    }

    /// The output grid y_n = κ/x_{N−1−n} (s [Mpc/h] or k [h/Mpc]), with κ = [`kappa`](Self::kappa).
    pub fn output_grid(&self) -> Vec<f64> {
        self.grid(self.ln_y0)
    }

    /// κ = k_c s_c, the product of the input and output grids' geometric centres (within e^{±Δ/2} of 1).
    pub fn kappa(&self) -> f64 {
        (self.ln_x0 + self.ln_y0 + self.step * (self.u.len() - 1) as f64).exp()
    }

    fn grid(&self, ln_start: f64) -> Vec<f64> {
        (0..self.u.len())
            .map(|j| (ln_start + self.step * j as f64).exp())
            .collect()
    }

    /// The transform of `f` given on the input grid (P_ℓ [(Mpc/h)^3] or ξ_ℓ), on the output grid.
    ///
    /// # Errors
    /// [`Error::LengthMismatch`] if `f` is not as long as the grid, [`Error::InvalidValue`] at the first
    /// value of `f` that is not finite.
    pub fn transform(&self, f: &[f64]) -> Result<Vec<f64>> {
        let n = self.u.len();
        if f.len() != n {
            return Err(Error::LengthMismatch {
                what: "Hankel plan grid and input values",
                left: n,
                right: f.len(),
            });
        }
        let name = self.direction.names()[1];
        check_finite("HankelPlan::transform input", name, f)?;
        let tilt = 3.0 - self.q;
        let mut buf: Vec<C64> = f
            .iter()
            .enumerate()
            .map(|(j, &v)| C64::new(v * (tilt * (self.ln_x0 + self.step * j as f64)).exp(), 0.0))
            .collect();
        self.fft.process(&mut buf);
        buf.iter_mut().zip(&self.u).for_each(|(c, u)| *c *= u);
        self.fft.process(&mut buf);
        Ok(buf
            .iter()
            .enumerate()
            .map(|(j, c)| c.re * (-self.q * (self.ln_y0 + self.step * j as f64)).exp())
            .collect())
    }
}

/// Settings of [`xi_from_pk_with`] and [`pk_from_xi_with`]; `Default` gives those of [`xi_from_pk`] and
/// [`pk_from_xi`]. With the defaults (tests/tests/suite/hankel.rs): Gaussian pairs k^ℓ e^{−k²R²/2}, ℓ ≤ 8, are
/// reproduced to ≲ 1e-6 of max|ξ| over 10 ≤ s ≤ 200 Mpc/h (limited by the input grid) and back to
/// ≲ 1e-7 of max|P|, the gm2012 linear spectrum P → ξ → P to ≲ 3e-6 over 0.01 ≤ k ≤ 0.3 h/Mpc, and
/// its ξ_0, ξ_2 (damped by e^{−k²}) agree with direct quadrature to ≲ 1e-7 of their maxima. Within
/// about half a decade of the ends of the reciprocal output range the unbiasing y^{−q} amplifies the
/// ringing, and the relative error of a small output there can be large.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct HankelOptions {
    /// Points per decade of the log-uniform grid (default 200). For ξ_0, ξ_2 of the gm2012 spectrum on
    /// 10 ≤ s ≤ 200 Mpc/h against 800 per decade: 1e-5 of max|ξ| with 50, 5e-7 with 100, 6e-8 with 200.
    pub points_per_decade: f64,
    /// Decades by which the grid is extended on each end (default 3). The ringing of cut ends, against
    /// 4 decades: P → ξ of Gaussians 7e-4 of max|ξ| with 0, 1e-5 with 1, ≲ 1e-6 (the input's own
    /// limit) from 2 on; ξ → P of Gaussians (ξ_0 flat at small s, so that s^{3−q}ξ falls only as s^1.5)
    /// 5e-5 of max|P| with 2, 4e-8 with 3.
    pub pad_decades: f64,
    /// The bias exponent q, −ℓ < q < 2 (default 1.5, the middle of the range of ℓ = 0; it makes the two
    /// directions exact inverses, and k^{3−q}P(k), s^{3−q}ξ(s) of realistic spectra vanish at both ends).
    /// A power law f ∝ x^{q−3} is transformed exactly.
    pub q: f64,
    /// k_damp [h/Mpc] of the damping exp(−(k/k_damp)²) of P → ξ, ignored for ξ → P (default none: the
    /// power-law extension suffices for a P(k) that falls faster than k^{−3/2}). Damping smooths ξ on
    /// scales ≲ √2/k_damp: for gm2012 on 10 ≤ s ≤ 200 Mpc/h it changes ξ_0 and ξ_2 by 4e-3 and 6e-2 of
    /// their maxima for k_damp = 1 h/Mpc, by 4e-5 and 6e-4 for k_damp = 10 h/Mpc.
    pub k_damp: Option<f64>,
}

impl Default for HankelOptions {
    fn default() -> Self {
        Self {
            points_per_decade: 200.0,
            pad_decades: 3.0,
            q: 1.5,
            k_damp: None,
        }
    }
}

/// ξ_ℓ(s) at `s_out` [Mpc/h] from P_ℓ(k) [(Mpc/h)^3] given at `k` [h/Mpc], any strictly increasing
/// positive grid of at least [`MIN_POINTS`] points, with the default [`HankelOptions`] (module docs).
///
/// # Errors
/// [`Error::InvalidParameter`] for ℓ > [`MAX_ELL`]; [`Error::LengthMismatch`] if `k` and `p` differ in
/// length; [`Error::TooFewPoints`]; [`Error::InvalidK`] or [`Error::NonIncreasingK`] for a k that is not
/// finite and positive or does not exceed the previous one; [`Error::InvalidValue`] for a P that is not
/// finite or an s that is not finite and positive; [`Error::InvalidChoice`] for an s outside
/// [min(1, κ)/k_max, max(1, κ)/k_min] (κ ≈ 1, [`HankelPlan::kappa`]).
pub fn xi_from_pk(k: &[f64], p: &[f64], ell: usize, s_out: &[f64]) -> Result<Vec<f64>> {
    xi_from_pk_with(k, p, ell, s_out, &HankelOptions::default())
}

/// [`xi_from_pk`] with the given options.
///
/// # Errors
/// Those of [`xi_from_pk`], and [`Error::InvalidParameter`] for options out of range.
pub fn xi_from_pk_with(
    k: &[f64],
    p: &[f64],
    ell: usize,
    s_out: &[f64],
    options: &HankelOptions,
) -> Result<Vec<f64>> {
    convert(k, p, ell, s_out, Direction::PkToXi, options)
}

/// P_ℓ(k) [(Mpc/h)^3] at `k_out` [h/Mpc] from ξ_ℓ(s) given at `s` [Mpc/h], any strictly increasing
/// positive grid of at least [`MIN_POINTS`] points, with the default [`HankelOptions`] (module docs).
///
/// # Errors
/// [`Error::InvalidParameter`] for ℓ > [`MAX_ELL`]; [`Error::LengthMismatch`] if `s` and `xi` differ in
/// length; [`Error::TooFewPoints`]; [`Error::InvalidValue`] for an s that is not finite and positive or
/// does not exceed the previous one, or a ξ that is not finite; [`Error::InvalidK`] for a k that is not
/// finite and positive; [`Error::OutOfRange`] for a k outside [min(1, κ)/s_max, max(1, κ)/s_min].
pub fn pk_from_xi(s: &[f64], xi: &[f64], ell: usize, k_out: &[f64]) -> Result<Vec<f64>> {
    pk_from_xi_with(s, xi, ell, k_out, &HankelOptions::default())
}

/// [`pk_from_xi`] with the given options (`k_damp` is ignored).
///
/// # Errors
/// Those of [`pk_from_xi`], and [`Error::InvalidParameter`] for options out of range.
pub fn pk_from_xi_with(
    s: &[f64],
    xi: &[f64],
    ell: usize,
    k_out: &[f64],
    options: &HankelOptions,
) -> Result<Vec<f64>> {
    convert(s, xi, ell, k_out, Direction::XiToPk, options)
}

/// The convenience transform: checks, resampling, extension, damping, FFTLog, interpolation.
fn convert(
    x: &[f64],
    f: &[f64],
    ell: usize,
    out: &[f64],
    direction: Direction,
    options: &HankelOptions,
) -> Result<Vec<f64>> {
    let origin = match direction {
        Direction::PkToXi => "xi_from_pk input",
        Direction::XiToPk => "pk_from_xi input",
    };
    let [x_name, f_name, y_name] = direction.names();
    check_ell(ell)?;
    check_options(options)?;
    if x.len() != f.len() {
        return Err(Error::LengthMismatch {
            what: "Hankel transform grid and values",
            left: x.len(),
            right: f.len(),
        });
    }
    if x.len() < MIN_POINTS {
        return Err(Error::TooFewPoints {
            origin: origin.into(),
            found: x.len(),
            min: MIN_POINTS,
        });
    }
    check_grid(origin, direction, x)?;
    check_finite(origin, f_name, f)?;
    for (i, &y) in out.iter().enumerate() {
        check_point("requested points", i, y, y_name)?;
    }
    let (first, last) = (x[0], x[x.len() - 1]);
    let span = (last / first).ln();
    let n_in = (span / LN_10 * options.points_per_decade).ceil() as usize + 1;
    let n_in = n_in.max(MIN_POINTS).next_multiple_of(2);
    let step = span / (n_in - 1) as f64;
    let pad = (options.pad_decades * LN_10 / step).round() as usize;
    let n = n_in + 2 * pad;
    if n > MAX_POINTS {
        let reason = "gives more than 2^22 points over the input range";
        return Err(invalid(
            "points_per_decade",
            options.points_per_decade,
            reason,
        ));
    }
    let ln_start = first.ln() - pad as f64 * step;
    let x_min = ln_start.exp();
    let x_max = (ln_start + (n - 1) as f64 * step).exp();
    let plan = HankelPlan::new(x_min, x_max, n, ell, direction, options.q)?;
    let xs = plan.input_grid();
    let mut values = vec![0.0; n];
    values[pad..pad + n_in].copy_from_slice(&resample(x, f, &xs[pad..pad + n_in]));
    // Power laws that would make x^{3−q} f grow away from the grid (a noisy or unsuitable end) are not used.
    let (m, tilt) = (FIT_POINTS, 3.0 - options.q);
    let low = power_law(&x[..m], &f[..m], 0).filter(|law| law.2 + tilt >= -1e-9);
    let high =
        power_law(&x[x.len() - m..], &f[f.len() - m..], m - 1).filter(|law| law.2 + tilt <= 1e-9);
    for j in 0..pad {
        values[j] = low.map_or(0.0, |(x0, f0, slope)| f0 * (xs[j] / x0).powf(slope));
        let i = n - 1 - j;
        values[i] = high.map_or(0.0, |(x0, f0, slope)| f0 * (xs[i] / x0).powf(slope));
    }
    if let (Direction::PkToXi, Some(k_damp)) = (direction, options.k_damp) {
        values
            .iter_mut()
            .zip(&xs)
            .for_each(|(v, k)| *v *= (-(k / k_damp).powi(2)).exp());
    }
    let g = plan.transform(&values)?;
    let ys = plan.output_grid();
    // The range reciprocal to the input, [1/x_last, 1/x_first] or the output grid's [κ/x_last, κ/x_first],
    // whichever is wider, within the grid.
    let lo = (1.0 / last).min(ys[pad]).max(ys[0]);
    let hi = (1.0 / first).max(ys[n - 1 - pad]).min(ys[n - 1]);
    let spline = LogSpline::new(ys.iter().map(|y| y.ln()).collect(), g);
    out.iter()
        .map(|&y| {
            if y < lo * (1.0 - 1e-12) || y > hi * (1.0 + 1e-12) {
                return Err(out_of_range(direction, y, lo, hi, x_name));
            }
            Ok(spline.eval(y.clamp(lo, hi).ln()))
        })
        .collect()
}

/// f at the log-uniform points `at` (inside [x_0, x_last]) by a cubic spline against ln x: of ln|f| if f
/// keeps one sign and has no zero, of f otherwise.
fn resample(x: &[f64], f: &[f64], at: &[f64]) -> Vec<f64> {
    let ln_x: Vec<f64> = x.iter().map(|v| v.ln()).collect();
    let one_sign = f.iter().all(|&v| v > 0.0) || f.iter().all(|&v| v < 0.0);
    if one_sign {
        let sign = f[0].signum();
        let spline = LogSpline::new(ln_x, f.iter().map(|v| v.abs().ln()).collect());
        at.iter()
            .map(|a| sign * spline.eval(a.ln()).exp())
            .collect()
    } else {
        let spline = LogSpline::new(ln_x, f.to_vec());
        at.iter().map(|a| spline.eval(a.ln())).collect()
    }
}

/// (x_a, f_a, slope): the power law through the point `anchor` of the slices with the least-squares slope
/// of ln|f| against ln x, or `None` if f changes sign or vanishes there.
fn power_law(x: &[f64], f: &[f64], anchor: usize) -> Option<(f64, f64, f64)> {
    if !(f.iter().all(|&v| v > 0.0) || f.iter().all(|&v| v < 0.0)) {
        return None;
    }
    let n = x.len() as f64;
    let lx: Vec<f64> = x.iter().map(|v| v.ln()).collect();
    let lf: Vec<f64> = f.iter().map(|v| v.abs().ln()).collect();
    let (mx, mf) = (lx.iter().sum::<f64>() / n, lf.iter().sum::<f64>() / n);
    let sxf: f64 = lx.iter().zip(&lf).map(|(a, b)| (a - mx) * (b - mf)).sum();
    let sxx: f64 = lx.iter().map(|a| (a - mx).powi(2)).sum();
    Some((x[anchor], f[anchor], sxf / sxx))
}

/// ln U_ℓ(z) = ln[√π 2^{z−2} Γ((ℓ + z)/2)/Γ((ℓ + 3 − z)/2)], the Mellin transform of j_ℓ.
fn ln_mellin(ell: usize, z: C64) -> C64 {
    let l = ell as f64;
    0.5 * PI.ln() + (z - 2.0) * LN_2 + ln_gamma((l + z) / 2.0) - ln_gamma((l + 3.0 - z) / 2.0)
}

/// (−1)^⌊ℓ/2⌋, the real sign of i^ℓ (even ℓ) or i^{ℓ−1} (odd ℓ; module docs).
fn sign(ell: usize) -> f64 {
    if (ell / 2).is_multiple_of(2) {
        1.0
    } else {
        -1.0
    }
}

mod checks;
mod gamma;
#[cfg(test)]
mod tests;
