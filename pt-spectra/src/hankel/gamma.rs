//! The complex ln Γ of the FFTLog coefficients.

use super::C64;
use std::f64::consts::PI;

/// Stirling-series coefficients B_{2k}/(2k(2k − 1)), k = 1..8.
const STIRLING: [f64; 8] = [
    1.0 / 12.0,
    -1.0 / 360.0,
    1.0 / 1260.0,
    -1.0 / 1680.0,
    1.0 / 1188.0,
    -691.0 / 360360.0,
    1.0 / 156.0,
    -3617.0 / 122400.0,
];

/// ln Γ(z) for complex z away from the poles 0, −1, −2, ….
///
/// Im z < 0 through ln Γ(z̄) = conj ln Γ(z); Re z < 1/2 through the reflection Γ(z)Γ(1 − z) = π/sin(πz),
/// with ln sin(πz) = −iπz + ln(1 − e^{2πiz}) + ln(i/2), which stays finite for large Im z; otherwise the
/// recurrence ln Γ(z) = ln Γ(z + n) − ln Π_{j<n}(z + j) up to |z + n| ≥ 10 and the Stirling series
/// with 8 terms, whose truncation error there (Re w ≥ 1/2) is below 1e-15: the first omitted term,
/// |B_18|/(18·17·|w|^17) ≤ 2e-18, times at most sec^18(π/4) = 512. Rounding adds an absolute error of
/// a few 1e-16 |z ln z| (measured: ≤ 6e-15 absolute where |ln Γ| ≤ 1, ≤ 4e-16 relative beyond, against
/// factorials up to 29!, Γ(±1/2), Γ(1 + i), |Γ(1/2 + iy)|² = π/cosh(πy) and |Γ(iy)|² = π/(y sinh(πy))
/// up to y = 300). The imaginary part is exact modulo 2π (the principal
/// branch for Re z > 0): Γ(z) = exp(ln Γ(z)) holds whatever the branch.
pub(super) fn ln_gamma(z: C64) -> C64 {
    if z.im < 0.0 {
        return ln_gamma(z.conj()).conj();
    }
    if z.re < 0.5 {
        let i_pi_z = C64::new(0.0, PI) * z;
        let ln_sin = -i_pi_z
            + (1.0 - (2.0 * i_pi_z).exp()).ln()
            + C64::new(0.5, 0.0).ln()
            + C64::new(0.0, PI / 2.0);
        return PI.ln() - ln_sin - ln_gamma(1.0 - z);
    }
    let (mut w, mut product) = (z, C64::new(1.0, 0.0));
    while w.norm() < 10.0 {
        product *= w;
        w += 1.0;
    }
    let inv = 1.0 / w;
    let inv2 = inv * inv;
    let series = STIRLING
        .iter()
        .rev()
        .fold(C64::new(0.0, 0.0), |acc, &c| acc * inv2 + c)
        * inv;
    (w - 0.5) * w.ln() - w + 0.5 * (2.0 * PI).ln() + series - product.ln()
}
