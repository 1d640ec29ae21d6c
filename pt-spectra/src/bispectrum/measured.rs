//! A bispectrum measurement in an analysis file's data set (`[dataset.bispectrum]`,
//! `[dataset.one_loop_bispectrum]`), read once for every bispectrum block: one declared layout per file.
//!
//! The bispectrum file is `k1 k2 k3` [h/Mpc] then B_ℓ [(Mpc/h)⁶] for each of `data_ells` (the Nseries files'
//! layout); the joint covariance is square over the power spectrum's entries (ℓ-major over the data file's
//! multipoles, every k) then the bispectrum's (ℓ-major over its `data_ells`, every triangle of its file), as
//! the Patchy P + B covariance. The fitted triangles are those with every side in [k_min, k_max].

use super::TriangleSet;
use crate::error::{Error, Result};
use crate::statistic::{Measured, Options, Spec};
use crate::table::DataColumns;
use std::path::PathBuf;
use std::sync::Arc;

/// The keys every bispectrum data set has.
pub(super) const DATA_KEYS: [&str; 7] = [
    "data",
    "data_ells",
    "ells",
    "k_min",
    "k_max",
    "bin_width",
    "covariance",
];

/// The measurement of a data set, as its table gives it (paths resolved).
pub(super) struct DataSpec {
    data: PathBuf,
    data_ells: Vec<usize>,
    /// The fitted multipoles.
    pub ells: Vec<usize>,
    k_min: f64,
    k_max: f64,
    /// The shells' width of bins (none: the triangles as points).
    pub bin_width: Option<f64>,
    covariance: PathBuf,
}

/// The measurement of a table whose keys are [`DATA_KEYS`] and `own` (the block's).
///
/// # Errors
/// [`Error::InvalidChoice`] naming the key for an unknown key, a missing file, multipoles other than 0, 2,
/// 4, k_max ≤ k_min.
pub(super) fn data_spec(o: &Options, own: &[&str]) -> Result<DataSpec> {
    o.known(&[&DATA_KEYS[..], own].concat())?;
    let ells_of = |k: &str, default: Vec<usize>| -> Result<Vec<usize>> {
        let v = o.counts(k)?.unwrap_or(default);
        if v.is_empty() || v.iter().any(|l| ![0, 2, 4].contains(l)) {
            return Err(o.bad(k, "the bispectrum multipoles are 0, 2, 4"));
        }
        Ok(v)
    };
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
    })
}

/// The triangles of a measurement: those fitted, and all of the file with the fitted ones' indices (a block
/// whose tensors were built for the whole file selects from them).
pub(super) struct Selection {
    /// The fitted triangles (bins of the measurement's width, or points).
    pub fitted: TriangleSet,
    /// Every triangle of the file [h/Mpc].
    pub all: Vec<[f64; 3]>,
    /// The fitted ones' indices among them, increasing.
    pub rows: Vec<usize>,
}

/// The error about `what`.
fn bad(what: String, reason: impl Into<String>) -> Error {
    Error::InvalidChoice {
        what,
        reason: reason.into(),
    }
}

/// The measured multipoles of `spec`'s file at the fitted triangles, with the block `block` makes of their
/// set; `note` ends the header line.
///
/// # Errors
/// [`Error::BadRow`], [`Error::InvalidChoice`] naming the file and the rule for a file not of its layout, a
/// fitted multipole not in the file, no triangle in the range; as `block`.
pub(super) fn measure(
    spec: &DataSpec,
    block: impl FnOnce(Selection) -> Result<Arc<dyn Spec>>,
    note: &str,
) -> Result<Measured> {
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
    let note = format!(
        "data {origin} ({} of its {n_tri} triangles: every side in [{}, {}] h/Mpc{}), joint \
         covariance {} (P then B, cross terms included){note}",
        fitted.len(),
        spec.k_min,
        spec.k_max,
        spec.bin_width
            .map_or(", at the triangles given".into(), |w| format!(
                ", averaged over bins of width {w}"
            )),
        spec.covariance.display(),
    );
    Ok(Measured {
        spec: block(Selection {
            fitted: set,
            all: triangles,
            rows: fitted.clone(),
        })?,
        // the fitted entries: multipole, then triangle
        fitted: b_rows
            .iter()
            .flat_map(|&j| fitted.iter().map(move |&t| j * n_tri + t))
            .collect(),
        columns: table.columns[3..].to_vec(),
        covariance: spec.covariance.clone(),
        layout: format!("{} multipoles x {n_tri} triangles", spec.data_ells.len()),
        note,
    })
}
