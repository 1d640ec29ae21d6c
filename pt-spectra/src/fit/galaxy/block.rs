//! A block after a data set's power spectrum in a galaxy fit ([`crate::statistic::Block`]): its
//! measured entries and their covariance with the power spectrum's and their own, fitted with the
//! block's model from the same linear spectrum, growth rate, distortion and IR setting as the power
//! spectrum, b1, b2, bs shared with it and its own parameters beside (those of
//! [`crate::statistic::Kind::linear`] marginalised as the power spectrum's counterterms can be).
//!
//! The data vector is [P points | block entries] with one covariance, cross terms included (a joint
//! covariance from mocks: P then the block). The block's terms depend on f and the distortion beyond a
//! polynomial; the objective keeps those of the last few (f, α∥, α⊥), so that a step of the biases or
//! of the block's own parameters is a contraction (microseconds).

use crate::error::{Error, Result};
use crate::linear::LinearSpectrum;
use crate::rsd::ap::Distortion;
use crate::rsd::ept::EptParams;
use crate::statistic::{Block, Kind, Prepared, Shared, Spec, Terms};
use std::cell::RefCell;
use std::sync::Arc;

/// Terms kept: a gradient's steps of f, α∥, α⊥ each make their own; the centre's is found again.
const TERMS_CACHE: usize = 4;

/// A block's own parameters at a fit's best fit.
#[derive(Debug, Clone, PartialEq)]
pub struct OwnValues {
    /// Their names ([`Kind::own`]).
    pub names: &'static [&'static str],
    /// Their values, in that order.
    pub values: Vec<f64>,
}

/// A data set's block: the model and the measured entries with their covariance.
#[derive(Clone)]
pub struct BlockFit {
    block: Arc<dyn Block>,
    spectrum: LinearSpectrum,
    /// What the block's terms need of the spectrum alone, made once.
    prepared: Prepared,
    values: Vec<f64>,
    cross: Vec<Vec<f64>>,
    covariance: Vec<Vec<f64>>,
    start: Vec<f64>,
}

impl std::fmt::Debug for BlockFit {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("BlockFit")
            .field("block", &self.block)
            .field("entries", &self.values.len())
            .field("start", &self.start)
            .finish_non_exhaustive()
    }
}

impl BlockFit {
    /// The block planned from `spec` (its configurations those fitted) for the tracer's linear
    /// `spectrum` (the power spectrum's), with IR resummation `ir`; `values` the measured entries in
    /// the block's order [its units]; `cross[a][j]` the covariance of the data file's power-spectrum
    /// entry a (ℓ-major over its multipoles, every k: the order of
    /// [`crate::fit::MultipoleData::covariance`]) with block entry j; `covariance` that of the block's
    /// entries.
    ///
    /// # Errors
    /// As the block's planning and preparation; [`Error::InvalidChoice`] for sizes that do not match
    /// the block or a value that is not finite.
    pub fn new(
        spec: &dyn Spec,
        spectrum: LinearSpectrum,
        ir: bool,
        values: Vec<f64>,
        cross: Vec<Vec<f64>>,
        covariance: Vec<Vec<f64>>,
    ) -> Result<Self> {
        let block: Arc<dyn Block> = Arc::from(spec.plan()?);
        let prepared = block.prepare(&spectrum, ir)?;
        let (n, name) = (block.len(), block.kind().name);
        let bad = |what: &str| Error::InvalidChoice {
            what: format!("the {name} data ({what})"),
            reason: format!("must match the {n} fitted entries"),
        };
        if values.len() != n {
            return Err(bad("values"));
        }
        if covariance.len() != n || covariance.iter().any(|r| r.len() != n) {
            return Err(bad("covariance"));
        }
        if cross.iter().any(|r| r.len() != n) {
            return Err(bad("cross-covariance with the power spectrum"));
        }
        if values
            .iter()
            .chain(covariance.iter().flatten())
            .chain(cross.iter().flatten())
            .any(|v| !v.is_finite())
        {
            return Err(Error::InvalidChoice {
                what: format!("the {name} data"),
                reason: "a value or covariance entry is not finite".into(),
            });
        }
        Ok(Self {
            start: block.kind().defaults.to_vec(),
            block,
            spectrum,
            prepared,
            values,
            cross,
            covariance,
        })
    }

    /// The start (or fixed) value `value` of the block's own parameter `name` (by default
    /// [`Kind::defaults`]).
    ///
    /// # Errors
    /// [`Error::InvalidChoice`] for another name or a value that is not finite.
    pub fn with_start(mut self, name: &str, value: f64) -> Result<Self> {
        let kind = self.kind();
        let i = kind.index(name).ok_or_else(|| Error::InvalidChoice {
            what: format!("{} parameter `{name}`", kind.name),
            reason: format!("the {}'s own are {}", kind.name, kind.own.join(", ")),
        })?;
        if !value.is_finite() {
            return Err(Error::InvalidChoice {
                what: format!("{name} = {value}"),
                reason: "must be finite".into(),
            });
        }
        self.start[i] = value;
        Ok(self)
    }

    /// The start (or fixed) values of the block's own parameters ([`Kind::own`]).
    pub fn start(&self) -> &[f64] {
        &self.start
    }

    /// The block's kind: its name and own parameters.
    pub fn kind(&self) -> &'static Kind {
        self.block.kind()
    }

    /// The number of fitted entries.
    pub fn len(&self) -> usize {
        self.values.len()
    }

    /// Whether there is no entry (never: a block has at least one).
    pub fn is_empty(&self) -> bool {
        self.values.is_empty()
    }

    /// One line for the header.
    pub fn describe(&self) -> String {
        self.block.describe()
    }

    pub(super) fn values(&self) -> &[f64] {
        &self.values
    }

    /// The covariance of power-spectrum entry `a` (the data file's order) with block entry `j`.
    pub(super) fn cross(&self, a: usize, j: usize) -> Result<f64> {
        self.cross
            .get(a)
            .map(|r| r[j])
            .ok_or_else(|| Error::InvalidChoice {
                what: format!("the {}'s cross-covariance", self.kind().name),
                reason: format!(
                    "has {} power-spectrum rows: fewer than the data's entries",
                    self.cross.len()
                ),
            })
    }

    pub(super) fn covariance(&self, i: usize, j: usize) -> f64 {
        self.covariance[i][j]
    }

    /// Entry `j` in words (for messages).
    pub(super) fn entry(&self, j: usize) -> String {
        self.block.entry(j)
    }
}

/// Terms made at (f, α∥, α⊥), keyed by their bits.
type CachedTerms = ([u64; 3], Arc<dyn Terms>);

/// The block of an objective: the data set's and its terms cache.
pub(super) struct BlockModel<'a> {
    pub(super) fit: &'a BlockFit,
    cache: RefCell<Vec<CachedTerms>>,
}

impl<'a> BlockModel<'a> {
    pub(super) fn new(fit: &'a BlockFit) -> Self {
        Self {
            fit,
            cache: RefCell::new(Vec::new()),
        }
    }

    /// The model entries (the block's order) at the galaxy model's `p` (b1, b2, bs, f), the
    /// distortion `ap` and the block's own parameters `own` ([`Kind::own`]).
    pub(super) fn values(
        &self,
        p: &EptParams,
        ap: Option<Distortion>,
        own: &[f64],
    ) -> Result<Vec<f64>> {
        let f = p.f();
        let (a, b) = ap.map_or((1.0, 1.0), |d| (d.apar, d.aperp));
        let key = [f.to_bits(), a.to_bits(), b.to_bits()];
        let cached = self
            .cache
            .borrow()
            .iter()
            .find(|(k, _)| *k == key)
            .map(|(_, t)| Arc::clone(t));
        let terms = match cached {
            Some(t) => t,
            None => {
                let fit = self.fit;
                let t: Arc<dyn Terms> =
                    Arc::from(fit.block.terms(&fit.spectrum, &fit.prepared, f, (a, b))?);
                let mut cache = self.cache.borrow_mut();
                if cache.len() == TERMS_CACHE {
                    cache.remove(0);
                }
                cache.push((key, Arc::clone(&t)));
                t
            }
        };
        let bias = p.bias();
        let shared = Shared {
            b1: bias.b1,
            b2: bias.b2,
            bs: bias.bs,
        };
        terms.values(shared, own)
    }
}
