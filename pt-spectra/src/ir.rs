//! Infrared resummation of the BAO (Blas, Garny, Ivanov & Sibiryakov 2016, arXiv:1605.02149;
//! Baldauf, Mirbabayi, Simonović & Zaldarriaga 2015, arXiv:1504.04366): the linear spectrum split into
//! a smooth no-wiggle part and the BAO wiggles, and the wiggles damped by the large-scale
//! displacements, Σ² at the BAO scale.
//!
//! * **Split** ([`no_wiggle`]): P_nw = P_ref · G_λ[P/P_ref], where P_ref is the Eisenstein & Hu (1998)
//!   no-wiggle fit of the gm2012 cosmology (any smooth broadband serves: the ratio P/P_ref is
//!   smoothed, so only its wiggles are removed) and G_λ a Gaussian filter in ln k of width
//!   λ = [`FILTER_WIDTH`] (Vlah, Seljak, Chu & Feng 2016, arXiv:1509.02120). P_w = P − P_nw.
//! * **Damping** ([`sigma2_bao`]): Σ² = (1/6π²)∫_0^{k_s} dq P_nw(q)[1 − j0(qℓ) + 2j2(qℓ)] with the BAO
//!   scale ℓ = [`BAO_SCALE`] and k_s = [`SIGMA_CUTOFF`] (the choices of CLASS-PT, Chudaykin, Ivanov,
//!   Philcox & Simonović 2020).
//! * **Models** (per pair X, Y, with the loop terms P^(n)[·] of the no-wiggle and full spectra and
//!   P^(n)_w = P^(n)\[P_lin\] − P^(n)\[P_nw\]):
//!   - `1l-spt-ir`: P_nw + P^(1)_nw + e^{−k²Σ²}[(1 + k²Σ²) P_w + P^(1)_w];
//!   - `2l-spt-ir`: P_nw + P^(1)_nw + P^(2)_nw + e^{−k²Σ²}[(1 + k²Σ² + k⁴Σ⁴/2) P_w + (1 + k²Σ²) P^(1)_w
//!     + P^(2)_w].
//!
//! Expanding e^{−k²Σ²} gives back SPT to the order of the model; the resummation acts on the wiggles
//! only.

use crate::cosmology::{Cosmology, TransferKind};
use crate::error::Result;
use crate::estimate::Estimate;
use crate::linear::{LinearSpectrum, LogGrid};
use crate::loops::{IrTerms, OneLoopTerms, Pair, TwoLoopCorrection};
use std::f64::consts::PI;

pub use crate::savgol::savitzky_golay_no_wiggle;

/// Width of the Gaussian filter in ln k.
pub const FILTER_WIDTH: f64 = 0.25;
/// The BAO scale ℓ in Σ² [Mpc/h].
pub const BAO_SCALE: f64 = 110.0;
/// The upper limit k_s of the Σ² integral [h/Mpc].
pub const SIGMA_CUTOFF: f64 = 0.2;

/// Nodes per unit ln k of the split's grid.
const NODES_PER_E_FOLD: f64 = 100.0;

/// The no-wiggle part of `spectrum` on its own k range (see the module docs): [`WiggleSplit`] built
/// and applied once. A plan that splits many spectra keeps its [`WiggleSplit`].
///
/// # Errors
/// As [`WiggleSplit::new`] and [`WiggleSplit::no_wiggle`].
pub fn no_wiggle(spectrum: &LinearSpectrum) -> Result<LinearSpectrum> {
    WiggleSplit::new()?.no_wiggle(spectrum)
}

/// The smooth reference P_ref of the split (cosmology independent: built once per plan).
#[derive(Debug, Clone)]
pub struct WiggleSplit {
    reference: LinearSpectrum,
}

impl WiggleSplit {
    /// The split with P_ref the Eisenstein & Hu no-wiggle spectrum of gm2012.
    ///
    /// # Errors
    /// As [`Cosmology::eisenstein_hu_spectrum`].
    pub fn new() -> Result<Self> {
        let reference = Cosmology::gm2012().eisenstein_hu_spectrum(
            TransferKind::NoWiggle,
            0.0,
            &LogGrid::new(1e-6, 1e4, 4000)?,
        )?;
        Ok(Self { reference })
    }

    /// The no-wiggle part of `spectrum` on its own k range (see the module docs).
    ///
    /// # Errors
    /// As [`LinearSpectrum::from_nodes`].
    pub fn no_wiggle(&self, spectrum: &LinearSpectrum) -> Result<LinearSpectrum> {
        split(spectrum, &self.reference)
    }
}

fn split(spectrum: &LinearSpectrum, reference: &LinearSpectrum) -> Result<LinearSpectrum> {
    let (lo, hi) = (spectrum.k_min().ln(), spectrum.k_max().ln());
    let n = ((hi - lo) * NODES_PER_E_FOLD).ceil() as usize + 1;
    let step = (hi - lo) / (n - 1) as f64;
    let ln_k: Vec<f64> = (0..n).map(|i| lo + step * i as f64).collect();
    let ratio: Vec<f64> = ln_k
        .iter()
        .map(|&x| (spectrum.eval(x.exp()) / reference.eval(x.exp())).ln())
        .collect();
    // Gaussian smoothing of ln(P/P_ref) in ln k; at the ends the kernel is renormalised over the
    // nodes that exist (the BAO sit far inside any table that reaches them).
    let reach = (4.0 * FILTER_WIDTH / step).ceil() as usize;
    let weights: Vec<f64> = (0..=reach)
        .map(|j| (-0.5 * (j as f64 * step / FILTER_WIDTH).powi(2)).exp())
        .collect();
    let smooth: Vec<f64> = (0..n)
        .map(|i| {
            let (mut sum, mut norm) = (0.0, 0.0);
            for j in i.saturating_sub(reach)..(i + reach + 1).min(n) {
                let w = weights[i.abs_diff(j)];
                sum += w * ratio[j];
                norm += w;
            }
            sum / norm
        })
        .collect();
    let k: Vec<f64> = ln_k.iter().map(|x| x.exp()).collect();
    let p = k
        .iter()
        .zip(&smooth)
        .map(|(&k, s)| reference.eval(k) * s.exp())
        .collect();
    LinearSpectrum::from_nodes(k, p)
}

/// Σ² = (1/6π²)∫_{q_min}^{k_s} dq P_nw(q)[1 − j0(qℓ) + 2j2(qℓ)] [(Mpc/h)²] with ℓ = [`BAO_SCALE`],
/// k_s = [`SIGMA_CUTOFF`]: Simpson in ln q (2048 intervals), error against the half rule
/// ([`bao_damping`], which gives δΣ² with it).
pub fn sigma2_bao(no_wiggle: &LinearSpectrum, q_min: f64) -> Estimate {
    bao_damping(no_wiggle, q_min).0
}

/// δΣ² = (1/2π²)∫_{q_min}^{k_s} dq P_nw(q) j2(qℓ) [(Mpc/h)²], the anisotropic part of the damping in
/// redshift space (Ivanov, Simonović & Zaldarriaga 2020, as CLASS-PT): Σ²_tot(μ) = [1 + fμ²(2 + f)]Σ²
/// + f²μ²(μ² − 1)δΣ², with ℓ = [`BAO_SCALE`], k_s = [`SIGMA_CUTOFF`]; Simpson in ln q as [`sigma2_bao`].
pub fn delta_sigma2_bao(no_wiggle: &LinearSpectrum, q_min: f64) -> Estimate {
    bao_damping(no_wiggle, q_min).1
}

/// (Σ², δΣ²) of `no_wiggle` ([`sigma2_bao`], [`delta_sigma2_bao`]) in one pass over the Simpson nodes
/// in ln q both integrals share: one evaluation of the spectrum and of the Bessel functions per node.
pub fn bao_damping(no_wiggle: &LinearSpectrum, q_min: f64) -> (Estimate, Estimate) {
    const INTERVALS: usize = 2048;
    let (lo, hi) = (q_min.ln(), SIGMA_CUTOFF.ln());
    if hi <= lo {
        return (Estimate::new(0.0, 0.0), Estimate::new(0.0, 0.0));
    }
    let (nodes, h) = crate::integrate::simpson_ln_nodes(lo, hi, INTERVALS);
    let mut isotropic = Vec::with_capacity(nodes.len());
    let mut anisotropic = Vec::with_capacity(nodes.len());
    for ln_q in nodes {
        let q = ln_q.exp();
        let x = q * BAO_SCALE;
        let (qp, j2x) = (q * no_wiggle.eval(q), j2(x));
        isotropic.push(qp * (1.0 - j0(x) + 2.0 * j2x));
        anisotropic.push(qp * j2x);
    }
    let ((s, es), (d, ed)) = (
        crate::integrate::simpson_of(&isotropic, h),
        crate::integrate::simpson_of(&anisotropic, h),
    );
    let (n_s, n_d) = (1.0 / (6.0 * PI * PI), 1.0 / (2.0 * PI * PI));
    (
        Estimate::new(n_s * s, n_s * es),
        Estimate::new(n_d * d, n_d * ed),
    )
}

/// Σ²_tot(μ) = [1 + fμ²(2 + f)]Σ² + f²μ²(μ² − 1)δΣ² [(Mpc/h)²], the damping of the wiggles in
/// redshift space (see [`delta_sigma2_bao`]) from Σ² = `sigma2` and δΣ² = `delta_sigma2`.
pub fn sigma2_total(sigma2: f64, delta_sigma2: f64, f: f64, mu: f64) -> f64 {
    let m2 = mu * mu;
    (1.0 + f * m2 * (2.0 + f)) * sigma2 + f * f * m2 * (m2 - 1.0) * delta_sigma2
}

/// Spherical Bessel j0(x) = sin x / x.
fn j0(x: f64) -> f64 {
    if x.abs() < 1e-4 {
        1.0 - x * x / 6.0
    } else {
        x.sin() / x
    }
}

/// Spherical Bessel j1(x) = sin x/x² − cos x/x.
pub fn j1(x: f64) -> f64 {
    if x.abs() < 1e-3 {
        x / 3.0 - x.powi(3) / 30.0
    } else {
        x.sin() / (x * x) - x.cos() / x
    }
}

/// Spherical Bessel j2(x) = (3/x² − 1) sin x/x − 3 cos x/x².
fn j2(x: f64) -> f64 {
    if x.abs() < 1e-2 {
        x * x / 15.0 - x.powi(4) / 210.0
    } else {
        (3.0 / (x * x) - 1.0) * x.sin() / x - 3.0 * x.cos() / (x * x)
    }
}

/// The wiggle split of `pair` at k index `i`: the linear spectrum and 1-loop correction of the
/// no-wiggle spectrum and their wiggle parts, x = k²Σ² and the damping e^{−k²Σ²} (module docs).
pub struct WiggleParts {
    /// P_nw.
    pub p_nw: Estimate,
    /// P_w = P − P_nw.
    pub p_w: Estimate,
    /// P^(1)\[P_nw\].
    pub one_nw: Estimate,
    /// P^(1)_w = P^(1)\[P\] − P^(1)\[P_nw\].
    pub one_w: Estimate,
    /// k²Σ².
    pub x: Estimate,
    /// e^{−k²Σ²}.
    pub d: Estimate,
}

/// The [`WiggleParts`] of `pair` at k index `i`, from the loop terms `t` of the linear spectrum and
/// those of the no-wiggle spectrum in `ir`.
pub fn wiggle_parts(t: &OneLoopTerms, ir: &IrTerms, pair: Pair, i: usize) -> WiggleParts {
    let nw = &ir.no_wiggle.one_loop;
    let k = t.k[i];
    WiggleParts {
        p_nw: Estimate::exact(nw.p_lin[i]),
        p_w: Estimate::exact(t.p_lin[i] - nw.p_lin[i]),
        one_nw: nw.one_loop(pair, i),
        one_w: t.one_loop(pair, i) - nw.one_loop(pair, i),
        x: k * k * ir.sigma2,
        d: damping(k, ir.sigma2),
    }
}

/// The IR-resummed spectrum of `pair` at k index `i` (module docs), from the loop terms `t` of the
/// linear spectrum, those of the no-wiggle spectrum in `ir`, and for `2l-spt-ir` the 2-loop terms
/// of both (full, no-wiggle).
pub fn resummed(
    t: &OneLoopTerms,
    ir: &IrTerms,
    two_loop: Option<(&TwoLoopCorrection, &TwoLoopCorrection)>,
    pair: Pair,
    i: usize,
) -> Estimate {
    let WiggleParts {
        p_nw,
        p_w,
        one_nw,
        one_w,
        x,
        d,
    } = wiggle_parts(t, ir, pair, i);
    match two_loop {
        None => p_nw + one_nw + d * ((1.0 + x) * p_w + one_w),
        Some((full, no_wiggle)) => {
            let (two_full, two_nw) = (full.pairs[pair].total[i], no_wiggle.pairs[pair].total[i]);
            let lo = 1.0 + x + 0.5 * x * x;
            p_nw + one_nw + two_nw + d * (lo * p_w + (1.0 + x) * one_w + (two_full - two_nw))
        }
    }
}

/// The damping factors of the IR-resummed models at k: (e^{−k²Σ²}, with its error).
pub fn damping(k: f64, sigma2: Estimate) -> Estimate {
    let e = (-k * k * sigma2.value).exp();
    Estimate::new(e, e * k * k * sigma2.error)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn delta_sigma2_matches_its_closed_form_for_a_constant_spectrum() {
        // For P_nw = P0 on [q_min, k_s]: δΣ² = (P0/2π²ℓ)[Si(x) − 3 j1(x)]/2 between x = q_min ℓ and
        // k_s ℓ, since 3 j1' = j0 − 2 j2 and ∫ j0 = Si. Si by its power series (k_s ℓ = 22: the terms reach
        // 2e8, so the sum keeps ~1e-8 of Si).
        let si = |x: f64| {
            let (mut term, mut sum) = (x, x);
            for n in 1..80 {
                let m = 2.0 * f64::from(n);
                term *= -x * x / (m * (m + 1.0));
                sum += term / (m + 1.0);
            }
            sum
        };
        let p0 = 2500.0;
        let flat =
            LinearSpectrum::from_fn(&LogGrid::new(1e-5, 10.0, 200).unwrap(), |_| p0).unwrap();
        let q_min = 1e-4;
        let l = BAO_SCALE;
        let antiderivative = |x: f64| 0.5 * (si(x) - 3.0 * j1(x));
        let exact = p0 / (2.0 * PI * PI * l)
            * (antiderivative(SIGMA_CUTOFF * l) - antiderivative(q_min * l));
        let (s, d) = bao_damping(&flat, q_min);
        assert!((d.value / exact - 1.0).abs() < 1e-7, "{} {exact}", d.value);
        assert!(d.error < 1e-6 * exact.abs());
        assert_eq!(
            (s, d),
            (sigma2_bao(&flat, q_min), delta_sigma2_bao(&flat, q_min))
        );
        // an empty range (q_min above the cut-off) integrates to 0
        let (s, d) = bao_damping(&flat, 1.0);
        assert_eq!((s.value, d.value), (0.0, 0.0));
    }

    #[test]
    fn the_split_leaves_no_wiggle_and_adds_up_to_the_input() {
        let p = LinearSpectrum::gm2012(0.0).unwrap();
        let nw = no_wiggle(&p).unwrap();
        let eh = Cosmology::gm2012()
            .eisenstein_hu_spectrum(TransferKind::NoWiggle, 0.0, &LogGrid::default())
            .unwrap();
        let k = LogGrid::new(0.02, 0.5, 2000).unwrap().points();
        // Local maxima of P/P_EH,nw (the wiggles) and of P_nw/P_EH,nw.
        let maxima = |s: &LinearSpectrum| {
            let r: Vec<f64> = k.iter().map(|&k| s.eval(k) / eh.eval(k)).collect();
            (1..r.len() - 1)
                .filter(|&i| r[i] > r[i - 1] && r[i] > r[i + 1])
                .count()
        };
        assert!(maxima(&p) >= 5, "{}", maxima(&p));
        assert!(maxima(&nw) <= 1, "{}", maxima(&nw));
        // The wiggles average out: σ8 of P_nw equals σ8 of P to 1e-3, and P_w = P − P_nw is a few per
        // cent of P around the BAO and ≤ 1e-3 of it on large scales.
        assert!((nw.sigma8() / p.sigma8() - 1.0).abs() < 1e-3);
        let wiggle = |k: f64| p.eval(k) / nw.eval(k) - 1.0;
        let peak = k.iter().map(|&k| wiggle(k).abs()).fold(0.0, f64::max);
        assert!(peak > 0.02 && peak < 0.15, "{peak}");
        assert!(wiggle(2e-3).abs() < 1e-3, "{}", wiggle(2e-3));
    }

    #[test]
    fn sigma2_matches_its_closed_form_for_a_constant_spectrum() {
        // For P_nw = P0 on [q_min, k_s]: Σ² = (P0/6π²)[k_s − q_min − 3(j1(k_s ℓ) − j1(q_min ℓ))/ℓ],
        // since ∫(1 − j0 + 2j2)dx = x − 3 j1(x).
        let p0 = 2500.0;
        let flat =
            LinearSpectrum::from_fn(&LogGrid::new(1e-5, 10.0, 200).unwrap(), |_| p0).unwrap();
        let q_min = 1e-4;
        let s = sigma2_bao(&flat, q_min);
        let l = BAO_SCALE;
        let exact = p0 / (6.0 * PI * PI)
            * (SIGMA_CUTOFF - q_min - 3.0 * (j1(SIGMA_CUTOFF * l) - j1(q_min * l)) / l);
        // Simpson's error with 2048 intervals in ln q over 7.6 e-folds of an oscillating integrand.
        assert!((s.value / exact - 1.0).abs() < 1e-8, "{} {exact}", s.value);
        assert!(s.error < 1e-6 * exact);
        // For the gm2012 spectrum at z = 0, Σ² is of order 30 (Mpc/h)² (BGIS 2016: Σ ≈ 5.5 Mpc/h).
        let nw = no_wiggle(&LinearSpectrum::gm2012(0.0).unwrap()).unwrap();
        let s = sigma2_bao(&nw, 1e-5).value;
        assert!(s > 20.0 && s < 45.0, "{s}");
    }
}
