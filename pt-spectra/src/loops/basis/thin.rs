//! Basis tensors on every other k of a dense log-uniform grid, the rows in between interpolated.
//!
//! The galaxy model with free Alcock–Paczynski parameters computes its loop terms on an internal
//! grid of 100 points per decade ([`crate::rsd::ap::POINTS_PER_DECADE`]), dense enough for the
//! four-point interpolation of P_lin's wiggles. The loop integrals are smoother than P_lin: the pair
//! columns (P22-type) and the linear forms of the P13-type terms (before they are multiplied by
//! P_lin(k), whose wiggles stay exact) follow six-point Lagrange interpolation in ln k from every
//! other point. So the tensors are made on those nodes only, half the rows to apply per spectrum.
//!
//! Each interpolated value carries an error estimate: twice the difference between the six-point and
//! the four-point interpolants of the same nodes. That difference is about the four-point error;
//! the six-point one is smaller by ~(ωh)² C₆/C₄ ≈ 0.35 for a wiggle of the BAO period at
//! k = 0.27 h/Mpc on these nodes, and the factor two covers the phase drifts of a chirped wiggle
//! (test `the_error_estimate_covers_a_wiggle`: P_lin-like 5% wiggles, far stronger than the loop
//! columns'). Measured on the BOSS CMASS NGC windowed data vector (P0, P2, P4
//! in 38 bins, AP, three cosmologies): thinning by two changes it by ≤ 8.9e-7 of each multipole's
//! largest value (by three it would be 1.4e-5, by four 4.7e-5: not done).

/// Grids at least this dense [points per decade of k], log-uniform, are thinned.
pub const MIN_POINTS_PER_DECADE: f64 = 80.0;

/// Grids of fewer points are not thinned (the interpolation needs six nodes).
const MIN_POINTS: usize = 24;

/// The nodes of a thinned grid and the interpolation of every grid point from them.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Thinning {
    /// Indices of the nodes in the grid: every other point, and the last one.
    nodes: Vec<usize>,
    /// The grid points between nodes: their index, the first of their six nodes, the nodes'
    /// weights, and the six-point minus the four-point weights (the error estimate's).
    between: Vec<(usize, usize, [f64; 6], [f64; 6])>,
    /// Points of the grid.
    len: usize,
}

impl Thinning {
    /// The thinning of `k` [h/Mpc], or `None` unless it is log-uniform (to 1e-9 in ln k) with at
    /// least [`MIN_POINTS_PER_DECADE`] per decade and [`MIN_POINTS`] points.
    pub(crate) fn of(k: &[f64]) -> Option<Self> {
        if k.len() < MIN_POINTS {
            return None;
        }
        let x: Vec<f64> = k.iter().map(|k| k.ln()).collect();
        let step = (x[x.len() - 1] - x[0]) / (x.len() - 1) as f64;
        let uniform = x
            .iter()
            .enumerate()
            .all(|(i, &xi)| (xi - x[0] - step * i as f64).abs() < 1e-9);
        if !(uniform && step > 0.0 && std::f64::consts::LN_10 / step >= MIN_POINTS_PER_DECADE) {
            return None;
        }
        let mut nodes: Vec<usize> = (0..k.len()).step_by(2).collect();
        if nodes.last() != Some(&(k.len() - 1)) {
            nodes.push(k.len() - 1);
        }
        let xn: Vec<f64> = nodes.iter().map(|&i| x[i]).collect();
        let m = nodes.len();
        let between = (0..k.len())
            .filter(|i| nodes.binary_search(i).is_err())
            .map(|i| {
                let xi = x[i];
                // the node interval [j, j + 1] holding xi, the stencils centred on it
                let j = xn
                    .partition_point(|&v| v <= xi)
                    .saturating_sub(1)
                    .min(m - 2);
                let first6 = j.saturating_sub(2).min(m - 6);
                let first4 = j.saturating_sub(1).min(m - 4);
                let w6 = lagrange(&xn[first6..first6 + 6], xi);
                let w4 = lagrange(&xn[first4..first4 + 4], xi);
                let mut diff = w6.clone();
                for (s, w) in w4.iter().enumerate() {
                    diff[first4 - first6 + s] -= w;
                }
                let w6: [f64; 6] = w6.try_into().expect("six weights");
                let diff: [f64; 6] = diff.try_into().expect("six weights");
                (i, first6, w6, diff)
            })
            .collect();
        Some(Self {
            nodes,
            between,
            len: k.len(),
        })
    }

    /// The indices of the nodes in the grid.
    pub(crate) fn nodes(&self) -> &[usize] {
        &self.nodes
    }

    /// Values given at the nodes, `width` per node (node-major), at every grid point, and error
    /// estimates for the first `with_errors` of each point's `width` (zero at the nodes).
    pub(crate) fn interpolate(
        &self,
        at_nodes: &[f64],
        width: usize,
        with_errors: usize,
    ) -> (Vec<f64>, Vec<f64>) {
        let mut values = self.nodes_only(at_nodes, width);
        let mut errors = vec![0.0; self.len * with_errors];
        for (i, first, w, dw) in &self.between {
            let rows = &at_nodes[first * width..(first + 6) * width];
            let v = &mut values[i * width..(i + 1) * width];
            for (s, row) in rows.chunks_exact(width).enumerate() {
                v.iter_mut().zip(row).for_each(|(v, r)| *v += w[s] * r);
            }
            let e = &mut errors[i * with_errors..(i + 1) * with_errors];
            for (s, row) in rows.chunks_exact(width).enumerate() {
                e.iter_mut().zip(row).for_each(|(e, r)| *e += dw[s] * r);
            }
            e.iter_mut().for_each(|e| *e = 2.0 * e.abs());
        }
        (values, errors)
    }

    /// [`Self::interpolate`]'s values alone (a linear map: tangents go through it exactly).
    pub(crate) fn values(&self, at_nodes: &[f64], width: usize) -> Vec<f64> {
        self.interpolate(at_nodes, width, 0).0
    }

    /// Non-negative sizes (error bounds) given at the nodes, carried to every grid point with the
    /// weights' absolute values.
    pub(crate) fn sizes(&self, at_nodes: &[f64], width: usize) -> Vec<f64> {
        let mut out = self.nodes_only(at_nodes, width);
        for (i, first, w, _) in &self.between {
            let rows = &at_nodes[first * width..(first + 6) * width];
            let v = &mut out[i * width..(i + 1) * width];
            for (s, row) in rows.chunks_exact(width).enumerate() {
                v.iter_mut()
                    .zip(row)
                    .for_each(|(v, r)| *v += w[s].abs() * r);
            }
        }
        out
    }

    /// The node values in their places on the grid, zero between.
    fn nodes_only(&self, at_nodes: &[f64], width: usize) -> Vec<f64> {
        let mut out = vec![0.0; self.len * width];
        for (row, &i) in at_nodes.chunks_exact(width).zip(&self.nodes) {
            out[i * width..(i + 1) * width].copy_from_slice(row);
        }
        out
    }
}

/// The Lagrange weights of the nodes `x` at `at`.
fn lagrange(x: &[f64], at: f64) -> Vec<f64> {
    (0..x.len())
        .map(|a| {
            (0..x.len())
                .filter(|&b| b != a)
                .map(|b| (at - x[b]) / (x[a] - x[b]))
                .product()
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn grid(n: usize, per_decade: f64) -> Vec<f64> {
        (0..n)
            .map(|i| 0.003 * 10f64.powf(i as f64 / per_decade))
            .collect()
    }

    #[test]
    fn only_dense_log_uniform_grids_are_thinned() {
        assert!(Thinning::of(&grid(200, 100.0)).is_some());
        assert!(Thinning::of(&grid(200, 50.0)).is_none());
        assert!(Thinning::of(&grid(20, 100.0)).is_none());
        let mut uneven = grid(200, 100.0);
        uneven[100] *= 1.001;
        assert!(Thinning::of(&uneven).is_none());
    }

    /// Quintics in ln k are reproduced exactly with zero error estimate for cubics; nodes are kept
    /// exactly; an odd and an even number of points both end on a node.
    #[test]
    fn interpolation_is_exact_for_quintics_and_keeps_the_nodes() {
        for n in [201, 200] {
            let k = grid(n, 100.0);
            let t = Thinning::of(&k).unwrap();
            assert_eq!(*t.nodes().last().unwrap(), n - 1);
            let quintic = |k: f64| {
                let x = (k / 0.05).ln();
                1.0 - 0.3 * x + 0.2 * x.powi(3) - 0.05 * x.powi(5)
            };
            let cubic = |k: f64| 2.0 + (k / 0.05).ln().powi(3);
            // two columns per node
            let at_nodes: Vec<f64> = t
                .nodes()
                .iter()
                .flat_map(|&i| [quintic(k[i]), cubic(k[i])])
                .collect();
            let (v, e) = t.interpolate(&at_nodes, 2, 2);
            assert_eq!(t.values(&at_nodes, 2), v);
            for (i, &ki) in k.iter().enumerate() {
                let (q, c) = (quintic(ki), cubic(ki));
                assert!((v[2 * i] - q).abs() < 1e-12 * q.abs().max(1.0), "{i}");
                assert!((v[2 * i + 1] - c).abs() < 1e-12 * c.abs().max(1.0), "{i}");
                assert!(e[2 * i + 1] < 1e-12 * c.abs().max(1.0), "{i}");
            }
            for (j, &i) in t.nodes().iter().enumerate() {
                assert_eq!(v[2 * i], at_nodes[2 * j]);
                assert_eq!(e[2 * i], 0.0);
            }
        }
    }

    /// For a function beyond degree five, a P_lin-like wiggle of the BAO period, the error estimate
    /// exceeds the interpolant's actual error at every k ≤ 0.3 h/Mpc (≥ 4.5 nodes per period; above,
    /// a wiggle of P_lin's strength is under-resolved on the nodes, and the loop columns' own wiggles,
    /// weaker by orders of magnitude, are what the measured 8.9e-7 of the data vector bounds).
    #[test]
    fn the_error_estimate_covers_a_wiggle() {
        let k = grid(230, 100.0);
        let t = Thinning::of(&k).unwrap();
        let f = |k: f64| (k / 0.1).powf(-1.5) * (1.0 + 0.05 * (105.0 * k).sin());
        let at_nodes: Vec<f64> = t.nodes().iter().map(|&i| f(k[i])).collect();
        let (v, e) = t.interpolate(&at_nodes, 1, 1);
        let mut covered = 0;
        for (i, &ki) in k.iter().enumerate().filter(|(_, &k)| k <= 0.3) {
            let actual = (v[i] - f(ki)).abs();
            assert!(
                actual <= e[i] + 1e-15 * f(ki),
                "{i} k {ki}: {actual:e} > {:e}",
                e[i]
            );
            covered += usize::from(e[i] > 0.0);
        }
        assert!(covered > 80, "{covered}");
    }
}
