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
//! * Measured (tests/tests/suite/one_loop.rs, CAMB gm2012 spectra, 1e-3 ≤ k ≤ 1 h/Mpc): default against reference
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

pub mod basis;
pub mod bias;
mod gamma2;
pub(crate) mod lattice;
mod mode_coupling;
mod one_loop;
mod p13;
mod p15;
mod p17;
mod p22;
mod plans;
pub mod redshift;
pub mod rsd_two_loop;
mod tns;
mod two_loop;

pub use gamma2::{Gamma2Basis, Gamma2Plan, Gamma2Terms};
pub use one_loop::OneLoopPlan;
pub use p13::{k1_kernels, p13_kernels};
pub use p15::{p15_angular_kernel, P15Table};
pub use p17::{p17_angular_kernel, P17Table};
pub use p22::f2_g2;
pub use rsd_two_loop::{
    check_ells as check_two_loop_ells, combined, mu2_nodes, node_weights, node_weights_on,
    rsd_two_loop, rsd_two_loop_of, NodeRule, RsdTwoLoopTerms, MAX_TWO_LOOP_ELL,
};
pub use tns::{tns, TnsCoefficients, TnsPlan, TnsTerms};
pub use two_loop::{
    two_loop, two_loop_refined, two_loop_with_progress, TwoLoopPair, TwoLoopSettings, TwoLoopTerms,
    REFINE_LIMIT,
};

use crate::error::{Error, Result};
pub use crate::estimate::Estimate;
use crate::linear::LinearSpectrum;
use crate::output::MethodNote;
use crate::precision::Precision;
use std::ops::{Index, IndexMut};

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

/// One value per [`Pair`] (δδ, δθ, θθ), indexed by the pair: `terms.p22[Pair::DeltaTheta]` or
/// `terms.p22.dt`.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct ByPair<T> {
    /// δδ.
    pub dd: T,
    /// δθ.
    pub dt: T,
    /// θθ.
    pub tt: T,
}

impl<T> ByPair<T> {
    /// The values `f(pair)` of the three pairs.
    pub fn from_fn(mut f: impl FnMut(Pair) -> T) -> Self {
        Self {
            dd: f(Pair::DeltaDelta),
            dt: f(Pair::DeltaTheta),
            tt: f(Pair::ThetaTheta),
        }
    }

    /// δδ, δθ, θθ from an array in that order.
    pub fn from_array([dd, dt, tt]: [T; 3]) -> Self {
        Self { dd, dt, tt }
    }

    /// Each value mapped by `f`.
    pub fn map<U>(self, mut f: impl FnMut(T) -> U) -> ByPair<U> {
        ByPair {
            dd: f(self.dd),
            dt: f(self.dt),
            tt: f(self.tt),
        }
    }

    /// The pairs and their values, in the order δδ, δθ, θθ.
    pub fn iter(&self) -> impl Iterator<Item = (Pair, &T)> {
        [
            (Pair::DeltaDelta, &self.dd),
            (Pair::DeltaTheta, &self.dt),
            (Pair::ThetaTheta, &self.tt),
        ]
        .into_iter()
    }
}

impl<T> ByPair<Vec<T>> {
    /// Per-pair rows `[δδ, δθ, θθ]` (one per k) regrouped into one vector per pair.
    pub fn from_rows(rows: &[[T; 3]]) -> Self
    where
        T: Copy,
    {
        Self::from_fn(|pair| rows.iter().map(|row| row[pair as usize]).collect())
    }
}

impl<T> Index<Pair> for ByPair<T> {
    type Output = T;
    fn index(&self, pair: Pair) -> &T {
        match pair {
            Pair::DeltaDelta => &self.dd,
            Pair::DeltaTheta => &self.dt,
            Pair::ThetaTheta => &self.tt,
        }
    }
}

impl<T> IndexMut<Pair> for ByPair<T> {
    fn index_mut(&mut self, pair: Pair) -> &mut T {
        match pair {
            Pair::DeltaDelta => &mut self.dd,
            Pair::DeltaTheta => &mut self.dt,
            Pair::ThetaTheta => &mut self.tt,
        }
    }
}

/// All 1-loop SPT terms on a k grid [(Mpc/h)^3].
#[derive(Debug, Clone, PartialEq)]
pub struct OneLoopTerms {
    /// Wavenumbers [h/Mpc].
    pub k: Vec<f64>,
    /// The linear spectrum at k [(Mpc/h)^3].
    pub p_lin: Vec<f64>,
    /// σ_v² = (1/6π²)∫P dq over [q_min, q_max] [(Mpc/h)²].
    pub sigma_v2: Estimate,
    /// P22 of each pair at each k.
    pub p22: ByPair<Vec<Estimate>>,
    /// P13 of each pair at each k, in the paper's normalisation (the correction is P22 + 2 P13).
    pub p13: ByPair<Vec<Estimate>>,
}

impl OneLoopTerms {
    /// The 1-loop correction P22 + 2 P13 of `pair` at k index `i`.
    pub fn one_loop(&self, pair: Pair, i: usize) -> Estimate {
        self.p22[pair][i] + 2.0 * self.p13[pair][i]
    }

    /// P33red_XY = P13_X P13_Y / P_lin at k index `i` (first term of eq. P33; P13_X = P13_δδ or P13_θθ).
    pub fn p33_reducible(&self, pair: Pair, i: usize) -> Estimate {
        let (a, b) = match pair {
            Pair::DeltaDelta => (self.p13.dd[i], self.p13.dd[i]),
            Pair::DeltaTheta => (self.p13.dd[i], self.p13.tt[i]),
            Pair::ThetaTheta => (self.p13.tt[i], self.p13.tt[i]),
        };
        a * b / self.p_lin[i]
    }

    /// Appends the terms of `other` (the next k of the grid, for computing a long grid in chunks).
    pub fn append(&mut self, other: Self) {
        self.k.extend(other.k);
        self.p_lin.extend(other.p_lin);
        for pair in Pair::ALL {
            self.p22[pair].extend(&other.p22[pair]);
            self.p13[pair].extend(&other.p13[pair]);
        }
    }
}

/// The 2-loop SPT terms of one pair at each k [(Mpc/h)^3].
#[derive(Debug, Clone, PartialEq, Default)]
pub struct TwoLoopPairTerms {
    /// P24 (the correction contains 2 P24).
    pub p24: Vec<Estimate>,
    /// P33^{2L} = P33irr, the mode-coupling part of P33 (P33 = P33red + P33irr).
    pub p33_2l: Vec<Estimate>,
    /// The whole 2-loop SPT correction 2P15 + 2P24 + P33.
    pub total: Vec<Estimate>,
}

/// The 2-loop terms of δδ, δθ, θθ.
#[derive(Debug, Clone, PartialEq)]
pub struct TwoLoopCorrection {
    /// The terms of each pair.
    pub pairs: ByPair<TwoLoopPairTerms>,
    /// Sobol points per random shift used at each k (after any refinement).
    pub points: Vec<usize>,
}

/// Every loop term a real-space plan computed, on one k grid: the 1-loop terms always, the others if
/// a model the plan covers needs them (a plan of `real --model all` covers every model). A model
/// takes its own terms from it as its family's type, [`crate::real::ModelTerms::of`], the one place
/// that fails with [`Error::MissingTerm`] if one is `None`.
#[derive(Debug, Clone, PartialEq)]
pub struct LoopTerms {
    /// P22, P13 and σ_v².
    pub one_loop: OneLoopTerms,
    /// The 2-loop propagator term P15 ([`p15_terms`]).
    pub p15: Option<ByPair<Vec<Estimate>>>,
    /// The 3-loop propagator term P17 ([`p17_terms`]).
    pub p17: Option<ByPair<Vec<Estimate>>>,
    /// The 2-loop SPT terms ([`two_loop_correction`]).
    pub two_loop: Option<TwoLoopCorrection>,
    /// RegPT's σ_d²(k) = (1/6π²)∫_{q_min}^{k/2} P dq at each k [(Mpc/h)²]
    /// ([`crate::resum::sigma_d2`]).
    pub sigma_d2: Option<Vec<Estimate>>,
    /// The no-wiggle terms of the IR-resummed models ([`crate::ir`]).
    pub ir: Option<Box<IrTerms>>,
    /// RegPT's vertex terms P24 and PΓ2 ([`Gamma2Plan`]).
    pub gamma2: Option<Gamma2Terms>,
    /// How P15 and the 2-loop terms were computed, if they were.
    pub two_loop_source: Option<TwoLoopSource>,
    /// How P22, P13, σ_v² and σ_d² were computed: `None` for the direct integrals.
    pub one_loop_source: Option<OneLoopSource>,
}

/// How the 1-loop terms of a spectrum were computed, when not directly.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum OneLoopSource {
    /// From the 1-loop basis tensors ([`basis::OneLoopBasis`]).
    Basis {
        /// Basis functions.
        functions: usize,
        /// The projection residual ε ([`basis::Projection::residual`]: smoothed).
        residual: f64,
        /// For a spectrum projected cut below the soft modes ([`basis::soft`]): Δ [(Mpc/h)²].
        soft: Option<f64>,
    },
    /// Directly, since the spectrum's projection residual exceeded the basis's limit.
    Fallback {
        /// The projection residual.
        residual: f64,
        /// The largest residual the basis accepts.
        max_residual: f64,
    },
}

impl OneLoopSource {
    /// The method in a word or two, for Python's `meta["methods"]` (the header line has the figures).
    pub fn method(&self) -> &'static str {
        match self {
            Self::Basis { .. } => "basis",
            Self::Fallback { .. } => crate::output::FALLBACK_RESIDUAL,
        }
    }

    /// One line for table headers.
    pub fn describe(&self) -> String {
        match *self {
            Self::Basis {
                functions,
                residual,
                soft,
            } => format!(
                "1-loop terms (P22, P13, sigma_v^2, sigma_d^2): basis tensors on {functions} \
                 functions, the same quadrature nodes as direct; projection residual {residual:.1e}; \
                 errors include the projection error (residual x |P13|, 2 x residual x |P22|){}",
                basis::soft::describe(soft)
            ),
            Self::Fallback {
                residual,
                max_residual,
            } => format!(
                "1-loop terms: direct integration, since the spectrum's projection residual on the \
                 basis, {residual:.1e}, exceeds {max_residual:.1e}"
            ),
        }
    }
}

/// How P15 and the 2-loop terms of a [`LoopTerms`] were computed.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum TwoLoopSource {
    /// Direct integration.
    Direct,
    /// Direct integration under [`TwoLoopMethod::Auto`](crate::precision::TwoLoopMethod::Auto): no basis
    /// tensors were cached for the k grid and precision, and `auto` does not build them.
    DirectUncached,
    /// From the basis tensors ([`basis`]): the spectrum's projection residual ε on `functions` basis
    /// functions; the errors include the projection error ε Σ|T| over the terms of each result.
    Basis {
        /// Basis functions.
        functions: usize,
        /// The projection residual ε ([`basis::Projection::residual`]: smoothed).
        residual: f64,
        /// The largest pointwise relative residual ([`basis::Projection::pointwise`]).
        pointwise: f64,
        /// For a spectrum projected cut below the soft modes ([`basis::soft`]): Δ [(Mpc/h)²].
        soft: Option<f64>,
    },
    /// Direct integration because the spectrum's projection residual exceeded the basis's limit.
    Fallback {
        /// The projection residual.
        residual: f64,
        /// The largest residual the basis accepts.
        max_residual: f64,
    },
}

impl TwoLoopSource {
    /// The method in a word or two, for Python's `meta["methods"]` (the header line has the figures).
    pub fn method(&self) -> &'static str {
        match self {
            Self::Direct => "direct",
            Self::DirectUncached => crate::output::FALLBACK_UNCACHED,
            Self::Basis { .. } => "basis",
            Self::Fallback { .. } => crate::output::FALLBACK_RESIDUAL,
        }
    }

    /// One line for table headers.
    pub fn describe(&self) -> String {
        match *self {
            Self::Direct => "2-loop terms: direct integration".into(),
            Self::DirectUncached => "2-loop terms: direct integration (method auto: no basis tensors \
                 are cached for this k grid and precision; method basis builds them once, minutes on 2 \
                 cores, then takes milliseconds per spectrum)"
                .into(),
            Self::Basis {
                functions,
                residual,
                pointwise,
                soft,
            } => format!(
                "2-loop terms (P15, P24, P33, total): basis tensors on {functions} functions (CAMB \
                 spectra over the EuclidEmulator2 box), the same quasi-Monte-Carlo points as direct; \
                 fixed points (no refinement); projection residual {residual:.1e} (smoothed over {} \
                 in ln q; pointwise {pointwise:.1e}); errors include the projection error residual x \
                 the sum of |P15|, |P24|, |P33| terms of each value{}",
                basis::SMOOTHING,
                basis::soft::describe(soft)
            ),
            Self::Fallback {
                residual,
                max_residual,
            } => format!(
                "2-loop terms: direct integration, since the spectrum's projection residual on the \
                 2-loop basis, {residual:.1e}, exceeds {max_residual:.1e} (the basis holds CAMB tables \
                 to k = 50 h/Mpc over the EuclidEmulator2 box; fits such as Eisenstein-Hu, tables of \
                 other ranges or with massive neutrinos are computed directly)"
            ),
        }
    }
}

/// What the IR-resummed models add to the loop terms of the linear spectrum.
#[derive(Debug, Clone, PartialEq)]
pub struct IrTerms {
    /// The BAO damping Σ² [(Mpc/h)²] ([`crate::ir::sigma2_bao`]).
    pub sigma2: Estimate,
    /// The loop terms of the no-wiggle spectrum (its `p_lin` is P_nw).
    pub no_wiggle: LoopTerms,
}

impl LoopTerms {
    /// How each part of these terms was computed (the header lines' [`OneLoopSource::describe`] and
    /// [`TwoLoopSource::describe`] in a word): the 1-loop terms always, the 2-loop terms and the
    /// no-wiggle spectrum's terms of the IR-resummed models if present and `with_two_loop`/`with_ir`
    /// (whether the table's model uses them).
    pub fn methods(&self, with_two_loop: bool, with_ir: bool) -> Vec<MethodNote> {
        let mut notes = Vec::new();
        let mut push = |prefix: &str, terms: &LoopTerms| {
            if with_two_loop {
                if let Some(s) = terms.two_loop_source {
                    notes.push(MethodNote::new(format!("{prefix}2-loop terms"), s.method()));
                }
            }
            let one = terms.one_loop_source.map_or("direct", |s| s.method());
            notes.push(MethodNote::new(format!("{prefix}1-loop terms"), one));
        };
        push("", self);
        if let (Some(ir), true) = (&self.ir, with_ir) {
            push("no-wiggle ", &ir.no_wiggle);
        }
        notes
    }

    /// The 1-loop terms alone.
    pub fn new(one_loop: OneLoopTerms) -> Self {
        Self {
            one_loop,
            p15: None,
            p17: None,
            two_loop: None,
            sigma_d2: None,
            ir: None,
            gamma2: None,
            two_loop_source: None,
            one_loop_source: None,
        }
    }

    /// Wavenumbers [h/Mpc].
    pub fn k(&self) -> &[f64] {
        &self.one_loop.k
    }

    /// P15, or [`Error::MissingTerm`] naming `needed_by`.
    pub fn p15(&self, needed_by: &dyn std::fmt::Display) -> Result<&ByPair<Vec<Estimate>>> {
        self.p15.as_ref().ok_or_else(|| missing("P15", needed_by))
    }

    /// P17, or [`Error::MissingTerm`] naming `needed_by`.
    pub fn p17(&self, needed_by: &dyn std::fmt::Display) -> Result<&ByPair<Vec<Estimate>>> {
        self.p17.as_ref().ok_or_else(|| missing("P17", needed_by))
    }

    /// RegPT's Γ2 terms, or [`Error::MissingTerm`] naming `needed_by`.
    pub fn gamma2(&self, needed_by: &dyn std::fmt::Display) -> Result<&Gamma2Terms> {
        self.gamma2
            .as_ref()
            .ok_or_else(|| missing("the Gamma2 terms P24, PGamma2", needed_by))
    }

    /// σ_d², or [`Error::MissingTerm`] naming `needed_by`.
    pub fn sigma_d2(&self, needed_by: &dyn std::fmt::Display) -> Result<&[Estimate]> {
        self.sigma_d2
            .as_deref()
            .ok_or_else(|| missing("sigma_d^2", needed_by))
    }

    /// The 2-loop terms, or [`Error::MissingTerm`] naming `needed_by`.
    pub fn two_loop(&self, needed_by: &dyn std::fmt::Display) -> Result<&TwoLoopCorrection> {
        self.two_loop
            .as_ref()
            .ok_or_else(|| missing("the 2-loop terms", needed_by))
    }
}

fn missing(term: &'static str, needed_by: &dyn std::fmt::Display) -> Error {
    Error::MissingTerm {
        term,
        needed_by: needed_by.to_string(),
        hint: " (compute the terms with a RealPlan for that model)",
    }
}

/// P15 of δδ, δθ, θθ at wavenumbers `k` for `spectrum` from the angular `table`, over the q range and
/// lattice step of `precision`.
pub fn p15_terms(
    table: &P15Table,
    k: &[f64],
    spectrum: &LinearSpectrum,
    precision: &Precision,
) -> ByPair<Vec<Estimate>> {
    let rows = table.evaluate(
        k,
        spectrum,
        (precision.q_min, precision.q_max),
        precision.lattice_step,
    );
    ByPair::from_rows(&rows)
}

/// P17 of δδ, δθ, θθ, as [`p15_terms`] from the P17 angular table.
pub fn p17_terms(
    table: &P17Table,
    k: &[f64],
    spectrum: &LinearSpectrum,
    precision: &Precision,
) -> ByPair<Vec<Estimate>> {
    let rows = table.evaluate(
        k,
        spectrum,
        (precision.q_min, precision.q_max),
        precision.lattice_step,
    );
    ByPair::from_rows(&rows)
}

/// The 2-loop terms for `spectrum` (from which `one_loop` and `p15` were computed with `precision`):
/// P24 and P33^{2L} from the quasi-Monte-Carlo integral ([`two_loop`]), and the whole correction
/// 2P15 + 2P24 + P33 as the sum of two infrared-safe parts, each one integral: the propagator part
/// 2P15 − P33red ([`P15Table::propagator_part`]) and the mode-coupling part 2P24 + P33irr + 2P33red
/// (see the `two_loop` module), with points added where the correction's error exceeds
/// [`Precision::two_loop_tolerance`] of it ([`two_loop_refined`]); or at low k, if it has the smaller
/// error, as 2P15 + P33red + (2P24 + P33irr). `points_progress` reports the quasi-Monte-Carlo points
/// done.
pub fn two_loop_correction(
    one_loop: &OneLoopTerms,
    p15: &ByPair<Vec<Estimate>>,
    table: &P15Table,
    spectrum: &LinearSpectrum,
    precision: &Precision,
    points_progress: &(dyn Fn(usize, usize) + Sync),
) -> TwoLoopCorrection {
    let k = &one_loop.k;
    let settings = TwoLoopSettings {
        points: precision.two_loop_points,
        replicas: precision.two_loop_replicas,
        tolerance: precision.two_loop_tolerance,
        seed: precision.two_loop_seed,
        ..TwoLoopSettings::default()
    };
    let q_range = (precision.q_min, precision.q_max);
    let propagator = table.propagator_part(k, spectrum, q_range, precision.lattice_step);
    let mc = two_loop_refined(
        k,
        spectrum,
        q_range,
        precision.lattice_step,
        &settings,
        &propagator,
        points_progress,
    );
    assemble_two_loop(one_loop, p15, &propagator, mc)
}

/// The 2-loop correction from its propagator part 2P15 − P33red and the mode-coupling integrals
/// ([`two_loop_correction`]).
pub(crate) fn assemble_two_loop(
    one_loop: &OneLoopTerms,
    p15: &ByPair<Vec<Estimate>>,
    propagator: &[[Estimate; 3]],
    mc: TwoLoopTerms,
) -> TwoLoopCorrection {
    let k = &one_loop.k;
    let pairs = ByPair::from_fn(|pair| {
        let j = pair as usize;
        let total = (0..k.len())
            .map(|i| {
                let ir_safe = propagator[i][j] + mc.pairs[j].ir_safe[i];
                // At k ≲ 0.03 h/Mpc, where the infrared pieces are small, the plain mode coupling can
                // be the more precise: take whichever estimate has the smaller error.
                let split = 2.0 * p15[pair][i]
                    + one_loop.p33_reducible(pair, i)
                    + mc.pairs[j].mode_coupling[i];
                ir_safe.more_precise(split)
            })
            .collect();
        TwoLoopPairTerms {
            p24: mc.pairs[j].p24.clone(),
            p33_2l: mc.pairs[j].p33_2l.clone(),
            total,
        }
    });
    TwoLoopCorrection {
        pairs,
        points: mc.points,
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
