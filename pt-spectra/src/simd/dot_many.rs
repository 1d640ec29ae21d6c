//! Several dot products of one f32 row with f64 vectors: the low-rank tensors' U applied to the
//! reduced products of several directions at once ([`crate::loops::basis::low_rank`]), each entry of
//! the row widened to f64 once for all of them.

/// Σ_i a_i b_q,i for each of the four vectors `b` (each at least as long as `a`), summed in f64.
pub(crate) fn dot32_four(a: &[f32], b: [&[f64]; 4]) -> [f64; 4] {
    let n = a.len();
    assert!(
        b.iter().all(|b| b.len() >= n),
        "vectors shorter than the row"
    );
    #[cfg(target_arch = "x86_64")]
    if let Some(simd) = pulp::x86::V3::try_new() {
        return simd.vectorize(|| dot32_four_v3(simd, a, b.map(|b| &b[..n])));
    }
    b.map(|b| a.iter().zip(b).map(|(x, y)| f64::from(*x) * y).sum::<f64>())
}

/// [`dot32_four`] with AVX2 and FMA: four entries of the row widened once per four products.
#[cfg(target_arch = "x86_64")]
#[inline(always)]
fn dot32_four_v3(simd: pulp::x86::V3, a: &[f32], b: [&[f64]; 4]) -> [f64; 4] {
    use pulp::{f32x4, f64x4};
    let (a4, a_rest) = pulp::as_arrays::<4, _>(a);
    let chunks = b.map(|b| pulp::as_arrays::<4, _>(b).0);
    let mut acc = [simd.splat_f64x4(0.0); 4];
    for (c, x) in a4.iter().enumerate() {
        let x: f32x4 = pulp::cast(*x);
        let x = simd.convert_f32x4_to_f64x4(x);
        for q in 0..4 {
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

#[cfg(test)]
mod tests {
    use super::*;

    /// Against the plain sums, at lengths with and without a tail.
    #[test]
    fn four_dots_equal_the_plain_sums() {
        for n in [0, 3, 4, 37, 160] {
            let a: Vec<f32> = (0..n).map(|i| (i as f32 * 0.37).sin()).collect();
            let b: Vec<Vec<f64>> = (0..4)
                .map(|q| (0..n).map(|i| ((i + 7 * q) as f64 * 0.11).cos()).collect())
                .collect();
            let got = dot32_four(&a, [&b[0], &b[1], &b[2], &b[3]]);
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
