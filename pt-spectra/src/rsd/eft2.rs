//! `eft2`: the matter multipoles of 2-loop perturbation theory in redshift space with the BAO
//! resummed and EFT counterterms, on the SPT terms of [`super::spt2`].
//!
//! **IR resummation** (the real-space `2l-spt-ir` of [`crate::ir`], with the redshift-space damping of
//! Ivanov, Simonović & Zaldarriaga 2020 as in CLASS-PT): with P_nw the no-wiggle part
//! ([`crate::ir::WiggleSplit`]), P_w = P − P_nw, the loop terms P^(n)[·] of each in redshift space and
//! P^(n)_w = P^(n)\[P\] − P^(n)\[P_nw\], Z₁ = 1 + fμ², x = k²Σ²(μ), D = e^{−x},
//!
//! ```text
//! P_s = Z₁²P_nw + P^(1)[P_nw] + P^(2)[P_nw] + D [(1 + x + x²/2) Z₁²P_w + (1 + x) P^(1)_w + P^(2)_w],
//! Σ²(μ) = [1 + fμ²(2 + f)] Σ² + f²μ²(μ² − 1) δΣ²,
//! ```
//!
//! Σ² and δΣ² of [`crate::ir::sigma2_bao`] and [`crate::ir::delta_sigma2_bao`]. Expanding D gives back
//! `spt2` to two loops. The 2-loop terms of P and P_nw are integrated on the same points
//! ([`crate::loops::rsd_two_loop_of`]), so P^(2)_w carries the small error of a difference of
//! correlated estimates.
//!
//! **Counterterms** ([`RsdCounterterm`]), each entering linearly, so a fit is linear in them (`--terms`
//! prints the multipoles of each template T_X = ∂P/∂X):
//! * `c0`, `c2`, `c4` [(Mpc/h)²]: −2 c_{2n} k² μ^{2n} P_IR(k, μ), the k² counterterm of the 1-loop
//!   spectrum and of the double-hard limit of the 2-loop terms (at f = 0, `c0` is the real-space
//!   `cs2`);
//! * `c0_1loop`, `c2_1loop`, `c4_1loop` [(Mpc/h)²]: −2 c k² μ^{2n} P^(1)_IR(k, μ), the counterterm
//!   inserted in the 1-loop diagrams, the single-hard limit of the 2-loop terms;
//! * `ctilde` [(Mpc/h)⁴]: −c̃ k⁴ f⁴ μ⁴ Z₁² P_IR(k, μ), the next-to-leading Fingers-of-God term of
//!   CLASS-PT;
//!
//! with the IR-resummed shapes P_IR = P_nw + D P_w and P^(1)_IR = P^(1)\[P_nw\] + D P^(1)_w (without
//! resummation P and P^(1)\[P\]). Taule & Garny (2023) describe their set as covering the single- and
//! double-hard UV limits with two parameters per multipole; this set has the same structure per power
//! of μ (their equations were not available to us) and is checked by what it must do: absorb the
//! dependence of the 2-loop multipoles on the loop cut-off (`tests/tests/suite/rsd_two_loop.rs`).
//!
//! **Multipoles** by a 24-node Gauss–Legendre rule in μ on [0, 1] (error: the change from 12 nodes)
//! for the deterministic parts, and for the 2-loop parts as functionals of their μ² nodes
//! ([`crate::loops::combined`], error the shifts' standard error).

use super::spt2::{loop_terms, two_loop_rsd_plan, LoopTensors};
use crate::error::{Error, Result};
use crate::integrate::legendre_nodes;
use crate::ir::{bao_damping, sigma2_total, WiggleSplit};
use crate::linear::LinearSpectrum;
use crate::loops::basis::training::{camb_basis, transformed_basis};
use crate::loops::basis::{LinearBasis, RsdTwoLoopBasis, SpectrumFamily, BASIS_SIZE};
use crate::loops::redshift::{RedshiftPlan, RedshiftTerms};
use crate::loops::rsd_two_loop::legendre;
use crate::loops::{combined, node_weights_on, Estimate, NodeRule, RsdTwoLoopTerms};
use crate::output::MethodNote;
use crate::precision::Precision;
use crate::progress::Progress;
use crate::store::TableStore;
use std::fmt;
use std::str::FromStr;

/// The counterterms of `eft2` (module docs).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum RsdCounterterm {
    /// −2 c0 k² P_IR.
    C0,
    /// −2 c2 k² μ² P_IR.
    C2,
    /// −2 c4 k² μ⁴ P_IR.
    C4,
    /// −2 c0_1loop k² P^(1)_IR.
    C0OneLoop,
    /// −2 c2_1loop k² μ² P^(1)_IR.
    C2OneLoop,
    /// −2 c4_1loop k² μ⁴ P^(1)_IR.
    C4OneLoop,
    /// −ctilde k⁴ f⁴ μ⁴ Z₁² P_IR.
    Ctilde,
}

impl RsdCounterterm {
    /// Every counterterm, in the order of [`RsdCounterterms::values`].
    pub const ALL: [RsdCounterterm; 7] = [
        Self::C0,
        Self::C2,
        Self::C4,
        Self::C0OneLoop,
        Self::C2OneLoop,
        Self::C4OneLoop,
        Self::Ctilde,
    ];

    /// The name on the command line and in Python.
    pub fn name(self) -> &'static str {
        match self {
            Self::C0 => "c0",
            Self::C2 => "c2",
            Self::C4 => "c4",
            Self::C0OneLoop => "c0_1loop",
            Self::C2OneLoop => "c2_1loop",
            Self::C4OneLoop => "c4_1loop",
            Self::Ctilde => "ctilde",
        }
    }

    /// The template ∂P_s/∂X at μ from the shapes at μ: P_IR, P^(1)_IR, and k, f, Z₁.
    fn template(self, k: f64, f: f64, mu: f64, lin: f64, one: f64) -> f64 {
        let (k2, m2) = (k * k, mu * mu);
        match self {
            Self::C0 => -2.0 * k2 * lin,
            Self::C2 => -2.0 * k2 * m2 * lin,
            Self::C4 => -2.0 * k2 * m2 * m2 * lin,
            Self::C0OneLoop => -2.0 * k2 * one,
            Self::C2OneLoop => -2.0 * k2 * m2 * one,
            Self::C4OneLoop => -2.0 * k2 * m2 * m2 * one,
            Self::Ctilde => {
                let z1 = 1.0 + f * m2;
                -k2 * k2 * f.powi(4) * m2 * m2 * z1 * z1 * lin
            }
        }
    }
}

impl fmt::Display for RsdCounterterm {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

impl FromStr for RsdCounterterm {
    type Err = Error;

    fn from_str(s: &str) -> Result<Self> {
        Self::ALL
            .into_iter()
            .find(|c| c.name() == s.trim())
            .ok_or_else(|| Error::UnknownName {
                what: "eft2 counterterm",
                name: s.to_string(),
                available: "c0, c2, c4, c0_1loop, c2_1loop, c4_1loop, ctilde",
            })
    }
}

/// The values of the counterterms (all 0 by default: IR-resummed SPT).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct RsdCounterterms {
    /// In the order of [`RsdCounterterm::ALL`].
    pub values: [f64; 7],
}

impl RsdCounterterms {
    /// From `NAME=VALUE` assignments, each name at most once.
    ///
    /// # Errors
    /// [`Error::UnknownName`] for an unknown name; [`Error::InvalidChoice`] for a missing `=`, a value
    /// that is not a finite number, or a name given twice.
    pub fn from_assignments<S: AsRef<str>>(assignments: &[S]) -> Result<Self> {
        let mut out = Self::default();
        let mut seen = [false; 7];
        for a in assignments {
            let a = a.as_ref();
            let bad = |reason: String| Error::InvalidChoice {
                what: format!("eft2 counterterm `{a}`"),
                reason,
            };
            let (name, value) = a
                .split_once('=')
                .ok_or_else(|| {
                    bad("write NAME=VALUE, NAME one of c0, c2, c4, c0_1loop, c2_1loop, c4_1loop, ctilde".into())
                })?;
            let c: RsdCounterterm = name.parse()?;
            let v: f64 = value
                .trim()
                .parse()
                .ok()
                .filter(|v: &f64| v.is_finite())
                .ok_or_else(|| bad(format!("'{value}' is not a finite number")))?;
            let j = RsdCounterterm::ALL
                .iter()
                .position(|&x| x == c)
                .unwrap_or(0);
            if seen[j] {
                return Err(bad(format!("{} is given twice", c.name())));
            }
            seen[j] = true;
            out.values[j] = v;
        }
        Ok(out)
    }

    /// `name = value, …` of every counterterm.
    pub fn describe(&self) -> String {
        RsdCounterterm::ALL
            .iter()
            .zip(self.values)
            .map(|(c, v)| format!("{c} = {v}"))
            .collect::<Vec<_>>()
            .join(", ")
    }
}

/// The plan of `eft2` on a k grid: the 1-loop weights, the wiggle split and the 2-loop settings.
#[derive(Debug, Clone)]
pub struct Eft2Plan {
    one_loop: RedshiftPlan,
    split: WiggleSplit,
    ir: bool,
    precision: Precision,
    /// The 1- and 2-loop basis tensors of the linear and (with IR resummation) no-wiggle spectra.
    tensors: LoopTensors,
}

/// The terms of `eft2` for one linear spectrum.
#[derive(Debug, Clone, PartialEq)]
pub struct Eft2Terms {
    /// Wavenumbers [h/Mpc].
    pub k: Vec<f64>,
    /// P_lin(k) and, with IR resummation, P_nw(k) [(Mpc/h)³].
    pub p_lin: Vec<f64>,
    p_nw: Vec<f64>,
    /// Σ² and δΣ² [(Mpc/h)²] (zero without IR resummation).
    pub sigma2: (Estimate, Estimate),
    one_full: RedshiftTerms,
    one_nw: Option<RedshiftTerms>,
    two_full: RsdTwoLoopTerms,
    two_nw: Option<RsdTwoLoopTerms>,
    /// Where the 2-loop terms came from (basis tensors or direct), for a header.
    pub source: String,
    /// The same in a word, for Python's `meta["methods"]`.
    pub method: MethodNote,
}

/// The multipoles of `eft2` per ℓ then per k, and those of each counterterm template.
#[derive(Debug, Clone, PartialEq)]
pub struct Eft2Multipoles {
    /// The model with the counterterms.
    pub total: Vec<Vec<Estimate>>,
    /// ∂P_ℓ/∂X per counterterm (in the order of [`RsdCounterterm::ALL`]), per ℓ, per k.
    pub templates: Vec<Vec<Vec<f64>>>,
}

two_loop_rsd_plan!(Eft2Plan, Eft2Terms, "2-loop EFT redshift-space terms");

impl Eft2Plan {
    /// The plan on `k` [h/Mpc] with IR resummation `ir`.
    ///
    /// # Errors
    /// As [`RedshiftPlan::new`] and [`WiggleSplit::new`].
    pub fn new(k: &[f64], ir: bool, precision: &Precision) -> Result<Self> {
        Ok(Self {
            one_loop: RedshiftPlan::new(k, precision)?,
            split: WiggleSplit::new()?,
            ir,
            precision: precision.clone(),
            tensors: LoopTensors::default(),
        })
    }

    /// The plan with the basis tensors of the 2-loop and 1-loop terms (of the linear spectra and,
    /// with IR resummation, of their no-wiggle parts) as `precision.two_loop` says
    /// ([`super::spt2::Spt2Plan::with_basis`]).
    ///
    /// # Errors
    /// As [`TableStore::for_method`].
    pub fn with_basis(mut self, store: &TableStore, progress: &dyn Progress) -> Result<Self> {
        let p = &self.precision;
        let lattice = RsdTwoLoopBasis::lattice((p.q_min, p.q_max), p.lattice_step);
        let linear = || camb_basis(lattice.clone(), BASIS_SIZE);
        // Made at most once (the training set through the split), for both tensors.
        let split_basis = std::cell::OnceCell::new();
        let split = &self.split;
        let no_wiggle = || {
            split_basis
                .get_or_init(|| {
                    transformed_basis(&lattice, BASIS_SIZE, &|s: &LinearSpectrum| {
                        split.no_wiggle(s).unwrap_or_else(|_| s.clone())
                    })
                })
                .clone()
        };
        let mut families: Vec<(_, &dyn Fn() -> LinearBasis)> =
            vec![(SpectrumFamily::Linear, &linear)];
        if self.ir {
            families.push((SpectrumFamily::NoWiggle, &no_wiggle));
        }
        self.tensors = LoopTensors::load(&self.one_loop, &families, store, progress)?;
        Ok(self)
    }

    /// The wavenumbers [h/Mpc].
    pub fn k(&self) -> &[f64] {
        self.one_loop.k()
    }

    /// Whether the BAO are resummed.
    pub fn ir(&self) -> bool {
        self.ir
    }

    /// The 2-loop integration settings ([`super::spt2::two_loop_settings`]).
    pub fn two_loop_settings(&self) -> crate::loops::TwoLoopSettings {
        super::spt2::two_loop_settings(&self.precision)
    }

    /// The terms of `spectrum` (with IR resummation: of it and of its no-wiggle part, the 2-loop terms
    /// of both on the same points); the points are reported to `progress`.
    ///
    /// # Errors
    /// As [`crate::loops::rsd_two_loop_of`] and [`WiggleSplit::no_wiggle`].
    pub fn terms(&self, spectrum: &LinearSpectrum, progress: &dyn Progress) -> Result<Eft2Terms> {
        let k = self.k();
        let p_lin: Vec<f64> = k.iter().map(|&k| spectrum.eval(k)).collect();
        if !self.ir {
            let (mut one, mut two, source, method) =
                loop_terms(&self.one_loop, &[spectrum], &self.tensors, progress)?;
            return Ok(Eft2Terms {
                k: k.to_vec(),
                p_nw: p_lin.clone(),
                p_lin,
                sigma2: (Estimate::default(), Estimate::default()),
                one_full: one.remove(0),
                one_nw: None,
                two_full: two.remove(0),
                two_nw: None,
                source,
                method,
            });
        }
        let nw = self.split.no_wiggle(spectrum)?;
        let (mut one, mut two, source, method) =
            loop_terms(&self.one_loop, &[spectrum, &nw], &self.tensors, progress)?;
        let q_min = self.precision.q_min;
        Ok(Eft2Terms {
            k: k.to_vec(),
            p_nw: k.iter().map(|&k| nw.eval(k)).collect(),
            p_lin,
            sigma2: bao_damping(&nw, q_min),
            one_nw: one.pop(),
            one_full: one.remove(0),
            two_nw: two.pop(),
            two_full: two.remove(0),
            source,
            method,
        })
    }
}

/// Gauss–Legendre nodes and weights on μ ∈ [0, 1].
fn mu_rule(n: usize) -> Vec<(f64, f64)> {
    let (x, w) = legendre_nodes(n);
    x.iter()
        .zip(&w)
        .map(|(&x, &w)| (0.5 * (x + 1.0), 0.5 * w))
        .collect()
}

/// Nodes of the multipole rule in μ (its error from half as many).
pub const MU_NODES: usize = 24;

impl Eft2Terms {
    /// Whether the BAO are resummed.
    pub fn ir(&self) -> bool {
        self.one_nw.is_some()
    }

    /// k²Σ²(μ) at k index `i` (0 without IR resummation).
    fn x(&self, i: usize, f: f64, mu: f64) -> f64 {
        let k = self.k[i];
        k * k * sigma2_total(self.sigma2.0.value, self.sigma2.1.value, f, mu)
    }

    /// At k index `i` and μ: the model without its 2-loop terms, and the shapes P_IR, P^(1)_IR of the
    /// counterterms.
    fn deterministic(
        &self,
        i: usize,
        f: f64,
        mu: f64,
        polys: &[([f64; 5], [f64; 5]); 2],
    ) -> [f64; 3] {
        let m2 = mu * mu;
        let z1 = 1.0 + f * m2;
        let at = |c: &[f64; 5]| c.iter().rev().fold(0.0, |acc, c| acc * m2 + c);
        let one_full = at(&polys[0].0);
        if !self.ir() {
            let p = self.p_lin[i];
            return [z1 * z1 * p + one_full, p, one_full];
        }
        let one_nw = at(&polys[1].0);
        let (p_nw, p_w) = (self.p_nw[i], self.p_lin[i] - self.p_nw[i]);
        let x = self.x(i, f, mu);
        let d = (-x).exp();
        let one_w = one_full - one_nw;
        let value = z1 * z1 * p_nw
            + one_nw
            + d * ((1.0 + x + 0.5 * x * x) * z1 * z1 * p_w + (1.0 + x) * one_w);
        [value, p_nw + d * p_w, one_nw + d * one_w]
    }

    /// The multipoles ℓ ∈ `ells` (even, ≤ 8) at growth rate `f` with the counterterms `ct`, and
    /// the multipoles of every counterterm template.
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] for a bad ℓ or a non-finite f.
    pub fn multipoles(
        &self,
        f: f64,
        ells: &[usize],
        ct: &RsdCounterterms,
    ) -> Result<Eft2Multipoles> {
        super::MultipoleRule::new(ells)?;
        if !f.is_finite() {
            return Err(Error::InvalidParameter {
                name: "growth rate f",
                value: f,
                reason: "must be finite",
            });
        }
        let params = [1.0, 0.0, 0.0, 0.0, f];
        let coefficients = self.one_full.coefficients(params);
        let (fine, coarse) = (mu_rule(MU_NODES), mu_rule(MU_NODES / 2));
        let rule = NodeRule::new();
        let mut total = vec![Vec::with_capacity(self.k.len()); ells.len()];
        let mut templates = vec![vec![Vec::with_capacity(self.k.len()); ells.len()]; 7];
        for i in 0..self.k.len() {
            let full = self.one_full.loop_polynomial_with(i, &coefficients);
            let nw = match &self.one_nw {
                Some(t) => t.loop_polynomial_with(i, &coefficients),
                None => full,
            };
            let polys = [full, nw];
            let mut one_loop_error: f64 = full.1.iter().sum();
            if self.ir() {
                one_loop_error += nw.1.iter().sum::<f64>();
            }
            // the model without its 2-loop terms and every template at the nodes of both rules
            let at_nodes = |rule: &[(f64, f64)]| -> Vec<(f64, f64, [f64; 8])> {
                rule.iter()
                    .map(|&(mu, w)| {
                        let [value, lin, one] = self.deterministic(i, f, mu, &polys);
                        let mut out = [value; 8];
                        for (c, o) in RsdCounterterm::ALL.iter().zip(&mut out[1..]) {
                            *o = c.template(self.k[i], f, mu, lin, one);
                        }
                        (mu, w, out)
                    })
                    .collect()
            };
            let (fine_values, coarse_values) = (at_nodes(&fine), at_nodes(&coarse));
            for (l, &ell) in ells.iter().enumerate() {
                let project = |values: &[(f64, f64, [f64; 8])]| -> [f64; 8] {
                    let mut out = [0.0; 8];
                    for (mu, w, v) in values {
                        let weight = (2 * ell + 1) as f64 * w * legendre(ell, *mu);
                        for (o, x) in out.iter_mut().zip(v) {
                            *o += weight * x;
                        }
                    }
                    out
                };
                let (a, b) = (project(&fine_values), project(&coarse_values));
                let mut value = a[0];
                let mut error = (a[0] - b[0]).abs() + (2 * ell + 1) as f64 * one_loop_error;
                for (j, (&c, t)) in ct.values.iter().zip(&a[1..]).enumerate() {
                    value += c * t;
                    error += (c * (t - b[1 + j])).abs();
                    templates[j][l].push(*t);
                }
                let g = |mu: f64| (2 * ell + 1) as f64 * legendre(ell, mu);
                let two = match &self.two_nw {
                    None => self.two_full.functional(i, f, &node_weights_on(&rule, g)),
                    Some(nw) => {
                        let d = |mu: f64| (-self.x(i, f, mu)).exp();
                        combined(
                            &[
                                (&self.two_full, node_weights_on(&rule, |mu| g(mu) * d(mu))),
                                (nw, node_weights_on(&rule, |mu| g(mu) * (1.0 - d(mu)))),
                            ],
                            i,
                            f,
                        )
                    }
                };
                total[l].push(Estimate::new(value, error) + two);
            }
        }
        Ok(Eft2Multipoles { total, templates })
    }
}

/// Measured multipoles to fit: P_ℓ(k) at the terms' k with 1σ errors, per ℓ.
#[derive(Debug, Clone, PartialEq)]
pub struct MeasuredMultipole {
    /// The multipole order (even, ≤ 8).
    pub ell: usize,
    /// P_ℓ at each k of the terms [(Mpc/h)³].
    pub values: Vec<f64>,
    /// Its 1σ errors.
    pub sigma: Vec<f64>,
}

/// The counterterms `free` that fit `data` by weighted least squares over k ≤ `k_max` at growth rate
/// `f` (the others held at `fixed`'s values): the model is linear in them, so the solution is exact
/// (diagonal errors, the model's own errors neglected). Returns the values (every counterterm:
/// `fixed`'s with the fitted ones replaced) and the 1σ errors of the fitted ones (0 for the others).
///
/// # Errors
/// [`Error::LengthMismatch`] unless every data vector has one value per k; [`Error::InvalidChoice`]
/// for no free counterterm, a non-positive σ, fewer points than parameters + 1, or templates
/// degenerate on the data; as [`Eft2Terms::multipoles`] for a bad ℓ or f.
pub fn fit_counterterms(
    terms: &Eft2Terms,
    f: f64,
    data: &[MeasuredMultipole],
    free: &[RsdCounterterm],
    fixed: &RsdCounterterms,
    k_max: f64,
) -> Result<(RsdCounterterms, RsdCounterterms)> {
    let bad = |reason: String| Error::InvalidChoice {
        what: "eft2 counterterm fit".into(),
        reason,
    };
    if free.is_empty() {
        return Err(bad("no free counterterm".into()));
    }
    for d in data {
        for (what, v) in [("k and the data", &d.values), ("k and sigma", &d.sigma)] {
            if v.len() != terms.k.len() {
                return Err(Error::LengthMismatch {
                    what,
                    left: terms.k.len(),
                    right: v.len(),
                });
            }
        }
        if d.sigma.iter().any(|&s| s.is_nan() || s <= 0.0) {
            return Err(bad(format!("every sigma of P{} must be positive", d.ell)));
        }
    }
    let ells: Vec<usize> = data.iter().map(|d| d.ell).collect();
    let model = terms.multipoles(f, &ells, fixed)?;
    let index = |c: &RsdCounterterm| RsdCounterterm::ALL.iter().position(|x| x == c).unwrap_or(0);
    let n = free.len();
    let (mut normal, mut rhs) = (vec![vec![0.0; n]; n], vec![0.0; n]);
    let mut points = 0;
    for (l, d) in data.iter().enumerate() {
        for (i, &k) in terms.k.iter().enumerate() {
            if k > k_max {
                continue;
            }
            points += 1;
            let w = 1.0 / (d.sigma[i] * d.sigma[i]);
            let r = d.values[i] - model.total[l][i].value;
            for (p, cp) in free.iter().enumerate() {
                let tp = model.templates[index(cp)][l][i];
                rhs[p] += w * tp * r;
                for (q, cq) in free.iter().enumerate() {
                    normal[p][q] += w * tp * model.templates[index(cq)][l][i];
                }
            }
        }
    }
    if points <= n {
        return Err(bad(format!(
            "{points} data points with k <= {k_max} for {n} counterterms: need more"
        )));
    }
    let (solution, inverse, _) = crate::linalg::solve_spd(&normal, &rhs)?;
    let (mut values, mut errors) = (*fixed, RsdCounterterms::default());
    for (p, c) in free.iter().enumerate() {
        values.values[index(c)] += solution[p];
        errors.values[index(c)] = inverse[p][p].sqrt();
    }
    Ok((values, errors))
}
