//! [`TableStore`]: the cosmology-independent angular tables (P15, P17) and the plans' basis tensors
//! (any [`CachedTensors`] type, through [`TableStore::for_method`]), built once and cached in a
//! directory the caller chooses.
//!
//! A table file is a header (the magic `PTSTAB01`, the number of values, and the 64-bit FNV-1a hash of
//! the payload's bytes) followed by the values as little-endian f64. A table is read from its file if
//! the file is there, its hash matches and the values pass the table's own checks (size, finite
//! values, a few entries recomputed); otherwise it is built and written atomically (a temporary file
//! renamed into place), so a reader never sees half a table, and a corrupted, truncated or stale file
//! is rebuilt, with a note through [`Progress::note`] that says why. A table that cannot be written
//! (full disk, read-only directory, a file where the directory should be, a lock file that cannot be
//! opened) is built and used from memory, with a note naming the path and the reason, and any
//! temporary file is removed: a cache never stops a run. A cache file that is not a regular file (a
//! FIFO, a device) is never read (it is rebuilt, with a note), so it cannot hang a run. While a
//! process builds a table it holds an operating-system lock on `<table>.lock` beside it
//! ([`std::fs::File::lock`]): another process that needs the same table waits for it (and says so
//! through [`Progress::note`]) instead of building it twice, and a process that dies while building
//! releases the lock with its death, so an interrupted build never blocks later runs.
//!
//! ```no_run
//! use pt_spectra::{progress::Silent, store::TableStore};
//! let store = TableStore::new("/tmp/pt-spectra-cache");
//! let p15 = store.p15(&Silent)?; // built on first use (~35 s on 2 cores), then read from the file
//! # Ok::<(), pt_spectra::error::Error>(())
//! ```

use crate::error::Result;
use crate::loops::{P15Table, P17Table};
use crate::progress::{Progress, Stage};
use std::path::{Path, PathBuf};
use std::sync::{Arc, Mutex};

/// Where the angular tables live, and the tables this store has already loaded.
#[derive(Debug, Default)]
pub struct TableStore {
    dir: Option<PathBuf>,
    p15: Mutex<Option<Arc<P15Table>>>,
    p17: Mutex<Option<Arc<P17Table>>>,
}

impl TableStore {
    /// A store caching its tables in `dir` (created when first needed).
    pub fn new(dir: impl Into<PathBuf>) -> Self {
        Self {
            dir: Some(dir.into()),
            ..Self::default()
        }
    }

    /// A store without a directory: tables are built in memory by each store that needs them.
    pub fn in_memory() -> Self {
        Self::default()
    }

    /// The conventional cache directory: `$PT_SPECTRA_CACHE`, else `$XDG_CACHE_HOME/pt-spectra`, else
    /// `$HOME/.cache/pt-spectra`; in memory if none of them is set.
    pub fn from_env() -> Self {
        let dir = std::env::var_os("PT_SPECTRA_CACHE")
            .map(PathBuf::from)
            .or_else(|| {
                std::env::var_os("XDG_CACHE_HOME").map(|d| PathBuf::from(d).join("pt-spectra"))
            })
            .or_else(|| {
                std::env::var_os("HOME").map(|d| PathBuf::from(d).join(".cache/pt-spectra"))
            });
        Self {
            dir,
            ..Self::default()
        }
    }

    /// The cache directory, if any.
    pub fn dir(&self) -> Option<&Path> {
        self.dir.as_deref()
    }

    /// The file a table of this store lives in (`file_name` as the table names it).
    fn path(&self, file_name: &str) -> Option<PathBuf> {
        self.dir.as_ref().map(|d| d.join(file_name))
    }

    /// The P15 angular table ([`P15Table`]): loaded by this store already, read from its file, or built
    /// (reporting [`Stage::P15Table`]) and written.
    ///
    /// # Errors
    /// None from the cache (a cache that cannot be used means a table built in memory, with a note).
    pub fn p15(&self, progress: &dyn Progress) -> Result<Arc<P15Table>> {
        load(
            &self.p15,
            self.path(&P15Table::file_name()),
            "P15",
            P15Table::from_f64s,
            || P15Table::build(&|d, t| progress.update(Stage::P15Table, d, t)),
            P15Table::to_f64s,
            progress,
        )
    }

    /// The P17 angular table ([`P17Table`]), as [`p15`](Self::p15).
    ///
    /// # Errors
    /// As [`p15`](Self::p15).
    pub fn p17(&self, progress: &dyn Progress) -> Result<Arc<P17Table>> {
        load(
            &self.p17,
            self.path(&P17Table::file_name()),
            "P17",
            P17Table::from_f64s,
            || P17Table::build(&|d, t| progress.update(Stage::P17Table, d, t)),
            P17Table::to_f64s,
            progress,
        )
    }
}

/// Tensors from the file at `path` if it is there and passes `read`'s checks; a corrupted file is
/// reported to `progress` (as `what`) and not used.
fn read_cached<T>(
    path: &Path,
    what: &str,
    progress: &dyn Progress,
    read: impl Fn(&[f64]) -> Option<T>,
) -> Option<Arc<T>> {
    let tensors = match read_f64s(path) {
        Stored::Missing => None,
        Stored::Invalid(why) => {
            progress.note(&format!(
                "the cached {what} `{}` {why}: not used (method basis rebuilds them)",
                path.display()
            ));
            return None;
        }
        Stored::Values(v) => read(&v),
    };
    if tensors.is_none() && path.exists() {
        progress.note(&format!(
            "the cached {what} `{}` fail their consistency checks: not used \
             (method basis rebuilds them)",
            path.display()
        ));
    }
    tensors.map(Arc::new)
}

/// The table in `slot`, else from [`cached`], kept in `slot`.
fn load<T>(
    slot: &Mutex<Option<Arc<T>>>,
    path: Option<PathBuf>,
    name: &str,
    read: impl Fn(&[f64]) -> Option<T>,
    build: impl FnOnce() -> T,
    write: impl Fn(&T) -> Vec<f64>,
    progress: &dyn Progress,
) -> Result<Arc<T>> {
    // Holding the slot while loading makes threads of one process share one build.
    let mut slot = slot
        .lock()
        .unwrap_or_else(std::sync::PoisonError::into_inner);
    if let Some(t) = slot.as_ref() {
        return Ok(Arc::clone(t));
    }
    let t = Arc::new(match path {
        None => build(),
        Some(path) => cached(&path, name, read, build, write, progress)?,
    });
    *slot = Some(Arc::clone(&t));
    Ok(t)
}

mod file;
mod tensors;

pub(crate) use file::cached;
#[cfg(test)]
use file::{fnv1a, HEADER};
use file::{read_f64s, Stored};
pub(crate) use tensors::cached_tensors;
pub use tensors::{CachedTensors, GridKey, RsdTwoLoopKey};
#[cfg(test)]
mod tests;
