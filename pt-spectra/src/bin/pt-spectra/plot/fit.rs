//! Fit figures: best-fit parameters versus k_max with truth, deviation bands and theory σ0 lines
//! (sigma_0_multipoles, f_dm, refind_beta_haloes, refind_f_haloes), and Δχ² contours.

use super::draw::{color, Curve, Figure, Panel, Style};
use super::real::rsd_color;
use super::table::Named;
use super::Args;
use anyhow::{bail, Result};
use pt_spectra::fit::CONTOUR_LEVELS;

/// `fit`: a panel for each of f, σ0 and A_b that an input has, with 1σ bars.
pub fn fits(args: &Args) -> Result<Figure> {
    let tables = args
        .inputs
        .iter()
        .map(|p| Named::read(p))
        .collect::<Result<Vec<_>>>()?;
    let mut panels: Vec<(&str, Panel)> = [("f", "f"), ("sigma0", "sigma0 [Mpc/h]"), ("ab", "A_b")]
        .into_iter()
        .filter(|(name, _)| tables.iter().any(|t| t.column(name).is_some()))
        .map(|(name, label)| (name, Panel::new(label)))
        .collect();
    if panels.is_empty() {
        bail!("no column f, sigma0 or ab in the inputs (expected `fit` output)");
    }
    let bands = args.bands(&[1.0, 2.0])?;
    let mut range = (f64::INFINITY, f64::NEG_INFINITY);
    let mut used = Vec::new();
    for (i, t) in tables.iter().enumerate() {
        let k = t.need("k_max")?;
        range = (range.0.min(k[0]), range.1.max(k[k.len() - 1]));
        let what = t.after("fit: ").unwrap_or_else(|| "fit".into());
        let rsd = what.split_whitespace().next().unwrap_or("").to_string();
        let real = what.rsplit(' ').next().unwrap_or("").to_string();
        let ells = t.after(" ells ").unwrap_or_default();
        let label = args.label(i, || format!("{rsd} + {real}, l = {ells}"))?;
        let mut c = rsd_color(&real);
        if used.contains(&(rsd.clone(), real.clone())) {
            c = color(5 + i);
        }
        used.push((rsd.clone(), real));
        let style = match rsd.as_str() {
            "kaiser" => Style::Dotted,
            "scoccimarro" => Style::Dashed,
            _ => Style::Solid,
        };
        for (p, (name, panel)) in panels.iter_mut().enumerate() {
            let Some(v) = t.column(name) else { continue };
            let (lo, hi) = (
                t.need(&format!("{name}_lo"))?,
                t.need(&format!("{name}_hi"))?,
            );
            // The fits are named in the first panel's legend only; the σ0 panel names its theory lines.
            let label = if p == 0 { label.clone() } else { String::new() };
            panel.curves.push(
                Curve::new(label, k.clone(), v)
                    .styled(style)
                    .colored(c)
                    .with_bars(lo.into_iter().zip(hi).collect()),
            );
        }
    }
    for (name, panel) in panels.iter_mut() {
        match *name {
            "f" => {
                if let Some(truth) = args.truth {
                    panel.lines.push((truth, Style::Solid));
                    for b in &bands {
                        panel.lines.push((truth * (1.0 - b), Style::DotDashed));
                        panel.lines.push((truth * (1.0 + b), Style::DotDashed));
                        panel.bands.push((truth * (1.0 - b), truth * (1.0 + b)));
                    }
                }
            }
            "ab" => panel.lines.push((1.0, Style::Solid)),
            _ => {
                // The theory σ0 of eq. sigmav: 1-loop SPT P_θθ solid, P_lin dot-dashed, in black (as
                // the paper's sigma_0_multipoles).
                let mut seen: Vec<f64> = Vec::new();
                for t in &tables {
                    for (column, label, c, style) in [
                        ("sigma0_1l", "sigma0 theory, 1L-SPT P_tt", 0, Style::Solid),
                        ("sigma0_lin", "sigma0 theory, P_lin", 0, Style::DotDashed),
                    ] {
                        let Some(v) = t.column(column).and_then(|v| v.first().copied()) else {
                            continue;
                        };
                        let first = !seen.iter().any(|s| (s - v).abs() <= 1e-9 * v.abs());
                        if first {
                            seen.push(v);
                            panel.curves.push(
                                Curve::new(label, vec![range.0, range.1], vec![v, v])
                                    .styled(style)
                                    .colored(color(c)),
                            );
                        }
                    }
                }
            }
        }
    }
    let mut panels: Vec<Panel> = panels.into_iter().map(|p| p.1).collect();
    if panels.len() > 1 {
        panels[0].weight = 2;
    }
    Ok(Figure::new(
        "Best fit versus k_max (1-sigma bars from the Delta chi2 contour)",
        "k_max [h/Mpc]",
        false,
        panels,
    ))
}

/// The segments where Δχ² on the structured grid (`x[i][j]`, `y[i][j]`, `v[i][j]`) crosses `level`, by
/// marching squares (crossings linearly interpolated on the cell edges), as one polyline with NaN
/// between segments.
fn level_lines(x: &[Vec<f64>], y: &[Vec<f64>], v: &[Vec<f64>], level: f64) -> (Vec<f64>, Vec<f64>) {
    let (mut px, mut py) = (Vec::new(), Vec::new());
    let n = v.len();
    let m = v.first().map_or(0, Vec::len);
    let cross = |a: (usize, usize), b: (usize, usize)| -> Option<(f64, f64)> {
        let (da, db) = (v[a.0][a.1] - level, v[b.0][b.1] - level);
        if !(da.is_finite() && db.is_finite()) || (da < 0.0) == (db < 0.0) {
            return None;
        }
        let t = da / (da - db);
        let lerp = |g: &[Vec<f64>]| g[a.0][a.1] + t * (g[b.0][b.1] - g[a.0][a.1]);
        Some((lerp(x), lerp(y)))
    };
    for i in 0..n.saturating_sub(1) {
        for j in 0..m.saturating_sub(1) {
            let (c00, c10, c11, c01) = ((i, j), (i + 1, j), (i + 1, j + 1), (i, j + 1));
            let points: Vec<(f64, f64)> = [(c00, c10), (c10, c11), (c11, c01), (c01, c00)]
                .into_iter()
                .filter_map(|(a, b)| cross(a, b))
                .collect();
            for pair in points.chunks_exact(2) {
                px.extend([pair[0].0, pair[1].0, f64::NAN]);
                py.extend([pair[0].1, pair[1].1, f64::NAN]);
            }
        }
    }
    (px, py)
}

/// `contour`: the Δχ² = 2.3 (solid) and 6.17 (dashed) contours of a `fit --contour-out` table at one
/// k_max, and the grid point of least χ².
pub fn contour(args: &Args) -> Result<Figure> {
    let t = Named::read(args.one_input()?)?;
    let n = &t.names;
    if n.len() < 7 || n[0] != "k_max" || n[1] != "i" || n[2] != "j" || n[6] != "delta_chi2" {
        bail!(
            "`{}`: expected `k_max i j <P1> <P2> chi2 delta_chi2 …` (fit --contour-out), found {}",
            t.origin,
            n.join(" ")
        );
    }
    let (xn, yn) = (n[3].clone(), n[4].clone());
    let (k, gi, gj) = (t.need("k_max")?, t.need("i")?, t.need("j")?);
    let (x, y, d) = (t.need(&xn)?, t.need(&yn)?, t.need("delta_chi2")?);
    let chosen = match args.k_max {
        Some(want) => k
            .iter()
            .copied()
            .min_by(|a, b| (a - want).abs().total_cmp(&(b - want).abs())),
        None => k.iter().copied().max_by(f64::total_cmp),
    }
    .unwrap_or(f64::NAN);
    let rows: Vec<usize> = (0..k.len()).filter(|&r| k[r] == chosen).collect();
    let index = |v: f64| (v >= 0.0 && v.fract() == 0.0).then_some(v as usize);
    let size = |g: &[f64]| {
        rows.iter()
            .filter_map(|&r| index(g[r]))
            .max()
            .map_or(0, |m| m + 1)
    };
    let (ni, nj) = (size(&gi), size(&gj));
    if ni < 2 || nj < 2 || ni * nj != rows.len() {
        bail!(
            "`{}`: the rows of k_max = {chosen} are not a grid (i, j) of {xn} and {yn}",
            t.origin
        );
    }
    let (mut gx, mut gy, mut gd) = (
        vec![vec![f64::NAN; nj]; ni],
        vec![vec![f64::NAN; nj]; ni],
        vec![vec![f64::NAN; nj]; ni],
    );
    for &r in &rows {
        let (Some(i), Some(j)) = (index(gi[r]), index(gj[r])) else {
            bail!(
                "`{}`: row with i = {}, j = {} is not on the grid",
                t.origin,
                gi[r],
                gj[r]
            );
        };
        (gx[i][j], gy[i][j], gd[i][j]) = (x[r], y[r], d[r]);
    }
    let mut panel = Panel::new(yn.clone());
    for (level, style) in CONTOUR_LEVELS.iter().zip([Style::Solid, Style::Dashed]) {
        let (px, py) = level_lines(&gx, &gy, &gd, *level);
        panel.curves.push(
            Curve::new(format!("Delta chi2 = {level}"), px, py)
                .styled(style)
                .colored(color(2)),
        );
    }
    let best = rows
        .iter()
        .copied()
        .min_by(|&a, &b| d[a].total_cmp(&d[b]))
        .unwrap_or(rows[0]);
    panel.curves.push(
        Curve::new("least chi2 on the grid", vec![x[best]], vec![y[best]])
            .styled(Style::Points)
            .colored(color(0)),
    );
    Ok(Figure::new(
        format!("Delta chi2 contours of ({xn}, {yn}) at k_max = {chosen}"),
        &xn,
        false,
        vec![panel],
    ))
}
