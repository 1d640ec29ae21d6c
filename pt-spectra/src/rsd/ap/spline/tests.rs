use super::*;
use crate::integrate::lagrange4;
use crate::linear::LinearSpectrum;
use crate::rsd::ap::Distortion;

/// The spline of one column `y` at grid position u, and its derivative in u.
fn eval(spline: &UniformSpline, c: &[[f64; 1]], u: f64) -> (f64, f64) {
    let (b, t) = spline.cell(u).expect("inside the evaluation range");
    let (w, dw) = (weights(t), weights_derivative(t));
    (0..4).fold((0.0, 0.0), |(v, d), j| {
        (v + w[j] * c[b + j][0], d + dw[j] * c[b + j][0])
    })
}

fn coefficients(y: &[f64]) -> (UniformSpline, Vec<[f64; 1]>) {
    let spline = UniformSpline::new(y.len());
    let mut c: Vec<[f64; 1]> = y.iter().map(|&v| [v]).collect();
    spline.prefilter(&mut c);
    (spline, c)
}

/// The BAO-wiggled linear spectrum (the embedded CAMB table) on the internal grid of a BOSS-like
/// output (0.015 … 0.38 h/Mpc) over the fits' AP range, and the grid's ln k_0 and step.
fn camb_column() -> (Vec<f64>, Vec<f64>, f64, f64) {
    let p = LinearSpectrum::gm2012(0.5).unwrap();
    let k: Vec<f64> = (0..38)
        .map(|i| 0.015 * (0.38f64 / 0.015).powf(i as f64 / 37.0))
        .collect();
    let grid = Distortion::new(1.25, 0.8)
        .unwrap()
        .internal_grid(&k)
        .unwrap();
    let n = grid.len();
    let (x0, step) = (grid[0].ln(), (grid[n - 1] / grid[0]).ln() / (n - 1) as f64);
    let y = grid.iter().map(|&k| p.eval(k)).collect();
    (grid, y, x0, step)
}

/// A cubic in u is reproduced exactly in every cell, the end cells (not-a-knot) included, with its
/// derivative, on grids of 4 points (one cubic: the spline is the Lagrange interpolant) and more.
#[test]
fn a_cubic_is_reproduced_exactly() {
    let cubic = |u: f64| 2.0 - 3.0 * u + 0.7 * u * u - 0.05 * u * u * u;
    let slope = |u: f64| -3.0 + 1.4 * u - 0.15 * u * u;
    for n in [4, 5, 6, 7, 12, 40] {
        let y: Vec<f64> = (0..n).map(|i| cubic(i as f64)).collect();
        let (spline, c) = coefficients(&y);
        let scale = y.iter().fold(0.0_f64, |m, v| m.max(v.abs()));
        for s in 0..=40 * (n - 3) {
            let u = 1.0 + s as f64 / 40.0;
            let (v, d) = eval(&spline, &c, u);
            assert!(
                (v - cubic(u)).abs() < 1e-13 * scale,
                "n {n} u {u}: {v} {}",
                cubic(u)
            );
            assert!(
                (d - slope(u)).abs() < 1e-13 * scale,
                "n {n} u {u}: {d} {}",
                slope(u)
            );
        }
        if n == 4 {
            let l = lagrange4(1.5);
            let lagrange: f64 = (0..4).map(|j| l[j] * y[j]).sum();
            assert!((eval(&spline, &c, 1.5).0 - lagrange).abs() < 1e-13 * scale);
        }
    }
}

/// The spline interpolates: at every grid point of the evaluation range its value is the sample (a
/// wiggly column, and the same at both cells' ends of an inner grid point).
#[test]
fn the_spline_goes_through_the_samples() {
    let (_, y, _, _) = camb_column();
    let (spline, c) = coefficients(&y);
    let n = y.len();
    let scale = y.iter().fold(0.0_f64, |m, v| m.max(v.abs()));
    for (i, &yi) in y.iter().enumerate().take(n - 1).skip(1) {
        let (v, _) = eval(&spline, &c, i as f64);
        assert!((v - yi).abs() < 1e-13 * scale, "{i}: {v} {yi}");
    }
}

/// The point of the spline (issue 47): its derivative in ln k is continuous across every cell edge
/// (the left and right limits, from the two cells' weights, agree to rounding), so the exact AP
/// derivatives agree with differences that straddle an edge. The four-point Lagrange stencil it
/// replaced has jumps there of ~1e-4 of the derivative's scale on the same wiggly column.
#[test]
fn the_derivative_is_continuous_across_cell_edges() {
    let (_, y, _, _) = camb_column();
    let (_, c) = coefficients(&y);
    let n = y.len();
    // one-sided limits at grid point j from the cell on its left (t = 1) and on its right (t = 0)
    let limits = |j: usize| {
        let side = |b: usize, t: f64| -> [f64; 2] {
            let (w, dw) = (
                weights_derivative(t),
                [1.0 - t, 3.0 * t - 2.0, 1.0 - 3.0 * t, t],
            );
            [0, 1].map(|o| (0..4).map(|q| [w, dw][o][q] * c[b + q][0]).sum())
        };
        (side(j - 2, 1.0), side(j - 1, 0.0))
    };
    let mut scale = [0.0_f64; 2];
    for j in 2..n - 2 {
        let (left, _) = limits(j);
        scale = [0, 1].map(|o| scale[o].max(left[o].abs()));
    }
    let mut lagrange_jump = 0.0_f64;
    for j in 2..n - 2 {
        let (left, right) = limits(j);
        // the second derivative (of size Δ²P″ against coefficients of size P) to the rounding of
        // its sum of four
        for (o, tolerance) in [1e-12, 1e-10].into_iter().enumerate() {
            assert!(
                (left[o] - right[o]).abs() < tolerance * scale[o],
                "derivative {} at {j}: {} {}",
                o + 1,
                left[o],
                right[o]
            );
        }
        // Lagrange's stencils of the cells left (points j−2 … j+1, t = 2) and right (j−1 … j+2, t = 1)
        if j + 2 < n {
            let d = |b: usize, t: f64| -> f64 {
                let h = 1e-4;
                let (a, z) = (lagrange4(t + h), lagrange4(t - h));
                (0..4).map(|q| (a[q] - z[q]) / (2.0 * h) * y[b + q]).sum()
            };
            lagrange_jump = lagrange_jump.max((d(j - 2, 2.0) - d(j - 1, 1.0)).abs() / scale[0]);
        }
    }
    eprintln!("the Lagrange stencil's largest derivative jump: {lagrange_jump:e}");
    assert!(lagrange_jump > 1e-6, "{lagrange_jump:e}");
}

/// On the wiggly linear spectrum (the embedded CAMB table, BAO included) at the middle of every cell
/// of the evaluation range, the spline is at least twice as accurate as the four-point Lagrange
/// interpolant it replaced.
#[test]
fn the_spline_is_as_accurate_as_lagrange_on_a_camb_spectrum() {
    let p = LinearSpectrum::gm2012(0.5).unwrap();
    let (_, y, x0, step) = camb_column();
    let (spline, c) = coefficients(&y);
    let n = y.len();
    let (mut worst_spline, mut worst_lagrange) = (0.0_f64, 0.0_f64);
    for j in 1..n - 2 {
        let u = j as f64 + 0.5;
        let truth = p.eval((x0 + u * step).exp());
        let (v, _) = eval(&spline, &c, u);
        let b = (j - 1).min(n - 4);
        let l = lagrange4(u - b as f64);
        let lagrange: f64 = (0..4).map(|q| l[q] * y[b + q]).sum();
        worst_spline = worst_spline.max((v / truth - 1.0).abs());
        worst_lagrange = worst_lagrange.max((lagrange / truth - 1.0).abs());
    }
    // measured: spline 2.4e-5, Lagrange 7.3e-5 (the BAO wiggles, (Δω)⁴/384 of their amplitude)
    eprintln!("mid-cell relative error: spline {worst_spline:e}, Lagrange {worst_lagrange:e}");
    assert!(
        worst_spline <= 0.5 * worst_lagrange,
        "{worst_spline:e} {worst_lagrange:e}"
    );
    assert!(worst_spline < 3e-5, "{worst_spline:e}");
}
