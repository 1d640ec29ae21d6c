//! The accumulation of one triangle's (or bin's) multipole coefficients per ℓ, term and bias monomial into
//! [`GalaxyLoopPolynomial`]s: what the multipole tensors' contractions ([`super::multipole_basis`],
//! [`super::multipole_bins`]) add their rows into.

use super::multipole_tensors::Products;
use super::one_loop_galaxy_poly::{GalaxyLoopPolynomial, Monomial, TermPolynomial};

/// The monomials of the seven terms (tree, B₂₂₂, B₃₂₁ᴵ, B₃₂₁ᴵᴵ, B₄₁₁, and the two subtracted amounts, which
/// have B₃₂₁ᴵᴵ's and B₄₁₁'s), in the order of the families' monomial indices, and the ascending order.
pub(super) struct Names {
    monomials: [Vec<Monomial>; 7],
    ascending: [Vec<usize>; 7],
}

impl Names {
    /// The table, made once per process (a constant of the kernels' generated products, which take
    /// ~0.1 ms to list: as much as a few bins' contraction).
    pub(super) fn get() -> &'static Self {
        static NAMES: std::sync::OnceLock<Names> = std::sync::OnceLock::new();
        NAMES.get_or_init(Self::new)
    }

    /// The number of monomials of term `t`.
    pub(super) fn len(&self, t: usize) -> usize {
        self.monomials[t].len()
    }

    fn new() -> Self {
        let pr = Products::new();
        let list = |s: &[Vec<usize>]| -> Vec<Monomial> {
            s.iter()
                .map(|m| [m[0] as u8, m[1] as u8, m[2] as u8])
                .collect()
        };
        let monomials = [
            list(&pr.tree.0),
            list(&pr.b222.0),
            list(&pr.b321.0),
            list(&pr.j.0),
            list(&pr.l.0),
            list(&pr.j.0),
            list(&pr.l.0),
        ];
        let ascending = std::array::from_fn(|t| {
            let mut order: Vec<usize> = (0..monomials[t].len()).collect();
            order.sort_by_key(|&i| monomials[t][i]);
            order
        });
        Self {
            monomials,
            ascending,
        }
    }
}

/// One triangle's coefficients per ℓ, term and monomial: values and rule − half rule.
#[derive(Clone)]
pub(super) struct Acc<'a> {
    names: &'a Names,
    sums: [[Vec<[f64; 2]>; 7]; 3],
}

impl<'a> Acc<'a> {
    pub(super) fn new(names: &'a Names) -> Self {
        Self {
            names,
            sums: std::array::from_fn(|_| {
                std::array::from_fn(|t| vec![[0.0; 2]; names.monomials[t].len()])
            }),
        }
    }

    pub(super) fn add(&mut self, idx: &[u16; 4], term: usize, value: f64, diff: f64) {
        let s = &mut self.sums[idx[0] as usize][term][idx[2] as usize];
        s[0] += value;
        s[1] += diff;
    }

    pub(super) fn polynomial(
        &self,
        ell: usize,
        k: [f64; 3],
        projection: f64,
    ) -> GalaxyLoopPolynomial {
        let term = |t: usize| {
            let order = &self.names.ascending[t];
            let sums = &self.sums[ell][t];
            TermPolynomial {
                monomials: order.iter().map(|&i| self.names.monomials[t][i]).collect(),
                values: order.iter().map(|&i| sums[i][0]).collect(),
                differences: order.iter().map(|&i| sums[i][1]).collect(),
            }
        };
        GalaxyLoopPolynomial {
            k,
            redshift: None,
            tree: term(0),
            b222: term(1),
            b321_i: term(2),
            b321_ii: term(3),
            b411: term(4),
            uv_b321_ii: term(5),
            uv_b411: term(6),
            projection,
        }
    }
}
