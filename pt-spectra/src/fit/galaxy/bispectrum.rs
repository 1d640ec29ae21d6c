//! The bispectrum beside a data set's power spectrum in a galaxy fit (issue 49, item 5): the measured
//! tree-level bispectrum multipoles of a triangle set, fitted as the block of
//! [`crate::bispectrum::block`] ([`super::block`]), b1, b2, bs shared with the power spectrum, its own
//! counterterm c1 and stochastic amplitudes ([`BISPECTRUM_NAMES`]; b_shot, p_shot, a_shot enter
//! linearly and can be marginalised, [`BISPECTRUM_LINEAR`]).

pub use crate::bispectrum::block::{BISPECTRUM_LINEAR, BISPECTRUM_NAMES};

/// A data set's bispectrum: [`super::block::BlockFit`] of a
/// [`crate::bispectrum::block::BispectrumBlock`].
pub type BispectrumFit = super::block::BlockFit;

#[cfg(test)]
pub(super) use super::block::BlockModel as BispectrumModel;
