//! The exact derivatives of the data vector with respect to the sampled cosmological parameters
//! ([`DERIVATIVE_NAMES`]: h, ω_b, ω_cdm, ln(10¹⁰A_s), n_s, Σm_ν, w0, wa), by the chain rule through
//! every stage, with no finite differences:
//!
//! dD/dθ = M [∂m/∂P · dP/dθ] + ∂D/∂f · df/dθ + ∂D/∂α∥ · dα∥/dθ + ∂D/∂α⊥ · dα⊥/dθ,
//!
//! - dP/dθ and df/dθ: the emulated tracer spectrum and its growth rate over dual numbers
//!   ([`crate::emulator::LinearEmulator::tracer_tangent`]: the principal components' polynomials, the
//!   growth ODE, the drag horizon that places the nodes, the spline through them);
//! - ∂m/∂P · δP: the loop terms' and multipoles' tangent along δP ([`crate::rsd::ept::tangent`]: the
//!   basis terms are quadratic in the spectrum, Σ²'s damping written out), then the observation
//!   matrix M;
//! - ∂D/∂f, ∂D/∂α: the template derivatives ([`CosmologyStep::template_jacobian`](super::CosmologyStep::template_jacobian));
//! - dα/dθ: α∥ = H_fid/H, α⊥ = D_M/D_M,fid over dual numbers ([`crate::rsd::ap::ap_parameters`]).
//!
//! A given `f` (a template fit's free growth rate) is a nuisance parameter: f's column then does
//! not enter the cosmological ones.

use super::linearised::{nuisance_jacobian, unit_sets};
use super::Pipeline;
use crate::cosmology::background::{CosmoDual, DERIVATIVE_NAMES, N_DERIVATIVES};
use crate::cosmology::Cosmology;
use crate::dual::Real;
use crate::error::{Error, Result};
use crate::rsd::ap::{ap_parameters, Distortion};
use crate::rsd::ept::tangent::TermsTangent;

/// The data vector of one cosmology with its exact derivatives.
#[derive(Debug, Clone)]
pub struct CosmologyJacobian {
    /// The data vector ([`Pipeline::len`]).
    pub data_vector: Vec<f64>,
    /// d(data vector)/dθ for θ in [`Self::names`] (all of [`DERIVATIVE_NAMES`], or those asked of
    /// [`Pipeline::full_jacobian_of`]), one column each.
    pub cosmological: Vec<Vec<f64>>,
    /// The names of [`Self::cosmological`]'s columns, in their order.
    names: Vec<&'static str>,
    /// The growth rate f used (the cosmology's, or the one given) with its derivatives (zero for a
    /// given f).
    pub growth_rate: CosmoDual,
    /// α∥ and α⊥ of the cosmology against the fiducial with their derivatives (`None` without
    /// fiducial).
    pub ap: Option<(CosmoDual, CosmoDual)>,
}

impl CosmologyJacobian {
    /// The names of [`Self::cosmological`]'s columns.
    pub fn names(&self) -> &[&'static str] {
        &self.names
    }
}

impl Pipeline {
    /// The data vector of `cosmology` (through the emulator) at the nuisance parameters `params`
    /// (by name, as [`Self::evaluate`]; `f` defaults to f(z) of the cosmology) and its exact
    /// derivatives with respect to [`DERIVATIVE_NAMES`] (module docs). The nuisance parameters'
    /// derivatives are [`CosmologyStep::jacobian`](super::CosmologyStep::jacobian)'s.
    ///
    /// # Errors
    /// As [`Self::evaluate`]; [`Error::InvalidChoice`] for a cosmology normalised by σ8, a pipeline
    /// with blocks after the power spectrum or without basis tensors, or a spectrum outside the basis's span (the
    /// direct integrals have no exact derivative).
    pub fn cosmology_jacobian(
        &self,
        cosmology: &Cosmology,
        params: &[(&str, f64)],
    ) -> Result<CosmologyJacobian> {
        Ok(self
            .jacobians(cosmology, params, &DERIVATIVE_NAMES, false)?
            .0)
    }

    /// [`Self::cosmology_jacobian`] and the nuisance parameters' rows ([`CosmologyStep::jacobian`](super::CosmologyStep::jacobian):
    /// one per name of [`super::JACOBIAN_NAMES`], f's last) of the same step, made once: the whole
    /// Jacobian of a sampler over cosmological and nuisance parameters.
    ///
    /// # Errors
    /// As [`Self::cosmology_jacobian`] and [`CosmologyStep::jacobian`](super::CosmologyStep::jacobian).
    pub fn full_jacobian(
        &self,
        cosmology: &Cosmology,
        params: &[(&str, f64)],
    ) -> Result<(CosmologyJacobian, Vec<Vec<f64>>)> {
        self.full_jacobian_of(cosmology, params, &DERIVATIVE_NAMES)
    }

    /// [`Self::full_jacobian`] with the cosmological columns of `derivatives` only (names of
    /// [`DERIVATIVE_NAMES`], in the order wanted): a sampler of flat ΛCDM needs no Σm_ν, w0 or wa
    /// column, and each column costs its own loop terms' tangent, projection and observation (measured:
    /// five of the eight take 13–20% less time than all eight). The columns asked for are the same numbers as
    /// [`Self::full_jacobian`]'s.
    ///
    /// # Errors
    /// As [`Self::full_jacobian`]; [`Error::InvalidChoice`] naming a name that is not in
    /// [`DERIVATIVE_NAMES`] or is given twice.
    pub fn full_jacobian_of(
        &self,
        cosmology: &Cosmology,
        params: &[(&str, f64)],
        derivatives: &[&str],
    ) -> Result<(CosmologyJacobian, Vec<Vec<f64>>)> {
        let (cosmological, nuisance) = self.jacobians(cosmology, params, derivatives, true)?;
        Ok((cosmological, nuisance.unwrap_or_default()))
    }

    /// [`Self::cosmology_jacobian`] with the columns of `derivatives` only ([`Self::full_jacobian_of`]).
    ///
    /// # Errors
    /// As [`Self::full_jacobian_of`].
    pub fn cosmology_jacobian_of(
        &self,
        cosmology: &Cosmology,
        params: &[(&str, f64)],
        derivatives: &[&str],
    ) -> Result<CosmologyJacobian> {
        Ok(self.jacobians(cosmology, params, derivatives, false)?.0)
    }

    /// The cosmological derivatives along `derivatives` and, if `nuisance`, the nuisance rows of the
    /// same step.
    fn jacobians(
        &self,
        cosmology: &Cosmology,
        params: &[(&str, f64)],
        derivatives: &[&str],
        nuisance: bool,
    ) -> Result<(CosmologyJacobian, Option<Vec<Vec<f64>>>)> {
        let columns = derivative_columns(derivatives)?;
        if let Some(b) = self.blocks.first() {
            return Err(Error::InvalidChoice {
                what: format!(
                    "the cosmological derivatives of a pipeline with a {} block",
                    b.kind().name
                ),
                reason: "they are built for the power spectrum only".into(),
            });
        }
        let z = self.settings.z;
        let seeded = cosmology.seeded()?;
        let tangent = self.emulator.tracer_tangent(cosmology, z)?;
        let f = match params.iter().find(|(n, _)| *n == "f") {
            Some(&(_, f)) => CosmoDual::cst(f),
            None => tangent.growth_rate(),
        };
        let ap = match &self.settings.fiducial {
            Some(fid) => Some(ap_parameters(&seeded, fid, z)?),
            None => None,
        };
        // the values of the f64 path (the duals' can differ in the last bits)
        let distortion = match &self.settings.fiducial {
            Some(fid) => Some(Distortion::from_cosmologies(cosmology, fid, z)?),
            None => None,
        };
        let spectrum = tangent.spectrum();
        let step = self.step_with(spectrum, f.value(), distortion)?;
        let p = step.params(params)?;
        // the nuisance polynomial's sets, f's row and the spectrum's columns in one projection
        // onto the multipoles (its weights cost more than applying them); the data vector by the
        // path of `evaluate`, so that the two are the same numbers
        let tangents = self.terms_tangents(&tangent, &columns)?;
        let sets = if nuisance {
            unit_sets(p.f())
        } else {
            Vec::new()
        };
        let projected = self.plan.multipoles_with_tangents(
            &step.terms,
            &sets,
            std::slice::from_ref(&p),
            (&tangents, &p),
            self.observation.model_ells(),
            step.ap,
        )?;
        let observe =
            |m: &[Vec<Vec<f64>>]| -> Vec<Vec<f64>> { m.iter().map(|m| self.observe(m)).collect() };
        let mut d_f = observe(&projected.df);
        let mut cosmological = observe(&projected.tangents);
        let data_vector = step.data_vector(params)?;
        let nuisance = if nuisance {
            let vectors = observe(&projected.values);
            Some(nuisance_jacobian(vectors, d_f.clone(), p.f(), params)?.1)
        } else {
            None
        };
        let d_f = d_f.remove(0);
        let [d_apar, d_aperp] = if self.settings.fiducial.is_some() {
            step.ap_jacobian(params)?
        } else {
            [vec![0.0; data_vector.len()], vec![0.0; data_vector.len()]]
        };
        let (dapar, daperp) = ap.map_or(([0.0; N_DERIVATIVES], [0.0; N_DERIVATIVES]), |(a, b)| {
            (a.d, b.d)
        });
        for (&j, column) in columns.iter().zip(cosmological.iter_mut()) {
            for (i, c) in column.iter_mut().enumerate() {
                *c += d_f[i] * f.d[j] + d_apar[i] * dapar[j] + d_aperp[i] * daperp[j];
            }
        }
        let jacobian = CosmologyJacobian {
            data_vector,
            cosmological,
            names: columns.iter().map(|&j| DERIVATIVE_NAMES[j]).collect(),
            growth_rate: f,
            ap,
        };
        Ok((jacobian, nuisance))
    }

    /// The loop terms' tangents along the spectrum's derivatives dP/dθ_j, j in `columns`.
    fn terms_tangents(
        &self,
        tangent: &crate::emulator::TracerTangent,
        columns: &[usize],
    ) -> Result<Vec<TermsTangent>> {
        let Some((lattice, grid)) = self.plan.tangent_nodes() else {
            return Err(Error::InvalidChoice {
                what: "the cosmological derivatives of a pipeline without basis tensors".into(),
                reason: "the loop terms' derivative is built on the basis".into(),
            });
        };
        let (on_lattice, on_grid) = (tangent.eval_many(&lattice), tangent.eval_many(grid));
        let column = |values: &[CosmoDual], j: usize| -> Vec<f64> {
            values.iter().map(|v| v.d[j]).collect()
        };
        let directions: Vec<(Vec<f64>, Vec<f64>)> = columns
            .iter()
            .map(|&j| (column(&on_lattice, j), column(&on_grid, j)))
            .collect();
        self.plan.terms_tangents(tangent.spectrum(), &directions)
    }
}

/// The indices in [`DERIVATIVE_NAMES`] of `names`, in their order.
///
/// # Errors
/// [`Error::InvalidChoice`] naming a name that is not a sampled cosmological parameter, or one given
/// twice.
fn derivative_columns(names: &[&str]) -> Result<Vec<usize>> {
    let mut columns = Vec::with_capacity(names.len());
    for (i, name) in names.iter().enumerate() {
        let bad = |reason: String| Error::InvalidChoice {
            what: format!("the cosmological derivative `{name}`"),
            reason,
        };
        let j = DERIVATIVE_NAMES
            .iter()
            .position(|n| n == name)
            .ok_or_else(|| {
                bad(format!(
                    "not a sampled parameter (they are {})",
                    DERIVATIVE_NAMES.join(", ")
                ))
            })?;
        if names[..i].contains(name) {
            return Err(bad("asked for twice".into()));
        }
        columns.push(j);
    }
    Ok(columns)
}
