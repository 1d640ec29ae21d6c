//! `rsd --rsd spt2`: the matter multipoles of 2-loop SPT in redshift space: the parts add up, f = 0
//! has no quadrupole from the loops, and the options it does not take are refused by name.

use super::*;

fn column(text: &str, name: &str) -> Vec<f64> {
    let j = column_names(text)
        .iter()
        .position(|&c| c == name)
        .unwrap_or_else(|| panic!("no column {name}"));
    rows(text).iter().map(|r| r[j]).collect()
}

const SMALL: [&str; 10] = [
    "rsd", "--rsd", "spt2", "--k-min", "0.05", "--k-max", "0.2", "--nk", "3", "--terms",
];

#[test]
fn parts_add_up_and_the_header_names_the_model() {
    let mut args = SMALL.to_vec();
    args.extend(["--precision", "fast", "--f", "0.6", "--ells", "0,2,4,6"]);
    let (ok, out, err) = run(&args);
    assert!(ok, "{err}");
    assert!(out.contains("spt2 (matter, 2-loop SPT in redshift space)") && out.contains("f = 0.6"));
    assert!(out.contains("no Fingers of God, no IR resummation, no counterterms"));
    for l in ["0", "2", "4", "6"] {
        let total = column(&out, &format!("P{l}"));
        let parts: Vec<f64> = ["lin", "1loop", "2loop"]
            .iter()
            .map(|p| column(&out, &format!("P{l}_{p}")))
            .fold(vec![0.0; 3], |acc, c| {
                acc.iter().zip(c).map(|(a, b)| a + b).collect()
            });
        for (t, p) in total.iter().zip(&parts) {
            assert!((t - p).abs() < 1e-8 * t.abs().max(1.0), "P{l}: {t} vs {p}");
        }
        let errors = column(&out, &format!("err_P{l}"));
        assert!(errors.iter().all(|e| *e > 0.0), "P{l}: {errors:?}");
    }
    // linear Kaiser quadrupole over monopole: (4f/3 + 4f²/7)/(1 + 2f/3 + f²/5)
    let f: f64 = 0.6;
    let ratio = (4.0 * f / 3.0 + 4.0 * f * f / 7.0) / (1.0 + 2.0 * f / 3.0 + f * f / 5.0);
    let (p0, p2) = (column(&out, "P0_lin"), column(&out, "P2_lin"));
    for (a, b) in p0.iter().zip(&p2) {
        assert!((b / a - ratio).abs() < 1e-8, "{}", b / a);
    }
}

#[test]
fn f_zero_leaves_no_quadrupole_in_the_loops() {
    let mut args = SMALL.to_vec();
    args.extend(["--precision", "fast", "--f", "0"]);
    let (ok, out, err) = run(&args);
    assert!(ok, "{err}");
    for part in ["P2_1loop", "P2_2loop", "P4_2loop"] {
        let p0 = column(&out, "P0_2loop");
        for (v, m) in column(&out, part).iter().zip(p0) {
            assert!(v.abs() < 1e-9 * m.abs(), "{part}: {v}");
        }
    }
}

#[test]
fn options_spt2_does_not_take_are_refused_by_name() {
    let with = |extra: &[&'static str]| {
        let mut a = vec!["rsd", "--rsd", "spt2", "--nk", "2"];
        a.extend_from_slice(extra);
        a
    };
    fails_naming(&[
        (
            with(&["--fog", "lorentzian"]),
            "--fog is not an option of --rsd spt2",
        ),
        (
            with(&["--bias", "2"]),
            "--bias/--bias-file/--amplitude is not an option",
        ),
        (with(&["--b2", "1"]), "--b2/--bs/--b3 is not an option"),
        (
            with(&["--real", "2l-spt"]),
            "--real is not an option of --rsd spt2",
        ),
        (
            with(&["--alpha0", "1"]),
            "--alpha0 is an option of --rsd ept",
        ),
        (with(&["--ells", "0,10"]), "multipole ell"),
        (with(&["--f", "nan"]), "f"),
    ]);
}

#[test]
fn eft2_is_linear_in_its_counterterms_and_refuses_bad_ones() {
    let base = [
        "rsd",
        "--rsd",
        "eft2",
        "--k-min",
        "0.05",
        "--k-max",
        "0.2",
        "--nk",
        "3",
        "--precision",
        "fast",
        "--ells",
        "0,2",
    ];
    let (ok, zero, err) = run(&base);
    assert!(ok, "{err}");
    assert!(
        err.contains("warning: every counterterm of eft2 is 0"),
        "{err}"
    );
    assert!(zero.contains("IR resummation: P_nw") && zero.contains("dSigma^2 ="));
    let mut with = base.to_vec();
    with.extend([
        "--ct",
        "c0=1.5",
        "--ct",
        "c2_1loop=-3",
        "--ct",
        "ctilde=40",
        "--terms",
    ]);
    let (ok, out, err) = run(&with);
    assert!(ok, "{err}");
    for l in ["0", "2"] {
        let (p, p0) = (
            column(&out, &format!("P{l}")),
            column(&zero, &format!("P{l}")),
        );
        let t: Vec<Vec<f64>> = ["c0", "c2_1loop", "ctilde"]
            .iter()
            .map(|c| column(&out, &format!("T{l}_{c}")))
            .collect();
        for i in 0..p.len() {
            let want = p0[i] + 1.5 * t[0][i] - 3.0 * t[1][i] + 40.0 * t[2][i];
            assert!(
                (p[i] - want).abs() < 1e-7 * p[i].abs().max(1.0),
                "P{l}: {} vs {want}",
                p[i]
            );
        }
    }
    let mut no_ir = base.to_vec();
    no_ir.push("--no-ir");
    let (ok, out, err) = run(&no_ir);
    assert!(ok && out.contains("no IR resummation (--no-ir)"), "{err}");
    let eft2 = |extra: &[&'static str]| {
        let mut a = vec!["rsd", "--rsd", "eft2", "--nk", "2"];
        a.extend_from_slice(extra);
        a
    };
    fails_naming(&[
        (eft2(&["--ct", "c6=1"]), "unknown eft2 counterterm `c6`"),
        (eft2(&["--ct", "c0"]), "write NAME=VALUE"),
        (eft2(&["--ct", "c0=1", "--ct", "c0=2"]), "c0 is given twice"),
        (eft2(&["--ct", "c0=inf"]), "finite number"),
        (
            eft2(&["--fog", "gaussian"]),
            "--fog is not an option of --rsd eft2",
        ),
        (
            vec!["rsd", "--rsd", "spt2", "--ct", "c0=1"],
            "--ct is an option of --rsd eft2",
        ),
        (
            vec!["rsd", "--rsd", "tns", "--ct", "c0=1"],
            "--ct is an option of --rsd eft2",
        ),
        (
            vec!["rsd", "--rsd", "spt2", "--no-ir"],
            "--no-ir is an option of --rsd ept",
        ),
    ]);
}
