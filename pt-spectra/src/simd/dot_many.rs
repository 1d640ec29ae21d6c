//! Several dot products of one f32 row with f64 vectors: the low-rank tensors' U applied to the
//! reduced products of several directions at once ([`crate::loops::basis::low_rank`]), each entry of
//! the row widened to f64 once for all of them.

/// Σ_i a_i b_q,i for each of the `N` vectors `b` (each at least as long as `a`), summed in f64; each
/// sum in the same order whatever N (the same numbers to the bit).
pub(crate) fn dot32_many<const N: usize>(a: &[f32], b: [&[f64]; N]) -> [f64; N] {
    let n = a.len();
    assert!(
        b.iter().all(|b| b.len() >= n),
        "vectors shorter than the row"
    );
    #[cfg(target_arch = "x86_64")]
    if let Some(simd) = pulp::x86::V3::try_new() {
        return simd.vectorize(|| dot32_many_v3(simd, a, b.map(|b| &b[..n])));
    }
    b.map(|b| a.iter().zip(b).map(|(x, y)| f64::from(*x) * y).sum::<f64>())
}

/// [`dot32_many`] with AVX2 and FMA: four entries of the row widened once per N products.
#[cfg(target_arch = "x86_64")]
#[inline(always)]
fn dot32_many_v3<const N: usize>(simd: pulp::x86::V3, a: &[f32], b: [&[f64]; N]) -> [f64; N] {
    use pulp::{f32x4, f64x4};
    let (a4, a_rest) = pulp::as_arrays::<4, _>(a);
    let chunks = b.map(|b| pulp::as_arrays::<4, _>(b).0);
    let mut acc = [simd.splat_f64x4(0.0); N];
    for (c, x) in a4.iter().enumerate() {
        let x: f32x4 = pulp::cast(*x);
        let x = simd.convert_f32x4_to_f64x4(x);
        for q in 0..N {
            let y: f64x4 = pulp::cast(chunks[q][c]);
            acc[q] = simd.mul_add_f64x4(x, y, acc[q]);
        }
    }
    let head = a4.len() * 4;
    std::array::from_fn(|q| {
        let s: [f64; 4] = pulp::cast(acc[q]);
        let tail: f64 = a_rest
            .iter()
            .zip(&b[q][head..])
            .map(|(x, y)| f64::from(*x) * y)
            .sum();
        (s[0] + s[1]) + (s[2] + s[3]) + tail
    })
}

/// `out[i]` = [`super::dot32`] of row i of the f32 matrix `a` (rows of `x.len()`) with `x`, to the
/// bit, with one dispatch for all rows: the low-rank tensors' U applied to one reduced vector, whose
/// rows are short (the rank), so that a dispatch and a call per row cost as much as the row.
pub(crate) fn matvec32(a: &[f32], x: &[f64], out: &mut [f64]) {
    let n = x.len();
    assert!(a.len() >= n * out.len(), "a matrix of {} rows", out.len());
    if n == 0 {
        out.iter_mut().for_each(|o| *o = 0.0);
        return;
    }
    #[cfg(target_arch = "x86_64")]
    if let Some(simd) = pulp::x86::V3::try_new() {
        return simd.vectorize(MatVec32 { simd, a, x, out });
    }
    for (o, row) in out.iter_mut().zip(a.chunks_exact(n)) {
        *o = super::dot32(row, x);
    }
}

/// [`matvec32`] with AVX2 and FMA: a type rather than a closure, so that the loop over rows is
/// compiled inside the dispatch (as `super::MatVecV3`).
#[cfg(target_arch = "x86_64")]
struct MatVec32<'a> {
    simd: pulp::x86::V3,
    a: &'a [f32],
    x: &'a [f64],
    out: &'a mut [f64],
}

#[cfg(target_arch = "x86_64")]
impl pulp::NullaryFnOnce for MatVec32<'_> {
    type Output = ();

    #[inline(always)]
    fn call(self) {
        let n = self.x.len();
        let full = self.out.len() / 4 * 4;
        let (head, rest) = self.out.split_at_mut(full);
        for (i, o) in head.chunks_exact_mut(4).enumerate() {
            let a = &self.a[4 * i * n..4 * (i + 1) * n];
            let four = std::array::from_fn(|q| &a[q * n..(q + 1) * n]);
            o.copy_from_slice(&dot32_rows_four_v3(self.simd, four, self.x));
        }
        for (j, o) in rest.iter_mut().enumerate() {
            let r = full + j;
            *o = super::dot32_v3(self.simd, &self.a[r * n..(r + 1) * n], self.x);
        }
    }
}

/// [`super::dot32`] of four rows with one vector, each row's sums in [`super::dot32_v3`]'s order (the
/// same numbers to the bit), the vector's entries loaded once for the four: short rows (a low-rank
/// tensor's rank) spend as much on a row's loop and final sums as on its products.
#[cfg(target_arch = "x86_64")]
#[inline(always)]
fn dot32_rows_four_v3(simd: pulp::x86::V3, a: [&[f32]; 4], b: &[f64]) -> [f64; 4] {
    use pulp::{f32x4, f64x4};
    let (b8, b_rest) = pulp::as_arrays::<8, _>(b);
    let a8 = a.map(|a| pulp::as_arrays::<8, _>(a).0);
    let mut acc = [[simd.splat_f64x4(0.0); 2]; 4];
    for (c, y) in b8.iter().enumerate() {
        for h in 0..2 {
            let y: f64x4 = pulp::cast([y[4 * h], y[4 * h + 1], y[4 * h + 2], y[4 * h + 3]]);
            for q in 0..4 {
                let x = &a8[q][c];
                let x: f32x4 = pulp::cast([x[4 * h], x[4 * h + 1], x[4 * h + 2], x[4 * h + 3]]);
                acc[q][h] = simd.mul_add_f64x4(simd.convert_f32x4_to_f64x4(x), y, acc[q][h]);
            }
        }
    }
    let head = b8.len() * 8;
    std::array::from_fn(|q| {
        let s: [f64; 4] = pulp::cast(simd.add_f64x4(acc[q][0], acc[q][1]));
        let tail: f64 = a[q][head..]
            .iter()
            .zip(b_rest)
            .map(|(x, y)| f64::from(*x) * y)
            .sum();
        (s[0] + s[1]) + (s[2] + s[3]) + tail
    })
}

/// `out[q][i]` = [`dot32_many`] of row i of `a` (rows of the vectors' length) with the `N` vectors `b`,
/// to the bit, with one dispatch for all rows and each row widened once for all N.
pub(crate) fn matvec32_many<const N: usize>(a: &[f32], b: [&[f64]; N], out: &mut [Vec<f64>; N]) {
    let n = b.first().map_or(0, |b| b.len());
    assert!(
        b.iter().all(|b| b.len() == n) && out.iter().all(|o| a.len() >= n * o.len()),
        "vectors of one length and a matrix of their rows"
    );
    if n == 0 {
        out.iter_mut().flatten().for_each(|o| *o = 0.0);
        return;
    }
    #[cfg(target_arch = "x86_64")]
    if let Some(simd) = pulp::x86::V3::try_new() {
        return simd.vectorize(MatVec32Many { simd, a, b, out });
    }
    for (i, row) in a.chunks_exact(n).take(out[0].len()).enumerate() {
        for (o, d) in out.iter_mut().zip(dot32_many(row, b)) {
            o[i] = d;
        }
    }
}

/// [`matvec32_many`] with AVX2 and FMA (as [`MatVec32`]).
#[cfg(target_arch = "x86_64")]
struct MatVec32Many<'a, const N: usize> {
    simd: pulp::x86::V3,
    a: &'a [f32],
    b: [&'a [f64]; N],
    out: &'a mut [Vec<f64>; N],
}

#[cfg(target_arch = "x86_64")]
impl<const N: usize> pulp::NullaryFnOnce for MatVec32Many<'_, N> {
    type Output = ();

    #[inline(always)]
    fn call(self) {
        let n = self.b[0].len();
        for (i, row) in self.a.chunks_exact(n).take(self.out[0].len()).enumerate() {
            let d = dot32_many_v3(self.simd, row, self.b);
            for (o, d) in self.out.iter_mut().zip(d) {
                o[i] = d;
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The matrix–vector products are the row-by-row dot products to the bit.
    #[test]
    fn matrix_products_are_the_dot_products() {
        for n in [0, 3, 37, 160] {
            let rows = 5;
            let a: Vec<f32> = (0..n * rows).map(|i| (i as f32 * 0.37).sin()).collect();
            let b: Vec<Vec<f64>> = (0..4)
                .map(|q| (0..n).map(|i| ((i + 7 * q) as f64 * 0.11).cos()).collect())
                .collect();
            let mut one = vec![1.0; rows];
            matvec32(&a, &b[0], &mut one);
            let mut four = std::array::from_fn(|_| vec![1.0; rows]);
            matvec32_many(&a, [&b[0], &b[1], &b[2], &b[3]], &mut four);
            let mut two = std::array::from_fn(|_| vec![1.0; rows]);
            matvec32_many(&a, [&b[2], &b[3]], &mut two);
            let mut single = [vec![1.0; rows]];
            matvec32_many(&a, [&b[1]], &mut single);
            for i in 0..rows {
                let row = &a[i * n..(i + 1) * n];
                assert_eq!(one[i].to_bits(), super::super::dot32(row, &b[0]).to_bits());
                let d = dot32_many(row, [&b[0], &b[1], &b[2], &b[3]]);
                for q in 0..4 {
                    assert_eq!(four[q][i].to_bits(), d[q].to_bits(), "{n} {i} {q}");
                }
                // each sum in the same order whatever the number of vectors
                assert_eq!(two[0][i].to_bits(), d[2].to_bits());
                assert_eq!(two[1][i].to_bits(), d[3].to_bits());
                assert_eq!(single[0][i].to_bits(), d[1].to_bits());
            }
        }
    }

    /// Against the plain sums, at lengths with and without a tail.
    #[test]
    fn four_dots_equal_the_plain_sums() {
        for n in [0, 3, 4, 37, 160] {
            let a: Vec<f32> = (0..n).map(|i| (i as f32 * 0.37).sin()).collect();
            let b: Vec<Vec<f64>> = (0..4)
                .map(|q| (0..n).map(|i| ((i + 7 * q) as f64 * 0.11).cos()).collect())
                .collect();
            let got = dot32_many(&a, [&b[0], &b[1], &b[2], &b[3]]);
            for q in 0..4 {
                let want: f64 = a.iter().zip(&b[q]).map(|(x, y)| f64::from(*x) * y).sum();
                assert!(
                    (got[q] - want).abs() <= 1e-13 * (1.0 + want.abs()),
                    "{n} {q}"
                );
            }
        }
    }
}
