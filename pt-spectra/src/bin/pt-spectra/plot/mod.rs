//! `pt-spectra plot`: one kind of figure per figure of the paper, from the tables the other subcommands
//! write (read by column name), as PNG or SVG (by the output extension), with the `plotters` crate and
//! an embedded DejaVu Sans font.
//!
//! Modules: [`table`] reads the inputs, [`draw`] draws a [`draw::Figure`]; the kinds are built in
//! [`real`] (models, propagators), [`rsd`] (multipoles, sn, tns-terms), [`fit`] (fit, contour),
//! [`halo`] (bias-noise) and [`fisher`] (ellipses).

use anyhow::{bail, Result};
use plotters::prelude::*;
use std::path::PathBuf;

mod draw;
mod fisher;
mod fit;
mod halo;
mod real;
mod rsd;
mod table;

/// The embedded font (DejaVu Sans, Bitstream Vera licence: `pt-spectra/data/fonts/LICENSE-DejaVu.txt`).
const FONT: &[u8] = include_bytes!("../../../../data/fonts/DejaVuSans.ttf");

/// What to draw (the paper's figure labels in brackets).
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum Kind {
    /// P_dd/P_nowiggle of every model (`real --model all`), and the ratio panel: data/model with
    /// `--data` (k P [σ]), else model/`--reference` [FigAz0, FigAz15 left].
    Models,
    /// N² (`N_dd`) of RPT models and the effective σ_v² = −2 ln N/k², with σ_v² of the header
    /// (`real --model …-rpt-… --terms`) [FigAz0, FigAz15 right].
    Propagators,
    /// P_ℓ/P_ℓ,nw of `rsd --no-wiggle` or `fit --model-out` tables (else k P_ℓ), `--data` (k P0 s0 P2 s2
    /// P4 s4) or the fitted data of a model table, the data/model ratio with `--bands`, and vertical
    /// lines where SN = P_hh/P_εε falls to 1 and 0.5 [multipoles_dark_matter, multipoles_haloes].
    Multipoles,
    /// Best fits versus k_max (`fit`): panels f, σ0 (with the theory σ0 of eq. sigmav) and A_b, those
    /// the inputs have; `--truth` with `--bands` around it [sigma_0_multipoles, f_dm,
    /// refind_beta_haloes, refind_f_haloes].
    Fit,
    /// b(k) and P_εε/P_Poisson (`halo --number-density`), one curve per input [bias_noise].
    BiasNoise,
    /// SN = P_hh/P_εε versus k (`rsd` with a noise), one curve per input, lines at 1, 0.5, 0.1 [S2N].
    Sn,
    /// The monopole's parts (`rsd --rsd tns --terms` with a noise): Scoccimarro part, TNS total, A, B
    /// and P_εε, negative values dashed, and each over P_εε with lines at 1, 0.5, 0.1 [Taruya_terms].
    TnsTerms,
    /// The Δχ² = 2.3 and 6.17 contours of a `fit --contour-out` table at one k_max, with the best fit.
    Contour,
    /// The 68% ellipses of α∥ and α⊥ against fσ8 of each bin of a `pt-spectra fisher` table.
    Ellipses,
}

/// Arguments of `pt-spectra plot`.
#[derive(clap::Args, Debug)]
pub struct Args {
    /// The kind of figure.
    #[arg(value_enum)]
    pub kind: Kind,
    /// Input tables (output of `real`, `rsd`, `fit` or `halo`); several are overlaid where that makes
    /// sense.
    #[arg(required = true)]
    pub inputs: Vec<PathBuf>,
    /// Output file: `.png` or `.svg`.
    #[arg(long, value_name = "FILE")]
    pub out: PathBuf,
    /// `models`: the column the ratio panel divides by without --data. Default: the last model.
    #[arg(long, value_name = "MODEL")]
    pub reference: Option<String>,
    /// Measured data: `models` k P [σ] (1-based columns 1, 2, 3); `multipoles` k P0 s0 P2 s2 P4 s4.
    #[arg(long, value_name = "FILE")]
    pub data: Option<PathBuf>,
    /// `fit`: the true f, drawn with the --bands around it.
    #[arg(long, value_name = "F", allow_hyphen_values = true)]
    pub truth: Option<f64>,
    /// Deviation bands in percent, e.g. `1,2` (the paper uses 1%, 2% and 5%). Default: `models` 1,
    /// `multipoles` 2, `fit` 1,2.
    #[arg(long, value_name = "PCT,PCT")]
    pub bands: Option<String>,
    /// `multipoles` of `fit --model-out` tables and `contour`: the k_max [h/Mpc] to draw (the nearest
    /// in the table). Default: the largest.
    #[arg(long, value_name = "K")]
    pub k_max: Option<f64>,
    /// Legend labels of the inputs, comma separated (default: from their headers, e.g. `z = 0.5`).
    #[arg(long, value_name = "L,L,…")]
    pub labels: Option<String>,
    /// Figure title (each kind has a default).
    #[arg(long, value_name = "TEXT", default_value = "")]
    pub title: String,
}

impl Args {
    /// The --bands as fractions (1 → 0.01), or `default` (in percent).
    pub fn bands(&self, default: &[f64]) -> Result<Vec<f64>> {
        let percent: Vec<f64> = match &self.bands {
            None => default.to_vec(),
            Some(s) => s
                .split(',')
                .map(|x| match x.trim().parse::<f64>() {
                    Ok(v) if v.is_finite() && v > 0.0 && v < 100.0 => Ok(v),
                    _ => bail!("--bands {s}: `{x}` is not a percentage in (0, 100)"),
                })
                .collect::<Result<_>>()?,
        };
        Ok(percent.into_iter().map(|p| p / 100.0).collect())
    }

    /// The legend label of the i-th input: from --labels, else `fallback`.
    pub fn label(&self, i: usize, fallback: impl FnOnce() -> String) -> Result<String> {
        match &self.labels {
            None => Ok(fallback()),
            Some(s) => {
                let labels: Vec<&str> = s.split(',').map(str::trim).collect();
                if labels.len() != self.inputs.len() {
                    bail!(
                        "--labels {s}: {} labels for {} inputs",
                        labels.len(),
                        self.inputs.len()
                    );
                }
                Ok(labels[i].to_string())
            }
        }
    }

    /// The single input of a kind that draws one table.
    pub fn one_input(&self) -> Result<&PathBuf> {
        match &self.inputs[..] {
            [one] => Ok(one),
            _ => bail!(
                "plot {:?} draws one table, {} were given",
                self.kind,
                self.inputs.len()
            ),
        }
    }
}

/// Runs the subcommand.
pub fn run(args: &Args) -> Result<()> {
    // Registering the same font twice is harmless; failure means the embedded file is broken.
    plotters::style::register_font("sans-serif", FontStyle::Normal, FONT)
        .map_err(|_| anyhow::anyhow!("embedded font"))?;
    let extension = args
        .out
        .extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase);
    if !matches!(extension.as_deref(), Some("png" | "svg")) {
        bail!(
            "--out {}: the file name must end in .png or .svg",
            args.out.display()
        );
    }
    let mut inputs: Vec<(&str, Option<&std::path::Path>)> = args
        .inputs
        .iter()
        .map(|p| ("input", Some(p.as_path())))
        .collect();
    inputs.push(("--data", args.data.as_deref()));
    crate::output::check_outputs(&[("--out", Some(args.out.as_path()))], &inputs)?;
    let mut figure = match args.kind {
        Kind::Models => real::models(args)?,
        Kind::Propagators => real::propagators(args)?,
        Kind::Multipoles => rsd::multipoles(args)?,
        Kind::Fit => fit::fits(args)?,
        Kind::BiasNoise => halo::bias_noise(args)?,
        Kind::Sn => rsd::signal_to_noise(args)?,
        Kind::TnsTerms => rsd::tns_terms(args)?,
        Kind::Contour => fit::contour(args)?,
        Kind::Ellipses => fisher::ellipses(args)?,
    };
    if !args.title.is_empty() {
        figure.title.clone_from(&args.title);
    }
    let size = (1000, figure.height);
    // Drawn into a temporary file of the same extension, renamed over --out once whole.
    let mut drawn = Ok(());
    pt_spectra::output::replace_with(&args.out, |tmp| {
        drawn = if extension.as_deref() == Some("png") {
            draw::draw(BitMapBackend::new(tmp, size).into_drawing_area(), &figure)
        } else {
            draw::draw(SVGBackend::new(tmp, size).into_drawing_area(), &figure)
        };
        match &drawn {
            Ok(()) => Ok(()),
            Err(e) => Err(std::io::Error::other(e.to_string())),
        }
    })
    .map_err(|e| match drawn {
        Err(drawing) => drawing,
        Ok(()) => anyhow::anyhow!("cannot write `{}`: {e}", args.out.display()),
    })
}
