//! The propagator terms P13 with the angle done analytically, and σ_v², as fixed weights on the lattice.
//!
//! With r = q/k, the angular integral of the symmetrised third-order kernels is
//!   ∫_{−1}^{1} dμ F_3^s(k, q, −q) = f_F(r)/(1512 r²),   ∫_{−1}^{1} dμ G_3^s(k, q, −q) = f_G(r)/(1512 r²),
//!   f_F(r) = 12/r² − 158 + 100r² − 42r⁴ + (3/r³)(r² − 1)³(7r² + 2) ln|(1 + r)/(1 − r)|,
//!   f_G(r) = 3 [12/r² − 82 + 4r² − 6r⁴ + (3/r³)(r² − 1)³(r² + 2) ln|(1 + r)/(1 − r)|],
//! (Makino, Sasaki & Suto 1992, PRD 46, 585; Jain & Bertschinger 1994, ApJ 431, 495, astro-ph/9311070;
//! the G form as in Scoccimarro 2004, astro-ph/0407214), checked against the generated
//! `pt_kernels::propagator_3` by angular quadrature in the tests. Hence
//!   P13_X(k) = 3P(k) ∫d³q/(2π)³ X_3^s(k, q, −q) P(q) = k³ P(k)/(2016 π²) ∫_0^∞ dr P(kr) f_X(r),
//! for X = F (δδ) and G (θθ), and P13_δθ = (P13_δδ + P13_θθ)/2.
//! Limits: f_F → −168, f_G → −168 as r → 0 (so 2P13 → −k²σ_v²P when all power sits at q ≪ k), and
//! f_F → −488/5, f_G → −504/5 as r → ∞ (2P13 → −(61/105, 9/5) k²σ_v²P for δδ, θθ).
//!
//! Numerics: the closed forms cancel catastrophically at small and large r (12/r² against the logarithm,
//! −42r⁴ against the logarithm), so for r < 0.3 and r > 1/0.3 their Taylor series in r² and 1/r² (ten
//! terms, exact rational coefficients; truncation error < 1e-14 relative) are used. At r = 1 the
//! logarithm diverges but (r² − 1)³ ln|1 − r| → 0, so f(1) = −88 (F) and −216 (G); f is continuous there
//! with a weak (r − 1)³ ln|r − 1| singularity, and the lattice cells are split at r = 1.

use super::lattice::{add_product_weights, Lattice};
use std::f64::consts::PI;

/// Below this r the small-r series is used, above 1/`SERIES_R` the large-r series.
const SERIES_R: f64 = 0.3;

/// f_F: coefficients of r^{2i} for r → 0.
const F_SMALL: [f64; 10] = [
    -168.0,
    928.0 / 5.0,
    -4512.0 / 35.0,
    416.0 / 21.0,
    2656.0 / 1155.0,
    3232.0 / 5005.0,
    544.0 / 2145.0,
    4384.0 / 36465.0,
    2976.0 / 46189.0,
    5536.0 / 146965.0,
];

/// f_F: coefficients of r^{−2i} for r → ∞.
const F_LARGE: [f64; 10] = [
    -488.0 / 5.0,
    96.0 / 5.0,
    -160.0 / 21.0,
    -1376.0 / 1155.0,
    -1952.0 / 5005.0,
    -2528.0 / 15015.0,
    -3104.0 / 36465.0,
    -2208.0 / 46189.0,
    -32.0 / 1105.0,
    -4832.0 / 260015.0,
];

/// f_G / 3: coefficients of r^{2i} for r → 0.
const G_SMALL: [f64; 10] = [
    -56.0,
    -32.0 / 5.0,
    -96.0 / 7.0,
    352.0 / 105.0,
    544.0 / 1155.0,
    736.0 / 5005.0,
    928.0 / 15015.0,
    224.0 / 7293.0,
    3936.0 / 230945.0,
    1504.0 / 146965.0,
];

/// f_G / 3: coefficients of r^{−2i} for r → ∞.
const G_LARGE: [f64; 10] = [
    -504.0 / 5.0,
    1248.0 / 35.0,
    -608.0 / 105.0,
    -160.0 / 231.0,
    -992.0 / 5005.0,
    -1184.0 / 15015.0,
    -1376.0 / 36465.0,
    -4704.0 / 230945.0,
    -352.0 / 29393.0,
    -1952.0 / 260015.0,
];

fn series(c: &[f64; 10], x2: f64) -> f64 {
    c.iter().rev().fold(0.0, |acc, &ci| acc * x2 + ci)
}

/// The P13 angular kernels [f_F(r), f_G(r)] of the module docs, r = q/k > 0.
pub fn p13_kernels(r: f64) -> [f64; 2] {
    if r < SERIES_R {
        let r2 = r * r;
        [series(&F_SMALL, r2), 3.0 * series(&G_SMALL, r2)]
    } else if r > 1.0 / SERIES_R {
        let s2 = 1.0 / (r * r);
        [series(&F_LARGE, s2), 3.0 * series(&G_LARGE, s2)]
    } else if r == 1.0 {
        [-88.0, -216.0]
    } else {
        let r2 = r * r;
        let log = ((1.0 + r) / (1.0 - r).abs()).ln();
        let cube = 3.0 * (r2 - 1.0).powi(3) * log / (r2 * r);
        let f = 12.0 / r2 - 158.0 + 100.0 * r2 - 42.0 * r2 * r2 + cube * (7.0 * r2 + 2.0);
        let g = 12.0 / r2 - 82.0 + 4.0 * r2 - 6.0 * r2 * r2 + cube * (r2 + 2.0);
        [f, 3.0 * g]
    }
}

/// K₁(r) = 3⟨X_3^s(k, q, −q)⟩ averaged over the directions of q, r = q/k, for X = F, G: f_X(r)/(1008 r²)
/// ([`p13_kernels`]). P13_X = P(k) ∫d³q/(2π)³ K₁X(q/k) P(q); the infrared limit of the P15 kernel is
/// ½K₁(r₁)K₁(r₂).
pub fn k1_kernels(r: f64) -> [f64; 2] {
    p13_kernels(r).map(|f| f / (1008.0 * r * r))
}

/// Lattice weights of one k: Σ_j w_j P_j = P13_X(k)/P(k) for X = F, G, with P the lattice samples.
#[derive(Debug, Clone)]
pub(crate) struct P13Weights {
    pub f: Vec<f64>,
    pub g: Vec<f64>,
}

/// The weights of P13_F/P and P13_G/P at `k` [h/Mpc] on `lattice`: k²/(2016π²) ∫ dx e^x f(e^x/k) P̃(x)
/// over the whole lattice, with the cells split at q = k.
pub(crate) fn p13_weights(lattice: &Lattice, k: f64, rule: (&[f64], &[f64])) -> P13Weights {
    let norm = k * k / (2016.0 * PI * PI);
    let (a, b) = (lattice.x0, lattice.x_end());
    let split = k.ln().clamp(a, b);
    let mut w = [vec![0.0; lattice.len], vec![0.0; lattice.len]];
    for (lo, hi) in [(a, split), (split, b)] {
        if hi > lo {
            add_product_weights(lattice, &mut w, (lo, hi), rule, |x| {
                let q = x.exp();
                p13_kernels(q / k).map(|f| norm * q * f)
            });
        }
    }
    let [f, g] = w;
    P13Weights { f, g }
}

/// The weights of σ_v² = (1/6π²) ∫ P dq = (1/6π²) ∫ dx e^x P̃(x) on `lattice`.
pub(crate) fn sigma_v2_weights(lattice: &Lattice, rule: (&[f64], &[f64])) -> Vec<f64> {
    let mut w = [vec![0.0; lattice.len]];
    let norm = 1.0 / (6.0 * PI * PI);
    add_product_weights(lattice, &mut w, (lattice.x0, lattice.x_end()), rule, |x| {
        [norm * x.exp()]
    });
    let [w] = w;
    w
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn series_and_closed_forms_join_continuously() {
        for r in [SERIES_R, 1.0 / SERIES_R] {
            let (below, above) = (
                p13_kernels(r * (1.0 - 1e-12)),
                p13_kernels(r * (1.0 + 1e-12)),
            );
            for i in 0..2 {
                assert!(
                    (below[i] - above[i]).abs() < 1e-11 * below[i].abs(),
                    "r={r} i={i}"
                );
            }
        }
        let near = p13_kernels(1.0 + 1e-9);
        assert!((near[0] + 88.0).abs() < 1e-6 && (near[1] + 216.0).abs() < 1e-6);
    }

    /// The closed forms (and K₁) against Gauss–Legendre angular integration of the generated kernels.
    #[test]
    fn closed_forms_match_angular_integrals_of_generated_kernels() {
        use crate::integrate::GaussLegendre;
        use pt_kernels::propagator_3;
        let gl = GaussLegendre::new(400);
        for r in [1e-3, 0.05, 0.29, 0.31, 0.5, 0.9, 1.3, 3.2, 3.4, 30.0] {
            let integral = |which: usize| {
                gl.integrate(|mu| propagator_3(&[1.0, r * mu, r * r])[which], -1.0, 1.0)
                    .0
            };
            for (which, f) in p13_kernels(r).into_iter().enumerate() {
                let expected = f / (1512.0 * r * r);
                let got = integral(which);
                assert!(
                    (got / expected - 1.0).abs() < 1e-10,
                    "r={r} kernel {which}: {got} vs {expected}"
                );
                // K₁ = 3⟨X_3^s⟩ = (3/2)∫dμ X_3^s.
                let k1 = k1_kernels(r)[which];
                assert!((k1 / (1.5 * got) - 1.0).abs() < 1e-10, "r={r} K₁ {which}");
            }
        }
    }

    #[test]
    fn limits() {
        let [f0, g0] = p13_kernels(1e-6);
        assert!((f0 + 168.0).abs() < 1e-9 && (g0 + 168.0).abs() < 1e-9);
        let [fi, gi] = p13_kernels(1e6);
        assert!((fi + 488.0 / 5.0).abs() < 1e-9 && (gi + 1512.0 / 5.0).abs() < 1e-9);
    }
}
