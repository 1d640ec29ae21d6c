//! The dot products of the tensor contractions and of the fixed quadrature weights, vectorised for the
//! processor they run on.
//!
//! Every basis evaluation is a few thousand dot products of a tensor row with the products of the
//! spectrum's coefficients, and RegPT's vertex a dot product of stored weights with the spectrum per
//! outer node; they are most of the cost of a new spectrum. The build targets baseline x86-64 (SSE2, two f64
//! lanes), so that a binary runs on any node of a cluster; these functions choose at run time, through
//! the `pulp` crate (safe wrappers of the processor's vector instructions, detected once), the widest
//! instructions the processor has: on x86-64 AVX2 with fused multiply–add (four f64 lanes), else the
//! portable code. The sums are the same to rounding (the order of the additions differs).

use pulp::{Arch, Simd, WithSimd};

/// Σ a_i b_i over the common length.
pub(crate) fn dot(a: &[f64], b: &[f64]) -> f64 {
    let n = a.len().min(b.len());
    Arch::new().dispatch(Dot(&a[..n], &b[..n]))
}

struct Dot<'a>(&'a [f64], &'a [f64]);

impl WithSimd for Dot<'_> {
    type Output = f64;

    #[inline(always)]
    fn with_simd<S: Simd>(self, simd: S) -> f64 {
        let (a, a_tail) = S::as_simd_f64s(self.0);
        let (b, b_tail) = S::as_simd_f64s(self.1);
        // Four independent accumulators hide the latency of the fused multiply–add.
        let (a4, a_rest) = pulp::as_arrays::<4, _>(a);
        let (b4, b_rest) = pulp::as_arrays::<4, _>(b);
        let mut acc = [simd.splat_f64s(0.0); 4];
        for (x, y) in a4.iter().zip(b4) {
            for i in 0..4 {
                acc[i] = simd.mul_add_f64s(x[i], y[i], acc[i]);
            }
        }
        for (x, y) in a_rest.iter().zip(b_rest) {
            acc[0] = simd.mul_add_f64s(*x, *y, acc[0]);
        }
        let sum = simd.add_f64s(simd.add_f64s(acc[0], acc[1]), simd.add_f64s(acc[2], acc[3]));
        let tail: f64 = a_tail.iter().zip(b_tail).map(|(x, y)| x * y).sum();
        simd.reduce_sum_f64s(sum) + tail
    }
}

/// Σ a_i b_i of f32 tensor entries and f64 products, summed in f64, over the common length.
pub(crate) fn dot32(a: &[f32], b: &[f64]) -> f64 {
    let n = a.len().min(b.len());
    let (a, b) = (&a[..n], &b[..n]);
    #[cfg(target_arch = "x86_64")]
    if let Some(simd) = pulp::x86::V3::try_new() {
        return simd.vectorize(|| dot32_v3(simd, a, b));
    }
    dot32_portable(a, b)
}

/// [`dot32`] with AVX2 and FMA: four f32 entries widened to f64 per instruction.
#[cfg(target_arch = "x86_64")]
#[inline(always)]
fn dot32_v3(simd: pulp::x86::V3, a: &[f32], b: &[f64]) -> f64 {
    use pulp::{f32x4, f64x4};
    let (a8, a_rest) = pulp::as_arrays::<8, _>(a);
    let (b8, b_rest) = pulp::as_arrays::<8, _>(b);
    let mut acc = [simd.splat_f64x4(0.0); 2];
    for (x, y) in a8.iter().zip(b8) {
        for h in 0..2 {
            let x: f32x4 = pulp::cast([x[4 * h], x[4 * h + 1], x[4 * h + 2], x[4 * h + 3]]);
            let y: f64x4 = pulp::cast([y[4 * h], y[4 * h + 1], y[4 * h + 2], y[4 * h + 3]]);
            acc[h] = simd.mul_add_f64x4(simd.convert_f32x4_to_f64x4(x), y, acc[h]);
        }
    }
    let s: [f64; 4] = pulp::cast(simd.add_f64x4(acc[0], acc[1]));
    let tail: f64 = a_rest
        .iter()
        .zip(b_rest)
        .map(|(x, y)| f64::from(*x) * y)
        .sum();
    (s[0] + s[1]) + (s[2] + s[3]) + tail
}

/// [`dot32`] in portable code, with four partial sums (so that it vectorises on any target).
fn dot32_portable(a: &[f32], b: &[f64]) -> f64 {
    let mut s = [0.0; 4];
    let (ca, cb) = (a.chunks_exact(4), b.chunks_exact(4));
    let tail: f64 = ca
        .remainder()
        .iter()
        .zip(cb.remainder())
        .map(|(x, y)| f64::from(*x) * y)
        .sum();
    for (x, y) in ca.zip(cb) {
        for i in 0..4 {
            s[i] += f64::from(x[i]) * y[i];
        }
    }
    (s[0] + s[1]) + (s[2] + s[3]) + tail
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn dot_products_are_exact_on_small_integers_at_every_length() {
        // Integer products and sums below 2^53 are exact in any order: every length exercises the
        // vector body, the four-accumulator remainder and the scalar tail.
        for n in 0..70 {
            let a: Vec<f64> = (0..n).map(|i| f64::from(i % 7) - 3.0).collect();
            let b: Vec<f64> = (0..n).map(|i| f64::from(i % 5) + 1.0).collect();
            let expected: f64 = a.iter().zip(&b).map(|(x, y)| x * y).sum();
            assert_eq!(dot(&a, &b), expected, "n = {n}");
            let a32: Vec<f32> = a.iter().map(|&x| x as f32).collect();
            assert_eq!(dot32(&a32, &b), expected, "n = {n}");
            assert_eq!(dot32_portable(&a32, &b), expected, "n = {n}");
        }
    }
}
