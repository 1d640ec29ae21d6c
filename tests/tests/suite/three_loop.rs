//! The 3-loop propagator term P17 from its angular table and the propagator N3: the factorised IR limit
//! of the angular kernel, the large-k Gaussian limit, and a direct 8-D Monte Carlo.
//!
//! The first test to run builds the P17 table (about 2.5 minutes on 2 cores) and caches it.

use pt_spectra::linear::LinearSpectrum;
use pt_spectra::loops::{k1_kernels, p17_angular_kernel, P17Table};
use rand::{Rng, SeedableRng};
use std::f64::consts::PI;

use crate::support::*;

fn table() -> std::sync::Arc<P17Table> {
    store().p17(&pt_spectra::progress::Silent).unwrap()
}

#[test]
fn angular_kernel_has_the_factorised_ir_limit() {
    // r_i ≪ 1: 105⟨X_7^s⟩ → K₁(r₁)K₁(r₂)K₁(r₃)/6, so that 6P17/P → (P13/P)³.
    for r in [[1e-3, 2e-3, 1.5e-3], [3e-3, 1e-3, 2e-3]] {
        for (x, kx) in p17_angular_kernel(r).into_iter().enumerate() {
            let limit = k1_kernels(r[0])[x] * k1_kernels(r[1])[x] * k1_kernels(r[2])[x] / 6.0;
            let diff = (kx.value - limit).abs();
            let allowed = 4.0 * kx.error + 1e-4 * limit.abs();
            assert!(diff < allowed, "{r:?} {x}: {kx:?} vs {limit}");
            // The comparison can fail: the quasi-Monte-Carlo error is a few per cent at most.
            assert!(kx.error < 0.03 * limit.abs(), "{r:?} {x}: {kx:?}");
        }
    }
}

#[test]
#[ignore = "slow exhaustive check: `cargo test --release --workspace -- --ignored` (CI runs it); builds the P17 table (~2.5 min on 2 cores) on an empty cache"]
fn large_k_limit_is_the_gaussian_damping() {
    // All power at q ≪ k: P17/P → (−k²σ_v²/2)³/6.
    let (spectrum, sigma_v2) = infrared_spectrum();
    let k = [0.3];
    let p17 = table().evaluate(&k, &spectrum, (1e-6, 1e2), 0.01);
    let p = spectrum.eval(k[0]);
    let limit = (-k[0] * k[0] * sigma_v2 / 2.0).powi(3) / 6.0;
    for x in [0, 2] {
        let got = p17[0][x];
        assert!(
            (got.value / p - limit).abs() < 4.0 * got.error / p + 1e-3 * limit.abs(),
            "{x}: {got:?} vs {limit}"
        );
    }
}

#[test]
#[ignore = "slow exhaustive check: `cargo test --release --workspace -- --ignored` (CI runs it); builds the P17 table (~2.5 min on 2 cores) on an empty cache"]
fn table_p17_matches_a_direct_monte_carlo() {
    // P17_δδ/P at k = 0.15 by plain Monte Carlo over (ln q₁, ln q₂, ln q₃, three directions).
    let spectrum = LinearSpectrum::gm2012(0.0).unwrap();
    let (k, q_lo, q_hi) = (0.15, 1e-3, 10.0);
    let p17 = table().evaluate(&[k], &spectrum, (q_lo, q_hi), 0.01)[0][0];
    let p = spectrum.eval(k);
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(17);
    let span = (q_hi / q_lo).ln();
    let n = 400_000;
    let (mut sum, mut sum2) = (0.0, 0.0);
    for _ in 0..n {
        let mut v = [[0.0; 3]; 3];
        let mut weight = 105.0 * span.powi(3) * (4.0 * PI).powi(3) / (2.0 * PI).powi(9);
        for vi in &mut v {
            let q = q_lo * (rng.gen::<f64>() * span).exp();
            let z: f64 = rng.gen_range(-1.0..1.0);
            let phi: f64 = rng.gen_range(0.0..2.0 * PI);
            let s = (1.0 - z * z).sqrt();
            *vi = [q * s * phi.cos(), q * s * phi.sin(), q * z];
            weight *= q.powi(3) * spectrum.eval(q);
        }
        let dot = |a: &[f64; 3], b: &[f64; 3]| a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
        let gram = [
            k * k,
            k * v[0][2],
            k * v[1][2],
            k * v[2][2],
            dot(&v[0], &v[0]),
            dot(&v[0], &v[1]),
            dot(&v[0], &v[2]),
            dot(&v[1], &v[1]),
            dot(&v[1], &v[2]),
            dot(&v[2], &v[2]),
        ];
        let [f7, _] = pt_kernels::propagator_7(&gram);
        let x = weight * f7;
        sum += x;
        sum2 += x * x;
    }
    let mean = sum / n as f64;
    let sigma = ((sum2 / n as f64 - mean * mean) / n as f64).sqrt();
    let table_value = p17.value / p;
    println!(
        "P17/P: table {table_value:.5e} ± {:.1e}, Monte Carlo {mean:.5e} ± {sigma:.1e}",
        p17.error / p
    );
    assert!(
        (table_value - mean).abs() < 4.0 * sigma + p17.error / p,
        "{table_value} vs {mean} ± {sigma}"
    );
    assert!(sigma < 0.05 * mean.abs(), "{sigma} vs {mean}");
}
