//! Redshift-space figures: multipoles over the no-wiggle reference with data and S/N lines
//! (multipoles_dark_matter, multipoles_haloes), the signal-to-noise (S2N) and the TNS terms
//! (Taruya_terms).

use super::draw::{color, Curve, Figure, Panel, Style};
use super::real::rsd_color;
use super::table::{interpolate, Measured, Named};
use super::Args;
use anyhow::{bail, Result};
use plotters::chart::SeriesLabelPosition;
use plotters::style::RGBColor;
use pt_spectra::halo::crossings;
use pt_spectra::jobs::SN_LEVELS;

/// The line of an RSD model as the paper draws it: Kaiser dotted, Scoccimarro dashed, TNS solid.
fn rsd_style(model: &str) -> Style {
    match model {
        "kaiser" => Style::Dotted,
        "scoccimarro" => Style::Dashed,
        _ => Style::Solid,
    }
}

/// The model column of ℓ in `t`: `P<l>`, or `P<l>_kmax<K>` of a `fit --model-out` table at the k_max
/// nearest `k_max` (default: the largest); with the k_max chosen.
fn model_column(t: &Named, l: usize, k_max: Option<f64>) -> Option<(String, Option<f64>)> {
    let plain = format!("P{l}");
    if t.names.contains(&plain) {
        return Some((plain, None));
    }
    let prefix = format!("P{l}_kmax");
    let options: Vec<(f64, &String)> = t
        .names
        .iter()
        .filter_map(|n| Some((n.strip_prefix(&prefix)?.parse::<f64>().ok()?, n)))
        .collect();
    let pick = match k_max {
        Some(want) => options
            .iter()
            .min_by(|a, b| (a.0 - want).abs().total_cmp(&(b.0 - want).abs())),
        None => options.iter().max_by(|a, b| a.0.total_cmp(&b.0)),
    }?;
    Some((pick.1.clone(), Some(pick.0)))
}

/// `multipoles`: P_ℓ/P_ℓ,nw (or k P_ℓ) of each input with the data, a data/model panel per ℓ, and
/// vertical lines where SN falls to 1 and 0.5.
pub fn multipoles(args: &Args) -> Result<Figure> {
    let tables = args
        .inputs
        .iter()
        .map(|p| Named::read(p))
        .collect::<Result<Vec<_>>>()?;
    let data = match &args.data {
        Some(path) => Some(Measured::multipoles(path)?),
        None => fitted_data(&tables[0]),
    };
    let bands = args.bands(&[2.0])?;
    let ells: Vec<usize> = [0, 2, 4]
        .into_iter()
        .filter(|&l| {
            tables
                .iter()
                .any(|t| model_column(t, l, args.k_max).is_some())
        })
        .collect();
    if ells.is_empty() {
        bail!("no P0, P2 or P4 column in the inputs (expected `rsd` or `fit --model-out` output)");
    }
    let has_nw = |t: &Named| ells.iter().all(|l| t.column(&format!("P{l}_nw")).is_some());
    let normalised = has_nw(&tables[0]);
    if tables.iter().any(|t| has_nw(t) != normalised) {
        bail!(
            "either every input or none must have the P<l>_nw columns (rsd --no-wiggle, fit \
             --model-out)"
        );
    }
    let sn_lines: Vec<(f64, String)> = tables
        .iter()
        .find_map(|t| Some((t.column("k")?, t.column("SN")?)))
        .map(|(k, sn)| {
            crossings(&k, &sn, &[1.0, 0.5])
                .into_iter()
                .zip(["S/N = 1", "S/N = 0.5"])
                .filter_map(|(c, label)| Some((c?, label.to_string())))
                .collect()
        })
        .unwrap_or_default();
    let mut panels = Vec::new();
    for &l in &ells {
        let name = format!("P{l}");
        let nw_name = format!("P{l}_nw");
        let mut value = Panel::new(if normalised {
            format!("{name} / {name},nw")
        } else {
            format!("k {name} [(Mpc/h)^2]")
        })
        .tall();
        let mut ratio = Panel::new(format!("data / model, {name}"));
        ratio.lines.push((1.0, Style::Solid));
        ratio.bands = bands.iter().map(|b| (1.0 - b, 1.0 + b)).collect();
        ratio.clamp = Some((0.5, 1.5));
        value.vlines.clone_from(&sn_lines);
        ratio.vlines.clone_from(&sn_lines);
        // One legend, in the first panel, above the curves that start near 1 at low k.
        value.legend = panels.is_empty().then_some(SeriesLabelPosition::UpperLeft);
        let reference = tables
            .iter()
            .find_map(|t| Some((t.column("k")?, t.column(&nw_name)?)));
        for (i, t) in tables.iter().enumerate() {
            let Some((column, k_max)) = model_column(t, l, args.k_max) else {
                continue;
            };
            let k = t.need("k")?;
            let p = t.need(&column)?;
            let what = t
                .after("rsd: ")
                .or_else(|| t.after("fit: "))
                .unwrap_or_else(|| "model".into());
            let rsd = what.split_whitespace().next().unwrap_or("").to_string();
            let real = what.rsplit(' ').next().unwrap_or("").to_string();
            let c = rsd_color(&real);
            let mut label = args.label(i, || format!("{rsd} + {real}"))?;
            if let Some(km) = k_max {
                label += &format!(" (k_max {km})");
            }
            let y: Vec<f64> = match t.column(&nw_name) {
                Some(nw) => p.iter().zip(&nw).map(|(p, n)| p / n).collect(),
                None => k.iter().zip(&p).map(|(k, p)| k * p).collect(),
            };
            value.curves.push(
                Curve::new(label, k.clone(), y)
                    .styled(rsd_style(&rsd))
                    .colored(c),
            );
            if let Some(d) = &data {
                let j = [0, 2, 4].iter().position(|&x| x == l).unwrap_or(0);
                let r =
                    d.k.iter()
                        .zip(&d.values[j])
                        .map(|(&x, v)| v / interpolate(&k, &p, x))
                        .collect();
                ratio.curves.push(
                    Curve::new("", d.k.clone(), r)
                        .styled(rsd_style(&rsd))
                        .colored(c),
                );
            }
        }
        if let Some(d) = &data {
            let j = [0, 2, 4].iter().position(|&x| x == l).unwrap_or(0);
            let scale: Vec<f64> = match &reference {
                Some((k, nw)) => d.k.iter().map(|&x| 1.0 / interpolate(k, nw, x)).collect(),
                None => d.k.clone(),
            };
            let y: Vec<f64> = d.values[j].iter().zip(&scale).map(|(v, s)| v * s).collect();
            let bars = y
                .iter()
                .zip(d.sigma[j].iter().zip(&scale))
                .map(|(y, (e, s))| (y - e * s, y + e * s))
                .collect();
            value.curves.push(
                Curve::new("data", d.k.clone(), y)
                    .styled(Style::Points)
                    .colored(color(0))
                    .with_bars(bars),
            );
        }
        panels.push(value);
        if data.is_some() {
            panels.push(ratio);
        }
    }
    let mut figure = Figure::new("Redshift-space multipoles", "k [h/Mpc]", false, panels);
    figure.height = 300 * ells.len() as u32 + 100;
    Ok(figure)
}

/// The fitted data of a `fit --model-out` table (`P<l>_data err_P<l>_data`), as multipoles 0, 2, 4
/// (missing ones NaN).
fn fitted_data(t: &Named) -> Option<Measured> {
    let k = t.column("k")?;
    let mut any = false;
    let (mut values, mut sigma) = (Vec::new(), Vec::new());
    for l in [0, 2, 4] {
        match (
            t.column(&format!("P{l}_data")),
            t.column(&format!("err_P{l}_data")),
        ) {
            (Some(v), Some(s)) => {
                any = true;
                values.push(v);
                sigma.push(s);
            }
            _ => {
                values.push(vec![f64::NAN; k.len()]);
                sigma.push(vec![f64::NAN; k.len()]);
            }
        }
    }
    any.then_some(Measured { k, values, sigma })
}

/// `sn`: the real-space signal-to-noise SN = P_hh/P_εε of each `rsd` table, lines at 1, 0.5, 0.1.
pub fn signal_to_noise(args: &Args) -> Result<Figure> {
    let mut panel = Panel::new("S/N = P_hh / P_eps");
    panel.log_y = true;
    panel.lines = SN_LEVELS.iter().map(|&v| (v, Style::Dotted)).collect();
    for (i, path) in args.inputs.iter().enumerate() {
        let t = Named::read(path)?;
        let label = args.label(i, || t.z_label())?;
        // The paper's colours by redshift: red, blue, green, orange.
        panel
            .curves
            .push(Curve::new(label, t.need("k")?, t.need("SN")?).colored(color(1 + i)));
    }
    Ok(Figure::new(
        "Signal-to-noise of haloes, P_hh/P_eps = b^2 P_dd/P_eps (lines: 1, 0.5, 0.1)",
        "k [h/Mpc]",
        true,
        vec![panel],
    ))
}

/// |y| as a solid curve where y > 0 and a dashed one where y < 0 (the paper's negative terms).
fn signed(label: &str, k: &[f64], y: &[f64], c: RGBColor) -> [Curve; 2] {
    let part = |sign: f64| -> Vec<f64> {
        y.iter()
            .map(|&v| if v * sign > 0.0 { v.abs() } else { f64::NAN })
            .collect()
    };
    [
        Curve::new(label, k.to_vec(), part(1.0)).colored(c),
        Curve::new("", k.to_vec(), part(-1.0))
            .styled(Style::Dashed)
            .colored(c),
    ]
}

/// `tns-terms`: the parts of the TNS monopole and P_εε, and each over P_εε.
pub fn tns_terms(args: &Args) -> Result<Figure> {
    let t = Named::read(args.one_input()?)?;
    let k = t.need("k")?;
    let noise = t.need("P_eps")?;
    let mut upper = Panel::new("|P0 part| [(Mpc/h)^3] (dashed: negative)").tall();
    upper.log_y = true;
    let mut lower = Panel::new("|part| / P_eps (S/N)");
    lower.log_y = true;
    lower.lines = SN_LEVELS.iter().map(|&v| (v, Style::Dotted)).collect();
    for (name, label, c) in [
        ("P0_sc", "Scoccimarro part", 1),
        ("P0", "TNS", 2),
        ("P0_A", "A", 3),
        ("P0_B", "B", 4),
    ] {
        let y = t.need(name)?;
        let over: Vec<f64> = y.iter().zip(&noise).map(|(y, n)| y / n).collect();
        upper.curves.extend(signed(label, &k, &y, color(c)));
        lower.curves.extend(signed("", &k, &over, color(c)));
    }
    upper
        .curves
        .push(Curve::new("P_eps", k.clone(), noise).colored(color(0)));
    Ok(Figure::new(
        format!("Parts of the halo monopole ({})", t.z_label()),
        "k [h/Mpc]",
        true,
        vec![upper, lower],
    ))
}
