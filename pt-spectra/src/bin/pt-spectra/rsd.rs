//! `pt-spectra rsd`: redshift-space multipoles P_ℓ(k) of a real-space model through an RSD model.

use crate::common::{list, BiasArgs, NoiseArgs};
use crate::input::Input;
use crate::progress::Bars;
use crate::real::write_output;
use anyhow::{bail, Result};
use pt_spectra::halo::crossings;
use pt_spectra::real::RealModel;
use pt_spectra::rsd::{fog_sigma, multipoles, Fog, RsdModel, RsdPlan, RsdSettings, Sigma0};
use std::path::PathBuf;

/// Signal-to-noise levels whose crossings are reported (the paper's table_noise).
const SN_LEVELS: [f64; 3] = [1.0, 0.5, 0.1];

/// A name through the library's `FromStr`, for clap.
pub fn parsed<T: std::str::FromStr<Err = pt_spectra::error::Error>>(
    s: &str,
) -> std::result::Result<T, String> {
    s.parse()
        .map_err(|e: pt_spectra::error::Error| e.to_string())
}

/// Arguments of `pt-spectra rsd`.
#[derive(clap::Args, Debug)]
pub struct Args {
    #[command(flatten)]
    input: Input,
    /// Real-space model for P_δδ, P_δθ, P_θθ: linear, 1l-spt, 2l-spt, 1l-rpt-n0..n3 or 2l-rpt-n0..n3.
    #[arg(long = "real", value_name = "M", default_value = "1l-rpt-n1", value_parser = parsed::<RealModel>)]
    real_model: RealModel,
    /// Redshift-space model: kaiser, scoccimarro or tns (Scoccimarro + the A and B terms of Taruya,
    /// Nishimichi & Saito 2010 at leading order).
    #[arg(long, value_name = "MODEL", default_value = "tns", value_parser = parsed::<RsdModel>)]
    rsd: RsdModel,
    /// Growth rate f. Default: f(z) of the cosmology.
    #[arg(long, value_name = "F", allow_hyphen_values = true)]
    f: Option<f64>,
    /// Fingers-of-God damping: none, lorentzian or gaussian (P^s → P^s D², D of kμσ0 D(z) f).
    #[arg(long, value_name = "KIND", default_value = "none", value_parser = parsed::<Fog>)]
    fog: Fog,
    /// σ0 of the damping [Mpc/h] (its z = 0 value; scaled by D(z) f), or its theory value σ(z)/D(z) from
    /// eq. sigmav, σ² = (1/6π²)∫P_θθ dq, with linear (`lin`) or 1-loop SPT (`1l-spt`) P_θθ.
    #[arg(
        long,
        value_name = "S",
        default_value = "0",
        allow_hyphen_values = true,
        value_parser = parsed::<Sigma0>
    )]
    sigma0: Sigma0,
    #[command(flatten)]
    bias: BiasArgs,
    #[command(flatten)]
    noise: NoiseArgs,
    /// Multipoles to print, even ℓ ≤ 8, comma separated.
    #[arg(long, value_name = "L,L,…", default_value = "0,2,4")]
    ells: String,
    /// Add the multipoles of the parts: P<l>_sc (Kaiser or Scoccimarro part), P<l>_A, P<l>_B (TNS terms).
    #[arg(long)]
    terms: bool,
    /// Write the table to this file instead of standard output.
    #[arg(long, value_name = "FILE")]
    out: Option<PathBuf>,
}

/// Runs the subcommand.
pub fn run(args: &Args) -> Result<()> {
    let (real, rsd, fog) = (args.real_model, args.rsd, args.fog);
    let ells: Vec<usize> = list(&args.ells, "--ells")?;
    pt_spectra::rsd::MultipoleRule::new(&ells)?;
    let (bias, noise) = (args.bias.bias()?, args.noise.noise()?);
    let (k, loaded) = args.input.load()?;
    let (prepared, precision) = (&loaded.prepared, &loaded.precision);
    let z = args.input.z();
    let f = args.f.unwrap_or(prepared.growth_rate);
    if !f.is_finite() {
        bail!("--f {f}: must be finite");
    }
    let b = bias.values(&k, args.bias.amplitude)?;
    let p_eps = noise.values(&k)?;
    let growth = prepared.growth_factor;
    let sigma0 = args.sigma0.resolve(&prepared.spectrum, growth, precision)?;
    let sigma = fog_sigma(sigma0, growth, f);
    let bars = Bars::default();
    let plan = RsdPlan::new(&k, real, rsd, precision, &loaded.store, &bars)?;
    let (spectra, tns) = plan.evaluate(&prepared.spectrum, &bars)?;
    let settings = RsdSettings {
        model: rsd,
        f,
        bias: b,
        fog,
        sigma,
        noise: p_eps,
        ells,
        parts: args.terms,
    };
    let m = multipoles(&spectra, tns.as_ref(), &settings)?;

    let mut header = vec![format!(
        "pt-spectra {} rsd: {rsd} with real-space {real}, z = {z}, f = {f}, {} times A_b = {}, \
         FoG {fog:?} with sigma0 = {} Mpc/h (sigma = sigma0 D(z) f = {sigma:.6} Mpc/h)",
        env!("CARGO_PKG_VERSION"),
        args.bias.describe(),
        args.bias.amplitude,
        sigma0
    )];
    header.extend(loaded.describe());
    if rsd.needs_tns() {
        header.push(
            "TNS A and B at leading order (linear P, tree-level bispectrum), A = b^3 A(f/b), B = b^4 B(f/b)"
                .into(),
        );
    }
    header.push(
        "P_l = (2l+1) int_0^1 dmu P^s(k,mu) L_l(mu), noise-subtracted; err_P_l bounds the numerical \
         error (loop integrals and mu quadrature)"
            .into(),
    );
    if let Some(sn) = &m.signal_to_noise {
        header.push(crossing_line(&k, sn));
    }
    write_output(args.out.as_ref(), &m.table(header).to_text())
}

/// Where the signal-to-noise falls to each of [`SN_LEVELS`].
fn crossing_line(k: &[f64], sn: &[f64]) -> String {
    let mut text = "signal-to-noise SN = P0/P_eps falls to".to_string();
    for (level, c) in SN_LEVELS.iter().zip(crossings(k, sn, &SN_LEVELS)) {
        match c {
            Some(kc) => text += &format!(" {level} at k = {kc:.4}"),
            None if sn[0] < *level => text += &format!(" {level}: below it at every k"),
            None => text += &format!(" {level}: not within the k range"),
        }
        text.push(';');
    }
    text
}
