//! `pt-spectra fit`: best-fit f, σ0, A_b with Δχ² errors against measured multipoles, versus k_max.

use crate::common::{list, parse_cs2, parsed, BiasArgs, NoiseArgs};
use crate::input::SpectrumInput;
use crate::output::{check_outputs, write_output};
use crate::progress::Bars;
use anyhow::{bail, Context, Result};
use pt_spectra::fit::{ContourGrid, MultipoleData, Parameter};
use pt_spectra::jobs::{fit_tables, FitOutputs, FitRequest, RsdRequest};
use pt_spectra::real::RealModel;
use pt_spectra::rsd::{Fog, RsdModel, RsdPlan, Sigma0};
use std::path::PathBuf;

/// Arguments of `pt-spectra fit`.
#[derive(clap::Args, Debug)]
pub struct Args {
    #[command(flatten)]
    spectrum: SpectrumInput,
    /// Measured multipoles: a table with k [h/Mpc] and, per multipole, P_l and its 1σ error [(Mpc/h)^3].
    #[arg(long, value_name = "FILE")]
    data: PathBuf,
    /// 1-based columns of the data: k, then P_l and σ_l for each of --data-ells.
    #[arg(long, value_name = "K,P,S,…", default_value = "1,2,3,4,5,6,7")]
    data_columns: String,
    /// The multipoles in the data file, in column order.
    #[arg(long, value_name = "L,L,…", default_value = "0,2,4")]
    data_ells: String,
    /// The multipoles to fit (jointly), a subset of --data-ells.
    #[arg(long, value_name = "L,L,…", default_value = "0")]
    ells: String,
    /// Optional full covariance of the fitted data vector (ℓ-major over --ells, all k of the file): a
    /// whitespace square matrix. Default: diagonal σ².
    #[arg(long, value_name = "FILE")]
    covariance: Option<PathBuf>,
    /// Real-space model: linear, 1l-spt, 2l-spt, 1l-rpt-n0..n3, 2l-rpt-n0..n3.
    #[arg(long = "real", value_name = "M", default_value = "1l-spt", value_parser = parsed::<RealModel>)]
    real_model: RealModel,
    /// Redshift-space model: kaiser, scoccimarro or tns.
    #[arg(long, value_name = "MODEL", default_value = "tns", value_parser = parsed::<RsdModel>)]
    rsd: RsdModel,
    /// Fingers of God: none, lorentzian or gaussian.
    #[arg(long, value_name = "KIND", default_value = "lorentzian", value_parser = parsed::<Fog>)]
    fog: Fog,
    /// Free parameters, comma separated: f, sigma0, ab, cs2 (the EFT counterterm of --cs2).
    #[arg(long, value_name = "P,P", default_value = "f,sigma0")]
    free: String,
    /// Growth rate: start value if free, value if fixed. Default: f(z) of the cosmology.
    #[arg(long, value_name = "F", allow_hyphen_values = true)]
    f: Option<f64>,
    /// σ0 [Mpc/h]: start value if free, value if fixed; a number, or the theory value of eq. sigmav as
    /// in `rsd`: `lin` (P_lin) or `1l-spt` (1-loop SPT P_θθ for q ≤ 0.3 h/Mpc, P_lin above).
    #[arg(
        long,
        value_name = "S",
        default_value = "3",
        allow_hyphen_values = true,
        value_parser = parsed::<Sigma0>
    )]
    sigma0: Sigma0,
    /// EFT counterterm c_s² [(Mpc/h)²] (as `real --cs2`): start value if free, value if fixed.
    #[arg(long, value_name = "CS2", default_value_t = 0.0, allow_hyphen_values = true, value_parser = parse_cs2)]
    cs2: f64,
    #[command(flatten)]
    bias: BiasArgs,
    #[command(flatten)]
    noise: NoiseArgs,
    /// Smallest k used [h/Mpc].
    #[arg(long, value_name = "K", default_value_t = 0.0)]
    k_min: f64,
    /// k_max [h/Mpc]: one value, a list `a,b,c`, or a scan `start:end:step`.
    #[arg(long, value_name = "K", default_value = "0.05:0.25:0.01")]
    k_max: String,
    /// Write the table to this file instead of standard output.
    #[arg(long, value_name = "FILE")]
    out: Option<PathBuf>,
    /// Write the best-fit model multipoles of every k_max to this file: `k`, the fitted data
    /// `P<l>_data err_P<l>_data`, the no-wiggle reference `P<l>_nw` and `P<l>_kmax<K>` (the model
    /// curves of the paper's figures; `plot multipoles` draws them).
    #[arg(long, value_name = "FILE")]
    model_out: Option<PathBuf>,
    /// Two free parameters, e.g. `f,sigma0`, `f,ab` or `f,cs2`: write their Δχ² surface at every k_max to
    /// --contour-out, the other free parameters re-minimised at each point (`plot contour` draws the
    /// Δχ² = 2.3 and 6.17 contours).
    #[arg(long, value_name = "P1,P2", requires = "contour_out")]
    contour: Option<String>,
    /// The file of the --contour surface: `k_max i j <P1> <P2> chi2 delta_chi2 <other free>`, a row per
    /// grid point (i, j).
    #[arg(long, value_name = "FILE", requires = "contour")]
    contour_out: Option<PathBuf>,
    /// Grid points per axis of the --contour surface (3 to 401).
    #[arg(long, value_name = "N", default_value_t = 41)]
    contour_points: usize,
    /// Half-width of each --contour axis in units of the Δχ² = 2.3 ellipse's semi-axis along it (the grid
    /// follows the ellipse's principal axes, which resolves degenerate planes such as f–A_b).
    #[arg(long, value_name = "S", default_value_t = 2.5)]
    contour_span: f64,
}

/// `a:b:step` (inclusive, to rounding), a list, or one value.
fn k_max_values(s: &str) -> Result<Vec<f64>> {
    let parts: Vec<&str> = s.split(':').collect();
    let v = match parts[..] {
        [a, b, step] => {
            let (a, b, step): (f64, f64, f64) =
                (a.trim().parse()?, b.trim().parse()?, step.trim().parse()?);
            if !(a.is_finite() && b >= a && step > 0.0) {
                bail!("--k-max {s}: needs start <= end and step > 0");
            }
            let n = ((b - a) / step + 1e-9).floor() as usize;
            (0..=n).map(|i| a + step * i as f64).collect()
        }
        [_] => list(s, "--k-max")?,
        _ => bail!("--k-max {s}: expected K, a list K,K,… or start:end:step"),
    };
    if let Some(bad) = v.iter().find(|k| !(k.is_finite() && **k > 0.0)) {
        bail!("--k-max: {bad} is not a positive wavenumber");
    }
    Ok(v)
}

/// Runs the subcommand.
pub fn run(args: &Args) -> Result<()> {
    let mut inputs = args.spectrum.files();
    inputs.push(("--data", Some(args.data.as_path())));
    inputs.push(("--covariance", args.covariance.as_deref()));
    inputs.extend(args.bias.files());
    inputs.extend(args.noise.files());
    let outputs = [
        ("--out", args.out.as_deref()),
        ("--model-out", args.model_out.as_deref()),
        ("--contour-out", args.contour_out.as_deref()),
    ];
    check_outputs(&outputs, &inputs)?;
    let free: Vec<Parameter> = args
        .free
        .split(',')
        .map(str::parse)
        .collect::<Result<_, _>>()?;
    let data_ells: Vec<usize> = list(&args.data_ells, "--data-ells")?;
    let ells: Vec<usize> = list(&args.ells, "--ells")?;
    let cols: Vec<usize> = list(&args.data_columns, "--data-columns")?;
    if cols.len() != 1 + 2 * data_ells.len() || cols.contains(&0) {
        bail!(
            "--data-columns {}: expected {} 1-based columns (k, then P_l, sigma_l for each of --data-ells {})",
            args.data_columns,
            1 + 2 * data_ells.len(),
            args.data_ells
        );
    }
    let mut spec = Vec::new();
    for &l in &ells {
        let Some(j) = data_ells.iter().position(|&d| d == l) else {
            bail!(
                "--ells: multipole {l} is not among --data-ells {}",
                args.data_ells
            );
        };
        spec.push((l, cols[1 + 2 * j] - 1, cols[2 + 2 * j] - 1));
    }
    let mut data = MultipoleData::read(&args.data, cols[0] - 1, &spec)?;
    if let Some(path) = &args.covariance {
        data = data.read_covariance(path).context("--covariance")?;
    }
    let request = FitRequest {
        model: RsdRequest {
            rsd: args.rsd,
            f: args.f,
            bias: args.bias.bias()?,
            amplitude: args.bias.amplitude,
            fog: args.fog,
            sigma0: args.sigma0,
            noise: args.noise.noise()?,
            ells,
            terms: false,
            no_wiggle: false,
            cs2: args.cs2,
            galaxy: None,
            ap: None,
        },
        free,
        k_min: args.k_min,
        k_max: k_max_values(&args.k_max)?,
        data_name: args.data.display().to_string(),
    };
    for (name, v) in [("--amplitude", args.bias.amplitude)]
        .into_iter()
        .chain(args.f.map(|f| ("--f", f)))
    {
        if !v.is_finite() {
            bail!("{name} {v}: must be finite");
        }
    }
    let loaded = args.spectrum.load()?;
    let bars = Bars::default();
    let (precision, store) = (&loaded.precision, &loaded.store);
    let outputs = FitOutputs {
        model: args.model_out.is_some(),
        contour: match &args.contour {
            None => None,
            Some(text) => Some(contour_grid(text, args, &request.free)?),
        },
    };
    let plan = RsdPlan::new(&data.k, args.real_model, args.rsd, precision, store, &bars)?;
    let tables = fit_tables(&plan, data, &request, outputs, &loaded.prepared, &bars)?;
    for (path, table) in [
        (args.model_out.as_ref(), tables.model.as_ref()),
        (args.contour_out.as_ref(), tables.contour.as_ref()),
    ] {
        if let (Some(path), Some(table)) = (path, table) {
            write_output(Some(path), table)?;
        }
    }
    write_output(args.out.as_ref(), &tables.fit)
}

/// The grid of `--contour P1,P2`: two different parameters among the free ones.
fn contour_grid(text: &str, args: &Args, free: &[Parameter]) -> Result<ContourGrid> {
    let pair: Vec<Parameter> = text
        .split(',')
        .map(str::parse)
        .collect::<Result<_, _>>()
        .with_context(|| format!("--contour {text}"))?;
    let [x, y] = pair[..] else {
        bail!("--contour {text}: expected two parameters P1,P2, e.g. f,sigma0");
    };
    let (points, span) = (args.contour_points, args.contour_span);
    ContourGrid::new(x, y, points, span, free).map_err(|e| match e {
        // "contour P1,P2: …" names the option's value already.
        pt_spectra::error::Error::InvalidChoice { .. } => anyhow::anyhow!("--{e}"),
        e => anyhow::Error::new(e)
            .context(format!("--contour-points {points} --contour-span {span}")),
    })
}
