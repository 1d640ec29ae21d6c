//! `pt-spectra rsd`: redshift-space multipoles P_ℓ(k) of a real-space model through an RSD model.

use crate::common::{ap_spec, list, parse_cs2, parsed, BiasArgs, GalaxyBiasArgs, NoiseArgs};
use crate::ept::{self, EptArgs, RsdChoice};
use crate::input::Input;
use crate::output::{check_outputs, write_output};
use crate::progress::Bars;
use anyhow::{bail, Context, Result};
use pt_spectra::jobs::{eft2_table, rsd_table, spt2_table, xi_table, NonlinearBias, RsdRequest};
use pt_spectra::linear::LogGrid;
use pt_spectra::real::RealModel;
use pt_spectra::rsd::eft2::{Eft2Plan, RsdCounterterms};
use pt_spectra::rsd::spt2::Spt2Plan;
use pt_spectra::rsd::{Fog, Observed, RsdModel, RsdPlan, Sigma0};
use std::path::PathBuf;

/// Arguments of `pt-spectra rsd`.
#[derive(clap::Args, Debug)]
pub struct Args {
    #[command(flatten)]
    input: Input,
    /// Real-space model for P_δδ, P_δθ, P_θθ: linear, 1l-spt, 2l-spt, 1l-rpt-n0..n3 or 2l-rpt-n0..n3.
    #[arg(long = "real", value_name = "M", default_value = pt_spectra::jobs::defaults::RSD_REAL_MODEL, value_parser = parsed::<RealModel>)]
    real_model: RealModel,
    /// Redshift-space model: kaiser, scoccimarro or tns (Scoccimarro + the A and B terms of Taruya,
    /// Nishimichi & Saito 2010 at leading order) on the --real model; or ept, the 1-loop galaxy model
    /// with IR resummation (velocileptors' REPT: --bias is b1, with --b2 --bs --b3, --alpha0..6,
    /// --sn --sn2 --sn4 in velocileptors' conventions, --no-ir); or spt2, the matter multipoles of
    /// 2-loop SPT in redshift space (kernels Z_2..Z_5; no FoG, IR resummation or counterterms; the
    /// 2-loop terms by quasi-Monte Carlo, ~1 s per k at default precision; --f, --ells, --terms); or
    /// eft2, the same with the BAO resummed (--no-ir: without) and the counterterms of --ct.
    #[arg(long, value_name = "MODEL", default_value = pt_spectra::jobs::defaults::RSD_MODEL, value_parser = parsed::<RsdChoice>)]
    rsd: RsdChoice,
    /// Growth rate f. Default: f(z) of the cosmology.
    #[arg(long, value_name = "F", allow_hyphen_values = true)]
    f: Option<f64>,
    /// Fingers-of-God damping: none, lorentzian or gaussian (P^s → P^s D², D of kμσ0 D(z) f).
    #[arg(long, value_name = "KIND", default_value = pt_spectra::jobs::defaults::RSD_FOG, value_parser = parsed::<Fog>)]
    fog: Fog,
    /// σ0 of the damping [Mpc/h] (its z = 0 value; scaled by D(z) f), or its theory value σ(z)/D(z) from
    /// eq. sigmav, σ² = (1/6π²)∫P_θθ dq, with linear (`lin`) or 1-loop SPT (`1l-spt`) P_θθ; `1l-spt`
    /// uses the 1-loop P_θθ for q ≤ 0.3 h/Mpc and P_lin above (1-loop P_θθ turns negative at
    /// q ≈ 0.5–1 h/Mpc).
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
    /// The nonlinear galaxy bias (scoccimarro, tns: the BOSS DR12 model of Beutler et al. 2017 with
    /// the bias terms of `real --bias-terms`, b1 is --bias, constant; ept: velocileptors' REPT).
    #[command(flatten)]
    galaxy: GalaxyBiasArgs,
    #[command(flatten)]
    noise: NoiseArgs,
    #[command(flatten)]
    ept: EptArgs,
    /// Alcock–Paczynski α∥ = H^fid(z)/H(z) (velocileptors' apar): the multipoles as measured in a
    /// fiducial cosmology, integrated over the distorted μ with every ℓ ≤ 8 of the model (needs --aperp).
    #[arg(
        long,
        value_name = "A",
        requires = "aperp",
        conflicts_with = "fiducial"
    )]
    apar: Option<f64>,
    /// Alcock–Paczynski α⊥ = D_M(z)/D_M^fid(z) (velocileptors' aperp; needs --apar).
    #[arg(long, value_name = "A", requires = "apar")]
    aperp: Option<f64>,
    /// The fiducial cosmology of the measurement (a preset or a CLASS/CAMB .ini): α∥ and α⊥ from
    /// its H(z) and D_M(z) against --cosmology's (distances in Mpc/h of each).
    #[arg(long, value_name = "NAME|FILE", conflicts_with = "aperp")]
    fiducial: Option<String>,
    /// EFT counterterm c_s² [(Mpc/h)²] added to the real-space spectra before the RSD model: P_dd −
    /// 2 c_s² k² P_lin, P_dt − 4 c_s² k² P_lin, P_tt − 6 c_s² k² P_lin (as `real --cs2`).
    #[arg(long, value_name = "CS2", default_value_t = 0.0, allow_hyphen_values = true, value_parser = parse_cs2)]
    cs2: f64,
    /// eft2 counterterm NAME=VALUE, repeatable: c0, c2, c4 [(Mpc/h)²] (−2 c k² μ^{2n} P_IR), c0_1loop,
    /// c2_1loop, c4_1loop [(Mpc/h)²] (−2 c k² μ^{2n} P^(1)_IR) and ctilde [(Mpc/h)⁴] (−c̃ k⁴ f⁴ μ⁴
    /// (1 + fμ²)² P_IR); docs/reference.md. Default 0.
    #[arg(long = "ct", value_name = "NAME=VALUE", allow_hyphen_values = true)]
    ct: Vec<String>,
    /// Multipoles to print, even ℓ ≤ 8, comma separated.
    #[arg(long, value_name = "L,L,…", default_value = "0,2,4")]
    ells: String,
    /// Add the multipoles of the parts: P<l>_sc (Kaiser or Scoccimarro part), P<l>_A, P<l>_B (TNS terms).
    #[arg(long)]
    terms: bool,
    /// Add the no-wiggle reference P<l>_nw: the linear Kaiser multipoles (same b(k) and f, no FoG) of the
    /// Eisenstein & Hu no-wiggle spectrum, by which `plot multipoles` divides as the paper does.
    #[arg(long)]
    no_wiggle: bool,
    /// Print the correlation-function multipoles ξ_ℓ(s) of the model instead (FFTLog of the P_ℓ on the
    /// k grid: give it a wide range, e.g. --k-min 1e-4 --k-max 1, as P_ℓ is extended by power laws
    /// beyond it), at --ns log-spaced s in [--s-min, --s-max] Mpc/h.
    #[arg(long)]
    xi: bool,
    /// Smallest s [Mpc/h] of --xi.
    #[arg(long, value_name = "S", default_value_t = 10.0, requires = "xi")]
    s_min: f64,
    /// Largest s [Mpc/h] of --xi.
    #[arg(long, value_name = "S", default_value_t = 200.0, requires = "xi")]
    s_max: f64,
    /// Number of s of --xi.
    #[arg(long, value_name = "N", default_value_t = 50, requires = "xi")]
    ns: usize,
    /// Write the table to this file instead of standard output.
    #[arg(long, value_name = "FILE")]
    out: Option<PathBuf>,
}

impl Args {
    /// The paper's model of --rsd; an error for ept options with it.
    fn paper_model(&self) -> Result<RsdModel> {
        match self.rsd {
            RsdChoice::Paper(m) => {
                if let Some(flag) = self.ept.given().first() {
                    bail!("{flag} is an option of --rsd ept, not of --rsd {m}");
                }
                Ok(m)
            }
            RsdChoice::Ept | RsdChoice::Spt2 | RsdChoice::Eft2 => {
                bail!("internal: {:?} has no paper model", self.rsd)
            }
        }
    }

    /// Refuses the options of the paper's models with ept.
    fn check_ept_options(&self) -> Result<()> {
        let refused = [
            ("--real", self.real_model != RealModel::OneLoopRptN1),
            ("--fog", self.fog != Fog::None),
            ("--sigma0", self.sigma0 != Sigma0::Value(0.0)),
            ("--cs2", self.cs2 != 0.0),
            ("--terms", self.terms),
            ("--no-wiggle", self.no_wiggle),
            ("--amplitude", self.bias.amplitude != 1.0),
            (
                "--shot-noise/--number-density/--noise-file (use --sn)",
                self.noise.is_set(),
            ),
        ];
        if let Some((flag, _)) = refused.iter().find(|(_, given)| *given) {
            bail!("{flag} is not an option of --rsd ept (its Fingers of God are the counterterms --alpha2..6)");
        }
        Ok(())
    }

    /// Refuses every option that `spt2` and `eft2` (matter, no FoG, no bias) do not take.
    fn check_spt2_options(&self) -> Result<()> {
        let name = if self.rsd == RsdChoice::Eft2 {
            "eft2"
        } else {
            "spt2"
        };
        if self.rsd == RsdChoice::Spt2 && !self.ct.is_empty() {
            bail!("--ct is an option of --rsd eft2 (spt2 has no counterterms)");
        }
        let refused = [
            ("--real", self.real_model != RealModel::OneLoopRptN1),
            ("--fog", self.fog != Fog::None),
            ("--sigma0", self.sigma0 != Sigma0::Value(0.0)),
            ("--cs2", self.cs2 != 0.0),
            ("--no-wiggle", self.no_wiggle),
            ("--xi", self.xi),
            ("--bias/--bias-file/--amplitude", self.bias.is_set()),
            ("--b2/--bs/--b3", self.galaxy().is_some()),
            (
                "--shot-noise/--number-density/--noise-file",
                self.noise.is_set(),
            ),
            (
                "--apar/--aperp/--fiducial",
                self.apar.is_some() || self.fiducial.is_some(),
            ),
            (
                "--window/--k-edges/--box",
                self.ept.has_window() || self.ept.has_bins(),
            ),
        ];
        if let Some((flag, _)) = refused.iter().find(|(_, given)| *given) {
            bail!("{flag} is not an option of --rsd {name} (matter multipoles of 2-loop perturbation theory: --f, --ells, --terms; eft2: --ct, --no-ir)");
        }
        let ept_only = self.ept.given();
        let allowed = |f: &&&str| self.rsd == RsdChoice::Eft2 && **f == "--no-ir";
        if let Some(flag) = ept_only.iter().find(|f| !allowed(f)) {
            bail!("{flag} is an option of --rsd ept, not of --rsd {name}");
        }
        Ok(())
    }

    /// The nonlinear bias of --b2, --bs, --b3, if any is given.
    fn galaxy(&self) -> Option<NonlinearBias> {
        self.galaxy.nonlinear()
    }

    /// The redshift-space settings of the options.
    fn request(&self) -> Result<RsdRequest> {
        let ells: Vec<usize> = list(&self.ells, "--ells")?;
        pt_spectra::rsd::MultipoleRule::new(&ells)?;
        Ok(RsdRequest {
            rsd: self.paper_model()?,
            f: self.f,
            bias: self.bias.bias()?,
            amplitude: self.bias.amplitude,
            fog: self.fog,
            sigma0: self.sigma0,
            noise: self.noise.noise()?,
            ells,
            terms: self.terms,
            no_wiggle: self.no_wiggle,
            cs2: self.cs2,
            galaxy: self.galaxy(),
            ap: None,
        })
    }
}

/// Runs the subcommand.
pub fn run(args: &Args) -> Result<()> {
    let mut inputs = args.input.files();
    inputs.extend(args.bias.files());
    inputs.extend(args.noise.files());
    let fiducial = args
        .fiducial
        .as_deref()
        .map(std::path::Path::new)
        .filter(|p| p.is_file());
    inputs.push(("--fiducial", fiducial));
    check_outputs(&[("--out", args.out.as_deref())], &inputs)?;
    let (k, loaded) = args.input.load()?;
    let ap = ap_spec(args.apar, args.aperp, args.fiducial.as_deref())?;
    let distortion = ap.distortion(&loaded.prepared.cosmology.cosmology, loaded.prepared.z)?;
    // f is checked before any loop integral runs (a 2-loop plan takes seconds).
    if let Some(f) = args.f {
        pt_spectra::cosmology::check_growth_rate(f)?;
    }
    if !args.ct.is_empty() && args.rsd != RsdChoice::Eft2 {
        bail!("--ct is an option of --rsd eft2 (the paper's models take --cs2; ept --alpha0..6)");
    }
    if args.rsd == RsdChoice::Spt2 {
        args.check_spt2_options()?;
        let ells: Vec<usize> = list(&args.ells, "--ells")?;
        pt_spectra::rsd::MultipoleRule::new(&ells)?;
        let precision = &loaded.precision;
        let plan = Spt2Plan::new(&k, precision)?.with_basis(&loaded.store, &Bars::default())?;
        let terms = plan.terms(loaded.prepared.tracer_spectrum(), &Bars::default())?;
        let table = spt2_table(
            &plan,
            &terms,
            args.f,
            &ells,
            args.terms,
            &loaded.prepared,
            precision,
        )?;
        return write_output(args.out.as_ref(), &table);
    }
    if args.rsd == RsdChoice::Eft2 {
        args.check_spt2_options()?;
        let ells: Vec<usize> = list(&args.ells, "--ells")?;
        pt_spectra::rsd::MultipoleRule::new(&ells)?;
        let ct = RsdCounterterms::from_assignments(&args.ct)?;
        if ct.values.iter().all(|&v| v == 0.0) {
            eprintln!("warning: every counterterm of eft2 is 0 (it is then IR-resummed 2-loop SPT): set them with --ct NAME=VALUE");
        }
        let precision = &loaded.precision;
        let plan = Eft2Plan::new(&k, !args.ept.no_ir(), precision)?
            .with_basis(&loaded.store, &Bars::default())?;
        let terms = plan.terms(loaded.prepared.tracer_spectrum(), &Bars::default())?;
        let table = eft2_table(
            &plan,
            &terms,
            args.f,
            &ells,
            &ct,
            args.terms,
            &loaded.prepared,
            precision,
        )?;
        return write_output(args.out.as_ref(), &table);
    }
    if args.rsd == RsdChoice::Ept {
        args.check_ept_options()?;
        let ells: Vec<usize> = list(&args.ells, "--ells")?;
        let shared = ept::Shared {
            bias: args.bias.bias()?,
            f: args.f,
            galaxy: args.galaxy(),
            ells: ells.clone(),
            distortion,
            xi: if args.xi { Some(s_grid(args)?) } else { None },
        };
        // ξ_ℓ of ept comes from the model on the transform's own k grid (survey::xi), not from the
        // table at --k-min..--k-max.
        let table = ept::table(shared, &args.ept, k, &loaded)?;
        return write_output(args.out.as_ref(), &table);
    }
    if let (Some(_), RsdChoice::Paper(model)) = (args.galaxy(), args.rsd) {
        args.galaxy.warn_if_implicit(&format!("--rsd {model}"));
    }
    let request = args.request()?;
    request.validate_galaxy()?;
    let mut request = request;
    // A window or bins: the model on their model k, with every multipole they need.
    let (window, bins) = args.ept.observation()?;
    if (window.is_some() || bins.is_some()) && (args.xi || args.terms) {
        bail!("--window/--k-edges/--box take neither --xi nor --terms (the observed table has the multipoles only)");
    }
    let spec = pt_spectra::jobs::ObservationSpec {
        window,
        bins,
        ap,
        ..Default::default()
    };
    let observation = spec.build(&request.ells, &k)?;
    let k = match &observation {
        Some(o) => {
            request.ells = o.model_ells().to_vec();
            o.k_model().to_vec()
        }
        None => k.into_vec(),
    };
    let grid = match distortion {
        Some(distortion) => {
            let grid = distortion.internal_grid(&k)?;
            request.ap = Some(Observed { distortion, k });
            grid
        }
        None => k,
    };
    let bars = Bars::default();
    let (precision, store) = (&loaded.precision, &loaded.store);
    let mut plan = RsdPlan::new(&grid, args.real_model, request.rsd, precision, store, &bars)?;
    if request.galaxy.is_some() {
        plan = plan.with_bias_terms()?;
    }
    let table = rsd_table(&plan, &request, &loaded.prepared, &bars)?;
    if let Some(o) = &observation {
        let observed = pt_spectra::jobs::observed_table(&table, o)?;
        return write_output(args.out.as_ref(), &observed);
    }
    finish(args, &table, &request.ells)
}

/// The separations of --xi: --ns log-spaced s in [--s-min, --s-max] Mpc/h.
fn s_grid(args: &Args) -> Result<Vec<f64>> {
    Ok(LogGrid::separations(args.s_min, args.s_max, args.ns)
        .context("invalid --s-min/--s-max/--ns")?
        .points())
}

/// Writes the multipoles, or with --xi their correlation functions.
fn finish(args: &Args, table: &pt_spectra::output::Table, ells: &[usize]) -> Result<()> {
    if args.xi {
        let s = s_grid(args)?;
        let xi = xi_table(table, ells, &s)?;
        return write_output(args.out.as_ref(), &xi);
    }
    write_output(args.out.as_ref(), table)
}
