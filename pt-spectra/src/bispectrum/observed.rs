//! The monomial slots of B at one configuration given in the observed (fiducial) frame: the
//! Alcock–Paczynski map to the true frame, the linear power of each side, the FoG factor and the
//! volume factor (module docs of [`crate::bispectrum`]).

use super::terms::{tree_slots, SLOTS};
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
