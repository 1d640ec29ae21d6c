//! Haloes as biased, stochastic tracers (Gil-Marín et al. 2012, section 4.4).
//!
//! δ_h = b(k) δ + ε, with b(k) = P_mh/P_mm from a table or a constant, scaled by an amplitude A_b
//! (b → A_b b), and a stochastic part ε uncorrelated with δ, P_εε = P_hh − P_mh²/P_mm from a table or the
//! Poisson value 1/n_h. The models describe the noise-subtracted spectrum
//! P^s_hh(k, μ) = ⟨δ^s_h δ^s_h⟩ − P_εε(k); a μ-independent P_εε changes only the monopole.
//! The signal-to-noise is P_hh/P_εε in real space, P_hh = b² P_δδ (the paper's S2N figure and table_noise).
//!
//! [`bias_and_noise`] measures b(k) and P_εε from spectra of a simulation (eqs. bias_eq and delta_field):
//! b = P_mh/P_mm and P_εε = P_hh − P_mh²/P_mm, with P_hh the measured halo spectrum (noise included).

use crate::error::{Error, Result};
use crate::table::{DataColumns, Tabulated};
use std::path::Path;

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

/// A measured power spectrum P(k) [(Mpc/h)^3] on strictly increasing k [h/Mpc], with optional 1σ errors.
#[derive(Debug, Clone, PartialEq)]
pub struct MeasuredSpectrum {
    /// What it is, e.g. `P_mh`.
    pub name: &'static str,
    /// The file it came from, or a description.
    pub origin: String,
    /// Wavenumbers [h/Mpc].
    pub k: Vec<f64>,
    /// P(k) [(Mpc/h)^3].
    pub p: Vec<f64>,
    /// 1σ errors of P [(Mpc/h)^3], if given.
    pub error: Option<Vec<f64>>,
}

impl MeasuredSpectrum {
    /// `name` from arrays (`origin` names them in messages; rows are numbered from 1).
    ///
    /// # Errors
    /// [`Error::LengthMismatch`]; [`Error::TooFewPoints`] for no rows; [`Error::InvalidK`],
    /// [`Error::NonIncreasingK`]; [`Error::InvalidValue`] for a value that is not finite or an error that
    /// is not finite and ≥ 0.
    pub fn new(
        name: &'static str,
        origin: &str,
        k: Vec<f64>,
        p: Vec<f64>,
        error: Option<Vec<f64>>,
    ) -> Result<Self> {
        let lines: Vec<usize> = (1..=k.len()).collect();
        Self::checked(name, origin, k, p, error, &lines)
    }

    /// `name` from the 0-based columns (k, P, optional error) of a table file.
    ///
    /// # Errors
    /// [`Error::Io`], [`Error::Parse`], [`Error::MissingColumn`], and as [`new`](Self::new) with line
    /// numbers.
    pub fn read(
        path: impl AsRef<Path>,
        name: &'static str,
        (k, p, error): (usize, usize, Option<usize>),
    ) -> Result<Self> {
        let mut wanted = vec![k, p];
        wanted.extend(error);
        let t = DataColumns::read(path, &wanted)?;
        let mut c = t.columns.into_iter();
        let (k, p, e) = (
            c.next().unwrap_or_default(),
            c.next().unwrap_or_default(),
            c.next(),
        );
        Self::checked(name, &t.origin, k, p, e, &t.lines)
    }

    fn checked(
        name: &'static str,
        origin: &str,
        k: Vec<f64>,
        p: Vec<f64>,
        error: Option<Vec<f64>>,
        lines: &[usize],
    ) -> Result<Self> {
        for (what, n) in [
            ("P and k", p.len()),
            ("errors and k", error.as_ref().map_or(k.len(), Vec::len)),
        ] {
            if n != k.len() {
                return Err(Error::LengthMismatch {
                    what,
                    left: n,
                    right: k.len(),
                });
            }
        }
        if k.is_empty() {
            return Err(Error::TooFewPoints {
                origin: origin.into(),
                found: 0,
                min: 1,
            });
        }
        crate::table::check_k_grid(origin, &k, lines)?;
        for i in 0..k.len() {
            let line = lines[i];
            if !p[i].is_finite() {
                return Err(Error::InvalidValue {
                    origin: origin.into(),
                    line,
                    name,
                    value: p[i],
                    reason: "must be finite",
                });
            }
            if let Some(e) = error
                .as_ref()
                .map(|e| e[i])
                .filter(|e| !(e.is_finite() && *e >= 0.0))
            {
                return Err(Error::InvalidValue {
                    origin: origin.into(),
                    line,
                    name: "error of P",
                    value: e,
                    reason: "must be finite and non-negative",
                });
            }
        }
        Ok(Self {
            name,
            origin: origin.into(),
            k,
            p,
            error,
        })
    }

    /// `n k in [a, b] h/Mpc from <origin>`.
    fn describe(&self) -> String {
        format!(
            "{} ({} k in [{}, {}] h/Mpc from {})",
            self.name,
            self.k.len(),
            self.k[0],
            self.k[self.k.len() - 1],
            self.origin
        )
    }
}

/// b(k) and P_εε(k) measured from simulation spectra, with propagated errors where the inputs have them.
#[derive(Debug, Clone, PartialEq)]
pub struct BiasNoise {
    /// Wavenumbers [h/Mpc] (those of the inputs).
    pub k: Vec<f64>,
    /// b = P_mh/P_mm.
    pub bias: Vec<f64>,
    /// P_εε = P_hh − P_mh²/P_mm [(Mpc/h)^3].
    pub noise: Vec<f64>,
    /// 1σ error of b, if any input has errors (linear propagation, inputs independent).
    pub bias_error: Option<Vec<f64>>,
    /// 1σ error of P_εε [(Mpc/h)^3], likewise.
    pub noise_error: Option<Vec<f64>>,
}

/// Relative tolerance on equal k of the three inputs (tables printed with 9–10 significant digits).
const SAME_K: f64 = 1e-8;

/// The scale-dependent bias and the stochasticity of eqs. bias_eq and delta_field from the measured
/// matter (`pmm`), matter–halo (`pmh`) and halo (`phh`, noise included) spectra on one k grid:
/// b = P_mh/P_mm, P_εε = P_hh − P_mh²/P_mm = P_hh − b² P_mm. Errors, where given, are propagated to first
/// order as independent (a missing error counts as 0): σ_b² = (σ_mh/P_mm)² + (b σ_mm/P_mm)²,
/// σ_εε² = σ_hh² + (2b σ_mh)² + (b² σ_mm)². The three spectra of a simulation share its modes, so their
/// errors correlate and these are an estimate, not a covariance analysis.
///
/// ```
/// use pt_spectra::halo::{bias_and_noise, MeasuredSpectrum};
/// let k = vec![0.05, 0.1];
/// let m = |name, p: Vec<f64>| MeasuredSpectrum::new(name, "memory", k.clone(), p, None).unwrap();
/// let r = bias_and_noise(&m("P_mm", vec![8e3, 5e3]), &m("P_mh", vec![2e4, 1.3e4]),
///                        &m("P_hh", vec![8.2e4, 5.98e4]))?;
/// assert_eq!(r.bias, [2.5, 2.6]);
/// assert!((r.noise[0] - 3.2e4).abs() < 1e-8 && (r.noise[1] - 2.6e4).abs() < 1e-8);
/// # Ok::<(), pt_spectra::error::Error>(())
/// ```
///
/// # Errors
/// [`Error::GridMismatch`] if the k grids differ (length, or a k by more than 1e-8 relative);
/// [`Error::InvalidPower`] where P_mm ≤ 0.
pub fn bias_and_noise(
    pmm: &MeasuredSpectrum,
    pmh: &MeasuredSpectrum,
    phh: &MeasuredSpectrum,
) -> Result<BiasNoise> {
    for (what, other) in [
        ("the k grids of P_mh and P_mm", pmh),
        ("the k grids of P_hh and P_mm", phh),
    ] {
        if other.k.len() != pmm.k.len() {
            return Err(Error::GridMismatch {
                what,
                expected: pmm.describe(),
                found: other.describe(),
            });
        }
        if let Some(i) =
            (0..pmm.k.len()).find(|&i| (other.k[i] - pmm.k[i]).abs() > SAME_K * pmm.k[i])
        {
            return Err(Error::GridMismatch {
                what,
                expected: format!("{}, row {} k = {}", pmm.describe(), i + 1, pmm.k[i]),
                found: format!("{}, row {} k = {}", other.describe(), i + 1, other.k[i]),
            });
        }
    }
    if let Some(i) = pmm.p.iter().position(|&p| p <= 0.0) {
        return Err(Error::InvalidPower {
            origin: format!("P_mm from {}", pmm.origin),
            line: i + 1,
            k: pmm.k[i],
            p: pmm.p[i],
        });
    }
    let n = pmm.k.len();
    let bias: Vec<f64> = (0..n).map(|i| pmh.p[i] / pmm.p[i]).collect();
    let noise: Vec<f64> = (0..n)
        .map(|i| phh.p[i] - pmh.p[i] * pmh.p[i] / pmm.p[i])
        .collect();
    let any_error = [pmm, pmh, phh].iter().any(|s| s.error.is_some());
    let err = |s: &MeasuredSpectrum, i: usize| s.error.as_ref().map_or(0.0, |e| e[i]);
    let (bias_error, noise_error) = if any_error {
        let (be, ne): (Vec<f64>, Vec<f64>) = (0..n)
            .map(|i| {
                let (b, m) = (bias[i], pmm.p[i]);
                let (s_mm, s_mh, s_hh) = (err(pmm, i), err(pmh, i), err(phh, i));
                (
                    ((s_mh / m).powi(2) + (b * s_mm / m).powi(2)).sqrt(),
                    (s_hh.powi(2) + (2.0 * b * s_mh).powi(2) + (b * b * s_mm).powi(2)).sqrt(),
                )
            })
            .unzip();
        (Some(be), Some(ne))
    } else {
        (None, None)
    };
    Ok(BiasNoise {
        k: pmm.k.clone(),
        bias,
        noise,
        bias_error,
        noise_error,
    })
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

    /// P_mm, P_mh = b P_mm, P_hh = b² P_mm + P_εε on `k` for a power law P_mm, b(k) = 2.6 (1 + 1.5 k²)
    /// and a sub-Poissonian, slightly falling P_εε: the spectra the paper's bias_noise figure measures.
    fn synthetic(k: &[f64]) -> [MeasuredSpectrum; 3] {
        let b = |k: f64| 2.6 * (1.0 + 1.5 * k * k);
        let eps = |k: f64| 0.65 / 1.79e-5 * (1.0 - 0.2 * k);
        let pmm: Vec<f64> = k.iter().map(|k| 2.0e4 * (k / 0.05f64).powf(-1.4)).collect();
        let m = |name, p: Vec<f64>| {
            MeasuredSpectrum::new(name, "synthetic", k.to_vec(), p, None).unwrap()
        };
        [
            m("P_mm", pmm.clone()),
            m("P_mh", k.iter().zip(&pmm).map(|(&k, p)| b(k) * p).collect()),
            m(
                "P_hh",
                k.iter()
                    .zip(&pmm)
                    .map(|(&k, p)| b(k) * b(k) * p + eps(k))
                    .collect(),
            ),
        ]
    }

    #[test]
    fn bias_and_noise_are_recovered_from_synthetic_spectra() {
        let k: Vec<f64> = (1..=30).map(|i| 0.01 * i as f64).collect();
        let [pmm, pmh, phh] = synthetic(&k);
        let r = bias_and_noise(&pmm, &pmh, &phh).unwrap();
        for (i, &ki) in k.iter().enumerate() {
            let (b, eps) = (
                2.6 * (1.0 + 1.5 * ki * ki),
                0.65 / 1.79e-5 * (1.0 - 0.2 * ki),
            );
            assert!((r.bias[i] / b - 1.0).abs() < 1e-14, "{} {b}", r.bias[i]);
            // P_εε is a difference of terms up to 40 times larger: rounding of ~1e-16 of those.
            assert!(
                (r.noise[i] / eps - 1.0).abs() < 1e-13,
                "{} {eps}",
                r.noise[i]
            );
        }
        assert_eq!((r.bias_error, r.noise_error), (None, None));
    }

    #[test]
    fn propagated_errors_match_finite_differences() {
        // σ_b and σ_εε against the derivatives taken numerically, one input error at a time.
        let k = vec![0.05, 0.1];
        let [mut pmm, mut pmh, mut phh] = synthetic(&k);
        let errors = [0.01 * pmm.p[1], 0.02 * pmh.p[1], 0.005 * phh.p[1]];
        pmm.error = Some(vec![0.0, errors[0]]);
        pmh.error = Some(vec![0.0, errors[1]]);
        phh.error = Some(vec![0.0, errors[2]]);
        let r = bias_and_noise(&pmm, &pmh, &phh).unwrap();
        let plain = |s: &MeasuredSpectrum| MeasuredSpectrum {
            error: None,
            ..s.clone()
        };
        let (mut var_b, mut var_e) = (0.0, 0.0);
        for (j, e) in errors.iter().enumerate() {
            let h = 1e-6 * e;
            let mut inputs = [plain(&pmm), plain(&pmh), plain(&phh)];
            inputs[j].p[1] += h;
            let up = bias_and_noise(&inputs[0], &inputs[1], &inputs[2]).unwrap();
            inputs[j].p[1] -= 2.0 * h;
            let down = bias_and_noise(&inputs[0], &inputs[1], &inputs[2]).unwrap();
            var_b += ((up.bias[1] - down.bias[1]) / (2.0 * h) * e).powi(2);
            var_e += ((up.noise[1] - down.noise[1]) / (2.0 * h) * e).powi(2);
        }
        let (sb, se) = (r.bias_error.unwrap(), r.noise_error.unwrap());
        assert!(
            (sb[1] / var_b.sqrt() - 1.0).abs() < 1e-5,
            "{} {}",
            sb[1],
            var_b.sqrt()
        );
        assert!(
            (se[1] / var_e.sqrt() - 1.0).abs() < 1e-5,
            "{} {}",
            se[1],
            var_e.sqrt()
        );
        assert_eq!((sb[0], se[0]), (0.0, 0.0));
    }

    #[test]
    fn mismatched_grids_and_bad_spectra_are_errors_naming_them() {
        let k = vec![0.05, 0.1, 0.2];
        let [pmm, pmh, phh] = synthetic(&k);
        let short = synthetic(&k[..2]);
        let e = bias_and_noise(&pmm, &short[1], &phh)
            .unwrap_err()
            .to_string();
        assert!(e.contains("P_mh and P_mm") && e.contains("2 k in"), "{e}");
        let shifted = synthetic(&[0.05, 0.1, 0.21]);
        let e = bias_and_noise(&pmm, &pmh, &shifted[2])
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("P_hh and P_mm") && e.contains("row 3 k = 0.21"),
            "{e}"
        );
        let mut negative = pmm.clone();
        negative.p[1] = -1.0;
        let e = bias_and_noise(&negative, &pmh, &phh)
            .unwrap_err()
            .to_string();
        assert!(e.contains("P_mm") && e.contains("P = -1"), "{e}");
        let e = MeasuredSpectrum::new("P_mh", "x.dat", vec![0.1, 0.05], vec![1.0, 1.0], None)
            .unwrap_err()
            .to_string();
        assert!(e.contains("x.dat:2") && e.contains("0.05"), "{e}");
        let e = MeasuredSpectrum::new("P_hh", "x.dat", vec![0.1], vec![f64::NAN], None)
            .unwrap_err()
            .to_string();
        assert!(e.contains("P_hh = NaN"), "{e}");
        let e = MeasuredSpectrum::new("P_hh", "x.dat", vec![0.1], vec![1.0], Some(vec![-1.0]))
            .unwrap_err()
            .to_string();
        assert!(e.contains("error of P = -1"), "{e}");
    }
}
