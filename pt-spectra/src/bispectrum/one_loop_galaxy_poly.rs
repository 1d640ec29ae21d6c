//! The one-loop galaxy bispectrum per bias monomial: every term of [`super::one_loop_galaxy`] as a polynomial
//! of degree 3 in the coefficients, computed once per triangle (and orientation) and then evaluated for any
//! [`LoopBias`] in microseconds.
//!
//! The galaxy kernels are affine in the coefficients
//! ([`galaxy_kernel_parts`](super::bias_kernels::galaxy_kernel_parts)): with x = (1, b1, b2, g2, b3, g2x, g3,
//! g21, g21x, g211, g22, g31), K_n = Σ_p x_p O_p,n (O₀ = 0 in real space; in redshift space O₀ is the part
//! without bias, fμ² at first order). Every term is a product of three kernels (tree Z₂Z₁Z₁, B₂₂₂ Z₂Z₂Z₂,
//! B₃₂₁ᴵ Z₁Z₃Z₂, B₃₂₁ᴵᴵ Z₂Z₁ ∫Z₃, B₄₁₁ Z₁Z₁ ∫Z₄), so a sum over the monomials x_p x_q x_r (p ≤ q ≤ r) that
//! the kernels' orders allow ([`LOWEST_ORDER`]: b1 from first order, b2, g2 from second, b3, g2x, g3, g21
//! from third, the rest from fourth; the constant from first order in redshift space only). The monomials per
//! term (counted independently in the tests):
//!
//! ```text
//!                tree  B₂₂₂  B₃₂₁ᴵ  B₃₂₁ᴵᴵ  B₄₁₁  subtracted from B₃₂₁ᴵᴵ, B₄₁₁
//! real space        3    10     18      18    11   17, 10
//! redshift space   10    20     44      44    34   40, 30
//! ```
//!
//! **One pass.** On each node of the loop rules the parts of every kernel are evaluated once (the direct path
//! evaluates the same kernels, so the cost is close to one direct evaluation) and accumulated as ordered
//! products of parts: B₂₂₂'s cubic form, B₃₂₁ᴵ's bilinear form Z₃ ⊗ Z₂ per ordered pair of sides (its linear
//! leg Z₁(k_a) is outside the integral), B₄₁₁'s and B₃₂₁ᴵᴵ's linear forms ∫Z₄ and ∫Z₃ per side; the factors
//! outside the integrals multiply them afterwards. Both the rule and the rule with half the nodes are
//! integrated, so each coefficient carries fine − coarse ([`TermPolynomial::differences`]), and the error of
//! a term at any bias, |Σ differences × monomials|, is the direct path's.
//!
//! **Renormalisation.** The UV constants c₃, c₄ of [`super::one_loop_galaxy`] are linear in the bias
//! operators' coefficients (b2 … g31, not b1 or the constant), one constant per part, computed from the
//! parts on the same angular rule; the subtracted amounts c σ² are polynomials too
//! ([`GalaxyLoopPolynomial::uv_b321_ii`], [`GalaxyLoopPolynomial::uv_b411`]) and the renormalised B₃₂₁ᴵᴵ,
//! B₄₁₁ have them subtracted coefficient by coefficient.

use super::bias_kernels::{loop_kernel_parts, LoopBias, LOWEST_ORDER, N_PARTS};
use super::ir_legs::{leading_order_spectrum, tree_legs};
use super::one_loop::{breaks, nodes, partition, triangle_vectors, OneLoopRule, Vec3};
use super::one_loop_galaxy::{sigma2, uv_parts, OneLoopGalaxy, UvParts};
use super::one_loop_rsd::Orientation;
use super::resum::IrInputs;
use crate::error::Result;
use crate::estimate::Estimate;
use crate::linear::LinearSpectrum;
use crate::vec3::{add, neg, norm, sub};
use rayon::prelude::*;
use std::collections::BTreeMap;

/// The names of the parts x_p of the monomials: the constant, then [`LoopBias::NAMES`].
pub const PART_NAMES: [&str; N_PARTS] = [
    "1", "b1", "b2", "g2", "b3", "g2x", "g3", "g21", "g21x", "g211", "g22", "g31",
];

/// A monomial x_p x_q x_r: three indices into [`PART_NAMES`], ascending.
pub type Monomial = [u8; 3];

/// The name of a monomial, e.g. "b1 b1 g2" (the constant's factors left out; "1" for the constant alone).
pub fn monomial_name(m: &Monomial) -> String {
    let names: Vec<&str> = m
        .iter()
        .filter(|&&p| p > 0)
        .map(|&p| PART_NAMES[p as usize])
        .collect();
    if names.is_empty() {
        "1".into()
    } else {
        names.join(" ")
    }
}

/// One term as a polynomial in the parts x = (1, b1, …, g31) [(Mpc/h)⁶].
#[derive(Debug, Clone, PartialEq, Default)]
pub struct TermPolynomial {
    /// The monomials that the term's kernel orders allow (module docs), ascending.
    pub monomials: Vec<Monomial>,
    /// Each monomial's coefficient on the rule.
    pub values: Vec<f64>,
    /// Each coefficient on the rule minus the one on the rule with half the nodes (signed; zero for the exact
    /// tree level and the subtracted amounts).
    pub differences: Vec<f64>,
}

impl TermPolynomial {
    /// The number of monomials.
    pub fn len(&self) -> usize {
        self.monomials.len()
    }

    /// Whether there are none.
    pub fn is_empty(&self) -> bool {
        self.monomials.is_empty()
    }

    /// The coefficients with their errors (|difference|).
    pub fn coefficients(&self) -> Vec<(Monomial, Estimate)> {
        self.monomials
            .iter()
            .zip(self.values.iter().zip(&self.differences))
            .map(|(m, (v, d))| (*m, Estimate::new(*v, d.abs())))
            .collect()
    }

    /// The term at the parts `x` (x₀ = 1): the value and |Σ differences × monomials|.
    pub fn evaluate_parts(&self, x: &[f64; N_PARTS]) -> Estimate {
        let (mut value, mut difference) = (0.0, 0.0);
        for (m, (v, d)) in self
            .monomials
            .iter()
            .zip(self.values.iter().zip(&self.differences))
        {
            let t = x[m[0] as usize] * x[m[1] as usize] * x[m[2] as usize];
            value += v * t;
            difference += d * t;
        }
        Estimate::new(value, difference.abs())
    }

    fn from_sums(sums: BTreeMap<Monomial, [f64; 2]>) -> Self {
        let mut t = Self::default();
        for (m, [fine, coarse]) in sums {
            t.monomials.push(m);
            t.values.push(fine);
            t.differences.push(fine - coarse);
        }
        t
    }
}

/// The one-loop galaxy bispectrum of one triangle (and orientation) per bias monomial (module docs).
#[derive(Debug, Clone, PartialEq)]
pub struct GalaxyLoopPolynomial {
    /// The sides [h/Mpc].
    pub k: [f64; 3],
    /// (f, orientation) in redshift space; None in real space.
    pub redshift: Option<(f64, Orientation)>,
    /// B₁₁₂ (exact).
    pub tree: TermPolynomial,
    /// B₂₂₂.
    pub b222: TermPolynomial,
    /// B₃₂₁ᴵ.
    pub b321_i: TermPolynomial,
    /// B₃₂₁ᴵᴵ, renormalised.
    pub b321_ii: TermPolynomial,
    /// B₄₁₁, renormalised.
    pub b411: TermPolynomial,
    /// The amount subtracted from the bare B₃₂₁ᴵᴵ.
    pub uv_b321_ii: TermPolynomial,
    /// The amount subtracted from the bare B₄₁₁.
    pub uv_b411: TermPolynomial,
    /// The relative bound of the basis's projection (zero on the direct path): each loop term's error at a
    /// bias includes this × the sum of the four loop terms' sizes there
    /// ([`super::one_loop_galaxy_basis`]).
    pub projection: f64,
}

impl GalaxyLoopPolynomial {
    /// The terms at the coefficients `bias`: [`super::one_loop_galaxy::one_loop_galaxy`]'s, to round-off.
    ///
    /// # Errors
    /// [`crate::error::Error::InvalidParameter`] for a coefficient that is not finite.
    pub fn evaluate(&self, bias: &LoopBias) -> Result<OneLoopGalaxy> {
        bias.check_finite()?;
        let mut x = [1.0; N_PARTS];
        x[1..].copy_from_slice(&bias.values());
        let mut loops =
            [&self.b222, &self.b321_i, &self.b321_ii, &self.b411].map(|t| t.evaluate_parts(&x));
        if self.projection != 0.0 {
            let size: f64 = loops.iter().map(|t| t.value.abs()).sum();
            loops
                .iter_mut()
                .for_each(|t| t.error += self.projection * size);
        }
        let [b222, b321_i, b321_ii, b411] = loops;
        Ok(OneLoopGalaxy {
            k: self.k,
            bias: *bias,
            redshift: self.redshift,
            tree: self.tree.evaluate_parts(&x),
            b222,
            b321_i,
            b321_ii,
            b411,
            uv_b321_ii: self.uv_b321_ii.evaluate_parts(&x).value,
            uv_b411: self.uv_b411.evaluate_parts(&x).value,
        })
    }

    /// The terms in the order tree, B₂₂₂, B₃₂₁ᴵ, B₃₂₁ᴵᴵ, B₄₁₁, then the two subtracted amounts.
    pub fn terms(&self) -> [&TermPolynomial; 7] {
        [
            &self.tree,
            &self.b222,
            &self.b321_i,
            &self.b321_ii,
            &self.b411,
            &self.uv_b321_ii,
            &self.uv_b411,
        ]
    }
}

/// The parts that a kernel of order `n` can hold (module docs).
fn support(n: usize, redshift: bool) -> Vec<usize> {
    (0..N_PARTS)
        .filter(|&p| {
            if p == 0 {
                redshift
            } else {
                LOWEST_ORDER[p - 1] <= n
            }
        })
        .collect()
}

pub(super) fn monomial(p: usize, q: usize, r: usize) -> Monomial {
    let mut m = [p as u8, q as u8, r as u8];
    m.sort_unstable();
    m
}

/// Adds (fine, coarse) to a monomial's sums.
fn put(sums: &mut BTreeMap<Monomial, [f64; 2]>, m: Monomial, fine: f64, coarse: f64) {
    let e = sums.entry(m).or_insert([0.0; 2]);
    e[0] += fine;
    e[1] += coarse;
}

/// The supports of the kernels of orders 1 to 4 and where each integral's sums lie in one flat vector:
/// B₂₂₂'s [s₂]³, B₃₂₁ᴵ's [3 a][3 b][s₃][s₂], B₄₁₁'s [3][s₄], J's [3][s₃].
pub(super) struct Layout {
    pub(super) s: [Vec<usize>; 5],
    pub(super) o321: usize,
    pub(super) o411: usize,
    pub(super) oj: usize,
    pub(super) len: usize,
}

impl Layout {
    pub(super) fn new(redshift: bool) -> Self {
        let s: [Vec<usize>; 5] = std::array::from_fn(|n| support(n, redshift));
        let (n2, n3, n4) = (s[2].len(), s[3].len(), s[4].len());
        let o321 = n2 * n2 * n2;
        let o411 = o321 + 9 * n3 * n2;
        let oj = o411 + 3 * n4;
        Self {
            s,
            o321,
            o411,
            oj,
            len: oj + 3 * n3,
        }
    }

    pub(super) fn i321(&self, a: usize, b: usize, i: usize, j: usize) -> usize {
        self.o321 + ((3 * a + b) * self.s[3].len() + i) * self.s[2].len() + j
    }
}

/// The loop integrals' sums on one rule (module docs), in the flat layout of [`Layout`].
fn loop_sums(
    p: &LinearSpectrum,
    kv: &[Vec3; 3],
    rule: &OneLoopRule,
    redshift: Option<(f64, Vec3)>,
    lay: &Layout,
) -> Vec<f64> {
    let k = kv.map(norm);
    let mirror = redshift.is_none_or(|(_, los)| los[1] == 0.0);
    let grid = nodes(rule, &breaks(&k), mirror);
    let z = |q: &[Vec3]| loop_kernel_parts(redshift, q);
    let (s2, s3, s4) = (&lay.s[2], &lay.s[3], &lay.s[4]);
    let n2 = s2.len();
    let (k1, k2) = (kv[0], kv[1]);
    grid.par_iter()
        .fold(
            || vec![0.0; lay.len],
            |mut acc, &(v, w)| {
                // B222: the pieces about q = 0, q = −k₁, q = k₂, as in `loop_integrals`.
                for (j, q) in [(0, v), (1, sub(v, k1)), (2, sub(k2, v))] {
                    let (a, b) = (add(q, k1), sub(k2, q));
                    let r = [norm(q), norm(a), norm(b)];
                    let s = w * 8.0 * partition(&r, j) * p.eval(r[0]) * p.eval(r[1]) * p.eval(r[2]);
                    let (x, y, t) = (z(&[neg(q), a]), z(&[neg(a), neg(b)]), z(&[b, q]));
                    add_triple_products(&mut acc, s, [&x[..], &y[..], &t[..]], s2);
                }
                // B321ᴵ: Z₃ ⊗ Z₂ per ordered pair (a outer, b in the loop), twice the piece about q = 0.
                let pq = p.eval(norm(v));
                for b in 0..3 {
                    let d = sub(kv[b], v);
                    let r = [norm(v), norm(d)];
                    let leg = w * 2.0 * 6.0 * partition(&r, 0) * pq * p.eval(r[1]);
                    let y = z(&[v, d]);
                    for a in (0..3).filter(|&a| a != b) {
                        let x = z(&[neg(v), neg(d), neg(kv[a])]);
                        for (i, &pi) in s3.iter().enumerate() {
                            let xi = leg * x[pi];
                            let at = lay.i321(a, b, i, 0);
                            for (c, &pl) in acc[at..at + n2].iter_mut().zip(s2) {
                                *c += xi * y[pl];
                            }
                        }
                    }
                }
                // B411's ∫Z₄(q, −q, −k_b, −k_c) P(q) and J_a = ∫Z₃(k_a, q, −q) P(q).
                for a in 0..3 {
                    let (b, c) = ((a + 1) % 3, (a + 2) % 3);
                    let x = z(&[v, neg(v), neg(kv[b]), neg(kv[c])]);
                    let at = lay.o411 + a * s4.len();
                    for (s, &pi) in acc[at..at + s4.len()].iter_mut().zip(s4) {
                        *s += w * pq * x[pi];
                    }
                    let x = z(&[kv[a], v, neg(v)]);
                    let at = lay.oj + a * s3.len();
                    for (s, &pi) in acc[at..at + s3.len()].iter_mut().zip(s3) {
                        *s += w * pq * x[pi];
                    }
                }
                acc
            },
        )
        .reduce(
            || vec![0.0; lay.len],
            |mut a, b| {
                a.iter_mut().zip(&b).for_each(|(x, y)| *x += y);
                a
            },
        )
}

/// The one-loop galaxy bispectrum terms of the triangle of sides `k` [h/Mpc] per bias monomial, in real space
/// (`redshift` None) or in redshift space at growth rate f and an orientation, for the linear spectrum `p`,
/// with `rule`: one pass over the nodes of the rule and one over the rule with half the nodes (module docs).
/// [`GalaxyLoopPolynomial::evaluate`] then gives [`super::one_loop_galaxy::one_loop_galaxy`]'s terms.
///
/// # Errors
/// As [`super::one_loop_galaxy::one_loop_galaxy`] (sides that do not close, a bad rule, f outside [0, 2], a bad
/// orientation).
pub fn one_loop_galaxy_polynomial(
    p: &LinearSpectrum,
    k: [f64; 3],
    redshift: Option<(f64, Orientation)>,
    rule: &OneLoopRule,
) -> Result<GalaxyLoopPolynomial> {
    galaxy_polynomial(p, None, k, redshift, rule)
}

/// [`one_loop_galaxy_polynomial`] without (`ir` None) or with the infrared resummation of
/// [`super::one_loop_ir`]: the loops on P_LO, the tree level's legs P_NLO.
pub(super) fn galaxy_polynomial(
    p: &LinearSpectrum,
    ir: Option<&IrInputs>,
    k: [f64; 3],
    redshift: Option<(f64, Orientation)>,
    rule: &OneLoopRule,
) -> Result<GalaxyLoopPolynomial> {
    rule.validate()?;
    let kv = triangle_vectors(k)?;
    let rsd = redshift.map(Orientation::checked_with).transpose()?;
    let mirror = rsd.is_none_or(|(_, los)| los[1] == 0.0);
    let lay = Layout::new(rsd.is_some());
    let resummed = ir.map(|ir| leading_order_spectrum(p, ir)).transpose()?;
    let (tree_pk, p) = match (ir, &resummed) {
        (Some(ir), Some(lo)) => (Some(tree_legs(p, ir, &kv, rsd)), lo),
        _ => (None, p),
    };
    let pk = kv.map(|v| p.eval(norm(v)));
    let pk_tree = tree_pk.unwrap_or(pk);
    let half = rule.half();
    let sums = LoopSums {
        fine: loop_sums(p, &kv, rule, rsd, &lay),
        coarse: loop_sums(p, &kv, &half, rsd, &lay),
        sigma2: [sigma2(p, &k, rule, mirror), sigma2(p, &k, &half, mirror)],
    };
    let uv = uv_parts(rsd, &kv, rule, mirror);
    Ok(assemble(k, redshift, rsd, &lay, &pk_tree, &pk, &sums, &uv))
}

/// The loop integrals' sums on the rule and the half rule (in the layout of [`Layout`]) and σ² on both.
pub(super) struct LoopSums {
    pub(super) fine: Vec<f64>,
    pub(super) coarse: Vec<f64>,
    pub(super) sigma2: [f64; 2],
}

/// The terms per monomial from the loop sums, the UV constants per part `uv` = (c₃, c₄), the spectrum at the
/// sides for the tree level (`pk_tree`) and for the factors of the loop terms outside the integrals
/// (`pk_loop`).
#[allow(clippy::too_many_arguments)]
pub(super) fn assemble(
    k: [f64; 3],
    redshift: Option<(f64, Orientation)>,
    rsd: Option<(f64, Vec3)>,
    lay: &Layout,
    pk_tree: &[f64; 3],
    pk: &[f64; 3],
    sums: &LoopSums,
    uv: &UvParts,
) -> GalaxyLoopPolynomial {
    let kv = triangle_vectors(k).expect("checked by the caller");
    let (s1, s2, s3, s4) = (&lay.s[1], &lay.s[2], &lay.s[3], &lay.s[4]);
    let z1 = kv.map(|v| loop_kernel_parts(rsd, &[v]));
    let z2 = |a: usize, b: usize| loop_kernel_parts(rsd, &[kv[a], kv[b]]);
    let (fine, coarse) = (&sums.fine, &sums.coarse);
    let [s_fine, s_coarse] = sums.sigma2;
    let (c3, c4) = uv;
    let mut terms: [BTreeMap<Monomial, [f64; 2]>; 7] = Default::default();
    let [tree, b222, b321_i, b321_ii, b411, uv_ii, uv_411] = &mut terms;
    *tree = tree_sums(&kv, rsd, lay, pk_tree);
    for (i, &pi) in s2.iter().enumerate() {
        for (l, &pl) in s2.iter().enumerate() {
            for (m, &pm) in s2.iter().enumerate() {
                let at = (i * s2.len() + l) * s2.len() + m;
                put(b222, monomial(pi, pl, pm), fine[at], coarse[at]);
            }
        }
    }
    for a in 0..3 {
        for b in (0..3).filter(|&b| b != a) {
            let z = z2(a, b);
            for &l in s1 {
                let outer = z1[a][l] * pk[a];
                for (i, &pi) in s3.iter().enumerate() {
                    for (j, &pj) in s2.iter().enumerate() {
                        let at = lay.i321(a, b, i, j);
                        put(
                            b321_i,
                            monomial(l, pi, pj),
                            outer * fine[at],
                            outer * coarse[at],
                        );
                    }
                }
                // B321ᴵᴵ: 6 Z₂(k_a, k_b) Z₁(k_b) P_a P_b [J_a − c₃(k_a) σ²].
                for &i in s2 {
                    let c = 6.0 * z[i] * z1[b][l] * pk[a] * pk[b];
                    for (m, &pm) in s3.iter().enumerate() {
                        let (jf, jc) = (
                            fine[lay.oj + a * s3.len() + m],
                            coarse[lay.oj + a * s3.len() + m],
                        );
                        let u = c * c3[a][pm];
                        let mono = monomial(i, l, pm);
                        put(b321_ii, mono, c * jf - u * s_fine, c * jc - u * s_coarse);
                        if pm >= 2 {
                            put(uv_ii, mono, u * s_fine, u * s_fine);
                        }
                    }
                }
            }
        }
    }
    for (a, c4a) in c4.iter().enumerate() {
        let (b, c) = ((a + 1) % 3, (a + 2) % 3);
        for &l in s1 {
            for &n in s1 {
                let legs = 12.0 * z1[b][l] * z1[c][n] * pk[b] * pk[c];
                for (m, &pm) in s4.iter().enumerate() {
                    let at = lay.o411 + a * s4.len() + m;
                    let u = legs * c4a[pm];
                    let mono = monomial(l, n, pm);
                    put(
                        b411,
                        mono,
                        legs * fine[at] - u * s_fine,
                        legs * coarse[at] - u * s_coarse,
                    );
                    if pm >= 2 {
                        put(uv_411, mono, u * s_fine, u * s_fine);
                    }
                }
            }
        }
    }
    let [tree, b222, b321_i, b321_ii, b411, uv_b321_ii, uv_b411] =
        terms.map(TermPolynomial::from_sums);
    GalaxyLoopPolynomial {
        k,
        redshift,
        tree,
        b222,
        b321_i,
        b321_ii,
        b411,
        uv_b321_ii,
        uv_b411,
        projection: 0.0,
    }
}

/// The tree level B₁₁₂ = Σ_{a<b} 2 Z₂(k_a, k_b) Z₁(k_a) Z₁(k_b) P_a P_b per monomial, with the spectrum
/// `pk_tree` at the sides `kv` (the linear one, or the resummed legs of [`super::one_loop_ir`]).
fn tree_sums(
    kv: &[Vec3; 3],
    rsd: Option<(f64, Vec3)>,
    lay: &Layout,
    pk_tree: &[f64; 3],
) -> BTreeMap<Monomial, [f64; 2]> {
    let (s1, s2) = (&lay.s[1], &lay.s[2]);
    let z1 = kv.map(|v| loop_kernel_parts(rsd, &[v]));
    let mut tree = BTreeMap::new();
    for (a, b) in [(0, 1), (1, 2), (2, 0)] {
        let c = 2.0 * pk_tree[a] * pk_tree[b];
        let z = loop_kernel_parts(rsd, &[kv[a], kv[b]]);
        for &i in s2 {
            for &l in s1 {
                for &m in s1 {
                    let t = c * z[i] * z1[a][l] * z1[b][m];
                    put(&mut tree, monomial(i, l, m), t, t);
                }
            }
        }
    }
    tree
}

/// The tree level's polynomial (as [`assemble`] makes it) of the triangle `k` in real space (`redshift`
/// None) or at (f, line of sight), with the spectrum `pk_tree` at the sides.
pub(super) fn tree_polynomial(
    k: [f64; 3],
    redshift: Option<(f64, Vec3)>,
    pk_tree: &[f64; 3],
) -> Result<TermPolynomial> {
    let kv = triangle_vectors(k)?;
    let lay = Layout::new(redshift.is_some());
    Ok(TermPolynomial::from_sums(tree_sums(
        &kv, redshift, &lay, pk_tree,
    )))
}

/// B222's monomials at one loop node: `acc[(i n + l) n + m] += s x[s2[i]] y[s2[l]] t[s2[m]]` for the
/// second-order slots `s2` (n of them) of the three kernels' parts `x`, `y`, `t` (one orientation's).
#[inline(always)]
pub(super) fn add_triple_products(acc: &mut [f64], s: f64, [x, y, t]: [&[f64]; 3], s2: &[usize]) {
    let n2 = s2.len();
    for (i, &pi) in s2.iter().enumerate() {
        let xi = s * x[pi];
        for (l, &pl) in s2.iter().enumerate() {
            let xy = xi * y[pl];
            let row = &mut acc[(i * n2 + l) * n2..(i * n2 + l + 1) * n2];
            for (c, &pm) in row.iter_mut().zip(s2) {
                *c += xy * t[pm];
            }
        }
    }
}
