//! `fit`: the best-fit model multipoles, Δχ² surfaces against a direct χ², the theory σ0.

use super::*;

#[test]
fn fit_writes_model_multipoles_and_contours_that_match_direct_chi2() {
    // Linear Kaiser, f and A_b free, no FoG: every χ² of the contour grid is the closed-form χ² of
    // the multipoles P0 = (A²b² + 2Abf/3 + f²/5) P_lin, P2 = (4Abf/3 + 4f²/7) P_lin, computed here;
    // the model table holds the closed forms at the best fit.
    let dir = scratch("fit_contour");
    let k_file = write(
        &dir,
        "k.dat",
        &(0..15)
            .map(|i| format!("{:e}\n", 0.01 * 1.25f64.powi(i)))
            .collect::<String>(),
    );
    let (ok, lin, err) = run(&["real", "--model", "linear", "--k-file", &k_file]);
    assert!(ok, "{err}");
    let lin = rows(&lin);
    let (b, f_true) = (2.0, 0.5);
    let model = |f: f64, a: f64, p: f64| {
        let ab = a * b;
        [
            p * (ab * ab + 2.0 * ab * f / 3.0 + f * f / 5.0),
            p * (4.0 * ab * f / 3.0 + 4.0 * f * f / 7.0),
        ]
    };
    let mut text = String::new();
    let mut data = Vec::new();
    for (i, r) in lin.iter().enumerate() {
        let m = model(f_true, 1.0, r[1]);
        let s = 0.01 * m[0];
        let shift = if i % 2 == 0 { 0.5 * s } else { -0.5 * s };
        let d = [m[0] + shift, m[1] - shift];
        text += &format!("{:e} {:e} {s:e} {:e} {s:e}\n", r[0], d[0], d[1]);
        data.push((r[0], r[1], d, s));
    }
    let mock = write(&dir, "mock.dat", &text);
    let (model_out, contour_out) = (
        dir.join("model.dat").display().to_string(),
        dir.join("contour.dat").display().to_string(),
    );
    let (ok, out, err) = run(&[
        "fit",
        "--data",
        &mock,
        "--data-columns",
        "1,2,3,4,5",
        "--data-ells",
        "0,2",
        "--ells",
        "0,2",
        "--rsd",
        "kaiser",
        "--real",
        "linear",
        "--fog",
        "none",
        "--bias",
        "2",
        "--free",
        "f,ab",
        "--k-max",
        "0.1,0.15",
        "--model-out",
        &model_out,
        "--contour",
        "f,ab",
        "--contour-out",
        &contour_out,
        "--contour-points",
        "11",
    ]);
    assert!(ok, "{err}");
    let fits = rows(&out);
    let chi2 = |f: f64, a: f64, k_max: f64| -> f64 {
        data.iter()
            .filter(|d| d.0 <= k_max * (1.0 + 1e-12))
            .map(|(_, p, d, s)| {
                let m = model(f, a, *p);
                ((d[0] - m[0]) / s).powi(2) + ((d[1] - m[1]) / s).powi(2)
            })
            .sum()
    };
    let contour = std::fs::read_to_string(&contour_out).unwrap();
    assert_eq!(
        column_names_of(&contour, "# k_max"),
        ["k_max", "i", "j", "f", "ab", "chi2", "delta_chi2"]
    );
    let grid = rows(&contour);
    assert_eq!(grid.len(), 2 * 11 * 11);
    // The inputs pass through 10 printed digits and the 1% errors amplify them 100 times: ~1e-7 of a
    // data point's share of χ², ~1e-6 of χ² in all.
    for r in &grid {
        let want = chi2(r[3], r[4], r[0]);
        assert!((r[5] / want - 1.0).abs() < 1e-5, "{r:?} vs {want}");
        let fit = fits.iter().find(|x| x[0] == r[0]).unwrap();
        assert!(
            (r[6] - (want - fit[8])).abs() < 1e-5 * want.max(1.0),
            "{r:?} {fit:?}"
        );
    }
    // The grid centre (i, j) = (5, 5) is the best fit, where Δχ² = 0.
    for fit in &fits {
        let centre = grid
            .iter()
            .find(|r| r[0] == fit[0] && r[1] == 5.0 && r[2] == 5.0)
            .unwrap();
        assert!(
            (centre[3] / fit[2] - 1.0).abs() < 1e-8 && centre[6].abs() < 1e-6,
            "{centre:?}"
        );
    }
    // The best fit at each k_max, and the model table at it.
    let table = std::fs::read_to_string(&model_out).unwrap();
    let names = column_names(&table);
    for fit in &fits {
        let (f, a) = (fit[2], fit[5]);
        let suffix = if fit[0] < 0.12 { "0.1" } else { "0.15" };
        let (c0, c2) = (
            names
                .iter()
                .position(|&n| n == format!("P0_kmax{suffix}"))
                .unwrap(),
            names
                .iter()
                .position(|&n| n == format!("P2_kmax{suffix}"))
                .unwrap(),
        );
        for (r, l) in rows(&table).iter().zip(&lin) {
            let m = model(f, a, l[1]);
            assert!((r[c0] / m[0] - 1.0).abs() < 1e-7 && (r[c2] / m[1] - 1.0).abs() < 1e-7);
        }
    }
    assert!(names.starts_with(&[
        "k",
        "P0_data",
        "err_P0_data",
        "P2_data",
        "err_P2_data",
        "P0_nw"
    ]));
    fails_naming(&[
        (
            vec!["fit", "--data", &mock, "--contour", "f,sigma0"],
            "--contour-out",
        ),
        (
            vec![
                "fit",
                "--data",
                &mock,
                "--data-columns",
                "1,2,3,4,5",
                "--data-ells",
                "0,2",
                "--free",
                "f,ab",
                "--contour",
                "f,sigma0",
                "--contour-out",
                "x.dat",
            ],
            "--contour f,sigma0",
        ),
        (vec!["fit", "--data", &mock, "--sigma0", "theory"], "theory"),
    ]);
}

#[test]
fn fit_takes_the_theory_sigma0_and_reports_it() {
    // `--sigma0 lin` fixes σ0 at the theory value that the sigma0_lin column reports.
    let dir = scratch("fit_sigma0");
    let (ok, out, err) = run(&[
        "rsd",
        "--rsd",
        "kaiser",
        "--real",
        "linear",
        "--fog",
        "lorentzian",
        "--sigma0",
        "lin",
        "--nk",
        "8",
        "--k-min",
        "0.02",
        "--k-max",
        "0.2",
    ]);
    assert!(ok, "{err}");
    let theory = header_number(&out, "with sigma0 = ");
    let mut text = String::new();
    for r in rows(&out) {
        let s = 0.01 * r[1];
        text += &format!("{} {} {s} {} {s} {} {s}\n", r[0], r[1], r[2], r[3]);
    }
    let data = write(&dir, "mock.dat", &text);
    let (ok, fit, err) = run(&[
        "fit", "--data", &data, "--rsd", "kaiser", "--real", "linear", "--free", "f", "--sigma0",
        "lin", "--k-max", "0.2",
    ]);
    assert!(ok, "{err}");
    let names = column_names_of(&fit, "# k_max");
    let r = &rows(&fit)[0];
    let col = |n: &str| names.iter().position(|&x| x == n).unwrap();
    assert!(
        (r[col("sigma0_lin")] / theory - 1.0).abs() < 1e-8,
        "{r:?} {theory}"
    );
    // σ0 fixed at the value the mock was made with: f is recovered and χ² vanishes.
    assert!(
        (r[col("f")] / header_number(&out, " f = ") - 1.0).abs() < 1e-6,
        "{r:?}"
    );
    assert!(r[col("chi2")] < 1e-6, "{r:?}");
    assert!(r[col("sigma0_1l")] < r[col("sigma0_lin")]);
}
