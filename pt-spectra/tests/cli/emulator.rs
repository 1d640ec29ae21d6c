//! `--cosmology` without `--linear`: the linear-spectrum emulator, with massive neutrinos from a CLASS
//! parameter file.

use super::{column_names, fails_naming, rows, run, scratch};

const NU_INI: &str = "h = 0.6766\nomega_b = 0.02242\nomega_cdm = 0.11933\nn_s = 0.9665\n\
                      A_s = 2.105209e-9\nN_ncdm = 1\nm_ncdm = 0.1\ndeg_ncdm = 3\nN_ur = 0.00641\n";

#[test]
fn a_cosmology_with_massive_neutrinos_is_emulated_with_p_cb_and_the_prescription() {
    let dir = scratch("emulator");
    let ini = dir.join("nu.ini");
    std::fs::write(&ini, NU_INI).unwrap();
    let ini = ini.to_str().unwrap();
    let grid = ["--k-min", "0.01", "--k-max", "0.3", "--nk", "6"];
    let mut args = vec![
        "real",
        "--model",
        "linear",
        "--cosmology",
        ini,
        "--z",
        "0.5",
    ];
    args.extend(grid);
    let (ok, out, err) = run(&args);
    assert!(ok, "{err}");
    assert!(
        out.contains("emulator") && out.contains("m_nu = 0.3 eV"),
        "{out}"
    );
    assert_eq!(column_names(&out)[..2], ["k", "P_lin"]);
    assert!(column_names(&out).contains(&"P_cb"), "{out}");
    let t = rows(&out);
    let cb = column_names(&out)
        .iter()
        .position(|&c| c == "P_cb")
        .unwrap();
    // neutrinos suppress all matter more than cold matter: P_cb/P_m ≈ 1/f_cb² at high k
    let f_cb = 1.0 - 0.3 / 93.14 / (0.02242 + 0.11933 + 0.3 / 93.14);
    let last = t.last().unwrap();
    assert!(
        (last[cb] / last[1] * f_cb * f_cb - 1.0).abs() < 0.01,
        "{last:?}"
    );
    // 1L-SPT: P_dd of all matter by the prescription, stated in the header
    let mut args = vec![
        "real",
        "--model",
        "1l-spt",
        "--cosmology",
        ini,
        "--z",
        "0.5",
    ];
    args.extend(grid);
    let (ok, out, err) = run(&args);
    assert!(ok, "{err}");
    assert!(out.contains("P_dd of all matter = P_lin + f_cb^2"), "{out}");
    let t = rows(&out);
    let (p_lin, p_dd, p_cb) = (t[5][1], t[5][2], t[5][5]);
    assert!(
        p_dd > p_lin && (p_dd - p_lin) < f_cb * f_cb * p_cb,
        "{:?}",
        t[5]
    );
}

#[test]
fn outside_the_prior_is_an_error_naming_the_parameter() {
    let dir = scratch("emulator-prior");
    let ini = dir.join("heavy.ini");
    std::fs::write(&ini, NU_INI.replace("m_ncdm = 0.1", "m_ncdm = 0.3")).unwrap();
    let grid = ["--k-min", "0.01", "--k-max", "0.3", "--nk", "3"];
    let ini = ini.to_str().unwrap();
    let mut heavy = vec!["real", "--model", "linear", "--cosmology", ini];
    heavy.extend(grid);
    let mut high_z = vec![
        "real",
        "--model",
        "linear",
        "--cosmology",
        "planck2018",
        "--z",
        "4",
    ];
    high_z.extend(grid);
    fails_naming(&[
        (
            heavy,
            "m_nu = 0.9 is outside the linear-spectrum emulator's prior [0, 0.45]",
        ),
        (high_z, "z = 4"),
    ]);
    // Eisenstein & Hu stays available
    let mut eh = vec![
        "real",
        "--model",
        "linear",
        "--cosmology",
        ini,
        "--eh",
        "wiggle",
    ];
    eh.extend(grid);
    let (ok, out, err) = run(&eh);
    assert!(ok && out.contains("Eisenstein & Hu"), "{err}");
}
