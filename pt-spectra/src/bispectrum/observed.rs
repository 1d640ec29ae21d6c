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
    let (qp2, qt2) = (s.q_par * s.q_par, s.q_perp * s.q_perp);
    let par_true = par.map(|p| p / s.q_par);
    let k_true = [0, 1, 2].map(|i| {
        let perp2 = (k[i] * k[i] - par[i] * par[i]).max(0.0);
        (par_true[i] * par_true[i] + perp2 / qt2).sqrt()
    });
    let dots_true = [0, 1, 2].map(|i| {
        let pp = par[i] * par[(i + 1) % 3];
        pp / qp2 + (dots[i] - pp) / qt2
    });
    let p = [0, 1, 2].map(|i| power(i, k_true[i], par_true[i] / k_true[i]));
    let mut slots = tree_slots(k_true, dots_true, par_true, p, s.f);
    let fog = s.fog.factor(par_true.iter().map(|p| p * p).sum());
    let volume = 1.0 / (qp2 * qt2 * qt2);
    for v in &mut slots[..SLOTS - 1] {
        *v *= fog * volume;
    }
    slots[SLOTS - 1] *= volume;
    slots
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
    let mu = [0, 1, 2].map(|i| par[i] / k[i]);
    let a: [[f64; 3]; 3] = [0, 1, 2].map(|i| [f * mu[i] * mu[i], 1.0, -par[i] * par[i]]);
    let mut out = [0.0; SLOTS];
    for i in 0..3 {
        let (j, l) = ((i + 1) % 3, (i + 2) % 3);
        let cos = dots[i] / (k[i] * k[j]);
        let ratio = k[i] / k[j] + k[j] / k[i];
        let f2 = 5.0 / 7.0 + 0.5 * cos * ratio + 2.0 / 7.0 * cos * cos;
        let g2 = 3.0 / 7.0 + 0.5 * cos * ratio + 4.0 / 7.0 * cos * cos;
        let k_par = par[i] + par[j]; // n̂·(kᵢ + kⱼ) = −n̂·k_l
        let mu12_sq = k_par * k_par / (k[l] * k[l]);
        let c = [
            f * mu12_sq * g2
                + 0.5
                    * f
                    * f
                    * k_par
                    * (mu[i] * mu[j] * mu[j] / k[i] + mu[j] * mu[i] * mu[i] / k[j]),
            f2 + 0.5 * f * k_par * (mu[i] / k[i] + mu[j] / k[j]),
            0.5,
            cos * cos - 1.0 / 3.0,
        ];
        let pp = 2.0 * p[i] * p[j];
        for al in 0..3 {
            for be in 0..3 {
                let ab = pp * a[i][al] * a[j][be];
                for (g, cg) in c.iter().enumerate() {
                    out[(al * 3 + be) * 4 + g] += ab * cg;
                }
            }
        }
        for be in 0..3 {
            out[36 + be] += p[i] * a[i][be];
            out[39 + be] += p[i] * a[i][0] * a[i][be];
        }
    }
    out[42] = 1.0;
    out
}
