//! Helpers shared by the loop-integral tests: reference tables, and a spectrum with all power at q ≪ k.
#![allow(dead_code)]

use pt_spectra::integrate::GaussLegendre;
use pt_spectra::linear::{LinearSpectrum, LogGrid};
use pt_spectra::store::TableStore;
use std::f64::consts::PI;
use std::sync::OnceLock;

/// The angular-table store of the test process: the cache directory of the environment
/// (`PT_SPECTRA_CACHE` in CI), so each table is built once per machine.
pub fn store() -> &'static TableStore {
    static STORE: OnceLock<TableStore> = OnceLock::new();
    STORE.get_or_init(TableStore::from_env)
}

/// The text of the reference table `name`: in this crate's `data/`, or, for the linear spectra and
/// velocileptors tables that pt-spectra's own tests read too, in `pt-spectra/tests/data/`.
pub fn data(name: &str) -> String {
    let own = format!("{}/data/{name}", env!("CARGO_MANIFEST_DIR"));
    let path = if std::path::Path::new(&own).exists() {
        own
    } else {
        format!(
            "{}/../pt-spectra/tests/data/{name}",
            env!("CARGO_MANIFEST_DIR")
        )
    };
    std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{path}: {e}"))
}

/// The numeric rows of a table (`#` lines and blank lines skipped).
pub fn rows(text: &str) -> Vec<Vec<f64>> {
    text.lines()
        .filter(|l| !l.trim_start().starts_with('#') && !l.trim().is_empty())
        .map(|l| l.split_whitespace().map(|v| v.parse().unwrap()).collect())
        .collect()
}

/// A spectrum with all its power at q ~ 1e-3 h/Mpc (P ∝ q/(1 + (q/q0)⁸)), tabulated on [1e-6, 1e2], and
/// its σ_v² = (1/6π²)∫P dq by an independent quadrature of the same shape.
pub fn infrared_spectrum() -> (LinearSpectrum, f64) {
    let q0 = 1e-3;
    let grid = LogGrid::new(1e-6, 1e2, 2000).unwrap();
    let shape = |q: f64| 1e6 * (q / q0) / (1.0 + (q / q0).powi(8));
    let spectrum = LinearSpectrum::from_fn(&grid, shape).unwrap();
    let rule = GaussLegendre::new(10);
    let edges: Vec<f64> = (0..=400).map(|i| -13.8 + 18.4 * i as f64 / 400.0).collect();
    let (sigma, _) = rule.integrate_panels(|x| x.exp() * shape(x.exp()), &edges);
    (spectrum, sigma / (6.0 * PI * PI))
}
