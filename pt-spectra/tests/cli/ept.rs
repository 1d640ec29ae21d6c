//! `rsd --rsd ept`: the galaxy model against velocileptors' REPT through the command line, and the
//! refusals of options that belong to other models.

use super::{column_names, fails_naming, rows, run};

const DATA: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/../tests/data/");

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
