//! The one-loop matter bispectrum of a new linear spectrum as contractions of precomputed tensors
//! (issue 50, part 3, real space): built once per triangle set and rule, cached, evaluated in
//! about a millisecond per set.
//!
//! Every loop term of [`super::one_loop`] is trilinear in the linear spectrum P. With P ≈ P̂ =
//! Σ_a c_a φ_a on the CAMB basis of the power-spectrum loops ([`LinearBasis`], [`BASIS_SIZE`]
//! functions on a lattice in ln q, interpolated as the loop plans interpolate), and P̂ used for
//! every spectrum inside a loop term (inside the integrals and at the sides):
//!
//! ```text
//! B₂₂₂   = Σ_{a≤b≤c} T_abc c_a c_b c_c,
//! B₃₂₁ᴵ  = Σ_{a≠b} P̂(k_a) Σ_{c≤d} M⁽ᵃᵇ⁾_cd c_c c_d,
//! B₃₂₁ᴵᴵ = Σ_{a≠b} 6 F₂(k_a, k_b) P̂(k_a) P̂(k_b) J_a·c,
//! B₄₁₁   = Σ_a P̂(k_b) P̂(k_c) L_a·c            (b, c the other two sides),
//! ```
//!
//! with T, M, J, L the integrals of the direct path with each spectrum replaced by a basis function,
//! on the same nodes (radial × angular, pieces of the partition of unity). A node's radius is the
//! distance to its piece's centre, the argument of one of the spectra of the integrand, so the
//! tensors are made radial node by radial node: the angular sum of the other two functions'
//! outer products, times the basis at the radius (n² per angular node instead of n³).
//!
//! The result therefore equals the direct result for P̂ (to round-off and to the lattice
//! interpolation, ≲ 1e-8): what differs from direct for P is the response to the projection
//! residual P − P̂. The error of each term is its quadrature error (the contraction of fine − coarse
//! tensors, as the direct path's fine − coarse difference) plus [`PROJECTION_FACTOR`] × ε × Σ|T|,
//! ε the smoothed projection residual ([`Projection::residual`]) and Σ|T| the sum of the four loop
//! terms' sizes (each term alone is infrared sensitive: its response to the residual scales with the
//! largest of them, not with itself). The tree level and the counterterm
//! shapes use P itself (exact). A spectrum whose residual exceeds [`MAX_RESIDUAL`] is evaluated
//! directly ([`OneLoopMatterPlan::evaluate`] says so).

use super::one_loop::{
    angular_nodes, breaks, f_n, one_loop_matter, partition, radial_nodes, tree_and_counterterms,
    triangle_vectors, OneLoopMatter, OneLoopRule, Vec3, PARTITION_POWER,
};
use crate::error::Result;
use crate::estimate::Estimate;
use crate::linear::LinearSpectrum;
use crate::loops::basis::{after_key, cache_file_name, training, LinearBasis, Projection};
use crate::loops::basis::{
    leading, pack_pairs, pack_triples, pair_products, triple_products, triples,
};
use crate::loops::basis::{BASIS_SIZE, MAX_RESIDUAL};
use crate::loops::lattice::Lattice;
use crate::simd::{axpy, dot};
use crate::vec3::{add, neg, norm, sub};
use rayon::prelude::*;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::Arc;

/// Version of the tensor layout and rules, part of the cache file name.
const VERSION: u32 = 2;

/// The projection error of each loop term is this × ε × Σ|T| (ε: the smoothed residual; Σ|T| the
/// sum of the four loop terms' sizes). Each term is cubic in P̂, so a uniform relative residual ε
/// moves it by 3ε; the residual is not uniform and the terms are infrared sensitive (each grows like
/// k²σ_v² P P where their sum does not), so the factor is measured: on seven CAMB tables not in the
/// training set at the 22 triangles of the Monte Carlo table, basis against direct, a term moved by
/// at most 2.0 ε Σ|T| and the one-loop B by 4.5 ε Σ|T| (2.4e-4 of itself)
/// (`tests/tests/suite/bispectrum_one_loop.rs`).
pub const PROJECTION_FACTOR: f64 = 3.0;

/// The ordered pairs (a, b) of B₃₂₁ᴵ (a outside the loop, b in it), in the order of the tensors.
const PAIRS: [(usize, usize); 6] = [(1, 0), (2, 0), (0, 1), (2, 1), (0, 2), (1, 2)];

/// The lattice of the basis for `rule` and sides up to `k_max`: every radius the integrands see
/// (|q| up to q_max + 2 k_max), from q_min/10 (radii below q_min come with partition weights
/// ≤ 1e-6: the lattice is zero below its start, the direct path extrapolates).
pub(super) fn lattice(rule: &OneLoopRule, k_max: f64) -> Lattice {
    Lattice::new(0.1 * rule.q_min, rule.q_max + 2.0 * k_max, 0.01)
}

pub(super) fn k_max(triangles: &[[f64; 3]]) -> f64 {
    triangles.iter().flatten().copied().fold(0.0, f64::max)
}

/// B₂₂₂'s loop momentum q at the node `v` of piece `piece` (centred on q = 0, −k₁, k₂: the piece's
/// radius is the argument of its spectrum), the other two arguments q + k₁, k₂ − q, and the three radii.
pub(super) fn b222_node(piece: usize, v: Vec3, k1: Vec3, k2: Vec3) -> (Vec3, Vec3, Vec3, [f64; 3]) {
    let q = match piece {
        0 => v,
        1 => sub(v, k1),
        _ => sub(k2, v),
    };
    let (a, b) = (add(q, k1), sub(k2, q));
    (q, a, b, [norm(q), norm(a), norm(b)])
}

/// The number of index pairs a ≤ b of n functions.
fn pairs(n: usize) -> usize {
    n * (n + 1) / 2
}

/// Values per triangle: φ at the sides (3n), then fine and fine − coarse tensors (T, M, L, J).
fn per_triangle(n: usize) -> usize {
    3 * n + 2 * tensor_len(n)
}

fn tensor_len(n: usize) -> usize {
    triples(n) + 6 * pairs(n) + 6 * n
}

/// The one-loop matter bispectrum tensors of a triangle set for one rule (cosmology independent).
#[derive(Debug, Clone, PartialEq)]
pub struct OneLoopMatterBasis {
    triangles: Vec<[f64; 3]>,
    rule: OneLoopRule,
    key: Vec<f64>,
    basis: LinearBasis,
    /// Per triangle, [`per_triangle`] values.
    tensors: Vec<f64>,
}

/// The settings that make the tensors (their cache key).
fn key(triangles: &[[f64; 3]], rule: &OneLoopRule) -> Vec<f64> {
    let mut key = key_head(VERSION, triangles, rule);
    key.extend(triangles.iter().flatten());
    key
}

/// The head of a one-loop bispectrum tensors' cache key (matter's and galaxies'): the layout `version`,
/// the basis, the partition and the rule, and the number of triangles.
pub(super) fn key_head(version: u32, triangles: &[[f64; 3]], rule: &OneLoopRule) -> Vec<f64> {
    vec![
        f64::from(version),
        BASIS_SIZE as f64,
        f64::from(training::VERSION),
        f64::from(PARTITION_POWER),
        rule.radial as f64,
        rule.mu as f64,
        rule.phi as f64,
        rule.q_min,
        rule.q_max,
        triangles.len() as f64,
    ]
}

impl OneLoopMatterBasis {
    /// The cache file name of the tensors of `triangles` and `rule`.
    pub fn file_name(triangles: &[[f64; 3]], rule: &OneLoopRule) -> String {
        cache_file_name("bispectrum-one-loop-basis", VERSION, &key(triangles, rule))
    }

    /// Builds the tensors of the triangles (sides [h/Mpc]) for `rule`, in parallel over triangles;
    /// `progress(done, total)` counts the triangles.
    ///
    /// # Errors
    /// As [`triangle_vectors`] for sides that do not close; a bad rule.
    pub fn build(
        triangles: &[[f64; 3]],
        rule: &OneLoopRule,
        progress: &(dyn Fn(usize, usize) + Sync),
    ) -> Result<Self> {
        rule.validate()?;
        let vectors = triangles
            .iter()
            .map(|&k| triangle_vectors(k))
            .collect::<Result<Vec<_>>>()?;
        let basis = training::camb_basis(lattice(rule, k_max(triangles)), BASIS_SIZE);
        let done = AtomicUsize::new(0);
        let per: Vec<Vec<f64>> = vectors
            .par_iter()
            .map(|kv| {
                let t = triangle_tensors(&basis, kv, rule);
                progress(done.fetch_add(1, Ordering::Relaxed) + 1, triangles.len());
                t
            })
            .collect();
        Ok(Self {
            triangles: triangles.to_vec(),
            rule: *rule,
            key: key(triangles, rule),
            basis,
            tensors: per.concat(),
        })
    }

    /// The triangles [h/Mpc].
    pub fn triangles(&self) -> &[[f64; 3]] {
        &self.triangles
    }

    /// The rule of the integrals.
    pub fn rule(&self) -> &OneLoopRule {
        &self.rule
    }

    /// The basis functions.
    pub fn functions(&self) -> usize {
        self.basis.len()
    }

    /// The projection of `p` on the basis (its residual decides whether the basis is used).
    pub fn project(&self, p: &LinearSpectrum) -> Projection {
        self.basis.project(&self.basis.sample(p))
    }

    /// The basis functions' samples (the CAMB basis on the tensors' lattice).
    pub fn linear_basis(&self) -> &LinearBasis {
        &self.basis
    }

    /// The projection of `p` on the basis's first `n` functions ([`LinearBasis::project_first`]):
    /// [`evaluate`](Self::evaluate) with it gives the terms of the basis of `n` functions (the
    /// tensors' entries with every index < n), their errors with that projection's residual.
    pub fn project_first(&self, p: &LinearSpectrum, n: usize) -> Projection {
        self.basis.project_first(&self.basis.sample(p), n)
    }

    /// The terms of every triangle for the spectrum `p` whose projection is `projection`.
    ///
    /// The contraction stops at the last non-zero coefficient: with a projection on the first n functions
    /// ([`project_first`](Self::project_first)) it reads only the entries with every index < n (the
    /// packed triples and pairs of those come first), n(n+1)(n+2)/6 of B₂₂₂'s.
    pub fn evaluate(&self, p: &LinearSpectrum, projection: &Projection) -> Vec<OneLoopMatter> {
        let n = self.basis.len();
        let c = leading(&projection.coefficients);
        let m = c.len();
        // The products on the packed pairs and triples of the power-spectrum tensors' layout.
        let (c2, c3) = (pair_products(c), triple_products(c));
        let eps = PROJECTION_FACTOR * projection.residual;
        self.triangles
            .iter()
            .zip(self.tensors.chunks_exact(per_triangle(n)))
            .map(|(&k, t)| {
                let kv = triangle_vectors(k).expect("checked at build");
                let (sides, rest) = t.split_at(3 * n);
                let ph: [f64; 3] = std::array::from_fn(|i| dot(&sides[i * n..i * n + m], c));
                let (fine, diff) = rest.split_at(tensor_len(n));
                let fine = contract(fine, n, &kv, &ph, c, &c2, &c3);
                let diff = contract(diff, n, &kv, &ph, c, &c2, &c3);
                let projection = eps * fine.iter().map(|t| t.abs()).sum::<f64>();
                let est = |i: usize| Estimate::new(fine[i], diff[i].abs() + projection);
                let pk = k.map(|v| p.eval(v));
                let (tree, counterterm_shapes) = tree_and_counterterms(&kv, &pk);
                OneLoopMatter {
                    k,
                    tree: Estimate::exact(tree),
                    b222: est(0),
                    b321_i: est(1),
                    b321_ii: est(2),
                    b411: est(3),
                    counterterm_shapes,
                }
            })
            .collect()
    }

    /// The cache file's values: the key, the basis, the tensors.
    pub(crate) fn to_f64s(&self) -> Vec<f64> {
        let mut v = vec![self.key.len() as f64];
        v.extend(&self.key);
        v.extend(self.basis.to_f64s());
        v.extend(&self.tensors);
        v
    }

    /// The tensors of `triangles` and `rule` from the values of their file, or `None` if the file
    /// was made for other settings or does not fit them.
    pub(crate) fn from_f64s(
        values: &[f64],
        triangles: &[[f64; 3]],
        rule: &OneLoopRule,
    ) -> Option<Self> {
        let expected = key(triangles, rule);
        let rest = after_key(values, &expected)?;
        let (basis, rest) = LinearBasis::from_f64s(lattice(rule, k_max(triangles)), rest)?;
        if rest.len() != triangles.len() * per_triangle(basis.len()) {
            return None;
        }
        Some(Self {
            triangles: triangles.to_vec(),
            rule: *rule,
            key: expected,
            tensors: rest.to_vec(),
            basis,
        })
    }
}

/// [B₂₂₂, B₃₂₁ᴵ, B₃₂₁ᴵᴵ, B₄₁₁] of one triangle's tensors `t` (fine, or fine − coarse) on `n` functions,
/// with P̂ at the sides `ph`, the first m ≤ n coefficients `c`, their pair and triple products (the
/// entries with every index < m: the first of the packed pairs and triples).
fn contract(
    t: &[f64],
    n: usize,
    kv: &[Vec3; 3],
    ph: &[f64; 3],
    c: &[f64],
    c2: &[f64],
    c3: &[f64],
) -> [f64; 4] {
    let m = c.len();
    let (t222, rest) = t.split_at(triples(n));
    let (m321, rest) = rest.split_at(6 * pairs(n));
    let (l, j) = rest.split_at(3 * n);
    let b222 = dot(&t222[..c3.len()], c3);
    let b321_i = PAIRS
        .iter()
        .zip(m321.chunks_exact(pairs(n)))
        .map(|(&(a, _), block)| ph[a] * dot(&block[..c2.len()], c2))
        .sum();
    let mut b321_ii = 0.0;
    let mut b411 = 0.0;
    for a in 0..3 {
        let (b, cc) = ((a + 1) % 3, (a + 2) % 3);
        let ja = dot(&j[a * n..a * n + m], c);
        for other in [b, cc] {
            b321_ii += 6.0 * f_n(&[kv[a], kv[other]]) * ph[a] * ph[other] * ja;
        }
        b411 += ph[b] * ph[cc] * dot(&l[a * n..a * n + m], c);
    }
    [b222, b321_i, b321_ii, b411]
}

/// One triangle's values: φ at the sides, the fine tensors, fine − coarse.
fn triangle_tensors(basis: &LinearBasis, kv: &[Vec3; 3], rule: &OneLoopRule) -> Vec<f64> {
    let n = basis.len();
    let mut out = Vec::with_capacity(per_triangle(n));
    let mut phi = vec![0.0; n];
    for v in kv {
        basis.at_ln(norm(*v).ln(), &mut phi);
        out.extend(&phi);
    }
    let fine = rule_tensors(basis, kv, rule);
    let coarse = rule_tensors(basis, kv, &rule.half());
    out.extend(&fine);
    out.extend(fine.iter().zip(&coarse).map(|(f, c)| f - c));
    out
}

/// The tensors (T packed, M packed, L, J) of one triangle on one rule.
fn rule_tensors(basis: &LinearBasis, kv: &[Vec3; 3], rule: &OneLoopRule) -> Vec<f64> {
    let n = basis.len();
    let k = kv.map(norm);
    let radial = radial_nodes(rule, &breaks(&k));
    let angular = angular_nodes(rule, true);
    let (k1, k2) = (kv[0], kv[1]);
    let mut t222 = vec![0.0; n * n * n];
    let mut m321 = vec![0.0; 6 * n * n];
    let (mut l411, mut j) = (vec![0.0; 3 * n], vec![0.0; 3 * n]);
    let (mut phi_p, mut phx, mut phy) = (vec![0.0; n], vec![0.0; n], vec![0.0; n]);
    let mut m = vec![0.0; n * n];
    let mut u = vec![0.0; 6 * n];
    for &(p, wp) in &radial {
        basis.at_ln(p.ln(), &mut phi_p);
        // B₂₂₂: piece j about q = 0, −k₁, k₂; the piece's radius p is the j-th spectrum's argument.
        for piece in 0..3 {
            m.iter_mut().for_each(|x| *x = 0.0);
            let (x, y) = [(1, 2), (0, 2), (0, 1)][piece];
            for &(unit, wu) in &angular {
                let (q, a, b, r) = b222_node(piece, unit.map(|c| c * p), k1, k2);
                let kern = f_n(&[neg(q), a]) * f_n(&[neg(a), neg(b)]) * f_n(&[b, q]);
                let s = 8.0 * wu * partition(&r, piece) * kern;
                if s == 0.0 {
                    continue;
                }
                basis.at_ln(r[x].ln(), &mut phx);
                basis.at_ln(r[y].ln(), &mut phy);
                for (row, &xa) in m.chunks_exact_mut(n).zip(&phx) {
                    axpy(row, s * xa, &phy);
                }
            }
            for (slab, &pa) in t222.chunks_exact_mut(n * n).zip(&phi_p) {
                axpy(slab, wp * pa, &m);
            }
        }
        // B₃₂₁ᴵ (twice the piece about q = 0), B₄₁₁ and J, whose radius is |q|.
        u.iter_mut().for_each(|x| *x = 0.0);
        let (mut s411, mut sj) = ([0.0; 3], [0.0; 3]);
        for &(unit, wu) in &angular {
            let v = unit.map(|c| c * p);
            for (slot, &(a, b)) in PAIRS.iter().enumerate() {
                let d = sub(kv[b], v);
                let r = [p, norm(d)];
                let leg = 12.0 * wu * partition(&r, 0) * f_n(&[v, d]);
                let s = leg * f_n(&[neg(v), neg(d), neg(kv[a])]);
                basis.at_ln(r[1].ln(), &mut phx);
                axpy(&mut u[slot * n..(slot + 1) * n], s, &phx);
            }
            for a in 0..3 {
                let (b, c) = ((a + 1) % 3, (a + 2) % 3);
                s411[a] += wu * 12.0 * f_n(&[v, neg(v), neg(kv[b]), neg(kv[c])]);
                sj[a] += wu * f_n(&[kv[a], v, neg(v)]);
            }
        }
        for (slot, us) in u.chunks_exact(n).enumerate() {
            let block = &mut m321[slot * n * n..(slot + 1) * n * n];
            for (row, &pc) in block.chunks_exact_mut(n).zip(&phi_p) {
                axpy(row, wp * pc, us);
            }
        }
        for a in 0..3 {
            axpy(&mut l411[a * n..(a + 1) * n], wp * s411[a], &phi_p);
            axpy(&mut j[a * n..(a + 1) * n], wp * sj[a], &phi_p);
        }
    }
    let mut out = Vec::with_capacity(tensor_len(n));
    out.extend(pack_triples(&t222, n));
    for block in m321.chunks_exact(n * n) {
        out.extend(pack_pairs(block, n));
    }
    out.extend(&l411);
    out.extend(&j);
    out
}

/// How the loop terms of an evaluation were computed.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum BispectrumLoopSource {
    /// Directly (no basis given to the plan).
    Direct,
    /// Directly, since no tensors were cached for the triangles and rule and the method `auto`
    /// does not build them.
    DirectUncached,
    /// From the basis tensors: `functions` basis functions, projection residual ε.
    Basis {
        /// Basis functions.
        functions: usize,
        /// The smoothed projection residual.
        residual: f64,
    },
    /// Directly, since the spectrum's projection residual exceeded the basis's limit.
    Fallback {
        /// The projection residual.
        residual: f64,
        /// The largest residual the basis accepts.
        max_residual: f64,
    },
}

impl BispectrumLoopSource {
    /// The method in a word or two, for Python's `meta["methods"]` (the header line has the figures).
    pub fn method(&self) -> &'static str {
        match self {
            Self::Direct => "direct",
            Self::DirectUncached => crate::output::FALLBACK_UNCACHED,
            Self::Basis { .. } => "basis",
            Self::Fallback { .. } => crate::output::FALLBACK_RESIDUAL,
        }
    }

    /// One line for table headers.
    pub fn describe(&self) -> String {
        match *self {
            Self::Direct => "loop terms: direct integration".into(),
            Self::DirectUncached => "loop terms: direct integration (method auto: no basis tensors cached for \
                 these triangles and rule; method basis builds them once, ~0.7 s per triangle and core, then \
                 ~10 us per triangle)"
                .into(),
            Self::Basis {
                functions,
                residual,
            } => format!(
                "loop terms: basis tensors on {functions} functions, the same nodes as direct; projection \
                 residual {residual:.1e}; err_ includes {PROJECTION_FACTOR} x residual x (sum of |loop terms|)"
            ),
            Self::Fallback {
                residual,
                max_residual,
            } => format!(
                "loop terms: direct integration, since the spectrum's projection residual on the basis, \
                 {residual:.1e}, exceeds {max_residual:.1e}"
            ),
        }
    }
}

/// The one-loop matter bispectrum of a triangle set: directly, or from basis tensors.
#[derive(Debug, Clone)]
pub struct OneLoopMatterPlan {
    triangles: Vec<[f64; 3]>,
    rule: OneLoopRule,
    basis: Option<Arc<OneLoopMatterBasis>>,
    max_residual: f64,
}

impl OneLoopMatterPlan {
    /// The direct plan of `triangles` (sides [h/Mpc]) and `rule`.
    ///
    /// # Errors
    /// As [`triangle_vectors`] for sides that do not close, naming the triangle; a bad rule.
    pub fn new(triangles: Vec<[f64; 3]>, rule: OneLoopRule) -> Result<Self> {
        rule.validate()?;
        for (i, &k) in triangles.iter().enumerate() {
            triangle_vectors(k).map_err(|e| crate::error::Error::InvalidChoice {
                what: format!("triangle {} ({}, {}, {})", i + 1, k[0], k[1], k[2]),
                reason: e.to_string(),
            })?;
        }
        Ok(Self {
            triangles,
            rule,
            basis: None,
            max_residual: MAX_RESIDUAL,
        })
    }

    /// The plan evaluated on `basis`, which must be made for the same triangles and rule (compared
    /// by value).
    ///
    /// # Errors
    /// [`crate::error::Error::InvalidChoice`] for tensors of other triangles or another rule.
    pub fn with_basis(mut self, basis: Arc<OneLoopMatterBasis>) -> Result<Self> {
        if basis.triangles != self.triangles || basis.rule != self.rule {
            return Err(crate::error::Error::InvalidChoice {
                what: "one-loop bispectrum basis tensors".into(),
                reason: "they were made for other triangles or another rule than the plan's".into(),
            });
        }
        self.basis = Some(basis);
        Ok(self)
    }

    /// The same plan with another largest projection residual for the basis.
    pub fn with_max_residual(mut self, max_residual: f64) -> Self {
        self.max_residual = max_residual;
        self
    }

    /// The triangles [h/Mpc].
    pub fn triangles(&self) -> &[[f64; 3]] {
        &self.triangles
    }

    /// Whether the plan holds basis tensors (else every spectrum is integrated directly).
    pub fn has_basis(&self) -> bool {
        self.basis.is_some()
    }

    /// The terms of every triangle for the linear spectrum `p`, and how they were computed.
    ///
    /// # Errors
    /// None for a plan made by [`Self::new`] (its triangles and rule are checked there).
    pub fn evaluate(
        &self,
        p: &LinearSpectrum,
    ) -> Result<(Vec<OneLoopMatter>, BispectrumLoopSource)> {
        self.evaluate_reporting(p, &|_, _| {})
    }

    /// [`evaluate`](Self::evaluate), reporting `progress(done, total)` per triangle when the
    /// integrals are direct (seconds per triangle).
    ///
    /// # Errors
    /// As [`evaluate`](Self::evaluate).
    pub fn evaluate_reporting(
        &self,
        p: &LinearSpectrum,
        progress: &dyn Fn(usize, usize),
    ) -> Result<(Vec<OneLoopMatter>, BispectrumLoopSource)> {
        let direct = || -> Result<Vec<OneLoopMatter>> {
            let n = self.triangles.len();
            let mut out = Vec::with_capacity(n);
            for (i, &k) in self.triangles.iter().enumerate() {
                out.push(one_loop_matter(p, k, &self.rule)?);
                progress(i + 1, n);
            }
            Ok(out)
        };
        let Some(basis) = &self.basis else {
            return Ok((direct()?, BispectrumLoopSource::Direct));
        };
        let projection = basis.project(p);
        if projection.residual.is_nan() || projection.residual > self.max_residual {
            let source = BispectrumLoopSource::Fallback {
                residual: projection.residual,
                max_residual: self.max_residual,
            };
            return Ok((direct()?, source));
        }
        let source = BispectrumLoopSource::Basis {
            functions: basis.functions(),
            residual: projection.residual,
        };
        Ok((basis.evaluate(p, &projection), source))
    }
}
