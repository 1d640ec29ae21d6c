use super::*;
use proptest::prelude::*;

/// Planck 2018 in CLASS's own names (h, physical densities, A_s), with keys CLASS needs for other work.
const CLASS_PLANCK2018: &str = "\
# CLASS input: Planck 2018, massless neutrinos
output = mPk            # matter power spectrum
P_k_max_h/Mpc = 50.

h = 0.6766
omega_b = 0.02242
omega_cdm = 0.11933     # cold dark matter
Omega_k = 0.
n_s = 0.9665
A_s = 2.105209e-9
k_pivot = 0.05
N_ur = 3.046
";

/// The same in the names of CAMB's Python `set_cosmology`/`set_params` (H0 in km/s/Mpc).
const CAMB_PLANCK2018: &str = "\
H0 = 67.66
ombh2 = 0.02242
omch2 = 0.11933
omk = 0
mnu = 0.0   # massless
ns = 0.9665
As = 2.105209e-9
w = -1
wa = 0
tau = 0.0544
";

/// The same in the names of CAMB's Fortran `params.ini`, with a Fortran exponent.
const CAMB_PARAMS_INI: &str = "\
#Parameters for CAMB
use_physical = T
hubble = 67.66
ombh2 = 0.02242
omch2 = 0.11933
omk = 0
scalar_amp(1) = 2.105209d-9
scalar_spectral_index(1) = 0.9665
pivot_scalar = 0.05
temp_cmb = 2.7255
";

/// Field by field agreement to `tol` relative (absolute for the quantities that vanish).
fn assert_same(a: &Cosmology, b: &Cosmology, tol: f64) {
    let close = |x: f64, y: f64| (x - y).abs() <= tol * x.abs().max(y.abs()).max(1.0);
    let fields = [
        ("omega_m", a.omega_m, b.omega_m),
        ("omega_lambda", a.omega_lambda, b.omega_lambda),
        ("h", a.h, b.h),
        ("omega_b_h2", a.omega_b_h2, b.omega_b_h2),
        ("n_s", a.n_s, b.n_s),
        ("w0", a.w0, b.w0),
        ("wa", a.wa, b.wa),
    ];
    for (name, x, y) in fields {
        assert!(close(x, y), "{name}: {x} vs {y}");
    }
    match (a.amplitude, b.amplitude) {
        (
            Amplitude::As { a_s, k_pivot },
            Amplitude::As {
                a_s: a_s2,
                k_pivot: k2,
            },
        ) => assert!(
            (a_s / a_s2 - 1.0).abs() <= tol && close(k_pivot, k2),
            "{:?} vs {:?}",
            a.amplitude,
            b.amplitude
        ),
        (Amplitude::Sigma8(s), Amplitude::Sigma8(s2)) => assert!(close(s, s2)),
        (x, y) => panic!("{x:?} vs {y:?}"),
    }
}

/// The error message of parsing `text`.
fn message(text: &str) -> String {
    Cosmology::from_ini_str(text, "test.ini")
        .unwrap_err()
        .to_string()
}

#[test]
fn class_and_camb_files_give_the_planck2018_preset() {
    let preset = Cosmology::planck2018();
    // H0/100 and the decimal inputs round differently from the preset's literals: a few ulp.
    let tol = 1e-14;
    let class = Cosmology::from_ini_str(CLASS_PLANCK2018, "class.ini").unwrap();
    assert_same(&class.cosmology, &preset, tol);
    assert_eq!(class.ignored, ["output", "P_k_max_h/Mpc"]);
    let camb = Cosmology::from_ini_str(CAMB_PLANCK2018, "camb.ini").unwrap();
    assert_same(&camb.cosmology, &preset, tol);
    // mnu = 0 is read (massless neutrinos, as the preset)
    assert_eq!(camb.ignored, ["tau"]);
    let params = Cosmology::from_ini_str(CAMB_PARAMS_INI, "params.ini").unwrap();
    assert_same(&params.cosmology, &preset, tol);
    assert_eq!(params.ignored, ["use_physical", "temp_cmb"]);
    assert_eq!(camb.cosmology.describe(), preset.describe());
    // Key–value pairs (as from a Python dict), with blanks around keys and values.
    let pairs = [
        (" h", "0.6766 "),
        ("omega_b", "0.02242"),
        ("omega_cdm", "0.11933"),
        ("n_s", "0.9665"),
        ("A_s", "2.105209e-9"),
        ("z_max_pk", "2"),
    ];
    let dict = Cosmology::from_keys(pairs, "dict").unwrap();
    assert_same(&dict.cosmology, &preset, tol);
    assert_eq!(dict.ignored, ["z_max_pk"]);
    let owned: Vec<(String, String)> = pairs
        .iter()
        .map(|(k, v)| (k.to_string(), v.to_string()))
        .collect();
    let slice: &[(String, String)] = &owned;
    let from_slice = Cosmology::from_keys(slice.iter().map(|(k, v)| (k, v)), "dict").unwrap();
    assert_eq!(from_slice, dict);
    assert_eq!(Cosmology::from_keys(owned, "dict").unwrap(), dict);
}

#[test]
fn alternative_class_keys_and_dark_energy() {
    // Ω_b, Ω_cdm instead of ω; H0; ln(10¹⁰A_s) = 3.047 is Planck's A_s = 2.1052093e-9.
    let h2 = 0.6766_f64.powi(2);
    let text = format!(
        "H0 = 67.66\nOmega_b = {}\nOmega_cdm = {}\nn_s = 0.9665\nln10^{{10}}A_s = 3.047\n",
        0.02242 / h2,
        0.11933 / h2
    );
    let parsed = Cosmology::from_ini_str(&text, "class.ini").unwrap();
    assert_same(&parsed.cosmology, &Cosmology::planck2018(), 2e-7);
    assert!(parsed.ignored.is_empty());
    // Curvature, w0–wa and σ8; k_pivot does not matter with σ8 and is reported as ignored.
    let text = "h = 0.7\nomega_b = 0.0245\nomega_cdm = 0.1225\nOmega_k = 0.02\nn_s = 0.96\n\
                sigma8 = 0.81\nk_pivot = 0.002\nw0_fld = -0.9\nwa_fld = -0.2\nOmega_Lambda = 0\n";
    let parsed = Cosmology::from_ini_str(text, "de.ini").unwrap();
    let c = parsed.cosmology;
    assert!((c.omega_m - 0.3).abs() < 1e-15 && (c.omega_k() - 0.02).abs() < 1e-15);
    assert!((c.omega_lambda - 0.68).abs() < 1e-15);
    assert_eq!(
        (c.w0, c.wa, c.amplitude),
        (-0.9, -0.2, Amplitude::Sigma8(0.81))
    );
    assert_eq!(parsed.ignored, ["k_pivot", "Omega_Lambda"]);
    // Synonyms that agree are accepted, including both dialects in one file.
    let text =
        "h = 0.6766\nH0 = 67.66\nomega_b = 0.02242\nombh2 = 0.022420001\nomega_cdm = 0.11933\n\
                n_s = 0.9665\nns = 0.9665\nA_s = 2.105209e-9\nAs = 2.105209e-9\n";
    let parsed = Cosmology::from_ini_str(text, "both.ini").unwrap();
    assert_same(&parsed.cosmology, &Cosmology::planck2018(), 1e-6);
}

#[test]
fn each_error_names_the_problem() {
    let base = "h = 0.7\nomega_b = 0.022\nomega_cdm = 0.12\nn_s = 0.96\n";
    let cases: [(String, &[&str]); 13] = [
        (
            format!("{base}sigma8 0.8\n"),
            &["test.ini:5:", "`sigma8 0.8`", "key = value"],
        ),
        (format!("= 0.8\n{base}"), &["test.ini:1:", "`= 0.8`"]),
        (
            format!("{base}sigma8 = 0.8x\n"),
            &["test.ini:5:", "`0.8x`", "`sigma8`", "finite number"],
        ),
        (
            format!("{base}A_s = inf\n"),
            &["test.ini:5:", "`inf`", "`A_s`"],
        ),
        (
            format!("{base}sigma8 =\n"),
            &["test.ini:5:", "``", "`sigma8`"],
        ),
        (
            "h = 0.7\nomega_cdm = 0.12\nn_s = 0.96\nsigma8 = 0.8\n".to_string(),
            &["test.ini:", "baryon density", "`omega_b`", "`ombh2`"],
        ),
        (
            base.to_string(),
            &["test.ini:", "amplitude", "`sigma8`", "`A_s`"],
        ),
        (
            format!("{base}sigma8 = 0.8\nH0 = 68\n"),
            &["test.ini:6:", "`H0 = 68`", "`h = 0.7` (line 1)", "Hubble"],
        ),
        (
            format!("{base}sigma8 = 0.8\nOmega_b = 0.05\n"),
            &[
                "test.ini:6:",
                "`Omega_b = 0.05`",
                "`omega_b = 0.022` (line 2)",
            ],
        ),
        (
            format!("{base}A_s = 2e-9\nsigma8 = 0.8\n"),
            &[
                "test.ini:6:",
                "`sigma8 = 0.8`",
                "`A_s = 2e-9` (line 5)",
                "not both",
            ],
        ),
        (
            format!("{base}sigma8 = 0.8\nn_s = 0.96\n"),
            &["test.ini:6:", "`n_s`", "twice", "line 4"],
        ),
        (
            format!("{base}sigma8 = 0.8\nw0_fld = -0.2\nwa_fld = 0.3\n"),
            &["test.ini:", "not give a valid cosmology", "w0 + wa"],
        ),
        (
            format!("{base}sigma8 = 0.8\nOmega_k = -2\n"),
            &[
                "test.ini:",
                "`Omega_k = -2` is outside the plausible range of Omega_k, [-1, 1]",
            ],
        ),
    ];
    for (text, needles) in cases {
        let m = message(&text);
        println!("{m}");
        for needle in needles {
            assert!(m.contains(needle), "`{needle}` not in: {m}");
        }
    }
    // Key–value pairs: "line" is the pair's 1-based index.
    let e = Cosmology::from_keys([("h", "0.7"), ("h", "0.7")], "dict").unwrap_err();
    assert_eq!(
        e.to_string(),
        "dict:2: `h` is given twice (first on line 1)"
    );
    let e = Cosmology::from_keys([("h", "0.7"), (" ", "1")], "dict").unwrap_err();
    assert!(e.to_string().starts_with("dict:2:"), "{e}");
    // Long lines are cut in messages.
    let m = message(&format!("{}\n", "x".repeat(500)));
    assert!(m.len() < 200 && m.contains('…'), "{m}");
}

#[test]
fn files_and_names() {
    let dir = std::env::temp_dir().join(format!("pt-spectra-ini-test-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("planck.ini");
    // A non-UTF-8 byte in a comment is harmless.
    let mut bytes = b"# \xff Latin-1 comment\r\n".to_vec();
    bytes.extend_from_slice(CLASS_PLANCK2018.replace('\n', "\r\n").as_bytes());
    std::fs::write(&path, bytes).unwrap();
    let from_file = Cosmology::from_ini_file(&path).unwrap();
    assert_eq!(
        from_file,
        Cosmology::from_ini_str(CLASS_PLANCK2018, "x").unwrap()
    );
    let by_name = Cosmology::from_name_or_file(path.to_str().unwrap()).unwrap();
    assert_eq!(by_name, from_file);
    std::fs::write(&path, "h = 0.7\nbad line\n").unwrap();
    let e = Cosmology::from_ini_file(&path).unwrap_err().to_string();
    assert!(
        e.contains("planck.ini:2:") && e.contains("`bad line`"),
        "{e}"
    );
    std::fs::remove_dir_all(&dir).unwrap();

    let preset = Cosmology::from_name_or_file("planck2018").unwrap();
    assert_eq!(preset.cosmology, Cosmology::planck2018());
    assert!(preset.ignored.is_empty());
    let e = Cosmology::from_name_or_file("planck2015").unwrap_err();
    assert!(matches!(e, Error::UnknownCosmology { .. }), "{e}");
    assert!(e.to_string().contains("gm2012, planck2018"), "{e}");
    let e = Cosmology::from_name_or_file("no/such/params.ini").unwrap_err();
    assert!(
        matches!(e, Error::Io { .. }) && e.to_string().contains("no/such/params.ini"),
        "{e}"
    );
}

/// A line for the fuzz test: a read key, an unknown key or junk, with a number-like or arbitrary value.
fn fuzz_line() -> impl Strategy<Value = String> {
    let keys: Vec<&str> = KEYS.iter().map(|(key, _, _)| *key).collect();
    let key = prop_oneof![
        prop::sample::select(keys).prop_map(str::to_string),
        "[ -~]{0,12}",
    ];
    let value = prop_oneof![
        any::<f64>().prop_map(|v| v.to_string()),
        (-3.0..3.0_f64).prop_map(|v| v.to_string()),
        (1e-10..1e-8_f64).prop_map(|v| format!("{v:e}")),
        "[ -~]{0,12}",
        any::<String>(),
    ];
    prop_oneof![
        (key, value).prop_map(|(k, v)| format!("{k} = {v}")),
        any::<String>(),
        "[ #=a-z0-9.]{0,20}",
    ]
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(512))]

    /// Arbitrary bytes (decoded lossily, as a file is) never make the parser panic.
    #[test]
    fn arbitrary_bytes_never_panic(bytes in prop::collection::vec(any::<u8>(), 0..400)) {
        let _ = Cosmology::from_ini_str(&String::from_utf8_lossy(&bytes), "fuzz");
    }

    /// Arbitrary mixes of read keys, junk keys and values never panic either, and a success is valid.
    #[test]
    fn arbitrary_key_values_never_panic(lines in prop::collection::vec(fuzz_line(), 0..16)) {
        if let Ok(parsed) = Cosmology::from_ini_str(&lines.join("\n"), "fuzz") {
            prop_assert!(parsed.cosmology.validate().is_ok());
        }
    }
}

#[test]
fn neutrino_masses_from_class_lists_camb_mnu_and_omnuh2() {
    let base = "h = 0.67\nomega_b = 0.022\nomega_cdm = 0.12\nn_s = 0.96\nA_s = 2.1e-9\n";
    let class = |extra: &str| Cosmology::from_ini_str(&format!("{base}{extra}"), "nu.ini");
    let c = class("N_ncdm = 3\nm_ncdm = 0.02, 0.02, 0.02\nN_ur = 0.00641\n")
        .unwrap()
        .cosmology;
    assert_eq!(c.m_nu, 0.06);
    // ω_ν is part of Ω_m
    let expected = (0.022 + 0.12 + 0.06 / 93.14) / (0.67 * 0.67);
    assert!((c.omega_m / expected - 1.0).abs() < 1e-14);
    assert_eq!(
        class("N_ncdm = 1\nm_ncdm = 0.05\ndeg_ncdm = 3\nN_ur = 0.00641\n")
            .unwrap()
            .cosmology
            .m_nu,
        0.15
    );
    let camb = "H0 = 67\nombh2 = 0.022\nomch2 = 0.12\nns = 0.96\nAs = 2.1e-9\n";
    let c = Cosmology::from_ini_str(&format!("{camb}mnu = 0.06\n"), "camb.ini").unwrap();
    assert_eq!(c.cosmology.m_nu, 0.06);
    let c = Cosmology::from_ini_str(&format!("{camb}omnuh2 = 0.001\n"), "params.ini").unwrap();
    assert!((c.cosmology.m_nu - 0.09314).abs() < 1e-12);
    // a list that disagrees with N_ncdm is an error naming the line
    let e = class("N_ncdm = 2\nm_ncdm = 0.02, 0.02, 0.02\n")
        .unwrap_err()
        .to_string();
    assert!(e.contains("m_ncdm") && e.contains("nu.ini:7"), "{e}");
    // without neutrino masses, N_ncdm and deg_ncdm are listed as ignored
    let c = class("N_ncdm = 0\n").unwrap();
    assert_eq!(c.ignored, ["N_ncdm"]);
}

/// Issue 45 (fault sweep 2): keys of CLASS and CAMB that set the neutrinos, the primordial spectrum
/// or the matter density another way were listed as ignored and the spectrum computed without them,
/// exit 0 (`N_ncdm = 1, omega_ncdm = 0.000644` emulated massless; `m_ncdm` without `N_ncdm`, which
/// CLASS does not read, as massive; `T_ncdm`, `alpha_s`, `T_cmb`, `Omega_m = 0.5` dropped; CAMB's
/// `nu_mass_eigenstates = 2` as degenerate; `mnu` beside three equal `m_ncdm` as CLASS's setting; a
/// case slip `M_ncdm` as an unknown key). Each is refused naming the line, the key and the rule, or
/// accepted where it states what is modelled.
#[test]
fn keys_that_change_the_spectrum_another_way_are_refused_naming_them() {
    let class = "h = 0.67\nomega_b = 0.022\nomega_cdm = 0.12\nn_s = 0.96\nA_s = 2.1e-9\n";
    let camb = "H0 = 67\nombh2 = 0.022\nomch2 = 0.12\nns = 0.96\nAs = 2.1e-9\n";
    let refused = |base: &str, extra: &str, names: &[&str]| {
        let e = Cosmology::from_ini_str(&format!("{base}{extra}"), "x.ini")
            .map(|p| format!("accepted: {:?} ignored {:?}", p.cosmology, p.ignored))
            .unwrap_err_or_text();
        for n in names {
            assert!(e.contains(n), "{extra}: `{n}` not in: {e}");
        }
    };
    let three = "N_ncdm = 1\nm_ncdm = 0.02\ndeg_ncdm = 3\nN_ur = 0.00641\n";
    refused(
        class,
        "N_ncdm = 1\nomega_ncdm = 0.000644\nN_ur = 2.0328\n",
        &["x.ini:6", "N_ncdm", "m_ncdm"],
    );
    refused(
        class,
        "omega_ncdm = 0.000644\n",
        &["x.ini:6", "omega_ncdm", "m_ncdm"],
    );
    refused(
        class,
        "Omega_ncdm = 0.0014\n",
        &["x.ini:6", "Omega_ncdm", "m_ncdm"],
    );
    refused(
        class,
        "m_ncdm = 0.06\nN_ur = 2.0328\n",
        &["x.ini:6", "N_ncdm is not given"],
    );
    refused(
        class,
        "N_ncdm = 0\nm_ncdm = 0.06\nN_ur = 2.0328\n",
        &["x.ini:7", "N_ncdm = 0"],
    );
    refused(
        class,
        "N_ncdm = 3\nm_ncdm = 0.02 0.02 0.02\nN_ur = 0.00641\n",
        &["x.ini:7", "comma-separated"],
    );
    refused(
        class,
        &format!("{three}T_ncdm = 0.8\n"),
        &["x.ini:10", "T_ncdm = 0.8", "0.71611"],
    );
    refused(
        class,
        &format!("{three}ksi_ncdm = 1\n"),
        &["x.ini:10", "ksi_ncdm"],
    );
    refused(
        class,
        "alpha_s = 0.05\n",
        &["x.ini:6", "alpha_s", "power law"],
    );
    refused(camb, "nrun = 0.05\n", &["x.ini:6", "nrun"]);
    refused(class, "T_cmb = 3.5\n", &["x.ini:6", "T_cmb", "2.7255"]);
    refused(class, "omega_ur = 0\n", &["x.ini:6", "omega_ur", "N_ur"]);
    refused(
        class,
        "Omega_m = 0.5\n",
        &["x.ini:6", "Omega_m = 0.5", "0.316"],
    );
    refused(
        class,
        "100*theta_s = 1.04\n",
        &["x.ini:6", "100*theta_s", "h or H0"],
    );
    refused(
        class,
        "M_ncdm = 0.06\n",
        &["x.ini:6", "M_ncdm", "`m_ncdm`", "case"],
    );
    refused(camb, "omnuh2 = 0.000644\nmassless_neutrinos = 0.046\nmassive_neutrinos = 3\nnu_mass_eigenstates = 2\n", &["x.ini:9", "nu_mass_eigenstates"]);
    refused(
        camb,
        "mnu = 0.06\nnum_massive_neutrinos = 3\nnu_mass_fractions = 0.5 0.5\n",
        &["x.ini:8", "nu_mass_fractions"],
    );
    // CAMB's mnu (one massive species by CAMB's default) beside CLASS's three equal masses
    refused(
        class,
        "N_ncdm = 3\nm_ncdm = 0.02,0.02,0.02\nN_ur = 0.00641\nmnu = 0.06\n",
        &["mnu = 0.06", "m_ncdm", "different neutrino settings"],
    );
    // what is modelled anyway is accepted (and listed as ignored)
    let ok = |base: &str, extra: &str| {
        Cosmology::from_ini_str(&format!("{base}{extra}"), "x.ini")
            .unwrap_or_else(|e| panic!("{extra}: {e}"))
    };
    let p = ok(
        class,
        &format!("{three}T_ncdm = 0.71611\nalpha_s = 0\nT_cmb = 2.7255\n"),
    );
    assert_eq!(p.ignored, ["T_ncdm", "alpha_s", "T_cmb"]);
    assert_eq!(
        p.cosmology.neutrinos,
        crate::cosmology::Neutrinos::ThreeDegenerate
    );
    ok(class, "Omega_m = 0.3163\n");
    ok(class, "omega_m = 0.142\n");
    let p = ok(
        camb,
        "mnu = 0.06\nnum_nu_massive = 3\nnu_mass_eigenstates = 1\n",
    );
    assert_eq!(
        p.cosmology.neutrinos,
        crate::cosmology::Neutrinos::ThreeDegenerate
    );
    // a Python dict is strict: an unknown key is an error naming it; a read key is not
    let pairs = [
        ("h", "0.67"),
        ("omega_b", "0.022"),
        ("omega_cdm", "0.12"),
        ("n_s", "0.96"),
        ("A_s", "2.1e-9"),
    ];
    let e = Cosmology::from_keys_strict(pairs.iter().copied().chain([("m_ncmd", "0.06")]), "dict")
        .unwrap_err()
        .to_string();
    assert!(e.contains("`m_ncmd`") && e.contains("dict:6"), "{e}");
    assert!(Cosmology::from_keys_strict(
        pairs.iter().copied().chain([("T_cmb", "2.7255")]),
        "dict"
    )
    .is_ok());
    assert!(
        Cosmology::from_keys(pairs.iter().copied().chain([("m_ncmd", "0.06")]), "dict").is_ok()
    );
}

/// `Result::unwrap_err` as text, or the accepted value's text (so that an acceptance fails the
/// caller's `contains` with what was accepted).
trait ErrText {
    fn unwrap_err_or_text(self) -> String;
}

impl ErrText for std::result::Result<String, crate::error::Error> {
    fn unwrap_err_or_text(self) -> String {
        match self {
            Ok(accepted) => accepted,
            Err(e) => e.to_string(),
        }
    }
}
