//! `pt-spectra fisher`: the Fisher forecast of a redshift survey with the galaxy model `ept`
//! (`pt_spectra::forecast`; the table from `pt_spectra::jobs::forecast_table`).

use crate::output::{check_outputs, write_output};
use crate::progress::Bars;
use anyhow::{bail, Context, Result};
use pt_spectra::forecast::Parameters;
use pt_spectra::jobs::{forecast_table, parse_bin};
use pt_spectra::setup::NamedCosmology;
use pt_spectra::store::TableStore;
use std::path::PathBuf;

/// Arguments of `pt-spectra fisher`.
#[derive(clap::Args, Debug)]
pub struct Args {
    /// A redshift bin, `z=0.57,volume=2.6e9,n_bar=3e-4,k_max=0.15,b1=2` (volume [(Mpc/h)^3], n_bar
    /// [(h/Mpc)^3], k [h/Mpc]; optionally k_min (0.01), dk (0.01), b_k_max (the bispectrum monopole of
    /// the shells' triangle bins up to it, with c1, b_shot, a_shot free) and fiducial nuisance values
    /// b2, bs, b3, alpha0 … sn4, c1, b_shot, p_shot, a_shot, else 0 (b_shot 1)); repeat for several bins.
    #[arg(long = "bin", value_name = "KEY=VALUE,...", required = true)]
    bins: Vec<String>,
    /// `template`: f, apar, aperp per bin (and sigma(fsigma8)); `cosmology`: omega_cdm, omega_b, h,
    /// logA, n_s shared by the bins.
    #[arg(long, value_name = "KIND", default_value = "template")]
    parameters: String,
    /// The fiducial cosmology: gm2012, planck2018 or a CAMB/CLASS parameter file (A_s-normalised for
    /// `--parameters cosmology`).
    #[arg(long, value_name = "NAME|FILE", default_value = "planck2018")]
    cosmology: String,
    /// The measured multipoles of every bin.
    #[arg(long, value_name = "L,...", default_value = "0,2")]
    ells: String,
    /// The free nuisance parameters of every bin (the others fixed at their fiducial values).
    #[arg(
        long,
        value_name = "NAME,...",
        default_value = "b1,b2,bs,alpha0,alpha2,sn"
    )]
    free: String,
    /// A Gaussian prior NAME:SIGMA on a cosmological parameter (e.g. `omega_b:0.00037`, BBN); repeat.
    #[arg(long, value_name = "NAME:SIGMA")]
    prior: Vec<String>,
    /// The table store of the basis tensors (default $PT_SPECTRA_CACHE or ~/.cache/pt-spectra).
    #[arg(long, value_name = "DIR")]
    cache_dir: Option<PathBuf>,
    /// Write the table to this file instead of standard output.
    #[arg(long, value_name = "FILE")]
    out: Option<PathBuf>,
}

/// Runs the subcommand.
pub fn run(args: &Args) -> Result<()> {
    check_outputs(&[("--out", args.out.as_deref())], &[])?;
    let parameters = match args.parameters.as_str() {
        "template" => Parameters::Template,
        "cosmology" => Parameters::Cosmology,
        other => bail!("--parameters {other}: valid are template, cosmology"),
    };
    let ells: Vec<usize> = crate::common::list(&args.ells, "--ells")?;
    let free: Vec<String> = args.free.split(',').map(|s| s.trim().to_string()).collect();
    let bins = args
        .bins
        .iter()
        .map(|b| parse_bin(b, &ells, &free).context("--bin"))
        .collect::<Result<Vec<_>>>()?;
    let priors = args
        .prior
        .iter()
        .map(|p| {
            let (name, sigma) = p
                .split_once(':')
                .with_context(|| format!("--prior {p}: expected NAME:SIGMA"))?;
            let sigma: f64 = sigma
                .trim()
                .parse()
                .with_context(|| format!("--prior {p}: `{sigma}` is not a number"))?;
            Ok((name.trim().to_string(), sigma))
        })
        .collect::<Result<Vec<_>>>()?;
    let (fiducial, _) =
        NamedCosmology::parse(&args.cosmology).map_err(|e| anyhow::anyhow!("--cosmology: {e}"))?;
    let store = match &args.cache_dir {
        Some(dir) => TableStore::new(dir),
        None => TableStore::from_env(),
    };
    let (table, _) = forecast_table(
        &bins,
        &fiducial,
        parameters,
        &priors,
        &store,
        &Bars::default(),
    )?;
    write_output(args.out.as_ref(), &table)
}
