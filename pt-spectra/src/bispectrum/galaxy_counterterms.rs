//! The counterterm and stochastic shapes of the one-loop galaxy bispectrum in real space: the terms that
//! absorb the loops' dependence on their cut-off (issue 50, part 2).
//!
//! With K₁ = b1 on the legs and K₂ the galaxy kernel ([`super::bias_kernels`]), the set is
//!
//! ```text
//! B_ct = Σ_cyc 2 P_i P_j [ ct_k2 b1 K₂(k_i, k_j)(k_i² + k_j²)                (K₁ → b1 − ct_k2 k²: ∇²δ)
//!                         + b1² ( ct_k3 k_l² + ct_kk (k_i² + k_j²)            (∇²δ², δ∇²δ)
//!                               + ct_tidal k_l² (μ_ij² − 1/3) + ct_f2k3 F₂(k_i, k_j) k_l² ) ]   (∇²G₂, ∇²δ⁽²⁾)
//!      + st_p Σ_a b1² P_a + st_1,
//! ```
//!
//! k_l the third side, μ_ij the cosine between k_i and k_j, coefficients ct_* in (Mpc/h)², st_p in
//! (Mpc/h)³, st_1 in (Mpc/h)⁶. For matter (b1 = 1, the rest 0) the first, second, fourth and fifth
//! shapes are the four of [`super::one_loop::COUNTERTERMS`] (the leg counterterm and the three k²
//! operators of second order: Baldauf et al. 2015, arXiv:1406.4135; Angulo et al. 2015,
//! arXiv:1406.4143). A biased tracer needs the derivative operator δ∇²δ as well (ct_kk: the
//! (k_i² + k_j²) of the legs at second order, which its own bias operators generate at one loop), and
//! the shapes of the stochastic terms: the q → ∞ limits of B₂₂₂ (a constant, ∝ ∫P³) and of B₃₂₁ᴵ
//! (∝ K₁(k_a) P_a ∫P²) are the shapes of the shot-noise terms (the tree-level model's A_shot/n̄² and
//! b1 B_shot Z₁ P/n̄, [`super::BispectrumParams`]), which they renormalise. Measured
//! (`tests/tests/suite/bispectrum_galaxy_ct.rs`): moving q_max from 1 to 10 h/Mpc changes the
//! one-loop galaxy B by up to 5e7 (Mpc/h)⁶ at 20 triangles (0.01–0.16 h/Mpc), and one set of these seven
//! coefficients takes the change out to 3–5e-4 of it for three bias sets (all eleven coefficients, or
//! velocileptors' b1, b2, bs); without the stochastic shapes 25–43% is left, without ct_kk 4–4.5%. In
//! redshift space: [`super::galaxy_counterterms_rsd`] (these seven at f = 0, and thirteen more).

use super::bias_kernels::{galaxy_kernel, LoopBias};
use super::one_loop::{f_n, triangle_vectors};
use crate::error::Result;
use crate::linear::LinearSpectrum;
use crate::vec3::norm;

/// The names of [`galaxy_counterterm_shapes`], in its order (module docs).
pub const GALAXY_COUNTERTERMS: [&str; 7] = [
    "ct_k2", "ct_k3", "ct_kk", "ct_tidal", "ct_f2k3", "st_p", "st_1",
];

/// The seven shapes of the module docs at the triangle of sides `k` [h/Mpc] with `bias`, for the
/// linear spectrum `p`: the five k² shapes in (Mpc/h)⁴, Σ b1² P_a in (Mpc/h)³ and 1.
///
/// # Errors
/// As [`triangle_vectors`] for sides that do not close; [`LoopBias::check_finite`].
pub fn galaxy_counterterm_shapes(
    p: &LinearSpectrum,
    k: [f64; 3],
    bias: &LoopBias,
) -> Result<[f64; 7]> {
    bias.check_finite()?;
    let kv = triangle_vectors(k)?;
    let k = kv.map(norm);
    let pk = k.map(|k| p.eval(k));
    let b1 = bias.b1;
    let mut shapes = [0.0; 7];
    for i in 0..3 {
        let (j, l) = ((i + 1) % 3, (i + 2) % 3);
        let pp = 2.0 * pk[i] * pk[j];
        let mu = (k[l] * k[l] - k[i] * k[i] - k[j] * k[j]) / (2.0 * k[i] * k[j]);
        let (kl2, kij2) = (k[l] * k[l], k[i] * k[i] + k[j] * k[j]);
        let k2 = galaxy_kernel(bias, &[kv[i], kv[j]])?;
        let f2 = f_n(&[kv[i], kv[j]]);
        shapes[0] += pp * b1 * k2 * kij2;
        shapes[1] += pp * b1 * b1 * kl2;
        shapes[2] += pp * b1 * b1 * kij2;
        shapes[3] += pp * b1 * b1 * kl2 * (mu * mu - 1.0 / 3.0);
        shapes[4] += pp * b1 * b1 * f2 * kl2;
        shapes[5] += b1 * b1 * pk[i];
    }
    shapes[6] = 1.0;
    Ok(shapes)
}
