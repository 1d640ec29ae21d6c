//! Quadrature helpers: Gauss–Legendre rules, panels, four-point Lagrange interpolation on a uniform grid.
//!
//! Every integral computed here returns `(value, error estimate)`. The estimate is always the difference
//! between the rule and a lower-resolution rule on the same interval (stated per function), which for the
//! smooth integrands of this crate bounds the actual error with a wide margin.
//!
//! No crate on crates.io offers fixed Gauss–Legendre rules that can be precomputed into plans (the loop
//! integrals of [`crate::loops`] store nodes and weights once per k grid and reuse them for every linear
//! spectrum), so the rules are built here by Newton iteration on the Legendre recurrence (Golub & Welsch
//! would also do; Newton from Tricomi's initial guess converges in 3–4 steps to machine precision).

use std::f64::consts::PI;

/// An n-point Gauss–Legendre rule on [−1, 1]: ∫_{−1}^{1} f(x) dx ≈ Σ_i w_i f(x_i), exact for polynomials of
/// degree ≤ 2n − 1.
///
/// ```
/// use pt_spectra::integrate::GaussLegendre;
/// let gl = GaussLegendre::new(5);
/// // Exact for degree ≤ 9; the error estimate compares with the 3-point rule (exact for degree ≤ 5).
/// let (v, err) = gl.integrate(|x| x.powi(9), 0.0, 1.0);
/// assert!((v - 0.1).abs() < 1e-15 && err > 1e-4);
/// let (v, err) = gl.integrate(|x| x.powi(5), 0.0, 1.0);
/// assert!((v - 1.0 / 6.0).abs() < 1e-15 && err < 1e-15);
/// ```
#[derive(Debug, Clone, PartialEq)]
pub struct GaussLegendre {
    nodes: Vec<f64>,
    weights: Vec<f64>,
    /// The ⌈n/2⌉-point rule used for the error estimate.
    coarse: Option<Box<GaussLegendre>>,
}

impl GaussLegendre {
    /// The n-point rule (n ≥ 1), nodes in increasing order.
    ///
    /// # Panics
    /// If `n == 0`.
    pub fn new(n: usize) -> Self {
        let (nodes, weights) = legendre_nodes(n);
        let coarse = (n > 1).then(|| {
            let (nodes, weights) = legendre_nodes(n.div_ceil(2));
            Box::new(Self {
                nodes,
                weights,
                coarse: None,
            })
        });
        Self {
            nodes,
            weights,
            coarse,
        }
    }

    /// Number of nodes n.
    pub fn len(&self) -> usize {
        self.nodes.len()
    }

    /// Always false: a rule has at least one node.
    pub fn is_empty(&self) -> bool {
        self.nodes.is_empty()
    }

    /// Nodes on [−1, 1], increasing.
    pub fn nodes(&self) -> &[f64] {
        &self.nodes
    }

    /// Weights on [−1, 1] (they sum to 2).
    pub fn weights(&self) -> &[f64] {
        &self.weights
    }

    /// Nodes and weights mapped to [a, b]: (x_i, w_i) with ∫_a^b f ≈ Σ w_i f(x_i).
    pub fn on(&self, a: f64, b: f64) -> impl Iterator<Item = (f64, f64)> + '_ {
        let (mid, half) = (0.5 * (a + b), 0.5 * (b - a));
        self.nodes
            .iter()
            .zip(&self.weights)
            .map(move |(&x, &w)| (mid + half * x, half * w))
    }

    /// ∫_a^b f(x) dx with the n-point rule, and the error estimate |I_n − I_⌈n/2⌉| (0 for n = 1).
    pub fn integrate(&self, f: impl Fn(f64) -> f64, a: f64, b: f64) -> (f64, f64) {
        let value: f64 = self.on(a, b).map(|(x, w)| w * f(x)).sum();
        let error = self.coarse.as_ref().map_or(0.0, |c| {
            let coarse: f64 = c.on(a, b).map(|(x, w)| w * f(x)).sum();
            (value - coarse).abs()
        });
        (value, error)
    }

    /// ∫ f over the consecutive panels [e_0, e_1], [e_1, e_2], … of `edges` with the n-point rule on each;
    /// the error estimate is the sum of the panels' estimates (see [`integrate`](Self::integrate)).
    pub fn integrate_panels(&self, f: impl Fn(f64) -> f64, edges: &[f64]) -> (f64, f64) {
        edges
            .windows(2)
            .map(|e| self.integrate(&f, e[0], e[1]))
            .fold((0.0, 0.0), |(v, e), (dv, de)| (v + dv, e + de))
    }
}

/// Nodes (increasing) and weights of the n-point Gauss–Legendre rule on [−1, 1].
///
/// Newton's method on P_n from Tricomi's approximation x_i ≈ cos(π(i − ¼)/(n + ½)); P_n and P_n′ from the
/// three-term recurrence. Converges to |Δx| < 1e-15 in a few steps for any n used here (≤ a few hundred).
///
/// # Panics
/// If `n == 0`.
pub fn legendre_nodes(n: usize) -> (Vec<f64>, Vec<f64>) {
    assert!(n > 0, "a Gauss–Legendre rule needs at least one node");
    let mut nodes = vec![0.0; n];
    let mut weights = vec![0.0; n];
    let nf = n as f64;
    for i in 0..n.div_ceil(2) {
        let mut x = (PI * (i as f64 + 0.75) / (nf + 0.5)).cos();
        let mut dp = 1.0;
        for _ in 0..100 {
            let (p, d) = legendre_and_derivative(n, x);
            dp = d;
            let dx = p / d;
            x -= dx;
            if dx.abs() < 1e-16 {
                dp = legendre_and_derivative(n, x).1;
                break;
            }
        }
        let w = 2.0 / ((1.0 - x * x) * dp * dp);
        nodes[i] = -x;
        nodes[n - 1 - i] = x;
        weights[i] = w;
        weights[n - 1 - i] = w;
    }
    if n % 2 == 1 {
        nodes[n / 2] = 0.0;
    }
    (nodes, weights)
}

/// (P_n(x), P_n′(x)) for n ≥ 1 by the recurrence (k+1) P_{k+1} = (2k+1) x P_k − k P_{k−1} and
/// (x² − 1) P_n′ = n (x P_n − P_{n−1}).
fn legendre_and_derivative(n: usize, x: f64) -> (f64, f64) {
    let (mut p0, mut p1) = (1.0, x);
    for k in 1..n {
        let kf = k as f64;
        let p2 = ((2.0 * kf + 1.0) * x * p1 - kf * p0) / (kf + 1.0);
        p0 = p1;
        p1 = p2;
    }
    (p1, n as f64 * (x * p1 - p0) / (x * x - 1.0))
}

/// Splits [a, b] into panels whose width at their left edge x is at most `width(x)` (> 0).
///
/// The panels are made by walking from a with steps `width(x)`; if the last step would leave a sliver
/// shorter than a quarter of a step, it is merged into the previous panel. Returns the edges
/// a = e_0 < e_1 < … < e_m = b (just [a, b] if the interval fits in one panel).
pub fn panel_edges(a: f64, b: f64, width: impl Fn(f64) -> f64) -> Vec<f64> {
    let mut edges = vec![a];
    let mut x = a;
    while x < b {
        let w = width(x);
        debug_assert!(w > 0.0, "panel width must be positive");
        let next = x + w;
        if next >= b - 0.25 * w {
            break;
        }
        edges.push(next);
        x = next;
    }
    edges.push(b);
    edges
}

/// Weights of four-point Lagrange interpolation through nodes at t = 0, 1, 2, 3 (unit spacing),
/// evaluated at `t` (usually in [0, 3]): f(t) ≈ Σ_j ℓ_j(t) f_j. Exact for cubics.
#[inline(always)]
pub fn lagrange4(t: f64) -> [f64; 4] {
    let (a, b, c, d) = (t, t - 1.0, t - 2.0, t - 3.0);
    let (ab, cd) = (a * b, c * d);
    [
        -b * cd * (1.0 / 6.0),
        a * cd * 0.5,
        -ab * d * 0.5,
        ab * c * (1.0 / 6.0),
    ]
}

/// ∫_a^b f(ln q) d ln q by composite Simpson with `intervals` (even) steps in ln q, with the error
/// estimate |S_h − S_2h| (the rule on every other node): the 1-D integrals over a spectrum's range
/// (σ_d², Σ²) where the integrand is smooth in ln q. Returns (0, 0) if b ≤ a.
pub fn simpson_ln(f: impl Fn(f64) -> f64, a: f64, b: f64, intervals: usize) -> (f64, f64) {
    if b <= a {
        return (0.0, 0.0);
    }
    let n = intervals.max(4) & !1;
    let h = (b - a) / n as f64;
    let y: Vec<f64> = (0..=n).map(|i| f(a + h * i as f64)).collect();
    simpson_of(&y, h)
}

/// The nodes ln q = a + h i, i = 0 … n, of [`simpson_ln`] on [a, b] with `intervals` steps, and h:
/// for integrands evaluated together (several integrals over one set of nodes, [`simpson_of`]).
pub fn simpson_ln_nodes(a: f64, b: f64, intervals: usize) -> (Vec<f64>, f64) {
    let n = intervals.max(4) & !1;
    let h = (b - a) / n as f64;
    ((0..=n).map(|i| a + h * i as f64).collect(), h)
}

/// Composite Simpson of the values `y` at equally spaced nodes h apart (an even number of intervals)
/// with the error estimate |S_h − S_2h|, as [`simpson_ln`].
pub fn simpson_of(y: &[f64], h: f64) -> (f64, f64) {
    let n = y.len() - 1;
    let rule = |stride: usize| {
        let m = n / stride;
        let inner: f64 = (1..m)
            .map(|i| y[i * stride] * if i % 2 == 1 { 4.0 } else { 2.0 })
            .sum();
        (y[0] + inner + y[n]) * h * stride as f64 / 3.0
    };
    let fine = rule(1);
    (fine, (fine - rule(2)).abs())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Gauss–Legendre weights and nodes are exact to round-off.
    const ROUND_OFF: f64 = 1e-14;

    #[test]
    fn rules_are_exact_to_degree_2n_minus_1() {
        for n in [1, 2, 3, 5, 8, 13, 32, 64] {
            let gl = GaussLegendre::new(n);
            assert!((gl.weights().iter().sum::<f64>() - 2.0).abs() < ROUND_OFF);
            for deg in 0..2 * n {
                let (v, _) = gl.integrate(|x| x.powi(deg as i32), -1.0, 1.0);
                let exact = if deg % 2 == 1 {
                    0.0
                } else {
                    2.0 / (deg as f64 + 1.0)
                };
                assert!(
                    (v - exact).abs() < 10.0 * ROUND_OFF,
                    "n={n} deg={deg} v={v}"
                );
            }
        }
    }

    #[test]
    fn known_three_point_rule() {
        let gl = GaussLegendre::new(3);
        let x = (0.6_f64).sqrt();
        assert!((gl.nodes()[0] + x).abs() < ROUND_OFF && gl.nodes()[1] == 0.0);
        assert!((gl.weights()[1] - 8.0 / 9.0).abs() < ROUND_OFF);
        assert!((gl.weights()[2] - 5.0 / 9.0).abs() < ROUND_OFF);
    }

    #[test]
    fn error_estimate_bounds_the_error_of_a_smooth_integral() {
        let gl = GaussLegendre::new(6);
        let edges = panel_edges(0.0, 3.0, |_| 0.5);
        let (v, err) = gl.integrate_panels(f64::sin, &edges);
        let exact = 1.0 - 3f64.cos();
        assert!((v - exact).abs() <= err && err < 1e-6, "v={v} err={err}");
    }

    #[test]
    fn panels_cover_the_interval() {
        let e = panel_edges(1.0, 2.0, |_| 0.3);
        assert_eq!(e.first(), Some(&1.0));
        assert_eq!(e.last(), Some(&2.0));
        assert!(e
            .windows(2)
            .all(|w| w[1] > w[0] && w[1] - w[0] <= 0.3 * 1.25 + 1e-12));
        assert_eq!(panel_edges(0.0, 0.1, |_| 1.0), vec![0.0, 0.1]);
    }

    #[test]
    fn lagrange_is_exact_for_cubics() {
        let f = |t: f64| 2.0 - t + 0.5 * t * t - 0.25 * t * t * t;
        for t in [0.0, 0.3, 1.0, 1.7, 2.5, 3.0] {
            let w = lagrange4(t);
            let v: f64 = (0..4).map(|j| w[j] * f(j as f64)).sum();
            assert!((v - f(t)).abs() < 1e-13, "t={t}");
        }
    }

    #[test]
    fn simpson_in_ln_q_integrates_and_bounds_its_error() {
        // ∫ q dq from 1e-3 to 1 is ∫ e^{2u} du over u = ln q: (1 − 1e-6)/2.
        // The error estimate |S_h − S_2h| is ~15 times the actual error of S_h (both O(h⁴)).
        let exact = 0.5 * (1.0 - 1e-6);
        for (n, bound) in [(64, 1e-4), (256, 1e-6)] {
            let (v, e) = simpson_ln(|u| (2.0 * u).exp(), 1e-3f64.ln(), 0.0, n);
            assert!((v - exact).abs() <= e && e < bound, "{n}: {v} {e}");
        }
        assert_eq!(simpson_ln(|u| u, 1.0, 0.5, 8), (0.0, 0.0));
    }
}
