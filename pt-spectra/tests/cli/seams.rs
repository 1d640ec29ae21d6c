//! Inputs that once gave a wrong number or a wrong message with exit 0 (issue 45): the growth far
//! in z, the separations of --xi.

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
