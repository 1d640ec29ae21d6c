//! Every table parser on hand-made edge cases (the random ones are in `parsers.rs`): empty and
//! header-only files, a second row of names, the line ends of every system, a byte order mark, escaped
//! garbage, huge column numbers, k a few ulps apart, powers near the largest float, denormal and huge
//! k ranges, huge values of opposite sign, covariance shapes, files that are not UTF-8. Each error
//! names the origin and the line.

use pt_spectra::error::Error;
use pt_spectra::fit::MultipoleData;
use pt_spectra::linear::{Columns, LinearSpectrum};
use pt_spectra::table::{DataColumns, Tabulated};

const ORIGIN: &str = "adversarial.dat";

fn linear_rows(n: usize) -> Vec<(f64, f64)> {
    (0..n)
        .map(|i| {
            let k = 1e-3 * 1.4f64.powi(i as i32);
            (k, 2e4 * k / (1.0 + (k / 0.02).powi(2)))
        })
        .collect()
}

fn linear_text(rows: &[(f64, f64)]) -> String {
    rows.iter().map(|(k, p)| format!("{k:e} {p:e}\n")).collect()
}

fn message(e: Error) -> String {
    e.to_string()
}

#[test]
fn empty_and_header_only_files_count_their_rows() {
    for text in [
        "",
        "\n\n",
        "# only a header\n# and another\n",
        "k P\n",
        "\u{feff}",
        "\r\n\r\n",
    ] {
        let e = LinearSpectrum::parse(text, ORIGIN, Columns::default()).unwrap_err();
        assert!(
            matches!(e, Error::TooFewPoints { found: 0, .. }),
            "{text:?}: {e}"
        );
        let e = MultipoleData::parse(text, ORIGIN, 0, &[(0, 1, 2)]).unwrap_err();
        assert!(message(e).starts_with(ORIGIN), "{text:?}");
        let t = DataColumns::parse(text, ORIGIN, &[0, 1]).unwrap();
        assert!(t.lines.is_empty());
    }
}

#[test]
fn a_second_row_of_names_is_an_error_on_its_line() {
    let e = DataColumns::parse("k P\nkh pk\n0.1 2\n", ORIGIN, &[0, 1]).unwrap_err();
    assert_eq!(
        message(e),
        format!("{ORIGIN}:2: cannot parse `kh` (column 1) as a number")
    );
    // Garbage throughout: the second line is named, not "0 rows".
    let e = DataColumns::parse("\u{7f}ELF\u{2}\u{1}\nxx yy zz\n", ORIGIN, &[0]).unwrap_err();
    assert!(message(e).starts_with(&format!("{ORIGIN}:2:")));
}

#[test]
fn line_ends_of_every_system_number_lines_alike() {
    for ending in ["\n", "\r\n", "\r"] {
        let text = ["# head", "0.1 1", "", "0.2 x"].join(ending);
        let e = DataColumns::parse(&text, ORIGIN, &[0, 1]).unwrap_err();
        assert!(
            message(e).starts_with(&format!("{ORIGIN}:4: cannot parse `x`")),
            "{ending:?}"
        );
    }
    // A classic-Mac file is read row by row, not as one long row.
    let t = DataColumns::parse("0.1 1\r0.2 2\r0.3 3", ORIGIN, &[0, 1]).unwrap();
    assert_eq!(t.columns[0], vec![0.1, 0.2, 0.3]);
    assert_eq!(t.lines, vec![1, 2, 3]);
}

#[test]
fn a_byte_order_mark_is_not_part_of_the_first_field() {
    let t = DataColumns::parse("\u{feff}0.1 1\n0.2 2\n", ORIGIN, &[0, 1]).unwrap();
    assert_eq!(t.columns[0], vec![0.1, 0.2]);
}

#[test]
fn unreadable_fields_are_shown_escaped_and_short() {
    let long = "7".repeat(30) + &"x".repeat(100);
    let e = DataColumns::parse(&format!("0.1 {long}\n"), ORIGIN, &[0, 1]).unwrap_err();
    let m = message(e);
    assert!(m.contains(&format!("`{}…`", &long[..40])), "{m}");
    let e = DataColumns::parse("0.1 \u{1b}[2J\n", ORIGIN, &[0, 1]).unwrap_err();
    let m = message(e);
    assert!(!m.contains('\u{1b}') && m.contains("\\u{1b}[2J"), "{m}");
}

#[test]
fn huge_column_numbers_are_missing_columns() {
    let e = DataColumns::parse("0.1 1\n", ORIGIN, &[0, usize::MAX]).unwrap_err();
    assert!(
        matches!(
            e,
            Error::MissingColumn {
                line: 1,
                column: usize::MAX,
                found: 2,
                ..
            }
        ),
        "{e}"
    );
}

#[test]
fn k_a_few_ulps_apart_are_refused_not_divided_by() {
    // Near 1e300, ln k of the next float rounds to the same value: the spline would divide by zero.
    let k = 1e300f64;
    assert_eq!(k.ln(), k.next_up().ln());
    let mut rows = linear_rows(25);
    rows[23].0 = k;
    rows[24].0 = k.next_up();
    let e = LinearSpectrum::parse(&linear_text(&rows), ORIGIN, Columns::default()).unwrap_err();
    assert!(
        message(e).starts_with(&format!("{ORIGIN}:25: k [h/Mpc] = ")),
        "{rows:?}"
    );
    let e = Tabulated::new(
        "b(k)",
        ORIGIN,
        vec![k, k.next_up()],
        vec![1.0, 2.0],
        true,
        &[7, 9],
    )
    .unwrap_err();
    assert!(message(e).starts_with(&format!("{ORIGIN}:9: k [h/Mpc]")));
    // Near 1 ln k does tell them apart: a steep spline, usable or refused at those rows.
    let mut rows: Vec<(f64, f64)> = (0..25)
        .map(|i| {
            let k = 0.2 * 1.2f64.powi(i);
            (k, 1e4 / (1.0 + k * k))
        })
        .collect();
    rows[9].0 = 1.0;
    rows[10].0 = 1.0f64.next_up();
    match LinearSpectrum::parse(&linear_text(&rows), ORIGIN, Columns::default()) {
        Ok(p) => {
            for x in [0.99, 1.0, 1.0f64.next_up(), 1.1] {
                assert!(p.eval(x).is_finite(), "{x}");
            }
        }
        Err(e) => assert!(
            matches!(e, Error::InvalidValue { line: 10 | 11, .. }),
            "{e}"
        ),
    }
}

#[test]
fn powers_near_the_largest_float_are_refused_at_their_line() {
    let mut rows = linear_rows(25);
    rows[12].1 = 1e308;
    let e = LinearSpectrum::parse(&linear_text(&rows), ORIGIN, Columns::default()).unwrap_err();
    let m = message(e);
    assert_eq!(
        m,
        format!(
            "{ORIGIN}:13: P [(Mpc/h)^3] = 1e308: exceeds 1e300: too close to the largest f64 to \
             interpolate and integrate"
        )
    );
    // A spike below 1e300 that the spline would carry above it is blamed on its row.
    rows[12].1 = 1e299;
    let e = LinearSpectrum::parse(&linear_text(&rows), ORIGIN, Columns::default()).unwrap_err();
    assert!(matches!(e, Error::InvalidValue { line: 13, .. }), "{e}");
    rows[12].1 = f64::MAX;
    assert!(LinearSpectrum::parse(&linear_text(&rows), ORIGIN, Columns::default()).is_err());
    // 1e300 everywhere with smooth k is fine, and so is its evaluation.
    let flat: Vec<(f64, f64)> = linear_rows(25).iter().map(|r| (r.0, 1e299)).collect();
    let p = LinearSpectrum::parse(&linear_text(&flat), ORIGIN, Columns::default()).unwrap();
    assert!((p.eval(0.01) / 1e299 - 1.0).abs() < 1e-12);
    // ... but not scaled beyond 1e300.
    assert!(p.scaled(100.0).is_err() && p.scaled(2.0).is_ok());
}

#[test]
fn denormal_and_huge_k_ranges_are_usable() {
    let rows: Vec<(f64, f64)> = (0..30)
        .map(|i| {
            let k = 10f64.powf(-323.0 + 21.0 * i as f64);
            (k, 10f64.powf(-300.0 + 20.0 * i as f64))
        })
        .collect();
    let p = LinearSpectrum::parse(&linear_text(&rows), ORIGIN, Columns::default()).unwrap();
    assert!(p.k_min() < 1e-322 && p.k_max() > 1e285);
    for (k, v) in &rows {
        assert!((p.eval(*k) / v - 1.0).abs() < 1e-9, "{k}");
    }
}

#[test]
fn tabulated_values_of_opposite_huge_sign_interpolate_finitely() {
    let f = Tabulated::new(
        "b(k)",
        ORIGIN,
        vec![0.1, 0.2],
        vec![-1.7e308, 1.7e308],
        false,
        &[],
    )
    .unwrap();
    let v = f.eval(0.2f64.sqrt() * 0.1f64.sqrt()).unwrap();
    assert!(v.is_finite() && v.abs() < 1e295, "{v}");
    assert_eq!(f.eval(0.1).unwrap(), -1.7e308);
}

fn two_by_two() -> MultipoleData {
    MultipoleData::parse("0.1 1 1\n0.2 1 1\n", "data", 0, &[(0, 1, 2)]).unwrap()
}

#[test]
fn covariance_shape_errors_name_file_and_line() {
    let cases = [
        // a row of another width: the sizes of both, not "column 2 was requested" (issue 45)
        (
            "1 0\n0 1 0\n",
            ":2: the covariance row has 3 columns, but the data vector has 2 values (1 multipole(s) × 2 k): the covariance must be 2 × 2",
        ),
        (
            "1 0\n0\n",
            ":2: the covariance row has 1 columns, but the data vector has 2 values",
        ),
        (
            "1\n0\n",
            ":1: the covariance row has 1 columns, but the data vector has 2 values",
        ),
        (
            "1 0\n0 1\n0 0\n",
            ":3: row 3 of the covariance is one too many",
        ),
        ("# c\n1 0\n0 -1\n", ":3: covariance diagonal = -1"),
        (
            "1 0.5\n0.4 1\n",
            ":2: covariance element (2, 1) = 0.4 differs from element (1, 2) = 0.5",
        ),
        (
            "1 nan\nnan 1\n",
            ":1: covariance element (1, 2) = NaN is not finite",
        ),
        (
            "1 0\n0 1e400\n",
            ":2: covariance element (2, 2) = inf is not finite",
        ),
        ("1 0\n0 x\n", ":2: cannot parse `x`"),
    ];
    for (text, needle) in cases {
        let e = two_by_two().parse_covariance(text, ORIGIN).unwrap_err();
        let m = message(e);
        assert!(m.starts_with(ORIGIN) && m.contains(needle), "{text:?}: {m}");
    }
    let e = two_by_two().parse_covariance("1 0\n", ORIGIN).unwrap_err();
    assert_eq!(
        message(e),
        format!("{ORIGIN}: 1 data row(s), at least 2 are needed")
    );
    // Asymmetry hidden by overflow: c_11 c_22 = inf must not make every difference tolerable.
    let e = two_by_two()
        .parse_covariance("1e300 1e295\n-1e295 1e300\n", ORIGIN)
        .unwrap_err();
    assert!(matches!(e, Error::BadRow { line: 2, .. }), "{e}");
    let ok = two_by_two()
        .parse_covariance("2, 0.5\r\n0.5, 3\r\n", ORIGIN)
        .unwrap();
    assert_eq!(ok.covariance, Some(vec![vec![2.0, 0.5], vec![0.5, 3.0]]));
    // The in-memory form names rows.
    let e = two_by_two()
        .with_covariance(vec![vec![1.0, 0.0], vec![0.0, 0.0]])
        .unwrap_err();
    assert!(message(e).starts_with("covariance matrix:2: covariance diagonal = 0"));
}

#[test]
fn files_that_are_not_utf8_are_read_and_refused_at_their_line() {
    let path = std::env::temp_dir().join(format!("pt-spectra-parsers-{}.dat", std::process::id()));
    // A Latin-1 µ in a comment is harmless; a stray byte in a number is named with its line.
    std::fs::write(&path, b"# \xb5m\n0.1 1\n0.2 \xff2\n").unwrap();
    let e = DataColumns::read(&path, &[0, 1]).unwrap_err();
    std::fs::remove_file(&path).unwrap();
    let m = message(e);
    assert!(
        m.starts_with(&format!("{}:3: cannot parse `\u{fffd}2`", path.display())),
        "{m}"
    );
}
