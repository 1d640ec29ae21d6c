//! The seam of every "plan once per grid, evaluate per spectrum" type: [`Plan`].
//!
//! A plan does the work that does not depend on the cosmology once, for one grid (wavenumbers,
//! triangles, pairs of sides) and one [`crate::precision::Precision`]: quadrature nodes and weights,
//! angular tables, basis tensors. [`Plan::terms`] then gives the terms of one linear spectrum (the
//! coefficients of the model's parameters, or its spectra), cheaply. Every plan states:
//! - its terms type ([`Plan::Terms`]; a real-space plan's `LoopTerms` holds the terms of every model
//!   it covers, from which each model takes its family's type, [`crate::real::ModelTerms`]),
//! - what an evaluation takes besides the spectrum ([`Plan::Settings`]: nothing for the loop terms;
//!   f, AP, FoG and IR for the bispectrum),
//! - how it computes a new spectrum's terms ([`Plan::method`]: integrated directly or contracted
//!   from basis tensors; the one place that chose it is [`crate::store::TableStore::for_method`], and
//!   a spectrum outside the tensors' span falls back to direct integrals, stated in its terms),
//! - its memory ([`Plan::bytes`]: each plan's own estimate, checked against the limit of
//!   [`crate::memory`] before it allocates).
//!
//! [`terms_batch`] evaluates many spectra on any plan over rayon's threads, the memory of the plan
//! and of the results checked first.
//!
//! ```
//! use pt_spectra::plan::{Method, Plan};
//! use pt_spectra::{linear::LinearSpectrum, loops::OneLoopPlan, precision::Precision};
//! let plan = OneLoopPlan::new(&[0.05, 0.1], &Precision::fast())?;
//! assert_eq!(plan.method(), Method::Direct);
//! let terms = Plan::terms(&plan, &LinearSpectrum::gm2012(0.0)?, (), &pt_spectra::progress::Silent)?;
//! assert_eq!(terms.k, [0.05, 0.1]);
//! # Ok::<(), pt_spectra::error::Error>(())
//! ```

use crate::error::Result;
use crate::linear::LinearSpectrum;
use crate::precision::Precision;
use crate::progress::{Progress, Silent};
use rayon::prelude::*;

/// How a plan computes the terms of a new spectrum.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Method {
    /// Integrated for each spectrum.
    Direct,
    /// Contracted from cosmology-independent basis tensors (a spectrum whose projection on the basis
    /// is not accurate enough is integrated directly instead, which its terms state).
    Basis,
}

impl Method {
    /// The name in headers and Python's `meta` (`direct`, `basis`).
    pub fn name(self) -> &'static str {
        match self {
            Self::Direct => "direct",
            Self::Basis => "basis",
        }
    }
}

/// Plan once per grid, evaluate per spectrum (module docs).
pub trait Plan: Sync {
    /// What an evaluation takes besides the linear spectrum (`()` for none).
    type Settings<'a>: Copy + Sync;
    /// The terms of one spectrum.
    type Terms: Send;

    /// What the plan computes, for messages (e.g. "1-loop terms on 40 k").
    fn describe(&self) -> String;

    /// How the terms of a new spectrum are computed.
    fn method(&self) -> Method;

    /// The estimated memory the plan holds \[bytes\] (with the process's own, [`crate::memory::PROCESS`]).
    fn bytes(&self) -> f64;

    /// The estimated memory of one spectrum's terms \[bytes\] (what a batch holds per spectrum).
    fn terms_bytes(&self) -> f64;

    /// The memory limit the plan was made under \[bytes\] (`None`: the default of [`crate::memory::limit`]).
    fn max_memory(&self) -> Option<f64>;

    /// The terms of `spectrum` (the linear spectrum at the prediction's redshift) with `settings`,
    /// reporting long integrals to `progress`.
    ///
    /// # Errors
    /// As each plan's own evaluation.
    fn terms(
        &self,
        spectrum: &LinearSpectrum,
        settings: Self::Settings<'_>,
        progress: &dyn Progress,
    ) -> Result<Self::Terms>;
}

/// The terms of every spectrum of `spectra` on `plan` with `settings`, spread over rayon's threads
/// one spectrum per task, in order. The plan's memory and that of all the results are checked against
/// the plan's limit first.
///
/// # Errors
/// [`crate::error::Error::MemoryLimit`] with the estimate and the limit if they do not fit; per
/// spectrum as [`Plan::terms`].
pub fn terms_batch<P: Plan>(
    plan: &P,
    spectra: &[LinearSpectrum],
    settings: P::Settings<'_>,
) -> Result<Vec<Result<P::Terms>>> {
    let (bytes, results) = (plan.bytes(), plan.terms_bytes() * spectra.len() as f64);
    let mut limit = Precision::default();
    limit.max_memory = plan.max_memory();
    crate::memory::check(
        bytes + results,
        &limit,
        &format!(
            "a batch of {} spectra of {} (the plan {}, the results {})",
            spectra.len(),
            plan.describe(),
            crate::memory::size(bytes),
            crate::memory::size(results)
        ),
    )?;
    Ok(spectra
        .par_iter()
        .map(|s| plan.terms(s, settings, &Silent))
        .collect())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::loops::OneLoopPlan;

    /// A batch is the plan's terms of each spectrum, in order, and a batch above the limit is refused
    /// with both figures before anything is evaluated.
    #[test]
    fn a_batch_is_each_spectrum_s_terms_and_is_checked_against_the_limit() {
        let spectra: Vec<LinearSpectrum> = [0.0, 0.5, 1.0]
            .iter()
            .map(|&z| LinearSpectrum::gm2012(z).unwrap())
            .collect();
        let mut precision = Precision::fast();
        let plan = OneLoopPlan::new(&[0.03, 0.1, 0.2], &precision).unwrap();
        let batch = terms_batch(&plan, &spectra, ()).unwrap();
        for (terms, spectrum) in batch.iter().zip(&spectra) {
            assert_eq!(terms.as_ref().unwrap(), &plan.par_evaluate(spectrum));
        }
        assert_eq!(plan.method(), Method::Direct);
        assert!(plan.describe().contains("on 3 k"), "{}", plan.describe());
        // the process's own memory is part of every plan's figure
        assert!(plan.bytes() > crate::memory::PROCESS && plan.terms_bytes() > 0.0);
        precision.max_memory = Some(1e6);
        let limited = OneLoopPlan::new(&[0.03, 0.1, 0.2], &precision).unwrap();
        let err = terms_batch(&limited, &spectra, ()).unwrap_err().to_string();
        assert!(
            err.contains("a batch of 3 spectra of 1-loop terms on 3 k")
                && err.contains("above 1.0 MB"),
            "{err}"
        );
    }
}
