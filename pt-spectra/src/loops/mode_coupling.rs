//! The integrand of the 2-loop mode-coupling integral (see [`super::two_loop`]) at one sample point,
//! written so that it is linear in each of its three spectra.
//!
//! At a point (q₁, q₂, cosines, φ) the integrand is P(q₁)P(q₂) Σ_t c_t P(z_t): nine "third legs" z_t
//! (k for the reducible part, |k ∓ q₁| and |k ∓ q₂| for 2P24, and the four q₃ = |k − q₁ − q₂| of the
//! images for P33irr), each with coefficients c_t (kernels, partitions of unity and the measure) that
//! do not depend on the spectrum. The direct integral ([`Sampled`]) multiplies in the spectrum at once;
//! the basis tensors ([`super::basis`]) accumulate the same coefficients against basis functions, so
//! that both give the same number for the same spectrum.

use super::lattice::Lattice;
use std::f64::consts::PI;

/// Accumulated quantities per point: [IR-safe part, 2P24, P33irr] × [δδ, δθ, θθ].
pub(crate) const ACC: usize = 9;

/// Third legs per point: k, |k ∓ q₁|, |k ∓ q₂|, and q₃ of the four images.
pub(crate) const LEGS: usize = 9;

/// Pair index j: (X, Y) = (F, F), (F, G), (G, G) → kernel indices.
const PAIRS: [(usize, usize); 3] = [(0, 0), (0, 1), (1, 1)];

/// One third leg: ln z (−∞ for a leg of zero weight) and its coefficients for the [`ACC`] quantities.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Leg {
    pub ln_z: f64,
    pub coef: [f64; ACC],
}

const NO_LEG: Leg = Leg {
    ln_z: f64::NEG_INFINITY,
    coef: [0.0; ACC],
};

/// The integrand at one point: P(q₁)P(q₂) Σ_t legs[t].coef P(legs[t].z).
#[derive(Debug, Clone, Copy)]
pub(crate) struct PointLegs {
    pub legs: [Leg; LEGS],
}

/// One sample point of the 5-D integral: ln q_i, the cosines x_i about k̂, cos φ, and the Jacobian of
/// the map from the unit cube (radial and cosine densities).
#[derive(Debug, Clone, Copy)]
pub(crate) struct Point {
    pub ln_q: [f64; 2],
    pub x: [f64; 2],
    pub cos_phi: f64,
    pub jacobian: f64,
}

/// Anchors (k [h/Mpc], centre shift c − ln k, width w) of the radial sampling density at higher k.
const RADIAL_ANCHORS: [(f64, f64, f64); 2] = [(0.1, -0.8, 0.75), (0.2, -1.0, 0.6)];

/// Centre c and width w in ln q of the radial sampling density ∝ 1/(w² + (ln q − c)²) at k: c = ln k
/// and w = `width` for k ≤ 0.05 h/Mpc, then linear in ln k through [`RADIAL_ANCHORS`] to
/// c = ln k − 1 (q ≈ k/2.7) and w = 0.6 at k ≥ 0.2. At high k the variance of the mode coupling comes
/// from q₁, q₂ ~ k/3 (three modes of similar size adding up to k, where P(q) is several times P(k));
/// the narrower density there cuts the errors at k ≥ 0.1 h/Mpc by 2.5–4 for the same points. At low k
/// the broad density is better.
fn radial_density(k: f64, width: f64) -> (f64, f64) {
    let mut from = (0.05, 0.0, width);
    for to in RADIAL_ANCHORS {
        if k < to.0 {
            let s = ((k / from.0).ln() / (to.0 / from.0).ln()).max(0.0);
            return (
                k.ln() + from.1 + s * (to.1 - from.1),
                from.2 + s * (to.2 - from.2),
            );
        }
        from = to;
    }
    (k.ln() + from.1, from.2)
}

/// Weight of the arcsine part of the cosine sampling density (the rest is uniform).
const ARCSINE_WEIGHT: f64 = 0.5;

/// The cosine x ∈ [−1, 1] at u ∈ [0, 1] and the Jacobian dx/du relative to the uniform map (2):
/// x = (1 − a)(2u − 1) + a sin(π(u − ½)), a = [`ARCSINE_WEIGHT`]. Monotonic, and denser towards |x| = 1.
#[inline]
fn cosine(u: f64) -> (f64, f64) {
    let s = PI * (u - 0.5);
    let a = ARCSINE_WEIGHT;
    (
        (1.0 - a) * (2.0 * u - 1.0) + a * s.sin(),
        (2.0 * (1.0 - a) + a * PI * s.cos()) / 2.0,
    )
}

/// The map from the unit cube to the sample points at one k: ln q = c + w tan θ with θ uniform on
/// [θ_lo, θ_hi] (points concentrate within a few w of the centre c, [`radial_density`]; the Jacobian
/// dln q/dt = (θ_hi − θ_lo) w / cos²θ), the cosines by [`cosine`], φ = πt.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Sampler {
    centre: f64,
    width: f64,
    t_lo: f64,
    t_hi: f64,
}

impl Sampler {
    /// The map at `k` [h/Mpc] on ln q ∈ [`lo`, `hi`], with the low-k radial width `radial_width`.
    pub fn new(k: f64, range: (f64, f64), radial_width: f64) -> Self {
        let (centre, width) = radial_density(k, radial_width);
        Self::with_density(centre, width, range)
    }

    /// The map on ln q ∈ [`lo`, `hi`] with the radial density ∝ 1/(w² + (ln q − c)²) of centre c =
    /// `centre` and width w = `width`.
    pub fn with_density(centre: f64, width: f64, (lo, hi): (f64, f64)) -> Self {
        Self {
            centre,
            width,
            t_lo: ((lo - centre) / width).atan(),
            t_hi: ((hi - centre) / width).atan(),
        }
    }

    /// (ln q, dln q/dt) at t.
    #[inline]
    fn radial(&self, t: f64) -> (f64, f64) {
        let (sin, cos) = (self.t_lo + (self.t_hi - self.t_lo) * t).sin_cos();
        (
            self.centre + self.width * sin / cos,
            (self.t_hi - self.t_lo) * self.width / (cos * cos),
        )
    }

    /// The point of the Sobol `point` moved by the random `shift` (Cranley–Patterson, mod 1).
    #[inline]
    pub fn point(&self, point: &[f64; 5], shift: &[f64; 5]) -> Point {
        let t: [f64; 5] = std::array::from_fn(|d| (point[d] + shift[d]).fract());
        let ((l1, j1), (l2, j2)) = (self.radial(t[0]), self.radial(t[1]));
        let ((x1, h1), (x2, h2)) = (cosine(t[2]), cosine(t[3]));
        Point {
            ln_q: [l1, l2],
            x: [x1, x2],
            cos_phi: (PI * t[4]).cos(),
            jacobian: j1 * h1 * j2 * h2,
        }
    }
}

/// The pointwise P33red = 9X_3(k, q₁, −q₁)Y_3(k, q₂, −q₂) (without P(k)P₁P₂, symmetrised in X ↔ Y)
/// for the three pairs, from the Gram matrix [kk, kq₁, kq₂, q₁q₁, q₁q₂, q₂q₂]. Its integral times P(k)
/// is P13_X P13_Y/P.
#[inline]
fn reducible_part(g: &[f64; 6]) -> [f64; 3] {
    let [kk, kq1, kq2, q1q1, _, q2q2] = *g;
    let a3 = pt_kernels::propagator_3(&[kk, kq1, q1q1]);
    let b3 = pt_kernels::propagator_3(&[kk, kq2, q2q2]);
    PAIRS.map(|(x, y)| 9.0 * 0.5 * (a3[x] * b3[y] + a3[y] * b3[x]))
}

/// What the 2P24 piece needs of one momentum q_i with k·q_i = σ kq_i (σ = ±1): ln p of the leg
/// p = |k − q_i|, the smooth partition w = p⁴/(q⁴ + p⁴) of the q_i ↔ k − q_i symmetry (×2 below), and
/// X_2^s(q_i, k − q_i) for X = F, G. `None` where w is negligible.
#[inline]
fn pair_leg(kk: f64, kq: f64, qq: f64) -> Option<(f64, f64, [f64; 2])> {
    let pp = (kk - 2.0 * kq + qq).max(0.0);
    let w = pp * pp / (qq * qq + pp * pp);
    (w > 1e-12).then(|| (0.5 * pp.ln(), w, pt_kernels::mode_coupling_2(&[kk, kq, qq])))
}

/// The 2P24 leg of one momentum ([`pair_leg`]) with m4 = X_4^s(q₁, k − q₁, q₂, −q₂), `scale` times
/// 24(X_2Y_4 + Y_2X_4)w for the three pairs, in the IR-safe and the 2P24 quantities.
#[inline]
fn p24_leg(leg: Option<(f64, f64, [f64; 2])>, m4: [f64; 2], scale: f64) -> Leg {
    let Some((ln_z, w, m2)) = leg else {
        return NO_LEG;
    };
    let mut coef = [0.0; ACC];
    for (j, &(x, y)) in PAIRS.iter().enumerate() {
        let c = scale * 24.0 * (m2[x] * m4[y] + m2[y] * m4[x]) * w;
        coef[j] = c;
        coef[3 + j] = c;
    }
    Leg { ln_z, coef }
}

/// The integrand at one point (ln q_i, cosines x_i about k̂, cos φ), averaged over its four images
/// q_i → ±q_i (antithetic: odd parts cancel exactly), times the measure (without the sampling
/// Jacobian), as third legs ([`PointLegs`]).
///
/// The images are (x₁, x₂, cos φ) → (x₁, x₂, c), (−x₁, −x₂, c), (−x₁, x₂, −c), (x₁, −x₂, −c): they
/// share |q_i| (so P(q_i) and the reducible part, even in each q_i), the legs |k ∓ q_i| come in two
/// kinds each, and q₁·q₂ keeps or flips its sign.
#[inline]
pub(crate) fn point_legs(k: f64, point: &Point) -> PointLegs {
    let (ln_q, x) = (point.ln_q, point.x);
    let q = [ln_q[0].exp(), ln_q[1].exp()];
    let (s1, s2) = (
        (1.0 - x[0] * x[0]).max(0.0).sqrt(),
        (1.0 - x[1] * x[1]).max(0.0).sqrt(),
    );
    let q1q2 = q[0] * q[1] * (x[0] * x[1] + s1 * s2 * point.cos_phi);
    let (kk, kq1, kq2, q11, q22) = (
        k * k,
        k * q[0] * x[0],
        k * q[1] * x[1],
        q[0] * q[0],
        q[1] * q[1],
    );
    // d³q₁d³q₂/(2π)⁶ = q₁³q₂³ dln q₁ dln q₂ · 2π dx₁ · 2 dx₂ dφ (φ ∈ [0, π]) / (2π)⁶; ¼ for the images.
    let measure = 0.25 * (q[0] * q[1]).powi(3) * 4.0 * PI / (2.0 * PI).powi(6);
    let mut legs = [NO_LEG; LEGS];
    // 2P33red in the IR-safe part, the same in all four images.
    let red = reducible_part(&[kk, kq1, kq2, q11, q1q2, q22]);
    legs[0].ln_z = k.ln();
    for (c, r) in legs[0].coef.iter_mut().zip(red) {
        *c = 4.0 * measure * 2.0 * r;
    }
    // X_4^s(q₁, k − q₁, q₂, −q₂) is even in q₂ and the leg depends on q₁ only, so the P24 half of q₁
    // takes two values over the images, set by the sign of k·q₁ (images 1, 4 and 2, 3), each twice,
    // with the weight ½ of the q₁ ↔ q₂ symmetrisation; likewise the half of q₂ (images 1, 3 and 2, 4).
    // The four X_4 are evaluated together (in lanes), as are the four X_3 below.
    let m4 = pt_kernels::mode_coupling_4_x4(&[
        [kk, kq1, kq2, q11, q1q2, q22],
        [kk, -kq1, -kq2, q11, q1q2, q22],
        [kk, kq2, kq1, q22, q1q2, q11],
        [kk, -kq2, -kq1, q22, q1q2, q11],
    ]);
    legs[1] = p24_leg(pair_leg(kk, kq1, q11), m4[0], measure);
    legs[2] = p24_leg(pair_leg(kk, -kq1, q11), m4[1], measure);
    legs[3] = p24_leg(pair_leg(kk, kq2, q22), m4[2], measure);
    legs[4] = p24_leg(pair_leg(kk, -kq2, q22), m4[3], measure);
    // (sign of k·q₁, sign of k·q₂, sign of q₁·q₂) of the four images.
    let signs = [
        (1.0, 1.0, 1.0),
        (-1.0, -1.0, 1.0),
        (-1.0, 1.0, -1.0),
        (1.0, -1.0, -1.0),
    ];
    let grams = signs.map(|(s1, s2, s12)| [kk, s1 * kq1, s2 * kq2, q11, s12 * q1q2, q22]);
    let m3 = pt_kernels::mode_coupling_3_x4(&grams);
    for (image, g) in grams.iter().enumerate() {
        let [_, a1, a2, _, q12, _] = *g;
        let q33 = (kk + q11 + q22 - 2.0 * a1 - 2.0 * a2 + 2.0 * q12).max(0.0);
        // The smooth partition w = q₃⁴/(q₁⁴ + q₂⁴ + q₃⁴) of the permutation symmetry (×3 below).
        let w3 = q33 * q33 / (q11 * q11 + q22 * q22 + q33 * q33);
        if w3 <= 1e-12 {
            continue;
        }
        let leg = &mut legs[5 + image];
        leg.ln_z = 0.5 * q33.ln();
        for (j, &(x, y)) in PAIRS.iter().enumerate() {
            let c = measure * m3[image][x] * m3[image][y] * 18.0 * w3;
            leg.coef[j] = c;
            leg.coef[6 + j] = c;
        }
    }
    PointLegs { legs }
}

/// The spectrum on the lattice, zero outside [q_min, q_max].
pub(crate) struct Sampled<'a> {
    pub lattice: &'a Lattice,
    pub samples: &'a [f64],
}

impl Sampled<'_> {
    /// P̃ at q = e^`ln_q`.
    #[inline]
    pub fn at_ln(&self, ln_q: f64) -> f64 {
        self.lattice.at_ln_or_zero(self.samples, ln_q)
    }

    /// The integrand at one point for this spectrum (the [`ACC`] quantities, times the measure but
    /// not the sampling Jacobian); the kernels are skipped where P(q₁)P(q₂) = 0.
    #[inline]
    pub fn integrand(&self, k: f64, point: &Point) -> [f64; ACC] {
        let (p1, p2) = (self.at_ln(point.ln_q[0]), self.at_ln(point.ln_q[1]));
        let mut out = [0.0; ACC];
        if p1 == 0.0 || p2 == 0.0 {
            return out;
        }
        for leg in &point_legs(k, point).legs {
            let p = self.at_ln(leg.ln_z);
            if p != 0.0 {
                for (o, c) in out.iter_mut().zip(leg.coef) {
                    *o += c * p;
                }
            }
        }
        out.map(|v| v * p1 * p2)
    }
}
