//! Haloes as biased, stochastic tracers (Gil-Marín et al. 2012, section 4.4).
//!
//! δ_h = b(k) δ + ε, with b(k) = P_mh/P_mm from a table or a constant, scaled by an amplitude A_b
//! (b → A_b b), and a stochastic part ε uncorrelated with δ, P_εε = P_hh − P_mh²/P_mm from a table or the
//! Poisson value 1/n_h. The models describe the noise-subtracted spectrum
//! P^s_hh(k, μ) = ⟨δ^s_h δ^s_h⟩ − P_εε(k); a μ-independent P_εε changes only the monopole.
//! The signal-to-noise is P_hh/P_εε (the paper's table_noise).

use crate::error::{Error, Result};
use crate::table::Tabulated;

/// The halo bias b(k) before the amplitude A_b.
#[derive(Debug, Clone, PartialEq)]
pub enum Bias {
    /// A constant b.
    Constant(f64),
    /// b(k) from a table.
    Table(Tabulated),
}

impl Default for Bias {
    fn default() -> Self {
        Bias::Constant(1.0)
    }
}

impl Bias {
    /// A_b b(k) at each k.
    ///
    /// # Errors
    /// [`Error::OutOfRange`] where a table does not cover k; [`Error::InvalidParameter`] for a
    /// non-finite amplitude or constant.
    pub fn values(&self, k: &[f64], amplitude: f64) -> Result<Vec<f64>> {
        finite("bias amplitude A_b", amplitude)?;
        match self {
            Bias::Constant(b) => {
                finite("bias b", *b)?;
                Ok(vec![amplitude * b; k.len()])
            }
            Bias::Table(t) => k.iter().map(|&k| Ok(amplitude * t.eval(k)?)).collect(),
        }
    }
}

/// The stochasticity spectrum P_εε(k) [(Mpc/h)^3].
#[derive(Debug, Clone, PartialEq, Default)]
pub enum Noise {
    /// No noise term.
    #[default]
    None,
    /// A constant P_εε (e.g. Poisson, 1/n_h: see [`Noise::poisson`]).
    Constant(f64),
    /// P_εε(k) from a table.
    Table(Tabulated),
}

impl Noise {
    /// Poisson shot noise 1/n_h for a number density `n` [(h/Mpc)^3].
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] unless n is finite and positive.
    pub fn poisson(n: f64) -> Result<Self> {
        if !(n.is_finite() && n > 0.0) {
            return Err(Error::InvalidParameter {
                name: "number density n_h [(h/Mpc)^3]",
                value: n,
                reason: "must be finite and positive",
            });
        }
        Ok(Noise::Constant(1.0 / n))
    }

    /// P_εε at each k, or `None` without a noise term.
    ///
    /// # Errors
    /// [`Error::OutOfRange`] where a table does not cover k; [`Error::InvalidParameter`] for a constant
    /// that is not finite and positive.
    pub fn values(&self, k: &[f64]) -> Result<Option<Vec<f64>>> {
        match self {
            Noise::None => Ok(None),
            Noise::Constant(p) => {
                if !(p.is_finite() && *p > 0.0) {
                    return Err(Error::InvalidParameter {
                        name: "shot noise P_eps [(Mpc/h)^3]",
                        value: *p,
                        reason: "must be finite and positive",
                    });
                }
                Ok(Some(vec![*p; k.len()]))
            }
            Noise::Table(t) => Ok(Some(k.iter().map(|&k| t.eval(k)).collect::<Result<_>>()?)),
        }
    }
}

fn finite(name: &'static str, v: f64) -> Result<()> {
    if v.is_finite() {
        Ok(())
    } else {
        Err(Error::InvalidParameter {
            name,
            value: v,
            reason: "must be finite",
        })
    }
}

/// For each level, the first k at which `ratio` (e.g. the signal-to-noise P_hh/P_εε on increasing `k`)
/// falls to the level from above, interpolated linearly in (ln k, ratio); `None` if it starts below the
/// level or never reaches it.
///
/// ```
/// use pt_spectra::halo::crossings;
/// let k = [0.01, 0.1, 1.0];
/// let c = crossings(&k, &[2.0, 1.0, 0.2], &[1.0, 0.5, 5.0, 0.01]);
/// assert!((c[0].unwrap() - 0.1).abs() < 1e-12);
/// assert!((c[1].unwrap() - 10f64.powf(-1.0 + 0.625)).abs() < 1e-12);
/// assert_eq!((c[2], c[3]), (None, None));
/// ```
pub fn crossings(k: &[f64], ratio: &[f64], levels: &[f64]) -> Vec<Option<f64>> {
    levels
        .iter()
        .map(|&level| {
            if ratio.first().is_none_or(|&r| r < level) {
                return None;
            }
            (1..k.len().min(ratio.len())).find_map(|i| {
                let (r0, r1) = (ratio[i - 1], ratio[i]);
                (r0 >= level && r1 < level).then(|| {
                    let t = (r0 - level) / (r0 - r1);
                    (k[i - 1].ln() + t * (k[i].ln() - k[i - 1].ln())).exp()
                })
            })
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bias_and_noise_values() {
        let k = [0.05, 0.1];
        assert_eq!(Bias::Constant(2.0).values(&k, 1.1).unwrap(), vec![2.2, 2.2]);
        let t = Tabulated::new("b(k)", "mem", vec![0.01, 1.0], vec![2.0, 4.0], true, &[]).unwrap();
        let b = Bias::Table(t).values(&[0.1], 0.5).unwrap();
        assert!((b[0] - 1.5).abs() < 1e-14);
        assert_eq!(
            Noise::poisson(1.79e-5)
                .unwrap()
                .values(&k)
                .unwrap()
                .unwrap()[1],
            1.0 / 1.79e-5
        );
        assert!(Noise::poisson(0.0).is_err());
        assert!(Noise::Constant(f64::NAN).values(&k).is_err());
        assert!(Bias::Constant(1.0).values(&k, f64::INFINITY).is_err());
        assert_eq!(Noise::None.values(&k).unwrap(), None);
    }
}
