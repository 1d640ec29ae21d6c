//! The bispectrum of a data set of an analysis file (`[dataset.bispectrum]`, docs/analysis.md): its
//! measured multipoles, the triangles fitted and the joint covariance of the power spectrum and the
//! bispectrum, made into a [`BispectrumFit`] beside the data set's power spectrum.
//!
//! One declared layout per file: the bispectrum file is `k1 k2 k3` [h/Mpc] then B_ℓ [(Mpc/h)⁶] for
//! each of `data_ells` (the Nseries files' layout); the joint covariance is square over the power
//! spectrum's entries (ℓ-major over the data file's multipoles, every k) then the bispectrum's
//! (ℓ-major over its `data_ells`, every triangle of its file), as the Patchy P + B covariance.

use crate::bispectrum::block::BispectrumBlock;
use crate::bispectrum::{Fog, LegendreSide, PlanRules, TriangleSet};
use crate::error::{Error, Result};
use crate::fit::galaxy::BispectrumFit;
use crate::fit::{DataLayout, MultipoleData};
use crate::linear::LinearSpectrum;
use crate::table::DataColumns;
use std::path::{Path, PathBuf};

/// The bispectrum of a data set, as the analysis file gives it (paths resolved).
#[derive(Debug, Clone, PartialEq)]
pub struct BispectrumSpec {
    /// The measured multipoles: `k1 k2 k3` then B_ℓ per `data_ells`.
    pub data: PathBuf,
    /// The multipoles in the file, in column order (default 0, 2, 4).
    pub data_ells: Vec<usize>,
    /// The fitted multipoles (default 0).
    pub ells: Vec<usize>,
    /// Triangles with every side in [k_min, k_max] are fitted [h/Mpc].
    pub k_min: f64,
    /// Triangles with every side in [k_min, k_max] are fitted [h/Mpc].
    pub k_max: f64,
    /// The width of the measurement's k shells [h/Mpc]: the model is averaged over each bin's
    /// triangles; `None`: evaluated at the triangles given.
    pub bin_width: Option<f64>,
    /// The joint covariance of the power spectrum and the bispectrum (module docs).
    pub covariance: PathBuf,
    /// The number density of the stochastic terms [(h/Mpc)³]; `None`: none (n̄ = ∞).
    pub n_bar: Option<f64>,
}

/// The error of `spec` about `what`.
fn bad(what: String, reason: impl Into<String>) -> Error {
    Error::InvalidChoice {
        what,
        reason: reason.into(),
    }
}

/// The bispectrum of `spec` beside the power spectrum `data` (its fitted multipoles, read from
/// `p_path` with `layout`): `data` with its covariance (the joint file's power-spectrum block), the
/// [`BispectrumFit`] for the tracer's `spectrum` with IR resummation `ir`, and a header line.
///
/// # Errors
/// [`Error::BadRow`], [`Error::InvalidChoice`] naming the file and the rule for a file not of its
/// layout, a fitted multipole not in the file, no triangle in the range, a covariance of the wrong
/// size or not a covariance ([`crate::fit::covariance::validate`]).
pub(super) fn load_bispectrum(
    spec: &BispectrumSpec,
    layout: &DataLayout,
    p_path: &Path,
    data: MultipoleData,
    spectrum: &LinearSpectrum,
    ir: bool,
) -> Result<(MultipoleData, BispectrumFit, String)> {
    let origin = spec.data.display().to_string();
    let text = crate::table::read_text(&spec.data)?;
    let width = 3 + spec.data_ells.len();
    let table = DataColumns::parse_exact(&text, &origin, width)?;
    let n_tri = table.lines.len();
    let triangles: Vec<[f64; 3]> = (0..n_tri)
        .map(|i| std::array::from_fn(|c| table.columns[c][i]))
        .collect();
    let fitted: Vec<usize> = (0..n_tri)
        .filter(|&i| {
            let t = triangles[i];
            t.iter().all(|&k| k >= spec.k_min && k <= spec.k_max)
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
    // the joint covariance: every power-spectrum entry of the data file, then every bispectrum entry
    let full_p = layout.read(p_path, &layout.data_ells)?;
    let n_p = full_p.values.iter().map(Vec::len).sum::<usize>();
    let n_total = n_p + spec.data_ells.len() * n_tri;
    let c_origin = spec.covariance.display().to_string();
    let c_text = crate::table::read_text(&spec.covariance)?;
    let data_lines: Vec<&str> = c_text
        .lines()
        .map(|l| l.split('#').next().unwrap_or(""))
        .filter(|l| !l.trim().is_empty())
        .collect();
    let rows_found = data_lines.len();
    let first_width = data_lines
        .first()
        .map_or(0, |l| l.split_whitespace().count());
    if rows_found != n_total || first_width != n_total {
        return Err(bad(
            c_origin,
            format!(
                "has {rows_found} rows of {first_width} columns: the joint covariance is square, \
                 {n_p} power-spectrum entries ({} multipoles x {} k) then {} bispectrum entries \
                 ({} multipoles x {n_tri} triangles)",
                layout.data_ells.len(),
                full_p.k.len(),
                n_total - n_p,
                spec.data_ells.len()
            ),
        ));
    }
    let c_table = DataColumns::parse_exact(&c_text, &c_origin, n_total)?;
    let c: Vec<Vec<f64>> = (0..n_total)
        .map(|r| (0..n_total).map(|s| c_table.columns[s][r]).collect())
        .collect();
    let mut blocks = full_p.values.clone();
    blocks.extend((0..spec.data_ells.len()).map(|j| table.columns[3 + j].clone()));
    let c = crate::fit::covariance::validate(c, &blocks, &c_origin, &c_table.lines)?;
    let p_block: Vec<Vec<f64>> = c[..n_p].iter().map(|r| r[..n_p].to_vec()).collect();
    let data = layout.attach_covariance(data, p_block)?;
    // the fitted bispectrum entries (multipole, then triangle) and the data's power-spectrum entries
    let b_index: Vec<usize> = b_rows
        .iter()
        .flat_map(|&j| fitted.iter().map(move |&t| n_p + j * n_tri + t))
        .collect();
    let p_index = layout.block_index(&data)?;
    let cross = p_index
        .iter()
        .map(|&a| b_index.iter().map(|&j| c[a][j]).collect())
        .collect();
    let covariance = b_index
        .iter()
        .map(|&i| b_index.iter().map(|&j| c[i][j]).collect())
        .collect();
    let values = b_rows
        .iter()
        .flat_map(|&j| {
            let column = &table.columns[3 + j];
            fitted.iter().map(move |&t| column[t])
        })
        .collect();
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
    let fit = BispectrumFit::new(block, spectrum.clone(), ir, values, cross, covariance)?;
    let line = format!(
        "{}; data {origin} ({} of its {n_tri} triangles: every side in [{}, {}] h/Mpc{}), joint \
         covariance {c_origin} (P then B, cross terms included){}",
        fit.describe(),
        fitted.len(),
        spec.k_min,
        spec.k_max,
        spec.bin_width
            .map_or(", at the triangles given".into(), |w| format!(
                ", averaged over bins of width {w}"
            )),
        if spec.n_bar.is_none() {
            "; no stochastic terms (n_bar not given)"
        } else {
            ""
        }
    );
    Ok((data, fit, line))
}
