//! Inputs that once gave a wrong number or a wrong message with exit 0 (issue 45): the growth far
//! in z, the separations of --xi (rsd and fit).

use super::{fails_naming, run};

/// The embedded spectrum rescaled by a growth without radiation: refused where that is more than
/// 1e-2 off (z = 1000 once gave a spectrum ~40% off, exit 0), warned about beyond 1e-3, and the
/// neglect stated in the header in any case.
#[test]
fn the_growth_without_radiation_is_bounded() {
    fails_naming(&[
        (
            vec!["real", "--model", "linear", "--z", "1000", "--nk", "5"],
            "z = 1000 for the embedded gm2012 spectrum given at z_input = 0: the growth here \
             neglects radiation",
        ),
        (
            vec!["real", "--model", "linear", "--z", "100", "--nk", "5"],
            "beyond |z - z_input| = 23.7 in this cosmology",
        ),
    ]);
    let (ok, out, err) = run(&["real", "--model", "linear", "--z", "5", "--nk", "5"]);
    assert!(ok, "{err}");
    assert!(
        err.contains("by a growth without radiation: about 2.1e-3 off"),
        "{err}"
    );
    assert!(
        out.contains("# warning: the embedded gm2012 spectrum is rescaled"),
        "{out}"
    );
    let (ok, out, err) = run(&["real", "--model", "linear", "--z", "2", "--nk", "5"]);
    assert!(ok && !err.contains("radiation"), "{err}");
    assert!(out.contains("radiation neglected in the growth: the rescaled P is about 8.4e-4 off"));
}

/// --s-min above --s-max names the separations, not k (the message once spoke of k_max).
#[test]
fn separations_are_named_as_separations() {
    let (ok, _, err) = run(&[
        "rsd", "--real", "linear", "--rsd", "kaiser", "--f", "0.5", "--nk", "20", "--xi",
        "--s-min", "200", "--s-max", "10",
    ]);
    assert!(!ok);
    assert!(
        err.contains("invalid --s-min/--s-max/--ns")
            && err.contains("invalid s_max [Mpc/h] = 10: must exceed s_min"),
        "{err}"
    );
    assert!(!err.contains("k_max") && !err.contains("k_min"), "{err}");
}

/// fit --xi with --s-min above --s-max names the separations (it once said `invalid k_max [h/Mpc] = 10`).
#[test]
fn fit_xi_separations_are_named_as_separations() {
    let dir = super::scratch("seams_fit_xi");
    let data: String = (1..=8)
        .map(|i| {
            let s = 20.0 * i as f64;
            format!(
                "{s} {} {} {} {}\n",
                100.0 / (s * s),
                1.0 / (s * s),
                10.0 / (s * s),
                0.1 / (s * s)
            )
        })
        .collect();
    let data = super::write(&dir, "xi.dat", &data);
    let (ok, _, err) = run(&[
        "fit",
        "--data",
        &data,
        "--data-ells",
        "0,2",
        "--data-columns",
        "1,2,3,4,5",
        "--ells",
        "0,2",
        "--free",
        "f",
        "--rsd",
        "ept",
        "--bias",
        "2",
        "--xi",
        "--s-min",
        "200",
        "--s-max",
        "10",
    ]);
    assert!(!ok);
    assert!(
        err.contains("--s-max 10 Mpc/h must exceed --s-min 200 Mpc/h"),
        "{err}"
    );
    assert!(!err.contains("k_max") && !err.contains("k_min"), "{err}");
}

#[test]
fn an_unknown_rsd_model_lists_every_model_the_help_lists() {
    let (ok, _, err) = super::run(&["rsd", "--rsd", "foo"]);
    assert!(!ok);
    for name in ["kaiser", "scoccimarro", "tns", "ept", "spt2", "eft2"] {
        assert!(err.contains(name), "{name} missing from: {err}");
    }
    let (_, help, _) = super::run(&["rsd", "--help"]);
    for name in ["kaiser", "scoccimarro", "tns", "ept", "spt2", "eft2"] {
        assert!(help.contains(name), "{name} missing from --help");
    }
}
