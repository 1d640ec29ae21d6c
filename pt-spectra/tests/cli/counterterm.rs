//! `--cs2`: the EFT counterterm −(2, 4, 6) c_s² k² P_lin of P_dd, P_dt, P_tt in `real`, through the RSD
//! models in `rsd`, and fitted by `fit --free cs2`; c_s² = 0 reproduces the committed fixture tables.

use super::*;

/// The fixture directory (the tables `tests/fixtures/make.sh` wrote with the binary of its time).
fn fixtures() -> std::path::PathBuf {
    std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures")
}

/// `run` in the fixture directory, so that file names in headers read as when the fixtures were made.
fn run_in_fixtures(args: &[&str]) -> (bool, String, String) {
    let out = Command::new(env!("CARGO_BIN_EXE_pt-spectra"))
        .current_dir(fixtures())
        .args(args)
        .output()
        .expect("the binary runs");
    let text = |b: Vec<u8>| String::from_utf8(b).expect("utf-8 output");
    (out.status.success(), text(out.stdout), text(out.stderr))
}

/// The values of the column `name` of a table whose names line starts `# k `.
fn column(text: &str, name: &str) -> Vec<f64> {
    column_of(text, "# k ", name)
}

/// The values of the column `name` of a table whose names line starts with `start`.
fn column_of(text: &str, start: &str, name: &str) -> Vec<f64> {
    let j = column_names_of(text, start)
        .iter()
        .position(|&c| c == name)
        .unwrap_or_else(|| panic!("no column {name}"));
    rows(text).iter().map(|r| r[j]).collect()
}

const GRID: [&str; 8] = [
    "--k-min",
    "0.02",
    "--k-max",
    "0.25",
    "--nk",
    "10",
    "--precision",
    "fast",
];

#[test]
fn zero_cs2_reproduces_the_fixture_tables_byte_for_byte() {
    // The fixtures were written before the counterterm existed (make.sh's commands).
    let real = ["real", "--model", "1l-rpt-n1", "--terms"];
    let rsd = [
        "rsd",
        "--rsd",
        "tns",
        "--real",
        "1l-spt",
        "--terms",
        "--no-wiggle",
        "--bias-file",
        "halo.dat",
        "--noise-file",
        "halo.dat",
    ];
    let fit = [
        "fit",
        "--data",
        "mock.dat",
        "--rsd",
        "tns",
        "--real",
        "1l-spt",
        "--fog",
        "lorentzian",
        "--sigma0",
        "4",
        "--free",
        "f,ab",
        "--ells",
        "0",
        "--k-max",
        "0.1:0.2:0.05",
        "--precision",
        "fast",
    ];
    for (args, fixture) in [
        ([&real[..], &GRID[..]].concat(), "prop_n1.dat"),
        ([&rsd[..], &GRID[..]].concat(), "rsd_halo.dat"),
        (fit.to_vec(), "fit_ab.dat"),
    ] {
        let want = std::fs::read_to_string(fixtures().join(fixture)).unwrap();
        for extra in [&[][..], &["--cs2", "0"][..]] {
            let (ok, out, err) = run_in_fixtures(&[&args[..], extra].concat());
            assert!(ok, "{err}");
            assert!(out == want, "{fixture} {extra:?} differs");
        }
    }
}

#[test]
fn real_adds_minus_2_4_6_cs2_k2_p_lin_exactly_and_says_so() {
    let cs2 = 1.7;
    let base = [&["real", "--model", "1l-spt", "--terms"][..], &GRID[..]].concat();
    let (ok, without, err) = run(&base);
    assert!(ok, "{err}");
    let (ok, with, err) = run(&[&base[..], &["--cs2", "1.7"][..]].concat());
    assert!(ok, "{err}");
    assert!(
        with.contains("EFT counterterm cs2 = 1.7 (Mpc/h)^2"),
        "{with}"
    );
    assert!(!without.contains("counterterm"));
    let (k, p_lin) = (column(&with, "k"), column(&with, "P_lin"));
    assert_eq!(p_lin, column(&without, "P_lin"));
    for (pair, factor) in [("dd", 2.0), ("dt", 4.0), ("tt", 6.0)] {
        let (a, b) = (
            column(&without, &format!("P_{pair}")),
            column(&with, &format!("P_{pair}")),
        );
        let ct = column(&with, &format!("P_ct_{pair}"));
        for i in 0..k.len() {
            let want = -factor * cs2 * k[i] * k[i] * p_lin[i];
            // 10 printed digits of each value.
            let digits = 1e-9 * (a[i].abs() + b[i].abs() + want.abs());
            assert!((b[i] - a[i] - want).abs() < digits, "{pair} k={}", k[i]);
            assert!(
                (ct[i] - want).abs() < 1e-9 * want.abs(),
                "{pair} k={}",
                k[i]
            );
        }
        // Exact: the errors are unchanged.
        let e = format!("err_P_{pair}");
        assert_eq!(column(&without, &e), column(&with, &e));
    }
}

#[test]
fn rsd_carries_the_counterterm_through_kaiser_and_scoccimarro() {
    // Linear real-space spectra, no FoG: closed-form multipoles of the counterterm-shifted
    // P_dd = P(1 − 2ck²), P_dt = P(1 − 4ck²), P_tt = P(1 − 6ck²).
    let (c, b, f) = (-2.5, 1.8, 0.6);
    let common = [
        "rsd", "--real", "linear", "--cs2", "-2.5", "--bias", "1.8", "--f", "0.6", "--ells",
        "0,2,4",
    ];
    for rsd in ["kaiser", "scoccimarro"] {
        let (ok, out, err) = run(&[&common[..], &["--rsd", rsd], &GRID[..]].concat());
        assert!(ok, "{err}");
        assert!(out.contains("cs2 = -2.5"), "{out}");
        let (ok, lin, err) = run(&[&["real", "--model", "linear"][..], &GRID[..]].concat());
        assert!(ok, "{err}");
        let (k, p) = (column(&lin, "k"), column(&lin, "P_lin"));
        for i in 0..k.len() {
            let x = c * k[i] * k[i];
            let (dd, dt, tt) = (
                p[i] * (1.0 - 2.0 * x),
                p[i] * (1.0 - 4.0 * x),
                p[i] * (1.0 - 6.0 * x),
            );
            let want = if rsd == "kaiser" {
                // (b + fμ²)² P_dd.
                [
                    dd * (b * b + 2.0 * b * f / 3.0 + f * f / 5.0),
                    dd * (4.0 * b * f / 3.0 + 4.0 * f * f / 7.0),
                    dd * 8.0 * f * f / 35.0,
                ]
            } else {
                // b² P_dd + 2bfμ² P_dt + f²μ⁴ P_tt.
                [
                    b * b * dd + 2.0 * b * f * dt / 3.0 + f * f * tt / 5.0,
                    4.0 * b * f * dt / 3.0 + 4.0 * f * f * tt / 7.0,
                    8.0 * f * f * tt / 35.0,
                ]
            };
            for (l, w) in [0, 2, 4].into_iter().zip(want) {
                let got = column(&out, &format!("P{l}"))[i];
                assert!(
                    (got - w).abs() < 1e-9 * p[i] * 4.0,
                    "{rsd} P{l} k={}: {got} {w}",
                    k[i]
                );
            }
        }
    }
}

#[test]
fn fit_recovers_an_injected_cs2_with_f_and_sigma0() {
    // Mock: TNS + 1L-SPT, Lorentzian FoG σ0 = 4 Mpc/h, c_s² = 1.3 (Mpc/h)², f = f(0) = 0.483147, at
    // z = 0, printed with 10 digits; errors 0.1% of P0 (no noise added). The fit starts at f = 0.55,
    // σ0 = 3, c_s² = 0.
    let dir = scratch("fit_cs2");
    let (ok, out, err) = run(&[
        "rsd",
        "--rsd",
        "tns",
        "--real",
        "1l-spt",
        "--fog",
        "lorentzian",
        "--sigma0",
        "4",
        "--cs2",
        "1.3",
        "--k-min",
        "0.02",
        "--k-max",
        "0.2",
        "--nk",
        "16",
        "--precision",
        "fast",
    ]);
    assert!(ok, "{err}");
    // f(z) as the header states it, in full.
    let f_true: f64 = out
        .split(", f = ")
        .nth(1)
        .and_then(|t| t.split(',').next())
        .and_then(|t| t.parse().ok())
        .expect("f in the header");
    let text: String = rows(&out)
        .iter()
        .map(|r| {
            let s = 1e-3 * r[1];
            format!(
                "{:e} {:e} {s:e} {:e} {s:e} {:e} {s:e}\n",
                r[0], r[1], r[2], r[3]
            )
        })
        .collect();
    let mock = write(&dir, "mock.dat", &text);
    let contour = dir.join("contour.dat").display().to_string();
    let (ok, out, err) = run(&[
        "fit",
        "--data",
        &mock,
        "--rsd",
        "tns",
        "--real",
        "1l-spt",
        "--fog",
        "lorentzian",
        "--free",
        "f,sigma0,cs2",
        "--f",
        "0.55",
        "--sigma0",
        "3",
        "--ells",
        "0,2,4",
        "--k-max",
        "0.2",
        "--precision",
        "fast",
        "--contour",
        "f,cs2",
        "--contour-out",
        &contour,
        "--contour-points",
        "5",
    ]);
    assert!(ok, "{err}");
    assert!(
        out.contains("free f,sigma0,cs2") && out.contains("cs2 = 0 (Mpc/h)^2"),
        "{out}"
    );
    let get = |name: &str| column_of(&out, "# k_max ", name)[0];
    let (cs2, f, sigma0) = (get("cs2"), get("f"), get("sigma0"));
    println!(
        "f = {f}, sigma0 = {sigma0}, cs2 = {cs2} [{}, {}]",
        get("cs2_lo"),
        get("cs2_hi")
    );
    // The mock's 10 printed digits and the minimiser's tolerance allow ~1e-7; the interval is 2e-2.
    assert!((f - f_true).abs() < 1e-6, "{f} vs {f_true}");
    assert!((sigma0 - 4.0).abs() < 1e-5, "{out}");
    assert!((cs2 - 1.3).abs() < 1e-5, "{out}");
    // The Δχ² = 3.53 interval of c_s² holds the truth and is finite; χ² ~ 0 (the mock is the model).
    assert!(get("cs2_lo") < 1.3 && get("cs2_hi") > 1.3, "{out}");
    assert!(get("cs2_hi") - get("cs2_lo") < 0.5, "{out}");
    assert!(get("chi2") < 1e-3, "{out}");
    // The contour table names c_s² as a parameter, with σ0 re-minimised.
    let c = std::fs::read_to_string(&contour).unwrap();
    let names = column_names_of(&c, "# k_max ");
    assert_eq!(
        names,
        [
            "k_max",
            "i",
            "j",
            "f",
            "cs2",
            "chi2",
            "delta_chi2",
            "sigma0"
        ]
    );
    assert_eq!(rows(&c).len(), 25);
}

#[test]
fn bad_cs2_values_are_named_errors() {
    fails_naming(&[
        (vec!["real", "--cs2", "nan"], "cs2"),
        (vec!["real", "--cs2", "inf"], "must be finite"),
        (vec!["rsd", "--cs2", "-inf"], "must be finite"),
        (
            vec!["fit", "--data", "x.dat", "--cs2", "NaN"],
            "must be finite",
        ),
        (vec!["real", "--cs2", "one"], "is not a number"),
        (
            vec!["fit", "--data", "x.dat", "--free", "f,cs3"],
            "f, sigma0, ab, cs2",
        ),
    ]);
}

#[test]
fn two_loop_eft_prints_its_templates_and_adds_each_counterterm_linearly() {
    // `2l-eft` is 2-loop SPT plus Σ X T_X: the run with counterterms minus the run without is that
    // sum of the printed templates, and T_dd_cs2 is the closed form −2 k² P_lin.
    let mut base = vec!["real", "--model", "2l-eft", "--terms"];
    base.extend(GRID);
    let (ok, zero, err) = run(&base);
    assert!(ok, "{err}");
    assert!(err.contains("every counterterm of 2l-eft is 0"), "{err}");
    assert!(zero.contains("# warning: every counterterm is 0"));
    let mut with = base.clone();
    with.extend(["--ct", "cs2=1.5", "--ct", "cs2_1loop=-0.5", "--ct", "c4=2"]);
    let (ok, out, err) = run(&with);
    assert!(ok && !err.contains("warning"), "{err}");
    assert!(out.contains("cs2 = 1.5 (Mpc/h)^2, cs2_1loop = -0.5 (Mpc/h)^2, c4 = 2 (Mpc/h)^4"));
    let (k, lin) = (column(&zero, "k"), column(&zero, "P_lin"));
    for pair in ["dd", "dt", "tt"] {
        let p0 = column(&zero, &format!("P_{pair}"));
        let p = column(&out, &format!("P_{pair}"));
        let t = |c: &str| column(&zero, &format!("T_{pair}_{c}"));
        let (a, b, c) = (t("cs2"), t("cs2_1loop"), t("c4"));
        for i in 0..k.len() {
            let want = 1.5 * a[i] - 0.5 * b[i] + 2.0 * c[i];
            assert!(
                (p[i] - p0[i] - want).abs() < 1e-8 * p0[i].abs(),
                "{pair} k={}",
                k[i]
            );
        }
    }
    let t = column(&zero, "T_dd_cs2");
    for i in 0..k.len() {
        assert!((t[i] + 2.0 * k[i] * k[i] * lin[i]).abs() < 1e-8 * t[i].abs());
    }
    let fails = |extra: &[&str], needle: &str| {
        let mut args = vec!["real", "--model", "2l-eft"];
        args.extend(GRID);
        args.extend(extra);
        let (ok, _, err) = run(&args);
        assert!(!ok && err.contains(needle), "{extra:?}: {err}");
    };
    fails(&["--ct", "cs3=1"], "available: cs2, cs2_1loop, c4");
    fails(&["--ct", "c4"], "NAME=VALUE");
    fails(&["--ct", "c4=inf"], "finite");
    fails(&["--ct", "cs2=1", "--cs2", "2"], "given twice");
    let mut spt = vec!["real", "--model", "2l-spt", "--ct", "c4=1"];
    spt.extend(GRID);
    let (ok, _, err) = run(&spt);
    assert!(!ok && err.contains("2l-eft and 2l-eft-ir"), "{err}");
}
