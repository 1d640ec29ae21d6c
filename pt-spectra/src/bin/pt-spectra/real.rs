//! `pt-spectra real`: real-space P_δδ, P_δθ, P_θθ of a model on a k grid, as a whitespace table.

use anyhow::{bail, Context, Result};
use indicatif::{ProgressBar, ProgressStyle};
use pt_spectra::cosmology::{Cosmology, TransferKind};
use pt_spectra::linear::{Columns, LinearSpectrum, LogGrid, GM2012_REDSHIFTS};
use pt_spectra::loops::{Estimate, OneLoopPlan, OneLoopTerms, Pair, PairTerms};
use pt_spectra::precision::Precision;
use pt_spectra::real::{from_terms, RealModel, RealSpectra};
use std::io::Write;
use std::path::PathBuf;

/// Above this many k values the loop terms are computed in chunks behind a progress bar.
const PROGRESS_THRESHOLD: usize = 2048;
/// k values per chunk.
const CHUNK: usize = 512;

/// Accuracy preset of the loop integrals.
#[derive(Clone, Copy, Debug, clap::ValueEnum)]
pub enum PrecisionPreset {
    /// About twice as fast, ≲ 3e-5 relative.
    Fast,
    /// ≲ 3e-6 relative.
    Default,
    /// Every resolution doubled (for convergence checks).
    Reference,
}

impl PrecisionPreset {
    fn name(self) -> &'static str {
        match self {
            PrecisionPreset::Fast => "fast",
            PrecisionPreset::Default => "default",
            PrecisionPreset::Reference => "reference",
        }
    }
}

/// Eisenstein & Hu (1998) transfer function choice.
#[derive(Clone, Copy, Debug, clap::ValueEnum)]
pub enum EhKind {
    /// Full fit with baryon acoustic oscillations.
    Wiggle,
    /// Smooth no-wiggle fit.
    NoWiggle,
}

/// `K,P` (1-based column numbers) as 0-based [`Columns`].
fn parse_columns(s: &str) -> std::result::Result<Columns, String> {
    let parts: Vec<&str> = s.split(',').map(str::trim).collect();
    let [k, p] = parts[..] else {
        return Err(format!(
            "`{s}`: expected two column numbers K,P (1-based), e.g. 1,2"
        ));
    };
    let one = |x: &str| match x.parse::<usize>() {
        Ok(n) if n >= 1 => Ok(n - 1),
        _ => Err(format!("`{x}` is not a column number (1, 2, …)")),
    };
    let (k, p) = (one(k)?, one(p)?);
    if k == p {
        return Err(format!("`{s}`: k and P must be different columns"));
    }
    Ok(Columns::new(k, p))
}

/// The linear spectrum, redshift and accuracy: the options `real`, `rsd` and `fit` share.
#[derive(clap::Args, Debug)]
pub struct SpectrumInput {
    /// Linear spectrum table (k [h/Mpc], P [(Mpc/h)^3]; CAMB or CLASS format). Default: the embedded
    /// CAMB spectrum of the Gil-Marín et al. (2012) cosmology.
    #[arg(long, value_name = "FILE", conflicts_with = "eh")]
    linear: Option<PathBuf>,
    /// Columns of k and P in the --linear table, 1-based, e.g. `1,3` for a CLASS file with several
    /// spectra. Default `1,2`.
    #[arg(long, value_name = "K,P", value_parser = parse_columns, requires = "linear")]
    columns: Option<Columns>,
    /// Use an Eisenstein & Hu (1998) linear spectrum of the gm2012 cosmology, normalised to σ8 = 0.8 at
    /// z = 0, instead of a table: `wiggle` (with BAO) or `no-wiggle` (the smooth fit).
    #[arg(long, value_name = "KIND", value_enum)]
    eh: Option<EhKind>,
    /// Redshift of the --linear table.
    #[arg(
        long,
        value_name = "Z",
        default_value_t = 0.0,
        allow_hyphen_values = true
    )]
    z_input: f64,
    /// Redshift of the output; the input is rescaled by [D(z)/D(z_input)]² of the gm2012 cosmology.
    #[arg(
        long,
        value_name = "Z",
        default_value_t = 0.0,
        allow_hyphen_values = true
    )]
    pub z: f64,
    /// Accuracy of the loop integrals.
    #[arg(long, value_enum, default_value = "default")]
    precision: PrecisionPreset,
}

/// The linear spectrum and the output k grid: the options `real` and `rsd` share.
#[derive(clap::Args, Debug)]
pub struct Input {
    #[command(flatten)]
    pub spectrum: SpectrumInput,
    /// Smallest output k [h/Mpc] (log-spaced grid).
    #[arg(
        long,
        value_name = "K",
        default_value_t = 1e-3,
        allow_hyphen_values = true
    )]
    k_min: f64,
    /// Largest output k [h/Mpc].
    #[arg(
        long,
        value_name = "K",
        default_value_t = 1.0,
        allow_hyphen_values = true
    )]
    k_max: f64,
    /// Number of log-spaced k values.
    #[arg(long, value_name = "N", default_value_t = 100)]
    nk: usize,
    /// Read the output k values [h/Mpc] from the first column of this file instead ('#' comments).
    #[arg(long, value_name = "FILE", conflicts_with_all = ["k_min", "k_max", "nk"])]
    k_file: Option<PathBuf>,
}

impl SpectrumInput {
    /// The linear spectrum at the output redshift and the loop-integral settings.
    pub fn load(&self) -> Result<(LinearSpectrum, Precision)> {
        let precision = match self.precision {
            PrecisionPreset::Fast => Precision::fast(),
            PrecisionPreset::Default => Precision::default(),
            PrecisionPreset::Reference => Precision::reference(),
        };
        Ok((linear_spectrum(self)?, precision))
    }

    /// Header lines naming the input spectrum and the integration settings.
    pub fn describe(&self, spectrum: &LinearSpectrum, precision: &Precision) -> String {
        let mut h = format!(
            "# linear spectrum: {} (z_input = {}; rescaled with the growth of the gm2012 cosmology)\n",
            spectrum.origin(),
            if self.linear.is_some() { self.z_input } else { self.z }
        );
        h += &format!(
            "# loop integrals over q in [{:e}, {:e}] h/Mpc, precision {}; the linear table covers [{:e}, \
             {:e}] h/Mpc and is extended by power laws (slopes {:.3}, {:.3})\n",
            precision.q_min,
            precision.q_max,
            self.precision.name(),
            spectrum.k_min(),
            spectrum.k_max(),
            spectrum.extrapolation_slopes().0,
            spectrum.extrapolation_slopes().1
        );
        h
    }
}

impl Input {
    /// The output k grid [h/Mpc], the linear spectrum at the output redshift (with a warning when the
    /// grid reaches its extrapolated ends) and the loop-integral settings.
    pub fn load(&self) -> Result<(Vec<f64>, LinearSpectrum, Precision)> {
        let k = match &self.k_file {
            Some(path) => read_k_file(path)?,
            None => LogGrid::new(self.k_min, self.k_max, self.nk)
                .context("invalid --k-min/--k-max/--nk")?
                .points(),
        };
        let (spectrum, precision) = self.spectrum.load()?;
        if let Some(ext) = spectrum.extrapolation_in(k[0], k[k.len() - 1]) {
            eprintln!("warning: output {ext}");
        }
        Ok((k, spectrum, precision))
    }

    /// Header lines naming the input spectrum and the integration settings.
    pub fn describe(&self, spectrum: &LinearSpectrum, precision: &Precision) -> String {
        self.spectrum.describe(spectrum, precision)
    }

    /// The output redshift.
    pub fn z(&self) -> f64 {
        self.spectrum.z
    }
}

/// Arguments of `pt-spectra real`.
#[derive(clap::Args, Debug)]
pub struct Args {
    #[command(flatten)]
    input: Input,
    /// Model: linear, 1l-spt, 2l-spt, 1l-rpt-n0..n3 or 2l-rpt-n0..n3 (N3 builds the P17 table once);
    /// or `all`: P_dd/P_nowiggle of every model, one column each (the paper's real-space comparison).
    #[arg(long, value_name = "M", default_value = "1l-spt")]
    model: String,
    /// Also print the separate loop terms, σ_v² and propagators, each with its error estimate.
    #[arg(long)]
    terms: bool,
    /// Write the table to this file instead of standard output.
    #[arg(long, value_name = "FILE")]
    out: Option<PathBuf>,
    /// Target relative error of the 2-loop correction of 2-loop models: where the quasi-Monte-Carlo
    /// error estimate exceeds it, points are added at that k (at most 4 times the initial ones).
    /// Default: 1e-3 with `--precision default`, 0 (fixed points) with `fast` and `reference`.
    #[arg(long, value_name = "REL", allow_hyphen_values = true)]
    two_loop_tolerance: Option<f64>,
}

impl Args {
    /// The k grid, the linear spectrum and the loop-integral settings with `--two-loop-tolerance`.
    fn load(&self) -> Result<(Vec<f64>, LinearSpectrum, Precision)> {
        let (k, spectrum, mut precision) = self.input.load()?;
        if let Some(tolerance) = self.two_loop_tolerance {
            precision.two_loop_tolerance = tolerance;
            precision
                .validate()
                .context("invalid --two-loop-tolerance")?;
        }
        Ok((k, spectrum, precision))
    }
}

/// Runs the subcommand.
pub fn run(args: &Args) -> Result<()> {
    if args.model.trim().eq_ignore_ascii_case("all") {
        return run_all(args);
    }
    let model: RealModel = args.model.parse()?;
    let (k, spectrum, precision) = args.load()?;
    let terms = loop_terms(&k, &precision, &spectrum, model)?;
    let spectra = from_terms(model, &terms)?;
    let mut text = header(args, model, &spectrum, &precision, &terms);
    text.push_str(&table(&spectra, &terms, args.terms));
    write_output(args.out.as_ref(), &text)
}

/// `--model all`: P_dd of every model over the no-wiggle spectrum, with errors.
fn run_all(args: &Args) -> Result<()> {
    let (k, spectrum, precision) = args.load()?;
    // Every model's terms are a subset of 2l-rpt-n3's.
    let terms = loop_terms(&k, &precision, &spectrum, RealModel::TwoLoopRptN3)?;
    let cosmology = Cosmology::gm2012();
    let eh = cosmology.eisenstein_hu_spectrum(TransferKind::NoWiggle, 0.0, &LogGrid::default())?;
    let no_wiggle = eh.scaled((spectrum.sigma8() / eh.sigma8()).powi(2))?;
    let mut text = format!(
        "# pt-spectra {} real --model all: P_dd of each model over the no-wiggle spectrum, z = {}\n",
        env!("CARGO_PKG_VERSION"),
        args.input.z()
    );
    text += &args.input.describe(&spectrum, &precision);
    text += &two_loop_line(&precision);
    text += "# P_nw: Eisenstein & Hu (1998) no-wiggle fit of the gm2012 cosmology, scaled to the sigma8 of the \
             linear input; columns <model> = P_dd(model)/P_nw, err_<model> its estimated numerical error; k [h/Mpc], \
             P_nw [(Mpc/h)^3]\n# k P_nw";
    let models: Vec<_> = RealModel::ALL
        .iter()
        .map(|&m| from_terms(m, &terms))
        .collect::<Result<_, _>>()?;
    for m in &models {
        text += &format!(" {}", m.model);
    }
    for m in &models {
        text += &format!(" err_{}", m.model);
    }
    text.push('\n');
    for (i, &ki) in k.iter().enumerate() {
        let nw = no_wiggle.eval(ki);
        let mut row = vec![ki, nw];
        row.extend(models.iter().map(|m| m.spectra[0][i].value / nw));
        row.extend(models.iter().map(|m| m.spectra[0][i].error / nw));
        let line: Vec<String> = row.iter().map(|v| format!("{v:.9e}")).collect();
        text += &line.join(" ");
        text.push('\n');
    }
    write_output(args.out.as_ref(), &text)
}

/// Writes `text` to `out`, or to standard output.
pub fn write_output(out: Option<&PathBuf>, text: &str) -> Result<()> {
    match out {
        Some(path) => std::fs::write(path, text)
            .with_context(|| format!("cannot write `{}`", path.display()))?,
        None => std::io::stdout().write_all(text.as_bytes())?,
    }
    Ok(())
}

/// The input spectrum at the output redshift.
fn linear_spectrum(args: &SpectrumInput) -> Result<LinearSpectrum> {
    for (name, z) in [("--z", args.z), ("--z-input", args.z_input)] {
        if !(z.is_finite() && z > -1.0) {
            bail!("{name} {z}: a redshift must be finite and > -1");
        }
    }
    let cosmology = Cosmology::gm2012();
    if let Some(kind) = args.eh {
        let kind = match kind {
            EhKind::Wiggle => TransferKind::Wiggle,
            EhKind::NoWiggle => TransferKind::NoWiggle,
        };
        return Ok(cosmology.eisenstein_hu_spectrum(kind, args.z, &LogGrid::default())?);
    }
    match &args.linear {
        Some(path) => {
            // The library error already names the file and the OS error; keep the message single.
            let columns = args.columns.unwrap_or_default();
            let p = LinearSpectrum::from_file_with_columns(path, columns)
                .map_err(|e| anyhow::anyhow!("{e}"))?;
            Ok(cosmology.rescale(&p, args.z_input, args.z)?)
        }
        None if GM2012_REDSHIFTS
            .iter()
            .any(|&zi| (zi - args.z).abs() < 1e-6) =>
        {
            Ok(LinearSpectrum::gm2012(args.z)?)
        }
        None => Ok(cosmology.rescale(&LinearSpectrum::gm2012(0.0)?, 0.0, args.z)?),
    }
}

/// k values from the first column of a file: finite, positive, strictly increasing.
fn read_k_file(path: &PathBuf) -> Result<Vec<f64>> {
    let text = std::fs::read_to_string(path)
        .with_context(|| format!("cannot read --k-file `{}`", path.display()))?;
    let mut k: Vec<f64> = Vec::new();
    for (i, line) in text.lines().enumerate() {
        let data = line.split('#').next().unwrap_or("");
        let Some(field) = data
            .split(|c: char| c == ',' || c.is_whitespace())
            .find(|s| !s.is_empty())
        else {
            continue;
        };
        let where_ = format!("{}:{}", path.display(), i + 1);
        let v: f64 = field
            .parse()
            .with_context(|| format!("{where_}: cannot parse `{field}` as k"))?;
        if !(v.is_finite() && v > 0.0) {
            bail!("{where_}: k = {v} h/Mpc is not a finite positive number");
        }
        if let Some(&prev) = k.last().filter(|&&prev| v <= prev) {
            bail!(
                "{where_}: k = {v} h/Mpc does not exceed the previous k = {prev} (k must increase)"
            );
        }
        k.push(v);
    }
    if k.is_empty() {
        bail!("--k-file `{}` contains no k values", path.display());
    }
    Ok(k)
}

/// The loop terms `model` needs: the 1-loop terms (in chunks behind a progress bar for long grids) and,
/// for N2, P15 (behind a progress bar while its angular table is built on first use).
pub fn loop_terms(
    k: &[f64],
    precision: &Precision,
    spectrum: &LinearSpectrum,
    model: RealModel,
) -> Result<OneLoopTerms> {
    let mut terms = one_loop_terms(k, precision, spectrum)?;
    if model.needs_p15() {
        with_table_progress("P15 angular table (once; cached)", |progress| {
            pt_spectra::loops::add_p15(&mut terms, spectrum, precision, progress)
        })?;
    }
    if model.needs_p17() {
        with_table_progress(
            "P17 angular table (once, a few minutes; cached)",
            |progress| pt_spectra::loops::add_p17(&mut terms, spectrum, precision, progress),
        )?;
    }
    if model.needs_two_loop() {
        let bar = ProgressBar::new(1).with_style(
            ProgressStyle::with_template("{msg} [{bar:40}] {percent}% ({eta})")
                .map_err(|e| anyhow::anyhow!("progress bar: {e}"))?,
        );
        bar.set_message(format!("2-loop mode coupling, {} k", k.len()));
        let progress = |done: usize, total: usize| {
            bar.set_length(total as u64);
            bar.set_position(done as u64);
        };
        pt_spectra::loops::add_two_loop(&mut terms, spectrum, precision, &|_, _| {}, &progress);
        bar.finish_and_clear();
    }
    Ok(terms)
}

/// Runs `work` with a progress bar on standard error that appears only if a table is being built.
fn with_table_progress(
    message: &'static str,
    work: impl FnOnce(&(dyn Fn(usize, usize) + Sync)),
) -> Result<()> {
    let bar = ProgressBar::hidden();
    bar.set_style(
        ProgressStyle::with_template("{msg} [{bar:40}] {pos}/{len} nodes ({eta})")
            .map_err(|e| anyhow::anyhow!("progress bar: {e}"))?,
    );
    bar.set_message(message);
    let progress = |done: usize, total: usize| {
        if bar.is_hidden() {
            bar.set_draw_target(indicatif::ProgressDrawTarget::stderr());
            bar.set_length(total as u64);
        }
        bar.set_position(done as u64);
    };
    work(&progress);
    bar.finish_and_clear();
    Ok(())
}

/// The 1-loop terms, in chunks behind a progress bar for long grids.
fn one_loop_terms(
    k: &[f64],
    precision: &Precision,
    spectrum: &LinearSpectrum,
) -> Result<OneLoopTerms> {
    if k.len() < PROGRESS_THRESHOLD {
        return Ok(OneLoopPlan::new(k, precision)?.par_evaluate(spectrum));
    }
    let bar = ProgressBar::new(k.len() as u64).with_style(
        ProgressStyle::with_template("{msg} [{bar:40}] {pos}/{len} k ({eta})")
            .map_err(|e| anyhow::anyhow!("progress bar: {e}"))?,
    );
    bar.set_message("1-loop terms");
    let mut all: Option<OneLoopTerms> = None;
    for chunk in k.chunks(CHUNK) {
        let part = OneLoopPlan::new(chunk, precision)?.par_evaluate(spectrum);
        match all.as_mut() {
            None => all = Some(part),
            Some(a) => append(a, part),
        }
        bar.inc(chunk.len() as u64);
    }
    bar.finish_and_clear();
    all.context("empty k grid")
}

fn append(all: &mut OneLoopTerms, part: OneLoopTerms) {
    all.k.extend(part.k);
    all.p_lin.extend(part.p_lin);
    for (a, b) in [
        (&mut all.dd, part.dd),
        (&mut all.dt, part.dt),
        (&mut all.tt, part.tt),
    ] {
        // Chunks carry only the 1-loop terms; the 2-loop ones are added to the whole grid afterwards.
        let PairTerms { p22, p13, .. } = b;
        a.p22.extend(p22);
        a.p13.extend(p13);
    }
}

/// The header line describing the 2-loop mode-coupling integration.
fn two_loop_line(precision: &Precision) -> String {
    let target = if precision.two_loop_tolerance > 0.0 {
        format!(
            "points added where the error exceeds {:e} of the correction",
            precision.two_loop_tolerance
        )
    } else {
        "fixed points".to_string()
    };
    format!(
        "# 2-loop mode coupling: randomised quasi-Monte Carlo, {} shifts x {} Sobol points at k = 0.16 \
         (scaled as k^3.5), seed {}; {target}\n",
        precision.two_loop_replicas, precision.two_loop_points, precision.two_loop_seed
    )
}

/// The '#' header: provenance, settings, and one line per column with its unit, then the names.
fn header(
    args: &Args,
    model: RealModel,
    spectrum: &LinearSpectrum,
    precision: &Precision,
    terms: &OneLoopTerms,
) -> String {
    let mut h = format!(
        "# pt-spectra {} real: model {model}, z = {}\n",
        env!("CARGO_PKG_VERSION"),
        args.input.z()
    );
    h += &args.input.describe(spectrum, precision);
    h += "# conventions: theta = -div v/(aHf); 1-loop correction = P22 + 2 P13; err_X = estimated absolute \
          numerical error of X\n";
    h += &format!(
        "# sigma_v2 = {:.8e} +- {:.1e} (Mpc/h)^2\n",
        terms.sigma_v2.value, terms.sigma_v2.error
    );
    if model.needs_two_loop() {
        h += &two_loop_line(precision);
    }
    if args.terms && model.propagator().is_some() {
        h += "# N_dd = N_delta^2, N_dt = N_delta N_theta, N_tt = N_theta^2: the factors multiplying \
              P_lin + P22 in the RPT model\n";
    }
    let columns = column_names(model, args.terms);
    for (i, (name, unit)) in columns.iter().enumerate() {
        h += &format!("# column {}: {name} [{unit}]\n", i + 1);
    }
    h += "# ";
    h += &columns
        .iter()
        .map(|(n, _)| n.as_str())
        .collect::<Vec<_>>()
        .join(" ");
    h.push('\n');
    h
}

const POWER: &str = "(Mpc/h)^3";

fn column_names(model: RealModel, terms: bool) -> Vec<(String, &'static str)> {
    let mut c: Vec<(String, &'static str)> = ["k", "P_lin", "P_dd", "P_dt", "P_tt"]
        .iter()
        .map(|n| (n.to_string(), if *n == "k" { "h/Mpc" } else { POWER }))
        .collect();
    if !terms {
        return c;
    }
    let with_err = |c: &mut Vec<(String, &'static str)>, name: String, unit| {
        c.push((name.clone(), unit));
        c.push((format!("err_{name}"), unit));
    };
    for s in ["dd", "dt", "tt"] {
        c.push((format!("err_P_{s}"), POWER));
    }
    for pair in Pair::ALL {
        let s = pair.suffix();
        with_err(&mut c, format!("P22_{s}"), POWER);
        with_err(&mut c, format!("P13_{s}"), POWER);
    }
    if model.needs_p15() {
        for pair in Pair::ALL {
            with_err(&mut c, format!("P15_{}", pair.suffix()), POWER);
        }
    }
    if model.needs_p17() {
        for pair in Pair::ALL {
            with_err(&mut c, format!("P17_{}", pair.suffix()), POWER);
        }
    }
    if model.needs_two_loop() {
        for pair in Pair::ALL {
            let s = pair.suffix();
            for name in ["P24", "P33", "P33_2L", "P2loop"] {
                with_err(&mut c, format!("{name}_{s}"), POWER);
            }
        }
    }
    with_err(&mut c, "sigma_v2".into(), "(Mpc/h)^2");
    if model.propagator().is_some() {
        for s in ["dd", "dt", "tt"] {
            with_err(&mut c, format!("N_{s}"), "1");
        }
    }
    c
}

fn table(spectra: &RealSpectra, terms: &OneLoopTerms, with_terms: bool) -> String {
    let mut out = String::with_capacity(spectra.k.len() * 200);
    for i in 0..spectra.k.len() {
        let mut row: Vec<f64> = vec![spectra.k[i], spectra.p_lin[i]];
        row.extend(spectra.spectra.iter().map(|s| s[i].value));
        if with_terms {
            row.extend(spectra.spectra.iter().map(|s| s[i].error));
            let push = |row: &mut Vec<f64>, e: Estimate| row.extend([e.value, e.error]);
            for pair in Pair::ALL {
                let t = terms.pair(pair);
                push(&mut row, t.p22[i]);
                push(&mut row, t.p13[i]);
            }
            if spectra.model.needs_p15() {
                for pair in Pair::ALL {
                    push(&mut row, terms.pair(pair).p15[i]);
                }
            }
            if spectra.model.needs_p17() {
                for pair in Pair::ALL {
                    push(&mut row, terms.pair(pair).p17[i]);
                }
            }
            if spectra.model.needs_two_loop() {
                for pair in Pair::ALL {
                    let t = terms.pair(pair);
                    let (red, irr) = (terms.p33_reducible(pair, i), t.p33_2l[i]);
                    push(&mut row, t.p24[i]);
                    push(
                        &mut row,
                        Estimate::new(red.value + irr.value, red.error + irr.error),
                    );
                    push(&mut row, irr);
                    push(&mut row, t.two_loop[i]);
                }
            }
            push(&mut row, terms.sigma_v2);
            if let Some(f) = &spectra.factors {
                for fj in f {
                    push(&mut row, fj[i]);
                }
            }
        }
        let line: Vec<String> = row.iter().map(|v| format!("{v:.9e}")).collect();
        out += &line.join(" ");
        out.push('\n');
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    fn write(name: &str, text: &str) -> PathBuf {
        let path =
            std::env::temp_dir().join(format!("pt-spectra-real-{}-{name}", std::process::id()));
        std::fs::write(&path, text).unwrap();
        path
    }

    #[test]
    fn k_files_are_validated_with_line_numbers() {
        let ok = write("ok", "# k\n0.01 1\n\n0.1, 2 # comment\n");
        assert_eq!(read_k_file(&ok).unwrap(), vec![0.01, 0.1]);
        for (name, text, needle) in [
            ("dec", "0.1\n0.05\n", ":2: k = 0.05"),
            ("nan", "0.1\nNaN\n", ":2: k = NaN"),
            ("neg", "-1\n", ":1: k = -1"),
            ("txt", "0.1\nabc\n", ":2: cannot parse `abc`"),
            ("empty", "# nothing\n", "no k values"),
        ] {
            let e = format!("{:#}", read_k_file(&write(name, text)).unwrap_err());
            assert!(e.contains(needle), "{name}: {e}");
        }
        let missing = format!(
            "{:#}",
            read_k_file(&PathBuf::from("/nonexistent/k")).unwrap_err()
        );
        assert!(missing.contains("/nonexistent/k"), "{missing}");
    }

    #[test]
    fn column_choices_are_one_based_and_checked() {
        assert_eq!(parse_columns("1,3").unwrap(), Columns::new(0, 2));
        for bad in ["0,1", "1", "1,1", "a,2", "1,2,3"] {
            assert!(parse_columns(bad).is_err(), "{bad}");
        }
    }

    #[test]
    fn every_row_has_one_value_per_named_column() {
        let p = LinearSpectrum::gm2012(0.0).unwrap();
        let terms = OneLoopPlan::new(&[0.05, 0.1], &Precision::fast())
            .unwrap()
            .evaluate(&p);
        for model in RealModel::ALL {
            for with_terms in [false, true] {
                let names = column_names(model, with_terms).len();
                let Ok(spectra) = from_terms(model, &terms) else {
                    continue;
                };
                let text = table(&spectra, &terms, with_terms);
                for line in text.lines() {
                    assert_eq!(
                        line.split_whitespace().count(),
                        names,
                        "{model} {with_terms}"
                    );
                }
            }
        }
    }
}
