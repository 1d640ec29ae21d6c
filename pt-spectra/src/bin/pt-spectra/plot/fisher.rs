//! The forecast's ellipses (`pt-spectra fisher` tables): α∥ and α⊥ against fσ8, one ellipse per bin.

use super::draw::{color, Curve, Figure, Panel, Style};
use super::table::Named;
use super::Args;
use anyhow::{bail, Result};

/// Δχ² of the 68% region of two parameters.
const DELTA_CHI2_68: f64 = 2.30;

/// Points of the Δχ² = `level` ellipse of centre (x, y), errors (sx, sy) and correlation ρ.
fn ellipse(centre: (f64, f64), sigma: (f64, f64), rho: f64, level: f64) -> (Vec<f64>, Vec<f64>) {
    // the Cholesky factor of [[sx², ρ sx sy], [ρ sx sy, sy²]] maps the unit circle onto the ellipse
    let (sx, sy) = sigma;
    let r = level.sqrt();
    (0..=120)
        .map(|i| {
            let t = 2.0 * std::f64::consts::PI * f64::from(i) / 120.0;
            let (c, s) = (t.cos(), t.sin());
            (
                centre.0 + r * sx * c,
                centre.1 + r * sy * (rho * c + (1.0 - rho * rho).max(0.0).sqrt() * s),
            )
        })
        .unzip()
}

/// α∥ (top) and α⊥ (bottom) against fσ8: the 68% (Δχ² = 2.30) ellipse of each bin of a
/// `pt-spectra fisher` table, marginalised over every other parameter.
pub fn ellipses(args: &Args) -> Result<Figure> {
    let t = Named::read(args.one_input()?)?;
    for name in [
        "z",
        "fsigma8",
        "sigma_fsigma8",
        "sigma_apar",
        "sigma_aperp",
        "corr_f_apar",
    ] {
        if !t.names.iter().any(|n| n == name) {
            bail!(
                "`{}`: expected a `pt-spectra fisher` table with template parameters (column `{name}` \
                 missing; found {})",
                t.origin,
                t.names.join(" ")
            );
        }
    }
    let (z, fs8, s_fs8) = (t.need("z")?, t.need("fsigma8")?, t.need("sigma_fsigma8")?);
    let mut panels = Vec::new();
    for (alpha, label) in [("apar", "alpha_par"), ("aperp", "alpha_perp")] {
        let sigma = t.need(&format!("sigma_{alpha}"))?;
        let rho = t.need(&format!("corr_f_{alpha}"))?;
        let mut panel = Panel::new(label);
        for i in 0..z.len() {
            let (x, y) = ellipse((fs8[i], 1.0), (s_fs8[i], sigma[i]), rho[i], DELTA_CHI2_68);
            panel
                .curves
                .push(Curve::new(format!("z = {}", z[i]), x, y).colored(color(i + 1)));
            panel.curves.push(
                Curve::new("", vec![fs8[i]], vec![1.0])
                    .styled(Style::Points)
                    .colored(color(i + 1)),
            );
        }
        panels.push(panel);
    }
    Ok(Figure::new(
        "Fisher forecast: 68% regions (Delta chi2 = 2.30), other parameters marginalised",
        "f sigma8",
        false,
        panels,
    ))
}

#[cfg(test)]
mod tests {
    use super::ellipse;

    #[test]
    fn the_ellipse_has_the_marginal_widths_and_the_correlation() {
        // the ellipse of level 1 spans ±σ in each parameter, and its points satisfy
        // dᵀC⁻¹d = level
        let (sx, sy, rho) = (0.02, 0.05, -0.6);
        let (x, y) = ellipse((0.4, 1.0), (sx, sy), rho, 1.0);
        let width = |v: &[f64], c: f64| v.iter().fold(0.0_f64, |m, a| m.max((a - c).abs()));
        assert!((width(&x, 0.4) / sx - 1.0).abs() < 1e-3);
        assert!((width(&y, 1.0) / sy - 1.0).abs() < 1e-3);
        for (a, b) in x.iter().zip(&y) {
            let (u, v) = ((a - 0.4) / sx, (b - 1.0) / sy);
            let q = (u * u - 2.0 * rho * u * v + v * v) / (1.0 - rho * rho);
            assert!((q - 1.0).abs() < 1e-12, "{q}");
        }
    }
}
