//! `pt-spectra plot`: the kinds of figure the paper shows, from the tables the other subcommands write,
//! as PNG or SVG (by the output extension), with the `plotters` crate and an embedded DejaVu Sans font.

use anyhow::{bail, Context, Result};
use plotters::coord::Shift;
use plotters::prelude::*;
use std::path::{Path, PathBuf};

/// The embedded font (DejaVu Sans, Bitstream Vera licence: `pt-spectra/data/fonts/LICENSE-DejaVu.txt`).
const FONT: &[u8] = include_bytes!("../../../data/fonts/DejaVuSans.ttf");

/// What to draw.
#[derive(Clone, Copy, Debug, clap::ValueEnum)]
pub enum Kind {
    /// P_dd/P_nowiggle of every model (`real --model all`), with the ratio to `--reference`.
    Models,
    /// N² (the `N_dd` column) and the effective σ_v² = −2 ln N/k² of RPT models (`real --model …-rpt-… --terms`).
    Propagators,
    /// k·P_ℓ of RSD models (`rsd`), with the ratio to `--data` (k P0 s0 P2 s2 P4 s4) if given.
    Multipoles,
    /// Best-fit f (and σ0) versus k_max (`fit`), with 1% and 2% bands around `--truth`.
    Fit,
}

/// Arguments of `pt-spectra plot`.
#[derive(clap::Args, Debug)]
pub struct Args {
    /// The kind of figure.
    #[arg(value_enum)]
    kind: Kind,
    /// Input tables (output of `real`, `rsd` or `fit`); several are overlaid where that makes sense.
    #[arg(required = true)]
    inputs: Vec<PathBuf>,
    /// Output file: `.png` or `.svg`.
    #[arg(long, value_name = "FILE")]
    out: PathBuf,
    /// `models`: the column the ratio panel divides by. Default: the last model.
    #[arg(long, value_name = "MODEL")]
    reference: Option<String>,
    /// `multipoles`: measured multipoles for the ratio panel.
    #[arg(long, value_name = "FILE")]
    data: Option<PathBuf>,
    /// `fit`: the true f, drawn with 1% and 2% bands.
    #[arg(long, value_name = "F")]
    truth: Option<f64>,
    /// Figure title.
    #[arg(long, value_name = "TEXT", default_value = "")]
    title: String,
}

/// Measured multipoles: k, then P_ℓ and σ_ℓ for ℓ = 0, 2, 4.
type Measured = (Vec<f64>, Vec<Vec<f64>>, Vec<Vec<f64>>);

/// A table written by pt-spectra: the names from its `# k …` line, and its rows.
struct Named {
    title: String,
    names: Vec<String>,
    rows: Vec<Vec<f64>>,
}

impl Named {
    fn read(path: &Path) -> Result<Self> {
        let text = std::fs::read_to_string(path)
            .with_context(|| format!("cannot read `{}`", path.display()))?;
        let names: Vec<String> = text
            .lines()
            .rfind(|l| l.starts_with("# k"))
            .with_context(|| {
                format!(
                    "`{}`: no `# k …` header line (not a pt-spectra table?)",
                    path.display()
                )
            })?
            .trim_start_matches('#')
            .split_whitespace()
            .map(str::to_string)
            .collect();
        let mut rows = Vec::new();
        for (i, line) in text
            .lines()
            .enumerate()
            .filter(|(_, l)| !l.starts_with('#') && !l.trim().is_empty())
        {
            let row: Vec<f64> = line
                .split_whitespace()
                .map(|v| v.parse::<f64>())
                .collect::<std::result::Result<_, _>>()
                .with_context(|| format!("`{}`:{}: not a row of numbers", path.display(), i + 1))?;
            if row.len() != names.len() {
                bail!(
                    "`{}`:{}: {} values for {} columns",
                    path.display(),
                    i + 1,
                    row.len(),
                    names.len()
                );
            }
            rows.push(row);
        }
        if rows.is_empty() {
            bail!("`{}`: no data rows", path.display());
        }
        let title = text
            .lines()
            .next()
            .unwrap_or("")
            .trim_start_matches('#')
            .trim()
            .to_string();
        Ok(Self { title, names, rows })
    }

    fn column(&self, name: &str) -> Option<Vec<f64>> {
        let j = self.names.iter().position(|n| n == name)?;
        Some(self.rows.iter().map(|r| r[j]).collect())
    }

    fn need(&self, name: &str) -> Result<Vec<f64>> {
        self.column(name).with_context(|| {
            format!(
                "the table has no column `{name}` (it has {})",
                self.names.join(" ")
            )
        })
    }
}

/// One curve.
struct Curve {
    label: String,
    x: Vec<f64>,
    y: Vec<f64>,
    /// Optional (low, high) error bars.
    bars: Option<Vec<(f64, f64)>>,
}

/// One panel: curves, axis labels, and horizontal reference lines (value, dashed?).
struct Panel {
    y_label: String,
    curves: Vec<Curve>,
    lines: Vec<f64>,
    bands: Vec<(f64, f64)>,
}

/// A figure: panels stacked vertically over a shared x axis.
struct Figure {
    title: String,
    x_label: String,
    log_x: bool,
    panels: Vec<Panel>,
}

const COLORS: [RGBColor; 12] = [
    RGBColor(0, 0, 0),
    RGBColor(188, 189, 34),
    RGBColor(0, 90, 50),
    RGBColor(214, 39, 40),
    RGBColor(31, 119, 180),
    RGBColor(44, 160, 44),
    RGBColor(255, 127, 14),
    RGBColor(148, 103, 189),
    RGBColor(140, 86, 75),
    RGBColor(227, 119, 194),
    RGBColor(127, 127, 127),
    RGBColor(23, 190, 207),
];

fn bounds(values: impl Iterator<Item = f64>) -> (f64, f64) {
    let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
    for v in values.filter(|v| v.is_finite()) {
        lo = lo.min(v);
        hi = hi.max(v);
    }
    if !lo.is_finite() {
        return (0.0, 1.0);
    }
    let pad = 0.05 * (hi - lo).max(1e-12 * hi.abs().max(1.0));
    (lo - pad, hi + pad)
}

fn draw<DB: DrawingBackend>(root: DrawingArea<DB, Shift>, fig: &Figure) -> Result<()>
where
    DB::ErrorType: 'static,
{
    let e = |e: DrawingAreaErrorKind<DB::ErrorType>| anyhow::anyhow!("drawing: {e:?}");
    root.fill(&WHITE).map_err(e)?;
    let root = root.titled(&fig.title, ("sans-serif", 22)).map_err(e)?;
    let (_, height) = root.dim_in_pixel();
    let n = fig.panels.len() as u32;
    // The first panel gets twice the height of the others.
    let unit = height / (n + 1);
    let mut areas = Vec::new();
    let mut rest = root;
    for i in 0..n {
        if i + 1 == n {
            areas.push(rest.clone());
        } else {
            let h = if i == 0 { 2 * unit } else { unit };
            let (top, bottom) = rest.split_vertically(h);
            areas.push(top);
            rest = bottom;
        }
    }
    // Log axes are drawn as linear axes in log10 x with labels 10^u (plotters' LogCoord can hang while
    // placing its key points).
    let tx = |x: f64| if fig.log_x { x.log10() } else { x };
    let xs = fig
        .panels
        .iter()
        .flat_map(|p| p.curves.iter().flat_map(|c| c.x.iter().copied()));
    let (x_lo, x_hi) = bounds(xs.filter(|&x| !fig.log_x || x > 0.0).map(tx));
    for (i, (area, panel)) in areas.iter().zip(&fig.panels).enumerate() {
        let ys = panel
            .curves
            .iter()
            .flat_map(|c| {
                c.y.iter()
                    .copied()
                    .chain(c.bars.iter().flatten().flat_map(|b| [b.0, b.1]))
            })
            .chain(panel.lines.iter().copied())
            .chain(panel.bands.iter().flat_map(|b| [b.0, b.1]));
        let (y_lo, y_hi) = bounds(ys);
        let last = i + 1 == fig.panels.len();
        let mut builder = ChartBuilder::on(area);
        builder
            .margin(8)
            .y_label_area_size(80)
            .x_label_area_size(if last { 45 } else { 8 });
        macro_rules! body {
            ($chart:expr) => {{
                let mut chart = $chart;
                let mut mesh = chart.configure_mesh();
                mesh.y_desc(panel.y_label.as_str())
                    .label_style(("sans-serif", 14));
                let log_label = |u: &f64| {
                    let v = 10f64.powf(*u);
                    let digits = ((-v.log10().floor()) as i64 + 1).clamp(0, 6) as usize;
                    format!("{v:.digits$}")
                };
                let none = |_: &f64| String::new();
                if last {
                    mesh.x_desc(fig.x_label.as_str());
                    if fig.log_x {
                        mesh.x_label_formatter(&log_label);
                    }
                } else {
                    mesh.x_label_formatter(&none);
                }
                mesh.draw().map_err(e)?;
                for &(a, b) in &panel.bands {
                    chart
                        .draw_series(std::iter::once(Rectangle::new(
                            [(x_lo, a), (x_hi, b)],
                            RGBColor(200, 200, 200).mix(0.35).filled(),
                        )))
                        .map_err(e)?;
                }
                for &y in &panel.lines {
                    chart
                        .draw_series(LineSeries::new(
                            [(x_lo, y), (x_hi, y)],
                            RGBColor(110, 110, 110).stroke_width(1),
                        ))
                        .map_err(e)?;
                }
                for (c, curve) in panel.curves.iter().enumerate() {
                    let color = COLORS[c % COLORS.len()];
                    let points: Vec<(f64, f64)> = curve
                        .x
                        .iter()
                        .map(|&x| tx(x))
                        .zip(curve.y.iter().copied())
                        .filter(|p| p.0.is_finite() && p.1.is_finite())
                        .collect();
                    let series = chart
                        .draw_series(LineSeries::new(points.clone(), color.stroke_width(2)))
                        .map_err(e)?;
                    if i == 0 {
                        series.label(curve.label.as_str()).legend(move |(x, y)| {
                            PathElement::new(vec![(x, y), (x + 20, y)], color.stroke_width(2))
                        });
                    }
                    if let Some(bars) = &curve.bars {
                        chart
                            .draw_series(
                                curve
                                    .x
                                    .iter()
                                    .zip(&curve.y)
                                    .zip(bars)
                                    .filter(|((_, y), (lo, hi))| {
                                        y.is_finite() && lo.is_finite() && hi.is_finite()
                                    })
                                    .map(|((&x, &y), &(lo, hi))| {
                                        ErrorBar::new_vertical(tx(x), lo, y, hi, color.filled(), 6)
                                    }),
                            )
                            .map_err(e)?;
                        chart
                            .draw_series(points.iter().map(|&p| Circle::new(p, 3, color.filled())))
                            .map_err(e)?;
                    }
                }
                if i == 0 {
                    chart
                        .configure_series_labels()
                        .background_style(WHITE.mix(0.85))
                        .border_style(BLACK)
                        .label_font(("sans-serif", 13))
                        .position(SeriesLabelPosition::LowerLeft)
                        .draw()
                        .map_err(e)?;
                }
            }};
        }
        body!(builder
            .build_cartesian_2d(x_lo..x_hi, y_lo..y_hi)
            .map_err(e)?);
    }
    Ok(())
}

fn models(args: &Args) -> Result<Figure> {
    let t = Named::read(&args.inputs[0])?;
    let k = t.need("k")?;
    let names: Vec<&String> = t
        .names
        .iter()
        .skip(2)
        .filter(|n| !n.starts_with("err_"))
        .collect();
    if names.is_empty() {
        bail!(
            "`{}`: no model columns (expected `real --model all` output)",
            args.inputs[0].display()
        );
    }
    let reference = args
        .reference
        .clone()
        .unwrap_or_else(|| names[names.len() - 1].clone());
    let r = t.need(&reference)?;
    let mut upper = Vec::new();
    let mut lower = Vec::new();
    for name in names {
        let y = t.need(name)?;
        lower.push(Curve {
            label: name.clone(),
            x: k.clone(),
            y: y.iter().zip(&r).map(|(a, b)| a / b).collect(),
            bars: None,
        });
        upper.push(Curve {
            label: name.clone(),
            x: k.clone(),
            y,
            bars: None,
        });
    }
    Ok(Figure {
        title: t.title,
        x_label: "k [h/Mpc]".into(),
        log_x: true,
        panels: vec![
            Panel {
                y_label: "P_dd / P_nowiggle".into(),
                curves: upper,
                lines: vec![],
                bands: vec![],
            },
            Panel {
                y_label: format!("ratio to {reference}"),
                curves: lower,
                lines: vec![1.0],
                bands: vec![(0.99, 1.01)],
            },
        ],
    })
}

fn propagators(args: &Args) -> Result<Figure> {
    let (mut upper, mut lower) = (Vec::new(), Vec::new());
    for path in &args.inputs {
        let t = Named::read(path)?;
        let k = t.need("k")?;
        let n = t.need("N_dd")?;
        let label = t
            .title
            .split("model ")
            .nth(1)
            .and_then(|s| s.split(',').next())
            .unwrap_or("model")
            .to_string();
        upper.push(Curve {
            label: label.clone(),
            x: k.clone(),
            y: n.clone(),
            bars: None,
        });
        let sigma: Vec<f64> = k
            .iter()
            .zip(&n)
            .map(|(k, n)| -(n.abs().max(1e-300)).ln() / (k * k))
            .collect();
        lower.push(Curve {
            label,
            x: k,
            y: sigma,
            bars: None,
        });
    }
    Ok(Figure {
        title: "RPT damping N_dd and effective sigma_v^2".into(),
        x_label: "k [h/Mpc]".into(),
        log_x: true,
        panels: vec![
            Panel {
                y_label: "N^2 = N_d N_d (factor on P_lin + P22)".into(),
                curves: upper,
                lines: vec![1.0],
                bands: vec![],
            },
            Panel {
                y_label: "sigma_v,eff^2 = -2 ln N / k^2 [(Mpc/h)^2]".into(),
                curves: lower,
                lines: vec![],
                bands: vec![],
            },
        ],
    })
}

fn multipoles(args: &Args) -> Result<Figure> {
    let data = args
        .data
        .as_ref()
        .map(|p| Named::read_data(p))
        .transpose()?;
    let mut panels = Vec::new();
    let mut ratio = Vec::new();
    for (input_index, path) in args.inputs.iter().enumerate() {
        let t = Named::read(path)?;
        let k = t.need("k")?;
        let label = t
            .title
            .split("rsd: ")
            .nth(1)
            .and_then(|s| s.split(',').next())
            .unwrap_or("model")
            .to_string();
        for (l, name) in ["P0", "P2", "P4"].iter().enumerate() {
            let Some(p) = t.column(name) else { continue };
            if panels.len() <= l {
                panels.push(Panel {
                    y_label: format!("k {name} [(Mpc/h)^2]"),
                    curves: vec![],
                    lines: vec![],
                    bands: vec![],
                });
            }
            panels[l].curves.push(Curve {
                label: format!("{label} {name}"),
                x: k.clone(),
                y: k.iter().zip(&p).map(|(k, p)| k * p).collect(),
                bars: None,
            });
            if let Some(d) = &data {
                let (dk, dv, ds) = (&d.0, &d.1[l], &d.2[l]);
                if input_index == 0 {
                    panels[l].curves.push(Curve {
                        label: format!("data {name}"),
                        x: dk.clone(),
                        y: dk.iter().zip(dv).map(|(k, p)| k * p).collect(),
                        bars: Some(
                            dk.iter()
                                .zip(dv.iter().zip(ds))
                                .map(|(k, (p, s))| (k * (p - s), k * (p + s)))
                                .collect(),
                        ),
                    });
                }
                // Ratios only for P0 and P2: P4 crosses zero in some models.
                if l < 2 {
                    let interp: Vec<f64> = dk.iter().map(|&x| interpolate(&k, &p, x)).collect();
                    ratio.push(Curve {
                        label: format!("{label} {name}"),
                        x: dk.clone(),
                        y: dv.iter().zip(&interp).map(|(d, m)| d / m).collect(),
                        bars: None,
                    });
                }
            }
        }
    }
    if panels.is_empty() {
        bail!("no P0, P2 or P4 column in the inputs (expected `rsd` output)");
    }
    if !ratio.is_empty() {
        panels.push(Panel {
            y_label: "data / model".into(),
            curves: ratio,
            lines: vec![1.0],
            bands: vec![(0.98, 1.02)],
        });
    }
    Ok(Figure {
        title: "Redshift-space multipoles".into(),
        x_label: "k [h/Mpc]".into(),
        log_x: false,
        panels,
    })
}

/// y(at), linear between the points (x increasing); a table of one row is constant, of none NaN.
fn interpolate(x: &[f64], y: &[f64], at: f64) -> f64 {
    if x.len() < 2 {
        // `clamp(1, x.len() - 1)` below would panic.
        return y.first().copied().unwrap_or(f64::NAN);
    }
    let j = x.partition_point(|&v| v <= at).clamp(1, x.len() - 1);
    let t = (at - x[j - 1]) / (x[j] - x[j - 1]);
    y[j - 1] + t * (y[j] - y[j - 1])
}

impl Named {
    /// Measured multipoles k P0 s0 P2 s2 P4 s4 (1-based columns 1..7, as `fit` reads by default).
    fn read_data(path: &Path) -> Result<Measured> {
        let t = pt_spectra::table::Table::read(path, &[0, 1, 2, 3, 4, 5, 6])
            .map_err(|e| anyhow::anyhow!("--data: {e}"))?;
        let c = &t.columns;
        Ok((
            c[0].clone(),
            vec![c[1].clone(), c[3].clone(), c[5].clone()],
            vec![c[2].clone(), c[4].clone(), c[6].clone()],
        ))
    }
}

fn fits(args: &Args) -> Result<Figure> {
    let mut f_panel = Panel {
        y_label: "f".into(),
        curves: vec![],
        lines: vec![],
        bands: vec![],
    };
    let mut s_panel = Panel {
        y_label: "sigma0 [Mpc/h]".into(),
        curves: vec![],
        lines: vec![],
        bands: vec![],
    };
    if let Some(truth) = args.truth {
        f_panel.lines.push(truth);
        f_panel.bands = vec![(0.98 * truth, 1.02 * truth), (0.99 * truth, 1.01 * truth)];
    }
    for path in &args.inputs {
        let t = Named::read(path)?;
        let k = t.need("k_max")?;
        let label = t
            .title
            .split("fit: ")
            .nth(1)
            .and_then(|s| s.split(", z").next())
            .unwrap_or("fit")
            .to_string();
        for (panel, name) in [(&mut f_panel, "f"), (&mut s_panel, "sigma0")] {
            let Some(v) = t.column(name) else { continue };
            let (lo, hi) = (
                t.need(&format!("{name}_lo"))?,
                t.need(&format!("{name}_hi"))?,
            );
            panel.curves.push(Curve {
                label: label.clone(),
                x: k.clone(),
                y: v,
                bars: Some(lo.into_iter().zip(hi).collect()),
            });
        }
    }
    let mut panels = vec![f_panel];
    if !s_panel.curves.is_empty() {
        panels.push(s_panel);
    }
    Ok(Figure {
        title: "Best fit versus k_max".into(),
        x_label: "k_max [h/Mpc]".into(),
        log_x: false,
        panels,
    })
}

/// Runs the subcommand.
pub fn run(args: &Args) -> Result<()> {
    // Registering the same font twice is harmless; failure means the embedded file is broken.
    plotters::style::register_font("sans-serif", FontStyle::Normal, FONT)
        .map_err(|_| anyhow::anyhow!("embedded font"))?;
    let mut figure = match args.kind {
        Kind::Models => models(args)?,
        Kind::Propagators => propagators(args)?,
        Kind::Multipoles => multipoles(args)?,
        Kind::Fit => fits(args)?,
    };
    // Each kind has its own default title; --title replaces it.
    if !args.title.is_empty() {
        figure.title.clone_from(&args.title);
    }
    let size = (1000, 800);
    match args
        .out
        .extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase)
        .as_deref()
    {
        Some("png") => draw(
            BitMapBackend::new(&args.out, size).into_drawing_area(),
            &figure,
        )?,
        Some("svg") => draw(
            SVGBackend::new(&args.out, size).into_drawing_area(),
            &figure,
        )?,
        _ => bail!(
            "--out {}: the file name must end in .png or .svg",
            args.out.display()
        ),
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn model_tables_of_one_row_interpolate_without_panic() {
        assert_eq!(interpolate(&[0.1], &[5.0], 0.3), 5.0);
        assert!(interpolate(&[], &[], 0.3).is_nan());
        assert_eq!(interpolate(&[0.1, 0.3], &[1.0, 3.0], 0.2), 2.0);
    }
}
