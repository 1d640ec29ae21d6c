//! e^x for x ≤ 0 without a library call: the BAO damping e^{−k²Σ²(…)} of the galaxy model's AP
//! projection is evaluated at every (k, μ) node of every step, where the library's exponential was a
//! sixth of the multipoles' cost.
//!
//! Cody–Waite reduction x = n ln 2 + r, |r| ≤ ln 2 / 2 (ln 2 split in two parts so that n ln2_hi is
//! exact), the Taylor polynomial of e^r to degree 13 (truncation ≤ 0.347¹⁴/14! = 4e-18 relative), and
//! the scaling by 2^n through the exponent bits. Within 2 ulp of the library's e^x (tested). Below
//! x = −708 (where 2^n would leave the normal range) and for x > 0 or NaN the library's is used.

/// log₂ e.
const LOG2_E: f64 = std::f64::consts::LOG2_E;
/// ln 2 in two parts (fdlibm's): n × `LN2_HI` is exact for |n| < 2²⁰.
const LN2_HI: f64 = 6.931_471_803_691_238_164_90e-1;
const LN2_LO: f64 = 1.908_214_929_270_587_700_02e-10;
/// 1.5 × 2⁵²: adding and subtracting it rounds to the nearest integer (round-to-nearest mode).
const SHIFT: f64 = 6_755_399_441_055_744.0;

/// 1/m! for m = 0..=13.
const INVERSE_FACTORIALS: [f64; 14] = {
    let mut c = [1.0; 14];
    let mut m = 1;
    while m < 14 {
        c[m] = c[m - 1] / m as f64;
        m += 1;
    }
    c
};

/// e^x for x ≤ 0, within 2 ulp of [`f64::exp`] (module docs); `f64::exp` itself outside
/// [−708, 0].
#[inline]
pub(crate) fn exp_nonpositive(x: f64) -> f64 {
    if !(-708.0..=0.0).contains(&x) {
        return x.exp();
    }
    let n = (x * LOG2_E + SHIFT) - SHIFT;
    let r = (x - n * LN2_HI) - n * LN2_LO;
    let p = INVERSE_FACTORIALS.iter().rev().fold(0.0, |p, &c| p * r + c);
    // n ∈ [−1022, 0]: 2^n is normal
    p * f64::from_bits(((n as i64 + 1023) as u64) << 52)
}

#[cfg(test)]
mod tests {
    use super::exp_nonpositive;

    /// Distance in units in the last place.
    fn ulps(a: f64, b: f64) -> u64 {
        (a.to_bits() as i64 - b.to_bits() as i64).unsigned_abs()
    }

    #[test]
    fn within_two_ulp_of_the_library_exponential() {
        let mut worst = 0;
        // a dense sweep of the whole range and the neighbourhoods of the reduction's boundaries
        let sweep = (0..=200_000).map(|i| -708.0 * (i as f64 / 200_000.0).powi(3));
        let edges = (0..1022).flat_map(|n| {
            let x = -(n as f64 + 0.5) * std::f64::consts::LN_2;
            [x, x.next_up(), x.next_down()]
        });
        for x in sweep
            .chain(edges)
            .chain([0.0, -0.0, -1e-300, -5e-324, -1e-12])
        {
            let (fast, exact) = (exp_nonpositive(x), x.exp());
            worst = worst.max(ulps(fast, exact));
            assert!(
                ulps(fast, exact) <= 2,
                "x = {x:e}: {fast:e} against {exact:e}"
            );
        }
        assert!(worst >= 1, "the sweep should meet some rounding difference");
    }

    #[test]
    fn outside_the_range_is_the_library_exponential() {
        for x in [
            1.0,
            1e-300,
            -708.5,
            -745.0,
            -746.0,
            -1e300,
            f64::NEG_INFINITY,
        ] {
            assert_eq!(exp_nonpositive(x).to_bits(), x.exp().to_bits(), "x = {x:e}");
        }
        assert!(exp_nonpositive(f64::NAN).is_nan());
    }
}
