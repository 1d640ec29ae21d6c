//! The training spectra of the basis: CAMB linear spectra over the EuclidEmulator2 prior, shipped
//! with the crate (`pt-spectra/data/two_loop_training_camb.f32`, made by
//! `examples/make_two_loop_training.py`).
//!
//! [`TRAINING_SPECTRA`] CAMB tables at z = 0 (1200 log-spaced k in [1e-4, 50] h/Mpc, the settings of
//! the test tables: massless neutrinos, N_eff = 3.046) for cosmologies drawn uniformly from the box
//! Ω_m ∈ [0.24, 0.40], Ω_b ∈ [0.04, 0.06], n_s ∈ [0.92, 1.00], h ∈ [0.61, 0.73],
//! w0 ∈ [−1.3, −0.7] (PPF dark energy). A_s and the redshift only rescale P (the growth is scale
//! independent for massless neutrinos) and a basis spans every amplitude, so they need no training
//! points. Each table becomes a [`LinearSpectrum`] exactly as a user's table does (spline in ln k,
//! power laws beyond its ends), so the basis represents tables made this way, extrapolation included.
//!
//! Eisenstein–Hu spectra are not in the span (their shape differs from CAMB's by percents; an
//! Eisenstein–Hu basis leaves 1–3e-2 on CAMB tables): they, and tables of other codes, ranges or
//! physics (massive neutrinos), are computed directly when their projection residual is too large.

use super::LinearBasis;
use crate::linear::LinearSpectrum;
use crate::loops::lattice::Lattice;

/// Version of the training set, part of the cache key of the tensors.
pub const VERSION: u32 = 2;

/// Number of training spectra.
pub const TRAINING_SPECTRA: usize = 100;

/// k values per training table.
const TABLE_LEN: usize = 1200;

/// The training tables: k, then P of each spectrum (little-endian f32).
const DATA: &[u8] = include_bytes!("../../../data/two_loop_training_camb.f32");

/// The training spectra (k [h/Mpc], P [(Mpc/h)^3]) as tables.
pub fn camb_training() -> Vec<LinearSpectrum> {
    let values: Vec<f64> = DATA
        .chunks_exact(4)
        .map(|b| f64::from(f32::from_le_bytes([b[0], b[1], b[2], b[3]])))
        .collect();
    assert_eq!(
        values.len(),
        TABLE_LEN * (TRAINING_SPECTRA + 1),
        "the shipped training tables have their documented size"
    );
    let k = values[..TABLE_LEN].to_vec();
    values[TABLE_LEN..]
        .chunks_exact(TABLE_LEN)
        .map(|p| {
            LinearSpectrum::from_nodes(k.clone(), p.to_vec())
                .expect("the shipped training tables are valid")
        })
        .collect()
}

/// The greedy basis of `n` functions from [`camb_training`] on `lattice`.
pub(crate) fn camb_basis(lattice: Lattice, n: usize) -> LinearBasis {
    let training: Vec<Vec<f64>> = camb_training().iter().map(|p| lattice.sample(p)).collect();
    LinearBasis::greedy(lattice, &training, n)
}
