//! The log-uniform lattice on which loop integrals sample the linear spectrum, and interpolation on it.
//!
//! A plan never evaluates [`LinearSpectrum`] inside its sums: it samples P once per spectrum on a lattice
//! ln q_j = ln q_min + j h (j = 0..N−1, ln q_{N−1} = ln q_max) and interpolates between lattice points
//! with four-point Lagrange polynomials in ln q ([`lagrange4`]), which are linear in the samples. The
//! integrals are therefore exact for the interpolant P̃, and the plan's weights do not depend on P.
//! For CDM spectra on the default step h = 0.01 the relative interpolation error of P̃ is ≲ 1e-8
//! (fourth order: ~ (n_eff h)⁴/40), far below the quadrature errors; the P13 and σ_v² error estimates
//! include it explicitly (half-resolution lattice, see [`crate::loops`]).

use crate::integrate::lagrange4;
use crate::linear::LinearSpectrum;

/// A lattice ln q_j = ln q_min + j h with an even number of intervals N − 1, so that every other point
/// forms the half-resolution lattice of step 2h.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Lattice {
    /// ln q_min.
    pub x0: f64,
    /// Step h in ln q.
    pub step: f64,
    /// 1/h (lookups multiply rather than divide).
    inv_step: f64,
    /// Number of points N (odd, ≥ 5).
    pub len: usize,
}

impl Lattice {
    /// The lattice from q_min to q_max [h/Mpc] with step ≤ `max_step` and an even number of intervals.
    pub fn new(q_min: f64, q_max: f64, max_step: f64) -> Self {
        let span = (q_max / q_min).ln();
        let intervals = ((span / max_step).ceil() as usize)
            .max(4)
            .next_multiple_of(2);
        let step = span / intervals as f64;
        Self {
            x0: q_min.ln(),
            step,
            inv_step: 1.0 / step,
            len: intervals + 1,
        }
    }

    /// Every other point: the lattice of step 2h over the same range.
    pub fn coarse(&self) -> Self {
        Self {
            x0: self.x0,
            step: 2.0 * self.step,
            inv_step: 0.5 * self.inv_step,
            len: self.len.div_ceil(2),
        }
    }

    /// ln q of point j.
    pub fn x(&self, j: usize) -> f64 {
        self.x0 + self.step * j as f64
    }

    /// ln q_max.
    pub fn x_end(&self) -> f64 {
        self.x(self.len - 1)
    }

    /// The fractional lattice index u = (ln q − ln q_min)/h of `q` [h/Mpc] (in [0, N−1] inside the range).
    pub fn position(&self, q: f64) -> f64 {
        (q.ln() - self.x0) / self.step
    }

    /// First point b of the four-point stencil used at fractional index u, and t = u − b ∈ [0, 3].
    ///
    /// Interior cells [j, j+1] use the points j−1..j+2; the first and last cells use one-sided stencils.
    #[inline(always)]
    pub fn stencil(&self, u: f64) -> (usize, f64) {
        let cell = u.max(0.0) as usize;
        let b = cell.saturating_sub(1).min(self.len - 4);
        (b, u - b as f64)
    }

    /// The samples P(q_j) of `spectrum` at the lattice points.
    pub fn sample(&self, spectrum: &LinearSpectrum) -> Vec<f64> {
        (0..self.len)
            .map(|j| spectrum.eval(self.x(j).exp()))
            .collect()
    }

    /// The interpolant P̃ at ln q = `x` from `samples`, and 0 outside [q_min, q_max] (the loop integrals'
    /// convention: no power outside the integration range).
    #[inline]
    pub fn at_ln_or_zero(&self, samples: &[f64], x: f64) -> f64 {
        let u = (x - self.x0) * self.inv_step;
        if (0.0..=(self.len - 1) as f64).contains(&u) {
            self.interpolate(samples, u)
        } else {
            0.0
        }
    }

    /// The interpolant P̃ at fractional index u from `samples` (u in [0, N−1]).
    #[inline(always)]
    pub fn interpolate(&self, samples: &[f64], u: f64) -> f64 {
        let (b, t) = self.stencil(u);
        let w = lagrange4(t);
        let s = &samples[b..b + 4];
        w[0] * s[0] + w[1] * s[1] + w[2] * s[2] + w[3] * s[3]
    }
}

/// Adds ∫ g_m(x) P̃(x) dx over the lattice cell(s) covering [a, b] ⊂ [x_0, x_{N−1}] to `weights[m]`
/// for each of the M kernels g_m, so that Σ_j weights[m]_j P_j = ∫_a^b g_m P̃ dx for the interpolant P̃
/// of any samples P_j.
///
/// Each cell (or part of a cell) is integrated with the `rule` (nodes, weights on [−1, 1], e.g.
/// Gauss–Legendre); `g` must be smooth on (a, b).
pub(crate) fn add_product_weights<const M: usize>(
    lattice: &Lattice,
    weights: &mut [Vec<f64>; M],
    (a, b): (f64, f64),
    rule: (&[f64], &[f64]),
    g: impl Fn(f64) -> [f64; M],
) {
    let first = ((a - lattice.x0) / lattice.step).floor().max(0.0) as usize;
    let mut j = first.min(lattice.len - 2);
    loop {
        let lo = lattice.x(j).max(a);
        let hi = lattice.x(j + 1).min(b);
        if hi > lo {
            let (mid, half) = (0.5 * (lo + hi), 0.5 * (hi - lo));
            for (&s, &w) in rule.0.iter().zip(rule.1) {
                let x = mid + half * s;
                let gx = g(x);
                let (base, t) = lattice.stencil((x - lattice.x0) / lattice.step);
                let l = lagrange4(t);
                for (wm, gm) in weights.iter_mut().zip(gx) {
                    for (i, li) in l.iter().enumerate() {
                        wm[base + i] += half * w * gm * li;
                    }
                }
            }
        }
        j += 1;
        if j + 1 >= lattice.len || lattice.x(j) >= b {
            break;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::integrate::legendre_nodes;

    #[test]
    fn lattice_has_even_intervals_and_nested_coarse_points() {
        let l = Lattice::new(1e-5, 1e3, 0.01);
        assert_eq!((l.len - 1) % 2, 0);
        assert!(l.step <= 0.01);
        assert!((l.x_end() - 1e3_f64.ln()).abs() < 1e-12);
        let c = l.coarse();
        assert!((c.x(7) - l.x(14)).abs() < 1e-12 && (c.x_end() - l.x_end()).abs() < 1e-12);
    }

    #[test]
    fn interpolation_reproduces_cubics_in_ln_q() {
        let l = Lattice::new(0.1, 10.0, 0.05);
        let f = |x: f64| 1.0 + x - 0.3 * x * x + 0.1 * x * x * x;
        let samples: Vec<f64> = (0..l.len).map(|j| f(l.x(j))).collect();
        for u in [
            0.0,
            0.4,
            1.0,
            17.3,
            (l.len - 1) as f64 - 0.2,
            (l.len - 1) as f64,
        ] {
            let x = l.x0 + u * l.step;
            assert!((l.interpolate(&samples, u) - f(x)).abs() < 1e-12, "u={u}");
        }
    }

    #[test]
    fn product_weights_integrate_the_interpolant() {
        let l = Lattice::new(0.1, 10.0, 0.05);
        let (n, w) = legendre_nodes(4);
        let mut weights = [vec![0.0; l.len]];
        let (a, b) = (l.x0 + 0.123, l.x_end() - 0.456);
        add_product_weights(&l, &mut weights, (a, b), (&n, &w), |x| [x.cos()]);
        let [weights] = weights;
        // P = x² is reproduced exactly by the interpolant: ∫ x² cos x dx.
        let samples: Vec<f64> = (0..l.len).map(|j| l.x(j).powi(2)).collect();
        let v: f64 = weights.iter().zip(&samples).map(|(w, s)| w * s).sum();
        let anti = |x: f64| x * x * x.sin() + 2.0 * x * x.cos() - 2.0 * x.sin();
        assert!((v - (anti(b) - anti(a))).abs() < 1e-12, "{v}");
    }
}
