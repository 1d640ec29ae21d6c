//! Progress reports of long computations, through a trait the caller implements (a progress bar in the
//! command line, a callback in Python); the library itself never prints.
//!
//! ```
//! use pt_spectra::progress::{Progress, Stage};
//! use std::sync::atomic::{AtomicUsize, Ordering};
//! struct Count(AtomicUsize);
//! impl Progress for Count {
//!     fn update(&self, _stage: Stage, _done: usize, _total: usize) {
//!         self.0.fetch_add(1, Ordering::Relaxed);
//!     }
//! }
//! let c = Count(AtomicUsize::new(0));
//! c.update(Stage::TwoLoopPoints, 1, 2);
//! assert_eq!(c.0.load(Ordering::Relaxed), 1);
//! ```

use std::fmt;

/// A stage of a computation that can take seconds or more.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[non_exhaustive]
pub enum Stage {
    /// The 1-loop terms (reported per k on long grids).
    OneLoop,
    /// Building the P15 angular table (once; cached in the [`TableStore`](crate::store::TableStore)).
    P15Table,
    /// Building the P17 angular table (once; cached).
    P17Table,
    /// The quasi-Monte-Carlo points of the 2-loop mode coupling.
    TwoLoopPoints,
    /// The cosmology-independent weights of RegPT's vertex Γ2 (once per plan).
    Gamma2Weights,
    /// The 2-loop basis tensors of a k grid (once; cached).
    TwoLoopBasis,
    /// The 1-loop basis tensors of a k grid (once; cached).
    OneLoopBasis,
    /// The TNS A and B basis tensors of a k grid (once; cached).
    TnsBasis,
    /// The basis tensors of the galaxy model's loop terms on a k grid (once; cached).
    RedshiftBasis,
    /// A stage a module names itself (e.g. `bispectrum::seam::ONE_LOOP_STAGE`): what it shows.
    Named(&'static str),
}

impl fmt::Display for Stage {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            Stage::OneLoop => "1-loop terms",
            Stage::P15Table => "P15 angular table (once; cached)",
            Stage::P17Table => "P17 angular table (once, a few minutes; cached)",
            Stage::TwoLoopPoints => "2-loop mode coupling",
            Stage::Gamma2Weights => "RegPT vertex weights (once per k grid)",
            Stage::TwoLoopBasis => "2-loop basis tensors (once per k grid, minutes; cached)",
            Stage::OneLoopBasis => "1-loop basis tensors (once per k grid; cached)",
            Stage::TnsBasis => "TNS basis tensors (once per k grid; cached)",
            Stage::RedshiftBasis => "galaxy-model basis tensors (once per k grid; cached)",
            Stage::Named(what) => what,
        })
    }
}

/// Receives progress reports. Calls may come from several threads at once.
pub trait Progress: Sync {
    /// `done` of `total` units of `stage` are finished (called now and then, and once with
    /// `done == total`).
    fn update(&self, stage: Stage, done: usize, total: usize) {
        let _ = (stage, done, total);
    }

    /// Something the user should know while waiting, e.g. that another process is building a table.
    fn note(&self, message: &str) {
        let _ = message;
    }
}

/// Ignores every report.
#[derive(Debug, Clone, Copy, Default)]
pub struct Silent;

impl Progress for Silent {}

/// A `Fn(done, total)` callback seen as the progress of one stage (for the lower-level functions that
/// take one).
pub(crate) fn stage_callback(
    progress: &dyn Progress,
    stage: Stage,
) -> impl Fn(usize, usize) + Sync + '_ {
    move |done, total| progress.update(stage, done, total)
}
