//! The bispectrum multipoles averaged exactly over the discrete modes of a periodic box, as the FFT
//! box estimator measures them: with k = k_f n (n ∈ ℤ³, k_f = 2π/L) and the line of sight ẑ,
//!
//! ```text
//! B_ℓ^box = (2ℓ + 1) Σ_{k₁∈a, k₂∈b, k₃=−k₁−k₂∈c} B(k₁, k₂, k₃; ẑ) L_ℓ(k̂_s·ẑ) / N_abc
//! ```
//!
//! over every ordered triple of modes of the three shells (N_abc their number), the Legendre
//! polynomial on the side s of the chosen shell (tests/data/bispectrum/DEFINITIONS.md (d)). The plan
//! enumerates the triples once and keeps each distinct configuration (|n₁|², |n₂|², |n₃|², n₁z, n₂z:
//! everything B depends on) with its multiplicity; a new spectrum costs one evaluation per configuration.
//! These keys are invariant under the 8 rotations and reflections of the box about the line of sight
//! applied to both modes, so n₁ runs over one mode per orbit (x ≥ y ≥ 0), counted with its orbit's size.
//! The sums are exact (no quadrature error; the errors are zero, round-off ~1e-13). The plan's cost
//! grows as the product of the two smaller shells' mode counts, (4πk²Δk/k_f³)².

use super::geometry::{LegendreSide, TriangleSet};
use super::observed::{accumulate, observed_slots};
use super::resum::IrInputs;
use super::terms::{BispectrumTerms, SLOTS};
use super::Settings;
use crate::error::{Error, Result};
use crate::ir::WiggleSplit;
use crate::linear::LinearSpectrum;
use crate::precision::Precision;
use crate::survey::legendre;
use std::collections::HashMap;
use std::f64::consts::PI;

/// Most ordered pairs of modes a plan visits (about a minute of enumeration).
const MAX_PAIRS: f64 = 2e10;

/// One distinct configuration of a bin: observed sides, dot products, line-of-sight components and the
/// weights (2ℓ + 1)L_ℓ(μ_s) × multiplicity / N_abc of ℓ = 0, 2, 4.
#[derive(Debug, Clone, Copy)]
struct Config {
    k: [f64; 3],
    dots: [f64; 3],
    par: [f64; 3],
    lambda: [f64; 3],
}

/// The bins of a triangle set averaged over the modes of a periodic box of side L [Mpc/h].
#[derive(Debug, Clone)]
pub struct BoxPlan {
    set: TriangleSet,
    box_size: f64,
    bins: Vec<Vec<Config>>,
    split: WiggleSplit,
    q_min: f64,
}

/// The integer vectors n with lo ≤ |n| < hi (in units of k_f), squared bounds compared exactly.
fn shell_modes(lo: f64, hi: f64) -> Vec<[i64; 3]> {
    let m = hi.ceil() as i64;
    let (lo2, hi2) = (lo * lo, hi * hi);
    let mut out = Vec::new();
    for x in -m..=m {
        for y in -m..=m {
            for z in -m..=m {
                let n2 = (x * x + y * y + z * z) as f64;
                if n2 >= lo2 && n2 < hi2 {
                    out.push([x, y, z]);
                }
            }
        }
    }
    out
}

impl BoxPlan {
    /// Plans the bins of `set` (which must have shells: [`TriangleSet::shells`] or
    /// [`TriangleSet::from_edges`]) in a box of side `box_size` [Mpc/h], the Legendre polynomial on the
    /// side in the shell `side` picks.
    ///
    /// # Errors
    /// [`Error::InvalidChoice`] for a set of points, a box size not finite and > 0, or more than
    /// 2e10 pairs of modes to visit (about a minute); [`Error::InvalidValue`] naming the bin (1-based) with no
    /// triangle of modes; as [`WiggleSplit::new`].
    pub fn new(set: TriangleSet, side: LegendreSide, box_size: f64) -> Result<Self> {
        if !(box_size.is_finite() && box_size > 0.0) {
            return Err(Error::InvalidChoice {
                what: format!("box size = {box_size}"),
                reason: "the side of the box must be finite and > 0 [Mpc/h]".into(),
            });
        }
        let Some(width) = set.width() else {
            return Err(Error::InvalidChoice {
                what: "box average of triangles without shells".into(),
                reason: "the box average needs bins: a shell width or k edges".into(),
            });
        };
        let kf = 2.0 * PI / box_size;
        let shells: Vec<[[f64; 2]; 3]> = set
            .triangles()
            .iter()
            .map(|c| c.map(|k| [(k - 0.5 * width) / kf, (k + 0.5 * width) / kf]))
            .collect();
        let pairs: f64 = shells
            .iter()
            .map(|s| {
                let count = |[lo, hi]: [f64; 2]| 4.0 / 3.0 * PI * (hi.powi(3) - lo.powi(3));
                count(s[0]) * count(s[1])
            })
            .sum();
        if pairs > MAX_PAIRS {
            return Err(Error::InvalidChoice {
                what: format!("box average, L = {box_size} Mpc/h"),
                reason: format!(
                    "about {pairs:.1e} pairs of modes to visit (limit {MAX_PAIRS:.0e}): use the continuous shells"
                ),
            });
        }
        let mut bins = Vec::with_capacity(shells.len());
        for (row, s) in shells.iter().enumerate() {
            let a = set.legendre_index(row, side);
            let m1 = shell_modes(s[1][0], s[1][1]);
            // one n₁ per orbit of the symmetries about z, with the orbit's size
            let m0: Vec<([i64; 3], u64)> = shell_modes(s[0][0], s[0][1])
                .into_iter()
                .filter(|n| n[0] >= n[1] && n[1] >= 0)
                .map(|n| {
                    let size = match (n[0], n[1]) {
                        (0, 0) => 1,
                        (x, y) if y == 0 || x == y => 4,
                        _ => 8,
                    };
                    (n, size)
                })
                .collect();
            let (lo2, hi2) = (s[2][0] * s[2][0], s[2][1] * s[2][1]);
            let mut counts: HashMap<[i64; 5], u64> = HashMap::new();
            for (n1, size) in &m0 {
                let n1sq = n1[0] * n1[0] + n1[1] * n1[1] + n1[2] * n1[2];
                for n2 in &m1 {
                    let n3 = [-n1[0] - n2[0], -n1[1] - n2[1], -n1[2] - n2[2]];
                    let n3sq = n3[0] * n3[0] + n3[1] * n3[1] + n3[2] * n3[2];
                    if (n3sq as f64) < lo2 || (n3sq as f64) >= hi2 {
                        continue;
                    }
                    let n2sq = n2[0] * n2[0] + n2[1] * n2[1] + n2[2] * n2[2];
                    *counts.entry([n1sq, n2sq, n3sq, n1[2], n2[2]]).or_default() += size;
                }
            }
            let total: u64 = counts.values().sum();
            if total == 0 {
                return Err(Error::InvalidValue {
                    origin: format!("box average, L = {box_size} Mpc/h"),
                    line: row + 1,
                    name: "k",
                    value: set.triangles()[row][2],
                    reason: "no triangle of the box's modes has its sides in these three shells",
                });
            }
            let mut configs: Vec<Config> = counts
                .into_iter()
                .map(|([s1, s2, s3, z1, z2], count)| {
                    let sq = [s1, s2, s3].map(|v| v as f64 * kf * kf);
                    let k = sq.map(f64::sqrt);
                    let par = [z1, z2, -z1 - z2].map(|z| z as f64 * kf);
                    let dots = [0, 1, 2].map(|i| 0.5 * (sq[(i + 2) % 3] - sq[i] - sq[(i + 1) % 3]));
                    let w = count as f64 / total as f64;
                    let lambda =
                        super::ELLS.map(|l| (2 * l + 1) as f64 * legendre(l, par[a] / k[a]) * w);
                    Config {
                        k,
                        dots,
                        par,
                        lambda,
                    }
                })
                .collect();
            // a fixed order, so that sums do not depend on the hash map's
            configs.sort_by(|x, y| {
                x.k.partial_cmp(&y.k)
                    .unwrap()
                    .then(x.par.partial_cmp(&y.par).unwrap())
            });
            bins.push(configs);
        }
        Ok(Self {
            set,
            box_size,
            bins,
            split: WiggleSplit::new()?,
            q_min: Precision::default().q_min,
        })
    }

    /// The bins.
    pub fn triangles(&self) -> &TriangleSet {
        &self.set
    }

    /// The side of the box [Mpc/h].
    pub fn box_size(&self) -> f64 {
        self.box_size
    }

    /// The number of distinct configurations of each bin.
    pub fn configurations(&self) -> Vec<usize> {
        self.bins.iter().map(Vec::len).collect()
    }

    /// The coefficients of every parameter monomial of B₀, B₂, B₄ of every bin (errors zero: exact sums).
    ///
    /// # Errors
    /// As [`Settings::validate`] and the no-wiggle split.
    pub fn terms(&self, spectrum: &LinearSpectrum, settings: &Settings) -> Result<BispectrumTerms> {
        settings.validate()?;
        let ir = if settings.ir {
            Some(IrInputs::split(spectrum, &self.split, self.q_min)?)
        } else {
            None
        };
        let power = |_: usize, k: f64, mu: f64| {
            let p = spectrum.eval(k);
            ir.as_ref()
                .map_or(p, |ir| ir.resum(p, ir.no_wiggle.eval(k), k, mu, settings.f))
        };
        let slots = self
            .bins
            .iter()
            .map(|configs| {
                let mut acc = [[0.0; SLOTS]; 3];
                for c in configs {
                    let slots = observed_slots(c.k, c.dots, c.par, settings, power);
                    accumulate(&mut acc, c.lambda, &slots);
                }
                acc
            })
            .collect();
        Ok(BispectrumTerms::exact(slots, self.set.triangles().to_vec()))
    }
}
