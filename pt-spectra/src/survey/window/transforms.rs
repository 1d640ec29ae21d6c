//! The FFTLog machinery of [`WindowPlan`](super::WindowPlan): the model between its nodes, the
//! transforms at one resolution, and Lagrange interpolation on log-uniform grids.

use super::{mixing_coefficient, Mixing, WindowMultipoles};
use crate::error::Result;
use crate::hankel::{Direction, HankelPlan};
use crate::linear::spline::LogSpline;
use crate::survey::MAX_ELL;

/// Points of the Lagrange interpolations (ξ_ℓ' onto the common s grid, P̂ to the output k).
pub(super) const STENCIL: usize = 8;
/// End points to which the low-k power law is fitted.
const FIT_POINTS: usize = 4;
/// The FFTLog bias exponent of both directions (they are then exact inverses).
const Q_BIAS: f64 = 1.5;

/// The smallest even n ≥ `n` whose half is 2^a 3^b (fast FFTs at both resolutions).
pub(super) fn fft_size(n: usize) -> usize {
    let half = n.div_ceil(2).max(16);
    let mut best = usize::MAX;
    let mut p2 = 1;
    while p2 < 2 * half {
        let mut m = p2;
        while m < half {
            m *= 3;
        }
        best = best.min(m);
        p2 *= 2;
    }
    2 * best
}

/// The transforms on the FFTLog grid taken with stride 1 (full) or 2 (half resolution).
#[derive(Debug, Clone)]
pub(super) struct Level {
    pub stride: usize,
    /// P → ξ per input ℓ'/2 (None if no output uses it), with the shift onto the common s grid.
    forward: Vec<Option<Forward>>,
    outputs: Vec<Output>,
}

#[derive(Debug, Clone)]
struct Forward {
    plan: HankelPlan,
    /// ξ on the common grid at j = Σ_m w_m ξ[j + offset + m] (None for the common grid itself).
    shift: Option<(isize, [f64; STENCIL])>,
}

/// Output ℓ: M_ℓℓ'(s) per input on the common s grid, the ξ → P plan, the interpolation to k_out.
#[derive(Debug, Clone)]
struct Output {
    m: Vec<Option<Vec<f64>>>,
    plan: HankelPlan,
    at: Vec<(usize, [f64; STENCIL])>,
}

impl Level {
    pub fn new(
        stride: usize,
        fft_k: &[f64],
        ells_out: &[usize],
        k_out: &[f64],
        window: &WindowMultipoles,
        mixing: Mixing,
    ) -> Result<Self> {
        let n = fft_k.len() / stride;
        let (k_lo, k_hi) = (fft_k[0], fft_k[(n - 1) * stride]);
        let plans = (0..=MAX_ELL / 2)
            .map(|i| HankelPlan::new(k_lo, k_hi, n, 2 * i, Direction::PkToXi, Q_BIAS))
            .collect::<Result<Vec<_>>>()?;
        let s = plans[0].output_grid();
        let step = (s[n - 1] / s[0]).ln() / (n - 1) as f64;
        // Q_ℓ'' on the common s grid, ℓ''/2 by ℓ''/2 (zero where the window has no such multipole).
        let q: Vec<Vec<f64>> = (0..=MAX_ELL / 2)
            .map(|i| s.iter().map(|&s| window.q(2 * i, s)).collect())
            .collect();
        let mut outputs = Vec::with_capacity(ells_out.len());
        for &ell in ells_out {
            let m: Vec<Option<Vec<f64>>> = (0..=MAX_ELL / 2)
                .map(|i| {
                    let terms: Vec<(f64, &[f64])> = window
                        .ells()
                        .iter()
                        .map(|&lq| (mixing_coefficient(mixing, ell, 2 * i, lq), lq))
                        .filter(|(c, _)| *c != 0.0)
                        .map(|(c, lq)| (c, q[lq / 2].as_slice()))
                        .collect();
                    (!terms.is_empty()).then(|| {
                        (0..n)
                            .map(|j| terms.iter().map(|(c, q)| c * q[j]).sum())
                            .collect()
                    })
                })
                .collect();
            let plan = HankelPlan::new(s[0], s[n - 1], n, ell, Direction::XiToPk, Q_BIAS)?;
            let at = interpolation(&plan.output_grid(), k_out);
            outputs.push(Output { m, plan, at });
        }
        let forward = plans
            .into_iter()
            .enumerate()
            .map(|(i, plan)| {
                let used = outputs.iter().any(|o| o.m[i].is_some());
                let d = (s[0] / plan.output_grid()[0]).ln() / step;
                let shift = (i > 0).then(|| {
                    let offset = d.floor() as isize - (STENCIL as isize / 2 - 1);
                    (offset, lagrange(d - offset as f64))
                });
                used.then_some(Forward { plan, shift })
            })
            .collect();
        Ok(Self {
            stride,
            forward,
            outputs,
        })
    }

    /// P̂_ℓ at the output k (`[ℓ][k]`) from the model P_ℓ' on the full FFTLog grid (`on_grid[ℓ'/2]`).
    pub fn apply(&self, on_grid: &[Vec<f64>]) -> Result<Vec<Vec<f64>>> {
        let mut xi: Vec<Option<Vec<f64>>> = Vec::with_capacity(on_grid.len());
        for (forward, values) in self.forward.iter().zip(on_grid) {
            let Some(f) = forward else {
                xi.push(None);
                continue;
            };
            let strided: Vec<f64> = values.iter().step_by(self.stride).copied().collect();
            let own = f.plan.transform(&strided)?;
            xi.push(Some(match f.shift {
                None => own,
                Some((offset, w)) => (0..own.len() as isize)
                    .map(|j| {
                        w.iter()
                            .enumerate()
                            .map(|(m, w)| {
                                let at = j + offset + m as isize;
                                usize::try_from(at)
                                    .ok()
                                    .and_then(|a| own.get(a))
                                    .map_or(0.0, |v| w * v)
                            })
                            .sum()
                    })
                    .collect(),
            }));
        }
        let n = on_grid[0].len() / self.stride;
        self.outputs
            .iter()
            .map(|o| {
                let mut product = vec![0.0; n];
                for (m, xi) in o.m.iter().zip(&xi) {
                    if let (Some(m), Some(xi)) = (m, xi) {
                        product
                            .iter_mut()
                            .zip(m.iter().zip(xi))
                            .for_each(|(p, (m, x))| *p += m * x);
                    }
                }
                let p = o.plan.transform(&product)?;
                Ok(o.at
                    .iter()
                    .map(|(start, w)| w.iter().zip(&p[*start..]).map(|(w, v)| w * v).sum())
                    .collect())
            })
            .collect()
    }
}

/// The weights of [`STENCIL`]-point Lagrange interpolation on nodes 0, 1, … at `t`.
fn lagrange(t: f64) -> [f64; STENCIL] {
    let mut w = [1.0; STENCIL];
    for (i, wi) in w.iter_mut().enumerate() {
        for m in 0..STENCIL {
            if m != i {
                *wi *= (t - m as f64) / (i as f64 - m as f64);
            }
        }
    }
    w
}

/// For each k of `at`, the first index and the weights of Lagrange interpolation in ln k on the
/// log-uniform `grid` (the stencil centred on k, moved inside the grid at its ends).
pub(super) fn interpolation(grid: &[f64], at: &[f64]) -> Vec<(usize, [f64; STENCIL])> {
    let n = grid.len();
    let (ln0, step) = (grid[0].ln(), (grid[n - 1] / grid[0]).ln() / (n - 1) as f64);
    at.iter()
        .map(|&k| {
            let u = (k.ln() - ln0) / step;
            let start = (u.floor() as isize - (STENCIL as isize / 2 - 1))
                .clamp(0, (n - STENCIL) as isize) as usize;
            (start, lagrange(u - start as f64))
        })
        .collect()
}

/// The model between its nodes: a not-a-knot spline in ln k of ln|P| (one sign) or P, and below the
/// first node a power law fitted to the first [`FIT_POINTS`] nodes (or zero).
pub(super) struct Resampled {
    spline: LogSpline,
    /// The sign of P if the spline is of ln|P|.
    log_sign: Option<f64>,
    range: (f64, f64),
    /// (k_0, P_0, slope) of the low-k extension.
    low: Option<(f64, f64, f64)>,
}

impl Resampled {
    pub fn new(k: &[f64], p: &[f64]) -> Self {
        Self::through(k.iter().copied().zip(p.iter().copied()).collect())
    }

    /// Through every other node (and the last).
    pub fn new_half(k: &[f64], p: &[f64]) -> Self {
        let n = k.len();
        let nodes = (0..n)
            .filter(|&i| i % 2 == 0 || i == n - 1)
            .map(|i| (k[i], p[i]))
            .collect();
        Self::through(nodes)
    }

    fn through(nodes: Vec<(f64, f64)>) -> Self {
        let one_sign =
            |n: &[(f64, f64)]| n.iter().all(|n| n.1 > 0.0) || n.iter().all(|n| n.1 < 0.0);
        let log = one_sign(&nodes);
        let x = nodes.iter().map(|n| n.0.ln()).collect();
        let y = nodes
            .iter()
            .map(|n| if log { n.1.abs().ln() } else { n.1 })
            .collect();
        let first = &nodes[..FIT_POINTS.min(nodes.len())];
        let low = one_sign(first).then(|| {
            let m = first.len() as f64;
            let lx: Vec<f64> = first.iter().map(|n| n.0.ln()).collect();
            let ly: Vec<f64> = first.iter().map(|n| n.1.abs().ln()).collect();
            let (mx, my) = (lx.iter().sum::<f64>() / m, ly.iter().sum::<f64>() / m);
            let sxy: f64 = lx.iter().zip(&ly).map(|(a, b)| (a - mx) * (b - my)).sum();
            let sxx: f64 = lx.iter().map(|a| (a - mx).powi(2)).sum();
            (nodes[0].0, nodes[0].1, sxy / sxx)
        });
        // The biased k^{3/2} P must fall towards k → 0, or the extension would wrap around.
        let low = low.filter(|law| law.2 + Q_BIAS >= 0.0);
        Self {
            spline: LogSpline::new(x, y),
            log_sign: log.then(|| nodes[0].1.signum()),
            range: (nodes[0].0, nodes[nodes.len() - 1].0),
            low,
        }
    }

    pub fn eval(&self, k: f64) -> f64 {
        let v = self.spline.eval(k.clamp(self.range.0, self.range.1).ln());
        self.log_sign.map_or(v, |sign| sign * v.exp())
    }

    /// The power-law extension below the first node (0 if there is none).
    pub fn extend(&self, k: f64) -> f64 {
        self.low
            .map_or(0.0, |(k0, p0, slope)| p0 * (k / k0).powf(slope))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fft_sizes_are_smooth() {
        for n in [10, 100, 1000, 2717, 5000] {
            let m = fft_size(n);
            assert!(
                m >= n && m.is_multiple_of(2) && m < 2 * n.max(32),
                "{n} → {m}"
            );
            let mut h = m / 2;
            for p in [2, 3] {
                while h.is_multiple_of(p) {
                    h /= p;
                }
            }
            assert_eq!(h, 1, "{n} → {m}");
        }
    }

    #[test]
    fn lagrange_weights_interpolate_polynomials() {
        let grid: Vec<f64> = (0..40).map(|i| 0.1 * 1.1f64.powi(i)).collect();
        let f = |k: f64| k.ln().powi(7) - 3.0 * k.ln();
        let values: Vec<f64> = grid.iter().map(|&k| f(k)).collect();
        for (k, (start, w)) in [0.1, 0.35, 2.0, 4.0]
            .iter()
            .zip(interpolation(&grid, &[0.1, 0.35, 2.0, 4.0]))
        {
            let v: f64 = w.iter().zip(&values[start..]).map(|(w, v)| w * v).sum();
            assert!((v - f(*k)).abs() < 1e-9 * f(*k).abs().max(1.0), "{k}: {v}");
        }
    }
}
