//! The multipoles B₀, B₂, B₄ of the one-loop galaxy bispectrum in redshift space, per bias monomial, in one
//! pass over the loop nodes (issue 50).
//!
//! B_ℓ(k₁, k₂, k₃) = (2ℓ + 1) ⟨B(n̂) L_ℓ(n̂·k̂_a)⟩ over the orientations n̂ of the line of sight (Scoccimarro et
//! al. 1999), with the Legendre polynomial on the side a that the tree level uses ([`LegendreSide`]: the
//! largest by default). **The orientation rule is exact.** Every kernel Z_n^g is a polynomial of degree ≤ 2n
//! in the components of n̂ (each velocity factor U(B) = f(k·n̂)(k_B·n̂)/k_B² G_B brings two), and so are the
//! UV constants c₃, c₄; every term of B is a product of kernels of orders adding to 6 (tree: 4) outside or
//! inside q-integrals whose measure does not involve n̂, so B(n̂) is an even polynomial of degree ≤ 12 and
//! B L₄ one of degree ≤ 16. In the triangle's frame (k₁ along z, k₂ in the x–z plane, n̂ = (sin θ cos φ,
//! sin θ sin φ, μ₁), [`Orientation`]) the product of Gauss–Legendre in μ₁ with 2m nodes and the midpoint rule in
//! φ with 2n points integrates it exactly if 2m − 1 ≥ 16 and 2n > 16: m = 5, n = 9. B is even in n̂ and the
//! triangle's plane is a mirror (φ → −φ), so the 180 nodes fold to the 45 with μ₁ > 0 and φ ∈ (0, π), weight
//! × 4: the orientation average adds no error (tested against a rule of 6 × 11 nodes to round-off).
//!
//! **One pass.** On each node q of the loop rule (the non-mirror rule of an orientation off the triangle's
//! plane) the subsets' real-space fields of every kernel are built once
//! ([`loop_kernel_parts_los`](super::bias_kernels)), and the redshift-space parts of the 45 orientations are
//! assembled from them and accumulated as [`super::one_loop_galaxy_poly`] does for one orientation; the UV
//! constants likewise. Each orientation's sums give its polynomial (the same assembly as at one orientation),
//! and B_ℓ's polynomial is their sum with the weights w_o (2ℓ + 1) L_ℓ(n̂_o·k̂_a). Both the rule and the rule
//! with half the nodes are integrated, so each coefficient of B_ℓ carries fine − coarse
//! ([`TermPolynomial::differences`]): the error of B_ℓ at any bias is that of the loop rule (the orientation
//! rule being exact).

use super::bias_kernels::{loop_kernel_parts_los, LoopBias, N_PARTS};
use super::geometry::LegendreSide;
use super::ir_legs::{leading_order_spectrum, tree_legs};
use super::one_loop::{
    angular_nodes, breaks, nodes, partition, triangle_vectors, OneLoopRule, Vec3,
};
use super::one_loop_galaxy::{sigma2, OneLoopGalaxy, UvParts};
use super::one_loop_galaxy_poly::{
    add_triple_products, assemble, GalaxyLoopPolynomial, Layout, LoopSums, TermPolynomial,
};
use super::one_loop_rsd::Orientation;
use super::resum::IrInputs;
use crate::error::{Error, Result};
use crate::integrate::legendre_nodes;
use crate::linear::LinearSpectrum;
use crate::vec3::{add, dot, neg, norm, sub};
use rayon::prelude::*;
use std::collections::BTreeMap;
use std::f64::consts::PI;

/// The exact orientation rule's positive Gauss–Legendre nodes in μ₁ (of 2 × 5) and midpoints in φ ∈ (0, π).
pub const ORIENTATION_RULE: (usize, usize) = (5, 9);

/// The orientations (μ₁ > 0, φ ∈ (0, π)) and weights (summing to 1) of the folded product rule of
/// Gauss–Legendre in μ₁ with `2 n_mu` nodes and `2 n_phi` midpoints in φ (module docs): exact for the
/// even, mirror-symmetric polynomials in n̂ of degree ≤ min(4 n_mu − 1, 2 n_phi − 1).
pub fn orientation_nodes(n_mu: usize, n_phi: usize) -> Vec<(Orientation, f64)> {
    let (x, w) = legendre_nodes(2 * n_mu);
    let mut out = Vec::with_capacity(n_mu * n_phi);
    for (mu, wm) in x.iter().zip(&w).filter(|(mu, _)| **mu > 0.0) {
        for j in 0..n_phi {
            let phi = (j as f64 + 0.5) * PI / n_phi as f64;
            // 4 copies (parity, mirror) × w_μ × π/n_φ over the sphere's 4π
            out.push((Orientation { mu1: *mu, phi }, wm / n_phi as f64));
        }
    }
    out
}

/// Legendre polynomials L₀, L₂, L₄ at x.
pub fn legendre_024(x: f64) -> [f64; 3] {
    let x2 = x * x;
    [
        1.0,
        0.5 * (3.0 * x2 - 1.0),
        (35.0 * x2 * x2 - 30.0 * x2 + 3.0) / 8.0,
    ]
}

/// The index of the Legendre side of the triangle `k` (the largest: the last of equal ones, as the tree
/// level's).
pub fn legendre_side_index(k: &[f64; 3], side: LegendreSide) -> Result<usize> {
    match side {
        LegendreSide::Index(a) if a < 3 => Ok(a),
        LegendreSide::Index(a) => Err(Error::InvalidChoice {
            what: format!("legendre side index {a}"),
            reason: "sides are numbered 0, 1, 2".into(),
        }),
        LegendreSide::Largest => {
            Ok((0..3).fold(0, |best, a| if k[a] >= k[best] { a } else { best }))
        }
    }
}

/// The multipole weights w_o (2ℓ + 1) L_ℓ(n̂_o·k̂_a) of the orientation rule `nodes` for the triangle `kv`
/// and side `a`, with each orientation's line of sight.
pub(super) fn multipole_weights(
    nodes: &[(Orientation, f64)],
    kv: &[Vec3; 3],
    a: usize,
) -> Result<(Vec<Vec3>, Vec<[f64; 3]>)> {
    let ka = kv[a].map(|x| x / norm(kv[a]));
    let mut los = Vec::with_capacity(nodes.len());
    let mut weights = Vec::with_capacity(nodes.len());
    for (o, w) in nodes {
        let n = o.line_of_sight()?;
        let l = legendre_024(dot(&n, &ka));
        weights.push([w * l[0], 5.0 * w * l[1], 9.0 * w * l[2]]);
        los.push(n);
    }
    Ok((los, weights))
}

/// The multipoles of the one-loop galaxy bispectrum of one triangle per bias monomial (module docs).
#[derive(Debug, Clone, PartialEq)]
pub struct GalaxyLoopMultipoles {
    /// The sides [h/Mpc].
    pub k: [f64; 3],
    /// The growth rate.
    pub f: f64,
    /// The index of the Legendre side.
    pub side: usize,
    /// B₀, B₂, B₄ per monomial (their `redshift` is None: averaged over the orientations).
    pub ells: [GalaxyLoopPolynomial; 3],
}

impl GalaxyLoopMultipoles {
    /// B₀, B₂, B₄ at the coefficients `bias` (each a [`OneLoopGalaxy`] whose `redshift` is None).
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] for a coefficient that is not finite.
    pub fn evaluate(&self, bias: &LoopBias) -> Result<[OneLoopGalaxy; 3]> {
        let [a, b, c] = &self.ells;
        Ok([a.evaluate(bias)?, b.evaluate(bias)?, c.evaluate(bias)?])
    }
}

/// The loop sums of every orientation (line of sight `los[o]`) on one rule, in the layout of [`Layout`]:
/// one flat vector per orientation; the subsets' fields of each kernel built once per node.
fn loop_sums_los(
    p: &LinearSpectrum,
    kv: &[Vec3; 3],
    rule: &OneLoopRule,
    f: f64,
    los: &[Vec3],
    lay: &Layout,
) -> Vec<Vec<f64>> {
    let k = kv.map(norm);
    let grid = nodes(rule, &breaks(&k), false);
    let (s2, s3, s4) = (&lay.s[2], &lay.s[3], &lay.s[4]);
    let (n2, no, len) = (s2.len(), los.len(), lay.len);
    let (k1, k2) = (kv[0], kv[1]);
    let flat = grid
        .par_iter()
        .fold(
            || {
                (
                    vec![0.0; no * len],
                    [
                        vec![[0.0; N_PARTS]; no],
                        vec![[0.0; N_PARTS]; no],
                        vec![[0.0; N_PARTS]; no],
                    ],
                )
            },
            |(mut acc, mut z), &(v, w)| {
                let [x, y, t] = &mut z;
                for (j, q) in [(0, v), (1, sub(v, k1)), (2, sub(k2, v))] {
                    let (a, b) = (add(q, k1), sub(k2, q));
                    let r = [norm(q), norm(a), norm(b)];
                    let s = w * 8.0 * partition(&r, j) * p.eval(r[0]) * p.eval(r[1]) * p.eval(r[2]);
                    loop_kernel_parts_los(&[f], los, &[neg(q), a], x);
                    loop_kernel_parts_los(&[f], los, &[neg(a), neg(b)], y);
                    loop_kernel_parts_los(&[f], los, &[b, q], t);
                    for o in 0..no {
                        let acc = &mut acc[o * len..(o + 1) * len];
                        add_triple_products(acc, s, [&x[o][..], &y[o][..], &t[o][..]], s2);
                    }
                }
                let pq = p.eval(norm(v));
                for b in 0..3 {
                    let d = sub(kv[b], v);
                    let r = [norm(v), norm(d)];
                    let leg = w * 2.0 * 6.0 * partition(&r, 0) * pq * p.eval(r[1]);
                    loop_kernel_parts_los(&[f], los, &[v, d], y);
                    for a in (0..3).filter(|&a| a != b) {
                        loop_kernel_parts_los(&[f], los, &[neg(v), neg(d), neg(kv[a])], x);
                        for o in 0..no {
                            let acc = &mut acc[o * len..(o + 1) * len];
                            for (i, &pi) in s3.iter().enumerate() {
                                let xi = leg * x[o][pi];
                                let at = lay.i321(a, b, i, 0);
                                for (c, &pl) in acc[at..at + n2].iter_mut().zip(s2) {
                                    *c += xi * y[o][pl];
                                }
                            }
                        }
                    }
                }
                for a in 0..3 {
                    let (b, c) = ((a + 1) % 3, (a + 2) % 3);
                    loop_kernel_parts_los(&[f], los, &[v, neg(v), neg(kv[b]), neg(kv[c])], x);
                    loop_kernel_parts_los(&[f], los, &[kv[a], v, neg(v)], y);
                    for o in 0..no {
                        let acc = &mut acc[o * len..(o + 1) * len];
                        let at = lay.o411 + a * s4.len();
                        for (s, &pi) in acc[at..at + s4.len()].iter_mut().zip(s4) {
                            *s += w * pq * x[o][pi];
                        }
                        let at = lay.oj + a * s3.len();
                        for (s, &pi) in acc[at..at + s3.len()].iter_mut().zip(s3) {
                            *s += w * pq * y[o][pi];
                        }
                    }
                }
                (acc, z)
            },
        )
        .map(|(acc, _)| acc)
        .reduce(
            || vec![0.0; no * len],
            |mut a, b| {
                a.iter_mut().zip(&b).for_each(|(x, y)| *x += y);
                a
            },
        );
    flat.chunks(len).map(<[f64]>::to_vec).collect()
}

/// The UV constants per part (as [`super::one_loop_galaxy`]'s `uv_parts`) of every orientation `los[o]`.
pub(super) fn uv_parts_los(
    f: f64,
    los: &[Vec3],
    kv: &[Vec3; 3],
    rule: &OneLoopRule,
) -> Vec<UvParts> {
    let angular = angular_nodes(rule, false);
    let total: f64 = angular.iter().map(|(_, w)| w).sum();
    let k_max = kv.iter().map(|v| norm(*v)).fold(0.0, f64::max);
    let no = los.len();
    let mut parts = vec![[0.0; N_PARTS]; no];
    let mut average = |big: f64, args: &dyn Fn(Vec3) -> Vec<Vec3>| {
        let mut s = vec![[0.0; N_PARTS]; no];
        for &(u, w) in &angular {
            loop_kernel_parts_los(&[f], los, &args(u.map(|x| x * big)), &mut parts);
            for (s, x) in s.iter_mut().zip(&parts) {
                for p in 2..N_PARTS {
                    s[p] += w * x[p] / total;
                }
            }
        }
        s
    };
    let mut out = vec![([[0.0; N_PARTS]; 3], [[0.0; N_PARTS]; 3]); no];
    for a in 0..3 {
        let (b, c) = ((a + 1) % 3, (a + 2) % 3);
        let three = |q: Vec3| vec![kv[a], q, neg(q)];
        let four = |q: Vec3| vec![q, neg(q), neg(kv[b]), neg(kv[c])];
        let (t1, t2) = (average(1e3 * k_max, &three), average(2e3 * k_max, &three));
        let (f1, f2) = (average(1e3 * k_max, &four), average(2e3 * k_max, &four));
        for o in 0..no {
            for p in 0..N_PARTS {
                out[o].0[a][p] = (4.0 * t2[o][p] - t1[o][p]) / 3.0;
                out[o].1[a][p] = (4.0 * f2[o][p] - f1[o][p]) / 3.0;
            }
        }
    }
    out
}

/// Σ_o c_o × polynomial_o, term by term and monomial by monomial (values and differences).
pub(super) fn combine(polys: &[GalaxyLoopPolynomial], c: &[f64]) -> GalaxyLoopPolynomial {
    let term = |get: &dyn Fn(&GalaxyLoopPolynomial) -> &TermPolynomial| {
        let mut sums: BTreeMap<[u8; 3], [f64; 2]> = BTreeMap::new();
        for (poly, &c) in polys.iter().zip(c) {
            let t = get(poly);
            for ((m, v), d) in t.monomials.iter().zip(&t.values).zip(&t.differences) {
                let e = sums.entry(*m).or_insert([0.0; 2]);
                e[0] += c * v;
                e[1] += c * d;
            }
        }
        TermPolynomial {
            monomials: sums.keys().copied().collect(),
            values: sums.values().map(|e| e[0]).collect(),
            differences: sums.values().map(|e| e[1]).collect(),
        }
    };
    GalaxyLoopPolynomial {
        k: polys[0].k,
        redshift: None,
        tree: term(&|p| &p.tree),
        b222: term(&|p| &p.b222),
        b321_i: term(&|p| &p.b321_i),
        b321_ii: term(&|p| &p.b321_ii),
        b411: term(&|p| &p.b411),
        uv_b321_ii: term(&|p| &p.uv_b321_ii),
        uv_b411: term(&|p| &p.uv_b411),
        projection: 0.0,
    }
}

/// B₀, B₂, B₄ of the one-loop galaxy bispectrum of the triangle of sides `k` [h/Mpc] per bias monomial at
/// growth rate `f`, the Legendre polynomial on `side`, for the linear spectrum `p` with the loop `rule`
/// (module docs); [`orientation_nodes`] with [`ORIENTATION_RULE`] unless `orientations` is given.
///
/// # Errors
/// As [`super::one_loop_galaxy_poly::one_loop_galaxy_polynomial`]: sides that do not close, a bad rule, f
/// outside [0, 2]; a side index beyond 2; an orientation rule of fewer than 1 node in either direction.
pub fn one_loop_galaxy_multipoles(
    p: &LinearSpectrum,
    k: [f64; 3],
    f: f64,
    side: LegendreSide,
    rule: &OneLoopRule,
    orientations: Option<(usize, usize)>,
) -> Result<GalaxyLoopMultipoles> {
    galaxy_multipoles(p, None, k, f, side, rule, orientations)
}

/// [`one_loop_galaxy_multipoles`] without (`ir` None) or with the infrared resummation of
/// [`super::one_loop_ir`]: the loops on P_LO (one pass, shared by the orientations), each orientation's
/// tree level with its legs P_NLO(k_a, μ_a).
pub(super) fn galaxy_multipoles(
    p: &LinearSpectrum,
    ir: Option<&IrInputs>,
    k: [f64; 3],
    f: f64,
    side: LegendreSide,
    rule: &OneLoopRule,
    orientations: Option<(usize, usize)>,
) -> Result<GalaxyLoopMultipoles> {
    rule.validate()?;
    crate::cosmology::check_growth_rate(f)?;
    let kv = triangle_vectors(k)?;
    let a = legendre_side_index(&k, side)?;
    let (n_mu, n_phi) = orientations.unwrap_or(ORIENTATION_RULE);
    if n_mu == 0 || n_phi == 0 {
        return Err(Error::InvalidChoice {
            what: format!("an orientation rule of {n_mu} x {n_phi} nodes"),
            reason: "at least one node in mu1 and in phi".into(),
        });
    }
    let nodes_o = orientation_nodes(n_mu, n_phi);
    let (los, weights) = multipole_weights(&nodes_o, &kv, a)?;
    let lay = Layout::new(true);
    let resummed = ir.map(|ir| leading_order_spectrum(p, ir)).transpose()?;
    let linear = p;
    let p = resummed.as_ref().unwrap_or(p);
    let pk = kv.map(|v| p.eval(norm(v)));
    let half = rule.half();
    let fine = loop_sums_los(p, &kv, rule, f, &los, &lay);
    let coarse = loop_sums_los(p, &kv, &half, f, &los, &lay);
    let sigma = [sigma2(p, &k, rule, false), sigma2(p, &k, &half, false)];
    let uv = uv_parts_los(f, &los, &kv, rule);
    let polys: Vec<GalaxyLoopPolynomial> = (0..los.len())
        .map(|o| {
            let sums = LoopSums {
                fine: fine[o].clone(),
                coarse: coarse[o].clone(),
                sigma2: sigma,
            };
            let orientation = nodes_o[o].0;
            let pk_tree = match ir {
                Some(ir) => tree_legs(linear, ir, &kv, Some((f, los[o]))),
                None => pk,
            };
            assemble(
                k,
                Some((f, orientation)),
                Some((f, los[o])),
                &lay,
                &pk_tree,
                &pk,
                &sums,
                &uv[o],
            )
        })
        .collect();
    let ells = std::array::from_fn(|l| {
        let c: Vec<f64> = weights.iter().map(|w| w[l]).collect();
        combine(&polys, &c)
    });
    Ok(GalaxyLoopMultipoles {
        k,
        f,
        side: a,
        ells,
    })
}
