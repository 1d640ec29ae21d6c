//! How the faces build the one-loop bispectrum block from their text ([`crate::statistic::Faces`]): a
//! pipeline's options (Python's `pt.Pipeline(..., one_loop_bispectrum={...})`) and an analysis file's
//! `[dataset.one_loop_bispectrum]` (the measurement's layout of [`crate::bispectrum::measured`], plus the
//! loop options). No forecast face (its Gaussian covariance is the tree-level block's).

use super::LoopBispectrumBlock;
use crate::bispectrum::measured::{data_spec, Selection};
use crate::bispectrum::one_loop::OneLoopRule;
use crate::bispectrum::{LegendreSide, TriangleSet};
use crate::error::Result;
use crate::statistic::{AnalysisFace, Faces, Measured, Options, Spec};
use std::sync::Arc;

/// The one-loop bispectrum's faces.
pub const FACES: Faces = Faces {
    keywords: &[],
    pipeline,
    survey: None,
    analysis: Some(AnalysisFace {
        check: analysis_check,
        measure,
    }),
};

/// The loop options of the block, in a pipeline and in an analysis file.
const LOOP_KEYS: [&str; 3] = ["rule", "q_range", "cache_dir"];

/// The options of the block in a pipeline.
const PIPELINE_KEYS: [&str; 6] = [
    "triangles",
    "bin_width",
    "ells",
    "rule",
    "q_range",
    "cache_dir",
];

/// The block of a pipeline: with `triangles` (rows k1 k2 k3 [h/Mpc]; bins of `bin_width` [h/Mpc]) the
/// multipoles `ells` (default 0, 2, 4) on the loop `rule` (nodes radial, mu, phi; default 12, 32, 24)
/// over `q_range` (q_min, q_max [h/Mpc]; default 1e-4, 10), the tensors read from `cache_dir` (default
/// $PT_SPECTRA_CACHE, else the user's cache); without options, none.
fn pipeline(o: &Options) -> Result<Option<Arc<dyn Spec>>> {
    o.known(&PIPELINE_KEYS)?;
    if o.entries.is_empty() {
        return Ok(None);
    }
    let triangles = o.rows::<3>("triangles", "k1, k2, k3")?.ok_or_else(|| {
        o.bad(
            "triangles",
            "the one-loop bispectrum block needs its triangles",
        )
    })?;
    let triangles = match o.number("bin_width")? {
        Some(w) => TriangleSet::shells(triangles, w)?,
        None => TriangleSet::points(triangles)?,
    };
    let rule = loop_rule(o)?;
    Ok(Some(Arc::new(LoopBispectrumBlock {
        triangles,
        side: LegendreSide::Largest,
        rule,
        ells: o.counts("ells")?.unwrap_or_else(|| vec![0, 2, 4]),
        fitted: None,
        cache_dir: o.text("cache_dir")?.map(Into::into),
    })))
}

/// The loop rule of the options `rule` and `q_range` (defaults: [`OneLoopRule::default`]).
///
/// # Errors
/// [`crate::error::Error::InvalidChoice`] naming the key for a rule that is not three counts or a q range
/// that is not two numbers; the rule's check.
fn loop_rule(o: &Options) -> Result<OneLoopRule> {
    let mut rule = OneLoopRule::default();
    if let Some(n) = o.counts("rule")? {
        let &[radial, mu, phi] = &n[..] else {
            return Err(o.bad("rule", "three node counts: radial, mu, phi"));
        };
        (rule.radial, rule.mu, rule.phi) = (radial, mu, phi);
    }
    if let Some(q) = o.numbers("q_range")? {
        let &[q_min, q_max] = &q[..] else {
            return Err(o.bad("q_range", "two numbers q_min, q_max [h/Mpc]"));
        };
        (rule.q_min, rule.q_max) = (q_min, q_max);
    }
    rule.validate()?;
    Ok(rule)
}

fn analysis_check(o: &Options) -> Result<()> {
    data_spec(o, &LOOP_KEYS)?;
    loop_rule(o).map(|_| ())
}

/// The measured multipoles of the table's file at the triangles fitted and the one-loop block of those
/// triangles on the table's rule, its tensors read from `cache_dir` when the fit is set up.
///
/// # Errors
/// As [`crate::bispectrum::measured`]'s reading; a bad rule.
fn measure(o: &Options) -> Result<Measured> {
    let spec = data_spec(o, &LOOP_KEYS)?;
    let rule = loop_rule(o)?;
    let cache_dir = o.text("cache_dir")?.map(Into::into);
    let ells = spec.ells.clone();
    let width = spec.bin_width;
    // the tensors are of the file's triangles (what a user builds them from); the block selects
    let block = |s: Selection| -> Result<Arc<dyn Spec>> {
        let triangles = match width {
            Some(w) => TriangleSet::shells(s.all, w)?,
            None => TriangleSet::points(s.all)?,
        };
        Ok(Arc::new(LoopBispectrumBlock {
            triangles,
            side: LegendreSide::Largest,
            rule,
            ells,
            cache_dir,
            fitted: Some(s.rows),
        }))
    };
    crate::bispectrum::measured::measure(&spec, block, "; the one-loop model")
}
