//! Correlation-function multipoles as a data vector: the model's ξ_ℓ(s) at the measured s, or averaged
//! over s bins, for fits of configuration-space measurements ([`XiPlan`]).
//!
//! ξ_ℓ(s) = i^ℓ ∫ k² dk/(2π²) P_ℓ(k) j_ℓ(ks) by FFTLog ([`crate::hankel::xi_from_pk_with`]), from the
//! model's P_ℓ on [`XiPlan::k_theory`]: the grid of [`WindowPlan`](super::WindowPlan) with its default
//! [`WindowOptions`] but 64 points per decade (log-uniform from 10⁻⁴ to 4 h/Mpc, steps ≤ 0.005 h/Mpc from 10⁻³ to 0.6 h/Mpc where
//! the BAO wiggles are), tapered to zero between 2.25 and 4 h/Mpc in the same way: the model's high k,
//! where a perturbative model is least reliable, enters ξ only at s ≲ 1 Mpc/h·(2π/2.25) and is smoothed
//! there; at s ≥ 20 Mpc/h the taper changes ξ_0 of a linear spectrum by < 1e-5 of its maximum.
//!
//! A Landy–Szalay estimate divides out the survey window (RR), so no window is applied; wide-angle
//! terms are neglected. With s-bin edges, the model is the s²-weighted mean over each bin (the pair-count
//! weight of a uniform field), by the Gauss–Legendre rules of [`BinAverage`]; the output s are the bins'
//! effective s (∫ s³ ds / ∫ s² ds).
//!
//! Error estimate per point: |ξ − ξ_half|/15 against the transform of the model through every other node
//! of the grid (the O(h⁴) scaling of the cubic spline) plus |ξ − ξ_100| against the transform at half the
//! default FFTLog sampling (100 points per decade); the bins add their own quadrature error.

use super::window::{taper, theory_grid};
use super::{check_ells, check_increasing, check_model, BinAverage, WindowOptions};
use crate::error::{Error, Result};
use crate::estimate::Estimate;
use crate::hankel::{xi_from_pk_with, HankelOptions};

/// The range of s [Mpc/h] a plan accepts: the transform is accurate there (module docs of
/// [`crate::hankel`]).
pub const S_RANGE: (f64, f64) = (1.0, 1000.0);

/// The k range [h/Mpc] over which the model's grid resolves the BAO (steps ≤ `dk`).
const FINE_RANGE: [f64; 2] = [1e-3, 0.6];

/// Points per decade of the model's grid outside [`FINE_RANGE`] (a Gaussian P_4 = k⁴e^{−32k²}, which
/// peaks at 0.35 h/Mpc, is transformed to 2.5e-5 of max|ξ_4| with 24, to < 1e-6 with 64).
const POINTS_PER_DECADE: f64 = 64.0;

/// The correlation-function multipoles at the output s from the model's P_ℓ, planned once (module
/// docs).
#[derive(Debug, Clone)]
pub struct XiPlan {
    ells: Vec<usize>,
    s_out: Vec<f64>,
    /// Where the transforms are evaluated (the output s, or the bins' nodes).
    s_eval: Vec<f64>,
    bins: Option<BinAverage>,
    k_theory: Vec<f64>,
    taper: Vec<f64>,
    /// Every other node of `k_theory` (both ends kept), for the spline error.
    half: Vec<usize>,
}

impl XiPlan {
    /// The plan of ξ_ℓ for `ells` at `s` [Mpc/h] (without bins), or averaged over the bins of
    /// `s_edges` [Mpc/h] (then `s` is ignored and the output s are the bins' effective s).
    ///
    /// # Errors
    /// [`Error::InvalidChoice`] for `ells` that are not distinct even multipoles ≤ 8;
    /// [`Error::InvalidK`] or [`Error::NonIncreasingK`] for s or edges that are not positive and
    /// increasing; [`Error::OutOfRange`] for an s outside [`S_RANGE`].
    pub fn new(ells: &[usize], s: &[f64], s_edges: Option<&[f64]>) -> Result<Self> {
        check_ells("correlation-function multipoles", ells)?;
        let (s_out, s_eval, bins) = match s_edges {
            None => {
                if s.is_empty() {
                    return Err(Error::TooFewPoints {
                        origin: "correlation-function s".into(),
                        found: 0,
                        min: 1,
                    });
                }
                check_increasing("correlation-function s [Mpc/h]", s, false)?;
                (s.to_vec(), s.to_vec(), None)
            }
            Some(edges) => {
                let b = BinAverage::new(edges)?;
                (b.k_eff(), b.k_theory().to_vec(), Some(b))
            }
        };
        for &v in &s_eval {
            if !(S_RANGE.0..=S_RANGE.1).contains(&v) {
                return Err(Error::OutOfRange {
                    what: "correlation-function s [Mpc/h] (of the plan's transform)".into(),
                    k: v,
                    min: S_RANGE.0,
                    max: S_RANGE.1,
                });
            }
        }
        let options = WindowOptions {
            points_per_decade: POINTS_PER_DECADE,
            ..WindowOptions::default()
        };
        let k_theory = theory_grid(&FINE_RANGE, 0.0, &options);
        let taper = k_theory.iter().map(|&k| taper(k, &options)).collect();
        let last = k_theory.len() - 1;
        let mut half: Vec<usize> = (0..last).step_by(2).collect();
        half.push(last);
        Ok(Self {
            ells: ells.to_vec(),
            s_out,
            s_eval,
            bins,
            k_theory,
            taper,
            half,
        })
    }

    /// Where the model's P_ℓ must be given: k [h/Mpc], increasing.
    pub fn k_theory(&self) -> &[f64] {
        &self.k_theory
    }

    /// The output s [Mpc/h] (the bins' effective s with bins).
    pub fn s_out(&self) -> &[f64] {
        &self.s_out
    }

    /// The multipoles.
    pub fn ells(&self) -> &[usize] {
        &self.ells
    }

    /// ξ_ℓ at the output s, one vector per ℓ of the plan, from the model's P_ℓ [(Mpc/h)^3] (one per ℓ of
    /// the plan, in its order) on [`k_theory`](Self::k_theory).
    ///
    /// # Errors
    /// [`Error::InvalidChoice`] or [`Error::LengthMismatch`] for a model of the wrong shape,
    /// [`Error::InvalidValue`] for a value that is not finite; those of the transform.
    pub fn apply(&self, p: &[Vec<f64>]) -> Result<Vec<Vec<Estimate>>> {
        self.check(p)?;
        let full = HankelOptions::default();
        let coarse = HankelOptions {
            points_per_decade: 0.5 * full.points_per_decade,
            ..full
        };
        let k_half: Vec<f64> = self.half.iter().map(|&i| self.k_theory[i]).collect();
        let mut out = Vec::with_capacity(self.ells.len());
        for (&ell, values) in self.ells.iter().zip(p) {
            let tapered: Vec<f64> = values.iter().zip(&self.taper).map(|(v, t)| v * t).collect();
            let xi = xi_from_pk_with(&self.k_theory, &tapered, ell, &self.s_eval, &full)?;
            let sparse = xi_from_pk_with(&self.k_theory, &tapered, ell, &self.s_eval, &coarse)?;
            let p_half: Vec<f64> = self.half.iter().map(|&i| tapered[i]).collect();
            let spline = xi_from_pk_with(&k_half, &p_half, ell, &self.s_eval, &full)?;
            let at_s: Vec<Estimate> = xi
                .iter()
                .zip(&sparse)
                .zip(&spline)
                .map(|((&v, &a), &b)| Estimate::new(v, (v - a).abs() + (v - b).abs() / 15.0))
                .collect();
            out.push(match &self.bins {
                None => at_s,
                Some(b) => b.apply_estimates(&at_s)?,
            });
        }
        Ok(out)
    }

    /// The values of [`apply`](Self::apply) without its error estimate (one transform per ℓ): what a
    /// fit evaluates at every step.
    ///
    /// # Errors
    /// As [`apply`](Self::apply).
    pub fn apply_values(&self, p: &[Vec<f64>]) -> Result<Vec<Vec<f64>>> {
        self.check(p)?;
        let options = HankelOptions::default();
        self.ells
            .iter()
            .zip(p)
            .map(|(&ell, values)| {
                let tapered: Vec<f64> =
                    values.iter().zip(&self.taper).map(|(v, t)| v * t).collect();
                let xi = xi_from_pk_with(&self.k_theory, &tapered, ell, &self.s_eval, &options)?;
                match &self.bins {
                    None => Ok(xi),
                    Some(b) => Ok(b.apply(&xi)?.iter().map(|e| e.value).collect()),
                }
            })
            .collect()
    }

    /// The model's shape: one P_ℓ per ℓ of the plan, each on k_theory.
    fn check(&self, p: &[Vec<f64>]) -> Result<()> {
        check_model("XiPlan::apply", p, self.k_theory.len())?;
        if p.len() != self.ells.len() {
            return Err(Error::InvalidChoice {
                what: "XiPlan::apply".into(),
                reason: format!(
                    "takes the model's P_l for l = {:?}, got {} multipoles",
                    self.ells,
                    p.len()
                ),
            });
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::PI;

    /// A Gaussian pair: P_ℓ(k) = k^ℓ e^{−k²R²/2} has ξ_ℓ(s) = (−1)^{ℓ/2} s^ℓ e^{−s²/2R²} / ((2π)^{3/2} R^{2ℓ+3})
    /// (the Hankel transform of a Gaussian times a solid harmonic).
    #[test]
    fn gaussian_pairs_every_ell() {
        let r = 8.0;
        let ells = [0, 2, 4, 6, 8];
        let s: Vec<f64> = (0..40).map(|i| 10.0 + 2.0 * f64::from(i)).collect();
        let plan = XiPlan::new(&ells, &s, None).unwrap();
        let model: Vec<Vec<f64>> = ells
            .iter()
            .map(|&l| {
                plan.k_theory()
                    .iter()
                    .map(|&k| k.powi(l as i32) * (-0.5 * k * k * r * r).exp())
                    .collect()
            })
            .collect();
        let xi = plan.apply(&model).unwrap();
        for (j, &l) in ells.iter().enumerate() {
            let exact = |s: f64| {
                let sign = if (l / 2) % 2 == 0 { 1.0 } else { -1.0 };
                sign * s.powi(l as i32) * (-0.5 * s * s / (r * r)).exp()
                    / ((2.0 * PI).powf(1.5) * r.powi(2 * l as i32 + 3))
            };
            let largest = s.iter().fold(0.0_f64, |m, &v| m.max(exact(v).abs()));
            for (i, &v) in s.iter().enumerate() {
                let err = (xi[j][i].value - exact(v)).abs() / largest;
                assert!(err < 1e-5, "l = {l}, s = {v}: {err:e} of max");
                assert!(
                    xi[j][i].error < 1e-3 * largest,
                    "l = {l}: error bar {}",
                    xi[j][i].error
                );
            }
        }
    }

    /// Bins: the plan's s²-weighted bin means equal Simpson's rule over the unbinned plan's ξ on a fine
    /// s grid (the gm2012 linear spectrum, BAO included).
    #[test]
    fn bins_average_with_pair_weight() {
        let edges: Vec<f64> = (0..=20).map(|i| 30.0 + 5.0 * f64::from(i)).collect();
        let binned = XiPlan::new(&[0, 2], &[], Some(&edges)).unwrap();
        let fine_s: Vec<f64> = (0..=4000).map(|i| 30.0 + 0.025 * f64::from(i)).collect();
        let unbinned = XiPlan::new(&[0, 2], &fine_s, None).unwrap();
        let lin = crate::linear::LinearSpectrum::gm2012(0.0).unwrap();
        let p: Vec<f64> = binned.k_theory().iter().map(|&k| lin.eval(k)).collect();
        let model = vec![p.clone(), p.iter().map(|v| 0.5 * v).collect()];
        let xb = binned.apply(&model).unwrap();
        let xf = unbinned.apply(&model).unwrap();
        // The values-only path of fits gives the same numbers, with and without bins.
        for (plan, full) in [(&binned, &xb), (&unbinned, &xf)] {
            let values = plan.apply_values(&model).unwrap();
            for (v, e) in values.iter().zip(full) {
                assert!(v.iter().zip(e).all(|(a, b)| *a == b.value));
            }
        }
        for l in 0..2 {
            let largest = xf[l].iter().fold(0.0_f64, |m, e| m.max(e.value.abs()));
            for (b, binned) in xb[l].iter().enumerate() {
                let (lo, n) = (200 * b, 200);
                let (mut num, mut den) = (0.0, 0.0);
                for i in 0..=n {
                    let w = if i == 0 || i == n {
                        1.0
                    } else if i % 2 == 1 {
                        4.0
                    } else {
                        2.0
                    };
                    let s = fine_s[lo + i];
                    num += w * s * s * xf[l][lo + i].value;
                    den += w * s * s;
                }
                let err = (binned.value - num / den).abs() / largest;
                assert!(err < 1e-5, "l = {l}, bin {b}: {err:e} of max");
            }
        }
        // The effective s of [30, 35]: ∫ s³ / ∫ s² = (3/4)(35⁴ − 30⁴)/(35³ − 30³).
        let s_eff =
            0.75 * (35.0f64.powi(4) - 30.0f64.powi(4)) / (35.0f64.powi(3) - 30.0f64.powi(3));
        assert!((binned.s_out()[0] - s_eff).abs() < 1e-12);
    }

    #[test]
    fn refuses_bad_input() {
        assert!(XiPlan::new(&[1], &[20.0], None).is_err());
        assert!(XiPlan::new(&[0], &[20.0, 10.0], None).is_err());
        assert!(XiPlan::new(&[0], &[0.1], None).is_err());
        let plan = XiPlan::new(&[0, 2], &[20.0], None).unwrap();
        let p = vec![vec![1.0; plan.k_theory().len()]];
        assert!(plan.apply(&p).is_err());
    }
}
