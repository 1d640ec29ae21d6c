//! The cached basis tensors of the one-loop matter bispectrum ([`OneLoopMatterBasis`]).

use super::{read_cached, TableStore};
use crate::bispectrum::one_loop::OneLoopRule;
use crate::bispectrum::one_loop_basis::OneLoopMatterBasis;
use crate::error::Result;
use crate::progress::{Progress, Stage};
use std::sync::Arc;

impl TableStore {
    /// The basis tensors of the one-loop matter bispectrum of `triangles` (sides [h/Mpc]) for
    /// `rule`: read from their file, or built (reporting [`Stage::OneLoopBispectrumBasis`]; about
    /// 0.3 s per triangle and core) and written. Without a directory they are built each time.
    ///
    /// # Errors
    /// Sides that do not close, a bad rule; none from the cache (a cache that cannot be used means
    /// tensors built in memory, with a note).
    pub fn one_loop_bispectrum_basis(
        &self,
        triangles: &[[f64; 3]],
        rule: &OneLoopRule,
        progress: &dyn Progress,
    ) -> Result<Arc<OneLoopMatterBasis>> {
        // Checked before the cache is looked at, so that a bad set is an error, not a build failure.
        crate::bispectrum::one_loop_basis::OneLoopMatterPlan::new(triangles.to_vec(), *rule)?;
        let build = || {
            OneLoopMatterBasis::build(triangles, rule, &|d, t| {
                progress.update(Stage::OneLoopBispectrumBasis, d, t)
            })
            .expect("triangles and rule checked above")
        };
        self.tensors(
            &OneLoopMatterBasis::file_name(triangles, rule),
            "one-loop bispectrum basis",
            |v| OneLoopMatterBasis::from_f64s(v, triangles, rule),
            build,
            OneLoopMatterBasis::to_f64s,
            progress,
        )
    }

    /// [`one_loop_bispectrum_basis`](Self::one_loop_bispectrum_basis) if its file is in the
    /// directory and valid (never builds them).
    pub fn cached_one_loop_bispectrum_basis(
        &self,
        triangles: &[[f64; 3]],
        rule: &OneLoopRule,
        progress: &dyn Progress,
    ) -> Option<Arc<OneLoopMatterBasis>> {
        let path = self.path(&OneLoopMatterBasis::file_name(triangles, rule))?;
        read_cached(&path, "one-loop bispectrum basis tensors", progress, |v| {
            OneLoopMatterBasis::from_f64s(v, triangles, rule)
        })
    }
}
