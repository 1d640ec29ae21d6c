//! The likelihood of an analysis file as an object that owns its data sets: what a sampler keeps
//! between calls (Python's `pt.AnalysisLikelihood`, a cobaya likelihood, an MCMC or HMC on its exact
//! gradient). It is the function `fit --analysis` minimises ([`JointLikelihood`]): the sum of the
//! sets' −2 ln L with their linear parameters marginalised (or profiled, as the file's
//! `[search] linear` says), every prior of the file included.

use super::joint_fit::{data_sets, load, shared_of, Analysis, Inputs, Loaded};
use crate::error::{Error, Result};
use crate::fit::galaxy::JointLikelihood;

/// The owned data sets and the parameters they share.
struct Owned {
    analysis: Analysis,
    loaded: Vec<Loaded>,
    shared: Vec<String>,
}

self_cell::self_cell!(
    struct Cell {
        owner: Owned,
        #[not_covariant]
        dependent: JointLikelihood,
    }
);

/// The joint likelihood of an analysis file (module docs).
pub struct AnalysisLikelihood {
    cell: Cell,
    header: Vec<String>,
}

impl AnalysisLikelihood {
    /// Loads every data set of `analysis` with `inputs` (the spectrum at each set's z, the
    /// precision and cache) and sets up the likelihood.
    ///
    /// # Errors
    /// As [`super::joint_fit_table`]'s loading and set-up (naming the file and the set).
    pub fn new(analysis: &Analysis, inputs: &Inputs) -> Result<Self> {
        let origin = analysis.origin.clone();
        let loaded = analysis
            .sets
            .iter()
            .map(|s| load(s, &origin, inputs))
            .collect::<Result<Vec<_>>>()?;
        let (shared, sharing) = shared_of(analysis, &data_sets(analysis, &loaded));
        let mut header = vec![format!(
            "likelihood of {origin}: -2 ln L of ept summed over {} data set(s) (their linear parameters \
             {}); shared parameters ({sharing}): {}",
            analysis.sets.len(),
            match analysis.search.linear {
                crate::fit::galaxy::Linear::Marginalised => "marginalised analytically",
                crate::fit::galaxy::Linear::Profiled => "profiled",
            },
            if shared.is_empty() {
                "none".into()
            } else {
                shared.join(", ")
            }
        )];
        for l in &loaded {
            header.extend(l.description.iter().cloned());
        }
        let owned = Owned {
            analysis: analysis.clone(),
            loaded,
            shared,
        };
        let cell = Cell::try_new(owned, |o| {
            let sets = data_sets(&o.analysis, &o.loaded);
            JointLikelihood::new(&sets, &o.shared, o.analysis.search.linear).map_err(|e| {
                Error::InvalidChoice {
                    what: o.analysis.origin.clone(),
                    reason: e.to_string(),
                }
            })
        })?;
        Ok(Self { cell, header })
    }

    /// The free parameters (a shared one by its name, a set's own as `name[label]`).
    pub fn names(&self) -> Vec<String> {
        self.cell.with_dependent(|_, l| l.names.clone())
    }

    /// Their (lower, upper) bounds, the fit's.
    pub fn bounds(&self) -> Vec<(f64, f64)> {
        self.cell.with_dependent(|_, l| {
            l.lower
                .iter()
                .copied()
                .zip(l.upper.iter().copied())
                .collect()
        })
    }

    /// Their start values (the file's).
    pub fn start(&self) -> Vec<f64> {
        self.cell.with_dependent(|_, l| l.start.clone())
    }

    /// −2 ln L at the free values `x` ([`JointLikelihood::minus_two_log_l`]).
    ///
    /// # Errors
    /// As [`JointLikelihood::minus_two_log_l`].
    pub fn minus_two_log_l(&self, x: &[f64]) -> Result<f64> {
        self.cell.with_dependent(|_, l| l.minus_two_log_l(x))
    }

    /// −2 ln L and its exact gradient ([`JointLikelihood::value_and_gradient`]).
    ///
    /// # Errors
    /// As [`JointLikelihood::value_and_gradient`].
    pub fn value_and_gradient(&self, x: &[f64]) -> Result<Option<(f64, Vec<f64>)>> {
        self.cell.with_dependent(|_, l| l.value_and_gradient(x))
    }

    /// Whether the exact gradient is available (every set without a block after its power spectrum).
    pub fn exact_gradient(&self) -> bool {
        self.cell.with_dependent(|_, l| l.exact_gradient())
    }

    /// The fitted points of all sets.
    pub fn points(&self) -> usize {
        self.cell.with_dependent(|_, l| l.points())
    }

    /// Per data set: its label and σ₈(z) of its template (fσ8 = f σ₈(z)).
    pub fn sigma8_z(&self) -> Vec<(String, f64)> {
        let o = self.cell.borrow_owner();
        o.analysis
            .sets
            .iter()
            .zip(&o.loaded)
            .map(|(s, l)| (s.label.clone(), l.template.sigma8_z))
            .collect()
    }

    /// What the likelihood is, one line per statement (the file, the sets, the sharing).
    pub fn header(&self) -> &[String] {
        &self.header
    }
}
