//! `pt-spectra rsd`: redshift-space multipoles P_ℓ(k) of a real-space model through an RSD model.

use crate::common::{list, BiasArgs, NoiseArgs};
use crate::real::{loop_terms, write_output, Input};
use anyhow::{bail, Result};
use pt_spectra::cosmology::Cosmology;
use pt_spectra::halo::crossings;
use pt_spectra::loops::TnsPlan;
use pt_spectra::real::{from_terms, RealModel};
use pt_spectra::rsd::{
    dispersion_theory, fog_sigma, DispersionInput, Fog, MultipoleRule, RsdModel,
};
use std::path::PathBuf;

/// Signal-to-noise levels whose crossings are reported (the paper's table_noise).
const SN_LEVELS: [f64; 3] = [1.0, 0.5, 0.1];

/// Arguments of `pt-spectra rsd`.
#[derive(clap::Args, Debug)]
pub struct Args {
    #[command(flatten)]
    input: Input,
    /// Real-space model for P_δδ, P_δθ, P_θθ: linear, 1l-spt, 2l-spt, 1l-rpt-n0..n2 or 2l-rpt-n0..n2.
    #[arg(long = "real", value_name = "M", default_value = "1l-rpt-n1")]
    real_model: String,
    /// Redshift-space model: kaiser, scoccimarro or tns (Scoccimarro + the A and B terms of Taruya,
    /// Nishimichi & Saito 2010 at leading order).
    #[arg(long, value_name = "MODEL", default_value = "tns")]
    rsd: String,
    /// Growth rate f. Default: f(z) of the gm2012 cosmology.
    #[arg(long, value_name = "F", allow_hyphen_values = true)]
    f: Option<f64>,
    /// Fingers-of-God damping: none, lorentzian or gaussian (P^s → P^s D², D of kμσ0 D(z) f).
    #[arg(long, value_name = "KIND", default_value = "none")]
    fog: String,
    /// σ0 of the damping [Mpc/h] (its z = 0 value; scaled by D(z) f), or its theory value σ(z)/D(z) from
    /// eq. sigmav, σ² = (1/6π²)∫P_θθ dq, with linear (`lin`) or 1-loop SPT (`1l-spt`) P_θθ.
    #[arg(
        long,
        value_name = "S",
        default_value = "0",
        allow_hyphen_values = true
    )]
    sigma0: String,
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
    let real: RealModel = args.real_model.parse()?;
    let rsd: RsdModel = args.rsd.parse()?;
    let fog: Fog = args.fog.parse()?;
    let ells: Vec<usize> = list(&args.ells, "--ells")?;
    let rule = MultipoleRule::new(&ells)?;
    let monopole = MultipoleRule::new(&[0])?;
    let (bias, noise) = (args.bias.bias()?, args.noise.noise()?);
    let (k, spectrum, precision) = args.input.load()?;
    let cosmology = Cosmology::gm2012();
    let z = args.input.z();
    let f = args.f.unwrap_or_else(|| cosmology.growth_rate(z));
    if !f.is_finite() {
        bail!("--f {f}: must be finite");
    }
    let b = bias.values(&k, args.bias.amplitude)?;
    let p_eps = noise.values(&k)?;
    let growth = cosmology.growth_factor(z);
    let sigma0 = match args.sigma0.trim() {
        "lin" => dispersion_theory(&spectrum, DispersionInput::Linear, &precision)?.value / growth,
        "1l-spt" => {
            dispersion_theory(&spectrum, DispersionInput::OneLoopSpt, &precision)?.value / growth
        }
        s => match s.parse::<f64>() {
            Ok(v) if v.is_finite() && v >= 0.0 => v,
            _ => bail!(
                "--sigma0 {s}: must be a finite non-negative number [Mpc/h], `lin` or `1l-spt`"
            ),
        },
    };
    let sigma = fog_sigma(sigma0, growth, f);
    let spectra = from_terms(real, &loop_terms(&k, &precision, &spectrum, real)?)?;
    let tns = if rsd.needs_tns() {
        Some(TnsPlan::new(&k, &precision)?.par_evaluate(&spectrum))
    } else {
        None
    };

    let bias_text = args.bias.describe();
    let mut text = format!(
        "# pt-spectra {} rsd: {rsd} with real-space {real}, z = {z}, f = {f}, {bias_text} times A_b = {}, \
         FoG {fog:?} with sigma0 = {} Mpc/h (sigma = sigma0 D(z) f = {sigma:.6} Mpc/h)\n",
        env!("CARGO_PKG_VERSION"),
        args.bias.amplitude,
        sigma0
    );
    text += &args.input.describe(&spectrum, &precision);
    if rsd.needs_tns() {
        text += "# TNS A and B at leading order (linear P, tree-level bispectrum), A = b^3 A(f/b), B = b^4 B(f/b)\n";
    }
    text += "# P_l = (2l+1) int_0^1 dmu P^s(k,mu) L_l(mu), noise-subtracted; err_P_l bounds the numerical \
             error (loop integrals and mu quadrature); k [h/Mpc], P [(Mpc/h)^3]\n";

    let mut rows = Vec::with_capacity(k.len());
    let mut signal_to_noise = Vec::with_capacity(k.len());
    for (i, &ki) in k.iter().enumerate() {
        let s = [0, 1, 2].map(|j| spectra.spectra[j][i]);
        let parts = rsd.parts(b[i], f, s, tns.as_ref().map(|t| &t.coefficients[i]))?;
        let total = rule.evaluate_polynomial(&parts.total(), fog, ki * sigma);
        let mut row = vec![ki];
        row.extend(total.iter().map(|e| e.value));
        if args.terms {
            for part in [parts.base, parts.a, parts.b] {
                let p = rule.evaluate_polynomial(&part, fog, ki * sigma);
                row.extend(p.iter().map(|e| e.value));
            }
        }
        if let Some(p_eps) = &p_eps {
            let p0 = monopole.evaluate_polynomial(&parts.total(), fog, ki * sigma)[0].value;
            row.extend([p_eps[i], p0 / p_eps[i]]);
            signal_to_noise.push(p0 / p_eps[i]);
        }
        row.extend(total.iter().map(|e| e.error));
        rows.push(row);
    }
    if p_eps.is_some() {
        text += "# signal-to-noise SN = P0/P_eps falls to";
        for (level, c) in SN_LEVELS
            .iter()
            .zip(crossings(&k, &signal_to_noise, &SN_LEVELS))
        {
            match c {
                Some(kc) => text += &format!(" {level} at k = {kc:.4}"),
                None if signal_to_noise[0] < *level => {
                    text += &format!(" {level}: below it at every k")
                }
                None => text += &format!(" {level}: not within the k range"),
            }
            text.push(';');
        }
        text.push('\n');
    }
    text += "# k";
    for l in &ells {
        text += &format!(" P{l}");
    }
    if args.terms {
        for part in ["sc", "A", "B"] {
            for l in &ells {
                text += &format!(" P{l}_{part}");
            }
        }
    }
    if p_eps.is_some() {
        text += " P_eps SN";
    }
    for l in &ells {
        text += &format!(" err_P{l}");
    }
    text.push('\n');
    for row in rows {
        let line: Vec<String> = row.iter().map(|v| format!("{v:.9e}")).collect();
        text += &line.join(" ");
        text.push('\n');
    }
    write_output(args.out.as_ref(), &text)
}
