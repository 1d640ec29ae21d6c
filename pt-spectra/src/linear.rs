//! Linear matter power spectrum input: tables, interpolation, extrapolation and simple integrals.
//!
//! Units throughout: k in h/Mpc, P(k) in (Mpc/h)^3, radii in Mpc/h, σ_v² in (Mpc/h)².
//!
//! * **Input.** CAMB `matterpower.dat` and CLASS `*_pk.dat` tables, or any text table with `#` comment lines
//!   and whitespace- or comma-separated columns ([`LinearSpectrum::from_file`], [`LinearSpectrum::parse`]);
//!   [`Columns`] picks the k and P columns of wider tables. The spectra of Gil-Marín et al. (2012,
//!   arXiv:1209.3771) computed with CAMB are embedded ([`LinearSpectrum::gm2012`]), so nothing has to be
//!   read from disk.
//! * **Validation.** k finite, positive and strictly increasing (ln k too); P finite and positive, and its
//!   interpolation below [`MAX_POWER`]; at least [`MIN_POINTS`] rows. Every failure is an [`Error`] naming
//!   the line and value.
//! * **Interpolation.** A not-a-knot cubic spline in (ln k, ln P). On the CAMB tables (Δln k = 0.011) it
//!   reproduces nodes dropped from a table decimated by 2 to < 1e-4 over 0.01–0.5 h/Mpc, BAO wiggles
//!   included (see the tests).
//! * **Extrapolation.** Outside [k_min, k_max] a power law P = P_end (k/k_end)^n, continuous at the end node,
//!   with the slope n fitted by least squares to ln P against ln k over the last [`EXTRAPOLATION_POINTS`]
//!   nodes at that end. [`LinearSpectrum::region`] and [`LinearSpectrum::extrapolation_in`] tell the
//!   caller when this happens so that it can warn.

mod grid;
mod interpolant;
pub(crate) mod spline;

use crate::error::{Error, Result};
pub use grid::LogGrid;
pub use interpolant::NodeInterpolant;
pub(crate) use spline::simpson;
use spline::{LogSpline, PowerLaw};
use std::f64::consts::PI;
use std::fmt;
use std::path::Path;

/// Minimum number of rows of a linear-spectrum table.
pub const MIN_POINTS: usize = 20;

/// Number of end nodes to which each extrapolating power law is fitted.
pub const EXTRAPOLATION_POINTS: usize = 5;

/// Largest P(k) [(Mpc/h)^3] a table may have, also between its nodes: bounds of the log-log spline must
/// stay below it so that P, its power-law tails and sums of it stay finite in f64.
pub const MAX_POWER: f64 = 1e300;

/// Why a table whose log-log spline overshoots [`MAX_POWER`] is refused.
const SPLINE_OVERFLOW: &str = "the log-log spline next to this row exceeds 1e300: P changes too \
                               abruptly here, or the k are too unevenly spaced";

/// Redshifts of the embedded Gil-Marín et al. (2012) linear spectra, see [`LinearSpectrum::gm2012`].
pub const GM2012_REDSHIFTS: [f64; 4] = [0.0, 0.5, 1.0, 1.5];

/// CAMB 2.0.5 tables for the gm2012 cosmology, with their provenance headers.
const GM2012_TABLES: [(&str, &str); 4] = [
    (
        "embedded linear_pk_gm2012_z0.0.dat",
        include_str!("../data/linear_pk_gm2012_z0.0.dat"),
    ),
    (
        "embedded linear_pk_gm2012_z0.5.dat",
        include_str!("../data/linear_pk_gm2012_z0.5.dat"),
    ),
    (
        "embedded linear_pk_gm2012_z1.0.dat",
        include_str!("../data/linear_pk_gm2012_z1.0.dat"),
    ),
    (
        "embedded linear_pk_gm2012_z1.5.dat",
        include_str!("../data/linear_pk_gm2012_z1.5.dat"),
    ),
];

/// Which columns (0-based) of a table hold k and P.
///
/// The default, `(0, 1)`, fits CAMB `matterpower.dat` and CLASS `pk.dat`. For a CLASS file with several
/// spectra or an output of another code, pick the columns, e.g. `Columns::new(0, 2)`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Columns {
    /// 0-based column of k [h/Mpc].
    pub k: usize,
    /// 0-based column of P(k) [(Mpc/h)^3].
    pub p: usize,
}

impl Columns {
    /// Columns `k` and `p` (0-based).
    pub const fn new(k: usize, p: usize) -> Self {
        Self { k, p }
    }
}

impl Default for Columns {
    fn default() -> Self {
        Self::new(0, 1)
    }
}

/// Where a wavenumber lies relative to the tabulated range.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Region {
    /// k < k_min: low-k power-law extrapolation.
    Below,
    /// k_min ≤ k ≤ k_max: spline interpolation.
    Table,
    /// k > k_max: high-k power-law extrapolation.
    Above,
}

/// A report that a range of wavenumbers reaches beyond the table, for the caller to warn about.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Extrapolation {
    /// The requested range [h/Mpc].
    pub requested: (f64, f64),
    /// The tabulated range [h/Mpc].
    pub table: (f64, f64),
    /// Power-law slopes d ln P / d ln k used below and above the table.
    pub slopes: (f64, f64),
}

impl fmt::Display for Extrapolation {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "k range [{:.4e}, {:.4e}] h/Mpc extends beyond the linear table [{:.4e}, {:.4e}] h/Mpc; \
             power-law extrapolation used (slope {:.3} below, {:.3} above)",
            self.requested.0,
            self.requested.1,
            self.table.0,
            self.table.1,
            self.slopes.0,
            self.slopes.1
        )
    }
}

/// A linear matter power spectrum P(k): validated nodes, a log-log cubic spline and power-law tails.
///
/// k in h/Mpc, P in (Mpc/h)^3. Cheap to evaluate ([`eval`](Self::eval) is an index guess plus a cubic)
/// and to clone.
///
/// ```
/// use pt_spectra::linear::LinearSpectrum;
/// let p = LinearSpectrum::gm2012(0.0)?;
/// let s8 = p.sigma8();
/// assert!((s8 - 0.8).abs() < 1e-3);
/// assert!(p.eval(0.1) > 5000.0);
/// # Ok::<(), pt_spectra::error::Error>(())
/// ```
#[derive(Debug, Clone)]
pub struct LinearSpectrum {
    k: Vec<f64>,
    p: Vec<f64>,
    spline: LogSpline,
    low: PowerLaw,
    high: PowerLaw,
    header: Vec<String>,
    origin: String,
}

impl LinearSpectrum {
    /// Reads a table with k in column 0 and P in column 1 (CAMB `matterpower.dat`, CLASS `pk.dat`).
    ///
    /// # Errors
    /// [`Error::Io`] if the file cannot be read, otherwise as [`parse`](Self::parse).
    pub fn from_file(path: impl AsRef<Path>) -> Result<Self> {
        Self::from_file_with_columns(path, Columns::default())
    }

    /// Reads a table taking k and P from the given 0-based columns.
    ///
    /// # Errors
    /// [`Error::Io`] if the file cannot be read, otherwise as [`parse`](Self::parse).
    pub fn from_file_with_columns(path: impl AsRef<Path>, columns: Columns) -> Result<Self> {
        let path = path.as_ref();
        let text = crate::table::read_text(path)?;
        Self::parse(&text, &path.display().to_string(), columns)
    }

    /// Parses a table from text; `origin` names it in error messages.
    ///
    /// Format: lines starting with `#` (after optional blanks) are header lines, kept as
    /// [`header`](Self::header); text after a `#` on a data line is ignored; blank lines are skipped;
    /// fields are separated by commas and/or whitespace; a single row of column names with no number in it
    /// (e.g. `k,P`) before the first data row is taken as a header line.
    ///
    /// # Errors
    /// [`Error::Parse`], [`Error::MissingColumn`], [`Error::InvalidK`], [`Error::NonIncreasingK`],
    /// [`Error::InvalidPower`], [`Error::InvalidValue`] (a k so close to the previous one that ln k does not
    /// increase, or a P whose log-log spline may exceed [`MAX_POWER`]; each with the line number),
    /// [`Error::TooFewPoints`], and [`Error::InvalidParameter`] if `columns.k == columns.p`.
    pub fn parse(text: &str, origin: &str, columns: Columns) -> Result<Self> {
        if columns.k == columns.p {
            return Err(invalid(
                "P column",
                columns.p as f64,
                "must differ from the k column",
            ));
        }
        let table = crate::table::DataColumns::parse(text, origin, &[columns.k, columns.p])?;
        let [k, p]: [Vec<f64>; 2] = table.columns.try_into().expect("two columns");
        let x: Vec<f64> = k.iter().map(|v| v.ln()).collect();
        for i in 0..k.len() {
            let previous = i.checked_sub(1).map(|j| (k[j], x[j]));
            check_row(origin, table.lines[i], (k[i], x[i]), p[i], previous)?;
        }
        Self::build((k, x), p, table.header, origin.to_string(), &table.lines)
    }

    /// A spectrum from nodes k [h/Mpc] and P [(Mpc/h)^3], validated as a table would be (row numbers are
    /// 1-based indices).
    ///
    /// # Errors
    /// [`Error::LengthMismatch`], [`Error::InvalidK`], [`Error::NonIncreasingK`], [`Error::InvalidPower`],
    /// [`Error::InvalidValue`], [`Error::TooFewPoints`].
    pub fn from_nodes(k: Vec<f64>, p: Vec<f64>) -> Result<Self> {
        if k.len() != p.len() {
            return Err(Error::LengthMismatch {
                what: "k and P",
                left: k.len(),
                right: p.len(),
            });
        }
        let origin = "in-memory nodes";
        let x: Vec<f64> = k.iter().map(|v| v.ln()).collect();
        for i in 0..k.len() {
            let previous = i.checked_sub(1).map(|j| (k[j], x[j]));
            check_row(origin, i + 1, (k[i], x[i]), p[i], previous)?;
        }
        Self::build((k, x), p, Vec::new(), origin.to_string(), &[])
    }

    /// Tabulates `p_of_k` [(Mpc/h)^3] on `grid` and interpolates it.
    ///
    /// # Errors
    /// As [`from_nodes`](Self::from_nodes), e.g. if `p_of_k` returns a non-positive value.
    pub fn from_fn(grid: &LogGrid, p_of_k: impl Fn(f64) -> f64) -> Result<Self> {
        let k = grid.points();
        let p = k.iter().map(|&q| p_of_k(q)).collect();
        Self::from_nodes(k, p)
    }

    /// The embedded CAMB 2.0.5 linear spectrum of the Gil-Marín et al. (2012) cosmology (Ω_m = 0.27,
    /// Ω_Λ = 0.73, h = 0.7, Ω_b h² = 0.023, n_s = 0.95, σ8 = 0.8) at `z` ∈ [`GM2012_REDSHIFTS`]:
    /// 1200 log-spaced k from 1e-4 to 50 h/Mpc; the file header (tool, settings, σ8(z), f(z)) is kept.
    ///
    /// # Errors
    /// [`Error::NoEmbeddedSpectrum`] if `z` is not one of 0, 0.5, 1, 1.5 (within 1e-6).
    pub fn gm2012(z: f64) -> Result<Self> {
        let index = GM2012_REDSHIFTS
            .iter()
            .position(|&zi| (zi - z).abs() < 1e-6)
            .ok_or(Error::NoEmbeddedSpectrum {
                z,
                available: "0, 0.5, 1, 1.5",
            })?;
        let (origin, text) = GM2012_TABLES[index];
        Self::parse(text, origin, Columns::default())
    }

    /// The embedded z = 0 spectrum, [`gm2012`](Self::gm2012)`(0.0)`; the table is checked by the tests.
    pub fn gm2012_z0() -> Self {
        Self::gm2012(0.0).expect("the embedded z = 0 table is valid")
    }

    /// The spectrum through validated rows; `lines` numbers them for messages (row numbers if empty).
    fn build(
        (k, x): (Vec<f64>, Vec<f64>),
        p: Vec<f64>,
        header: Vec<String>,
        origin: String,
        lines: &[usize],
    ) -> Result<Self> {
        if k.len() < MIN_POINTS {
            return Err(Error::TooFewPoints {
                origin,
                found: k.len(),
                min: MIN_POINTS,
            });
        }
        let y: Vec<f64> = p.iter().map(|v| v.ln()).collect();
        let m = EXTRAPOLATION_POINTS;
        let n = k.len();
        let low = PowerLaw::fit(&x[..m], &y[..m], 0);
        let high = PowerLaw::fit(&x[n - m..], &y[n - m..], m - 1);
        let spline = LogSpline::new(x, y);
        // Rows spaced very unevenly, or P changing abruptly, can make the spline exceed f64 between the
        // nodes. The overshoot spreads along the spline: blame the row where it is worst.
        if spline
            .upper_bounds()
            .any(|bound| bound.is_nan() || bound >= MAX_POWER.ln())
        {
            let j = spline.worst_node();
            return Err(Error::InvalidValue {
                origin,
                line: lines.get(j).copied().unwrap_or(j + 1),
                name: "P [(Mpc/h)^3]",
                value: p[j],
                reason: SPLINE_OVERFLOW,
            });
        }
        Ok(Self {
            k,
            p,
            spline,
            low,
            high,
            header,
            origin,
        })
    }

    /// P(k) in (Mpc/h)^3 at k in h/Mpc.
    ///
    /// Spline in (ln k, ln P) inside the table, power laws outside (see the module docs). Returns 0 for
    /// k ≤ 0 (the linear spectrum vanishes at k = 0) and NaN for NaN.
    pub fn eval(&self, k: f64) -> f64 {
        if k.is_nan() {
            f64::NAN
        } else if k <= 0.0 {
            0.0
        } else if k < self.k_min() {
            self.low.eval(k)
        } else if k > self.k_max() {
            self.high.eval(k)
        } else {
            self.spline.eval(k.ln()).exp()
        }
    }

    /// P at ln k = `x` (k in h/Mpc), as [`eval`](Self::eval) (equal to round-off) without its
    /// exp/ln pair: for samples on a grid uniform in ln k (the loop lattice).
    pub fn eval_ln(&self, x: f64) -> f64 {
        let (lo, hi) = self.spline.range();
        if x.is_nan() {
            f64::NAN
        } else if x < lo {
            self.low.eval_ln(x)
        } else if x > hi {
            self.high.eval_ln(x)
        } else {
            self.spline.eval(x).exp()
        }
    }

    /// P at every ln k = `x` of an increasing sequence (the loop lattice), as [`eval_ln`](Self::eval_ln)
    /// to within 2 ulp: ln P first, then one vectorised exp pass ([`crate::simd`]).
    pub(crate) fn eval_ln_many(&self, x: impl Iterator<Item = f64>) -> Vec<f64> {
        let (lo, hi) = self.spline.range();
        let (ln_low, ln_high) = (self.low.p0.ln(), self.high.p0.ln());
        let mut v: Vec<f64> = x
            .map(|x| {
                if x < lo {
                    ln_low + self.low.slope * (x - self.low.ln_k0)
                } else if x > hi {
                    ln_high + self.high.slope * (x - self.high.ln_k0)
                } else {
                    self.spline.eval(x)
                }
            })
            .collect();
        crate::simd::exp_in_place(&mut v);
        v
    }

    /// Smallest tabulated k [h/Mpc].
    pub fn k_min(&self) -> f64 {
        self.k[0]
    }

    /// Largest tabulated k [h/Mpc].
    pub fn k_max(&self) -> f64 {
        self.k[self.k.len() - 1]
    }

    /// The nodes: k [h/Mpc] and P [(Mpc/h)^3].
    pub fn nodes(&self) -> (&[f64], &[f64]) {
        (&self.k, &self.p)
    }

    /// The `#` header lines of the source table (without the `#`), e.g. provenance.
    pub fn header(&self) -> &[String] {
        &self.header
    }

    /// The file path or description the spectrum came from.
    pub fn origin(&self) -> &str {
        &self.origin
    }

    /// Power-law slopes d ln P/d ln k used for extrapolation (below, above) the table.
    pub fn extrapolation_slopes(&self) -> (f64, f64) {
        (self.low.slope, self.high.slope)
    }

    /// Whether `k` [h/Mpc] is below, inside or above the tabulated range.
    pub fn region(&self, k: f64) -> Region {
        if k < self.k_min() {
            Region::Below
        } else if k > self.k_max() {
            Region::Above
        } else {
            Region::Table
        }
    }

    /// `Some` report if [k_lo, k_hi] [h/Mpc] reaches outside the table, so that the caller can warn.
    pub fn extrapolation_in(&self, k_lo: f64, k_hi: f64) -> Option<Extrapolation> {
        (k_lo < self.k_min() || k_hi > self.k_max()).then(|| Extrapolation {
            requested: (k_lo, k_hi),
            table: (self.k_min(), self.k_max()),
            slopes: self.extrapolation_slopes(),
        })
    }

    /// The spectrum of the table's nodes with k ∈ [`k_lo`, `k_hi`] only, extended by power laws beyond
    /// them as any table is (what a table of that range would give).
    ///
    /// # Errors
    /// As [`from_nodes`](Self::from_nodes), e.g. [`Error::TooFewPoints`] if the range keeps too few
    /// nodes.
    pub fn restricted(&self, k_lo: f64, k_hi: f64) -> Result<Self> {
        let (k, p): (Vec<f64>, Vec<f64>) = self
            .k
            .iter()
            .zip(&self.p)
            .filter(|(&k, _)| k >= k_lo && k <= k_hi)
            .unzip();
        Self::from_nodes(k, p)
    }

    /// The spectrum multiplied by a constant `factor` (e.g. a growth ratio D²(z)/D²(z_in)).
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] unless `factor` is finite and positive and keeps P below
    /// [`MAX_POWER`].
    pub fn scaled(&self, factor: f64) -> Result<Self> {
        check_positive("scale factor", factor)?;
        let peak = self.spline.upper_bounds().fold(f64::NEG_INFINITY, f64::max);
        // The bounds are finite (checked when built) and so is ln(factor).
        if peak + factor.ln() >= MAX_POWER.ln() {
            return Err(invalid(
                "scale factor",
                factor,
                "would raise P(k) above 1e300 (Mpc/h)^3",
            ));
        }
        let mut out = self.clone();
        out.p.iter_mut().for_each(|v| *v *= factor);
        out.spline.shift(factor.ln());
        out.low.p0 *= factor;
        out.high.p0 *= factor;
        Ok(out)
    }

    /// P(s k) as a spectrum: the nodes at k/s with the same P (the spline in ln k and the power laws move
    /// with them). A loop integral at the sides s k of P is s³ times the one at k of this spectrum: the
    /// isotropic Alcock–Paczynski dilation of the one-loop bispectrum block.
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] unless `s` is finite and positive.
    pub fn dilated(&self, s: f64) -> Result<Self> {
        check_positive("dilation", s)?;
        let mut out = Self::from_nodes(self.k.iter().map(|k| k / s).collect(), self.p.clone())?;
        out.header.clone_from(&self.header);
        out.origin = format!("{} at k x {s}", self.origin);
        Ok(out)
    }

    /// RMS linear density contrast in a top-hat sphere of radius `r` [Mpc/h], with its error estimate.
    ///
    /// σ²(R) = (1/2π²) ∫ k³ P(k) W²(kR) d ln k, W(x) = 3(sin x − x cos x)/x³. The integral runs over
    /// kR ∈ [1e-3, 300] (beyond it the integrand of a CDM spectrum is < 1e-6 of the total), with the
    /// power-law extrapolations where that reaches past the table (check
    /// [`extrapolation_in`](Self::extrapolation_in)`(1e-3/R, 300/R)`). Composite Simpson in ln k with
    /// ≥ 16 points per period of W²; the error is |S_n − S_{n/2}|/15.
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] unless `r` is finite and positive.
    pub fn sigma_r(&self, r: f64) -> Result<(f64, f64)> {
        check_positive("R [Mpc/h]", r)?;
        let (x_lo, x_hi) = (1e-3_f64, 300.0_f64);
        let span = (x_hi / x_lo).ln();
        let needed = (span * 16.0 * x_hi / PI).ceil() as usize;
        let n = needed.next_power_of_two().max(1024);
        let integrand = |lnk: f64| {
            let k = lnk.exp();
            k.powi(3) * self.eval(k) * top_hat(k * r).powi(2)
        };
        let (s2, err) = simpson(integrand, (x_lo / r).ln(), (x_hi / r).ln(), n);
        let norm = 1.0 / (2.0 * PI * PI);
        let sigma = (s2 * norm).sqrt();
        Ok((sigma, 0.5 * err * norm / sigma))
    }

    /// σ8 = σ(R = 8 Mpc/h), see [`sigma_r`](Self::sigma_r).
    pub fn sigma8(&self) -> f64 {
        self.sigma_r(8.0).map_or(f64::NAN, |(s, _)| s)
    }

    /// Linear velocity dispersion σ_v² = (1/6π²) ∫ P(q) dq over [k_min, k_max] of the table, in (Mpc/h)²,
    /// with an error estimate.
    ///
    /// Composite Simpson in ln q on the spline with 8 sub-intervals per table interval; the error is
    /// |S_n − S_{n/2}|/15. No extrapolated tails are added.
    pub fn sigma_v2(&self) -> (f64, f64) {
        let n = 8 * (self.k.len() - 1);
        let integrand = |lnq: f64| {
            let q = lnq.exp();
            q * self.eval(q)
        };
        let (a, b) = (self.k_min().ln(), self.k_max().ln());
        let (v, e) = simpson(integrand, a, b, n);
        let norm = 1.0 / (6.0 * PI * PI);
        (v * norm, e * norm)
    }
}

/// Fourier transform of the top-hat window, W(x) = 3(sin x − x cos x)/x³, with its series for small x.
pub fn top_hat(x: f64) -> f64 {
    if x.abs() < 1e-2 {
        let x2 = x * x;
        1.0 - x2 / 10.0 + x2 * x2 / 280.0
    } else {
        3.0 * (x.sin() - x * x.cos()) / (x * x * x)
    }
}

/// Checks one row (k with its ln k, P) against the previous one's (k, ln k).
fn check_row(
    origin: &str,
    line: usize,
    (k, ln_k): (f64, f64),
    p: f64,
    previous: Option<(f64, f64)>,
) -> Result<()> {
    if !(k.is_finite() && k > 0.0) {
        return Err(Error::InvalidK {
            origin: origin.into(),
            line,
            k,
        });
    }
    if let Some((previous, _)) = previous.filter(|&(prev, _)| k <= prev) {
        return Err(Error::NonIncreasingK {
            origin: origin.into(),
            line,
            k,
            previous,
        });
    }
    if previous.is_some_and(|(_, ln_prev)| ln_k <= ln_prev) {
        return Err(Error::InvalidValue {
            origin: origin.into(),
            line,
            name: "k [h/Mpc]",
            value: k,
            reason: crate::table::K_TOO_CLOSE,
        });
    }
    if !(p.is_finite() && p > 0.0) {
        return Err(Error::InvalidPower {
            origin: origin.into(),
            line,
            k,
            p,
        });
    }
    if p >= MAX_POWER {
        return Err(Error::InvalidValue {
            origin: origin.into(),
            line,
            name: "P [(Mpc/h)^3]",
            value: p,
            reason: "exceeds 1e300: too close to the largest f64 to interpolate and integrate",
        });
    }
    Ok(())
}

fn check_positive(name: &'static str, value: f64) -> Result<()> {
    if value.is_finite() && value > 0.0 {
        Ok(())
    } else {
        Err(invalid(name, value, "must be finite and positive"))
    }
}

fn invalid(name: &'static str, value: f64, reason: &'static str) -> Error {
    Error::InvalidParameter {
        name,
        value,
        reason,
    }
}

#[cfg(test)]
mod tests;
