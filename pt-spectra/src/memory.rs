//! Memory limits of plans, checked before they allocate, so that a grid too large for the machine
//! is an error with the figure rather than a process that grows until the machine runs out.
//!
//! Each plan states its own estimate (e.g. [`crate::loops::OneLoopPlan::memory_estimate`],
//! [`crate::real::RealPlan::memory_estimate`], which sums the plans it holds; the [`crate::plan::Plan`]
//! trait's `bytes`): the measured peak resident memory of the release binary (2 December 2026,
//! `--precision default`, k up to 1 h/Mpc) per output k, scaled with the node density of the P22-type
//! rules ([`node_density`]), rounded up. This module holds what they share: the process's own
//! memory ([`PROCESS`]), the limit ([`limit`]) and the check ([`check`]).
//!
//! ```
//! use pt_spectra::{memory, precision::Precision, real::{RealModel, RealPlan}};
//! let e = RealPlan::memory_estimate(100_000, RealModel::OneLoopSpt, &Precision::default());
//! assert!(e > 30e9 && e < 60e9); // ~0.4 MB per k
//! let mut p = Precision::default();
//! p.max_memory = Some(1e9);
//! let err = memory::check(e, &p, "1l-spt on 100000 k").unwrap_err().to_string();
//! assert!(err.contains("1l-spt on 100000 k needs about 40 GB") && err.contains("above 1.0 GB"), "{err}");
//! ```

use crate::error::{Error, Result};
use crate::precision::Precision;

/// Bytes of the process itself (binary, runtime, the embedded tables), counted once in every plan's
/// check.
pub const PROCESS: f64 = 20e6;

/// The node density of the P22-type rules of `precision` relative to the default, by which the
/// plans on those rules scale their bytes per k: ~(order / panel width)² nodes per k, 20² at the
/// default.
pub fn node_density(precision: &Precision) -> f64 {
    (precision.p22_order as f64 / precision.p22_ln_width / 20.0).powi(2)
}

/// The environment variable both faces read for the limit when it is not given (`8G`, `500M`, …).
pub const ENV: &str = "PT_SPECTRA_MAX_MEMORY";

/// The limit of [`ENV`], if set.
///
/// # Errors
/// As [`parse_size`], naming the variable.
pub fn env_max_memory() -> Result<Option<f64>> {
    match std::env::var(ENV) {
        Ok(text) => parse_size(&text)
            .map(Some)
            .map_err(|e| Error::InvalidChoice {
                what: format!("${ENV}"),
                reason: e.to_string(),
            }),
        Err(_) => Ok(None),
    }
}

/// The fraction of the machine's memory a plan may take by default.
pub const DEFAULT_FRACTION: f64 = 0.5;

/// The total memory of this machine \[bytes\] (`MemTotal` of `/proc/meminfo`), if known.
pub fn machine_bytes() -> Option<f64> {
    let text = std::fs::read_to_string("/proc/meminfo").ok()?;
    let line = text.lines().find(|l| l.starts_with("MemTotal:"))?;
    let kib: f64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kib * 1024.0)
}

/// The limit that applies: `precision.max_memory` (which the faces set from `--max-memory` or
/// [`ENV`]), else [`DEFAULT_FRACTION`] of the machine's memory
/// (8 GB where it is not known), with a description of where it came from.
pub fn limit(precision: &Precision) -> (f64, String) {
    match (precision.max_memory, machine_bytes()) {
        (Some(limit), _) => (limit, format!("the limit given by --max-memory or ${ENV}")),
        (None, Some(machine)) => (
            DEFAULT_FRACTION * machine,
            format!(
                "the default limit, half of this machine's {}; --max-memory or ${ENV} \
                 changes it",
                size(machine)
            ),
        ),
        (None, None) => (
            8e9,
            format!(
                "the default limit where the machine's memory is unknown; --max-memory or ${ENV} \
                 changes it"
            ),
        ),
    }
}

/// The address space \[bytes\] this process may still map under an address-space limit (`ulimit -v`,
/// `RLIMIT_AS`): the limit of `/proc/self/limits` less the `VmSize` of `/proc/self/status`; `None`
/// without such a limit (or off Linux). Beyond it an allocation fails, which Rust turns into an abort,
/// so plans that allocate per user input (batches) count it as part of their limit.
pub fn address_space_left() -> Option<f64> {
    let limits = std::fs::read_to_string("/proc/self/limits").ok()?;
    let line = limits
        .lines()
        .find(|l| l.starts_with("Max address space"))?;
    let soft: f64 = line
        .trim_start_matches("Max address space")
        .split_whitespace()
        .next()?
        .parse()
        .ok()?;
    let status = std::fs::read_to_string("/proc/self/status").ok()?;
    let kib: f64 = status
        .lines()
        .find(|l| l.starts_with("VmSize:"))?
        .split_whitespace()
        .nth(1)?
        .parse()
        .ok()?;
    Some((soft - kib * 1024.0).max(0.0))
}

/// An allocation of `bytes` for `what` that failed (the system gave less than [`limit`] allows: an
/// address-space limit, or the machine's memory), as [`Error::MemoryLimit`].
pub fn allocation_failed(bytes: f64, what: &str) -> Error {
    Error::MemoryLimit {
        what: what.to_string(),
        needed: size(bytes),
        limit: "what the system gives this process".into(),
        origin: "the allocation failed: an address-space limit (ulimit -v) or the machine's \
                 memory; a smaller batch or a larger limit helps"
            .into(),
    }
}

/// `bytes` against the limit of `precision`; `what` says what would be built.
///
/// # Errors
/// [`Error::MemoryLimit`] with both figures if the estimate exceeds the limit.
pub fn check(bytes: f64, precision: &Precision, what: &str) -> Result<()> {
    let (limit, source) = limit(precision);
    if bytes > limit {
        return Err(Error::MemoryLimit {
            what: what.to_string(),
            needed: size(bytes),
            limit: size(limit),
            origin: source,
        });
    }
    Ok(())
}

/// [`check`], and `bytes` against the address space the process has left
/// ([`address_space_left`]), for allocations that would otherwise abort the process.
///
/// # Errors
/// [`Error::MemoryLimit`] with both figures.
pub fn check_allocation(bytes: f64, precision: &Precision, what: &str) -> Result<()> {
    check(bytes, precision, what)?;
    match address_space_left() {
        Some(left) if bytes > left => Err(Error::MemoryLimit {
            what: what.to_string(),
            needed: size(bytes),
            limit: size(left),
            origin: "the address space this process has left under its limit (ulimit -v)".into(),
        }),
        _ => Ok(()),
    }
}

/// `bytes` as `12 GB`, `340 MB` (decimal units, two significant figures).
pub fn size(bytes: f64) -> String {
    let (value, unit) = [(1e12, "TB"), (1e9, "GB"), (1e6, "MB"), (1e3, "kB")]
        .into_iter()
        .find(|&(scale, _)| bytes >= scale)
        .map_or((bytes, "bytes"), |(scale, unit)| (bytes / scale, unit));
    let digits = if value >= 10.0 { 0 } else { 1 };
    format!("{value:.digits$} {unit}")
}

/// A size such as `8G`, `500M`, `2.5GB`, `1e9` (bytes) or `64k`: decimal units.
///
/// # Errors
/// [`Error::InvalidChoice`] if it is not a positive number with an optional k, M, G, T (B) suffix.
pub fn parse_size(text: &str) -> Result<f64> {
    let t = text.trim();
    let t = t.strip_suffix(['B', 'b']).unwrap_or(t);
    let (number, scale) = match t.char_indices().last() {
        Some((i, 'k' | 'K')) => (&t[..i], 1e3),
        Some((i, 'M' | 'm')) => (&t[..i], 1e6),
        Some((i, 'G' | 'g')) => (&t[..i], 1e9),
        Some((i, 'T' | 't')) => (&t[..i], 1e12),
        _ => (t, 1.0),
    };
    match number.trim().parse::<f64>() {
        Ok(v) if v.is_finite() && v > 0.0 => Ok(v * scale),
        _ => Err(Error::InvalidChoice {
            what: format!("memory size `{text}`"),
            reason: "expected a positive number of bytes, optionally with k, M, G or T (e.g. 8G)"
                .into(),
        }),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::loops::TnsPlan;
    use crate::real::{RealModel, RealPlan};

    #[test]
    fn sizes_are_parsed_and_printed() {
        assert_eq!(parse_size("8G").unwrap(), 8e9);
        assert_eq!(parse_size("500MB").unwrap(), 5e8);
        assert_eq!(parse_size("1e9").unwrap(), 1e9);
        assert_eq!(parse_size(" 2.5 g").unwrap(), 2.5e9);
        for bad in ["", "G", "-1G", "0", "nan", "8X", "inf"] {
            assert!(parse_size(bad).is_err(), "{bad}");
        }
        assert_eq!(size(3.4e12), "3.4 TB");
        assert_eq!(size(714e6), "714 MB");
        assert_eq!(size(12.0), "12 bytes");
    }

    /// The estimate is above what was measured, within a factor 2.5 (the measurements in the module docs).
    #[test]
    fn estimates_bound_the_measured_memory() {
        let d = Precision::default();
        for (nk, model, tns, preset, measured) in [
            (1000, RealModel::OneLoopSpt, false, "default", 340e6),
            (200, RealModel::OneLoopSpt, false, "fast", 36e6),
            (200, RealModel::OneLoopSpt, false, "reference", 962e6),
            (300, RealModel::OneLoopSpt, true, "default", 356e6),
            (80, RealModel::TwoLoopRegPt, false, "default", 118e6),
        ] {
            let p = Precision::preset(preset).unwrap();
            let tns = if tns {
                TnsPlan::memory_estimate(nk, &p)
            } else {
                0.0
            };
            let e = RealPlan::memory_estimate(nk, model, &p) + tns;
            assert!(
                e >= measured && e < 2.5 * measured,
                "{model:?} {preset} {nk}: {e:e}"
            );
        }
        assert!(RealPlan::memory_estimate(10_000_000, RealModel::OneLoopSpt, &d) > 1e12);
    }
}
