//! The emulator's prior: the box of parameters it was trained on, and the mapping from a [`Cosmology`]
//! to a point of it.

use crate::cosmology::{Amplitude, Cosmology};
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

/// A cosmology as a point of the prior.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PriorPoint {
    /// The eight parameters in the order of [`PARAMETER_NAMES`].
    pub values: [f64; 8],
    /// A_s, or `None` when the cosmology is normalised by σ8 (then set by the emulator).
    pub a_s: Option<f64>,
    /// The pivot of A_s and n_s in 1/Mpc.
    pub k_pivot: f64,
}

impl PriorPoint {
    /// Ω_b, Ω_m, h, Σm_ν, w0, wa, A_s (or σ8) and n_s of `cosmology`.
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] naming `Omega_k` for a curved cosmology (the emulator is flat).
    pub fn of(cosmology: &Cosmology) -> Result<Self> {
        let c = cosmology;
        if c.omega_k().abs() > 1e-9 {
            return Err(Error::InvalidParameter {
                name: "Omega_k",
                value: c.omega_k(),
                reason:
                    "the linear-spectrum emulator is trained on flat cosmologies; give a linear \
                         spectrum (--linear) or use Eisenstein & Hu (--eh)",
            });
        }
        let (a_s, k_pivot) = match c.amplitude {
            Amplitude::As { a_s, k_pivot } => (Some(a_s), k_pivot),
            Amplitude::Sigma8(_) => (None, Amplitude::DEFAULT_K_PIVOT),
        };
        let ln_as = a_s.map_or(f64::NAN, |a| (1e10 * a).ln());
        let values = [
            c.omega_b_h2 / (c.h * c.h),
            c.omega_m,
            c.h,
            c.m_nu,
            c.w0,
            c.wa,
            ln_as,
            c.n_s,
        ];
        Ok(Self {
            values,
            a_s,
            k_pivot,
        })
    }

    /// The six shape parameters mapped to [−1, 1] by the prior box.
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] naming the first shape parameter outside the box, with the range in
    /// the message.
    pub fn unit(&self, prior: &[PriorRange]) -> Result<[f64; SHAPE_PARAMETERS]> {
        self.unit_in(prior, prior)
    }

    /// [`unit`](Self::unit) with the range check against `stated` (a box inside `prior`, the prior
    /// the emulator states) and the mapping by `prior` (the training box).
    ///
    /// # Errors
    /// [`Error::OutsidePrior`] naming the first shape parameter outside `stated`.
    pub fn unit_in(
        &self,
        prior: &[PriorRange],
        stated: &[PriorRange],
    ) -> Result<[f64; SHAPE_PARAMETERS]> {
        for (range, &v) in stated.iter().zip(&self.values).take(SHAPE_PARAMETERS) {
            let t = 2.0 * (v - range.min) / (range.max - range.min) - 1.0;
            if t.is_nan() || t.abs() > 1.0 + 2.0 * EDGE_TOL {
                return Err(outside(range, v));
            }
        }
        let mut u = [0.0; SHAPE_PARAMETERS];
        for (i, (range, &v)) in prior
            .iter()
            .zip(&self.values)
            .take(SHAPE_PARAMETERS)
            .enumerate()
        {
            let width = range.max - range.min;
            let t = 2.0 * (v - range.min) / width - 1.0;
            if t.is_nan() || t.abs() > 1.0 + 2.0 * EDGE_TOL {
                return Err(outside(range, v));
            }
            u[i] = t.clamp(-1.0, 1.0);
        }
        Ok(u)
    }
}

impl PriorPoint {
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
    ) -> Result<[f64; COORDINATES]> {
        let u = self.unit_in(prior, stated)?;
        let [_, om, _, _, w0, wa, ..] = self.values;
        let q =
            (1.0 - om) / om * a_early.powf(-3.0 * (w0 + wa)) * (-3.0 * wa * (1.0 - a_early)).exp();
        let limit = q_bound * q_max;
        if q.is_nan() || q > limit * (1.0 + EDGE_TOL) {
            return Err(Error::OutsidePrior {
                name: EARLY_DE_NAME,
                value: q,
                min: 0.0,
                max: limit,
            });
        }
        let mut out = [0.0; COORDINATES];
        out[..SHAPE_PARAMETERS].copy_from_slice(&u);
        out[SHAPE_PARAMETERS] = (2.0 * (q / q_max).sqrt() - 1.0).clamp(-1.0, 1.0);
        Ok(out)
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
