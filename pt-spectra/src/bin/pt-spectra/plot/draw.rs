//! Figures as data (curves, panels) and their drawing with `plotters` on a PNG or SVG backend.

use anyhow::Result;
use plotters::coord::Shift;
use plotters::prelude::*;

/// How a curve is drawn.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Style {
    /// A solid line.
    Solid,
    /// A dashed line.
    Dashed,
    /// A dotted line.
    Dotted,
    /// Dot-dashed (reference lines): drawn as long dashes.
    DotDashed,
    /// Markers only (measured data).
    Points,
}

/// One curve; non-finite points split it into pieces.
pub struct Curve {
    /// The legend entry (none if empty).
    pub label: String,
    /// x values (k, k_max or a parameter).
    pub x: Vec<f64>,
    /// y values.
    pub y: Vec<f64>,
    /// Optional (low, high) error bars.
    pub bars: Option<Vec<(f64, f64)>>,
    /// Line style.
    pub style: Style,
    /// The colour; by default the panel's palette by curve index.
    pub color: Option<RGBColor>,
}

impl Curve {
    /// A solid curve in the palette colour.
    pub fn new(label: impl Into<String>, x: Vec<f64>, y: Vec<f64>) -> Self {
        Self {
            label: label.into(),
            x,
            y,
            bars: None,
            style: Style::Solid,
            color: None,
        }
    }

    /// With line style `style`.
    pub fn styled(mut self, style: Style) -> Self {
        self.style = style;
        self
    }

    /// With colour `color`.
    pub fn colored(mut self, color: RGBColor) -> Self {
        self.color = Some(color);
        self
    }

    /// With error bars.
    pub fn with_bars(mut self, bars: Vec<(f64, f64)>) -> Self {
        self.bars = Some(bars);
        self
    }
}

/// One panel: curves, its y axis, horizontal reference lines and bands, labelled vertical lines.
pub struct Panel {
    /// The y-axis label.
    pub y_label: String,
    /// The curves.
    pub curves: Vec<Curve>,
    /// Horizontal reference lines (value, style).
    pub lines: Vec<(f64, Style)>,
    /// Shaded horizontal bands (low, high).
    pub bands: Vec<(f64, f64)>,
    /// Vertical lines at x with a label.
    pub vlines: Vec<(f64, String)>,
    /// Logarithmic y axis (non-positive values are left out).
    pub log_y: bool,
    /// Height relative to the other panels (value panels 2, ratio panels 1).
    pub weight: u32,
    /// Limits of the y axis: values outside are left out (ratios near a zero crossing).
    pub clamp: Option<(f64, f64)>,
    /// Where the legend goes, if the panel has one (curves with labels).
    pub legend: Option<SeriesLabelPosition>,
}

impl Panel {
    /// An empty linear panel.
    pub fn new(y_label: impl Into<String>) -> Self {
        Self {
            y_label: y_label.into(),
            curves: Vec::new(),
            lines: Vec::new(),
            bands: Vec::new(),
            vlines: Vec::new(),
            log_y: false,
            weight: 1,
            clamp: None,
            legend: Some(SeriesLabelPosition::LowerLeft),
        }
    }

    /// With height weight 2 (the value panel above a ratio panel).
    pub fn tall(mut self) -> Self {
        self.weight = 2;
        self
    }
}

/// A figure: panels stacked vertically over a shared x axis, their heights in proportion to their
/// weights.
pub struct Figure {
    /// The title.
    pub title: String,
    /// The x-axis label.
    pub x_label: String,
    /// Logarithmic x axis.
    pub log_x: bool,
    /// The panels, top to bottom.
    pub panels: Vec<Panel>,
    /// The height in pixels (the width is 1000).
    pub height: u32,
}

impl Figure {
    /// A figure 800 pixels high.
    pub fn new(title: impl Into<String>, x_label: &str, log_x: bool, panels: Vec<Panel>) -> Self {
        Self {
            title: title.into(),
            x_label: x_label.into(),
            log_x,
            panels,
            height: 800,
        }
    }
}

/// The palette: black first (linear theory, truth), then the paper's red, blue, green, orange.
pub const COLORS: [RGBColor; 10] = [
    RGBColor(0, 0, 0),
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

/// The i-th palette colour.
pub fn color(i: usize) -> RGBColor {
    COLORS[i % COLORS.len()]
}

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

/// `v` on a log axis: log10 v, NaN for v ≤ 0.
fn log_or_nan(v: f64) -> f64 {
    if v > 0.0 {
        v.log10()
    } else {
        f64::NAN
    }
}

/// The label of a log-axis tick at u = log10 v.
fn log_label(u: &f64) -> String {
    let v = 10f64.powf(*u);
    let digits = ((-v.log10().floor()) as i64 + 1).clamp(0, 6) as usize;
    if v >= 1e5 {
        format!("{v:.0e}")
    } else {
        format!("{v:.digits$}")
    }
}

/// The finite runs of `points`.
fn pieces(points: Vec<(f64, f64)>) -> Vec<Vec<(f64, f64)>> {
    let mut out = vec![Vec::new()];
    for p in points {
        if p.0.is_finite() && p.1.is_finite() {
            out.last_mut().expect("non-empty").push(p);
        } else if !out.last().expect("non-empty").is_empty() {
            out.push(Vec::new());
        }
    }
    out.retain(|p| !p.is_empty());
    out
}

/// Draws `fig` on `root` and presents it (writes the file of a file backend).
pub fn draw<DB: DrawingBackend>(root: DrawingArea<DB, Shift>, fig: &Figure) -> Result<()>
where
    DB::ErrorType: 'static,
{
    let e = |e: DrawingAreaErrorKind<DB::ErrorType>| anyhow::anyhow!("drawing: {e:?}");
    root.fill(&WHITE).map_err(e)?;
    let whole = root.clone();
    let root = root.titled(&fig.title, ("sans-serif", 22)).map_err(e)?;
    let (_, height) = root.dim_in_pixel();
    let n = fig.panels.len();
    let unit = height
        / fig
            .panels
            .iter()
            .map(|p| p.weight.max(1))
            .sum::<u32>()
            .max(1);
    let mut areas = Vec::new();
    let mut rest = root;
    for (i, panel) in fig.panels.iter().enumerate() {
        if i + 1 == n {
            areas.push(rest.clone());
        } else {
            let (top, bottom) = rest.split_vertically(panel.weight.max(1) * unit);
            areas.push(top);
            rest = bottom;
        }
    }
    // Log axes are drawn as linear axes in log10 with labels 10^u (plotters' LogCoord can hang while
    // placing its key points).
    let tx = |x: f64| if fig.log_x { log_or_nan(x) } else { x };
    let xs = fig.panels.iter().flat_map(|p| {
        p.curves
            .iter()
            .flat_map(|c| c.x.iter().copied())
            .chain(p.vlines.iter().map(|v| v.0))
    });
    let (x_lo, x_hi) = bounds(xs.map(tx));
    for (i, (area, panel)) in areas.iter().zip(&fig.panels).enumerate() {
        let clamp = panel.clamp.unwrap_or((f64::NEG_INFINITY, f64::INFINITY));
        let ty = |y: f64| {
            if !(clamp.0..=clamp.1).contains(&y) {
                f64::NAN
            } else if panel.log_y {
                log_or_nan(y)
            } else {
                y
            }
        };
        let ys = panel
            .curves
            .iter()
            .flat_map(|c| {
                c.y.iter()
                    .copied()
                    .chain(c.bars.iter().flatten().flat_map(|b| [b.0, b.1]))
            })
            .chain(panel.lines.iter().map(|l| l.0))
            .chain(panel.bands.iter().flat_map(|b| [b.0, b.1]));
        let (y_lo, y_hi) = bounds(ys.map(ty));
        let last = i + 1 == fig.panels.len();
        let mut chart = ChartBuilder::on(area)
            .margin(8)
            .y_label_area_size(80)
            .x_label_area_size(if last { 45 } else { 8 })
            .build_cartesian_2d(x_lo..x_hi, y_lo..y_hi)
            .map_err(e)?;
        let none = |_: &f64| String::new();
        let mut mesh = chart.configure_mesh();
        // Few labels and no minor lines on short panels, which they would fill.
        mesh.y_desc(panel.y_label.as_str())
            .label_style(("sans-serif", 14))
            .y_labels(if panel.weight >= 2 { 10 } else { 5 })
            .max_light_lines(if panel.weight >= 2 { 4 } else { 1 });
        if panel.log_y {
            mesh.y_label_formatter(&log_label);
        }
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
            let (a, b) = (ty(a), ty(b));
            chart
                .draw_series(std::iter::once(Rectangle::new(
                    [(x_lo, a), (x_hi, b)],
                    RGBColor(200, 200, 200).mix(0.35).filled(),
                )))
                .map_err(e)?;
        }
        let grey = RGBColor(110, 110, 110);
        for &(y, style) in &panel.lines {
            let y = ty(y);
            line(&mut chart, vec![(x_lo, y), (x_hi, y)], style, grey, 1).map_err(e)?;
        }
        for (x, label) in &panel.vlines {
            let x = tx(*x);
            line(
                &mut chart,
                vec![(x, y_lo), (x, y_hi)],
                Style::DotDashed,
                grey,
                1,
            )
            .map_err(e)?;
            chart
                .draw_series(std::iter::once(Text::new(
                    label.clone(),
                    (x, y_hi - 0.06 * (y_hi - y_lo)),
                    ("sans-serif", 13),
                )))
                .map_err(e)?;
        }
        for (c, curve) in panel.curves.iter().enumerate() {
            let color = curve.color.unwrap_or_else(|| color(c));
            let points: Vec<(f64, f64)> = curve
                .x
                .iter()
                .map(|&x| tx(x))
                .zip(curve.y.iter().map(|&y| ty(y)))
                .collect();
            for (j, piece) in pieces(points.clone()).into_iter().enumerate() {
                let series = line(&mut chart, piece, curve.style, color, 2).map_err(e)?;
                if j == 0 && !curve.label.is_empty() {
                    let style = curve.style;
                    series.label(curve.label.as_str()).legend(move |(x, y)| {
                        let s = legend_strokes(style);
                        let path =
                            |k: usize| PathElement::new(s[k].to_vec(), color.stroke_width(2));
                        EmptyElement::at((x, y)) + path(0) + path(1) + path(2) + path(3)
                    });
                }
            }
            if let Some(bars) = &curve.bars {
                chart
                    .draw_series(
                        points
                            .iter()
                            .zip(bars)
                            .filter(|((x, y), (lo, hi))| {
                                x.is_finite() && y.is_finite() && lo.is_finite() && hi.is_finite()
                            })
                            .map(|(&(x, y), &(lo, hi))| {
                                ErrorBar::new_vertical(x, ty(lo), y, ty(hi), color.filled(), 6)
                            }),
                    )
                    .map_err(e)?;
            }
        }
        if let Some(position) = panel.legend.clone() {
            if panel.curves.iter().any(|c| !c.label.is_empty()) {
                chart
                    .configure_series_labels()
                    .background_style(WHITE.mix(0.85))
                    .border_style(BLACK)
                    .label_font(("sans-serif", 13))
                    .position(position)
                    .draw()
                    .map_err(e)?;
            }
        }
    }
    // Written here, where a failure is an error (on drop, plotters would ignore it).
    whole.present().map_err(e)
}

type Chart<'a, DB> = ChartContext<
    'a,
    DB,
    Cartesian2d<plotters::coord::types::RangedCoordf64, plotters::coord::types::RangedCoordf64>,
>;

/// Draws `points` in `style`; returns the series for its legend entry.
fn line<'a, 'b, DB: DrawingBackend + 'a>(
    chart: &'b mut Chart<'a, DB>,
    points: Vec<(f64, f64)>,
    style: Style,
    color: RGBColor,
    width: u32,
) -> std::result::Result<
    &'b mut plotters::chart::SeriesAnno<'a, DB>,
    DrawingAreaErrorKind<DB::ErrorType>,
> {
    let stroke = color.stroke_width(width);
    match style {
        Style::Solid => chart.draw_series(LineSeries::new(points, stroke)),
        Style::Dashed => chart.draw_series(DashedLineSeries::new(points, 10, 6, stroke)),
        Style::Dotted => chart.draw_series(DashedLineSeries::new(points, 2, 5, stroke)),
        Style::DotDashed => chart.draw_series(DashedLineSeries::new(points, 14, 5, stroke)),
        Style::Points => chart.draw_series(
            points
                .into_iter()
                .map(move |p| Circle::new(p, 3, color.filled())),
        ),
    }
}

/// The four strokes of a curve's legend mark, relative to its anchor: a line, dashes, dots, or a small
/// square for markers (four strokes for every style, so that the marks are one element type).
fn legend_strokes(style: Style) -> [[(i32, i32); 2]; 4] {
    match style {
        Style::Solid => [
            [(0, 0), (5, 0)],
            [(5, 0), (10, 0)],
            [(10, 0), (15, 0)],
            [(15, 0), (20, 0)],
        ],
        Style::Dashed => [
            [(0, 0), (7, 0)],
            [(0, 0), (7, 0)],
            [(12, 0), (19, 0)],
            [(12, 0), (19, 0)],
        ],
        Style::DotDashed => [
            [(0, 0), (9, 0)],
            [(0, 0), (9, 0)],
            [(13, 0), (22, 0)],
            [(13, 0), (22, 0)],
        ],
        Style::Dotted => [
            [(0, 0), (2, 0)],
            [(6, 0), (8, 0)],
            [(12, 0), (14, 0)],
            [(18, 0), (20, 0)],
        ],
        Style::Points => [
            [(7, -3), (13, -3)],
            [(7, 3), (13, 3)],
            [(7, -3), (7, 3)],
            [(13, -3), (13, 3)],
        ],
    }
}
