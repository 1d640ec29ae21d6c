//! Priors of a galaxy fit's parameters: Gaussian, flat or log-normal, per parameter by name.

use crate::error::{Error, Result};
use std::fmt;

/// The shape of a prior.
#[derive(Debug, Clone, PartialEq)]
pub enum PriorShape {
    /// N(mean, σ²): −2 ln p = ((x − mean)/σ)².
    Gaussian {
        /// The mean.
        mean: f64,
        /// The standard deviation (> 0).
        sigma: f64,
    },
    /// Uniform on [lo, hi]: −2 ln p = 0 inside, and the fit is bounded by it.
    Flat {
        /// The lower end.
        lo: f64,
        /// The upper end (> lo).
        hi: f64,
    },
    /// ln x ~ N(mu, σ²), x > 0: −2 ln p = ((ln x − mu)/σ)² + 2 ln x (the density in x, Jacobian
    /// 1/x included); the fit is bounded to x > 0.
    LogNormal {
        /// The mean of ln x.
        mu: f64,
        /// The standard deviation of ln x (> 0).
        sigma: f64,
    },
}

/// A prior on a parameter.
#[derive(Debug, Clone, PartialEq)]
pub struct Prior {
    /// The parameter's name (one of [`crate::rsd::ept::PARAM_NAMES`], `apar`, `aperp`).
    pub name: String,
    /// Its shape.
    pub shape: PriorShape,
}

impl Prior {
    /// A Gaussian prior N(mean, σ²) on `name`.
    pub fn gaussian(name: &str, mean: f64, sigma: f64) -> Self {
        Self {
            name: name.to_string(),
            shape: PriorShape::Gaussian { mean, sigma },
        }
    }

    /// Parses `NAME:MEAN,SIGMA` (Gaussian), `NAME:flat,LO,HI` or `NAME:lognormal,MU,SIGMA` (MU, SIGMA
    /// of ln x), the form of the command line's `--prior` and the Python `priors`.
    ///
    /// # Errors
    /// [`Error::InvalidChoice`] naming the text and the expected forms; as [`PriorShape::check`].
    pub fn parse(text: &str) -> Result<Self> {
        let bad = |why: &str| Error::InvalidChoice {
            what: format!("prior `{text}`"),
            reason: format!(
                "{why}: expected NAME:MEAN,SIGMA (Gaussian), NAME:flat,LO,HI or \
                 NAME:lognormal,MU,SIGMA (of ln x), e.g. b2:0,1 or f:flat,0,2"
            ),
        };
        let (name, rest) = text.split_once(':').ok_or_else(|| bad("no `:`"))?;
        let parts: Vec<&str> = rest.split(',').map(str::trim).collect();
        let number = |s: &str| {
            s.parse::<f64>()
                .map_err(|_| bad(&format!("`{s}` is not a number")))
        };
        let shape = match parts[..] {
            [kind, a, b] if kind.eq_ignore_ascii_case("flat") => PriorShape::Flat {
                lo: number(a)?,
                hi: number(b)?,
            },
            [kind, a, b]
                if kind.eq_ignore_ascii_case("lognormal")
                    || kind.eq_ignore_ascii_case("log-normal") =>
            {
                PriorShape::LogNormal {
                    mu: number(a)?,
                    sigma: number(b)?,
                }
            }
            [kind, _, _] => return Err(bad(&format!("unknown prior kind `{kind}`"))),
            [a, b] => PriorShape::Gaussian {
                mean: number(a)?,
                sigma: number(b)?,
            },
            _ => return Err(bad("wrong number of values")),
        };
        let name = name.trim().to_string();
        shape.check(&name)?;
        Ok(Self { name, shape })
    }
}

impl PriorShape {
    /// (mean, 1/σ²) of a Gaussian prior; `None` for the others.
    pub fn gaussian(&self) -> Option<(f64, f64)> {
        match *self {
            PriorShape::Gaussian { mean, sigma } => Some((mean, 1.0 / (sigma * sigma))),
            _ => None,
        }
    }

    /// −2 ln p(x) up to a constant (+∞ outside a flat prior's range or at x ≤ 0 of a log-normal one).
    pub fn minus_two_log(&self, x: f64) -> f64 {
        match *self {
            PriorShape::Gaussian { mean, sigma } => ((x - mean) / sigma).powi(2),
            PriorShape::Flat { lo, hi } => {
                if (lo..=hi).contains(&x) {
                    0.0
                } else {
                    f64::INFINITY
                }
            }
            PriorShape::LogNormal { mu, sigma } => {
                if x > 0.0 {
                    ((x.ln() - mu) / sigma).powi(2) + 2.0 * x.ln()
                } else {
                    f64::INFINITY
                }
            }
        }
    }

    /// The first and second derivatives of [`Self::minus_two_log`] at `x` inside the support (0 for
    /// a flat prior; with y = ln x, a log-normal's −2 ln p = ((y − μ)/σ)² + 2y).
    pub fn minus_two_log_derivatives(&self, x: f64) -> (f64, f64) {
        match *self {
            PriorShape::Gaussian { mean, sigma } => {
                (2.0 * (x - mean) / (sigma * sigma), 2.0 / (sigma * sigma))
            }
            PriorShape::Flat { .. } => (0.0, 0.0),
            PriorShape::LogNormal { mu, sigma } => {
                let dy = 2.0 * (x.ln() - mu) / (sigma * sigma) + 2.0;
                (dy / x, (2.0 / (sigma * sigma) - dy) / (x * x))
            }
        }
    }

    /// The range the prior allows: a flat prior's, (0, ∞) for a log-normal one, ℝ for a Gaussian.
    pub fn support(&self) -> (f64, f64) {
        match *self {
            PriorShape::Gaussian { .. } => (f64::NEG_INFINITY, f64::INFINITY),
            PriorShape::Flat { lo, hi } => (lo, hi),
            PriorShape::LogNormal { .. } => (f64::MIN_POSITIVE, f64::INFINITY),
        }
    }

    /// A draw from the prior given a standard normal `z` and a uniform `u` in [0, 1).
    pub fn draw(&self, z: f64, u: f64) -> f64 {
        match *self {
            PriorShape::Gaussian { mean, sigma } => mean + sigma * z,
            PriorShape::Flat { lo, hi } => lo + (hi - lo) * u,
            PriorShape::LogNormal { mu, sigma } => (mu + sigma * z).exp(),
        }
    }

    /// Checks the values of the prior on `name`.
    ///
    /// # Errors
    /// [`Error::InvalidChoice`] naming the parameter and the rule (σ > 0 and finite, finite mean,
    /// finite lo < hi).
    pub fn check(&self, name: &str) -> Result<()> {
        let ok = match *self {
            PriorShape::Gaussian { mean, sigma } | PriorShape::LogNormal { mu: mean, sigma } => {
                mean.is_finite() && sigma > 0.0 && sigma.is_finite()
            }
            PriorShape::Flat { lo, hi } => lo.is_finite() && hi.is_finite() && lo < hi,
        };
        if ok {
            Ok(())
        } else {
            Err(Error::InvalidChoice {
                what: format!("the prior {self} on {name}"),
                reason: match self {
                    PriorShape::Flat { .. } => "a flat prior needs finite lo < hi".into(),
                    _ => "needs a finite mean and 0 < sigma < infinity".into(),
                },
            })
        }
    }
}

impl fmt::Display for PriorShape {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match *self {
            PriorShape::Gaussian { mean, sigma } => write!(f, "N({mean}, {sigma}^2)"),
            PriorShape::Flat { lo, hi } => write!(f, "U[{lo}, {hi}]"),
            PriorShape::LogNormal { mu, sigma } => write!(f, "lnN({mu}, {sigma}^2) (of ln x)"),
        }
    }
}

/// The priors of the DESI DR1 full-shape analysis in the physical basis (desilike's defaults for
/// velocileptors): b1p flat on [0, 3]; b2p, bsp N(0, 5²); α₀p, α₂p, α₄p N(0, 12.5²) (50% of linear
/// theory at k = 0.2 h/Mpc); sn0p N(0, 2²); sn2p, sn4p N(0, 5²). b3p is fixed at 0 there.
pub fn desi_priors() -> Vec<Prior> {
    let gaussian = |name: &str, sigma: f64| Prior::gaussian(name, 0.0, sigma);
    vec![
        Prior {
            name: "b1p".into(),
            shape: PriorShape::Flat { lo: 0.0, hi: 3.0 },
        },
        gaussian("b2p", 5.0),
        gaussian("bsp", 5.0),
        gaussian("alpha0p", 12.5),
        gaussian("alpha2p", 12.5),
        gaussian("alpha4p", 12.5),
        gaussian("sn0p", 2.0),
        gaussian("sn2p", 5.0),
        gaussian("sn4p", 5.0),
    ]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parse_the_three_forms_and_refuse_bad_ones() {
        assert_eq!(
            Prior::parse("b2:0,1").unwrap(),
            Prior::gaussian("b2", 0.0, 1.0)
        );
        assert_eq!(
            Prior::parse("f: flat, 0.2, 1.5").unwrap().shape,
            PriorShape::Flat { lo: 0.2, hi: 1.5 }
        );
        assert_eq!(
            Prior::parse("b1:lognormal,0.7,0.3").unwrap().shape,
            PriorShape::LogNormal {
                mu: 0.7,
                sigma: 0.3
            }
        );
        for bad in [
            "b2",
            "b2:0",
            "b2:0,-1",
            "b2:0,x",
            "f:flat,1,0",
            "b1:beta,1,2",
            "b2:1,2,3,4",
        ] {
            let e = Prior::parse(bad).unwrap_err().to_string();
            assert!(
                e.contains(bad) || e.contains("b2") || e.contains("f"),
                "{bad}: {e}"
            );
        }
    }

    /// The derivatives against central differences of the density itself.
    #[test]
    fn minus_two_log_derivatives_match_differences() {
        for shape in [
            PriorShape::Gaussian {
                mean: 0.3,
                sigma: 2.0,
            },
            PriorShape::LogNormal {
                mu: 0.2,
                sigma: 0.7,
            },
            PriorShape::Flat { lo: -1.0, hi: 4.0 },
        ] {
            let x = 1.3;
            let h = 1e-4;
            let f = |x: f64| shape.minus_two_log(x);
            let (d1, d2) = shape.minus_two_log_derivatives(x);
            let fd1 = (f(x + h) - f(x - h)) / (2.0 * h);
            let fd2 = (f(x + h) - 2.0 * f(x) + f(x - h)) / (h * h);
            assert!((d1 - fd1).abs() < 1e-7, "{shape}: {d1} {fd1}");
            assert!((d2 - fd2).abs() < 1e-5, "{shape}: {d2} {fd2}");
        }
    }

    /// −2 ln p against the densities written out: the log-normal's differences between two points are
    /// those of −2 ln[exp(−(ln x − μ)²/2σ²)/x].
    #[test]
    fn minus_two_log_densities() {
        let g = PriorShape::Gaussian {
            mean: 1.0,
            sigma: 2.0,
        };
        assert_eq!(g.minus_two_log(5.0), 4.0);
        let flat = PriorShape::Flat { lo: 0.0, hi: 1.0 };
        assert_eq!(flat.minus_two_log(0.5), 0.0);
        assert_eq!(flat.minus_two_log(1.5), f64::INFINITY);
        let ln = PriorShape::LogNormal {
            mu: 0.5,
            sigma: 0.4,
        };
        let density = |x: f64| (-(x.ln() - 0.5f64).powi(2) / (2.0 * 0.16)).exp() / x;
        let (a, b) = (1.3, 2.9);
        let want = -2.0 * (density(b) / density(a)).ln();
        let got = ln.minus_two_log(b) - ln.minus_two_log(a);
        assert!((got - want).abs() < 1e-12, "{got} {want}");
        assert_eq!(ln.minus_two_log(-1.0), f64::INFINITY);
    }
}
