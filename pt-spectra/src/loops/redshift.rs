//! The 1-loop power spectrum of biased tracers in redshift space (standard Eulerian PT), as tables of
//! terms that multiply monomials of (b1, b2, bs, b3, f) and powers of μ: the terms of the galaxy model
//! `ept` ([`crate::rsd::ept`]; Chen, Vlah, Castorina & White 2021, arXiv:2012.04636, whose velocity
//! moments summed to 4th order are exactly this spectrum).
//!
//! With the bias expansion δ_g = b1 δ + (b2/2)(δ² − ⟨δ²⟩) + bs (s² − ⟨s²⟩) + b3 O₃ and the line-of-sight
//! velocity in units of −aHf, the redshift-space density is (Scoccimarro, Couchman & Frieman 1999)
//!   δ_s(k) = Σ_{m≥0} (fμk)^m/m! ∫ δ_D(k − Σp) (1 + δ_g)(p₀) Π_{j=1}^m (μ_j/p_j) θ(p_j),
//! so Z₁ = b1 + fμ² and, with the six second-order kernels of (k₁, k₂), k = k₁ + k₂,
//!   Z₂ = b1 K₁ + b1 f K₂ + f K₃ + f² K₄ + b2 K₅ + bs K₆,
//!   K₁ = F₂, K₂ = (μk/2)(μ₁/k₁ + μ₂/k₂), K₃ = μ² G₂, K₄ = (μk/2)(μ₁μ₂²/k₁ + μ₂μ₁²/k₂), K₅ = ½,
//!   K₆ = S₂ = (k̂₁·k̂₂)² − 1/3.
//! P^s = Z₁²P + 2∫Z₂²PP' + 6Z₁P∫Z₃(k, q, −q)P(q). Every P22-type column is 2∫K_aK_bPP' averaged over the
//! azimuth of q about k: with u = q̂·ẑ = xμ + √(1−x²)√(1−μ²) cos φ (x = k̂·q̂) and p = k − q, each K is
//! a polynomial in (μ, u) — K₂ = (k/2)(1/q − q/p²) μu + (k²/2p²) μ², K₄ = (k³/2qp²) μ³u − (k²/2p²) μ²u²
//! — and ⟨u^j⟩_φ a polynomial in μ, so each column is exactly a polynomial in μ² (`PAIR_COLUMNS`).
//!
//! Z₃(k, q, −q), symmetrised, has (terms with a zero-momentum pair dropped: they vanish or are the
//! ⟨δ²⟩, ⟨s²⟩ subtracted above) the real-space parts b1 F₃ + fμ² G₃ + b3 O₃ and four line-of-sight
//! parts, which after the azimuth are, per unit of 6Z₁P(k)∫d³q/(2π)³ P(q), r = q/k, x = k̂·q̂,
//! D = 1 + r² − 2rx, G⁻ = G₂(k, −q) = 3/7 + 4x²/7 − (x/2)(r + 1/r):
//!   b1 f μ² [ (2/3)(1 − rx)G⁻/D − (x²/3)(1 + 1/r²) ]          (θ₁δ₂ and θ₂δ₁: `LOS_B1F`),
//!   f² μ² (2/3) G⁻ [−(1 − x²)/2]/D,  f² μ⁴ (2/3) G⁻ [x/r − x² + (1 − x²)/2]/D   (θ₁θ₂),
//!   −(b1 f² μ² + f³ μ⁴)(1/6r²)[x²μ² + (1 − x²)(1 − μ²)/2]       (θ₁θ₁δ₁, θ₁θ₁θ₁: −(kμfσ_v)²Z₁²P).
//! The x integrals are Gauss–Legendre rules (through ln(a − x), a = (1 + r²)/2r, near r = 1, where the
//! integrand of the pole at x = a is steep), checked against brute-force quadrature in the tests.
//!
//! The cubic bias: b3 multiplies Z₁ sig3nl ([`super::bias`]), velocileptors' normalisation: b3 = 2 b3nl
//! of FAST-PT and Saito et al. 2014.
//!
//! Numerics and errors as [`super::bias`]: P22-type columns on the P22 nodes, the others as lattice
//! weights (cells split at q = k), the error the change on the half-resolution rules, floored at
//! `p22_error_floor` for the pair columns.

use super::bias::sig3nl_kernel;
use super::lattice::{add_product_weights, Lattice};
use super::one_loop::{validate_grid, COARSE_ORDER_DROP};
use super::p13::{p13_weights, sigma_v2_weights};
use super::p22::{Layout, PairNodes};

mod kernels;
use super::Estimate;
use crate::error::Result;
use crate::integrate::legendre_nodes;
use crate::linalg::dot;
use crate::linear::LinearSpectrum;
use crate::precision::Precision;
#[cfg(test)]
use kernels::pair_polynomials;
pub(crate) use kernels::NPAIR;
use kernels::{pair_columns, KERNEL_COEFFICIENTS, NLOS};
pub use kernels::{Monomial, PAIR_COLUMNS};
use rayon::prelude::*;
use std::f64::consts::PI;

/// Nodes and weights of the x integrals of the line-of-sight kernels.
struct XRule {
    x: Vec<f64>,
    w: Vec<f64>,
}

impl XRule {
    fn new(n: usize) -> Self {
        let (x, w) = legendre_nodes(n);
        Self { x, w }
    }

    /// ∫_lo^hi g(t) dt.
    fn integrate<const M: usize>(&self, lo: f64, hi: f64, g: impl Fn(f64) -> [f64; M]) -> [f64; M] {
        let (m, h) = (0.5 * (lo + hi), 0.5 * (hi - lo));
        let mut s = [0.0; M];
        for (&x, &w) in self.x.iter().zip(&self.w) {
            for (si, gi) in s.iter_mut().zip(g(m + h * x)) {
                *si += h * w * gi;
            }
        }
        s
    }
}

/// The three line-of-sight kernels of r = q/k (module docs), the x integrals done numerically.
fn los_kernels(r: f64, rule: &XRule) -> [f64; NLOS] {
    let inv = 1.0 / r;
    // The integrands times D = 1 + r² − 2rx (each has exactly one factor 1/D), and the rest.
    let numerators = |x: f64| {
        let g = 3.0 / 7.0 + 4.0 / 7.0 * x * x - 0.5 * x * (r + inv);
        let y2 = 1.0 - x * x;
        [
            2.0 / 3.0 * (1.0 - r * x) * g,
            2.0 / 3.0 * g * (-0.5 * y2),
            2.0 / 3.0 * g * (x * inv - x * x + 0.5 * y2),
        ]
    };
    let a = (1.0 + r * r) / (2.0 * r);
    let direct = |x: f64| numerators(x).map(|n| n / (1.0 + r * r - 2.0 * r * x));
    let mut s = if (r - 1.0).abs() > 0.5 {
        rule.integrate(-1.0, 1.0, direct)
    } else {
        // x in [0, 1] through t = ln(a − x): dx/D = −dt/(2r).
        let left = rule.integrate(-1.0, 0.0, direct);
        let through = |t: f64| numerators(a - t.exp()).map(|n| n / (2.0 * r));
        let (t0, t1) = ((a - 1.0).max(1e-300).ln(), a.ln());
        let split = t0.max(-6.0);
        let mut right = rule.integrate(split, t1, through);
        if split > t0 {
            let low = rule.integrate(t0, split, through);
            for (r, l) in right.iter_mut().zip(low) {
                *r += l;
            }
        }
        std::array::from_fn(|i| left[i] + right[i])
    };
    // The θ₁δ₂ part: ∫ −(x²/3)(1 + 1/r²) dx.
    s[0] -= 2.0 / 9.0 * (1.0 + inv * inv);
    s
}

/// The lattice weights (fine or half-resolution) of one plan.
#[derive(Debug, Clone)]
pub(crate) struct Rule {
    pub lattice: Lattice,
    pub pairs: PairNodes<NPAIR>,
    /// Per k: weights of [3∫F₃P, 3∫G₃P, sig3nl/P, LOS₁, LOS₂, LOS₃] (all per unit P_lin(k)).
    pub lattice_weights: Vec<[Vec<f64>; 6]>,
    pub sigma_v2: Vec<f64>,
}

impl Rule {
    fn new(ks: &[f64], lattice: Lattice, precision: &Precision, drop: usize) -> Self {
        let (nodes, weights) = legendre_nodes(precision.p13_cell_order);
        let cell = (nodes.as_slice(), weights.as_slice());
        let layout = Layout::new(precision, drop);
        let pairs = PairNodes::new(ks, &lattice, &layout, &|k, q, p, measure| {
            let c = measure / (PI * PI);
            pair_columns(k, q, p).map(|v| c * v)
        });
        let xrule = XRule::new(24);
        let lattice_weights = ks
            .par_iter()
            .map(|&k| {
                let p13 = p13_weights(&lattice, k, cell);
                let (a, b) = (lattice.x0, lattice.x_end());
                let split = k.ln().clamp(a, b);
                let mut w: [Vec<f64>; 4] = std::array::from_fn(|_| vec![0.0; lattice.len]);
                let norm = 6.0 / (4.0 * PI * PI);
                for (lo, hi) in [(a, split), (split, b)] {
                    if hi > lo {
                        add_product_weights(&lattice, &mut w, (lo, hi), cell, |x| {
                            let q = x.exp();
                            let q3 = q * q * q;
                            let [l1, l2, l3] = los_kernels(q / k, &xrule);
                            [
                                q3 / (2.0 * PI * PI) * sig3nl_kernel(q / k),
                                norm * q3 * l1,
                                norm * q3 * l2,
                                norm * q3 * l3,
                            ]
                        });
                    }
                }
                let [s3, l1, l2, l3] = w;
                [p13.f, p13.g, s3, l1, l2, l3]
            })
            .collect();
        let sigma_v2 = sigma_v2_weights(&lattice, cell);
        Self {
            lattice,
            pairs,
            lattice_weights,
            sigma_v2,
        }
    }

    /// The pair columns at k index `i` of `S` spectra at once from their lattice `samples` (one
    /// pass over the nodes: the weights are read once).
    fn pairs<const S: usize>(&self, i: usize, samples: [&[f64]; S]) -> [[f64; NPAIR]; S] {
        let (mut start, outer) = self.pairs.ranges(i);
        let mut total = [[0.0; NPAIR]; S];
        for o in outer {
            let end = self.pairs.outer_end[o] as usize;
            let mut acc = [[0.0; NPAIR]; S];
            let nodes = self.pairs.inner_b[start..end]
                .iter()
                .zip(&self.pairs.inner_l[start..end])
                .zip(&self.pairs.inner_w[start..end]);
            for ((&b, l), w) in nodes {
                let l = l.map(f64::from);
                let pp: [f64; S] = std::array::from_fn(|j| {
                    let s = &samples[j][b as usize..b as usize + 4];
                    (l[0] * s[0] + l[1] * s[1]) + (l[2] * s[2] + l[3] * s[3])
                });
                for (c, w) in w.iter().enumerate() {
                    let w = f64::from(*w);
                    for j in 0..S {
                        acc[j][c] += w * pp[j];
                    }
                }
            }
            for j in 0..S {
                let pq = self.lattice.interpolate(samples[j], self.pairs.outer_u[o]);
                for (t, a) in total[j].iter_mut().zip(acc[j]) {
                    *t += pq * a;
                }
            }
            start = end;
        }
        total
    }
}

/// The pair columns and the lattice-weight terms of one k.
pub(crate) type Row = ([Estimate; NPAIR], [Estimate; 6]);

/// One term of the table: `monomial` · μ^{2n} · `values[i]` at the i-th k.
#[derive(Debug, Clone, PartialEq)]
pub struct RedshiftTerm {
    /// The parameters it multiplies.
    pub monomial: Monomial,
    /// The power of μ is 2n.
    pub n: usize,
    /// Its value per k [(Mpc/h)³], with error.
    pub values: Vec<Estimate>,
}

/// The 1-loop redshift-space spectrum of one linear spectrum on the plan's k grid, as terms.
#[derive(Debug, Clone, PartialEq)]
pub struct RedshiftTerms {
    /// Wavenumbers [h/Mpc].
    pub k: Vec<f64>,
    /// P_lin(k) [(Mpc/h)³].
    pub p_lin: Vec<f64>,
    /// The loop terms (linear Z₁²P not included), like monomials and powers merged.
    pub terms: Vec<RedshiftTerm>,
    /// σ_v² = (1/6π²)∫P dq [(Mpc/h)²].
    pub sigma_v2: Estimate,
}

impl RedshiftTerms {
    /// The loop part Σ monomial · values as coefficients of μ^{2n} (n ≤ 4) at k index `i` for
    /// `params` = [b1, b2, bs, b3, f]: (values, errors).
    pub fn loop_polynomial(&self, i: usize, params: [f64; 5]) -> ([f64; 5], [f64; 5]) {
        self.loop_polynomial_with(i, &self.coefficients(params))
    }

    /// The value of every term's monomial at `params` = [b1, b2, bs, b3, f], in the order of
    /// [`Self::terms`]: computed once per parameter point for [`Self::loop_polynomial_with`].
    pub fn coefficients(&self, params: [f64; 5]) -> Vec<f64> {
        self.terms.iter().map(|t| t.monomial.eval(params)).collect()
    }

    /// ∂/∂f of [`Self::coefficients`] (the loop part is linear in them: its f-derivative is
    /// [`Self::loop_values_all`] of these).
    pub fn coefficients_df(&self, params: [f64; 5]) -> Vec<f64> {
        self.terms
            .iter()
            .map(|t| t.monomial.eval_df(params))
            .collect()
    }

    /// The values only of [`Self::loop_polynomial_with`] at every grid point (the fast path of the
    /// multipoles' values): term by term, the terms of zero coefficient skipped (most, for the unit
    /// parameter sets of a nuisance polynomial).
    pub fn loop_values_all(&self, coefficients: &[f64]) -> Vec<[f64; 5]> {
        let mut v = vec![[0.0; 5]; self.terms.first().map_or(0, |t| t.values.len())];
        for (t, &c) in self.terms.iter().zip(coefficients) {
            if c != 0.0 {
                for (v, x) in v.iter_mut().zip(&t.values) {
                    v[t.n] += c * x.value;
                }
            }
        }
        v
    }

    /// [`Self::loop_polynomial`] from the monomials' values `coefficients`.
    pub fn loop_polynomial_with(&self, i: usize, coefficients: &[f64]) -> ([f64; 5], [f64; 5]) {
        let (mut v, mut e) = ([0.0; 5], [0.0; 5]);
        for (t, c) in self.terms.iter().zip(coefficients) {
            v[t.n] += c * t.values[i].value;
            e[t.n] += c.abs() * t.values[i].error;
        }
        (v, e)
    }

    fn push(&mut self, monomial: Monomial, n: usize, values: Vec<Estimate>) {
        match self
            .terms
            .iter_mut()
            .find(|t| t.monomial == monomial && t.n == n)
        {
            Some(t) => {
                for (a, b) in t.values.iter_mut().zip(values) {
                    *a += b;
                }
            }
            None => self.terms.push(RedshiftTerm {
                monomial,
                n,
                values,
            }),
        }
    }
}

/// The plan of the 1-loop redshift-space terms on a fixed k grid: all weights, independent of the
/// linear spectrum.
#[derive(Debug, Clone)]
pub struct RedshiftPlan {
    k: Vec<f64>,
    precision: Precision,
    fine: Rule,
    coarse: Rule,
}

/// Bytes per output k of the plan at the default node density (31 f32 weights per P22 node).
const BYTES_PER_K: f64 = 1.8e6;

impl RedshiftPlan {
    /// The estimated memory of a plan on `nk` wavenumbers with `precision` \[bytes\] (its rules at
    /// `BYTES_PER_K` per k, scaled with the node density), which [`new`](Self::new) checks against
    /// the limit before it allocates.
    pub fn memory_estimate(nk: usize, precision: &Precision) -> f64 {
        BYTES_PER_K * crate::memory::node_density(precision) * nk as f64
    }

    /// The plan for wavenumbers `k` [h/Mpc] with the P22 and P13 settings of `precision`.
    ///
    /// # Errors
    /// As [`crate::loops::OneLoopPlan::new`]; [`crate::error::Error::MemoryLimit`] above the memory
    /// limit.
    pub fn new(k: &[f64], precision: &Precision) -> Result<Self> {
        validate_grid(k, precision)?;
        crate::memory::check(
            crate::memory::PROCESS + Self::memory_estimate(k.len(), precision),
            precision,
            &format!("the redshift-space 1-loop plan on {} k", k.len()),
        )?;
        let lattice = Lattice::new(precision.q_min, precision.q_max, precision.lattice_step);
        let coarse_lattice = lattice.coarse();
        let (coarse, fine) = rayon::join(
            || Rule::new(k, coarse_lattice, precision, COARSE_ORDER_DROP),
            || Rule::new(k, lattice, precision, 0),
        );
        Ok(Self {
            k: k.to_vec(),
            precision: precision.clone(),
            fine,
            coarse,
        })
    }

    /// The wavenumbers [h/Mpc].
    pub fn k(&self) -> &[f64] {
        &self.k
    }

    /// The settings the plan was built with.
    pub fn precision(&self) -> &Precision {
        &self.precision
    }

    /// The fine rule and the half-resolution rule of the error estimates (the basis tensors of
    /// [`super::basis::RedshiftBasis`] are made from them).
    pub(crate) fn rules(&self) -> (&Rule, &Rule) {
        (&self.fine, &self.coarse)
    }

    /// The terms of `spectrum` (over the plan's q range, through its power-law extrapolation).
    pub fn evaluate(&self, spectrum: &LinearSpectrum) -> RedshiftTerms {
        let fine = self.fine.lattice.sample(spectrum);
        let coarse: Vec<f64> = fine.iter().step_by(2).copied().collect();
        let floor = self.precision.p22_error_floor;
        let rows: Vec<Row> = (0..self.k.len())
            .into_par_iter()
            .with_min_len(4)
            .map(|i| {
                let ([a], [b]) = (self.fine.pairs(i, [&fine]), self.coarse.pairs(i, [&coarse]));
                self.row(i, spectrum.eval(self.k[i]), &a, &b, floor, &fine, &coarse)
            })
            .collect();
        self.assemble(spectrum, &rows, &fine, &coarse)
    }

    /// The terms of `full` and of its no-wiggle part `no_wiggle` in one pass over the nodes (what
    /// IR resummation needs). The errors of the no-wiggle terms are those of the full ones (the
    /// rules are the same and the spectra differ by the wiggles only).
    pub fn evaluate_with_no_wiggle(
        &self,
        full: &LinearSpectrum,
        no_wiggle: &LinearSpectrum,
    ) -> (RedshiftTerms, RedshiftTerms) {
        let fine = self.fine.lattice.sample(full);
        let fine_nw = self.fine.lattice.sample(no_wiggle);
        let coarse: Vec<f64> = fine.iter().step_by(2).copied().collect();
        let coarse_nw: Vec<f64> = fine_nw.iter().step_by(2).copied().collect();
        let floor = self.precision.p22_error_floor;
        let rows: Vec<(Row, Row)> = (0..self.k.len())
            .into_par_iter()
            .with_min_len(4)
            .map(|i| {
                let [a, a_nw] = self.fine.pairs(i, [&fine, &fine_nw]);
                let [b] = self.coarse.pairs(i, [&coarse]);
                let k = self.k[i];
                let row = self.row(i, full.eval(k), &a, &b, floor, &fine, &coarse);
                let mut row_nw = self.row(
                    i,
                    no_wiggle.eval(k),
                    &a_nw,
                    &a_nw,
                    0.0,
                    &fine_nw,
                    &coarse_nw,
                );
                for (e, f) in row_nw.0.iter_mut().zip(&row.0) {
                    e.error = f.error;
                }
                for (e, f) in row_nw.1.iter_mut().zip(&row.1) {
                    e.error = f.error;
                }
                (row, row_nw)
            })
            .collect();
        let (rows, rows_nw): (Vec<Row>, Vec<Row>) = rows.into_iter().unzip();
        (
            self.assemble(full, &rows, &fine, &coarse),
            self.assemble(no_wiggle, &rows_nw, &fine_nw, &coarse_nw),
        )
    }

    /// One k's pair columns (fine `a`, half-resolution `b`) and lattice-weight terms, with errors.
    #[allow(clippy::too_many_arguments)]
    fn row(
        &self,
        i: usize,
        p: f64,
        a: &[f64; NPAIR],
        b: &[f64; NPAIR],
        floor: f64,
        fine: &[f64],
        coarse: &[f64],
    ) -> Row {
        let pairs = std::array::from_fn(|j| {
            Estimate::new(a[j], (a[j] - b[j]).abs().max(floor * a[j].abs()))
        });
        let lw = std::array::from_fn(|j| {
            let s = dot(&self.fine.lattice_weights[i][j], fine);
            let c = dot(&self.coarse.lattice_weights[i][j], coarse);
            Estimate::new(p * s, (p * (s - c)).abs())
        });
        (pairs, lw)
    }

    /// The terms from the rows of every k.
    fn assemble(
        &self,
        spectrum: &LinearSpectrum,
        rows: &[Row],
        fine: &[f64],
        coarse: &[f64],
    ) -> RedshiftTerms {
        let sv = dot(&self.fine.sigma_v2, fine);
        let sv_coarse = dot(&self.coarse.sigma_v2, coarse);
        let sigma_v2 = Estimate::new(sv, (sv - sv_coarse).abs());
        let p_lin: Vec<f64> = self.k.iter().map(|&k| spectrum.eval(k)).collect();
        self.assemble_rows(p_lin, rows, sigma_v2)
    }

    /// The terms from the rows of every k, P_lin at k and σ_v².
    pub(crate) fn assemble_rows(
        &self,
        p_lin: Vec<f64>,
        rows: &[Row],
        sigma_v2: Estimate,
    ) -> RedshiftTerms {
        let sv_p: Vec<Estimate> = p_lin.iter().map(|&p| sigma_v2 * p).collect();
        self.assemble_rows_with(p_lin, rows, sigma_v2, &sv_p)
    }

    /// [`Self::assemble_rows`] with the products σ_v² P_lin at every k given (`sv_p`): the one
    /// term that is a product of two linear functionals of the spectrum, whose tangent
    /// ([`crate::loops::basis::RedshiftBasis::evaluate_tangents`]) is δσ_v² P + σ_v² δP.
    pub(crate) fn assemble_rows_with(
        &self,
        p_lin: Vec<f64>,
        rows: &[Row],
        sigma_v2: Estimate,
        sv_p: &[Estimate],
    ) -> RedshiftTerms {
        let nk = self.k.len();
        let mut out = RedshiftTerms {
            k: self.k.clone(),
            p_lin: p_lin.clone(),
            terms: Vec::new(),
            sigma_v2,
        };
        let column = |f: &dyn Fn(usize) -> Estimate| (0..nk).map(f).collect::<Vec<_>>();
        for (c, &(a, b, n)) in PAIR_COLUMNS.iter().enumerate() {
            let m = KERNEL_COEFFICIENTS[a].times(KERNEL_COEFFICIENTS[b]);
            let sym = if a == b { 1.0 } else { 2.0 };
            out.push(m, n, column(&|i| sym * rows[i].0[c]));
        }
        let mono = Monomial::new;
        // Real-space P13: 6Z₁P∫(b1F₃ + fμ²G₃)P = b1²·2P13_F + b1fμ²·2(P13_F + P13_G) + f²μ⁴·2P13_G.
        let lw = |j: usize| column(&|i| rows[i].1[j]);
        let (pf, pg) = (lw(0), lw(1));
        out.push(
            mono(2, 0, 0, 0, 0),
            0,
            pf.iter().map(|&e| 2.0 * e).collect(),
        );
        out.push(
            mono(1, 0, 0, 0, 1),
            1,
            pf.iter().zip(&pg).map(|(&a, &b)| 2.0 * (a + b)).collect(),
        );
        out.push(
            mono(0, 0, 0, 0, 2),
            2,
            pg.iter().map(|&e| 2.0 * e).collect(),
        );
        // The cubic bias: Z₁ b3 sig3nl.
        let s3 = lw(2);
        out.push(mono(1, 0, 0, 1, 0), 0, s3.clone());
        out.push(mono(0, 0, 0, 1, 1), 1, s3);
        // Line of sight, times Z₁ = b1 + fμ².
        let (l1, l2, l3) = (lw(3), lw(4), lw(5));
        out.push(mono(2, 0, 0, 0, 1), 1, l1.clone());
        out.push(mono(1, 0, 0, 0, 2), 2, l1);
        out.push(mono(1, 0, 0, 0, 2), 1, l2.clone());
        out.push(mono(0, 0, 0, 0, 3), 2, l2);
        out.push(mono(1, 0, 0, 0, 2), 2, l3.clone());
        out.push(mono(0, 0, 0, 0, 3), 3, l3);
        // −(kμfσ_v)² Z₁² P.
        let d = column(&|i| sv_p[i] * (-self.k[i] * self.k[i]));
        out.push(mono(2, 0, 0, 0, 2), 1, d.clone());
        out.push(mono(1, 0, 0, 0, 3), 2, d.iter().map(|&e| 2.0 * e).collect());
        out.push(mono(0, 0, 0, 0, 4), 3, d);
        out
    }
}

#[cfg(test)]
mod tests;
