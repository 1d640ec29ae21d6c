//! Output tables: each column declared once (name, unit, values), written as text by the command line
//! and handed to Python as arrays under the same names; and [`write_atomic`], through which every file
//! is written (whole or not at all).
//!
//! Text format: `#` header lines, then `# column i: name [unit]` for every column, then `# ` and the
//! names, then one row per k with every value as `{:.9e}`, separated by single spaces.
//!
//! ```
//! use pt_spectra::{estimate::Estimate, output::Table};
//! let mut t = Table::new(vec!["an example".into()]);
//! t.push("k", "h/Mpc", vec![0.1, 0.2]);
//! t.push_estimates("P", "(Mpc/h)^3", &[Estimate::new(1.0, 0.01), Estimate::new(2.0, 0.02)]);
//! assert_eq!(t.names(), ["k", "P", "err_P"]);
//! assert!(t.to_text().ends_with("2.000000000e-1 2.000000000e0 2.000000000e-2\n"));
//! assert!(t.checked().is_ok());
//! t.push("bad", "1", vec![1.0, f64::NAN]);
//! assert_eq!(t.checked().unwrap_err().to_string(),
//!            "the result has a non-finite value, bad = NaN at k = 0.2 h/Mpc: not written (a bug or \
//!             an input outside what the model handles; please report it with the command)");
//! ```

mod atomic;
mod written;
pub use atomic::{replace_with, write_atomic, write_atomic_with};
pub use written::WrittenTable;

use crate::error::{number, Error, Result};
use crate::estimate::Estimate;

/// The unit of spectra.
pub const POWER: &str = "(Mpc/h)^3";
/// The unit of wavenumbers.
pub const WAVENUMBER: &str = "h/Mpc";

/// One column: its name, unit and a value per row.
#[derive(Debug, Clone, PartialEq)]
pub struct Column {
    /// The name, e.g. `P22_dd` or `err_P22_dd`.
    pub name: String,
    /// The unit, e.g. `(Mpc/h)^3`, or `1` for a ratio.
    pub unit: &'static str,
    /// The values.
    pub values: Vec<f64>,
    /// `Some(meaning)` if NaN is a documented value of this column (e.g. a 1σ bound that does not
    /// exist); `None` (every column but such) if every value must be finite.
    pub undefined: Option<&'static str>,
}

/// [`MethodNote::method`] of a part integrated directly because the spectrum's projection on the basis
/// tensors was not accurate enough.
pub const FALLBACK_RESIDUAL: &str =
    "direct (fallback: projection residual above the basis's limit)";

/// [`MethodNote::method`] of a part integrated directly under method `auto` because no basis tensors
/// were cached: what `auto` promises (no build), so not called a fallback (no Python warning).
pub const FALLBACK_UNCACHED: &str = "direct (method auto: no basis tensors cached)";

/// How one part of a table was computed: by direct integration or from basis tensors, and why a
/// slower path was taken. The header states the same with its figures; Python's `meta["methods"]`
/// gives these (one record, so the two cannot disagree: both come from the loop terms' sources).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct MethodNote {
    /// The part, e.g. `1-loop terms`, `no-wiggle 2-loop terms`.
    pub part: String,
    /// `direct`, `basis`, or `direct (…)` with the reason for a fallback.
    pub method: String,
}

impl MethodNote {
    /// The note of `part` computed by `method`.
    pub fn new(part: impl Into<String>, method: impl Into<String>) -> Self {
        Self {
            part: part.into(),
            method: method.into(),
        }
    }
}

/// A table: header lines (without the `#`) and columns of equal length.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Table {
    /// Lines saying what was computed, how and from what.
    pub header: Vec<String>,
    /// The columns, in order.
    pub columns: Vec<Column>,
    /// How its parts were computed (empty for tables that integrate nothing by two methods).
    pub methods: Vec<MethodNote>,
}

impl Table {
    /// An empty table with `header` lines.
    pub fn new(header: Vec<String>) -> Self {
        Self {
            header,
            columns: Vec::new(),
            methods: Vec::new(),
        }
    }

    /// Appends a column.
    pub fn push(&mut self, name: impl Into<String>, unit: &'static str, values: Vec<f64>) {
        self.columns.push(Column {
            name: name.into(),
            unit,
            values,
            undefined: None,
        });
    }

    /// Appends a column in which NaN is a documented value meaning `meaning` (said in the header
    /// when it occurs).
    pub fn push_undefined_as(
        &mut self,
        name: impl Into<String>,
        unit: &'static str,
        values: Vec<f64>,
        meaning: &'static str,
    ) {
        let name = name.into();
        if values.iter().any(|v| v.is_nan()) {
            self.header.push(format!("{name} = NaN: {meaning}"));
        }
        self.columns.push(Column {
            name,
            unit,
            values,
            undefined: Some(meaning),
        });
    }

    /// Appends the values of `estimates` as `name` and their errors as `err_<name>`.
    pub fn push_estimates(&mut self, name: &str, unit: &'static str, estimates: &[Estimate]) {
        self.push(name, unit, estimates.iter().map(|e| e.value).collect());
        self.push(
            format!("err_{name}"),
            unit,
            estimates.iter().map(|e| e.error).collect(),
        );
    }

    /// The column names.
    pub fn names(&self) -> Vec<&str> {
        self.columns.iter().map(|c| c.name.as_str()).collect()
    }

    /// The values of the column `name`.
    pub fn column(&self, name: &str) -> Option<&[f64]> {
        self.columns
            .iter()
            .find(|c| c.name == name)
            .map(|c| c.values.as_slice())
    }

    /// The number of rows.
    pub fn rows(&self) -> usize {
        self.columns.first().map_or(0, |c| c.values.len())
    }

    /// The table itself if every value is finite: the check both faces make before they hand a table
    /// out, so that a NaN or an infinity (from a corrupted input, an overflow, a bug) is never
    /// printed as a result. The one exception is a column pushed with
    /// [`push_undefined_as`](Self::push_undefined_as), where NaN has a meaning the header states (a fit's
    /// 1σ bound that does not exist).
    ///
    /// # Errors
    /// [`Error::NonFiniteOutput`] naming the first non-finite value's column and row (by the first
    /// column's name and value, e.g. `k = 0.05`).
    pub fn checked(&self) -> Result<&Self> {
        for c in &self.columns {
            let allowed = |v: &f64| v.is_finite() || (v.is_nan() && c.undefined.is_some());
            if let Some(i) = c.values.iter().position(|v| !allowed(v)) {
                let at = match self.columns.first() {
                    Some(first) if first.values[i].is_finite() => {
                        let unit = if first.unit == "1" { "" } else { first.unit };
                        format!("{} = {} {unit}", first.name, number(&first.values[i]))
                            .trim_end()
                            .to_string()
                    }
                    _ => format!("row {}", i + 1),
                };
                return Err(Error::NonFiniteOutput {
                    column: c.name.clone(),
                    at,
                    value: c.values[i],
                });
            }
        }
        Ok(self)
    }

    /// The table as text (see the module docs).
    pub fn to_text(&self) -> String {
        let n = self.rows();
        let mut out = String::with_capacity(64 * self.columns.len() * (n + 2));
        for line in &self.header {
            out += "# ";
            out += line;
            out.push('\n');
        }
        for (i, c) in self.columns.iter().enumerate() {
            out += &format!("# column {}: {} [{}]\n", i + 1, c.name, c.unit);
        }
        out += "# ";
        out += &self.names().join(" ");
        out.push('\n');
        for i in 0..n {
            let row: Vec<String> = self
                .columns
                .iter()
                .map(|c| format!("{:.9e}", c.values[i]))
                .collect();
            out += &row.join(" ");
            out.push('\n');
        }
        out
    }
}
