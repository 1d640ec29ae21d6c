//! Arithmetic of 3-vectors of wavenumbers [h/Mpc], `[f64; 3]`, for the integrands that build
//! their kernels' arguments (the 2-loop redshift-space integrand, the one-loop bispectrum).

/// a + b.
#[inline]
pub(crate) fn add(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] + b[0], a[1] + b[1], a[2] + b[2]]
}

/// a − b.
#[inline]
pub(crate) fn sub(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

/// −a.
#[inline]
pub(crate) fn neg(a: [f64; 3]) -> [f64; 3] {
    a.map(|x| -x)
}

/// a·b.
#[inline]
pub(crate) fn dot(a: &[f64; 3], b: &[f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

/// |a|².
#[inline]
pub(crate) fn norm2(a: [f64; 3]) -> f64 {
    dot(&a, &a)
}

/// |a|.
#[inline]
pub(crate) fn norm(a: [f64; 3]) -> f64 {
    norm2(a).sqrt()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn vector_arithmetic_on_exact_integers() {
        let (a, b) = ([1.0, -2.0, 3.0], [4.0, 5.0, -6.0]);
        assert_eq!(add(a, b), [5.0, 3.0, -3.0]);
        assert_eq!(sub(a, b), [-3.0, -7.0, 9.0]);
        assert_eq!(neg(a), [-1.0, 2.0, -3.0]);
        assert_eq!(dot(&a, &b), -24.0);
        assert_eq!(norm2(a), 14.0);
        assert_eq!(norm([3.0, 4.0, 12.0]), 13.0);
    }
}
