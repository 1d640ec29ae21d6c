//! `--two-loop basis|direct|auto`: the basis tensors are built once for a grid, then used (also by
//! `auto`), agree with the direct integrals, and a spectrum outside their span is computed directly
//! with a warning.

use super::{column_names, fails_naming, rows, run};

#[test]
fn two_loop_basis_is_built_once_then_used_and_refuses_spectra_outside_its_span() {
    // A grid of its own, so that no other test finds these tensors in the cache.
    let grid = [
        "real",
        "--model",
        "2l-spt",
        "--terms",
        "--precision",
        "fast",
        "--nk",
        "3",
        "--k-min",
        "0.0311",
        "--k-max",
        "0.0917",
    ];
    let with = |extra: &[&'static str]| {
        let mut args = grid.to_vec();
        args.extend(extra);
        let (ok, out, err) = run(&args);
        assert!(ok, "{args:?}: {err}");
        (out, err)
    };
    let (basis, _) = with(&["--two-loop", "basis"]);
    assert!(basis.contains("basis tensors on 36 functions"), "{basis}");
    let (direct, _) = with(&["--two-loop", "direct"]);
    assert!(
        direct.contains("# 2-loop terms: direct integration\n"),
        "{direct}"
    );
    let (auto, _) = with(&[]);
    assert!(auto.contains("basis tensors on 36 functions"), "{auto}");
    assert_eq!(rows(&auto), rows(&basis), "auto reads the cached tensors");
    let names = column_names(&basis);
    let col = |n: &str| names.iter().position(|&x| x == n).unwrap();
    for (b, d) in rows(&basis).iter().zip(rows(&direct)) {
        for x in ["dd", "dt", "tt"] {
            let (v, e) = (
                b[col(&format!("P2loop_{x}"))],
                b[col(&format!("err_P2loop_{x}"))],
            );
            let w = d[col(&format!("P2loop_{x}"))];
            assert!(
                (v - w).abs() <= 1e-3 * w.abs() && (v - w).abs() <= e,
                "{x}: {v} vs {w} ± {e}"
            );
        }
    }
    // Eisenstein–Hu spectra are outside the span of the CAMB training spectra.
    let (eh, err) = with(&["--eh", "wiggle", "--two-loop", "basis"]);
    assert!(
        err.contains("note: 2-loop terms: direct integration, since"),
        "{err}"
    );
    assert!(eh.contains("exceeds 2.0e-3"), "{eh}");
    fails_naming(&[([&grid[..], &["--two-loop", "fancy"]].concat(), "fancy")]);
}
