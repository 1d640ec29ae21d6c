//! The [`Plan`] seam of the bispectrum plans: the tree-level multipoles' terms (orientation and bin
//! averages, a periodic box's modes, the Sugiyama multipoles), with f, AP, FoG and IR as their
//! settings, and the one-loop matter terms; the bispectrum's progress stages and its tensors in the
//! store's cache ([`crate::store::CachedTensors`]), so that neither `progress` nor `store` names it.

use super::one_loop_basis::{BispectrumLoopSource, OneLoopMatterPlan};
use super::{BispectrumPlan, BispectrumTerms, BoxPlan, Settings, SugiyamaPlan, SugiyamaTerms};
use crate::bispectrum::one_loop::OneLoopMatter;
use crate::error::Result;
use crate::linear::LinearSpectrum;
use crate::plan::{Method, Plan};
use crate::progress::{Progress, Stage};
use crate::store::cached_tensors;

/// Bytes of one orientation node of an average (three line-of-sight components and its share of a
/// group's weights).
const NODE_BYTES: f64 = 32.0;
/// Bytes of one triangle's one-loop basis tensors (the cache file of the 62 Nseries triangles: 13 MB).
const ONE_LOOP_TENSOR_BYTES: f64 = 0.25e6;
/// Bytes of one triangle's one-loop terms (six estimates and the sides).
const ONE_LOOP_TERMS_BYTES: f64 = 150.0;

/// Bytes of the slots of `n` configurations with `ells` multipoles, on the fine and the coarse rule.
fn slot_bytes(n: usize, ells: usize) -> f64 {
    (2 * n * ells * super::observed::SLOTS * 8) as f64
}

/// Implements the [`Plan`] items every tree-level plan shares: f, AP, FoG and IR as settings, direct
/// evaluation, the default memory limit.
macro_rules! tree_level_plan {
    ($plan:ty, $terms:ty, $what:literal, $len:expr, $ells:expr, $nodes:expr) => {
        impl Plan for $plan {
            type Settings<'a> = &'a Settings;
            type Terms = $terms;

            fn describe(&self) -> String {
                format!(concat!($what, " of {} configurations"), $len(self))
            }

            fn method(&self) -> Method {
                Method::Direct
            }

            fn bytes(&self) -> f64 {
                crate::memory::PROCESS + NODE_BYTES * $nodes(self)
            }

            fn terms_bytes(&self) -> f64 {
                slot_bytes($len(self), $ells)
            }

            fn max_memory(&self) -> Option<f64> {
                None
            }

            fn terms(
                &self,
                spectrum: &LinearSpectrum,
                settings: &Settings,
                _progress: &dyn Progress,
            ) -> Result<$terms> {
                <$plan>::terms(self, spectrum, settings)
            }
        }
    };
}

tree_level_plan!(
    BispectrumPlan,
    BispectrumTerms,
    "tree-level B0, B2, B4",
    |p: &BispectrumPlan| p.triangles().len(),
    3,
    |p: &BispectrumPlan| {
        // a bin of three shells has ~1.2 n³ shapes of n nodes per shell panel
        let r = p.rules();
        let shapes = if p.triangles().width().is_some() {
            1.2 * (r.n_shell as f64).powi(3)
        } else {
            1.0
        };
        2.0 * p.triangles().len() as f64 * shapes * (r.n_mu * r.n_phi) as f64
    }
);
tree_level_plan!(
    BoxPlan,
    BispectrumTerms,
    "tree-level B0, B2, B4 over a box's modes",
    |p: &BoxPlan| p.triangles().len(),
    3,
    |p: &BoxPlan| p.configurations().iter().sum::<usize>() as f64
);
tree_level_plan!(
    SugiyamaPlan,
    SugiyamaTerms,
    "Sugiyama multipoles",
    |p: &SugiyamaPlan| p.pairs().len(),
    super::SUGIYAMA_MULTIPOLES.len(),
    |p: &SugiyamaPlan| {
        let r = p.rules();
        2.0 * p.pairs().len() as f64 * (r.n_panels * r.n_k3 * r.n_mu * r.n_phi) as f64
    }
);

impl Plan for OneLoopMatterPlan {
    type Settings<'a> = ();
    type Terms = (Vec<OneLoopMatter>, BispectrumLoopSource);

    fn describe(&self) -> String {
        format!(
            "one-loop matter bispectrum terms of {} triangles",
            self.triangles().len()
        )
    }

    fn method(&self) -> Method {
        if self.has_basis() {
            Method::Basis
        } else {
            Method::Direct
        }
    }

    fn bytes(&self) -> f64 {
        let tensors = if self.has_basis() {
            ONE_LOOP_TENSOR_BYTES * self.triangles().len() as f64
        } else {
            0.0
        };
        crate::memory::PROCESS + tensors
    }

    fn terms_bytes(&self) -> f64 {
        ONE_LOOP_TERMS_BYTES * self.triangles().len() as f64
    }

    fn max_memory(&self) -> Option<f64> {
        None
    }

    fn terms(
        &self,
        spectrum: &LinearSpectrum,
        (): (),
        progress: &dyn Progress,
    ) -> Result<Self::Terms> {
        let stage = crate::progress::stage_callback(progress, ONE_LOOP_STAGE);
        self.evaluate_reporting(spectrum, &stage)
    }
}

/// The progress stage of the one-loop bispectrum's direct integrals (per triangle).
pub const ONE_LOOP_STAGE: Stage = Stage::Named("one-loop bispectrum (per triangle)");

/// The progress stage of a build of the one-loop bispectrum's basis tensors.
pub const ONE_LOOP_BASIS_STAGE: Stage =
    Stage::Named("one-loop bispectrum basis tensors (once per triangle set; cached)");

// The one-loop basis tensors in the store's cache, keyed by the triangles and the rule.
cached_tensors!(
    super::one_loop_basis::OneLoopMatterBasis,
    (&'a [[f64; 3]], &'a super::one_loop::OneLoopRule),
    "one-loop bispectrum basis",
    ONE_LOOP_BASIS_STAGE,
    (triangles, rule)
);
cached_tensors!(
    super::one_loop_galaxy_basis::GalaxyLoopBasis,
    (&'a [[f64; 3]], &'a super::one_loop::OneLoopRule),
    "one-loop galaxy bispectrum basis",
    ONE_LOOP_BASIS_STAGE,
    (triangles, rule)
);
cached_tensors!(
    super::multipole_basis::MultipoleLoopBasis,
    (
        &'a [[f64; 3]],
        super::geometry::LegendreSide,
        &'a super::one_loop::OneLoopRule
    ),
    "one-loop galaxy multipole tensors",
    ONE_LOOP_BASIS_STAGE,
    (triangles, side, rule)
);
cached_tensors!(
    super::multipole_bins::MultipoleBinBasis,
    (
        &'a super::geometry::TriangleSet,
        super::geometry::LegendreSide,
        &'a super::one_loop::OneLoopRule,
        &'a [super::one_loop::OneLoopRule; 2]
    ),
    "one-loop galaxy multipole bin tensors",
    ONE_LOOP_BASIS_STAGE,
    (set, side, rule, rules)
);
