//! The integrand of the 2-loop redshift-space terms at one sample point, as third legs whose
//! coefficients do not depend on the spectrum ([`PointLegs`]), and the sampling ([`Sampling`]) that
//! the direct integral and the basis tensors share, so that both see the same points.

use super::zn::{product, FPoly, SubsetKernels};
use super::{mu2_nodes, NodeIntegrals, MU_NODES};
use crate::loops::mode_coupling::{Point, Sampled, Sampler};
use crate::loops::two_loop::{points_at, random_shifts, sobol_sequence};
use crate::loops::TwoLoopSettings;
use crate::vec3::{neg, norm2, sub};
use std::f64::consts::PI;

/// The points, shifts and maps of one integration on a k grid.
pub(crate) struct Sampling {
    /// Sobol points per shift at each k.
    pub counts: Vec<usize>,
    /// The Sobol points (ln q₁, ln q₂, x₁, x₂, φ, φ_n; the longest k's prefix).
    pub points: Vec<[f64; 6]>,
    /// The Cranley–Patterson shifts of the replicas.
    pub shifts: Vec<[f64; 6]>,
    nodes: [(f64, f64); MU_NODES],
    ln_range: (f64, f64),
    radial_width: f64,
}

/// Points per shift at `k` for the redshift-space terms: the real-space rule ([`points_at`]), but
/// never fewer than twice `points` (it halves them at k ≲ 0.13 and keeps them to 0.2). At low k the
/// redshift-space integrand has rare large contributions that fewer points miss: with the
/// real-space rule the default precision's 2-loop multipoles at k ≤ 0.1 (2^11 points per shift)
/// came out 0.7–0.9% smaller in magnitude than cosPT's (an independent code, `tests/tests/suite/cospt.rs`) and
/// than with 4 times the points, beyond their errors; with twice `points` (2^13) they agree.
pub(crate) fn rsd_points_at(k: f64, points: usize) -> usize {
    points_at(k, points).max(rsd_min_points(points))
}

/// The fewest points per shift [`rsd_points_at`] gives at any k: twice `points`.
pub(crate) fn rsd_min_points(points: usize) -> usize {
    2 * points
}

impl Sampling {
    /// The sampling of `settings` on `k` over q ∈ `q_range`.
    pub fn new(k: &[f64], q_range: (f64, f64), settings: &TwoLoopSettings) -> Self {
        let counts: Vec<usize> = k
            .iter()
            .map(|&k| rsd_points_at(k, settings.points))
            .collect();
        Self {
            points: sobol_sequence()
                .take(counts.iter().copied().max().unwrap_or(0))
                .collect(),
            counts,
            shifts: random_shifts(settings),
            nodes: mu2_nodes().map(|m2| (m2.sqrt(), (1.0 - m2).max(0.0).sqrt())),
            ln_range: (q_range.0.ln(), q_range.1.ln()),
            radial_width: settings.radial_width,
        }
    }

    /// The maps of the propagator and the mode-coupling parts at `k`.
    pub fn samplers(&self, k: f64) -> [Sampler; 2] {
        [
            propagator_sampler(self.ln_range),
            Sampler::new(k, self.ln_range, self.radial_width),
        ]
    }

    /// The integrand's legs at the Sobol point `unit` moved by `shift`, at `k` with the
    /// [`samplers`](Self::samplers) of k: [propagator part, mode-coupling part].
    pub fn legs(
        &self,
        k: f64,
        unit: &[f64; 6],
        shift: &[f64; 6],
        samplers: &[Sampler; 2],
    ) -> [PointLegs; 2] {
        let head: [f64; 5] = std::array::from_fn(|d| shift[d]);
        let point: [f64; 5] = std::array::from_fn(|d| unit[d]);
        let los = lines_of_sight(2.0 * PI * (unit[5] + shift[5]).fract(), &self.nodes);
        [
            propagator_legs(k, &samplers[0].point(&point, &head), &los),
            mode_coupling_legs(k, &samplers[1].point(&point, &head), &los),
        ]
    }
}

/// The line of sight at each node for the azimuth `phi_n`.
fn lines_of_sight(phi_n: f64, nodes: &[(f64, f64); MU_NODES]) -> Los {
    std::array::from_fn(|a| {
        let phi = phi_n + 2.0 * PI * a as f64 / AZIMUTHS as f64;
        let (cos_n, sin_n) = (phi.cos(), phi.sin());
        nodes.map(|(mu, smu)| [smu * cos_n, smu * sin_n, mu])
    })
}

/// Azimuths of the line of sight per point, φ_n + 2πa/A: the f^m part of the integrand is a
/// homogeneous polynomial of degree 2m in n̂, so with the opposite azimuth its terms odd in the
/// transverse components (√(1 − μ²) times odd powers) cancel at every point, and the rest is a
/// polynomial in μ² of degree ≤ m, which the seven nodes hold exactly. Measured (k = 0.05, 0.1,
/// f = 0.7): keeping only the 28 coefficients with one azimuth left the multipoles' errors 1.3–2.2
/// times larger; the second azimuth doubles the kernel assembly (40 k, default precision: 48 s
/// against 25 s) and four gave nothing more.
const AZIMUTHS: usize = 2;

/// The lines of sight of a point: [azimuth][node].
type Los = [[[f64; 3]; MU_NODES]; AZIMUTHS];

/// The integrand at one sample point, linear in each of its three spectra: P(q₁)P(q₂) Σ_t C_t P(z_t)
/// with third legs z_t and coefficients C_t (kernels, partitions, measure and sampling Jacobian) per
/// node in μ² and power of f, none of which depend on the spectrum.
pub(crate) struct PointLegs {
    pub ln_q: [f64; 2],
    /// (ln z_t, C_t).
    pub legs: Vec<(f64, NodeIntegrals)>,
}

impl PointLegs {
    /// Adds the integrand for the spectrum `sampled` to `acc`.
    pub fn add_to(&self, sampled: &Sampled, acc: &mut NodeIntegrals) {
        let p12 = sampled.at_ln(self.ln_q[0]) * sampled.at_ln(self.ln_q[1]);
        if p12 == 0.0 {
            return;
        }
        for (ln_z, coef) in &self.legs {
            let p = sampled.at_ln(*ln_z);
            if p == 0.0 {
                continue;
            }
            for (out, c) in acc.iter_mut().zip(coef) {
                for (o, c) in out.iter_mut().zip(c) {
                    *o += p12 * p * c;
                }
            }
        }
    }
}

/// The vectors k, q₁, q₂ of a point (k along z, q₁ in the xz plane) and the measure
/// d³q₁d³q₂/(2π)⁶ (as the real-space integrand's, with ¼ for the images) times the sampling
/// Jacobian.
fn vectors(k: f64, point: &Point) -> ([[f64; 3]; 3], f64) {
    let q = [point.ln_q[0].exp(), point.ln_q[1].exp()];
    let x = point.x;
    let (s1, s2) = (
        (1.0 - x[0] * x[0]).max(0.0).sqrt(),
        (1.0 - x[1] * x[1]).max(0.0).sqrt(),
    );
    let (c, s) = (
        point.cos_phi,
        (1.0 - point.cos_phi * point.cos_phi).max(0.0).sqrt(),
    );
    let q1 = [q[0] * s1, 0.0, q[0] * x[0]];
    let q2 = [q[1] * s2 * c, q[1] * s2 * s, q[1] * x[1]];
    let measure = 0.25 * (q[0] * q[1]).powi(3) * 4.0 * PI / (2.0 * PI).powi(6) * point.jacobian;
    ([[0.0, 0.0, k], q1, q2], measure)
}

/// c · Z_a Z_b at every node (polynomials in f), from the kernels' values at the nodes.
fn products(c: f64, a: &Kernels, b: &Kernels) -> NodeIntegrals {
    let c = c / AZIMUTHS as f64;
    std::array::from_fn(|j| {
        let mut sum = [0.0; 7];
        for (x, y) in a.iter().zip(b) {
            for (s, v) in sum.iter_mut().zip(product(&x[j], &y[j])) {
                *s += c * v;
            }
        }
        sum
    })
}

/// A kernel at every line of sight of a point: [azimuth][node].
type Kernels = [[FPoly; MU_NODES]; AZIMUTHS];

/// Z of the vectors `args` of `kernels` at every line of sight.
fn at_nodes(kernels: &SubsetKernels, args: usize, los: &Los) -> Kernels {
    los.map(|set| std::array::from_fn(|j| kernels.redshift(args, &set[j])))
}

/// The propagator part 2P15 − P33red at one point (the same in the four images): one leg, z = k.
fn propagator_legs(k: f64, point: &Point, los: &Los) -> PointLegs {
    let ([kv, q1, q2], measure) = vectors(k, point);
    let kernels = SubsetKernels::new(&[kv, q1, neg(q1), q2, neg(q2)]);
    let c = 4.0 * measure;
    let z1 = at_nodes(&kernels, 0b00001, los);
    let z5 = at_nodes(&kernels, 0b11111, los);
    let z3a = at_nodes(&kernels, 0b00111, los);
    let z3b = at_nodes(&kernels, 0b11001, los);
    let mut coef = products(30.0 * c, &z1, &z5);
    for (row, add) in coef.iter_mut().zip(products(-9.0 * c, &z3a, &z3b)) {
        row.iter_mut().zip(add).for_each(|(r, a)| *r += a);
    }
    PointLegs {
        ln_q: point.ln_q,
        legs: vec![(k.ln(), coef)],
    }
}

/// The mode-coupling part 2P24 + P33irr + 2P33red at one point, averaged over the four images:
/// legs z = k (2P33red), |k ∓ q_i| (2P24) and the four q₃ (P33irr).
fn mode_coupling_legs(k: f64, point: &Point, los: &Los) -> PointLegs {
    let ([kv, q1, q2], measure) = vectors(k, point);
    let mut legs = Vec::with_capacity(9);
    // 2P33red: the same in all four images
    let z3a = at_nodes(&SubsetKernels::new(&[kv, q1, neg(q1)]), 0b111, los);
    let z3b = at_nodes(&SubsetKernels::new(&[kv, q2, neg(q2)]), 0b111, los);
    legs.push((k.ln(), products(4.0 * 18.0 * measure, &z3a, &z3b)));
    // 2P24: the half of q₁ (both signs) and of q₂, each with the partition w = p⁴/(q⁴ + p⁴), p = k − q
    for (a, b) in [(q1, q2), (neg(q1), q2), (q2, q1), (neg(q2), q1)] {
        let p = sub(kv, a);
        let (pp, aa) = (norm2(p), norm2(a));
        let w = pp * pp / (aa * aa + pp * pp);
        if w > 1e-12 {
            let kernels = SubsetKernels::new(&[a, p, b, neg(b)]);
            let z2 = at_nodes(&kernels, 0b0011, los);
            let z4 = at_nodes(&kernels, 0b1111, los);
            legs.push((0.5 * pp.ln(), products(48.0 * w * measure, &z2, &z4)));
        }
    }
    // P33irr: the four images, each with the partition w₃ = q₃⁴/(q₁⁴ + q₂⁴ + q₃⁴)
    let (q11, q22) = (norm2(q1), norm2(q2));
    for (a, b) in [(q1, q2), (neg(q1), neg(q2)), (neg(q1), q2), (q1, neg(q2))] {
        let q3 = sub(sub(kv, a), b);
        let q33 = norm2(q3);
        let w3 = q33 * q33 / (q11 * q11 + q22 * q22 + q33 * q33);
        if w3 > 1e-12 {
            let kernels = SubsetKernels::new(&[a, b, q3]);
            let z3 = at_nodes(&kernels, 0b111, los);
            legs.push((0.5 * q33.ln(), products(18.0 * w3 * measure, &z3, &z3)));
        }
    }
    PointLegs {
        ln_q: point.ln_q,
        legs,
    }
}

/// The radial map of the propagator part: 2P15 − P33red gathers q³P(q) · k²/q² from q ≫ k (where
/// the pointwise kernel is O(k²/q²) and only its angular average smaller), so its density is
/// ∝ 1/(w² + ln²(q/c)) with c = [`PROPAGATOR_CENTRE`] and w = [`PROPAGATOR_WIDTH`] at every k: among
/// c ∈ {0.03, 0.1, 0.3, 1} h/Mpc and w ∈ {1.5, 2.5, 4} this gave the smallest variance at k = 0.01,
/// 0.1 and 0.3 h/Mpc (z = 0), 1.5–2.4 times below the mode-coupling map's.
fn propagator_sampler(range: (f64, f64)) -> Sampler {
    Sampler::with_density(PROPAGATOR_CENTRE.ln(), PROPAGATOR_WIDTH, range)
}

/// Centre [h/Mpc] of the radial density of the propagator part.
const PROPAGATOR_CENTRE: f64 = 0.3;
/// Width in ln q of the radial density of the propagator part.
const PROPAGATOR_WIDTH: f64 = 1.5;
