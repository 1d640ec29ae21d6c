//! The monomial slots of B at one configuration: in the true frame ([`tree_slots`]), and given in the
//! observed (fiducial) frame ([`observed_slots`]: the Alcock–Paczynski map to the true frame, the linear
//! power of each side, the FoG factor and the volume factor; module docs of [`crate::bispectrum`]).

use super::Settings;

/// The slots at observed sides of lengths `k`, dot products `dots` (k₀·k₁, k₁·k₂, k₂·k₀) and
/// line-of-sight components `par` [h/Mpc], times the AP volume factor 1/(q∥²q⊥⁴); FoG on every slot but
/// 1/n̄². `power(i, k, μ)` is the (resummed) linear power of side i at its true k and μ.
pub(super) fn observed_slots(
    k: [f64; 3],
    dots: [f64; 3],
    par: [f64; 3],
    s: &Settings,
    power: impl Fn(usize, f64, f64) -> f64,
) -> [f64; SLOTS] {
    let mut out = [0.0; SLOTS];
    add_observed_slots(&mut out, k, dots, par, s, power);
    out
}

/// Adds the slots of [`observed_slots`] to `out` (the inner loop of the orientation and bin averages:
/// no array of slots is made per node).
#[inline]
pub(super) fn add_observed_slots(
    out: &mut [f64; SLOTS],
    k: [f64; 3],
    dots: [f64; 3],
    par: [f64; 3],
    s: &Settings,
    power: impl Fn(usize, f64, f64) -> f64,
) {
    let (inv_qp2, inv_qt2) = (1.0 / (s.q_par * s.q_par), 1.0 / (s.q_perp * s.q_perp));
    let inv_qp = 1.0 / s.q_par;
    let mut par_true = [0.0; 3];
    let mut k_true = [0.0; 3];
    let mut inv_k = [0.0; 3];
    let mut p = [0.0; 3];
    let mut x = 0.0;
    for i in 0..3 {
        par_true[i] = par[i] * inv_qp;
        let perp2 = (k[i] * k[i] - par[i] * par[i]).max(0.0);
        k_true[i] = (par_true[i] * par_true[i] + perp2 * inv_qt2).sqrt();
        inv_k[i] = 1.0 / k_true[i];
        p[i] = power(i, k_true[i], par_true[i] * inv_k[i]);
        x += par_true[i] * par_true[i];
    }
    let mut dots_true = [0.0; 3];
    for i in 0..3 {
        let pp = par[i] * par[(i + 1) % 3];
        dots_true[i] = pp * inv_qp2 + (dots[i] - pp) * inv_qt2;
    }
    let volume = inv_qp2 * inv_qt2 * inv_qt2;
    let fog = s.fog.factor(x);
    add_tree_slots(
        out,
        (k_true, inv_k),
        dots_true,
        par_true,
        p,
        s.f,
        fog * volume,
        volume,
    );
}

/// Adds `slots` times each weight to the matching accumulator.
pub(super) fn accumulate<const N: usize>(
    acc: &mut [[f64; SLOTS]; N],
    weights: [f64; N],
    slots: &[f64; SLOTS],
) {
    for (acc, g) in acc.iter_mut().zip(weights) {
        for (a, v) in acc.iter_mut().zip(slots) {
            *a += g * v;
        }
    }
}

/// Number of monomial slots per triangle and ℓ: 36 of Z₁Z₁Z₂ (3 × 3 × 4), 3 + 3 of the 1/n̄ terms, 1 of
/// the 1/n̄² term.
pub(super) const SLOTS: usize = 43;

/// The slots of B at one configuration with true sides of lengths `k`, dot products `dots`, line-of-sight
/// components `par` and linear power `p` (see the module docs of [`crate::bispectrum`]):
/// Z₁ = u·a with u = (1, b₁, c₁), a = (fμ², 1, −k²μ²); Z₂ = v·c with v = (1, b₁, b₂, b_s).
pub(super) fn tree_slots(
    k: [f64; 3],
    dots: [f64; 3],
    par: [f64; 3],
    p: [f64; 3],
    f: f64,
) -> [f64; SLOTS] {
    let mut out = [0.0; SLOTS];
    let inv_k = k.map(|k| 1.0 / k);
    add_tree_slots(&mut out, (k, inv_k), dots, par, p, f, 1.0, 1.0);
    out
}

/// Adds the slots of [`tree_slots`] to `out` (sides `k` with their inverses), those of the P-dependent terms times `scale` and the
/// constant 1/n̄² slot as `constant`.
#[inline]
#[allow(clippy::too_many_arguments)]
fn add_tree_slots(
    out: &mut [f64; SLOTS],
    (k, inv_k): ([f64; 3], [f64; 3]),
    dots: [f64; 3],
    par: [f64; 3],
    p: [f64; 3],
    f: f64,
    scale: f64,
    constant: f64,
) {
    let mu = [par[0] * inv_k[0], par[1] * inv_k[1], par[2] * inv_k[2]];
    let a: [[f64; 3]; 3] = [
        [f * mu[0] * mu[0], 1.0, -par[0] * par[0]],
        [f * mu[1] * mu[1], 1.0, -par[1] * par[1]],
        [f * mu[2] * mu[2], 1.0, -par[2] * par[2]],
    ];
    // per pair (i, j) = (0, 1), (1, 2), (2, 0): 2 P_i P_j × scale and the four coefficients of Z₂
    let mut pp = [0.0; 3];
    let mut c = [[0.0; 4]; 3];
    for i in 0..3 {
        let (j, l) = ((i + 1) % 3, (i + 2) % 3);
        let cos = dots[i] * inv_k[i] * inv_k[j];
        let ratio = k[i] * inv_k[j] + k[j] * inv_k[i];
        let f2 = 5.0 / 7.0 + 0.5 * cos * ratio + 2.0 / 7.0 * cos * cos;
        let g2 = 3.0 / 7.0 + 0.5 * cos * ratio + 4.0 / 7.0 * cos * cos;
        let k_par = par[i] + par[j]; // n̂·(kᵢ + kⱼ) = −n̂·k_l
        let mu12_sq = k_par * k_par * inv_k[l] * inv_k[l];
        c[i] = [
            f * mu12_sq * g2
                + 0.5
                    * f
                    * f
                    * k_par
                    * (mu[i] * mu[j] * mu[j] * inv_k[i] + mu[j] * mu[i] * mu[i] * inv_k[j]),
            f2 + 0.5 * f * k_par * (mu[i] * inv_k[i] + mu[j] * inv_k[j]),
            0.5,
            cos * cos - 1.0 / 3.0,
        ];
        pp[i] = 2.0 * p[i] * p[j] * scale;
    }
    // each slot written once per configuration, the three pairs summed in registers (a slot
    // updated once per pair went through memory three times)
    for al in 0..3 {
        for be in 0..3 {
            let w: [f64; 3] = std::array::from_fn(|i| pp[i] * a[i][al] * a[(i + 1) % 3][be]);
            let base = (al * 3 + be) * 4;
            for g in 0..4 {
                out[base + g] += w[0] * c[0][g] + w[1] * c[1][g] + w[2] * c[2][g];
            }
        }
    }
    for be in 0..3 {
        let (mut shot_b, mut shot_p) = (0.0, 0.0);
        for i in 0..3 {
            let ps = p[i] * scale;
            shot_b += ps * a[i][be];
            shot_p += ps * a[i][0] * a[i][be];
        }
        out[36 + be] += shot_b;
        out[39 + be] += shot_p;
    }
    out[42] += constant;
}
