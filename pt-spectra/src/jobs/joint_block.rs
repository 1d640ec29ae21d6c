//! A block after a data set's power spectrum in an analysis file (`[dataset.<kind name>]`,
//! docs/analysis.md): its measurement read by its kind ([`crate::statistic::AnalysisFace`]) and the
//! joint covariance of the power spectrum and the block, made into a [`BlockFit`] beside the data
//! set's power spectrum.
//!
//! The joint covariance is square over the power spectrum's entries (ℓ-major over the data file's
//! multipoles, every k) then every entry of the block's file, in the order of its
//! [`crate::statistic::Measured::columns`].

use crate::error::{Error, Result};
use crate::fit::galaxy::BlockFit;
use crate::fit::{DataLayout, MultipoleData};
use crate::linear::LinearSpectrum;
use crate::statistic::{Kind, Options};
use crate::table::DataColumns;
use std::path::Path;

/// The error of `spec` about `what`.
fn bad(what: String, reason: impl Into<String>) -> Error {
    Error::InvalidChoice {
        what,
        reason: reason.into(),
    }
}

/// The block of `kind` with `options` beside the power spectrum `data` (its fitted multipoles, read
/// from `p_path` with `layout`): `data` with its covariance (the joint file's power-spectrum block),
/// the [`BlockFit`] for the tracer's `spectrum` with IR resummation `ir`, and a header line.
///
/// # Errors
/// [`Error::InvalidChoice`] for a kind without an analysis face; as its measurement; naming the
/// file and the rule for a covariance of the wrong size or not a covariance
/// ([`crate::fit::covariance::validate`]).
pub(super) fn load_block(
    kind: &'static Kind,
    options: &Options,
    layout: &DataLayout,
    p_path: &Path,
    data: MultipoleData,
    spectrum: &LinearSpectrum,
    ir: bool,
) -> Result<(MultipoleData, BlockFit, String)> {
    let face = kind
        .faces
        .analysis
        .ok_or_else(|| options.bad("", format!("a {} block cannot be fitted", kind.name)))?;
    let measured = (face.measure)(options)?;
    // the joint covariance: every power-spectrum entry of the data file, then every block entry
    let full_p = layout.read(p_path, &layout.data_ells)?;
    let n_p = full_p.values.iter().map(Vec::len).sum::<usize>();
    let n_b: usize = measured.columns.iter().map(Vec::len).sum();
    let n_total = n_p + n_b;
    let c_origin = measured.covariance.display().to_string();
    let c_text = crate::table::read_text(&measured.covariance)?;
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
                 {n_p} power-spectrum entries ({} multipoles x {} k) then {n_b} {} entries ({})",
                layout.data_ells.len(),
                full_p.k.len(),
                kind.name,
                measured.layout
            ),
        ));
    }
    let c_table = DataColumns::parse_exact(&c_text, &c_origin, n_total)?;
    let c: Vec<Vec<f64>> = (0..n_total)
        .map(|r| (0..n_total).map(|s| c_table.columns[s][r]).collect())
        .collect();
    let mut blocks = full_p.values.clone();
    blocks.extend(measured.columns.iter().cloned());
    let c = crate::fit::covariance::validate(c, &blocks, &c_origin, &c_table.lines)?;
    let p_block: Vec<Vec<f64>> = c[..n_p].iter().map(|r| r[..n_p].to_vec()).collect();
    let data = layout.attach_covariance(data, p_block)?;
    // the fitted block entries and the data's power-spectrum entries
    let b_index: Vec<usize> = measured.fitted.iter().map(|&i| n_p + i).collect();
    let p_index = layout.block_index(&data)?;
    let cross = p_index
        .iter()
        .map(|&a| b_index.iter().map(|&j| c[a][j]).collect())
        .collect();
    let covariance = b_index
        .iter()
        .map(|&i| b_index.iter().map(|&j| c[i][j]).collect())
        .collect();
    let flat: Vec<f64> = measured.columns.concat();
    if measured.fitted.is_empty() || measured.fitted.iter().any(|&i| i >= n_b) {
        return Err(bad(
            format!("the {} entries fitted", kind.name),
            format!("must be among the {n_b} of its file, at least one"),
        ));
    }
    let values = measured.fitted.iter().map(|&i| flat[i]).collect();
    let fit = BlockFit::new(
        measured.spec.as_ref(),
        spectrum.clone(),
        ir,
        values,
        cross,
        covariance,
    )?;
    let line = format!("{}; {}", fit.describe(), measured.note);
    Ok((data, fit, line))
}
