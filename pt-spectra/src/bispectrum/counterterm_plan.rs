//! The multipoles of the counterterm and stochastic shapes of the one-loop galaxy bispectrum
//! ([`super::galaxy_counterterms_rsd`]) of a triangle set, planned once (cosmology independent) so that a
//! new linear spectrum and growth rate cost a contraction and a new bias a smaller one: the bispectrum
//! block's ([`super::loop_block`]) counterterms in a fit.
//!
//! Every shape is a polynomial in f, b1, b2, g2 (Z₁ = b1 + fμ², Z₂ affine in the bias and quadratic in f)
//! times 2 P(k_i) P(k_j) of a pair of sides or P(k_i) of a leg. The plan writes the shapes once as such
//! polynomials ([`super::bias_poly::Poly`], through the same `pair_parts` as the numbers) at every
//! orientation of the exact rule and every closed triangle of a bin (the nodes of the direct table,
//! [`super::one_loop_bins::CORRECTION_NODES`] per shell panel), and keeps, per bin, the coefficients of
//! f^m × (bias monomial) × (the spectrum's factor of a node). Evaluating is then
//! Σ coefficient × f^m × factor (exact: no approximation beyond rounding, tested against
//! [`super::galaxy_counterterms_rsd::redshift_counterterm_multipoles`]).

use super::bias_kernels::{galaxy_kernel, galaxy_redshift_kernel, LoopBias};
use super::bias_poly::Poly;
use super::galaxy_counterterms_rsd::{pair_parts, Sight, N_REDSHIFT_CT, STOCHASTIC_LEGS};
use super::geometry::{LegendreSide, TriangleSet};
use super::one_loop::triangle_vectors;
use super::one_loop_bins::CORRECTION_NODES;
use super::one_loop_galaxy_multipoles::{multipole_weights, orientation_nodes, ORIENTATION_RULE};
use crate::error::{Error, Result};
use crate::linear::LinearSpectrum;
use rayon::prelude::*;

/// The bias monomials (exponents of b1, b2, g2) the shapes hold: Z₁Z₁Z₂ and Z₁³ at most.
pub const MONOMIALS: [[u8; 3]; 10] = [
    [0, 0, 0],
    [1, 0, 0],
    [2, 0, 0],
    [3, 0, 0],
    [0, 1, 0],
    [1, 1, 0],
    [2, 1, 0],
    [0, 0, 1],
    [1, 0, 1],
    [2, 0, 1],
];

/// The highest power of f in a shape (Z₂ f² Z₁Z₁ of ct_fog).
const MAX_F_POWER: usize = 6;

/// The values per bin: [ℓ][shape][monomial] flattened.
const PER_BIN: usize = 3 * N_REDSHIFT_CT * MONOMIALS.len();

/// The spectrum's factors of a node: 2 P_i P_j of the pairs (0..3), P_i of the legs (3..6).
const SLOTS: usize = 6;

/// One coefficient: into `out` ([ℓ][shape][monomial]), times f^`m` and the factor `slot` of the bin
/// (node × [`SLOTS`] + factor; the last slot of a bin is 1).
#[derive(Debug, Clone, Copy)]
struct Entry {
    out: u16,
    m: u8,
    slot: u16,
    c: f64,
}

/// The planned shapes of one bin (or triangle).
#[derive(Debug, Clone)]
struct BinPlan {
    /// Its nodes' sides [h/Mpc].
    nodes: Vec<[f64; 3]>,
    entries: Vec<Entry>,
}

/// The counterterm and stochastic multipoles of a triangle set, planned (module docs).
#[derive(Debug, Clone)]
pub struct CountertermPlan {
    bins: Vec<BinPlan>,
}

/// The multipoles of every shape per bias monomial at one (spectrum, f): [`Self::at`] a bias.
#[derive(Debug, Clone)]
pub struct CountertermTerms {
    values: Vec<[f64; PER_BIN]>,
}

impl CountertermPlan {
    /// Plans `set` (bins: their closed triangles as the direct table's; points: the triangles) with the
    /// Legendre polynomial on `side`.
    ///
    /// # Errors
    /// As [`triangle_vectors`] for a node that does not close; [`Error::InvalidChoice`] for a bin of
    /// more nodes than a plan indexes.
    pub fn new(set: &TriangleSet, side: LegendreSide) -> Result<Self> {
        let bins = (0..set.len())
            .into_par_iter()
            .map(|i| {
                plan_bin(
                    &set.shapes(i, CORRECTION_NODES),
                    set.legendre_index(i, side),
                )
            })
            .collect::<Result<Vec<_>>>()?;
        Ok(Self { bins })
    }

    /// The number of bins (or triangles).
    pub fn len(&self) -> usize {
        self.bins.len()
    }

    /// Whether there is none.
    pub fn is_empty(&self) -> bool {
        self.bins.is_empty()
    }

    /// The multipoles per bias monomial for the linear spectrum `p` at growth rate `f`.
    ///
    /// # Errors
    /// f outside [0, 2].
    pub fn evaluate(&self, p: &LinearSpectrum, f: f64) -> Result<CountertermTerms> {
        crate::cosmology::check_growth_rate(f)?;
        let powers: [f64; MAX_F_POWER + 1] = std::array::from_fn(|m| f.powi(m as i32));
        let values = self
            .bins
            .iter()
            .map(|bin| {
                let mut factors = Vec::with_capacity(bin.nodes.len() * SLOTS + 1);
                for k in &bin.nodes {
                    let pk = k.map(|k| p.eval(k));
                    for i in 0..3 {
                        factors.push(2.0 * pk[i] * pk[(i + 1) % 3]);
                    }
                    factors.extend(pk);
                }
                factors.push(1.0);
                let mut out = [0.0; PER_BIN];
                for e in &bin.entries {
                    out[usize::from(e.out)] +=
                        e.c * powers[usize::from(e.m)] * factors[usize::from(e.slot)];
                }
                out
            })
            .collect();
        Ok(CountertermTerms { values })
    }
}

impl CountertermTerms {
    /// B₀, B₂, B₄ of every shape of every bin at `bias` (its b1, b2, g2), as
    /// [`super::galaxy_counterterms_rsd::redshift_counterterm_multipoles`] gives them.
    pub fn at(&self, bias: &LoopBias) -> Vec<[[f64; N_REDSHIFT_CT]; 3]> {
        let x = [bias.b1, bias.b2, bias.g2];
        let mono: Vec<f64> = MONOMIALS
            .iter()
            .map(|e| (0..3).map(|v| x[v].powi(i32::from(e[v]))).product())
            .collect();
        self.values
            .iter()
            .map(|v| {
                std::array::from_fn(|l| {
                    std::array::from_fn(|s| {
                        let at = (l * N_REDSHIFT_CT + s) * MONOMIALS.len();
                        v[at..at + MONOMIALS.len()]
                            .iter()
                            .zip(&mono)
                            .map(|(c, m)| c * m)
                            .sum()
                    })
                })
            })
            .collect()
    }
}

/// Z₂ of the pair `q` along `n` as a polynomial in f, b1, b2, g2 (and Z₂ at f = 0): affine in the bias,
/// quadratic in f, read from the kernel at the unit biases and f = 0, 1, 2.
fn z2_polys(q: &[[f64; 3]; 2], n: &[f64; 3]) -> Result<(Poly, Poly)> {
    // LoopBias' b1, b2, g2 are its values 0, 1, 2; the polynomial's variables 1, 2, 3
    let unit = |c: Option<usize>| {
        let mut v = [0.0; super::bias_kernels::N_BIAS];
        if let Some(c) = c {
            v[c] = 1.0;
        }
        LoopBias::from_values(v)
    };
    // each kernel once: at no bias and at each unit bias, f = 0, 1, 2
    let redshift = |c| -> Result<[f64; 3]> {
        let b = unit(c);
        Ok([
            galaxy_redshift_kernel(&b, q, 0.0, n)?,
            galaxy_redshift_kernel(&b, q, 1.0, n)?,
            galaxy_redshift_kernel(&b, q, 2.0, n)?,
        ])
    };
    let (base, base_real) = (redshift(None)?, galaxy_kernel(&unit(None), q)?);
    let mut terms = Vec::new();
    let mut real = vec![([0; 4], base_real)];
    for c in [None, Some(0), Some(1), Some(2)] {
        let mut e = [0u8; 4];
        let [z0, z1, z2] = match c {
            None => base,
            Some(c) => {
                e[c + 1] = 1;
                real.push((e, galaxy_kernel(&unit(Some(c)), q)? - base_real));
                let z = redshift(Some(c))?;
                std::array::from_fn(|m| z[m] - base[m])
            }
        };
        // the quadratic in f through f = 0, 1, 2
        for (m, coefficient) in [
            z0,
            (-3.0 * z0 + 4.0 * z1 - z2) / 2.0,
            (z0 - 2.0 * z1 + z2) / 2.0,
        ]
        .into_iter()
        .enumerate()
        {
            let mut e = e;
            e[0] = m as u8;
            terms.push((e, coefficient));
        }
    }
    Ok((Poly::from_terms(terms), Poly::from_terms(real)))
}

/// The plan of one bin of closed triangles `nodes` (sides, weight) with the Legendre side `a`.
fn plan_bin(nodes: &[([f64; 3], f64)], a: usize) -> Result<BinPlan> {
    let n_slots = nodes.len() * SLOTS + 1;
    if n_slots > usize::from(u16::MAX) {
        return Err(Error::InvalidChoice {
            what: format!("a triangle bin of {} closed triangles", nodes.len()),
            reason: "the counterterm plan indexes at most 10922 per bin".into(),
        });
    }
    let (b1, f) = (Poly::var(1), Poly::var(0));
    let (n_mu, n_phi) = ORIENTATION_RULE;
    let orientations = orientation_nodes(n_mu, n_phi);
    let mut entries = Vec::new();
    for (node, (k, w)) in nodes.iter().enumerate() {
        let kv = triangle_vectors(*k)?;
        let (los, weights) = multipole_weights(&orientations, &kv, a)?;
        // [slot][ℓ][shape] summed over the orientations
        let mut acc: Vec<[[Poly; N_REDSHIFT_CT]; 3]> = (0..SLOTS)
            .map(|_| std::array::from_fn(|_| std::array::from_fn(|_| Poly::default())))
            .collect();
        for (n, lw) in los.iter().zip(&weights) {
            let unit = n.map(|x| x / crate::vec3::norm(*n));
            let sight = Sight::new(&kv, &unit);
            for i in 0..3 {
                let (z2, z2_real) = z2_polys(&[kv[i], kv[(i + 1) % 3]], &unit)?;
                let parts = pair_parts(&sight, i, &b1, &f, &z2, &z2_real);
                for (s, part) in parts.into_iter().enumerate() {
                    let slot = if STOCHASTIC_LEGS.contains(&s) {
                        3 + i
                    } else {
                        i
                    };
                    for (l, lw) in lw.iter().enumerate() {
                        let t = std::mem::take(&mut acc[slot][l][s]);
                        acc[slot][l][s] = t + part.clone() * (w * lw);
                    }
                }
            }
        }
        for (slot, ells) in acc.iter().enumerate() {
            for (l, shapes) in ells.iter().enumerate() {
                for (s, poly) in shapes.iter().enumerate() {
                    for (e, c) in poly.terms() {
                        entries.push(entry(l, s, e, node * SLOTS + slot, *c)?);
                    }
                }
            }
        }
        // st_1 = 1: its multipoles are w δ_ℓ0 on the exact rule
        let one: f64 = weights.iter().map(|lw| lw[0]).sum();
        entries.push(entry(0, 6, &[0; 4], n_slots - 1, w * one)?);
    }
    Ok(BinPlan {
        nodes: nodes.iter().map(|(k, _)| *k).collect(),
        entries,
    })
}

/// The entry of ℓ index `l`, shape `s`, monomial `e` and slot.
fn entry(l: usize, s: usize, e: &[u8; 4], slot: usize, c: f64) -> Result<Entry> {
    let mono = MONOMIALS
        .iter()
        .position(|m| m[..] == e[1..])
        .filter(|_| usize::from(e[0]) <= MAX_F_POWER)
        .ok_or_else(|| Error::InvalidChoice {
            what: format!(
                "the monomial f^{} b1^{} b2^{} g2^{} of a counterterm shape",
                e[0], e[1], e[2], e[3]
            ),
            reason: "is not among the plan's (an internal inconsistency)".into(),
        })?;
    Ok(Entry {
        out: ((l * N_REDSHIFT_CT + s) * MONOMIALS.len() + mono) as u16,
        m: e[0],
        slot: slot as u16,
        c,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bispectrum::galaxy_counterterms_rsd::redshift_counterterm_multipoles;

    #[test]
    fn the_plan_gives_the_direct_multipoles_at_any_f_and_bias() {
        let p = LinearSpectrum::gm2012(0.5).unwrap();
        let points = vec![[0.05, 0.07, 0.09], [0.02, 0.1, 0.11], [0.08, 0.08, 0.08]];
        let set = TriangleSet::points(points.clone()).unwrap();
        let plan = CountertermPlan::new(&set, LegendreSide::Largest).unwrap();
        for (f, bias) in [
            (0.0, LoopBias::from_velocileptors(1.8, -0.5, 0.3)),
            (0.74, LoopBias::from_velocileptors(2.1, 0.4, -0.6)),
            (1.3, LoopBias::from_class_pt(1.2, 0.9, 0.2, 0.3)),
        ] {
            let got = plan.evaluate(&p, f).unwrap().at(&bias);
            for (t, g) in points.iter().zip(&got) {
                let want = redshift_counterterm_multipoles(&p, *t, &bias, f, LegendreSide::Largest)
                    .unwrap();
                for l in 0..3 {
                    let scale = want[l].iter().map(|x| x.abs()).fold(0.0, f64::max);
                    for s in 0..N_REDSHIFT_CT {
                        let d = (g[l][s] - want[l][s]).abs();
                        assert!(
                            d <= 1e-11 * scale.max(want[0][s].abs()),
                            "f {f} triangle {t:?} l {l} shape {s}: {} vs {}",
                            g[l][s],
                            want[l][s]
                        );
                    }
                }
            }
        }
    }
}
