//! The seam of a statistic beside the power spectrum in a data vector (issue 46): a [`Block`] of
//! entries after the power spectrum's, computed from the same linear spectrum, growth rate f,
//! Alcock–Paczynski distortion and IR setting, sharing the biases b1, b2, bs ([`Shared`]) with the
//! galaxy model and adding parameters of its own ([`Kind`]).
//!
//! The pipeline ([`crate::pipeline`]), the galaxy fits ([`crate::fit::galaxy`]) and the forecasts
//! ([`crate::forecast`]) hold blocks as `Box<dyn Block>` and never name a statistic; a statistic
//! implements the trait in its own module and is listed in [`crate::blocks`] (docs/architecture.md,
//! "Adding a statistic").
//!
//! A block's terms depend on f and the distortion beyond a polynomial: they are made per (f, α∥, α⊥)
//! ([`Block::terms`], from what the spectrum alone gives, [`Block::prepare`], made once), and a step
//! of the parameters is then a contraction ([`Terms::values`]).

use crate::error::{Error, Result};
use crate::linear::LinearSpectrum;
use std::any::Any;
use std::path::PathBuf;
use std::sync::Arc;

mod options;
pub use options::{OptionValue, Options};

/// The galaxy model's parameters a block shares (velocileptors' bias convention); f and the
/// distortion are where its terms are made ([`Block::terms`]).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Shared {
    /// Linear bias.
    pub b1: f64,
    /// Quadratic bias ((b2/2)δ²).
    pub b2: f64,
    /// Tidal bias.
    pub bs: f64,
}

impl Shared {
    /// The shared values of `params` by name (not given: 0, as the galaxy model's).
    pub fn from_params(params: &[(&str, f64)]) -> Self {
        let mut s = Self::default();
        for &(name, v) in params {
            match name {
                "b1" => s.b1 = v,
                "b2" => s.b2 = v,
                "bs" => s.bs = v,
                _ => {}
            }
        }
        s
    }
}

/// A fit's range of a parameter: (lower bound, upper bound, start box lower, upper, typical σ).
pub type Range = (f64, f64, f64, f64, f64);

/// What kind of block, independently of its configurations: its name and its own parameters.
#[derive(Debug)]
pub struct Kind {
    /// Its name in messages and headers, and its key in the faces (an analysis file's
    /// `[dataset.<name>]`, a Python keyword).
    pub name: &'static str,
    /// Its own parameters, in the order of [`Terms::values`]' `own`.
    pub own: &'static [&'static str],
    /// Their values when not given.
    pub defaults: &'static [f64],
    /// Their units in tables ("1": none).
    pub units: &'static [&'static str],
    /// Those that enter the block linearly (affinely): a fit marginalises them analytically.
    pub linear: &'static [&'static str],
    /// Per own parameter, its range in a fit ([`Range`]).
    pub ranges: &'static [Range],
    /// Those a forecast frees by default.
    pub forecast_free: &'static [&'static str],
    /// How the faces build it from their text ([`Options`]).
    pub faces: Faces,
}

/// Settings of a block as the pipeline's settings hold them.
pub type SharedSpec = Arc<dyn Spec>;

/// How the faces build a kind of block from their text, each from [`Options`]: the pipeline's
/// keywords, a forecast's survey bin, an analysis file's data set.
#[derive(Debug, Clone, Copy)]
pub struct Faces {
    /// Its keywords in a pipeline's face besides its name (e.g. Python's `pt.Pipeline`): given, they
    /// are its options.
    pub keywords: &'static [&'static str],
    /// The block of a pipeline from its options; `None` where they do not ask for it.
    pub pipeline: fn(&Options) -> Result<Option<SharedSpec>>,
    /// Its face in a forecast's survey bin, if a forecast can hold it.
    pub survey: Option<SurveyFace>,
    /// Its measurement in an analysis file's data set, if a fit can hold it.
    pub analysis: Option<AnalysisFace>,
}

/// A block in a forecast's survey bin, switched on by one number of the bin (its key).
#[derive(Debug, Clone, Copy)]
pub struct SurveyFace {
    /// The key of the bin that holds the number (e.g. the largest side of the triangle bins).
    pub key: &'static str,
    /// Checks the number against the bin's shells.
    pub check: fn(f64, &Shells) -> Result<()>,
    /// The block of the bin.
    pub plan: fn(f64, &Shells) -> Result<Arc<dyn Spec>>,
    /// What the block is, for the forecast's header (a phrase after the power spectrum's).
    pub note: fn(f64) -> String,
}

/// A forecast bin's k shells and density, which its blocks are planned on.
#[derive(Debug, Clone, PartialEq)]
pub struct Shells {
    /// The first shell's lower edge [h/Mpc].
    pub k_min: f64,
    /// The last shell's upper edge [h/Mpc].
    pub k_max: f64,
    /// The shell width [h/Mpc].
    pub dk: f64,
    /// The edges: `k_min`, then every shell's upper edge [h/Mpc].
    pub edges: Vec<f64>,
    /// The number density [(h/Mpc)³].
    pub n_bar: f64,
}

/// A block measured beside a data set's power spectrum in an analysis file's table
/// (`[dataset.<kind name>]`).
#[derive(Debug, Clone, Copy)]
pub struct AnalysisFace {
    /// Checks the table when the file is read (keys, types, that the files exist).
    pub check: fn(&Options) -> Result<()>,
    /// Reads the measurement when the data set is loaded.
    pub measure: fn(&Options) -> Result<Measured>,
}

/// A block's measurement, as read by [`AnalysisFace::measure`]: the generic fit reads the joint
/// covariance of the power spectrum and the block (square over every power-spectrum entry of the
/// data file, then every entry of the block's file) and keeps the fitted entries.
#[derive(Debug)]
pub struct Measured {
    /// The block fitted.
    pub spec: Arc<dyn Spec>,
    /// Every entry of its file in the joint covariance's order, in columns (e.g. a multipole's
    /// values at every triangle).
    pub columns: Vec<Vec<f64>>,
    /// The fitted entries (in the block's order): their positions among the file's (columns
    /// concatenated).
    pub fitted: Vec<usize>,
    /// The joint covariance file.
    pub covariance: PathBuf,
    /// The file's entries in words, for the covariance's error (e.g. "3 multipoles x 40 triangles").
    pub layout: String,
    /// The header line after the block's description (the data, the selection, the covariance).
    pub note: String,
}

impl Kind {
    /// The index of `name` among [`Self::own`].
    pub fn index(&self, name: &str) -> Option<usize> {
        self.own.iter().position(|&n| n == name)
    }

    /// The own values of `params` by name, [`Self::defaults`] for those not given; other names are
    /// skipped.
    pub fn own_values(&self, params: &[(&str, f64)]) -> Vec<f64> {
        let mut own = self.defaults.to_vec();
        for &(name, v) in params {
            if let Some(i) = self.index(name) {
                own[i] = v;
            }
        }
        own
    }
}

/// The survey a forecast's Gaussian covariance of a block is for.
pub struct Survey<'a> {
    /// Its volume [(Mpc/h)³].
    pub volume: f64,
    /// The width of its k shells [h/Mpc].
    pub dk: f64,
    /// The measured power (monopole and shot noise, P(k) + 1/n̄) at k [h/Mpc].
    pub power: &'a dyn Fn(f64) -> f64,
}

/// What a block's terms need of a spectrum alone (e.g. the IR resummation's split), made once per
/// spectrum by [`Block::prepare`] and read by [`Block::terms`] of the same block.
pub type Prepared = Arc<dyn Any + Send + Sync>;

/// A statistic's block of the data vector, planned on its configurations (cosmology independent).
pub trait Block: std::fmt::Debug + Send + Sync {
    /// Its kind: name and own parameters.
    fn kind(&self) -> &'static Kind;

    /// The number of entries.
    fn len(&self) -> usize;

    /// Whether there is no entry (never for a planned block).
    fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Entry `j` in words, for messages.
    fn entry(&self, j: usize) -> String;

    /// One line for a header: what the block is and how it is computed.
    fn describe(&self) -> String;

    /// What the terms need of `spectrum` alone, with IR resummation `ir`.
    ///
    /// # Errors
    /// As the statistic's preparation.
    fn prepare(&self, spectrum: &LinearSpectrum, ir: bool) -> Result<Prepared>;

    /// The terms of `spectrum` (`prepared` by [`Self::prepare`] from it) at growth rate `f` and
    /// distortion `ap` = (α∥, α⊥).
    ///
    /// # Errors
    /// As the statistic's terms; [`Error::InvalidChoice`] for `prepared` of another kind.
    fn terms(
        &self,
        spectrum: &LinearSpectrum,
        prepared: &Prepared,
        f: f64,
        ap: (f64, f64),
    ) -> Result<Box<dyn Terms>>;

    /// The Gaussian variance of each entry in `survey` (no covariance between entries or with the
    /// power spectrum).
    ///
    /// # Errors
    /// [`Error::InvalidChoice`] for a block without one.
    fn gaussian_variances(&self, survey: &Survey) -> Result<Vec<f64>>;
}

/// A block's terms at one (spectrum, f, distortion).
pub trait Terms: Send + Sync {
    /// The entries at the shared parameters and the block's own ones (in [`Kind::own`]'s order).
    ///
    /// # Errors
    /// As the statistic's evaluation.
    fn values(&self, shared: Shared, own: &[f64]) -> Result<Vec<f64>>;
}

/// The error of `prepared` read by a block of another kind.
pub fn foreign(kind: &Kind) -> Error {
    Error::InvalidChoice {
        what: format!("the prepared spectrum of a {} block", kind.name),
        reason: "was made by a block of another kind".into(),
    }
}

/// Settings that plan into a [`Block`] (e.g. a statistic's configurations from an analysis file),
/// held by the pipeline's settings as `Arc<dyn Spec>`.
pub trait Spec: std::fmt::Debug + Send + Sync {
    /// The planned block.
    ///
    /// # Errors
    /// As the statistic's planning.
    fn plan(&self) -> Result<Box<dyn Block>>;
}
