//! The σ0 of the Fingers-of-God damping: a value or the theory value, and the memo of the theory
//! values of one spectrum.

use super::{dispersion_theory, DispersionInput};
use crate::error::{Error, Result};
use crate::linear::LinearSpectrum;
use crate::precision::Precision;

/// The σ0 of the Fingers-of-God damping [Mpc/h]: a number, or the theory value σ(z)/D(z) of eq.
/// sigmav (σ² = (1/6π²)∫P_θθ dq) with linear or 1-loop SPT P_θθ ([`dispersion_theory`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Sigma0 {
    /// A value [Mpc/h] (finite, ≥ 0).
    Value(f64),
    /// The theory value with the P_θθ of `DispersionInput`.
    Theory(DispersionInput),
}

impl std::str::FromStr for Sigma0 {
    type Err = Error;

    /// A number [Mpc/h], `lin` or `1l-spt`.
    fn from_str(s: &str) -> Result<Self> {
        match s.trim() {
            "lin" => Ok(Sigma0::Theory(DispersionInput::Linear)),
            "1l-spt" => Ok(Sigma0::Theory(DispersionInput::OneLoopSpt)),
            t => match t.parse::<f64>() {
                Ok(v) => Sigma0::value(v),
                _ => Err(Error::UnknownName {
                    what: "sigma0",
                    name: s.to_string(),
                    available: "a finite non-negative number [Mpc/h], lin, 1l-spt",
                }),
            },
        }
    }
}

impl Sigma0 {
    /// The value `v` [Mpc/h].
    ///
    /// # Errors
    /// [`Error::UnknownName`] unless `v` is finite and ≥ 0 (the message lists what is accepted).
    pub fn value(v: f64) -> Result<Self> {
        if v.is_finite() && v >= 0.0 {
            Ok(Sigma0::Value(v))
        } else {
            Err(Error::UnknownName {
                what: "sigma0",
                name: v.to_string(),
                available: "a finite non-negative number [Mpc/h], lin, 1l-spt",
            })
        }
    }

    /// σ0 [Mpc/h]: the value, or the theory value for the linear `spectrum` at a redshift where the
    /// growth factor is `growth_factor`, integrated with `precision`.
    ///
    /// # Errors
    /// As [`dispersion_theory`].
    pub fn resolve(
        self,
        spectrum: &LinearSpectrum,
        growth_factor: f64,
        precision: &Precision,
    ) -> Result<f64> {
        self.resolve_with(spectrum, growth_factor, precision, &Dispersions::default())
    }

    /// [`Self::resolve`] with the theory values of `spectrum` at `precision` kept in `memo` (computed
    /// at its first use: the 1-loop value needs a 400-node 1-loop plan). `memo` must belong to this
    /// spectrum and precision.
    ///
    /// # Errors
    /// As [`dispersion_theory`].
    pub fn resolve_with(
        self,
        spectrum: &LinearSpectrum,
        growth_factor: f64,
        precision: &Precision,
        memo: &Dispersions,
    ) -> Result<f64> {
        match self {
            Sigma0::Value(v) => Ok(v),
            Sigma0::Theory(input) => {
                let cell = match input {
                    DispersionInput::Linear => &memo.linear,
                    DispersionInput::OneLoopSpt => &memo.one_loop,
                };
                let value = match cell.get() {
                    Some(&v) => v,
                    None => {
                        let v = dispersion_theory(spectrum, input, precision)?.value;
                        *cell.get_or_init(|| v)
                    }
                };
                Ok(value / growth_factor)
            }
        }
    }
}

/// The theory velocity dispersions σ_v [Mpc/h] of one linear spectrum at one precision, each computed
/// at its first use ([`Sigma0::resolve_with`]): what a chain's fast steps with `sigma0 = lin` or `1l-spt`
/// reuse instead of integrating again.
#[derive(Debug, Default)]
pub struct Dispersions {
    linear: std::sync::OnceLock<f64>,
    one_loop: std::sync::OnceLock<f64>,
}

impl Dispersions {
    /// The values computed so far: (linear, 1-loop SPT), σ_v at the spectrum's redshift [Mpc/h].
    pub fn computed(&self) -> (Option<f64>, Option<f64>) {
        (self.linear.get().copied(), self.one_loop.get().copied())
    }
}
