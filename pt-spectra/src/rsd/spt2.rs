//! `spt2`: the matter multipoles of 2-loop standard perturbation theory in redshift space,
//!
//! ```text
//! P_s(k, μ) = (1 + fμ²)² P_lin + P^(1)_s(k, μ; f) + P^(2)_s(k, μ; f),
//! ```
//!
//! P^(1)_s the 1-loop terms P22 + 2P13 with the kernels Z₂, Z₃ ([`crate::loops::redshift`] at b1 = 1 and
//! no other bias: exact in μ, deterministic quadrature), P^(2)_s the 2-loop terms 2P15 + 2P24 + P33
//! with Z₄, Z₅ ([`mod@crate::loops::rsd_two_loop`]: quasi-Monte Carlo, a polynomial of degree 6 in f and
//! in μ²). Every term is a polynomial in f, so a new f costs no integral. No Fingers-of-God damping, no
//! IR resummation, no counterterms: plain SPT, the base of [`super::eft2`] (with counterterms and IR
//! resummation, Taule & Garny 2023 find 1-loop within sample variance of Quijote to k ≈ 0.1 and
//! 2-loop to ≈ 0.18 h/Mpc at z = 0 and 0.5).
//!
//! The 2-loop terms come from basis tensors ([`Spt2Plan::with_basis`]) when the plan has them and the
//! spectrum projects well, else they are integrated; [`Spt2Terms::source`] says which.
//!
//! Errors: the 1-loop coefficients' error bounds times (2ℓ+1) (as [`super::MultipoleRule`]), plus the
//! standard error over the random shifts of the 2-loop multipole at this f.

use crate::error::{Error, Result};
use crate::linear::LinearSpectrum;
use crate::loops::basis::training::camb_basis;
use crate::loops::basis::{
    LinearBasis, Projection, RedshiftBasis, RedshiftFamily, RsdTwoLoopBasis, SpectrumFamily,
    BASIS_SIZE,
};
use crate::loops::redshift::{RedshiftPlan, RedshiftTerms};
use crate::loops::{
    check_two_loop_ells, rsd_two_loop_of, Estimate, RsdTwoLoopTerms, TwoLoopSettings,
};
use crate::output::MethodNote;
use crate::precision::Precision;
use crate::progress::{stage_callback, Progress, Stage};
use crate::store::TableStore;
use std::sync::Arc;

/// The redshift-space 2-loop Sobol points per shift are the real-space ones
/// ([`Precision::two_loop_points`]) over this factor: each point costs ~30 μs of kernels (seven nodes
/// in μ² at two azimuths, nine configurations) against ~1 μs in real space.
pub const POINTS_DIVISOR: usize = 4;

/// The 2-loop integration settings of `precision` in redshift space: the real-space ones with
/// [`POINTS_DIVISOR`] times fewer points.
pub fn two_loop_settings(precision: &Precision) -> TwoLoopSettings {
    TwoLoopSettings {
        points: (precision.two_loop_points / POINTS_DIVISOR).max(1),
        replicas: precision.two_loop_replicas,
        seed: precision.two_loop_seed,
        ..TwoLoopSettings::default()
    }
}

/// The basis tensors of a 2-loop model for the spectra of [`loop_terms`] (the linear spectrum,
/// then with IR resummation its no-wiggle part): the 2-loop ones and the 1-loop ones on the same
/// basis functions, so that one projection per spectrum serves both (the 1-loop ones are kept only
/// if there are 2-loop ones for every spectrum).
#[derive(Debug, Clone, Default)]
pub(crate) struct LoopTensors {
    two_loop: Vec<Arc<RsdTwoLoopBasis>>,
    one_loop: Vec<Arc<RedshiftBasis>>,
}

impl LoopTensors {
    /// Basis if the plan holds 2-loop tensors, else direct.
    pub(crate) fn method(&self) -> crate::plan::Method {
        if self.two_loop.is_empty() {
            crate::plan::Method::Direct
        } else {
            crate::plan::Method::Basis
        }
    }

    /// The tensors of the spectra `families` (each with the basis its tensors are built on) for the
    /// 1-loop `plan`, as `precision.two_loop` says: built (`basis`), read if cached (`auto`), or none
    /// (`direct`).
    ///
    /// # Errors
    /// As [`TableStore::for_method`].
    pub(crate) fn load(
        plan: &RedshiftPlan,
        families: &[(SpectrumFamily, &dyn Fn() -> LinearBasis)],
        store: &TableStore,
        progress: &dyn Progress,
    ) -> Result<Self> {
        let (k, precision) = (plan.k(), plan.precision());
        let mut two_loop = Vec::new();
        let mut one_loop = Vec::new();
        for &(family, basis) in families {
            two_loop.extend(tensors_of(k, precision, family, basis, store, progress)?);
            let family = match family {
                SpectrumFamily::Linear => RedshiftFamily::Linear,
                SpectrumFamily::NoWiggle => RedshiftFamily::SplitNoWiggle,
            };
            let build = |tick: &(dyn Fn(usize, usize) + Sync)| {
                RedshiftBasis::build(plan, family, basis(), tick)
            };
            let key = (k, precision, family);
            one_loop.extend(store.for_method::<RedshiftBasis>(
                precision.two_loop,
                key,
                build,
                progress,
            )?);
        }
        if two_loop.len() != families.len() {
            two_loop.clear();
        }
        let same_functions = one_loop.len() == two_loop.len()
            && one_loop
                .iter()
                .zip(&two_loop)
                .all(|(one, two)| one.basis() == two.basis());
        if !same_functions {
            one_loop.clear();
        }
        Ok(Self { two_loop, one_loop })
    }
}

/// Bytes per k of one spectrum's 2-loop redshift-space terms (the 1- and 2-loop terms of each
/// multipole's kernel coefficients, ~200 estimates of 16 bytes).
pub(crate) const TWO_LOOP_TERMS_BYTES_PER_K: f64 = 3.2e3;

/// Implements [`crate::plan::Plan`] for a plan of 2-loop redshift-space terms `$terms` with the fields
/// `one_loop` ([`RedshiftPlan`]), `precision` and `tensors` ([`LoopTensors`]) and an inherent
/// `terms(spectrum, progress)`. Memory: the process, the 1-loop plan and, with tensors, the 2-loop
/// basis's per-k estimate per spectrum family.
macro_rules! two_loop_rsd_plan {
    ($plan:ty, $terms:ty, $what:literal) => {
        impl crate::plan::Plan for $plan {
            type Settings<'a> = ();
            type Terms = $terms;

            fn describe(&self) -> String {
                format!(concat!($what, " on {} k"), self.k().len())
            }

            fn method(&self) -> crate::plan::Method {
                self.tensors.method()
            }

            fn bytes(&self) -> f64 {
                let nk = self.k().len();
                let tensors = match self.tensors.method() {
                    crate::plan::Method::Direct => 0.0,
                    crate::plan::Method::Basis => {
                        crate::loops::basis::TwoLoopBasis::memory_estimate(nk, &self.precision)
                    }
                };
                crate::memory::PROCESS
                    + crate::loops::redshift::RedshiftPlan::memory_estimate(nk, &self.precision)
                    + tensors
            }

            fn terms_bytes(&self) -> f64 {
                super::spt2::TWO_LOOP_TERMS_BYTES_PER_K * self.k().len() as f64
            }

            fn max_memory(&self) -> Option<f64> {
                self.precision.max_memory
            }

            fn terms(
                &self,
                spectrum: &LinearSpectrum,
                (): (),
                progress: &dyn Progress,
            ) -> Result<$terms> {
                <$plan>::terms(self, spectrum, progress)
            }
        }
    };
}
pub(crate) use two_loop_rsd_plan;

two_loop_rsd_plan!(Spt2Plan, Spt2Terms, "2-loop SPT redshift-space terms");

/// The 1- and 2-loop redshift-space terms of `spectra` (a spectrum and, for IR resummation, its
/// no-wiggle part): from the basis `tensors` when every spectrum is represented by its basis
/// (the 1-loop terms from the plan's own integrals if there are no 1-loop tensors), else integrated
/// directly (the 2-loop terms on the same points for all spectra); with where they came from (a
/// header line).
///
/// # Errors
/// As [`rsd_two_loop_of`].
#[allow(clippy::type_complexity)]
pub(crate) fn loop_terms(
    plan: &RedshiftPlan,
    spectra: &[&LinearSpectrum],
    tensors: &LoopTensors,
    progress: &dyn Progress,
) -> Result<(Vec<RedshiftTerms>, Vec<RsdTwoLoopTerms>, String, MethodNote)> {
    let (k, precision) = (plan.k(), plan.precision());
    let one_on_basis = tensors.one_loop.len() == spectra.len();
    let subject = if one_on_basis {
        "1- and 2-loop terms"
    } else {
        "2-loop terms"
    };
    let (two, note, projections) =
        two_loop_terms_noted(k, spectra, &tensors.two_loop, subject, precision, progress)?;
    let method = match (&projections, tensors.two_loop.is_empty()) {
        (Some(_), _) => "basis",
        (None, false) => crate::output::FALLBACK_RESIDUAL,
        (None, true) => "direct",
    };
    let method = MethodNote::new(subject, method);
    let one = match projections {
        Some(projections) if one_on_basis => spectra
            .iter()
            .zip(&tensors.one_loop)
            .zip(&projections)
            .map(|((s, t), projection)| {
                let p_lin: Vec<f64> = k.iter().map(|&k| s.eval(k)).collect();
                t.evaluate(plan, &p_lin, projection)
            })
            .collect(),
        _ => spectra.iter().map(|s| plan.evaluate(s)).collect(),
    };
    Ok((one, two, note + &few_points_caveat(precision), method))
}

/// Points per shift at low k below which the header warns ([`few_points_caveat`]): 2^13, the
/// count of the default precision there, checked against cosPT (`tests/tests/suite/cospt.rs`).
const VALIDATED_LOW_K_POINTS: usize = 1 << 13;

/// The header's caveat for fewer points at low k than [`VALIDATED_LOW_K_POINTS`] (`--precision
/// fast`: 2^11): with 2^11 there (the default's count before), the 2-loop multipoles at k ≤ 0.1
/// h/Mpc came out 0.7–0.9% smaller in magnitude than cosPT's, all of one sign, beyond their
/// reported errors (8 random shifts miss the rare large contributions of the nearly singular
/// integrand); ≲ 1e-4 of P0.
fn few_points_caveat(precision: &Precision) -> String {
    let points = two_loop_settings(precision).points;
    let low_k = crate::loops::rsd_two_loop::rsd_points_at(0.01, points);
    if low_k >= VALIDATED_LOW_K_POINTS {
        return String::new();
    }
    format!(
        "; caveat: {low_k} 2-loop points per shift at k <= 0.1 h/Mpc, fewer than the \
         {VALIDATED_LOW_K_POINTS} checked against cosPT (--precision default): with 2048 the 2-loop \
         multipoles there ran 0.7-0.9% smaller in magnitude, beyond their errors (<~ 1e-4 of P0)"
    )
}

/// The 2-loop terms of [`loop_terms`], where they came from (without the caveat; from the basis,
/// "`subject` from basis tensors …") and, from the basis, the spectra's projections.
#[allow(clippy::type_complexity)]
fn two_loop_terms_noted(
    k: &[f64],
    spectra: &[&LinearSpectrum],
    tensors: &[Arc<RsdTwoLoopBasis>],
    subject: &str,
    precision: &Precision,
    progress: &dyn Progress,
) -> Result<(Vec<RsdTwoLoopTerms>, String, Option<Vec<Projection>>)> {
    let mut note = String::from("2-loop terms integrated for this spectrum (direct)");
    if tensors.len() == spectra.len() {
        let projections: Vec<_> = spectra
            .iter()
            .zip(tensors)
            .map(|(s, t)| t.project(s))
            .collect();
        if projections.iter().all(RsdTwoLoopBasis::accepts) {
            let residuals: Vec<String> = projections
                .iter()
                .map(|p| format!("{:.1e}", p.residual))
                .collect();
            let terms = tensors
                .iter()
                .zip(&projections)
                .map(|(t, p)| t.evaluate_projected(p))
                .collect();
            let soft = projections
                .iter()
                .find_map(crate::loops::basis::Projection::soft_delta);
            let note = format!(
                "{subject} from basis tensors (projection residual {}; the projection error, {} x \
                 residual x |value|, is in the errors){}",
                residuals.join(", "),
                crate::loops::basis::RSD_PROJECTION_FACTOR,
                crate::loops::basis::soft::describe(soft)
            );
            return Ok((terms, note, Some(projections)));
        }
        note = format!(
            "2-loop terms integrated for this spectrum (direct): its projection residual exceeds {:e}, \
             the basis tensors' limit",
            crate::loops::basis::MAX_RESIDUAL
        );
    }
    let callback = stage_callback(progress, Stage::TwoLoopPoints);
    let terms = rsd_two_loop_of(
        k,
        spectra,
        (precision.q_min, precision.q_max),
        precision.lattice_step,
        &two_loop_settings(precision),
        &callback,
    )?;
    Ok((terms, note, None))
}

/// The basis tensors of `family` on `basis()` as `precision.two_loop` says: built (`basis`), read if
/// cached (`auto`), or none (`direct`).
///
/// # Errors
/// As [`TableStore::for_method`].
pub(crate) fn tensors_of(
    k: &[f64],
    precision: &Precision,
    family: SpectrumFamily,
    basis: &dyn Fn() -> LinearBasis,
    store: &TableStore,
    progress: &dyn Progress,
) -> Result<Option<Arc<RsdTwoLoopBasis>>> {
    let (range, step) = ((precision.q_min, precision.q_max), precision.lattice_step);
    let settings = two_loop_settings(precision);
    let build = |tick: &(dyn Fn(usize, usize) + Sync)| {
        RsdTwoLoopBasis::build(k, range, step, &settings, family, basis(), tick)
    };
    let key = (k, range, step, &settings, family);
    store.for_method::<RsdTwoLoopBasis>(precision.two_loop, key, build, progress)
}

/// The plan of `spt2` on a k grid: the 1-loop weights (cosmology independent), the settings of the
/// 2-loop integration and, with [`with_basis`](Self::with_basis), the 2-loop basis tensors.
#[derive(Debug, Clone)]
pub struct Spt2Plan {
    one_loop: RedshiftPlan,
    precision: Precision,
    tensors: LoopTensors,
}

/// The three parts of the model for one linear spectrum.
#[derive(Debug, Clone, PartialEq)]
pub struct Spt2Terms {
    /// Wavenumbers [h/Mpc].
    pub k: Vec<f64>,
    /// P_lin(k) [(Mpc/h)³].
    pub p_lin: Vec<f64>,
    /// The 1-loop terms.
    pub one_loop: RedshiftTerms,
    /// The 2-loop terms.
    pub two_loop: RsdTwoLoopTerms,
    /// Where the 2-loop terms came from (basis tensors or direct), for a header.
    pub source: String,
    /// The same in a word, for Python's `meta["methods"]`.
    pub method: MethodNote,
}

/// The multipoles of one part or of the whole, per ℓ then per k.
pub type Multipoles = Vec<Vec<Estimate>>;

/// The multipoles of [`Spt2Terms::multipoles`] by part.
#[derive(Debug, Clone, PartialEq)]
pub struct Spt2Multipoles {
    /// Linear Kaiser, (1 + fμ²)² P_lin (exact).
    pub linear: Multipoles,
    /// The 1-loop correction.
    pub one_loop: Multipoles,
    /// The 2-loop correction.
    pub two_loop: Multipoles,
    /// Their sum, errors added.
    pub total: Multipoles,
}

impl Spt2Plan {
    /// The plan for wavenumbers `k` [h/Mpc] with `precision`.
    ///
    /// # Errors
    /// As [`RedshiftPlan::new`].
    pub fn new(k: &[f64], precision: &Precision) -> Result<Self> {
        Ok(Self {
            one_loop: RedshiftPlan::new(k, precision)?,
            precision: precision.clone(),
            tensors: LoopTensors::default(),
        })
    }

    /// The plan with the 2-loop basis tensors as `precision.two_loop` says (`basis`: read or built in
    /// `store`, minutes once per k grid and precision; `auto`: if cached; `direct`: none).
    ///
    /// # Errors
    /// As [`TableStore::for_method`].
    pub fn with_basis(mut self, store: &TableStore, progress: &dyn Progress) -> Result<Self> {
        let lattice = RsdTwoLoopBasis::lattice(
            (self.precision.q_min, self.precision.q_max),
            self.precision.lattice_step,
        );
        let basis = || camb_basis(lattice.clone(), BASIS_SIZE);
        let families: [(_, &dyn Fn() -> LinearBasis); 1] = [(SpectrumFamily::Linear, &basis)];
        self.tensors = LoopTensors::load(&self.one_loop, &families, store, progress)?;
        Ok(self)
    }

    /// The wavenumbers [h/Mpc].
    pub fn k(&self) -> &[f64] {
        self.one_loop.k()
    }

    /// The 2-loop integration settings ([`two_loop_settings`]).
    pub fn two_loop_settings(&self) -> TwoLoopSettings {
        two_loop_settings(&self.precision)
    }

    /// The terms of `spectrum`, the 2-loop ones from the basis tensors when the plan has them and
    /// the spectrum projects well, else integrated (the points reported to `progress`,
    /// [`Stage::TwoLoopPoints`]).
    ///
    /// # Errors
    /// As [`rsd_two_loop_of`].
    pub fn terms(&self, spectrum: &LinearSpectrum, progress: &dyn Progress) -> Result<Spt2Terms> {
        let k = self.k();
        let (mut one, mut two, source, method) =
            loop_terms(&self.one_loop, &[spectrum], &self.tensors, progress)?;
        Ok(Spt2Terms {
            k: k.to_vec(),
            p_lin: k.iter().map(|&k| spectrum.eval(k)).collect(),
            one_loop: one.remove(0),
            two_loop: two.remove(0),
            source,
            method,
        })
    }
}

impl Spt2Terms {
    /// The multipoles ℓ ∈ `ells` (even, ≤ [`super::MAX_ELL`]) at growth rate `f`, by part.
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] for a bad ℓ or a non-finite f.
    pub fn multipoles(&self, f: f64, ells: &[usize]) -> Result<Spt2Multipoles> {
        check_two_loop_ells(ells)?;
        super::check_ells(ells)?;
        if !f.is_finite() {
            return Err(Error::InvalidParameter {
                name: "growth rate f",
                value: f,
                reason: "must be finite",
            });
        }
        let moment = |ell: usize, n: usize| super::polynomial_moment(ell, n);
        let per_ell = |g: &dyn Fn(usize, usize) -> Estimate| -> Multipoles {
            ells.iter()
                .map(|&ell| (0..self.k.len()).map(|i| g(ell, i)).collect())
                .collect()
        };
        let linear = per_ell(&|ell, i| {
            let c = [1.0, 2.0 * f, f * f];
            let v = c
                .iter()
                .enumerate()
                .map(|(n, c)| c * moment(ell, n))
                .sum::<f64>();
            Estimate::new(v * self.p_lin[i], 0.0)
        });
        let params = [1.0, 0.0, 0.0, 0.0, f];
        let coefficients = self.one_loop.coefficients(params);
        let one_loop = per_ell(&|ell, i| {
            let (v, e) = self.one_loop.loop_polynomial_with(i, &coefficients);
            let value = v.iter().enumerate().map(|(n, c)| c * moment(ell, n)).sum();
            Estimate::new(value, (2 * ell + 1) as f64 * e.iter().sum::<f64>())
        });
        let two = self.two_loop.multipoles_at_every_k(f, ells);
        let two_loop: Multipoles = (0..ells.len())
            .map(|l| two.iter().map(|row| row[l]).collect())
            .collect();
        let total = (0..ells.len())
            .map(|l| {
                (0..self.k.len())
                    .map(|i| linear[l][i] + one_loop[l][i] + two_loop[l][i])
                    .collect()
            })
            .collect();
        Ok(Spt2Multipoles {
            linear,
            one_loop,
            two_loop,
            total,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The redshift-space points: at least twice the settings' at every k (the real-space rule's
    /// beyond), so the default has the 2^13 per shift at low k that cosPT checked and only `fast`
    /// gets the header's caveat, with its count.
    #[test]
    fn fewer_low_k_points_than_checked_get_the_caveat() {
        use crate::loops::rsd_two_loop::rsd_points_at;
        let points = two_loop_settings(&Precision::default()).points;
        assert_eq!(rsd_points_at(0.01, points), 1 << 13);
        // k = 0.4: the real-space rule's 2^round(3.5 log2(0.4/0.16)) = 32 times.
        assert_eq!(rsd_points_at(0.4, points), 32 * points);
        assert!(few_points_caveat(&Precision::default()).is_empty());
        assert!(few_points_caveat(&Precision::reference()).is_empty());
        let fast = few_points_caveat(&Precision::fast());
        assert!(fast.contains("caveat: 2048 2-loop points"), "{fast}");
    }
}
