//! The [`Plan`] seam of [`RealPlan`]: the loop terms of its model.

use super::RealPlan;
use crate::error::Result;
use crate::linear::LinearSpectrum;
use crate::loops::LoopTerms;
use crate::plan::{Method, Plan};
use crate::progress::Progress;

/// Bytes per k of one spectrum's loop terms with every part a model may hold (the 1- and 2-loop terms
/// of the spectrum and of its no-wiggle part: ~120 estimates of 16 bytes).
const TERMS_BYTES_PER_K: f64 = 2e3;

impl Plan for RealPlan {
    type Settings<'a> = ();
    type Terms = LoopTerms;

    fn describe(&self) -> String {
        format!("the {} terms on {} k", self.model.name(), self.k.len())
    }

    fn method(&self) -> Method {
        let tensors =
            self.basis.is_some() || self.one_loop_basis.is_some() || self.gamma2_basis.is_some();
        if tensors {
            Method::Basis
        } else {
            Method::Direct
        }
    }

    fn bytes(&self) -> f64 {
        Self::memory_estimate(self.k.len(), self.model, &self.precision)
    }

    fn terms_bytes(&self) -> f64 {
        TERMS_BYTES_PER_K * self.k.len() as f64
    }

    fn max_memory(&self) -> Option<f64> {
        self.precision.max_memory
    }

    fn terms(
        &self,
        spectrum: &LinearSpectrum,
        (): (),
        progress: &dyn Progress,
    ) -> Result<LoopTerms> {
        RealPlan::terms(self, spectrum, progress)
    }
}
