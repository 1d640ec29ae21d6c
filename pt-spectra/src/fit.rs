//! Fits of the growth rate f, the FoG dispersion σ0 and the bias amplitude A_b to measured multipoles
//! (Gil-Marín et al. 2012, sections 4.2–4.5).
//!
//! * χ² = Σ_ℓ Σ_{k ≤ k_max} [(P_ℓ,data − P_ℓ,model)/σ_ℓ]² (diagonal, as the paper), or
//!   (d − m)ᵀ C⁻¹ (d − m) with a full covariance of the data vector (ℓ-major: all k of the first ℓ, …).
//! * The model ([`MultipoleModel`]) holds everything that does not depend on (f, σ0, A_b): the real-space
//!   spectra and the TNS coefficients per k. A new parameter point costs one polynomial per k and a
//!   32-point μ quadrature with FoG: no loop integral is ever recomputed.
//! * The best fit minimises χ² over the free parameters with Nelder–Mead (the `argmin` crate). The 1σ
//!   interval of each free parameter is where its profile χ² (minimised over the other free parameters,
//!   1-D Brent) crosses χ²_min + Δχ², Δχ² = 1, 2.3, 3.53 for 1, 2, 3 free parameters: found on the
//!   contour by bracketing and bisection, never from a quadratic approximation.
//! * σ0 enters only through σ0², so it is fitted as is and reported as |σ0|.

use crate::error::{number, Error, Result};
use crate::loops::{Estimate, TnsCoefficients, TnsTerms};
use crate::real::RealSpectra;
use crate::rsd::{Fog, MultipoleRule, RsdModel};
use crate::table::Table;
use argmin::core::{CostFunction, Executor, State};
use argmin::solver::brent::BrentOpt;
use argmin::solver::neldermead::NelderMead;
use std::fmt;
use std::path::Path;
use std::str::FromStr;

/// Measured multipoles P_ℓ(k) with their 1σ errors.
#[derive(Debug, Clone, PartialEq)]
pub struct MultipoleData {
    /// Wavenumbers [h/Mpc], strictly increasing.
    pub k: Vec<f64>,
    /// The multipole orders.
    pub ells: Vec<usize>,
    /// `values[j][i]`: P_ℓj at k_i [(Mpc/h)^3].
    pub values: Vec<Vec<f64>>,
    /// `sigma[j][i]`: the 1σ error of `values[j][i]`, > 0.
    pub sigma: Vec<Vec<f64>>,
    /// Optional full covariance of the data vector (ℓ-major), replacing the diagonal σ².
    pub covariance: Option<Vec<Vec<f64>>>,
}

/// The table columns of k and, per (ℓ, value, error), the value and error columns.
fn wanted(k_column: usize, columns: &[(usize, usize, usize)]) -> Vec<usize> {
    let mut wanted = vec![k_column];
    for &(_, v, s) in columns {
        wanted.extend([v, s]);
    }
    wanted
}

impl MultipoleData {
    /// Reads a table: k in the 0-based column `k_column`, and for each (ℓ, value column, error column).
    ///
    /// # Errors
    /// [`Error::Io`], [`Error::Parse`], [`Error::MissingColumn`]; [`Error::InvalidK`],
    /// [`Error::NonIncreasingK`]; [`Error::InvalidValue`] for a NaN or infinite value or an error that is
    /// not finite and positive.
    pub fn read(
        path: impl AsRef<Path>,
        k_column: usize,
        columns: &[(usize, usize, usize)],
    ) -> Result<Self> {
        Self::from_table(&Table::read(path, &wanted(k_column, columns))?, columns)
    }

    /// As [`read`](Self::read), from text (`origin` names it in messages).
    ///
    /// # Errors
    /// As [`read`](Self::read).
    pub fn parse(
        text: &str,
        origin: &str,
        k_column: usize,
        columns: &[(usize, usize, usize)],
    ) -> Result<Self> {
        Self::from_table(
            &Table::parse(text, origin, &wanted(k_column, columns))?,
            columns,
        )
    }

    /// Measured multipoles from arrays: `k` and, for each ℓ of `ells`, the values and 1σ errors on that
    /// grid (`origin` names them in messages; rows are numbered from 1).
    ///
    /// # Errors
    /// [`Error::LengthMismatch`] for arrays of different lengths, otherwise as [`read`](Self::read).
    pub fn from_arrays(
        k: Vec<f64>,
        ells: &[usize],
        values: Vec<Vec<f64>>,
        sigma: Vec<Vec<f64>>,
        origin: &str,
    ) -> Result<Self> {
        for (what, n) in [
            ("values and ells", values.len()),
            ("errors and ells", sigma.len()),
        ] {
            if n != ells.len() {
                return Err(Error::LengthMismatch {
                    what,
                    left: n,
                    right: ells.len(),
                });
            }
        }
        let mut columns = vec![k];
        for (v, s) in values.into_iter().zip(sigma) {
            columns.extend([v, s]);
        }
        if let Some(bad) = columns.iter().find(|c| c.len() != columns[0].len()) {
            return Err(Error::LengthMismatch {
                what: "multipole arrays and k",
                left: bad.len(),
                right: columns[0].len(),
            });
        }
        let table = Table {
            origin: origin.to_string(),
            header: Vec::new(),
            lines: (1..=columns[0].len()).collect(),
            columns,
        };
        let spec: Vec<(usize, usize, usize)> = ells
            .iter()
            .enumerate()
            .map(|(j, &l)| (l, 1 + 2 * j, 2 + 2 * j))
            .collect();
        Self::from_table(&table, &spec)
    }

    fn from_table(table: &Table, columns: &[(usize, usize, usize)]) -> Result<Self> {
        let k = table.columns[0].clone();
        let origin = &table.origin;
        if k.is_empty() {
            return Err(Error::TooFewPoints {
                origin: origin.clone(),
                found: 0,
                min: 1,
            });
        }
        for i in 0..k.len() {
            let line = table.lines[i];
            if !(k[i].is_finite() && k[i] > 0.0) {
                return Err(Error::InvalidK {
                    origin: origin.clone(),
                    line,
                    k: k[i],
                });
            }
            if i > 0 && k[i] <= k[i - 1] {
                return Err(Error::NonIncreasingK {
                    origin: origin.clone(),
                    line,
                    k: k[i],
                    previous: k[i - 1],
                });
            }
        }
        let (mut values, mut sigma) = (Vec::new(), Vec::new());
        for (j, _) in columns.iter().enumerate() {
            let (v, s) = (&table.columns[1 + 2 * j], &table.columns[2 + 2 * j]);
            for i in 0..k.len() {
                let line = table.lines[i];
                if !v[i].is_finite() {
                    return Err(Error::InvalidValue {
                        origin: origin.clone(),
                        line,
                        name: "P_l",
                        value: v[i],
                        reason: "must be finite",
                    });
                }
                if !(s[i].is_finite() && s[i] > 0.0) {
                    return Err(Error::InvalidValue {
                        origin: origin.clone(),
                        line,
                        name: "sigma_l",
                        value: s[i],
                        reason: "must be finite and positive",
                    });
                }
            }
            values.push(v.clone());
            sigma.push(s.clone());
        }
        Ok(Self {
            k,
            ells: columns.iter().map(|c| c.0).collect(),
            values,
            sigma,
            covariance: None,
        })
    }

    /// Attaches a full covariance matrix of the data vector (ℓ-major, n_ℓ·n_k square, symmetric).
    ///
    /// # Errors
    /// [`Error::LengthMismatch`] for a wrong size; [`Error::InvalidValue`] for a diagonal element that is
    /// not finite and positive, [`Error::BadRow`] for a non-finite or asymmetric element (row numbers
    /// 1-based, origin `covariance matrix`).
    pub fn with_covariance(self, c: Vec<Vec<f64>>) -> Result<Self> {
        let n = self.ells.len() * self.k.len();
        if c.len() != n || c.iter().any(|r| r.len() != n) {
            return Err(Error::LengthMismatch {
                what: "covariance rows and data vector",
                left: c.len(),
                right: n,
            });
        }
        self.checked_covariance(c, "covariance matrix", &[])
    }

    /// Reads the covariance of the data vector (ℓ-major, n_ℓ·n_k square, symmetric) from a table file:
    /// one matrix row per data row, n_ℓ·n_k columns each.
    ///
    /// # Errors
    /// [`Error::Io`], and as [`parse_covariance`](Self::parse_covariance).
    pub fn read_covariance(self, path: impl AsRef<Path>) -> Result<Self> {
        let path = path.as_ref();
        let text = crate::table::read_text(path)?;
        self.parse_covariance(&text, &path.display().to_string())
    }

    /// As [`read_covariance`](Self::read_covariance), from text (`origin` names it in messages).
    ///
    /// # Errors
    /// Each naming `origin` and the line: [`Error::Parse`], [`Error::MissingColumn`] and
    /// [`Error::BadRow`] for a row that is not n_ℓ·n_k numbers, [`Error::BadRow`] for a row too many or a
    /// non-finite or asymmetric element, [`Error::InvalidValue`] for a diagonal element that is not finite
    /// and positive; [`Error::TooFewPoints`] for too few rows.
    pub fn parse_covariance(self, text: &str, origin: &str) -> Result<Self> {
        let n = self.ells.len() * self.k.len();
        let table = Table::parse_exact(text, origin, n)?;
        let rows = table.lines.len();
        if rows < n {
            return Err(Error::TooFewPoints {
                origin: origin.into(),
                found: rows,
                min: n,
            });
        }
        if rows > n {
            return Err(Error::BadRow {
                origin: origin.into(),
                line: table.lines[n],
                problem: format!(
                    "row {} of the covariance is one too many: the data vector has {} values \
                     ({} multipole(s) × {} k)",
                    n + 1,
                    n,
                    self.ells.len(),
                    self.k.len()
                ),
            });
        }
        let c = (0..n)
            .map(|i| table.columns.iter().map(|column| column[i]).collect())
            .collect();
        self.checked_covariance(c, origin, &table.lines)
    }

    /// Attaches the n×n matrix `c` after checking it; `lines` numbers its rows for messages (row numbers if
    /// empty).
    fn checked_covariance(
        mut self,
        c: Vec<Vec<f64>>,
        origin: &str,
        lines: &[usize],
    ) -> Result<Self> {
        let line = |i: usize| lines.get(i).copied().unwrap_or(i + 1);
        for (i, row) in c.iter().enumerate() {
            if let Some(j) = row.iter().position(|v| !v.is_finite()) {
                return Err(Error::BadRow {
                    origin: origin.into(),
                    line: line(i),
                    problem: format!(
                        "covariance element ({}, {}) = {} is not finite (row, column 1-based)",
                        i + 1,
                        j + 1,
                        number(&row[j])
                    ),
                });
            }
            // (Finite: checked above.)
            if row[i] <= 0.0 {
                return Err(Error::InvalidValue {
                    origin: origin.into(),
                    line: line(i),
                    name: "covariance diagonal",
                    value: row[i],
                    reason: "must be finite and positive",
                });
            }
            for j in 0..i {
                // sqrt before the product: c_ii c_jj may overflow, and then any asymmetry would pass.
                let tolerance = 1e-9 * c[i][i].sqrt() * c[j][j].sqrt();
                // Both finite: the difference is finite or infinite, never NaN.
                if (row[j] - c[j][i]).abs() > tolerance {
                    return Err(Error::BadRow {
                        origin: origin.into(),
                        line: line(i),
                        problem: format!(
                            "covariance element ({}, {}) = {} differs from element ({}, {}) = {}: \
                             the matrix must be symmetric (row, column 1-based)",
                            i + 1,
                            j + 1,
                            number(&row[j]),
                            j + 1,
                            i + 1,
                            number(&c[j][i])
                        ),
                    });
                }
            }
        }
        self.covariance = Some(c);
        Ok(self)
    }

    /// Number of k ≤ `k_max` (with k ≥ `k_min`) and the first index.
    fn range(&self, k_min: f64, k_max: f64) -> (usize, usize) {
        let start = self.k.partition_point(|&k| k < k_min);
        let end = self.k.partition_point(|&k| k <= k_max);
        (start, end.max(start))
    }
}

/// A parameter that can be fitted.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Parameter {
    /// The growth rate f.
    F,
    /// The FoG dispersion σ0 [Mpc/h] (z = 0 value; σ = σ0 D(z) f).
    Sigma0,
    /// The bias amplitude A_b (b → A_b b).
    Amplitude,
}

impl Parameter {
    /// The unit of the parameter's values.
    pub fn unit(self) -> &'static str {
        match self {
            Parameter::Sigma0 => "Mpc/h",
            Parameter::F | Parameter::Amplitude => "1",
        }
    }

    /// The name, as on the command line: `f`, `sigma0`, `ab`.
    pub fn name(self) -> &'static str {
        match self {
            Parameter::F => "f",
            Parameter::Sigma0 => "sigma0",
            Parameter::Amplitude => "ab",
        }
    }
}

impl fmt::Display for Parameter {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

impl FromStr for Parameter {
    type Err = Error;

    fn from_str(s: &str) -> Result<Self> {
        match s.trim().to_ascii_lowercase().as_str() {
            "f" => Ok(Parameter::F),
            "sigma0" | "s0" => Ok(Parameter::Sigma0),
            "ab" | "a_b" | "amplitude" => Ok(Parameter::Amplitude),
            _ => Err(Error::UnknownName {
                what: "fit parameter",
                name: s.to_string(),
                available: "f, sigma0, ab",
            }),
        }
    }
}

/// A point in parameter space.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Params {
    /// Growth rate f.
    pub f: f64,
    /// σ0 [Mpc/h].
    pub sigma0: f64,
    /// Bias amplitude A_b.
    pub amplitude: f64,
}

impl Params {
    /// The value of `p`.
    pub fn get(&self, p: Parameter) -> f64 {
        match p {
            Parameter::F => self.f,
            Parameter::Sigma0 => self.sigma0,
            Parameter::Amplitude => self.amplitude,
        }
    }

    fn set(&mut self, p: Parameter, v: f64) {
        match p {
            Parameter::F => self.f = v,
            Parameter::Sigma0 => self.sigma0 = v,
            Parameter::Amplitude => self.amplitude = v,
        }
    }
}

/// The multipoles of one RSD model as a function of (f, σ0, A_b) on a fixed k grid.
#[derive(Debug, Clone)]
pub struct MultipoleModel {
    k: Vec<f64>,
    rsd: RsdModel,
    fog: Fog,
    growth_factor: f64,
    bias: Vec<f64>,
    spectra: Vec<[Estimate; 3]>,
    tns: Option<Vec<TnsCoefficients>>,
    rule: MultipoleRule,
}

impl MultipoleModel {
    /// The model at the k of `real` (and `tns`, needed for [`RsdModel::Tns`]), with b(k) before A_b in
    /// `bias`, FoG `fog`, the growth factor D(z) of the damping scale σ = σ0 D f, and multipoles `ells`.
    ///
    /// # Errors
    /// [`Error::LengthMismatch`] if the grids differ, [`Error::InvalidParameter`] for TNS without `tns`
    /// or a bad ℓ.
    pub fn new(
        real: &RealSpectra,
        tns: Option<&TnsTerms>,
        rsd: RsdModel,
        fog: Fog,
        growth_factor: f64,
        bias: Vec<f64>,
        ells: &[usize],
    ) -> Result<Self> {
        let n = real.k.len();
        if bias.len() != n {
            return Err(Error::LengthMismatch {
                what: "bias and k",
                left: bias.len(),
                right: n,
            });
        }
        let tns = match (rsd.needs_tns(), tns) {
            (true, None) => {
                return Err(Error::MissingTerm {
                    term: "the TNS A and B coefficients",
                    needed_by: "the tns model".into(),
                    hint: " (TnsPlan, or an RsdPlan)",
                })
            }
            (true, Some(t)) if t.coefficients.len() != n => {
                return Err(Error::LengthMismatch {
                    what: "TNS coefficients and k",
                    left: t.coefficients.len(),
                    right: n,
                })
            }
            (true, Some(t)) => Some(t.coefficients.clone()),
            (false, _) => None,
        };
        Ok(Self {
            k: real.k.clone(),
            rsd,
            fog,
            growth_factor,
            bias,
            spectra: (0..n)
                .map(|i| [real.spectra.dd[i], real.spectra.dt[i], real.spectra.tt[i]])
                .collect(),
            tns,
            rule: MultipoleRule::new(ells)?,
        })
    }

    /// The wavenumbers [h/Mpc].
    pub fn k(&self) -> &[f64] {
        &self.k
    }

    /// The multipole orders.
    pub fn ells(&self) -> &[usize] {
        self.rule.ells()
    }

    /// P_ℓ at k indices `range` for `params`, written ℓ-major into `out` (length n_ℓ · range.len()).
    pub fn multipoles_into(&self, params: &Params, range: std::ops::Range<usize>, out: &mut [f64]) {
        let n = range.len();
        let mut row = [0.0; crate::rsd::MAX_ELL / 2 + 1];
        let sigma = params.sigma0 * self.growth_factor * params.f;
        for (c, i) in range.enumerate() {
            let b = params.amplitude * self.bias[i];
            let parts = self
                .rsd
                .parts(
                    b,
                    params.f,
                    self.spectra[i],
                    self.tns.as_ref().map(|t| &t[i]),
                )
                .expect("TNS coefficients are present when needed");
            let poly = parts.total();
            let ells = self.rule.ells().len();
            self.rule
                .evaluate_values(&poly.value, self.fog, self.k[i] * sigma, &mut row[..ells]);
            for j in 0..ells {
                out[j * n + c] = row[j];
            }
        }
    }

    /// P_ℓ(k) for `params`: `result[j][i]` for the j-th ℓ.
    pub fn multipoles(&self, params: &Params) -> Vec<Vec<f64>> {
        let n = self.k.len();
        let mut out = vec![0.0; n * self.ells().len()];
        self.multipoles_into(params, 0..n, &mut out);
        out.chunks(n).map(<[f64]>::to_vec).collect()
    }
}

/// What to fit.
#[derive(Debug, Clone, PartialEq)]
pub struct FitSettings {
    /// The free parameters (1 to 3, no repeats).
    pub free: Vec<Parameter>,
    /// Starting values of the free parameters and the values of the fixed ones.
    pub start: Params,
    /// Smallest k used [h/Mpc].
    pub k_min: f64,
}

/// The best fit at one k_max.
#[derive(Debug, Clone, PartialEq)]
pub struct FitResult {
    /// k_max [h/Mpc].
    pub k_max: f64,
    /// Number of data points used (n_ℓ × n_k).
    pub points: usize,
    /// Best-fit parameters (fixed ones at their given values).
    pub best: Params,
    /// χ² at the best fit.
    pub chi2: f64,
    /// Degrees of freedom, points − free parameters.
    pub dof: usize,
    /// For each free parameter, the 1σ interval (lower, upper) from the Δχ² contour (NaN if the profile
    /// does not reach χ²_min + Δχ² within 50 times the starting step).
    pub intervals: Vec<(Parameter, f64, f64)>,
}

/// Δχ² of the 1σ region for n free parameters.
pub fn delta_chi2(n: usize) -> f64 {
    match n {
        1 => 1.0,
        2 => 2.30,
        _ => 3.53,
    }
}

/// The data of one fit window (k ≤ k_max) and its χ².
struct Residuals<'a> {
    model: &'a MultipoleModel,
    /// Data indices of the model k (the model is built on the data grid).
    range: std::ops::Range<usize>,
    /// L⁻¹ of the Cholesky factor of the covariance window, or `None` for the diagonal σ.
    inverse_factor: Option<Vec<Vec<f64>>>,
    data_vector: Vec<f64>,
    sigma_vector: Vec<f64>,
}

impl Residuals<'_> {
    fn chi2(&self, p: &Params) -> f64 {
        let mut r = vec![0.0; self.data_vector.len()];
        self.model.multipoles_into(p, self.range.clone(), &mut r);
        for (r, d) in r.iter_mut().zip(&self.data_vector) {
            *r = d - *r;
        }
        match &self.inverse_factor {
            None => r
                .iter()
                .zip(&self.sigma_vector)
                .map(|(r, s)| (r / s).powi(2))
                .sum(),
            Some(l) => l
                .iter()
                .map(|row| row.iter().zip(&r).map(|(a, b)| a * b).sum::<f64>().powi(2))
                .sum(),
        }
    }
}

/// χ² as a function of the free parameters, the others at `base`.
struct Window<'a> {
    residuals: &'a Residuals<'a>,
    base: Params,
    free: Vec<Parameter>,
}

impl Window<'_> {
    fn params(&self, x: &[f64]) -> Params {
        let mut p = self.base;
        for (&name, &v) in self.free.iter().zip(x) {
            p.set(name, v);
        }
        p
    }

    fn chi2(&self, p: &Params) -> f64 {
        self.residuals.chi2(p)
    }
}

/// The profile χ² of one parameter: the others minimised (1-D Brent when one other is free).
struct Profile<'a> {
    window: &'a Window<'a>,
    parameter: Parameter,
}

impl Profile<'_> {
    fn at(&self, value: f64, best: &Params, steps: &[f64]) -> f64 {
        let others: Vec<(usize, Parameter)> = self
            .window
            .free
            .iter()
            .copied()
            .enumerate()
            .filter(|&(_, p)| p != self.parameter)
            .collect();
        let mut p = *best;
        p.set(self.parameter, value);
        match others.len() {
            0 => self.window.chi2(&p),
            1 => {
                let (i, other) = others[0];
                let centre = best.get(other);
                let span = 20.0 * steps[i];
                let line = Line {
                    window: self.window,
                    point: p,
                    parameter: other,
                };
                let solver =
                    BrentOpt::new(centre - span, centre + span).set_tolerance(1e-10, 1e-12);
                Executor::new(line, solver)
                    .configure(|s| s.param(centre).max_iters(200))
                    .run()
                    .map(|r| r.state().get_best_cost())
                    .unwrap_or(f64::INFINITY)
            }
            _ => {
                let sub = Window {
                    residuals: self.window.residuals,
                    base: p,
                    free: others.iter().map(|o| o.1).collect(),
                };
                let x0: Vec<f64> = others.iter().map(|&(_, o)| best.get(o)).collect();
                let o_steps: Vec<f64> = others.iter().map(|&(i, _)| steps[i]).collect();
                minimise(&sub, &x0, &o_steps).1
            }
        }
    }
}

/// χ² along one parameter with the others fixed.
struct Line<'a> {
    window: &'a Window<'a>,
    point: Params,
    parameter: Parameter,
}

impl CostFunction for Line<'_> {
    type Param = f64;
    type Output = f64;

    fn cost(&self, x: &f64) -> std::result::Result<f64, argmin::core::Error> {
        let mut p = self.point;
        p.set(self.parameter, *x);
        Ok(self.window.chi2(&p))
    }
}

/// Nelder–Mead from `x0` with initial simplex steps `steps`; (best point, χ²).
fn minimise(window: &Window, x0: &[f64], steps: &[f64]) -> (Vec<f64>, f64) {
    let mut simplex = vec![x0.to_vec()];
    for (i, s) in steps.iter().enumerate() {
        let mut v = x0.to_vec();
        v[i] += s;
        simplex.push(v);
    }
    let solver = NelderMead::new(simplex)
        .with_sd_tolerance(1e-10)
        .expect("valid tolerance");
    match Executor::new(window, solver)
        .configure(|s| s.max_iters(2000))
        .run()
    {
        Ok(r) => {
            let s = r.state();
            (
                s.get_best_param().cloned().unwrap_or_else(|| x0.to_vec()),
                s.get_best_cost(),
            )
        }
        Err(_) => (x0.to_vec(), f64::INFINITY),
    }
}

impl CostFunction for &Window<'_> {
    type Param = Vec<f64>;
    type Output = f64;

    fn cost(&self, x: &Vec<f64>) -> std::result::Result<f64, argmin::core::Error> {
        Ok(self.chi2(&self.params(x)))
    }
}

/// Lower-triangular Cholesky factor of a symmetric positive-definite matrix, or `None`.
fn cholesky(a: &[Vec<f64>]) -> Option<Vec<Vec<f64>>> {
    let n = a.len();
    let mut l = vec![vec![0.0; n]; n];
    for i in 0..n {
        for j in 0..=i {
            let s: f64 = (0..j).map(|m| l[i][m] * l[j][m]).sum();
            if i == j {
                let d = a[i][i] - s;
                // Also refuse NaN and infinity: huge elements overflow the sums.
                if !(d > 0.0 && d.is_finite()) {
                    return None;
                }
                l[i][i] = d.sqrt();
            } else {
                l[i][j] = (a[i][j] - s) / l[j][j];
            }
        }
    }
    Some(l)
}

/// L⁻¹ for lower-triangular L (forward substitution on the identity).
#[allow(clippy::needless_range_loop)] // the triangular index ranges read as the algorithm
fn invert_lower(l: &[Vec<f64>]) -> Vec<Vec<f64>> {
    let n = l.len();
    let mut inv = vec![vec![0.0; n]; n];
    for c in 0..n {
        for i in c..n {
            let s: f64 = (c..i).map(|m| l[i][m] * inv[m][c]).sum();
            inv[i][c] = ((if i == c { 1.0 } else { 0.0 }) - s) / l[i][i];
        }
    }
    inv
}

/// Fits `model` to `data` using k ∈ [k_min, k_max], for each `k_max`.
///
/// # Errors
/// [`Error::InvalidParameter`] for no or repeated free parameters, a model grid that is not the data grid,
/// ells that differ, fewer data points than free parameters, or a covariance window that is not
/// positive definite.
pub fn fit(
    model: &MultipoleModel,
    data: &MultipoleData,
    settings: &FitSettings,
    k_max: &[f64],
) -> Result<Vec<FitResult>> {
    let free = &settings.free;
    if free.is_empty() || free.len() > 3 || (1..free.len()).any(|i| free[..i].contains(&free[i])) {
        return Err(Error::InvalidParameter {
            name: "number of distinct free parameters",
            value: free.len() as f64,
            reason: "must be 1, 2 or 3 distinct of f, sigma0, ab",
        });
    }
    if model.k() != data.k.as_slice() {
        return Err(Error::InvalidParameter {
            name: "model k grid",
            value: model.k().len() as f64,
            reason: "must be the data k grid",
        });
    }
    if model.ells() != data.ells.as_slice() {
        return Err(Error::InvalidParameter {
            name: "number of multipoles",
            value: model.ells().len() as f64,
            reason: "the model must have the data's ells, in order",
        });
    }
    let dchi2 = delta_chi2(free.len());
    let mut results = Vec::with_capacity(k_max.len());
    for &km in k_max {
        let (start, end) = data.range(settings.k_min, km);
        let n_k = end - start;
        let points = n_k * data.ells.len();
        if points <= free.len() {
            return Err(Error::InvalidParameter {
                name: "k_max [h/Mpc]",
                value: km,
                reason: "leaves no more data points than free parameters",
            });
        }
        let mut data_vector = Vec::with_capacity(points);
        let mut sigma_vector = Vec::with_capacity(points);
        for j in 0..data.ells.len() {
            data_vector.extend(&data.values[j][start..end]);
            sigma_vector.extend(&data.sigma[j][start..end]);
        }
        let inverse_factor = match &data.covariance {
            None => None,
            Some(c) => {
                let n_all = data.k.len();
                let index = |j: usize, i: usize| j * n_all + i;
                let ids: Vec<usize> = (0..data.ells.len())
                    .flat_map(|j| (start..end).map(move |i| index(j, i)))
                    .collect();
                let sub: Vec<Vec<f64>> = ids
                    .iter()
                    .map(|&a| ids.iter().map(|&b| c[a][b]).collect())
                    .collect();
                let l = cholesky(&sub).ok_or(Error::InvalidParameter {
                    name: "k_max [h/Mpc]",
                    value: km,
                    reason: "the covariance window is not positive definite",
                })?;
                Some(invert_lower(&l))
            }
        };
        let residuals = Residuals {
            model,
            range: start..end,
            inverse_factor,
            data_vector,
            sigma_vector,
        };
        let window = Window {
            residuals: &residuals,
            base: settings.start,
            free: free.clone(),
        };
        let x0: Vec<f64> = free.iter().map(|&p| settings.start.get(p)).collect();
        let steps: Vec<f64> = x0.iter().map(|v| 0.05 * v.abs().max(0.1)).collect();
        let (x, _) = minimise(&window, &x0, &steps);
        // Restart once from the optimum: Nelder–Mead can stall on a ridge.
        let (x, chi2) = minimise(&window, &x, &steps);
        let mut best = window.params(&x);
        // χ² depends on σ0² only.
        best.sigma0 = best.sigma0.abs();
        let intervals = free
            .iter()
            .enumerate()
            .map(|(i, &p)| {
                let profile = Profile {
                    window: &window,
                    parameter: p,
                };
                let centre = best.get(p);
                let target = chi2 + dchi2;
                let crossing = |direction: f64| -> f64 {
                    let step = direction * steps[i] * 0.2;
                    let (mut inside, mut outside) = (centre, centre + step);
                    let mut tries = 0;
                    while profile.at(outside, &best, &steps) < target {
                        inside = outside;
                        outside = centre + (outside - centre) * 2.0;
                        tries += 1;
                        if tries > 12 {
                            return f64::NAN;
                        }
                    }
                    for _ in 0..40 {
                        let mid = 0.5 * (inside + outside);
                        if profile.at(mid, &best, &steps) < target {
                            inside = mid;
                        } else {
                            outside = mid;
                        }
                        if (outside - inside).abs() < 1e-7 * centre.abs().max(1e-3) {
                            break;
                        }
                    }
                    0.5 * (inside + outside)
                };
                let (lo, hi) = (crossing(-1.0), crossing(1.0));
                (p, lo, hi)
            })
            .collect::<Vec<_>>();
        // A σ0 interval reaching below 0 contains 0 (χ² is even in σ0).
        let intervals = intervals
            .into_iter()
            .map(|(p, lo, hi)| {
                if p == Parameter::Sigma0 && lo < 0.0 {
                    (p, 0.0, hi)
                } else {
                    (p, lo, hi)
                }
            })
            .collect();
        results.push(FitResult {
            k_max: km,
            points,
            best,
            chi2,
            dof: points - free.len(),
            intervals,
        });
    }
    Ok(results)
}
