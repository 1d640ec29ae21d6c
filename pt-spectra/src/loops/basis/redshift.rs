//! The terms of the galaxy model in redshift space ([`RedshiftPlan`], the `ept` model) of a new
//! spectrum as contractions on the basis.
//!
//! The 31 pair columns are bilinear forms of the lattice samples on the plan's P22 nodes, the six
//! lattice-weight terms (P13 of F₃ and G₃, sig3nl, the three line-of-sight terms) P(k) times linear
//! forms, σ_v² a linear form: on the basis, contractions with c ⊗ c and c (module `forms`), the same
//! nodes and interpolation as the direct plan, so the only difference from `direct` (beside the
//! low-rank form of the pair columns, whose bound is added to their errors: module `low_rank`) is
//! the response to the projection residual ε, added to the errors as 2ε|T| for the pair columns and
//! ε P(k) Σ|w|P̂ for the others. The quadrature error is the plan's (fine minus half-resolution, the
//! bilinear part of the half-resolution rule on the first [`super::ERROR_FUNCTIONS`] functions). With
//! IR resummation the no-wiggle spectrum is projected too; its terms carry the errors of the full
//! ones (as in the direct plan) plus its own projection error.
//!
//! The no-wiggle spectrum of the galaxy model is a fixed linear filter of P on a log grid
//! ([`crate::ir::savitzky_golay_no_wiggle`]); on the lattice it is linear in the samples, so the
//! no-wiggle part of P = Σ c_a φ_a is Σ c_a S[φ_a]. The [`RedshiftFamily::FilteredNoWiggle`]
//! tensors are therefore those of the filtered basis functions S[φ_a], contracted with the
//! spectrum's own coefficients: one projection, no filter and no second basis per spectrum.
//!
//! The 2-loop redshift-space models (`spt2`, `eft2`) take their 1-loop terms from these tensors
//! too: on the CAMB basis for the linear spectrum and, for the no-wiggle spectrum of their IR split
//! (not a linear filter), on the split training set's basis ([`RedshiftFamily::SplitNoWiggle`]),
//! with the projections their 2-loop tensors already made.

use super::forms::{
    concat, linear_form, pair_forms, pair_products, pair_products_both, per_k, RuleRows,
};
use super::low_rank::{LowRank, PAIR_TOLERANCE};
use super::thin::Thinning;
use super::{error_functions, LinearBasis, Projection, BASIS_SIZE};
use crate::loops::redshift::{RedshiftPlan, RedshiftTerms, Row, NPAIR};
use crate::loops::Estimate;
use crate::precision::Precision;

/// Version of the tensor layout and rules, part of the cache file name.
const VERSION: u32 = 4;

/// Lattice-weight terms per k.
const LW: usize = 6;

/// Linear forms per k: the six lattice-weight terms of the fine rule, of the half-resolution rule,
/// and with absolute weights (the projection error's scale).
const LINEAR: usize = 3 * LW;

/// Which spectra basis tensors are for: linear spectra (the shipped CAMB training set), or their
/// no-wiggle parts. The real-space and 2-loop bases take the latter on a basis of their own (the
/// training set through the no-wiggle filter: those are not in the span of the linear basis, their
/// smoothed tails differ by ~1e-2). [`RedshiftBasis`] has families of its own ([`RedshiftFamily`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SpectrumFamily {
    /// Linear spectra.
    Linear,
    /// No-wiggle parts of linear spectra.
    NoWiggle,
}

/// Which spectra a [`RedshiftBasis`] is for, and how its functions are read.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum RedshiftFamily {
    /// Linear spectra, on the functions of the given basis (the CAMB training set's).
    Linear,
    /// The galaxy model's no-wiggle parts ([`crate::ir::savitzky_golay_no_wiggle`], linear in P):
    /// the filtered functions S\[φ_a\] of the given linear basis, contracted with the spectrum's own
    /// coefficients (module docs).
    FilteredNoWiggle,
    /// The no-wiggle parts of the IR split ([`crate::ir::WiggleSplit`], not linear in P) of the
    /// 2-loop redshift-space models: the functions of the given basis, the training set through the
    /// split (as the 2-loop tensors of [`SpectrumFamily::NoWiggle`]), on which the no-wiggle spectrum
    /// is projected itself.
    SplitNoWiggle,
}

impl RedshiftFamily {
    fn tag(self) -> &'static str {
        match self {
            Self::Linear => "lin",
            Self::FilteredNoWiggle => "nw",
            Self::SplitNoWiggle => "splitnw",
        }
    }

    /// Its code in the cache key (0 and 1 as before the split family existed).
    fn code(self) -> f64 {
        match self {
            Self::Linear => 0.0,
            Self::FilteredNoWiggle => 1.0,
            Self::SplitNoWiggle => 2.0,
        }
    }
}

/// The redshift-space basis tensors on one k grid for one [`Precision`] (cosmology independent).
#[derive(Debug, Clone, PartialEq)]
pub struct RedshiftBasis {
    k: Vec<f64>,
    key: Vec<f64>,
    basis: LinearBasis,
    /// On a dense log-uniform grid, the tensors are made at every other k and the rows interpolated
    /// between (module `thin`); `None`: at every k. Below, "per k" means per node.
    thin: Option<Thinning>,
    /// Per k and pair column: the bound of the low-rank truncation per unit of
    /// [`LowRank::norm`] (the low-rank form's own at the nodes, carried to every k).
    truncation: Vec<f64>,
    /// The pair columns of the fine rule on the pairs of all n functions, row k × column, in
    /// low-rank form ([`LowRank`]: its truncation bound is added to the errors).
    pairs: LowRank,
    /// Per k: fine − half-resolution pair columns on the pairs of the first n_err functions (the
    /// quadrature error estimate; not of low rank).
    pairs_diff: Vec<f32>,
    /// Per k: [`LINEAR`] forms of length n.
    linear: Vec<f64>,
    /// σ_v²: the fine form and fine − coarse.
    sigma_v2: Vec<f64>,
    p22_error_floor: f64,
}

/// The settings that make the tensors (their cache key).
fn key(k: &[f64], precision: &Precision, family: RedshiftFamily) -> Vec<f64> {
    let mut key = vec![
        f64::from(VERSION),
        family.code(),
        BASIS_SIZE as f64,
        NPAIR as f64,
    ];
    key.extend(precision.one_loop_key());
    key.extend([f64::from(super::training::VERSION), k.len() as f64]);
    key.extend(k);
    key
}

/// [`RedshiftBasis::truncation`] of the low-rank form `pairs` (rows per node × pair column).
fn truncation_on_grid(pairs: &LowRank, thin: Option<&Thinning>) -> Vec<f64> {
    let at_nodes: Vec<f64> = (0..pairs.rows()).map(|row| pairs.bound(row, 1.0)).collect();
    match thin {
        Some(t) => t.sizes(&at_nodes, NPAIR),
        None => at_nodes,
    }
}

impl RedshiftBasis {
    /// The cache file name of the tensors for `k`, `precision` and `family`.
    pub fn file_name(k: &[f64], precision: &Precision, family: RedshiftFamily) -> String {
        let prefix = format!("redshift-basis-{}", family.tag());
        super::cache_file_name(&prefix, VERSION, &key(k, precision, family))
    }

    /// Builds the tensors of `plan` on `basis` (on the plan's lattice; for
    /// [`RedshiftFamily::FilteredNoWiggle`] on its filtered functions) in parallel over k;
    /// `progress(done, total)` counts the k values.
    pub fn build(
        plan: &RedshiftPlan,
        family: RedshiftFamily,
        basis: LinearBasis,
        progress: &(dyn Fn(usize, usize) + Sync),
    ) -> Self {
        let (k, precision) = (plan.k(), plan.precision());
        let (fine, coarse) = plan.rules();
        let n = basis.len();
        let n_err = error_functions(n);
        let rows = match family {
            RedshiftFamily::Linear | RedshiftFamily::SplitNoWiggle => RuleRows::new(&basis),
            RedshiftFamily::FilteredNoWiggle => {
                let step = fine.lattice.step;
                let filter = |f: &[f64]| crate::savgol::no_wiggle_samples(f, step);
                RuleRows::from_rows(basis.transformed_rows(&filter), n)
            }
        };
        let (fine_rows, coarse_rows) = rows.on(&fine.lattice, &coarse.lattice);
        let thin = Thinning::of(k);
        let nodes: Vec<usize> = match &thin {
            Some(t) => t.nodes().to_vec(),
            None => (0..k.len()).collect(),
        };
        let per_k = per_k(nodes.len(), progress, |j| {
            let i = nodes[j];
            let f = pair_forms(&fine.pairs, i, &fine_rows, n, 0..NPAIR, 0..0, 0..0).pairs;
            let c = pair_forms(&coarse.pairs, i, &coarse_rows, n_err, 0..NPAIR, 0..0, 0..0);
            let pairs: Vec<f64> = f.concat();
            let diff: Vec<f32> = f
                .iter()
                .zip(&c.pairs)
                .flat_map(|(f, c)| f.iter().zip(c).map(|(f, c)| (f - c) as f32))
                .collect();
            let mut linear = Vec::with_capacity(LINEAR * n);
            for w in &fine.lattice_weights[i] {
                linear.extend(linear_form(w, &fine_rows));
            }
            for w in &coarse.lattice_weights[i] {
                linear.extend(linear_form(w, &coarse_rows));
            }
            for w in &fine.lattice_weights[i] {
                let abs: Vec<f64> = w.iter().map(|v| v.abs()).collect();
                linear.extend(linear_form(&abs, &fine_rows));
            }
            (pairs, diff, linear)
        });
        let sv_fine = linear_form(&fine.sigma_v2, &fine_rows);
        let sv_coarse = linear_form(&coarse.sigma_v2, &coarse_rows);
        let mut sigma_v2 = sv_fine.clone();
        sigma_v2.extend(sv_fine.iter().zip(&sv_coarse).map(|(f, c)| f - c));
        let (pairs, pairs_diff, linear) = concat(per_k);
        let sigma = super::training::coefficient_scale(&basis);
        let pairs = LowRank::new(&pairs, nodes.len() * NPAIR, 2, &sigma, PAIR_TOLERANCE);
        Self {
            k: k.to_vec(),
            key: key(k, precision, family),
            basis,
            truncation: truncation_on_grid(&pairs, thin.as_ref()),
            thin,
            pairs,
            pairs_diff,
            linear,
            sigma_v2,
            p22_error_floor: precision.p22_error_floor,
        }
    }

    /// The basis.
    pub fn basis(&self) -> &LinearBasis {
        &self.basis
    }

    /// Whether the tensors sit on every other k of the grid (module `thin`).
    pub fn is_thinned(&self) -> bool {
        self.thin.is_some()
    }

    /// The rows (pair columns and lattice-weight terms with errors) and σ_v² of the spectrum with
    /// P_lin = `p_lin` at the grid's k and projection `projection`; the pair columns' quadrature
    /// error only if `quadrature` (the no-wiggle terms take the full ones' errors instead).
    fn rows(
        &self,
        p_lin: &[f64],
        projection: &Projection,
        quadrature: bool,
    ) -> (Vec<Row>, Estimate) {
        let c = &projection.coefficients;
        let n = c.len();
        let pairs_err = error_functions(n) * (error_functions(n) + 1) / 2;
        let (s2, s2_single) = pair_products_both(c);
        let values = self.pairs.apply(&s2);
        let diffs = quadrature.then(|| {
            let mut diffs = vec![0.0; values.len()];
            crate::simd::matvec_f32(&self.pairs_diff, &s2_single[..pairs_err], &mut diffs);
            diffs
        });
        let mut forms = vec![0.0; self.linear.len() / n];
        crate::simd::matvec(&self.linear, c, &mut forms);
        let norm = self.pairs.norm(c);
        // on a thinned grid, every k from the nodes, with the interpolation's error estimate
        let (values, values_err, diffs, forms, forms_err) = match &self.thin {
            Some(t) => {
                let (values, values_err) = t.interpolate(&values, NPAIR, NPAIR);
                let (forms, forms_err) = t.interpolate(&forms, LINEAR, LW);
                let diffs = diffs.map(|d| t.values(&d, NPAIR));
                (values, Some(values_err), diffs, forms, Some(forms_err))
            }
            None => (values, None, diffs, forms, None),
        };
        let at = |v: &Option<Vec<f64>>, i: usize| v.as_ref().map_or(0.0, |v| v[i]);
        let eps = projection.residual;
        let floor = self.p22_error_floor;
        // A spectrum cut below the soft modes (module `soft`): every column and σ_v² are the cut
        // spectrum's, so that the terms (infrared-safe sums) are the whole one's up to (q/k)².
        let rows = p_lin
            .iter()
            .enumerate()
            .map(|(i, &p)| {
                let soft = projection.soft_response_error(self.k[i], p);
                let form = |m: usize| forms[i * LINEAR + m];
                let pair = std::array::from_fn(|m| {
                    let row = i * NPAIR + m;
                    let (a, diff) = (values[row], at(&diffs, row));
                    let quadrature = diff.abs().max(floor * a.abs());
                    let truncation = self.truncation[row] * norm;
                    let error = quadrature + 2.0 * eps * a.abs() + truncation + soft;
                    Estimate::new(a, error + at(&values_err, row))
                });
                let lw = std::array::from_fn(|m| {
                    let (s, sc, abs) = (form(m), form(LW + m), form(2 * LW + m));
                    let thinning = p.abs() * at(&forms_err, i * LW + m);
                    let error = (p * (s - sc)).abs() + eps * (p * abs).abs() + soft;
                    Estimate::new(p * s, error + thinning)
                });
                (pair, lw)
            })
            .collect();
        let sv = crate::simd::dot(&self.sigma_v2[..n], c);
        let sv_diff = crate::simd::dot(&self.sigma_v2[n..], c);
        (rows, Estimate::new(sv, sv_diff.abs() + eps * sv.abs()))
    }

    /// [`Self::rows`]' values alone, every error NaN (not estimated): the chain step's path, which
    /// reads no error. It skips the pair tensors' quadrature differences, the forms of the errors,
    /// the thinning's error interpolation and the truncation bounds (a third of the terms' cost).
    fn row_values(&self, p_lin: &[f64], c: &[f64]) -> (Vec<Row>, Estimate) {
        let values = self.at_grid(self.pairs.apply(&pair_products(c)), NPAIR);
        let forms = self.value_forms(c);
        let unknown = |v: f64| Estimate::new(v, f64::NAN);
        let rows = p_lin
            .iter()
            .enumerate()
            .map(|(i, &p)| {
                let pair = std::array::from_fn(|m| unknown(values[i * NPAIR + m]));
                let lw = std::array::from_fn(|m| unknown(p * forms[i * LINEAR + m]));
                (pair, lw)
            })
            .collect();
        let sv = crate::simd::dot(&self.sigma_v2[..c.len()], c);
        (rows, unknown(sv))
    }

    /// The forms of the values of `c` (the first LW of each k's LINEAR; the others, of the errors,
    /// left 0) at every k of the grid.
    fn value_forms(&self, c: &[f64]) -> Vec<f64> {
        let n = c.len();
        let mut forms = vec![0.0; self.linear.len() / n];
        for (d, l) in forms
            .chunks_exact_mut(LINEAR)
            .zip(self.linear.chunks_exact(LINEAR * n))
        {
            crate::simd::matvec(&l[..LW * n], c, &mut d[..LW]);
        }
        self.at_grid(forms, LINEAR)
    }

    /// The P13-type forms of `c` at every k and σ_v² of `c`: what [`Self::rows_tangent`] needs of
    /// the spectrum itself (the same for every direction).
    fn tangent_base(&self, c: &[f64]) -> (Vec<f64>, f64) {
        (
            self.value_forms(c),
            crate::simd::dot(&self.sigma_v2[..c.len()], c),
        )
    }

    /// Values given per node, `width` per node, at every k of the grid (the identity unless the
    /// grid is thinned): a fixed linear map, so tangents go through it exactly.
    fn at_grid(&self, at_nodes: Vec<f64>, width: usize) -> Vec<f64> {
        match &self.thin {
            Some(t) => t.values(&at_nodes, width),
            None => at_nodes,
        }
    }

    /// The tangent of [`Self::rows`]' values along (`dp_lin`, `dc`) at (`p_lin`, c): `values`, the
    /// pair rows' tangent ([`Self::pair_tangents`]: the tensors on c_a dc_b + dc_a c_b); the
    /// P13-type rows P_lin times a linear form of c by the product rule (`base`: the forms of c and
    /// σ_v², [`Self::tangent_base`]); dσ_v² and the tangent of σ_v² P_lin at every k. Exact (all are
    /// polynomials in (P_lin, c)); the errors are zero.
    fn rows_tangent(
        &self,
        values: &[f64],
        (forms, sv): (&[f64], f64),
        (p_lin, dp_lin): (&[f64], &[f64]),
        dc: &[f64],
    ) -> (Vec<Row>, Estimate, Vec<Estimate>) {
        let n = dc.len();
        let dforms = self.value_forms(dc);
        let exact = |v: f64| Estimate::new(v, 0.0);
        let rows = p_lin
            .iter()
            .zip(dp_lin)
            .enumerate()
            .map(|(i, (&p, &dp))| {
                let pair = std::array::from_fn(|m| exact(values[i * NPAIR + m]));
                let lw = std::array::from_fn(|m| {
                    let at = i * LINEAR + m;
                    exact(dp * forms[at] + p * dforms[at])
                });
                (pair, lw)
            })
            .collect();
        // (σ_v² P)' = δσ_v² P + σ_v² δP
        let dsv = crate::simd::dot(&self.sigma_v2[..n], dc);
        let sv_p = p_lin
            .iter()
            .zip(dp_lin)
            .map(|(p, dp)| exact(dsv * p + sv * dp))
            .collect();
        (rows, exact(dsv), sv_p)
    }

    /// The pair rows' tangents along every direction `dcs` at `c`: the tensors applied to the
    /// symmetric products c_a dc_b + dc_a c_b ([`LowRank::apply_pair_tangents`]: the reduction's
    /// Jacobian in c made once, U read once for all directions).
    fn pair_tangents(&self, c: &[f64], dcs: &[&[f64]]) -> Vec<Vec<f64>> {
        let at_nodes = self.pairs.apply_pair_tangents(c, dcs);
        at_nodes
            .into_iter()
            .map(|v| self.at_grid(v, NPAIR))
            .collect()
    }

    /// The tangents of [`Self::evaluate_with_no_wiggle`]'s two sets of terms at (`p_lin`, `p_nw`,
    /// `c`) along the directions (`dp_lin[j]`, `dp_nw[j]`, `dcs[j]`), both families sharing the
    /// coefficients c of the spectrum's projection (`no_wiggle: None` without IR resummation).
    #[allow(clippy::type_complexity)]
    pub fn evaluate_tangents(
        &self,
        plan: &RedshiftPlan,
        (p_lin, dp_lin): (&[f64], &[&[f64]]),
        no_wiggle: Option<(&RedshiftBasis, &[f64], &[&[f64]])>,
        (c, dcs): (&[f64], &[&[f64]]),
    ) -> Vec<(RedshiftTerms, Option<RedshiftTerms>)> {
        let full_pairs = self.pair_tangents(c, dcs);
        let full_base = self.tangent_base(c);
        let nw = no_wiggle
            .map(|(t, p_nw, dp_nw)| (t, p_nw, dp_nw, t.pair_tangents(c, dcs), t.tangent_base(c)));
        (0..dcs.len())
            .map(|j| {
                let base = (full_base.0.as_slice(), full_base.1);
                let (rows, dsv, sv_p) =
                    self.rows_tangent(&full_pairs[j], base, (p_lin, dp_lin[j]), dcs[j]);
                let full = plan.assemble_rows_with(dp_lin[j].to_vec(), &rows, dsv, &sv_p);
                let nw = nw.as_ref().map(|(t, p_nw, dp_nw, pairs, (forms, sv))| {
                    let (rows, dsv, sv_p) =
                        t.rows_tangent(&pairs[j], (forms, *sv), (p_nw, dp_nw[j]), dcs[j]);
                    plan.assemble_rows_with(dp_nw[j].to_vec(), &rows, dsv, &sv_p)
                });
                (full, nw)
            })
            .collect()
    }

    /// The terms of `plan` (whose tensors these are) for the spectrum with P_lin = `p_lin` at the
    /// grid's k and projection `projection`.
    pub fn evaluate(
        &self,
        plan: &RedshiftPlan,
        p_lin: &[f64],
        projection: &Projection,
    ) -> RedshiftTerms {
        let (rows, sigma_v2) = self.rows(p_lin, projection, true);
        plan.assemble_rows(p_lin.to_vec(), &rows, sigma_v2)
    }

    /// [`Self::evaluate_with_no_wiggle`]'s values alone, every error NaN (not estimated):
    /// the chain step's terms; `no_wiggle` `None` for [`Self::evaluate`]'s.
    pub fn evaluate_values(
        &self,
        plan: &RedshiftPlan,
        (p_lin, c): (&[f64], &[f64]),
        no_wiggle: Option<(&RedshiftBasis, &[f64])>,
    ) -> (RedshiftTerms, Option<RedshiftTerms>) {
        let (rows, sigma_v2) = self.row_values(p_lin, c);
        let nw = no_wiggle.map(|(t, p_nw)| {
            let (rows, sigma_v2) = t.row_values(p_nw, c);
            plan.assemble_rows(p_nw.to_vec(), &rows, sigma_v2)
        });
        (plan.assemble_rows(p_lin.to_vec(), &rows, sigma_v2), nw)
    }

    /// The terms of a spectrum and of its no-wiggle part (as
    /// [`RedshiftPlan::evaluate_with_no_wiggle`]), the latter on the tensors `no_wiggle` (of the
    /// no-wiggle family): the no-wiggle terms carry the full terms' errors (their quadrature error:
    /// the same nodes) plus their own projection and truncation errors.
    pub fn evaluate_with_no_wiggle(
        &self,
        plan: &RedshiftPlan,
        (p_lin, projection): (&[f64], &Projection),
        no_wiggle: &RedshiftBasis,
        (p_nw, projection_nw): (&[f64], &Projection),
    ) -> (RedshiftTerms, RedshiftTerms) {
        let (rows, sigma_v2) = self.rows(p_lin, projection, true);
        let (mut rows_nw, mut sigma_v2_nw) = no_wiggle.rows(p_nw, projection_nw, false);
        let add = |nw: &mut Estimate, full: &Estimate| nw.error += full.error;
        for (nw, full) in rows_nw.iter_mut().zip(&rows) {
            nw.0.iter_mut().zip(&full.0).for_each(|(a, b)| add(a, b));
            nw.1.iter_mut().zip(&full.1).for_each(|(a, b)| add(a, b));
        }
        add(&mut sigma_v2_nw, &sigma_v2);
        (
            plan.assemble_rows(p_lin.to_vec(), &rows, sigma_v2),
            plan.assemble_rows(p_nw.to_vec(), &rows_nw, sigma_v2_nw),
        )
    }

    /// The tensors as the values of their cache file.
    pub(crate) fn to_f64s(&self) -> Vec<f64> {
        let mut v = vec![self.key.len() as f64];
        v.extend(&self.key);
        v.extend(self.basis.to_f64s());
        v.extend(self.pairs.to_f64s());
        v.extend(self.pairs_diff.iter().map(|&t| f64::from(t)));
        v.extend(&self.linear);
        v.extend(&self.sigma_v2);
        v
    }

    /// The tensors for `k` and `precision` from the values of their file, or `None` if the file was
    /// made for other settings or does not fit them.
    pub(crate) fn from_f64s(
        values: &[f64],
        k: &[f64],
        precision: &Precision,
        family: RedshiftFamily,
    ) -> Option<Self> {
        let expected = key(k, precision, family);
        let rest = super::after_key(values, &expected)?;
        let lattice = super::lattice_of(precision);
        let (basis, rest) = LinearBasis::from_f64s(lattice, rest)?;
        let (pairs, rest) = LowRank::from_f64s(rest)?;
        let n = basis.len();
        let n_err = error_functions(n);
        let thin = Thinning::of(k);
        let nk = thin.as_ref().map_or(k.len(), |t| t.nodes().len());
        let sizes = [nk * NPAIR * n_err * (n_err + 1) / 2, nk * LINEAR * n, 2 * n];
        if rest.len() != sizes.iter().sum::<usize>()
            || !pairs.has_shape(nk * NPAIR, n * (n + 1) / 2)
        {
            return None;
        }
        let (pairs_diff, rest) = rest.split_at(sizes[0]);
        let (linear, sigma_v2) = rest.split_at(sizes[1]);
        Some(Self {
            k: k.to_vec(),
            key: expected,
            basis,
            truncation: truncation_on_grid(&pairs, thin.as_ref()),
            thin,
            pairs,
            pairs_diff: pairs_diff.iter().map(|&t| t as f32).collect(),
            linear: linear.to_vec(),
            sigma_v2: sigma_v2.to_vec(),
            p22_error_floor: precision.p22_error_floor,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::linear::LinearSpectrum;

    #[test]
    fn terms_agree_with_direct_for_spectra_not_trained_on_and_survive_their_file() {
        let k: Vec<f64> = (0..8).map(|i| 0.01 * 1.5_f64.powi(i)).collect();
        let plan = RedshiftPlan::new(&k, &Precision::fast()).unwrap();
        let lattice = plan.rules().0.lattice.clone();
        let linear = super::super::training::camb_basis(lattice, BASIS_SIZE);
        let tensors = RedshiftBasis::build(&plan, RedshiftFamily::Linear, linear, &|_, _| {});
        let basis = tensors.basis();
        let dir = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/data/");
        for i in 0..3 {
            let p =
                LinearSpectrum::from_file(format!("{dir}linear_pk_camb_heldout_{i}.dat")).unwrap();
            let direct = plan.evaluate(&p);
            let projection = basis.project(&basis.sample(&p));
            let on_basis = tensors.evaluate(&plan, &direct.p_lin, &projection);
            assert_eq!(on_basis.terms.len(), direct.terms.len());
            for (a, d) in on_basis.terms.iter().zip(&direct.terms) {
                assert_eq!((a.monomial, a.n), (d.monomial, d.n));
                for (j, (a, d)) in a.values.iter().zip(&d.values).enumerate() {
                    let diff = (a.value - d.value).abs();
                    // Within 3e-4 of P_lin and within the errors.
                    assert!(diff < 3e-4 * direct.p_lin[j], "{i} {j}: {a:?} {d:?}");
                    assert!(diff <= a.error + d.error, "{i} {j}: {a:?} {d:?}");
                }
            }
        }
        let v = tensors.to_f64s();
        assert_eq!(
            RedshiftBasis::from_f64s(&v, &k, plan.precision(), RedshiftFamily::Linear).unwrap(),
            tensors
        );
        for other in [
            RedshiftFamily::FilteredNoWiggle,
            RedshiftFamily::SplitNoWiggle,
        ] {
            assert!(RedshiftBasis::from_f64s(&v, &k, plan.precision(), other).is_none());
        }
        assert!(
            RedshiftBasis::from_f64s(&v, &k[1..], plan.precision(), RedshiftFamily::Linear)
                .is_none()
        );
    }
}
