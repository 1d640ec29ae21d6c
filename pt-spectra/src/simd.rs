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

mod dot_many;
mod exp;
pub(crate) use dot_many::{matvec32, matvec32_many};
pub(crate) use exp::exp_in_place;

/// Σ a_i b_i over the common length with four partial sums in a fixed order: vectorised by the
/// compiler and the same rounding on every machine (unlike [`dot`], whose lanes follow the processor),
/// for the sums whose printed digits tests compare byte for byte (the 1-loop plan's).
pub(crate) fn dot_fixed(a: &[f64], b: &[f64]) -> f64 {
    let n = a.len().min(b.len());
    let (a, b) = (&a[..n], &b[..n]);
    let mut s = [0.0; 4];
    let (ca, cb) = (a.chunks_exact(4), b.chunks_exact(4));
    let (ra, rb) = (ca.remainder(), cb.remainder());
    for (x, y) in ca.zip(cb) {
        for j in 0..4 {
            s[j] += x[j] * y[j];
        }
    }
    let tail: f64 = ra.iter().zip(rb).map(|(x, y)| x * y).sum();
    (s[0] + s[1]) + (s[2] + s[3]) + tail
}

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
        dot_simd(simd, self.0, self.1)
    }
}

/// The rows of `a` (each of the length of `x`, as many as `out` holds) times `x`, each as [`dot`],
/// with one detection of the instructions for all of them (short rows: linear forms on the basis).
pub(crate) fn matvec(a: &[f64], x: &[f64], out: &mut [f64]) {
    assert!(
        a.len() >= x.len() * out.len(),
        "a matrix of {} rows",
        out.len()
    );
    if x.is_empty() {
        out.iter_mut().for_each(|o| *o = 0.0);
        return;
    }
    Arch::new().dispatch(MatVec(a, x, out));
}

struct MatVec<'a>(&'a [f64], &'a [f64], &'a mut [f64]);

impl WithSimd for MatVec<'_> {
    type Output = ();

    #[inline(always)]
    fn with_simd<S: Simd>(self, simd: S) {
        let MatVec(a, x, out) = self;
        for (o, row) in out.iter_mut().zip(a.chunks_exact(x.len())) {
            *o = dot_simd(simd, row, x);
        }
    }
}

#[inline(always)]
fn dot_simd<S: Simd>(simd: S, a: &[f64], b: &[f64]) -> f64 {
    let (a, a_tail) = S::as_simd_f64s(a);
    let (b, b_tail) = S::as_simd_f64s(b);
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

/// y += a x over the common length (a spectrum's projection rebuilt from its basis functions).
pub(crate) fn axpy(y: &mut [f64], a: f64, x: &[f64]) {
    let n = y.len().min(x.len());
    Arch::new().dispatch(Axpy(&mut y[..n], a, &x[..n]));
}

struct Axpy<'a>(&'a mut [f64], f64, &'a [f64]);

impl WithSimd for Axpy<'_> {
    type Output = ();

    #[inline(always)]
    fn with_simd<S: Simd>(self, simd: S) {
        let Axpy(y, a, x) = self;
        let (ys, y_tail) = S::as_mut_simd_f64s(y);
        let (xs, x_tail) = S::as_simd_f64s(x);
        let av = simd.splat_f64s(a);
        for (y, x) in ys.iter_mut().zip(xs) {
            *y = simd.mul_add_f64s(av, *x, *y);
        }
        for (y, x) in y_tail.iter_mut().zip(x_tail) {
            *y += a * x;
        }
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

/// y = Σ_p c_p x_p over the rows x_p = `rows[p·stride..][..y.len()]` (f32 entries widened to f64,
/// one row per coefficient), summed in f64: the emulator's principal components weighted by their
/// coefficients ([`crate::emulator`]). Four rows per pass over y, so that y is loaded and stored once
/// for four products; with AVX2 four lanes and fused multiply–adds.
pub(crate) fn combine_rows_f32(y: &mut [f64], c: &[f64], rows: &[f32], stride: usize) {
    let n = y.len();
    assert!(
        c.is_empty() || rows.len() >= (c.len() - 1) * stride + n,
        "{} rows of {n} at a stride of {stride}",
        c.len()
    );
    y.fill(0.0);
    // Groups of four rows; a short last group repeats its last row with a zero coefficient (adds 0).
    let groups = (0..c.len()).step_by(4).map(|p| {
        let last = c.len() - 1;
        let coefficient = |q: usize| if p + q <= last { c[p + q] } else { 0.0 };
        let row = |q: usize| &rows[(p + q).min(last) * stride..][..n];
        ([0, 1, 2, 3].map(coefficient), [0, 1, 2, 3].map(row))
    });
    #[cfg(target_arch = "x86_64")]
    if let Some(simd) = pulp::x86::V3::try_new() {
        return simd.vectorize(CombineV3 { simd, y, groups });
    }
    for (c, x) in groups {
        for (i, y) in y.iter_mut().enumerate() {
            *y += c[0] * f64::from(x[0][i])
                + c[1] * f64::from(x[1][i])
                + c[2] * f64::from(x[2][i])
                + c[3] * f64::from(x[3][i]);
        }
    }
}

/// [`combine_rows_f32`] with AVX2 and FMA, a type rather than a closure as [`MatVecV3`].
#[cfg(target_arch = "x86_64")]
struct CombineV3<'a, I> {
    simd: pulp::x86::V3,
    y: &'a mut [f64],
    groups: I,
}

#[cfg(target_arch = "x86_64")]
impl<'a, I: Iterator<Item = ([f64; 4], [&'a [f32]; 4])>> pulp::NullaryFnOnce for CombineV3<'_, I> {
    type Output = ();

    #[inline(always)]
    fn call(self) {
        for (c, x) in self.groups {
            combine4_v3(self.simd, self.y, c, x);
        }
    }
}

/// y += Σ_q c_q x_q of four rows of [`combine_rows_f32`] with AVX2 and FMA.
#[cfg(target_arch = "x86_64")]
#[inline(always)]
fn combine4_v3(simd: pulp::x86::V3, y: &mut [f64], c: [f64; 4], x: [&[f32]; 4]) {
    use pulp::{f32x4, f64x4};
    let (y4, y_tail) = pulp::as_arrays_mut::<4, _>(y);
    let x4 = x.map(|r| pulp::as_arrays::<4, _>(r).0);
    let cv = c.map(|c| simd.splat_f64x4(c));
    for (i, y) in y4.iter_mut().enumerate() {
        let mut acc: f64x4 = pulp::cast(*y);
        for q in 0..4 {
            let xq: f32x4 = pulp::cast(x4[q][i]);
            acc = simd.mul_add_f64x4(simd.convert_f32x4_to_f64x4(xq), cv[q], acc);
        }
        *y = pulp::cast(acc);
    }
    let start = 4 * y4.len();
    for (i, y) in (start..).zip(y_tail) {
        for q in 0..4 {
            *y += c[q] * f64::from(x[q][i]);
        }
    }
}

/// Σ a_i b_i of f32 tensor entries and f32 products over the common length, multiplied and summed
/// in f32 in 32 partial sums (each of about n/32 terms: for the 1-loop pair rows 21, a rounding of
/// ~1e-7 of Σ|a_i b_i|, the size of the entries' own f32 rounding), added in f32 to eight and those
/// in f64. Twice the throughput of [`dot32`] when the tensor is in cache (eight lanes, no widening).
pub(crate) fn dot_f32(a: &[f32], b: &[f32]) -> f64 {
    let n = a.len().min(b.len());
    let (a, b) = (&a[..n], &b[..n]);
    #[cfg(target_arch = "x86_64")]
    if let Some(simd) = pulp::x86::V3::try_new() {
        return simd.vectorize(|| dot_f32_v3(simd, a, b));
    }
    dot_f32_portable(a, b)
}

/// Checks that a matrix of `len` entries holds `out.len()` rows of `n`; with `n` = 0 zeroes `out`
/// and says so (the product is then done).
fn no_columns(len: usize, n: usize, out: &mut [f64]) -> bool {
    assert!(
        len >= n * out.len(),
        "a matrix of {} rows of {n}",
        out.len()
    );
    if n == 0 {
        out.iter_mut().for_each(|o| *o = 0.0);
    }
    n == 0
}

/// The rows of `a` (each of the length of `x`, as many as `out` holds) times `x`, each as
/// [`dot_f32`] (the same sums), with one detection of the instructions for all of them: a
/// low-rank tensor's thousands of short rows ([`crate::loops::basis`]).
pub(crate) fn matvec_f32(a: &[f32], x: &[f32], out: &mut [f64]) {
    let n = x.len();
    if no_columns(a.len(), n, out) {
        return;
    }
    #[cfg(target_arch = "x86_64")]
    if let Some(simd) = pulp::x86::V3::try_new() {
        return simd.vectorize(MatVecV3 { simd, a, x, out });
    }
    for (o, row) in out.iter_mut().zip(a.chunks_exact(n)) {
        *o = dot_f32_portable(row, x);
    }
}

/// [`matvec_f32`] with AVX2 and FMA. A type rather than a closure: its `call` is inlined whole into
/// the dispatch, so that the loop over rows is compiled for those instructions (a closure with a
/// loop is not inlined, and its intrinsics become calls, five times slower).
#[cfg(target_arch = "x86_64")]
struct MatVecV3<'a> {
    simd: pulp::x86::V3,
    a: &'a [f32],
    x: &'a [f32],
    out: &'a mut [f64],
}

#[cfg(target_arch = "x86_64")]
impl pulp::NullaryFnOnce for MatVecV3<'_> {
    type Output = ();

    #[inline(always)]
    fn call(self) {
        for (o, row) in self.out.iter_mut().zip(self.a.chunks_exact(self.x.len())) {
            *o = dot_f32_v3(self.simd, row, self.x);
        }
    }
}

/// [`dot_f32`] with AVX2 and FMA: four accumulators of eight lanes, then the remainder by eight.
#[cfg(target_arch = "x86_64")]
#[inline(always)]
fn dot_f32_v3(simd: pulp::x86::V3, a: &[f32], b: &[f32]) -> f64 {
    use pulp::f32x8;
    let (a32, a_rest) = pulp::as_arrays::<32, _>(a);
    let (b32, b_rest) = pulp::as_arrays::<32, _>(b);
    let mut acc = [simd.splat_f32x8(0.0); 4];
    for (x, y) in a32.iter().zip(b32) {
        let x: [f32x8; 4] = pulp::cast(*x);
        let y: [f32x8; 4] = pulp::cast(*y);
        for h in 0..4 {
            acc[h] = simd.mul_add_f32x8(x[h], y[h], acc[h]);
        }
    }
    let (a8, a_tail) = pulp::as_arrays::<8, _>(a_rest);
    let (b8, b_tail) = pulp::as_arrays::<8, _>(b_rest);
    for (h, (x, y)) in a8.iter().zip(b8).enumerate() {
        acc[h] = simd.mul_add_f32x8(pulp::cast(*x), pulp::cast(*y), acc[h]);
    }
    let sum = simd.add_f32x8(
        simd.add_f32x8(acc[0], acc[1]),
        simd.add_f32x8(acc[2], acc[3]),
    );
    sum_lanes(pulp::cast(sum), a_tail, b_tail)
}

/// The eight partial sums in f64 (a tree), plus the tail's products.
fn sum_lanes(l: [f32; 8], a_tail: &[f32], b_tail: &[f32]) -> f64 {
    let l = l.map(f64::from);
    let tail: f64 = a_tail
        .iter()
        .zip(b_tail)
        .map(|(x, y)| f64::from(*x) * f64::from(*y))
        .sum();
    (((l[0] + l[1]) + (l[2] + l[3])) + ((l[4] + l[5]) + (l[6] + l[7]))) + tail
}

/// [`dot_f32`] in portable code: the same partial sums.
fn dot_f32_portable(a: &[f32], b: &[f32]) -> f64 {
    let (ca, cb) = (a.chunks_exact(32), b.chunks_exact(32));
    let (a_rest, b_rest) = (ca.remainder(), cb.remainder());
    let mut lanes = [[0.0f32; 8]; 4];
    for (x, y) in ca.zip(cb) {
        for (i, (x, y)) in x.iter().zip(y).enumerate() {
            lanes[i / 8][i % 8] += x * y;
        }
    }
    let (ra, rb) = (a_rest.chunks_exact(8), b_rest.chunks_exact(8));
    let (a_tail, b_tail) = (ra.remainder(), rb.remainder());
    for (h, (x, y)) in ra.zip(rb).enumerate() {
        for (i, (x, y)) in x.iter().zip(y).enumerate() {
            lanes[h][i] += x * y;
        }
    }
    let sum = std::array::from_fn(|i| (lanes[0][i] + lanes[1][i]) + (lanes[2][i] + lanes[3][i]));
    sum_lanes(sum, a_tail, b_tail)
}

/// `x` rounded to bfloat16 (the top 16 bits of its f32, to nearest even): the f32 exponent range
/// with 8 significant bits, a relative rounding of at most 2^-8 = 0.4%. For stored numbers that only
/// make an error estimate, where half the bytes of f32 halve the memory they stream.
pub(crate) fn to_bf16(x: f32) -> u16 {
    let bits = x.to_bits();
    if x.is_nan() {
        return ((bits >> 16) as u16) | 0x40;
    }
    let round = 0x7fff + ((bits >> 16) & 1);
    (bits.wrapping_add(round) >> 16) as u16
}

/// The f32 value of a bfloat16 ([`to_bf16`]), exact.
#[inline(always)]
pub(crate) fn from_bf16(h: u16) -> f32 {
    f32::from_bits(u32::from(h) << 16)
}

/// The rows of `a` (bfloat16 entries, [`to_bf16`], each of the length of `x`, as many as `out`
/// holds) times `x`: each entry widened to f32, multiplied and summed in f32 in 16 partial sums (a
/// rounding of ~1e-7 of Σ|a_i x_i| for rows of a few hundred), added in f64; one detection of the
/// processor's instructions for all rows.
pub(crate) fn matvec_bf16(a: &[u16], x: &[f32], out: &mut [f64]) {
    let n = x.len();
    if no_columns(a.len(), n, out) {
        return;
    }
    Arch::new().dispatch(MatVecBf16 { a, x, out });
}

/// [`matvec_bf16`] for the instructions `pulp` chose: the portable loop, inlined into the dispatch
/// so that it is compiled (and vectorised) for them.
struct MatVecBf16<'a> {
    a: &'a [u16],
    x: &'a [f32],
    out: &'a mut [f64],
}

impl WithSimd for MatVecBf16<'_> {
    type Output = ();

    #[inline(always)]
    fn with_simd<S: Simd>(self, _simd: S) {
        let n = self.x.len();
        for (o, row) in self.out.iter_mut().zip(self.a.chunks_exact(n)) {
            *o = dot_bf16(row, self.x);
        }
    }
}

/// Σ a_i b_i of one row of [`matvec_bf16`].
#[inline(always)]
fn dot_bf16(a: &[u16], b: &[f32]) -> f64 {
    let (ca, cb) = (a.chunks_exact(16), b.chunks_exact(16));
    let (a_tail, b_tail) = (ca.remainder(), cb.remainder());
    let mut lanes = [0.0f32; 16];
    for (x, y) in ca.zip(cb) {
        for i in 0..16 {
            lanes[i] += from_bf16(x[i]) * y[i];
        }
    }
    let tail: f64 = a_tail
        .iter()
        .zip(b_tail)
        .map(|(x, y)| f64::from(from_bf16(*x)) * f64::from(*y))
        .sum();
    lanes.iter().map(|&l| f64::from(l)).sum::<f64>() + tail
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
            let mut out = [f64::NAN; 2];
            matvec(&[b.clone(), a.clone()].concat(), &a, &mut out);
            assert_eq!(out, [expected, dot(&a, &a)], "n = {n}");
            let mut y = b.clone();
            axpy(&mut y, 2.0, &a);
            assert!(
                y.iter()
                    .zip(&a)
                    .zip(&b)
                    .all(|((y, a), b)| *y == b + 2.0 * a),
                "n = {n}"
            );
            let a32: Vec<f32> = a.iter().map(|&x| x as f32).collect();
            assert_eq!(dot32(&a32, &b), expected, "n = {n}");
            assert_eq!(dot32_portable(&a32, &b), expected, "n = {n}");
            let b32: Vec<f32> = b.iter().map(|&x| x as f32).collect();
            assert_eq!(dot_f32(&a32, &b32), expected, "n = {n}");
            assert_eq!(dot_f32_portable(&a32, &b32), expected, "n = {n}");
            // Small integers are exact in bfloat16 too.
            let a16: Vec<u16> = a32.iter().map(|&x| to_bf16(x)).collect();
            let mut out = [f64::NAN; 1];
            matvec_bf16(&a16, &b32, &mut out);
            assert_eq!(out[0], expected, "n = {n}");
            // Three rows of a matrix at once: each row's own dot product.
            let rows: Vec<f32> = [a32.clone(), b32.clone(), a32.clone()].concat();
            let mut out = [f64::NAN; 3];
            matvec_f32(&rows, &b32, &mut out);
            let bb: f64 = b.iter().map(|x| x * x).sum();
            assert_eq!(out, [expected, bb, expected], "n = {n}");
            // Five rows weighted (two groups of four, the second short): exact on small integers.
            let mut y = vec![f64::NAN; n as usize];
            let stride = n as usize + 3;
            let rows: Vec<f32> = (0..5 * stride).map(|i| (i % 11) as f32 - 5.0).collect();
            combine_rows_f32(&mut y, &[1.0, -2.0, 3.0, 0.5, 4.0], &rows, stride);
            for (i, y) in y.iter().enumerate() {
                let r = |p: usize| f64::from(rows[p * stride + i]);
                let e = r(0) - 2.0 * r(1) + 3.0 * r(2) + 0.5 * r(3) + 4.0 * r(4);
                assert_eq!(*y, e, "n = {n}, i = {i}");
            }
        }
    }

    #[test]
    fn exp_is_within_two_ulp_of_the_library_exp() {
        let mut x: Vec<f64> = (0..20001).map(|i| -700.0 + 0.07 * i as f64).collect();
        x.extend([
            0.0,
            1e-300,
            -1e-17,
            0.5 * std::f64::consts::LN_2,
            708.9,
            -707.9,
        ]);
        let mut e = x.clone();
        exp_in_place(&mut e);
        for (x, e) in x.iter().zip(&e) {
            let reference = x.exp();
            assert!(
                (e / reference - 1.0).abs() <= 2.0 * f64::EPSILON,
                "{x}: {e} {reference}"
            );
        }
        let mut nan = [f64::NAN];
        exp_in_place(&mut nan);
        assert!(nan[0].is_nan());
    }

    #[test]
    fn bfloat16_rounds_to_nearest_even_within_its_half_ulp() {
        // 1 + 2^-8 is halfway between 1 and 1 + 2^-7: to even (1); 1 + 3·2^-8 to 1 + 2^-6.
        assert_eq!(from_bf16(to_bf16(1.0 + 2f32.powi(-8))), 1.0);
        assert_eq!(
            from_bf16(to_bf16(1.0 + 3.0 * 2f32.powi(-8))),
            1.0 + 2f32.powi(-6)
        );
        assert!(from_bf16(to_bf16(f32::NAN)).is_nan());
        assert_eq!(from_bf16(to_bf16(f32::INFINITY)), f32::INFINITY);
        let mut worst = 0.0f64;
        for i in 0..10_000 {
            let x = ((i as f32) * 0.618_034).sin() * 10f32.powi(i % 30 - 15);
            let r = f64::from(from_bf16(to_bf16(x)));
            if x != 0.0 {
                worst = worst.max((r / f64::from(x) - 1.0).abs());
            }
        }
        assert!(worst <= 2f64.powi(-8), "{worst}");
        assert!(worst > 2f64.powi(-9), "{worst}");
    }
}
