//! Typed access to the cached basis tensors: one trait, [`CachedTensors`], that each tensor type
//! implements (its cache file's name and the checked reading of it, both from the settings that made
//! the tensors: their key), and the store's generic methods. [`TableStore::for_method`] is the one
//! place where a [`TwoLoopMethod`] becomes "read or build the tensors", "use them if cached" or "none";
//! every plan asks it rather than deciding for itself.

use super::{cached, read_cached, TableStore};
use crate::error::Result;
use crate::loops::basis::{
    OneLoopBasis, RedshiftBasis, RedshiftFamily, RsdTwoLoopBasis, SpectrumFamily, TnsBasis,
    TwoLoopBasis,
};
use crate::loops::TwoLoopSettings;
use crate::precision::{Precision, TwoLoopMethod};
use crate::progress::{Progress, Stage};
use std::sync::Arc;

/// Cosmology-independent tensors a [`TableStore`] caches: made once from their key (the grid and the
/// settings), written as f64 values after that key, read back only if the key matches.
pub trait CachedTensors: Sized {
    /// The settings the tensors are made from: their file's name and the check of its contents.
    type Key<'a>: Copy;
    /// What the tensors are, in notes (e.g. "2-loop basis").
    const WHAT: &'static str;
    /// The progress stage of a build.
    const STAGE: Stage;
    /// The cache file's name for `key`.
    fn cache_name(key: Self::Key<'_>) -> String;
    /// The tensors from a file's values if they were made with `key` and pass their checks.
    fn read(values: &[f64], key: Self::Key<'_>) -> Option<Self>;
    /// The values of the file (key first).
    fn write(&self) -> Vec<f64>;
}

impl TableStore {
    /// The tensors of `key`: read from their file, or made by `build` (given the progress callback
    /// of [`CachedTensors::STAGE`]: done, total) and written; without a directory, made each time.
    ///
    /// # Errors
    /// None from the cache (a cache that cannot be used means tensors made in memory, with a note).
    pub fn tensors<T: CachedTensors>(
        &self,
        key: T::Key<'_>,
        build: impl FnOnce(&(dyn Fn(usize, usize) + Sync)) -> T,
        progress: &dyn Progress,
    ) -> Result<Arc<T>> {
        let tick = |done, total| progress.update(T::STAGE, done, total);
        let build = || build(&tick);
        Ok(Arc::new(match self.path(&T::cache_name(key)) {
            None => build(),
            Some(path) => cached(
                &path,
                T::WHAT,
                |v| T::read(v, key),
                build,
                T::write,
                progress,
            )?,
        }))
    }

    /// The tensors of `key` if their file is in the directory and valid (never made here; a
    /// corrupted file is reported to `progress` and not used).
    pub fn cached<T: CachedTensors>(
        &self,
        key: T::Key<'_>,
        progress: &dyn Progress,
    ) -> Option<Arc<T>> {
        let path = self.path(&T::cache_name(key))?;
        read_cached(&path, &format!("{} tensors", T::WHAT), progress, |v| {
            T::read(v, key)
        })
    }

    /// The tensors `method` asks for: [`TwoLoopMethod::Basis`] reads or makes them
    /// ([`tensors`](Self::tensors)), [`TwoLoopMethod::Auto`] uses them if cached
    /// ([`cached`](Self::cached): a one-off run never waits for a build), [`TwoLoopMethod::Direct`]
    /// none.
    ///
    /// # Errors
    /// As [`tensors`](Self::tensors).
    pub fn for_method<T: CachedTensors>(
        &self,
        method: TwoLoopMethod,
        key: T::Key<'_>,
        build: impl FnOnce(&(dyn Fn(usize, usize) + Sync)) -> T,
        progress: &dyn Progress,
    ) -> Result<Option<Arc<T>>> {
        match method {
            TwoLoopMethod::Direct => Ok(None),
            TwoLoopMethod::Auto => Ok(self.cached::<T>(key, progress)),
            TwoLoopMethod::Basis => self.tensors::<T>(key, build, progress).map(Some),
        }
    }
}

/// Implements [`CachedTensors`] for a tensor type whose key is the tuple of the arguments its
/// inherent `file_name(…)` and `from_f64s(values, …)` take, in that order (and `to_f64s()`); exported
/// so that a statistic's module implements its own cache (e.g. `bispectrum::seam`) and the store names
/// none of them.
macro_rules! cached_tensors {
    ($tensors:ty, $key:ty, $what:literal, $stage:expr, ($($arg:ident),+)) => {
        impl $crate::store::CachedTensors for $tensors {
            type Key<'a> = $key;
            const WHAT: &'static str = $what;
            const STAGE: $crate::progress::Stage = $stage;
            fn cache_name(($($arg),+): Self::Key<'_>) -> String {
                Self::file_name($($arg),+)
            }
            fn read(values: &[f64], ($($arg),+): Self::Key<'_>) -> Option<Self> {
                Self::from_f64s(values, $($arg),+)
            }
            fn write(&self) -> Vec<f64> {
                self.to_f64s()
            }
        }
    };
}
pub(crate) use cached_tensors;

/// The key of the 1- and 2-loop basis tensors: k, the precision and the spectrum family.
pub type GridKey<'a> = (&'a [f64], &'a Precision, SpectrumFamily);

/// The key of [`RsdTwoLoopBasis`]: k, the q range, the lattice step, the integration settings and
/// the spectrum family.
pub type RsdTwoLoopKey<'a> = (
    &'a [f64],
    (f64, f64),
    f64,
    &'a TwoLoopSettings,
    SpectrumFamily,
);

cached_tensors!(
    TwoLoopBasis,
    GridKey<'a>,
    "2-loop basis",
    Stage::TwoLoopBasis,
    (k, precision, family)
);
cached_tensors!(
    OneLoopBasis,
    GridKey<'a>,
    "1-loop basis",
    Stage::OneLoopBasis,
    (k, precision, family)
);
cached_tensors!(
    TnsBasis,
    (&'a [f64], &'a Precision),
    "TNS basis",
    Stage::TnsBasis,
    (k, precision)
);
cached_tensors!(
    RedshiftBasis,
    (&'a [f64], &'a Precision, RedshiftFamily),
    "redshift-space basis",
    Stage::RedshiftBasis,
    (k, precision, family)
);
cached_tensors!(
    RsdTwoLoopBasis,
    RsdTwoLoopKey<'a>,
    "2-loop redshift-space basis",
    Stage::TwoLoopBasis,
    (k, range, step, settings, family)
);
