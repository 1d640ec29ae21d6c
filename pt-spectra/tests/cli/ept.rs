//! `rsd --rsd ept`: the galaxy model against velocileptors' REPT through the command line, and the
//! refusals of options that belong to other models.

use super::{column_names, column_names_of, fails_naming, rows, run};

const DATA: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/data/");

/// Set A of tests/data/velocileptors_rept_planck2018_z1.0.dat without IR (columns 2–4) at every
/// fifth k: within 2e-4 of P0 (the library test's bound).
#[test]
fn ept_matches_rept_from_the_command_line() {
    let linear = format!("{DATA}linear_pk_planck2018_z1.0.dat");
    let (ok, out, err) = run(&[
        "rsd", "--rsd", "ept", "--no-ir", "--linear", &linear, "--f", "0.873875", "--bias", "1.8",
        "--b2", "0.5", "--bs", "-0.3", "--b3", "0.1", "--alpha0", "10", "--alpha2", "-5",
        "--alpha4", "3", "--alpha6", "1", "--sn", "1000", "--sn2", "500", "--sn4", "100",
        "--k-min", "0.005", "--k-max", "0.3", "--nk", "50",
    ]);
    assert!(ok, "{err}");
    assert_eq!(
        column_names(&out),
        ["k", "P0", "P2", "P4", "err_P0", "err_P2", "err_P4"]
    );
    let ours = rows(&out);
    let text =
        std::fs::read_to_string(format!("{DATA}velocileptors_rept_planck2018_z1.0.dat")).unwrap();
    let reference = rows(&text);
    for (o, r) in ours.iter().zip(&reference).step_by(5) {
        assert!(
            (o[0] / r[0] - 1.0).abs() < 1e-8,
            "k grids differ: {} {}",
            o[0],
            r[0]
        );
        for l in 0..3 {
            assert!(
                (o[1 + l] - r[1 + l]).abs() < 2e-4 * r[1],
                "k {} ℓ {}: {} vs {}",
                o[0],
                2 * l,
                o[1 + l],
                r[1 + l]
            );
        }
    }
}

#[test]
fn ept_refuses_other_models_options_and_bad_values() {
    fails_naming(&[
        (vec!["rsd", "--rsd", "ept", "--fog", "gaussian"], "--fog"),
        (vec!["rsd", "--rsd", "ept", "--sigma0", "3"], "--sigma0"),
        (vec!["rsd", "--rsd", "ept", "--shot-noise", "100"], "--sn"),
        (vec!["rsd", "--rsd", "tns", "--sn", "100"], "--sn"),
        (vec!["rsd", "--rsd", "kaiser", "--no-ir"], "--no-ir"),
        (vec!["rsd", "--rsd", "ept", "--f", "-0.5"], "f"),
        (
            vec!["rsd", "--rsd", "ept", "--apar", "0", "--aperp", "1"],
            "apar",
        ),
        (vec!["rsd", "--rsd", "ept", "--alpha2", "nan"], "alpha2"),
    ]);
}

/// `fit --rsd ept` on noise-free multipoles made by `rsd --rsd ept`: f, b1, b2 free, α0 and sn
/// marginalised, a prior on b2; the truth is recovered well within the errors.
#[test]
fn ept_fit_recovers_the_parameters_of_its_own_multipoles() {
    let dir = super::scratch("ept_fit");
    let text = super::ept_multipoles(&[
        "--bias", "2", "--b2", "-0.4", "--alpha0", "8", "--sn", "900", "--f", "0.7",
    ]);
    let data = super::write(&dir, "data.txt", &text);
    let (ok, out, err) = run(&[
        "fit",
        "--rsd",
        "ept",
        "--data",
        &data,
        "--ells",
        "0,2,4",
        "--free",
        "f,b1,b2",
        "--marginalise",
        "alpha0,sn",
        "--prior",
        "b2:0,2",
        "--k-max",
        "0.2",
        "--precision",
        "fast",
        "--bias",
        "1.8",
        "--f",
        "0.6",
    ]);
    assert!(ok, "{err}");
    let names = column_names_of(&out, "# k_max ");
    let row = &rows(&out)[0];
    let get = |n: &str| row[names.iter().position(|c| *c == n).unwrap()];
    for (name, truth) in [
        ("f", 0.7),
        ("b1", 2.0),
        ("b2", -0.4),
        ("alpha0", 8.0),
        ("sn", 900.0),
    ] {
        let (v, e) = (get(name), get(&format!("err_{name}")));
        assert!((v - truth).abs() < 0.1 * e, "{name}: {v} ± {e}");
    }
    fails_naming(&[
        (
            vec![
                "fit",
                "--rsd",
                "ept",
                "--data",
                &data,
                "--marginalise",
                "b2",
            ],
            "linearly",
        ),
        (
            vec!["fit", "--rsd", "ept", "--data", &data, "--prior", "b2:0,-1"],
            "sigma",
        ),
        (
            vec!["fit", "--rsd", "ept", "--data", &data, "--prior", "b2=0"],
            "NAME:MEAN,SIGMA",
        ),
        // A prior on a fixed parameter was listed in the header and ignored.
        (
            vec!["fit", "--rsd", "ept", "--data", &data, "--prior", "b2:0,1"],
            "the prior on b2: b2 is fixed, and a prior acts only on a free or marginalised parameter \
             (free: f, b1; marginalised: none)",
        ),
        (
            vec!["fit", "--rsd", "ept", "--data", &data, "--free", "q"],
            "`q`",
        ),
        (
            vec!["fit", "--data", &data, "--prior", "f:0.5,0.1"],
            "--prior",
        ),
    ]);
}

/// `fit --rsd ept --basis desi`: the DESI physical basis is a change of variables of the model's
/// b1, b2 and sn (with the other parameters fixed), so f and its error are those of the
/// velocileptors fit; the table has the physical parameters (b1p = b1 sigma8_z), then the model's
/// they map to; the DESI priors are stated; bad combinations are refused by name.
#[test]
fn ept_fit_in_the_desi_physical_basis() {
    let dir = super::scratch("ept_fit_desi");
    let text = super::ept_multipoles(&["--bias", "2", "--b2", "-0.4", "--sn", "900", "--f", "0.7"]);
    let data = super::write(&dir, "data.txt", &text);
    let fit = |extra: &[&str]| {
        let mut a = vec![
            "fit",
            "--rsd",
            "ept",
            "--data",
            &data,
            "--ells",
            "0,2,4",
            "--k-max",
            "0.2",
            "--precision",
            "fast",
            "--bias",
            "1.8",
            "--f",
            "0.6",
            "--starts",
            "2",
        ];
        a.extend(extra);
        let (ok, out, err) = run(&a);
        assert!(ok, "{err}");
        let names: Vec<String> = column_names_of(&out, "# k_max ")
            .iter()
            .map(|c| c.to_string())
            .collect();
        let row = rows(&out)[0].clone();
        let get = move |n: &str| {
            row[names
                .iter()
                .position(|c| c == n)
                .unwrap_or_else(|| panic!("no column {n}"))]
        };
        (out, get)
    };
    let (_, vel) = fit(&["--free", "f,b1,b2", "--marginalise", "sn"]);
    let (out, phys) = fit(&[
        "--basis",
        "desi",
        "--n-bar",
        "3e-4",
        "--free",
        "f,b1p,b2p",
        "--marginalise",
        "sn0p",
    ]);
    assert!(out.contains("parameter basis: DESI DR1 physical"), "{out}");
    assert!(
        (vel("f") - phys("f")).abs() < 0.01 * vel("err_f"),
        "{} vs {}",
        vel("f"),
        phys("f")
    );
    assert!((vel("err_f") / phys("err_f") - 1.0).abs() < 0.02);
    assert!((phys("b1p") - phys("b1") * phys("sigma8_z")).abs() < 1e-6 * phys("b1p"));
    assert!((phys("sn0p") - phys("sn") * 3e-4).abs() < 1e-6 * phys("sn0p").abs());
    assert!((phys("b1") - vel("b1")).abs() < 0.01 * vel("err_b1"));
    // CLASS-PT's bias: b2 = b2^CLASS-PT - (4/3) bG2 with bG2 = bs (here fixed at 0 in both fits)
    let (out, cpt) = fit(&[
        "--basis",
        "classpt",
        "--free",
        "f,b1,b2",
        "--marginalise",
        "sn",
        "--bs",
        "0",
    ]);
    assert!(out.contains("parameter basis: CLASS-PT's bias"), "{out}");
    assert!((cpt("f") - vel("f")).abs() < 0.01 * vel("err_f"));
    assert!((cpt("b2") - cpt("b2_velocileptors")).abs() < 1e-9 * cpt("b2").abs().max(1.0));
    assert!((cpt("bG2") - cpt("bs")).abs() < 1e-12);
    let (out, _) = fit(&[
        "--basis",
        "desi",
        "--n-bar",
        "3e-4",
        "--free",
        "f,b1p,b2p",
        "--marginalise",
        "sn0p,alpha0p",
        "--desi-priors",
    ]);
    assert!(
        out.contains("b2p") && out.contains("N(0, 5)") || out.contains("b2p:"),
        "{out}"
    );
    fails_naming(&[
        (
            vec![
                "fit", "--rsd", "ept", "--data", &data, "--basis", "desi", "--free", "f,b1p",
            ],
            "--n-bar",
        ),
        (
            vec!["fit", "--rsd", "ept", "--data", &data, "--n-bar", "3e-4"],
            "belong to the basis desi",
        ),
        (
            vec!["fit", "--rsd", "ept", "--data", &data, "--basis", "lpt"],
            "velocileptors, classpt, desi",
        ),
        (
            vec![
                "fit", "--rsd", "ept", "--data", &data, "--basis", "desi", "--n-bar", "3e-4",
                "--free", "f,b1",
            ],
            "velocileptors name",
        ),
    ]);
}

/// With a distortion, the fit table has `apar aperp` (and their errors when free).
#[test]
fn ept_fit_prints_the_distortion() {
    let dir = super::scratch("ept_fit_ap");
    let (ok, out, err) = run(&[
        "rsd",
        "--rsd",
        "ept",
        "--bias",
        "2",
        "--f",
        "0.7",
        "--apar",
        "1.03",
        "--aperp",
        "0.98",
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
    let mut text = String::new();
    for r in rows(&out) {
        let s = 0.005 * r[1];
        text += &format!("{} {} {s} {} {s} {} {s}\n", r[0], r[1], r[2], r[3]);
    }
    let data = super::write(&dir, "data.txt", &text);
    let (ok, out, err) = run(&[
        "fit",
        "--rsd",
        "ept",
        "--data",
        &data,
        "--ells",
        "0,2,4",
        "--free",
        "f,b1,apar,aperp",
        "--apar",
        "1",
        "--aperp",
        "1",
        "--k-max",
        "0.2",
        "--precision",
        "fast",
        "--bias",
        "1.9",
    ]);
    assert!(ok, "{err}");
    let names = column_names_of(&out, "# k_max ");
    let row = &rows(&out)[0];
    let get = |n: &str| row[names.iter().position(|c| *c == n).unwrap()];
    for (name, truth) in [("apar", 1.03), ("aperp", 0.98), ("f", 0.7)] {
        let (v, e) = (get(name), get(&format!("err_{name}")));
        assert!((v - truth).abs() < 0.1 * e, "{name}: {v} ± {e}");
    }
}

/// `--window` with a window that cuts nothing (Q0 = 1 to 10⁵ Mpc/h, Q2 = Q4 = 0) leaves the
/// multipoles unchanged, `--k-edges` averages them over bins, and `--box` over a box's modes; the
/// paper's models refuse them.
#[test]
fn ept_window_and_bins() {
    let dir = super::scratch("ept_window");
    let mut text = String::from("# s Q0 Q2 Q4\n");
    for i in 0..400 {
        let s = 0.01 * 1e7_f64.powf(i as f64 / 399.0);
        text += &format!("{s} 1 0 0\n");
    }
    let window = super::write(&dir, "identity.dat", &text);
    let base = [
        "rsd",
        "--rsd",
        "ept",
        "--bias",
        "2",
        "--no-ir",
        "--precision",
        "fast",
    ];
    let grid = ["--k-min", "0.02", "--k-max", "0.2", "--nk", "10"];
    let (ok, plain, err) = run(&[&base[..], &grid[..]].concat());
    assert!(ok, "{err}");
    let (ok, windowed, err) = run(&[&base[..], &grid[..], &["--window", &window]].concat());
    assert!(ok, "{err}");
    for (a, b) in rows(&plain).iter().zip(rows(&windowed)) {
        for l in 1..4 {
            assert!(
                (a[l] - b[l]).abs() < 1e-3 * a[1],
                "k {}: {} vs {}",
                a[0],
                a[l],
                b[l]
            );
        }
    }
    // One narrow bin is nearly the value at its effective k.
    let (ok, binned, err) = run(&[&base[..], &["--k-edges", "0.099,0.101"]].concat());
    assert!(ok, "{err}");
    let b = &rows(&binned)[0];
    let k_file = super::write(&dir, "k.dat", &format!("{}\n", b[0]));
    let (ok, at, err) = run(&[&base[..], &["--k-file", &k_file]].concat());
    assert!(ok, "{err}");
    let a = &rows(&at)[0];
    // The curvature of P across the bin: (width/k)² ~ 4e-4 of P at most.
    assert!((a[1] - b[1]).abs() < 5e-4 * a[1], "{} vs {}", a[1], b[1]);
    let (ok, boxed, err) =
        run(&[&base[..], &["--k-edges", "0.05,0.06,0.07", "--box", "1000"]].concat());
    assert!(ok, "{err}");
    assert_eq!(rows(&boxed).len(), 2);
    fails_naming(&[
        (
            vec!["rsd", "--rsd", "tns", "--window", &window, "--terms"],
            "--terms",
        ),
        (vec!["rsd", "--rsd", "ept", "--k-edges", "0.1"], "--k-edges"),
        (
            vec![
                "rsd",
                "--rsd",
                "ept",
                "--window",
                &window,
                "--window-mixing",
                "x",
            ],
            "--window-mixing",
        ),
        (
            vec![
                "rsd",
                "--rsd",
                "ept",
                "--window",
                &window,
                "--k-edges",
                "0.05,0.1",
                "--box",
                "500",
            ],
            "box",
        ),
    ]);
}

/// `fit --rsd ept --k-edges` fits binned multipoles made by `rsd --rsd ept --k-edges`: the truth back.
#[test]
fn ept_fit_through_bins() {
    let dir = super::scratch("ept_fit_bins");
    let edges = "0.02:0.2:0.01";
    let (ok, out, err) = run(&[
        "rsd",
        "--rsd",
        "ept",
        "--bias",
        "2",
        "--b2",
        "-0.4",
        "--f",
        "0.7",
        "--k-edges",
        edges,
        "--precision",
        "fast",
    ]);
    assert!(ok, "{err}");
    let mut text = String::new();
    for r in rows(&out) {
        let s = 0.01 * r[1];
        text += &format!("{} {} {s} {} {s} {} {s}\n", r[0], r[1], r[2], r[3]);
    }
    let data = super::write(&dir, "binned.txt", &text);
    let (ok, out, err) = run(&[
        "fit",
        "--rsd",
        "ept",
        "--data",
        &data,
        "--ells",
        "0,2",
        "--free",
        "f,b1,b2",
        "--k-edges",
        edges,
        "--k-max",
        "0.2",
        "--precision",
        "fast",
        "--bias",
        "1.8",
        "--f",
        "0.6",
    ]);
    assert!(ok, "{err}");
    let names = column_names_of(&out, "# k_max ");
    let row = &rows(&out)[0];
    let get = |n: &str| row[names.iter().position(|c| *c == n).unwrap()];
    for (name, truth) in [("f", 0.7), ("b1", 2.0), ("b2", -0.4)] {
        let (v, e) = (get(name), get(&format!("err_{name}")));
        assert!((v - truth).abs() < 0.05 * e, "{name}: {v} ± {e}");
    }
    assert!(out.contains("bins: the k^2-weighted mean"));
}
