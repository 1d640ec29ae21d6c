//! [`WindowMultipoles`]: the configuration-space window multipoles Q_ℓ(s) of a survey, read from a file.
//!
//! Q(s, μ) = Σ_ℓ Q_ℓ(s) L_ℓ(μ) is the pair-count window, the normalised fraction of pairs at separation
//! s and angle μ to the line of sight that the survey keeps; Q0(s → 0) = 1 by convention. Between the
//! tabulated s the Q_ℓ are a not-a-knot cubic spline in ln s, below the first s they keep their first
//! value, beyond the last s they are zero.
//!
//! File layouts (plain text, `#` comments, white space or commas):
//! * `s Q0 Q2 Q4 …` with s in Mpc/h, strictly increasing. A line of names before the data (as a comment
//!   or not) may give the columns in any order: `s` (or `r`) and `Q0`, `Q2`, … (or `Q_0`, `W0`, …).
//!   Without names, the columns after s are Q0, Q2, Q4, … in order.
//! * The BOSS DR12 files as the CLASS-PT BOSS likelihoods read them (lss_montepython, `window.dat`):
//!   columns Q0 Q2 Q4, no s column, one row per point of the log-uniform grid
//!   s_i = 0.01 · (1000/0.01)^{i/(N−1)} Mpc/h, i = 0 … N−1 (N = 128 there), see [`boss_s_grid`].
//!
//! Without a names line, a file is read as having an s column if its first column is positive and
//! strictly increasing (the Q0 of a window never is), as the BOSS layout otherwise.

use super::super::text::parse_table;
use super::super::{check_ells, MAX_ELL};
use crate::error::{Error, Result};
use crate::linear::spline::LogSpline;
use crate::table::read_text;
use std::path::Path;

/// The smallest s [Mpc/h] of the BOSS DR12 window grid.
pub const BOSS_S_MIN: f64 = 0.01;
/// The largest s [Mpc/h] of the BOSS DR12 window grid.
pub const BOSS_S_MAX: f64 = 1000.0;
/// The fewest s points of a window (for the spline).
const MIN_POINTS: usize = 4;
/// |Q0(0) − 1| above which [`WindowMultipoles::normalisation_warning`] warns.
const NORMALISATION_TOLERANCE: f64 = 1e-3;

/// The s grid [Mpc/h] of an `n`-row BOSS-format window: log-uniform from [`BOSS_S_MIN`] to [`BOSS_S_MAX`].
pub fn boss_s_grid(n: usize) -> Vec<f64> {
    let span = (BOSS_S_MAX / BOSS_S_MIN).ln();
    let last = n.saturating_sub(1).max(1) as f64;
    (0..n)
        .map(|i| BOSS_S_MIN * (span * i as f64 / last).exp())
        .collect()
}

/// The window multipoles Q_ℓ(s) on an s grid [Mpc/h] (module docs).
#[derive(Debug, Clone)]
pub struct WindowMultipoles {
    s: Vec<f64>,
    ells: Vec<usize>,
    q: Vec<Vec<f64>>,
    splines: Vec<LogSpline>,
    origin: String,
}

impl WindowMultipoles {
    /// The window with the columns `q[j]` = Q_ℓ for ℓ = `ells[j]` at the points `s` [Mpc/h].
    ///
    /// # Errors
    /// [`Error::InvalidChoice`] unless `ells` are distinct even multipoles ≤ 8 that include 0;
    /// [`Error::LengthMismatch`] if a column's length differs from that of `s`; [`Error::TooFewPoints`]
    /// for fewer than 4 points; [`Error::InvalidValue`] for an s that is not finite and positive or not
    /// above the previous one, or a Q that is not finite.
    pub fn from_columns(s: Vec<f64>, ells: Vec<usize>, q: Vec<Vec<f64>>) -> Result<Self> {
        let lines: Vec<usize> = (1..=s.len()).collect();
        Self::build(s, ells, q, "window columns".into(), &lines)
    }

    /// Reads a window file (module docs for the layouts).
    ///
    /// # Errors
    /// [`Error::Io`] if the file cannot be read, and those of [`parse`](Self::parse).
    pub fn from_file(path: impl AsRef<Path>) -> Result<Self> {
        let path = path.as_ref();
        Self::parse(&read_text(path)?, &path.display().to_string())
    }

    /// Parses the text of a window file; `origin` names it in messages.
    ///
    /// # Errors
    /// [`Error::Parse`] or [`Error::BadRow`] for a malformed row, [`Error::InvalidChoice`] for column
    /// names that are not `s` and `Q<ℓ>` or a layout that cannot be read, and those of
    /// [`from_columns`](Self::from_columns).
    pub fn parse(text: &str, origin: &str) -> Result<Self> {
        let table = parse_table(text, origin)?;
        let width = table.rows.first().map_or(0, Vec::len);
        if table.rows.is_empty() {
            return Err(Error::TooFewPoints {
                origin: origin.into(),
                found: 0,
                min: MIN_POINTS,
            });
        }
        let invalid = |reason: String| Error::InvalidChoice {
            what: format!("window file `{origin}`"),
            reason,
        };
        // Names: a non-comment names line, or the last comment line made only of column names.
        let names = match &table.names {
            Some(n) => Some(column_names(n).ok_or_else(|| {
                invalid(format!(
                    "the names line {n:?} is not made of `s` and `Q<ell>` names"
                ))
            })?),
            None => table.comments.iter().rev().find_map(|(_, c)| {
                let fields: Vec<String> = c.split_whitespace().map(String::from).collect();
                column_names(&fields)
            }),
        };
        let columns: Vec<Column> = match names {
            Some(n) if n.len() != width => {
                return Err(invalid(format!(
                    "{} column names for rows of {width} columns",
                    n.len()
                )))
            }
            Some(n) => n,
            None => {
                let first: Vec<f64> = table.rows.iter().map(|r| r[0]).collect();
                let has_s = width >= 2
                    && first.iter().all(|&v| v > 0.0)
                    && first.windows(2).all(|w| w[1] > w[0]);
                let n_q = if has_s { width - 1 } else { width };
                if n_q > MAX_ELL / 2 + 1 {
                    return Err(invalid(format!(
                        "{width} columns: at most Q0 … Q8 (5 columns) after an optional s column"
                    )));
                }
                let q = (0..n_q).map(|j| Column::Q(2 * j));
                if has_s {
                    std::iter::once(Column::S).chain(q).collect()
                } else {
                    q.collect()
                }
            }
        };
        let column = |j: usize| table.rows.iter().map(|r| r[j]).collect::<Vec<f64>>();
        let s = match columns.iter().position(|c| *c == Column::S) {
            Some(j) => column(j),
            None => boss_s_grid(table.rows.len()),
        };
        let (mut ells, mut q) = (Vec::new(), Vec::new());
        for (j, c) in columns.iter().enumerate() {
            if let Column::Q(ell) = *c {
                ells.push(ell);
                q.push(column(j));
            }
        }
        Self::build(s, ells, q, origin.into(), &table.lines)
    }

    fn build(
        s: Vec<f64>,
        ells: Vec<usize>,
        q: Vec<Vec<f64>>,
        origin: String,
        lines: &[usize],
    ) -> Result<Self> {
        check_ells("window multipoles", &ells)?;
        if !ells.contains(&0) {
            return Err(Error::InvalidChoice {
                what: format!("window `{origin}` with multipoles {ells:?}"),
                reason: "Q0 is needed".into(),
            });
        }
        if ells.len() != q.len() {
            return Err(Error::LengthMismatch {
                what: "window multipoles and their columns",
                left: ells.len(),
                right: q.len(),
            });
        }
        for column in &q {
            if column.len() != s.len() {
                return Err(Error::LengthMismatch {
                    what: "window s and Q_ell columns",
                    left: s.len(),
                    right: column.len(),
                });
            }
        }
        if s.len() < MIN_POINTS {
            return Err(Error::TooFewPoints {
                origin,
                found: s.len(),
                min: MIN_POINTS,
            });
        }
        let line = |i: usize| lines.get(i).copied().unwrap_or(i + 1);
        for (i, &v) in s.iter().enumerate() {
            let reason = if !(v.is_finite() && v > 0.0) {
                "must be a finite positive number"
            } else if i > 0 && v.ln() <= s[i - 1].ln() {
                "must exceed the previous s (s strictly increasing)"
            } else {
                continue;
            };
            return Err(Error::InvalidValue {
                origin,
                line: line(i),
                name: "s [Mpc/h]",
                value: v,
                reason,
            });
        }
        for column in &q {
            if let Some(i) = column.iter().position(|v| !v.is_finite()) {
                return Err(Error::InvalidValue {
                    origin,
                    line: line(i),
                    name: "Q_ell",
                    value: column[i],
                    reason: "must be finite",
                });
            }
        }
        let ln_s: Vec<f64> = s.iter().map(|v| v.ln()).collect();
        let splines = q
            .iter()
            .map(|c| LogSpline::new(ln_s.clone(), c.clone()))
            .collect();
        Ok(Self {
            s,
            ells,
            q,
            splines,
            origin,
        })
    }

    /// The s grid [Mpc/h].
    pub fn s(&self) -> &[f64] {
        &self.s
    }

    /// The multipoles ℓ of the columns, in their order.
    pub fn ells(&self) -> &[usize] {
        &self.ells
    }

    /// The tabulated Q_ℓ, if ℓ is given.
    pub fn column(&self, ell: usize) -> Option<&[f64]> {
        let j = self.ells.iter().position(|&l| l == ell)?;
        Some(&self.q[j])
    }

    /// Where the window came from (a path or `window columns`).
    pub fn origin(&self) -> &str {
        &self.origin
    }

    /// Q_ℓ(s) at s [Mpc/h]: the spline in ln s between the nodes, the first value below the first s, 0
    /// beyond the last s, and 0 for a multipole that is not given (and for s that is NaN).
    pub fn q(&self, ell: usize, s: f64) -> f64 {
        let Some(j) = self.ells.iter().position(|&l| l == ell) else {
            return 0.0;
        };
        let last = self.s.len() - 1;
        if s.is_nan() || s > self.s[last] {
            0.0
        } else if s <= self.s[0] {
            self.q[j][0]
        } else {
            self.splines[j].eval(s.ln())
        }
    }

    /// Q0(s → 0), the value at the first s: 1 for a normalised window.
    pub fn normalisation(&self) -> f64 {
        self.q(0, 0.0)
    }

    /// A message if Q0(0) differs from 1 by more than 1e-3 (the windowed P_ℓ are then Q0(0) times too
    /// large at high k; [`normalised`](Self::normalised) divides it out), `None` otherwise.
    pub fn normalisation_warning(&self) -> Option<String> {
        let q0 = self.normalisation();
        ((q0 - 1.0).abs() > NORMALISATION_TOLERANCE).then(|| {
            format!(
                "window `{}`: Q0 at the smallest s ({} Mpc/h) is {q0}, not 1: the windowed multipoles \
                 tend to {q0} times the model at high k (divide the Q_ell by Q0(0) to normalise)",
                self.origin, self.s[0]
            )
        })
    }

    /// The window with every Q_ℓ divided by Q0(0), so that Q0(0) = 1.
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] if Q0(0) is zero.
    pub fn normalised(&self) -> Result<Self> {
        let q0 = self.normalisation();
        if q0 == 0.0 {
            return Err(Error::InvalidParameter {
                name: "Q0(0)",
                value: q0,
                reason: "a window with Q0(0) = 0 cannot be normalised",
            });
        }
        let q = self
            .q
            .iter()
            .map(|c| c.iter().map(|v| v / q0).collect())
            .collect();
        let lines: Vec<usize> = (1..=self.s.len()).collect();
        Self::build(
            self.s.clone(),
            self.ells.clone(),
            q,
            self.origin.clone(),
            &lines,
        )
    }
}

/// A column of a window file.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Column {
    S,
    Q(usize),
}

/// The columns named by `fields` (at least 2 names, at most one s), or `None` if they are not names.
fn column_names(fields: &[String]) -> Option<Vec<Column>> {
    if fields.len() < 2 {
        return None;
    }
    let columns: Vec<Column> = fields
        .iter()
        .map(|f| {
            let f = f.to_ascii_lowercase();
            if f == "s" || f == "r" {
                return Some(Column::S);
            }
            let rest = f.strip_prefix('q').or_else(|| f.strip_prefix('w'))?;
            let rest = rest.strip_prefix('_').unwrap_or(rest);
            rest.parse::<usize>().ok().map(Column::Q)
        })
        .collect::<Option<_>>()?;
    (columns.iter().filter(|c| **c == Column::S).count() <= 1).then_some(columns)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn layouts_are_recognised() {
        // An s column, detected from the numbers.
        let text = "# sphere\n1 1 0\n2 0.9 0.01\n4 0.8 0.02\n8 0.5 0.03\n16 0.1 0.02\n";
        let w = WindowMultipoles::parse(text, "t").unwrap();
        assert_eq!(w.s(), &[1.0, 2.0, 4.0, 8.0, 16.0]);
        assert_eq!(w.ells(), &[0, 2]);
        assert_eq!(w.q(2, 4.0), 0.02);
        assert_eq!(w.q(0, 0.5), 1.0);
        assert_eq!(w.q(0, 17.0), 0.0);
        assert_eq!(w.q(4, 4.0), 0.0);
        // BOSS layout: three Q columns, no s.
        let rows: String = (0..8)
            .map(|i| format!("{} {} {}\n", 1.0 - 0.01 * i as f64, -0.001 * i as f64, 0.0))
            .collect();
        let w = WindowMultipoles::parse(&rows, "boss").unwrap();
        assert_eq!(w.ells(), &[0, 2, 4]);
        assert_eq!(w.s(), boss_s_grid(8).as_slice());
        assert!((w.s()[7] - 1000.0).abs() < 1e-9 && (w.s()[0] - 0.01).abs() < 1e-15);
        // Names, in any order, as a comment or a plain line.
        for text in [
            "# Q2 s Q0\n0 1 1\n0.1 2 0.9\n0.2 3 0.8\n0.3 4 0.7\n",
            "q_2 r W0\n0 1 1\n0.1 2 0.9\n0.2 3 0.8\n0.3 4 0.7\n",
        ] {
            let w = WindowMultipoles::parse(text, "named").unwrap();
            assert_eq!(w.ells(), &[2, 0]);
            assert_eq!(w.s(), &[1.0, 2.0, 3.0, 4.0]);
            assert_eq!(w.column(0).unwrap(), &[1.0, 0.9, 0.8, 0.7]);
        }
    }

    #[test]
    fn spline_in_ln_s_is_exact_for_cubics_in_ln_s() {
        let s: Vec<f64> = (0..20).map(|i| 0.5 * 1.3f64.powi(i)).collect();
        let f = |s: f64| 1.0 - 0.1 * s.ln() + 0.01 * s.ln().powi(3);
        let w = WindowMultipoles::from_columns(
            s.clone(),
            vec![0],
            vec![s.iter().map(|&v| f(v)).collect()],
        )
        .unwrap();
        for x in [0.7, 3.3, 50.0, 70.0] {
            assert!((w.q(0, x) - f(x)).abs() < 1e-12, "{x}");
        }
    }

    #[test]
    fn normalisation_is_reported_and_fixed() {
        let s = vec![1.0, 2.0, 3.0, 4.0];
        let w = WindowMultipoles::from_columns(s, vec![0], vec![vec![0.5, 0.4, 0.3, 0.2]]).unwrap();
        assert_eq!(w.normalisation(), 0.5);
        assert!(w.normalisation_warning().unwrap().contains("0.5"));
        let n = w.normalised().unwrap();
        assert_eq!(n.normalisation(), 1.0);
        assert!(n.normalisation_warning().is_none());
        assert!((n.q(0, 4.0) - 0.4).abs() < 1e-15);
    }

    #[test]
    fn bad_windows_are_refused() {
        let s = || vec![1.0, 2.0, 3.0, 4.0];
        let q = || vec![vec![1.0; 4]];
        assert!(WindowMultipoles::from_columns(s(), vec![2], q()).is_err());
        assert!(WindowMultipoles::from_columns(s(), vec![0], vec![vec![1.0; 3]]).is_err());
        let e = WindowMultipoles::from_columns(vec![1.0, 2.0, 2.0, 4.0], vec![0], q()).unwrap_err();
        assert!(matches!(e, Error::InvalidValue { line: 3, .. }), "{e}");
        let e = WindowMultipoles::from_columns(s(), vec![0], vec![vec![1.0, f64::NAN, 1.0, 1.0]]);
        assert!(matches!(e, Err(Error::InvalidValue { line: 2, .. })));
        let e = WindowMultipoles::parse("1 2\n3 4\n", "short").unwrap_err();
        assert!(matches!(e, Error::TooFewPoints { found: 2, .. }), "{e}");
        let e = WindowMultipoles::parse("s Q0 Q3\n1 1 0\n2 1 0\n3 1 0\n4 1 0\n", "odd");
        assert!(matches!(e, Err(Error::InvalidChoice { .. })));
        let e = WindowMultipoles::parse("s Q0 x\n1 1 0\n", "names");
        assert!(matches!(e, Err(Error::InvalidChoice { .. })));
        let five: String = (1..5).map(|i| format!("{i} 1 0 0 0 0\n")).collect();
        let w = WindowMultipoles::parse(&five, "s and five Q").unwrap();
        assert_eq!(w.ells(), &[0, 2, 4, 6, 8]);
        let six: String = (1..5).map(|i| format!("{i} 1 0 0 0 0 0\n")).collect();
        assert!(WindowMultipoles::parse(&six, "s and six Q").is_err());
    }
}
