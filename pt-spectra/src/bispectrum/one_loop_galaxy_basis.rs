//! The one-loop galaxy bispectrum per bias monomial of a new linear spectrum as contractions of precomputed
//! tensors, real space (issue 50): [`super::one_loop_basis`]'s construction with one tensor per monomial of
//! each integral, giving [`super::one_loop_galaxy_poly`]'s polynomials for a new spectrum, which a new bias
//! then evaluates in microseconds.
//!
//! With P ≈ P̂ = Σ_a c_a φ_a on the CAMB basis ([`BASIS_SIZE`] functions) for every spectrum inside a loop
//! term (the integrals and the factors at the sides; the tree level uses P), each loop integral of the
//! polynomial path becomes, per monomial of its kernels' parts:
//!
//! ```text
//! B₂₂₂:  T⁽ᵐ⁾_abc c_a c_b c_c           per monomial m of Z₂Z₂Z₂ (10),
//! B₃₂₁ᴵ: M⁽ᵃᵇ,ᵐ⁾_cd c_c c_d             per ordered pair of sides and pair m of parts of Z₃ ⊗ Z₂ (18),
//! B₄₁₁:  L⁽ᵃ,ᵖ⁾·c,  J: J⁽ᵃ,ᵖ⁾·c          per side and part p of Z₄ (11) or Z₃ (7),
//! σ²:    s·c                             (the UV subtraction's ∫P on the triangle's rule),
//! ```
//!
//! on the same nodes as the direct path, made radial node by radial node as the matter tensors are; the UV
//! constants per part do not depend on P and are stored. So the polynomial from the tensors equals the
//! direct polynomial for P̂ (to round-off and the lattice interpolation); for P the difference is the
//! response to the projection residual ε, which the loop terms' errors include as the matter terms' do:
//! [`PROJECTION_FACTOR`] × ε × Σ|loop terms| at the bias evaluated ([`GalaxyLoopPolynomial::projection`]). Per triangle and rule (fine and fine − coarse) the tensors
//! hold 2 × (10 × 8436 + 6 × 18 × 666 + 3 × (11 + 7) × 36 + 36) ≈ 3.2e5 values for 36 functions (2.6 MB;
//! 157 MB for the 62 Nseries triangles) against the matter's 2.5e4; cached by [`crate::store::TableStore`] as
//! the matter tensors are (the key includes the kernels' values at fixed arguments).

use super::bias_kernels::{loop_kernel_parts, N_PARTS};
use super::one_loop::{
    angular_nodes, breaks, partition, radial_nodes, triangle_vectors, OneLoopRule, Vec3,
};
use super::one_loop_basis::{self, b222_node, PROJECTION_FACTOR};
use super::one_loop_galaxy::{uv_parts, UvParts};
use super::one_loop_galaxy_poly::{assemble, GalaxyLoopPolynomial, Layout, LoopSums};
use crate::error::Result;
use crate::linear::LinearSpectrum;
use crate::loops::basis::{after_key, cache_file_name, Projection, BASIS_SIZE};
use crate::loops::basis::{leading, pack_pairs, pack_triples, pair_products, training};
use crate::loops::basis::{triple_products, triples, LinearBasis};
use crate::loops::lattice::Lattice;
use crate::simd::{axpy, dot};
use crate::vec3::{neg, norm, sub};
use rayon::prelude::*;
use std::sync::atomic::{AtomicUsize, Ordering};

/// The monomials of a product of kernel parts from the supports `sets` (sorted index tuples), and for each
/// ordered choice of parts (indices into the supports) its monomial's slot.
pub(super) fn slots(sets: &[&[usize]]) -> (Vec<Vec<usize>>, Vec<usize>) {
    let mut list: Vec<Vec<usize>> = Vec::new();
    let mut slot = Vec::new();
    let mut choice = vec![0; sets.len()];
    loop {
        let mut m: Vec<usize> = choice.iter().zip(sets).map(|(&i, s)| s[i]).collect();
        m.sort_unstable();
        let at = list.iter().position(|x| *x == m).unwrap_or_else(|| {
            list.push(m);
            list.len() - 1
        });
        slot.push(at);
        // the next choice, last index fastest
        let mut d = sets.len();
        loop {
            if d == 0 {
                return (list, slot);
            }
            d -= 1;
            choice[d] += 1;
            if choice[d] < sets[d].len() {
                break;
            }
            choice[d] = 0;
        }
    }
}

/// The tensor layout of one triangle on one rule: B₂₂₂'s packed triples per monomial, B₃₂₁ᴵ's packed pairs per
/// ordered pair of sides and pair of parts, L and J per side and part, σ².
struct Shape {
    n: usize,
    lay: Layout,
    m222: Vec<Vec<usize>>,
    slot222: Vec<usize>,
    m321: Vec<Vec<usize>>,
    slot321: Vec<usize>,
}

impl Shape {
    fn new(n: usize) -> Self {
        let lay = Layout::new(false);
        let (m222, slot222) = slots(&[&lay.s[2], &lay.s[2], &lay.s[2]]);
        let (m321, slot321) = slots(&[&lay.s[3], &lay.s[2]]);
        Self {
            n,
            lay,
            m222,
            slot222,
            m321,
            slot321,
        }
    }

    fn pairs(&self) -> usize {
        self.n * (self.n + 1) / 2
    }

    fn len(&self) -> usize {
        let (s3, s4) = (self.lay.s[3].len(), self.lay.s[4].len());
        self.m222.len() * triples(self.n)
            + 6 * self.m321.len() * self.pairs()
            + 3 * (s4 + s3) * self.n
            + self.n
    }
}

/// The one-loop galaxy bispectrum tensors per bias monomial of a triangle set for one rule, real space
/// (cosmology independent; module docs).
#[derive(Debug, Clone, PartialEq)]
pub struct GalaxyLoopBasis {
    triangles: Vec<[f64; 3]>,
    rule: OneLoopRule,
    basis: LinearBasis,
    /// Per triangle: φ at the sides (3n), the fine tensors, fine − coarse.
    tensors: Vec<Vec<f64>>,
    /// Per triangle: the UV constants per part.
    uv: Vec<UvParts>,
}

impl GalaxyLoopBasis {
    /// Builds the tensors of the triangles (sides [h/Mpc]) for `rule`, in parallel over triangles.
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
        let basis = training::camb_basis(lattice(triangles, rule), BASIS_SIZE);
        let shape = Shape::new(basis.len());
        let done = AtomicUsize::new(0);
        let tensors = vectors
            .par_iter()
            .map(|kv| {
                let t = triangle_tensors(&basis, &shape, kv, rule);
                progress(done.fetch_add(1, Ordering::Relaxed) + 1, triangles.len());
                t
            })
            .collect();
        let uv = vectors
            .iter()
            .map(|kv| uv_parts(None, kv, rule, true))
            .collect();
        Ok(Self {
            triangles: triangles.to_vec(),
            rule: *rule,
            basis,
            tensors,
            uv,
        })
    }

    /// The cache file name of the tensors of `triangles` and `rule` (and of the present kernels: their values
    /// at fixed arguments are part of the key, so a change of the kernels makes new tensors).
    pub fn file_name(triangles: &[[f64; 3]], rule: &OneLoopRule) -> String {
        cache_file_name("bispectrum-galaxy-basis", VERSION, &key(triangles, rule))
    }

    /// The cache file's values: the key, the basis, per triangle the tensors and the UV constants.
    pub(crate) fn to_f64s(&self) -> Vec<f64> {
        let key = key(&self.triangles, &self.rule);
        let mut v = vec![key.len() as f64];
        v.extend(&key);
        v.extend(self.basis.to_f64s());
        for (t, (c3, c4)) in self.tensors.iter().zip(&self.uv) {
            v.extend(t);
            v.extend(c3.iter().chain(c4).flatten());
        }
        v
    }

    /// The tensors of `triangles` and `rule` from the values of their file, or `None` if the file was made for
    /// other settings or does not fit them.
    pub(crate) fn from_f64s(
        values: &[f64],
        triangles: &[[f64; 3]],
        rule: &OneLoopRule,
    ) -> Option<Self> {
        let rest = after_key(values, &key(triangles, rule))?;
        let (basis, rest) = LinearBasis::from_f64s(lattice(triangles, rule), rest)?;
        let n = basis.len();
        let per = 3 * n + 2 * Shape::new(n).len();
        let uv_len = 6 * N_PARTS;
        if rest.len() != triangles.len() * (per + uv_len) {
            return None;
        }
        let mut tensors = Vec::with_capacity(triangles.len());
        let mut uv = Vec::with_capacity(triangles.len());
        for chunk in rest.chunks_exact(per + uv_len) {
            let (t, c) = chunk.split_at(per);
            tensors.push(t.to_vec());
            let part = |i: usize| -> [f64; N_PARTS] { std::array::from_fn(|p| c[i * N_PARTS + p]) };
            uv.push((
                std::array::from_fn(&part),
                std::array::from_fn(|a| part(3 + a)),
            ));
        }
        Some(Self {
            triangles: triangles.to_vec(),
            rule: *rule,
            basis,
            tensors,
            uv,
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

    /// The number of stored values (all triangles).
    pub fn values(&self) -> usize {
        self.tensors.iter().map(Vec::len).sum()
    }

    /// P̂, the projection of `p` on the basis, as a spectrum on the basis's lattice (what the tensors integrate
    /// in place of P: the direct polynomials of it equal the tensors' up to the two interpolations).
    ///
    /// # Errors
    /// As [`LinearSpectrum::from_nodes`] (a projection that is not positive on the lattice).
    pub fn projected_spectrum(&self, p: &LinearSpectrum) -> Result<LinearSpectrum> {
        let projection = self.project(p);
        let l = lattice(&self.triangles, &self.rule);
        LinearSpectrum::from_nodes(
            (0..l.len).map(|j| l.x(j).exp()).collect(),
            projection.samples,
        )
    }

    /// The projection of `p` on the basis.
    pub fn project(&self, p: &LinearSpectrum) -> Projection {
        self.basis.project(&self.basis.sample(p))
    }

    /// The polynomials of every triangle for the spectrum `p` (P at the sides of the tree level, P̂ elsewhere),
    /// with [`GalaxyLoopPolynomial::projection`] = [`PROJECTION_FACTOR`] × the projection residual (the matter
    /// terms' bound on the response to it, relative to the sum of the loop terms' sizes).
    pub fn evaluate(&self, p: &LinearSpectrum) -> Vec<GalaxyLoopPolynomial> {
        self.evaluate_projected(p, &self.project(p))
    }

    /// The basis functions' samples (the CAMB basis on the tensors' lattice).
    pub fn linear_basis(&self) -> &LinearBasis {
        &self.basis
    }

    /// The projection of `p` on the basis's first `n` functions ([`LinearBasis::project_first`]):
    /// [`evaluate_projected`](Self::evaluate_projected) with it gives the polynomials of the basis of `n`
    /// functions (the tensors' entries with every index < n).
    pub fn project_first(&self, p: &LinearSpectrum, n: usize) -> Projection {
        self.basis.project_first(&self.basis.sample(p), n)
    }

    /// [`evaluate`](Self::evaluate) with the coefficients and residual of `projection` (of `p`, on this basis:
    /// [`project`](Self::project) or [`project_first`](Self::project_first)).
    pub fn evaluate_projected(
        &self,
        p: &LinearSpectrum,
        projection: &Projection,
    ) -> Vec<GalaxyLoopPolynomial> {
        let n = self.basis.len();
        let c = leading(&projection.coefficients);
        let m = c.len();
        let shape = Shape::new(n);
        let (c2, c3) = (pair_products(c), triple_products(c));
        self.triangles
            .iter()
            .zip(self.tensors.iter().zip(&self.uv))
            .map(|(&k, (t, uv))| {
                let (sides, rest) = t.split_at(3 * n);
                let ph: [f64; 3] = std::array::from_fn(|i| dot(&sides[i * n..i * n + m], c));
                let (fine, diff) = rest.split_at(shape.len());
                let (f, sf) = contract(&shape, fine, c, &c2, &c3);
                let (d, sd) = contract(&shape, diff, c, &c2, &c3);
                let sums = LoopSums {
                    coarse: f.iter().zip(&d).map(|(f, d)| f - d).collect(),
                    fine: f,
                    sigma2: [sf, sf - sd],
                };
                let pk = k.map(|v| p.eval(v));
                GalaxyLoopPolynomial {
                    projection: PROJECTION_FACTOR * projection.residual,
                    ..assemble(k, None, None, &shape.lay, &pk, &ph, &sums, uv)
                }
            })
            .collect()
    }
}

/// Version of the tensor layout, part of the cache file name.
const VERSION: u32 = 1;

/// The lattice of the basis (the matter tensors').
fn lattice(triangles: &[[f64; 3]], rule: &OneLoopRule) -> Lattice {
    one_loop_basis::lattice(rule, one_loop_basis::k_max(triangles))
}

/// The settings that make the tensors (their cache key): the head of the matter tensors' key with this
/// layout's version, the kernels' parts at fixed arguments of orders 2, 3 and 4 (the kernels'
/// fingerprint), the triangles.
pub(super) fn key(triangles: &[[f64; 3]], rule: &OneLoopRule) -> Vec<f64> {
    let mut key = one_loop_basis::key_head(VERSION, triangles, rule);
    let q = [
        [0.31, -0.12, 0.57],
        [-0.22, 0.41, 0.13],
        [0.05, -0.37, -0.29],
        [0.44, 0.18, -0.61],
    ];
    for order in 2..=4 {
        key.extend(loop_kernel_parts(None, &q[..order]));
    }
    key.extend(triangles.iter().flatten());
    key
}

/// One rule's tensors contracted with the first m ≤ n coefficients `c` (pair and triple products `c2`, `c3`;
/// the entries with every index < m, the first of the packed pairs and triples): the loop sums in the layout
/// of [`Layout`] (each monomial's value at one ordered choice of its parts), and σ².
fn contract(shape: &Shape, t: &[f64], c: &[f64], c2: &[f64], c3: &[f64]) -> (Vec<f64>, f64) {
    let (n, lay, used) = (shape.n, &shape.lay, c.len());
    let (s2, s3, s4) = (&lay.s[2], &lay.s[3], &lay.s[4]);
    let mut out = vec![0.0; lay.len];
    let (t222, rest) = t.split_at(shape.m222.len() * triples(n));
    for (m, t) in shape.m222.iter().zip(t222.chunks_exact(triples(n))) {
        let at = |p: usize| s2.iter().position(|&x| x == p).expect("a part of Z₂");
        out[(at(m[0]) * s2.len() + at(m[1])) * s2.len() + at(m[2])] = dot(&t[..c3.len()], c3);
    }
    let (t321, rest) = rest.split_at(6 * shape.m321.len() * shape.pairs());
    let mut blocks = t321.chunks_exact(shape.pairs());
    for a in 0..3 {
        for b in (0..3).filter(|&b| b != a) {
            for m in &shape.m321 {
                let v = dot(&blocks.next().expect("the layout's blocks")[..c2.len()], c2);
                // one ordered choice (a part of Z₃, one of Z₂) with this pair of parts
                let (i, j) = s3
                    .iter()
                    .enumerate()
                    .find_map(|(i, &p)| {
                        let q = if p == m[0] { m[1] } else { m[0] };
                        (p == m[0] || p == m[1])
                            .then(|| s2.iter().position(|&x| x == q).map(|j| (i, j)))
                            .flatten()
                    })
                    .expect("a pair of parts of Z₃ and Z₂");
                out[lay.i321(a, b, i, j)] = v;
            }
        }
    }
    let (l, rest) = rest.split_at(3 * s4.len() * n);
    for (s, l) in out[lay.o411..lay.oj].iter_mut().zip(l.chunks_exact(n)) {
        *s = dot(&l[..used], c);
    }
    let (j, sigma) = rest.split_at(3 * s3.len() * n);
    for (s, j) in out[lay.oj..].iter_mut().zip(j.chunks_exact(n)) {
        *s = dot(&j[..used], c);
    }
    (out, dot(&sigma[..used], c))
}

/// One triangle's values: φ at the sides, the fine tensors, fine − coarse.
fn triangle_tensors(
    basis: &LinearBasis,
    shape: &Shape,
    kv: &[Vec3; 3],
    rule: &OneLoopRule,
) -> Vec<f64> {
    let n = basis.len();
    let mut out = Vec::with_capacity(3 * n + 2 * shape.len());
    let mut phi = vec![0.0; n];
    for v in kv {
        basis.at_ln(norm(*v).ln(), &mut phi);
        out.extend(&phi);
    }
    let fine = rule_tensors(basis, shape, kv, rule);
    let coarse = rule_tensors(basis, shape, kv, &rule.half());
    out.extend(&fine);
    out.extend(fine.iter().zip(&coarse).map(|(f, c)| f - c));
    out
}

/// The tensors of one triangle on one rule (the layout of [`Shape`]).
fn rule_tensors(
    basis: &LinearBasis,
    shape: &Shape,
    kv: &[Vec3; 3],
    rule: &OneLoopRule,
) -> Vec<f64> {
    let n = basis.len();
    let (s2, s3, s4) = (&shape.lay.s[2], &shape.lay.s[3], &shape.lay.s[4]);
    let (n222, n321) = (shape.m222.len(), shape.m321.len());
    let k = kv.map(norm);
    let radial = radial_nodes(rule, &breaks(&k));
    let angular = angular_nodes(rule, true);
    let angular_sum: f64 = angular.iter().map(|(_, w)| w).sum();
    let z = |q: &[Vec3]| loop_kernel_parts(None, q);
    let (k1, k2) = (kv[0], kv[1]);
    let mut t222 = vec![0.0; n222 * n * n * n];
    let mut m321 = vec![0.0; 9 * n321 * n * n];
    let (mut l411, mut j) = (vec![0.0; 3 * s4.len() * n], vec![0.0; 3 * s3.len() * n]);
    let mut sigma = vec![0.0; n];
    let (mut phi_p, mut phx, mut phy) = (vec![0.0; n], vec![0.0; n], vec![0.0; n]);
    let mut m = vec![0.0; n222 * n * n];
    let mut u = vec![0.0; 9 * n321 * n];
    let mut w222 = vec![0.0; n222];
    for &(p, wp) in &radial {
        basis.at_ln(p.ln(), &mut phi_p);
        axpy(&mut sigma, wp * angular_sum, &phi_p);
        for piece in 0..3 {
            m.iter_mut().for_each(|x| *x = 0.0);
            let (x, y) = [(1, 2), (0, 2), (0, 1)][piece];
            for &(unit, wu) in &angular {
                let (q, a, b, r) = b222_node(piece, unit.map(|c| c * p), k1, k2);
                let s = 8.0 * wu * partition(&r, piece);
                let (za, zb, zc) = (z(&[neg(q), a]), z(&[neg(a), neg(b)]), z(&[b, q]));
                w222.iter_mut().for_each(|x| *x = 0.0);
                let mut slot = shape.slot222.iter();
                for &pa in s2 {
                    for &pb in s2 {
                        for &pc in s2 {
                            w222[*slot.next().expect("27 slots")] += za[pa] * zb[pb] * zc[pc];
                        }
                    }
                }
                basis.at_ln(r[x].ln(), &mut phx);
                basis.at_ln(r[y].ln(), &mut phy);
                for (mm, &wm) in m.chunks_exact_mut(n * n).zip(&w222) {
                    if wm != 0.0 {
                        for (row, &xa) in mm.chunks_exact_mut(n).zip(&phx) {
                            axpy(row, s * wm * xa, &phy);
                        }
                    }
                }
            }
            for (t, mm) in t222.chunks_exact_mut(n * n * n).zip(m.chunks_exact(n * n)) {
                for (slab, &pa) in t.chunks_exact_mut(n * n).zip(&phi_p) {
                    axpy(slab, wp * pa, mm);
                }
            }
        }
        // B₃₂₁ᴵ (twice the piece about q = 0), B₄₁₁ and J, whose radius is |q|.
        u.iter_mut().for_each(|x| *x = 0.0);
        let mut s411 = vec![0.0; 3 * s4.len()];
        let mut sj = vec![0.0; 3 * s3.len()];
        for &(unit, wu) in &angular {
            let v = unit.map(|c| c * p);
            for b in 0..3 {
                let d = sub(kv[b], v);
                let r = [p, norm(d)];
                let leg = 12.0 * wu * partition(&r, 0);
                let y = z(&[v, d]);
                basis.at_ln(r[1].ln(), &mut phx);
                for a in (0..3).filter(|&a| a != b) {
                    let x = z(&[neg(v), neg(d), neg(kv[a])]);
                    let mut slot = shape.slot321.iter();
                    for &pi in s3 {
                        for &pj in s2 {
                            let sl = *slot.next().expect("the slots");
                            let w = leg * x[pi] * y[pj];
                            let at = ((3 * a + b) * n321 + sl) * n;
                            axpy(&mut u[at..at + n], w, &phx);
                        }
                    }
                }
            }
            for a in 0..3 {
                let (b, c) = ((a + 1) % 3, (a + 2) % 3);
                let x = z(&[v, neg(v), neg(kv[b]), neg(kv[c])]);
                for (s, &pi) in s411[a * s4.len()..(a + 1) * s4.len()].iter_mut().zip(s4) {
                    *s += wu * x[pi];
                }
                let x = z(&[kv[a], v, neg(v)]);
                for (s, &pi) in sj[a * s3.len()..(a + 1) * s3.len()].iter_mut().zip(s3) {
                    *s += wu * x[pi];
                }
            }
        }
        for (block, us) in m321.chunks_exact_mut(n * n).zip(u.chunks_exact(n)) {
            for (row, &pc) in block.chunks_exact_mut(n).zip(&phi_p) {
                axpy(row, wp * pc, us);
            }
        }
        for (l, &s) in l411.chunks_exact_mut(n).zip(&s411) {
            axpy(l, wp * s, &phi_p);
        }
        for (l, &s) in j.chunks_exact_mut(n).zip(&sj) {
            axpy(l, wp * s, &phi_p);
        }
    }
    let mut out = Vec::with_capacity(shape.len());
    for t in t222.chunks_exact(n * n * n) {
        out.extend(pack_triples(t, n));
    }
    for (i, block) in m321.chunks_exact(n * n).enumerate() {
        let pair = i / n321;
        if pair / 3 != pair % 3 {
            out.extend(pack_pairs(block, n));
        }
    }
    out.extend(&l411);
    out.extend(&j);
    out.extend(&sigma);
    out
}
