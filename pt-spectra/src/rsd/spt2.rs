//! `spt2`: the matter multipoles of 2-loop standard perturbation theory in redshift space,
//!
//! ```text
//! P_s(k, μ) = (1 + fμ²)² P_lin + P^(1)_s(k, μ; f) + P^(2)_s(k, μ; f),
//! ```
//!
//! P^(1)_s the 1-loop terms P22 + 2P13 with the kernels Z₂, Z₃ ([`crate::loops::redshift`] at b1 = 1 and
//! no other bias: exact in μ, deterministic quadrature), P^(2)_s the 2-loop terms 2P15 + 2P24 + P33
//! with Z₄, Z₅ ([`mod@crate::loops::rsd_two_loop`]: quasi-Monte Carlo, a polynomial of degree 6 in f and
//! in μ²). Every term is a polynomial in f, so a new f costs no integral. No Fingers-of-God damping, no
//! IR resummation, no counterterms: plain SPT, whose reach in redshift space is short (the issue's
//! figures: 1-loop to k ≈ 0.1, 2-loop to ≈ 0.18 h/Mpc at z ≈ 1 with counterterms).
//!
//! Errors: the 1-loop coefficients' error bounds times (2ℓ+1) (as [`super::MultipoleRule`]), plus the
//! standard error over the random shifts of the 2-loop multipole at this f.

use crate::error::{Error, Result};
use crate::linear::LinearSpectrum;
use crate::loops::redshift::{RedshiftPlan, RedshiftTerms};
use crate::loops::{check_two_loop_ells, rsd_two_loop, Estimate, RsdTwoLoopTerms, TwoLoopSettings};
use crate::precision::Precision;
use crate::progress::{stage_callback, Progress, Stage};

/// The redshift-space 2-loop Sobol points per shift are the real-space ones
/// ([`Precision::two_loop_points`]) over this factor: each point costs ~16 μs of kernels (seven lines
/// of sight, nine configurations) against ~1 μs in real space.
pub const POINTS_DIVISOR: usize = 4;

/// The 2-loop integration settings of `precision` in redshift space: the real-space ones with
/// [`POINTS_DIVISOR`] times fewer points.
pub fn two_loop_settings(precision: &Precision) -> TwoLoopSettings {
    TwoLoopSettings {
        points: (precision.two_loop_points / POINTS_DIVISOR).max(1),
        replicas: precision.two_loop_replicas,
        seed: precision.two_loop_seed,
        ..TwoLoopSettings::default()
    }
}

/// The plan of `spt2` on a k grid: the 1-loop weights (cosmology independent) and the settings of the
/// 2-loop integration.
#[derive(Debug, Clone)]
pub struct Spt2Plan {
    one_loop: RedshiftPlan,
    precision: Precision,
}

/// The three parts of the model for one linear spectrum.
#[derive(Debug, Clone, PartialEq)]
pub struct Spt2Terms {
    /// Wavenumbers [h/Mpc].
    pub k: Vec<f64>,
    /// P_lin(k) [(Mpc/h)³].
    pub p_lin: Vec<f64>,
    /// The 1-loop terms.
    pub one_loop: RedshiftTerms,
    /// The 2-loop terms.
    pub two_loop: RsdTwoLoopTerms,
}

/// The multipoles of one part or of the whole, per ℓ then per k.
pub type Multipoles = Vec<Vec<Estimate>>;

/// The multipoles of [`Spt2Terms::multipoles`] by part.
#[derive(Debug, Clone, PartialEq)]
pub struct Spt2Multipoles {
    /// Linear Kaiser, (1 + fμ²)² P_lin (exact).
    pub linear: Multipoles,
    /// The 1-loop correction.
    pub one_loop: Multipoles,
    /// The 2-loop correction.
    pub two_loop: Multipoles,
    /// Their sum, errors added.
    pub total: Multipoles,
}

impl Spt2Plan {
    /// The plan for wavenumbers `k` [h/Mpc] with `precision`.
    ///
    /// # Errors
    /// As [`RedshiftPlan::new`].
    pub fn new(k: &[f64], precision: &Precision) -> Result<Self> {
        Ok(Self {
            one_loop: RedshiftPlan::new(k, precision)?,
            precision: precision.clone(),
        })
    }

    /// The wavenumbers [h/Mpc].
    pub fn k(&self) -> &[f64] {
        self.one_loop.k()
    }

    /// The 2-loop integration settings ([`two_loop_settings`]).
    pub fn two_loop_settings(&self) -> TwoLoopSettings {
        two_loop_settings(&self.precision)
    }

    /// The terms of `spectrum`; the 2-loop points are reported to `progress`
    /// ([`Stage::TwoLoopPoints`]).
    ///
    /// # Errors
    /// As [`rsd_two_loop()`].
    pub fn terms(&self, spectrum: &LinearSpectrum, progress: &dyn Progress) -> Result<Spt2Terms> {
        let p = &self.precision;
        let k = self.k();
        let callback = stage_callback(progress, Stage::TwoLoopPoints);
        let two_loop = rsd_two_loop(
            k,
            spectrum,
            (p.q_min, p.q_max),
            p.lattice_step,
            &self.two_loop_settings(),
            &callback,
        )?;
        Ok(Spt2Terms {
            k: k.to_vec(),
            p_lin: k.iter().map(|&k| spectrum.eval(k)).collect(),
            one_loop: self.one_loop.evaluate(spectrum),
            two_loop,
        })
    }
}

impl Spt2Terms {
    /// The multipoles ℓ ∈ `ells` (even, ≤ [`super::MAX_ELL`]) at growth rate `f`, by part.
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] for a bad ℓ or a non-finite f.
    pub fn multipoles(&self, f: f64, ells: &[usize]) -> Result<Spt2Multipoles> {
        check_two_loop_ells(ells)?;
        if let Some(&bad) = ells.iter().find(|&&l| l > super::MAX_ELL) {
            return Err(Error::InvalidParameter {
                name: "multipole ell",
                value: bad as f64,
                reason: "must be even and at most 8",
            });
        }
        if !f.is_finite() {
            return Err(Error::InvalidParameter {
                name: "growth rate f",
                value: f,
                reason: "must be finite",
            });
        }
        let moment = |ell: usize, n: usize| super::polynomial_moment(ell, n);
        let per_ell = |g: &dyn Fn(usize, usize) -> Estimate| -> Multipoles {
            ells.iter()
                .map(|&ell| (0..self.k.len()).map(|i| g(ell, i)).collect())
                .collect()
        };
        let linear = per_ell(&|ell, i| {
            let c = [1.0, 2.0 * f, f * f];
            let v = c
                .iter()
                .enumerate()
                .map(|(n, c)| c * moment(ell, n))
                .sum::<f64>();
            Estimate::new(v * self.p_lin[i], 0.0)
        });
        let params = [1.0, 0.0, 0.0, 0.0, f];
        let coefficients = self.one_loop.coefficients(params);
        let one_loop = per_ell(&|ell, i| {
            let (v, e) = self.one_loop.loop_polynomial_with(i, &coefficients);
            let value = v.iter().enumerate().map(|(n, c)| c * moment(ell, n)).sum();
            Estimate::new(value, (2 * ell + 1) as f64 * e.iter().sum::<f64>())
        });
        let two: Vec<Vec<Estimate>> = (0..self.k.len())
            .map(|i| self.two_loop.multipoles(i, f, ells))
            .collect();
        let two_loop: Multipoles = (0..ells.len())
            .map(|l| two.iter().map(|row| row[l]).collect())
            .collect();
        let total = (0..ells.len())
            .map(|l| {
                (0..self.k.len())
                    .map(|i| linear[l][i] + one_loop[l][i] + two_loop[l][i])
                    .collect()
            })
            .collect();
        Ok(Spt2Multipoles {
            linear,
            one_loop,
            two_loop,
            total,
        })
    }
}
