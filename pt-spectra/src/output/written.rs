//! Reading back the tables pt-spectra writes ([`super::Table::to_text`]): the header lines, the names
//! of the `# k …` line and the rows, so that a table can be used by name (`plot`, scripts).

use crate::error::{Error, Result};
use std::path::Path;

/// A table written by pt-spectra, read back.
#[derive(Debug, Clone, PartialEq)]
pub struct WrittenTable {
    /// The file (or description), for messages.
    pub origin: String,
    /// The header lines without `# ` (the first says what was computed).
    pub header: Vec<String>,
    /// The column names.
    pub names: Vec<String>,
    rows: Vec<Vec<f64>>,
}

impl WrittenTable {
    /// Reads a table from `path`.
    ///
    /// # Errors
    /// [`Error::Io`]; as [`Self::parse`].
    pub fn read(path: &Path) -> Result<Self> {
        let text = crate::table::read_text(path)?;
        Self::parse(&text, &path.display().to_string())
    }

    /// Parses a table: the names are on the last `#` line before the first row, which must start with
    /// `# k` (`k`, `k_max`, …) or, for the tables of redshift bins (`fisher`), `# z `.
    ///
    /// # Errors
    /// [`Error::InvalidChoice`] without such a names line, [`Error::BadRow`] for a row that is not
    /// numbers or has another number of values than names, [`Error::TooFewPoints`] without rows.
    pub fn parse(text: &str, origin: &str) -> Result<Self> {
        let header: Vec<String> = text
            .lines()
            .take_while(|l| l.starts_with('#'))
            .map(|l| l.trim_start_matches('#').trim().to_string())
            .collect();
        let names: Vec<String> = header
            .last()
            .filter(|l| l.starts_with('k') || l.starts_with("z "))
            .ok_or_else(|| Error::InvalidChoice {
                what: format!("`{origin}`"),
                reason: "has no `# k …` names line (not a pt-spectra table?)".into(),
            })?
            .split_whitespace()
            .map(str::to_string)
            .collect();
        let mut rows = Vec::new();
        for (i, line) in text
            .lines()
            .enumerate()
            .filter(|(_, l)| !l.starts_with('#') && !l.trim().is_empty())
        {
            let bad = |problem: String| Error::BadRow {
                origin: format!("`{origin}`"),
                line: i + 1,
                problem,
            };
            let row: Vec<f64> = line
                .split_whitespace()
                .map(|v| v.parse::<f64>())
                .collect::<std::result::Result<_, _>>()
                .map_err(|_| bad("not a row of numbers".into()))?;
            if row.len() != names.len() {
                return Err(bad(format!(
                    "{} values for {} columns",
                    row.len(),
                    names.len()
                )));
            }
            rows.push(row);
        }
        if rows.is_empty() {
            return Err(Error::TooFewPoints {
                origin: format!("`{origin}` (data rows)"),
                found: 0,
                min: 1,
            });
        }
        Ok(Self {
            origin: origin.to_string(),
            header,
            names,
            rows,
        })
    }

    /// The first header line (what was computed).
    pub fn title(&self) -> &str {
        self.header.first().map_or("", String::as_str)
    }

    /// The text of the first header line after `key` up to the next `,` (e.g. the model after `rsd: `).
    pub fn after(&self, key: &str) -> Option<String> {
        let t = self.title();
        let at = t.find(key)? + key.len();
        Some(t[at..].split(',').next().unwrap_or("").trim().to_string())
    }

    /// The number after `key` in any header line (e.g. `sigma_v2 = `).
    pub fn header_number(&self, key: &str) -> Option<f64> {
        self.header.iter().find_map(|l| {
            let at = l.find(key)? + key.len();
            let rest = &l[at..];
            let end = rest
                .find(|c: char| c == ',' || c == ';' || c.is_whitespace())
                .unwrap_or(rest.len());
            rest[..end].parse().ok()
        })
    }

    /// The values of the column `name`.
    pub fn column(&self, name: &str) -> Option<Vec<f64>> {
        let j = self.names.iter().position(|n| n == name)?;
        Some(self.rows.iter().map(|r| r[j]).collect())
    }

    /// The values of the column `name`.
    ///
    /// # Errors
    /// [`Error::InvalidChoice`] naming the table's columns.
    pub fn need(&self, name: &str) -> Result<Vec<f64>> {
        self.column(name).ok_or_else(|| Error::InvalidChoice {
            what: format!("`{}`", self.origin),
            reason: format!("has no column `{name}` (it has {})", self.names.join(" ")),
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::output::Table;

    /// A table written by [`Table::to_text`] reads back by name, header numbers included.
    #[test]
    fn a_written_table_reads_back() {
        let mut t = Table::new(vec![
            "pt-spectra 0 rsd: tns, z = 0.5".into(),
            "sigma_v2 = 3.5e1 +- 1".into(),
        ]);
        t.push("k", "h/Mpc", vec![0.1, 0.2]);
        t.push("P0", "(Mpc/h)^3", vec![1e4, 5e3]);
        let w = WrittenTable::parse(&t.to_text(), "t").unwrap();
        assert_eq!(w.names, ["k", "P0"]);
        assert_eq!(w.column("P0").unwrap(), [1e4, 5e3]);
        assert_eq!(w.after("rsd: ").as_deref(), Some("tns"));
        assert_eq!(w.header_number("sigma_v2 = "), Some(35.0));
        assert!(w
            .need("P2")
            .unwrap_err()
            .to_string()
            .contains("has no column `P2` (it has k P0)"));
        assert!(WrittenTable::parse("1 2\n", "x").is_err());
        assert!(WrittenTable::parse("# k P0\n0.1 x\n", "x")
            .unwrap_err()
            .to_string()
            .contains("not a row of numbers"));
    }
}
