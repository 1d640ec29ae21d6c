//! Triangles, triangle bins and the quadrature nodes of their orientation and bin averages (see the
//! module docs of [`crate::bispectrum`]).

use crate::error::{Error, Result};
use crate::integrate::legendre_nodes;
use crate::survey::legendre;
use std::f64::consts::PI;

/// The side whose cosine with the line of sight the Legendre polynomial of B_ℓ takes.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum LegendreSide {
    /// The side of the largest k (bin centre; the last of equal ones), as the window-free estimator.
    #[default]
    Largest,
    /// Side 0, 1 or 2 in the order the triangles are given.
    Index(usize),
}

impl LegendreSide {
    /// The choices by name, as the CLI and Python take them (sides numbered from 1).
    pub const NAMES: [&'static str; 4] = ["largest", "1", "2", "3"];

    /// The side by name: `largest`, `1`, `2` or `3`.
    ///
    /// # Errors
    /// [`Error::InvalidChoice`] listing [`LegendreSide::NAMES`].
    pub fn by_name(name: &str) -> Result<Self> {
        match name.trim().to_ascii_lowercase().as_str() {
            "largest" => Ok(Self::Largest),
            "1" => Ok(Self::Index(0)),
            "2" => Ok(Self::Index(1)),
            "3" => Ok(Self::Index(2)),
            _ => Err(Error::InvalidChoice {
                what: format!("legendre side = {name}"),
                reason: format!("valid: {}", Self::NAMES.join(", ")),
            }),
        }
    }
}

/// Relative tolerance of the triangle condition k_a ≤ k_b + k_c for triangles given as three numbers.
const CLOSURE_TOLERANCE: f64 = 1e-9;

/// The triangles of a prediction: points (k₁, k₂, k₃) [h/Mpc], or bins of three shells averaged over
/// all their closed triangles.
#[derive(Debug, Clone, PartialEq)]
pub struct TriangleSet {
    centres: Vec<[f64; 3]>,
    /// Per triangle, the [lower, upper) edges of its three shells (empty for points).
    shells: Vec<[[f64; 2]; 3]>,
    width: Option<f64>,
}

impl TriangleSet {
    /// Triangles at the given sides, each closing (k_a ≤ k_b + k_c) with k > 0.
    ///
    /// # Errors
    /// [`Error::InvalidValue`] naming the row (1-based) of a side that is not finite and > 0 or of a
    /// triangle that does not close; [`Error::InvalidChoice`] for no triangles.
    pub fn points(triangles: Vec<[f64; 3]>) -> Result<Self> {
        check_sides(&triangles)?;
        for (row, t) in triangles.iter().enumerate() {
            let largest = t.iter().copied().fold(0.0, f64::max);
            let sum: f64 = t.iter().sum();
            if largest > (sum - largest) * (1.0 + CLOSURE_TOLERANCE) {
                return Err(Error::InvalidValue {
                    origin: "triangles".into(),
                    line: row + 1,
                    name: "k",
                    value: largest,
                    reason:
                        "a side is longer than the other two together: the triangle does not close",
                });
            }
        }
        Ok(Self {
            centres: triangles,
            shells: Vec::new(),
            width: None,
        })
    }

    /// Bins of width Δk [h/Mpc] centred on the given sides (as the `k1 k2 k3` columns of a measurement),
    /// each averaged over all closed triangles of its shells [k − Δk/2, k + Δk/2).
    ///
    /// # Errors
    /// As [`points`](Self::points) for the centres (a shell must start above k = 0), and
    /// [`Error::InvalidValue`] for a bin with no closed triangle.
    pub fn shells(centres: Vec<[f64; 3]>, width: f64) -> Result<Self> {
        if !(width.is_finite() && width > 0.0) {
            return Err(Error::InvalidChoice {
                what: format!("bin width = {width}"),
                reason: "the shell width must be finite and > 0 [h/Mpc]".into(),
            });
        }
        check_sides(&centres)?;
        let shells: Vec<[[f64; 2]; 3]> = centres
            .iter()
            .map(|c| c.map(|k| [k - 0.5 * width, k + 0.5 * width]))
            .collect();
        for (row, s) in shells.iter().enumerate() {
            if s.iter().any(|e| e[0] <= 0.0) {
                return Err(Error::InvalidValue {
                    origin: "triangle bins".into(),
                    line: row + 1,
                    name: "k - width/2",
                    value: s.iter().map(|e| e[0]).fold(f64::INFINITY, f64::min),
                    reason: "a shell must lie at k > 0",
                });
            }
            if shape_nodes(s, 4).is_empty() {
                return Err(Error::InvalidValue {
                    origin: "triangle bins".into(),
                    line: row + 1,
                    name: "k",
                    value: centres[row].iter().copied().fold(0.0, f64::max),
                    reason: "no closed triangle has its sides in these three shells",
                });
            }
        }
        Ok(Self {
            centres,
            shells,
            width: Some(width),
        })
    }

    /// All bins k₁ ≤ k₂ ≤ k₃ of the uniform shells between consecutive `edges` [h/Mpc] whose centres
    /// close a triangle (k₃ ≤ k₁ + k₂), in the order of the window-free measurements (k₁, then k₂, then
    /// k₃ increasing).
    ///
    /// # Errors
    /// [`Error::InvalidChoice`] for fewer than two edges, edges not increasing or not uniform (to
    /// 1e-9 relative); as [`shells`](Self::shells).
    pub fn from_edges(edges: &[f64]) -> Result<Self> {
        if edges.len() < 2 || !edges.windows(2).all(|w| w[1] > w[0]) {
            return Err(Error::InvalidChoice {
                what: "k edges".into(),
                reason: "need at least two strictly increasing edges [h/Mpc]".into(),
            });
        }
        let width = edges[1] - edges[0];
        if edges
            .windows(2)
            .any(|w| ((w[1] - w[0]) - width).abs() > 1e-9 * width.max(w[1]))
        {
            return Err(Error::InvalidChoice {
                what: "k edges".into(),
                reason: "triangle bins need uniform shells (equal widths)".into(),
            });
        }
        let c: Vec<f64> = edges.windows(2).map(|w| 0.5 * (w[0] + w[1])).collect();
        let mut centres = Vec::new();
        for i in 0..c.len() {
            for j in i..c.len() {
                for l in j..c.len() {
                    if c[l] <= c[i] + c[j] * (1.0 + CLOSURE_TOLERANCE) {
                        centres.push([c[i], c[j], c[l]]);
                    }
                }
            }
        }
        Self::shells(centres, width)
    }

    /// The triangles (bin centres) [h/Mpc].
    pub fn triangles(&self) -> &[[f64; 3]] {
        &self.centres
    }

    /// Number of triangles.
    pub fn len(&self) -> usize {
        self.centres.len()
    }

    /// Whether there are none (never, for a constructed set).
    pub fn is_empty(&self) -> bool {
        self.centres.is_empty()
    }

    /// The shell width [h/Mpc], `None` for points.
    pub fn width(&self) -> Option<f64> {
        self.width
    }

    /// The sides (k, weight) of triangle `i`, weights summing to 1 (`n` Gauss–Legendre nodes per side
    /// for bins).
    pub fn shapes(&self, i: usize, n: usize) -> Vec<([f64; 3], f64)> {
        if self.shells.is_empty() {
            vec![(self.centres[i], 1.0)]
        } else {
            shape_nodes(&self.shells[i], n)
        }
    }

    /// The index of the Legendre side of triangle `i`.
    pub fn legendre_index(&self, i: usize, side: LegendreSide) -> usize {
        match side {
            LegendreSide::Index(a) => a,
            LegendreSide::Largest => {
                let t = self.centres[i];
                (0..3).fold(0, |best, a| if t[a] >= t[best] { a } else { best })
            }
        }
    }
}

fn check_sides(triangles: &[[f64; 3]]) -> Result<()> {
    if triangles.is_empty() {
        return Err(Error::InvalidChoice {
            what: "triangles".into(),
            reason: "no triangle given".into(),
        });
    }
    for (row, t) in triangles.iter().enumerate() {
        if let Some(&k) = t.iter().find(|k| !(k.is_finite() && **k > 0.0)) {
            return Err(Error::InvalidValue {
                origin: "triangles".into(),
                line: row + 1,
                name: "k",
                value: k,
                reason: "every side must be finite and > 0 [h/Mpc]",
            });
        }
    }
    Ok(())
}

/// Nodes of the average over the closed triangles of three shells, weight k₁k₂k₃ dk₁dk₂dk₃: n-point
/// Gauss–Legendre in k₁ and k₂ on panels of their shells split where the closed part of the k₃ shell,
/// max(lo₃, |k₁ − k₂|) ≤ k₃ ≤ min(hi₃, k₁ + k₂), changes form (so the integrand is smooth on every
/// panel), and in k₃ on that closed part. Weights normalised to 1; empty if no triangle closes.
fn shape_nodes(shells: &[[f64; 2]; 3], n: usize) -> Vec<([f64; 3], f64)> {
    let (x, w) = legendre_nodes(n);
    let [[lo1, hi1], [lo2, hi2], [lo3, hi3]] = *shells;
    // the lines k₂ = ±k₁ ± lo₃, ±k₁ ± hi₃ where the k₃ interval changes form
    let k2_breaks = |k1: f64| [hi3 - k1, lo3 - k1, k1 + lo3, k1 - lo3, k1 + hi3, k1 - hi3];
    let mut k1_breaks = Vec::new();
    for k2 in [lo2, hi2] {
        k1_breaks.extend([hi3 - k2, lo3 - k2, k2 + lo3, k2 - lo3, k2 + hi3, k2 - hi3]);
    }
    // where a falling line k₂ = c − k₁ crosses a rising one k₂ = k₁ + d inside the k₂ shell, the pieces
    // of the k₂ integrand change order: the k₂ integral has a kink there (at the shell centre of an
    // equilateral bin, where an odd Gauss rule puts a node)
    for c in [lo3, hi3] {
        for d in [lo3, -lo3, hi3, -hi3] {
            if (lo2..=hi2).contains(&(0.5 * (c + d))) {
                k1_breaks.push(0.5 * (c - d));
            }
        }
    }
    let mut nodes = Vec::new();
    for (k1, w1) in panels(lo1, hi1, &k1_breaks, &x, &w) {
        for (k2, w2) in panels(lo2, hi2, &k2_breaks(k1), &x, &w) {
            let lo = lo3.max((k1 - k2).abs());
            let hi = hi3.min(k1 + k2);
            if hi <= lo {
                continue;
            }
            for (k3, w3) in panels(lo, hi, &[], &x, &w) {
                nodes.push(([k1, k2, k3], w1 * w2 * w3 * k1 * k2 * k3));
            }
        }
    }
    let total: f64 = nodes.iter().map(|n| n.1).sum();
    if total > 0.0 {
        for n in &mut nodes {
            n.1 /= total;
        }
        nodes
    } else {
        Vec::new()
    }
}

/// The Gauss–Legendre rule (`x`, `w` on [−1, 1]) on every panel of [a, b] split at the `breaks` inside it.
fn panels(a: f64, b: f64, breaks: &[f64], x: &[f64], w: &[f64]) -> Vec<(f64, f64)> {
    let tiny = 1e-12 * (b - a);
    let mut edges: Vec<f64> = breaks
        .iter()
        .copied()
        .filter(|&t| t > a + tiny && t < b - tiny)
        .collect();
    edges.push(a);
    edges.push(b);
    edges.sort_by(f64::total_cmp);
    edges.dedup_by(|p, q| (*p - *q).abs() <= tiny);
    let mut out = Vec::with_capacity(x.len() * (edges.len() - 1));
    for e in edges.windows(2) {
        let (mid, half) = (0.5 * (e[0] + e[1]), 0.5 * (e[1] - e[0]));
        out.extend(x.iter().zip(w).map(|(&x, &w)| (mid + half * x, half * w)));
    }
    out
}

/// One shape of a triangle or bin in the observed (fiducial) frame: sides, their dot products (k₀·k₁,
/// k₁·k₂, k₂·k₀) and the orientation nodes of its average, in groups of one μ of the Legendre side.
#[derive(Debug, Clone)]
pub(super) struct Shape {
    pub(super) k: [f64; 3],
    /// The Legendre side: its line-of-sight component is the same for every azimuth of a group.
    pub(super) side: usize,
    pub(super) dots: [f64; 3],
    pub(super) groups: Vec<MuGroup>,
}

/// The orientations of one μ of the Legendre side (its azimuths): the sides' line-of-sight
/// components, and the (2ℓ + 1)L_ℓ(μ) × weight of ℓ = 0, 2, 4 of each (the shape's bin weight
/// included), the same for every azimuth.
#[derive(Debug, Clone)]
pub(super) struct MuGroup {
    pub(super) par: Vec<[f64; 3]>,
    pub(super) lambda: [f64; 3],
}

/// The line-of-sight components n̂·kᵢ [h/Mpc] of the three sides of `k` for the orientations of a rule
/// about side `a`, with the weights (2ℓ + 1) L_ℓ(μ_a) w for ℓ = 0, 2, 4 (w summing to 1 over the rule):
/// `[par₀, par₁, par₂, λ₀, λ₂, λ₄]` per orientation. B is even in n̂ and in the azimuth φ about k_a (the
/// sides lie in a plane through k_a), so the rule covers μ_a ∈ [0, 1] and φ ∈ (0, π). In μ_a: the `n_mu`
/// positive nodes of the 2n_mu-point Gauss–Legendre rule on [−1, 1] (the azimuthal average is even in
/// μ_a, so the half rule is exact for its polynomials of degree ≤ 4n_mu − 1); in φ: the `n_phi` nodes of
/// the 2n_phi-point trapezoid rule there.
pub(crate) fn orientations(k: [f64; 3], a: usize, n_mu: usize, n_phi: usize) -> Vec<[f64; 6]> {
    let (b, c) = ((a + 1) % 3, (a + 2) % 3);
    // k_a along z, k_b in the xz plane, k_c = −k_a − k_b
    let cos_ab = ((k[c] * k[c] - k[a] * k[a] - k[b] * k[b]) / (2.0 * k[a] * k[b])).clamp(-1.0, 1.0);
    let sin_ab = (1.0 - cos_ab * cos_ab).sqrt();
    let mut side = [[0.0; 2]; 3]; // (x, z) components
    side[a] = [0.0, k[a]];
    side[b] = [k[b] * sin_ab, k[b] * cos_ab];
    side[c] = [-side[a][0] - side[b][0], -side[a][1] - side[b][1]];
    let (x, w_x) = legendre_nodes(2 * n_mu);
    let mut out = Vec::with_capacity(n_mu * n_phi);
    // the positive half (nodes symmetric about 0, weights summing to 1 on it)
    for (&mu, &w) in x.iter().zip(&w_x).filter(|(&x, _)| x > 0.0) {
        let sin = (1.0 - mu * mu).max(0.0).sqrt();
        let lambda = crate::bispectrum::ELLS.map(|l| (2 * l + 1) as f64 * legendre(l, mu));
        for m in 0..n_phi {
            let phi = PI * (m as f64 + 0.5) / n_phi as f64;
            let nx = sin * phi.cos();
            let weight = w / n_phi as f64;
            let par = side.map(|s| s[0] * nx + s[1] * mu);
            out.push([
                par[0],
                par[1],
                par[2],
                lambda[0] * weight,
                lambda[1] * weight,
                lambda[2] * weight,
            ]);
        }
    }
    out
}
