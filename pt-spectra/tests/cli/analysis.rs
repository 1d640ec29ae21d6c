//! `fit --analysis FILE.toml`: the joint fit of two data sets made by `rsd --rsd ept` with
//! different b1 and the same f, and the file's errors.

use super::{column_names_of, fails_naming, rows, run, scratch, write};

/// Noise-free ept multipoles ℓ = 0, 2, 4 with b1 = `b1`, f = 0.7, as `k P0 σ P2 σ P4 σ` (σ = 1% of
/// P0) on 25 k in [0.02, 0.2] h/Mpc.
fn model(b1: &str) -> String {
    super::ept_multipoles(&[
        "--bias", b1, "--b2", "-0.4", "--alpha0", "8", "--sn", "900", "--f", "0.7",
    ])
}

/// The body of a data set of the analysis file.
fn set(label: &str, data: &str) -> String {
    format!(
        "[[dataset]]\nlabel = \"{label}\"\ndata = \"{data}\"\nz = 0.0\nells = [0, 2]\nk_max = 0.2\n\
         free = [\"f\", \"b1\"]\nmarginalise = [\"alpha0\", \"sn\"]\n\
         [dataset.start]\nb1 = 2.0\nb2 = -0.4\nf = 0.6\n\n"
    )
}

const SEARCH: &str = "[search]\nstarts = 4\nprofile_check = false\n\n";

/// Two sets with b1 = 1.8 and 2.2 and f = 0.7 shared by default (same z, same tracer): a row per
/// set, each b1 recovered, one f (the same value and error in both rows); the header states the sets
/// and the sharing.
#[test]
fn analysis_file_fits_two_sets_with_a_shared_f() {
    let dir = scratch("analysis_two_sets");
    write(&dir, "low.dat", &model("1.8"));
    write(&dir, "high.dat", &model("2.2"));
    let file = write(
        &dir,
        "joint.toml",
        &format!(
            "{SEARCH}{}{}",
            set("low", "low.dat"),
            set("high", "high.dat")
        ),
    );
    let (ok, out, err) = run(&["fit", "--analysis", &file, "--precision", "fast"]);
    assert!(ok, "{err}");
    assert!(out.contains("data set low: "), "{out}");
    assert!(out.contains("data set high: "), "{out}");
    assert!(
        out.contains("shared parameters (the default") && out.contains("): f;"),
        "{out}"
    );
    assert!(
        out.contains("joint free parameters: f, b1[low], b1[high]"),
        "{out}"
    );
    let names = column_names_of(&out, "# set ");
    let table = rows(&out);
    assert_eq!(table.len(), 2);
    let get = |r: usize, n: &str| table[r][names.iter().position(|c| *c == n).unwrap()];
    for (r, b1) in [(0, 1.8), (1, 2.2)] {
        let (v, e) = (get(r, "b1"), get(r, "err_b1"));
        assert!((v - b1).abs() < 0.1 * e, "b1 of set {r}: {v} ± {e}");
        let (f, ef) = (get(r, "f"), get(r, "err_f"));
        assert!((f - 0.7).abs() < 0.1 * ef, "f: {f} ± {ef}");
    }
    assert_eq!(get(0, "f"), get(1, "f"));
    assert_eq!(get(0, "err_f"), get(1, "err_f"));
    assert!(names.contains(&"fsigma8"));
}

/// The same two sets in the DESI physical basis (`basis = "desi"`, `n_bar`): b1p, b2p free per set,
/// f shared, sn0p marginalised, against b1, b2 and sn in the model's basis (the counterterm fixed at 0
/// in both): a change of variables, so the same b1 (= b1p/sigma8_z) and f; `desi_priors` puts the DESI
/// priors in the header; a set without n_bar, or sets in two bases, refused by name.
#[test]
fn analysis_file_in_the_desi_physical_basis() {
    let dir = scratch("analysis_desi");
    write(&dir, "low.dat", &model("1.8"));
    write(&dir, "high.dat", &model("2.2"));
    // b2 free in both: a fixed b2p is not a fixed b2 (b2 = b2p/sigma8^2 + (8/21)(b1 - 1)).
    let vel = |label: &str, data: &str| {
        set(label, data)
            .replace("free = [\"f\", \"b1\"]", "free = [\"f\", \"b1\", \"b2\"]")
            .replace(
                "marginalise = [\"alpha0\", \"sn\"]",
                "marginalise = [\"sn\"]",
            )
    };
    let desi = |label: &str, data: &str| {
        set(label, data)
            .replace("free = [\"f\", \"b1\"]", "free = [\"f\", \"b1p\", \"b2p\"]")
            .replace(
                "marginalise = [\"alpha0\", \"sn\"]",
                "marginalise = [\"sn0p\"]\nbasis = \"desi\"\nn_bar = 3e-4",
            )
    };
    let fit = |name: &str, body: String| {
        let file = write(&dir, name, &format!("{SEARCH}{body}"));
        let (ok, out, err) = run(&["fit", "--analysis", &file, "--precision", "fast"]);
        assert!(ok, "{err}");
        out
    };
    let a = fit("vel.toml", vel("low", "low.dat") + &vel("high", "high.dat"));
    let b = fit(
        "desi.toml",
        desi("low", "low.dat") + &desi("high", "high.dat"),
    );
    assert!(
        b.contains("data set low: parameter basis: DESI DR1 physical"),
        "{b}"
    );
    let column = |out: &str, r: usize, n: &str| {
        let names = column_names_of(out, "# set ");
        rows(out)[r][names
            .iter()
            .position(|c| *c == n)
            .unwrap_or_else(|| panic!("{n}"))]
    };
    for r in 0..2 {
        let (x, y, e) = (
            column(&a, r, "b1"),
            column(&b, r, "b1"),
            column(&a, r, "err_b1"),
        );
        assert!((x - y).abs() < 0.01 * e, "b1 of set {r}: {x} vs {y} ± {e}");
        let b1p = column(&b, r, "b1p");
        assert!((b1p - y * column(&b, r, "sigma8_z")).abs() < 1e-9 * b1p);
        let (x, y, e) = (
            column(&a, r, "f"),
            column(&b, r, "f"),
            column(&a, r, "err_f"),
        );
        assert!((x - y).abs() < 0.01 * e, "f: {x} vs {y} ± {e}");
    }
    let with_priors =
        |l: &str, d: &str| desi(l, d).replace("n_bar = 3e-4", "n_bar = 3e-4\ndesi_priors = true");
    let c = fit(
        "priors.toml",
        with_priors("low", "low.dat") + &with_priors("high", "high.dat"),
    );
    assert!(
        c.contains("b1p: U[0, 3]") && c.contains("sn0p: N(0, 2^2)"),
        "{c}"
    );
    let mixed = write(
        &dir,
        "mixed.toml",
        &format!(
            "{SEARCH}{}{}",
            desi("low", "low.dat"),
            set("high", "high.dat")
        ),
    );
    let no_n_bar = write(
        &dir,
        "no_n_bar.toml",
        &desi("low", "low.dat").replace("n_bar = 3e-4", ""),
    );
    fails_naming(&[
        (vec!["fit", "--analysis", &mixed], "same basis"),
        (vec!["fit", "--analysis", &no_n_bar], "needs n_bar"),
    ]);
}

/// Every mistake in the file is an error naming the file, the key and the rule.
#[test]
fn analysis_file_errors_name_the_file_key_and_rule() {
    let dir = scratch("analysis_errors");
    write(&dir, "low.dat", "0.05 1 0.1 1 0.1 1 0.1\n");
    let case = |name: &str, text: &str| write(&dir, name, text);
    let good = set("low", "low.dat");
    let unknown = case("unknown.toml", &good.replace("k_max", "kmax"));
    let missing = case("missing.toml", &set("low", "nowhere.dat"));
    let shared = case("shared.toml", &format!("shared = [\"apar\"]\n{good}"));
    let syntax = case("syntax.toml", "[[dataset]\nlabel = 1\n");
    let top = case("top.toml", &format!("share = [\"f\"]\n{good}"));
    let twice = case("twice.toml", &format!("{good}{good}"));
    let prior = case(
        "prior.toml",
        &good.replace("k_max = 0.2", "k_max = 0.2\npriors = [\"b2:0\"]"),
    );
    fails_naming(&[
        (
            vec!["fit", "--analysis", &unknown],
            "unknown.toml: `dataset[1].kmax`: unknown key",
        ),
        (
            vec!["fit", "--analysis", &missing],
            "missing.toml: `dataset[1].data`: the file",
        ),
        (
            vec!["fit", "--analysis", &missing],
            "nowhere.dat does not exist",
        ),
        (
            vec!["fit", "--analysis", &shared],
            "shared.toml: `shared`: `apar` is declared shared but no data set has it free",
        ),
        (
            vec!["fit", "--analysis", &syntax],
            "syntax.toml: is not valid TOML",
        ),
        (
            vec!["fit", "--analysis", &top],
            "top.toml: `share`: unknown key",
        ),
        (
            vec!["fit", "--analysis", &twice],
            "twice.toml: `dataset[2].label`: `low` is given twice",
        ),
        (
            vec!["fit", "--analysis", &prior],
            "prior.toml: `dataset[1].priors`",
        ),
        (
            vec!["fit", "--analysis", &unknown, "--data", &unknown],
            "cannot be used with",
        ),
        (
            vec!["fit", "--analysis", "/nonexistent/a.toml"],
            "/nonexistent/a.toml",
        ),
        (
            vec!["fit", "--analysis", &unknown, "--rsd", "kaiser"],
            "--analysis fits the galaxy model",
        ),
    ]);
}

/// A data set with its bispectrum (`[dataset.bispectrum]`): noise-free P (`rsd --rsd ept`) and B0, B2
/// (`bispectrum`) of one truth (b1 = 2, b2 = −0.4, f = 0.7, c1 = 4, b_shot = 1.3, n̄ = 3e-4), a
/// diagonal joint covariance (1% of P0, 2% of |B0|): f, b1, b2, c1 free, b_shot marginalised, the
/// truth recovered; the header states the bispectrum and the table has its parameters; a joint file
/// of the wrong size and a `covariance` beside it refused by name.
#[test]
fn analysis_file_fits_the_power_spectrum_with_its_bispectrum() {
    let dir = scratch("analysis_bispectrum");
    let p = super::ept_multipoles(&[
        "--bias", "2", "--b2", "-0.4", "--alpha0", "8", "--sn", "900", "--f", "0.7",
    ]);
    write(&dir, "p.dat", &p);
    let tri = "0.03 0.03 0.03\n0.05 0.05 0.05\n0.08 0.08 0.08\n0.04 0.05 0.06\n0.06 0.08 0.1\n\
               0.02 0.08 0.09\n0.05 0.1 0.1\n0.03 0.06 0.08\n";
    let triangles = write(&dir, "tri.dat", tri);
    let (ok, out, err) = run(&[
        "bispectrum",
        "--triangles",
        &triangles,
        "--b1",
        "2",
        "--b2",
        "-0.4",
        "--f",
        "0.7",
        "--c1",
        "4",
        "--n-bar",
        "3e-4",
        "--b-shot",
        "1.3",
    ]);
    assert!(ok, "{err}");
    let b: Vec<Vec<f64>> = rows(&out);
    let names = column_names_of(&out, "# k1 ");
    let col = |n: &str| names.iter().position(|c| *c == n).unwrap();
    let b_text: String = b
        .iter()
        .map(|r| {
            format!(
                "{} {} {} {} {} {}\n",
                r[0],
                r[1],
                r[2],
                r[col("B0")],
                r[col("B2")],
                r[col("B4")]
            )
        })
        .collect();
    write(&dir, "b.dat", &b_text);
    // the diagonal joint covariance: P0, P2, P4 (25 k each, sigma of the data file), then B0, B2, B4
    let mut variances: Vec<f64> = Vec::new();
    let p_rows = rows(&p);
    for j in 0..3 {
        variances.extend(p_rows.iter().map(|r| r[2 + 2 * j].powi(2)));
    }
    for _ in 0..3 {
        variances.extend(b.iter().map(|r| (0.02 * r[col("B0")]).powi(2)));
    }
    let n = variances.len();
    let matrix = |n: usize| -> String {
        (0..n)
            .map(|i| {
                let row: Vec<String> = (0..n)
                    .map(|j| {
                        if i == j {
                            variances[i].to_string()
                        } else {
                            "0".into()
                        }
                    })
                    .collect();
                row.join(" ") + "\n"
            })
            .collect()
    };
    write(&dir, "joint.dat", &matrix(n));
    let analysis = |covariance: &str, extra: &str| {
        format!(
            "{SEARCH}[[dataset]]\nlabel = \"pb\"\ndata = \"p.dat\"\nz = 0.0\nells = [0, 2]\n\
             k_max = 0.2\nfree = [\"f\", \"b1\", \"b2\", \"c1\"]\n\
             marginalise = [\"alpha0\", \"sn\", \"b_shot\"]\n{extra}\
             [dataset.start]\nb1 = 1.9\nb2 = 0.0\nf = 0.6\n\
             [dataset.bispectrum]\ndata = \"b.dat\"\nells = [0, 2]\nk_max = 0.1\n\
             covariance = \"{covariance}\"\nn_bar = 3e-4\n"
        )
    };
    let file = write(&dir, "pb.toml", &analysis("joint.dat", ""));
    let (ok, out, err) = run(&["fit", "--analysis", &file, "--precision", "fast"]);
    assert!(ok, "{err}");
    assert!(
        out.contains("data set pb: bispectrum: B_l for l in [0, 2] of 8 triangles"),
        "{out}"
    );
    let names = column_names_of(&out, "# set ");
    let table = rows(&out);
    let get = |n: &str| table[0][names.iter().position(|c| *c == n).unwrap()];
    for (name, want) in [
        ("f", 0.7),
        ("b1", 2.0),
        ("b2", -0.4),
        ("c1", 4.0),
        ("b_shot", 1.3),
    ] {
        let (v, e) = (get(name), get(&format!("err_{name}")));
        assert!((v - want).abs() < 0.1 * e, "{name}: {v} ± {e}");
    }
    assert_eq!(get("points"), 50.0 + 16.0);
    // refused: a joint file of the wrong size; a covariance beside the joint one
    write(&dir, "small.dat", &matrix(n - 1));
    let small = write(&dir, "small.toml", &analysis("small.dat", ""));
    let both = write(
        &dir,
        "both.toml",
        &analysis("joint.dat", "covariance = \"joint.dat\"\n"),
    );
    let (ok, _, err) = run(&["fit", "--analysis", &small, "--precision", "fast"]);
    assert!(
        !ok && err.contains("small.dat") && err.contains("the joint covariance is square"),
        "{err}"
    );
    let (ok, _, err) = run(&["fit", "--analysis", &both, "--precision", "fast"]);
    assert!(!ok && err.contains("covariance with a bispectrum"), "{err}");
}
