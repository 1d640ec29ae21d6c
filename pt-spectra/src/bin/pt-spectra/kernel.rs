//! `pt-spectra kernel F|G --q x,y,z [--q …] [--exact]`.

use anyhow::{bail, Context, Result};
use num_bigint::BigInt;
use num_rational::BigRational;
use num_traits::{One, Zero};
use pt_kernels::{kernels, Scalar, MAX_ORDER};
use std::str::FromStr;

/// Which kernel to print.
#[derive(Clone, Copy, Debug, clap::ValueEnum)]
pub enum Which {
    /// The density kernel F_n^s.
    F,
    /// The velocity-divergence kernel G_n^s.
    G,
}

/// Arguments of `pt-spectra kernel`.
#[derive(clap::Args, Debug)]
pub struct Args {
    /// F (density) or G (velocity divergence).
    #[arg(value_enum, ignore_case = true)]
    which: Which,
    /// One argument vector as x,y,z (h/Mpc); repeat for each of the n arguments.
    #[arg(long = "q", value_name = "X,Y,Z", allow_hyphen_values = true)]
    q: Vec<String>,
    /// Compute in exact rational arithmetic; components may be integers, fractions p/q or decimals, and the
    /// result is printed as a reduced fraction.
    #[arg(long)]
    exact: bool,
}

/// Runs the subcommand and prints the kernel on one line.
pub fn run(args: &Args) -> Result<()> {
    let n = args.q.len();
    if n == 0 {
        bail!("no argument vector given: pass one --q x,y,z per argument (1 to {MAX_ORDER})");
    }
    if n > MAX_ORDER {
        bail!("kernel order n = {n} is not supported: at most {MAX_ORDER} --q vectors");
    }
    let vectors: Vec<[BigRational; 3]> = args
        .q
        .iter()
        .map(|s| parse_vector(s))
        .collect::<Result<_>>()?;
    if args.exact {
        let value = pick(args.which, kernels(&vectors)?);
        println!("{}", format_rational(&value));
    } else {
        let v: Vec<[f64; 3]> = args
            .q
            .iter()
            .map(|s| parse_float_vector(s))
            .collect::<Result<_>>()?;
        println!("{}", pick(args.which, kernels(&v)?));
    }
    Ok(())
}

fn pick<T: Scalar>(which: Which, [f, g]: [T; 2]) -> T {
    match which {
        Which::F => f,
        Which::G => g,
    }
}

fn components(s: &str) -> Result<[&str; 3]> {
    let parts: Vec<&str> = s.split(',').map(str::trim).collect();
    match parts.as_slice() {
        [x, y, z] if !x.is_empty() && !y.is_empty() && !z.is_empty() => Ok([x, y, z]),
        _ => bail!("--q '{s}': expected three comma-separated components x,y,z"),
    }
}

fn parse_vector(s: &str) -> Result<[BigRational; 3]> {
    let [x, y, z] = components(s)?;
    let parse = |c: &str| parse_rational(c).with_context(|| format!("--q '{s}'"));
    Ok([parse(x)?, parse(y)?, parse(z)?])
}

fn parse_float_vector(s: &str) -> Result<[f64; 3]> {
    let [x, y, z] = components(s)?;
    let parse = |c: &str| -> Result<f64> {
        let v = if c.contains('/') {
            let r = parse_rational(c)?;
            f64_of(&r)
        } else {
            f64::from_str(c).map_err(|_| anyhow::anyhow!("component '{c}' is not a number"))?
        };
        if !v.is_finite() {
            bail!("component '{c}' is not finite");
        }
        Ok(v)
    };
    Ok([parse(x)?, parse(y)?, parse(z)?])
}

fn f64_of(r: &BigRational) -> f64 {
    use num_traits::ToPrimitive;
    r.to_f64().unwrap_or(f64::NAN)
}

/// Parses `3`, `-2/7` or `0.125` (decimals are converted exactly) into a rational.
fn parse_rational(c: &str) -> Result<BigRational> {
    let bad = || anyhow::anyhow!("component '{c}' is not an integer, a fraction p/q or a decimal");
    if let Some((p, q)) = c.split_once('/') {
        let p = BigInt::from_str(p.trim()).map_err(|_| bad())?;
        let q = BigInt::from_str(q.trim()).map_err(|_| bad())?;
        if q.is_zero() {
            bail!("component '{c}' has a zero denominator");
        }
        return Ok(BigRational::new(p, q));
    }
    let (mantissa, exponent) = match c.find(['e', 'E']) {
        Some(i) => (&c[..i], i32::from_str(&c[i + 1..]).map_err(|_| bad())?),
        None => (c, 0),
    };
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
    let scale = exponent - frac.len() as i32;
    let ten = BigRational::from_integer(BigInt::from(10));
    let factor = (0..scale.unsigned_abs()).fold(BigRational::one(), |acc, _| acc * &ten);
    let value = BigRational::from_integer(num);
    Ok(if scale >= 0 {
        value * factor
    } else {
        value / factor
    })
}

/// `p/q` in lowest terms, or an integer.
fn format_rational(r: &BigRational) -> String {
    if r.denom().is_one() {
        r.numer().to_string()
    } else {
        format!("{}/{}", r.numer(), r.denom())
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
        for bad in ["", "x", "1/0", "1/", ".", "-", "1.2.3"] {
            assert!(parse_rational(bad).is_err(), "{bad:?} must be refused");
        }
    }

    #[test]
    fn vectors_need_three_components() {
        assert!(parse_vector("1,2").is_err());
        assert!(parse_vector("1,2,3,4").is_err());
        assert!(parse_vector("1,,3").is_err());
        assert!(parse_float_vector("1,nan,3").is_err());
        assert!(parse_float_vector("1,inf,3").is_err());
        assert_eq!(parse_float_vector("1, 1/4 ,3").unwrap(), [1.0, 0.25, 3.0]);
    }

    #[test]
    fn fractions_print_reduced() {
        assert_eq!(format_rational(&q(34, 42)), "17/21");
        assert_eq!(format_rational(&q(-4, 2)), "-2");
    }
}
