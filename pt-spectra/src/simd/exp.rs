//! The exponential of many values without a library call, written so that it vectorises
//! ([`exp_in_place`]): a spectrum's samples on the loop lattice, the BAO damping of all k of a μ node
//! in the AP multipoles (a BOSS step's: 95 → 84 µs). One value at a time the library's is faster: this
//! one's degree-13 Horner chain is latency-bound (the multipoles took 108 µs called per point).

/// e^v for every v in `values`, in place, to within 2 ulp of [`f64::exp`] for v ∈ [−708, 709]
/// (clamped there): the samples of a spectrum on the loop lattice are exp of its ln-spline, a few
/// thousand per spectrum. Range reduction v = n ln 2 + r, |r| ≤ ln 2 / 2, the Taylor series of e^r
/// to degree 13 (remainder < 1e-17) and 2^n from the exponent bits, written so that it vectorises.
pub(crate) fn exp_in_place(values: &mut [f64]) {
    #[cfg(target_arch = "x86_64")]
    if let Some(simd) = pulp::x86::V3::try_new() {
        return simd.vectorize(|| values.iter_mut().for_each(|v| *v = exp_reduced(*v)));
    }
    values.iter_mut().for_each(|v| *v = exp_reduced(*v));
}

#[inline(always)]
fn exp_reduced(v: f64) -> f64 {
    // ln 2 split so that n · LN2_HI is exact for |n| < 2^20 (fdlibm's constants).
    const LN2_HI: f64 = f64::from_bits(0x3fe6_2e42_fee0_0000);
    const LN2_LO: f64 = f64::from_bits(0x3dea_39ef_3579_3c76);
    // 1.5 · 2^52: adding it rounds to an integer held in the low mantissa bits.
    const SHIFT: f64 = 6_755_399_441_055_744.0;
    let x = v.clamp(-708.0, 709.0);
    let t = x * std::f64::consts::LOG2_E + SHIFT;
    let n = t - SHIFT;
    let r = (x - n * LN2_HI) - n * LN2_LO;
    // 1/j! for j = 13 … 2, then 1 + r(1 + r(…)).
    const INV_FACT: [f64; 12] = [
        1.0 / 6_227_020_800.0,
        1.0 / 479_001_600.0,
        1.0 / 39_916_800.0,
        1.0 / 3_628_800.0,
        1.0 / 362_880.0,
        1.0 / 40_320.0,
        1.0 / 5_040.0,
        1.0 / 720.0,
        1.0 / 120.0,
        1.0 / 24.0,
        1.0 / 6.0,
        0.5,
    ];
    let mut p = INV_FACT[0];
    for c in &INV_FACT[1..] {
        p = p * r + c;
    }
    let e_r = (p * r + 1.0) * r + 1.0;
    // n + 1023 ∈ [1, 2046] after the clamp: the biased exponent of 2^n.
    let two_n = f64::from_bits(t.to_bits().wrapping_add(1023) << 52);
    if v.is_nan() {
        v
    } else {
        e_r * two_n
    }
}
