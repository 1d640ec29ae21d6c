//! Exact-rational input for the kernels: parsing `3`, `-2/7`, `0.125`, `1.5e-2` into rationals, the
//! guard that refuses numbers too large for the exact kernel to finish, and printing a reduced fraction.
//! The command line and the Python module both parse through here.

use crate::MAX_ORDER;
use num_bigint::BigInt;
use num_rational::BigRational;
use num_traits::{One, Zero};
use std::str::FromStr;

/// Longest component, in characters, and largest |exponent| of a decimal one: an exponent such as
/// `1e999999999` would otherwise take forever to expand.
pub const MAX_EXACT_DIGITS: usize = 10_000;

/// For n = 1..=7 vectors, the most decimal digits all exact components may have together (numerators
/// and denominators in lowest terms). The cost of the exact kernel grows about as the square of the size
/// of the numbers and sevenfold per order; these keep one evaluation under about 20 s on one core
/// (random fractions of 10 digits over 10 digits in all 21 components of F_7 take about 12 s).
pub const EXACT_DIGIT_BUDGET: [usize; MAX_ORDER] = [60_000, 30_000, 12_000, 5_000, 2_000, 600, 300];

/// Why an exact input was refused.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum ExactInputError {
    /// Not an integer, a fraction or a decimal.
    #[error("component '{0}' is not an integer, a fraction p/q or a decimal")]
    NotANumber(String),
    /// A fraction with denominator 0.
    #[error("component '{0}' has a zero denominator")]
    ZeroDenominator(String),
    /// Too many characters or too large an exponent.
    #[error(
        "component '{0}' is too large for exact arithmetic: at most {MAX_EXACT_DIGITS} characters and \
         |exponent| <= {MAX_EXACT_DIGITS}"
    )]
    TooLong(String),
    /// The numbers together are too large for the exact kernel of this order.
    #[error(
        "the components have about {total} digits in all (numerators and denominators in lowest \
         terms), at most {budget} for n = {n}: the exact kernel's cost grows steeply with the size of \
         the numbers. Use fewer digits, or f64"
    )]
    TooManyDigits {
        /// Digits of all components.
        total: usize,
        /// The budget of order n.
        budget: usize,
        /// The order.
        n: usize,
    },
}

/// Parses `3`, `-2/7` or `0.125` (decimals, with an optional exponent, are converted exactly).
///
/// # Errors
/// [`ExactInputError`] naming the component.
pub fn parse_rational(c: &str) -> Result<BigRational, ExactInputError> {
    let c = c.trim();
    let bad = || ExactInputError::NotANumber(shorten(c));
    let too_long = || ExactInputError::TooLong(shorten(c));
    if c.len() > MAX_EXACT_DIGITS {
        return Err(too_long());
    }
    if let Some((p, q)) = c.split_once('/') {
        let p = BigInt::from_str(p.trim()).map_err(|_| bad())?;
        let q = BigInt::from_str(q.trim()).map_err(|_| bad())?;
        if q.is_zero() {
            return Err(ExactInputError::ZeroDenominator(shorten(c)));
        }
        return Ok(BigRational::new(p, q));
    }
    let (mantissa, exponent) = match c.find(['e', 'E']) {
        Some(i) => (&c[..i], i64::from_str(&c[i + 1..]).map_err(|_| bad())?),
        None => (c, 0),
    };
    // Checked before expanding 10^exponent; also keeps the scale arithmetic far from overflow.
    if exponent.unsigned_abs() > MAX_EXACT_DIGITS as u64 {
        return Err(too_long());
    }
    let (int, frac) = mantissa.split_once('.').unwrap_or((mantissa, ""));
    if int.trim_start_matches(['-', '+']).is_empty() && frac.is_empty() {
        return Err(bad());
    }
    let digits = format!("{int}{frac}");
    let digits = if digits == "-" || digits == "+" {
        format!("{digits}0")
    } else {
        digits
    };
    let num = BigInt::from_str(&digits).map_err(|_| bad())?;
    // |exponent| ≤ MAX_EXACT_DIGITS and frac.len() ≤ c.len(): no overflow, and a small power.
    let scale = exponent - frac.len() as i64;
    let factor = BigRational::from_integer(num_traits::pow(
        BigInt::from(10),
        scale.unsigned_abs() as usize,
    ));
    let value = BigRational::from_integer(num);
    Ok(if scale >= 0 {
        value * factor
    } else {
        value / factor
    })
}

/// Refuses exact vectors whose numbers are too large for the exact kernel to finish in reasonable
/// time ([`EXACT_DIGIT_BUDGET`]).
///
/// # Errors
/// [`ExactInputError::TooManyDigits`].
pub fn check_exact_size(vectors: &[[BigRational; 3]]) -> Result<(), ExactInputError> {
    let digits = |x: &BigInt| (x.bits() as f64 * std::f64::consts::LOG10_2).ceil() as usize;
    let total: usize = vectors
        .iter()
        .flatten()
        .map(|c| digits(c.numer()) + digits(c.denom()))
        .sum();
    let n = vectors.len();
    let budget = EXACT_DIGIT_BUDGET[n.clamp(1, MAX_ORDER) - 1];
    if total > budget {
        return Err(ExactInputError::TooManyDigits { total, budget, n });
    }
    Ok(())
}

/// `p/q` in lowest terms, or an integer.
pub fn format_rational(r: &BigRational) -> String {
    if r.denom().is_one() {
        r.numer().to_string()
    } else {
        format!("{}/{}", r.numer(), r.denom())
    }
}

/// `c`, cut to 40 characters for a message.
fn shorten(c: &str) -> String {
    match c.char_indices().nth(40) {
        Some((i, _)) => format!("{}…", &c[..i]),
        None => c.to_string(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn q(n: i64, d: i64) -> BigRational {
        BigRational::new(n.into(), d.into())
    }

    #[test]
    fn rationals_parse_exactly() {
        assert_eq!(parse_rational("3").unwrap(), q(3, 1));
        assert_eq!(parse_rational("-2/6").unwrap(), q(-1, 3));
        assert_eq!(parse_rational("0.125").unwrap(), q(1, 8));
        assert_eq!(parse_rational("-1.5e-2").unwrap(), q(-3, 200));
        assert_eq!(parse_rational("2E3").unwrap(), q(2000, 1));
        assert_eq!(parse_rational(" 7/2 ").unwrap(), q(7, 2));
        for bad in ["", "x", "1/0", "1/", ".", "-", "1.2.3"] {
            assert!(parse_rational(bad).is_err(), "{bad:?} must be refused");
        }
    }

    #[test]
    fn huge_exact_components_are_refused_quickly() {
        let start = std::time::Instant::now();
        for huge in [
            "1e999999999",
            "1.5e-2147483648",
            "1e-2147483649",
            "-7E+10001",
            &"9".repeat(10_001),
            &format!("1/{}", "3".repeat(10_000)),
        ] {
            let e = parse_rational(huge).unwrap_err().to_string();
            assert!(e.contains("too large for exact arithmetic"), "{e}");
            assert!(e.len() < 200, "{e}");
        }
        let e = parse_rational("1e99999999999999999999").unwrap_err();
        assert!(e.to_string().contains("is not an integer"), "{e}");
        assert!(start.elapsed().as_secs() < 5);
        // At the cap: still exact.
        let big = parse_rational("1e10000").unwrap();
        assert_eq!(big, BigRational::from_integer(BigInt::from(10).pow(10_000)));
        assert_eq!(parse_rational("25e-10000").unwrap() * &big, q(25, 1));
        // Within the cap, but more than the exact kernel of this order can take in reasonable time.
        let one = || [q(1, 1), q(0, 1), q(2, 3)];
        let mut vectors = vec![one(), [big.clone(), q(1, 1), q(0, 1)]];
        assert!(check_exact_size(&vectors).is_ok());
        vectors.extend([one(), one(), one(), one(), one()]);
        let e = check_exact_size(&vectors).unwrap_err().to_string();
        assert!(e.contains("at most 300 for n = 7"), "{e}");
        assert!(check_exact_size(&[one(), one(), one(), one(), one(), one(), one()]).is_ok());
    }

    #[test]
    fn fractions_print_reduced() {
        assert_eq!(format_rational(&q(34, 42)), "17/21");
        assert_eq!(format_rational(&q(-4, 2)), "-2");
    }
}
