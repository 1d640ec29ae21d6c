//! `pt-spectra fisher`: the table and its header, the volume scaling of the errors, bad input.

use super::{column_names_of, fails_naming, rows, run};

/// The data rows of `text` by column name (the names line starts with `# z ` or `# omega_cdm `).
fn columns(text: &str) -> Vec<std::collections::HashMap<String, f64>> {
    let names = column_names_of(text, "# z ");
    rows(text)
        .into_iter()
        .map(|r| names.iter().map(|n| n.to_string()).zip(r).collect())
        .collect()
}

#[test]
fn a_two_bin_template_forecast_states_its_survey_and_scales_with_the_volume() {
    let cache = std::env::temp_dir().join("pt-spectra-cli-fisher");
    let cache = cache.to_str().unwrap();
    let bin = |v: &str| format!("z=0.61,volume={v},n_bar=3e-4,k_max=0.15,b1=2.1");
    let (one, four) = (bin("2.6e9"), bin("1.04e10"));
    let (ok, out, err) = run(&[
        "fisher",
        "--bin",
        "z=0.38,volume=1.9e9,n_bar=4e-4,k_max=0.15,b1=1.9",
        "--bin",
        &one,
        "--cache-dir",
        cache,
    ]);
    assert!(ok, "{err}");
    for needle in [
        "fisher: Fisher forecast",
        "planck2018",
        "Gaussian with shot noise",
        "bin 2: z = 0.61",
        "free nuisance b1, b2, bs, alpha0, alpha2, sn",
        "largest error",
    ] {
        assert!(out.contains(needle), "{needle}: {out}");
    }
    let rows = columns(&out);
    assert_eq!(rows.len(), 2);
    // the correlations are in [-1, 1] and the table draws as ellipses
    for r in &rows {
        for c in ["corr_f_apar", "corr_f_aperp", "corr_apar_aperp"] {
            assert!(r[c].abs() < 1.0, "{c} = {}", r[c]);
        }
    }
    let dir = super::scratch("fisher");
    let (table, png) = (dir.join("fisher.txt"), dir.join("ellipses.png"));
    std::fs::write(&table, &out).unwrap();
    let (ok, _, err) = run(&[
        "plot",
        "ellipses",
        table.to_str().unwrap(),
        "--out",
        png.to_str().unwrap(),
    ]);
    assert!(
        ok && std::fs::metadata(&png).unwrap().len() > 10_000,
        "{err}"
    );
    let s = rows[1]["sigma_fsigma8"] / rows[1]["fsigma8"];
    assert!(s > 0.03 && s < 0.3, "{s}");
    let (ok, out4, err) = run(&["fisher", "--bin", &four, "--cache-dir", cache]);
    assert!(ok, "{err}");
    let (ok, out1, err) = run(&["fisher", "--bin", &one, "--cache-dir", cache]);
    assert!(ok, "{err}");
    let (a, b) = (&columns(&out1)[0], &columns(&out4)[0]);
    for name in ["sigma_fsigma8", "sigma_apar", "sigma_aperp"] {
        // the covariance is ∝ 1/V: four times the volume halves every error (printed to 10 digits)
        assert!(
            (a[name] / b[name] - 2.0).abs() < 1e-8,
            "{name}: {} {}",
            a[name],
            b[name]
        );
    }
}

#[test]
fn the_bispectrum_monopole_narrows_the_forecast_and_is_stated() {
    let cache = std::env::temp_dir().join("pt-spectra-cli-fisher");
    let cache = cache.to_str().unwrap();
    let p = "z=0.57,volume=2.6e9,n_bar=3e-4,k_max=0.15,b1=2";
    let pb = format!("{p},b_k_max=0.08,c1=1");
    let (ok, out_p, err) = run(&["fisher", "--bin", p, "--cache-dir", cache]);
    assert!(ok, "{err}");
    let (ok, out_pb, err) = run(&["fisher", "--bin", &pb, "--cache-dir", cache]);
    assert!(ok, "{err}");
    assert!(out_pb.contains("bispectrum monopole B0") && out_pb.contains("c1 = 1"));
    assert!(out_pb.contains("b_shot, a_shot (marginalised)"), "{out_pb}");
    let (a, b) = (&columns(&out_p)[0], &columns(&out_pb)[0]);
    for name in ["sigma_fsigma8", "sigma_apar", "sigma_aperp"] {
        assert!(b[name] < a[name], "{name}: {} vs {}", b[name], a[name]);
    }
}

#[test]
fn bad_forecast_input_is_named() {
    let good = "z=0.5,volume=1e9,n_bar=3e-4,k_max=0.15,b1=2";
    fails_naming(&[
        (
            vec!["fisher", "--bin", "z=0.5,volume=1e9,k_max=0.15,b1=2"],
            "`n_bar` is required",
        ),
        (
            vec![
                "fisher",
                "--bin",
                "z=0.5,volume=1e9,n_bar=3e-4,k_max=0.15,b1=2,bias=2",
            ],
            "unknown key `bias`",
        ),
        (
            vec![
                "fisher",
                "--bin",
                "z=0.5,volume=-1,n_bar=3e-4,k_max=0.15,b1=2",
            ],
            "volume",
        ),
        (
            vec!["fisher", "--bin", good, "--parameters", "all"],
            "valid are template, cosmology",
        ),
        (
            vec!["fisher", "--bin", good, "--prior", "h"],
            "expected NAME:SIGMA",
        ),
        (
            vec!["fisher", "--bin", good, "--prior", "omega_b:0.0004"],
            "prior on `omega_b`",
        ),
        (vec!["fisher", "--bin", good, "--free", "b1,b7"], "b7"),
        (
            vec![
                "fisher",
                "--bin",
                "z=0.5,volume=1e9,n_bar=3e-4,k_max=0.15,b1=2,c1=1",
            ],
            "unknown key `c1`",
        ),
        (
            vec![
                "fisher",
                "--bin",
                "z=0.5,volume=1e9,n_bar=3e-4,k_max=0.15,b1=2,b_k_max=0.3",
            ],
            "b_k_max",
        ),
    ]);
}
