//! The TNS A and B coefficients of a new spectrum as contractions on the basis.
//!
//! Each of the 15 coefficients of [`TnsPlan`] (6 of A, 9 of B, at b = 1) is, at each k, a bilinear
//! form of the lattice samples (the P(q)P(|k−q|) kernels) plus, for A, P̃(k) times linear forms (the
//! P(k)P(q) and P(k)P(|k−q|) kernels), all on the P22 nodes of the TNS plan. On the basis they are
//! contractions with c ⊗ c and c (module `forms`), the same nodes and interpolation, so the result
//! is the direct result for the projected spectrum (to ~1e-7: f32 tensors), and differs from `direct`
//! by the response to the projection residual ε. The kernels change sign, so that response is not
//! bounded by ε times the coefficient: it is taken as [`PROJECTION_FACTOR`] ε times the sum of the
//! magnitudes of the coefficient's parts (bilinear, and P(k) times linear). On the three CAMB
//! spectra not trained on (fast precision, 10 k in [0.01, 0.2]) every coefficient is within 1.1e-4
//! of the largest at its k, and within the sum of the two errors. The quadrature error is the plan's fine minus
//! half-resolution difference (the bilinear part of the half-resolution rule on the first
//! [`super::ERROR_FUNCTIONS`] functions) plus the floor of [`Precision::p22_error_floor`].

use super::forms::{
    concat, dot32, dot_f32, fine_and_diff, pair_forms, pair_products_both, per_k, Rows, RuleRows,
};
use super::{error_functions, LinearBasis, Projection, BASIS_SIZE};
use crate::loops::tns::{Rule, A_LEN, B_LEN};
use crate::loops::{Estimate, TnsCoefficients, TnsPlan, TnsTerms};
use crate::precision::Precision;

/// Version of the tensor layout and rules, part of the cache file name.
const VERSION: u32 = 1;

/// Coefficients: A then B.
const COEFFICIENTS: usize = A_LEN + B_LEN;

/// Linear forms per k and rule: A's P(k)P(p) and P(k)P(q) forms (P(k) itself is the spectrum's value,
/// not its projection's: the pointwise residual at one k, up to 1e-3 for CAMB tables, would enter the
/// large P(k) parts of A unsmoothed).
const LINEAR: usize = 2 * A_LEN;

/// The projection error of a coefficient: this times ε times the magnitudes of its parts.
pub const PROJECTION_FACTOR: f64 = 2.0;

/// The TNS basis tensors on one k grid for one [`Precision`] (cosmology independent).
#[derive(Debug, Clone, PartialEq)]
pub struct TnsBasis {
    k: Vec<f64>,
    key: Vec<f64>,
    basis: LinearBasis,
    /// Per k: the 15 bilinear forms of the fine rule on the pairs of all n functions.
    pairs: Vec<f32>,
    /// Per k: fine − half-resolution bilinear forms on the pairs of the first n_err functions.
    pairs_diff: Vec<f32>,
    /// Per k: [`LINEAR`] forms of length n for the fine rule, then for the half-resolution rule.
    linear: Vec<f64>,
    p22_error_floor: f64,
}

/// The settings that make the tensors (their cache key).
fn key(k: &[f64], precision: &Precision) -> Vec<f64> {
    let mut key = vec![f64::from(VERSION), BASIS_SIZE as f64];
    key.extend(precision.one_loop_key());
    key.extend([f64::from(super::training::VERSION), k.len() as f64]);
    key.extend(k);
    key
}

/// The forms of `rule` at k index `i`: the bilinear ones on the first `n` functions, then the
/// [`LINEAR`] linear ones (all functions).
fn forms(rule: &Rule, i: usize, rows: &Rows<'_>, n: usize) -> (Vec<Vec<f64>>, Vec<f64>) {
    let f = pair_forms(
        &rule.nodes,
        i,
        rows,
        n,
        0..COEFFICIENTS,
        COEFFICIENTS..COEFFICIENTS + A_LEN,
        COEFFICIENTS + A_LEN..COEFFICIENTS + 2 * A_LEN,
    );
    let linear: Vec<f64> = f.inner.into_iter().chain(f.outer).flatten().collect();
    (f.pairs, linear)
}

impl TnsBasis {
    /// The cache file name of the tensors for `k` and `precision`.
    pub fn file_name(k: &[f64], precision: &Precision) -> String {
        super::cache_file_name("tns-basis", VERSION, &key(k, precision))
    }

    /// Builds the tensors of `plan` in parallel over k; `progress(done, total)` counts the k values.
    pub fn build(plan: &TnsPlan, progress: &(dyn Fn(usize, usize) + Sync)) -> Self {
        let (k, precision) = (plan.k(), plan.precision());
        let (fine, coarse) = plan.rules();
        let basis = super::training::camb_basis(fine.lattice.clone(), BASIS_SIZE);
        let n = basis.len();
        let n_err = error_functions(n);
        let rows = RuleRows::new(&basis);
        let (fine_rows, coarse_rows) = rows.on(&fine.lattice, &coarse.lattice);
        let per_k = per_k(k.len(), progress, |i| {
            let (f, mut linear) = forms(fine, i, &fine_rows, n);
            let (c, linear_coarse) = forms(coarse, i, &coarse_rows, n_err);
            linear.extend(linear_coarse);
            let (pairs, diff) = fine_and_diff(&f, &c);
            (pairs, diff, linear)
        });
        let (pairs, pairs_diff, linear) = concat(per_k);
        Self {
            k: k.to_vec(),
            key: key(k, precision),
            basis,
            pairs,
            pairs_diff,
            linear,
            p22_error_floor: precision.p22_error_floor,
        }
    }

    /// The wavenumbers [h/Mpc].
    pub fn k(&self) -> &[f64] {
        &self.k
    }

    /// The basis.
    pub fn basis(&self) -> &LinearBasis {
        &self.basis
    }

    /// The TNS coefficients of the spectrum whose values at the grid's k are `p_lin` and whose
    /// projection on the basis is `projection` (the caller decides whether its residual is small
    /// enough).
    pub fn evaluate(&self, p_lin: &[f64], projection: &Projection) -> TnsTerms {
        let c = &projection.coefficients;
        let n = c.len();
        let (pairs, n_err) = (n * (n + 1) / 2, error_functions(n));
        let pairs_err = n_err * (n_err + 1) / 2;
        let (s2, s2_single) = pair_products_both(c);
        let eps = PROJECTION_FACTOR * projection.residual;
        let floor = self.p22_error_floor;
        let coefficients = (0..self.k.len())
            .map(|i| {
                let p_k = p_lin[i];
                // A spectrum cut below the soft modes (module `soft`): the coefficients are
                // infrared safe (measured response ≤ 0.03 k²P|Δ|).
                let soft = projection.soft_response_error(self.k[i], p_k);
                let t = &self.pairs[i * COEFFICIENTS * pairs..][..COEFFICIENTS * pairs];
                let d =
                    &self.pairs_diff[i * COEFFICIENTS * pairs_err..][..COEFFICIENTS * pairs_err];
                let l = &self.linear[i * 2 * LINEAR * n..][..2 * LINEAR * n];
                let form = |rule: usize, m: usize| {
                    let at = (rule * LINEAR + m) * n;
                    crate::simd::dot(&l[at..at + n], c)
                };
                let value = |m: usize| -> Estimate {
                    let bilinear = dot_f32(&t[m * pairs..(m + 1) * pairs], &s2_single);
                    let diff = dot32(&d[m * pairs_err..(m + 1) * pairs_err], &s2[..pairs_err]);
                    let (mut fine, mut coarse) = (bilinear, bilinear - diff);
                    let mut linear = 0.0;
                    if m < A_LEN {
                        linear = p_k * (form(0, m) + form(0, A_LEN + m));
                        fine += linear;
                        coarse += p_k * (form(1, m) + form(1, A_LEN + m));
                    }
                    let projection = eps * (bilinear.abs() + linear.abs()) + soft;
                    Estimate::new(
                        fine,
                        (fine - coarse).abs() + floor * fine.abs() + projection,
                    )
                };
                TnsCoefficients::from_packed(
                    std::array::from_fn(value),
                    std::array::from_fn(|m| value(A_LEN + m)),
                )
            })
            .collect();
        TnsTerms {
            k: self.k.clone(),
            p_lin: p_lin.to_vec(),
            coefficients,
            basis_residual: Some(projection.residual),
            basis_soft: projection.soft_delta(),
        }
    }

    /// The tensors as the values of their cache file.
    pub(crate) fn to_f64s(&self) -> Vec<f64> {
        let mut v = vec![self.key.len() as f64];
        v.extend(&self.key);
        v.extend(self.basis.to_f64s());
        v.extend(self.pairs.iter().map(|&t| f64::from(t)));
        v.extend(self.pairs_diff.iter().map(|&t| f64::from(t)));
        v.extend(&self.linear);
        v
    }

    /// The tensors for `k` and `precision` from the values of their file, or `None` if the file was
    /// made for other settings or does not fit them.
    pub(crate) fn from_f64s(values: &[f64], k: &[f64], precision: &Precision) -> Option<Self> {
        let expected = key(k, precision);
        let rest = super::after_key(values, &expected)?;
        let lattice = super::lattice_of(precision);
        let (basis, rest) = LinearBasis::from_f64s(lattice, rest)?;
        let n = basis.len();
        let n_err = error_functions(n);
        let nk = k.len();
        let sizes = [
            nk * COEFFICIENTS * n * (n + 1) / 2,
            nk * COEFFICIENTS * n_err * (n_err + 1) / 2,
            nk * 2 * LINEAR * n,
        ];
        if rest.len() != sizes.iter().sum::<usize>() {
            return None;
        }
        let (pairs, rest) = rest.split_at(sizes[0]);
        let (pairs_diff, linear) = rest.split_at(sizes[1]);
        let single = |v: &[f64]| v.iter().map(|&t| t as f32).collect();
        Some(Self {
            k: k.to_vec(),
            key: expected,
            basis,
            pairs: single(pairs),
            pairs_diff: single(pairs_diff),
            linear: linear.to_vec(),
            p22_error_floor: precision.p22_error_floor,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::linear::LinearSpectrum;

    fn held_out(i: usize) -> LinearSpectrum {
        let dir = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/data/");
        LinearSpectrum::from_file(format!("{dir}linear_pk_camb_heldout_{i}.dat")).unwrap()
    }

    /// Every (kind, n, m) coefficient of A and B at k index `i`.
    fn all(t: &TnsTerms, i: usize) -> Vec<Estimate> {
        let c = &t.coefficients[i];
        let mut v: Vec<Estimate> = (1..=3)
            .flat_map(|m| (1..=m).map(move |n| (n, m)))
            .map(|(n, m)| c.a(n, m))
            .collect();
        v.extend(
            (2..=4)
                .flat_map(|m| (1..=m).map(move |n| (n, m)))
                .map(|(n, m)| c.b(n, m)),
        );
        v
    }

    #[test]
    fn coefficients_agree_with_direct_for_spectra_not_trained_on_and_survive_their_file() {
        let k: Vec<f64> = (0..10).map(|i| 0.01 * 1.4_f64.powi(i)).collect();
        let plan = TnsPlan::new(&k, &Precision::fast()).unwrap();
        let tensors = TnsBasis::build(&plan, &|_, _| {});
        let basis = tensors.basis();
        let dir = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/data/");
        let curved =
            LinearSpectrum::from_file(format!("{dir}linear_pk_camb_curved_wa_z0.5.dat")).unwrap();
        for (i, p) in (0..3).map(held_out).chain([curved]).enumerate() {
            let direct = plan.evaluate(&p);
            let projection = basis.project_spectrum(&p, super::super::MAX_RESIDUAL);
            assert!(projection.residual < super::super::MAX_RESIDUAL);
            let on_basis = tensors.evaluate(&direct.p_lin, &projection);
            for (j, kj) in k.iter().enumerate() {
                let scale = all(&direct, j)
                    .iter()
                    .map(|e| e.value.abs())
                    .fold(0.0, f64::max);
                for (a, d) in all(&on_basis, j).iter().zip(all(&direct, j)) {
                    let diff = (a.value - d.value).abs();
                    // Within 3e-4 of the largest coefficient at this k (measured 1.1e-4; 1.3e-4
                    // for the curved spectrum, 5e-4 of the coefficient itself), and within the
                    // errors.
                    assert!(diff < 3e-4 * scale, "{i} k={kj}: {a:?} {d:?}");
                    assert!(diff <= a.error + d.error, "{i} k={kj}: {a:?} {d:?}");
                }
            }
        }
        let v = tensors.to_f64s();
        assert_eq!(
            TnsBasis::from_f64s(&v, &k, plan.precision()).unwrap(),
            tensors
        );
        assert!(TnsBasis::from_f64s(&v, &k[1..], plan.precision()).is_none());
    }
}
