//! `pt-spectra kernel F|G|Z --q x,y,z [--q …] [--f F] [--los x,y,z] [--exact]`.

use anyhow::{bail, Context, Result};
use num_rational::BigRational;
use pt_kernels::exact::{check_exact_size, format_rational, parse_rational};
use pt_kernels::{kernels, Scalar, MAX_ORDER};
use std::str::FromStr;

/// Which kernel to print.
#[derive(Clone, Copy, Debug, clap::ValueEnum)]
pub enum Which {
    /// The density kernel F_n^s.
    F,
    /// The velocity-divergence kernel G_n^s.
    G,
    /// The redshift-space kernel Z_n (Scoccimarro, Couchman & Frieman 1999), n ≤ 5; needs --f.
    Z,
}

/// Arguments of `pt-spectra kernel`.
#[derive(clap::Args, Debug)]
pub struct Args {
    /// F (density), G (velocity divergence) or Z (density in redshift space).
    #[arg(value_enum, ignore_case = true)]
    which: Which,
    /// The growth rate f of Z (a number, or p/q with --exact).
    #[arg(long, allow_hyphen_values = true)]
    f: Option<String>,
    /// The line of sight of Z as x,y,z (only its direction enters).
    #[arg(
        long,
        value_name = "X,Y,Z",
        default_value = "0,0,1",
        allow_hyphen_values = true
    )]
    los: String,
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
    if let Which::Z = args.which {
        return run_redshift(args);
    }
    if args.f.is_some() {
        bail!(
            "--f is for the redshift-space kernel Z, not {:?}",
            args.which
        );
    }
    if args.exact {
        let value = pick(args.which, kernels(&exact_vectors(&args.q)?)?);
        println!("{}", format_rational(&value));
    } else {
        let v = float_vectors(&args.q)?;
        println!(
            "{}",
            finite(args.which, &args.q, pick(args.which, kernels(&v)?))?
        );
    }
    Ok(())
}

/// The --q vectors in exact rationals, within the size budget of their order.
fn exact_vectors(q: &[String]) -> Result<Vec<[BigRational; 3]>> {
    let vectors: Vec<[BigRational; 3]> =
        q.iter().map(|s| parse_vector(s)).collect::<Result<_>>()?;
    check_exact_size(&vectors).context("--exact")?;
    Ok(vectors)
}

/// The --q vectors in f64, with a warning if their lengths differ enough to cost digits.
fn float_vectors(q: &[String]) -> Result<Vec<[f64; 3]>> {
    let v: Vec<[f64; 3]> = q
        .iter()
        .map(|s| parse_float_vector(s))
        .collect::<Result<_>>()?;
    if let Some(note) = pt_kernels::cancellation_note(&v) {
        eprintln!("warning: {note}");
    }
    Ok(v)
}

/// `kernel Z`: Z_n of the --q vectors with --f along --los.
fn run_redshift(args: &Args) -> Result<()> {
    use pt_kernels::redshift::{redshift_kernel, MAX_REDSHIFT_ORDER};
    let n = args.q.len();
    if n > MAX_REDSHIFT_ORDER {
        bail!("Z_n is available for n <= {MAX_REDSHIFT_ORDER}, got {n} --q vectors");
    }
    let Some(f) = &args.f else {
        bail!("kernel Z needs the growth rate: --f F (e.g. --f 0.75)");
    };
    if args.exact {
        let vectors = exact_vectors(&args.q)?;
        let f = parse_rational(f).context("--f")?;
        let los = parse_vector(&args.los).context("--los")?;
        println!("{}", format_rational(&redshift_kernel(&vectors, &f, &los)?));
    } else {
        let v = float_vectors(&args.q)?;
        let f: f64 = f
            .parse()
            .ok()
            .filter(|x: &f64| x.is_finite())
            .with_context(|| format!("--f '{f}' is not a finite number"))?;
        let los = parse_float_vector(&args.los).context("--los")?;
        println!(
            "{}",
            finite(args.which, &args.q, redshift_kernel(&v, &f, &los)?)?
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
        Which::Z => "Z",
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
        Which::G => g,
        _ => f,
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

#[cfg(test)]
mod tests {
    use super::*;

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
    fn huge_f64_components_are_not_finite() {
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
}
