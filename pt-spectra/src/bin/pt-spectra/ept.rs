//! `pt-spectra rsd --rsd ept`: the galaxy model's options and run.

use crate::progress::Bars;
use anyhow::{bail, Context, Result};
use pt_spectra::halo::Bias;
use pt_spectra::jobs::{ept_plan, ept_table, EptRequest};
use pt_spectra::output::Table;
use pt_spectra::rsd::ap::Distortion;
use pt_spectra::rsd::ept::EptParams;
use pt_spectra::table::KGrid;
use std::str::FromStr;

/// `--rsd`: one of the paper's models or the galaxy model `ept`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum RsdChoice {
    /// Kaiser, Scoccimarro or TNS on a real-space model.
    Paper(pt_spectra::rsd::RsdModel),
    /// The 1-loop galaxy model (velocileptors' REPT).
    Ept,
    /// The matter multipoles of 2-loop SPT in redshift space.
    Spt2,
    /// The matter multipoles of the 2-loop EFT in redshift space, BAO resummed.
    Eft2,
}

impl RsdChoice {
    /// Every name `--rsd` takes, in the order of its help (one list for the help and the errors).
    pub const NAMES: &'static str = "kaiser, scoccimarro, tns, ept, spt2, eft2";
}

impl FromStr for RsdChoice {
    type Err = pt_spectra::error::Error;
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        if s.eq_ignore_ascii_case("ept") {
            return Ok(Self::Ept);
        }
        if s.eq_ignore_ascii_case("spt2") {
            return Ok(Self::Spt2);
        }
        if s.eq_ignore_ascii_case("eft2") {
            return Ok(Self::Eft2);
        }
        s.parse()
            .map(Self::Paper)
            .map_err(|_| pt_spectra::error::Error::UnknownName {
                what: "RSD model",
                name: s.to_string(),
                available: Self::NAMES,
            })
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
    /// Any model (fit: ept): convolve with a survey window: Q_ℓ(s) multipoles (columns declared by a
    /// names line `# s Q0 Q2 Q4 …` in the file, s in Mpc/h, or by --window-format), or a window matrix
    /// (`.npy` with a `.npy.txt` sidecar, or text with an `ells_out` header). Wide-angle terms are
    /// neglected.
    #[arg(long, value_name = "FILE")]
    window: Option<std::path::PathBuf>,
    /// The columns of a Q_ℓ(s) --window file that has no names line: `s,Q0,Q2,Q4` (file order), `boss`
    /// (the CLASS-PT BOSS DR12 layout: Q0 Q2 Q4 without s on 128 log-uniform s from 0.01 to 1000
    /// Mpc/h; `boss:N` for N rows) or `header` (the default: the file's names line).
    #[arg(
        long,
        value_name = "LAYOUT",
        requires = "window",
        default_value = "header"
    )]
    window_format: String,
    /// How Q_ℓ mix the multipoles: wilson (Wilson et al. 2017, every Q_ℓ given; the default) or
    /// classpt-boss (the CLASS-PT BOSS likelihoods: Q ≤ 4, no ξ4 in ξ̂0, ξ̂2).
    #[arg(long, value_name = "M", default_value = "wilson")]
    window_mixing: String,
    /// Any model (fit: ept): average over k bins with the k² (mode-count) weight: edges [h/Mpc] as `a,b,c,…` or
    /// `start:end:step`; the output k are the bins' effective k.
    #[arg(long, value_name = "EDGES")]
    k_edges: Option<String>,
    /// Any model (fit: ept): average over the discrete modes of a periodic box of side L [Mpc/h] in the bins of
    /// --k-edges (what simulation measurements are).
    #[arg(long, value_name = "L", requires = "k_edges")]
    r#box: Option<f64>,
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

    /// Whether --window is given.
    pub fn has_window(&self) -> bool {
        self.window.is_some()
    }

    /// Whether --k-edges (or --box) is given.
    pub fn has_bins(&self) -> bool {
        self.k_edges.is_some() || self.r#box.is_some()
    }

    /// The window and bins of the options, if any.
    pub fn observation(
        &self,
    ) -> Result<(
        Option<pt_spectra::survey::observe::Window>,
        Option<pt_spectra::survey::observe::Bins>,
    )> {
        use pt_spectra::survey::observe::{Bins, Window};
        let mixing = match self.window_mixing.as_str() {
            "wilson" => pt_spectra::survey::Mixing::Wilson,
            "classpt-boss" => pt_spectra::survey::Mixing::ClassPtBoss,
            other => bail!("--window-mixing {other}: expected wilson or classpt-boss"),
        };
        let format = pt_spectra::survey::WindowFormat::parse(&self.window_format)
            .map_err(|e| anyhow::anyhow!("--window-format: {e}"))?;
        let window = match &self.window {
            Some(path) => Some(
                Window::read(path, mixing, &format)
                    .map_err(|e| anyhow::anyhow!("--window: {e}"))?,
            ),
            None => None,
        };
        let edges = self
            .k_edges
            .as_deref()
            .map(|text| edges(text, "--k-edges"))
            .transpose()?;
        let bins = Bins::of(edges, self.r#box).context("--box")?;
        Ok((window, bins))
    }
}

/// Bin edges from `a,b,c,…` or `start:end:step` (inclusive, to rounding).
pub fn edges(text: &str, flag: &str) -> Result<Vec<f64>> {
    let parts: Vec<&str> = text.split(':').collect();
    let v: Vec<f64> = match parts[..] {
        [a, b, step] => {
            let (a, b, step): (f64, f64, f64) =
                (a.trim().parse()?, b.trim().parse()?, step.trim().parse()?);
            if !(a.is_finite() && b > a && step > 0.0) {
                bail!("{flag} {text}: needs start < end and step > 0");
            }
            let n = ((b - a) / step + 1e-9).floor() as usize;
            (0..=n).map(|i| a + step * i as f64).collect()
        }
        _ => text
            .split(',')
            .map(|x| x.trim().parse::<f64>())
            .collect::<Result<_, _>>()
            .map_err(|e| anyhow::anyhow!("{flag} {text}: {e}"))?,
    };
    if v.len() < 2 {
        bail!("{flag} {text}: give at least two edges");
    }
    Ok(v)
}

/// What `ept` takes from the shared `rsd` options.
pub struct Shared {
    pub bias: Bias,
    pub f: Option<f64>,
    /// --b2, --bs, --b3 in velocileptors' convention, and the one they were given in.
    pub galaxy: Option<pt_spectra::jobs::NonlinearBias>,
    pub ells: Vec<usize>,
    pub distortion: Option<Distortion>,
    /// --xi: the s [Mpc/h] of the correlation-function multipoles.
    pub xi: Option<Vec<f64>>,
}

/// The table of `rsd --rsd ept` (the options of the paper's models are refused by the caller).
pub fn table(
    shared: Shared,
    args: &EptArgs,
    k: KGrid,
    loaded: &crate::input::Loaded,
) -> Result<Table> {
    let b1 = match shared.bias {
        Bias::Constant(b) => b,
        Bias::Table(_) => bail!("--rsd ept takes a constant --bias (b1), not --bias-file"),
    };
    let mut params = EptParams::new(b1, shared.f.unwrap_or(f64::NAN));
    for (name, value) in [
        ("b2", shared.galaxy.map(|g| g.b2)),
        ("bs", shared.galaxy.map(|g| g.bs)),
        ("b3", shared.galaxy.map(|g| g.b3)),
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
    let request = EptRequest {
        params,
        ells: shared.ells,
        ap: None,
        bias_given: shared.galaxy.map(|g| g.given).unwrap_or_default(),
    };
    let (window, bins) = args.observation()?;
    let spec = pt_spectra::jobs::ObservationSpec {
        window,
        bins,
        xi: shared.xi.is_some(),
        s_edges: None,
        ap: shared.distortion.map_or(
            pt_spectra::rsd::ap::ApSpec::None,
            pt_spectra::rsd::ap::ApSpec::Scalings,
        ),
    };
    let at = shared.xi.as_deref().unwrap_or(&k);
    let Some(observation) = spec
        .build(&request.ells, at)
        .context("--xi/--window/--k-edges")?
    else {
        let plan = ept_plan(
            &k,
            !args.no_ir,
            shared.distortion,
            false,
            &loaded.precision,
            &loaded.store,
            &Bars::default(),
        )?;
        return Ok(ept_table(
            &plan,
            &request,
            &loaded.prepared,
            &loaded.precision,
        )?);
    };
    let plan = ept_plan(
        observation.k_model(),
        !args.no_ir,
        shared.distortion,
        false,
        &loaded.precision,
        &loaded.store,
        &Bars::default(),
    )?;
    let terms = plan.terms(loaded.prepared.tracer_spectrum())?;
    Ok(pt_spectra::jobs::ept_observed_table(
        &plan,
        &terms,
        &request,
        &loaded.prepared,
        &loaded.precision,
        &observation,
    )?)
}
