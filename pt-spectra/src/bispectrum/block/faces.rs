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
use crate::bispectrum::{Fog, LegendreSide, PlanRules, TriangleSet};
use crate::error::{Error, Result};
use crate::statistic::{AnalysisFace, Faces, Measured, Options, Shells, Spec, SurveyFace};
use crate::table::DataColumns;
use std::path::PathBuf;
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

/// The keys of a `[dataset.bispectrum]`.
const ANALYSIS_KEYS: [&str; 8] = [
    "data",
    "data_ells",
    "ells",
    "k_min",
    "k_max",
    "bin_width",
    "covariance",
    "n_bar",
];

/// The bispectrum of a data set, as the analysis file gives it (paths resolved).
struct DataSpec {
    data: PathBuf,
    data_ells: Vec<usize>,
    ells: Vec<usize>,
    k_min: f64,
    k_max: f64,
    bin_width: Option<f64>,
    covariance: PathBuf,
    n_bar: Option<f64>,
}

/// A `[dataset.bispectrum]` table (n_bar by default the data set's).
fn data_spec(o: &Options) -> Result<DataSpec> {
    o.known(&ANALYSIS_KEYS)?;
    let ells_of = |k: &str, default: Vec<usize>| -> Result<Vec<usize>> {
        let v = o.counts(k)?.unwrap_or(default);
        if v.is_empty() || v.iter().any(|l| ![0, 2, 4].contains(l)) {
            return Err(o.bad(k, "the bispectrum multipoles are 0, 2, 4"));
        }
        Ok(v)
    };
    let n_bar = o
        .inherited("n_bar")
        .map(|v| o.number_of("n_bar", v))
        .transpose()?;
    if let Some(n) = n_bar {
        if !(n.is_finite() && n > 0.0) {
            return Err(o.bad("n_bar", "must be > 0 [(h/Mpc)^3]"));
        }
    }
    let k_min = o.number("k_min")?.unwrap_or(0.0);
    let k_max = o.number_of("k_max", o.need("k_max")?)?;
    if k_max <= k_min {
        return Err(o.bad("k_max", "must exceed k_min"));
    }
    let file = |k: &str| {
        o.need(k)?;
        Ok::<_, Error>(o.file(k)?.expect("given"))
    };
    Ok(DataSpec {
        data: file("data")?,
        data_ells: ells_of("data_ells", vec![0, 2, 4])?,
        ells: ells_of("ells", vec![0])?,
        k_min,
        k_max,
        bin_width: o.number("bin_width")?,
        covariance: file("covariance")?,
        n_bar,
    })
}

fn analysis_check(o: &Options) -> Result<()> {
    data_spec(o).map(|_| ())
}

/// The error about `what`.
fn bad(what: String, reason: impl Into<String>) -> Error {
    Error::InvalidChoice {
        what,
        reason: reason.into(),
    }
}

/// The measured multipoles of the table's file at the triangles fitted (every side in [k_min,
/// k_max]) and the block of those triangles.
///
/// # Errors
/// [`Error::BadRow`], [`Error::InvalidChoice`] naming the file and the rule for a file not of its
/// layout, a fitted multipole not in the file, no triangle in the range.
fn measure(o: &Options) -> Result<Measured> {
    let spec = data_spec(o)?;
    let origin = spec.data.display().to_string();
    let text = crate::table::read_text(&spec.data)?;
    let table = DataColumns::parse_exact(&text, &origin, 3 + spec.data_ells.len())?;
    let n_tri = table.lines.len();
    let triangles: Vec<[f64; 3]> = (0..n_tri)
        .map(|i| std::array::from_fn(|c| table.columns[c][i]))
        .collect();
    let fitted: Vec<usize> = (0..n_tri)
        .filter(|&i| {
            triangles[i]
                .iter()
                .all(|&k| k >= spec.k_min && k <= spec.k_max)
        })
        .collect();
    if fitted.is_empty() {
        return Err(bad(
            format!("{origin}: k_min = {}, k_max = {}", spec.k_min, spec.k_max),
            "no triangle has every side in the range",
        ));
    }
    let b_rows = spec
        .ells
        .iter()
        .map(|l| {
            spec.data_ells.iter().position(|d| d == l).ok_or_else(|| {
                bad(
                    format!("the fitted bispectrum multipole {l}"),
                    format!("is not in {origin} (its multipoles {:?})", spec.data_ells),
                )
            })
        })
        .collect::<Result<Vec<usize>>>()?;
    let centres: Vec<[f64; 3]> = fitted.iter().map(|&t| triangles[t]).collect();
    let set = match spec.bin_width {
        Some(w) => TriangleSet::shells(centres, w)?,
        None => TriangleSet::points(centres)?,
    };
    let block = BispectrumBlock {
        triangles: set,
        side: LegendreSide::Largest,
        rules: PlanRules::default(),
        ells: spec.ells.clone(),
        fog: Fog::None,
        n_bar: spec.n_bar.unwrap_or(f64::INFINITY),
    };
    let note = format!(
        "data {origin} ({} of its {n_tri} triangles: every side in [{}, {}] h/Mpc{}), joint \
         covariance {} (P then B, cross terms included){}",
        fitted.len(),
        spec.k_min,
        spec.k_max,
        spec.bin_width
            .map_or(", at the triangles given".into(), |w| format!(
                ", averaged over bins of width {w}"
            )),
        spec.covariance.display(),
        if spec.n_bar.is_none() {
            "; no stochastic terms (n_bar not given)"
        } else {
            ""
        }
    );
    Ok(Measured {
        spec: Arc::new(block),
        // the fitted entries: multipole, then triangle
        fitted: b_rows
            .iter()
            .flat_map(|&j| fitted.iter().map(move |&t| j * n_tri + t))
            .collect(),
        columns: table.columns[3..].to_vec(),
        covariance: spec.covariance,
        layout: format!("{} multipoles x {n_tri} triangles", spec.data_ells.len()),
        note,
    })
}
