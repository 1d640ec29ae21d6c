//! Option groups and parsers shared by the subcommands.

use anyhow::{Context, Result};
use pt_spectra::halo::{Bias, Noise};
use pt_spectra::table::Tabulated;
use std::path::{Path, PathBuf};

/// The halo bias b(k) and its amplitude A_b.
#[derive(clap::Args, Debug)]
pub struct BiasArgs {
    /// Constant linear bias b.
    #[arg(
        long,
        value_name = "B",
        default_value_t = 1.0,
        allow_hyphen_values = true,
        conflicts_with = "bias_file"
    )]
    bias: f64,
    /// Scale-dependent bias b(k) from a table: k [h/Mpc] in column 1 and b in the column named `b` on
    /// a `# k …` names line (as `halo` writes), else column 2; interpolated in ln k, not extrapolated.
    #[arg(long, value_name = "FILE")]
    bias_file: Option<PathBuf>,
    /// Bias amplitude A_b: b(k) → A_b b(k) (in `fit`: its start value if free, its value if fixed).
    #[arg(
        long,
        value_name = "A",
        default_value_t = 1.0,
        allow_hyphen_values = true
    )]
    pub amplitude: f64,
}

impl BiasArgs {
    /// Whether any of the options differs from its default (b = 1, no table, A_b = 1).
    pub fn is_set(&self) -> bool {
        self.bias != 1.0 || self.bias_file.is_some() || self.amplitude != 1.0
    }

    /// The file these options read, by option.
    pub fn files(&self) -> Vec<(&'static str, Option<&Path>)> {
        vec![("--bias-file", self.bias_file.as_deref())]
    }

    /// The bias the options give.
    pub fn bias(&self) -> Result<Bias> {
        Ok(match &self.bias_file {
            Some(path) => {
                Bias::Table(Tabulated::read_column(path, "b(k)", "b", true).context("--bias-file")?)
            }
            None => Bias::Constant(self.bias),
        })
    }
}

/// The stochasticity P_εε.
#[derive(clap::Args, Debug)]
pub struct NoiseArgs {
    /// Constant stochasticity P_εε [(Mpc/h)^3]. `rsd`: its models are of the noise-subtracted spectrum
    /// P^s_hh = ⟨δ_h δ_h⟩ − P_εε, so P_εε is not added to or subtracted from them; it adds the columns
    /// P_eps, SN = P_hh/P_εε = b² P_δδ/P_εε (real space, the paper's signal-to-noise) and SN_s = P0/P_εε
    /// and the k where each falls to 1, 0.5 and 0.1. `fit`: subtracted from the measured monopole
    /// (P_εε changes only the monopole).
    #[arg(long, value_name = "P", allow_hyphen_values = true, conflicts_with_all = ["number_density", "noise_file"])]
    shot_noise: Option<f64>,
    /// Poisson stochasticity P_εε = 1/n_h for the halo number density n_h [(h/Mpc)^3].
    #[arg(
        long,
        value_name = "N",
        allow_hyphen_values = true,
        conflicts_with = "noise_file"
    )]
    number_density: Option<f64>,
    /// P_εε(k) from a table: k [h/Mpc] in column 1 and P_εε [(Mpc/h)^3] in the column named `P_eps`
    /// on a `# k …` names line (as `halo` writes), else column 2.
    #[arg(long, value_name = "FILE")]
    noise_file: Option<PathBuf>,
}

impl NoiseArgs {
    /// Whether any noise option is given.
    pub fn is_set(&self) -> bool {
        self.shot_noise.is_some() || self.number_density.is_some() || self.noise_file.is_some()
    }

    /// The file these options read, by option.
    pub fn files(&self) -> Vec<(&'static str, Option<&Path>)> {
        vec![("--noise-file", self.noise_file.as_deref())]
    }

    /// The noise the options give.
    pub fn noise(&self) -> Result<Noise> {
        Ok(
            match (&self.noise_file, self.shot_noise, self.number_density) {
                (Some(path), _, _) => Noise::Table(
                    Tabulated::read_column(path, "P_eps(k)", "P_eps", true)
                        .context("--noise-file")?,
                ),
                (None, Some(p), _) => Noise::Constant(p),
                (None, None, Some(n)) => Noise::poisson(n).context("--number-density")?,
                (None, None, None) => Noise::None,
            },
        )
    }
}

/// A name through the library's `FromStr`, for clap.
pub fn parsed<T: std::str::FromStr<Err = pt_spectra::error::Error>>(
    s: &str,
) -> std::result::Result<T, String> {
    s.parse()
        .map_err(|e: pt_spectra::error::Error| e.to_string())
}

/// The EFT counterterm c_s² [(Mpc/h)²] of `--cs2`: a finite number.
pub fn parse_cs2(s: &str) -> std::result::Result<f64, String> {
    let v: f64 = s
        .trim()
        .parse()
        .map_err(|_| format!("`{s}` is not a number (c_s^2 in (Mpc/h)^2)"))?;
    pt_spectra::real::check_cs2(v).map_err(|e| e.to_string())?;
    Ok(v)
}

/// A comma-separated list; `what` names the option in messages.
pub fn list<T: std::str::FromStr>(s: &str, what: &str) -> Result<Vec<T>> {
    s.split(',')
        .map(|x| {
            x.trim()
                .parse::<T>()
                .map_err(|_| anyhow::anyhow!("{what}: `{x}` is not valid"))
        })
        .collect()
}
