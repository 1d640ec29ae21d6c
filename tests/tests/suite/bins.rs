//! Bin averages (`pt_spectra::survey::bins`) against brute force:
//!
//! * [`BoxModes`]: the multipoles of P(k, μ) averaged over the discrete modes of a periodic box, by the
//!   grouped fast path (a closure, and the model's multipoles on a grid) against a triple loop over
//!   every mode n ∈ [−N, N]³;
//! * [`BinAverage`]: k²-weighted bin means of the gm2012 spectrum against composite Gauss–Legendre
//!   quadrature on fine panels;
//! * [`WindowMatrix`] files (text and `.npy` with its sidecar) holding the bin average as a matrix.

use pt_spectra::integrate::GaussLegendre;
use pt_spectra::linear::LinearSpectrum;
use pt_spectra::survey::{legendre, BinAverage, BoxModes, WindowMatrix};
use std::f64::consts::PI;
use std::time::Instant;

/// (1 + μ²/2)² e^{−k/0.1}/k, and its multipoles: (1 + μ²/2)² = 1 + μ² + μ⁴/4 =
/// (1 + 1/3 + 1/20) L0 + (2/3 + 1/7) L2 + (2/35) L4.
fn model(k: f64, mu: f64) -> f64 {
    (1.0 + 0.5 * mu * mu).powi(2) * (-k / 0.1).exp() / k
}

const MODEL_ELLS: [f64; 3] = [1.0 + 1.0 / 3.0 + 0.05, 2.0 / 3.0 + 1.0 / 7.0, 2.0 / 35.0];

/// The multipoles ℓ = 0, 2, 4 of `p` over the modes of the box in each bin, by a loop over all modes.
fn brute_force(box_side: f64, edges: &[f64], p: impl Fn(f64, f64) -> f64) -> Vec<[f64; 3]> {
    let fundamental = 2.0 * PI / box_side;
    let n = (edges[edges.len() - 1] / fundamental).ceil() as i64 + 1;
    let mut sums = vec![[0.0; 3]; edges.len() - 1];
    let mut counts = vec![0u64; edges.len() - 1];
    for i in -n..=n {
        for j in -n..=n {
            for l in -n..=n {
                let n2 = (i * i + j * j + l * l) as u64;
                if n2 == 0 {
                    continue;
                }
                let k = fundamental * (n2 as f64).sqrt();
                let Some(b) = (0..edges.len() - 1).find(|&b| k >= edges[b] && k < edges[b + 1])
                else {
                    continue;
                };
                let mu = l as f64 / (n2 as f64).sqrt();
                let v = p(k, mu);
                for (e, s) in sums[b].iter_mut().enumerate() {
                    *s += (4 * e + 1) as f64 * v * legendre(2 * e, mu);
                }
                counts[b] += 1;
            }
        }
    }
    sums.iter()
        .zip(&counts)
        .map(|(s, &c)| s.map(|v| v / c as f64))
        .collect()
}

#[test]
fn box_modes_match_the_brute_force_sum() {
    let box_side = 500.0;
    let edges: Vec<f64> = (0..=20).map(|i| 0.005 + 0.01 * i as f64).collect();
    let t0 = Instant::now();
    let modes = BoxModes::new(box_side, &edges, &[0, 2, 4]).unwrap();
    let t_modes = t0.elapsed();
    let brute = brute_force(box_side, &edges, model);
    // The fast path with the closure: the same modes, summed by groups.
    let fast = modes.average(model);
    let mut worst: f64 = 0.0;
    for (b, expected) in brute.iter().enumerate() {
        for ell in 0..3 {
            worst = worst.max((fast[ell][b].value - expected[ell]).abs() / expected[0].abs());
        }
    }
    // The plan: the model's multipoles on a log grid, 4-point Lagrange in ln k.
    let (k_lo, k_hi) = (0.99 * 2.0 * PI / box_side, 0.21);
    let grid: Vec<f64> = (0..=300)
        .map(|i| k_lo * (k_hi / k_lo).powf(i as f64 / 300.0))
        .collect();
    let multipoles = |grid: &[f64]| -> Vec<Vec<f64>> {
        MODEL_ELLS
            .iter()
            .map(|c| grid.iter().map(|&k| c * model(k, 0.0)).collect())
            .collect()
    };
    let t1 = Instant::now();
    let plan = modes.plan(&grid, 3).unwrap();
    let t_plan = t1.elapsed();
    let t2 = Instant::now();
    let planned = plan.apply(&multipoles(&grid)).unwrap();
    let t_apply = t2.elapsed();
    let exact = modes.distinct_k();
    let on_modes = modes
        .plan(&exact, 3)
        .unwrap()
        .apply(&multipoles(&exact))
        .unwrap();
    let (mut worst_grid, mut worst_exact, mut bound_ok) = (0.0f64, 0.0f64, true);
    for (b, expected) in brute.iter().enumerate() {
        for ell in 0..3 {
            let d = (planned[ell][b].value - expected[ell]).abs() / expected[0].abs();
            worst_grid = worst_grid.max(d);
            bound_ok &= (planned[ell][b].value - expected[ell]).abs() <= planned[ell][b].error;
            let d = (on_modes[ell][b].value - expected[ell]).abs() / expected[0].abs();
            worst_exact = worst_exact.max(d);
        }
    }
    println!(
        "box L = {box_side}: {} modes in {} bins, {} distinct |k|; |fast − brute|/P0 ≤ {worst:.1e} \
         (closure), {worst_exact:.1e} (plan on the distinct |k|), {worst_grid:.1e} (plan on 301 log k); \
         modes {t_modes:?}, plan {t_plan:?}, apply {t_apply:?}",
        modes.counts().iter().sum::<u64>(),
        modes.counts().len(),
        exact.len()
    );
    assert!(worst < 1e-12, "{worst:e}");
    assert!(worst_exact < 1e-12, "{worst_exact:e}");
    assert!(worst_grid < 1e-6, "{worst_grid:e}");
    assert!(
        bound_ok,
        "the interpolation error estimate must bound the error"
    );
    // Effective k: the mean |k| over the modes.
    let first: f64 = 2.0 * PI / box_side;
    assert!((modes.k_eff()[0] - first).abs() < 1e-15 && modes.counts()[0] == 6);
}

#[test]
fn box_modes_of_a_large_box_are_fast() {
    let edges: Vec<f64> = (0..=60).map(|i| 0.005 * i as f64 + 0.0025).collect();
    let t0 = Instant::now();
    let modes = BoxModes::new(2000.0, &edges, &[0, 2, 4]).unwrap();
    let elapsed = t0.elapsed();
    let n: u64 = modes.counts().iter().sum();
    println!(
        "L = 2000 Mpc/h, k < 0.3025: {n} modes, {} distinct |k|, {elapsed:?}",
        modes.distinct_k().len()
    );
    // Shell counts approach 4πk²Δk (L/2π)³.
    let b = 40;
    let k = modes.k_eff()[b];
    let expected = 4.0 * PI * k * k * 0.005 * (2000.0 / (2.0 * PI)).powi(3);
    assert!((modes.counts()[b] as f64 / expected - 1.0).abs() < 0.01);
}

#[test]
fn bin_means_match_fine_quadrature() {
    let p = LinearSpectrum::gm2012(0.0).unwrap();
    let edges: Vec<f64> = (0..=48).map(|i| 0.005 * i as f64).collect();
    let fine = GaussLegendre::new(20);
    for n in [2, 3, 4] {
        let bins = BinAverage::with_nodes(&edges, n).unwrap();
        let values: Vec<f64> = bins.k_theory().iter().map(|&k| p.eval(k)).collect();
        let means = bins.apply(&values).unwrap();
        let (mut worst, mut worst_above, mut bounded) = (0.0f64, 0.0f64, 0);
        for (m, e) in means.iter().zip(edges.windows(2)) {
            let panels: Vec<f64> = (0..=16)
                .map(|i| e[0] + (e[1] - e[0]) * i as f64 / 16.0)
                .collect();
            let (num, _) = fine.integrate_panels(|k| k * k * p.eval(k), &panels);
            let exact = num * 3.0 / (e[1].powi(3) - e[0].powi(3));
            let d = (m.value - exact).abs();
            worst = worst.max(d / exact);
            if e[0] > 0.0 {
                worst_above = worst_above.max(d / exact);
            }
            bounded += usize::from(d <= m.error);
        }
        println!(
            "{n} nodes per bin ({} model points): worst relative error {worst:.1e} ({worst_above:.1e} \
             without the bin [0, 0.005)), the estimate bounds it in {bounded}/48 bins",
            bins.k_theory().len()
        );
        // The bins where the width is comparable to k dominate: [0.005, 0.01) (9e-5 with 3 nodes).
        assert!(worst < [1e-2, 2e-4, 1e-4][n - 2], "{n}: {worst:e}");
        assert!(
            worst_above < [1e-3, 2e-4, 1e-4][n - 2],
            "{n}: {worst_above:e}"
        );
        assert!(bounded >= 46, "{n}: {bounded}");
    }
}

#[test]
fn window_matrix_files_apply_a_bin_average() {
    // The bin average is linear: its matrix, for ℓ = 0 and 2 separately, from unit vectors.
    let edges: Vec<f64> = (0..=6).map(|i| 0.02 + 0.02 * i as f64).collect();
    let bins = BinAverage::new(&edges).unwrap();
    let nodes = bins.k_theory().to_vec();
    let mut columns = Vec::new();
    for i in 0..nodes.len() {
        let mut unit = vec![0.0; nodes.len()];
        unit[i] = 1.0;
        columns.push(bins.apply(&unit).unwrap());
    }
    let (rows, cols) = (2 * edges.len() - 2, 2 * nodes.len());
    let mut w = vec![0.0; rows * cols];
    for block in 0..2 {
        for (j, column) in columns.iter().enumerate() {
            for (b, v) in column.iter().enumerate() {
                w[(block * 6 + b) * cols + block * nodes.len() + j] = v.value;
            }
        }
    }
    let join = |v: &[f64]| {
        v.iter()
            .map(|x| format!("{x:e}"))
            .collect::<Vec<_>>()
            .join(" ")
    };
    let meta = format!(
        "# ells_out 0 2\n# k_out {}\n# ells_theory 0 2\n# k_theory {}\n",
        join(&bins.k_eff()),
        join(&nodes)
    );
    let text: String = w.chunks(cols).map(|r| join(r) + "\n").collect();
    let dir = std::env::temp_dir().join(format!("pt-spectra-bins-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    std::fs::write(dir.join("w.txt"), format!("{meta}{text}")).unwrap();
    // .npy: version 1.0 header, C order float64, and the metadata in w.npy.txt.
    let mut header =
        format!("{{'descr': '<f8', 'fortran_order': False, 'shape': ({rows}, {cols}), }}");
    while (header.len() + 11) % 64 != 0 {
        header.push(' ');
    }
    header.push('\n');
    let mut npy = b"\x93NUMPY\x01\x00".to_vec();
    npy.extend_from_slice(&(header.len() as u16).to_le_bytes());
    npy.extend_from_slice(header.as_bytes());
    w.iter()
        .for_each(|v| npy.extend_from_slice(&v.to_le_bytes()));
    std::fs::write(dir.join("w.npy"), npy).unwrap();
    std::fs::write(dir.join("w.npy.txt"), meta).unwrap();
    let p = LinearSpectrum::gm2012(0.0).unwrap();
    let p0: Vec<f64> = nodes.iter().map(|&k| p.eval(k)).collect();
    let p2: Vec<f64> = p0.iter().map(|v| 0.4 * v).collect();
    let expected = [bins.apply(&p0).unwrap(), bins.apply(&p2).unwrap()];
    for name in ["w.txt", "w.npy"] {
        let matrix = WindowMatrix::from_file(dir.join(name)).unwrap();
        assert_eq!(matrix.k_theory(2).unwrap(), nodes.as_slice());
        let out = matrix.apply(&[p0.clone(), p2.clone()]).unwrap();
        for (o, e) in out.iter().flatten().zip(expected.iter().flatten()) {
            assert!(
                (o.value - e.value).abs() < 1e-12 * e.value.abs(),
                "{name}: {o:?} {e:?}"
            );
        }
    }
    std::fs::remove_dir_all(&dir).unwrap();
}
