//! Wigner 3j symbols with zero projections, exactly, and the window mixing coefficients built from them.
//!
//! (l1 l2 l3; 0 0 0)² = [(2g−2l1)! (2g−2l2)! (2g−2l3)! / (2g+1)!] · [g! / ((g−l1)! (g−l2)! (g−l3)!)]²
//! for even 2g = l1 + l2 + l3 and |l1 − l2| ≤ l3 ≤ l1 + l2, zero otherwise (Edmonds 1957, eq. 3.7.17), in
//! big-integer rationals. With ∫_{−1}^{1} L_a L_b L_c dμ = 2 (a b c; 0 0 0)², the product of ξ(s, μ) and
//! Q(s, μ) has the multipoles ξ̂_ℓ = Σ_{ℓ',ℓ''} (2ℓ+1) (ℓ ℓ' ℓ''; 0 0 0)² ξ_ℓ' Q_ℓ''.

use num_bigint::BigInt;
use num_rational::BigRational;
use num_traits::{One, ToPrimitive, Zero};

fn factorial(n: usize) -> BigInt {
    (1..=n).fold(BigInt::one(), |acc, i| acc * BigInt::from(i))
}

/// (l1 l2 l3; 0 0 0)², exact.
pub(crate) fn three_j_zero_squared(l1: usize, l2: usize, l3: usize) -> BigRational {
    let sum = l1 + l2 + l3;
    if sum % 2 == 1 || l3 > l1 + l2 || l1 > l2 + l3 || l2 > l1 + l3 {
        return BigRational::zero();
    }
    let g = sum / 2;
    let root = factorial(g) / (factorial(g - l1) * factorial(g - l2) * factorial(g - l3));
    let num = factorial(2 * g - 2 * l1)
        * factorial(2 * g - 2 * l2)
        * factorial(2 * g - 2 * l3)
        * &root
        * &root;
    BigRational::new(num, factorial(2 * g + 1))
}

/// (2ℓ+1) (ℓ ℓ' ℓ''; 0 0 0)², exact: the weight of ξ_ℓ' Q_ℓ'' in ξ̂_ℓ.
pub(crate) fn wilson_rational(ell: usize, ell_in: usize, ell_q: usize) -> BigRational {
    three_j_zero_squared(ell, ell_in, ell_q) * BigRational::from_integer(BigInt::from(2 * ell + 1))
}

/// [`wilson_rational`] as f64.
pub(crate) fn wilson(ell: usize, ell_in: usize, ell_q: usize) -> f64 {
    wilson_rational(ell, ell_in, ell_q).to_f64().unwrap_or(0.0)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn r(n: i64, d: i64) -> BigRational {
        BigRational::new(BigInt::from(n), BigInt::from(d))
    }

    /// Wilson et al. (2017), eq. (A3)–(A5) in our notation, Q up to ℓ = 4:
    /// ξ̂0 = ξ0Q0 + ξ2Q2/5 + ξ4Q4/9,
    /// ξ̂2 = ξ0Q2 + ξ2[Q0 + 2Q2/7 + 2Q4/7] + ξ4[2Q2/7 + 100Q4/693],
    /// ξ̂4 = ξ0Q4 + ξ2[18Q2/35 + 20Q4/77] + ξ4[Q0 + 20Q2/77 + 162Q4/1001].
    #[test]
    fn wilson_coefficients_to_ell_4() {
        let table: [((usize, usize, usize), BigRational); 17] = [
            ((0, 0, 0), r(1, 1)),
            ((0, 2, 2), r(1, 5)),
            ((0, 4, 4), r(1, 9)),
            ((2, 0, 2), r(1, 1)),
            ((2, 2, 0), r(1, 1)),
            ((2, 2, 2), r(2, 7)),
            ((2, 2, 4), r(2, 7)),
            ((2, 4, 2), r(2, 7)),
            ((2, 4, 4), r(100, 693)),
            ((4, 0, 4), r(1, 1)),
            ((4, 2, 2), r(18, 35)),
            ((4, 2, 4), r(20, 77)),
            ((4, 4, 0), r(1, 1)),
            ((4, 4, 2), r(20, 77)),
            ((4, 4, 4), r(162, 1001)),
            ((0, 2, 0), r(0, 1)),
            ((0, 2, 4), r(0, 1)),
        ];
        for ((l, a, b), expected) in &table {
            assert_eq!(&wilson_rational(*l, *a, *b), expected, "({l}, {a}, {b})");
        }
        // Every other combination with ℓ, ℓ', ℓ'' ≤ 4 vanishes.
        for l in (0..=4).step_by(2) {
            for a in (0..=4).step_by(2) {
                for b in (0..=4).step_by(2) {
                    let listed = table.iter().any(|(key, _)| *key == (l, a, b));
                    if !listed {
                        assert!(wilson_rational(l, a, b).is_zero(), "({l}, {a}, {b})");
                    }
                }
            }
        }
    }

    /// Σ_ℓ'' (2ℓ''+1)(ℓ ℓ' ℓ''; 000)² = 1 (orthogonality), and ℓ'' = 0 couples ℓ' = ℓ with weight 1.
    #[test]
    fn orthogonality_and_symmetry() {
        for l in 0..=8 {
            for a in 0..=8 {
                let total: BigRational = (0..=16)
                    .map(|b| three_j_zero_squared(l, a, b) * r(2 * b as i64 + 1, 1))
                    .fold(BigRational::zero(), |s, x| s + x);
                assert_eq!(total, r(1, 1), "ℓ = {l}, ℓ' = {a}");
                assert_eq!(three_j_zero_squared(l, a, 3), three_j_zero_squared(3, l, a));
            }
            assert_eq!(wilson_rational(l, l, 0), r(1, 1));
        }
        assert!((wilson(8, 8, 8) - wilson_rational(8, 8, 8).to_f64().unwrap()).abs() < 1e-16);
    }
}
