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
    /// result is printed as a reduced fraction. The total size of the numbers is capped per order (300
    /// digits for n = 7), as the cost grows steeply with it.
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
    if args.exact {
        let vectors: Vec<[BigRational; 3]> = args
            .q
            .iter()
            .map(|s| parse_vector(s))
            .collect::<Result<_>>()?;
        check_exact_size(&vectors)?;
        let value = pick(args.which, kernels(&vectors)?);
        println!("{}", format_rational(&value));
    } else {
        let v: Vec<[f64; 3]> = args
            .q
            .iter()
            .map(|s| parse_float_vector(s))
            .collect::<Result<_>>()?;
        if let Some(note) = pt_kernels::cancellation_note(&v) {
            eprintln!("warning: {note}");
        }
        println!(
            "{}",
            finite(args.which, &args.q, pick(args.which, kernels(&v)?))?
        );
    }
    Ok(())
}

/// `value` if finite; otherwise an error naming the kernel and the inputs. Components near the ends of
/// the f64 range overflow (or underflow to zero) in the dot products of the kernel's Gram matrix.
fn finite(which: Which, q: &[String], value: f64) -> Result<f64> {
    if value.is_finite() {
        return Ok(value);
    }
    let name = match which {
        Which::F => "F",
        Which::G => "G",
    };
    let args: Vec<String> = q.iter().map(|v| format!("--q {v}")).collect();
    bail!(
        "{name}_{n} at {} is {value} in f64: the dot products of the vectors overflow or underflow. \
         The kernels are unchanged when all vectors are scaled by one factor: rescale them, or use --exact",
        args.join(" "),
        n = q.len()
    )
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

/// Longest component of an exact vector, in characters, and largest |exponent| of a decimal one: an
/// exponent such as `1e999999999` would otherwise take forever to expand.
const MAX_EXACT_DIGITS: usize = 10_000;

/// For n = 1..=7 vectors, the most decimal digits all exact components may have together (numerators
/// and denominators in lowest terms). The cost of the exact kernel grows about as the square of the size
/// of the numbers and sevenfold per order; these keep one evaluation under about 20 s on one core
/// (random fractions of 10 digits over 10 digits in all 21 components of F_7 take about 12 s).
const EXACT_DIGIT_BUDGET: [usize; MAX_ORDER] = [60_000, 30_000, 12_000, 5_000, 2_000, 600, 300];

/// Refuses exact vectors whose numbers are too large for the exact kernel to finish in reasonable time.
fn check_exact_size(vectors: &[[BigRational; 3]]) -> Result<()> {
    let digits = |x: &BigInt| (x.bits() as f64 * std::f64::consts::LOG10_2).ceil() as usize;
    let total: usize = vectors
        .iter()
        .flatten()
        .map(|c| digits(c.numer()) + digits(c.denom()))
        .sum();
    let n = vectors.len();
    let budget = EXACT_DIGIT_BUDGET[n.clamp(1, MAX_ORDER) - 1];
    if total > budget {
        bail!(
            "--exact: the components have about {total} digits in all (numerators and denominators in \
             lowest terms), at most {budget} for n = {n}: the exact kernel's cost grows steeply with the \
             size of the numbers. Use fewer digits, or f64 (without --exact)"
        );
    }
    Ok(())
}

/// Parses `3`, `-2/7` or `0.125` (decimals are converted exactly) into a rational.
fn parse_rational(c: &str) -> Result<BigRational> {
    let bad = || anyhow::anyhow!("component '{c}' is not an integer, a fraction p/q or a decimal");
    let too_long = || {
        anyhow::anyhow!(
            "component '{}' is too large for exact arithmetic: at most {MAX_EXACT_DIGITS} characters \
             and |exponent| <= {MAX_EXACT_DIGITS}",
            shorten(c)
        )
    };
    if c.len() > MAX_EXACT_DIGITS {
        return Err(too_long());
    }
    if let Some((p, q)) = c.split_once('/') {
        let p = BigInt::from_str(p.trim()).map_err(|_| bad())?;
        let q = BigInt::from_str(q.trim()).map_err(|_| bad())?;
        if q.is_zero() {
            bail!("component '{c}' has a zero denominator");
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

/// `c`, cut to 40 characters for a message.
fn shorten(c: &str) -> String {
    match c.char_indices().nth(40) {
        Some((i, _)) => format!("{}…", &c[..i]),
        None => c.to_string(),
    }
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
        // f64 components need no rational parse: a huge exponent is just not finite there.
        assert!(parse_float_vector("1e999999999,0,0")
            .unwrap_err()
            .to_string()
            .contains("not finite"));
    }

    #[test]
    fn overflowing_f64_kernels_are_errors_naming_the_inputs() {
        let q: Vec<String> = ["1e200,0,0", "-1e200,1e-200,0"].map(String::from).to_vec();
        let v: Vec<[f64; 3]> = q.iter().map(|s| parse_float_vector(s).unwrap()).collect();
        for which in [Which::F, Which::G] {
            let value = pick(which, kernels(&v).unwrap());
            assert!(!value.is_finite(), "{value}");
            let e = finite(which, &q, value).unwrap_err().to_string();
            assert!(e.contains("--q 1e200,0,0 --q -1e200,1e-200,0"), "{e}");
            assert!(e.contains("_2 at") && e.contains("--exact"), "{e}");
        }
        let max = format!("{:e},1,0", f64::MAX);
        let q = vec![max.clone(), "1,1,1".to_string(), max];
        let v: Vec<[f64; 3]> = q.iter().map(|s| parse_float_vector(s).unwrap()).collect();
        let value = pick(Which::F, kernels(&v).unwrap());
        assert!(finite(Which::F, &q, value).is_err(), "{value}");
        assert_eq!(finite(Which::G, &q, 0.25).unwrap(), 0.25);
    }

    #[test]
    fn fractions_print_reduced() {
        assert_eq!(format_rational(&q(34, 42)), "17/21");
        assert_eq!(format_rational(&q(-4, 2)), "-2");
    }
}
