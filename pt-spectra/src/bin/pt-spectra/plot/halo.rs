//! The halo bias and stochasticity figure (bias_noise).

use super::draw::{color, Curve, Figure, Panel, Style};
use super::table::Named;
use super::Args;
use anyhow::Result;

/// `bias-noise`: b(k) and P_εε/P_Poisson of each `halo --number-density` table, one colour per input.
pub fn bias_noise(args: &Args) -> Result<Figure> {
    let mut bias = Panel::new("b(k) = P_mh / P_mm");
    let mut noise = Panel::new("P_eps / P_Poisson");
    noise.lines.push((1.0, Style::Dotted));
    for (i, path) in args.inputs.iter().enumerate() {
        let t = Named::read(path)?;
        let k = t.need("k")?;
        let label = args.label(i, || t.z_label())?;
        let c = color(1 + i);
        let bars = |v: &[f64], e: Option<Vec<f64>>| -> Option<Vec<(f64, f64)>> {
            Some(v.iter().zip(e?).map(|(v, e)| (v - e, v + e)).collect())
        };
        let b = t.need("b")?;
        let mut curve = Curve::new(label.clone(), k.clone(), b.clone()).colored(c);
        curve.bars = bars(&b, t.column("err_b"));
        bias.curves.push(curve);
        let n = t.need("P_eps_n")?;
        let mut curve = Curve::new("", k, n.clone()).colored(c);
        curve.bars = bars(&n, t.column("err_P_eps_n"));
        noise.curves.push(curve);
    }
    Ok(Figure::new(
        "Halo bias and stochasticity",
        "k [h/Mpc]",
        false,
        vec![bias, noise],
    ))
}
