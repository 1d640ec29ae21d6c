//! Joint fits of several data sets: −2 ln L the sum of each set's (independent covariances), with
//! the parameters declared shared taking one value in every set and the others one per set.
//!
//! Each data set has its own data vector, covariance, window and bins, fitted multipoles and k ranges,
//! plan (its redshift's spectrum and AP range), start, free and marginalised parameters and priors:
//! a [`GalaxyFitRequest`] as for a single fit. Its −2 ln L is the single fit's objective (the module
//! docs of [`super`]), the linear parameters marginalised analytically per set (each set its own
//! counterterms and stochastic terms, and its own ln det F). The joint free vector holds every shared
//! parameter once and every other free parameter once per set; the sum is minimised by the single
//! fit's search ([`super::search`]: the same bounds, starts, minimiser, Hessian errors and profile
//! check), so that one data set gives exactly the single fit.
//!
//! A shared parameter must be free in every set and not marginalised (a marginalised parameter is
//! a set's own); its prior, given in one set or identically in several, counts once; its bounds are
//! the intersection of the sets'. [`default_shared`]: f, α∥, α⊥ (those free in every set) when the
//! sets have the same redshift and tracer, none otherwise.
//!
//! Two copies of one data set with covariance C each are one copy with C/2 when every free parameter
//! is shared and the linear ones are profiled (with them marginalised, each copy has its own ln det F
//! and prior terms, which C/2 counts once).

use super::objective::{objective, Objective};
use super::search::{bound, find, package, Space};
use super::{
    slot_index, BlockFit, GalaxyFit, GalaxyFitRequest, Linear, MultipoleData, Observation, Search,
};
use crate::error::{Error, Result};
use crate::rsd::ept::{EptPlan, EptTerms};

/// The parameters shared by default when every data set has the same redshift and tracer.
pub const DEFAULT_SHARED: [&str; 3] = ["f", "apar", "aperp"];

/// Redshifts closer than this are the same (the default sharing).
pub const SAME_REDSHIFT: f64 = 1e-6;

/// One data set of a joint fit.
#[derive(Clone)]
pub struct DataSet<'a> {
    /// Its name in the output (`b1[<label>]`, …): unique among the sets.
    pub label: String,
    /// Its redshift (the default sharing; the plan is the spectrum's at this redshift).
    pub z: f64,
    /// Its tracer (the default sharing; empty: not stated).
    pub tracer: String,
    /// The plan on its model k.
    pub plan: &'a EptPlan,
    /// The terms of its spectrum.
    pub terms: &'a EptTerms,
    /// Its multipoles and covariance.
    pub data: &'a MultipoleData,
    /// What to fit (its start, free, marginalised, priors, ℓ and k ranges).
    pub request: GalaxyFitRequest,
    /// Its window and bins, if any.
    pub observation: Option<&'a Observation>,
    /// Its block after the power spectrum, if any (fitted with one covariance).
    pub block: Option<&'a BlockFit>,
}

/// The result of a joint fit.
#[derive(Debug, Clone, PartialEq)]
pub struct JointFit {
    /// The joint free parameters: a shared one by its name, a set's own as `name[label]`.
    pub names: Vec<String>,
    /// The shared parameters.
    pub shared: Vec<String>,
    /// Per data set its fit: its parameters at the joint best fit, its free parameters' errors (and
    /// their covariance block) from the joint Hessian and profiles, its χ² and −2 ln L (its term of
    /// the sum), its points; the search's report (starts, agreement, evaluations) is the joint one.
    pub sets: Vec<GalaxyFit>,
    /// The joint free parameters' errors (as [`GalaxyFit::errors`]), in the order of [`Self::names`].
    pub errors: Vec<f64>,
    /// Their covariance 2H⁻¹ (`None` where H is not positive definite).
    pub covariance: Option<Vec<Vec<f64>>>,
    /// Σ χ² of the sets.
    pub chi2: f64,
    /// Σ −2 ln L of the sets (the shared priors once).
    pub minus_two_log_l: f64,
    /// Σ fitted points.
    pub points: usize,
}

/// The default shared parameters of `sets`: [`DEFAULT_SHARED`] free in every set when all have the
/// same redshift (to [`SAME_REDSHIFT`]) and tracer; none otherwise.
pub fn default_shared(sets: &[DataSet]) -> Vec<String> {
    let Some(first) = sets.first() else {
        return Vec::new();
    };
    let same = sets
        .iter()
        .all(|s| (s.z - first.z).abs() <= SAME_REDSHIFT && s.tracer == first.tracer);
    if !same {
        return Vec::new();
    }
    DEFAULT_SHARED
        .iter()
        .filter(|n| sets.iter().all(|s| s.request.free.iter().any(|f| f == *n)))
        .map(|n| n.to_string())
        .collect()
}

/// The joint −2 ln L of data sets (the sum of theirs, the shared parameters once, each set's linear
/// parameters marginalised analytically or profiled): what [`fit_joint`] minimises and what a sampler
/// calls (cobaya's likelihood, an MCMC or HMC on its exact gradient). Its parameters are
/// [`Self::names`] (a shared one by its name, a set's own as `name[label]`) within
/// [`Self::lower`], [`Self::upper`] (the fit's bounds: wide ranges narrowed by flat priors and the
/// plans' AP range); its value includes every prior of the requests.
pub struct JointLikelihood<'a> {
    objectives: Vec<Objective<'a>>,
    /// Per set, the joint index of each of its free parameters.
    map: Vec<Vec<usize>>,
    /// The joint free parameters.
    pub names: Vec<String>,
    /// Their lower bounds.
    pub lower: Vec<f64>,
    /// Their upper bounds.
    pub upper: Vec<f64>,
    /// Their start values (the requests', within the bounds).
    pub start: Vec<f64>,
    /// Their typical σ (the start box of the fit's search).
    scale: Vec<f64>,
    /// Per joint parameter: its slot (in its first set).
    slots: Vec<usize>,
    /// The sets' labels.
    labels: Vec<String>,
}

impl<'a> JointLikelihood<'a> {
    /// The likelihood of `sets` with the parameters `shared` (module docs of [`fit_joint`]), the
    /// linear parameters as `linear` says.
    ///
    /// # Errors
    /// As [`fit_joint`].
    pub fn new(sets: &[DataSet<'a>], shared: &[String], linear: Linear) -> Result<Self> {
        build(sets, shared, linear)
    }

    /// Set `s`'s free values in the joint vector `x`.
    fn part(&self, s: usize, x: &[f64]) -> Vec<f64> {
        self.map[s].iter().map(|&g| x[g]).collect()
    }

    fn cost(&self, x: &[f64]) -> f64 {
        self.objectives
            .iter()
            .enumerate()
            .map(|(s, o)| o.cost(&self.part(s, x)))
            .sum()
    }

    /// −2 ln L at the joint free values `x` (in the order of [`Self::names`]).
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] for a wrong length or a value outside the bounds; as the model
    /// (naming the set) where it cannot be evaluated.
    pub fn minus_two_log_l(&self, x: &[f64]) -> Result<f64> {
        self.check(x)?;
        let mut sum = 0.0;
        for (s, o) in self.objectives.iter().enumerate() {
            sum += o
                .evaluate(&self.part(s, x))
                .map_err(|e| self.in_set(s, e))?
                .0;
        }
        Ok(sum)
    }

    /// −2 ln L and its exact gradient at `x`; `None` where a set has no exact gradient (a block
    /// after the power spectrum: [`Self::exact_gradient`]).
    ///
    /// # Errors
    /// As [`Self::minus_two_log_l`].
    pub fn value_and_gradient(&self, x: &[f64]) -> Result<Option<(f64, Vec<f64>)>> {
        self.check(x)?;
        let (mut value, mut gradient) = (0.0, vec![0.0; x.len()]);
        for (s, o) in self.objectives.iter().enumerate() {
            let Some((v, g, _)) = o
                .value_and_gradient(&self.part(s, x))
                .map_err(|e| self.in_set(s, e))?
            else {
                return Ok(None);
            };
            value += v;
            for (&j, g) in self.map[s].iter().zip(g) {
                gradient[j] += g;
            }
        }
        Ok(Some((value, gradient)))
    }

    /// The sum of the sets' −2 ln L with its exact gradient and Gauss–Newton curvature (each set's
    /// scattered onto the joint parameters), if every set has one; +∞ outside the model's domain.
    #[allow(clippy::type_complexity)]
    fn cost_and_gradient(&self, x: &[f64]) -> Option<(f64, Vec<f64>, Vec<f64>)> {
        let (mut value, mut gradient, mut curvature) =
            (0.0, vec![0.0; x.len()], vec![0.0; x.len()]);
        for (s, o) in self.objectives.iter().enumerate() {
            let (v, g, c) = o.cost_and_gradient(&self.part(s, x))?;
            value += v;
            for ((&j, g), c) in self.map[s].iter().zip(g).zip(c) {
                gradient[j] += g;
                curvature[j] += c;
            }
        }
        Some((value, gradient, curvature))
    }

    /// Whether every set's objective has an exact gradient.
    pub fn exact_gradient(&self) -> bool {
        self.objectives.iter().all(|o| o.exact_gradient)
    }

    /// The number of fitted points (all sets).
    pub fn points(&self) -> usize {
        self.objectives.iter().map(Objective::points).sum()
    }

    fn check(&self, x: &[f64]) -> Result<()> {
        if x.len() != self.names.len() {
            return Err(Error::InvalidParameter {
                name: "number of likelihood parameters",
                value: x.len() as f64,
                reason: "must equal the number of the likelihood's free parameters (its names)",
            });
        }
        for (j, &v) in x.iter().enumerate() {
            if !(v >= self.lower[j] && v <= self.upper[j]) {
                return Err(Error::InvalidChoice {
                    what: format!("{} = {v}", self.names[j]),
                    reason: format!(
                        "is outside the likelihood's range [{}, {}] (the fit's bounds: its flat \
                         priors and the plan's AP range)",
                        self.lower[j], self.upper[j]
                    ),
                });
            }
        }
        Ok(())
    }

    fn in_set(&self, s: usize, e: Error) -> Error {
        Error::InvalidChoice {
            what: format!("data set `{}`", self.labels[s]),
            reason: e.to_string(),
        }
    }

    /// The search space of the fit: per parameter its slot and prior, the bounds, σ and start.
    fn space(&self) -> Space<'_> {
        let (params, boxes) = self
            .slots
            .iter()
            .enumerate()
            .map(|(j, &slot)| {
                let s = (0..self.map.len())
                    .find(|&s| self.map[s].contains(&j))
                    .expect("every joint parameter is some set's");
                let o = &self.objectives[s];
                ((slot, o.priors[slot].as_ref()), o.start_box(slot))
            })
            .unzip();
        Space {
            params,
            lo: self.lower.clone(),
            hi: self.upper.clone(),
            scale: self.scale.clone(),
            x0: self.start.clone(),
            boxes,
        }
    }
}

/// The error of a sharing rule broken.
fn sharing(name: &str, reason: String) -> Error {
    Error::InvalidChoice {
        what: format!("the shared parameter `{name}`"),
        reason,
    }
}

/// The joint best fit of `sets` with the parameters `shared` (module docs), searched as `search`.
///
/// # Errors
/// [`Error::InvalidChoice`] for no set, repeated labels, a shared name that is not a parameter,
/// that no set frees, that a set does not free or marginalises, or with different priors in two
/// sets; as [`super::fit_galaxy_search`] for each set.
pub fn fit_joint(sets: &[DataSet], shared: &[String], search: &Search) -> Result<JointFit> {
    let joint = build(sets, shared, search.linear)?;
    // Errors of the model at the start are the user's: reported as they are, naming the set.
    for (s, o) in joint.objectives.iter().enumerate() {
        o.evaluate(&joint.part(s, &joint.start))
            .map_err(|e| Error::InvalidChoice {
                what: format!("data set `{}` at the start", sets[s].label),
                reason: e.to_string(),
            })?;
    }
    let space = joint.space();
    let exact = |x: &[f64]| joint.cost_and_gradient(x);
    let grad = joint
        .exact_gradient()
        .then_some(&exact as &crate::fit::bounded::ValueGradient);
    let found = find(&|x: &[f64]| joint.cost(x), grad, &space, search)?;
    let x = &found.best.x;
    let mut fits = Vec::with_capacity(sets.len());
    for (s, o) in joint.objectives.iter().enumerate() {
        fits.push(package(
            o,
            &joint.part(s, x),
            &found,
            found.errors.select(&joint.map[s]),
        )?);
    }
    Ok(JointFit {
        names: joint.names.clone(),
        shared: shared.to_vec(),
        chi2: fits.iter().map(|f| f.chi2).sum(),
        minus_two_log_l: fits.iter().map(|f| f.minus_two_log_l).sum(),
        points: fits.iter().map(|f| f.points).sum(),
        sets: fits,
        errors: found.errors.given.clone(),
        covariance: found.errors.covariance.clone(),
    })
}

/// The [`JointLikelihood`] of `sets` (as [`fit_joint`] checks them).
fn build<'a>(
    sets: &[DataSet<'a>],
    shared: &[String],
    linear: Linear,
) -> Result<JointLikelihood<'a>> {
    if sets.is_empty() {
        return Err(Error::InvalidChoice {
            what: "a joint fit".into(),
            reason: "needs at least one data set".into(),
        });
    }
    for (i, s) in sets.iter().enumerate() {
        if sets[..i].iter().any(|t| t.label == s.label) {
            return Err(Error::InvalidChoice {
                what: format!("the data set label `{}`", s.label),
                reason: "is given twice: labels name the sets' own parameters".into(),
            });
        }
    }
    let mut objectives = Vec::with_capacity(sets.len());
    for s in sets {
        let mut o = objective(s.plan, s.terms, s.data, &s.request, s.observation, s.block)
            .map_err(|e| Error::InvalidChoice {
                what: format!("data set `{}`", s.label),
                reason: e.to_string(),
            })?;
        o.log_det = linear == Linear::Marginalised;
        objectives.push(o);
    }
    let basis = sets.first().map(|s| s.request.basis).unwrap_or_default();
    if let Some(s) = sets
        .iter()
        .find(|s| s.request.basis.names() != basis.names())
    {
        return Err(Error::InvalidChoice {
            what: format!("the parameter basis of data set `{}`", s.label),
            reason: format!(
                "every data set of a joint fit takes the same basis ({} here, {} in `{}`), so that \
                 a shared name means one parameter",
                s.request.basis.label(),
                basis.label(),
                sets[0].label
            ),
        });
    }
    // per set, the slots of the shared parameters (a block's own sit after the model's and AP's)
    let shared_slots: Vec<Vec<usize>> = objectives
        .iter()
        .map(|o| {
            let own = o.block.as_ref().map_or(&[][..], |b| b.fit.kind().own);
            shared
                .iter()
                .map(|n| slot_index(n, &basis, own))
                .collect::<Result<_>>()
        })
        .collect::<Result<_>>()?;
    for (n, name) in shared.iter().enumerate() {
        if shared[..n].contains(name) {
            return Err(sharing(name, "is declared shared twice".into()));
        }
        let frees: Vec<bool> = objectives
            .iter()
            .zip(&shared_slots)
            .map(|(o, slots)| o.free.contains(&slots[n]))
            .collect();
        if let Some(s) = sets.iter().find(|s| s.request.marginalise.contains(name)) {
            return Err(sharing(
                name,
                format!(
                    "is marginalised in data set `{}`: a marginalised parameter is a set's own (free \
                     it in every set to share it)",
                    s.label
                ),
            ));
        }
        if !frees.iter().any(|&f| f) {
            return Err(sharing(
                name,
                "no data set has it free: a shared parameter must be free in every set".into(),
            ));
        }
        if let Some(s) = frees.iter().position(|&f| !f) {
            return Err(sharing(
                name,
                format!(
                    "is not free in data set `{}`: a shared parameter must be free in every set",
                    sets[s].label
                ),
            ));
        }
        // Its prior: one, counted once (kept in the first set that gives it).
        let mut prior = None;
        for ((o, s), slots) in objectives.iter_mut().zip(sets).zip(&shared_slots) {
            let slot = slots[n];
            match (prior.as_ref(), o.priors[slot].take()) {
                (_, None) => {}
                (None, Some(p)) => {
                    o.priors[slot] = Some(p.clone());
                    prior = Some(p);
                }
                (Some(q), Some(p)) if *q == p => {}
                (Some(q), Some(p)) => {
                    return Err(sharing(
                        name,
                        format!(
                            "has the prior {q} in one set and {p} in data set `{}`: a shared \
                             parameter has one prior",
                            s.label
                        ),
                    ))
                }
            }
        }
    }
    // The joint parameters, in the sets' order of their free ones; a shared one at its first.
    let mut names = Vec::new();
    let mut slots = Vec::new();
    let (mut lo, mut hi, mut scale, mut x0) = (Vec::new(), Vec::new(), Vec::new(), Vec::new());
    let mut map = Vec::with_capacity(sets.len());
    for (s, o) in objectives.iter().enumerate() {
        let mut own = Vec::with_capacity(o.free.len());
        for (j, &slot) in o.free.iter().enumerate() {
            let (a, b, sc) = bound(o, slot);
            let at = shared_slots[s].iter().position(|&i| i == slot);
            if let Some(g) = at
                .filter(|_| s > 0)
                .map(|n| map_of(&map, shared_slots[0][n], &objectives))
            {
                let g = g.expect("a shared parameter is free in the first set");
                lo[g] = f64::max(lo[g], a);
                hi[g] = f64::min(hi[g], b);
                own.push(g);
                continue;
            }
            own.push(names.len());
            names.push(if at.is_some() {
                sets[s].request.free[j].clone()
            } else {
                format!("{}[{}]", sets[s].request.free[j], sets[s].label)
            });
            slots.push(slot);
            lo.push(a);
            hi.push(b);
            scale.push(sc);
            x0.push(o.start[slot]);
        }
        map.push(own);
    }
    for (j, v) in x0.iter_mut().enumerate() {
        if lo[j] > hi[j] {
            return Err(sharing(
                &names[j],
                "the sets' bounds (priors, AP ranges) do not overlap".into(),
            ));
        }
        *v = v.clamp(lo[j], hi[j]);
    }
    Ok(JointLikelihood {
        objectives,
        map,
        names,
        lower: lo,
        upper: hi,
        start: x0,
        scale,
        slots,
        labels: sets.iter().map(|s| s.label.clone()).collect(),
    })
}

/// The joint index of the shared `slot`: its index in the first set's map.
fn map_of(map: &[Vec<usize>], slot: usize, objectives: &[Objective]) -> Option<usize> {
    let j = objectives[0].free.iter().position(|&i| i == slot)?;
    map.first().map(|m| m[j])
}
