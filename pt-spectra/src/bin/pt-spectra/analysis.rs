//! `pt-spectra fit --analysis FILE.toml`: the joint fit of several data sets (docs/analysis.md).

use crate::ept::RsdChoice;
use crate::input::SpectrumInput;
use crate::output::{check_outputs, write_output};
use crate::progress::Bars;
use anyhow::{bail, Result};
use std::path::{Path, PathBuf};

/// Reads the analysis file at `path`, fits it with the spectrum of `spectrum` (at each set's z) and
/// writes the table to `out` (standard output if `None`).
pub fn run(
    path: &Path,
    spectrum: &SpectrumInput,
    rsd: RsdChoice,
    out: Option<&Path>,
) -> Result<()> {
    // The analysis fits the galaxy model: --rsd ept, or --rsd left at its default.
    let default: RsdChoice = pt_spectra::jobs::defaults::RSD_MODEL.parse()?;
    if rsd != RsdChoice::Ept && rsd != default {
        bail!("--analysis fits the galaxy model: give --rsd ept (or no --rsd), not another model");
    }
    let analysis = pt_spectra::jobs::analysis::read_analysis(path)?;
    let mut inputs = spectrum.files();
    inputs.push(("--analysis", Some(path)));
    let data: Vec<(&'static str, Option<&Path>)> = analysis
        .sets
        .iter()
        .flat_map(|s| {
            [
                ("a data file of --analysis", Some(s.data.as_path())),
                ("a covariance of --analysis", s.covariance.as_deref()),
                ("a window of --analysis", s.window.as_deref()),
            ]
        })
        .collect();
    inputs.extend(data);
    check_outputs(&[("--out", out)], &inputs)?;
    let first = spectrum.load_at(analysis.sets[0].z, "z of the first data set")?;
    let prepare = |z: f64| {
        spectrum
            .load_at(z, "z of a data set")
            .map(|l| l.prepared)
            .map_err(|e| pt_spectra::error::Error::InvalidChoice {
                what: format!("the linear spectrum at z = {z}"),
                reason: e.to_string(),
            })
    };
    let bars = Bars::default();
    let inputs = pt_spectra::jobs::Inputs {
        prepare: &prepare,
        precision: &first.precision,
        store: &first.store,
        progress: &bars,
    };
    let mut header = vec![format!(
        "pt-spectra {} fit --analysis {}: ept (velocileptors' REPT conventions) jointly to every data \
         set of the file",
        pt_spectra::jobs::VERSION,
        path.display()
    )];
    header.extend(pt_spectra::jobs::describe_inputs(
        &first.prepared,
        &first.precision,
    ));
    let (table, _) = pt_spectra::jobs::joint_fit_table(&analysis, &inputs, header)?;
    write_output(out.map(PathBuf::from).as_ref(), &table)
}
