//! How the faces build the bispectrum block from their text ([`crate::statistic::Faces`]): a
//! pipeline's keywords (Python's `pt.Pipeline(triangles=…)`), a forecast bin's `b_k_max`, an
//! analysis file's `[dataset.bispectrum]` (docs/analysis.md).
//!
//! The analysis file's layout, one per file: the bispectrum file is `k1 k2 k3` [h/Mpc] then B_ℓ
//! [(Mpc/h)⁶] for each of `data_ells` (the Nseries files' layout); the joint covariance is square over
//! the power spectrum's entries (ℓ-major over the data file's multipoles, every k) then the
//! bispectrum's (ℓ-major over its `data_ells`, every triangle of its file), as the Patchy P + B
//! covariance.

use super::BispectrumBlock;
use crate::bispectrum::measured::{data_spec, Selection};
use crate::bispectrum::{Fog, LegendreSide, PlanRules, TriangleSet};
use crate::error::{Error, Result};
use crate::statistic::{AnalysisFace, Faces, Measured, Options, Shells, Spec, SurveyFace};
use std::sync::Arc;

/// The bispectrum's faces.
pub const FACES: Faces = Faces {
    keywords: &PIPELINE_KEYS,
    pipeline,
    survey: Some(SurveyFace {
        key: "b_k_max",
        check: survey_check,
        plan: survey_plan,
        note: survey_note,
    }),
    analysis: Some(AnalysisFace {
        check: analysis_check,
        measure,
    }),
};

/// The keywords of the block in a pipeline's face.
const PIPELINE_KEYS: [&str; 6] = [
    "triangles",
    "bin_width",
    "b_ells",
    "n_bar",
    "fog",
    "sigma_fog",
];

/// The block of a pipeline: with `triangles` (rows k1 k2 k3 [h/Mpc]; bins of `bin_width`) the
/// multipoles `b_ells` (default 0), FoG `fog` (`none`) of `sigma_fog` [Mpc/h], stochastic terms at
/// `n_bar` (none); without, none (and `bin_width`, `n_bar`, `fog` are refused).
fn pipeline(o: &Options) -> Result<Option<Arc<dyn Spec>>> {
    o.known(&PIPELINE_KEYS)?;
    let fog = o.text("fog")?.unwrap_or("none");
    let n_bar = o.number("n_bar")?;
    let bin_width = o.number("bin_width")?;
    let Some(triangles) = o.rows::<3>("triangles", "k1, k2, k3")? else {
        if bin_width.is_some() || n_bar.is_some() || fog != "none" {
            return Err(Error::InvalidChoice {
                what: "bin_width, n_bar and fog are for the bispectrum block".into(),
                reason: "give triangles".into(),
            });
        }
        return Ok(None);
    };
    let fog = Fog::by_name(fog, o.number("sigma_fog")?.unwrap_or(0.0))?;
    let triangles = match bin_width {
        Some(w) => TriangleSet::shells(triangles, w)?,
        None => TriangleSet::points(triangles)?,
    };
    Ok(Some(Arc::new(BispectrumBlock {
        ells: o.counts("b_ells")?.unwrap_or_else(|| vec![0]),
        fog,
        n_bar: n_bar.unwrap_or(f64::INFINITY),
        ..BispectrumBlock::monopole(triangles)
    })))
}

/// `b_k_max` within the bin's shells.
fn survey_check(b: f64, s: &Shells) -> Result<()> {
    if !(b.is_finite() && b >= s.k_min + s.dk && b <= s.k_max + 1e-12) {
        return Err(Error::InvalidChoice {
            what: format!("b_k_max = {b}"),
            reason: "the bispectrum's bins are the power spectrum's shells: k_min + dk <= b_k_max <= k_max"
                .into(),
        });
    }
    Ok(())
}

/// B0, the monopole of all closed triangle bins of the bin's shells up to `b_max`, with its n̄.
fn survey_plan(b_max: f64, s: &Shells) -> Result<Arc<dyn Spec>> {
    let edges: Vec<f64> = s
        .edges
        .iter()
        .copied()
        .filter(|&e| e <= b_max + 1e-12)
        .collect();
    let triangles = TriangleSet::from_edges(&edges)?;
    Ok(Arc::new(BispectrumBlock {
        n_bar: s.n_bar,
        ..BispectrumBlock::monopole(triangles)
    }))
}

/// The forecast header's phrase.
fn survey_note(m: f64) -> String {
    format!(
        " and the bispectrum monopole B0 of every closed triangle bin of these shells up to \
         {m} h/Mpc (tree level, IR resummed; Gaussian variance s123 k_f^3 P_t P_t P_t / V_B \
         with the monopole, no P-B cross-covariance: an optimistic bound on what B adds)"
    )
}

/// The tree-level block's own keys of a `[dataset.bispectrum]` (besides the measurement's).
const ANALYSIS_KEYS: [&str; 1] = ["n_bar"];

/// The data set's n̄ (the table's, else the data set's) if given.
fn n_bar(o: &Options) -> Result<Option<f64>> {
    let n_bar = o
        .inherited("n_bar")
        .map(|v| o.number_of("n_bar", v))
        .transpose()?;
    if let Some(n) = n_bar {
        if !(n.is_finite() && n > 0.0) {
            return Err(o.bad("n_bar", "must be > 0 [(h/Mpc)^3]"));
        }
    }
    Ok(n_bar)
}

fn analysis_check(o: &Options) -> Result<()> {
    data_spec(o, &ANALYSIS_KEYS)?;
    n_bar(o).map(|_| ())
}

/// The measured multipoles of the table's file at the triangles fitted (every side in [k_min,
/// k_max]) and the block of those triangles ([`crate::bispectrum::measured`]).
///
/// # Errors
/// As [`measured::measure`](crate::bispectrum::measured); a bad n̄.
fn measure(o: &Options) -> Result<Measured> {
    let spec = data_spec(o, &ANALYSIS_KEYS)?;
    let n_bar = n_bar(o)?;
    let ells = spec.ells.clone();
    let block = |s: Selection| -> Result<Arc<dyn Spec>> {
        Ok(Arc::new(BispectrumBlock {
            triangles: s.fitted,
            side: LegendreSide::Largest,
            rules: PlanRules::default(),
            ells,
            fog: Fog::None,
            n_bar: n_bar.unwrap_or(f64::INFINITY),
        }))
    };
    let note = if n_bar.is_none() {
        "; no stochastic terms (n_bar not given)"
    } else {
        ""
    };
    crate::bispectrum::measured::measure(&spec, block, note)
}
