//! Every table parser against adversarial files: random bytes, truncated lines, huge, tiny and non-finite
//! numbers, garbage fields, duplicate or decreasing k, rows with too few or too many columns, empty and
//! header-only files, Windows and classic-Mac line ends.
//!
//! Each parser must return (never panic) either a value that is usable (finite interpolation inside the
//! table) or an error whose message names the origin and, for a problem on a line, that line as
//! `origin:line:`. The generated files number their lines themselves, so the expected line does not come
//! from the code under test.

use proptest::prelude::*;
use pt_spectra::error::Error;
use pt_spectra::fit::MultipoleData;
use pt_spectra::linear::{Columns, LinearSpectrum, MAX_POWER, MIN_POINTS};
use pt_spectra::table::{DataColumns, Tabulated};

const ORIGIN: &str = "adversarial.dat";

/// The line an error is about, if it is about one.
fn line_of(e: &Error) -> Option<usize> {
    match e {
        Error::Parse { line, .. }
        | Error::MissingColumn { line, .. }
        | Error::InvalidK { line, .. }
        | Error::NonIncreasingK { line, .. }
        | Error::InvalidPower { line, .. }
        | Error::InvalidValue { line, .. }
        | Error::BadRow { line, .. } => Some(*line),
        _ => None,
    }
}

/// The error names the origin; an error about a line names it as `origin:line:`, and that line is
/// one of `allowed` (any line of the text if `allowed` is empty); an error about no line is a count of
/// rows.
fn check_error(e: &Error, text: &str, allowed: &[usize]) -> Result<(), TestCaseError> {
    let message = e.to_string();
    prop_assert!(message.contains(ORIGIN), "no origin: {message}");
    match line_of(e) {
        Some(line) => {
            let needle = format!("{ORIGIN}:{line}:");
            prop_assert!(message.starts_with(&needle), "{message}");
            let lines = text.matches(['\n', '\r']).count() + 1;
            prop_assert!(
                line >= 1 && line <= lines,
                "line {line} of {lines}: {message}"
            );
            prop_assert!(
                allowed.is_empty() || allowed.contains(&line),
                "line {line}, expected one of {allowed:?}: {message}"
            );
        }
        None => prop_assert!(
            matches!(e, Error::TooFewPoints { .. }),
            "an error about no line must count rows: {e:?}"
        ),
    }
    // Short enough to read, whatever the file holds.
    prop_assert!(message.chars().count() < 400, "{message}");
    Ok(())
}

/// The linear spectrum is usable: finite at its nodes and between them, at its ends and just beyond.
fn check_spectrum(p: &LinearSpectrum) -> Result<(), TestCaseError> {
    let (k, _) = p.nodes();
    prop_assert!(k.len() >= MIN_POINTS);
    for w in k.windows(2) {
        let middle = (0.5 * (w[0].ln() + w[1].ln())).exp().clamp(w[0], w[1]);
        for x in [w[0], middle, w[1]] {
            let v = p.eval(x);
            prop_assert!((0.0..MAX_POWER * 1.0001).contains(&v), "P({x}) = {v}");
        }
    }
    let (low, high) = p.extrapolation_slopes();
    prop_assert!(low.is_finite() && high.is_finite(), "{low} {high}");
    for x in [p.k_min() * (1.0 - 1e-9), p.k_max() * (1.0 + 1e-9)] {
        let v = p.eval(x);
        prop_assert!(v.is_finite() && v >= 0.0, "P({x}) = {v}");
    }
    Ok(())
}

/// Tokens that are not acceptable numbers, or acceptable numbers at the edges of f64.
const TOKENS: &[&str] = &[
    "1e308",
    "-1e308",
    "1.7976931348623157e308",
    "1e400",
    "-1e400",
    "inf",
    "-inf",
    "infinity",
    "NaN",
    "nan",
    "-0",
    "0",
    "0.0",
    "5e-324",
    "1e-320",
    "2.2250738585072014e-308",
    "1e-400",
    "abc",
    "1.2.3",
    "0x10",
    "1e",
    "+",
    "-",
    ".",
    "--1",
    "1e999999999",
    "１",
    "\u{feff}1",
    "\u{1b}[31m",
    "1,5",
    "\"0.1\"",
    "0.1;",
    "99999999999999999999999999999999999999999999999999999",
];

/// How a valid table is spoiled: on data row `row` (taken modulo the number of rows), column `column`
/// (modulo the row's width).
#[derive(Debug, Clone)]
enum Spoil {
    None,
    /// Cut the row after this many characters (modulo its length).
    Truncate(usize, usize),
    /// Replace a field by one of [`TOKENS`].
    Token(usize, usize, usize),
    /// Give the row the k of the previous row.
    DuplicateK(usize),
    /// Swap the k of the row and the next one.
    SwapK(usize),
    /// Drop this many fields from the end of the row.
    Drop(usize, usize),
    /// Add this many fields to the row.
    Extra(usize, usize),
    /// Replace the row by this text (no line end in it).
    Garbage(usize, String),
}

/// The look of a table file.
#[derive(Debug, Clone)]
struct Style {
    /// 0 nothing, 1 `#` lines, 2 a row of column names, 3 both.
    header: u8,
    separator: &'static str,
    ending: &'static str,
    final_ending: bool,
    blank_lines: bool,
    number_format: u8,
}

fn style() -> impl Strategy<Value = Style> {
    (
        0u8..4,
        prop::sample::select(vec![" ", "\t", ", ", ",", "  \t "]),
        prop::sample::select(vec!["\n", "\r\n", "\r"]),
        any::<bool>(),
        any::<bool>(),
        0u8..3,
    )
        .prop_map(
            |(header, separator, ending, final_ending, blank_lines, number_format)| Style {
                header,
                separator,
                ending,
                final_ending,
                blank_lines,
                number_format,
            },
        )
}

fn spoil() -> impl Strategy<Value = Spoil> {
    let at = || 0usize..1000;
    prop_oneof![
        1 => Just(Spoil::None),
        2 => (at(), at()).prop_map(|(r, c)| Spoil::Truncate(r, c)),
        3 => (at(), at(), 0..TOKENS.len()).prop_map(|(r, c, t)| Spoil::Token(r, c, t)),
        1 => at().prop_map(Spoil::DuplicateK),
        1 => at().prop_map(Spoil::SwapK),
        1 => (at(), 1usize..4).prop_map(|(r, n)| Spoil::Drop(r, n)),
        1 => (at(), 1usize..3).prop_map(|(r, n)| Spoil::Extra(r, n)),
        1 => (at(), "[ -~]{0,30}").prop_map(|(r, g)| Spoil::Garbage(r, g)),
    ]
}

fn format_number(v: f64, style: &Style) -> String {
    match style.number_format {
        0 => format!("{v:e}"),
        1 => format!("{v:.9e}"),
        _ => format!("{v}"),
    }
}

/// A spoiled table file: its text, the file line of each data row, and the spoiled row (index).
#[derive(Debug, Clone)]
struct File {
    text: String,
    lines: Vec<usize>,
    spoiled: Option<usize>,
}

impl File {
    /// The file lines an error about the spoiled row may name: that row, the rows next to it (a changed
    /// k is compared with its neighbours), or `reach` rows either side.
    fn allowed(&self, reach: usize) -> Vec<usize> {
        match self.spoiled {
            None => Vec::new(),
            Some(r) => {
                let lo = r.saturating_sub(reach);
                let hi = (r + reach).min(self.lines.len() - 1);
                self.lines[lo..=hi].to_vec()
            }
        }
    }
}

/// Writes `rows` (numbers) in `style`, spoiled by `spoil`.
fn write_file(rows: &[Vec<f64>], names: &[&str], style: &Style, spoil: &Spoil) -> File {
    let n = rows.len();
    let mut fields: Vec<Vec<String>> = rows
        .iter()
        .map(|r| r.iter().map(|&v| format_number(v, style)).collect())
        .collect();
    let mut replaced: Vec<Option<String>> = vec![None; n];
    let spoiled = match spoil {
        Spoil::None => None,
        Spoil::Truncate(r, _)
        | Spoil::Token(r, _, _)
        | Spoil::Drop(r, _)
        | Spoil::Extra(r, _)
        | Spoil::Garbage(r, _) => Some(r % n),
        Spoil::DuplicateK(r) | Spoil::SwapK(r) if n >= 2 => Some(r % (n - 1)),
        _ => None,
    };
    match (spoil, spoiled) {
        (Spoil::Token(_, c, t), Some(r)) => {
            let width = fields[r].len();
            fields[r][c % width] = TOKENS[*t].to_string();
        }
        (Spoil::DuplicateK(_), Some(r)) => fields[r + 1][0] = fields[r][0].clone(),
        (Spoil::SwapK(_), Some(r)) => {
            let k = fields[r][0].clone();
            fields[r][0] = std::mem::replace(&mut fields[r + 1][0], k);
        }
        (Spoil::Drop(_, d), Some(r)) => {
            let keep = fields[r].len().saturating_sub(*d);
            fields[r].truncate(keep);
        }
        (Spoil::Extra(_, e), Some(r)) => {
            for i in 0..*e {
                fields[r].push(format!("{}", 1.5 + i as f64));
            }
        }
        (Spoil::Garbage(_, g), Some(r)) => replaced[r] = Some(g.clone()),
        _ => {}
    }
    let mut line_texts: Vec<String> = Vec::new();
    if style.header & 1 == 1 {
        line_texts.push("# produced by an adversarial generator".into());
        line_texts.push("#".into());
    }
    if style.header & 2 == 2 {
        line_texts.push(names[..rows[0].len()].join(style.separator));
    }
    let mut lines = Vec::with_capacity(n);
    for (i, row) in fields.iter().enumerate() {
        if style.blank_lines && i % 7 == 3 {
            line_texts.push(String::new());
            line_texts.push("   # a comment between rows".into());
        }
        let mut text = replaced[i]
            .clone()
            .unwrap_or_else(|| row.join(style.separator));
        if let (Spoil::Truncate(_, at), Some(r)) = (spoil, spoiled) {
            if r == i {
                let cut = at % text.chars().count().max(1);
                text = text.chars().take(cut).collect();
            }
        }
        if i % 5 == 2 {
            text.push_str(" # a trailing comment");
        }
        line_texts.push(text);
        lines.push(line_texts.len());
    }
    let mut text = line_texts.join(style.ending);
    if style.final_ending {
        text.push_str(style.ending);
    }
    // The spoiled row's line was counted before it was made empty or a comment: such a row is skipped.
    File {
        text,
        lines,
        spoiled,
    }
}

/// Rows of k (log-spaced from a random start) and `columns − 1` further values: positive, or of any sign
/// in the columns `signed` says.
fn rows(
    count: std::ops::Range<usize>,
    columns: usize,
    signed: fn(usize) -> bool,
) -> impl Strategy<Value = Vec<Vec<f64>>> {
    (
        -5.0f64..1.0,
        0.005f64..0.3,
        count.prop_flat_map(move |n| {
            prop::collection::vec(prop::collection::vec(-2.0f64..5.0, columns - 1), n)
        }),
        any::<u64>(),
    )
        .prop_map(move |(start, step, exponents, signs)| {
            exponents
                .iter()
                .enumerate()
                .map(|(i, e)| {
                    let mut row = vec![10f64.powf(start + step * i as f64)];
                    row.extend(e.iter().enumerate().map(|(j, x)| {
                        let negative = signed(j + 1) && (signs >> ((i + j) % 64)) & 1 == 1;
                        let v = 10f64.powf(*x);
                        if negative {
                            -v
                        } else {
                            v
                        }
                    }));
                    row
                })
                .collect()
        })
}

/// Text made of the characters of tables, in random order: near misses of valid files.
fn table_like_text() -> impl Strategy<Value = String> {
    "[0-9eE+\\-., \t#\r\nna]{0,400}"
}

/// Arbitrary bytes, decoded as the readers decode files (invalid UTF-8 replaced).
fn random_bytes() -> impl Strategy<Value = String> {
    prop::collection::vec(any::<u8>(), 0..600)
        .prop_map(|b| String::from_utf8_lossy(&b).into_owned())
}

fn any_text() -> impl Strategy<Value = String> {
    prop_oneof![table_like_text(), random_bytes()]
}

const NAMES: &[&str] = &["k", "P", "s0", "P2", "s2", "x", "y"];

fn config() -> ProptestConfig {
    let default = ProptestConfig::default();
    ProptestConfig {
        // PROPTEST_CASES (read by the default) searches longer.
        cases: if std::env::var_os("PROPTEST_CASES").is_some() {
            default.cases
        } else {
            400
        },
        // Failures print their minimal input; no regression files are written into the tree.
        failure_persistence: None,
        ..default
    }
}

fn no_sign(_: usize) -> bool {
    false
}

proptest! {
    #![proptest_config(config())]

    #[test]
    fn table_parse_survives_anything(text in any_text(), wide in any::<bool>()) {
        let columns: &[usize] = if wide { &[0, 3, 1] } else { &[0, 1] };
        match DataColumns::parse(&text, ORIGIN, columns) {
            Ok(t) => {
                prop_assert_eq!(t.columns.len(), columns.len());
                prop_assert!(t.columns.iter().all(|c| c.len() == t.lines.len()));
            }
            Err(e) => check_error(&e, &text, &[])?,
        }
    }

    #[test]
    fn spoiled_tables_name_the_spoiled_line(
        rows in rows(2..30, 3, |c| c == 2), style in style(), spoil in spoil()
    ) {
        let file = write_file(&rows, NAMES, &style, &spoil);
        match DataColumns::parse(&file.text, ORIGIN, &[0, 2]) {
            Ok(t) => prop_assert!(t.lines.len() <= rows.len() + 1),
            Err(e) => check_error(&e, &file.text, &file.allowed(1))?,
        }
    }

    #[test]
    fn tabulated_functions_are_checked_and_interpolate_finitely(
        mut rows in rows(1..30, 2, |_| true), style in style(), spoil in spoil(), positive in any::<bool>()
    ) {
        if positive {
            rows.iter_mut().for_each(|r| r[1] = r[1].abs());
        }
        let file = write_file(&rows, NAMES, &style, &spoil);
        let result = DataColumns::parse(&file.text, ORIGIN, &[0, 1]).and_then(|t| {
            let [k, v]: [Vec<f64>; 2] = t.columns.try_into().expect("two columns");
            Tabulated::new("b(k)", &t.origin, k, v, positive, &t.lines)
        });
        match result {
            Ok(f) => {
                let (lo, hi) = f.range();
                for x in [lo, (0.5 * (lo.ln() + hi.ln())).exp(), hi] {
                    let v = f.eval(x);
                    prop_assert!(matches!(v, Ok(v) if v.is_finite()), "{x}: {v:?}");
                }
            }
            Err(e) => {
                // A valid file fails only for too few rows.
                if matches!(spoil, Spoil::None) {
                    prop_assert!(rows.len() < 2, "a valid table is refused: {e}");
                }
                check_error(&e, &file.text, &file.allowed(1))?;
            }
        }
    }

    #[test]
    fn linear_spectra_are_usable_or_refused_at_the_line(
        rows in rows(MIN_POINTS - 2..60, 3, no_sign), style in style(), spoil in spoil()
    ) {
        let file = write_file(&rows, NAMES, &style, &spoil);
        for columns in [Columns::default(), Columns::new(0, 2)] {
            match LinearSpectrum::parse(&file.text, ORIGIN, columns) {
                Ok(p) => check_spectrum(&p)?,
                Err(e) => {
                    if matches!(spoil, Spoil::None) {
                        prop_assert!(rows.len() < MIN_POINTS, "a valid table is refused: {e}");
                    }
                    check_error(&e, &file.text, &file.allowed(2))?;
                }
            }
        }
    }

    #[test]
    fn linear_spectra_survive_any_text(text in any_text()) {
        match LinearSpectrum::parse(&text, ORIGIN, Columns::default()) {
            Ok(p) => check_spectrum(&p)?,
            Err(e) => check_error(&e, &text, &[])?,
        }
    }

    /// k and P anywhere in the f64 range, denormals included: refused at a line, or finite inside.
    #[test]
    fn linear_spectra_at_the_edges_of_f64(
        mut nodes in prop::collection::vec((-323.5f64..308.2, -323.5f64..308.25), MIN_POINTS..40),
        tiny_steps in any::<bool>(),
    ) {
        nodes.sort_by(|a, b| a.0.total_cmp(&b.0));
        let mut text = String::new();
        let mut previous = 0.0f64;
        for (i, (lk, lp)) in nodes.iter().enumerate() {
            // Some tables crowd their k into a few units in the last place.
            let k = if tiny_steps && i % 3 == 1 {
                previous.next_up()
            } else {
                10f64.powf(*lk)
            };
            previous = k;
            text.push_str(&format!("{k:e} {:e}\n", 10f64.powf(*lp)));
        }
        match LinearSpectrum::parse(&text, ORIGIN, Columns::default()) {
            Ok(p) => check_spectrum(&p)?,
            Err(e) => check_error(&e, &text, &[])?,
        }
    }

    #[test]
    fn measured_multipoles_name_the_spoiled_line(
        rows in rows(1..25, 5, |c| c == 1 || c == 3), style in style(), spoil in spoil()
    ) {
        let file = write_file(&rows, NAMES, &style, &spoil);
        let result = MultipoleData::parse(&file.text, ORIGIN, 0, &[(0, 1, 2), (2, 3, 4)]);
        match result {
            Ok(d) => {
                prop_assert!(d.k.windows(2).all(|w| w[0] < w[1]));
                prop_assert!(d.sigma.iter().flatten().all(|s| s.is_finite() && *s > 0.0));
                prop_assert!(d.values.iter().flatten().all(|v| v.is_finite()));
            }
            Err(e) => {
                prop_assert!(!matches!(spoil, Spoil::None), "a valid table is refused: {e}");
                check_error(&e, &file.text, &file.allowed(1))?;
            }
        }
    }

    #[test]
    fn measured_multipoles_survive_any_text(text in any_text()) {
        if let Err(e) = MultipoleData::parse(&text, ORIGIN, 0, &[(0, 1, 2)]) {
            check_error(&e, &text, &[])?;
        }
    }

    #[test]
    fn covariance_files_name_the_bad_line(
        n_k in 1usize..5,
        seed in prop::collection::vec(-1.0f64..1.0, 64),
        style in style(),
        spoil in spoil(),
        rows_off in -1i32..2,
    ) {
        let k: Vec<f64> = (0..n_k).map(|i| 0.01 * (i + 1) as f64).collect();
        let data = MultipoleData {
            ells: vec![0, 2],
            values: vec![vec![1.0; n_k]; 2],
            sigma: vec![vec![1.0; n_k]; 2],
            k,
            covariance: None,
        };
        // Diagonally dominant, symmetric: positive definite.
        let n = 2 * n_k;
        let matrix: Vec<Vec<f64>> = (0..n)
            .map(|i| {
                (0..n)
                    .map(|j| if i == j { n as f64 + 1.0 } else { seed[(i.min(j) * 8 + i.max(j)) % 64] })
                    .collect()
            })
            .collect();
        let mut rows = matrix.clone();
        match rows_off {
            -1 => { rows.pop(); }
            1 => rows.push(matrix[0].clone()),
            _ => {}
        }
        // No column names in a matrix (a names row of numbers-only width would be a data row).
        let style = Style { header: style.header & 1, ..style };
        let file = write_file(&rows, NAMES, &style, &spoil);
        match data.parse_covariance(&file.text, ORIGIN) {
            Ok(d) => {
                // (A spoiled row may have become empty or a comment, making up for an extra row.)
                if matches!(spoil, Spoil::None) {
                    prop_assert_eq!(rows_off, 0);
                }
                prop_assert_eq!(d.covariance.map(|c| c.len()), Some(n));
            }
            Err(e) => {
                if matches!(spoil, Spoil::None) {
                    prop_assert!(rows_off != 0, "a valid matrix is refused: {e}");
                }
                check_error(&e, &file.text, &[])?;
            }
        }
    }

    #[test]
    fn covariance_survives_any_text(text in any_text(), n_k in 1usize..4) {
        let data = MultipoleData {
            k: (1..=n_k).map(|i| i as f64).collect(),
            ells: vec![0],
            values: vec![vec![1.0; n_k]],
            sigma: vec![vec![1.0; n_k]],
            covariance: None,
        };
        if let Err(e) = data.parse_covariance(&text, ORIGIN) {
            check_error(&e, &text, &[])?;
        }
    }
}

// Plain tests of edge cases the properties found or that matter on their own.
