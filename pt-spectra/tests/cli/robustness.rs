//! Never a silently wrong number (issue 29): the cases of the fault-injection report rerun as written,
//! and property tests that any `real`/`rsd` argument set either succeeds with finite output or fails
//! with a message and exit code 1, never a panic (exit 101) or a signal.

use super::{fails_naming, rows, run, scratch, write};
use proptest::prelude::*;
use std::process::Command;

#[test]
fn the_reported_cases_give_the_right_answer_or_a_clear_error() {
    let dir = scratch("robustness");
    let lin = dir.join("lin.dat");
    std::fs::copy(
        concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/data/linear_pk_gm2012_z0.0.dat"
        ),
        &lin,
    )
    .unwrap();
    let lin = lin.display().to_string();
    let kf = write(&dir, "kf.dat", "0.1\n0.2\n");
    let h_percent = write(
        &dir,
        "h.ini",
        "h = 67.66\nomega_b = 0.02242\nomega_cdm = 0.11933\nn_s = 0.9665\nA_s = 2.1e-9\n",
    );
    let a_s = write(
        &dir,
        "as.ini",
        "h = 0.6766\nomega_b = 0.02242\nomega_cdm = 0.11933\nn_s = 0.9665\nA_s = 2.1\n",
    );
    let sigma8 = write(
        &dir,
        "s8.ini",
        "h = 0.6766\nomega_b = 0.02242\nomega_cdm = 0.11933\nn_s = 0.9665\nsigma8 = 80\n",
    );
    // A --cache-dir that is a file is no longer an error: the tables are built in memory with a note
    // (issue 45 item 7; store::tests::an_unusable_cache_directory_is_used_from_memory_with_a_note).
    let lin_before = std::fs::read(&lin).unwrap();
    fails_naming(&[
        (
            vec![
                "real",
                "--k-min",
                "0.1",
                "--k-max",
                "0.2",
                "--nk",
                "3",
                "--q-range",
                "1e-200,1e200",
            ],
            "q_min [h/Mpc] = 1e-200: must be in [1e-8, 1e6]",
        ),
        (
            vec!["real", "--model", "1l-spt", "--nk", "10000000"],
            "the 1l-spt plan on 10000000 k needs about 4.0 TB of memory",
        ),
        (
            vec!["real", "--nk", "100", "--max-memory", "10M"],
            "above 10 MB (the limit given by --max-memory",
        ),
        (
            vec!["real", "--cosmology", &h_percent, "--nk", "3"],
            "`h = 67.66` is outside the plausible range of h, [0.2, 1.5] (h is H0/100: this looks \
             like H0",
        ),
        (
            vec!["real", "--cosmology", &a_s, "--nk", "3"],
            "`A_s = 2.1` is outside the plausible range of A_s",
        ),
        (
            vec!["real", "--cosmology", &sigma8, "--nk", "3"],
            "`sigma8 = 80` is outside the plausible range of sigma8, [0.05, 3]",
        ),
        (
            vec!["rsd", "--f", "-1", "--nk", "3"],
            "invalid f = -1: must be in [0, 2]",
        ),
        (
            vec!["real", "--linear", &lin, "--out", &lin, "--nk", "3"],
            "would overwrite the input --linear",
        ),
        (
            vec!["real", "--k-file", &kf, "--out", &kf],
            "would overwrite the input --k-file",
        ),
        (
            vec!["real", "--linear", &lin, "--columns", "1,3", "--nk", "3"],
            ":5: column 3 was requested but the row has only 2 column(s)",
        ),
    ]);
    assert_eq!(
        std::fs::read(&lin).unwrap(),
        lin_before,
        "the input was changed"
    );
    // Tiny and huge kernel arguments: the kernels are homogeneous of degree 0.
    for s in ["1e-170", "1e-300", "1e170", "1e300"] {
        let (a, b) = (format!("{s},0,0"), format!("0,{s},0"));
        let (ok, out, err) = run(&["kernel", "F", "--q", &a, "--q", &b]);
        assert!(ok, "{err}");
        let f: f64 = out.trim().parse().unwrap();
        assert!((f - 5.0 / 7.0).abs() < 1e-15, "scale {s}: {f}");
    }
    let (ok, _, err) = run(&["kernel", "F", "--q", "1e-6,0,0", "--q", "0,1,0"]);
    assert!(
        ok && err.contains("lengths differ by a factor 1.0e6"),
        "{err}"
    );
}

/// One argument set of `real` or `rsd`, from a vocabulary of ordinary, extreme and malformed values.
fn arguments() -> impl Strategy<Value = Vec<String>> {
    let pick = |options: &'static [&'static str]| proptest::sample::select(options);
    let optional = |name: &'static str, values: &'static [&'static str]| {
        proptest::option::of(pick(values)).prop_map(move |v| match v {
            Some(v) => vec![name.to_string(), v.to_string()],
            None => Vec::new(),
        })
    };
    let numbers: &'static [&'static str] = &[
        "0", "-1", "1e-300", "1e300", "nan", "inf", "-inf", "0.05", "0.3", "1", "2", "x", "",
    ];
    let common = (
        optional("--k-min", numbers),
        optional("--k-max", numbers),
        optional(
            "--nk",
            &["0", "1", "2", "4", "-3", "1e3", "99999999999999999999", "x"],
        ),
        optional(
            "--z",
            &["-1", "-0.999", "0", "0.5", "1", "3", "1e3", "nan", "-2"],
        ),
        optional("--z-input", &["0", "1", "-1", "nan"]),
        optional(
            "--q-range",
            &[
                "1e-5,1e3",
                "1e-8,1e6",
                "1e-9,1",
                "1,0.5",
                "0,1",
                "1e-200,1e200",
                "a,b",
                "1e-4,1e-3",
            ],
        ),
        optional("--precision", &["fast", "default", "nope"]),
        optional(
            "--cosmology",
            &["gm2012", "planck2018", "nope", "/nonexistent.ini"],
        ),
        optional("--eh", &["wiggle", "no-wiggle"]),
        optional("--cs2", numbers),
        optional("--max-memory", &["1", "100M", "1G", "x", "-1G"]),
    );
    let real = (
        optional(
            "--model",
            &[
                "linear",
                "1l-spt",
                "1l-spt-ir",
                "1l-regpt",
                "1l-rpt-n0",
                "1l-rpt-n1",
                "1l-rpt-n2",
                "2l-rpt-n1",
                "all",
                "bogus",
            ],
        ),
        proptest::bool::ANY,
    )
        .prop_map(|(model, terms)| {
            let mut a = vec!["real".to_string()];
            a.extend(model);
            if terms {
                a.push("--terms".into());
            }
            a
        });
    let rsd = (
        (
            optional(
                "--real",
                &[
                    "linear",
                    "1l-spt",
                    "1l-rpt-n1",
                    "1l-regpt",
                    "2l-spt",
                    "bogus",
                ],
            ),
            optional("--rsd", &["kaiser", "scoccimarro", "tns", "bogus"]),
            optional("--f", numbers),
            optional("--fog", &["none", "lorentzian", "gaussian", "bogus"]),
            optional("--sigma0", &["0", "3", "-3", "lin", "1l-spt", "nan", "x"]),
            optional("--bias", numbers),
        ),
        (
            optional("--amplitude", numbers),
            optional("--shot-noise", numbers),
            optional("--number-density", numbers),
            optional("--ells", &["0", "0,2,4", "0,2,4,6,8", "1", "10", "", "x"]),
            optional("--b2", numbers),
            optional("--apar", &["0.9", "1", "1.1", "0", "-1", "nan", "x"]),
        ),
        optional("--aperp", &["0.95", "1", "3", "x"]),
    )
        .prop_map(|((a, b, c, d, e, f), (g, h, i, j, l, m), n)| {
            let mut args = vec!["rsd".to_string()];
            for part in [a, b, c, d, e, f, g, h, i, j, l, m, n] {
                args.extend(part);
            }
            args
        });
    (prop_oneof![real, rsd], common).prop_map(|(mut args, (a, b, c, d, e, f, g, h, i, j, k))| {
        for part in [a, b, c, d, e, f, g, h, i, j, k] {
            args.extend(part);
        }
        args
    })
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 160, failure_persistence: None, ..ProptestConfig::default() })]

    /// Any argument set: exit 0 with a table of finite numbers, or exit 1 with `error: …` (clap's
    /// usage errors exit 2 with its message); never a panic (101) or a signal.
    #[test]
    fn any_argument_set_succeeds_with_finite_output_or_fails_with_a_message(args in arguments()) {
        // Keep a run short: 2-loop direct integrals over a long grid would take minutes.
        let two_loop = args.iter().any(|a| a.starts_with("2l-"));
        let mut command = Command::new(env!("CARGO_BIN_EXE_pt-spectra"));
        command.args(&args);
        if two_loop && !args.iter().any(|a| a == "--nk") {
            command.args(["--nk", "2"]);
        }
        let out = command.output().expect("the binary runs");
        let (stdout, stderr) = (String::from_utf8_lossy(&out.stdout), String::from_utf8_lossy(&out.stderr));
        match out.status.code() {
            Some(0) => {
                let table = rows(&stdout);
                prop_assert!(!table.is_empty(), "{args:?}: no rows");
                prop_assert!(table.iter().flatten().all(|v| v.is_finite()), "{args:?}: non-finite output");
            }
            Some(1) => prop_assert!(
                stderr.lines().any(|l| l.starts_with("error: ") && l.len() > 12),
                "{args:?}: {stderr}"
            ),
            Some(2) => prop_assert!(stderr.contains("error:"), "{args:?}: {stderr}"),
            code => prop_assert!(false, "{args:?}: exit {code:?}: {stderr}"),
        }
    }
}
