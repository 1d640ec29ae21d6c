//! `halo` and the S/N: b(k) and P_εε recovered from synthetic spectra, fed to `rsd`.

use super::*;

#[test]
fn halo_recovers_bias_and_noise_that_feed_rsd() {
    // Synthetic P_mm, P_mh = b P_mm, P_hh = b² P_mm + P_εε: `halo` returns b(k) and P_εε to the
    // printed digits, and its table, read by column name, gives rsd the SN = b² P_lin/P_εε.
    let dir = scratch("halo");
    let k: Vec<f64> = (0..12).map(|i| 0.01 * 1.3f64.powi(i)).collect();
    let b = |k: f64| 2.6 * (1.0 + 1.5 * k * k);
    let eps = |k: f64| 0.65 / 1.79e-5 * (1.0 - 0.2 * k);
    let pmm = |k: f64| 2.0e4 * (k / 0.05).powf(-1.2);
    let table = |p: &dyn Fn(f64) -> f64| -> String {
        k.iter()
            .map(|&k| format!("{k:e} {:e} {:e}\n", p(k), 0.01 * p(k)))
            .collect()
    };
    let mm = write(&dir, "pmm.dat", &table(&pmm));
    let mh = write(&dir, "pmh.dat", &table(&|k| b(k) * pmm(k)));
    let hh = write(&dir, "phh.dat", &table(&|k| b(k) * b(k) * pmm(k) + eps(k)));
    let out = dir.join("halo.dat").display().to_string();
    let (ok, _, err) = run(&[
        "halo",
        "--pmm",
        &mm,
        "--pmh",
        &mh,
        "--phh",
        &hh,
        "--number-density",
        "1.79e-5",
        "--out",
        &out,
    ]);
    assert!(ok, "{err}");
    let text = std::fs::read_to_string(&out).unwrap();
    assert_eq!(column_names(&text), ["k", "b", "P_eps", "P_eps_n"]);
    for (r, &ki) in rows(&text).iter().zip(&k) {
        assert!((r[0] / ki - 1.0).abs() < 1e-9);
        assert!((r[1] / b(ki) - 1.0).abs() < 1e-9, "{r:?}");
        assert!((r[2] / eps(ki) - 1.0).abs() < 1e-9, "{r:?}");
        assert!(
            (r[3] / (0.65 * (1.0 - 0.2 * ki)) - 1.0).abs() < 1e-9,
            "{r:?}"
        );
    }
    // With the error columns: err_b and err_P_eps from the first-order formulas.
    let (ok, with_errors, err) = run(&[
        "halo",
        "--pmm",
        &mm,
        "--pmh",
        &mh,
        "--phh",
        &hh,
        "--columns",
        "1,2,3",
    ]);
    assert!(ok, "{err}");
    assert_eq!(
        column_names(&with_errors),
        ["k", "b", "P_eps", "err_b", "err_P_eps"]
    );
    for (r, &ki) in rows(&with_errors).iter().zip(&k) {
        let (bk, m) = (b(ki), pmm(ki));
        let (s_mm, s_mh, s_hh) = (0.01 * m, 0.01 * bk * m, 0.01 * (bk * bk * m + eps(ki)));
        let err_b = ((s_mh / m).powi(2) + (bk * s_mm / m).powi(2)).sqrt();
        let err_e = (s_hh.powi(2) + (2.0 * bk * s_mh).powi(2) + (bk * bk * s_mm).powi(2)).sqrt();
        assert!((r[3] / err_b - 1.0).abs() < 1e-6, "{r:?} {err_b}");
        assert!((r[4] / err_e - 1.0).abs() < 1e-6, "{r:?} {err_e}");
    }
    // rsd reads b and P_eps by name from the halo table; at the table's nodes (no interpolation) the
    // real-space S/N of linear input is b² P_lin/P_εε.
    let nodes = write(
        &dir,
        "k.dat",
        &k[2..10]
            .iter()
            .map(|k| format!("{k:e}\n"))
            .collect::<String>(),
    );
    let (ok, rsd, err) = run(&[
        "rsd",
        "--rsd",
        "kaiser",
        "--real",
        "linear",
        "--k-file",
        &nodes,
        "--bias-file",
        &out,
        "--noise-file",
        &out,
    ]);
    assert!(ok, "{err}");
    let (ok, lin, err) = run(&["real", "--model", "linear", "--k-file", &nodes]);
    assert!(ok, "{err}");
    let names = column_names(&rsd);
    let col = |n: &str| names.iter().position(|&x| x == n).unwrap();
    for (r, l) in rows(&rsd).iter().zip(rows(&lin)) {
        let (bk, e) = (b(r[0]), eps(r[0]));
        assert!((r[col("P_eps")] / e - 1.0).abs() < 1e-8, "{r:?}");
        let want = bk * bk * l[1] / e;
        assert!(
            (r[col("SN")] / want - 1.0).abs() < 1e-8,
            "{} vs {want}",
            r[col("SN")]
        );
    }
    let shifted = write(
        &dir,
        "shifted.dat",
        &table(&pmm).replacen(&format!("{:e}", k[3]), "0.0234", 1),
    );
    let bad = write(&dir, "bad.dat", "0.01 1e4\n0.02 x\n");
    fails_naming(&[
        (
            vec!["halo", "--pmm", &mm, "--pmh", &shifted, "--phh", &hh],
            "row 4 k = 0.0234",
        ),
        (
            vec!["halo", "--pmm", &mm, "--pmh", &mh, "--phh", &bad],
            "`x`",
        ),
        (
            vec![
                "halo",
                "--pmm",
                &mm,
                "--pmh",
                &mh,
                "--phh",
                "/nonexistent/p",
            ],
            "/nonexistent/p",
        ),
        (
            vec![
                "halo",
                "--pmm",
                &mm,
                "--pmh",
                &mh,
                "--phh",
                &hh,
                "--columns",
                "1,1",
            ],
            "--columns",
        ),
        (
            vec![
                "halo",
                "--pmm",
                &mm,
                "--pmh",
                &mh,
                "--phh",
                &hh,
                "--number-density",
                "-1",
            ],
            "number density",
        ),
    ]);
}
