//! The emulator file: little-endian binary written by `pt-spectra/data/fit_emulator.py`.
//!
//! ```text
//! magic        8 bytes  "PTEMU001"
//! n_terms      u32      polynomial terms
//! n_z          u32      redshift nodes
//! n_x          u32      wavenumber nodes
//! rescale      u32      1: the nodes are x = k r_d (r_d the drag sound horizon in Mpc/h), 0: x = k
//! n_pc         2 × u32  principal components of ln(P_cb/A_s) and of ln(P_m/P_cb)
//! prior        8 × (f64 min, f64 max)
//! z_nodes      n_z × f64
//! ln_x         f64 min, f64 max (uniform in ln x)
//! early DE     f64 a_e, f64 q_max: the seventh coordinate is 2 √(q/q_max) − 1, q = ρ_DE/ρ_m at a_e
//! exponents    n_terms × 7 u8 (Legendre degrees of the seven coordinates of each term)
//! 2 × target   mean n_z·n_x f64; components n_pc·n_z·n_x f32; coefficients n_terms·n_pc f64
//! error        2 × n_x f64: |Δ ln P| of P_cb and of P_m on the test set (99th percentile over
//!              cosmologies and redshifts, per x)
//! ```

use super::prior::{PriorRange, COORDINATES, PARAMETER_NAMES};
use crate::error::{Error, Result};

/// The magic bytes that open an emulator file of this layout.
pub const MAGIC: &[u8; 8] = b"PTEMU001";

/// One emulated quantity (a function of x and z): mean + Σ_j c_j(θ) V_j, with c_j a polynomial in θ.
#[derive(Debug, Clone)]
pub struct Target {
    /// Mean over the training set, n_z × n_x.
    pub mean: Vec<f64>,
    /// Principal components, n_pc × (n_z × n_x).
    pub components: Vec<f32>,
    /// Polynomial coefficients, n_terms × n_pc.
    pub coefficients: Vec<f64>,
    /// Number of principal components.
    pub n_pc: usize,
}

/// The parsed file.
#[derive(Debug, Clone)]
pub struct Parsed {
    pub prior: Vec<PriorRange>,
    pub z_nodes: Vec<f64>,
    pub ln_x: (f64, f64),
    pub n_x: usize,
    pub rescale: bool,
    pub exponents: Vec<[u8; COORDINATES]>,
    pub a_early: f64,
    pub q_max: f64,
    pub targets: [Target; 2],
    pub error: [Vec<f64>; 2],
}

/// A cursor over the bytes that names the file and the offset in its errors.
struct Reader<'a> {
    bytes: &'a [u8],
    at: usize,
    what: &'a str,
}

impl<'a> Reader<'a> {
    fn fail(&self, reason: &'static str) -> Error {
        Error::BadDataFile {
            what: self.what.to_string(),
            offset: self.at,
            reason,
        }
    }

    fn take(&mut self, n: usize) -> Result<&'a [u8]> {
        let end = self.at.checked_add(n).filter(|&e| e <= self.bytes.len());
        let end = end.ok_or_else(|| self.fail("file ends early"))?;
        let out = &self.bytes[self.at..end];
        self.at = end;
        Ok(out)
    }

    /// The bytes of `n` values of `width` bytes, if that does not overflow.
    fn bytes_of(&self, n: usize, width: usize) -> Result<usize> {
        n.checked_mul(width)
            .ok_or_else(|| self.fail("a table size is implausibly large"))
    }

    fn count(&mut self, max: usize) -> Result<usize> {
        let b = self.take(4)?;
        let v = u32::from_le_bytes([b[0], b[1], b[2], b[3]]) as usize;
        if v == 0 || v > max {
            return Err(self.fail("a count is zero or implausibly large"));
        }
        Ok(v)
    }

    /// `n` values, `n` bounded by the counts of the header ([`Self::count`]) and checked against the
    /// bytes left before anything is allocated.
    fn f64s(&mut self, n: usize) -> Result<Vec<f64>> {
        let b = self.take(self.bytes_of(n, 8)?)?;
        let v: Vec<f64> = b
            .chunks_exact(8)
            .map(|c| f64::from_le_bytes(c.try_into().expect("8 bytes")))
            .collect();
        if v.iter().any(|x| !x.is_finite()) {
            return Err(self.fail("a number is not finite"));
        }
        Ok(v)
    }

    fn f32s(&mut self, n: usize) -> Result<Vec<f32>> {
        let b = self.take(self.bytes_of(n, 4)?)?;
        let v: Vec<f32> = b
            .chunks_exact(4)
            .map(|c| f32::from_le_bytes(c.try_into().expect("4 bytes")))
            .collect();
        if v.iter().any(|x| !x.is_finite()) {
            return Err(self.fail("a number is not finite"));
        }
        Ok(v)
    }
}

/// Parses an emulator file; `what` names it in errors.
///
/// # Errors
/// [`Error::BadDataFile`] with the byte offset where the layout is broken.
pub fn parse(bytes: &[u8], what: &str) -> Result<Parsed> {
    let mut r = Reader { bytes, at: 0, what };
    if r.take(8)? != MAGIC {
        return Err(r.fail("not an emulator file of layout PTEMU001"));
    }
    let n_terms = r.count(100_000)?;
    let n_z = r.count(1000)?;
    let n_x = r.count(100_000)?;
    let rescale = r.take(4)?[0] == 1;
    let n_pc = [r.count(10_000)?, r.count(10_000)?];
    let bounds = r.f64s(16)?;
    let prior: Vec<PriorRange> = PARAMETER_NAMES
        .iter()
        .enumerate()
        .map(|(i, &name)| PriorRange {
            name,
            min: bounds[2 * i],
            max: bounds[2 * i + 1],
        })
        .collect();
    if prior.iter().any(|p| p.min >= p.max) {
        return Err(r.fail("a prior range is empty"));
    }
    let z_nodes = r.f64s(n_z)?;
    if z_nodes.windows(2).any(|w| w[0] >= w[1]) || n_z < 4 {
        return Err(r.fail("redshift nodes must increase, and be at least 4"));
    }
    let lx = r.f64s(4)?;
    if !(lx[0] < lx[1] && lx[2] > 0.0 && lx[2] < 1.0 && lx[3] > 0.0) {
        return Err(r.fail("bad wavenumber range or early-dark-energy coordinate"));
    }
    let exponents = r
        .take(r.bytes_of(n_terms, COORDINATES)?)?
        .chunks_exact(COORDINATES)
        .map(|c| c.try_into().expect("seven exponents"))
        .collect();
    let mut target = |n_pc: usize| -> Result<Target> {
        Ok(Target {
            // Products of counts each bounded by `count` (≤ 1e4 × 1e3 × 1e5): no overflow.
            mean: r.f64s(n_z * n_x)?,
            components: r.f32s(n_pc * n_z * n_x)?,
            coefficients: r.f64s(n_terms * n_pc)?,
            n_pc,
        })
    };
    let targets = [target(n_pc[0])?, target(n_pc[1])?];
    let error = [r.f64s(n_x)?, r.f64s(n_x)?];
    if r.at != bytes.len() {
        return Err(r.fail("bytes left after the last table"));
    }
    Ok(Parsed {
        prior,
        z_nodes,
        ln_x: (lx[0], lx[1]),
        n_x,
        rescale,
        exponents,
        a_early: lx[2],
        q_max: lx[3],
        targets,
        error,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A crafted header (the largest counts allowed, or a count beyond them) on a file too short for
    /// them: an error naming the file and the byte offset, before any table is allocated.
    #[test]
    fn a_crafted_header_is_an_error_naming_the_file() {
        let header = |counts: [u32; 3]| {
            let mut b = MAGIC.to_vec();
            for c in counts {
                b.extend(c.to_le_bytes());
            }
            b.extend([0u8; 4]);
            for c in [10_000u32, 10_000] {
                b.extend(c.to_le_bytes());
            }
            for i in 0..8 {
                b.extend((i as f64).to_le_bytes());
                b.extend((i as f64 + 1.0).to_le_bytes());
            }
            b
        };
        let e = parse(&header([100_000, 1000, 100_000]), "crafted.bin")
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("crafted.bin") && e.contains("file ends early"),
            "{e}"
        );
        let e = parse(&header([u32::MAX, 1000, 100_000]), "crafted.bin")
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("crafted.bin") && e.contains("implausibly large"),
            "{e}"
        );
    }
}
