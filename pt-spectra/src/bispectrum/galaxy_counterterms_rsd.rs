//! The counterterm and stochastic shapes of the one-loop galaxy bispectrum in redshift space, at one
//! orientation and as multipoles (issue 50): the real-space set of [`super::galaxy_counterterms`] with
//! Z₁ = b1 + fμ² and Z₂ = Z₂^g on the legs, and the shapes that the line of sight adds.
//!
//! With Z₁(k_a) = b1 + fμ_a², Z₂ the galaxy kernel ([`super::bias_kernels`]), μ_a = k̂_a·n̂, for each pair
//! (i, j) of sides and l the third, 𝒫 = 2 P_i P_j, k_∥ = (k_i + k_j)·n̂ and Σ over the three pairs:
//!
//! ```text
//! leg (Z₁ → Z₁ − (c₀ + c₂fμ² + c₄f²μ⁴)k²: ∇²δ, ∇_∥²δ, ∇_∥⁴/∇²δ, the power spectrum's three counterterms)
//!   ct_k2, ct_k2_mu2, ct_k2_mu4 :  Σ 𝒫 Z₂ [k_i² (fμ_i²)ⁿ Z₁(k_j) + k_j² (fμ_j²)ⁿ Z₁(k_i)],   n = 0, 1, 2
//! second-order operators with two derivatives (× 𝒫 Z₁(k_i) Z₁(k_j)):
//!   ct_k3 k_l²,  ct_kk (k_i² + k_j²),  ct_tidal k_l²(μ_ij² − 1/3),  ct_f2k3 F₂ k_l²      (real space's)
//!   ct_k3_mu2 f k_l²μ_l²,  ct_kk_mu2 f(k_i²μ_i² + k_j²μ_j²),  ct_g2k3_mu2 f G₂ k_l²μ_l²  (∇_∥² of δ², δ, θ⁽²⁾)
//! the redshift-space mapping of the first-order counterterms (× 𝒫 Z₁(k_i) Z₁(k_j)): the displacement
//!   f k_∥ (μ_i/k_i) u_∥ of one leg by the velocity of the other, with the density's or the velocity's
//!   counterterm on a leg (D'Amico et al.'s "local counterterm contributing non-locally"):
//!   ct_map      (f k_∥/2) [(k_i·n̂) k_j²/k_i² + (k_j·n̂) k_i²/k_j²]
//!   ct_map_mu2  (f k_∥/2) [(k_i·n̂) k_j² fμ_j²/k_i² + (k_j·n̂) k_i² fμ_i²/k_j²]
//!   ct_vel      (f k_∥/2) [(k_i·n̂) Z₁(k_j) + (k_j·n̂) Z₁(k_i)]
//! the second-order galaxy field under two derivatives (× 𝒫 Z₁(k_i) Z₁(k_j)): the velocity dispersion's
//!   damping of the tree level, −(f²k_∥²σ_v²/2) Z₂ on the third side (the UV limit of a pair of hard
//!   velocities in Z₄), and ∇² of the redshift-space part of the second-order field:
//!   ct_fog   Z₂ f² k_l² μ_l²,     ct_z2k3   [Z₂ − Z₂(f = 0)] k_l²
//! stochastic (the tree-level model's (1/n̄)[b1 B_shot + fμ_a²(1 + P_shot)] Z₁P + (1 + A_shot)/n̄², and the
//! f²μ⁴ that B₃₂₁ᴵ's q → ∞ limit also has):
//!   st_p Σ_a b1 Z₁(k_a) P_a,  st_p_mu2 Σ_a fμ_a² Z₁(k_a) P_a,  st_p_mu4 Σ_a f²μ_a⁴ Z₁(k_a) P_a,  st_1 1.
//! ```
//!
//! At f = 0 the first seven ([`super::galaxy_counterterms::GALAXY_COUNTERTERMS`]'s, in its order) are the
//! real-space shapes and the others vanish. Coefficients ct_* in (Mpc/h)², st_p* in (Mpc/h)³, st_1 in
//! (Mpc/h)⁶. The map to the tree-level EFT model of this crate (Ivanov et al. 2022, arXiv:2110.10161,
//! eq. 2.5; [`super::BispectrumParams`]): its c₁ (Z₁ → Z₁ − c₁k²μ²) is ct_k2_mu2 = c₁/f; its B_shot/n̄,
//! (1 + P_shot)/n̄ and (1 + A_shot)/n̄² are st_p, st_p_mu2 and st_1 (docs/bispectrum.md: the set, its
//! literature and the cut-off test).

use super::bias_kernels::{galaxy_kernel, galaxy_redshift_kernel, LoopBias};
use super::bias_poly::Ring;
use super::galaxy_counterterms::galaxy_counterterm_shapes;
use super::geometry::LegendreSide;
use super::one_loop::{f_n, triangle_vectors};
use super::one_loop_galaxy_multipoles::{
    legendre_side_index, multipole_weights, orientation_nodes, ORIENTATION_RULE,
};
use super::one_loop_rsd::Orientation;
use crate::error::Result;
use crate::linear::LinearSpectrum;
use crate::vec3::{dot, norm};

/// The names of [`redshift_counterterm_shapes`], in its order (module docs): the first seven are
/// [`super::galaxy_counterterms::GALAXY_COUNTERTERMS`].
pub const REDSHIFT_COUNTERTERMS: [&str; 20] = [
    "ct_k2",
    "ct_k3",
    "ct_kk",
    "ct_tidal",
    "ct_f2k3",
    "st_p",
    "st_1",
    "ct_k2_mu2",
    "ct_k2_mu4",
    "ct_k3_mu2",
    "ct_kk_mu2",
    "ct_g2k3_mu2",
    "ct_map",
    "ct_map_mu2",
    "ct_vel",
    "st_p_mu2",
    "st_p_mu4",
    "ct_k3_mu4",
    "ct_fog",
    "ct_z2k3",
];

/// The number of redshift-space shapes.
pub const N_REDSHIFT_CT: usize = REDSHIFT_COUNTERTERMS.len();

/// The power d of k in each shape of [`REDSHIFT_COUNTERTERMS`] beside its linear spectra: the shape at the
/// sides s k with P is s^d times the shape at k with P(s ·) (the isotropic dilation of the Alcock–Paczynski
/// effect). 2 for the ct_* (coefficients in (Mpc/h)², two linear spectra: B in (Mpc/h)⁶), 0 for the st_*.
pub const REDSHIFT_COUNTERTERM_K_POWERS: [i32; N_REDSHIFT_CT] = {
    let mut out = [0; N_REDSHIFT_CT];
    let mut i = 0;
    while i < N_REDSHIFT_CT {
        // "ct_" against "st_": the first byte
        out[i] = if REDSHIFT_COUNTERTERMS[i].as_bytes()[0] == b'c' {
            2
        } else {
            0
        };
        i += 1;
    }
    out
};

/// The shapes of the module docs at the triangle of sides `k` [h/Mpc] with `bias`, growth rate and
/// orientation `redshift`, for the linear spectrum `p`; at f = 0 the first seven are
/// [`galaxy_counterterm_shapes`]' and the rest zero.
///
/// # Errors
/// As [`triangle_vectors`]; [`LoopBias::check_finite`]; f outside [0, 2] or a bad orientation.
pub fn redshift_counterterm_shapes(
    p: &LinearSpectrum,
    k: [f64; 3],
    bias: &LoopBias,
    redshift: (f64, Orientation),
) -> Result<[f64; N_REDSHIFT_CT]> {
    bias.check_finite()?;
    let (f, n) = Orientation::checked_with(redshift)?;
    let kv = triangle_vectors(k)?;
    shapes_at(p, k, &kv, bias, f, &n)
}

/// The shapes at the triangle of sides `sides`, vectors `kv`, and unit line of sight `n`.
fn shapes_at(
    p: &LinearSpectrum,
    sides: [f64; 3],
    kv: &[[f64; 3]; 3],
    bias: &LoopBias,
    f: f64,
    n: &[f64; 3],
) -> Result<[f64; N_REDSHIFT_CT]> {
    if f == 0.0 {
        let real = galaxy_counterterm_shapes(p, sides, bias)?;
        let mut out = [0.0; N_REDSHIFT_CT];
        out[..7].copy_from_slice(&real);
        return Ok(out);
    }
    let k = kv.map(norm);
    let pk = k.map(|k| p.eval(k));
    let sight = Sight::new(kv, n);
    let mut s = [0.0; N_REDSHIFT_CT];
    for i in 0..3 {
        let j = (i + 1) % 3;
        let z2 = galaxy_redshift_kernel(bias, &[kv[i], kv[j]], f, n)?;
        let z2_real = galaxy_kernel(bias, &[kv[i], kv[j]])?;
        let parts = pair_parts(&sight, i, &bias.b1, &f, &z2, &z2_real);
        let pp = 2.0 * pk[i] * pk[j];
        for (c, (s, x)) in s.iter_mut().zip(parts).enumerate() {
            *s += x * if STOCHASTIC_LEGS.contains(&c) {
                pk[i]
            } else {
                pp
            };
        }
    }
    s[6] = 1.0;
    Ok(s)
}

/// The shapes whose part of pair i (`pair_parts`) multiplies P(k_i) (st_p, st_p_mu2, st_p_mu4); the
/// others' multiplies 2 P(k_i) P(k_j), and st_1 (index 6) is 1.
pub const STOCHASTIC_LEGS: [usize; 3] = [5, 15, 16];

/// What the shapes need of a triangle `kv` and a unit line of sight: the sides, their parts along the line
/// of sight k_a·n̂ and μ_a².
#[derive(Debug, Clone, Copy)]
pub(super) struct Sight<'a> {
    kv: &'a [[f64; 3]; 3],
    k: [f64; 3],
    par: [f64; 3],
    mu2: [f64; 3],
}

impl<'a> Sight<'a> {
    /// The triangle `kv` seen along the unit vector `n`.
    pub(super) fn new(kv: &'a [[f64; 3]; 3], n: &[f64; 3]) -> Self {
        let k = kv.map(norm);
        let par = [0, 1, 2].map(|a| dot(&kv[a], n));
        let mu2 = [0, 1, 2].map(|a| par[a] * par[a] / (k[a] * k[a]));
        Self { kv, k, par, mu2 }
    }
}

/// The part of each shape (module docs) from the pair of sides (i, j = i + 1 mod 3) and the leg i,
/// without the linear spectrum (2 P_i P_j for the pair's, P_i for [`STOCHASTIC_LEGS`]; st_1 zero), at the
/// coefficients b1, f and the second-order kernels Z₂ (redshift space) and Z₂(f = 0) of the pair: numbers
/// or polynomials in them ([`Ring`]).
pub(super) fn pair_parts<T: Ring>(
    sight: &Sight,
    i: usize,
    b1: &T,
    f: &T,
    z2: &T,
    z2_real: &T,
) -> [T; N_REDSHIFT_CT] {
    let (j, l) = ((i + 1) % 3, (i + 2) % 3);
    let (k, par, mu2) = (sight.k, sight.par, sight.mu2);
    let z1 = |a: usize| b1.clone() + f.clone() * mu2[a];
    let zz = z1(i) * z1(j);
    let (ki2, kj2, kl2) = (k[i] * k[i], k[j] * k[j], k[l] * k[l]);
    let mu = (kl2 - ki2 - kj2) / (2.0 * k[i] * k[j]);
    let f2 = f_n(&[sight.kv[i], sight.kv[j]]);
    let g2 = 3.0 / 7.0 + 0.5 * mu * (k[i] / k[j] + k[j] / k[i]) + 4.0 / 7.0 * mu * mu;
    let ff = f.clone() * f.clone();
    let leg = |wi: T, wj: T| z2.clone() * (wi * ki2 * z1(j) + wj * kj2 * z1(i));
    let one = || T::from(1.0);
    let kpar = f.clone() * (0.5 * (par[i] + par[j]));
    let mut s: [T; N_REDSHIFT_CT] = std::array::from_fn(|_| T::from(0.0));
    s[0] = leg(one(), one());
    s[1] = zz.clone() * kl2;
    s[2] = zz.clone() * (ki2 + kj2);
    s[3] = zz.clone() * (kl2 * (mu * mu - 1.0 / 3.0));
    s[4] = zz.clone() * (f2 * kl2);
    s[7] = leg(f.clone() * mu2[i], f.clone() * mu2[j]);
    s[8] = leg(
        ff.clone() * (mu2[i] * mu2[i]),
        ff.clone() * (mu2[j] * mu2[j]),
    );
    s[9] = zz.clone() * f.clone() * (kl2 * mu2[l]);
    s[10] = zz.clone() * f.clone() * (ki2 * mu2[i] + kj2 * mu2[j]);
    s[11] = zz.clone() * f.clone() * (g2 * kl2 * mu2[l]);
    s[12] = zz.clone() * kpar.clone() * (par[i] * kj2 / ki2 + par[j] * ki2 / kj2);
    s[13] = zz.clone()
        * kpar.clone()
        * f.clone()
        * (par[i] * kj2 * mu2[j] / ki2 + par[j] * ki2 * mu2[i] / kj2);
    s[14] = zz.clone() * kpar * (z1(j) * par[i] + z1(i) * par[j]);
    s[17] = zz.clone() * ff.clone() * (kl2 * mu2[l] * mu2[l]);
    s[18] = zz.clone() * z2.clone() * ff.clone() * (kl2 * mu2[l]);
    s[19] = zz * (z2.clone() - z2_real.clone()) * kl2;
    s[5] = b1.clone() * z1(i);
    s[15] = f.clone() * mu2[i] * z1(i);
    s[16] = ff * (mu2[i] * mu2[i]) * z1(i);
    s
}

/// The multipoles ℓ = 0, 2, 4 of [`redshift_counterterm_shapes`] (the Legendre polynomial on `side`), on
/// the exact orientation rule of [`super::one_loop_galaxy_multipoles`] (every shape is an even polynomial
/// of degree ≤ 12 in n̂).
///
/// # Errors
/// As [`redshift_counterterm_shapes`]; a side index beyond 2.
pub fn redshift_counterterm_multipoles(
    p: &LinearSpectrum,
    k: [f64; 3],
    bias: &LoopBias,
    f: f64,
    side: LegendreSide,
) -> Result<[[f64; N_REDSHIFT_CT]; 3]> {
    bias.check_finite()?;
    crate::cosmology::check_growth_rate(f)?;
    let kv = triangle_vectors(k)?;
    let a = legendre_side_index(&k, side)?;
    let (n_mu, n_phi) = ORIENTATION_RULE;
    let (los, weights) = multipole_weights(&orientation_nodes(n_mu, n_phi), &kv, a)?;
    let mut out = [[0.0; N_REDSHIFT_CT]; 3];
    for (n, w) in los.iter().zip(&weights) {
        let s = shapes_at(p, k, &kv, bias, f, n)?;
        for (o, w) in out.iter_mut().zip(w) {
            for (o, s) in o.iter_mut().zip(&s) {
                *o += w * s;
            }
        }
    }
    Ok(out)
}
