//! [`WindowMultipoles`]: the configuration-space window multipoles Q_ℓ(s) of a survey, read from a file.
//!
//! Q(s, μ) = Σ_ℓ Q_ℓ(s) L_ℓ(μ) is the pair-count window, the normalised fraction of pairs at separation
//! s and angle μ to the line of sight that the survey keeps; Q0(s → 0) = 1 by convention. Between the
//! tabulated s the Q_ℓ are a not-a-knot cubic spline in ln s, below the first s they keep their first
//! value, beyond the last s they are zero.
//!
//! File layout (plain text, `#` comments, white space or commas): declared, never guessed from the
//! numbers ([`WindowFormat`]): columns `s Q0 Q2 Q4 …` in any order named on a line before the data (or
//! by the caller), s in Mpc/h, strictly increasing; or the BOSS DR12 files as the CLASS-PT BOSS
//! likelihoods read them (lss_montepython, `window.dat`): columns Q0 Q2 Q4, no s column, one row per
//! point of the log-uniform grid s_i = 0.01 · (1000/0.01)^{i/(N−1)} Mpc/h, i = 0 … N−1 (N = 128
//! there), see [`boss_s_grid`], declared with [`WindowFormat::boss`].

use super::super::check_ells;
use super::super::text::parse_table;
use super::format::{check_has_s, column_names, Column, Layout, WindowFormat, WINDOW_FORMAT_HELP};
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

    /// Reads a window file laid out as `format` declares (module docs).
    ///
    /// # Errors
    /// [`Error::Io`] if the file cannot be read, and those of [`parse`](Self::parse).
    pub fn from_file(path: impl AsRef<Path>, format: &WindowFormat) -> Result<Self> {
        let path = path.as_ref();
        Self::parse(&read_text(path)?, &path.display().to_string(), format)
    }

    /// Parses the text of a window file laid out as `format` declares; `origin` names it in messages.
    ///
    /// # Errors
    /// [`Error::Parse`] or [`Error::BadRow`] for a malformed row or a row count the BOSS layout does not
    /// have, [`Error::InvalidChoice`] for a file that does not declare its columns (with the default
    /// [`WindowFormat::header`]), column names that are not `s` and `Q<ℓ>`, names that disagree with
    /// `format` or with the width of the rows, and those of [`from_columns`](Self::from_columns).
    pub fn parse(text: &str, origin: &str, format: &WindowFormat) -> Result<Self> {
        let table = parse_table(text, origin)?;
        let Some(&first_line) = table.lines.first() else {
            return Err(Error::TooFewPoints {
                origin: origin.into(),
                found: 0,
                min: MIN_POINTS,
            });
        };
        let width = table.rows[0].len();
        let invalid = |reason: String| Error::InvalidChoice {
            what: format!("window file `{origin}`"),
            reason,
        };
        // Names in the file: a non-comment names line, or the last comment line made only of names.
        let named = match &table.names {
            Some(n) => Some(column_names(n).ok_or_else(|| {
                invalid(format!(
                    "the names line {n:?} is not made of `s` and `Q<ell>` names"
                ))
            })?),
            None => table.comments.iter().rev().find_map(|(_, c)| {
                let fields: Vec<&str> = c
                    .split(|c: char| c == ',' || c.is_whitespace())
                    .filter(|f| !f.is_empty())
                    .collect();
                column_names(&fields)
            }),
        };
        let boss_names = [Column::Q(0), Column::Q(2), Column::Q(4)];
        let columns: Vec<Column> = match (&format.0, named) {
            (Layout::Header, None) => {
                return Err(invalid(format!(
                    "no names line declares its columns (they are not guessed from the \
                     numbers): add a line such as `# s Q0 Q2 Q4` before the data, or give the \
                     layout (`--window-format`, Python `window_format`): {WINDOW_FORMAT_HELP}"
                )))
            }
            (Layout::Header, Some(n)) => {
                check_has_s(&n).map_err(|r| invalid(format!("its names line: {r}")))?;
                n
            }
            (Layout::Columns(c), Some(n)) if *c != n => {
                return Err(invalid(format!(
                    "its names line ({}) disagrees with the format given ({format})",
                    WindowFormat(Layout::Columns(n))
                )))
            }
            (Layout::Columns(c), _) => c.clone(),
            (Layout::Boss(_), Some(n)) if n != boss_names => {
                return Err(invalid(format!(
                    "its names line ({}) disagrees with the format given ({format}: Q0 Q2 Q4 \
                     without s)",
                    WindowFormat(Layout::Columns(n))
                )))
            }
            (Layout::Boss(rows), _) => {
                if table.rows.len() != *rows {
                    return Err(Error::BadRow {
                        origin: origin.into(),
                        line: table.lines.last().copied().unwrap_or(first_line),
                        problem: format!(
                            "{} rows, but the layout {format} has exactly {rows} (one per point \
                             of its s grid: a row missing or repeated would shift every s)",
                            table.rows.len()
                        ),
                    });
                }
                boss_names.to_vec()
            }
        };
        if columns.len() != width {
            return Err(Error::BadRow {
                origin: origin.into(),
                line: first_line,
                problem: format!(
                    "the row has {width} columns, the declared layout ({}) has {}",
                    WindowFormat(Layout::Columns(columns.clone())),
                    columns.len()
                ),
            });
        }
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
        // The multipoles must be 0, 2, …, ℓ_max without a gap: a names line with a wrong ℓ (`Q6` for
        // `Q4`) would otherwise leave Q4 out of the mixing, silently.
        let top = ells.iter().copied().max().unwrap_or(0);
        if let Some(gap) = (0..=top).step_by(2).find(|l| !ells.contains(l)) {
            return Err(Error::InvalidChoice {
                what: format!("window `{origin}` with multipoles {ells:?}"),
                reason: format!(
                    "Q{gap} is missing below Q{top}: the multipoles must be 0, 2, …, ℓ_max \
                     without a gap (a wrong ℓ in the names line or --window-format?)"
                ),
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
        // Q0 → 1 as s → 0 for a normalised window (a pair count's monopole, positive for any
        // normalisation): Q0(0) ≤ 0 is a sign flip or another column, and flipped every windowed
        // multipole with exit 0 (issue 45). (Q0(0) ≠ 1 but positive is warned about.)
        let q0 = &q[ells.iter().position(|&l| l == 0).expect("checked")];
        if q0[0] <= 0.0 {
            return Err(Error::InvalidValue {
                origin,
                line: line(0),
                name: "Q0 at the smallest s",
                value: q0[0],
                reason:
                    "must be positive: Q0 tends to 1 as s -> 0 for a normalised window (a sign \
                         flip, or another quantity in the Q0 column?)",
            });
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

#[cfg(test)]
mod tests {
    use super::*;

    fn header() -> WindowFormat {
        WindowFormat::header()
    }

    #[test]
    fn layouts_are_declared_not_guessed() {
        // An s column declared by a names line, or by the caller.
        let rows = "1 1 0\n2 0.9 0.01\n4 0.8 0.02\n8 0.5 0.03\n16 0.1 0.02\n";
        let given = WindowFormat::parse("s,Q0,Q2").unwrap();
        for (text, format) in [
            (format!("# sphere\n# s Q0 Q2\n{rows}"), header()),
            (format!("# s, Q0, Q2\n{rows}"), header()),
            (format!("# sphere\n{rows}"), given.clone()),
            (format!("s Q0 Q2\n{rows}"), given),
        ] {
            let w = WindowMultipoles::parse(&text, "t", &format).unwrap();
            assert_eq!(w.s(), &[1.0, 2.0, 4.0, 8.0, 16.0]);
            assert_eq!(w.ells(), &[0, 2]);
            assert_eq!(w.q(2, 4.0), 0.02);
            assert_eq!(w.q(0, 0.5), 1.0);
            assert_eq!(w.q(0, 17.0), 0.0);
            assert_eq!(w.q(4, 4.0), 0.0);
        }
        // Nothing declared: refused, with how to declare it (the numbers are not looked at).
        let e = WindowMultipoles::parse(&format!("# sphere\n{rows}"), "w.dat", &header());
        let e = e.unwrap_err().to_string();
        assert!(
            e.contains("w.dat") && e.contains("# s Q0 Q2 Q4") && e.contains("--window-format"),
            "{e}"
        );
        // BOSS layout: three Q columns, no s, declared with its row count.
        let rows: String = (0..8)
            .map(|i| format!("{} {} {}\n", 1.0 - 0.01 * i as f64, -0.001 * i as f64, 0.0))
            .collect();
        let w = WindowMultipoles::parse(&rows, "boss", &WindowFormat::boss(8).unwrap()).unwrap();
        assert_eq!(w.ells(), &[0, 2, 4]);
        assert_eq!(w.s(), boss_s_grid(8).as_slice());
        assert!((w.s()[7] - 1000.0).abs() < 1e-9 && (w.s()[0] - 0.01).abs() < 1e-15);
        let e = WindowMultipoles::parse(&rows, "boss", &WindowFormat::boss(9).unwrap());
        assert!(matches!(e, Err(Error::BadRow { line: 8, .. })), "{e:?}");
        let e = WindowMultipoles::parse(&rows, "boss", &header()).unwrap_err();
        assert!(e.to_string().contains("no names line"), "{e}");
        let e = WindowMultipoles::parse(&format!("# Q0 Q2 Q4\n{rows}"), "b", &header());
        assert!(e.unwrap_err().to_string().contains("no s column"));
        // Names, in any order, as a comment or a plain line.
        for text in [
            "# Q2 s Q0\n0 1 1\n0.1 2 0.9\n0.2 3 0.8\n0.3 4 0.7\n",
            "q_2 r W0\n0 1 1\n0.1 2 0.9\n0.2 3 0.8\n0.3 4 0.7\n",
        ] {
            let w = WindowMultipoles::parse(text, "named", &header()).unwrap();
            assert_eq!(w.ells(), &[2, 0]);
            assert_eq!(w.s(), &[1.0, 2.0, 3.0, 4.0]);
            assert_eq!(w.column(0).unwrap(), &[1.0, 0.9, 0.8, 0.7]);
        }
        // A names line that disagrees with the format given, or with the rows' width.
        let text = "# s Q0 Q2\n1 1 0\n2 1 0\n3 1 0\n4 1 0\n";
        let other = WindowFormat::parse("s,Q0,Q4").unwrap();
        let e = WindowMultipoles::parse(text, "n", &other)
            .unwrap_err()
            .to_string();
        assert!(e.contains("disagrees"), "{e}");
        let e = WindowMultipoles::parse(text, "n", &WindowFormat::boss(4).unwrap());
        assert!(e.unwrap_err().to_string().contains("disagrees"));
        let e =
            WindowMultipoles::parse("# s Q0 Q2 Q4\n1 1 0\n2 1 0\n3 1 0\n4 1 0\n", "n", &header());
        assert!(matches!(e, Err(Error::BadRow { line: 2, .. })), "{e:?}");
        // A names line with a wrong ℓ (Q6 for Q4): refused naming the file and the missing Q4.
        let e = WindowMultipoles::parse("# s Q0 Q2 Q6\n1 1 0 0\n2 1 0 0\n", "w.dat", &header());
        let e = e.unwrap_err().to_string();
        assert!(
            e.contains("w.dat") && e.contains("Q4 is missing below Q6"),
            "{e}"
        );
    }

    /// The case: a duplicated row (the s column is then not increasing) is refused naming the
    /// line, whatever the layout declared, never read as another layout.
    #[test]
    fn a_duplicated_or_swapped_row_is_refused_with_its_line() {
        let mut rows: Vec<String> = (1..=6)
            .map(|i| format!("{i} {} 0", 1.0 / i as f64))
            .collect();
        let dup = {
            let mut r = rows.clone();
            r.insert(3, r[2].clone());
            r
        };
        rows.swap(2, 3);
        for (what, r) in [("duplicated", dup), ("swapped", rows)] {
            for (text, format) in [
                (format!("# s Q0 Q2\n{}\n", r.join("\n")), header()),
                (
                    format!("{}\n", r.join("\n")),
                    WindowFormat::parse("s,Q0,Q2").unwrap(),
                ),
            ] {
                let e = WindowMultipoles::parse(&text, "w.dat", &format).unwrap_err();
                let line = if format.is_header() { 5 } else { 4 };
                assert!(
                    matches!(e, Error::InvalidValue { line: l, .. } if l == line),
                    "{what}: {e}"
                );
                assert!(e.to_string().contains("strictly increasing"), "{e}");
            }
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
        let e = WindowMultipoles::parse("s Q0\n1 2\n3 4\n", "short", &header()).unwrap_err();
        assert!(matches!(e, Error::TooFewPoints { found: 2, .. }), "{e}");
        let e = WindowMultipoles::parse("s Q0 Q3\n1 1 0\n2 1 0\n3 1 0\n4 1 0\n", "odd", &header());
        assert!(matches!(e, Err(Error::InvalidChoice { .. })));
        let e = WindowMultipoles::parse("s Q0 x\n1 1 0\n", "names", &header());
        assert!(matches!(e, Err(Error::InvalidChoice { .. })));
        let five: String = (1..5).map(|i| format!("{i} 1 0 0 0 0\n")).collect();
        let five = format!("s Q0 Q2 Q4 Q6 Q8\n{five}");
        let w = WindowMultipoles::parse(&five, "s and five Q", &header()).unwrap();
        assert_eq!(w.ells(), &[0, 2, 4, 6, 8]);
        let six: String = (1..5).map(|i| format!("{i} 1 0 0 0 0 0\n")).collect();
        let six = format!("s Q0 Q2 Q4 Q6 Q8 Q10\n{six}");
        assert!(WindowMultipoles::parse(&six, "s and six Q", &header()).is_err());
    }
}
