//! Numerical helpers of [`LinearSpectrum`](super::LinearSpectrum): a not-a-knot cubic spline, an anchored
//! power law and composite Simpson quadrature with an error estimate.

use crate::dual::Real;

/// Not-a-knot cubic spline y(x) through at least 4 nodes with strictly increasing x.
#[derive(Debug, Clone)]
pub(crate) struct LogSpline {
    x: Vec<f64>,
    y: Vec<f64>,
    /// Second derivatives y'' at the nodes.
    m: Vec<f64>,
    /// 1 / mean spacing, for the index guess on (nearly) uniform grids.
    inv_dx: f64,
}

impl LogSpline {
    /// The spline through (x_i, y_i); x strictly increasing, at least 4 nodes (checked by the caller).
    pub(crate) fn new(x: Vec<f64>, y: Vec<f64>) -> Self {
        let n = x.len();
        debug_assert!(n >= 4 && y.len() == n);
        let m = not_a_knot_second_derivatives(&x, &y);
        let inv_dx = (n - 1) as f64 / (x[n - 1] - x[0]);
        Self { x, y, m, inv_dx }
    }

    /// For each interval [x_i, x_{i+1}], an upper bound of y there (NaN if the spline is not finite):
    /// max(y_i, y_{i+1}) plus the largest cubic term, |a³ − a| ≤ 2/(3√3) for a ∈ [0, 1].
    pub(super) fn upper_bounds(&self) -> impl Iterator<Item = f64> + '_ {
        let cubic = 2.0 / (3.0 * 3f64.sqrt()) / 6.0;
        self.x.windows(2).enumerate().map(move |(i, x)| {
            let h = x[1] - x[0];
            let bend = (self.m[i].abs() + self.m[i + 1].abs()) * h * h * cubic;
            // `+` keeps a NaN of m; f64::max would drop it.
            if self.y[i] > self.y[i + 1] {
                self.y[i] + bend
            } else {
                self.y[i + 1] + bend
            }
        })
    }

    /// The node to blame for the largest overshoot: of the two ends of the interval with the largest
    /// [`upper_bounds`](Self::upper_bounds), the one where |y''| is larger (NaN counts as largest).
    pub(super) fn worst_node(&self) -> usize {
        let i = self
            .upper_bounds()
            .enumerate()
            .max_by(|a, b| a.1.total_cmp(&b.1))
            .map_or(0, |(i, _)| i);
        if self.m[i + 1].abs().total_cmp(&self.m[i].abs()).is_gt() {
            i + 1
        } else {
            i
        }
    }

    /// Adds a constant to y (multiplies P by e^c when y = ln P).
    pub(super) fn shift(&mut self, c: f64) {
        self.y.iter_mut().for_each(|v| *v += c);
    }

    /// The index i with x_i ≤ x ≤ x_{i+1}, for x inside [x_0, x_{n−1}].
    fn interval(&self, x: f64) -> usize {
        let last = self.x.len() - 2;
        let guess = (((x - self.x[0]) * self.inv_dx) as usize).min(last);
        for i in [guess, guess.saturating_sub(1), (guess + 1).min(last)] {
            if self.x[i] <= x && x <= self.x[i + 1] {
                return i;
            }
        }
        self.x.partition_point(|&v| v <= x).clamp(1, last + 1) - 1
    }

    /// The first and last node x_0, x_{n−1}.
    pub(crate) fn range(&self) -> (f64, f64) {
        (self.x[0], self.x[self.x.len() - 1])
    }

    /// The spline of other values `y` at the same nodes (the same not-a-knot rule: linear in `y`).
    pub(super) fn with_values(&self, y: Vec<f64>) -> Self {
        debug_assert_eq!(y.len(), self.x.len());
        let m = not_a_knot_second_derivatives(&self.x, &y);
        Self {
            x: self.x.clone(),
            y,
            m,
            inv_dx: self.inv_dx,
        }
    }

    /// dy/dx for x inside [x_0, x_{n−1}]: (y_{i+1} − y_i)/h + ((3b² − 1) y''_{i+1} − (3a² − 1) y''_i) h/6.
    pub(super) fn derivative(&self, x: f64) -> f64 {
        let i = self.interval(x);
        let h = self.x[i + 1] - self.x[i];
        let a = (self.x[i + 1] - x) / h;
        let b = 1.0 - a;
        (self.y[i + 1] - self.y[i]) / h
            + ((3.0 * b * b - 1.0) * self.m[i + 1] - (3.0 * a * a - 1.0) * self.m[i]) * h / 6.0
    }

    /// y(x) for x inside [x_0, x_{n−1}].
    pub(crate) fn eval(&self, x: f64) -> f64 {
        let i = self.interval(x);
        let h = self.x[i + 1] - self.x[i];
        let a = (self.x[i + 1] - x) / h;
        let b = 1.0 - a;
        a * self.y[i]
            + b * self.y[i + 1]
            + ((a * a * a - a) * self.m[i] + (b * b * b - b) * self.m[i + 1]) * h * h / 6.0
    }
}

/// Second derivatives of the not-a-knot cubic spline (y''' continuous at x_1 and x_{n−2}).
///
/// The interior equations h_{i−1} M_{i−1} + 2(h_{i−1}+h_i) M_i + h_i M_{i+1} = 6(d_i − d_{i−1}),
/// d_i = (y_{i+1} − y_i)/h_i, for i = 1..n−2, with M_0 and M_{n−1} eliminated through the not-a-knot
/// conditions, form a tridiagonal system solved by the Thomas algorithm.
fn not_a_knot_second_derivatives(x: &[f64], y: &[f64]) -> Vec<f64> {
    let n = x.len();
    let h: Vec<f64> = x.windows(2).map(|w| w[1] - w[0]).collect();
    let d: Vec<f64> = (0..n - 1).map(|i| (y[i + 1] - y[i]) / h[i]).collect();
    // Unknowns M_1..M_{n-2}: sub-diagonal a, diagonal b, super-diagonal c, right-hand side r.
    let size = n - 2;
    let mut a = vec![0.0; size];
    let mut b = vec![0.0; size];
    let mut c = vec![0.0; size];
    let mut r = vec![0.0; size];
    for j in 0..size {
        let i = j + 1;
        a[j] = h[i - 1];
        b[j] = 2.0 * (h[i - 1] + h[i]);
        c[j] = h[i];
        r[j] = 6.0 * (d[i] - d[i - 1]);
    }
    // M_0 = (1 + h0/h1) M_1 − (h0/h1) M_2.
    let (h0, h1) = (h[0], h[1]);
    b[0] += h0 * (1.0 + h0 / h1);
    c[0] -= h0 * h0 / h1;
    // M_{n−1} = (1 + hl/hp) M_{n−2} − (hl/hp) M_{n−3}, hl = h_{n−2}, hp = h_{n−3}.
    let (hl, hp) = (h[n - 2], h[n - 3]);
    b[size - 1] += hl * (1.0 + hl / hp);
    a[size - 1] -= hl * hl / hp;
    let inner = thomas(&a, &b, &c, &r);
    let mut m = Vec::with_capacity(n);
    m.push((1.0 + h0 / h1) * inner[0] - h0 / h1 * inner[1]);
    m.extend_from_slice(&inner);
    m.push((1.0 + hl / hp) * inner[size - 1] - hl / hp * inner[size - 2]);
    m
}

/// Solves the tridiagonal system a_j u_{j−1} + b_j u_j + c_j u_{j+1} = r_j (a_0, c_{n−1} unused).
fn thomas(a: &[f64], b: &[f64], c: &[f64], r: &[f64]) -> Vec<f64> {
    let n = b.len();
    let mut cp = vec![0.0; n];
    let mut rp = vec![0.0; n];
    cp[0] = c[0] / b[0];
    rp[0] = r[0] / b[0];
    for j in 1..n {
        let denom = b[j] - a[j] * cp[j - 1];
        cp[j] = c[j] / denom;
        rp[j] = (r[j] - a[j] * rp[j - 1]) / denom;
    }
    let mut u = rp;
    for j in (0..n - 1).rev() {
        u[j] -= cp[j] * u[j + 1];
    }
    u
}

/// P(k) = p0 (k/k0)^slope.
#[derive(Debug, Clone, Copy)]
pub(super) struct PowerLaw {
    pub(super) k0: f64,
    pub(super) p0: f64,
    pub(super) slope: f64,
    /// ln k0.
    pub(super) ln_k0: f64,
}

impl PowerLaw {
    /// Least-squares slope of y = ln P against x = ln k, anchored at node `anchor` of the slices.
    pub(super) fn fit(x: &[f64], y: &[f64], anchor: usize) -> Self {
        Self {
            k0: x[anchor].exp(),
            p0: y[anchor].exp(),
            slope: least_squares_slope(x, y),
            ln_k0: x[anchor],
        }
    }

    /// P(k).
    pub(super) fn eval(&self, k: f64) -> f64 {
        self.p0 * (k / self.k0).powf(self.slope)
    }

    /// P at ln k = `x`.
    pub(super) fn eval_ln(&self, x: f64) -> f64 {
        self.p0 * (self.slope * (x - self.ln_k0)).exp()
    }
}

/// The least-squares slope of y against x (linear in y).
pub(super) fn least_squares_slope(x: &[f64], y: &[f64]) -> f64 {
    let n = x.len() as f64;
    let (mx, my) = (x.iter().sum::<f64>() / n, y.iter().sum::<f64>() / n);
    let sxy: f64 = x.iter().zip(y).map(|(a, b)| (a - mx) * (b - my)).sum();
    let sxx: f64 = x.iter().map(|a| (a - mx).powi(2)).sum();
    sxy / sxx
}

/// Composite Simpson rule for ∫_a^b f(x) dx with `n` (rounded up to even, ≥ 4) intervals, over any
/// [`Real`] (dual numbers carry the derivative of the sum).
///
/// Returns (S_n, |S_n − S_{n/2}|/15), the second being the Richardson error estimate (of the values).
pub(crate) fn simpson<T: Real>(f: impl Fn(f64) -> T, a: f64, b: f64, n: usize) -> (T, f64) {
    let n = n.max(4).div_ceil(4) * 4;
    let h = (b - a) / n as f64;
    let (mut fine, mut coarse) = (T::cst(0.0), T::cst(0.0));
    for i in 0..=n {
        let v = f(if i == n { b } else { a + h * i as f64 });
        let w_fine = match i {
            0 => 1.0,
            _ if i == n => 1.0,
            _ if i % 2 == 1 => 4.0,
            _ => 2.0,
        };
        fine += v * w_fine;
        if i % 2 == 0 {
            let w_coarse = match i {
                0 => 1.0,
                _ if i == n => 1.0,
                _ if i % 4 == 2 => 4.0,
                _ => 2.0,
            };
            coarse += v * w_coarse;
        }
    }
    let (fine, coarse) = (fine * h / 3.0, coarse * 2.0 * h / 3.0);
    let error = (fine.value() - coarse.value()).abs() / 15.0;
    (fine, error)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn spline_is_exact_for_cubics_and_interpolates_nodes() {
        // Not-a-knot reproduces any cubic exactly, also on a non-uniform grid.
        let x: Vec<f64> = (0..12)
            .map(|i| f64::from(i) + 0.1 * f64::from(i * i % 5))
            .collect();
        let cubic = |t: f64| 1.0 - 2.0 * t + 0.3 * t * t - 0.05 * t * t * t;
        let y: Vec<f64> = x.iter().map(|&t| cubic(t)).collect();
        let s = LogSpline::new(x.clone(), y);
        for t in [0.0, 0.37, 3.3, 7.77, 11.0, x[11]] {
            assert!((s.eval(t) - cubic(t)).abs() < 1e-10, "t = {t}");
        }
    }

    /// The derivative of a cubic, and the spline of other values at the same nodes, are exact.
    #[test]
    fn derivative_and_other_values_are_exact_for_cubics() {
        let x: Vec<f64> = (0..9)
            .map(|i| f64::from(i) * 0.3 + 0.01 * f64::from(i % 3))
            .collect();
        let s = LogSpline::new(x.clone(), x.iter().map(|t| t.sin()).collect());
        let cubic = |t: f64| 0.5 + t - 0.7 * t * t + 0.2 * t * t * t;
        let d_cubic = |t: f64| 1.0 - 1.4 * t + 0.6 * t * t;
        let c = s.with_values(x.iter().map(|&t| cubic(t)).collect());
        for t in [0.0, 0.4, 1.3, 2.0, x[8]] {
            assert!((c.eval(t) - cubic(t)).abs() < 1e-12, "t = {t}");
            assert!((c.derivative(t) - d_cubic(t)).abs() < 1e-11, "t = {t}");
        }
    }

    #[test]
    fn simpson_error_estimate_brackets_the_error() {
        let (v, e) = simpson(f64::exp, 0.0, 2.0, 16);
        let exact = 2f64.exp() - 1.0;
        assert!((v - exact).abs() < 1e-5);
        assert!((v - exact).abs() < 2.0 * e && e < 1e-4);
    }

    #[test]
    fn power_law_fit_recovers_slope() {
        let x: Vec<f64> = (0..5).map(|i| f64::from(i) * 0.1).collect();
        let y: Vec<f64> = x.iter().map(|t| 2.0 - 3.0 * t).collect();
        let pl = PowerLaw::fit(&x, &y, 4);
        assert!((pl.slope + 3.0).abs() < 1e-12);
        assert!((pl.eval(x[4].exp()) - y[4].exp()).abs() < 1e-12);
    }
}
