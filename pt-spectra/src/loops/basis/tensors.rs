//! Accumulating the 2-loop mode-coupling integral on a basis: one pass over the quasi-Monte-Carlo
//! points of a k and a random shift adds, at every point, the integrand's coefficients times every
//! product of basis functions φ_a(q₁)φ_b(q₂)φ_c(z) of its legs ([`point_legs`]).
//!
//! The integrand is P(q₁)P(q₂)Σ_t C_t P(z_t), so with P = Σ c_a φ_a it is
//! Σ_{a,b,c} c_a c_b c_c L_ab R_c, L_ab = φ_a(q₁)φ_b(q₂), R_c = Σ_t C_t φ_c(z_t). Only the fully
//! symmetrised tensor matters (it is contracted with c ⊗ c ⊗ c), so L is kept for a ≤ b
//! (φ_a(q₁)φ_b(q₂) + φ_b(q₁)φ_a(q₂)) and the result is folded onto a ≤ b ≤ c at the end. Points are
//! added in batches (a rank-B update of the (ab, c) matrix, each row kept in cache across the batch).

use super::{pair_index, triple_index, LinearBasis};
use crate::loops::mode_coupling::{point_legs, Sampler, ACC};

/// Points per batch of the rank-B update.
const BATCH: usize = 32;

/// The sum over `points` (moved by `shift`) at `k` of the integrand's basis tensor, for the [`ACC`]
/// quantities: `[quantity][triple_index(a, b, c)]` with a ≤ b ≤ c, weighted so that contracting with
/// c_a c_b c_c gives the sum of the integrand (times the sampling Jacobians) for P = Σ c_a φ_a.
/// `tick(points)` is called after each batch.
pub(super) fn shifted_tensor(
    k: f64,
    shift: &[f64; 5],
    points: &[[f64; 5]],
    basis: &LinearBasis,
    ln_range: (f64, f64),
    radial_width: f64,
    tick: &dyn Fn(usize),
) -> Vec<f64> {
    let n = basis.len();
    let pairs = n * (n + 1) / 2;
    let row = ACC * n;
    // (ab) × (quantity, c), accumulated over all points.
    let mut acc = vec![0.0; pairs * row];
    let mut left = vec![0.0; BATCH * pairs];
    let mut right = vec![0.0; BATCH * row];
    let (mut phi1, mut phi2, mut phiz) = (vec![0.0; n], vec![0.0; n], vec![0.0; n]);
    let sampler = Sampler::new(k, ln_range, radial_width);
    for chunk in points.chunks(BATCH) {
        for (p, raw) in chunk.iter().enumerate() {
            let point = sampler.point(raw, shift);
            let legs = point_legs(k, &point);
            basis.at_ln(point.ln_q[0], &mut phi1);
            basis.at_ln(point.ln_q[1], &mut phi2);
            let l = &mut left[p * pairs..(p + 1) * pairs];
            for b in 0..n {
                for a in 0..b {
                    l[pair_index(a, b)] = phi1[a] * phi2[b] + phi1[b] * phi2[a];
                }
                l[pair_index(b, b)] = phi1[b] * phi2[b];
            }
            let r = &mut right[p * row..(p + 1) * row];
            r.iter_mut().for_each(|x| *x = 0.0);
            for leg in &legs.legs {
                if leg.coef.iter().all(|&c| c == 0.0) {
                    continue;
                }
                basis.at_ln(leg.ln_z, &mut phiz);
                for (v, &c) in leg.coef.iter().enumerate() {
                    if c != 0.0 {
                        let c = c * point.jacobian;
                        let rv = &mut r[v * n..(v + 1) * n];
                        rv.iter_mut().zip(&phiz).for_each(|(x, z)| *x += c * z);
                    }
                }
            }
        }
        let used = chunk.len();
        rank_update(&mut acc, &left, &right, used, pairs, row);
        tick(used);
    }
    fold(&acc, n, ACC)
}

/// acc[i][j] += Σ_{p < used} left[p][i] right[p][j] for the (`rows` × `cols`) matrix `acc`: blocks of
/// 4 × 4 entries kept in (eight SSE2) registers across the points, 4 + 4 loads per 16 multiply-adds
/// (4 × 8 blocks spill to the stack).
pub(super) fn rank_update(
    acc: &mut [f64],
    left: &[f64],
    right: &[f64],
    used: usize,
    rows: usize,
    cols: usize,
) {
    const R: usize = 4;
    const C: usize = 4;
    let (full_rows, full_cols) = (rows - rows % R, cols - cols % C);
    for i0 in (0..full_rows).step_by(R) {
        for j0 in (0..full_cols).step_by(C) {
            let mut block = [[0.0; C]; R];
            for p in 0..used {
                let l = &left[p * rows + i0..][..R];
                let r = &right[p * cols + j0..][..C];
                for (b, &li) in block.iter_mut().zip(l) {
                    for (x, &rj) in b.iter_mut().zip(r) {
                        *x += li * rj;
                    }
                }
            }
            for (i, b) in block.iter().enumerate() {
                let out = &mut acc[(i0 + i) * cols + j0..][..C];
                out.iter_mut().zip(b).for_each(|(o, x)| *o += x);
            }
        }
    }
    // The remainder rows and columns one entry at a time.
    for i in 0..rows {
        let cols_from = if i < full_rows { full_cols } else { 0 };
        for j in cols_from..cols {
            let s: f64 = (0..used)
                .map(|p| left[p * rows + i] * right[p * cols + j])
                .sum();
            acc[i * cols + j] += s;
        }
    }
}

/// The (ab, quantity, c) sums of `quantities` quantities folded onto the symmetric
/// [quantity][a ≤ b ≤ c] tensor.
pub(super) fn fold(acc: &[f64], n: usize, quantities: usize) -> Vec<f64> {
    let triples = n * (n + 1) * (n + 2) / 6;
    let mut out = vec![0.0; quantities * triples];
    for b in 0..n {
        for a in 0..=b {
            let row = &acc[pair_index(a, b) * quantities * n..][..quantities * n];
            for c in 0..n {
                let mut s = [a, b, c];
                s.sort_unstable();
                let t = triple_index(s[0], s[1], s[2]);
                for v in 0..quantities {
                    out[v * triples + t] += row[v * n + c];
                }
            }
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_blocked_rank_update_is_the_matrix_product() {
        // 6 × 11 (remainders in both directions) from 5 points, against the plain triple loop.
        let (rows, cols, used) = (6, 11, 5);
        let left: Vec<f64> = (0..used * rows).map(|i| (i as f64 * 0.37).sin()).collect();
        let right: Vec<f64> = (0..used * cols).map(|i| (i as f64 * 0.71).cos()).collect();
        let mut acc = vec![1.0; rows * cols];
        rank_update(&mut acc, &left, &right, used, rows, cols);
        for i in 0..rows {
            for j in 0..cols {
                let s: f64 = (0..used)
                    .map(|p| left[p * rows + i] * right[p * cols + j])
                    .sum();
                assert!((acc[i * cols + j] - 1.0 - s).abs() < 1e-14, "{i} {j}");
            }
        }
    }
}
