//! The 2-loop SPT correction in two infrared-safe parts; mode coupling by randomised quasi-Monte Carlo.
//!
//! P^(2)_XY = 2P15_XY + 2P24_XY + P33_XY (eqs. P15, P24, P33 of the paper), with
//! * 2P15_XY = 15 P(k) ∫∫ (X_5 + Y_5)(k, q₁, −q₁, q₂, −q₂) P₁P₂,
//! * P33red_XY = 9 P(k) ∫X_3(k, q₁, −q₁)P₁ ∫Y_3(k, q₂, −q₂)P₂ = P13_X P13_Y / P(k) (first term of eq. P33),
//! * 2P24_XY = 12 ∫∫ (X_2 Y_4 + Y_2 X_4) P(q₁) P(|k − q₁|) P(q₂), X_2 = X_2^s(q₁, k − q₁),
//!   X_4 = X_4^s(q₁, k − q₁, q₂, −q₂),
//! * P33irr_XY = P33^{2L}_XY = 6 ∫∫ X_3 Y_3 P(q₁)P(q₂)P(q₃), X_3 = X_3^s(q₁, q₂, q₃), q₃ = k − q₁ − q₂,
//!
//! ∫ ≡ ∫d³q/(2π)³. Each term alone has large infrared pieces (∝ k²σ_v² times 1-loop terms, and
//! (k²σ_v²)² P(k)) that cancel in the sum. The sum is regrouped into two infrared-safe parts:
//!
//! P^(2) = [2P15 − P33red] + [2P24 + P33irr + 2 P33red].
//!
//! As q₁ → 0 (or q₂ → 0, or both), 15(X_5 + Y_5) and 9(X_3 Y_3 + Y_3 X_3)/2 have the same limit,
//! since F_n^s(…, q, −q) → −(k·q)²/q⁴ F_{n−2}^s(…)/(n(n − 1)): so 2P15 and P33red have the same infrared
//! pieces and so have, with the opposite sign, 2P24 + P33irr. The propagator part 2P15 − P33red is one
//! deterministic integral of 2K − K₁(r₁)K₁(r₂) on the P15 angular table (`P15Table::propagator_part`;
//! its 1/r² pieces cancel at each node); the mode-coupling part is
//! integrated here as one function, 2P24 + P33irr + 2·[9P(k)X_3(k, q₁, −q₁)Y_3(k, q₂, −q₂)P₁P₂],
//! in which the leading singularities cancel point by point. This needs no 5th-order kernel per point.
//!
//! Following Carrasco, Foreman, Green & Senatore (2014) and Blas, Garny & Konstandin (2013), the
//! mode-coupling integrands are mapped so that every infrared singularity sits at q₁ → 0 or q₂ → 0:
//! P24 is restricted to |k − q₁| > q₁ (×2, the q₁ ↔ k − q₁ symmetry), P33irr to q₃ > q₁, q₂ (×3, its
//! permutation symmetry), with smooth partitions of unity, and the sum is symmetrised in q₁ ↔ q₂.
//!
//! Integration: (ln q₁, ln q₂) on [ln q_min, ln q_max]², q̂₁ = (s₁, 0, x₁) and
//! q̂₂ = (s₂ cos φ, s₂ sin φ, x₂) about k̂ with x₁, x₂ ∈ [−1, 1], φ ∈ [0, π] (reflection symmetry), by a
//! Sobol sequence (Joe–Kuo direction numbers, the `sobol` crate) in R independent Cranley–Patterson
//! random shifts, each point taken with its four images q_i → ±q_i (antithetic: odd parts of the integrand
//! cancel exactly). The radial variables are drawn with density ∝ 1/(w² + (ln q − c)²), centred on q = k
//! at low k and on q ≈ k/2.7 at k ≥ 0.2 (`radial_density`), and the cosines x_i with a density that rises
//! towards |x| = 1 (half uniform, half arcsine): at high k the variance comes from q₁, q₂ ~ k/3 nearly
//! parallel to k, where P24 and P33irr are large and cancel in part. The value is the mean over the
//! shifts and the error is their standard error. Every k uses the same points, so results are
//! reproducible and smooth in k.
//!
//! Accuracy (default settings: 8 shifts × 2^14 points at k = 0.16 h/Mpc, scaled ∝ k^3.5 from ½ to 32
//! times, × 4 images; z = 0; the README has the table): the error of the 2-loop correction is ≤ 2e-4 of
//! it for k ≤ 0.05 h/Mpc, ≤ 6e-4 for k ≤ 0.12 and ≤ 1e-3 up to k = 0.36 for δδ, and up to 0.4 for δθ
//! and θθ. With a tolerance ([`two_loop_refined`], 1e-3 through `add_two_loop`) the points of any k
//! whose correction misses it are increased until it does: on 40 log-spaced k in [0.005, 0.4] only δδ
//! at k = 0.4 (1.1e-3 → 6.6e-4 with 1.3× its points), whose correction (−114 (Mpc/h)³) is a 0.7%
//! remainder of terms of ±1.7e4. Independent randomisations differ by 0.9–1.2σ rms (≤ 3σ over 120
//! values).
//!
//! The kernels of the four images are evaluated together in four SIMD lanes
//! ([`pt_kernels::mode_coupling_3_x4`], [`pt_kernels::mode_coupling_4_x4`]).
//!
//! The same points also give 2P24 and P33irr separately (needed by 2-loop RPT, whose mode-coupling term is
//! P33^{2L}); those carry larger errors, since their infrared pieces do not cancel.

use super::lattice::Lattice;
use super::mode_coupling::{Sampled, Sampler, ACC};
use super::Estimate;
use crate::linear::LinearSpectrum;
use rayon::prelude::*;
use sobol::params::JoeKuoD6;
use sobol::Sobol;
use std::f64::consts::PI;
use std::sync::atomic::{AtomicUsize, Ordering};

/// Settings of the 2-loop integration.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TwoLoopSettings {
    /// Sobol points per random shift at k = 0.16 h/Mpc, scaled ∝ k^3.5:
    /// `points` × 2^round(3.5 log2(k/0.16)), between ½ and 32 times `points` (before any refinement,
    /// see [`two_loop_refined`]).
    pub points: usize,
    /// Number of independent random shifts (the error is their standard error).
    pub replicas: usize,
    /// Seed of the random shifts.
    pub seed: u64,
    /// Width w in ln q of the radial sampling density ∝ 1/(w² + ln²(q/k)) at k ≤ 0.05 h/Mpc (it narrows
    /// and moves to q < k at higher k, see `radial_density`). Default 2.
    pub radial_width: f64,
    /// Target relative error of the 2-loop correction of each pair, reached by adding points where it is
    /// missed ([`two_loop_refined`]); 0 (the default here) keeps the points fixed. `add_two_loop` sets
    /// it from [`Precision::two_loop_tolerance`](crate::precision::Precision::two_loop_tolerance).
    pub tolerance: f64,
}

impl Default for TwoLoopSettings {
    fn default() -> Self {
        Self {
            points: 1 << 14,
            replicas: 8,
            seed: 2,
            radial_width: 2.0,
            tolerance: 0.0,
        }
    }
}

/// The 2-loop mode-coupling terms of one pair at each k [(Mpc/h)^3].
#[derive(Debug, Clone, Default, PartialEq)]
pub struct TwoLoopPair {
    /// The infrared-safe mode-coupling part 2P24 + P33irr + 2P33red (module docs): the 2-loop SPT
    /// correction is 2P15 − P33red plus this.
    pub ir_safe: Vec<Estimate>,
    /// P24 (the correction contains 2 P24).
    pub p24: Vec<Estimate>,
    /// P33irr = P33^{2L}, the mode-coupling part of P33.
    pub p33_2l: Vec<Estimate>,
    /// 2P24 + P33irr from one integrand.
    pub mode_coupling: Vec<Estimate>,
}

/// The 2-loop terms of δδ, δθ, θθ on a k grid.
#[derive(Debug, Clone, PartialEq)]
pub struct TwoLoopTerms {
    /// Wavenumbers [h/Mpc].
    pub k: Vec<f64>,
    /// δδ, δθ, θθ.
    pub pairs: [TwoLoopPair; 3],
    /// Sobol points per random shift used at each k (after any refinement).
    pub points: Vec<usize>,
}

/// The Sobol points used at k: `points` × 2^round(3.5 log2(k/0.16)) (∝ k^3.5), between ½ and 32 times
/// `points` (½ for k < 0.145, 16 at k ≥ 0.32, 32 at k ≥ 0.39 h/Mpc). The relative error of the
/// correction at fixed points grows steeply with k (at k = 0.4 the δδ correction is a 0.7% remainder of
/// its terms); at k ≲ 0.14 h/Mpc half of the points already give ≲ 6e-4. On 40 log-spaced k over
/// [0.005, 0.4] the total cost is that of 2.3 × `points` at every k.
pub(crate) fn points_at(k: f64, points: usize) -> usize {
    let power = (3.5 * (k / 0.16).log2()).round().clamp(-1.0, 5.0) as i32;
    if power >= 0 {
        points << power
    } else {
        (points >> (-power)).max(1)
    }
}

/// Number of quantities per k: [IR-safe part, 2P24, P33irr, 2P24 + P33irr] × [δδ, δθ, θθ] (the
/// last three from the middle six).
pub(crate) const VALUES: usize = 12;

/// The 2-loop terms of `spectrum` at `k` [h/Mpc], over q ∈ `q_range` (P̃ on a lattice of step
/// `lattice_step` in ln q), in parallel over k and random shifts.
pub fn two_loop(
    k: &[f64],
    spectrum: &LinearSpectrum,
    q_range: (f64, f64),
    lattice_step: f64,
    settings: &TwoLoopSettings,
) -> TwoLoopTerms {
    two_loop_with_progress(k, spectrum, q_range, lattice_step, settings, &|_, _| {})
}

/// [`two_loop`], calling `progress(done, total)` with the points integrated so far (all k and shifts).
pub fn two_loop_with_progress(
    k: &[f64],
    spectrum: &LinearSpectrum,
    q_range: (f64, f64),
    lattice_step: f64,
    settings: &TwoLoopSettings,
    progress: &(dyn Fn(usize, usize) + Sync),
) -> TwoLoopTerms {
    let offsets = vec![[Estimate::default(); 3]; k.len()];
    two_loop_refined(
        k,
        spectrum,
        q_range,
        lattice_step,
        settings,
        &offsets,
        progress,
    )
}

/// The D-dimensional Sobol sequence (Joe–Kuo direction numbers) whose prefixes every k takes, without
/// its first point (the origin): D = 5 here, 6 in redshift space (the line-of-sight azimuth).
pub(crate) fn sobol_sequence<const D: usize>() -> impl Iterator<Item = [f64; D]> {
    Sobol::<f64>::new(D, &JoeKuoD6::standard())
        .skip(1)
        .map(|p| std::array::from_fn(|d| p[d]))
}

/// The Cranley–Patterson random shifts of the replicas (ChaCha8 from `settings.seed`).
pub(crate) fn random_shifts<const D: usize>(settings: &TwoLoopSettings) -> Vec<[f64; D]> {
    use rand::{Rng, SeedableRng};
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(settings.seed);
    (0..settings.replicas)
        .map(|_| std::array::from_fn(|_| rng.gen::<f64>()))
        .collect()
}

/// Refinement stops at this many times the initial points of a k (`points` × 2^round(3.5 log2(k/0.16)),
/// between ½ and 32 times `points`, see [`TwoLoopSettings::points`]).
pub const REFINE_LIMIT: usize = 4;

/// Assumed convergence rate of the error, ∝ points^−α, when refinement predicts the points needed
/// (measured: α = 0.6–1).
const RATE: f64 = 0.75;

/// The points per shift at which the error `ratio` × tolerance is predicted to fall to 0.9 × the
/// tolerance from `points` (error ∝ points^−[`RATE`]): between 1.25 and 4 times as many, a multiple of
/// min(2^12, points/4), at most `limit`.
fn refined_points(points: usize, ratio: f64, limit: usize) -> usize {
    let factor = (ratio / 0.9).powf(1.0 / RATE).clamp(1.25, 4.0);
    let chunk = (points / 4).clamp(1, 1 << 12);
    ((points as f64 * factor / chunk as f64).ceil() as usize * chunk).min(limit)
}

/// [`two_loop_with_progress`], refined to `settings.tolerance`: the whole 2-loop correction of pair j
/// at k_i is taken to be `offsets[i][j]` (the propagator part 2P15 − P33red, computed elsewhere) plus
/// the infrared-safe part integrated here, errors added. While its error exceeds
/// `settings.tolerance` × |correction| for some pair, the points of that k are increased (to where
/// error ∝ points^−0.75 predicts 0.9 × the tolerance, by 1.25 to 4 times per round; the Sobol sequence
/// is continued, so earlier points are kept) up to [`REFINE_LIMIT`] times their initial number; beyond
/// it the error stays as estimated (e.g. where the correction crosses zero). After a refinement the
/// error reported is at least the previous round's error scaled by (points before/after)^0.75, so
/// that stopping at the first estimate below the tolerance does not favour estimates that came out low.
/// A tolerance of 0 keeps the initial points. `progress(done, total)` reports the points so far;
/// `total` grows with each refinement. [`TwoLoopTerms::points`] gives the points used.
///
/// # Panics
/// If `offsets` does not have one row per k.
pub fn two_loop_refined(
    k: &[f64],
    spectrum: &LinearSpectrum,
    q_range: (f64, f64),
    lattice_step: f64,
    settings: &TwoLoopSettings,
    offsets: &[[Estimate; 3]],
    progress: &(dyn Fn(usize, usize) + Sync),
) -> TwoLoopTerms {
    assert_eq!(offsets.len(), k.len(), "one offset row per k");
    let lattice = Lattice::new(q_range.0, q_range.1, lattice_step);
    let samples = lattice.sample(spectrum);
    let sampled = Sampled {
        lattice: &lattice,
        samples: &samples,
    };
    // Every k takes a prefix of the same sequence, continued as refinement needs.
    let mut sequence = sobol_sequence();
    let mut points: Vec<[f64; 5]> = Vec::new();
    let shifts = random_shifts(settings);
    let ln_range = (q_range.0.ln(), q_range.1.ln());
    let replica_sum = |k: f64, shift: &[f64; 5], points: &[[f64; 5]]| {
        shifted_sum(k, shift, points, &sampled, ln_range, settings.radial_width)
    };
    let replicas = shifts.len();
    let mut target: Vec<usize> = k.iter().map(|&k| points_at(k, settings.points)).collect();
    let limit: Vec<usize> = target.iter().map(|&n| REFINE_LIMIT * n).collect();
    let mut done_points = vec![0; k.len()];
    let mut sums = vec![[0.0; ACC]; k.len() * replicas];
    let mut rows = vec![[Estimate::default(); VALUES]; k.len()];
    let mut total = 0;
    let done = AtomicUsize::new(0);
    loop {
        // Continue the sequence to the longest target, then integrate the new points of every
        // (k, shift) that needs them: one parallel job each, since the points per k differ by up to
        // 32 times and jobs per k alone would leave cores idle at the end.
        let longest = target.iter().copied().max().unwrap_or(0);
        if longest > points.len() {
            let more = longest - points.len();
            points.extend(sequence.by_ref().take(more));
        }
        let jobs: Vec<usize> = (0..k.len() * replicas)
            .filter(|&job| target[job / replicas] > done_points[job / replicas])
            .collect();
        if jobs.is_empty() {
            break;
        }
        total += jobs
            .iter()
            .map(|&job| target[job / replicas] - done_points[job / replicas])
            .sum::<usize>();
        let new: Vec<[f64; ACC]> = jobs
            .par_iter()
            .map(|&job| {
                let i = job / replicas;
                let range = done_points[i]..target[i];
                let n = range.len();
                let sum = replica_sum(k[i], &shifts[job % replicas], &points[range]);
                progress(done.fetch_add(n, Ordering::Relaxed) + n, total);
                sum
            })
            .collect();
        for (&job, sum) in jobs.iter().zip(new) {
            for (a, b) in sums[job].iter_mut().zip(sum) {
                *a += b;
            }
        }
        for (i, row) in rows.iter_mut().enumerate() {
            if target[i] == done_points[i] {
                continue;
            }
            let mut new = estimates(&sums[i * replicas..(i + 1) * replicas], target[i]);
            // After a refinement the error is at least what the previous round's predicts for the
            // new points: stopping as soon as the estimate dips below the tolerance would otherwise
            // favour estimates that came out low.
            if done_points[i] > 0 {
                let scale = (done_points[i] as f64 / target[i] as f64).powf(RATE);
                for (e, previous) in new.iter_mut().zip(row.iter()) {
                    e.error = e.error.max(previous.error * scale);
                }
            }
            *row = new;
        }
        done_points.clone_from(&target);
        if settings.tolerance <= 0.0 {
            break;
        }
        for (i, points) in target.iter_mut().enumerate() {
            let ratio = worst_ratio(&rows[i], &offsets[i], settings.tolerance);
            if ratio > 1.0 {
                *points = refined_points(*points, ratio, limit[i]);
            }
        }
    }
    TwoLoopTerms::from_rows(k, &rows, done_points)
}

impl TwoLoopTerms {
    /// The terms from one row of [`VALUES`] estimates per k.
    pub(crate) fn from_rows(k: &[f64], rows: &[[Estimate; VALUES]], points: Vec<usize>) -> Self {
        let pair = |j: usize| TwoLoopPair {
            ir_safe: rows.iter().map(|r| r[j]).collect(),
            p24: rows
                .iter()
                .map(|r| Estimate::new(0.5 * r[3 + j].value, 0.5 * r[3 + j].error))
                .collect(),
            p33_2l: rows.iter().map(|r| r[6 + j]).collect(),
            mode_coupling: rows.iter().map(|r| r[9 + j]).collect(),
        };
        Self {
            k: k.to_vec(),
            pairs: [pair(0), pair(1), pair(2)],
            points,
        }
    }
}

/// The sum of the integrand (times the radial and cosine Jacobians) at k over `points` moved by one
/// random `shift` (Cranley–Patterson, mod 1), on ln q ∈ `ln_range`.
fn shifted_sum(
    k: f64,
    shift: &[f64; 5],
    points: &[[f64; 5]],
    sampled: &Sampled,
    ln_range: (f64, f64),
    radial_width: f64,
) -> [f64; ACC] {
    let sampler = Sampler::new(k, ln_range, radial_width);
    let mut acc = [0.0; ACC];
    for point in points {
        let point = sampler.point(point, shift);
        let v = sampled.integrand(k, &point);
        for (a, b) in acc.iter_mut().zip(v) {
            *a += point.jacobian * b;
        }
    }
    acc
}

/// The largest error of the three pairs' corrections (offset + `row`, errors added) in units of
/// `tolerance` × |correction|: above 1, the k needs more points.
fn worst_ratio(row: &[Estimate; VALUES], offsets: &[Estimate; 3], tolerance: f64) -> f64 {
    (0..3)
        .map(|j| {
            let (offset, part) = (offsets[j], row[j]);
            (offset.error + part.error) / (tolerance * (offset.value + part.value).abs())
        })
        .fold(0.0, f64::max)
}

/// The mean over the shifts of their integrals, each the sum of `points` integrand values times the
/// volume of (x₁, x₂, φ) over the points (the radial Jacobians are in the sums), and its standard error;
/// the [`VALUES`] quantities from the [`ACC`] accumulated ones.
fn estimates(sums: &[[f64; ACC]], points: usize) -> [Estimate; VALUES] {
    // Volume of (x₁, x₂, φ): 2 · 2 · π.
    let scale = integral_scale(points);
    let integrals: Vec<[f64; ACC]> = sums.iter().map(|m| m.map(|v| v * scale)).collect();
    replica_estimates(&integrals)
}

/// The factor from a sum over `points` (with the radial Jacobians) to the integral: the volume of
/// (x₁, x₂, φ), 2 · 2 · π, over the points.
pub(crate) fn integral_scale(points: usize) -> f64 {
    4.0 * PI / points as f64
}

/// The mean over the replicas of their integrals and its standard error, for the [`VALUES`]
/// quantities from the [`ACC`] accumulated ones.
pub(crate) fn replica_estimates(integrals: &[[f64; ACC]]) -> [Estimate; VALUES] {
    let r = integrals.len() as f64;
    let value = |m: &[f64; ACC], v: usize| {
        if v < ACC {
            m[v]
        } else {
            m[v - 6] + m[v - 3]
        }
    };
    std::array::from_fn(|v| {
        let mean = integrals.iter().map(|m| value(m, v)).sum::<f64>() / r;
        let var = integrals
            .iter()
            .map(|m| (value(m, v) - mean).powi(2))
            .sum::<f64>()
            / (r - 1.0).max(1.0);
        Estimate::new(mean, (var / r).sqrt())
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn refined_points_follow_the_assumed_rate_within_their_bounds() {
        let n = 1 << 16;
        // Error 0.9 · 2^0.75 × the tolerance: error ∝ N^−0.75 reaches 0.9 × the tolerance at 2N
        // (up to one rounding chunk of 2^12).
        let twice = refined_points(n, 0.9 * 2f64.powf(RATE), usize::MAX);
        assert!((2 * n..=2 * n + (1 << 12)).contains(&twice), "{twice}");
        // Just above the tolerance: at least 1.25 times; far above: at most 4 times, and the limit.
        assert_eq!(refined_points(n, 0.901, usize::MAX), n + n / 4);
        assert_eq!(refined_points(n, 100.0, usize::MAX), 4 * n);
        assert_eq!(refined_points(n, 100.0, 3 * n), 3 * n);
        // Small counts round to a quarter of the points.
        assert_eq!(refined_points(512, 0.901, usize::MAX), 640);
    }

    #[test]
    fn worst_ratio_is_the_largest_error_of_the_whole_corrections_over_the_tolerance() {
        let mut row = [Estimate::default(); VALUES];
        row[0] = Estimate::new(10.0, 0.01);
        row[1] = Estimate::new(-4.0, 0.002);
        row[2] = Estimate::new(1.0, 0.001);
        let offsets = [
            Estimate::new(90.0, 0.0),
            Estimate::new(-6.0, 0.008),
            Estimate::new(1.0, 0.0),
        ];
        // Relative errors 0.01/100, 0.01/10, 0.001/2: the δθ pair sets it, 1e-3 / 1e-3.
        let r = worst_ratio(&row, &offsets, 1e-3);
        assert!((r - 1.0).abs() < 1e-12, "{r}");
    }
}
