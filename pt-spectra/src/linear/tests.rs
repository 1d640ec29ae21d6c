//! Unit tests of [`LinearSpectrum`](super::LinearSpectrum) against the embedded CAMB tables and the
//! FAST-PT σ_v² header value, and of every parse error.

use super::*;

/// Interpolation requirement on BAO wiggles: the spline through every second CAMB node reproduces the
/// dropped nodes to this relative accuracy over 0.01–0.5 h/Mpc.
const INTERPOLATION_TOL: f64 = 1e-4;
/// σ8 of the embedded CAMB table (tuned by As to 0.8; CAMB integrates its own k grid).
const SIGMA8_TOL: f64 = 1e-3;

fn table(rows: &[(f64, f64)]) -> String {
    rows.iter().map(|(k, p)| format!("{k:e} {p:e}\n")).collect()
}

fn power_law_rows(n: usize) -> Vec<(f64, f64)> {
    (0..n)
        .map(|i| {
            let k = 1e-3 * 1.5f64.powi(i as i32);
            (k, 1e4 * k.powf(0.96) / (1.0 + (k / 0.02).powi(3)))
        })
        .collect()
}

#[test]
fn embedded_tables_parse_with_headers() {
    for z in GM2012_REDSHIFTS {
        let p = LinearSpectrum::gm2012(z).unwrap();
        assert_eq!(p.nodes().0.len(), 1200);
        assert_eq!((p.k_min(), p.k_max()), (1e-4, 50.0));
        assert!(p.header()[0].contains("CAMB 2.0.5"), "{:?}", p.header());
    }
    assert!(matches!(
        LinearSpectrum::gm2012(0.3),
        Err(Error::NoEmbeddedSpectrum { .. })
    ));
}

#[test]
fn spline_reproduces_dropped_nodes_of_camb_table() {
    let full = LinearSpectrum::gm2012_z0();
    let (k, p) = full.nodes();
    let even = |v: &[f64]| v.iter().step_by(2).copied().collect::<Vec<_>>();
    let half = LinearSpectrum::from_nodes(even(k), even(p)).unwrap();
    let mut worst = (0.0_f64, 0.0);
    for i in (1..k.len())
        .step_by(2)
        .filter(|&i| (0.01..=0.5).contains(&k[i]))
    {
        let err = (half.eval(k[i]) / p[i] - 1.0).abs();
        if err > worst.0 {
            worst = (err, k[i]);
        }
    }
    println!(
        "decimated-by-2 max rel. error {:.3e} at k = {:.4}",
        worst.0, worst.1
    );
    assert!(worst.0 < INTERPOLATION_TOL, "{worst:?}");
    // The full table interpolates its own nodes exactly.
    assert!((full.eval(k[500]) / p[500] - 1.0).abs() < 1e-13);
}

#[test]
fn sigma8_of_embedded_table() {
    let p = LinearSpectrum::gm2012_z0();
    let (s8, err) = p.sigma_r(8.0).unwrap();
    println!("sigma8 = {s8:.6} +- {err:.1e}");
    assert!((s8 - 0.8).abs() < SIGMA8_TOL * 0.8, "sigma8 = {s8}");
    assert!(err < 1e-6);
    assert!(p.extrapolation_in(1e-3 / 8.0, 300.0 / 8.0).is_none());
}

#[test]
fn sigma_v2_matches_fastpt_header() {
    // FAST-PT header: 36.9474495 (Mpc/h)^2 from a trapezoid in ln q over its extrapolated grid
    // 1e-5..1e3 h/Mpc; the tails beyond the table add ~1e-3 (Mpc/h)^2.
    let (v, err) = LinearSpectrum::gm2012_z0().sigma_v2();
    println!("sigma_v^2 = {v:.6} +- {err:.1e}");
    assert!((v / 36.9474495 - 1.0).abs() < 1e-4, "{v}");
    assert!(err < 1e-5 * v);
}

#[test]
fn scaling_and_extrapolation() {
    let p = LinearSpectrum::gm2012_z0();
    let q = p.scaled(0.25).unwrap();
    for k in [1e-5, 0.1, 0.123, 100.0] {
        assert!((q.eval(k) / p.eval(k) - 0.25).abs() < 1e-14, "k = {k}");
    }
    assert!((q.sigma8() / p.sigma8() - 0.5).abs() < 1e-12);
    assert!(matches!(
        p.scaled(-1.0),
        Err(Error::InvalidParameter { .. })
    ));
    // Power laws are continuous at the ends and have sensible slopes (≈ n_s below, ≈ −3 above).
    let (lo, hi) = p.extrapolation_slopes();
    assert!(
        (lo - 0.95).abs() < 0.05 && (-3.0..-2.4).contains(&hi),
        "{lo} {hi}"
    );
    assert!((p.eval(p.k_min() * (1.0 - 1e-12)) / p.eval(p.k_min()) - 1.0).abs() < 1e-9);
    assert!((p.eval(p.k_max() * (1.0 + 1e-12)) / p.eval(p.k_max()) - 1.0).abs() < 1e-9);
    assert_eq!(p.region(1e-5), Region::Below);
    assert_eq!(p.region(60.0), Region::Above);
    assert_eq!(p.region(1.0), Region::Table);
    let report = p.extrapolation_in(1e-5, 1.0).unwrap();
    assert!(report.to_string().contains("beyond the linear table"));
    assert_eq!((p.eval(0.0), p.eval(-1.0)), (0.0, 0.0));
}

#[test]
fn comma_separated_and_class_style_headers_parse() {
    let rows = power_law_rows(30);
    let csv: String = "k,P\n".to_string()
        + &rows
            .iter()
            .map(|(k, p)| format!("{k:e}, {p:e}\n"))
            .collect::<String>();
    let a = LinearSpectrum::parse(&csv, "csv", Columns::default()).unwrap();
    let class = "# Matter power spectrum P(k) at redshift z=0\n# for k=1e-3 to 191 h/Mpc,\n\
                 # number of wavenumbers equal to 30\n# 1:k (h/Mpc)   2:P (Mpc/h)^3   3:P_cb\n\n"
        .to_string()
        + &rows
            .iter()
            .map(|(k, p)| format!("  {k:.12e}\t{:.12e}  {p:.12e}\n", 2.0 * p))
            .collect::<String>();
    let b = LinearSpectrum::parse(&class, "pk.dat", Columns::new(0, 2)).unwrap();
    assert_eq!(b.header().len(), 4);
    assert_eq!(a.nodes().0.len(), 30);
    for (k, p) in &rows {
        assert!((a.eval(*k) / p - 1.0).abs() < 1e-12);
        assert!((b.eval(*k) / p - 1.0).abs() < 1e-12);
    }
    let wide = LinearSpectrum::parse(&class, "pk.dat", Columns::new(0, 1)).unwrap();
    assert!((wide.eval(rows[3].0) / rows[3].1 - 2.0).abs() < 1e-12);
}

fn parse_err(text: &str, columns: Columns) -> Error {
    LinearSpectrum::parse(text, "test.dat", columns).unwrap_err()
}

#[test]
fn bad_tables_give_the_right_error() {
    let good = power_law_rows(25);
    let with = |i: usize, row: (f64, f64)| {
        let mut rows = good.clone();
        rows[i] = row;
        table(&rows)
    };
    let e = parse_err(&with(10, (good[9].0, good[10].1)), Columns::default());
    assert!(matches!(e, Error::NonIncreasingK { line: 11, .. }), "{e}");
    let e = parse_err(&with(4, (good[4].0, -2.0)), Columns::default());
    assert!(
        matches!(e, Error::InvalidPower { line: 5, p, .. } if p == -2.0),
        "{e}"
    );
    assert!(e.to_string().starts_with("test.dat:5: P = -2"), "{e}");
    let e = parse_err(&with(7, (good[7].0, f64::NAN)), Columns::default());
    assert!(matches!(e, Error::InvalidPower { line: 8, .. }), "{e}");
    let e = parse_err(&with(0, (f64::NAN, 1.0)), Columns::default());
    assert!(matches!(e, Error::InvalidK { line: 1, .. }), "{e}");
    let e = parse_err(&with(0, (-1e-3, 1.0)), Columns::default());
    assert!(matches!(e, Error::InvalidK { line: 1, .. }), "{e}");
    let e = parse_err(&table(&good[..12]), Columns::default());
    assert!(
        matches!(
            e,
            Error::TooFewPoints {
                found: 12,
                min: MIN_POINTS,
                ..
            }
        ),
        "{e}"
    );
    let e = parse_err(&table(&good), Columns::new(0, 2));
    assert!(
        matches!(
            e,
            Error::MissingColumn {
                line: 1,
                column: 2,
                found: 2,
                ..
            }
        ),
        "{e}"
    );
    let e = parse_err(&table(&good), Columns::new(1, 1));
    assert!(matches!(e, Error::InvalidParameter { .. }), "{e}");
    // P in the k column: not increasing (the spectrum turns over).
    let e = parse_err(&table(&good), Columns::new(1, 0));
    assert!(matches!(e, Error::NonIncreasingK { .. }), "{e}");
    let text = table(&good).replacen("e", "x", 1);
    assert!(matches!(
        parse_err(&text, Columns::default()),
        Error::Parse { line: 1, .. }
    ));
    let e = LinearSpectrum::from_file("/nonexistent/pk.dat").unwrap_err();
    assert!(matches!(e, Error::Io { .. }) && e.to_string().contains("/nonexistent/pk.dat"));
    let e = LinearSpectrum::from_nodes(vec![1.0; 3], vec![1.0; 2]).unwrap_err();
    assert!(matches!(e, Error::LengthMismatch { .. }));
}

#[test]
fn reads_files_and_grids() {
    let path = std::env::temp_dir().join(format!("pt_spectra_linear_{}.dat", std::process::id()));
    std::fs::write(&path, table(&power_law_rows(22))).unwrap();
    let p = LinearSpectrum::from_file(&path).unwrap();
    std::fs::remove_file(&path).unwrap();
    assert_eq!(p.origin(), path.display().to_string());
    let grid = LogGrid::new(1e-3, 10.0, 41).unwrap();
    let pts = grid.points();
    assert_eq!((pts[0], pts[40]), (1e-3, 10.0));
    assert!((pts[10] / 1e-2 - 1.0).abs() < 1e-12);
    assert!(LogGrid::new(1.0, 0.5, 10).is_err() && LogGrid::new(1.0, 2.0, 1).is_err());
    let f = LinearSpectrum::from_fn(&grid, |k| k.powf(-1.5)).unwrap();
    assert!((f.eval(0.3) / 0.3f64.powf(-1.5) - 1.0).abs() < 1e-12);
    assert!((f.eval(100.0) / 100f64.powf(-1.5) - 1.0).abs() < 1e-9);
    assert!(LinearSpectrum::from_fn(&grid, |k| 1.0 - k).is_err());
    // The small-x series joins the closed form at x = 1e-2.
    let x: f64 = 1e-2;
    let closed = 3.0 * (x.sin() - x * x.cos()) / x.powi(3);
    assert!((top_hat(x * (1.0 - 1e-12)) - closed).abs() < 1e-9);
}
