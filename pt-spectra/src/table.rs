//! Plain-text tables: column selection with line-numbered errors, and functions of k tabulated in files
//! (scale-dependent bias, noise spectra), interpolated in ln k without extrapolation.
//!
//! Format (as for linear spectra): lines starting with `#` (after optional blanks) are header lines;
//! text after a `#` on a data line is ignored; blank lines are skipped; fields are separated by commas
//! and/or whitespace; a single row of column names with no number in it before the first data row is
//! taken as a header line; every data row has as many fields as the first. Lines end with `\n`, `\r\n` or a lone `\r`; a leading byte-order mark is
//! ignored.

use crate::error::{Error, Result};
use std::path::Path;

/// The text of the file at `path`. Bytes that are not UTF-8 (a Latin-1 `µ` in a comment, a binary file)
/// become U+FFFD, so that a table reports the line they are on rather than refusing the whole file.
///
/// # Errors
/// [`Error::Io`] naming the file.
pub(crate) fn read_text(path: &Path) -> Result<String> {
    let bytes = std::fs::read(path).map_err(|source| Error::Io {
        path: path.to_path_buf(),
        source,
    })?;
    Ok(match String::from_utf8(bytes) {
        Ok(text) => text,
        Err(e) => String::from_utf8_lossy(e.as_bytes()).into_owned(),
    })
}

/// The lines of `text` numbered from 1, without their ends: `\n`, `\r\n` and a lone `\r` (classic Mac
/// OS) each end a line, as a text editor counts them; a leading UTF-8 byte-order mark is dropped.
fn numbered_lines(text: &str) -> impl Iterator<Item = (usize, &str)> {
    let mut rest = Some(text.strip_prefix('\u{feff}').unwrap_or(text));
    let lines = std::iter::from_fn(move || {
        let s = rest?;
        match s.find(['\n', '\r']) {
            None => {
                rest = None;
                (!s.is_empty()).then_some(s)
            }
            Some(i) => {
                let end = if s[i..].starts_with("\r\n") { 2 } else { 1 };
                rest = Some(&s[i + end..]);
                Some(&s[..i])
            }
        }
    });
    (1..).zip(lines)
}

/// A field as shown in a message: control characters escaped, at most 40 characters (then `…`), so that
/// a binary or one-line file gives a short readable message.
fn shown(field: &str) -> String {
    const MAX: usize = 40;
    let mut out: String = field
        .chars()
        .take(MAX)
        .map(|c| {
            if c.is_control() || c == '\u{feff}' {
                c.escape_debug().to_string()
            } else {
                c.to_string()
            }
        })
        .collect();
    if field.chars().nth(MAX).is_some() {
        out.push('…');
    }
    out
}

/// What a row of k needs beyond k > previous k: ln k must increase too, or the interpolation in ln k
/// divides by zero (two k a few units in the last place apart).
pub(crate) const K_TOO_CLOSE: &str =
    "too close to the previous k: ln k does not increase (remove one of the two rows)";

/// The selected columns of a table's data rows.
#[derive(Debug, Clone, PartialEq)]
pub struct DataColumns {
    /// File path or description, for messages.
    pub origin: String,
    /// Header lines (without the `#`).
    pub header: Vec<String>,
    /// 1-based line number of each data row.
    pub lines: Vec<usize>,
    /// `columns[j][i]`: the value of the j-th requested column on data row i.
    pub columns: Vec<Vec<f64>>,
}

impl DataColumns {
    /// Reads the 0-based `columns` of the file at `path`.
    ///
    /// # Errors
    /// [`Error::Io`], and as [`parse`](Self::parse).
    pub fn read(path: impl AsRef<Path>, columns: &[usize]) -> Result<Self> {
        let path = path.as_ref();
        Self::parse(&read_text(path)?, &path.display().to_string(), columns)
    }

    /// Parses the 0-based `columns` of `text`; `origin` names it in messages. Values may be any f64
    /// (NaN and infinities included: callers check what they need, e.g. with [`Tabulated::new`]).
    ///
    /// # Errors
    /// [`Error::Parse`] for a field that is not a number, [`Error::MissingColumn`] for a short row,
    /// [`Error::BadRow`] for a row whose width differs from the first row's.
    pub fn parse(text: &str, origin: &str, columns: &[usize]) -> Result<Self> {
        Self::parse_rows(text, origin, columns, None)
    }

    /// Parses a table whose every data row has exactly `width` columns (e.g. a matrix), all kept.
    ///
    /// # Errors
    /// As [`parse`](Self::parse), and [`Error::BadRow`] for a row with more than `width` columns.
    pub fn parse_exact(text: &str, origin: &str, width: usize) -> Result<Self> {
        Self::parse_rows(text, origin, &(0..width).collect::<Vec<_>>(), Some(width))
    }

    fn parse_rows(
        text: &str,
        origin: &str,
        columns: &[usize],
        width: Option<usize>,
    ) -> Result<Self> {
        let need = columns.iter().max().map_or(0, |c| c.saturating_add(1));
        let mut table = Self {
            origin: origin.to_string(),
            header: Vec::new(),
            lines: Vec::new(),
            columns: vec![Vec::new(); columns.len()],
        };
        let mut named_columns = false;
        let mut first_width: Option<(usize, usize)> = None;
        for (line, raw) in numbered_lines(text) {
            let (data, comment) = raw.split_once('#').unwrap_or((raw, ""));
            let fields: Vec<&str> = data
                .split(|c: char| c == ',' || c.is_whitespace())
                .filter(|s| !s.is_empty())
                .collect();
            if fields.is_empty() {
                if data.trim().is_empty() && raw.trim_start().starts_with('#') {
                    table.header.push(comment.trim().to_string());
                }
                continue;
            }
            // One row of column names (no number in it) may precede the data; a second such row is
            // reported as a parse error on its line.
            if table.lines.is_empty()
                && !named_columns
                && fields.iter().all(|f| f.parse::<f64>().is_err())
            {
                named_columns = true;
                table.header.push(data.trim().to_string());
                continue;
            }
            if fields.len() < need {
                let column = columns
                    .iter()
                    .copied()
                    .find(|&c| c >= fields.len())
                    .unwrap_or(need - 1);
                return Err(Error::MissingColumn {
                    origin: origin.into(),
                    line,
                    column,
                    found: fields.len(),
                });
            }
            if let Some(width) = width.filter(|&w| fields.len() > w) {
                return Err(Error::BadRow {
                    origin: origin.into(),
                    line,
                    problem: format!("the row has {} columns, {width} expected", fields.len()),
                });
            }
            // Every row as wide as the first: a field dropped or added in one row would shift the
            // columns after it, and the columns asked for would take their neighbours' values.
            match first_width {
                None => first_width = Some((fields.len(), line)),
                Some((w, first)) if fields.len() != w => {
                    return Err(Error::BadRow {
                        origin: origin.into(),
                        line,
                        problem: format!(
                            "the row has {} columns, the first row (line {first}) has {w}: every row \
                             must have as many (a field dropped or added shifts the columns after it)",
                            fields.len()
                        ),
                    });
                }
                Some(_) => {}
            }
            for (values, &c) in table.columns.iter_mut().zip(columns) {
                let field = fields[c];
                values.push(field.parse::<f64>().map_err(|_| Error::Parse {
                    origin: origin.into(),
                    line,
                    column: c,
                    field: shown(field),
                })?);
            }
            table.lines.push(line);
        }
        Ok(table)
    }
}

/// The 0-based index of the column `name` on the last `# k …` names line of `text` before its first
/// data row, if there is such a line and it has that name (not as its first column).
pub fn named_column(text: &str, name: &str) -> Option<usize> {
    let mut found = None;
    for line in text.lines() {
        let t = line.trim_start();
        let Some(rest) = t.strip_prefix('#') else {
            if !t.is_empty() {
                break;
            }
            continue;
        };
        let names: Vec<&str> = rest.split_whitespace().collect();
        if names.first() == Some(&"k") {
            found = names.iter().skip(1).position(|&n| n == name).map(|j| j + 1);
        }
    }
    found
}

/// A function of k [h/Mpc] given at strictly increasing k and interpolated linearly in ln k. It is not
/// extrapolated: asking outside its range is an error.
#[derive(Debug, Clone, PartialEq)]
pub struct Tabulated {
    name: &'static str,
    origin: String,
    k: Vec<f64>,
    values: Vec<f64>,
}

impl Tabulated {
    /// Where the table came from (a file path or a description).
    pub fn origin(&self) -> &str {
        &self.origin
    }

    /// The function `name` (e.g. `b(k)`), checked: at least 2 rows, k finite, positive and strictly
    /// increasing (in ln k too), values finite and, if `positive`, > 0. `lines` gives each row's line
    /// number for messages (row numbers if empty).
    ///
    /// # Errors
    /// [`Error::TooFewPoints`], [`Error::InvalidK`], [`Error::NonIncreasingK`], [`Error::InvalidValue`]
    /// (also for a k so close to the previous one that ln k does not increase).
    pub fn new(
        name: &'static str,
        origin: &str,
        k: Vec<f64>,
        values: Vec<f64>,
        positive: bool,
        lines: &[usize],
    ) -> Result<Self> {
        if k.len() != values.len() {
            return Err(Error::LengthMismatch {
                what: "k and values",
                left: k.len(),
                right: values.len(),
            });
        }
        if k.len() < 2 {
            return Err(Error::TooFewPoints {
                origin: origin.into(),
                found: k.len(),
                min: 2,
            });
        }
        check_k_grid(origin, &k, lines)?;
        let line = |i: usize| lines.get(i).copied().unwrap_or(i + 1);
        for i in 0..k.len() {
            if i > 0 && k[i].ln() <= k[i - 1].ln() {
                return Err(Error::InvalidValue {
                    origin: origin.into(),
                    line: line(i),
                    name: "k [h/Mpc]",
                    value: k[i],
                    reason: K_TOO_CLOSE,
                });
            }
            if !(values[i].is_finite() && (!positive || values[i] > 0.0)) {
                return Err(Error::InvalidValue {
                    origin: origin.into(),
                    line: line(i),
                    name,
                    value: values[i],
                    reason: if positive {
                        "must be finite and positive"
                    } else {
                        "must be finite"
                    },
                });
            }
        }
        Ok(Self {
            name,
            origin: origin.to_string(),
            k,
            values,
        })
    }

    /// Reads `name` from columns (k, value) of a file (0-based).
    ///
    /// # Errors
    /// As [`DataColumns::read`] and [`new`](Self::new).
    pub fn read(
        path: impl AsRef<Path>,
        name: &'static str,
        (k_column, value_column): (usize, usize),
        positive: bool,
    ) -> Result<Self> {
        let table = DataColumns::read(path, &[k_column, value_column])?;
        let [k, v]: [Vec<f64>; 2] = table.columns.try_into().expect("two columns");
        Self::new(name, &table.origin, k, v, positive, &table.lines)
    }

    /// Reads `name` from a file whose first column is k and whose value column is the one named
    /// `column` on a `# k …` names line (as every table of pt-spectra has: `halo` output feeds
    /// `--bias-file` by its column `b` and `--noise-file` by `P_eps`), else the second column of a file
    /// of exactly two columns. A wider file without `column` on such a line is refused: its value
    /// column is not guessed.
    ///
    /// ```
    /// use pt_spectra::table::Tabulated;
    /// let path = std::env::temp_dir().join(format!("pt-named-{}.dat", std::process::id()));
    /// std::fs::write(&path, "# column 1: k [h/Mpc]\n# k b P_eps\n0.01 2.5 3e4\n0.1 2.6 2.9e4\n")?;
    /// let noise = Tabulated::read_column(&path, "P_eps(k)", "P_eps", true)?;
    /// assert_eq!(noise.eval(0.1)?, 2.9e4);
    /// let bias = Tabulated::read_column(&path, "b(k)", "b", true)?;
    /// assert_eq!(bias.eval(0.01)?, 2.5);
    /// // No column `bias` on the names line of a three-column file: refused, not column 2.
    /// assert!(Tabulated::read_column(&path, "b(k)", "bias", true).is_err());
    /// # Ok::<(), Box<dyn std::error::Error>>(())
    /// ```
    ///
    /// # Errors
    /// As [`read`](Self::read); [`Error::InvalidChoice`] for a file of more than two columns without
    /// `column` on its names line.
    pub fn read_column(
        path: impl AsRef<Path>,
        name: &'static str,
        column: &str,
        positive: bool,
    ) -> Result<Self> {
        let path = path.as_ref();
        let text = read_text(path)?;
        let origin = path.display().to_string();
        let table = match named_column(&text, column) {
            Some(c) => DataColumns::parse(&text, &origin, &[0, c])?,
            None => DataColumns::parse_exact(&text, &origin, 2).map_err(|e| match e {
                Error::BadRow { line, .. } => Error::InvalidChoice {
                    what: format!("`{origin}` (line {line})"),
                    reason: format!(
                        "has more than 2 columns and no `# k …` names line with `{column}`: name \
                         the columns (e.g. `# k {column} …`) so that {name} is read from the right one"
                    ),
                },
                e => e,
            })?,
        };
        let [k, v]: [Vec<f64>; 2] = table.columns.try_into().expect("two columns");
        Self::new(name, &table.origin, k, v, positive, &table.lines)
    }

    /// The k range [h/Mpc].
    pub fn range(&self) -> (f64, f64) {
        (self.k[0], self.k[self.k.len() - 1])
    }

    /// The value at `k` [h/Mpc].
    ///
    /// # Errors
    /// [`Error::OutOfRange`] outside the tabulated range.
    pub fn eval(&self, k: f64) -> Result<f64> {
        let (lo, hi) = self.range();
        if !(k >= lo * (1.0 - 1e-12) && k <= hi * (1.0 + 1e-12)) {
            return Err(Error::OutOfRange {
                what: format!("{} from {}", self.name, self.origin),
                k,
                min: lo,
                max: hi,
            });
        }
        let j = self
            .k
            .partition_point(|&x| x <= k)
            .clamp(1, self.k.len() - 1);
        let (k0, k1) = (self.k[j - 1], self.k[j]);
        let t = (k.ln() - k0.ln()) / (k1.ln() - k0.ln());
        let (v0, v1) = (self.values[j - 1], self.values[j]);
        let step = v1 - v0;
        // Values of opposite sign near f64::MAX: the difference overflows, the weighted mean does not.
        Ok(if step.is_finite() {
            v0 + t * step
        } else {
            (1.0 - t) * v0 + t * v1
        })
    }
}

/// Checks a k grid [h/Mpc]: every k finite and positive, strictly increasing. Errors name `origin` and
/// the line of the value (`lines[i]`, or i + 1 where `lines` is shorter): the one check of every reader
/// of k (tables, linear spectra, measured spectra, fit data, k files).
///
/// # Errors
/// [`Error::InvalidK`], [`Error::NonIncreasingK`].
pub fn check_k_grid(origin: &str, k: &[f64], lines: &[usize]) -> Result<()> {
    let line = |i: usize| lines.get(i).copied().unwrap_or(i + 1);
    for (i, &v) in k.iter().enumerate() {
        if !(v.is_finite() && v > 0.0) {
            return Err(Error::InvalidK {
                origin: origin.into(),
                line: line(i),
                k: v,
            });
        }
        if i > 0 && v <= k[i - 1] {
            return Err(Error::NonIncreasingK {
                origin: origin.into(),
                line: line(i),
                k: v,
                previous: k[i - 1],
            });
        }
    }
    Ok(())
}

/// Checks wavenumbers given as an array (a library or Python argument named `what`, e.g. `k` or
/// `linear k`): not empty, every k finite and positive, strictly increasing, as [`check_k_grid`] for
/// files, but the errors name the 0-based index, `what[i]`, the way the caller indexes the array.
///
/// # Errors
/// [`Error::InvalidChoice`] naming `what`, the index, the value and the rule.
pub fn check_k_values(what: &str, k: &[f64]) -> Result<()> {
    let bad = |i: usize, reason: String| Error::InvalidChoice {
        what: format!("{what}[{i}] = {} h/Mpc", crate::error::number(&k[i])),
        reason,
    };
    if k.is_empty() {
        return Err(Error::InvalidChoice {
            what: what.into(),
            reason: "the k grid is empty (at least one k is needed)".into(),
        });
    }
    for (i, &v) in k.iter().enumerate() {
        if !(v.is_finite() && v > 0.0) {
            return Err(bad(i, "every k must be finite and positive".into()));
        }
        if i > 0 && v <= k[i - 1] {
            return Err(bad(
                i,
                format!(
                    "does not exceed {what}[{}] = {} h/Mpc (k must be strictly increasing)",
                    i - 1,
                    crate::error::number(&k[i - 1])
                ),
            ));
        }
    }
    Ok(())
}

/// `n k in [a, b] h/Mpc`: a k grid [h/Mpc] in a message.
pub(crate) fn describe_grid(k: &[f64]) -> String {
    match (k.first(), k.last()) {
        (Some(a), Some(b)) => format!("{} k in [{a}, {b}] h/Mpc", k.len()),
        _ => "an empty k grid".into(),
    }
}

/// The relative difference below which two k [h/Mpc] are the same point: values written and read
/// back as text with 10 or more significant digits.
const SAME_K: f64 = 1e-9;

/// Whether `a` and `b` are the same k grid, point by point (never by their lengths alone).
pub(crate) fn same_k(a: &[f64], b: &[f64]) -> bool {
    a.len() == b.len() && a.iter().zip(b).all(|(x, y)| (x / y - 1.0).abs() <= SAME_K)
}

/// A validated grid of wavenumbers [h/Mpc]: not empty, finite, positive and strictly increasing (the
/// checks of [`check_k_grid`]). What both faces turn a user's k (a file, arrays, `--k-min/--k-max/--nk`)
/// into before any plan is made; it derefs to `[f64]`.
#[derive(Debug, Clone, PartialEq)]
pub struct KGrid(Vec<f64>);

impl KGrid {
    /// The grid `k` read from `origin` (`lines[i]`: the line of value i, for the errors).
    ///
    /// # Errors
    /// [`Error::TooFewPoints`] for no values; as [`check_k_grid`].
    pub fn new(origin: &str, k: Vec<f64>, lines: &[usize]) -> Result<Self> {
        if k.is_empty() {
            return Err(Error::TooFewPoints {
                origin: origin.into(),
                found: 0,
                min: 1,
            });
        }
        check_k_grid(origin, &k, lines)?;
        Ok(Self(k))
    }

    /// The grid of a k file: the first column of the file at `path`, one k per line (`#` comments,
    /// one optional row of column names, comma or blank separated, any line ends).
    ///
    /// A file of one row of several numbers (a row vector, `0.05 0.1 0.2` or `0.05,0.1,0.2`) is
    /// refused: its first column is one k, and the others were dropped with exit 0 (issue 45).
    ///
    /// # Errors
    /// [`Error::Io`]; [`Error::TooFewPoints`] for no values; [`Error::BadRow`] for one row of several
    /// numbers; as [`DataColumns::parse`] and [`check_k_grid`].
    pub fn read(path: impl AsRef<Path>) -> Result<Self> {
        let path = path.as_ref();
        Self::parse(&read_text(path)?, &path.display().to_string())
    }

    /// [`read`](Self::read) from the text of a k file; `origin` names it in messages.
    ///
    /// # Errors
    /// As [`read`](Self::read).
    pub fn parse(text: &str, origin: &str) -> Result<Self> {
        let table = DataColumns::parse(text, origin, &[0])?;
        if let [line] = table.lines[..] {
            let row = numbered_lines(text)
                .find(|(l, _)| *l == line)
                .map_or("", |(_, raw)| raw.split_once('#').map_or(raw, |(d, _)| d));
            let fields = row
                .split(|c: char| c == ',' || c.is_whitespace())
                .filter(|s| !s.is_empty())
                .count();
            if fields > 1 {
                return Err(Error::BadRow {
                    origin: origin.into(),
                    line,
                    problem: format!(
                        "the only row has {fields} numbers: a k file has one k per line (in its \
                         first column), so this row would be the single k {} (a row vector? write \
                         one k per line)",
                        table.columns[0][0]
                    ),
                });
            }
        }
        let k = table.columns.into_iter().next().unwrap_or_default();
        Self::new(origin, k, &table.lines)
    }

    /// The grid of an array argument named `what` (e.g. a Python `k`).
    ///
    /// # Errors
    /// As [`check_k_values`].
    pub fn from_values(what: &str, k: Vec<f64>) -> Result<Self> {
        check_k_values(what, &k)?;
        Ok(Self(k))
    }

    /// A grid made valid by construction (e.g. [`crate::linear::LogGrid::k_grid`]).
    pub(crate) fn valid(k: Vec<f64>) -> Self {
        debug_assert!(check_k_grid("a constructed grid", &k, &[]).is_ok() && !k.is_empty());
        Self(k)
    }

    /// The wavenumbers [h/Mpc].
    pub fn as_slice(&self) -> &[f64] {
        &self.0
    }

    /// The wavenumbers as a vector.
    pub fn into_vec(self) -> Vec<f64> {
        self.0
    }
}

impl std::ops::Deref for KGrid {
    type Target = [f64];

    fn deref(&self) -> &[f64] {
        &self.0
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn k_grids_are_checked_once_and_name_the_bad_value() {
        let g = KGrid::new("k.dat", vec![0.01, 0.02, 0.04], &[3, 4, 5]).unwrap();
        assert_eq!(g.len(), 3);
        assert_eq!(g.as_slice(), &[0.01, 0.02, 0.04]);
        let e = KGrid::new("k.dat", vec![0.01, 0.01], &[3, 4]).unwrap_err();
        assert!(e.to_string().starts_with("k.dat:4:"), "{e}");
        let e = KGrid::new("k.dat", vec![0.01, f64::NAN], &[]).unwrap_err();
        assert!(e.to_string().contains("k.dat:2"), "{e}");
        assert!(KGrid::new("k.dat", vec![], &[]).is_err());
        assert!(KGrid::new("k.dat", vec![-0.1], &[]).is_err());
    }

    /// Issue 45: a k file of one row of several numbers (a row vector) was read as its first number
    /// alone, exit 0; it is refused naming the file, the line and the rule. One k per line (one value
    /// or several columns), and one single k, are read as before.
    #[test]
    fn a_k_file_of_one_row_of_numbers_is_refused() {
        for text in ["0.05 0.1 0.2\n", "# k\n0.05,0.1,0.2\n", "0.05, 0.1\n"] {
            let e = KGrid::parse(text, "k.txt").unwrap_err().to_string();
            assert!(
                e.contains("k.txt:") && e.contains("one k per line"),
                "{text}: {e}"
            );
        }
        assert_eq!(KGrid::parse("0.1\n", "k.txt").unwrap().as_slice(), &[0.1]);
        let g = KGrid::parse("# k P\n0.05 1\n0.1 2\n", "k.txt").unwrap();
        assert_eq!(g.as_slice(), &[0.05, 0.1]);
        assert!(KGrid::parse("# nothing\n", "k.txt").is_err());
        let e = KGrid::parse("0.2\n0.1\n", "k.txt").unwrap_err().to_string();
        assert!(e.starts_with("k.txt:2:"), "{e}");
    }

    /// Arrays are checked as files are, but the errors name the argument and the 0-based index.
    #[test]
    fn k_arrays_name_the_argument_the_index_and_the_rule() {
        let g = KGrid::from_values("k", vec![0.01, 0.02]).unwrap();
        assert_eq!(g.as_slice(), &[0.01, 0.02]);
        let e = |k: Vec<f64>| KGrid::from_values("k", k).unwrap_err().to_string();
        assert_eq!(
            e(vec![0.2, 0.1, 0.05]),
            "k[1] = 0.1 h/Mpc: does not exceed k[0] = 0.2 h/Mpc (k must be strictly increasing)"
        );
        assert!(e(vec![0.1, 0.1, 0.1]).starts_with("k[1] = 0.1 h/Mpc: does not exceed k[0]"));
        assert_eq!(
            e(vec![0.1, f64::NAN]),
            "k[1] = NaN h/Mpc: every k must be finite and positive"
        );
        assert!(e(vec![-0.1]).starts_with("k[0] = -0.1 h/Mpc: every k must be finite"));
        assert!(e(vec![]).starts_with("k: the k grid is empty"));
    }

    #[test]
    fn columns_are_selected_and_bad_rows_named() {
        let text = "# bias\nk,b,x\n0.01 1.5 9\n0.02, 1.7, 9 # note\n\n0.04 2.1 9\n";
        let t = DataColumns::parse(text, "b.dat", &[0, 1]).unwrap();
        assert_eq!(t.columns[1], vec![1.5, 1.7, 2.1]);
        assert_eq!(t.lines, vec![3, 4, 6]);
        let e = DataColumns::parse("0.1 2\n0.2\n", "b.dat", &[0, 1]).unwrap_err();
        assert!(e.to_string().starts_with("b.dat:2:"), "{e}");
        let e = DataColumns::parse("0.1 x\n", "b.dat", &[0, 1]).unwrap_err();
        assert!(e.to_string().contains("`x`"), "{e}");
    }

    #[test]
    fn interpolation_is_linear_in_ln_k_and_does_not_extrapolate() {
        let f = Tabulated::new("b(k)", "mem", vec![0.01, 0.1], vec![1.0, 2.0], true, &[]).unwrap();
        assert!((f.eval(0.01f64.sqrt() * 0.1f64.sqrt()).unwrap() - 1.5).abs() < 1e-14);
        assert_eq!(f.eval(0.1).unwrap(), 2.0);
        let e = f.eval(0.2).unwrap_err().to_string();
        assert!(e.contains("b(k)") && e.contains("0.2"), "{e}");
        let nan = Tabulated::new(
            "b(k)",
            "mem",
            vec![0.01, 0.1],
            vec![1.0, f64::NAN],
            true,
            &[],
        );
        assert!(nan.unwrap_err().to_string().contains("NaN"));
        let down = Tabulated::new("b(k)", "mem", vec![0.1, 0.01], vec![1.0, 1.0], true, &[]);
        assert!(down.is_err());
    }

    #[test]
    fn named_columns_are_found_on_the_k_line_only() {
        let text = "# halo\n# column 1: k [h/Mpc]\n# k b P_eps\n0.1 2 3\n";
        assert_eq!(named_column(text, "P_eps"), Some(2));
        assert_eq!(named_column(text, "b"), Some(1));
        assert_eq!(named_column(text, "k"), None);
        assert_eq!(named_column(text, "SN"), None);
        // Only header lines before the data count; a names row without `#` is not a `# k` line.
        assert_eq!(named_column("0.1 2\n# k b\n", "b"), None);
        assert_eq!(named_column("k b\n0.1 2\n", "b"), None);
    }
}
