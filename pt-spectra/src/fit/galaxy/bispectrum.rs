//! The bispectrum beside a data set's power spectrum in a galaxy fit (issue 49, item 5): the measured
//! tree-level bispectrum multipoles of a triangle set, fitted with the block of
//! [`crate::bispectrum::block`] from the same linear spectrum, growth rate, distortion and IR
//! setting as the power spectrum, b1, b2, bs shared with it (velocileptors' convention, or mapped
//! from the physical basis), and its own counterterm c1 and stochastic amplitudes
//! ([`BISPECTRUM_NAMES`]; b_shot, p_shot, a_shot enter linearly and can be marginalised).
//!
//! The data vector is [P points | B entries] with one covariance, cross terms included (a joint
//! covariance from mocks: P then B). B's terms depend on f and the distortion beyond a polynomial;
//! the objective keeps those of the last few (f, α∥, α⊥), so that a step of the biases or of the
//! bispectrum's own parameters is a contraction (microseconds).

pub use crate::bispectrum::block::BISPECTRUM_NAMES;
use crate::bispectrum::block::{BispectrumBlock, PlannedBispectrum};
use crate::bispectrum::{BispectrumParams, BispectrumTerms, IrInputs};
use crate::error::{Error, Result};
use crate::linear::LinearSpectrum;
use crate::rsd::ap::Distortion;
use crate::rsd::ept::EptParams;
use std::cell::RefCell;
use std::sync::Arc;

/// The bispectrum parameters that enter B linearly (affinely): the objective marginalises them as
/// it does the power spectrum's counterterms.
pub const BISPECTRUM_LINEAR: [&str; 3] = ["b_shot", "p_shot", "a_shot"];

/// Terms kept: a gradient's steps of f, α∥, α⊥ each make their own; the centre's is found again.
const TERMS_CACHE: usize = 4;

/// A data set's bispectrum: the model block and the measured entries with their covariance.
#[derive(Debug, Clone)]
pub struct BispectrumFit {
    block: PlannedBispectrum,
    spectrum: LinearSpectrum,
    /// The IR resummation's inputs of the spectrum, made once (`None`: no resummation).
    ir: Option<IrInputs>,
    values: Vec<f64>,
    cross: Vec<Vec<f64>>,
    covariance: Vec<Vec<f64>>,
    description: String,
    start: [f64; 4],
}

impl BispectrumFit {
    /// The bispectrum of `block` (its triangles and multipoles those fitted) for the tracer's linear
    /// `spectrum` (the power spectrum's), with IR resummation `ir`; `values` the measured entries in
    /// the block's order (multipole, then triangle) [(Mpc/h)⁶]; `cross[a][j]` the covariance of the
    /// data file's power-spectrum entry a (ℓ-major over its multipoles, every k: the order of
    /// [`crate::fit::MultipoleData::covariance`]) with bispectrum entry j; `covariance` that of the
    /// bispectrum entries.
    ///
    /// # Errors
    /// As the block's planning; [`Error::InvalidChoice`] for sizes that do not match the block or a
    /// value that is not finite.
    pub fn new(
        block: BispectrumBlock,
        spectrum: LinearSpectrum,
        ir: bool,
        values: Vec<f64>,
        cross: Vec<Vec<f64>>,
        covariance: Vec<Vec<f64>>,
    ) -> Result<Self> {
        let description = format!(
            "bispectrum: B_l for l in {:?} of {} triangles, tree level (Legendre side {:?}, {:?}, \
             FoG {:?}, n_bar {} (h/Mpc)^3), b1, b2, bs shared with the power spectrum",
            block.ells,
            block.triangles.len(),
            block.side,
            block.rules,
            block.fog,
            block.n_bar
        );
        let block = PlannedBispectrum::new(block)?;
        let ir = if ir {
            Some(block.ir_inputs(&spectrum)?)
        } else {
            None
        };
        let n = block.len();
        let bad = |what: &str| Error::InvalidChoice {
            what: format!("the bispectrum data ({what})"),
            reason: format!("must match the {n} fitted entries (multipoles x triangles)"),
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
                what: "the bispectrum data".into(),
                reason: "a value or covariance entry is not finite".into(),
            });
        }
        Ok(Self {
            block,
            spectrum,
            ir,
            values,
            cross,
            covariance,
            description,
            start: {
                let d = BispectrumParams::default();
                [d.c1, d.b_shot, d.p_shot, d.a_shot]
            },
        })
    }

    /// The start (or fixed) value `value` of the bispectrum's parameter `name` ([`BISPECTRUM_NAMES`];
    /// by default c1 = 0, Poisson b_shot = 1, p_shot = a_shot = 0, as
    /// [`BispectrumParams::default`]).
    ///
    /// # Errors
    /// [`Error::InvalidChoice`] for another name or a value that is not finite.
    pub fn with_start(mut self, name: &str, value: f64) -> Result<Self> {
        let i = BISPECTRUM_NAMES
            .iter()
            .position(|&n| n == name)
            .ok_or_else(|| Error::InvalidChoice {
                what: format!("bispectrum parameter `{name}`"),
                reason: format!("the bispectrum's own are {}", BISPECTRUM_NAMES.join(", ")),
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

    /// The start (or fixed) values of the bispectrum's own parameters ([`BISPECTRUM_NAMES`]).
    pub fn start(&self) -> &[f64; 4] {
        &self.start
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
    pub fn describe(&self) -> &str {
        &self.description
    }

    pub(super) fn values(&self) -> &[f64] {
        &self.values
    }

    /// The covariance of power-spectrum entry `a` (the data file's order) with bispectrum entry `j`.
    pub(super) fn cross(&self, a: usize, j: usize) -> Result<f64> {
        self.cross
            .get(a)
            .map(|r| r[j])
            .ok_or_else(|| Error::InvalidChoice {
                what: "the bispectrum's cross-covariance".into(),
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

/// The bispectrum of an objective: the data set's and its terms cache.
pub(super) struct BispectrumModel<'a> {
    pub(super) fit: &'a BispectrumFit,
    cache: RefCell<Vec<([u64; 3], Arc<BispectrumTerms>)>>,
}

impl<'a> BispectrumModel<'a> {
    pub(super) fn new(fit: &'a BispectrumFit) -> Self {
        Self {
            fit,
            cache: RefCell::new(Vec::new()),
        }
    }

    /// The model entries (the block's order) at the galaxy model's `p` (b1, b2, bs, f), the
    /// distortion `ap` and the bispectrum's own parameters `own` ([`BISPECTRUM_NAMES`]).
    pub(super) fn values(
        &self,
        p: &EptParams,
        ap: Option<Distortion>,
        own: &[f64; 4],
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
                let t = Arc::new(self.fit.block.terms_resummed(
                    &self.fit.spectrum,
                    f,
                    (a, b),
                    self.fit.ir.as_ref(),
                )?);
                let mut cache = self.cache.borrow_mut();
                if cache.len() == TERMS_CACHE {
                    cache.remove(0);
                }
                cache.push((key, Arc::clone(&t)));
                t
            }
        };
        let [c1, b_shot, p_shot, a_shot] = *own;
        let bias = p.bias();
        let params = BispectrumParams {
            b1: bias.b1,
            b2: bias.b2,
            bs: bias.bs,
            c1,
            b_shot,
            p_shot,
            a_shot,
            n_bar: f64::INFINITY, // set by the block
        };
        self.fit.block.values(&terms, params)
    }
}
