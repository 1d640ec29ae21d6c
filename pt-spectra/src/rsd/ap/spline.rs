//! The interpolant of the Alcock–Paczynski projections: a cubic B-spline in ln k on the uniform grid
//! of [`super::Distortion::internal_grid`] (C², so the exact derivatives in α∥, α⊥ have no jumps where
//! k′ crosses a cell edge).
//!
//! With u = (ln k − ln k_0)/Δ the grid position, the spline is s(u) = Σ_m c_m B(u − m), B the
//! cubic B-spline of unit knots (support [−2, 2]). In the cell j ≤ u ≤ j + 1, t = u − j, it reads
//! the four coefficients c_{j−1} … c_{j+2} with the weights
//!   (1 − t)³/6,  (3t³ − 6t² + 4)/6,  (−3t³ + 3t² + 3t + 1)/6,  t³/6,
//! the same four points as the four-point Lagrange stencil it replaces. The coefficients solve the
//! interpolation conditions c_{i−1} + 4c_i + c_{i+1} = 6y_i at every grid point, closed by
//! not-a-knot ends (the third derivative continuous at the second and the second-to-last grid point:
//! one cubic over the first two cells and over the last two), which keeps the O(Δ⁴) accuracy up to
//! the ends. The evaluation range is the grid without its outermost cells, 1 ≤ u ≤ n − 2 (the grid
//! has two points beyond the needed k′ at each end), so c_0 … c_{n−1} suffice:
//!   c_1 = (8y_1 − y_0 − y_2)/6 (the cubic through y_0, y_1, y_2 of the first two cells: c = y − y″Δ²/6
//!   with the exact second difference), likewise c_{n−2};
//!   c_{i−1} + 4c_i + c_{i+1} = 6y_i for 2 ≤ i ≤ n − 3 (tridiagonal, strictly diagonally dominant);
//!   c_0 = 6y_1 − 4c_1 − c_2, c_{n−1} = 6y_{n−2} − 4c_{n−2} − c_{n−3}.
//! The elimination's pivots depend on n only: [`UniformSpline::new`] makes them once, and
//! [`UniformSpline::prefilter`] turns columns of samples into coefficients in O(n) per column.
//! Everything is linear in the samples: the prefilter and the weights are one linear map, used
//! alike by the values, their errors, the tangents and the exact AP derivatives.

/// The prefilter of cubic B-spline interpolation on n ≥ 4 uniform points with not-a-knot ends
/// ([module docs](self)).
#[derive(Debug, Clone, PartialEq)]
pub struct UniformSpline {
    n: usize,
    /// 1/d_i of the forward elimination of the interior system (index i, 2 ≤ i ≤ n − 3).
    inverse_pivots: Vec<f64>,
}

impl UniformSpline {
    /// The prefilter of `n` points. Fewer than 4 have no evaluation range ([`Self::cell`] is
    /// `None`) and no coefficients ([`Self::prefilter`] panics).
    pub fn new(n: usize) -> Self {
        let mut inverse_pivots = vec![0.0; n];
        let mut d = 4.0;
        for inverse in inverse_pivots.iter_mut().take(n.saturating_sub(2)).skip(2) {
            *inverse = 1.0 / d;
            d = 4.0 - 1.0 / d;
        }
        Self { n, inverse_pivots }
    }

    /// Replaces the samples `y` (one row of W columns per grid point) by the spline coefficients
    /// c_0 … c_{n−1} of each column.
    ///
    /// # Panics
    /// If `y` does not have one row per grid point or there are fewer than 4.
    pub fn prefilter<const W: usize>(&self, y: &mut [[f64; W]]) {
        let n = self.n;
        assert_eq!(y.len(), n, "samples on the spline's grid");
        assert!(n >= 4, "a cubic spline needs at least 4 points, got {n}");
        let combine = |a: &[f64; W], b: f64, c: &[f64; W], d: f64, e: &[f64; W], g: f64| {
            std::array::from_fn::<f64, W, _>(|q| a[q] * b + c[q] * d + e[q] * g)
        };
        let sixth = 1.0 / 6.0;
        // the not-a-knot ends, from the samples before they are overwritten
        let (y1, y_end) = (y[1], y[n - 2]);
        let c1 = combine(&y[1], 8.0 * sixth, &y[0], -sixth, &y[2], -sixth);
        let c_end = combine(&y[n - 2], 8.0 * sixth, &y[n - 1], -sixth, &y[n - 3], -sixth);
        y[1] = c1;
        y[n - 2] = c_end;
        // the interior rows 2 … n−3: right-hand sides 6y_i less the known neighbours, forward
        // elimination (each row less the previous one over its pivot), back substitution
        if n > 4 {
            let (first, last) = (2, n - 3);
            for i in first..=last {
                let mut r = y[i].map(|v| 6.0 * v);
                if i == first {
                    r.iter_mut().zip(&c1).for_each(|(r, c)| *r -= c);
                }
                if i == last {
                    r.iter_mut().zip(&c_end).for_each(|(r, c)| *r -= c);
                }
                if i > first {
                    let s = self.inverse_pivots[i - 1];
                    r.iter_mut().zip(&y[i - 1]).for_each(|(r, p)| *r -= p * s);
                }
                y[i] = r;
            }
            y[last] = y[last].map(|r| r * self.inverse_pivots[last]);
            for i in (first..last).rev() {
                let s = self.inverse_pivots[i];
                y[i] = std::array::from_fn(|q| (y[i][q] - y[i + 1][q]) * s);
            }
        }
        y[0] = combine(&y1, 6.0, &y[1], -4.0, &y[2], -1.0);
        y[n - 1] = combine(&y_end, 6.0, &y[n - 2], -4.0, &y[n - 3], -1.0);
    }

    /// The cell of the grid position `u` (1 ≤ u ≤ n − 2, to 1e-9): the first of its four
    /// coefficients and t = u − (first + 1) ∈ [0, 1] (slightly outside at the tolerance); `None`
    /// outside.
    pub fn cell(&self, u: f64) -> Option<(usize, f64)> {
        let last = self.n as f64 - 1.0;
        if self.n < 4 || !(1.0 - 1e-9..=last - 1.0 + 1e-9).contains(&u) {
            return None;
        }
        // u > 0 here: truncation is the floor (without a library call)
        let b = (u as usize).saturating_sub(1).min(self.n - 4);
        Some((b, u - (b + 1) as f64))
    }
}

/// The weights of the four coefficients of a cell at t ∈ [0, 1] (non-negative, summing to 1).
#[inline(always)]
pub fn weights(t: f64) -> [f64; 4] {
    let s = 1.0 - t;
    let t2 = t * t;
    let t3 = t2 * t;
    const SIXTH: f64 = 1.0 / 6.0;
    [
        s * s * s * SIXTH,
        (3.0 * t3 - 6.0 * t2 + 4.0) * SIXTH,
        (-3.0 * t3 + 3.0 * t2 + 3.0 * t + 1.0) * SIXTH,
        t3 * SIXTH,
    ]
}

/// d/dt of [`weights`] (divide by the step for d/d ln k).
#[inline(always)]
pub fn weights_derivative(t: f64) -> [f64; 4] {
    let s = 1.0 - t;
    [
        -0.5 * s * s,
        (1.5 * t - 2.0) * t,
        (-1.5 * t + 1.0) * t + 0.5,
        0.5 * t * t,
    ]
}

#[cfg(test)]
mod tests;
