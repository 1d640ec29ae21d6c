//! Small dense linear algebra of the fits (the multipole fits, the counterterms of `2l-eft`): Cholesky
//! factors, triangular inverses, SPD solves.

use crate::error::{Error, Result};

/// Σ aᵢbᵢ over the common length, summed in order (the same rounding on every machine: the small
/// solves and fits); the loop integrals' long sums use the vectorised [`crate::simd::dot`].
pub(crate) fn dot(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}

/// Lower-triangular Cholesky factor of a symmetric positive-definite matrix, or `None` (also for NaN
/// or infinite pivots: huge elements overflow the sums).
pub(crate) fn cholesky(a: &[Vec<f64>]) -> Option<Vec<Vec<f64>>> {
    cholesky_pivot(a).ok()
}

/// As [`cholesky`], or the 0-based row and the value of the first pivot that is not finite and
/// positive.
pub(crate) fn cholesky_pivot(a: &[Vec<f64>]) -> std::result::Result<Vec<Vec<f64>>, (usize, f64)> {
    let n = a.len();
    let mut l = vec![vec![0.0; n]; n];
    for i in 0..n {
        for j in 0..=i {
            let s: f64 = (0..j).map(|m| l[i][m] * l[j][m]).sum();
            if i == j {
                let d = a[i][i] - s;
                if !(d > 0.0 && d.is_finite()) {
                    return Err((i, d));
                }
                l[i][i] = d.sqrt();
            } else {
                l[i][j] = (a[i][j] - s) / l[j][j];
            }
        }
    }
    Ok(l)
}

/// L⁻¹ for lower-triangular L (forward substitution on the identity).
#[allow(clippy::needless_range_loop)] // the triangular index ranges read as the algorithm
pub(crate) fn invert_lower(l: &[Vec<f64>]) -> Vec<Vec<f64>> {
    let n = l.len();
    let mut inv = vec![vec![0.0; n]; n];
    for c in 0..n {
        for i in c..n {
            let s: f64 = (c..i).map(|m| l[i][m] * inv[m][c]).sum();
            inv[i][c] = ((if i == c { 1.0 } else { 0.0 }) - s) / l[i][i];
        }
    }
    inv
}

/// Solves F a = b for symmetric positive definite F: (a, F⁻¹, ln det F).
pub(crate) fn solve_spd(f: &[Vec<f64>], b: &[f64]) -> Result<(Vec<f64>, Vec<Vec<f64>>, f64)> {
    let n = b.len();
    let l = cholesky(f).ok_or_else(|| Error::InvalidChoice {
        what: format!("the {n} marginalised (or free) parameters"),
        reason: "their templates are degenerate on the fitted data (give them priors, or fewer)"
            .into(),
    })?;
    let log_det = 2.0 * (0..n).map(|i| l[i][i].ln()).sum::<f64>();
    let solve = |rhs: &[f64]| {
        let mut y = vec![0.0; n];
        for i in 0..n {
            y[i] = (rhs[i] - (0..i).map(|j| l[i][j] * y[j]).sum::<f64>()) / l[i][i];
        }
        let mut x = vec![0.0; n];
        for i in (0..n).rev() {
            x[i] = (y[i] - (i + 1..n).map(|j| l[j][i] * x[j]).sum::<f64>()) / l[i][i];
        }
        x
    };
    let inverse = (0..n)
        .map(|i| {
            solve(
                &(0..n)
                    .map(|j| f64::from(u8::from(i == j)))
                    .collect::<Vec<_>>(),
            )
        })
        .collect();
    Ok((solve(b), inverse, log_det))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A 3×3 SPD matrix: L Lᵀ = A, L⁻¹ L = 1, the solve and ln det against hand values.
    #[test]
    fn factor_invert_and_solve() {
        let a = vec![
            vec![4.0, 2.0, 0.4],
            vec![2.0, 5.0, 1.0],
            vec![0.4, 1.0, 3.0],
        ];
        let l = cholesky(&a).unwrap();
        for i in 0..3 {
            for j in 0..3 {
                let v: f64 = (0..3).map(|m| l[i][m] * l[j][m]).sum();
                assert!((v - a[i][j]).abs() < 1e-14);
                let u: f64 = (0..3).map(|m| invert_lower(&l)[i][m] * l[m][j]).sum();
                assert!((u - f64::from(u8::from(i == j))).abs() < 1e-14);
            }
        }
        let (x, inv, log_det) = solve_spd(&a, &[1.0, 2.0, 3.0]).unwrap();
        for i in 0..3 {
            assert!((dot(&a[i], &x) - [1.0, 2.0, 3.0][i]).abs() < 1e-13);
            let e: f64 = (0..3).map(|m| a[i][m] * inv[m][i]).sum();
            assert!((e - 1.0).abs() < 1e-13);
        }
        // det A = 4(15 − 1) − 2(6 − 0.4) + 0.4(2 − 2) = 44.8.
        assert!((log_det - 44.8f64.ln()).abs() < 1e-13);
        assert!(cholesky(&[vec![1.0, 2.0], vec![2.0, 1.0]]).is_none());
        assert!(cholesky(&[vec![f64::NAN]]).is_none());
    }
}

/// The eigenpairs of the symmetric matrix `a` (rows) by cyclic Jacobi rotations, by decreasing
/// eigenvalue: (λ, unit eigenvector) (the SVD templates of the one-loop multipole tensors).
pub(crate) fn symmetric_eigen(a: &[Vec<f64>]) -> Vec<(f64, Vec<f64>)> {
    let n = a.len();
    let mut a = a.to_vec();
    let mut v: Vec<Vec<f64>> = (0..n)
        .map(|i| (0..n).map(|j| f64::from(u8::from(i == j))).collect())
        .collect();
    let scale: f64 = a.iter().flatten().map(|x| x * x).sum();
    for _sweep in 0..100 {
        let off: f64 = (0..n)
            .flat_map(|i| (0..n).filter(move |&j| j != i).map(move |j| (i, j)))
            .map(|(i, j)| a[i][j] * a[i][j])
            .sum();
        if off <= 1e-30 * scale {
            break;
        }
        for p in 0..n {
            for q in p + 1..n {
                if a[p][q] == 0.0 {
                    continue;
                }
                // the rotation in the (p, q) plane that zeroes a[p][q]
                let theta = (a[q][q] - a[p][p]) / (2.0 * a[p][q]);
                let t = theta.signum() / (theta.abs() + (theta * theta + 1.0).sqrt());
                let (c, s) = (1.0 / (t * t + 1.0).sqrt(), t / (t * t + 1.0).sqrt());
                for row in a.iter_mut().chain(v.iter_mut()) {
                    let (x, y) = (row[p], row[q]);
                    row[p] = c * x - s * y;
                    row[q] = s * x + c * y;
                }
                let (low, high) = a.split_at_mut(q);
                for (x, y) in low[p].iter_mut().zip(high[0].iter_mut()) {
                    (*x, *y) = (c * *x - s * *y, s * *x + c * *y);
                }
            }
        }
    }
    let mut out: Vec<(f64, Vec<f64>)> = (0..n)
        .map(|i| (a[i][i], v.iter().map(|row| row[i]).collect()))
        .collect();
    out.sort_by(|x, y| y.0.total_cmp(&x.0));
    out
}

#[cfg(test)]
mod eigen_tests {
    /// A u = λ u for every pair of a 5 × 5 symmetric matrix, and the eigenvalues of diag(3, 1, 2) in
    /// decreasing order.
    #[test]
    fn eigenpairs_satisfy_their_equation() {
        let a: Vec<Vec<f64>> = (0..5)
            .map(|i| {
                (0..5)
                    .map(|j| 1.0 / (1.0 + i as f64 + j as f64) + f64::from(u8::from(i == j)))
                    .collect()
            })
            .collect();
        for (lambda, u) in super::symmetric_eigen(&a) {
            for (row, ui) in a.iter().zip(&u) {
                let au: f64 = row.iter().zip(&u).map(|(x, y)| x * y).sum();
                assert!((au - lambda * ui).abs() < 1e-12, "{au} {lambda} {ui}");
            }
            assert!((u.iter().map(|x| x * x).sum::<f64>() - 1.0).abs() < 1e-12);
        }
        let d = vec![
            vec![3.0, 0.0, 0.0],
            vec![0.0, 1.0, 0.0],
            vec![0.0, 0.0, 2.0],
        ];
        let l: Vec<f64> = super::symmetric_eigen(&d).iter().map(|x| x.0).collect();
        assert_eq!(l, vec![3.0, 2.0, 1.0]);
    }
}
