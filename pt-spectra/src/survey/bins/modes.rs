//! [`BoxModes`]: the discrete modes of a periodic box in k bins, and the multipoles of a model averaged
//! over them.
//!
//! The modes are k = (2π/L) n, n ∈ ℤ³ \ {0}, with μ = n_z/|n| (line of sight along z); a mode is in the
//! bin [k_a, k_b) if k_a ≤ (2π/L)√(n·n) < k_b, computed in f64 as written. Both n and −n are counted (as
//! an FFT of the box does; the means are the same). For even ℓ,
//!   P̂_ℓ(bin) = (2ℓ+1)/N Σ_n P(k_n, μ_n) L_ℓ(μ_n) = (2ℓ+1)/N Σ_g c_g ½[P(k_g, μ_g) + P(k_g, −μ_g)] L_ℓ(μ_g),
//! where the modes are grouped by (n·n, n_z²), i.e. by (|k|, |μ|), with c_g modes per group: the groups
//! are what is stored, made once each as n·n = m + n_z² with c_g = r₂(m) (×2 for n_z ≠ 0), r₂(m) the
//! number of (i, j) ∈ ℤ² with i² + j² = m, counted once over the quadrant i, j ≥ 0. For a model given by its multipoles, P(k, μ) = Σ_ℓ' P_ℓ'(k) L_ℓ'(μ),
//!   P̂_ℓ(bin) = Σ_ℓ' Σ_{|k|} A_ℓℓ'(|k|) P_ℓ'(|k|),
//!   A_ℓℓ'(|k|) = (2ℓ+1)/N Σ_{g at |k|} c_g L_ℓ(μ_g) L_ℓ'(μ_g),
//! and P_ℓ'(|k|) is interpolated from the model's grid by 4-point Lagrange interpolation in ln k
//! ([`BoxModesPlan`]; exact if the grid holds every |k|, [`BoxModes::distinct_k`]); the error estimate is
//! the difference to 3-point interpolation.

use super::super::{check_ells, check_increasing, check_model, legendre};
use crate::error::{Error, Result};
use crate::estimate::Estimate;
use std::f64::consts::PI;

/// The largest k_max L/2π of a box (e.g. L = 2000 Mpc/h to k = 0.8 h/Mpc): about 2e6 groups, 80 MB.
const MAX_N: f64 = 256.0;

/// Modes of a box with the same |n|² and n_z²: (|k|, |μ|) and how many modes.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ModeGroup {
    /// n·n.
    pub n2: u64,
    /// n_z².
    pub nz2: u64,
    /// The number of modes (over all signs and orders of the components).
    pub count: u64,
    /// |k| = (2π/L)√(n·n) [h/Mpc].
    pub k: f64,
    /// |μ| = |n_z|/|n|.
    pub mu: f64,
}

/// The modes of a periodic box of side L in k bins (module docs).
#[derive(Debug, Clone, PartialEq)]
pub struct BoxModes {
    box_side: f64,
    edges: Vec<f64>,
    ells: Vec<usize>,
    bins: Vec<Vec<ModeGroup>>,
    counts: Vec<u64>,
    k_mean: Vec<f64>,
}

impl BoxModes {
    /// The modes of the box of side `box_side` [Mpc/h] in the bins between consecutive `k_edges` [h/Mpc],
    /// for the output multipoles `ells`.
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] for a side that is not finite and positive or a k range that needs
    /// more than 256 modes per axis; [`Error::TooFewPoints`], [`Error::InvalidK`] or
    /// [`Error::NonIncreasingK`] for bad edges; [`Error::InvalidChoice`] for bad `ells` or a bin that
    /// holds no mode.
    pub fn new(box_side: f64, k_edges: &[f64], ells: &[usize]) -> Result<Self> {
        if !(box_side.is_finite() && box_side > 0.0) {
            return Err(Error::InvalidParameter {
                name: "box side L [Mpc/h]",
                value: box_side,
                reason: "must be a finite positive number",
            });
        }
        if k_edges.len() < 2 {
            return Err(Error::TooFewPoints {
                origin: "k bin edges".into(),
                found: k_edges.len(),
                min: 2,
            });
        }
        check_increasing("k bin edges", k_edges, true)?;
        check_ells("box-mode multipoles", ells)?;
        let fundamental = 2.0 * PI / box_side;
        let k_top = k_edges[k_edges.len() - 1];
        let n_top = k_top / fundamental;
        if n_top > MAX_N {
            return Err(Error::InvalidParameter {
                name: "k_max L / 2pi (modes per axis)",
                value: n_top,
                reason: "must be at most 256",
            });
        }
        let n_max = n_top.ceil() as u64 + 1;
        let n2_max = (n_max * n_max) as usize;
        // r2[m]: the number of (i, j) ∈ ℤ² with i² + j² = m, the same for every n_z.
        let mut r2 = vec![0u64; n2_max + 1];
        for i in 0..=n_max {
            for j in 0..=n_max {
                if let Some(r) = r2.get_mut((i * i + j * j) as usize) {
                    *r += if i > 0 { 2 } else { 1 } * if j > 0 { 2 } else { 1 };
                }
            }
        }
        // Each (n², n_z²) once: n² = m + l², with r2[m] (2 r2[m] for l > 0) modes.
        let mut bins: Vec<Vec<ModeGroup>> = vec![Vec::new(); k_edges.len() - 1];
        for l in 0..=n_max {
            for (m, &count) in r2.iter().enumerate().filter(|(_, &c)| c > 0) {
                let n2 = m as u64 + l * l;
                let k = fundamental * (n2 as f64).sqrt();
                if n2 == 0 || k < k_edges[0] || k >= k_top {
                    continue;
                }
                let bin = k_edges.partition_point(|&e| e <= k) - 1;
                bins[bin].push(ModeGroup {
                    n2,
                    nz2: l * l,
                    count: if l > 0 { 2 * count } else { count },
                    k,
                    mu: ((l * l) as f64 / n2 as f64).sqrt(),
                });
            }
        }
        bins.iter_mut()
            .for_each(|b| b.sort_unstable_by_key(|g| (g.n2, g.nz2)));
        let mut counts = Vec::with_capacity(bins.len());
        let mut k_mean = Vec::with_capacity(bins.len());
        for (b, groups) in bins.iter().enumerate() {
            let n: u64 = groups.iter().map(|g| g.count).sum();
            if n == 0 {
                return Err(Error::InvalidChoice {
                    what: format!("k bin [{}, {}) h/Mpc", k_edges[b], k_edges[b + 1]),
                    reason: format!(
                        "holds no mode of a box of side {box_side} Mpc/h (fundamental k = {fundamental} \
                         h/Mpc): widen or drop it"
                    ),
                });
            }
            counts.push(n);
            k_mean.push(groups.iter().map(|g| g.count as f64 * g.k).sum::<f64>() / n as f64);
        }
        Ok(Self {
            box_side,
            edges: k_edges.to_vec(),
            ells: ells.to_vec(),
            bins,
            counts,
            k_mean,
        })
    }

    /// The box side L [Mpc/h].
    pub fn box_side(&self) -> f64 {
        self.box_side
    }

    /// The bin edges [h/Mpc].
    pub fn edges(&self) -> &[f64] {
        &self.edges
    }

    /// The output multipoles.
    pub fn ells(&self) -> &[usize] {
        &self.ells
    }

    /// The number of modes in each bin.
    pub fn counts(&self) -> &[u64] {
        &self.counts
    }

    /// The mean |k| over the modes of each bin [h/Mpc], the bin's effective k.
    pub fn k_eff(&self) -> &[f64] {
        &self.k_mean
    }

    /// The mode groups of bin `bin` (empty if there is no such bin), by increasing (n·n, n_z²).
    pub fn groups(&self, bin: usize) -> &[ModeGroup] {
        self.bins.get(bin).map_or(&[], Vec::as_slice)
    }

    /// Every distinct |k| of the modes [h/Mpc], increasing: a grid on which [`plan`](Self::plan) is exact.
    pub fn distinct_k(&self) -> Vec<f64> {
        let mut k: Vec<(u64, f64)> = self.bins.iter().flatten().map(|g| (g.n2, g.k)).collect();
        k.sort_unstable_by_key(|g| g.0);
        k.dedup_by_key(|g| g.0);
        k.into_iter().map(|g| g.1).collect()
    }

    /// The multipoles (`[ℓ][bin]`, ℓ as in [`ells`](Self::ells)) of the model `p(k, μ)` (k in h/Mpc)
    /// averaged over the modes, evaluated once per group and sign of μ: exact sums (error 0; they
    /// agree with a loop over every mode to 1e-14, tests/tests/suite/bins.rs).
    pub fn average(&self, p: impl Fn(f64, f64) -> f64) -> Vec<Vec<Estimate>> {
        let mut out = vec![vec![0.0; self.bins.len()]; self.ells.len()];
        for (b, groups) in self.bins.iter().enumerate() {
            let norm = 1.0 / self.counts[b] as f64;
            for g in groups {
                let value = if g.nz2 == 0 {
                    p(g.k, 0.0)
                } else {
                    0.5 * (p(g.k, g.mu) + p(g.k, -g.mu))
                };
                let weight = g.count as f64 * norm * value;
                for (row, &ell) in out.iter_mut().zip(&self.ells) {
                    row[b] += (2 * ell + 1) as f64 * weight * legendre(ell, g.mu);
                }
            }
        }
        out.into_iter()
            .map(|row| row.into_iter().map(Estimate::exact).collect())
            .collect()
    }

    /// The plan of the averages of a model given by its multipoles P_0, P_2, … (`n_model_ells` of them,
    /// 1 to 5) on `k_grid` [h/Mpc] (increasing, at least 4 points, covering every mode's |k|).
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] for `n_model_ells` outside 1..=5, [`Error::TooFewPoints`],
    /// [`Error::InvalidK`] or [`Error::NonIncreasingK`] for a bad grid, [`Error::OutOfRange`] if a mode's
    /// |k| is outside it.
    pub fn plan(&self, k_grid: &[f64], n_model_ells: usize) -> Result<BoxModesPlan> {
        if !(1..=5).contains(&n_model_ells) {
            return Err(Error::InvalidParameter {
                name: "number of model multipoles",
                value: n_model_ells as f64,
                reason: "must be between 1 and 5 (P_0 … P_8)",
            });
        }
        if k_grid.len() < 4 {
            return Err(Error::TooFewPoints {
                origin: "box-mode model grid".into(),
                found: k_grid.len(),
                min: 4,
            });
        }
        check_increasing("box-mode model grid", k_grid, false)?;
        let ln_k: Vec<f64> = k_grid.iter().map(|k| k.ln()).collect();
        let (first, last) = (k_grid[0], k_grid[k_grid.len() - 1]);
        for g in self.bins.iter().flatten() {
            if g.k < first || g.k > last {
                return Err(Error::OutOfRange {
                    what: "the box-mode model grid".into(),
                    k: g.k,
                    min: first,
                    max: last,
                });
            }
        }
        let mut weights = Vec::with_capacity(self.ells.len());
        for &ell in &self.ells {
            let mut per_bin = Vec::with_capacity(self.bins.len());
            for (b, groups) in self.bins.iter().enumerate() {
                let norm = (2 * ell + 1) as f64 / self.counts[b] as f64;
                let mut per_in = vec![SparseRow::default(); n_model_ells];
                // Groups are sorted by n²: sum A_ℓℓ' over each |k|, then interpolate once.
                for same_k in groups.chunk_by(|a, b| a.n2 == b.n2) {
                    for (j, w) in per_in.iter_mut().enumerate() {
                        let a: f64 = same_k
                            .iter()
                            .map(|g| g.count as f64 * legendre(ell, g.mu) * legendre(2 * j, g.mu))
                            .sum();
                        w.add(&ln_k, same_k[0].k.ln(), norm * a);
                    }
                }
                per_bin.push(per_in);
            }
            weights.push(per_bin);
        }
        Ok(BoxModesPlan {
            k_grid: k_grid.to_vec(),
            n_model_ells,
            weights,
        })
    }
}

/// The weights on a range of grid nodes of cubic (and quadratic) interpolation, summed over modes.
#[derive(Debug, Clone, Default, PartialEq)]
struct SparseRow {
    start: usize,
    cubic: Vec<f64>,
    quadratic: Vec<f64>,
}

impl SparseRow {
    /// Adds `a` × the interpolation weights at ln k = `x` on the nodes `grid` (ln k).
    fn add(&mut self, grid: &[f64], x: f64, a: f64) {
        let n = grid.len();
        let i = grid.partition_point(|&g| g <= x).clamp(1, n - 1) - 1;
        let cubic_start = i.saturating_sub(1).min(n - 4);
        let nearer_left = x - grid[i] < grid[i + 1] - x;
        let quad_start = if nearer_left { i.saturating_sub(1) } else { i }.min(n - 3);
        for (start, len, cubic) in [(cubic_start, 4, true), (quad_start, 3, false)] {
            let nodes = &grid[start..start + len];
            for (m, &xm) in nodes.iter().enumerate() {
                let w: f64 = nodes
                    .iter()
                    .enumerate()
                    .filter(|&(q, _)| q != m)
                    .map(|(_, &xq)| (x - xq) / (xm - xq))
                    .product();
                self.put(start + m, a * w, cubic);
            }
        }
    }

    fn put(&mut self, index: usize, w: f64, cubic: bool) {
        if self.cubic.is_empty() {
            self.start = index;
        }
        if index < self.start {
            let shift = self.start - index;
            for v in [&mut self.cubic, &mut self.quadratic] {
                v.splice(0..0, std::iter::repeat_n(0.0, shift));
            }
            self.start = index;
        }
        let at = index - self.start;
        if at >= self.cubic.len() {
            self.cubic.resize(at + 1, 0.0);
            self.quadratic.resize(at + 1, 0.0);
        }
        if cubic {
            self.cubic[at] += w;
        } else {
            self.quadratic[at] += w;
        }
    }

    fn dot(&self, values: &[f64]) -> (f64, f64) {
        let v = &values[self.start..self.start + self.cubic.len()];
        let c = self.cubic.iter().zip(v).map(|(w, v)| w * v).sum();
        let q = self.quadratic.iter().zip(v).map(|(w, v)| w * v).sum();
        (c, q)
    }
}

/// The box-mode averages of a model given by its multipoles on a k grid, planned once ([`BoxModes::plan`]).
#[derive(Debug, Clone, PartialEq)]
pub struct BoxModesPlan {
    k_grid: Vec<f64>,
    n_model_ells: usize,
    /// [output ℓ][bin][model ℓ'/2].
    weights: Vec<Vec<Vec<SparseRow>>>,
}

impl BoxModesPlan {
    /// The model's grid [h/Mpc].
    pub fn k_theory(&self) -> &[f64] {
        &self.k_grid
    }

    /// P̂_ℓ per bin (`[ℓ][bin]`) from the model's P_0, P_2, … on [`k_theory`](Self::k_theory), with the
    /// interpolation error estimate (cubic against quadratic).
    ///
    /// # Errors
    /// [`Error::InvalidChoice`] unless as many multipoles as planned are given, [`Error::LengthMismatch`]
    /// for one of the wrong length, [`Error::InvalidValue`] for a value that is not finite.
    pub fn apply(&self, p: &[Vec<f64>]) -> Result<Vec<Vec<Estimate>>> {
        check_model("BoxModesPlan::apply", p, self.k_grid.len())?;
        if p.len() != self.n_model_ells {
            return Err(Error::InvalidChoice {
                what: "BoxModesPlan::apply".into(),
                reason: format!(
                    "{} model multipoles given, the plan was made for {}",
                    p.len(),
                    self.n_model_ells
                ),
            });
        }
        Ok(self
            .weights
            .iter()
            .map(|per_bin| {
                per_bin
                    .iter()
                    .map(|per_in| {
                        let (c, q) = per_in
                            .iter()
                            .zip(p)
                            .map(|(w, values)| w.dot(values))
                            .fold((0.0, 0.0), |s, x| (s.0 + x.0, s.1 + x.1));
                        Estimate::new(c, (c - q).abs())
                    })
                    .collect()
            })
            .collect())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn mode_counts_of_a_small_box() {
        // L = 2π: k = |n|. Shells: |n|² = 1 (6 modes), 2 (12), 3 (8), 4 (6).
        let modes = BoxModes::new(2.0 * PI, &[0.5, 1.2, 1.5, 1.8, 2.1], &[0, 2]).unwrap();
        assert_eq!(modes.counts(), &[6, 12, 8, 6]);
        assert!((modes.k_eff()[1] - 2f64.sqrt()).abs() < 1e-15);
        // |n|² = 1: μ² = 1 (2 modes) and 0 (4 modes).
        let g = modes.groups(0);
        assert_eq!(g.len(), 2);
        assert_eq!((g[0].nz2, g[0].count, g[1].nz2, g[1].count), (0, 4, 1, 2));
        // The mean of L2(μ) over a full shell vanishes; of μ²: 1/3 on every shell.
        let avg = modes.average(|_, mu| mu * mu);
        for (b, a) in avg[0].iter().enumerate().take(4) {
            assert!((a.value - 1.0 / 3.0).abs() < 1e-15, "{b}");
        }
        // Shell |n|² = 1: ⟨μ⁴⟩ = 1/3, so 5⟨μ² L2⟩ = 5(3/3 − 1/3)/2 = 5/3.
        assert!((avg[1][0].value - 5.0 / 3.0).abs() < 1e-15);
        assert_eq!(modes.distinct_k().len(), 4);
    }

    #[test]
    fn plan_is_exact_on_the_distinct_k() {
        let modes = BoxModes::new(300.0, &[0.02, 0.05, 0.1], &[0, 2, 4]).unwrap();
        let model = |k: f64, mu: f64| (1.0 + 0.5 * mu * mu).powi(2) * (-k / 0.1).exp() / k;
        let direct = modes.average(model);
        let grid = modes.distinct_k();
        let g = |k: f64| (-k / 0.1).exp() / k;
        // (1 + μ²/2)² = 1 + μ² + μ⁴/4: multipoles 1 + 1/3 + 1/20, 2/3 + 1/7, 2/35.
        let c = [1.0 + 1.0 / 3.0 + 0.05, 2.0 / 3.0 + 1.0 / 7.0, 2.0 / 35.0];
        let p: Vec<Vec<f64>> = c
            .iter()
            .map(|c| grid.iter().map(|&k| c * g(k)).collect())
            .collect();
        let planned = modes.plan(&grid, 3).unwrap().apply(&p).unwrap();
        for (a, b) in direct.iter().flatten().zip(planned.iter().flatten()) {
            assert!(
                (a.value - b.value).abs() < 1e-12 * a.value.abs().max(1.0),
                "{a:?} {b:?}"
            );
            assert!(b.error < 1e-12 * a.value.abs().max(1.0));
        }
    }

    #[test]
    fn bad_boxes_are_refused() {
        assert!(BoxModes::new(-1.0, &[0.0, 0.1], &[0]).is_err());
        assert!(BoxModes::new(1e5, &[0.0, 0.1], &[0]).is_err());
        // A bin between two shells holds no mode.
        let e = BoxModes::new(2.0 * PI, &[0.5, 1.1, 1.2], &[0]).unwrap_err();
        assert!(matches!(e, Error::InvalidChoice { .. }), "{e}");
        let modes = BoxModes::new(2.0 * PI, &[0.5, 1.5], &[0]).unwrap();
        assert!(modes.plan(&[1.0, 1.1, 1.2, 1.3], 1).is_err());
        assert!(modes.plan(&[0.5, 1.0, 1.5, 2.0], 6).is_err());
        let plan = modes.plan(&[0.5, 1.0, 1.5, 2.0], 1).unwrap();
        assert!(plan.apply(&[vec![1.0; 4], vec![1.0; 4]]).is_err());
    }
}
