//! The objective of a galaxy fit: −2 ln L of the free parameters with the linear ones marginalised
//! analytically (the module docs of [`super`]), on one window of data.

use super::block::{BlockFit, BlockModel};
use super::search::{ranges, Range};
use super::{GalaxyFitRequest, PriorShape, AP_SLOT, OWN_SLOT};
use crate::error::{Error, Result};
use crate::fit::MultipoleData;
use crate::linalg::{cholesky, dot, invert_lower, solve_spd};
use crate::rsd::ept::{EptParams, EptPlan, EptTerms, PARAM_NAMES};
use crate::survey::observe::Observation;
use crate::table::{describe_grid, same_k};

/// The slots of the biases b1, b2, bs, b3 ([`PARAM_NAMES`]).
const BIASES: [usize; 4] = [0, 1, 2, 3];

/// The largest change of a template, relative to the largest template value, that counts as none
/// when the biases change (rounding of the model's sums: ~1e-15 relative).
const TEMPLATE_TOLERANCE: f64 = 1e-10;

/// Templates kept: a gradient's bias steps find those of its centre among the last few (the steps of
/// f, α∥, α⊥ before them made their own).
const CACHE_SIZE: usize = 8;

/// A cached template: the key of the slots it was made at and its rows.
type CachedTemplate = (Vec<u64>, Vec<Vec<f64>>);

/// The objective of one request on one data window.
pub(super) struct Objective<'a> {
    pub(super) plan: &'a EptPlan,
    pub(super) terms: &'a EptTerms,
    /// The window and bins between the model and the data, if any.
    pub(super) observation: Option<&'a Observation>,
    /// Every slot's start or fixed value (the model's parameters, α∥, α⊥, the block's own).
    pub(super) start: Vec<f64>,
    /// Whether the measurement has a distortion.
    pub(super) has_ap: bool,
    /// The parameter basis of the slots, converted to the model's at every evaluation.
    pub(super) basis: super::FitBasis,
    pub(super) ells: Vec<usize>,
    pub(super) free: Vec<usize>,
    pub(super) marg: Vec<usize>,
    /// Per slot, its prior, if any.
    pub(super) priors: Vec<Option<PriorShape>>,
    /// Per fitted ℓ (in the order of `ells`), the k indices of its fitted points.
    pub(super) window: Vec<Vec<usize>>,
    /// Whether the marginalised templates are independent of the biases (checked at construction).
    pub(super) bias_free_templates: bool,
    /// Whether [`Self::value_and_gradient`] gives the exact gradient (checked at construction).
    pub(super) exact_gradient: bool,
    /// The last [`CACHE_SIZE`] templates and the slots they were made at ([`Self::template_key`]).
    pub(super) cache: std::cell::RefCell<Vec<CachedTemplate>>,
    /// Whether −2 ln L holds ln det F (the linear parameters marginalised), or not (profiled).
    pub(super) log_det: bool,
    /// L⁻¹ of the Cholesky factor of the window's covariance.
    pub(super) whiten: Vec<Vec<f64>>,
    /// L⁻¹ d.
    pub(super) data: Vec<f64>,
    /// The block after the power spectrum, if the data set has one: its entries follow the
    /// power spectrum's in the model and data vectors.
    pub(super) block: Option<BlockModel<'a>>,
}

impl Objective<'_> {
    pub(super) fn slots(&self, x: &[f64]) -> Vec<f64> {
        let mut v = self.start.clone();
        for (&i, &value) in self.free.iter().zip(x) {
            v[i] = value;
        }
        v
    }

    pub(super) fn split(
        &self,
        v: &[f64],
    ) -> Result<(EptParams, Option<crate::rsd::ap::Distortion>)> {
        let n = PARAM_NAMES.len();
        let mut model = [0.0; PARAM_NAMES.len()];
        model.copy_from_slice(&v[..n]);
        let p = self.basis.to_ept(&model);
        let ap = if self.has_ap {
            Some(crate::rsd::ap::Distortion::new(v[n], v[n + 1])?)
        } else {
            None
        };
        Ok((p, ap))
    }

    /// Whether the data set has a block after the power spectrum.
    pub(super) fn has_block(&self) -> bool {
        self.block.is_some()
    }

    /// The range of slot `i` in a fit: the basis's ([`super::search::RANGES`]), a block's own from
    /// its kind.
    pub(super) fn range(&self, i: usize) -> Range {
        match (i.checked_sub(OWN_SLOT), &self.block) {
            (Some(j), Some(b)) => b.fit.kind().ranges[j],
            _ => ranges(&self.basis)[i],
        }
    }

    /// The start box (lower, upper) of slot `i` ([`Self::range`]).
    pub(super) fn start_box(&self, i: usize) -> (f64, f64) {
        let (_, _, from, to, _) = self.range(i);
        (from, to)
    }

    /// The multipoles the plan evaluates: the window's model multipoles, or the fitted ones.
    pub(super) fn plan_ells(&self) -> &[usize] {
        self.observation.map_or(&self.ells, |o| o.model_ells())
    }

    /// The power spectrum's fitted points (not whitened) of the plan's multipoles `m` over
    /// [`Self::plan_ells`]: through the window and bins, if any (linear in `m`).
    pub(super) fn fitted_points(&self, m: Vec<Vec<f64>>) -> Result<Vec<f64>> {
        let m = match self.observation {
            None => m,
            Some(o) => {
                // the chain as its matrix (made once per observation): one product per model
                let (matrix, _) = o.matrix()?;
                let flat = crate::survey::observe::apply_matrix(matrix, &m);
                flat.chunks(o.k_out().len()).map(<[f64]>::to_vec).collect()
            }
        };
        Ok(m.iter()
            .zip(&self.window)
            .flat_map(|(l, window)| window.iter().map(move |&i| l[i]))
            .collect())
    }

    /// L⁻¹ `raw`: a vector of the fitted entries whitened.
    pub(super) fn whitened(&self, raw: &[f64]) -> Vec<f64> {
        self.whiten
            .iter()
            .map(|row| row.iter().zip(raw).map(|(a, b)| a * b).sum())
            .collect()
    }

    /// The whitened model at the slots `v` (L⁻¹ m): the power spectrum's fitted points, then the
    /// block's entries.
    pub(super) fn model(&self, v: &[f64]) -> Result<Vec<f64>> {
        let (p, ap) = self.split(v)?;
        let m = self
            .plan
            .multipole_values_at(self.terms, &p, self.plan_ells(), ap)?;
        let mut raw = self.fitted_points(m)?;
        if let Some(b) = &self.block {
            raw.extend(b.values(&p, ap, &v[OWN_SLOT..])?);
        }
        Ok(self.whitened(&raw))
    }

    /// The whitened templates Tᵢ = m(v, aᵢ = 1) − m(v, aᵢ = 0) of the marginalised parameters at the
    /// slots `v` (theirs at 0), `m0` the model at `v` (the model is linear in them in either basis).
    fn templates(&self, v: &[f64], m0: &[f64]) -> Result<Vec<Vec<f64>>> {
        self.marg
            .iter()
            .map(|&i| {
                let mut w = v.to_vec();
                w[i] = 1.0;
                self.model(&w)
                    .map(|m| m.iter().zip(m0).map(|(a, b)| a - b).collect())
            })
            .collect()
    }

    /// The slots the templates can depend on: all but the biases and the marginalised ones.
    fn template_key(&self, v: &[f64]) -> Vec<u64> {
        (0..v.len())
            .filter(|i| !BIASES.contains(i) && !self.marg.contains(i))
            .map(|i| v[i].to_bits())
            .collect()
    }

    /// Whether the templates at the start are those at other biases (to [`TEMPLATE_TOLERANCE`]):
    /// the counterterms and stochastic terms of the model do not multiply a bias, so that a step
    /// of b1, b2, bs, b3 alone reuses them (module docs of [`super`]). Checked, not assumed.
    fn check_bias_free_templates(&mut self) -> Result<()> {
        if self.marg.is_empty() {
            return Ok(());
        }
        let mut v = self.start.clone();
        for &i in &self.marg {
            v[i] = 0.0;
        }
        let at = |v: &[f64]| -> Result<Vec<Vec<f64>>> { self.templates(v, &self.model(v)?) };
        let t0 = at(&v)?;
        for (&i, shift) in BIASES.iter().zip([0.37, -0.41, 0.23, 0.11]) {
            v[i] += shift;
        }
        let t1 = at(&v)?;
        let scale = t0.iter().flatten().fold(0.0f64, |m, v| m.max(v.abs()));
        self.bias_free_templates = t0
            .iter()
            .flatten()
            .zip(t1.iter().flatten())
            .all(|(a, b)| (a - b).abs() <= TEMPLATE_TOLERANCE * scale);
        Ok(())
    }

    /// −2 ln L at the free values `x`; +∞ outside the model's domain (e.g. f < 0).
    pub(super) fn cost(&self, x: &[f64]) -> f64 {
        self.evaluate(x).map_or(f64::INFINITY, |e| e.0)
    }

    /// [`Self::value_and_gradient`] for the minimiser: `None` without an exact gradient, +∞
    /// outside the model's domain.
    #[allow(clippy::type_complexity)]
    pub(super) fn cost_and_gradient(&self, x: &[f64]) -> Option<(f64, Vec<f64>, Vec<f64>)> {
        match self.value_and_gradient(x) {
            Ok(found) => found,
            Err(_) => Some((f64::INFINITY, vec![0.0; x.len()], vec![f64::NAN; x.len()])),
        }
    }

    /// The number of fitted data points.
    pub(super) fn points(&self) -> usize {
        self.data.len()
    }

    /// (−2 ln L, χ², the slots with â, the errors of â) at the free values `x`.
    ///
    /// # Errors
    /// As the model's evaluation (e.g. f or α outside the plan's range).
    pub(super) fn evaluate(&self, x: &[f64]) -> Result<(f64, f64, Vec<f64>, Vec<f64>)> {
        let mut v = self.slots(x);
        for &i in &self.marg {
            v[i] = 0.0;
        }
        let m0 = self.model(&v)?;
        let key = self.template_key(&v);
        let cached = if self.bias_free_templates {
            self.cache
                .borrow()
                .iter()
                .find(|(k, _)| *k == key)
                .map(|(_, t)| t.clone())
        } else {
            None
        };
        let templates = match cached {
            Some(t) => t,
            None => {
                let t = self.templates(&v, &m0)?;
                let mut cache = self.cache.borrow_mut();
                if cache.len() == CACHE_SIZE {
                    cache.remove(0);
                }
                cache.push((key, t.clone()));
                t
            }
        };
        let m = self.marginalise(&mut v, &m0, &templates)?;
        let errors = (0..m.ahat.len()).map(|a| m.inverse[a][a].sqrt()).collect();
        Ok((m.total, m.chi2, v, errors))
    }

    /// The linear parameters marginalised at the slots `v` (set to their best values â here), the
    /// whitened model `m0` without them and their templates: −2 ln L (with ln det F if
    /// [`Self::log_det`], the priors of the marginalised and the free parameters), χ², â, F⁻¹ and
    /// the residual L⁻¹(d − m0) − Σ âₐTₐ.
    pub(super) fn marginalise(
        &self,
        v: &mut [f64],
        m0: &[f64],
        templates: &[Vec<f64>],
    ) -> Result<Marginal> {
        let r0: Vec<f64> = self.data.iter().zip(m0).map(|(d, m)| d - m).collect();
        let n = self.marg.len();
        let mut f = vec![vec![0.0; n]; n];
        let mut b = vec![0.0; n];
        for a in 0..n {
            let (mean, precision) = self.priors[self.marg[a]]
                .as_ref()
                .and_then(PriorShape::gaussian)
                .unwrap_or((0.0, 0.0));
            b[a] = dot(&templates[a], &r0) + precision * mean;
            for c in 0..n {
                f[a][c] = dot(&templates[a], &templates[c]);
            }
            f[a][a] += precision;
        }
        let (ahat, inverse, log_det) = solve_spd(&f, &b)?;
        let residual: Vec<f64> = r0
            .iter()
            .enumerate()
            .map(|(j, r)| r - (0..n).map(|a| ahat[a] * templates[a][j]).sum::<f64>())
            .collect();
        let chi2 = dot(&residual, &residual);
        let mut total = chi2 + if self.log_det { log_det } else { 0.0 };
        for (a, &i) in self.marg.iter().enumerate() {
            v[i] = ahat[a];
            if let Some((mean, precision)) = self.priors[i].as_ref().and_then(PriorShape::gaussian)
            {
                total += precision * (ahat[a] - mean).powi(2);
            }
        }
        for &i in &self.free {
            if let Some(prior) = &self.priors[i] {
                total += prior.minus_two_log(v[i]);
            }
        }
        Ok(Marginal {
            total,
            chi2,
            ahat,
            inverse,
            residual,
        })
    }
}

/// The linear parameters marginalised at one point ([`Objective::marginalise`]).
pub(super) struct Marginal {
    /// −2 ln L.
    pub(super) total: f64,
    /// χ² at â.
    pub(super) chi2: f64,
    /// The best values â of the marginalised parameters.
    pub(super) ahat: Vec<f64>,
    /// F⁻¹, the inverse of their Fisher matrix (with their priors).
    pub(super) inverse: Vec<Vec<f64>>,
    /// L⁻¹(d − m0) − Σ âₐTₐ.
    pub(super) residual: Vec<f64>,
}

/// The objective of `request` on `data` (through `observation`, if any).
///
/// # Errors
/// As [`super::fit_galaxy_observed`].
pub(super) fn objective<'a>(
    plan: &'a EptPlan,
    terms: &'a EptTerms,
    data: &MultipoleData,
    request: &GalaxyFitRequest,
    observation: Option<&'a Observation>,
    block: Option<&'a BlockFit>,
) -> Result<Objective<'a>> {
    let (free, marg, priors) = super::request::validate(request, block.map(BlockFit::kind))?;
    if request.ap.is_none() && free.iter().any(|&i| (AP_SLOT..OWN_SLOT).contains(&i)) {
        return Err(Error::InvalidChoice {
            what: "free apar/aperp".into(),
            reason: "the fit needs a distortion to start from (the measurement's AP)".into(),
        });
    }
    let k = match observation {
        None => plan.k(),
        Some(o) => {
            if plan.k() != o.k_model() || !same_k(o.k_out(), &data.k) || o.ells() != request.ells {
                return Err(Error::InvalidChoice {
                    what: "the fit's window and bins".into(),
                    reason: format!(
                        "the plan must be on their model k and their output ({}, l {:?}) on the \
                         data's ({}, l {:?})",
                        describe_grid(o.k_out()),
                        o.ells(),
                        describe_grid(&data.k),
                        request.ells
                    ),
                });
            }
            data.k.as_slice()
        }
    };
    if observation.is_none() && !same_k(k, &data.k) {
        return Err(Error::InvalidChoice {
            what: "the fit's model grid".into(),
            reason: "the plan must be built on the data's k".into(),
        });
    }
    let mut rows = Vec::new();
    for &l in &request.ells {
        let j = data
            .ells
            .iter()
            .position(|&d| d == l)
            .ok_or(Error::InvalidParameter {
                name: "fitted multipole ell",
                value: l as f64,
                reason: "is not in the data",
            })?;
        rows.push(j);
    }
    let mut window = Vec::with_capacity(rows.len());
    for &l in &request.ells {
        let (mut lo, mut hi) = (request.k_min, request.k_max);
        for &(_, a, b) in request.ell_ranges.iter().filter(|r| r.0 == l) {
            lo = lo.max(a);
            hi = hi.min(b);
        }
        window.push(
            (0..k.len())
                .filter(|&i| (lo..=hi).contains(&k[i]))
                .collect::<Vec<usize>>(),
        );
    }
    let points: usize = window.iter().map(Vec::len).sum::<usize>() + block.map_or(0, BlockFit::len);
    if points <= free.len() + marg.len() {
        return Err(Error::InvalidParameter {
            name: "k_max [h/Mpc]",
            value: request.k_max,
            reason: "the fitted window holds no more points than parameters",
        });
    }
    // The window's covariance: the data's full covariance (ℓ-major over the data's ells), or σ².
    let position = |r: usize, i: usize| r * k.len() + i;
    // The fitted points (data row, k index), ℓ-major.
    let fitted: Vec<(usize, usize)> = rows
        .iter()
        .zip(&window)
        .flat_map(|(&r, w)| w.iter().map(move |&i| (r, i)))
        .collect();
    let mut cov: Vec<Vec<f64>> = fitted
        .iter()
        .map(|&(r, i)| {
            fitted
                .iter()
                .map(|&(s, j)| match &data.covariance {
                    Some(c) => c[position(r, i)][position(s, j)],
                    None if (r, i) == (s, j) => data.sigma[r][i].powi(2),
                    None => 0.0,
                })
                .collect()
        })
        .collect();
    // With a block: its entries after the power spectrum's, with the cross terms.
    if let Some(b) = block {
        if data.covariance.is_none() {
            return Err(Error::InvalidChoice {
                what: format!("a fit of the power spectrum and the {}", b.kind().name),
                reason: "needs their joint covariance (the cross terms), not diagonal errors"
                    .into(),
            });
        }
        let nb = b.len();
        for (row, &(r, i)) in cov.iter_mut().zip(&fitted) {
            for j in 0..nb {
                row.push(b.cross(position(r, i), j)?);
            }
        }
        for j in 0..nb {
            let mut row = Vec::with_capacity(fitted.len() + nb);
            for &(r, i) in &fitted {
                row.push(b.cross(position(r, i), j)?);
            }
            row.extend((0..nb).map(|m| b.covariance(j, m)));
            cov.push(row);
        }
    }
    // the degeneracy of the rows inverted (the file's other rows may be nearly degenerate: few-mode
    // bins the fit leaves out; fit::covariance)
    crate::fit::covariance::check_conditioning(
        &cov,
        &format!("the {points} fitted points"),
        &|i| match (fitted.get(i), block) {
            (Some(&(r, j)), _) => format!("P{} at k = {} h/Mpc", data.ells[r], k[j]),
            (None, Some(b)) => b.entry(i - fitted.len()),
            (None, None) => format!("point {}", i + 1),
        },
    )?;
    if let Some(n) = request.n_mocks {
        if n < points + 3 {
            return Err(Error::InvalidParameter {
                name: "number of mocks",
                value: n as f64,
                reason: "the Hartlap factor needs more mocks than fitted points + 2",
            });
        }
        // C⁻¹ → h C⁻¹ is C → C/h.
        let h = (n - points - 2) as f64 / (n - 1) as f64;
        for row in cov.iter_mut() {
            for v in row.iter_mut() {
                *v /= h;
            }
        }
    }
    let l = cholesky(&cov).ok_or_else(|| Error::InvalidChoice {
        what: format!("the covariance of the {points} fitted points"),
        reason: "is not positive definite".into(),
    })?;
    let whiten = invert_lower(&l);
    let mut raw: Vec<f64> = fitted.iter().map(|&(r, i)| data.values[r][i]).collect();
    raw.extend(block.map_or(&[][..], BlockFit::values));
    let data_vector = whiten.iter().map(|row| dot(row, &raw)).collect();
    let mut start = vec![0.0; OWN_SLOT];
    let in_basis = request.basis.from_ept(&request.start);
    if let Some(i) = in_basis.iter().position(|v| !v.is_finite()) {
        return Err(Error::InvalidParameter {
            name: "start value in the fit's basis",
            value: in_basis[i],
            reason: "the start (b1, f) cannot be expressed in the fit's parameter basis",
        });
    }
    start[..PARAM_NAMES.len()].copy_from_slice(&in_basis);
    if let Some(d) = request.ap {
        start[AP_SLOT] = d.apar;
        start[AP_SLOT + 1] = d.aperp;
    }
    if let Some(b) = block {
        start.extend(b.start());
    }
    let mut objective = Objective {
        plan,
        terms,
        observation,
        start,
        has_ap: request.ap.is_some(),
        basis: request.basis,
        ells: request.ells.clone(),
        free,
        marg,
        priors,
        window,
        log_det: true,
        bias_free_templates: false,
        exact_gradient: false,
        cache: std::cell::RefCell::new(Vec::new()),
        whiten,
        data: data_vector,
        block: block.map(BlockModel::new),
    };
    objective.check_bias_free_templates()?;
    // (a model the checks cannot evaluate falls back to differences; its errors surface at the start)
    objective.exact_gradient = objective.check_exact_gradient().unwrap_or(false);
    Ok(objective)
}
