//! `pt-spectra rsd`: redshift-space multipoles P_ℓ(k) of a real-space model through an RSD model.

use crate::real::{loop_terms, write_output, Input};
use anyhow::{bail, Context, Result};
use pt_spectra::cosmology::Cosmology;
use pt_spectra::real::{from_terms, RealModel};
use pt_spectra::rsd::{fog_sigma, Fog, MultipoleRule, RsdModel};
use std::path::PathBuf;

/// Arguments of `pt-spectra rsd`.
#[derive(clap::Args, Debug)]
pub struct Args {
    #[command(flatten)]
    input: Input,
    /// Real-space model for P_δδ, P_δθ, P_θθ: linear, 1l-spt, 1l-rpt-n0 or 1l-rpt-n1.
    #[arg(long = "real", value_name = "M", default_value = "1l-rpt-n1")]
    real_model: String,
    /// Redshift-space model: kaiser or scoccimarro.
    #[arg(long, value_name = "MODEL", default_value = "scoccimarro")]
    rsd: String,
    /// Growth rate f. Default: f(z) of the gm2012 cosmology.
    #[arg(long, value_name = "F", allow_hyphen_values = true)]
    f: Option<f64>,
    /// Fingers-of-God damping: none, lorentzian or gaussian (P^s → P^s D², D of kμσ0 D(z) f).
    #[arg(long, value_name = "KIND", default_value = "none")]
    fog: String,
    /// σ0 of the damping [Mpc/h] (its z = 0 value; scaled by D(z) f).
    #[arg(
        long,
        value_name = "S",
        default_value_t = 0.0,
        allow_hyphen_values = true
    )]
    sigma0: f64,
    /// Constant linear bias b.
    #[arg(
        long,
        value_name = "B",
        default_value_t = 1.0,
        allow_hyphen_values = true
    )]
    bias: f64,
    /// Multipoles to print, even ℓ ≤ 8, comma separated.
    #[arg(long, value_name = "L,L,…", default_value = "0,2,4")]
    ells: String,
    /// Write the table to this file instead of standard output.
    #[arg(long, value_name = "FILE")]
    out: Option<PathBuf>,
}

fn parse_ells(s: &str) -> Result<Vec<usize>> {
    s.split(',')
        .map(|x| {
            x.trim()
                .parse::<usize>()
                .with_context(|| format!("--ells: `{x}` is not a multipole order"))
        })
        .collect()
}

/// Runs the subcommand.
pub fn run(args: &Args) -> Result<()> {
    let real: RealModel = args.real_model.parse()?;
    let rsd: RsdModel = args.rsd.parse()?;
    let fog: Fog = args.fog.parse()?;
    let ells = parse_ells(&args.ells)?;
    let rule = MultipoleRule::new(&ells)?;
    let (k, spectrum, precision) = args.input.load()?;
    let cosmology = Cosmology::gm2012();
    let z = args.input.z;
    let f = args.f.unwrap_or_else(|| cosmology.growth_rate(z));
    for (name, v) in [("--f", f), ("--bias", args.bias)] {
        if !v.is_finite() {
            bail!("{name} {v}: must be finite");
        }
    }
    if !(args.sigma0.is_finite() && args.sigma0 >= 0.0) {
        bail!("--sigma0 {}: must be finite and non-negative", args.sigma0);
    }
    let sigma = fog_sigma(args.sigma0, cosmology.growth_factor(z), f);
    let spectra = from_terms(real, &loop_terms(&k, &precision, &spectrum)?);

    let mut text = format!(
        "# pt-spectra {} rsd: {rsd} with real-space {real}, z = {z}, f = {f}, b = {}, FoG {fog:?} with \
         sigma0 = {} Mpc/h (sigma = sigma0 D(z) f = {sigma:.6} Mpc/h)\n",
        env!("CARGO_PKG_VERSION"),
        args.bias,
        args.sigma0
    );
    text += &args.input.describe(&spectrum, &precision);
    text += "# P_l = (2l+1) int_0^1 dmu P^s(k,mu) L_l(mu); err_P_l bounds the numerical error (loop integrals \
             and mu quadrature); k [h/Mpc], P [(Mpc/h)^3]\n# k";
    for l in &ells {
        text += &format!(" P{l}");
    }
    for l in &ells {
        text += &format!(" err_P{l}");
    }
    text.push('\n');
    for (i, &ki) in k.iter().enumerate() {
        let values = |j: usize| spectra.spectra[j][i].value;
        let errors = |j: usize| spectra.spectra[j][i].error;
        let c = rsd.coefficients(args.bias, f, [values(0), values(1), values(2)]);
        let dc = rsd.coefficients(args.bias.abs(), f.abs(), [errors(0), errors(1), errors(2)]);
        let p = rule.evaluate(&c, fog, ki * sigma);
        let mut row = vec![ki];
        row.extend(p.iter().map(|e| e.value));
        // |L_l| ≤ 1 and 0 < mu^2n D² ≤ 1 on [0, 1], so an error δc_n moves P_l by at most (2l+1) Σ|δc_n|.
        let spread: f64 = dc.iter().sum();
        row.extend(
            p.iter()
                .zip(&ells)
                .map(|(e, &l)| e.error + (2 * l + 1) as f64 * spread),
        );
        let line: Vec<String> = row.iter().map(|v| format!("{v:.9e}")).collect();
        text += &line.join(" ");
        text.push('\n');
    }
    write_output(args.out.as_ref(), &text)
}
