//! The checks of a covariance matrix of a data vector before a fit inverts it: square and finite (by
//! the readers), symmetric, positive definite, not nearly degenerate, and no variance absurdly small
//! for the data it belongs to. A matrix that passes Cholesky but is nearly singular (two rows equal to
//! the digits a file keeps, one variance of 1e-10) gives a χ² whose minimum the minimiser does not
//! find and NaN errors, with exit 0: each is refused naming the origin, the row and the rule.
//!
//! Where: a file is checked when it is read ([`validate`]: finite, symmetric, positive definite, the
//! scale of each variance), and the degeneracy of the rows a fit inverts when the fit is set up
//! ([`check_conditioning`]: the fitted points only). A real covariance can be nearly degenerate in
//! points no fit uses: the BOSS DR12 SGC file's first bins (k < 0.005 h/Mpc, correlated 0.99 through the
//! small cap's window) make its ℓ = 0, 2 correlation matrix's condition number 2.0e7, while the fitted
//! points of any k_min ≥ 0.005 have ≤ 3e3. [`validate_whole`] applies every rule to the whole matrix
//! (Python's `check_covariance`).
//!
//! Bounds, and why:
//! * Symmetry: |C_ij − C_ji| ≤ [`SYMMETRY_TOLERANCE`] · √(C_ii C_jj). A matrix written with 6
//!   significant digits from a symmetric one that differs in its last bits (e.g. a sample covariance
//!   summed in another order) rounds the two halves apart by up to 1e-6 of the element; 1e-5 leaves
//!   room for that and refuses real asymmetry (a transposed block, a row of another matrix). The two
//!   halves are then averaged, so that no result depends on which half is read.
//! * Degeneracy: the condition number of the correlation matrix R = D^{-1/2} C D^{-1/2} (D the
//!   diagonal), which separates degeneracy from the scale of the blocks (the Patchy P+B covariance has
//!   cond C = 6e18 but cond R = 80), must not exceed [`MAX_CORRELATION_CONDITION`] = 1e6. Measured on
//!   the real covariances: BOSS DR12 CMASS NGC (MD-Patchy, 174 rows) 6.1e4 (the P0, P2 blocks 4.1e4,
//!   the fitted 72 rows 3.2e2); Patchy NGC z3 P+B (420 rows) 80, its P blocks 37; a sample covariance
//!   of 84 Nseries mocks for the 76 P0, P2 bins below k = 0.2: 1.7e3 (for all 234 bins it is singular).
//!   At 1e6 the smallest eigenvalue of R is at the level of the rounding of a file written with 6
//!   digits (5e-7 of each element), so C⁻¹ along it is set by the rounding, not by the measurement.
//! * Scale: every σ_i = √C_ii must be at least [`MIN_RELATIVE_ERROR`] = 1e-6 of the RMS of its
//!   multipole's data (the RMS, not the value, since P2 and P4 cross zero). The most precise
//!   measurements in use (the mean of 15000 Quijote boxes) have σ/P ~ 1e-4; a σ a million times below
//!   the data is a unit or column mistake (e.g. relative variances given as variances).

use crate::error::{number, Error, Result};
use crate::linalg::cholesky_pivot;

/// The largest |C_ij − C_ji| / √(C_ii C_jj) accepted (module docs).
pub const SYMMETRY_TOLERANCE: f64 = 1e-5;

/// The largest condition number of the correlation matrix accepted (module docs).
pub const MAX_CORRELATION_CONDITION: f64 = 1e6;

/// The smallest σ_i / RMS(data of its multipole) accepted (module docs).
pub const MIN_RELATIVE_ERROR: f64 = 1e-6;

/// Iterations of the power and inverse iterations that estimate the extreme eigenvalues of R: they
/// need the condition number to a factor of a few only (the bound is 16 times above the largest real
/// case and the faults are 1e10 above it).
const EIGEN_ITERATIONS: usize = 200;

/// Checks the square matrix `c` as the covariance of the data vector made of the blocks `values`
/// (ℓ-major: `values[j]` the data of multipole j): every element finite, the diagonal positive, then
/// the rules of the module docs but the condition number (a fit checks that on the points it fits:
/// [`check_conditioning`]). Returns it symmetrised. `origin` names it in messages and `lines[i]` the
/// line of row i (row numbers where `lines` is shorter).
///
/// # Errors
/// [`Error::LengthMismatch`] unless `c` is square and as long as the data vector; [`Error::BadRow`]
/// for a non-finite element; [`Error::InvalidValue`] for a diagonal element that is not positive; as
/// the symmetry and positive-definiteness checks of the module docs otherwise.
pub fn validate(
    c: Vec<Vec<f64>>,
    values: &[Vec<f64>],
    origin: &str,
    lines: &[usize],
) -> Result<Vec<Vec<f64>>> {
    let (c, _) = validate_rows(c, values, origin, lines)?;
    Ok(c)
}

/// [`validate`] and the condition number of the whole matrix ([`check_conditioning`]), the row of a
/// nearly singular matrix named by its line and its place (point, block) in the data vector.
///
/// # Errors
/// As [`validate`]; [`Error::BadRow`] for a condition number above [`MAX_CORRELATION_CONDITION`].
pub fn validate_whole(
    c: Vec<Vec<f64>>,
    values: &[Vec<f64>],
    origin: &str,
    lines: &[usize],
) -> Result<Vec<Vec<f64>>> {
    let (c, blocks) = validate_rows(c, values, origin, lines)?;
    if let Err((condition, row)) = conditioning(&c) {
        // where the row sits in the data vector: (block, point), 1-based
        let (mut block, mut point) = (0, row);
        while block < blocks.len() && point >= blocks[block] {
            point -= blocks[block];
            block += 1;
        }
        return Err(Error::BadRow {
            origin: origin.into(),
            line: lines.get(row).copied().unwrap_or(row + 1),
            problem: nearly_singular(
                condition,
                &format!(
                    "row {} (point {} of block {} of the data vector: the multipoles in order, then \
                     any statistic after them)",
                    row + 1,
                    point + 1,
                    block + 1
                ),
            ),
        });
    }
    Ok(c)
}

/// The message of a nearly singular matrix whose most degenerate direction weighs most on `row`.
fn nearly_singular(condition: f64, row: &str) -> String {
    format!(
        "the covariance is nearly singular: its correlation matrix has condition number {} > \
         {MAX_CORRELATION_CONDITION:e} (the real BOSS and Patchy covariances have ≤ 6.1e4 on their \
         fitted points); {row} weighs most on its most degenerate direction (two rows equal to the \
         digits written? a row of another matrix?)",
        number(&condition)
    )
}

/// Checks that the covariance `c` of the points a fit inverts (symmetric and positive definite: a
/// block of a matrix [`validate`] passed) is not nearly singular: the condition number of its
/// correlation matrix at most [`MAX_CORRELATION_CONDITION`] (module docs). `what` names the points
/// ("the 72 fitted points") and `row(i)` point i in the message (e.g. "P2 at k = 0.105 h/Mpc").
///
/// # Errors
/// [`Error::InvalidChoice`] naming the condition number, the bound and the row that weighs most on
/// the most degenerate direction.
pub fn check_conditioning(c: &[Vec<f64>], what: &str, row: &dyn Fn(usize) -> String) -> Result<()> {
    conditioning(c)
        .map(|_| ())
        .map_err(|(condition, i)| Error::InvalidChoice {
            what: format!("the covariance of {what}"),
            reason: nearly_singular(condition, &row(i)),
        })
}

/// The condition number of the correlation matrix of the SPD matrix `c` if within the bound, else
/// (it, the row of the largest component of the most degenerate direction); a matrix that is not
/// positive definite (a block of a checked one cannot be) is (NaN, its failing row).
fn conditioning(c: &[Vec<f64>]) -> std::result::Result<f64, (f64, usize)> {
    let r = correlation(c);
    let l = cholesky_pivot(&r).map_err(|(i, _)| (f64::NAN, i))?;
    let (condition, row) = correlation_condition(&r, &l);
    if condition.is_nan() || condition > MAX_CORRELATION_CONDITION {
        Err((condition, row))
    } else {
        Ok(condition)
    }
}

/// The correlation matrix R = D^{-1/2} C D^{-1/2} of `c` (D its diagonal).
fn correlation(c: &[Vec<f64>]) -> Vec<Vec<f64>> {
    let sigma: Vec<f64> = (0..c.len()).map(|i| c[i][i].sqrt()).collect();
    c.iter()
        .zip(&sigma)
        .map(|(row, si)| row.iter().zip(&sigma).map(|(x, sj)| x / si / sj).collect())
        .collect()
}

/// [`validate`]'s checks; also returns the blocks' lengths.
fn validate_rows(
    c: Vec<Vec<f64>>,
    values: &[Vec<f64>],
    origin: &str,
    lines: &[usize],
) -> Result<(Vec<Vec<f64>>, Vec<usize>)> {
    let n: usize = values.iter().map(Vec::len).sum();
    if c.len() != n || c.iter().any(|r| r.len() != n) {
        return Err(Error::LengthMismatch {
            what: "covariance rows and data vector",
            left: c.len(),
            right: n,
        });
    }
    let line = |i: usize| lines.get(i).copied().unwrap_or(i + 1);
    for (i, row) in c.iter().enumerate() {
        if let Some(j) = row.iter().position(|v| !v.is_finite()) {
            return Err(Error::BadRow {
                origin: origin.into(),
                line: line(i),
                problem: format!(
                    "covariance element ({}, {}) = {} is not finite (row, column 1-based)",
                    i + 1,
                    j + 1,
                    number(&row[j])
                ),
            });
        }
        // (Finite: checked above.)
        if row[i] <= 0.0 {
            return Err(Error::InvalidValue {
                origin: origin.into(),
                line: line(i),
                name: "covariance diagonal",
                value: row[i],
                reason: "must be finite and positive",
            });
        }
    }
    // The RMS of each multipole's data, per element of the data vector.
    let scale: Vec<f64> = values
        .iter()
        .flat_map(|v| std::iter::repeat_n(rms(v), v.len()))
        .collect();
    let blocks: Vec<usize> = values.iter().map(Vec::len).collect();
    Ok((check(c, &scale, origin, &line)?, blocks))
}

/// The root mean square of `v`, scaled by its largest |x| (the squares of values near f64::MAX would
/// overflow).
fn rms(v: &[f64]) -> f64 {
    let top = v.iter().fold(0.0f64, |m, x| m.max(x.abs()));
    if top > 0.0 {
        top * (v.iter().map(|x| (x / top).powi(2)).sum::<f64>() / v.len() as f64).sqrt()
    } else {
        0.0
    }
}

/// Checks the n×n matrix `c` (finite, as the readers ensure) as the covariance of a data vector whose
/// element i belongs to the multipole block with data RMS `scale[i]`; returns it symmetrised. `origin`
/// names it and `line(i)` the line of row i in messages.
///
/// # Errors
/// [`Error::BadRow`] naming the row (and column) and the rule: an asymmetric pair, a variance that is
/// not positive or too small for its data, or a row that makes the matrix not positive definite.
fn check(
    mut c: Vec<Vec<f64>>,
    scale: &[f64],
    origin: &str,
    line: &dyn Fn(usize) -> usize,
) -> Result<Vec<Vec<f64>>> {
    let n = c.len();
    let bad = |i: usize, problem: String| Error::BadRow {
        origin: origin.into(),
        line: line(i),
        problem,
    };
    for (i, row) in c.iter().enumerate() {
        let v = row[i];
        // (Not `v <= 0.0`: a NaN must be refused too.)
        if v.is_nan() || v <= 0.0 {
            return Err(bad(
                i,
                format!(
                    "covariance row {}: the variance {} must be positive",
                    i + 1,
                    number(&v)
                ),
            ));
        }
        if let Some(&s) = scale.get(i) {
            if v.sqrt() < MIN_RELATIVE_ERROR * s {
                return Err(bad(
                    i,
                    format!(
                        "covariance row {}: the variance {} (sigma {}) is below ({MIN_RELATIVE_ERROR:e})² \
                         of the square of its multipole's data (RMS {}): no measurement is that \
                         precise (relative variances given as variances? a unit mistake?)",
                        i + 1,
                        number(&v),
                        number(&v.sqrt()),
                        number(&s)
                    ),
                ));
            }
        }
    }
    for i in 0..n {
        for j in 0..i {
            // sqrt before the product: c_ii c_jj may overflow, and then any asymmetry would pass.
            let tolerance = SYMMETRY_TOLERANCE * c[i][i].sqrt() * c[j][j].sqrt();
            if (c[i][j] - c[j][i]).abs() > tolerance {
                return Err(bad(
                    i,
                    format!(
                        "covariance element ({}, {}) = {} differs from element ({}, {}) = {} by more \
                         than {SYMMETRY_TOLERANCE:e} of sqrt(C_ii C_jj): the matrix must be symmetric \
                         (row, column 1-based)",
                        i + 1,
                        j + 1,
                        number(&c[i][j]),
                        j + 1,
                        i + 1,
                        number(&c[j][i])
                    ),
                ));
            }
            let mean = 0.5 * c[i][j] + 0.5 * c[j][i];
            c[i][j] = mean;
            c[j][i] = mean;
        }
    }
    cholesky_pivot(&correlation(&c)).map_err(|(i, pivot)| {
        bad(
            i,
            format!(
                "the covariance is not positive definite: row {} is, to rounding, a combination of \
                 the rows before it (Cholesky pivot of the correlation matrix {} ≤ 0; a repeated \
                 or mistyped row or column?)",
                i + 1,
                number(&pivot)
            ),
        )
    })?;
    Ok(c)
}

/// An estimate of λ_max/λ_min of the SPD matrix `r` with Cholesky factor `l` (power iteration on r,
/// inverse iteration through l), and the row of the largest component of the λ_min eigenvector.
fn correlation_condition(r: &[Vec<f64>], l: &[Vec<f64>]) -> (f64, usize) {
    let n = r.len();
    let start = || -> Vec<f64> { (0..n).map(|i| 1.0 + 0.5 * (i as f64).sin()).collect() };
    let normalise = |x: &mut Vec<f64>| {
        let norm = x.iter().map(|v| v * v).sum::<f64>().sqrt();
        x.iter_mut().for_each(|v| *v /= norm);
        norm
    };
    let mut x = start();
    normalise(&mut x);
    let mut lambda_max = 0.0;
    for _ in 0..EIGEN_ITERATIONS {
        let mut y: Vec<f64> = r.iter().map(|row| crate::linalg::dot(row, &x)).collect();
        lambda_max = normalise(&mut y);
        x = y;
    }
    let mut x = start();
    normalise(&mut x);
    let mut inverse_min = 0.0;
    for _ in 0..EIGEN_ITERATIONS {
        // y = r⁻¹ x = L⁻ᵀ L⁻¹ x.
        let mut y = vec![0.0; n];
        for i in 0..n {
            y[i] = (x[i] - (0..i).map(|j| l[i][j] * y[j]).sum::<f64>()) / l[i][i];
        }
        for i in (0..n).rev() {
            y[i] = (y[i] - (i + 1..n).map(|j| l[j][i] * y[j]).sum::<f64>()) / l[i][i];
        }
        inverse_min = normalise(&mut y);
        x = y;
    }
    let row = (0..n)
        .max_by(|&a, &b| x[a].abs().total_cmp(&x[b].abs()))
        .unwrap_or(0);
    (lambda_max * inverse_min, row)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn line(i: usize) -> usize {
        i + 10
    }

    /// A smooth correlated covariance: C_ij = σ_i σ_j ρ^|i−j|.
    fn ar1(n: usize, rho: f64) -> Vec<Vec<f64>> {
        let s: Vec<f64> = (0..n).map(|i| 100.0 / (1.0 + i as f64)).collect();
        (0..n)
            .map(|i| {
                (0..n)
                    .map(|j| s[i] * s[j] * rho.powi((i as i32 - j as i32).abs()))
                    .collect()
            })
            .collect()
    }

    /// The condition number of R_ij = 0.9^|i−j| at n = 200: 354.4071342347946 by numpy's eigvalsh (it
    /// tends to (1 + ρ)²/(1 − ρ)² = 361 as n → ∞); the estimate finds it to 1% (measured: 0.4% low).
    #[test]
    fn condition_number_of_a_known_matrix() {
        let rho: f64 = 0.9;
        let c = ar1(200, rho);
        let s: Vec<f64> = (0..200).map(|i| c[i][i].sqrt()).collect();
        let r: Vec<Vec<f64>> = (0..200)
            .map(|i| (0..200).map(|j| c[i][j] / s[i] / s[j]).collect())
            .collect();
        let l = cholesky_pivot(&r).unwrap();
        let (cond, _) = correlation_condition(&r, &l);
        let want = 354.407_134_234_794_6;
        assert!((cond / want - 1.0).abs() < 0.01, "{cond} {want}");
        assert!(check(c.clone(), &[], "c", &line).is_ok());
        assert!(check_conditioning(&c, "c", &|i| format!("point {i}")).is_ok());
    }

    /// The faults: two rows equal to 6 digits, one variance of 1e-10, an asymmetric pair, a
    /// negative variance: each refused naming the row's line and the rule.
    #[test]
    fn faults_are_refused_naming_the_row_and_rule() {
        let base = ar1(30, 0.5);
        let six = |x: f64| format!("{x:.5e}").parse::<f64>().unwrap();
        // Row and column 8 (0-based 7) := 7 (0-based 6), written with 6 digits.
        let mut dup = base.clone();
        dup[7] = dup[6].clone();
        for row in dup.iter_mut() {
            row[7] = row[6];
        }
        let dup: Vec<Vec<f64>> = dup
            .iter()
            .map(|r| r.iter().map(|&x| six(x)).collect())
            .collect();
        // the whole matrix (Python's check_covariance): refused naming the line and the place in
        // the data vector (blocks of 20, 10)
        let values = [vec![1e3; 20], vec![1e3; 10]];
        let lines: Vec<usize> = (0..30).map(line).collect();
        let e = validate_whole(dup.clone(), &values, "cov.dat", &lines)
            .unwrap_err()
            .to_string();
        assert!(e.starts_with("cov.dat:1"), "{e}");
        assert!(
            (e.contains("row 8") || e.contains("row 7"))
                && (e.contains("condition number") || e.contains("positive definite")),
            "{e}"
        );
        if e.contains("condition number") {
            assert!(
                e.contains("point 8 of block 1") || e.contains("point 7 of block 1"),
                "{e}"
            );
            // read as a fit's file it passes; the fit's check of its points refuses it, naming
            // the point, unless the fit leaves one of the two rows out
            let c = validate(dup, &values, "cov.dat", &lines).unwrap();
            let e = check_conditioning(&c, "the 30 fitted points", &|i| format!("P0 point {i}"))
                .unwrap_err()
                .to_string();
            assert!(
                e.contains("the 30 fitted points")
                    && (e.contains("P0 point 7") || e.contains("P0 point 6"))
                    && e.contains("condition number"),
                "{e}"
            );
            let keep: Vec<usize> = (0..30).filter(|&i| i != 7).collect();
            let sub: Vec<Vec<f64>> = keep
                .iter()
                .map(|&i| keep.iter().map(|&j| c[i][j]).collect())
                .collect();
            assert!(check_conditioning(&sub, "29", &|i| i.to_string()).is_ok());
        }
        let mut tiny = base.clone();
        tiny[4] = vec![0.0; 30];
        for row in tiny.iter_mut() {
            row[4] = 0.0;
        }
        tiny[4][4] = 1e-10;
        let scale = vec![1e4; 30];
        let e = check(tiny, &scale, "cov.dat", &line)
            .unwrap_err()
            .to_string();
        assert!(
            e.starts_with("cov.dat:14:") && e.contains("row 5") && e.contains("1e-6"),
            "{e}"
        );
        let mut asym = base.clone();
        asym[3][1] *= 1.001;
        let e = check(asym, &[], "cov.dat", &line).unwrap_err().to_string();
        assert!(e.contains("(4, 2)") && e.contains("symmetric"), "{e}");
        let mut negative = base.clone();
        negative[2][2] = -1.0;
        let e = check(negative, &[], "cov.dat", &line)
            .unwrap_err()
            .to_string();
        assert!(
            e.starts_with("cov.dat:12:") && e.contains("positive"),
            "{e}"
        );
        // Rounding to 6 digits of a valid matrix leaves it valid, and symmetrised.
        let mut rounded: Vec<Vec<f64>> = base
            .iter()
            .map(|r| r.iter().map(|&x| six(x)).collect())
            .collect();
        rounded[5][2] = rounded[2][5] * (1.0 + 2e-6);
        let c = check(rounded, &scale, "cov.dat", &line).unwrap();
        assert_eq!(c[5][2], c[2][5]);
    }
}
