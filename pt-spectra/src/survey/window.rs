//! The survey window: configuration-space window multipoles ([`WindowPlan`]) or a window matrix
//! ([`WindowMatrix`]).
//!
//! # Window multipoles (Wilson, Peacock, Percival & Ross 2017)
//!
//! With Q(s, μ) = Σ_ℓ Q_ℓ(s) L_ℓ(μ) ([`WindowMultipoles`]) the windowed correlation function is
//! ξ̂(s, μ) = ξ(s, μ) Q(s, μ), whose multipoles are
//!   ξ̂_ℓ(s) = Σ_{ℓ',ℓ''} M_{ℓℓ'ℓ''} ξ_ℓ'(s) Q_ℓ''(s),   M_{ℓℓ'ℓ''} = (2ℓ+1) (ℓ ℓ' ℓ''; 0 0 0)²
//! ([`mixing_coefficient`], exact rationals from the 3j symbols), and the windowed power spectrum is
//!   P̂_ℓ(k) = 4π (−i)^ℓ ∫ s² ds ξ̂_ℓ(s) j_ℓ(ks),   ξ_ℓ(s) = i^ℓ ∫ k² dk/(2π²) P_ℓ(k) j_ℓ(ks).
//! For Q to ℓ = 4 (the BOSS files) and ℓ, ℓ' ≤ 4 this is Wilson et al.'s
//!   ξ̂0 = ξ0Q0 + ξ2Q2/5 + ξ4Q4/9,
//!   ξ̂2 = ξ0Q2 + ξ2[Q0 + 2Q2/7 + 2Q4/7] + ξ4[2Q2/7 + 100Q4/693],
//!   ξ̂4 = ξ0Q4 + ξ2[18Q2/35 + 20Q4/77] + ξ4[Q0 + 20Q2/77 + 162Q4/1001].
//! [`Mixing::Wilson`] (the default) uses every Q_ℓ'' the window has (ℓ'' ≤ 8) and every ξ_ℓ' given;
//! [`Mixing::ClassPtBoss`] is what the CLASS-PT BOSS DR12 likelihoods do (lss_montepython, which fit
//! P0 and P2 only): Q_ℓ'' for ℓ'' ≤ 4 only, and the ξ4 terms of ℓ = 0, 2 dropped,
//! ξ̂0 = ξ0Q0 + ξ2Q2/5, ξ̂2 = ξ0Q2 + ξ2(Q0 + 2(Q2 + Q4)/7); ξ̂4 (and ξ̂6, ξ̂8) are Wilson's truncated at Q4.
//! On the ellipsoidal test window (tests/tests/suite/window.rs) the two differ by up to 1e-3 of P0 at k = 0.0025
//! h/Mpc and 1.3e-4 at 0.0075. Wide-angle terms are neglected (see [`crate::survey`]).
//!
//! # Method
//!
//! 1. The model P_ℓ' is given on [`WindowPlan::k_theory`]: log-uniform from `k_min` to `k_max` with
//!    `points_per_decade`, but with steps of at most `dk` over the output range widened by a margin
//!    (default max(3 dk, 20/s_½), s_½ where Q0 falls to half), where the BAO wiggles must be resolved
//!    for the window's kernel; between these nodes it is a not-a-knot cubic spline in ln k (of ln|P|
//!    where P keeps one sign, of P otherwise).
//! 2. It is resampled on a log-uniform FFTLog grid from k_min/10^`pad_decades` (a power law fitted to the
//!    first four nodes below k_min, or zero where k^{3/2} P would not fall towards k → 0) to
//!    k_max·10^`pad_decades`, tapered to zero over the last `taper_decades` below k_max by
//!    T(x) = x − sin(2πx)/2π (x = ln(k_max/k)/ln(k_max/k_taper)) and zero above k_max. The zeros make
//!    ξ flat at s ≪ 1/k_max, so that the biased s^{3/2} ξ vanishes at the small-s end of the grid (with
//!    the grid ending at k_max, ξ at s < 1/k_max would wrap around to the large-s end, where Q = 0).
//! 3. ξ_ℓ' = FFTLog ([`HankelPlan`](crate::hankel::HankelPlan), q = 1.5) on its reciprocal
//!    low-ringing s grid, moved onto the grid of ℓ' = 0 (they differ by a fraction of a step) by
//!    8-point Lagrange interpolation in ln s; then
//!    Σ_ℓ' M_ℓℓ'(s) ξ_ℓ'(s), M_ℓℓ' = Σ_ℓ'' M_{ℓℓ'ℓ''} Q_ℓ''(s), FFTLog back to P̂_ℓ (one per output ℓ),
//!    and 8-point Lagrange interpolation in ln k to the output k.
//!
//! The two transforms are exact inverses on the same grid, so a window with Q0 = 1 and Q_ℓ>0 = 0 out to
//! the end of the s grid returns the resampled model; the model's high k (where a perturbative model is
//! least reliable) enters through ξ at small s, as it is. Q_ℓ = 0 beyond the window's last s, so ξ is
//! needed only up to there (writing P̂ = P + FFTLog[(M − 1)ξ] instead would weight the transform's ringing
//! floor at s up to 1/k_min by s²: it is not done).
//!
//! All transforms are planned once; [`WindowPlan::apply`] costs 2 × (n_ℓ' + n_ℓ) FFTLogs (at full and
//! half resolution). Measured (tests/tests/suite/window.rs): a uniform sphere (R = 100, 300 Mpc/h) against the
//! direct 3-D convolution to ≤ 1.2e-5 of P̂0 for 0.005 ≤ k ≤ 0.3 h/Mpc, a BOSS-format window against an
//! independent numpy quadrature to ≤ 2e-5; 0.5 ms per call for P0, P2, P4 at 240 output k.
//!
//! Error estimate: |P̂ − P̂_half| against the same computation on every other point of the FFTLog grid
//! (an over-estimate for converged transforms), plus the model's spline error for ℓ' = ℓ,
//! |S − S_half|/15 against the spline through every other node (the O(h⁴) scaling), the largest at
//! the midpoints of the three intervals of the model's grid nearest to the output k. It does not see
//! spline errors far from the output k that the kernel's tails sample (a few 1e-6 of P̂0 for the sphere).

mod format;
mod matrix;
mod multipoles;
mod npy;
mod transforms;
mod wigner;

pub use format::{WindowFormat, BOSS_ROWS, WINDOW_FORMAT_HELP};
pub use matrix::WindowMatrix;
pub use multipoles::{boss_s_grid, WindowMultipoles, BOSS_S_MAX, BOSS_S_MIN};

use super::{check_ells, check_increasing, check_model, MAX_ELL};
use crate::error::{Error, Result};
use crate::estimate::Estimate;
use std::f64::consts::{LN_10, PI};
use transforms::{fft_size, Level, Resampled};

/// How the window multipoles mix the model's multipoles (module docs).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Mixing {
    /// Wilson et al. (2017) with every Q_ℓ'' of the window and every ξ_ℓ' given (the default).
    #[default]
    Wilson,
    /// The CLASS-PT BOSS likelihoods: Q_ℓ'' for ℓ'' ≤ 4, and no ξ_ℓ' with ℓ' ≥ 4 in ξ̂0, ξ̂2.
    ClassPtBoss,
}

impl Mixing {
    /// Whether ξ_ℓ' Q_ℓ'' enters ξ̂_ℓ: always for [`Wilson`](Self::Wilson) (ℓ'' ≤ 8); for
    /// [`ClassPtBoss`](Self::ClassPtBoss) if ℓ'' ≤ 4 and, for ℓ ≤ 2, ℓ' ≤ 2.
    pub fn uses(self, ell: usize, ell_in: usize, ell_q: usize) -> bool {
        match self {
            Self::Wilson => ell_q <= MAX_ELL,
            Self::ClassPtBoss => ell_q <= 4 && (ell > 2 || ell_in <= 2),
        }
    }
}

/// The weight of ξ_ℓ' Q_ℓ'' in ξ̂_ℓ: (2ℓ+1) (ℓ ℓ' ℓ''; 0 0 0)² if [`Mixing::uses`] the term, else 0.
pub fn mixing_coefficient(mixing: Mixing, ell: usize, ell_in: usize, ell_q: usize) -> f64 {
    if mixing.uses(ell, ell_in, ell_q) {
        wigner::wilson(ell, ell_in, ell_q)
    } else {
        0.0
    }
}

/// Settings of [`WindowPlan`] (module docs, "Method"); `Default` gives the values stated per field.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct WindowOptions {
    /// The smallest k of the model, h/Mpc (default 1e-4).
    pub k_min: f64,
    /// The largest k of the model, h/Mpc (default 4); the output k must lie below k_max·10^−taper.
    pub k_max: f64,
    /// Points per decade of the model's grid away from the output range (default 24).
    pub points_per_decade: f64,
    /// The largest step of the model's grid over the output range, h/Mpc (default 0.005: about 12
    /// points per BAO wiggle).
    pub dk: f64,
    /// Points per decade of the FFTLog grid (default 128; the sphere test is the same with 256).
    pub fft_points_per_decade: f64,
    /// Decades below k_max over which the model is tapered to zero (default 0.25).
    pub taper_decades: f64,
    /// How far beyond the output k the model's grid keeps steps ≤ dk, h/Mpc (default `None`: 20/s_½,
    /// s_½ the first s where Q0 falls to half its value at s → 0, and at least 3 dk). Windows with sharp
    /// edges have kernels with q⁻⁴ tails: a uniform sphere of radius R has 3/(πRq) of its weight beyond
    /// q, which samples the model far from the output k.
    pub margin: Option<f64>,
    /// Decades by which the FFTLog grid extends below k_min (with the power law) and above k_max (with
    /// zeros), default 3: the biased s^{3/2} ξ(s) must vanish at both ends of the s grid, or the
    /// transform wraps ξ at s ≲ 1/k_max around to the largest s (where the window is zero).
    pub pad_decades: f64,
}

impl Default for WindowOptions {
    fn default() -> Self {
        Self {
            k_min: 1e-4,
            k_max: 4.0,
            points_per_decade: 24.0,
            dk: 0.005,
            fft_points_per_decade: 128.0,
            taper_decades: 0.25,
            margin: None,
            pad_decades: 3.0,
        }
    }
}

/// The fine range of the model's grid extends this many window widths 1/s_½ beyond the output k
/// (s_½: where Q0 falls to half its value at s → 0).
const MARGIN_WIDTHS: f64 = 20.0;

/// The window-multipole convolution of a model from its multipoles on [`k_theory`](Self::k_theory) to the
/// windowed multipoles at the output k, planned once (module docs).
#[derive(Debug, Clone)]
pub struct WindowPlan {
    ells_out: Vec<usize>,
    k_out: Vec<f64>,
    k_theory: Vec<f64>,
    /// The midpoints of the model's intervals where its spline error is probed, and for each output k
    /// the range of them (the three intervals nearest to it).
    midpoints: Vec<f64>,
    probes: Vec<std::ops::Range<usize>>,
    mixing: Mixing,
    /// The FFTLog grid (an even number of points, half of them 2^a 3^b) and the taper on it (1 below
    /// k_min, where the power law is used, 0 above k_max).
    fft_k: Vec<f64>,
    taper: Vec<f64>,
    k_min: f64,
    levels: [Level; 2],
}

impl WindowPlan {
    /// The plan of the windowed multipoles `ells_out` at `k_out` [h/Mpc] with the default
    /// [`WindowOptions`].
    ///
    /// # Errors
    /// As [`with_options`](Self::with_options).
    pub fn new(
        ells_out: &[usize],
        k_out: &[f64],
        window: &WindowMultipoles,
        mixing: Mixing,
    ) -> Result<Self> {
        Self::with_options(ells_out, k_out, window, mixing, &WindowOptions::default())
    }

    /// The plan with the given options.
    ///
    /// # Errors
    /// [`Error::InvalidChoice`] for `ells_out` that are not distinct even multipoles ≤ 8;
    /// [`Error::InvalidParameter`] for options out of range; [`Error::InvalidK`] or
    /// [`Error::NonIncreasingK`] for `k_out` that are not positive and increasing (at least one);
    /// [`Error::OutOfRange`] for a k_out outside [k_min, k_max·10^−taper].
    pub fn with_options(
        ells_out: &[usize],
        k_out: &[f64],
        window: &WindowMultipoles,
        mixing: Mixing,
        options: &WindowOptions,
    ) -> Result<Self> {
        check_ells("windowed multipoles", ells_out)?;
        check_options(options)?;
        if k_out.is_empty() {
            return Err(Error::TooFewPoints {
                origin: "window plan output k".into(),
                found: 0,
                min: 1,
            });
        }
        check_increasing("window plan output k", k_out, false)?;
        let k_taper = options.k_max * 10f64.powf(-options.taper_decades);
        for &k in k_out {
            if k < options.k_min || k > k_taper {
                return Err(Error::OutOfRange {
                    what: "the window plan's model range (WindowOptions k_min, k_max, taper)"
                        .into(),
                    k,
                    min: options.k_min,
                    max: k_taper,
                });
            }
        }
        let margin = options.margin.unwrap_or_else(|| {
            window_width(window).map_or(3.0 * options.dk, |w| {
                (MARGIN_WIDTHS * w).max(3.0 * options.dk)
            })
        });
        let k_theory = theory_grid(k_out, margin, options);
        let last = k_theory.len() - 2;
        let probes = k_out
            .iter()
            .map(|&k| {
                let i = k_theory.partition_point(|&t| t <= k).clamp(1, last + 1) - 1;
                i.saturating_sub(1)..(i + 2).min(last + 1)
            })
            .collect::<Vec<_>>();
        let (first, end) = (probes[0].start, probes[probes.len() - 1].end);
        let midpoints = (first..end)
            .map(|j| 0.5 * (k_theory[j] + k_theory[j + 1]))
            .collect();
        let probes = probes
            .into_iter()
            .map(|r| r.start - first..r.end - first)
            .collect();
        let pad = 10f64.powf(options.pad_decades);
        let (k_lo, k_hi) = (options.k_min / pad, options.k_max * pad);
        let n = fft_size(((k_hi / k_lo).log10() * options.fft_points_per_decade).ceil() as usize);
        let step = (k_hi / k_lo).ln() / (n - 1) as f64;
        let fft_k: Vec<f64> = (0..n).map(|j| k_lo * (step * j as f64).exp()).collect();
        let taper = fft_k.iter().map(|&k| taper(k, options)).collect();
        let level = |stride| Level::new(stride, &fft_k, ells_out, k_out, window, mixing);
        Ok(Self {
            ells_out: ells_out.to_vec(),
            k_out: k_out.to_vec(),
            k_theory,
            midpoints,
            probes,
            mixing,
            taper,
            k_min: options.k_min,
            levels: [level(1)?, level(2)?],
            fft_k,
        })
    }

    /// Where the model must be evaluated: k [h/Mpc], increasing.
    pub fn k_theory(&self) -> &[f64] {
        &self.k_theory
    }

    /// The output k [h/Mpc].
    pub fn k_out(&self) -> &[f64] {
        &self.k_out
    }

    /// The output multipoles.
    pub fn ells_out(&self) -> &[usize] {
        &self.ells_out
    }

    /// The mixing.
    pub fn mixing(&self) -> Mixing {
        self.mixing
    }

    /// The number of points of the FFTLog grid.
    pub fn fft_points(&self) -> usize {
        self.fft_k.len()
    }

    /// The windowed multipoles P̂_ℓ [(Mpc/h)^3] at the output k, one vector per output ℓ, from the model's
    /// P_0, P_2, … (1 to 5 of them, in order) on [`k_theory`](Self::k_theory); missing higher multipoles
    /// are zero.
    ///
    /// # Errors
    /// [`Error::InvalidChoice`] for no or more than 5 multipoles, [`Error::LengthMismatch`] for one not
    /// as long as k_theory, [`Error::InvalidValue`] for a value that is not finite,
    /// [`Error::NonFiniteOutput`] if the result is not finite.
    pub fn apply(&self, p: &[Vec<f64>]) -> Result<Vec<Vec<Estimate>>> {
        check_model("WindowPlan::apply", p, self.k_theory.len())?;
        let n_out = self.k_out.len();
        let mut on_grid = Vec::with_capacity(p.len());
        let mut spline_error = Vec::with_capacity(p.len());
        for values in p {
            let model = Resampled::new(&self.k_theory, values);
            on_grid.push(self.on_fft_grid(&model));
            let coarse = Resampled::new_half(&self.k_theory, values);
            let at_midpoints: Vec<f64> = self
                .midpoints
                .iter()
                .map(|&k| (model.eval(k) - coarse.eval(k)).abs() / 15.0)
                .collect();
            spline_error.push(
                self.probes
                    .iter()
                    .map(|r| {
                        at_midpoints[r.clone()]
                            .iter()
                            .fold(0.0, |a: f64, &b| a.max(b))
                    })
                    .collect::<Vec<_>>(),
            );
        }
        let windowed = [
            self.levels[0].apply(&on_grid)?,
            self.levels[1].apply(&on_grid)?,
        ];
        let mut out = Vec::with_capacity(self.ells_out.len());
        for (o, &ell) in self.ells_out.iter().enumerate() {
            let spline = (mixing_coefficient(self.mixing, ell, ell, 0) != 0.0)
                .then(|| spline_error.get(ell / 2))
                .flatten();
            let mut row = Vec::with_capacity(n_out);
            for j in 0..n_out {
                let value = windowed[0][o][j];
                if !value.is_finite() {
                    return Err(Error::NonFiniteOutput {
                        column: format!("windowed P_{ell}"),
                        at: format!("k = {} h/Mpc", self.k_out[j]),
                        value,
                    });
                }
                let e = spline.map_or(0.0, |d| d[j]);
                row.push(Estimate::new(value, e + (value - windowed[1][o][j]).abs()));
            }
            out.push(row);
        }
        Ok(out)
    }

    /// The values of [`apply`](Self::apply) without its error estimate (one FFTLog level, no spline
    /// probe): what a fit evaluates at every step.
    ///
    /// # Errors
    /// As [`apply`](Self::apply).
    pub fn apply_values(&self, p: &[Vec<f64>]) -> Result<Vec<Vec<f64>>> {
        check_model("WindowPlan::apply_values", p, self.k_theory.len())?;
        let on_grid: Vec<Vec<f64>> = p
            .iter()
            .map(|values| self.on_fft_grid(&Resampled::new(&self.k_theory, values)))
            .collect();
        let windowed = self.levels[0].apply(&on_grid)?;
        for (row, &ell) in windowed.iter().zip(&self.ells_out) {
            if let Some((j, &value)) = row.iter().enumerate().find(|(_, v)| !v.is_finite()) {
                return Err(Error::NonFiniteOutput {
                    column: format!("windowed P_{ell}"),
                    at: format!("k = {} h/Mpc", self.k_out[j]),
                    value,
                });
            }
        }
        Ok(windowed)
    }

    /// The model on the FFTLog grid: the power law below k_min, tapered to zero towards k_max.
    fn on_fft_grid(&self, model: &Resampled) -> Vec<f64> {
        self.fft_k
            .iter()
            .zip(&self.taper)
            .map(|(&k, &t)| {
                if k < self.k_min {
                    model.extend(k)
                } else if t == 0.0 {
                    0.0
                } else {
                    t * model.eval(k)
                }
            })
            .collect()
    }
}

/// The model's grid: log-uniform steps, at most `dk` over the output range ± `margin` (module docs).
pub(super) fn theory_grid(k_out: &[f64], margin: f64, o: &WindowOptions) -> Vec<f64> {
    let (lo, hi) = (k_out[0] - margin, k_out[k_out.len() - 1] + margin);
    let ratio = (LN_10 / o.points_per_decade).exp_m1();
    let mut grid = vec![o.k_min];
    let mut k = o.k_min;
    loop {
        let mut step = k * ratio;
        if (lo..=hi).contains(&k) {
            step = step.min(o.dk);
        }
        if k + step >= o.k_max - 0.25 * step {
            grid.push(o.k_max);
            return grid;
        }
        k += step;
        grid.push(k);
    }
}

/// The taper of the model at k (step 2 of the module docs): 1 up to k_max·10^−taper_decades (and below
/// k_min), T(x) = x − sin(2πx)/2π over the last `taper_decades`, 0 from k_max on.
pub(super) fn taper(k: f64, o: &WindowOptions) -> f64 {
    let k_taper = o.k_max * 10f64.powf(-o.taper_decades);
    if k < o.k_min || k <= k_taper {
        1.0
    } else if k >= o.k_max {
        0.0
    } else {
        let x = ((o.k_max / k).ln() / (o.k_max / k_taper).ln()).clamp(0.0, 1.0);
        x - (2.0 * PI * x).sin() / (2.0 * PI)
    }
}

/// 1/s_½ [h/Mpc], s_½ the first tabulated s where Q0 ≤ Q0(0)/2 (None if Q0 never falls to half).
fn window_width(window: &WindowMultipoles) -> Option<f64> {
    let q0 = window.column(0)?;
    let i = q0.iter().position(|&q| q.abs() <= 0.5 * q0[0].abs())?;
    Some(1.0 / window.s()[i])
}

fn check_options(o: &WindowOptions) -> Result<()> {
    let bad = |name, value, reason| {
        Err(Error::InvalidParameter {
            name,
            value,
            reason,
        })
    };
    if !(o.k_min.is_finite() && o.k_min > 0.0) {
        return bad("k_min [h/Mpc]", o.k_min, "must be a finite positive number");
    }
    if !(o.k_max.is_finite() && o.k_max >= 10.0 * o.k_min) {
        return bad(
            "k_max [h/Mpc]",
            o.k_max,
            "must be finite and at least 10 k_min",
        );
    }
    if !(o.points_per_decade.is_finite() && (4.0..=1e4).contains(&o.points_per_decade)) {
        return bad(
            "points_per_decade",
            o.points_per_decade,
            "must be between 4 and 1e4",
        );
    }
    if (o.k_max / o.k_min).log10() * o.points_per_decade < 8.0 {
        let reason = "must give at least 8 model points between k_min and k_max";
        return bad("points_per_decade", o.points_per_decade, reason);
    }
    if !(o.dk.is_finite() && o.dk > 0.0) {
        return bad("dk [h/Mpc]", o.dk, "must be a finite positive number");
    }
    let fft = o.fft_points_per_decade;
    if !(fft.is_finite() && (32.0..=1e5).contains(&fft)) {
        return bad("fft_points_per_decade", fft, "must be between 32 and 1e5");
    }
    let t = o.taper_decades;
    if !(t.is_finite() && t >= 0.0 && o.k_max * 10f64.powf(-t) > o.k_min) {
        return bad("taper_decades", t, "must be at least 0 and end above k_min");
    }
    if let Some(m) = o.margin.filter(|m| !(m.is_finite() && *m >= 0.0)) {
        return bad("margin [h/Mpc]", m, "must be finite and at least 0");
    }
    if !(o.pad_decades.is_finite() && (0.0..=10.0).contains(&o.pad_decades)) {
        return bad("pad_decades", o.pad_decades, "must be between 0 and 10");
    }
    Ok(())
}

#[cfg(test)]
mod tests;
