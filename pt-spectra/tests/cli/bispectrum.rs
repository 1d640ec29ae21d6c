//! `pt-spectra bispectrum`: the real-space limit against the closed form, bins, headers and refusals.

use super::{fails_naming, rows, run};

/// The embedded gm2012 spectrum at z = 0 (the default input), read back from `real --model linear`.
/// Each call writes its own k file: tests run in parallel threads of one process, and two calls at
/// the same k once shared a file name, so that one read the file while the other truncated it.
fn p_lin(k: f64) -> f64 {
    static CALLS: std::sync::atomic::AtomicUsize = std::sync::atomic::AtomicUsize::new(0);
    let call = CALLS.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
    let file = std::env::temp_dir().join(format!("pt-spectra-bk-k-{}-{call}", std::process::id()));
    std::fs::write(&file, format!("{k}\n")).unwrap();
    let (ok, out, err) = run(&[
        "real",
        "--model",
        "linear",
        "--k-file",
        file.to_str().unwrap(),
    ]);
    assert!(ok, "{err}");
    rows(&out)[0][1]
}

#[test]
fn real_space_b0_is_the_closed_form_and_b2_b4_vanish() {
    let tri = [[0.02, 0.03, 0.04], [0.05, 0.05, 0.05], [0.01, 0.1, 0.105]];
    let file = std::env::temp_dir().join(format!("pt-spectra-bk-{}", std::process::id()));
    let text: String = tri
        .iter()
        .map(|t| format!("{} {} {}\n", t[0], t[1], t[2]))
        .collect();
    std::fs::write(&file, format!("# k1 k2 k3\n{text}")).unwrap();
    let (b1, b2, bs) = (1.8, 0.4, -0.2);
    let (ok, out, err) = run(&[
        "bispectrum",
        "--triangles",
        file.to_str().unwrap(),
        "--f",
        "0",
        "--no-ir",
        "--b1",
        "1.8",
        "--b2",
        "0.4",
        "--bs",
        "-0.2",
    ]);
    assert!(ok, "{err}");
    assert!(
        err.contains("without --bin-width"),
        "the point evaluation is warned about: {err}"
    );
    assert!(out.contains("at the given triangles (not averaged over bins)"));
    for (t, r) in tri.iter().zip(rows(&out)) {
        let mut closed = 0.0;
        for i in 0..3 {
            let (j, l) = ((i + 1) % 3, (i + 2) % 3);
            let c = (t[l] * t[l] - t[i] * t[i] - t[j] * t[j]) / (2.0 * t[i] * t[j]);
            let f2 = 5.0 / 7.0 + 0.5 * c * (t[i] / t[j] + t[j] / t[i]) + 2.0 / 7.0 * c * c;
            closed += 2.0
                * b1
                * b1
                * (b1 * f2 + 0.5 * b2 + bs * (c * c - 1.0 / 3.0))
                * p_lin(t[i])
                * p_lin(t[j]);
        }
        // the table prints 10 significant digits of both
        assert!(
            (r[3] / closed - 1.0).abs() < 1e-8,
            "{t:?}: {} vs {closed}",
            r[3]
        );
        assert!(
            r[4].abs() < 1e-9 * closed && r[5].abs() < 1e-9 * closed,
            "{r:?}"
        );
    }
    // The same bias in CLASS-PT's convention (b2 + (4/3) bs, b_G2 = bs) and FAST-PT's (2 bs): the
    // same bispectrum, and the header says how it was given.
    for extra in [
        [
            "--b2",
            "0.13333333333333336",
            "--bs",
            "-0.2",
            "--bias-convention",
            "classpt",
        ],
        ["--b2", "0.4", "--bs", "-0.4", "--bias-convention", "fastpt"],
    ] {
        let mut a = vec![
            "bispectrum",
            "--triangles",
            file.to_str().unwrap(),
            "--f",
            "0",
            "--no-ir",
            "--b1",
            "1.8",
        ];
        a.extend(extra);
        let (ok, same, err) = run(&a);
        assert!(ok, "{err}");
        assert!(same.contains("given in"), "{same}");
        for (x, y) in rows(&same).iter().zip(rows(&out)) {
            assert!(
                (x[3] / y[3] - 1.0).abs() < 1e-9,
                "{extra:?}: {x:?} vs {y:?}"
            );
        }
    }
}

#[test]
fn bins_from_edges_carry_errors_and_the_header_says_what_was_computed() {
    let (ok, out, err) = run(&[
        "bispectrum",
        "--k-edges",
        "0.01:0.05:0.01",
        "--b1",
        "2",
        "--n-bar",
        "3e-4",
        "--fog",
        "lorentzian",
        "--sigma-fog",
        "4",
    ]);
    assert!(ok, "{err}");
    for needle in [
        "bin averages over all closed triangles",
        "f(z) of the cosmology",
        "Lorentzian",
        "IR resummation of the BAO",
    ] {
        assert!(out.contains(needle), "{needle}: {out}");
    }
    let r = rows(&out);
    assert_eq!(r.len(), 17, "bins of 4 shells whose centres close");
    for row in r {
        assert!(
            row[3] > 0.0 && row[6] > 0.0 && row[6] < 1e-2 * row[3],
            "{row:?}"
        );
    }
}

#[test]
fn the_effective_triangle_shortcut_states_its_error_and_needs_bins() {
    let args = |effective: bool| {
        let mut a = vec![
            "bispectrum",
            "--k-edges",
            "0.01:0.05:0.01",
            "--b1",
            "2",
            "--fog",
            "lorentzian",
            "--sigma-fog",
            "4",
        ];
        if effective {
            a.push("--effective");
        }
        run(&a)
    };
    let (ok, average, err) = args(false);
    assert!(ok, "{err}");
    let (ok, shortcut, err) = args(true);
    assert!(ok, "{err}");
    assert!(
        shortcut.contains("effective-triangle shortcut"),
        "{shortcut}"
    );
    let (a, s) = (rows(&average), rows(&shortcut));
    assert_eq!(a.len(), s.len());
    let mut off = false;
    for (a, s) in a.iter().zip(&s) {
        // columns k1 k2 k3 B0 B2 B4 err_B0 err_B2 err_B4: the shortcut's stated error covers its
        // distance from the bin average, and that distance is not nothing
        for l in 0..3 {
            assert!(
                (s[3 + l] - a[3 + l]).abs() <= s[6 + l] + a[6 + l],
                "{a:?} {s:?}"
            );
        }
        off |= (s[3] - a[3]).abs() > 10.0 * a[6];
    }
    assert!(off, "the shortcut differs from the average somewhere");
    fails_naming(&[(
        vec![
            "bispectrum",
            "--k-edges",
            "0.01:0.05:0.01",
            "--box",
            "1000",
            "--effective",
        ],
        "effective-triangle shortcut",
    )]);
}

#[test]
fn bad_triangles_and_choices_are_refused() {
    let file = std::env::temp_dir().join(format!("pt-spectra-bk-bad-{}", std::process::id()));
    std::fs::write(&file, "0.01 0.02 0.05\n").unwrap();
    let f = file.to_str().unwrap();
    fails_naming(&[
        (vec!["bispectrum"], "give the triangles"),
        (vec!["bispectrum", "--triangles", f], "does not close"),
        (
            vec!["bispectrum", "--k-edges", "0.01,0.02,0.04"],
            "uniform shells",
        ),
        (
            vec![
                "bispectrum",
                "--k-edges",
                "0.01:0.05:0.01",
                "--fog",
                "lorentz",
            ],
            "valid: none, lorentzian, gaussian",
        ),
        (
            vec![
                "bispectrum",
                "--k-edges",
                "0.01:0.05:0.01",
                "--legendre-side",
                "4",
            ],
            "valid: largest, 1, 2, 3",
        ),
        (
            vec!["bispectrum", "--k-edges", "0.01:0.05:0.01", "--n-bar", "-1"],
            "n_bar",
        ),
        (
            vec!["bispectrum", "--k-edges", "0.01:0.05:0.01", "--q-par", "0"],
            "q_par",
        ),
    ]);
}

#[test]
fn sugiyama_multipoles_at_pairs_with_errors_and_refusals() {
    let file = std::env::temp_dir().join(format!("pt-spectra-bk-pairs-{}", std::process::id()));
    std::fs::write(&file, "# k1 k2\n0.05 0.05\n0.02 0.1\n").unwrap();
    let f = file.to_str().unwrap();
    let (ok, out, err) = run(&[
        "bispectrum",
        "--basis",
        "sugiyama",
        "--pairs",
        f,
        "--f",
        "0",
        "--no-ir",
        "--b1",
        "1.8",
    ]);
    assert!(ok, "{err}");
    assert!(out.contains("Sugiyama et al. (2019)") && out.contains("err_B*: difference"));
    assert!(out.contains("# k1 k2 B000 B110 B202 B022 B112 B220 err_B000"));
    for r in rows(&out) {
        // f = 0: B does not depend on the line of sight, the L = 2 multipoles vanish
        assert!(r[2] > 0.0 && r[8] <= 1e-4 * r[2], "{r:?}");
        for m in [4, 5, 6] {
            assert!(r[m].abs() <= 1e-10 * r[2], "{r:?}");
        }
    }
    fails_naming(&[
        (vec!["bispectrum", "--basis", "sugiyama"], "needs --pairs"),
        (
            vec!["bispectrum", "--basis", "bispec", "--pairs", f],
            "valid: scoccimarro, sugiyama",
        ),
        (
            vec!["bispectrum", "--pairs", f],
            "--pairs is for --basis sugiyama",
        ),
        (
            vec![
                "bispectrum",
                "--basis",
                "sugiyama",
                "--pairs",
                f,
                "--k-edges",
                "0.01:0.05:0.01",
            ],
            "cannot be used with",
        ),
    ]);
}

#[test]
fn box_averages_from_edges_are_exact_sums() {
    // L = 1000 Mpc/h, shells of width 3 k_f: the header says what was summed, errors are zero
    let kf = 2.0 * std::f64::consts::PI / 1000.0;
    let edges = format!("{},{},{}", 1.5 * kf, 4.5 * kf, 7.5 * kf);
    let (ok, out, err) = run(&[
        "bispectrum",
        "--k-edges",
        &edges,
        "--box",
        "1000",
        "--no-ir",
    ]);
    assert!(ok, "{err}");
    assert!(out.contains("discrete modes of a periodic box of side 1000 Mpc/h"));
    let rows = rows(&out);
    assert!(!rows.is_empty());
    for r in rows {
        assert!(r[3] > 0.0 && r[6] == 0.0, "{r:?}");
    }
    fails_naming(&[(
        vec!["bispectrum", "--k-edges", &edges, "--box", "-1"],
        "side of the box",
    )]);
}

/// `--loop 1`: the one-loop matter terms at triangles, the tree column the closed form, the total the
/// sum of the terms, a header that says what was computed; galaxy options, bins and other orders refused.
#[test]
fn one_loop_matter_terms_at_triangles_and_refusals() {
    let file = std::env::temp_dir().join(format!("pt-spectra-bk1-{}", std::process::id()));
    std::fs::write(&file, "# k1 k2 k3\n0.05 0.1 0.12\n0.1 0.1 0.1\n").unwrap();
    let path = file.to_str().unwrap();
    let (ok, out, err) = run(&["bispectrum", "--loop", "1", "--triangles", path]);
    assert!(ok, "{err}");
    assert!(
        out.contains("one-loop matter bispectrum in real space"),
        "{out}"
    );
    assert!(out.contains("no counterterms"), "{out}");
    assert!(out.contains("0.0001 <= |q| <= 10 h/Mpc"), "{out}");
    let names =
        "# k1 k2 k3 B_tree B222 B321_I B321_II B411 B_1loop err_B_tree err_B222 err_B321_I \
                 err_B321_II err_B411 err_B_1loop shape_ct_f2 shape_ct_k3 shape_ct_tidal shape_ct_f2k3";
    assert!(out.lines().any(|l| l == names), "{out}");
    for (t, r) in [[0.05, 0.1, 0.12], [0.1, 0.1, 0.1]].iter().zip(rows(&out)) {
        // the tree 2 F2 P P + cyclic, and the c_s²-type counterterm shape: each term times k_i² + k_j²
        let (mut closed, mut shape) = (0.0, 0.0);
        for i in 0..3 {
            let (j, l) = ((i + 1) % 3, (i + 2) % 3);
            let c = (t[l] * t[l] - t[i] * t[i] - t[j] * t[j]) / (2.0 * t[i] * t[j]);
            let f2 = 5.0 / 7.0 + 0.5 * c * (t[i] / t[j] + t[j] / t[i]) + 2.0 / 7.0 * c * c;
            closed += 2.0 * f2 * p_lin(t[i]) * p_lin(t[j]);
            shape += 2.0 * f2 * p_lin(t[i]) * p_lin(t[j]) * (t[i] * t[i] + t[j] * t[j]);
        }
        assert!(
            (r[15] - shape).abs() < 1e-8 * shape,
            "{t:?}: shape {} vs {shape}",
            r[15]
        );
        assert!(
            (r[3] - closed).abs() < 1e-8 * closed,
            "{t:?}: {} vs {closed}",
            r[3]
        );
        let sum: f64 = r[3..8].iter().sum();
        assert!(
            (r[8] - sum).abs() < 1e-8 * sum.abs(),
            "{t:?}: total {} vs {sum}",
            r[8]
        );
        assert!(
            r[14] > 0.0 && r[14] < 1e-3 * r[8].abs(),
            "{t:?}: err {}",
            r[14]
        );
    }
    // Through the basis tensors (built in a private cache, then read back): every column within the
    // direct run's and its own errors, and the header says how the loop terms were computed.
    assert!(out.contains("loop terms: direct integration"), "{out}");
    let cache = std::env::temp_dir().join(format!("pt-spectra-bk1-cache-{}", std::process::id()));
    let cache_arg = cache.to_str().unwrap();
    for _ in 0..2 {
        let (ok, basis, err) = run(&[
            "bispectrum",
            "--loop",
            "1",
            "--triangles",
            path,
            "--two-loop",
            "basis",
            "--cache-dir",
            cache_arg,
        ]);
        assert!(ok, "{err}");
        assert!(
            basis.contains("loop terms: basis tensors on 36 functions"),
            "{basis}"
        );
        for (b, d) in rows(&basis).iter().zip(rows(&out)) {
            for j in 3..9 {
                let tol = b[j + 6] + d[j + 6];
                assert!(
                    (b[j] - d[j]).abs() <= tol,
                    "column {j}: {} vs {} (+- {tol})",
                    b[j],
                    d[j]
                );
            }
        }
    }
    let _ = std::fs::remove_dir_all(&cache);
    // Redshift space at one orientation (--mu1, --phi-los, --f): at f = 0 the real-space terms (the
    // line of sight in the triangle's plane: the same nodes), the header states f and the orientation.
    let (ok, rsd, err) = run(&[
        "bispectrum",
        "--loop",
        "1",
        "--triangles",
        path,
        "--mu1",
        "0.5",
        "--f",
        "0",
    ]);
    assert!(ok, "{err}");
    assert!(
        rsd.contains("in redshift space (SPT)")
            && rsd.contains("f = 0, line of sight at mu1 = 0.5"),
        "{rsd}"
    );
    for (b, d) in rows(&rsd).iter().zip(rows(&out)) {
        for j in 3..9 {
            assert!(
                (b[j] - d[j]).abs() <= 1e-10 * d[j].abs(),
                "column {j}: {} vs {}",
                b[j],
                d[j]
            );
        }
    }
    let (ok, rsd, err) = run(&[
        "bispectrum",
        "--loop",
        "1",
        "--triangles",
        path,
        "--mu1",
        "0.5",
        "--phi-los",
        "0.3",
        "--f",
        "0.7",
    ]);
    assert!(ok, "{err}");
    assert!(
        rows(&rsd)[1][3] > 1.5 * rows(&out)[1][3],
        "Kaiser-like boost of the tree: {rsd}"
    );
    let with = |extra: &[&'static str]| {
        let mut a = vec!["bispectrum", "--loop", "1", "--triangles", path];
        a.extend(extra);
        a
    };
    // Galaxies (any bias option): with matter's bias the galaxy kernels are F_n, so the galaxy path
    // without the IR resummation gives the matter columns (its own kernels and renormalisation, nothing
    // subtracted for b1 alone); b2 alone adds b2 sum_(a<b) P_a P_b to the tree (K2 += b2/2), exactly.
    let (ok, galaxy, err) = run(&with(&["--bias-convention", "velocileptors", "--no-ir"]));
    assert!(ok, "{err}");
    assert!(
        galaxy.contains("one-loop galaxy bispectrum in real space")
            && galaxy.contains("no IR resummation (--no-ir"),
        "{galaxy}"
    );
    // By default (as the tree level) the galaxy bispectrum is IR-resummed: the header says so with its
    // Sigma^2; the tree column is the library's resummed tree (legs P_nw + e^-x (1 + x) P_w, the split
    // of the default spectrum, gm2012 at z = 0), the loops differ from the plain ones, the total sums.
    let (ok, resummed, err) = run(&with(&["--bias-convention", "velocileptors"]));
    assert!(ok, "{err}");
    assert!(
        resummed.contains("IR resummation of the BAO (leading order")
            && resummed.contains("Sigma^2 = ")
            && resummed.contains("not in err_"),
        "{resummed}"
    );
    {
        use pt_spectra::bispectrum::one_loop::OneLoopRule;
        use pt_spectra::bispectrum::{bias_kernels::LoopBias, one_loop_ir, IrInputs};
        let p = pt_spectra::linear::LinearSpectrum::gm2012_z0();
        let split = pt_spectra::ir::WiggleSplit::new().unwrap();
        let q_min = pt_spectra::precision::Precision::default().q_min;
        let ir = IrInputs::split(&p, &split, q_min).unwrap();
        let tiny = OneLoopRule {
            radial: 2,
            mu: 2,
            phi: 2,
            ..OneLoopRule::default()
        };
        let triangles = [[0.05, 0.1, 0.12], [0.1, 0.1, 0.1]];
        for ((t, r), g) in triangles.iter().zip(rows(&resummed)).zip(rows(&galaxy)) {
            let b = one_loop_ir::one_loop_galaxy_ir(&p, &ir, *t, &LoopBias::matter(), None, &tiny)
                .unwrap();
            assert!(
                (r[3] - b.tree.value).abs() < 2e-9 * r[3].abs(),
                "{t:?}: {r:?}"
            );
            assert!(
                (r[3] - g[3]).abs() > 1e-4 * g[3].abs(),
                "{t:?}: the tree resummed"
            );
            for j in 4..8 {
                assert!((r[j] - g[j]).abs() > 1e-6 * g[j].abs(), "{t:?}: column {j}");
            }
            let sum: f64 = r[3..8].iter().sum();
            assert!((r[8] - sum).abs() < 1e-8 * sum.abs(), "{t:?}");
        }
    }
    assert!(galaxy.contains("b1 = 1, b2 = 0, g2 = 0"), "{galaxy}");
    for (g, m) in rows(&galaxy).iter().zip(rows(&out)) {
        for j in 3..9 {
            assert!(
                (g[j] - m[j]).abs() <= 1e-12 * m[j].abs(),
                "column {j}: {} vs {}",
                g[j],
                m[j]
            );
        }
        assert!(g[15] == 0.0 && g[16] == 0.0, "uv of matter: {g:?}");
    }
    let (ok, b2, err) = run(&with(&["--b2", "0.5", "--no-ir"]));
    assert!(ok, "{err}");
    for (t, (g, m)) in [[0.05, 0.1, 0.12], [0.1, 0.1, 0.1]]
        .iter()
        .zip(rows(&b2).iter().zip(rows(&out)))
    {
        let pp = p_lin(t[0]) * p_lin(t[1]) + p_lin(t[1]) * p_lin(t[2]) + p_lin(t[2]) * p_lin(t[0]);
        let expected = m[3] + 0.5 * pp;
        // the table prints 10 significant digits
        assert!(
            (g[3] - expected).abs() < 2e-9 * expected,
            "{t:?}: {} vs {expected}",
            g[3]
        );
    }
    fails_naming(&[
        (with(&["--loop-bias", "b2=1"]), "valid: b3, g2x"),
        (with(&["--loop-bias", "g21"]), "NAME=VALUE"),
        (with(&["--loop-bias", "g21=1,g21=2"]), "given twice"),
        (
            with(&["--b1", "2", "--mu1", "0.5", "--two-loop", "basis"]),
            "real space only",
        ),
        (
            vec!["bispectrum", "--triangles", path, "--b-gamma3", "0.1"],
            "give --loop 1",
        ),
        (with(&["--f", "0.5"]), "--f"),
        (with(&["--bin-width", "0.01"]), "not built yet"),
        (
            vec!["bispectrum", "--loop", "1", "--k-edges", "0.02:0.1:0.02"],
            "--k-edges",
        ),
        (
            vec!["bispectrum", "--loop", "2", "--triangles", path],
            "--loop 2: valid",
        ),
        (
            vec!["bispectrum", "--triangles", path, "--mu1", "0.5"],
            "give --loop 1",
        ),
        (
            vec![
                "bispectrum",
                "--loop",
                "1",
                "--triangles",
                path,
                "--mu1",
                "1.5",
            ],
            "mu1",
        ),
        (
            vec![
                "bispectrum",
                "--loop",
                "1",
                "--triangles",
                path,
                "--mu1",
                "0.5",
                "--two-loop",
                "basis",
            ],
            "real space only",
        ),
    ]);
}
