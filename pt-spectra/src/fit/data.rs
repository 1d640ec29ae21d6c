//! Measured multipoles: reading them from tables or arrays, with checks that name the bad row.

use crate::error::{Error, Result};
use crate::table::DataColumns;
use std::path::Path;

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
        Self::from_table(
            &DataColumns::read(path, &wanted(k_column, columns))?,
            columns,
        )
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
            &DataColumns::parse(text, origin, &wanted(k_column, columns))?,
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
        let table = DataColumns {
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

    fn from_table(table: &DataColumns, columns: &[(usize, usize, usize)]) -> Result<Self> {
        let k = table.columns[0].clone();
        let origin = &table.origin;
        if k.is_empty() {
            return Err(Error::TooFewPoints {
                origin: origin.clone(),
                found: 0,
                min: 1,
            });
        }
        crate::table::check_k_grid(origin, &k, &table.lines)?;
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
    /// not finite and positive, [`Error::BadRow`] for a non-finite or asymmetric element, a matrix that
    /// is not positive definite, or a variance absurdly small for its data (the rules of
    /// [`crate::fit::covariance`]; row numbers 1-based, origin `covariance matrix`). Whether the rows a
    /// fit inverts are nearly degenerate is checked by the fit, on those rows.
    pub fn with_covariance(self, c: Vec<Vec<f64>>) -> Result<Self> {
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
    /// non-finite or asymmetric element and the other faults of [`crate::fit::covariance`],
    /// [`Error::InvalidValue`] for a diagonal element that is not finite and positive;
    /// [`Error::TooFewPoints`] for too few rows.
    pub fn parse_covariance(self, text: &str, origin: &str) -> Result<Self> {
        let n = self.ells.len() * self.k.len();
        // A row narrower or wider than the data vector is a matrix of another size (or layout):
        // said so, with both sizes, rather than as "column 16 was requested" (issue 45).
        let size = |line: usize, found: usize| Error::BadRow {
            origin: origin.into(),
            line,
            problem: format!(
                "the covariance row has {found} columns, but the data vector has {n} values ({} \
                 multipole(s) × {} k): the covariance must be {n} × {n}, one matrix row per line, \
                 ℓ-major",
                self.ells.len(),
                self.k.len()
            ),
        };
        let table = DataColumns::parse_exact(text, origin, n).map_err(|e| match e {
            Error::MissingColumn { line, found, .. } => size(line, found),
            Error::BadRow {
                line, ref problem, ..
            } if problem.ends_with(" expected") => {
                let found = problem
                    .split_whitespace()
                    .nth(3)
                    .and_then(|w| w.parse().ok())
                    .unwrap_or(0);
                size(line, found)
            }
            e => e,
        })?;
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

    /// Attaches the n×n matrix `c` after checking it (finite, then the checks of
    /// [`super::covariance::validate`]: symmetric, positive definite, no variance absurdly small for its
    /// data); `lines` numbers its rows for messages (row numbers if empty).
    pub(super) fn checked_covariance(
        mut self,
        c: Vec<Vec<f64>>,
        origin: &str,
        lines: &[usize],
    ) -> Result<Self> {
        self.covariance = Some(super::covariance::validate(c, &self.values, origin, lines)?);
        Ok(self)
    }

    /// Number of k ≤ `k_max` (with k ≥ `k_min`) and the first index.
    pub(super) fn range(&self, k_min: f64, k_max: f64) -> (usize, usize) {
        let start = self.k.partition_point(|&k| k < k_min);
        let end = self.k.partition_point(|&k| k <= k_max);
        (start, end.max(start))
    }
}
