//! `fit --rsd ept` on what surveys measure: correlation-function multipoles (`--xi`) and a range per
//! multipole (`--k-range-ell`).

use super::{column_names_of, fails_naming, rows, run};

fn value(out: &str, first: &str, name: &str, row: usize) -> f64 {
    let names = column_names_of(out, first);
    let j = names
        .iter()
        .position(|c| *c == name)
        .unwrap_or_else(|| panic!("no column {name} in {names:?}"));
    rows(out)[row][j]
}

/// ξ_0, ξ_2 made by `rsd --rsd ept --xi` with 2% errors are fitted by `fit --xi`: f, b1 free, α0, α2
/// marginalised; the truth is recovered well within the errors at two s_max.
#[test]
fn xi_fit_recovers_the_parameters_of_its_own_correlation_function() {
    let dir = super::scratch("xi_fit");
    let (ok, out, err) = run(&[
        "rsd",
        "--rsd",
        "ept",
        "--bias",
        "2",
        "--b2",
        "-0.4",
        "--alpha0",
        "8",
        "--alpha2",
        "-3",
        "--f",
        "0.7",
        "--ells",
        "0,2",
        "--xi",
        "--s-min",
        "20",
        "--s-max",
        "160",
        "--ns",
        "29",
        "--precision",
        "fast",
    ]);
    assert!(ok, "{err}");
    assert!(
        out.contains("Landy-Szalay"),
        "the header says how xi is made"
    );
    let table = rows(&out);
    let (m0, m2) = table.iter().fold((0.0_f64, 0.0_f64), |(a, b), r| {
        (a.max(r[1].abs()), b.max(r[2].abs()))
    });
    let mut text = String::new();
    for r in &table {
        let w = 30.0 / r[0];
        text += &format!(
            "{} {} {} {} {}\n",
            r[0],
            r[1],
            0.02 * m0 * w,
            r[2],
            0.02 * m2 * w
        );
    }
    let data = super::write(&dir, "xi.txt", &text);
    let (ok, out, err) = run(&[
        "fit",
        "--rsd",
        "ept",
        "--xi",
        "--data",
        &data,
        "--data-columns",
        "1,2,3,4,5",
        "--data-ells",
        "0,2",
        "--ells",
        "0,2",
        "--free",
        "f,b1",
        "--b2",
        "-0.4",
        "--marginalise",
        "alpha0,alpha2",
        "--s-min",
        "20",
        "--s-max",
        "100,160",
        "--precision",
        "fast",
        "--bias",
        "1.8",
        "--f",
        "0.5",
    ]);
    assert!(ok, "{err}");
    for row in 0..2 {
        for (name, truth) in [("f", 0.7), ("b1", 2.0), ("alpha0", 8.0), ("alpha2", -3.0)] {
            let v = value(&out, "# s_max ", name, row);
            let e = value(&out, "# s_max ", &format!("err_{name}"), row);
            assert!(e > 0.0 && (v - truth).abs() < 0.05 * e, "{name}: {v} ± {e}");
        }
    }
    fails_naming(&[
        (
            vec![
                "fit", "--rsd", "ept", "--xi", "--data", &data, "--k-max", "0.2",
            ],
            "--s-max",
        ),
        (
            vec![
                "fit", "--rsd", "ept", "--xi", "--data", &data, "--window", &data,
            ],
            "--window",
        ),
        (vec!["fit", "--rsd", "tns", "--xi", "--data", &data], "--xi"),
        (vec!["rsd", "--rsd", "ept", "--xi", "--s-min", "0.01"], "s"),
    ]);
}

/// P4 corrupted (×3) above k = 0.1: with `--k-range-ell 4:0,0.1` the fit recovers the truth from
/// P0, P2 to 0.2 and P4 to 0.1 (and counts those points); without it, it does not.
#[test]
fn a_range_per_multipole_leaves_out_the_points_beyond_it() {
    let dir = super::scratch("ell_range_fit");
    let (ok, out, err) = run(&[
        "rsd",
        "--rsd",
        "ept",
        "--bias",
        "2",
        "--f",
        "0.7",
        "--alpha0",
        "5",
        "--k-min",
        "0.02",
        "--k-max",
        "0.2",
        "--nk",
        "25",
        "--precision",
        "fast",
    ]);
    assert!(ok, "{err}");
    let table = rows(&out);
    let mut text = String::new();
    for r in &table {
        let s = 0.01 * r[1];
        let p4 = if r[0] > 0.1 { 3.0 * r[3] } else { r[3] };
        text += &format!("{} {} {s} {} {s} {p4} {s}\n", r[0], r[1], r[2]);
    }
    let data = super::write(&dir, "data.txt", &text);
    let fit = |extra: &[&str]| {
        let mut args = vec![
            "fit",
            "--rsd",
            "ept",
            "--data",
            &data,
            "--ells",
            "0,2,4",
            "--free",
            "f,b1",
            "--marginalise",
            "alpha0",
            "--k-max",
            "0.2",
            "--precision",
            "fast",
            "--bias",
            "1.8",
            "--f",
            "0.6",
        ];
        args.extend_from_slice(extra);
        let (ok, out, err) = run(&args);
        assert!(ok, "{err}");
        out
    };
    let narrowed = fit(&["--k-range-ell", "4:0,0.1"]);
    assert!(narrowed.contains("l = 4: within [0, 0.1]"));
    let n_low = table.iter().filter(|r| r[0] <= 0.1).count();
    let points = value(&narrowed, "# k_max ", "points", 0);
    assert_eq!(points as usize, 2 * table.len() + n_low);
    for (name, truth) in [("f", 0.7), ("b1", 2.0)] {
        let v = value(&narrowed, "# k_max ", name, 0);
        let e = value(&narrowed, "# k_max ", &format!("err_{name}"), 0);
        assert!((v - truth).abs() < 0.05 * e, "{name}: {v} ± {e}");
    }
    let all = fit(&[]);
    let v = value(&all, "# k_max ", "f", 0);
    let e = value(&all, "# k_max ", "err_f", 0);
    assert!(
        (v - 0.7).abs() > 3.0 * e,
        "the corrupted P4 moves f: {v} ± {e}"
    );
    fails_naming(&[
        (
            vec![
                "fit",
                "--rsd",
                "ept",
                "--data",
                &data,
                "--k-range-ell",
                "6:0,0.1",
            ],
            "6",
        ),
        (
            vec![
                "fit",
                "--rsd",
                "ept",
                "--data",
                &data,
                "--k-range-ell",
                "4:0.1",
            ],
            "L:KMIN,KMAX",
        ),
        (
            vec![
                "fit",
                "--rsd",
                "ept",
                "--data",
                &data,
                "--ells",
                "0,4",
                "--k-range-ell",
                "4:0.2,0.1",
            ],
            "k_max",
        ),
        (
            vec![
                "fit",
                "--rsd",
                "tns",
                "--data",
                &data,
                "--k-range-ell",
                "4:0,0.1",
            ],
            "--k-range-ell",
        ),
    ]);
}

/// The paper's models through a window: one that cuts nothing (Q0 = 1 to s = 1e9 Mpc/h) leaves linear
/// Kaiser's multipoles as they are; --terms with a window, and a window in a paper model's fit, are
/// refused.
#[test]
fn paper_models_take_a_window() {
    let dir = super::scratch("paper_window");
    let mut text = String::from("# s Q0 Q2 Q4\n");
    for i in 0..600 {
        let s = 1e-3 * (1e12f64).powf(f64::from(i) / 599.0);
        text += &format!("{s:e} 1 0 0\n");
    }
    let window = super::write(&dir, "window.txt", &text);
    let base = [
        "rsd", "--rsd", "kaiser", "--real", "linear", "--bias", "2", "--f", "0.7", "--k-min",
        "0.02", "--k-max", "0.25", "--nk", "12",
    ];
    let (ok, plain, err) = run(&base);
    assert!(ok, "{err}");
    let mut windowed = base.to_vec();
    windowed.extend(["--window", &window]);
    let (ok, out, err) = run(&windowed);
    assert!(ok, "{err}");
    assert!(out.contains("wide-angle terms neglected"));
    let (a, b) = (rows(&plain), rows(&out));
    let largest = a.iter().fold(0.0_f64, |m, r| m.max(r[1]));
    for (r, w) in a.iter().zip(&b) {
        assert!((r[0] / w[0] - 1.0).abs() < 1e-12);
        for l in 1..4 {
            assert!(
                (r[l] - w[l]).abs() < 2e-5 * largest,
                "k {} column {l}: {} vs {}",
                r[0],
                r[l],
                w[l]
            );
        }
    }
    let mut terms = windowed.clone();
    terms.push("--terms");
    fails_naming(&[
        (terms, "--terms"),
        (
            vec![
                "fit", "--rsd", "tns", "--data", &window, "--window", &window,
            ],
            "--window",
        ),
    ]);
}
