//! The cached basis tensors of the 2-loop redshift-space terms ([`RsdTwoLoopBasis`]).

use super::{read_cached, TableStore};
use crate::error::Result;
use crate::loops::basis::{LinearBasis, RsdTwoLoopBasis, SpectrumFamily};
use crate::loops::TwoLoopSettings;
use crate::progress::{Progress, Stage};
use std::sync::Arc;

impl TableStore {
    /// The basis tensors of the 2-loop redshift-space terms ([`RsdTwoLoopBasis`]) on `k` for the
    /// integration `settings` over `q_range` (lattice step `lattice_step`), for the spectra of `family`
    /// on `basis()`: read from their file, or built (reporting [`Stage::TwoLoopBasis`]; minutes) and
    /// written. Without a directory they are built each time.
    ///
    /// # Errors
    /// None from the cache (a cache that cannot be used means tensors built in memory, with a note).
    #[allow(clippy::too_many_arguments)]
    pub fn rsd_two_loop_basis(
        &self,
        k: &[f64],
        q_range: (f64, f64),
        lattice_step: f64,
        settings: &TwoLoopSettings,
        family: SpectrumFamily,
        basis: &dyn Fn() -> LinearBasis,
        progress: &dyn Progress,
    ) -> Result<Arc<RsdTwoLoopBasis>> {
        let build = || {
            RsdTwoLoopBasis::build(
                k,
                q_range,
                lattice_step,
                settings,
                family,
                basis(),
                &|d, t| progress.update(Stage::TwoLoopBasis, d, t),
            )
        };
        self.tensors(
            &RsdTwoLoopBasis::file_name(k, q_range, lattice_step, settings, family),
            "2-loop redshift-space basis",
            |v| RsdTwoLoopBasis::from_f64s(v, k, q_range, lattice_step, settings, family),
            build,
            RsdTwoLoopBasis::to_f64s,
            progress,
        )
    }

    /// [`rsd_two_loop_basis`](Self::rsd_two_loop_basis) if its file is in the directory and valid
    /// (never builds them).
    pub fn cached_rsd_two_loop_basis(
        &self,
        k: &[f64],
        q_range: (f64, f64),
        lattice_step: f64,
        settings: &TwoLoopSettings,
        family: SpectrumFamily,
        progress: &dyn Progress,
    ) -> Option<Arc<RsdTwoLoopBasis>> {
        let path = self.path(&RsdTwoLoopBasis::file_name(
            k,
            q_range,
            lattice_step,
            settings,
            family,
        ))?;
        read_cached(
            &path,
            "2-loop redshift-space basis tensors",
            progress,
            |v| RsdTwoLoopBasis::from_f64s(v, k, q_range, lattice_step, settings, family),
        )
    }
}
