//! `real --bias-terms` and `real --bias B1 --b2 … --bs … --b3 …`: the columns, P_gg and P_gm of the bias
//! expansion, and the refusals.

use super::{column_names, fails_naming, rows, run};

#[test]
fn bias_columns_and_galaxy_spectra() {
    let grid = [
        "--k-min",
        "0.02",
        "--k-max",
        "0.2",
        "--nk",
        "4",
        "--precision",
        "fast",
    ];
    let args = |extra: &[&'static str]| {
        let mut a = vec!["real", "--model", "1l-spt"];
        a.extend(grid);
        a.extend(extra);
        a
    };
    let (ok, plain, err) = run(&args(&[]));
    assert!(ok, "{err}");
    let (ok, out, err) = run(&args(&[
        "--bias-terms",
        "--bias",
        "2",
        "--b2",
        "0.5",
        "--bs",
        "-0.3",
        "--b3",
        "0.2",
        "--bias-convention",
        "fastpt",
    ]));
    assert!(ok, "{err}");
    assert!(!err.contains("warning"), "{err}");
    // The same bias in velocileptors' convention (the default: bs s², b1 b3 sig3nl), and in
    // CLASS-PT's (b2 + (4/3)bs, b_G2 = bs, b_Γ3 = −(b3 + 15 bs)/6): the same table but its header.
    for (extra, note) in [
        (
            vec!["--b2", "0.5", "--bs", "-0.15", "--b3", "0.4"],
            "warning: --bs and --b3 of real",
        ),
        (
            vec![
                "--b2",
                "0.3",
                "--bs",
                "-0.15",
                "--b3",
                "0.30833333333333335",
                "--bias-convention",
                "classpt",
            ],
            "given in CLASS-PT's: b1 = 2, b2 = 0.3",
        ),
    ] {
        let mut a = args(&["--bias-terms", "--bias", "2"]);
        a.extend(extra);
        let (ok, same, err) = run(&a);
        assert!(ok, "{err}");
        assert!(err.contains(note) || same.contains(note), "{note}: {err}");
        for (x, y) in rows(&same).iter().zip(rows(&out)) {
            for (u, v) in x.iter().zip(&y) {
                assert!((u - v).abs() <= 1e-12 * v.abs(), "{x:?} vs {y:?}");
            }
        }
    }
    let names = column_names(&out);
    for name in [
        "Pd1d2",
        "err_Pd1d2",
        "Ps2s2",
        "Pt1s2",
        "sig3nl",
        "err_sig3nl",
        "P_gg",
        "err_P_gg",
        "P_gm",
    ] {
        assert!(names.contains(&name), "{name}: {names:?}");
    }
    assert!(
        out.contains("sigma4 = int P^2") && out.contains("b3nl = 0.2"),
        "{out}"
    );
    let plain_names = column_names(&plain);
    let (plain, table) = (rows(&plain), rows(&out));
    let col = |n: &str| names.iter().position(|&c| c == n).unwrap();
    for (p, r) in plain.iter().zip(&table) {
        // The matter columns (and their errors) are those of the plain run, by name.
        for (j, name) in plain_names.iter().enumerate() {
            assert_eq!(p[j], r[col(name)], "{name}");
        }
        let (dd, b1, b2, bs, b3) = (r[col("P_dd")], 2.0, 0.5, -0.3, 0.2);
        let gg = b1 * b1 * dd
            + b1 * b2 * r[col("Pd1d2")]
            + 0.25 * b2 * b2 * r[col("Pd2d2")]
            + b1 * bs * r[col("Pd1s2")]
            + 0.5 * b2 * bs * r[col("Pd2s2")]
            + 0.25 * bs * bs * r[col("Ps2s2")]
            + 2.0 * b1 * b3 * r[col("sig3nl")];
        let gm = b1 * dd
            + 0.5 * b2 * r[col("Pd1d2")]
            + 0.5 * bs * r[col("Pd1s2")]
            + b3 * r[col("sig3nl")];
        // The table prints 10 significant digits.
        assert!(
            (r[col("P_gg")] - gg).abs() < 1e-8 * gg.abs(),
            "{} vs {gg}",
            r[col("P_gg")]
        );
        assert!(
            (r[col("P_gm")] - gm).abs() < 1e-8 * gm.abs(),
            "{} vs {gm}",
            r[col("P_gm")]
        );
    }
    fails_naming(&[
        (args(&["--b2", "1"]), "--bias"),
        (
            vec!["real", "--model", "all", "--nk", "3", "--bias", "2"],
            "choose it with --model",
        ),
    ]);
}

/// `rsd --b2 …` (nonlinear bias), `--apar --aperp` and `--fiducial` (Alcock–Paczynski): the header
/// says so, α = 1 changes the multipoles by the interpolation only, and bad combinations are refused.
#[test]
fn nonlinear_bias_and_alcock_paczynski_in_rsd() {
    let base = [
        "rsd",
        "--real",
        "1l-spt",
        "--rsd",
        "tns",
        "--bias",
        "2",
        "--k-min",
        "0.03",
        "--k-max",
        "0.2",
        "--nk",
        "3",
        "--precision",
        "fast",
    ];
    let args = |extra: &[&'static str]| {
        let mut a = base.to_vec();
        a.extend(extra);
        a
    };
    let (ok, plain, err) = run(&base);
    assert!(ok, "{err}");
    let (ok, b2_zero, err) = run(&args(&["--b2", "0"]));
    assert!(ok, "{err}");
    assert_eq!(
        rows(&plain),
        rows(&b2_zero),
        "b2 = bs = b3 = 0 is linear bias"
    );
    assert!(b2_zero.contains("Beutler et al. 2017"));
    let (ok, identity, err) = run(&args(&["--apar", "1", "--aperp", "1"]));
    assert!(ok, "{err}");
    assert!(identity.contains("Alcock-Paczynski: apar = 1, aperp = 1"));
    for (a, b) in rows(&plain).iter().zip(rows(&identity)) {
        for j in 1..4 {
            assert!((a[j] - b[j]).abs() < 1e-5 * a[1], "{a:?} vs {b:?}");
        }
    }
    let (ok, fid, err) = run(&args(&[
        "--z",
        "0.5",
        "--cosmology",
        "planck2018",
        "--fiducial",
        "gm2012",
    ]));
    assert!(ok, "{err}");
    assert!(fid.contains("Alcock-Paczynski: apar = 0.9"), "{fid}");
    fails_naming(&[
        (
            args(&["--apar", "0", "--aperp", "1"]),
            "apar = 0: must be in [0.5, 2]",
        ),
        (args(&["--apar", "1.1"]), "--aperp"),
        (
            args(&["--fiducial", "gm2012"]),
            "must be positive for the Alcock-Paczynski",
        ),
        (
            args(&["--apar", "1", "--aperp", "1", "--shot-noise", "100"]),
            "noise with the Alcock-Paczynski",
        ),
        (
            vec!["rsd", "--rsd", "kaiser", "--nk", "3", "--b2", "1"],
            "Kaiser is linear in the bias",
        ),
    ]);
}

/// `rsd --xi`: linear Kaiser ξ_ℓ are the Kaiser factors times the transforms of P_lin (the transform
/// is linear), ξ2 with the i² = −1 of its definition included in both.
#[test]
fn correlation_function_multipoles_of_linear_kaiser() {
    let grid = ["--k-min", "1e-4", "--k-max", "1", "--nk", "300"];
    let mut rsd = vec![
        "rsd", "--real", "linear", "--rsd", "kaiser", "--bias", "2", "--f", "0.5",
    ];
    rsd.extend(grid);
    rsd.extend(["--xi", "--s-min", "20", "--s-max", "150", "--ns", "6"]);
    let (ok, out, err) = run(&rsd);
    assert!(ok, "{err}");
    assert!(out.contains("by FFTLog"), "{out}");
    let mut real = vec!["real", "--model", "linear"];
    real.extend(grid);
    let (ok, lin, err) = run(&real);
    assert!(ok, "{err}");
    let lin = rows(&lin);
    let (k, p): (Vec<f64>, Vec<f64>) = lin.iter().map(|r| (r[0], r[1])).unzip();
    let table = rows(&out);
    let s: Vec<f64> = table.iter().map(|r| r[0]).collect();
    let (b, f) = (2.0, 0.5);
    let factors = [
        b * b + 2.0 * b * f / 3.0 + f * f / 5.0,
        4.0 * b * f / 3.0 + 4.0 * f * f / 7.0,
        8.0 * f * f / 35.0,
    ];
    for (j, (l, factor)) in [0, 2, 4].into_iter().zip(factors).enumerate() {
        let want = pt_spectra::hankel::xi_from_pk(&k, &p, l, &s).unwrap();
        let scale = want.iter().fold(0.0_f64, |m, v| m.max(v.abs())) * factor;
        for (row, w) in table.iter().zip(&want) {
            assert!(
                (row[1 + j] - factor * w).abs() < 1e-6 * scale,
                "l = {l}: {} vs {}",
                row[1 + j],
                factor * w
            );
        }
    }
}
