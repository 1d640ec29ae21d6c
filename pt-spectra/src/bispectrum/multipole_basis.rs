//! The one-loop galaxy multipoles B₀, B₂, B₄ in redshift space for a new linear spectrum and growth rate
//! from precomputed tensors (issue 50): [`super::one_loop_galaxy_multipoles`]'s polynomials per bias
//! monomial, in milliseconds for a triangle set instead of half a minute per triangle.
//!
//! **Functions.** The loop terms are cubic in the spectrum, so their tensors grow as m³ in the number of
//! functions m that P̂ = Σ c_a t_a is projected on. The CAMB basis needs its first 24 functions for 1e-3 of
//! B; its 16 leading SVD templates (the eigenvectors of Σ ĉĉᵀ over the unit coefficient vectors of its
//! training tables and cuts, COBRA's construction in the basis's span) give 7.8e-4 (docs/bispectrum.md,
//! "how many basis functions"). So the tensors are built on [`TEMPLATES`] templates: t = R φ with R the
//! leading eigenvectors, c = R c₃₆ from the 36-function projection, and the projection residual of
//! Σ c_a t_a against P goes into every loop term's error ([`PROJECTION_FACTOR`] × residual × Σ|loop terms|,
//! as the real-space tensors').
//!
//! **f free.** The tensors hold each term's powers f⁰ … f⁶ (`multipole_tensors`), so f is a
//! per-call input as the spectrum is (both change with the cosmology). The tree level is exact with the
//! true P at the sides. The IR resummation of [`super::one_loop_ir`] ([`MultipoleLoopBasis::evaluate_ir`]):
//! the loops are the tensors contracted with P_LO's projection, the tree level is kept per orientation
//! (without the multipole weights, 45 × 3 sides × monomials × powers of f per triangle) and multiplied by
//! each orientation's legs P_NLO(k_a, μ_a). The loops' factors P_LO(k_a) outside the integrals (B₃₂₁, B₄₁₁)
//! are then P_LO's own values at the sides, not its projection's: the damped wiggles are where P_LO's
//! projection errs most, and on 9 resummed spectra not trained on the worst |ΔB_ℓ|/|B₀| fell from 3.1e-3 to
//! 9.8e-4 (1.4e-3 → 4.1e-4 on Planck 2018 z = 0). Without IR the projection's values are kept: its errors
//! inside and outside the integrals partly cancel (with the true values the worst of 12 spectra rose from
//! 4.1e-4 to 7.9e-4). Not in this path: bin averages (the triangles given are
//! evaluated as such; [`super::one_loop_bins`] corrects the direct path's effective triangles).

use super::geometry::LegendreSide;
use super::ir_legs::{leading_order_spectrum, tree_legs_along};
pub(super) use super::multipole_acc::{Acc, Names};
use super::multipole_cache::{write_triangle, Reader};
use super::multipole_tensors::{
    triangle_tensors, Products, Rows, Setup, TriangleTensors, DIFF_TEMPLATES, F_NODES,
};
use super::one_loop::{triangle_vectors, OneLoopRule, Vec3};
use super::one_loop_basis::{self, PROJECTION_FACTOR};
use super::one_loop_galaxy_multipoles::{
    legendre_side_index, multipole_weights, orientation_nodes, GalaxyLoopMultipoles,
    ORIENTATION_RULE,
};
use super::resum::IrInputs;
use crate::error::Result;
use crate::linear::LinearSpectrum;
use crate::loops::basis::training::{camb_basis, camb_samples};
use crate::loops::basis::{
    after_key, cache_file_name, pair_products, triple_products, LinearBasis, Projection, BASIS_SIZE,
};
use crate::simd::{dot, matvec_f32};
use rayon::prelude::*;
use std::sync::atomic::{AtomicUsize, Ordering};

/// The number of SVD templates the tensors are built on (module docs).
pub const TEMPLATES: usize = 16;

/// The leading `m` SVD templates of `basis` (rows of R, each of the basis's length): the eigenvectors of
/// Σ ĉĉᵀ over the unit coefficient vectors ĉ of the training tables and cuts on the basis's lattice.
fn templates(basis: &LinearBasis, m: usize) -> Vec<Vec<f64>> {
    let samples = camb_samples(basis.lattice());
    let refs: Vec<&[f64]> = samples.iter().map(Vec::as_slice).collect();
    let n = basis.len();
    let mut a = vec![vec![0.0; n]; n];
    for c in basis.coefficients_many(&refs) {
        let norm2: f64 = c.iter().map(|x| x * x).sum();
        for (row, ci) in a.iter_mut().zip(&c) {
            for (x, cj) in row.iter_mut().zip(&c) {
                *x += ci * cj / norm2;
            }
        }
    }
    crate::linalg::symmetric_eigen(&a)
        .into_iter()
        .take(m)
        .map(|(_, u)| u)
        .collect()
}

/// The one-loop galaxy multipole tensors of a triangle set (cosmology independent; module docs).
#[derive(Debug, Clone, PartialEq)]
pub struct MultipoleLoopBasis {
    triangles: Vec<[f64; 3]>,
    rule: OneLoopRule,
    /// The Legendre side asked for, and its index on each triangle.
    side: LegendreSide,
    sides: Vec<usize>,
    /// Per triangle, the orientations' lines of sight and multipole weights (the IR resummation's tree).
    orientations: Vec<(Vec<Vec3>, Vec<[f64; 3]>)>,
    basis: LinearBasis,
    /// R: the templates' coefficients on the basis, m rows.
    templates: Vec<Vec<f64>>,
    tensors: Vec<TriangleTensors>,
}

impl MultipoleLoopBasis {
    /// Builds the tensors of the triangles (sides [h/Mpc]) with the Legendre polynomial on `side`, for
    /// `rule`, in parallel over triangles; `progress(done, total)`.
    ///
    /// # Errors
    /// As [`triangle_vectors`] for sides that do not close; a bad rule or side.
    pub fn build(
        triangles: &[[f64; 3]],
        side: LegendreSide,
        rule: &OneLoopRule,
        progress: &(dyn Fn(usize, usize) + Sync),
    ) -> Result<Self> {
        rule.validate()?;
        let indices = triangles
            .iter()
            .map(|k| legendre_side_index(k, side))
            .collect::<Result<Vec<_>>>()?;
        let k_max = one_loop_basis::k_max(triangles);
        Self::build_at(triangles, side, &indices, rule, k_max, progress)
    }

    /// [`build`](Self::build) with the Legendre side's index of each triangle given (`side` is what the cache
    /// key records) and the basis's lattice for sides up to `k_max` [h/Mpc] (the bins' nodes reach beyond
    /// their effective triangles).
    pub(super) fn build_at(
        triangles: &[[f64; 3]],
        side: LegendreSide,
        indices: &[usize],
        rule: &OneLoopRule,
        k_max: f64,
        progress: &(dyn Fn(usize, usize) + Sync),
    ) -> Result<Self> {
        rule.validate()?;
        let lattice = one_loop_basis::lattice(rule, k_max);
        let basis = camb_basis(lattice, BASIS_SIZE);
        let templates = templates(&basis, TEMPLATES);
        let phi = |x: f64, out: &mut [f64]| template_values(&basis, &templates, x, out);
        let products = Products::new();
        let mut setups = Vec::with_capacity(triangles.len());
        let mut orientations = Vec::with_capacity(triangles.len());
        for (&k, &a) in triangles.iter().zip(indices) {
            let s = setup(k, a, &phi, templates.len(), &products)?;
            orientations.push((s.los.clone(), s.weights.clone()));
            setups.push(s);
        }
        let sides = indices.to_vec();
        let done = AtomicUsize::new(0);
        let tensors = setups
            .par_iter()
            .map(|s| {
                let mut t = triangle_tensors(s, rule);
                let (m, d) = (s.m, DIFF_TEMPLATES.min(s.m));
                t.b222.make_single(triples(m), triples(d));
                t.b321.make_single(pairs(m), pairs(d));
                t.j.make_single_renormalised(&t.sigma);
                t.l.make_single_renormalised(&t.sigma);
                progress(done.fetch_add(1, Ordering::Relaxed) + 1, triangles.len());
                t
            })
            .collect();
        Ok(Self {
            triangles: triangles.to_vec(),
            rule: *rule,
            side,
            sides,
            orientations,
            basis,
            templates,
            tensors,
        })
    }

    /// The templates at ln q = `x` (m values into `out`).
    pub(super) fn phi(&self, x: f64, out: &mut [f64]) {
        template_values(&self.basis, &self.templates, x, out);
    }

    /// The cache file name of the tensors of `triangles`, `side` and `rule` (and of the present kernels).
    pub fn file_name(triangles: &[[f64; 3]], side: LegendreSide, rule: &OneLoopRule) -> String {
        cache_file_name(
            "bispectrum-multipole-basis",
            VERSION,
            &key(triangles, side, rule),
        )
    }

    /// The cache file's values ([`super::multipole_cache`]): the key, the basis, the templates, per
    /// triangle its side, orientations and tensors.
    pub(crate) fn to_f64s(&self) -> Vec<f64> {
        let mut v = key(&self.triangles, self.side, &self.rule);
        v.insert(0, v.len() as f64);
        v.extend(self.basis.to_f64s());
        v.extend(self.templates.iter().flatten());
        let m = self.templates.len();
        for ((&s, o), t) in self.sides.iter().zip(&self.orientations).zip(&self.tensors) {
            write_triangle(s, o, t, m, &mut v);
        }
        v
    }

    /// The tensors of `triangles`, `side` and `rule` from their file's values, or `None` if the file was
    /// made for other settings or does not fit them.
    pub(crate) fn from_f64s(
        values: &[f64],
        triangles: &[[f64; 3]],
        side: LegendreSide,
        rule: &OneLoopRule,
    ) -> Option<Self> {
        Self::from_f64s_at(
            values,
            triangles,
            side,
            rule,
            one_loop_basis::k_max(triangles),
        )
    }

    /// [`from_f64s`](Self::from_f64s) for tensors built with the basis's lattice up to `k_max` [h/Mpc]
    /// ([`build_at`](Self::build_at)).
    pub(super) fn from_f64s_at(
        values: &[f64],
        triangles: &[[f64; 3]],
        side: LegendreSide,
        rule: &OneLoopRule,
        k_max: f64,
    ) -> Option<Self> {
        let rest = after_key(values, &key(triangles, side, rule))?;
        let lattice = one_loop_basis::lattice(rule, k_max);
        let (basis, rest) = LinearBasis::from_f64s(lattice, rest)?;
        let mut r = Reader { values: rest };
        let n = basis.len();
        let templates: Vec<Vec<f64>> = r
            .take(TEMPLATES * n)?
            .chunks_exact(n)
            .map(<[f64]>::to_vec)
            .collect();
        let no = ORIENTATION_RULE.0 * ORIENTATION_RULE.1;
        let (mut sides, mut orientations, mut tensors) = (Vec::new(), Vec::new(), Vec::new());
        for _ in triangles {
            let (s, o, mut t) = r.triangle(TEMPLATES, no)?;
            // files written when J and L were kept bare in f64 (their flag says so)
            for family in [&mut t.j, &mut t.l] {
                if family.single.0.is_empty() && !family.index.is_empty() {
                    family.make_single_renormalised(&t.sigma);
                }
            }
            sides.push(s);
            orientations.push(o);
            tensors.push(t);
        }
        r.values.is_empty().then(|| Self {
            triangles: triangles.to_vec(),
            rule: *rule,
            side,
            sides,
            orientations,
            basis,
            templates,
            tensors,
        })
    }

    /// The Legendre side asked for at the build.
    pub fn side(&self) -> LegendreSide {
        self.side
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
        self.tensors
            .iter()
            .map(|t| {
                let rows = |r: &Rows| {
                    r.fine.len() + r.diff.len() + r.uv.len() + r.single.0.len() + r.single.1.len()
                };
                t.sides.len()
                    + t.sigma[0].len() * 2
                    + rows(&t.b222)
                    + rows(&t.b321)
                    + rows(&t.j)
                    + rows(&t.l)
                    + rows(&t.tree)
                    + rows(&t.tree_o)
            })
            .sum()
    }

    /// The projection of `p` on the templates: their coefficients, and the projection (samples, residual)
    /// of Σ c_a t_a against `p` on the basis's lattice.
    pub fn project(&self, p: &LinearSpectrum) -> (Vec<f64>, Projection) {
        let samples = self.basis.sample(p);
        let c36 = self.basis.project(&samples).coefficients;
        let c: Vec<f64> = self.templates.iter().map(|r| dot(r, &c36)).collect();
        let mut back = vec![0.0; c36.len()];
        for (r, &ci) in self.templates.iter().zip(&c) {
            back.iter_mut().zip(r).for_each(|(b, x)| *b += ci * x);
        }
        (c, self.basis.with_coefficients(&samples, back))
    }

    /// P̂ = Σ c_a t_a, the projection of `p` on the templates, as a spectrum on the basis's lattice (what the
    /// tensors integrate in place of P: the direct multipoles of it equal the tensors' loop terms up to the
    /// lattice interpolation).
    ///
    /// # Errors
    /// As [`LinearSpectrum::from_nodes`] (a projection that is not positive on the lattice).
    pub fn projected_spectrum(&self, p: &LinearSpectrum) -> Result<LinearSpectrum> {
        self.basis.spectrum_of(&self.project(p).1)
    }

    /// B₀, B₂, B₄ per bias monomial of every triangle for the spectrum `p` at growth rate `f` (P at the
    /// sides of the tree level, P̂ elsewhere), with their
    /// [`super::one_loop_galaxy_poly::GalaxyLoopPolynomial::projection`] = [`PROJECTION_FACTOR`] × the
    /// templates' projection residual.
    ///
    /// # Errors
    /// [`crate::error::Error::InvalidParameter`] for f outside [0, 2].
    pub fn evaluate(&self, p: &LinearSpectrum, f: f64) -> Result<Vec<GalaxyLoopMultipoles>> {
        Ok(self.evaluate_projected(p, f, None)?.0)
    }

    /// [`evaluate`](Self::evaluate) (`ir` None) or [`evaluate_ir`](Self::evaluate_ir), with the projection
    /// on the templates of the spectrum the loops integrated (`p`, or P_LO): its residual decides whether
    /// the tensors represent it, and nothing is projected twice.
    ///
    /// # Errors
    /// As [`evaluate_ir`](Self::evaluate_ir).
    pub fn evaluate_projected(
        &self,
        p: &LinearSpectrum,
        f: f64,
        ir: Option<&IrInputs>,
    ) -> Result<(Vec<GalaxyLoopMultipoles>, Projection)> {
        match ir {
            None => self.evaluate_with(p, f, None),
            Some(ir) => self.evaluate_with(&leading_order_spectrum(p, ir)?, f, Some((p, ir))),
        }
    }

    /// [`evaluate`](Self::evaluate) with the infrared resummation of [`super::one_loop_ir`]: the loops on
    /// P_LO (projected on the templates), each orientation's tree level with its legs P_NLO(k_a, μ_a) of `p`.
    ///
    /// # Errors
    /// As [`evaluate`](Self::evaluate); as [`leading_order_spectrum`].
    pub fn evaluate_ir(
        &self,
        p: &LinearSpectrum,
        ir: &IrInputs,
        f: f64,
    ) -> Result<Vec<GalaxyLoopMultipoles>> {
        Ok(self.evaluate_projected(p, f, Some(ir))?.0)
    }

    /// The multipoles with the loops of `p`, the tree level of `p` or (`ir` Some((linear, inputs))) of the
    /// resummed legs of `linear`.
    fn evaluate_with(
        &self,
        p: &LinearSpectrum,
        f: f64,
        ir: Option<(&LinearSpectrum, &IrInputs)>,
    ) -> Result<(Vec<GalaxyLoopMultipoles>, Projection)> {
        crate::cosmology::check_growth_rate(f)?;
        let (c, projection) = self.project(p);
        let multipoles = self.contract(&c, projection.residual, p, f, ir);
        Ok((multipoles, projection))
    }

    /// The multipoles of the templates' coefficients `c` (the projection of the loops' spectrum, whose
    /// projection residual is `residual`), the tree level of `p` or of the resummed legs (`ir`), at a growth
    /// rate `f` the caller has checked.
    pub(super) fn contract(
        &self,
        c: &[f64],
        residual: f64,
        p: &LinearSpectrum,
        f: f64,
        ir: Option<(&LinearSpectrum, &IrInputs)>,
    ) -> Vec<GalaxyLoopMultipoles> {
        let names = Names::get();
        let single = |v: Vec<f64>| -> Vec<f32> { v.iter().map(|&x| x as f32).collect() };
        let (c2_32, c3_32) = (single(pair_products(c)), single(triple_products(c)));
        let c_32 = single(c.to_vec());
        let fp: [f64; F_NODES] = std::array::from_fn(|i| f.powi(i as i32));
        let bound = PROJECTION_FACTOR * residual;
        self.triangles
            .iter()
            .zip(self.tensors.iter().zip(&self.sides).zip(&self.orientations))
            .map(|(&k, ((t, &side), (los, weights)))| {
                let m = c.len();
                let pk = k.map(|v| p.eval(v));
                // the loops' factors P(k_a) outside the integrals: resummed, the spectrum's own (the
                // damped wiggles at a side are where P_LO's projection errs most); else the projection's
                // (its errors inside and outside the integrals partly cancel; module docs)
                let ph: [f64; 3] = if ir.is_some() {
                    pk
                } else {
                    std::array::from_fn(|a| dot(&t.sides[a * m..(a + 1) * m], c))
                };
                let sigma = dot(&t.sigma[0], c);
                // the products of the two sides other than s, for the loop terms and the tree level
                let other = |x: &[f64; 3], s: usize| x[(s + 1) % 3] * x[(s + 2) % 3];
                let mut acc = Acc::new(names);
                let d = DIFF_TEMPLATES.min(m);
                for (idx, (fine, diff)) in single_rows(&t.b222, &c3_32, &c3_32[..triples(d)]) {
                    let w = fp[idx[3] as usize];
                    acc.add(idx, 1, w * fine, w * diff);
                }
                for (idx, (fine, diff)) in single_rows(&t.b321, &c2_32, &c2_32[..pairs(d)]) {
                    let w = fp[idx[3] as usize] * ph[idx[1] as usize];
                    acc.add(idx, 2, w * fine, w * diff);
                }
                for (family, (term, uv_term)) in [(&t.j, (3, 5)), (&t.l, (4, 6))] {
                    // the rows hold J − U s: the renormalised terms
                    for ((idx, (jf, jd)), &u) in single_rows(family, &c_32, &c_32).zip(&family.uv) {
                        let w = fp[idx[3] as usize] * other(&ph, idx[1] as usize);
                        acc.add(idx, term, w * jf, w * jd);
                        acc.add(idx, uv_term, w * u * sigma, 0.0);
                    }
                }
                match ir {
                    None => {
                        for (idx, (fine, _)) in rows(&t.tree, 1) {
                            let w = fp[idx[3] as usize] * other(&pk, idx[1] as usize);
                            acc.add(idx, 0, w * fine[0], 0.0);
                        }
                    }
                    Some((linear, inputs)) => {
                        let kv = triangle_vectors(k).expect("checked at the build");
                        let legs = tree_legs_along(linear, inputs, &kv, f, los);
                        // Σ over orientations o and sides s of w_ℓ(o) P(k_s+1, μ) P(k_s+2, μ) × the row:
                        // the three weights of an (o, s) made once, then per row one product per ℓ
                        // into the monomial's sum (rows come by (o, s))
                        let mut sums = [(); 3].map(|_| vec![0.0; names.len(0)]);
                        let (mut at, mut g) = (u16::MAX, [0.0; 3]);
                        for (idx, (fine, _)) in rows(&t.tree_o, 1) {
                            if idx[1] != at {
                                at = idx[1];
                                let (o, s) = (at as usize / 3, at as usize % 3);
                                let legs = other(&legs[o], s);
                                g = weights[o].map(|w| w * legs);
                            }
                            let v = fp[idx[3] as usize] * fine[0];
                            for (sum, g) in sums.iter_mut().zip(g) {
                                sum[idx[2] as usize] += g * v;
                            }
                        }
                        for (ell, sum) in sums.iter().enumerate() {
                            for (m, &v) in sum.iter().enumerate() {
                                acc.add(&[ell as u16, 0, m as u16, 0], 0, v, 0.0);
                            }
                        }
                    }
                }
                GalaxyLoopMultipoles {
                    k,
                    f,
                    side,
                    ells: std::array::from_fn(|ell| acc.polynomial(ell, k, bound)),
                }
            })
            .collect()
    }
}

/// The templates `templates` (rows on `basis`) at ln q = `x` into `out`.
fn template_values(basis: &LinearBasis, templates: &[Vec<f64>], x: f64, out: &mut [f64]) {
    let mut all = vec![0.0; basis.len()];
    basis.at_ln(x, &mut all);
    for (o, r) in out.iter_mut().zip(templates) {
        *o = dot(r, &all);
    }
}

/// The build's inputs for the triangle `k` with the Legendre polynomial on its side `a`: the exact
/// orientation rule's lines of sight and multipole weights.
pub(super) fn setup<'a>(
    k: [f64; 3],
    a: usize,
    phi: &'a (dyn Fn(f64, &mut [f64]) + Sync),
    m: usize,
    products: &'a Products,
) -> Result<Setup<'a>> {
    let kv = triangle_vectors(k)?;
    let (n_mu, n_phi) = ORIENTATION_RULE;
    let (los, weights) = multipole_weights(&orientation_nodes(n_mu, n_phi), &kv, a)?;
    Ok(Setup {
        kv,
        los,
        weights,
        phi,
        m,
        products,
    })
}

/// Version of the layout, part of the cache file name.
const VERSION: u32 = 2;

/// The settings that make the tensors (their cache key): the real-space galaxy tensors' key (the basis, the
/// rule, the kernels' fingerprint, the triangles) with this layout's version, the number of templates and
/// the Legendre side (−1 for the largest).
fn key(triangles: &[[f64; 3]], side: LegendreSide, rule: &OneLoopRule) -> Vec<f64> {
    let mut key = super::one_loop_galaxy_basis::key(triangles, rule);
    key.extend([f64::from(VERSION), TEMPLATES as f64, side_code(side)]);
    key
}

/// The Legendre side as a cache key's number: −1 for the largest, else its index.
pub(super) fn side_code(side: LegendreSide) -> f64 {
    match side {
        LegendreSide::Largest => -1.0,
        LegendreSide::Index(a) => a as f64,
    }
}

/// The rows of a family with their values on the rule and rule − half rule, `len` each.
fn rows(r: &Rows, len: usize) -> impl Iterator<Item = (&[u16; 4], (&[f64], &[f64]))> {
    r.index
        .iter()
        .zip(r.fine.chunks_exact(len).zip(r.diff.chunks_exact(len)))
}

/// The rows of a family held in f32 contracted with `x` (the pair or triple products) and their rule − half
/// rule with `x_diff` (the products on the first [`DIFF_TEMPLATES`] templates): (index, (value, difference)).
fn single_rows<'a>(
    r: &'a Rows,
    x: &[f32],
    x_diff: &[f32],
) -> impl Iterator<Item = (&'a [u16; 4], (f64, f64))> {
    let mut fine = vec![0.0; r.index.len()];
    let mut diff = vec![0.0; r.index.len()];
    matvec_f32(&r.single.0, x, &mut fine);
    matvec_f32(&r.single.1, x_diff, &mut diff);
    r.index.iter().zip(fine.into_iter().zip(diff))
}

#[cfg(test)]
#[path = "multipole_basis_tests.rs"]
mod tests;

/// The number of packed pairs a ≤ b of m functions.
pub(super) fn pairs(m: usize) -> usize {
    m * (m + 1) / 2
}

/// The number of packed triples a ≤ b ≤ c of m functions.
pub(super) fn triples(m: usize) -> usize {
    m * (m + 1) * (m + 2) / 6
}
