//! The emulator's prior: the box of parameters it was trained on, and the mapping from a [`Cosmology`]
//! to a point of it.

use crate::cosmology::background::Background;
use crate::cosmology::{Amplitude, Cosmology};
use crate::dual::Real;
use crate::error::{Error, Result};

/// One parameter of the prior: its name (the CLASS/cobaya spelling), its range and its unit.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PriorRange {
    /// `Omega_b`, `Omega_m` (all matter, neutrinos included), `h`, `m_nu` (Σm_ν in eV), `w0`, `wa`,
    /// `ln10^{10}A_s` or `n_s`.
    pub name: &'static str,
    /// Smallest value trained on.
    pub min: f64,
    /// Largest value trained on.
    pub max: f64,
}

/// The names of the eight parameters, in the order of the emulator file.
pub const PARAMETER_NAMES: [&str; 8] = [
    "Omega_b",
    "Omega_m",
    "h",
    "m_nu",
    "w0",
    "wa",
    "ln10^{10}A_s",
    "n_s",
];

/// Number of parameters that shape the transfer functions (the emulator's inputs); A_s and n_s enter
/// through the exact primordial factor A_s (k/k_pivot)^{n_s − 1}.
pub const SHAPE_PARAMETERS: usize = 6;

/// Number of coordinates of the emulator's polynomials: the six shape parameters and the early
/// dark-energy density (see [`PriorPoint::coordinates`]).
pub const COORDINATES: usize = 7;

/// The name of the early dark-energy density in errors and headers: q = ρ_DE/ρ_m at a = 0.1, a
/// function of Ω_m, w0 and wa ([`PriorPoint::coordinates`]).
pub const EARLY_DE_NAME: &str = "rho_DE/rho_m at a = 0.1 (from Omega_m, w0, wa)";

/// Tolerance on the box edges, relative to the width: a value within it of an edge counts as inside
/// (parameter files round to ~7 digits).
const EDGE_TOL: f64 = 1e-9;

/// A cosmology as a point of the prior, over `T`: `f64`, or [`crate::dual::Dual`] for the derivatives
/// of the emulated spectra ([`LinearEmulator::tracer_tangent`](super::LinearEmulator::tracer_tangent)).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PriorPoint<T = f64> {
    /// The eight parameters in the order of [`PARAMETER_NAMES`] (ln(10¹⁰A_s) NaN for a cosmology
    /// normalised by σ8).
    pub values: [T; 8],
    /// ln A_s, or `None` when the cosmology is normalised by σ8 (then set by the emulator).
    pub ln_a_s: Option<T>,
    /// The pivot of A_s and n_s in 1/Mpc.
    pub k_pivot: f64,
}

impl PriorPoint {
    /// Ω_b, Ω_m, h, Σm_ν, w0, wa, A_s (or σ8) and n_s of `cosmology`.
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] naming `Omega_k` for a curved cosmology (the emulator is flat).
    pub fn of(cosmology: &Cosmology) -> Result<Self> {
        Self::of_background(&cosmology.background())
    }
}

impl<T: Real> PriorPoint<T> {
    /// The point of a cosmology's parameters over `T` ([`Cosmology::background`] for values,
    /// [`Cosmology::seeded`] for values with derivatives): Ω_b = ω_b/h², Ω_m, h, Σm_ν, w0, wa,
    /// ln(10¹⁰A_s), n_s.
    ///
    /// # Errors
    /// As [`of`](PriorPoint::of).
    pub fn of_background(b: &Background<T>) -> Result<Self> {
        if b.omega_k.value().abs() > 1e-9 {
            return Err(Error::InvalidParameter {
                name: "Omega_k",
                value: b.omega_k.value(),
                reason:
                    "the linear-spectrum emulator is trained on flat cosmologies; give a linear \
                         spectrum (--linear) or use Eisenstein & Hu (--eh)",
            });
        }
        let ln_10_as = b.ln_a_s.map_or(T::cst(f64::NAN), |l| l + 1e10_f64.ln());
        let values = [
            b.omega_b_h2 / (b.h * b.h),
            b.omega_m,
            b.h,
            b.m_nu,
            b.w0,
            b.wa,
            ln_10_as,
            b.n_s,
        ];
        Ok(Self {
            values,
            ln_a_s: b.ln_a_s,
            k_pivot: b.k_pivot.unwrap_or(Amplitude::DEFAULT_K_PIVOT),
        })
    }

    /// The six shape parameters mapped to [−1, 1] by the prior box.
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] naming the first shape parameter outside the box, with the range in
    /// the message.
    pub fn unit(&self, prior: &[PriorRange]) -> Result<[T; SHAPE_PARAMETERS]> {
        self.unit_in(prior, prior)
    }

    /// [`unit`](Self::unit) with the range check against `stated` (a box inside `prior`, the prior
    /// the emulator states) and the mapping by `prior` (the training box). A value within the edge
    /// tolerance outside the box maps to ±1 (derivative 0, as the clamped value's).
    ///
    /// # Errors
    /// [`Error::OutsidePrior`] naming the first shape parameter outside `stated`.
    pub fn unit_in(
        &self,
        prior: &[PriorRange],
        stated: &[PriorRange],
    ) -> Result<[T; SHAPE_PARAMETERS]> {
        for (range, v) in stated.iter().zip(&self.values).take(SHAPE_PARAMETERS) {
            let v = v.value();
            let t = 2.0 * (v - range.min) / (range.max - range.min) - 1.0;
            if t.is_nan() || t.abs() > 1.0 + 2.0 * EDGE_TOL {
                return Err(outside(range, v));
            }
        }
        let mut u = [T::cst(0.0); SHAPE_PARAMETERS];
        for (i, (range, &v)) in prior
            .iter()
            .zip(&self.values)
            .take(SHAPE_PARAMETERS)
            .enumerate()
        {
            let width = range.max - range.min;
            let t = (v - range.min) * 2.0 / width - 1.0;
            if t.value().is_nan() || t.value().abs() > 1.0 + 2.0 * EDGE_TOL {
                return Err(outside(range, v.value()));
            }
            u[i] = clamp_unit(t);
        }
        Ok(u)
    }

    /// The emulator's seven coordinates: [`unit`](Self::unit), and 2 √(q/q_max) − 1 with
    /// q = ρ_DE/ρ_m at a = `a_early` = (1 − Ω_m)/Ω_m a^{−3(w0+wa)} e^{−3wa(1−a)} (flat), on which the
    /// amplitude of large scales depends steeply as w0 + wa → 0; q_max is its largest value in the box.
    /// The prior is bounded in q too: q ≤ `q_bound` q_max (the corner of the box where w0 + wa is
    /// closest to 0 is beyond the emulator's accuracy).
    ///
    /// # Errors
    /// As [`unit_in`](Self::unit_in) (`stated`: the box the emulator states, inside the training box
    /// `prior`); [`Error::OutsidePrior`] naming [`EARLY_DE_NAME`] and its bound for q
    /// beyond it.
    pub fn coordinates(
        &self,
        prior: &[PriorRange],
        stated: &[PriorRange],
        a_early: f64,
        q_max: f64,
        q_bound: f64,
    ) -> Result<[T; COORDINATES]> {
        let u = self.unit_in(prior, stated)?;
        let [_, om, _, _, w0, wa, ..] = self.values;
        // a^{−3(w0+wa)} = e^{−3(w0+wa) ln a}
        let q = (-om + 1.0) / om
            * ((w0 + wa) * (-3.0 * a_early.ln())).exp()
            * (wa * (-3.0 * (1.0 - a_early))).exp();
        let limit = q_bound * q_max;
        if q.value().is_nan() || q.value() > limit * (1.0 + EDGE_TOL) {
            return Err(Error::OutsidePrior {
                name: EARLY_DE_NAME,
                value: q.value(),
                min: 0.0,
                max: limit,
            });
        }
        let mut out = [T::cst(0.0); COORDINATES];
        out[..SHAPE_PARAMETERS].copy_from_slice(&u);
        out[SHAPE_PARAMETERS] = clamp_unit((q / q_max).sqrt() * 2.0 - 1.0);
        Ok(out)
    }
}

/// `t` clamped to [−1, 1]: `t` inside, the constant edge beyond it.
fn clamp_unit<T: Real>(t: T) -> T {
    let v = t.value();
    if v.abs() > 1.0 {
        T::cst(v.clamp(-1.0, 1.0))
    } else {
        t
    }
}

/// The error of a value outside the prior, naming the parameter and the range.
fn outside(range: &PriorRange, value: f64) -> Error {
    Error::OutsidePrior {
        name: range.name,
        value,
        min: range.min,
        max: range.max,
    }
}
