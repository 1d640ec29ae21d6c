//! The 3-loop propagator term P17 from a cosmology-independent angular table (for the propagator N3).
//!
//! P17_X(k) = 105 P(k) ∫d³q₁d³q₂d³q₃/(2π)⁹ X_7^s(k, q₁, −q₁, q₂, −q₂, q₃, −q₃) P(q₁)P(q₂)P(q₃) (eq. P_1n
//! with 7!! = 105), so with r_i = q_i/k and K_X(r₁, r₂, r₃) = 105⟨X_7^s⟩ over the three directions,
//! P17_X/P(k) = (k⁹/8π⁶) ∫∫∫ dr₁dr₂dr₃ r₁²r₂²r₃² K_X P(kr₁)P(kr₂)P(kr₃). P17_δθ = (P17_δδ + P17_θθ)/2.
//!
//! **Angular table.** The average over the five angles (x_i = k̂·q̂_i, traded for p_i = |k̂ − r_i q̂_i| as in
//! P15 and restricted to x_i ≥ 0 by the q_i → −q_i symmetry, and the azimuths φ₂, φ₃ of q₂, q₃ about k
//! relative to q₁) is a randomised quasi-Monte-Carlo integral: [`ANGULAR_POINTS`] Sobol points in each of
//! four random shifts, tent-transformed; the value is their mean and the error their standard error. The kernel is
//! symmetric in (r₁, r₂, r₃), so the radial rule covers r₃ ≤ r₂ ≤ r₁ (×6) in u = ln r ∈ [ln [`R_MIN`],
//! ln [`R_MAX`]] with Gauss–Legendre panels split at r = 1. The table holds K at every node; it is built
//! once (under 2 minutes on 2 cores, with progress; the four shifts of each point run in the four
//! lanes of [`pt_kernels::propagator_7_x4`]) and cached like the P15 table
//! ([`TableStore`](crate::store::TableStore)). The UV beyond R_MAX·k is dropped (P17 matters only where N3 differs from N2,
//! k ≳ 0.05 h/Mpc, for which q > 50 h/Mpc carries no power).
//!
//! Limits (tests): K_F → K₁(r₁)K₁(r₂)K₁(r₃)/6 for r_i ≪ 1, so that 6P17/P → (P13/P)³ and N3 → N1 for
//! factorised kernels.

use super::lattice::Lattice;
use super::p15::edges_with;
use super::Estimate;
use crate::integrate::GaussLegendre;
use crate::linear::LinearSpectrum;
use rayon::prelude::*;
use sobol::params::JoeKuoD6;
use sobol::Sobol;
use std::f64::consts::PI;
use std::sync::OnceLock;

/// Smallest r = q/k of the radial rule.
pub const R_MIN: f64 = 1e-4;
/// Largest r = q/k of the radial rule.
pub const R_MAX: f64 = 1e3;
/// Sobol points per random shift of the angular integrals.
pub const ANGULAR_POINTS: usize = 256;
/// Random shifts of the angular integrals (the error is their standard error); four, one per lane of
/// [`pt_kernels::propagator_7_x4`].
const SHIFTS: usize = 4;
/// Gauss–Legendre order per radial panel.
const RADIAL_ORDER: usize = 4;
/// Version of the table layout and rules, part of the cache file name.
const TABLE_VERSION: u32 = 1;

/// Largest radial panel width in u = ln r at u: 0.35 near r ~ 1, growing to 1.5 in the tails.
fn width(u: f64) -> f64 {
    (0.35 * (1.0 + 0.6 * (u.abs() - 1.5).max(0.0))).min(1.5)
}

/// Sobol points of the angular rule, and its random shifts.
type AngularRule = (Vec<[f64; 5]>, [[f64; 5]; SHIFTS]);

/// The Sobol points of the angular rule and the random shifts (fixed: the table is deterministic).
fn angular_points() -> &'static AngularRule {
    static POINTS: OnceLock<AngularRule> = OnceLock::new();
    POINTS.get_or_init(|| {
        let points = Sobol::<f64>::new(5, &JoeKuoD6::standard())
            .skip(1)
            .take(ANGULAR_POINTS)
            .map(|p| std::array::from_fn(|d| p[d]))
            .collect();
        use rand::{Rng, SeedableRng};
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(17);
        let shifts = [(); SHIFTS].map(|()| std::array::from_fn(|_| rng.gen::<f64>()));
        (points, shifts)
    })
}

/// [K_F, K_G](r₁, r₂, r₃) = 105⟨[F, G]_7^s(k, ±q₁, ±q₂, ±q₃)⟩ and their errors (randomised QMC).
pub fn p17_angular_kernel(r: [f64; 3]) -> [Estimate; 2] {
    let (points, shifts) = angular_points();
    let ranges = r.map(|r| ((1.0 - r).abs(), (1.0 + r * r).sqrt()));
    // The four shifts of each point are evaluated together, one per lane of the kernel.
    let mut sums = [[0.0; 2]; SHIFTS];
    for point in points {
        let configurations = shifts.map(|shift| {
            // Random shift, then the tent transform 1 − |2t − 1|, which makes the shifted rule
            // converge like a symmetric one on non-periodic integrands.
            let t: [f64; 5] =
                std::array::from_fn(|d| 1.0 - (2.0 * (point[d] + shift[d]).fract() - 1.0).abs());
            let mut dirs = [[0.0; 3]; 3];
            let mut jacobian = 1.0;
            for i in 0..3 {
                let (a, b) = ranges[i];
                let p = a + (b - a) * t[i];
                let x = ((1.0 + r[i] * r[i] - p * p) / (2.0 * r[i])).clamp(-1.0, 1.0);
                let s = (1.0 - x * x).sqrt();
                // dx = p dp / r over x ∈ [0, 1]: the average over x is ∫ dx.
                jacobian *= (b - a) * p / r[i];
                let phi = if i == 0 { 0.0 } else { 2.0 * PI * t[2 + i] };
                dirs[i] = [r[i] * s * phi.cos(), r[i] * s * phi.sin(), r[i] * x];
            }
            use crate::vec3::dot;
            let [q1, q2, q3] = &dirs;
            let gram = [
                1.0,
                q1[2],
                q2[2],
                q3[2],
                dot(q1, q1),
                dot(q1, q2),
                dot(q1, q3),
                dot(q2, q2),
                dot(q2, q3),
                dot(q3, q3),
            ];
            (gram, jacobian)
        });
        let kernels = pt_kernels::propagator_7_x4(&configurations.map(|(gram, _)| gram));
        for ((sum, [f, g]), (_, jacobian)) in sums.iter_mut().zip(kernels).zip(configurations) {
            sum[0] += jacobian * f;
            sum[1] += jacobian * g;
        }
    }
    let estimates = sums.map(|acc| acc.map(|a| 105.0 * a / points.len() as f64));
    std::array::from_fn(|x| {
        let n = SHIFTS as f64;
        let mean = estimates.iter().map(|e| e[x]).sum::<f64>() / n;
        let var = estimates.iter().map(|e| (e[x] - mean).powi(2)).sum::<f64>() / (n - 1.0);
        Estimate::new(mean, (var / n).sqrt())
    })
}

/// A node of the radial rule on r₃ ≤ r₂ ≤ r₁: u_i = ln r_i and the weight of 6 r₁³r₂³r₃³ du₁du₂du₃.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Node {
    u: [f64; 3],
    w: f64,
}

fn radial_rule() -> Vec<Node> {
    let rule = GaussLegendre::new(RADIAL_ORDER);
    let (lo, hi) = (R_MIN.ln(), R_MAX.ln());
    let mut nodes = Vec::new();
    for e1 in edges_with(lo, hi, &[0.0], width).windows(2) {
        for (u1, w1) in rule.on(e1[0], e1[1]) {
            for e2 in edges_with(lo, u1, &[0.0], width).windows(2) {
                for (u2, w2) in rule.on(e2[0], e2[1]) {
                    for e3 in edges_with(lo, u2, &[0.0], width).windows(2) {
                        for (u3, w3) in rule.on(e3[0], e3[1]) {
                            let w = 6.0 * w1 * w2 * w3 * (3.0 * (u1 + u2 + u3)).exp();
                            nodes.push(Node { u: [u1, u2, u3], w });
                        }
                    }
                }
            }
        }
    }
    nodes
}

/// The P17 table: K_F, K_G (with errors) at every node of the radial rule.
#[derive(Debug, Clone, PartialEq)]
pub struct P17Table {
    nodes: Vec<Node>,
    kernels: Vec<[Estimate; 2]>,
}

impl P17Table {
    /// The memory the angular table holds \[bytes\] (a plan that uses it counts it once).
    pub const MEMORY: f64 = 6e6;
}

impl P17Table {
    /// The table's file name in a [`TableStore`](crate::store::TableStore) directory.
    pub fn file_name() -> String {
        format!("p17-v{TABLE_VERSION}-a{ANGULAR_POINTS}-r{RADIAL_ORDER}.bin")
    }
}

impl P17Table {
    /// Number of radial nodes.
    pub fn len(&self) -> usize {
        self.nodes.len()
    }

    /// Whether the table is empty (never, for a built table).
    pub fn is_empty(&self) -> bool {
        self.nodes.is_empty()
    }

    /// The table as the values of its file (see [`TableStore`](crate::store::TableStore)).
    pub(crate) fn to_f64s(&self) -> Vec<f64> {
        self.kernels
            .iter()
            .flat_map(|k| [k[0].value, k[0].error, k[1].value, k[1].error])
            .collect()
    }

    /// Builds the table (in parallel).
    pub fn build(progress: &(dyn Fn(usize, usize) + Sync)) -> Self {
        let nodes = radial_rule();
        let total = nodes.len();
        let done = std::sync::atomic::AtomicUsize::new(0);
        let kernels = nodes
            .par_iter()
            .map(|n| {
                let k = p17_angular_kernel(n.u.map(f64::exp));
                let d = done.fetch_add(1, std::sync::atomic::Ordering::Relaxed) + 1;
                if d.is_multiple_of(512) || d == total {
                    progress(d, total);
                }
                k
            })
            .collect();
        Self { nodes, kernels }
    }

    /// The table from the values of its file, or `None` if they do not fit the rule or a few
    /// recomputed entries differ (a stale or corrupted file).
    pub(crate) fn from_f64s(values: &[f64]) -> Option<Self> {
        let nodes = radial_rule();
        if values.len() != 4 * nodes.len() || values.iter().any(|v| !v.is_finite()) {
            return None;
        }
        let kernels: Vec<[Estimate; 2]> = values
            .chunks_exact(4)
            .map(|v| [Estimate::new(v[0], v[1]), Estimate::new(v[2], v[3])])
            .collect();
        // A stale file is caught by recomputing a few entries.
        for i in [0, nodes.len() / 2, nodes.len() - 1] {
            let k = p17_angular_kernel(nodes[i].u.map(f64::exp));
            if (0..2).any(|x| k[x].value != kernels[i][x].value) {
                return None;
            }
        }
        Some(Self { nodes, kernels })
    }

    /// [P17_δδ, P17_δθ, P17_θθ] at each k [(Mpc/h)^3] over q ∈ `q_range` (P̃ on a lattice of step
    /// `lattice_step` in ln q), with errors from the angular integrals (in parallel over k).
    pub fn evaluate(
        &self,
        k: &[f64],
        spectrum: &LinearSpectrum,
        q_range: (f64, f64),
        lattice_step: f64,
    ) -> Vec<[Estimate; 3]> {
        let lattice = Lattice::new(q_range.0, q_range.1, lattice_step);
        let samples = lattice.sample(spectrum);
        let p_at = |x: f64| lattice.at_ln_or_zero(&samples, x);
        k.par_iter()
            .map(|&k| {
                let ln_k = k.ln();
                let (mut value, mut error) = ([0.0; 2], [0.0; 2]);
                for (n, kern) in self.nodes.iter().zip(&self.kernels) {
                    let ppp = n.w * n.u.iter().map(|&u| p_at(ln_k + u)).product::<f64>();
                    for x in 0..2 {
                        value[x] += ppp * kern[x].value;
                        error[x] += (ppp * kern[x].error).abs();
                    }
                }
                let norm = k.powi(9) / (8.0 * PI.powi(6)) * spectrum.eval(k);
                let e = |x: usize| Estimate::new(norm * value[x], norm.abs() * error[x]);
                let (dd, tt) = (e(0), e(1));
                [dd, Estimate::mean(dd, tt), tt]
            })
            .collect()
    }
}
