//! `plot`: every kind of figure, PNG and SVG, from the committed fixture tables.

use super::*;

/// A committed fixture table (`tests/fixtures/make.sh` made them).
fn fixture(name: &str) -> String {
    format!("{}/tests/fixtures/{name}", env!("CARGO_MANIFEST_DIR"))
}

#[test]
fn every_plot_kind_writes_png_and_svg_and_bad_input_is_refused() {
    // One figure of each kind from the small fixture tables, never from a 2-loop run.
    let dir = scratch("plot");
    let f = fixture;
    let kinds: Vec<(&str, Vec<String>)> = vec![
        (
            "models",
            vec![f("models.dat"), "--data".into(), f("pk_measured.dat")],
        ),
        (
            "models",
            vec![f("models.dat"), "--reference".into(), "1l-spt".into()],
        ),
        ("propagators", vec![f("prop_n0.dat"), f("prop_n1.dat")]),
        (
            "multipoles",
            vec![f("rsd_halo.dat"), "--data".into(), f("mock.dat")],
        ),
        (
            "multipoles",
            vec![f("model_tns.dat"), "--k-max".into(), "0.15".into()],
        ),
        (
            "fit",
            vec![
                f("fit_tns.dat"),
                f("fit_ab.dat"),
                "--truth".into(),
                "0.4831".into(),
            ],
        ),
        ("fit", vec![f("fit_ab.dat"), "--bands".into(), "5".into()]),
        (
            "bias-noise",
            vec![
                f("halo.dat"),
                f("halo.dat"),
                "--labels".into(),
                "a,b".into(),
            ],
        ),
        ("sn", vec![f("rsd_halo.dat")]),
        ("tns-terms", vec![f("rsd_halo.dat")]),
        (
            "contour",
            vec![f("contour_tns.dat"), "--k-max".into(), "0.1".into()],
        ),
    ];
    for (n, (kind, inputs)) in kinds.iter().enumerate() {
        for ext in ["png", "svg"] {
            let out = dir.join(format!("{n}-{kind}.{ext}")).display().to_string();
            let mut args = vec!["plot", kind];
            args.extend(inputs.iter().map(String::as_str));
            args.extend(["--out", &out]);
            let (ok, _, err) = run(&args);
            assert!(ok, "{args:?}: {err}");
            let bytes = std::fs::read(&out).unwrap();
            let magic: &[u8] = if ext == "png" { b"\x89PNG" } else { b"<svg" };
            assert!(
                bytes.windows(magic.len()).take(200).any(|w| w == magic),
                "{kind} {ext}"
            );
            // Axes, labels and curves: tens of kilobytes of PNG, hundreds of SVG elements.
            if ext == "png" {
                assert!(bytes.len() > 20_000, "{kind}: {} bytes", bytes.len());
            } else {
                let text = String::from_utf8_lossy(&bytes);
                let elements = text.matches("<polyline").count() + text.matches("<line").count();
                assert!(elements > 50, "{kind}: {elements} lines in the SVG");
            }
        }
    }
    let gif = dir.join("m.gif").display().to_string();
    let (models, rsd) = (f("models.dat"), f("rsd_halo.dat"));
    fails_naming(&[
        (
            vec!["plot", "models", &models, "--out", &gif],
            ".png or .svg",
        ),
        (
            vec!["plot", "propagators", &models, "--out", "x.png"],
            "N_dd",
        ),
        (
            vec!["plot", "fit", "/nonexistent/f.dat", "--out", "x.png"],
            "/nonexistent/f.dat",
        ),
        (
            vec!["plot", "bias-noise", &rsd, "--out", "x.png"],
            "column `b`",
        ),
        (
            vec!["plot", "tns-terms", &models, "--out", "x.png"],
            "P_eps",
        ),
        (
            vec!["plot", "tns-terms", &rsd, &rsd, "--out", "x.png"],
            "draws one table",
        ),
        (
            vec!["plot", "contour", &rsd, "--out", "x.png"],
            "--contour-out",
        ),
        (
            vec![
                "plot",
                "fit",
                &f("fit_ab.dat"),
                "--bands",
                "1,x",
                "--out",
                "x.png",
            ],
            "--bands",
        ),
        (
            vec!["plot", "sn", &rsd, "--labels", "a,b", "--out", "x.png"],
            "--labels",
        ),
    ]);
}
