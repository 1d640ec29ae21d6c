//! `pt-spectra rsd --rsd ept`: the galaxy model's options and run.

use anyhow::{bail, Result};
use pt_spectra::halo::Bias;
use pt_spectra::jobs::{ept_plan, ept_table, EptRequest};
use pt_spectra::output::Table;
use pt_spectra::rsd::ap::Distortion;
use pt_spectra::rsd::ept::EptParams;
use std::str::FromStr;

/// `--rsd`: one of the paper's models or the galaxy model `ept`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum RsdChoice {
    /// Kaiser, Scoccimarro or TNS on a real-space model.
    Paper(pt_spectra::rsd::RsdModel),
    /// The 1-loop galaxy model (velocileptors' REPT).
    Ept,
}

impl FromStr for RsdChoice {
    type Err = pt_spectra::error::Error;
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        if s.eq_ignore_ascii_case("ept") {
            return Ok(Self::Ept);
        }
        s.parse().map(Self::Paper)
    }
}

/// The counterterms, stochastic terms and IR switch of `ept` (velocileptors' names and units).
#[derive(clap::Args, Debug)]
pub struct EptArgs {
    /// ept counterterm α0 [(Mpc/h)²]: α0 k² P_lin (velocileptors' alpha0).
    #[arg(long, value_name = "A", allow_hyphen_values = true)]
    alpha0: Option<f64>,
    /// ept counterterm α2 [(Mpc/h)²]: α2 k²μ² P_lin.
    #[arg(long, value_name = "A", allow_hyphen_values = true)]
    alpha2: Option<f64>,
    /// ept counterterm α4 [(Mpc/h)²]: α4 k²μ⁴ P_lin.
    #[arg(long, value_name = "A", allow_hyphen_values = true)]
    alpha4: Option<f64>,
    /// ept counterterm α6 [(Mpc/h)²]: α6 k²μ⁶ P_lin.
    #[arg(long, value_name = "A", allow_hyphen_values = true)]
    alpha6: Option<f64>,
    /// ept constant shot noise sn [(Mpc/h)³].
    #[arg(long, value_name = "SN", allow_hyphen_values = true)]
    sn: Option<f64>,
    /// ept stochastic term sn2 [(Mpc/h)⁵]: sn2 k²μ².
    #[arg(long, value_name = "SN", allow_hyphen_values = true)]
    sn2: Option<f64>,
    /// ept stochastic term sn4 [(Mpc/h)⁷]: sn4 k⁴μ⁴.
    #[arg(long, value_name = "SN", allow_hyphen_values = true)]
    sn4: Option<f64>,
    /// ept without IR resummation of the BAO: plain 1-loop SPT in redshift space.
    #[arg(long)]
    no_ir: bool,
}

impl EptArgs {
    /// Whether --no-ir is given.
    pub fn no_ir(&self) -> bool {
        self.no_ir
    }

    /// The counterterm and stochastic values given, by parameter name.
    pub fn values(&self) -> [(&'static str, Option<f64>); 7] {
        [
            ("alpha0", self.alpha0),
            ("alpha2", self.alpha2),
            ("alpha4", self.alpha4),
            ("alpha6", self.alpha6),
            ("sn", self.sn),
            ("sn2", self.sn2),
            ("sn4", self.sn4),
        ]
    }

    /// The options given, by name, for the error when a paper model gets them.
    pub fn given(&self) -> Vec<&'static str> {
        let mut out: Vec<&'static str> = [
            ("--alpha0", self.alpha0),
            ("--alpha2", self.alpha2),
            ("--alpha4", self.alpha4),
            ("--alpha6", self.alpha6),
            ("--sn", self.sn),
            ("--sn2", self.sn2),
            ("--sn4", self.sn4),
        ]
        .iter()
        .filter(|(_, v)| v.is_some())
        .map(|(n, _)| *n)
        .collect();
        if self.no_ir {
            out.push("--no-ir");
        }
        out
    }
}

/// What `ept` takes from the shared `rsd` options.
pub struct Shared {
    pub bias: Bias,
    pub f: Option<f64>,
    pub b2: Option<f64>,
    pub bs: Option<f64>,
    pub b3: Option<f64>,
    pub ells: Vec<usize>,
    pub distortion: Option<Distortion>,
}

/// The table of `rsd --rsd ept` (the options of the paper's models are refused by the caller).
pub fn table(
    shared: Shared,
    args: &EptArgs,
    k: Vec<f64>,
    loaded: &crate::input::Loaded,
) -> Result<Table> {
    let b1 = match shared.bias {
        Bias::Constant(b) => b,
        Bias::Table(_) => bail!("--rsd ept takes a constant --bias (b1), not --bias-file"),
    };
    let mut params = EptParams::new(b1, shared.f.unwrap_or(f64::NAN));
    for (name, value) in [
        ("b2", shared.b2),
        ("bs", shared.bs),
        ("b3", shared.b3),
        ("alpha0", args.alpha0),
        ("alpha2", args.alpha2),
        ("alpha4", args.alpha4),
        ("alpha6", args.alpha6),
        ("sn", args.sn),
        ("sn2", args.sn2),
        ("sn4", args.sn4),
    ] {
        if let Some(v) = value {
            params.set(name, v)?;
        }
    }
    let plan = ept_plan(&k, !args.no_ir, shared.distortion, false, &loaded.precision)?;
    let request = EptRequest {
        params,
        ells: shared.ells,
    };
    Ok(ept_table(
        &plan,
        &request,
        &loaded.prepared,
        &loaded.precision,
    )?)
}
