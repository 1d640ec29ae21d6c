//! Outputs byte for byte as before: the commands of `tests/fixtures/make.sh` (every subcommand but
//! `plot` and the 2-loop `real --model all`) rerun on the committed inputs, compared with the
//! committed tables they made. A change of any number, column or header line of `real`, `rsd`,
//! `halo` or `fit` fails here; a deliberate change regenerates the fixtures with `make.sh`.

use super::scratch;
use std::path::Path;
use std::process::Command;

const FIXTURES: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/fixtures");

/// Runs the binary in `dir` (relative paths as in make.sh) with an empty cache, so that no cached
/// basis tensors change the method of `auto`; returns its stdout.
fn run_in(dir: &Path, args: &[&str]) -> String {
    let cache = dir.join("cache");
    let out = Command::new(env!("CARGO_BIN_EXE_pt-spectra"))
        .args(args)
        .current_dir(dir)
        .env("PT_SPECTRA_CACHE", &cache)
        .output()
        .expect("the binary runs");
    assert!(
        out.status.success(),
        "{args:?}: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    String::from_utf8(out.stdout).expect("utf-8")
}

fn same(dir: &Path, name: &str) {
    let made = std::fs::read_to_string(dir.join(name)).unwrap();
    let fixture = std::fs::read_to_string(Path::new(FIXTURES).join(name)).unwrap();
    if made != fixture {
        let line = made
            .lines()
            .zip(fixture.lines())
            .position(|(a, b)| a != b)
            .map_or("the line count".to_string(), |i| format!("line {}", i + 1));
        panic!("{name} differs from its fixture at {line}");
    }
}

#[test]
fn real_rsd_halo_and_fit_write_their_fixtures_byte_for_byte() {
    let dir = scratch("fixtures");
    for input in ["pmm.dat", "pmh.dat", "phh.dat", "mock.dat"] {
        std::fs::copy(Path::new(FIXTURES).join(input), dir.join(input)).unwrap();
    }
    let grid = [
        "--k-min",
        "0.02",
        "--k-max",
        "0.25",
        "--nk",
        "10",
        "--precision",
        "fast",
    ];
    for n in ["0", "1"] {
        let model = format!("1l-rpt-n{n}");
        let out = format!("prop_n{n}.dat");
        let mut args = vec!["real", "--model", &model, "--terms"];
        args.extend(grid);
        args.extend(["--out", &out]);
        run_in(&dir, &args);
        same(&dir, &out);
    }
    run_in(
        &dir,
        &[
            "halo",
            "--pmm",
            "pmm.dat",
            "--pmh",
            "pmh.dat",
            "--phh",
            "phh.dat",
            "--columns",
            "1,2,3",
            "--number-density",
            "1.79e-5",
            "--out",
            "halo.dat",
        ],
    );
    same(&dir, "halo.dat");
    let mut args = vec![
        "rsd",
        "--rsd",
        "tns",
        "--real",
        "1l-spt",
        "--terms",
        "--no-wiggle",
        "--bias-file",
        "halo.dat",
        "--noise-file",
        "halo.dat",
    ];
    args.extend(grid);
    args.extend(["--out", "rsd_halo.dat"]);
    run_in(&dir, &args);
    same(&dir, "rsd_halo.dat");
    let fit = [
        "fit", "--data", "mock.dat", "--rsd", "tns", "--real", "1l-spt",
    ];
    let mut args = fit.to_vec();
    args.extend([
        "--free",
        "f,sigma0",
        "--ells",
        "0,2",
        "--k-max",
        "0.1:0.2:0.05",
        "--precision",
        "fast",
        "--out",
        "fit_tns.dat",
        "--model-out",
        "model_tns.dat",
        "--contour",
        "f,sigma0",
        "--contour-out",
        "contour_tns.dat",
        "--contour-points",
        "9",
    ]);
    run_in(&dir, &args);
    for name in ["fit_tns.dat", "model_tns.dat", "contour_tns.dat"] {
        same(&dir, name);
    }
    let mut args = fit.to_vec();
    args.extend([
        "--fog",
        "lorentzian",
        "--sigma0",
        "4",
        "--free",
        "f,ab",
        "--ells",
        "0",
        "--k-max",
        "0.1:0.2:0.05",
        "--precision",
        "fast",
        "--out",
        "fit_ab.dat",
    ]);
    run_in(&dir, &args);
    same(&dir, "fit_ab.dat");
}
