//! `pt-spectra bispectrum`: the real-space limit against the closed form, bins, headers and refusals.

use super::{fails_naming, rows, run};

/// The embedded gm2012 spectrum at z = 0 (the default input), read back from `real --model linear`.
fn p_lin(k: f64) -> f64 {
    let ks = format!("{k}");
    let file = std::env::temp_dir().join(format!("pt-spectra-bk-k-{}-{ks}", std::process::id()));
    std::fs::write(&file, format!("{k}\n")).unwrap();
    let (ok, out, err) = run(&[
        "real",
        "--model",
        "linear",
        "--k-file",
        file.to_str().unwrap(),
    ]);
    assert!(ok, "{err}");
    rows(&out)[0][1]
}

#[test]
fn real_space_b0_is_the_closed_form_and_b2_b4_vanish() {
    let tri = [[0.02, 0.03, 0.04], [0.05, 0.05, 0.05], [0.01, 0.1, 0.105]];
    let file = std::env::temp_dir().join(format!("pt-spectra-bk-{}", std::process::id()));
    let text: String = tri
        .iter()
        .map(|t| format!("{} {} {}\n", t[0], t[1], t[2]))
        .collect();
    std::fs::write(&file, format!("# k1 k2 k3\n{text}")).unwrap();
    let (b1, b2, bs) = (1.8, 0.4, -0.2);
    let (ok, out, err) = run(&[
        "bispectrum",
        "--triangles",
        file.to_str().unwrap(),
        "--f",
        "0",
        "--no-ir",
        "--b1",
        "1.8",
        "--b2",
        "0.4",
        "--bs",
        "-0.2",
    ]);
    assert!(ok, "{err}");
    assert!(
        err.contains("without --bin-width"),
        "the point evaluation is warned about: {err}"
    );
    assert!(out.contains("at the given triangles (not averaged over bins)"));
    for (t, r) in tri.iter().zip(rows(&out)) {
        let mut closed = 0.0;
        for i in 0..3 {
            let (j, l) = ((i + 1) % 3, (i + 2) % 3);
            let c = (t[l] * t[l] - t[i] * t[i] - t[j] * t[j]) / (2.0 * t[i] * t[j]);
            let f2 = 5.0 / 7.0 + 0.5 * c * (t[i] / t[j] + t[j] / t[i]) + 2.0 / 7.0 * c * c;
            closed += 2.0
                * b1
                * b1
                * (b1 * f2 + 0.5 * b2 + bs * (c * c - 1.0 / 3.0))
                * p_lin(t[i])
                * p_lin(t[j]);
        }
        // the table prints 10 significant digits of both
        assert!(
            (r[3] / closed - 1.0).abs() < 1e-8,
            "{t:?}: {} vs {closed}",
            r[3]
        );
        assert!(
            r[4].abs() < 1e-9 * closed && r[5].abs() < 1e-9 * closed,
            "{r:?}"
        );
    }
}

#[test]
fn bins_from_edges_carry_errors_and_the_header_says_what_was_computed() {
    let (ok, out, err) = run(&[
        "bispectrum",
        "--k-edges",
        "0.01:0.05:0.01",
        "--b1",
        "2",
        "--n-bar",
        "3e-4",
        "--fog",
        "lorentzian",
        "--sigma-fog",
        "4",
    ]);
    assert!(ok, "{err}");
    for needle in [
        "bin averages over all closed triangles",
        "f(z) of the cosmology",
        "Lorentzian",
        "IR resummation of the BAO",
    ] {
        assert!(out.contains(needle), "{needle}: {out}");
    }
    let r = rows(&out);
    assert_eq!(r.len(), 17, "bins of 4 shells whose centres close");
    for row in r {
        assert!(
            row[3] > 0.0 && row[6] > 0.0 && row[6] < 1e-2 * row[3],
            "{row:?}"
        );
    }
}

#[test]
fn bad_triangles_and_choices_are_refused() {
    let file = std::env::temp_dir().join(format!("pt-spectra-bk-bad-{}", std::process::id()));
    std::fs::write(&file, "0.01 0.02 0.05\n").unwrap();
    let f = file.to_str().unwrap();
    fails_naming(&[
        (vec!["bispectrum"], "give the triangles"),
        (vec!["bispectrum", "--triangles", f], "does not close"),
        (
            vec!["bispectrum", "--k-edges", "0.01,0.02,0.04"],
            "uniform shells",
        ),
        (
            vec![
                "bispectrum",
                "--k-edges",
                "0.01:0.05:0.01",
                "--fog",
                "lorentz",
            ],
            "valid: none, lorentzian, gaussian",
        ),
        (
            vec![
                "bispectrum",
                "--k-edges",
                "0.01:0.05:0.01",
                "--legendre-side",
                "4",
            ],
            "valid: largest, 1, 2, 3",
        ),
        (
            vec!["bispectrum", "--k-edges", "0.01:0.05:0.01", "--n-bar", "-1"],
            "n_bar",
        ),
        (
            vec!["bispectrum", "--k-edges", "0.01:0.05:0.01", "--q-par", "0"],
            "q_par",
        ),
    ]);
}
