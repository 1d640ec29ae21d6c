//! Spectra that differ from the basis's span only at horizon scales (curved cosmologies), evaluated
//! on the basis all the same: the spectrum below [`SOFT_CUT`] is replaced by the power law a table
//! starting there would get, and what that changes is put back at leading order in q/k.
//!
//! A curved universe's CAMB spectrum is the flat-like one times (1 − 3K/k²)², K = −Ω_k (H0/c)²
//! (the Poisson equation on curved space; against CAMB with the other parameters fixed, at
//! Ω_k = ±0.01, 0.05: to three digits at k = 1e-4 h/Mpc, within 1e-4 of P at k ≥ 1e-3): +0.7% at
//! k = 1e-3 h/Mpc for Ω_k = 0.01, +78% at 1e-4. No small basis of flat
//! spectra follows that, but cut at 1e-3 (the library's power law below, as the training set's cut
//! tables have) it projects: smoothed residual 9e-5 for Ω_k = ±0.01, 2.6e-4 for 0.03 (4.3e-4
//! for 0.05).
//!
//! The loop terms see modes q ≪ k through their infrared limits only. With δP = P − P_cut (non-zero
//! below ~1e-3 h/Mpc) and Δ = ∫ δP dq / 6π² (its share of σ_v²), every 1-loop P22 of δδ, δθ, θθ
//! changes by +k² P(k) Δ and every P13 by −½ k² P(k) Δ (P_1loop = P22 + 2 P13; the soft limits of
//! F₂, G₂ and F₃, G₃, whose sum cancels), σ_v² by Δ and RegPT's σ_d²(k) by the part of Δ below k/2;
//! the next order is (q/k)² smaller (measured between the direct terms of whole and cut tables:
//! the shifts hold to 1.2e-3 of themselves for k ≥ 0.01). The 1-loop basis adds these to the terms
//! of the cut spectrum, and [`RESPONSE_FACTOR`] k² P(k) |Δ| ([`SoftModes::error`]) to their errors
//! for the next order. Every other term is evaluated on the cut spectrum throughout (the 2-loop
//! correction with the cut spectrum's 1-loop terms), so that its infrared-safe sums are the whole
//! spectrum's up to (q/k)²: measured, TNS A and B and the galaxy model's terms move by ≤ 0.03
//! k² P |Δ| ([`RESPONSE_FACTOR`]), each 2-loop term alone by ≤ 0.18 k² |Δ| (|P22| + |P13|)
//! ([`TWO_LOOP_FACTOR`]).

use crate::linear::LinearSpectrum;
use crate::loops::lattice::Lattice;
use crate::loops::{Estimate, OneLoopTerms, Pair};
use std::f64::consts::PI;

/// Below this [h/Mpc] a spectrum that does not project whole is replaced by the power law of a
/// table starting here (the lower end of the training set's cut tables).
pub const SOFT_CUT: f64 = 1e-3;

/// The soft-mode error of the 1-loop terms after their soft limits are put back (measured ≤ 1.2e-3
/// k² P |Δ| for k ≥ 0.01), and of the terms that are not put back but are infrared safe, each a
/// sum of diagrams whose soft limits cancel (TNS A and B; the galaxy model's terms, one per
/// monomial, with −(kμfσ_v)²Z₁²P among them), is this times [`SoftModes::error`]: measured
/// directly on whole and cut CAMB spectra (Ω_k = ±0.01, 0.03, k from 0.005), their responses are
/// ≤ 0.03 k² P |Δ|.
pub const RESPONSE_FACTOR: f64 = 0.1;

/// The soft-mode error of each 2-loop term alone (P15, P24, P33): this times k² |Δ| (|P22| + |P13|),
/// the displacement's response one loop lower; measured ≤ 0.18 of that (Ω_k = ±0.01, P15 θθ).
pub const TWO_LOOP_FACTOR: f64 = 0.5;

/// What the cut of a spectrum below [`SOFT_CUT`] changed.
#[derive(Debug, Clone, PartialEq)]
pub struct SoftModes {
    /// Δ = ∫ (P − P_cut) dq / 6π² [(Mpc/h)²] over the lattice.
    pub delta: f64,
    /// ∫ |P − P_cut| dq / 6π² [(Mpc/h)²].
    pub delta_abs: f64,
    /// ∫_{q_min}^{q_j} (P − P_cut) dq / 6π² at the lattice points q_j while P − P_cut is non-zero (Δ
    /// beyond).
    cumulative: Vec<(f64, f64)>,
}

impl SoftModes {
    /// The part of Δ below `q` [h/Mpc] (linear between lattice points).
    pub fn delta_below(&self, q: f64) -> f64 {
        let x = q.ln();
        match self.cumulative.iter().position(|&(xj, _)| xj >= x) {
            None => self.delta,
            Some(0) => 0.0,
            Some(j) => {
                let ((x0, d0), (x1, d1)) = (self.cumulative[j - 1], self.cumulative[j]);
                d0 + (d1 - d0) * (x - x0) / (x1 - x0)
            }
        }
    }

    /// k² Δ P: the change of every 1-loop P22 (and −2 times that of every P13) at `k` [h/Mpc] where
    /// the linear spectrum is `p`.
    pub fn p22_shift(&self, k: f64, p: f64) -> f64 {
        k * k * self.delta * p
    }

    /// The error added to a term at `k` where the linear spectrum is `p`: k² P |Δ|_abs, the size of
    /// the soft response of any 1-loop term.
    pub fn error(&self, k: f64, p: f64) -> f64 {
        k * k * self.delta_abs * p.abs()
    }

    /// The 1-loop terms of the cut spectrum made those of the whole one at leading order in q/k:
    /// P22 + k²PΔ, P13 − ½k²PΔ, σ_v² + Δ, σ_d²(k) + the part of Δ below k/2 (the last two exact:
    /// they are linear in P); and the soft error on P22 and P13 (for the next order).
    pub(crate) fn put_back(&self, terms: &mut OneLoopTerms, sigma_d2: &mut [Estimate]) {
        self.shift(terms, 1.0);
        for (i, &k) in terms.k.iter().enumerate() {
            sigma_d2[i].value += self.delta_below(0.5 * k);
            let error = RESPONSE_FACTOR * self.error(k, terms.p_lin[i]);
            for pair in Pair::ALL {
                terms.p22[pair][i].error += error;
                terms.p13[pair][i].error += error;
            }
        }
    }

    /// The 1-loop terms of the whole spectrum (after [`put_back`](Self::put_back)) back to those of
    /// the cut one, for terms that must see the same spectrum as the 1-loop ones they are
    /// assembled with (the 2-loop correction, whose sum is infrared safe only so).
    pub(crate) fn take_out(&self, terms: &OneLoopTerms) -> OneLoopTerms {
        let mut terms = terms.clone();
        self.shift(&mut terms, -1.0);
        terms
    }

    /// The values of P22, P13 and σ_v² moved by `sign` times their soft limits.
    fn shift(&self, terms: &mut OneLoopTerms, sign: f64) {
        terms.sigma_v2.value += sign * self.delta;
        for i in 0..terms.k.len() {
            let shift = sign * self.p22_shift(terms.k[i], terms.p_lin[i]);
            for pair in Pair::ALL {
                terms.p22[pair][i].value += shift;
                terms.p13[pair][i].value -= 0.5 * shift;
            }
        }
    }
}

/// The clause a table header adds for a spectrum projected cut below the soft modes (`soft`: its
/// Δ [(Mpc/h)²]), or nothing.
pub fn describe(soft: Option<f64>) -> String {
    soft.map_or(String::new(), |delta| {
        format!(
            "; the spectrum projected cut below {SOFT_CUT:.0e} h/Mpc (horizon-scale power the basis \
             does not span, e.g. from spatial curvature), its soft modes (Delta = {delta:.2e} \
             (Mpc/h)^2 of sigma_v^2) put back at leading order in q/k, their response in the errors"
        )
    })
}

/// The spectrum cut below [`SOFT_CUT`] (the library's power law below its first node), or `None`
/// if its table starts above the cut or keeps fewer than 8 nodes.
pub fn cut(spectrum: &LinearSpectrum) -> Option<LinearSpectrum> {
    let k = spectrum.nodes().0;
    let first = k.iter().position(|&k| k >= SOFT_CUT)?;
    if first == 0 || k.len() - first < 8 {
        return None;
    }
    spectrum.restricted(SOFT_CUT, f64::INFINITY).ok()
}

/// Δ, |Δ| and the running Δ of the lattice samples `full` of a spectrum and `cut` of its cut
/// (trapezoid rule in ln q).
pub(crate) fn soft_modes(lattice: &Lattice, full: &[f64], cut: &[f64]) -> SoftModes {
    let norm = lattice.step / (6.0 * PI * PI);
    let diff = |j: usize| (full[j] - cut[j]) * lattice.x(j).exp();
    // P − P_cut is non-zero below the cut and, from the spline's end condition, just above it.
    let end = (0..lattice.len)
        .rev()
        .find(|&j| full[j] != cut[j])
        .map_or(0, |j| (j + 1).min(lattice.len - 1));
    let (mut delta, mut delta_abs) = (0.0, 0.0);
    let mut cumulative = vec![(lattice.x(0), 0.0)];
    for j in 1..=end {
        let (a, b) = (diff(j - 1), diff(j));
        delta += 0.5 * norm * (a + b);
        delta_abs += 0.5 * norm * (a.abs() + b.abs());
        cumulative.push((lattice.x(j), delta));
    }
    SoftModes {
        delta,
        delta_abs,
        cumulative,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::loops::OneLoopPlan;
    use crate::precision::Precision;

    fn table(name: &str) -> LinearSpectrum {
        let dir = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/data/");
        LinearSpectrum::from_file(format!("{dir}{name}")).unwrap()
    }

    /// The soft limits the basis puts back: between a curved spectrum and its cut, the direct 1-loop
    /// P22 differ by +k²PΔ and P13 by −½k²PΔ up to (q/k)² (q ≲ 2e-3 h/Mpc), σ_v² by Δ.
    #[test]
    fn the_direct_terms_of_a_spectrum_and_its_cut_differ_by_the_soft_limits() {
        let k = [0.01, 0.03, 0.1, 0.3];
        let plan = OneLoopPlan::new(&k, &Precision::fast()).unwrap();
        let lattice = plan.rules().0.lattice.clone();
        for name in [
            "linear_pk_camb_curved_wa_z0.5.dat",
            "linear_pk_camb_closed_z0.0.dat",
        ] {
            let full = table(name);
            let cut = cut(&full).unwrap();
            let sample = |p: &LinearSpectrum| {
                let x = (0..lattice.len).map(|j| lattice.x(j));
                p.eval_ln_many(x)
            };
            let soft = soft_modes(&lattice, &sample(&full), &sample(&cut));
            // Ω_k = +0.01 raises the power below 1e-3 h/Mpc, −0.01 lowers it.
            assert_eq!(soft.delta > 0.0, name.contains("curved"), "{name}");
            assert!(soft.delta_abs >= soft.delta.abs() && soft.delta_abs < 1e-2);
            assert_eq!(soft.delta_below(1e-6), 0.0);
            assert_eq!(soft.delta_below(1.0), soft.delta);
            let (a, b) = (plan.evaluate(&full), plan.evaluate(&cut));
            let dv = a.sigma_v2.value - b.sigma_v2.value;
            assert!(
                (dv / soft.delta - 1.0).abs() < 1e-3,
                "{name}: {dv} {}",
                soft.delta
            );
            for (i, &ki) in k.iter().enumerate() {
                let shift = soft.p22_shift(ki, a.p_lin[i]);
                for pair in Pair::ALL {
                    let d22 = a.p22[pair][i].value - b.p22[pair][i].value;
                    let d13 = a.p13[pair][i].value - b.p13[pair][i].value;
                    // (q/k)² ≤ (2e-3/0.01)² = 4e-2; measured ≤ 1.2e-3
                    assert!(
                        (d22 / shift - 1.0).abs() < 5e-3,
                        "{name} {ki} {pair:?}: {d22} {shift}"
                    );
                    assert!(
                        (d13 / shift + 0.5).abs() < 5e-3,
                        "{name} {ki} {pair:?}: {d13} {shift}"
                    );
                }
            }
        }
    }

    #[test]
    fn only_tables_that_start_below_the_cut_are_cut() {
        let full = table("linear_pk_camb_heldout_0.dat");
        let cut_table = cut(&full).unwrap();
        assert!(cut_table.nodes().0[0] >= SOFT_CUT);
        // Above the cut (beyond the spline's end condition) the same spectrum.
        for k in [3e-3, 0.1, 10.0] {
            assert!((cut_table.eval(k) / full.eval(k) - 1.0).abs() < 1e-6, "{k}");
        }
        assert!(cut(&cut_table).is_none(), "already cut");
    }
}
