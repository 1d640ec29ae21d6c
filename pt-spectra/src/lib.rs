//! Eulerian perturbation-theory power spectra of matter and haloes in real and redshift space, after
//! Gil-Marín, Wagner, Verde, Porciani & Jimenez (2012, arXiv:1209.3771).
//!
//! Conventions: k in h/Mpc, P(k) in (Mpc/h)^3, lengths in Mpc/h, ∫d³q/(2π)³.
//!
//! Modules:
//! * [`error`]: the crate's [`Error`](error::Error) and [`Result`](error::Result).
//! * [`linear`]: the linear spectrum [`LinearSpectrum`](linear::LinearSpectrum): CAMB/CLASS tables, the
//!   embedded gm2012 CAMB spectra, log-log spline interpolation, power-law extrapolation, σ(R), σ_v².
//! * [`cosmology`]: [`Cosmology`](cosmology::Cosmology), flat or curved with w0–wa dark energy, normalised by
//!   σ8 or A_s: linear growth D(z), f(z) (exact for Λ, an ODE otherwise), the Eisenstein & Hu (1998)
//!   transfer functions with and without BAO wiggles, presets and CLASS/CAMB parameter files.
//! * [`emulator`]: the linear spectra P_m(k, z) and P_cb(k, z) and the growth rate f_cb(k, z) of a flat
//!   w0–wa cosmology with massive neutrinos from its parameters, without a Boltzmann code (trained on CAMB).
//! * [`loops`], [`resum`], [`real`]: 1- and 2-loop SPT terms, the propagator terms P13, P15, P17 (angular
//!   tables), and TNS terms, all with error estimates; RPT propagators N0..N3; real-space models.
//! * [`rsd`]: Kaiser, Scoccimarro and TNS redshift-space models, Fingers of God, Legendre multipoles.
//! * [`bias`]: the galaxy bias parameters in one convention (velocileptors') and the exact maps to
//!   FAST-PT's and CLASS-PT's.
//! * [`bispectrum`]: the tree-level galaxy bispectrum in redshift space, B₀, B₂, B₄ over the orientations
//!   of a triangle and the triangle bins of a measurement, with AP, IR resummation, FoG and shot noise.
//! * [`statistic`]: the seam of a block of the data vector after the power spectrum (its parameters,
//!   terms, values, Gaussian covariance), which the pipeline, fits and forecasts hold; [`blocks`] lists
//!   the statistics that implement it.
//! * [`fit`]: χ² fits of f, σ0 and A_b to measured multipoles, with Δχ² contour errors, versus k_max.
//! * [`halo`]: scale-dependent bias, stochasticity (shot noise) and signal-to-noise of haloes.
//! * [`hankel`]: FFTLog Hankel transforms between power-spectrum multipoles P_ℓ(k) and correlation-function
//!   multipoles ξ_ℓ(s), ℓ ≤ 8.
//! * [`table`]: plain-text tables and tabulated functions of k.
//! * [`memory`]: memory estimates of plans, checked against a limit before they allocate.
//!
//! ```
//! use pt_spectra::{cosmology::Cosmology, linear::LinearSpectrum};
//! let cosmo = Cosmology::gm2012();
//! let p0 = LinearSpectrum::gm2012(0.0)?;
//! let p1 = cosmo.rescale(&p0, 0.0, 1.0)?; // P ∝ D²
//! assert!((p1.sigma8() / p0.sigma8() - cosmo.growth_factor(1.0)).abs() < 1e-9);
//! # Ok::<(), pt_spectra::error::Error>(())
//! ```

pub mod bias;
pub mod bispectrum;
pub mod blocks;
pub mod cosmology;
pub mod dual;
pub mod emulator;
pub mod error;
pub mod estimate;
pub mod fit;
pub mod forecast;
pub mod halo;
pub mod hankel;
pub mod integrate;
pub mod ir;
pub mod jobs;
pub(crate) mod linalg;
pub mod linear;
pub mod loops;
pub mod memory;
pub mod output;
pub mod pipeline;
pub mod plan;
pub mod precision;
pub mod progress;
pub mod real;
pub mod resum;
pub mod rsd;
mod savgol;
pub mod setup;
mod simd;
pub mod statistic;
pub mod store;
pub mod survey;
pub mod table;
mod vec3;

/// The README's library example, compiled and run as a doctest.
#[doc = include_str!("../../README.md")]
#[cfg(doctest)]
pub struct ReadmeDoctests;

/// The reference's examples, compiled and run as doctests.
#[doc = include_str!("../../docs/reference.md")]
#[cfg(doctest)]
pub struct ReferenceDoctests;
