//! Real-space figures: the models over the no-wiggle spectrum with measured data, and the RPT
//! propagators (the paper's FigAz0 and FigAz15).

use super::draw::{color, Curve, Figure, Panel, Style};
use super::table::{interpolate, Measured, Named};
use super::Args;
use anyhow::{bail, Result};

/// The colour of a real-space model in the paper's redshift-space figures: linear black, 1L-SPT red,
/// 2L-SPT blue, RPT-N1 green, RPT-N2 orange (N0 purple, N3 brown).
pub fn rsd_color(name: &str) -> plotters::style::RGBColor {
    color(match name {
        "linear" => 0,
        "1l-spt" => 1,
        "2l-spt" => 2,
        n if n.ends_with("n1") => 3,
        n if n.ends_with("n2") => 4,
        n if n.ends_with("n0") => 5,
        _ => 6,
    })
}

/// The paper's colour and line of a real-space model in its real-space figures: linear black dotted;
/// SPT blue, RPT-N0 red, N1 green, N2 orange, N3 purple; 1-loop solid, 2-loop dashed.
pub fn model_look(name: &str) -> (plotters::style::RGBColor, Style) {
    if name == "linear" {
        return (color(0), Style::Dotted);
    }
    let c = match name.rsplit('-').next().unwrap_or("") {
        "spt" => 2,
        "n0" => 1,
        "n1" => 3,
        "n2" => 4,
        "n3" => 5,
        _ => 6,
    };
    let style = if name.starts_with("2l") {
        Style::Dashed
    } else {
        Style::Solid
    };
    (color(c), style)
}

/// `models`: P_dd/P_nw of every model; the ratio panel is data/model with --data, else
/// model/--reference.
pub fn models(args: &Args) -> Result<Figure> {
    let input = args.one_input()?;
    let t = Named::read(input)?;
    let k = t.need("k")?;
    let p_nw = t.need("P_nw")?;
    let names: Vec<&String> = t
        .names
        .iter()
        .skip(2)
        .filter(|n| !n.starts_with("err_"))
        .collect();
    if names.is_empty() {
        bail!(
            "`{}`: no model columns (expected `real --model all` output)",
            input.display()
        );
    }
    let bands = args.bands(&[1.0])?;
    let mut upper = Panel::new("P_dd / P_nowiggle");
    // The paper's range; models that have broken down (N2, N3 at high k) leave it.
    upper.clamp = Some((0.7, 1.3));
    let mut lower = Panel::new("");
    lower.lines.push((1.0, Style::Solid));
    lower.bands = bands.iter().map(|b| (1.0 - b, 1.0 + b)).collect();
    // Models far off (N3 or 1-loop SPT at high k) would flatten the others.
    lower.clamp = Some((0.75, 1.25));
    let data = args.data.as_deref().map(Measured::spectrum).transpose()?;
    let ln_nw: Vec<f64> = p_nw.iter().map(|p| p.ln()).collect();
    let ln_k: Vec<f64> = k.iter().map(|k| k.ln()).collect();
    let nw_at = |x: f64| interpolate(&ln_k, &ln_nw, x.ln()).exp();
    let reference = args
        .reference
        .clone()
        .unwrap_or_else(|| names[names.len() - 1].clone());
    let r = t.need(&reference)?;
    for name in &names {
        let y = t.need(name)?;
        let (c, style) = model_look(name);
        match &data {
            Some(d) => lower.curves.push(
                Curve::new(
                    "",
                    d.k.clone(),
                    d.k.iter()
                        .zip(&d.values[0])
                        .map(|(&x, p)| p / nw_at(x) / interpolate(&k, &y, x))
                        .collect(),
                )
                .styled(style)
                .colored(c),
            ),
            None => lower.curves.push(
                Curve::new(
                    "",
                    k.clone(),
                    y.iter().zip(&r).map(|(a, b)| a / b).collect(),
                )
                .styled(style)
                .colored(c),
            ),
        }
        upper.curves.push(
            Curve::new(name.as_str(), k.clone(), y)
                .styled(style)
                .colored(c),
        );
    }
    lower.y_label = match &data {
        Some(_) => "data / model".into(),
        None => format!("ratio to {reference}"),
    };
    if let Some(d) = &data {
        let over =
            |v: &[f64]| -> Vec<f64> { d.k.iter().zip(v).map(|(&x, p)| p / nw_at(x)).collect() };
        let y = over(&d.values[0]);
        let bars = y
            .iter()
            .zip(over(&d.sigma[0]))
            .map(|(y, s)| (y - s, y + s))
            .collect();
        upper.curves.push(
            Curve::new("data", d.k.clone(), y)
                .styled(Style::Points)
                .colored(color(0))
                .with_bars(bars),
        );
    }
    Ok(Figure::new(
        t.title(),
        "k [h/Mpc]",
        true,
        vec![upper.tall(), lower],
    ))
}

/// `propagators`: N² of each RPT table and −2 ln N/k², with σ_v² of the header.
pub fn propagators(args: &Args) -> Result<Figure> {
    let mut upper = Panel::new("N^2 = N_d N_d (factor on P_lin + P22)");
    upper.lines.push((1.0, Style::Solid));
    let mut lower = Panel::new("-2 ln N / k^2 [(Mpc/h)^2]");
    for (i, path) in args.inputs.iter().enumerate() {
        let t = Named::read(path)?;
        let k = t.need("k")?;
        let n = t.need("N_dd")?;
        let model = t.after("model ").unwrap_or_else(|| "model".into());
        let label = args.label(i, || model.clone())?;
        let (c, _) = model_look(&model);
        let style = [Style::Solid, Style::Dashed, Style::Dotted, Style::DotDashed][i % 4];
        let sigma: Vec<f64> = k
            .iter()
            .zip(&n)
            .map(|(k, n)| -(n.abs().max(1e-300)).ln() / (k * k))
            .collect();
        upper.curves.push(
            Curve::new(label.clone(), k.clone(), n)
                .styled(style)
                .colored(c),
        );
        lower
            .curves
            .push(Curve::new("", k, sigma).styled(style).colored(c));
        if let Some(s) = t.header_number("sigma_v2 = ") {
            if !lower.lines.iter().any(|l| l.0 == s) {
                lower.lines.push((s, Style::DotDashed));
            }
        }
    }
    Ok(Figure::new(
        "RPT damping N^2 and the effective sigma_v^2 (line: sigma_v^2)",
        "k [h/Mpc]",
        true,
        vec![upper.tall(), lower],
    ))
}
