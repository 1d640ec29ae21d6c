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

/// The Alcock–Paczynski distortion of `--apar`/`--aperp` or `--fiducial` (a preset or a CLASS/CAMB
/// .ini) as the library takes it ([`pt_spectra::rsd::ap::ApSpec`]).
pub fn ap_spec(
    apar: Option<f64>,
    aperp: Option<f64>,
    fiducial: Option<&str>,
) -> Result<pt_spectra::rsd::ap::ApSpec> {
    let fiducial = fiducial
        .map(|name| {
            pt_spectra::setup::NamedCosmology::parse(name)
                .map(|c| c.0.cosmology)
                .map_err(|e| anyhow::anyhow!("--fiducial: {e}"))
        })
        .transpose()?;
    Ok(pt_spectra::rsd::ap::ApSpec::from_options(
        apar, aperp, fiducial,
    )?)
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

/// The nonlinear galaxy bias, one meaning for every model: velocileptors' convention unless
/// --bias-convention says which other the values are written in (`pt_spectra::bias`).
#[derive(clap::Args, Debug)]
pub struct GalaxyBiasArgs {
    /// Second-order local bias b2: (b2/2)δ² (with --bias-convention classpt, CLASS-PT's b2).
    #[arg(long, value_name = "B2", allow_hyphen_values = true)]
    pub b2: Option<f64>,
    /// Tidal bias bs: bs s², velocileptors' (with --bias-convention fastpt FAST-PT's (bs/2)s², with
    /// classpt CLASS-PT's b_G2).
    #[arg(long, value_name = "BS", allow_hyphen_values = true)]
    pub bs: Option<f64>,
    /// Cubic bias b3: b1 b3 sig3nl in P_gg, velocileptors' (with --bias-convention fastpt FAST-PT's
    /// b3nl = b3/2, with classpt CLASS-PT's b_Γ3).
    #[arg(long, value_name = "B3", allow_hyphen_values = true)]
    pub b3: Option<f64>,
    /// The convention --b2, --bs, --b3 are written in: velocileptors (the default, for every model),
    /// fastpt (b2, bs, b3nl of FAST-PT, McDonald & Roy 2009, Beutler et al. 2017), classpt (b2, b_G2,
    /// b_Γ3 of CLASS-PT). The header gives the values in velocileptors' convention and as given.
    #[arg(long, value_name = "NAME", value_parser = parsed::<pt_spectra::bias::BiasConvention>)]
    pub bias_convention: Option<pt_spectra::bias::BiasConvention>,
}

impl GalaxyBiasArgs {
    /// Whether any of --b2, --bs, --b3 is given.
    pub fn any(&self) -> bool {
        self.b2.is_some() || self.bs.is_some() || self.b3.is_some()
    }

    /// The convention of the values.
    pub fn convention(&self) -> pt_spectra::bias::BiasConvention {
        self.bias_convention.unwrap_or_default()
    }

    /// The bias with linear bias `b1`, in velocileptors' convention.
    pub fn params(&self, b1: f64) -> pt_spectra::bias::BiasParams {
        let v = |x: Option<f64>| x.unwrap_or(0.0);
        pt_spectra::bias::BiasParams::from_convention(
            self.convention(),
            [b1, v(self.b2), v(self.bs), v(self.b3)],
        )
    }

    /// The nonlinear bias of --b2, --bs, --b3, if any is given.
    pub fn nonlinear(&self) -> Option<pt_spectra::jobs::NonlinearBias> {
        let v = |x: Option<f64>| x.unwrap_or(0.0);
        self.any().then(|| {
            pt_spectra::jobs::NonlinearBias::new(
                self.convention(),
                v(self.b2),
                v(self.bs),
                v(self.b3),
            )
        })
    }

    /// A warning for `model`, whose --bs and --b3 were FAST-PT's before they meant one thing for every
    /// model, when they are given without --bias-convention.
    pub fn warn_if_implicit(&self, model: &str) {
        if self.bias_convention.is_none() && (self.bs.is_some() || self.b3.is_some()) {
            eprintln!(
                "warning: {}",
                pt_spectra::bias::implicit_convention_warning(
                    model,
                    "--bs and --b3",
                    "--bias-convention fastpt"
                )
            );
        }
    }
}
