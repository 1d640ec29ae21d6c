//! The tensors of one triangle's one-loop galaxy multipoles B₀, B₂, B₄ in redshift space with f free
//! (issue 50): what [`super::multipole_basis`] stores and contracts.
//!
//! [`super::one_loop_galaxy_multipoles`]'s one pass, with every spectrum inside a loop term replaced by
//! P̂ = Σ_a c_a φ_a on m functions (the templates of [`super::multipole_basis`]), and with f kept free: every
//! kernel Z_n^g is a polynomial of degree ≤ n in f, so every term is one of degree ≤ 6 (tree level 4), and the
//! pass runs at the [`F_NODES`] Chebyshev nodes f_j in [0, 2] at once (the kernels' subset fields built once
//! per node, [`loop_kernel_parts_los`]); the seven values of each coefficient give its seven powers of f
//! exactly (the inverse Vandermonde matrix, [`powers`]). The orientation average is done inside the pass
//! (the 45 orientations' weights w_o (2ℓ + 1) L_ℓ applied before the outer products), so per ℓ, bias monomial
//! and power of f the terms are:
//!
//! ```text
//! B₂₂₂:   T_abc c_a c_b c_c                          (packed triples)
//! B₃₂₁ᴵ:  P̂(k_s) M_ab c_a c_b, per side s outside     (packed pairs; Z₁(k_s) inside the orientation sum)
//! B₃₂₁ᴵᴵ: P̂ P̂ (J·c − U σ²), per side s left out       (J: ∫Z₃ with 6 Z₂ Z₁ of the two sides; U: c₃'s)
//! B₄₁₁:   P̂ P̂ (L·c − U σ²), per side s left out       (L: ∫Z₄ with 12 Z₁ Z₁; U: c₄'s)
//! tree:   P P  × a number, per side left out          (exact; the true P at the sides)
//! ```
//!
//! with σ² = s·c. Each is made on the rule and on the rule with half the nodes (the errors, as the direct
//! path's); a power whose coefficients are zero on both is not stored ([`Rows`]).

use super::bias_kernels::{loop_kernel_parts, loop_kernel_parts_los, N_PARTS};
use super::one_loop::{angular_nodes, breaks, partition, radial_nodes, OneLoopRule, Vec3};
use super::one_loop_basis::b222_node;
use super::one_loop_galaxy_basis::slots;
use super::one_loop_galaxy_multipoles::uv_parts_los;
use super::one_loop_galaxy_poly::Layout;
use crate::simd::axpy;
use crate::vec3::{neg, norm, sub};

/// The templates on which the long rows' rule − half rule (the quadrature errors of B₂₂₂ and B₃₂₁ᴵ) are
/// kept: the error of an error, ~1% of it (the leading 8 templates leave ~7e-3 of B).
pub(super) const DIFF_TEMPLATES: usize = 8;

/// The number of nodes in f: a polynomial of degree 6 is fixed by 7 values.
pub(super) const F_NODES: usize = 7;

/// The nodes in f: Chebyshev points of [0, 2] (the growth rates [`crate::cosmology::check_growth_rate`]
/// accepts).
pub(super) fn f_nodes() -> [f64; F_NODES] {
    std::array::from_fn(|j| 1.0 + ((j as f64 + 0.5) * std::f64::consts::PI / F_NODES as f64).cos())
}

/// The matrix A with Σ_j A[p][j] y(f_j) = the coefficient of f^p of the polynomial of degree < 7 through
/// the values y(f_j) at [`f_nodes`]: the inverse of the Vandermonde matrix by Gauss–Jordan elimination
/// with partial pivoting.
pub(super) fn powers() -> [[f64; F_NODES]; F_NODES] {
    let f = f_nodes();
    // [V | I], V[j][p] = f_j^p
    let mut a: Vec<Vec<f64>> = (0..F_NODES)
        .map(|j| {
            let mut row: Vec<f64> = (0..F_NODES).map(|p| f[j].powi(p as i32)).collect();
            row.extend((0..F_NODES).map(|i| f64::from(u8::from(i == j))));
            row
        })
        .collect();
    for col in 0..F_NODES {
        let pivot = (col..F_NODES)
            .max_by(|&x, &y| a[x][col].abs().total_cmp(&a[y][col].abs()))
            .expect("rows");
        a.swap(col, pivot);
        let d = a[col][col];
        a[col].iter_mut().for_each(|x| *x /= d);
        for r in (0..F_NODES).filter(|&r| r != col) {
            let m = a[r][col];
            let pivot_row = a[col].clone();
            a[r].iter_mut()
                .zip(&pivot_row)
                .for_each(|(x, y)| *x -= m * y);
        }
    }
    std::array::from_fn(|p| std::array::from_fn(|j| a[p][F_NODES + j]))
}

/// The monomials and slots of the five products of kernel parts (in the order of their ordered choices,
/// last index fastest; [`slots`]).
pub(super) struct Products {
    pub(super) lay: Layout,
    /// Z₂ Z₂ Z₂ (B₂₂₂).
    pub(super) b222: (Vec<Vec<usize>>, Vec<usize>),
    /// Z₁(k_s) Z₃ Z₂ (B₃₂₁ᴵ).
    pub(super) b321: (Vec<Vec<usize>>, Vec<usize>),
    /// Z₂ Z₁ ∫Z₃ (B₃₂₁ᴵᴵ).
    pub(super) j: (Vec<Vec<usize>>, Vec<usize>),
    /// Z₁ Z₁ ∫Z₄ (B₄₁₁).
    pub(super) l: (Vec<Vec<usize>>, Vec<usize>),
    /// Z₂ Z₁ Z₁ (tree).
    pub(super) tree: (Vec<Vec<usize>>, Vec<usize>),
}

impl Products {
    pub(super) fn new() -> Self {
        let lay = Layout::new(true);
        let [_, s1, s2, s3, s4] = &lay.s;
        Self {
            b222: slots(&[s2, s2, s2]),
            b321: slots(&[s1, s3, s2]),
            j: slots(&[s2, s1, s3]),
            l: slots(&[s1, s1, s4]),
            tree: slots(&[s2, s1, s1]),
            lay,
        }
    }
}

/// One family of a triangle's stored coefficients: per kept row (ℓ, key, monomial, power of f) `len`
/// values on the rule and `len` of rule − half rule, and for B₃₂₁ᴵᴵ, B₄₁₁ the subtracted U.
#[derive(Debug, Clone, PartialEq, Default)]
pub(super) struct Rows {
    /// (ℓ index, key: side, monomial index, power of f) per row.
    pub(super) index: Vec<[u16; 4]>,
    /// Values per row, `len` each.
    pub(super) fine: Vec<f64>,
    /// Rule − half rule per row.
    pub(super) diff: Vec<f64>,
    /// U per row (B₃₂₁ᴵᴵ, B₄₁₁; empty otherwise).
    pub(super) uv: Vec<f64>,
    /// `fine` and `diff` in f32 once [`Rows::make_single`] has moved them there (the long rows of B₂₂₂ and
    /// B₃₂₁ᴵ, read at every evaluation: half the bytes), `diff` on the first [`DIFF_TEMPLATES`] templates;
    /// for B₃₂₁ᴵᴵ and B₄₁₁ renormalised ([`Rows::make_single_renormalised`]).
    pub(super) single: (Vec<f32>, Vec<f32>),
}

impl Rows {
    /// Moves the values to f32 (each entry rounded to 6e-8 of itself), keeping of each row of rule − half
    /// rule (length `len`) its first `diff_len` entries: those on the first [`DIFF_TEMPLATES`] templates.
    pub(super) fn make_single(&mut self, len: usize, diff_len: usize) {
        let single = |v: &[f64]| -> Vec<f32> { v.iter().map(|&x| x as f32).collect() };
        let diff: Vec<f32> = self
            .diff
            .chunks_exact(len)
            .flat_map(|row| single(&row[..diff_len]))
            .collect();
        self.single = (single(&self.fine), diff);
        self.fine.clear();
        self.diff.clear();
    }

    /// [`make_single`](Self::make_single) of B₃₂₁ᴵᴵ's or B₄₁₁'s vectors (length m) renormalised first:
    /// J − U s on the rule and J_diff − U s_diff on rule − half rule (`sigma`: σ²'s vectors), so that f32
    /// rounds the renormalised term, not the bare one that nearly cancels against U σ².
    pub(super) fn make_single_renormalised(&mut self, sigma: &[Vec<f64>; 2]) {
        let m = sigma[0].len();
        for (slot, s) in [(&mut self.fine, &sigma[0]), (&mut self.diff, &sigma[1])] {
            for (row, u) in slot.chunks_exact_mut(m).zip(&self.uv) {
                row.iter_mut().zip(s).for_each(|(j, s)| *j -= u * s);
            }
        }
        self.make_single(m, m);
    }

    /// Keeps the powers of f of `node` (fine) and `half` values laid out [`ells`][key][f node][monomial][len]
    /// whose coefficients are not all zero (relative to the largest of the row's monomial scaled by 2^p).
    fn from_nodes(
        ells: usize,
        keys: usize,
        monos: usize,
        len: usize,
        node: &[f64],
        half: &[f64],
        uv: Option<&[f64]>,
    ) -> Self {
        let a = powers();
        let mut out = Self::default();
        for ell in 0..ells {
            for key in 0..keys {
                for mono in 0..monos {
                    let at = |j: usize, i: usize| {
                        (((ell * keys + key) * F_NODES + j) * monos + mono) * len + i
                    };
                    let power = |src: &[f64], p: usize, i: usize| -> f64 {
                        (0..F_NODES).map(|j| a[p][j] * src[at(j, i)]).sum()
                    };
                    let fine: Vec<Vec<f64>> = (0..F_NODES)
                        .map(|p| (0..len).map(|i| power(node, p, i)).collect())
                        .collect();
                    let diff: Vec<Vec<f64>> = (0..F_NODES)
                        .map(|p| {
                            (0..len)
                                .map(|i| power(node, p, i) - power(half, p, i))
                                .collect()
                        })
                        .collect();
                    let u: Vec<f64> = (0..F_NODES)
                        .map(|p| {
                            uv.map_or(0.0, |u| {
                                (0..F_NODES)
                                    .map(|j| {
                                        a[p][j]
                                            * u[((ell * keys + key) * F_NODES + j) * monos + mono]
                                    })
                                    .sum()
                            })
                        })
                        .collect();
                    let size = |p: usize| {
                        let m = fine[p]
                            .iter()
                            .chain(&diff[p])
                            .fold(u[p].abs(), |m, x| m.max(x.abs()));
                        m * 2f64.powi(p as i32)
                    };
                    let largest = (0..F_NODES).map(size).fold(0.0, f64::max);
                    for p in (0..F_NODES).filter(|&p| size(p) > 1e-11 * largest) {
                        out.index
                            .push([ell as u16, key as u16, mono as u16, p as u16]);
                        out.fine.extend(&fine[p]);
                        out.diff.extend(&diff[p]);
                        if uv.is_some() {
                            out.uv.push(u[p]);
                        }
                    }
                }
            }
        }
        out
    }
}

/// One triangle's stored coefficients (module docs).
#[derive(Debug, Clone, PartialEq)]
pub(super) struct TriangleTensors {
    /// The templates at the three sides, m each.
    pub(super) sides: Vec<f64>,
    /// σ²'s vectors: rule, rule − half rule.
    pub(super) sigma: [Vec<f64>; 2],
    pub(super) b222: Rows,
    pub(super) b321: Rows,
    pub(super) j: Rows,
    pub(super) l: Rows,
    pub(super) tree: Rows,
    /// The tree level per orientation o and side left out t (key 3o + t), without the multipole weights
    /// (the IR resummation's legs depend on the orientation).
    pub(super) tree_o: Rows,
}

/// The orientation-averaged loop sums of one rule at the nodes in f, laid out as [`Rows::from_nodes`]
/// takes them, and σ²'s vector.
struct RuleSums {
    b222: Vec<f64>,
    b321: Vec<f64>,
    j: Vec<f64>,
    l: Vec<f64>,
    sigma: Vec<f64>,
}

/// The inputs of one triangle's build: its vectors, the lines of sight and multipole weights of the
/// orientations, the functions, the products' slots, the nodes in f.
pub(super) struct Setup<'a> {
    pub(super) kv: [Vec3; 3],
    pub(super) los: Vec<Vec3>,
    pub(super) weights: Vec<[f64; 3]>,
    /// The m functions at ln q.
    pub(super) phi: &'a (dyn Fn(f64, &mut [f64]) + Sync),
    pub(super) m: usize,
    pub(super) products: &'a Products,
}

/// One triangle's tensors (module docs).
pub(super) fn triangle_tensors(s: &Setup, rule: &OneLoopRule) -> TriangleTensors {
    let (m, no, fs) = (s.m, s.los.len(), f_nodes());
    let pr = s.products;
    let mut sides = vec![0.0; 3 * m];
    for (v, out) in s.kv.iter().zip(sides.chunks_exact_mut(m)) {
        (s.phi)(norm(*v).ln(), out);
    }
    // Z₁ and Z₂ at the sides per node in f and orientation, and the UV constants
    let z1: Vec<[[f64; N_PARTS]; 3]> = (0..F_NODES * no)
        .map(|i| {
            s.kv.map(|v| loop_kernel_parts(Some((fs[i / no], s.los[i % no])), &[v]))
        })
        .collect();
    let z2: Vec<[[f64; N_PARTS]; 3]> = (0..F_NODES * no)
        .map(|i| {
            let r = Some((fs[i / no], s.los[i % no]));
            // the pair without side t: (a, b) = (t + 1, t + 2)
            std::array::from_fn(|t| loop_kernel_parts(r, &[s.kv[(t + 1) % 3], s.kv[(t + 2) % 3]]))
        })
        .collect();
    let uv: Vec<_> = fs
        .iter()
        .flat_map(|&f| uv_parts_los(f, &s.los, &s.kv, rule))
        .collect();
    let fine = rule_sums(s, rule, &z1);
    let half = rule_sums(s, &rule.half(), &z1);
    let [_, s1, s2, s3, s4] = &pr.lay.s;
    // The tree level, B₃₂₁ᴵᴵ's and B₄₁₁'s factors outside the integrals, per side left out t.
    let (nt, nj, nl) = (pr.tree.0.len(), pr.j.0.len(), pr.l.0.len());
    let mut tree = vec![0.0; 3 * 3 * F_NODES * nt];
    let mut tree_o = vec![0.0; no * 3 * F_NODES * nt];
    let mut j = vec![0.0; 3 * 3 * F_NODES * nj * m];
    let mut jh = j.clone();
    let mut l = vec![0.0; 3 * 3 * F_NODES * nl * m];
    let mut lh = l.clone();
    let (mut uj, mut ul) = (
        vec![0.0; 3 * 3 * F_NODES * nj],
        vec![0.0; 3 * 3 * F_NODES * nl],
    );
    for (i, (w, (z1, z2))) in (0..F_NODES * no)
        .map(|i| (s.weights[i % no], (&z1[i], &z2[i])))
        .enumerate()
    {
        let (jn, o) = (i / no, i % no);
        let (c3, c4) = &uv[i];
        for t in 0..3 {
            let (a, b) = ((t + 1) % 3, (t + 2) % 3);
            let mut slot = pr.tree.1.iter();
            for &pi in s2 {
                for &pl in s1 {
                    for &pm in s1 {
                        let v = 2.0 * z2[t][pi] * z1[a][pl] * z1[b][pm];
                        let mono = *slot.next().expect("slots");
                        for (ell, w) in w.iter().enumerate() {
                            tree[((ell * 3 + t) * F_NODES + jn) * nt + mono] += w * v;
                        }
                        tree_o[((o * 3 + t) * F_NODES + jn) * nt + mono] += v;
                    }
                }
            }
            // B₃₂₁ᴵᴵ: 6 Z₂(k_a, k_b) Z₁(k_b) [J_a − c₃(k_a) σ²], both orders (a, b) of the pair
            for (a, b) in [(a, b), (b, a)] {
                let mut slot = pr.j.1.iter();
                for &pi in s2 {
                    for &pl in s1 {
                        let c = 6.0 * z2[t][pi] * z1[b][pl];
                        for (mi, &pm) in s3.iter().enumerate() {
                            let mono = *slot.next().expect("slots");
                            let src = ((o * F_NODES + jn) * 3 + a) * s3.len() + mi;
                            for (ell, w) in w.iter().enumerate() {
                                let row = ((ell * 3 + t) * F_NODES + jn) * nj + mono;
                                uj[row] += w * c * c3[a][pm];
                                axpy(
                                    &mut j[row * m..(row + 1) * m],
                                    w * c,
                                    &fine.j[src * m..(src + 1) * m],
                                );
                                axpy(
                                    &mut jh[row * m..(row + 1) * m],
                                    w * c,
                                    &half.j[src * m..(src + 1) * m],
                                );
                            }
                        }
                    }
                }
            }
            // B₄₁₁: 12 Z₁(k_a) Z₁(k_b) [L_t − c₄(k_t) σ²]
            let mut slot = pr.l.1.iter();
            for &pa in s1 {
                for &pb in s1 {
                    let c = 12.0 * z1[a][pa] * z1[b][pb];
                    for (mi, &pm) in s4.iter().enumerate() {
                        let mono = *slot.next().expect("slots");
                        let src = ((o * F_NODES + jn) * 3 + t) * s4.len() + mi;
                        for (ell, w) in w.iter().enumerate() {
                            let row = ((ell * 3 + t) * F_NODES + jn) * nl + mono;
                            ul[row] += w * c * c4[t][pm];
                            axpy(
                                &mut l[row * m..(row + 1) * m],
                                w * c,
                                &fine.l[src * m..(src + 1) * m],
                            );
                            axpy(
                                &mut lh[row * m..(row + 1) * m],
                                w * c,
                                &half.l[src * m..(src + 1) * m],
                            );
                        }
                    }
                }
            }
        }
    }
    let pairs = m * (m + 1) / 2;
    let triples = m * (m + 1) * (m + 2) / 6;
    TriangleTensors {
        sides,
        sigma: [
            fine.sigma.clone(),
            fine.sigma
                .iter()
                .zip(&half.sigma)
                .map(|(a, b)| a - b)
                .collect(),
        ],
        b222: Rows::from_nodes(3, 1, pr.b222.0.len(), triples, &fine.b222, &half.b222, None),
        b321: Rows::from_nodes(3, 3, pr.b321.0.len(), pairs, &fine.b321, &half.b321, None),
        j: Rows::from_nodes(3, 3, nj, m, &j, &jh, Some(&uj)),
        l: Rows::from_nodes(3, 3, nl, m, &l, &lh, Some(&ul)),
        tree: Rows::from_nodes(3, 3, nt, 1, &tree, &tree, None),
        tree_o: Rows::from_nodes(1, 3 * no, nt, 1, &tree_o, &tree_o, None),
    }
}

/// The loop sums of one rule (module docs): B₂₂₂'s packed triples and B₃₂₁ᴵ's packed pairs per
/// [ℓ][side][f node][monomial], the ∫Z₃ (J) and ∫Z₄ (L) vectors per [orientation][f node][side][part],
/// σ²'s vector.
fn rule_sums(s: &Setup, rule: &OneLoopRule, z1: &[[[f64; N_PARTS]; 3]]) -> RuleSums {
    let (m, no, fs, pr) = (s.m, s.los.len(), f_nodes(), s.products);
    let [_, s1, s2, s3, s4] = &pr.lay.s;
    let (n222, n321) = (pr.b222.0.len(), pr.b321.0.len());
    let kv = &s.kv;
    let radial = radial_nodes(rule, &breaks(&kv.map(norm)));
    let angular = angular_nodes(rule, false);
    let angular_sum: f64 = angular.iter().map(|(_, w)| w).sum();
    let nfo = F_NODES * no;
    let parts =
        |q: &[Vec3], out: &mut Vec<[f64; N_PARTS]>| loop_kernel_parts_los(&fs, &s.los, q, out);
    let (mut x, mut y, mut z) = (
        vec![[0.0; N_PARTS]; nfo],
        vec![[0.0; N_PARTS]; nfo],
        vec![[0.0; N_PARTS]; nfo],
    );
    let c222 = 3 * F_NODES * n222;
    let c321 = 3 * 3 * F_NODES * n321;
    let mut t222 = vec![0.0; c222 * m * m * m];
    let mut m321 = vec![0.0; c321 * m * m];
    let (nj, nl) = (nfo * 3 * s3.len(), nfo * 3 * s4.len());
    let (mut j, mut l) = (vec![0.0; nj * m], vec![0.0; nl * m]);
    let mut sigma = vec![0.0; m];
    let (mut phi_p, mut phx, mut phy) = (vec![0.0; m], vec![0.0; m], vec![0.0; m]);
    let mut mm = vec![0.0; c222 * m * m];
    let mut u = vec![0.0; c321 * m];
    let mut w222 = vec![0.0; c222];
    let mut w321 = vec![0.0; c321];
    let mut tmp = vec![0.0; n222.max(n321)];
    for &(p, wp) in &radial {
        (s.phi)(p.ln(), &mut phi_p);
        axpy(&mut sigma, wp * angular_sum, &phi_p);
        for piece in 0..3 {
            mm.iter_mut().for_each(|v| *v = 0.0);
            let (ix, iy) = [(1, 2), (0, 2), (0, 1)][piece];
            for &(unit, wu) in &angular {
                let (q, a, b, r) = b222_node(piece, unit.map(|c| c * p), kv[0], kv[1]);
                let sc = 8.0 * wu * partition(&r, piece);
                parts(&[neg(q), a], &mut x);
                parts(&[neg(a), neg(b)], &mut y);
                parts(&[b, q], &mut z);
                w222.iter_mut().for_each(|v| *v = 0.0);
                for i in 0..nfo {
                    let (jn, o) = (i / no, i % no);
                    tmp[..n222].iter_mut().for_each(|v| *v = 0.0);
                    let mut slot = pr.b222.1.iter();
                    for &pa in s2 {
                        let xa = x[i][pa];
                        for &pb in s2 {
                            let xy = xa * y[i][pb];
                            for &pc in s2 {
                                tmp[*slot.next().expect("slots")] += xy * z[i][pc];
                            }
                        }
                    }
                    for (ell, w) in s.weights[o].iter().enumerate() {
                        let row = &mut w222[(ell * F_NODES + jn) * n222..][..n222];
                        axpy(row, *w, &tmp[..n222]);
                    }
                }
                (s.phi)(r[ix].ln(), &mut phx);
                (s.phi)(r[iy].ln(), &mut phy);
                for (block, &wc) in mm.chunks_exact_mut(m * m).zip(&w222) {
                    if wc != 0.0 {
                        for (row, &xa) in block.chunks_exact_mut(m).zip(&phx) {
                            axpy(row, sc * wc * xa, &phy);
                        }
                    }
                }
            }
            for (t, block) in t222.chunks_exact_mut(m * m * m).zip(mm.chunks_exact(m * m)) {
                for (slab, &pa) in t.chunks_exact_mut(m * m).zip(&phi_p) {
                    axpy(slab, wp * pa, block);
                }
            }
        }
        // B₃₂₁ᴵ (twice the piece about q = 0), and the ∫Z₃, ∫Z₄ of B₃₂₁ᴵᴵ and B₄₁₁, whose radius is |q|.
        u.iter_mut().for_each(|v| *v = 0.0);
        let mut sj = vec![0.0; nj];
        let mut sl = vec![0.0; nl];
        for &(unit, wu) in &angular {
            let v = unit.map(|c| c * p);
            for b in 0..3 {
                let d = sub(kv[b], v);
                let r = [p, norm(d)];
                let leg = 12.0 * wu * partition(&r, 0);
                parts(&[v, d], &mut y);
                (s.phi)(r[1].ln(), &mut phx);
                w321.iter_mut().for_each(|v| *v = 0.0);
                for a in (0..3).filter(|&a| a != b) {
                    parts(&[neg(v), neg(d), neg(kv[a])], &mut x);
                    for i in 0..nfo {
                        let (jn, o) = (i / no, i % no);
                        tmp[..n321].iter_mut().for_each(|v| *v = 0.0);
                        let mut slot = pr.b321.1.iter();
                        for &pl in s1 {
                            let za = z1[i][a][pl];
                            for &pi in s3 {
                                let zx = za * x[i][pi];
                                for &pj in s2 {
                                    tmp[*slot.next().expect("slots")] += zx * y[i][pj];
                                }
                            }
                        }
                        for (ell, w) in s.weights[o].iter().enumerate() {
                            let row = &mut w321[((ell * 3 + a) * F_NODES + jn) * n321..][..n321];
                            axpy(row, *w, &tmp[..n321]);
                        }
                    }
                }
                for (us, &wc) in u.chunks_exact_mut(m).zip(&w321) {
                    if wc != 0.0 {
                        axpy(us, leg * wc, &phx);
                    }
                }
            }
            for a in 0..3 {
                let (b, c) = ((a + 1) % 3, (a + 2) % 3);
                parts(&[v, neg(v), neg(kv[b]), neg(kv[c])], &mut x);
                parts(&[kv[a], v, neg(v)], &mut y);
                for i in 0..nfo {
                    let (jn, o) = (i / no, i % no);
                    let at = ((o * F_NODES + jn) * 3 + a) * s4.len();
                    for (acc, &pi) in sl[at..at + s4.len()].iter_mut().zip(s4.iter()) {
                        *acc += wu * x[i][pi];
                    }
                    let at = ((o * F_NODES + jn) * 3 + a) * s3.len();
                    for (acc, &pi) in sj[at..at + s3.len()].iter_mut().zip(s3.iter()) {
                        *acc += wu * y[i][pi];
                    }
                }
            }
        }
        for (block, us) in m321.chunks_exact_mut(m * m).zip(u.chunks_exact(m)) {
            for (row, &pc) in block.chunks_exact_mut(m).zip(&phi_p) {
                axpy(row, wp * pc, us);
            }
        }
        for (v, &w) in j.chunks_exact_mut(m).zip(&sj) {
            axpy(v, wp * w, &phi_p);
        }
        for (v, &w) in l.chunks_exact_mut(m).zip(&sl) {
            axpy(v, wp * w, &phi_p);
        }
    }
    let pack3 = |t: &[f64]| crate::loops::basis::pack_triples(t, m);
    let pack2 = |t: &[f64]| crate::loops::basis::pack_pairs(t, m);
    RuleSums {
        b222: t222.chunks_exact(m * m * m).flat_map(pack3).collect(),
        b321: m321.chunks_exact(m * m).flat_map(pack2).collect(),
        j,
        l,
        sigma,
    }
}
