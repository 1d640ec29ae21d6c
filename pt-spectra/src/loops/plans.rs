//! The [`Plan`] seam of the loop-term plans: each is integrated directly for every spectrum, holds its
//! own memory estimate (`memory_estimate` of each plan) and the process's, and gives its terms type.

use super::bias::{BiasPlan, BiasTerms};
use super::redshift::{RedshiftPlan, RedshiftTerms};
use super::{OneLoopPlan, OneLoopTerms, TnsPlan, TnsTerms};
use crate::error::Result;
use crate::linear::LinearSpectrum;
use crate::plan::{Method, Plan};
use crate::progress::Progress;

/// Bytes of one estimate (value and error).
const ESTIMATE: f64 = 16.0;

/// Implements [`Plan`] for a loop-term plan `$plan` whose `$evaluate(spectrum)` gives `$terms`, made
/// of `$per_k` estimates per wavenumber.
macro_rules! loop_plan {
    ($plan:ty, $terms:ty, $what:literal, $evaluate:ident, $per_k:expr) => {
        impl Plan for $plan {
            type Settings<'a> = ();
            type Terms = $terms;

            fn describe(&self) -> String {
                format!(concat!($what, " on {} k"), self.k().len())
            }

            fn method(&self) -> Method {
                Method::Direct
            }

            fn bytes(&self) -> f64 {
                crate::memory::PROCESS + Self::memory_estimate(self.k().len(), self.precision())
            }

            fn terms_bytes(&self) -> f64 {
                $per_k * ESTIMATE * self.k().len() as f64
            }

            fn max_memory(&self) -> Option<f64> {
                self.precision().max_memory
            }

            fn terms(
                &self,
                spectrum: &LinearSpectrum,
                (): (),
                _progress: &dyn Progress,
            ) -> Result<$terms> {
                Ok(self.$evaluate(spectrum))
            }
        }
    };
}

// P22 and P13 of three pairs, σ_v², P_lin and the P13 pieces: at most 12 estimates per k.
loop_plan!(
    OneLoopPlan,
    OneLoopTerms,
    "1-loop terms",
    par_evaluate,
    12.0
);
// A and B: 2 × 9 coefficients (values and errors) and P_lin.
loop_plan!(TnsPlan, TnsTerms, "TNS A and B terms", par_evaluate, 20.0);
// Seven pair terms and sig3nl.
loop_plan!(BiasPlan, BiasTerms, "1-loop bias terms", evaluate, 8.0);
// The redshift-space 1-loop terms: one estimate per kernel coefficient of every term.
loop_plan!(
    RedshiftPlan,
    RedshiftTerms,
    "redshift-space 1-loop terms",
    evaluate,
    64.0
);
