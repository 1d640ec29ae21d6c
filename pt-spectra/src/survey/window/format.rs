//! [`WindowFormat`]: how the columns of a Q_ℓ(s) window file are declared. There is one declared layout
//! per file, never one guessed from the numbers: a wrong guess (a duplicated row makes the s column
//! non-increasing, and a guesser then reads it as Q0) multiplies the windowed P0 by ~150 with exit 0.
//!
//! * [`WindowFormat::header`] (the default): the file declares its columns on a names line before the
//!   data, as a comment or not: `s Q0 Q2 Q4` (any order; `s` or `r`, `Q<ℓ>`, `Q_<ℓ>` or `W<ℓ>`; blanks
//!   or commas between them). A file without one is refused with a message that says how to declare it.
//! * [`WindowFormat::columns`]: the caller names the columns, e.g. `s,Q0,Q2,Q4` (CLI `--window-format`);
//!   a names line in the file must then agree with it.
//! * [`WindowFormat::boss`]: the CLASS-PT BOSS DR12 layout, columns Q0 Q2 Q4 without s on the log-uniform
//!   grid s_i = 0.01 · (1000/0.01)^{i/(N−1)} Mpc/h of exactly N rows (`boss` is N = 128, as in the
//!   CLASS-PT files; `boss:N` another N): the row count is the only check of the s it implies, so it is
//!   declared too. A swapped pair of rows cannot be detected in this layout (it has no s column).

use crate::error::{Error, Result};

/// The rows of the CLASS-PT BOSS DR12 window files (`window.dat` of lss_montepython).
pub const BOSS_ROWS: usize = 128;

/// A column of a window file.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum Column {
    /// s [Mpc/h].
    S,
    /// Q_ℓ.
    Q(usize),
}

/// How the columns of a window file are declared (module docs).
#[derive(Debug, Clone, PartialEq, Eq, Default)]
pub struct WindowFormat(pub(super) Layout);

#[derive(Debug, Clone, PartialEq, Eq, Default)]
pub(super) enum Layout {
    /// A names line in the file.
    #[default]
    Header,
    /// Columns named by the caller (one of them s).
    Columns(Vec<Column>),
    /// Q0 Q2 Q4 on the BOSS grid of this many rows.
    Boss(usize),
}

/// What `--window-format` (and Python's `window_format`) accepts, for messages.
pub const WINDOW_FORMAT_HELP: &str = "`s,Q0,Q2,Q4` (the columns in file order: s [Mpc/h] and Q<ell>), \
     `boss` (the CLASS-PT BOSS DR12 layout: Q0 Q2 Q4 without s on 128 log-uniform s from 0.01 to 1000 \
     Mpc/h; `boss:N` for N rows), or `header` (a names line such as `# s Q0 Q2 Q4` in the file, the \
     default)";

impl WindowFormat {
    /// The columns are named on a line of the file (the default).
    pub fn header() -> Self {
        Self(Layout::Header)
    }

    /// The CLASS-PT BOSS layout of `rows` rows (Q0 Q2 Q4, no s: module docs).
    ///
    /// # Errors
    /// [`Error::InvalidChoice`] for fewer than 4 rows.
    pub fn boss(rows: usize) -> Result<Self> {
        if rows < 4 {
            return Err(Error::InvalidChoice {
                what: format!("window format boss:{rows}"),
                reason: "a window needs at least 4 rows".into(),
            });
        }
        Ok(Self(Layout::Boss(rows)))
    }

    /// The columns in file order from their names, e.g. `["s", "Q0", "Q2", "Q4"]`.
    ///
    /// # Errors
    /// [`Error::InvalidChoice`] for a name that is not `s`/`r` or `Q<ℓ>`, no or two s columns.
    pub fn columns<S: AsRef<str>>(names: &[S]) -> Result<Self> {
        let what = || {
            let names: Vec<&str> = names.iter().map(AsRef::as_ref).collect();
            format!("window format `{}`", names.join(","))
        };
        let columns = column_names(names).ok_or_else(|| Error::InvalidChoice {
            what: what(),
            reason: format!("expected {WINDOW_FORMAT_HELP}"),
        })?;
        check_has_s(&columns).map_err(|reason| Error::InvalidChoice {
            what: what(),
            reason,
        })?;
        Ok(Self(Layout::Columns(columns)))
    }

    /// The format a user wrote: `header`, `boss`, `boss:N` or column names separated by commas or
    /// blanks (`s,Q0,Q2,Q4`).
    ///
    /// # Errors
    /// [`Error::InvalidChoice`] naming [`WINDOW_FORMAT_HELP`].
    pub fn parse(text: &str) -> Result<Self> {
        let t = text.trim();
        let lower = t.to_ascii_lowercase();
        if lower == "header" {
            return Ok(Self::header());
        }
        if lower == "boss" {
            return Self::boss(BOSS_ROWS);
        }
        if let Some(n) = lower.strip_prefix("boss:") {
            let rows = n
                .trim()
                .parse::<usize>()
                .map_err(|_| Error::InvalidChoice {
                    what: format!("window format `{t}`"),
                    reason: format!(
                        "`boss:N` needs a whole number of rows; expected {WINDOW_FORMAT_HELP}"
                    ),
                })?;
            return Self::boss(rows);
        }
        let names: Vec<&str> = t
            .split(|c: char| c == ',' || c.is_whitespace())
            .filter(|s| !s.is_empty())
            .collect();
        Self::columns(&names)
    }

    /// Whether the file must declare its columns itself.
    pub fn is_header(&self) -> bool {
        self.0 == Layout::Header
    }
}

impl std::fmt::Display for WindowFormat {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match &self.0 {
            Layout::Header => write!(f, "header"),
            Layout::Boss(n) => write!(f, "boss:{n}"),
            Layout::Columns(c) => {
                let names: Vec<String> = c
                    .iter()
                    .map(|c| match c {
                        Column::S => "s".to_string(),
                        Column::Q(l) => format!("Q{l}"),
                    })
                    .collect();
                write!(f, "{}", names.join(","))
            }
        }
    }
}

/// `Err(reason)` unless exactly one of `columns` is s.
pub(super) fn check_has_s(columns: &[Column]) -> std::result::Result<(), String> {
    match columns.iter().filter(|c| **c == Column::S).count() {
        1 => Ok(()),
        0 => Err(
            "no s column: name it (`s Q0 Q2 Q4`), or declare the CLASS-PT BOSS layout \
                  without s with the format `boss`"
                .into(),
        ),
        _ => Err("two s columns".into()),
    }
}

/// The columns named by `fields` (at least 2 names), or `None` if they are not all column names.
pub(super) fn column_names<S: AsRef<str>>(fields: &[S]) -> Option<Vec<Column>> {
    if fields.len() < 2 {
        return None;
    }
    fields
        .iter()
        .map(|f| {
            let f = f.as_ref().to_ascii_lowercase();
            if f == "s" || f == "r" {
                return Some(Column::S);
            }
            let rest = f.strip_prefix('q').or_else(|| f.strip_prefix('w'))?;
            let rest = rest.strip_prefix('_').unwrap_or(rest);
            rest.parse::<usize>().ok().map(Column::Q)
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn formats_are_parsed_and_refused_with_the_choices() {
        assert_eq!(
            WindowFormat::parse("header").unwrap(),
            WindowFormat::header()
        );
        assert_eq!(WindowFormat::parse("BOSS").unwrap().0, Layout::Boss(128));
        assert_eq!(
            WindowFormat::parse("boss:1000").unwrap().0,
            Layout::Boss(1000)
        );
        let f = WindowFormat::parse("s,Q0,Q_2 W4").unwrap();
        assert_eq!(
            f.0,
            Layout::Columns(vec![Column::S, Column::Q(0), Column::Q(2), Column::Q(4)])
        );
        assert_eq!(f.to_string(), "s,Q0,Q2,Q4");
        for bad in ["Q0,Q2,Q4", "s,s,Q0", "s,x", "boss:2", "boss:many", "", "s"] {
            let e = WindowFormat::parse(bad).unwrap_err().to_string();
            assert!(e.contains("window format"), "{bad}: {e}");
        }
        let e = WindowFormat::parse("Q0 Q2 Q4").unwrap_err().to_string();
        assert!(e.contains("no s column") && e.contains("boss"), "{e}");
    }
}
