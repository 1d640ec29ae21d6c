// Index loops mirror the formulae's subscripts.
#![allow(clippy::needless_range_loop)]

use super::*;

/// Z₂ of SPT in redshift space with bias (Scoccimarro, Couchman & Frieman 1999, with b2/2 δ² + bs s²)
/// written directly from the vectors, `n` the line of sight.
fn z2_direct(k1: [f64; 3], k2: [f64; 3], n: [f64; 3], [b1, b2, bs, f]: [f64; 4]) -> f64 {
    let dot = |a: [f64; 3], b: [f64; 3]| a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
    let k = [k1[0] + k2[0], k1[1] + k2[1], k1[2] + k2[2]];
    let (m1, m2, mk) = (dot(k1, k1).sqrt(), dot(k2, k2).sqrt(), dot(k, k).sqrt());
    let (mu1, mu2, mu) = (dot(k1, n) / m1, dot(k2, n) / m2, dot(k, n) / mk);
    let c = dot(k1, k2) / (m1 * m2);
    let f2 = 5.0 / 7.0 + 0.5 * c * (m1 / m2 + m2 / m1) + 2.0 / 7.0 * c * c;
    let g2 = 3.0 / 7.0 + 0.5 * c * (m1 / m2 + m2 / m1) + 4.0 / 7.0 * c * c;
    b1 * f2
        + f * mu * mu * g2
        + 0.5 * f * mu * mk * (mu1 / m1 * (b1 + f * mu2 * mu2) + mu2 / m2 * (b1 + f * mu1 * mu1))
        + 0.5 * b2
        + bs * (c * c - 1.0 / 3.0)
}

/// The azimuthal average of Z₂² against the columns' polynomials, and every column outside
/// `PAIR_COLUMNS` is identically zero.
#[test]
fn pair_columns_are_the_azimuthal_average_of_z2_squared() {
    let params = [1.7, -0.6, 0.35, 0.8];
    let [b1, b2, bs, f] = params;
    let coef = [b1, b1 * f, f, f * f, b2, bs];
    for &(k, q, x) in &[
        (0.1, 0.03, 0.4),
        (0.2, 0.5, -0.7),
        (0.05, 0.049, 0.999),
        (0.3, 2.0, 0.1),
    ] {
        let y = (1.0_f64 - x * x).sqrt();
        let k1 = [q * y, 0.0, q * x];
        let k2 = [-q * y, 0.0, k - q * x];
        let p = (k2[0] * k2[0] + k2[2] * k2[2]).sqrt();
        let polys = pair_polynomials(k, q, p);
        for a in 0..6 {
            for b in a..6 {
                for (i, &c) in polys[a][b].iter().enumerate() {
                    let listed = i % 2 == 0 && PAIR_COLUMNS.contains(&(a, b, i / 2));
                    assert!(
                        listed || c.abs() < 1e-12 * (1.0 + (k / q).powi(4)),
                        "{a}{b} μ^{i}: {c}"
                    );
                }
            }
        }
        for mu in [0.0, 0.3, 0.77, 1.0] {
            let nphi = 64;
            let avg: f64 = (0..nphi)
                .map(|j| {
                    let phi = 2.0 * PI * j as f64 / nphi as f64;
                    let s = (1.0_f64 - mu * mu).sqrt();
                    let n = [s * phi.cos(), s * phi.sin(), mu];
                    z2_direct(k1, k2, n, params).powi(2)
                })
                .sum::<f64>()
                / nphi as f64;
            let mut ours = 0.0;
            for a in 0..6 {
                for b in a..6 {
                    let sym = if a == b { 1.0 } else { 2.0 };
                    let v: f64 = polys[a][b].iter().rev().fold(0.0, |acc, c| acc * mu + c);
                    ours += sym * coef[a] * coef[b] * v;
                }
            }
            assert!(
                (ours - avg).abs() < 1e-11 * avg.abs().max(1.0),
                "k {k} q {q} x {x} μ {mu}: {ours} vs {avg}"
            );
        }
    }
}

/// The line-of-sight kernels against brute-force quadrature (many Gauss–Legendre panels, graded
/// towards x = 1).
#[test]
fn los_kernels_match_brute_force() {
    let rule = XRule::new(24);
    let fine = XRule::new(40);
    for r in [
        1e-3, 0.05, 0.3, 0.6, 0.93, 0.999, 1.0005, 1.07, 1.6, 3.0, 40.0, 1e4,
    ] {
        let inv = 1.0 / r;
        let integrand = |x: f64| {
            let g = 3.0 / 7.0 + 4.0 / 7.0 * x * x - 0.5 * x * (r + inv);
            let d = 1.0 + r * r - 2.0 * r * x;
            let y2 = 1.0 - x * x;
            [
                2.0 / 3.0 * (1.0 - r * x) * g / d - x * x / 3.0 * (1.0 + inv * inv),
                2.0 / 3.0 * g * (-0.5 * y2) / d,
                2.0 / 3.0 * g * (x * inv - x * x + 0.5 * y2) / d,
            ]
        };
        let mut want = [0.0; 3];
        let mut edges = vec![-1.0, 0.0];
        let mut e = 0.5;
        while e > 1e-14 {
            edges.push(1.0 - e);
            e *= 0.5;
        }
        edges.push(1.0);
        edges.sort_by(f64::total_cmp);
        for w in edges.windows(2) {
            let s = fine.integrate(w[0], w[1], integrand);
            for (a, b) in want.iter_mut().zip(s) {
                *a += b;
            }
        }
        let got = los_kernels(r, &rule);
        let scale = want
            .iter()
            .fold(1.0 / (r * r).max(1.0), |m: f64, v| m.max(v.abs()));
        for (g, w) in got.iter().zip(want) {
            // At large r the first kernel is O(1/r²) from terms O(1) that cancel: absolute 1e-15.
            assert!(
                (g - w).abs() < 1e-10 * scale + 1e-15,
                "r = {r}: {got:?} vs {want:?}"
            );
        }
    }
}

/// At f = 0 the terms are the real-space galaxy spectrum of the bias plan and the 1-loop plan.
#[test]
fn real_space_limit_is_the_bias_expansion() {
    let p = LinearSpectrum::gm2012(0.0).unwrap();
    let ks = [0.02, 0.1, 0.25];
    let precision = Precision::fast();
    let t = RedshiftPlan::new(&ks, &precision).unwrap().evaluate(&p);
    let bias = super::super::bias::BiasPlan::new(&ks, &precision)
        .unwrap()
        .evaluate(&p);
    let one = super::super::one_loop(&p, &ks, &precision).unwrap();
    let (b1, b2, bs, b3) = (1.9, 0.7, -0.4, 0.3);
    for i in 0..ks.len() {
        let (v, _) = t.loop_polynomial(i, [b1, b2, bs, b3, 0.0]);
        assert!(v[1..].iter().all(|c| *c == 0.0));
        let pd = one.one_loop(super::super::Pair::DeltaDelta, i).value;
        let pair = |n: &str| bias.pair(n).unwrap()[i].value;
        // (b2/2) δ², bs s² and b3 = 2b3nl here (velocileptors), FAST-PT's Pd.. = 2∫… with bs/2 s².
        let want = b1 * b1 * pd
            + b1 * b2 * pair("Pd1d2")
            + 0.25 * b2 * b2 * pair("Pd2d2")
            + 2.0 * b1 * bs * pair("Pd1s2")
            + b2 * bs * pair("Pd2s2")
            + bs * bs * pair("Ps2s2")
            + b1 * b3 * bias.sig3nl[i].value;
        assert!(
            (v[0] - want).abs() < 1e-5 * want.abs(),
            "k {}: {} vs {want}",
            ks[i],
            v[0]
        );
    }
}
