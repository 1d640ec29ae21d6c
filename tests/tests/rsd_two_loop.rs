//! The 2-loop matter spectrum in redshift space (`pt_spectra::loops::rsd_two_loop`): at f = 0 the
//! real-space 2-loop correction (its own angular table and quasi-Monte Carlo) and no μ dependence, the
//! large-scale limit to Kaiser, and an independent plain Monte Carlo of the same integrals with the
//! exact expansion of pt-kernels (`pt_kernels::redshift::redshift_kernel`) on explicit vectors.

use pt_spectra::linear::LinearSpectrum;
use pt_spectra::loops::{rsd_two_loop, P15Table, RsdTwoLoopTerms, TwoLoopSettings};
use pt_spectra::precision::Precision;
use pt_spectra::rsd::spt2::Spt2Plan;

mod support;
use support::*;

fn table() -> std::sync::Arc<P15Table> {
    store().p15(&pt_spectra::progress::Silent).unwrap()
}

fn terms(k: &[f64], spectrum: &LinearSpectrum, points: usize, seed: u64) -> RsdTwoLoopTerms {
    let precision = Precision::default();
    let settings = TwoLoopSettings {
        points,
        seed,
        ..TwoLoopSettings::default()
    };
    rsd_two_loop(
        k,
        spectrum,
        (precision.q_min, precision.q_max),
        precision.lattice_step,
        &settings,
        &|_, _| {},
    )
    .unwrap()
}

/// One sample of the independent Monte Carlo: the whole 2-loop integrand (no partitions, no images,
/// no grouping) at explicit vectors with the exact expansion of pt-kernels, times the weights of the
/// monopole and quadrupole at the line of sight's μ.
fn plain_sample(k: f64, f: f64, p: &LinearSpectrum, rng: &mut impl rand::Rng) -> [f64; 2] {
    use pt_kernels::redshift::redshift_kernel;
    use std::f64::consts::PI;
    // ln q normal about ln 0.1 with width 1.6 (a density unlike the integrator's), directions uniform
    let (centre, width) = (0.1f64.ln(), 1.6);
    let draw = |rng: &mut dyn rand::RngCore| {
        let (u1, u2): (f64, f64) = (rand::Rng::gen(rng), rand::Rng::gen(rng));
        let g = (-2.0 * (1.0 - u1).ln()).sqrt() * (2.0 * PI * u2).cos();
        let ln_q = centre + width * g;
        let density = (-0.5 * g * g).exp() / (width * (2.0 * PI).sqrt());
        let (c, phi): (f64, f64) = (
            2.0 * rand::Rng::gen::<f64>(rng) - 1.0,
            2.0 * PI * rand::Rng::gen::<f64>(rng),
        );
        let s = (1.0 - c * c).sqrt();
        let q = ln_q.exp();
        // d³q = q³ dln q dΩ; the density of (ln q, Ω) is density/(4π)
        (
            [q * s * phi.cos(), q * s * phi.sin(), q * c],
            q.powi(3) * 4.0 * PI / density,
        )
    };
    let (q1, w1) = draw(rng);
    let (q2, w2) = draw(rng);
    let mu: f64 = rng.gen();
    let phi_n = 2.0 * PI * rng.gen::<f64>();
    let los = [
        (1.0 - mu * mu).sqrt() * phi_n.cos(),
        (1.0 - mu * mu).sqrt() * phi_n.sin(),
        mu,
    ];
    let kv = [0.0, 0.0, k];
    let neg = |v: [f64; 3]| v.map(|x| -x);
    let sub = |a: [f64; 3], b: [f64; 3]| [a[0] - b[0], a[1] - b[1], a[2] - b[2]];
    let norm = |a: [f64; 3]| (a[0] * a[0] + a[1] * a[1] + a[2] * a[2]).sqrt();
    let z = |q: &[[f64; 3]]| redshift_kernel(q, &f, &los).unwrap();
    let (p1, p2, pk) = (p.eval(norm(q1)), p.eval(norm(q2)), p.eval(k));
    let z1 = 1.0 + f * mu * mu;
    let p15 = 30.0 * z1 * pk * z(&[kv, q1, neg(q1), q2, neg(q2)]);
    let red = 9.0 * pk * z(&[kv, q1, neg(q1)]) * z(&[kv, q2, neg(q2)]);
    let p1k = sub(kv, q1);
    let p24 = 24.0 * z(&[q1, p1k]) * z(&[q1, p1k, q2, neg(q2)]) * p.eval(norm(p1k));
    let q3 = sub(p1k, q2);
    let z3 = z(&[q1, q2, q3]);
    let p33 = 6.0 * z3 * z3 * p.eval(norm(q3));
    let value = (p15 + red + p24 + p33) * p1 * p2 * w1 * w2 / (2.0 * PI).powi(6);
    // P_ℓ = (2ℓ+1)∫₀¹ L_ℓ P dμ with μ uniform on [0, 1]
    [value, 5.0 * 0.5 * (3.0 * mu * mu - 1.0) * value]
}

#[test]
fn an_independent_plain_monte_carlo_agrees_within_its_error() {
    // The same integrals by plain Monte Carlo with the exact kernels of pt-kernels on explicit
    // vectors: no subset recursion of our own, no infrared grouping, partitions, images, nodes in μ
    // or quasi-random points; the line of sight drawn at random.
    use rand::SeedableRng;
    let spectrum = LinearSpectrum::gm2012(0.0).unwrap();
    let k = [0.05, 0.1];
    let f = 0.7;
    let t = terms(&k, &spectrum, 1 << 12, 5);
    let samples = 1 << 18;
    for (i, &ki) in k.iter().enumerate() {
        let sums: Vec<[f64; 4]> = std::thread::scope(|s| {
            let handles: Vec<_> = (0..2u64)
                .map(|thread| {
                    let spectrum = &spectrum;
                    s.spawn(move || {
                        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(100 + thread);
                        let mut acc = [0.0; 4];
                        for _ in 0..samples / 2 {
                            let [a, b] = plain_sample(ki, f, spectrum, &mut rng);
                            acc[0] += a;
                            acc[1] += b;
                            acc[2] += a * a;
                            acc[3] += b * b;
                        }
                        acc
                    })
                })
                .collect();
            handles.into_iter().map(|h| h.join().unwrap()).collect()
        });
        let n = samples as f64;
        let total: [f64; 4] = std::array::from_fn(|j| sums.iter().map(|s| s[j]).sum::<f64>());
        let ours = t.multipoles(i, f, &[0, 2]);
        for l in 0..2 {
            let mean = total[l] / n;
            let error = ((total[2 + l] / n - mean * mean) / n).sqrt();
            let combined = error.hypot(ours[l].error);
            println!(
                "k = {ki} ℓ = {}: plain {mean:.2} ± {error:.2}, ours {:.2} ± {:.2}",
                2 * l,
                ours[l].value,
                ours[l].error
            );
            assert!(
                (mean - ours[l].value).abs() < 4.0 * combined,
                "k = {ki} ℓ = {}: plain MC {mean} ± {error}, ours {:?}",
                2 * l,
                ours[l]
            );
            assert!(
                combined < 0.1 * ours[l].value.abs(),
                "k = {ki}: too loose a check"
            );
        }
    }
}

#[test]
fn at_f_zero_it_is_the_real_space_correction_and_independent_of_mu() {
    // Z_n = F_n at f = 0: every node holds the same real-space integrand, so the quadrupole and
    // hexadecapole vanish to rounding, and the monopole is the real-space 2-loop correction, here
    // from the P15 angular table and the real-space quasi-Monte Carlo (other points, other maps).
    let spectrum = LinearSpectrum::gm2012(0.0).unwrap();
    let k = [0.02, 0.1, 0.25];
    let t = terms(&k, &spectrum, 1 << 12, 7);
    let precision = Precision::default();
    let range = (precision.q_min, precision.q_max);
    let part = table().propagator_part(&k, &spectrum, range, precision.lattice_step);
    let settings = TwoLoopSettings::default();
    let mc = pt_spectra::loops::two_loop(&k, &spectrum, range, precision.lattice_step, &settings);
    for (i, &ki) in k.iter().enumerate() {
        let real_value = part[i][0].value + mc.pairs[0].ir_safe[i].value;
        let real_error = part[i][0].error + mc.pairs[0].ir_safe[i].error;
        let m = t.multipoles(i, 0.0, &[0, 2, 4]);
        let combined = real_error.hypot(m[0].error);
        assert!(
            (m[0].value - real_value).abs() < 4.0 * combined,
            "k = {ki}: {:?} vs real space {real_value} ± {real_error}",
            m[0]
        );
        assert!(m[0].error < 0.02 * real_value.abs(), "k = {ki}: {:?}", m[0]);
        for e in &m[1..] {
            assert!(e.value.abs() < 1e-12 * real_value.abs(), "k = {ki}: {e:?}");
        }
        // and P(k, μ) is flat in μ
        let (a, b) = (t.at(i, 0.0, 0.1).value, t.at(i, 0.0, 0.9).value);
        assert!((a - b).abs() < 1e-12 * a.abs(), "{a} {b}");
    }
}

#[test]
fn on_large_scales_the_multipoles_tend_to_kaiser() {
    // P_ℓ/P_ℓ^Kaiser → 1 as k → 0: the loops vanish relative to (1 + fμ²)²P_lin like k² (at f = 0.8,
    // z = 0: all loops −85k², −190k², −450k² for ℓ = 0, 2, 4, the 2-loop part a third of it), the
    // 2-loop part by a factor 4.0 per halving of k; the linear part is exact.
    let spectrum = LinearSpectrum::gm2012(0.0).unwrap();
    let k = [0.0025, 0.005, 0.01];
    let mut precision = Precision::default();
    precision.two_loop_points = 1 << 12;
    let plan = Spt2Plan::new(&k, &precision).unwrap();
    let terms = plan
        .terms(&spectrum, &pt_spectra::progress::Silent)
        .unwrap();
    let f = 0.8;
    let m = terms.multipoles(f, &[0, 2, 4]).unwrap();
    let kaiser = [
        1.0 + 2.0 * f / 3.0 + f * f / 5.0,
        4.0 * f / 3.0 + 4.0 * f * f / 7.0,
        8.0 * f * f / 35.0,
    ];
    let mut previous = [f64::INFINITY; 3];
    for (i, &ki) in k.iter().enumerate() {
        let p = spectrum.eval(ki);
        for l in 0..3 {
            let lin = m.linear[l][i].value;
            assert!(
                (lin / (kaiser[l] * p) - 1.0).abs() < 1e-13,
                "ℓ = {}: {lin}",
                2 * l
            );
            let two = m.two_loop[l][i].value / lin;
            let total = m.total[l][i].value / lin - 1.0;
            println!(
                "k = {ki} ℓ = {}: 2-loop/Kaiser {two:.3e}, all loops {total:.3e}",
                2 * l
            );
            assert!(
                total.abs() < 600.0 * ki * ki,
                "k = {ki} ℓ = {}: {total}",
                2 * l
            );
            // the 2-loop share shrinks by about 4 per halving of k
            if previous[l].is_finite() {
                let ratio = two / previous[l];
                assert!(
                    (2.5..6.0).contains(&ratio),
                    "k = {ki} ℓ = {}: {ratio}",
                    2 * l
                );
            }
            previous[l] = two;
        }
    }
}
