//! How the faces build the one-loop bispectrum block from their text ([`crate::statistic::Faces`]): a
//! pipeline's options (Python's `pt.Pipeline(..., one_loop_bispectrum={...})`). No forecast face (its
//! Gaussian covariance is the tree-level block's) and no analysis-file face yet.

use super::LoopBispectrumBlock;
use crate::bispectrum::one_loop::OneLoopRule;
use crate::bispectrum::{LegendreSide, TriangleSet};
use crate::error::Result;
use crate::statistic::{Faces, OptionValue, Options, Spec};
use std::sync::Arc;

/// The one-loop bispectrum's faces.
pub const FACES: Faces = Faces {
    keywords: &[],
    pipeline,
    survey: None,
    analysis: None,
};

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
    let mut rule = OneLoopRule::default();
    if let Some(n) = o.counts("rule")? {
        let &[radial, mu, phi] = &n[..] else {
            return Err(o.bad("rule", "three node counts: radial, mu, phi"));
        };
        (rule.radial, rule.mu, rule.phi) = (radial, mu, phi);
    }
    if let Some(q) = numbers(o, "q_range")? {
        let &[q_min, q_max] = &q[..] else {
            return Err(o.bad("q_range", "two numbers q_min, q_max [h/Mpc]"));
        };
        (rule.q_min, rule.q_max) = (q_min, q_max);
    }
    rule.validate()?;
    Ok(Some(Arc::new(LoopBispectrumBlock {
        triangles,
        side: LegendreSide::Largest,
        rule,
        ells: o.counts("ells")?.unwrap_or_else(|| vec![0, 2, 4]),
        cache_dir: o.text("cache_dir")?.map(Into::into),
    })))
}

/// The numbers at `key`, if given.
///
/// # Errors
/// [`crate::error::Error::InvalidChoice`] for another value.
fn numbers(o: &Options, key: &str) -> Result<Option<Vec<f64>>> {
    let Some(v) = o.get(key) else {
        return Ok(None);
    };
    let bad = || o.bad(key, "must be a list of numbers");
    let OptionValue::List(items) = v else {
        return Err(bad());
    };
    items
        .iter()
        .map(|x| match x {
            OptionValue::Number(v) => Ok(*v),
            OptionValue::Integer(n) => Ok(*n as f64),
            _ => Err(bad()),
        })
        .collect::<Result<Vec<_>>>()
        .map(Some)
}
