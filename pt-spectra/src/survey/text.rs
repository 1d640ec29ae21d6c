//! The plain-text tables of the survey module: `#` comments, an optional line of column names before the
//! data, rows of numbers separated by white space or commas, every row as wide as the first.

use crate::error::{Error, Result};

/// A parsed table.
#[derive(Debug, Clone, Default)]
pub(super) struct TextTable {
    /// The comment lines before the first data row: (1-based line, text after the `#`, trimmed).
    pub comments: Vec<(usize, String)>,
    /// A first non-comment line without any number: its fields.
    pub names: Option<Vec<String>>,
    /// The data rows.
    pub rows: Vec<Vec<f64>>,
    /// The 1-based line of each row.
    pub lines: Vec<usize>,
}

/// Parses `text` (`origin` names it in messages).
///
/// # Errors
/// [`Error::Parse`] for a field that is not a number, [`Error::BadRow`] for a row whose width differs
/// from the first row's.
pub(super) fn parse_table(text: &str, origin: &str) -> Result<TextTable> {
    let mut table = TextTable::default();
    let text = text.strip_prefix('\u{feff}').unwrap_or(text);
    for (i, raw) in text.lines().enumerate() {
        let line = i + 1;
        let (data, comment) = raw.split_once('#').unwrap_or((raw, ""));
        let fields: Vec<&str> = data
            .split(|c: char| c == ',' || c.is_whitespace())
            .filter(|s| !s.is_empty())
            .collect();
        if fields.is_empty() {
            if raw.trim_start().starts_with('#') && table.rows.is_empty() {
                table.comments.push((line, comment.trim().to_string()));
            }
            continue;
        }
        if table.rows.is_empty()
            && table.names.is_none()
            && fields.iter().all(|f| f.parse::<f64>().is_err())
        {
            table.names = Some(fields.iter().map(|s| s.to_string()).collect());
            continue;
        }
        let row = fields
            .iter()
            .enumerate()
            .map(|(column, f)| {
                f.parse::<f64>().map_err(|_| Error::Parse {
                    origin: origin.into(),
                    line,
                    column,
                    field: f.chars().take(40).collect(),
                })
            })
            .collect::<Result<Vec<f64>>>()?;
        if let Some(first) = table.rows.first() {
            if row.len() != first.len() {
                return Err(Error::BadRow {
                    origin: origin.into(),
                    line,
                    problem: format!(
                        "the row has {} columns, the first row (line {}) has {}",
                        row.len(),
                        table.lines[0],
                        first.len()
                    ),
                });
            }
        }
        table.rows.push(row);
        table.lines.push(line);
    }
    Ok(table)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn comments_names_and_rows() {
        let text = "# a comment\n#s Q0\n s Q0 \n1 2\n3,4 # inline\n\n";
        let t = parse_table(text, "t").unwrap();
        assert_eq!(t.comments.len(), 2);
        assert_eq!(t.comments[1], (2, "s Q0".to_string()));
        assert_eq!(t.names, Some(vec!["s".to_string(), "Q0".to_string()]));
        assert_eq!(t.rows, vec![vec![1.0, 2.0], vec![3.0, 4.0]]);
        assert_eq!(t.lines, vec![4, 5]);
    }

    #[test]
    fn bad_rows_are_named() {
        let e = parse_table("1 2\n3 x\n", "f.dat").unwrap_err();
        assert!(
            matches!(
                e,
                Error::Parse {
                    line: 2,
                    column: 1,
                    ..
                }
            ),
            "{e}"
        );
        let e = parse_table("1 2\n3\n", "f.dat").unwrap_err();
        assert!(matches!(e, Error::BadRow { line: 2, .. }), "{e}");
    }
}
