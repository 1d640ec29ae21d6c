//! `pt-spectra halo`: b(k) = P_mh/P_mm and P_εε = P_hh − P_mh²/P_mm from measured spectra.

use crate::output::{check_outputs, write_output};
use anyhow::{bail, Context, Result};
use pt_spectra::halo::MeasuredSpectrum;
use pt_spectra::jobs::{halo_table, HaloRequest};
use std::path::PathBuf;

/// Arguments of `pt-spectra halo`.
#[derive(clap::Args, Debug)]
pub struct Args {
    /// The measured matter power spectrum P_mm (k [h/Mpc], P [(Mpc/h)^3], optional 1σ error).
    #[arg(long, value_name = "FILE")]
    pmm: PathBuf,
    /// The measured matter–halo cross spectrum P_mh, on the k of --pmm.
    #[arg(long, value_name = "FILE")]
    pmh: PathBuf,
    /// The measured halo spectrum P_hh, noise included, on the k of --pmm.
    #[arg(long, value_name = "FILE")]
    phh: PathBuf,
    /// 1-based columns of k, P and optionally its 1σ error in all three files, e.g. `1,2,3`: with an
    /// error column the errors of b and P_εε are propagated (err_b, err_P_eps).
    #[arg(long, value_name = "K,P[,E]", default_value = "1,2")]
    columns: String,
    /// Halo number density n_h [(h/Mpc)^3]: adds P_eps_n = P_εε n_h, the ratio to Poisson noise 1/n_h.
    #[arg(long, value_name = "N", allow_hyphen_values = true)]
    number_density: Option<f64>,
    /// Write the table to this file instead of standard output.
    #[arg(long, value_name = "FILE")]
    out: Option<PathBuf>,
}

/// `K,P[,E]` (1-based) as 0-based (k, P, error) columns.
fn columns(s: &str) -> Result<(usize, usize, Option<usize>)> {
    let c: Vec<usize> = s
        .split(',')
        .map(|x| match x.trim().parse::<usize>() {
            Ok(n) if n >= 1 => Ok(n - 1),
            _ => bail!("--columns {s}: `{x}` is not a column number (1, 2, …)"),
        })
        .collect::<Result<_>>()?;
    match c[..] {
        [k, p] if k != p => Ok((k, p, None)),
        [k, p, e] if k != p && k != e && p != e => Ok((k, p, Some(e))),
        _ => bail!("--columns {s}: expected two or three different 1-based columns K,P[,E]"),
    }
}

/// Runs the subcommand.
pub fn run(args: &Args) -> Result<()> {
    let inputs = [
        ("--pmm", Some(args.pmm.as_path())),
        ("--pmh", Some(args.pmh.as_path())),
        ("--phh", Some(args.phh.as_path())),
    ];
    check_outputs(&[("--out", args.out.as_deref())], &inputs)?;
    let cols = columns(&args.columns)?;
    let read = |path: &PathBuf, name: &'static str, option: &str| {
        MeasuredSpectrum::read(path, name, cols).with_context(|| option.to_string())
    };
    let request = HaloRequest {
        pmm: read(&args.pmm, "P_mm", "--pmm")?,
        pmh: read(&args.pmh, "P_mh", "--pmh")?,
        phh: read(&args.phh, "P_hh", "--phh")?,
        number_density: args.number_density,
    };
    let table = halo_table(&request)?;
    write_output(args.out.as_ref(), &table)
}
