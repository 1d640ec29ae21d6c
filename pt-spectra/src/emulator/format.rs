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
//!
//! Layout `PTEMU002` (`pt-spectra/data/fit_emulator_neutrinos.py`) is the same after its magic, then:
//!
//! ```text
//! box          6 × (f64 min, f64 max): the stated prior of the six shape parameters (inside the
//!                       training box of `prior`, which still maps them to [−1, 1])
//! q_bound      f64      the prior's bound on the early dark energy: q/q_max ≤ q_bound (in (0, 1])
//! worst        2 × f64  the measured worst |Δ ln P| of P_cb and P_m over the bounded prior
//!                       (three degenerate neutrinos)
//! n_heads      u32      heads (0 to 4: one per neutrino setting, and the massless head)
//! per head:    setting u32, n_terms u32, n_pc 2 × u32, exponents n_terms × 7 u8, 2 × target (as
//!              above with this head's n_terms and n_pc), worst 2 × f64 (as above, this head's
//!              cosmologies); setting 1: one massive species, the targets ln(P_setting/P_degenerate)
//!              of P_cb and of P_m (`fit_emulator_neutrinos.py`); setting 2: Σm_ν = 0, the targets
//!              ln P(CAMB, massless) − ln P(base emulator at Σm_ν = 0), the same for P_cb and P_m
//!              (`fit_emulator_massless.py`)
//! ```
//!
//! A `PTEMU001` file reads as box = prior, q_bound = 1, no heads, and the largest per-x error as the worst.

use super::prior::{PriorRange, COORDINATES, PARAMETER_NAMES};
use crate::cosmology::Neutrinos;
use crate::error::{Error, Result};

/// The magic bytes that open an emulator file of the first layout (no neutrino heads).
pub const MAGIC: &[u8; 8] = b"PTEMU001";

/// The magic bytes of the layout with the prior bound and the neutrino heads.
pub const MAGIC_2: &[u8; 8] = b"PTEMU002";

/// Largest Legendre degree a file may use (the Rust code builds P_0..P_max per coordinate).
const MAX_DEGREE: u8 = 30;

/// Most heads a file may hold.
const MAX_HEADS: usize = 4;

/// What a head corrects.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum HeadOf {
    /// A neutrino setting other than three degenerate species: ln(P_setting/P_degenerate).
    Setting(Neutrinos),
    /// Σm_ν = 0: CAMB's massless spectrum over the base emulator's at Σm_ν = 0 (the edge of its
    /// training box, and CAMB's massless run is not the limit of its massive runs).
    Massless,
}

/// A head: a correction to ln P_cb and ln P_m, emulated as the base targets are.
#[derive(Debug, Clone)]
pub struct Head {
    /// What it corrects.
    pub of: HeadOf,
    /// Its polynomial terms.
    pub exponents: Vec<[u8; COORDINATES]>,
    /// ln(P_cb ratio) and ln(P_m ratio).
    pub targets: [Target; 2],
    /// Measured worst |Δ ln P| of P_cb and P_m with this head's cosmologies.
    pub worst: [f64; 2],
}

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
    /// The stated prior of the six shape parameters (the training box for a `PTEMU001` file).
    pub stated: Vec<PriorRange>,
    /// q/q_max ≤ q_bound (1 for a `PTEMU001` file).
    pub q_bound: f64,
    /// Measured worst |Δ ln P| of P_cb and P_m (three degenerate neutrinos).
    pub worst: [f64; 2],
    pub heads: Vec<Head>,
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

    /// One target of `nodes` = n_z·n_x values per component.
    fn target(&mut self, nodes: usize, n_terms: usize, n_pc: usize) -> Result<Target> {
        Ok(Target {
            mean: self.f64s(nodes)?,
            components: self.f32s(n_pc * nodes)?,
            coefficients: self.f64s(n_terms * n_pc)?,
            n_pc,
        })
    }

    /// One head (layout PTEMU002).
    fn head(&mut self, nodes: usize) -> Result<Head> {
        let of = match self.count(2)? {
            1 => HeadOf::Setting(Neutrinos::OneMassive),
            2 => HeadOf::Massless,
            _ => unreachable!("count(2) is 1 or 2"),
        };
        let n_terms = self.count(100_000)?;
        let n_pc = [self.count(10_000)?, self.count(10_000)?];
        let exponents = self.exponents(n_terms)?;
        let targets = [
            self.target(nodes, n_terms, n_pc[0])?,
            self.target(nodes, n_terms, n_pc[1])?,
        ];
        let w = self.f64s(2)?;
        if w.iter().any(|&v| v < 0.0) {
            return Err(self.fail("a measured error is negative"));
        }
        Ok(Head {
            of,
            exponents,
            targets,
            worst: [w[0], w[1]],
        })
    }

    /// `n_terms` rows of seven Legendre degrees.
    fn exponents(&mut self, n_terms: usize) -> Result<Vec<[u8; COORDINATES]>> {
        let bytes = self.take(self.bytes_of(n_terms, COORDINATES)?)?;
        if bytes.iter().any(|&d| d > MAX_DEGREE) {
            return Err(self.fail("a polynomial degree is implausibly large"));
        }
        Ok(bytes
            .chunks_exact(COORDINATES)
            .map(|c| c.try_into().expect("seven exponents"))
            .collect())
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
    let magic = r.take(8)?;
    let version_2 = magic == MAGIC_2;
    if magic != MAGIC && !version_2 {
        return Err(r.fail("not an emulator file of layout PTEMU001 or PTEMU002"));
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
    let exponents = r.exponents(n_terms)?;
    let targets = [
        r.target(n_z * n_x, n_terms, n_pc[0])?,
        r.target(n_z * n_x, n_terms, n_pc[1])?,
    ];
    let error = [r.f64s(n_x)?, r.f64s(n_x)?];
    let (stated, q_bound, worst, heads) = if version_2 {
        let b = r.f64s(12)?;
        let stated: Vec<PriorRange> = prior[..6]
            .iter()
            .enumerate()
            .map(|(i, p)| PriorRange {
                name: p.name,
                min: b[2 * i],
                max: b[2 * i + 1],
            })
            .collect();
        if stated
            .iter()
            .zip(&prior)
            .any(|(s, p)| !(s.min < s.max && s.min >= p.min && s.max <= p.max))
        {
            return Err(r.fail("the stated prior must be a non-empty box inside the training box"));
        }
        let v = r.f64s(3)?;
        if !(v[0] > 0.0 && v[0] <= 1.0) || v[1] < 0.0 || v[2] < 0.0 {
            return Err(r.fail("the prior bound must be in (0, 1] and the errors non-negative"));
        }
        let b = r.take(4)?;
        let n_heads = u32::from_le_bytes([b[0], b[1], b[2], b[3]]) as usize;
        if n_heads > MAX_HEADS {
            return Err(r.fail("too many heads"));
        }
        let mut heads: Vec<Head> = Vec::with_capacity(n_heads);
        for _ in 0..n_heads {
            let head = r.head(n_z * n_x)?;
            if heads.iter().any(|h| h.of == head.of) {
                return Err(r.fail("two heads correct the same thing"));
            }
            heads.push(head);
        }
        (stated, v[0], [v[1], v[2]], heads)
    } else {
        let largest = |e: &[f64]| e.iter().copied().fold(0.0, f64::max);
        let stated = prior[..6].to_vec();
        (
            stated,
            1.0,
            [largest(&error[0]), largest(&error[1])],
            Vec::new(),
        )
    };
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
        stated,
        q_bound,
        worst,
        heads,
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
