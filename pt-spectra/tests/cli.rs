//! The `pt-spectra` binary end to end: outputs against closed forms, bad input against clear errors.

use std::process::Command;

fn run(args: &[&str]) -> (bool, String, String) {
    let out = Command::new(env!("CARGO_BIN_EXE_pt-spectra"))
        .args(args)
        .output()
        .expect("the binary runs");
    let text = |b: Vec<u8>| String::from_utf8(b).expect("utf-8 output");
    (out.status.success(), text(out.stdout), text(out.stderr))
}

/// The numeric rows of a table.
fn rows(text: &str) -> Vec<Vec<f64>> {
    text.lines()
        .filter(|l| !l.starts_with('#'))
        .map(|l| l.split_whitespace().map(|x| x.parse().unwrap()).collect())
        .collect()
}

#[test]
fn linear_kaiser_multipoles_follow_the_closed_form() {
    let (b, f) = (1.7, 0.6);
    let (ok, out, err) = run(&[
        "rsd", "--rsd", "kaiser", "--real", "linear", "--bias", "1.7", "--f", "0.6", "--nk", "5",
        "--k-min", "0.01", "--k-max", "0.3",
    ]);
    assert!(ok, "{err}");
    let (ok, lin, err) = run(&[
        "real", "--model", "linear", "--nk", "5", "--k-min", "0.01", "--k-max", "0.3",
    ]);
    assert!(ok, "{err}");
    for (m, l) in rows(&out).iter().zip(rows(&lin)) {
        let p = l[1];
        let expected = [
            p * (b * b + 2.0 * b * f / 3.0 + f * f / 5.0),
            p * (4.0 * b * f / 3.0 + 4.0 * f * f / 7.0),
            p * 8.0 * f * f / 35.0,
        ];
        for (got, want) in m[1..4].iter().zip(expected) {
            assert!(
                (got / want - 1.0).abs() < 1e-8,
                "k = {}: {got} vs {want}",
                m[0]
            );
        }
    }
}

#[test]
fn bad_input_exits_non_zero_naming_the_problem() {
    for (args, needle) in [
        (vec!["rsd", "--fog", "cauchy"], "cauchy"),
        (vec!["rsd", "--ells", "0,3"], "ell = 3"),
        (vec!["rsd", "--rsd", "tns-x"], "tns-x"),
        (vec!["rsd", "--sigma0", "-1"], "--sigma0"),
        (vec!["real", "--model", "3l-spt"], "3l-spt"),
        (
            vec!["real", "--linear", "/nonexistent/pk.dat"],
            "/nonexistent/pk.dat",
        ),
        (vec!["real", "--k-min", "0.5", "--k-max", "0.1"], "k_max"),
        (vec!["kernel", "F"], "no argument vector"),
        (vec!["kernel", "F", "--q", "1,0", "--q", "0,1,0"], "1,0"),
    ] {
        let (ok, _, err) = run(&args);
        assert!(!ok, "{args:?} should fail");
        assert!(err.contains(needle), "{args:?}: {err}");
    }
}
