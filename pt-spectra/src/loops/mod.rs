//! Loop corrections of standard perturbation theory (SPT) in real space, with error estimates.
//!
//! Conventions (Gil-Marín et al. 2012, arXiv:1209.3771, section 2.1): θ ≡ −∇·v/(aHf), so θ_lin = δ_lin,
//! and the 1-loop correction of P_XY is P22_XY + 2 P13_XY, with
//! * P22_δδ = 2∫d³q/(2π)³ [F_2^s(q, k−q)]² P(q)P(|k−q|), P22_δθ = 2∫F₂G₂PP, P22_θθ = 2∫G₂²PP;
//! * P13_δδ = 3P(k)∫d³q/(2π)³ F_3^s(k, q, −q)P(q), P13_θθ = 3P∫G₃P, P13_δθ = (3/2)P∫(F₃ + G₃)P
//!   (so 2·P13_δθ is FAST-PT's and RegPT's P13_dt = 3P∫(F₃ + G₃)P);
//! * σ_v² = (1/6π²)∫P(q)dq.
//!
//! Every term is an [`Estimate`]: a value and an error estimate. How the errors are estimated:
//! * **σ_v² and P13** are exact integrals of the lattice interpolant P̃ (see below) against the closed-form
//!   angular kernels; the error is |I_h − I_2h|, the change when the lattice step h is doubled (every
//!   other lattice point). For a fourth-order interpolant this overestimates the error of I_h ~16-fold.
//! * **P22** uses Gauss–Legendre panels (module `p22`); the error is |I − I′|, where I′ lowers every
//!   panel's order from n to n − 2 (narrow inner ranges: n_narrow − 1) on the same panels and uses the
//!   half-resolution lattice, with a floor of [`Precision::p22_error_floor`] × |I| (default 3e-6):
//!   Gauss–Legendre converges exponentially on smooth integrands, so |I − I′| mostly exceeds the actual
//!   error by 1–2 orders of magnitude, but on tabulated spectra (BAO wiggles through a C² spline, table
//!   round-off, power-law joins) convergence turns erratic at the 1e-6 level, which the floor covers.
//! * Measured (tests/one_loop.rs, CAMB gm2012 spectra, 1e-3 ≤ k ≤ 1 h/Mpc): default against reference
//!   settings ≤ 2.5e-6 (P22) and ≤ 3e-10 (P13); against FAST-PT ≤ 9e-6 (P22) and ≤ 1.5e-6 (2P13) for
//!   0.01 ≤ k ≤ 0.5; against an independent brute-force P22 quadrature ≤ 7e-7.
//!
//! Speed: [`OneLoopPlan`] is built once per k grid (cosmology independent). It samples the linear
//! spectrum once on a lattice uniform in ln q (step [`Precision::lattice_step`]) and interpolates it with
//! cubic Lagrange polynomials in ln q, which are linear in the samples, so each term is a fixed weighted
//! sum of the samples (P13, σ_v²) or of products of interpolated values (P22).
//!
//! Integration range: q ∈ [q_min, q_max] = [1e-5, 1e3] h/Mpc by default (FAST-PT's extrapolated range
//! for the reference tables; with it σ_v² of the gm2012 z = 0 table is 36.947450 (Mpc/h)², matching the
//! FAST-PT header to 2e-8). Cutting the integrals to the CAMB table range [1e-4, 50] h/Mpc instead changes
//! σ_v² by −4.5e-5, P13 by −(3–7)e-5 and P22 by −1.9e-4 at k = 0.01 h/Mpc (−1.5e-5 at k = 0.1): enough
//! to miss the FAST-PT reference at the 1e-4 level.
//!
//! [`Precision::lattice_step`]: crate::precision::Precision::lattice_step
//! [`Precision::p22_error_floor`]: crate::precision::Precision::p22_error_floor

mod lattice;
mod one_loop;
mod p13;
mod p15;
mod p17;
mod p22;
mod tns;
mod two_loop;

pub use one_loop::OneLoopPlan;
pub use p13::{k1_kernels, p13_kernels};
pub use p15::{cache_path, p15_angular_kernel, P15Table};
pub use p17::{p17_angular_kernel, P17Table};
pub use p22::f2_g2;
pub use tns::{tns, TnsCoefficients, TnsPlan, TnsTerms};
pub use two_loop::{
    two_loop, two_loop_refined, two_loop_with_progress, TwoLoopPair, TwoLoopSettings, TwoLoopTerms,
    REFINE_LIMIT,
};

use crate::error::Result;
use crate::linear::LinearSpectrum;
use crate::precision::Precision;

/// A computed value with an estimate of its numerical error (same units).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Estimate {
    /// The value.
    pub value: f64,
    /// The estimated absolute numerical error (≥ 0).
    pub error: f64,
}

impl Estimate {
    /// A value with its error estimate.
    pub const fn new(value: f64, error: f64) -> Self {
        Self { value, error }
    }

    /// The mean of two estimates, errors averaged: the δθ propagator terms are the means of the δδ and
    /// θθ ones (P1n_δθ = (P1n_δδ + P1n_θθ)/2).
    pub fn mean(a: Self, b: Self) -> Self {
        Self::new(0.5 * (a.value + b.value), 0.5 * (a.error + b.error))
    }

    /// The error relative to |value| (∞ if the value is 0 and the error is not).
    pub fn relative_error(&self) -> f64 {
        if self.error == 0.0 {
            0.0
        } else {
            self.error / self.value.abs()
        }
    }
}

/// Which pair of fields a spectrum correlates.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Pair {
    /// Density–density, P_δδ.
    DeltaDelta,
    /// Density–velocity divergence, P_δθ.
    DeltaTheta,
    /// Velocity divergence–velocity divergence, P_θθ.
    ThetaTheta,
}

impl Pair {
    /// All three, in the order δδ, δθ, θθ.
    pub const ALL: [Pair; 3] = [Pair::DeltaDelta, Pair::DeltaTheta, Pair::ThetaTheta];

    /// Short name used in table headers: `dd`, `dt`, `tt`.
    pub fn suffix(self) -> &'static str {
        match self {
            Pair::DeltaDelta => "dd",
            Pair::DeltaTheta => "dt",
            Pair::ThetaTheta => "tt",
        }
    }
}

/// The 1-loop terms of one pair on the plan's k grid [(Mpc/h)^3].
#[derive(Debug, Clone, Default, PartialEq)]
pub struct PairTerms {
    /// P22 at each k.
    pub p22: Vec<Estimate>,
    /// P13 at each k, in the paper's normalisation (the correction is P22 + 2 P13).
    pub p13: Vec<Estimate>,
    /// P15 at each k (2-loop propagator term, the correction containing 2 P15), or empty if not computed
    /// (see [`add_p15`]).
    pub p15: Vec<Estimate>,
    /// P17 at each k (3-loop propagator term), or empty if not computed (see [`add_p17`]).
    pub p17: Vec<Estimate>,
    /// P24 at each k (the correction contains 2 P24), or empty if not computed (see [`add_two_loop`]).
    pub p24: Vec<Estimate>,
    /// P33^{2L} = P33irr, the mode-coupling part of P33, or empty (see [`add_two_loop`]).
    pub p33_2l: Vec<Estimate>,
    /// The whole 2-loop SPT correction 2P15 + 2P24 + P33, or empty (see [`add_two_loop`]).
    pub two_loop: Vec<Estimate>,
}

impl PairTerms {
    fn with_capacity(n: usize) -> Self {
        Self {
            p22: Vec::with_capacity(n),
            p13: Vec::with_capacity(n),
            p15: Vec::new(),
            p17: Vec::new(),
            p24: Vec::new(),
            p33_2l: Vec::new(),
            two_loop: Vec::new(),
        }
    }

    /// The 1-loop correction P22 + 2 P13 at k index `i`, errors added linearly.
    pub fn one_loop(&self, i: usize) -> Estimate {
        let (a, b) = (self.p22[i], self.p13[i]);
        Estimate::new(a.value + 2.0 * b.value, a.error + 2.0 * b.error)
    }
}

/// All 1-loop SPT terms on a k grid.
#[derive(Debug, Clone, PartialEq)]
pub struct OneLoopTerms {
    /// Wavenumbers [h/Mpc].
    pub k: Vec<f64>,
    /// The linear spectrum at k [(Mpc/h)^3].
    pub p_lin: Vec<f64>,
    /// σ_v² = (1/6π²)∫P dq over [q_min, q_max] [(Mpc/h)²].
    pub sigma_v2: Estimate,
    /// δδ terms.
    pub dd: PairTerms,
    /// δθ terms.
    pub dt: PairTerms,
    /// θθ terms.
    pub tt: PairTerms,
}

impl OneLoopTerms {
    /// The terms of `pair`.
    pub fn pair(&self, pair: Pair) -> &PairTerms {
        match pair {
            Pair::DeltaDelta => &self.dd,
            Pair::DeltaTheta => &self.dt,
            Pair::ThetaTheta => &self.tt,
        }
    }

    fn pair_mut(&mut self, pair: Pair) -> &mut PairTerms {
        match pair {
            Pair::DeltaDelta => &mut self.dd,
            Pair::DeltaTheta => &mut self.dt,
            Pair::ThetaTheta => &mut self.tt,
        }
    }
}

/// Adds P15 of δδ, δθ, θθ to `terms` (computed for `spectrum`, which must be the one `terms` were made
/// from) from the angular table ([`P15Table::get`], built or read from the cache on first use; `progress`
/// is called while it is built), over the q range and lattice step of `precision`.
pub fn add_p15(
    terms: &mut OneLoopTerms,
    spectrum: &LinearSpectrum,
    precision: &Precision,
    progress: &(dyn Fn(usize, usize) + Sync),
) {
    let rows = P15Table::get(progress).evaluate(
        &terms.k,
        spectrum,
        (precision.q_min, precision.q_max),
        precision.lattice_step,
    );
    terms.set_rows(&rows, |pair| &mut pair.p15);
}

/// Adds P17 of δδ, δθ, θθ to `terms`, as [`add_p15`] from the P17 angular table ([`P17Table::get`]).
pub fn add_p17(
    terms: &mut OneLoopTerms,
    spectrum: &LinearSpectrum,
    precision: &Precision,
    progress: &(dyn Fn(usize, usize) + Sync),
) {
    let rows = P17Table::get(progress).evaluate(
        &terms.k,
        spectrum,
        (precision.q_min, precision.q_max),
        precision.lattice_step,
    );
    terms.set_rows(&rows, |pair| &mut pair.p17);
}

impl OneLoopTerms {
    /// Sets one term of δδ, δθ, θθ from rows [δδ, δθ, θθ] per k.
    fn set_rows(
        &mut self,
        rows: &[[Estimate; 3]],
        field: impl Fn(&mut PairTerms) -> &mut Vec<Estimate>,
    ) {
        for (j, pair) in [&mut self.dd, &mut self.dt, &mut self.tt]
            .into_iter()
            .enumerate()
        {
            *field(pair) = rows.iter().map(|row| row[j]).collect();
        }
    }

    /// P33red_XY = P13_X P13_Y / P_lin at k index `i` (first term of eq. P33; P13_X = P13_δδ or P13_θθ).
    pub fn p33_reducible(&self, pair: Pair, i: usize) -> Estimate {
        let (a, b) = match pair {
            Pair::DeltaDelta => (self.dd.p13[i], self.dd.p13[i]),
            Pair::DeltaTheta => (self.dd.p13[i], self.tt.p13[i]),
            Pair::ThetaTheta => (self.tt.p13[i], self.tt.p13[i]),
        };
        let p = self.p_lin[i];
        Estimate::new(
            a.value * b.value / p,
            (a.value.abs() * b.error + b.value.abs() * a.error) / p,
        )
    }
}

/// Adds the 2-loop terms to `terms` (made from `spectrum` with `precision`): P15 (if missing, from the
/// angular table), P24 and P33^{2L} from the quasi-Monte-Carlo integral ([`two_loop`]), and the whole
/// correction 2P15 + 2P24 + P33 as the sum of two infrared-safe parts, each one integral: the
/// propagator part 2P15 − P33red ([`P15Table::propagator_part`]) and the mode-coupling part
/// 2P24 + P33irr + 2P33red (see the `two_loop` module), with points added where the correction's error
/// exceeds [`Precision::two_loop_tolerance`] of it ([`two_loop_refined`]); or at low k, if it has the
/// smaller error, as 2P15 + P33red + (2P24 + P33irr). `table_progress` reports the P15 table build
/// (if P15 is missing and the table is not cached), `points_progress` the quasi-Monte-Carlo points
/// done.
pub fn add_two_loop(
    terms: &mut OneLoopTerms,
    spectrum: &LinearSpectrum,
    precision: &Precision,
    table_progress: &(dyn Fn(usize, usize) + Sync),
    points_progress: &(dyn Fn(usize, usize) + Sync),
) {
    if terms.dd.p15.len() != terms.k.len() {
        add_p15(terms, spectrum, precision, table_progress);
    }
    let settings = TwoLoopSettings {
        points: precision.two_loop_points,
        replicas: precision.two_loop_replicas,
        tolerance: precision.two_loop_tolerance,
        seed: precision.two_loop_seed,
        ..TwoLoopSettings::default()
    };
    let propagator = P15Table::get(table_progress).propagator_part(
        &terms.k,
        spectrum,
        (precision.q_min, precision.q_max),
        precision.lattice_step,
    );
    let mc = two_loop_refined(
        &terms.k,
        spectrum,
        (precision.q_min, precision.q_max),
        precision.lattice_step,
        &settings,
        &propagator,
        points_progress,
    );
    for (j, pair) in Pair::ALL.into_iter().enumerate() {
        let total: Vec<Estimate> = (0..terms.k.len())
            .map(|i| {
                let (p15, red, propagator, ir_safe) = (
                    terms.pair(pair).p15[i],
                    terms.p33_reducible(pair, i),
                    propagator[i][j],
                    mc.pairs[j].ir_safe[i],
                );
                let ir_safe = Estimate::new(
                    propagator.value + ir_safe.value,
                    propagator.error + ir_safe.error,
                );
                // At k ≲ 0.03 h/Mpc, where the infrared pieces are small, the plain mode coupling can
                // be the more precise: take whichever estimate has the smaller error.
                let m = mc.pairs[j].mode_coupling[i];
                let split = Estimate::new(
                    2.0 * p15.value + red.value + m.value,
                    2.0 * p15.error + red.error + m.error,
                );
                if split.error < ir_safe.error {
                    split
                } else {
                    ir_safe
                }
            })
            .collect();
        let t = terms.pair_mut(pair);
        t.p24 = mc.pairs[j].p24.clone();
        t.p33_2l = mc.pairs[j].p33_2l.clone();
        t.two_loop = total;
    }
}

/// All 1-loop terms of `spectrum` at wavenumbers `k` [h/Mpc]: builds a [`OneLoopPlan`] and evaluates it
/// (in parallel over k). Build the plan yourself to reuse it for several spectra.
///
/// # Errors
/// As [`OneLoopPlan::new`].
pub fn one_loop(
    spectrum: &LinearSpectrum,
    k: &[f64],
    precision: &Precision,
) -> Result<OneLoopTerms> {
    Ok(OneLoopPlan::new(k, precision)?.par_evaluate(spectrum))
}
