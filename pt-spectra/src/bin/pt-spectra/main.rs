//! The `pt-spectra` command-line tool: perturbation-theory kernels and power spectra.
//!
//! Units everywhere: k in h/Mpc, P in (Mpc/h)^3. Every subcommand prints a clear error and exits non-zero
//! on bad input.

use clap::{Parser, Subcommand};
use std::process::ExitCode;

mod analysis;
mod bispectrum;
mod common;
mod ept;
mod fisher;
mod fit;
mod halo;
mod input;
mod kernel;
mod output;
mod plot;
mod progress;
mod real;
mod rsd;

/// Perturbation-theory power spectra of matter and haloes (Gil-Marín et al. 2012, arXiv:1209.3771).
#[derive(Parser)]
#[command(name = "pt-spectra", version, about, long_about = None)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Evaluate the symmetrised SPT kernel F_n^s or G_n^s (n = number of --q, 1..=7).
    Kernel(kernel::Args),
    /// Real-space P_δδ, P_δθ, P_θθ (linear, 1- and 2-loop SPT, 1- and 2-loop RPT with N0..N3) on a k grid.
    Real(Box<real::Args>),
    /// Redshift-space multipoles P_ℓ(k) (Kaiser, Scoccimarro or TNS; Fingers of God; halo bias and noise).
    Rsd(Box<rsd::Args>),
    /// Fit f, σ0 and the bias amplitude to measured multipoles, with Δχ² errors, versus k_max.
    Fit(Box<fit::Args>),
    /// Tree-level galaxy bispectrum multipoles B0, B2, B4 in redshift space at triangles or triangle bins.
    Bispectrum(Box<bispectrum::Args>),
    /// Fisher forecast of a redshift survey (volume, n̄, k range per bin) with the galaxy model ept.
    Fisher(Box<fisher::Args>),
    /// Halo bias b(k) = P_mh/P_mm and stochasticity P_εε = P_hh − P_mh²/P_mm from measured spectra.
    Halo(halo::Args),
    /// Draw the paper's kinds of figure (PNG or SVG) from the tables of the other subcommands.
    Plot(plot::Args),
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    let result = match cli.command {
        Command::Kernel(args) => kernel::run(&args),
        Command::Real(args) => real::run(&args),
        Command::Rsd(args) => rsd::run(&args),
        Command::Fit(args) => fit::run(&args),
        Command::Halo(args) => halo::run(&args),
        Command::Fisher(args) => fisher::run(&args),
        Command::Bispectrum(args) => bispectrum::run(&args),
        Command::Plot(args) => plot::run(&args),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {}", message(&e));
            ExitCode::FAILURE
        }
    }
}

/// The error and its causes, `: `-separated, each cause left out if the text so far already says it
/// (the library's messages include their OS error, which is also their `source`).
fn message(e: &anyhow::Error) -> String {
    let mut text = String::new();
    for cause in e.chain() {
        let part = cause.to_string();
        if text.contains(&part) {
            continue;
        }
        if !text.is_empty() {
            text.push_str(": ");
        }
        text.push_str(&part);
    }
    text
}
