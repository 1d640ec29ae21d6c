//! Basis tensors in low-rank form, with a rigorous bound on what the truncation changes.
//!
//! The rows of a basis tensor (one per k and term) are linear forms on the products of the
//! coefficients s_j (c_a c_b on the pairs a ≤ b, or c_a c_b c_c on the triples): a matrix A of
//! rows × columns. Its rows are smooth in k and the terms are related, so A has a small numerical
//! rank: the galaxy model's 31 × 50 rows on 666 pairs need 160 directions (112 for the no-wiggle
//! set), the 2-loop means' 9 × 40 rows 192 of 8,436 triples. Then A s ≈ U (V s): r products of
//! length `columns` and `rows` of length r, a third to a half of the bytes and work of A s.
//!
//! The factorisation is made in scaled coordinates B = R⁻¹ A C, with C = diag(σ_a σ_b …) the
//! largest product of each column over the training spectra (σ_a = max |c_a|) and R =
//! diag(Σ_j |A_ij| C_jj) the size of each row, by a randomised range finder (blocks of random ±1
//! probes, each orthogonalised twice against those before) until the residual of every scaled row
//! is below a tolerance ([`PAIR_TOLERANCE`], [`TRIPLE_TOLERANCE`]). The residual of each row of
//! A − U V is then computed exactly with the rounded f32 factors, e_i = ‖(A − U V)_i C‖₂, so that by
//! Cauchy–Schwarz the truncation changes row i of any spectrum by at most e_i ‖s / C‖₂ ≤
//! e_i ‖c / σ‖₂^d (d = 2 for pairs, 3 for triples): a bound, not an estimate, which the callers add
//! to the errors. On held-out CAMB and CLASS tables it is ≤ 3e-5 of each galaxy-model column
//! (median 6e-7), against a projection error of ~1e-4.

use crate::linalg::dot;
use crate::simd::{dot32, matvec_f32};
use rand::Rng;
use rand::SeedableRng;
use rayon::prelude::*;

/// Residual (root mean square over the probes) of a scaled row, whose entries sum to 1 in absolute
/// value, at which the factorisation of pair tensors stops.
pub const PAIR_TOLERANCE: f64 = 1e-6;

/// The same for triple tensors (the 2-loop means): their rows spread over 8,436 columns, so each
/// entry and the residual are smaller for the same relative accuracy.
pub const TRIPLE_TOLERANCE: f64 = 1e-5;

/// Probes per block of the range finder.
const BLOCK: usize = 16;

/// A matrix of `rows` × `columns` as U V (module docs), with the bound of each row.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct LowRank {
    rows: usize,
    columns: usize,
    rank: usize,
    /// Degree of the products (2: pairs, 3: triples).
    degree: i32,
    /// σ_a: the largest |c_a| over the training spectra.
    sigma: Vec<f64>,
    /// Per row: e_i.
    bound: Vec<f64>,
    /// U, rows × rank.
    u: Vec<f32>,
    /// V, rank × columns.
    v: Vec<f32>,
}

impl LowRank {
    /// The low-rank form of `a` (`rows` × `columns`, by row) whose columns are the products of
    /// `degree` coefficients (pairs or triples of [`super::pair_index`], [`super::triple_index`])
    /// of spectra with |c_a| up to `sigma[a]`.
    pub(crate) fn new(a: &[f64], rows: usize, degree: i32, sigma: &[f64], tolerance: f64) -> Self {
        let columns = a.len() / rows.max(1);
        assert_eq!(rows * columns, a.len(), "a matrix of {rows} rows");
        let scale = column_scale(sigma, degree, columns);
        // B = R⁻¹ A C, each row of absolute sum 1 (or 0).
        let size: Vec<f64> = a
            .par_chunks_exact(columns)
            .map(|row| row.iter().zip(&scale).map(|(x, s)| (x * s).abs()).sum())
            .collect();
        let b: Vec<f64> = a
            .par_chunks_exact(columns)
            .zip(&size)
            .flat_map_iter(|(row, &r)| {
                let inv = if r > 0.0 { 1.0 / r } else { 0.0 };
                row.iter().zip(&scale).map(move |(x, s)| x * s * inv)
            })
            .collect();
        let q = range(&b, rows, columns, tolerance);
        let rank = q.len();
        // V = Qᵀ B, then the factors with R and C⁻¹ folded in, rounded to f32.
        let v: Vec<f32> = q
            .par_iter()
            .flat_map_iter(|qa| {
                let mut va = vec![0.0; columns];
                for (row, &x) in b.chunks_exact(columns).zip(qa) {
                    va.iter_mut().zip(row).for_each(|(v, y)| *v += x * y);
                }
                va.into_iter()
                    .zip(&scale)
                    .map(|(v, s)| if *s > 0.0 { (v / s) as f32 } else { 0.0 })
            })
            .collect();
        let u: Vec<f32> = (0..rows)
            .flat_map(|i| {
                let r = size[i];
                q.iter().map(move |qa| (r * qa[i]) as f32)
            })
            .collect();
        // The exact residual of each row with the rounded factors, in the scaled columns.
        let bound = (0..rows)
            .into_par_iter()
            .map(|i| {
                let mut rest = a[i * columns..(i + 1) * columns].to_vec();
                for (&uia, va) in u[i * rank..(i + 1) * rank]
                    .iter()
                    .zip(v.chunks_exact(columns))
                {
                    let uia = f64::from(uia);
                    rest.iter_mut()
                        .zip(va)
                        .for_each(|(r, &x)| *r -= uia * f64::from(x));
                }
                rest.iter()
                    .zip(&scale)
                    .map(|(r, s)| (r * s).powi(2))
                    .sum::<f64>()
                    .sqrt()
            })
            .collect();
        Self {
            rows,
            columns,
            rank,
            degree,
            sigma: sigma.to_vec(),
            bound,
            u,
            v,
        }
    }

    /// The number of rows.
    pub(crate) fn rows(&self) -> usize {
        self.rows
    }

    /// Whether the form is of a matrix of `rows` × `columns`.
    pub(crate) fn has_shape(&self, rows: usize, columns: usize) -> bool {
        (self.rows, self.columns) == (rows, columns)
    }

    /// The rank r.
    #[cfg(test)]
    pub(crate) fn rank(&self) -> usize {
        self.rank
    }

    /// U (V s) for the products `s`: the stored (f32) factors applied in f64 arithmetic ([`dot32`]),
    /// so that the result is a fixed linear map of `s` to f64 rounding: smooth in the spectrum, as
    /// the exact derivatives of the pipeline ([`crate::rsd::ept::tangent`]) and their finite-difference
    /// checks need (rounding `s` and V s to f32, as this once did, left ~1e-7 of noise on every term,
    /// which steps in the parameters of 1% turned into 1e-5 of a derivative).
    pub(crate) fn apply(&self, s: &[f64]) -> Vec<f64> {
        self.apply_many(std::slice::from_ref(&s.to_vec())).remove(0)
    }

    /// [`Self::apply`] of several product vectors, U read once for all (each row of U is applied to
    /// every z while it is in the cache: reading U bounds an application).
    pub(crate) fn apply_many(&self, s: &[Vec<f64>]) -> Vec<Vec<f64>> {
        let z: Vec<Vec<f64>> = s.iter().map(|s| self.reduce(s)).collect();
        let mut out = vec![vec![0.0; self.rows]; s.len()];
        for (o, z) in out.iter_mut().zip(&z) {
            crate::simd::matvec32(&self.u, z, o);
        }
        out
    }

    /// The tangents U (V s') of the pair products s = c_a c_b along every direction `dcs`, s' =
    /// c_a dc_b + dc_a c_b (pair tensors only): V s' = H dc with H = ∂(V s)/∂c, made once (its
    /// row r: H_b = Σ_a V_{r,(a,b)} c_a, the diagonal pair counted twice), so a direction costs a
    /// product of length n instead of V's columns; then U applied to all of them, each row of U
    /// read once and widened once per four directions (`simd::matvec32_many`).
    pub(crate) fn apply_pair_tangents(&self, c: &[f64], dcs: &[&[f64]]) -> Vec<Vec<f64>> {
        let n = c.len();
        assert!(
            self.degree == 2 && self.columns == n * (n + 1) / 2,
            "pair tangents of a form of {} columns for {n} coefficients",
            self.columns
        );
        let mut h = vec![0.0; n];
        let z: Vec<Vec<f64>> = {
            let mut z = vec![vec![0.0; self.rank]; dcs.len()];
            for (r, va) in self.v.chunks_exact(self.columns).enumerate() {
                h.fill(0.0);
                for b in 0..n {
                    let row = &va[super::pair_index(0, b)..=super::pair_index(b, b)];
                    // Σ_{a ≤ b} V_ab c_a into H_b, and V_ab c_b into every H_a (a = b twice)
                    h[b] += dot32(row, &c[..=b]);
                    for (ha, &v) in h[..=b].iter_mut().zip(row) {
                        *ha += f64::from(v) * c[b];
                    }
                }
                for (zj, dc) in z.iter_mut().zip(dcs) {
                    zj[r] = crate::linalg::dot(&h, dc);
                }
            }
            z
        };
        // four directions per pass, the last pass as many as remain (each direction's sums in the
        // same order whatever the pass: the same numbers for any set of directions)
        fn pass<const N: usize>(u: &[f32], rows: usize, z: &[Vec<f64>], out: &mut Vec<Vec<f64>>) {
            let mut many = std::array::from_fn(|_| vec![0.0; rows]);
            crate::simd::matvec32_many::<N>(u, std::array::from_fn(|q| z[q].as_slice()), &mut many);
            out.extend(many);
        }
        let mut out = Vec::with_capacity(z.len());
        for group in z.chunks(4) {
            match group.len() {
                4 => pass::<4>(&self.u, self.rows, group, &mut out),
                3 => pass::<3>(&self.u, self.rows, group, &mut out),
                2 => pass::<2>(&self.u, self.rows, group, &mut out),
                _ => pass::<1>(&self.u, self.rows, group, &mut out),
            }
        }
        out
    }

    /// V s for the products `s` in f64 (summed in f64, [`dot32`]).
    pub(crate) fn reduce(&self, s: &[f64]) -> Vec<f64> {
        let mut z = vec![0.0; self.rank];
        crate::simd::matvec32(&self.v, &s[..self.columns], &mut z);
        z
    }

    /// V s for the products `s` in f32, summed as [`dot_f32`] (32 partial sums in f32, then f64):
    /// for the 2-loop redshift-space means, whose 8,436 products per row make the f64
    /// [`reduce`](Self::reduce) bound by its arithmetic. On the held-out CAMB spectra the multipoles
    /// move by ≤ 3e-3 of their Monte Carlo error from the f64 sums and f32 deviations (this and the
    /// bfloat16 deviations of module `rsd_two_loop` together). Blocks of 64 rows of V in parallel.
    pub(crate) fn reduce_f32(&self, s: &[f32]) -> Vec<f64> {
        const BLOCK_ROWS: usize = 64;
        let mut z = vec![0.0; self.rank];
        let s = &s[..self.columns];
        z.par_chunks_mut(BLOCK_ROWS)
            .zip(self.v.par_chunks(BLOCK_ROWS * self.columns))
            .for_each(|(z, v)| matvec_f32(v, s, z));
        z
    }

    /// Row `i` of U (V s), from `z` = V s.
    #[inline]
    pub(crate) fn row(&self, i: usize, z: &[f64]) -> f64 {
        dot32(&self.u[i * self.rank..(i + 1) * self.rank], z)
    }

    /// ‖c/σ‖₂^d: the factor by which [`bound`](Self::bound) scales for coefficients `c`.
    pub(crate) fn norm(&self, c: &[f64]) -> f64 {
        let t = c
            .iter()
            .zip(&self.sigma)
            .map(|(c, s)| if *s > 0.0 { (c / s).powi(2) } else { 0.0 })
            .sum::<f64>()
            .sqrt();
        t.powi(self.degree)
    }

    /// The largest change of row `i` by the truncation for coefficients of [`norm`](Self::norm)
    /// `norm`.
    #[inline]
    pub(crate) fn bound(&self, i: usize, norm: f64) -> f64 {
        self.bound[i] * norm
    }

    /// The values for a cache file: rows, columns, rank, degree, σ, the bounds, U, V.
    pub(crate) fn to_f64s(&self) -> Vec<f64> {
        let mut out = vec![
            self.rows as f64,
            self.columns as f64,
            self.rank as f64,
            f64::from(self.degree),
            self.sigma.len() as f64,
        ];
        out.extend(&self.sigma);
        out.extend(&self.bound);
        out.extend(self.u.iter().map(|&x| f64::from(x)));
        out.extend(self.v.iter().map(|&x| f64::from(x)));
        out
    }

    /// The form from [`to_f64s`](Self::to_f64s) values (and the rest of the slice), if they fit.
    pub(crate) fn from_f64s(values: &[f64]) -> Option<(Self, &[f64])> {
        let head = values.get(..5)?;
        // Every size is at most the values the file holds (checked before any product is formed).
        let mut counts = head.iter().map(|&v| super::stored_count(v, values.len()));
        let [rows, columns, rank, degree, n] = std::array::from_fn(|_| counts.next().flatten());
        let [rows, columns, rank, degree, n] = [rows?, columns?, rank?, degree?, n?];
        let sizes = [n, rows, rows.checked_mul(rank)?, rank.checked_mul(columns)?];
        let total = sizes
            .iter()
            .try_fold(5_usize, |total, &size| total.checked_add(size))?;
        if values.len() < total || !(2..=3).contains(&degree) {
            return None;
        }
        let mut rest = &values[5..];
        let mut take = |len: usize| {
            let (part, r) = rest.split_at(len);
            rest = r;
            part
        };
        let sigma = take(n).to_vec();
        let bound = take(rows).to_vec();
        let single = |v: &[f64]| v.iter().map(|&x| x as f32).collect();
        let u = single(take(rows * rank));
        let v = single(take(rank * columns));
        let form = Self {
            rows,
            columns,
            rank,
            degree: degree as i32,
            sigma,
            bound,
            u,
            v,
        };
        Some((form, rest))
    }
}

/// C_jj: the product of σ over the coefficients of column j (pairs a ≤ b or triples a ≤ b ≤ c in
/// their storage order).
fn column_scale(sigma: &[f64], degree: i32, columns: usize) -> Vec<f64> {
    let n = sigma.len();
    let mut scale = Vec::with_capacity(columns);
    match degree {
        2 => {
            for b in 0..n {
                for a in 0..=b {
                    scale.push(sigma[a] * sigma[b]);
                }
            }
        }
        3 => {
            for c in 0..n {
                for b in 0..=c {
                    for a in 0..=b {
                        scale.push(sigma[a] * sigma[b] * sigma[c]);
                    }
                }
            }
        }
        _ => panic!("products of degree {degree}"),
    }
    assert_eq!(scale.len(), columns, "{columns} columns for {n} functions");
    scale
}

/// An orthonormal basis (columns of length `rows`) of the range of `b` to `tolerance`: blocks of
/// [`BLOCK`] images of random ±1 vectors, each orthogonalised twice against the basis so far; it
/// stops when a block's largest remainder is below the tolerance (for ±1 probes the expected
/// squared remainder is the squared Frobenius norm of the residual, which bounds every row's), or at
/// full rank.
fn range(b: &[f64], rows: usize, columns: usize, tolerance: f64) -> Vec<Vec<f64>> {
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(0x006c_6f77_7261_6e6b);
    let mut q: Vec<Vec<f64>> = Vec::new();
    let full = rows.min(columns);
    while q.len() < full {
        let probes: Vec<Vec<f64>> = (0..BLOCK)
            .map(|_| {
                (0..columns)
                    .map(|_| if rng.gen::<bool>() { 1.0 } else { -1.0 })
                    .collect()
            })
            .collect();
        let images: Vec<Vec<f64>> = probes
            .par_iter()
            .map(|w| b.chunks_exact(columns).map(|row| dot(row, w)).collect())
            .collect();
        // Orthogonal to the basis so far, each image is R ω of the residual R: its square at row i
        // averages ‖R_i‖² over the probes, the estimate the loop stops on (with a margin of 3 for
        // the spread of 16 probes).
        let images: Vec<Vec<f64>> = images
            .into_iter()
            .map(|mut y| {
                for _ in 0..2 {
                    for e in &q {
                        let d = dot(&y, e);
                        y.iter_mut().zip(e).for_each(|(x, e)| *x -= d * e);
                    }
                }
                y
            })
            .collect();
        let largest = (0..rows)
            .map(|i| images.iter().map(|y| y[i] * y[i]).sum::<f64>() / BLOCK as f64)
            .fold(0.0, f64::max)
            .sqrt();
        let before = q.len();
        for mut y in images {
            for _ in 0..2 {
                for e in &q[before..] {
                    let d = dot(&y, e);
                    y.iter_mut().zip(e).for_each(|(x, e)| *x -= d * e);
                }
            }
            let norm = dot(&y, &y).sqrt();
            // A remainder at round-off is in the span already.
            if norm > 1e-13 && q.len() < full {
                y.iter_mut().for_each(|x| *x /= norm);
                q.push(y);
            }
        }
        if 3.0 * largest < tolerance {
            break;
        }
    }
    q
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A smooth family of rows: row (k, m) = Σ_j f_m(k, j) on pairs, of small numerical rank.
    fn smooth(rows: usize, n: usize) -> Vec<f64> {
        let columns = n * (n + 1) / 2;
        (0..rows * columns)
            .map(|x| {
                let (i, j) = ((x / columns) as f64, (x % columns) as f64);
                (-(i / 40.0 - j / 300.0).powi(2)).exp() * (1.0 + 0.1 * (i * 0.37).sin())
            })
            .collect()
    }

    /// Per row of `a` (by row, the products `s` of the coefficients `c` as columns): the difference
    /// of the low-rank row from the exact one, the exact one, and the bound.
    fn against_exact(form: &LowRank, a: &[f64], s: &[f64], c: &[f64]) -> Vec<(f64, f64, f64)> {
        let z = form.reduce(s);
        let norm = form.norm(c);
        a.chunks_exact(s.len())
            .enumerate()
            .map(|(i, row)| {
                let exact: f64 = row.iter().zip(s).map(|(x, y)| x * y).sum();
                ((form.row(i, &z) - exact).abs(), exact, form.bound(i, norm))
            })
            .collect()
    }

    #[test]
    fn a_low_rank_form_is_within_its_bound_and_survives_its_file() {
        let n = 12;
        let rows = 120;
        let a = smooth(rows, n);
        let sigma: Vec<f64> = (0..n).map(|a| 1.0 / (1.0 + a as f64)).collect();
        let form = LowRank::new(&a, rows, 2, &sigma, PAIR_TOLERANCE);
        assert!(form.rank() < rows / 2, "rank {}", form.rank());
        // Coefficients of mixed signs up to 3σ: the exact contraction against the low-rank one.
        let c: Vec<f64> = sigma
            .iter()
            .enumerate()
            .map(|(i, s)| s * (3.0 * ((i * 7) as f64).sin()))
            .collect();
        let s = super::super::forms::pair_products(&c);
        let mut worst: f64 = 0.0;
        for (i, (diff, exact, bound)) in against_exact(&form, &a, &s, &c).into_iter().enumerate() {
            assert!(diff <= bound, "{i}: {diff:e}");
            worst = worst.max(diff / exact.abs());
        }
        assert!(worst < 1e-6, "{worst:e}");
        let v = form.to_f64s();
        let (back, rest) = LowRank::from_f64s(&v).unwrap();
        assert!(rest.is_empty());
        assert_eq!(back, form);
        assert!(LowRank::from_f64s(&v[..v.len() - 1]).is_none());
    }

    /// The tangents along five directions (one group of four and a short one) equal the form
    /// applied to the symmetric products c_a dc_b + dc_a c_b written out.
    #[test]
    fn pair_tangents_equal_the_form_on_the_symmetric_products() {
        let (rows, n) = (40, 9);
        let a = smooth(rows, n);
        let sigma = vec![1.0; n];
        let form = LowRank::new(&a, rows, 2, &sigma, PAIR_TOLERANCE);
        let c: Vec<f64> = (0..n).map(|a| 0.3 + (a as f64 * 0.7).sin()).collect();
        let dcs: Vec<Vec<f64>> = (0..5)
            .map(|j| (0..n).map(|a| ((a + 3 * j) as f64 * 0.45).cos()).collect())
            .collect();
        let products: Vec<Vec<f64>> = dcs
            .iter()
            .map(|dc| {
                let mut s = vec![0.0; n * (n + 1) / 2];
                for b in 0..n {
                    for a in 0..=b {
                        s[super::super::pair_index(a, b)] = c[a] * dc[b] + dc[a] * c[b];
                    }
                }
                s
            })
            .collect();
        let want = form.apply_many(&products);
        let refs: Vec<&[f64]> = dcs.iter().map(Vec::as_slice).collect();
        let got = form.apply_pair_tangents(&c, &refs);
        assert_eq!(got.len(), 5);
        let scale = want.iter().flatten().fold(0.0_f64, |m, v| m.max(v.abs()));
        for (g, w) in got.iter().flatten().zip(want.iter().flatten()) {
            assert!((g - w).abs() <= 1e-13 * scale, "{g} {w}");
        }
    }

    #[test]
    fn a_matrix_of_full_rank_is_kept_whole_and_triples_are_scaled() {
        // Random entries: no structure, so the rank is the number of rows, and the bound is at
        // round-off (the f32 factors).
        let n = 4;
        let columns = n * (n + 1) * (n + 2) / 6;
        let rows = 6;
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(3);
        let a: Vec<f64> = (0..rows * columns)
            .map(|_| rng.gen_range(-1.0..1.0))
            .collect();
        let form = LowRank::new(&a, rows, 3, &[1.0, 0.5, 0.25, 2.0], TRIPLE_TOLERANCE);
        assert_eq!(form.rank(), rows);
        let c = [0.3, -0.2, 0.1, 1.5];
        let s = super::super::triple_products(&c);
        for (i, (diff, _, bound)) in against_exact(&form, &a, &s, &c).into_iter().enumerate() {
            assert!(diff <= bound + 1e-15, "{i}: {diff:e}");
            assert!(diff < 1e-6, "{i}: {diff:e}");
        }
    }
}
