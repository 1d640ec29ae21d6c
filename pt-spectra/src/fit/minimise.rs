//! χ² of one fit window and its minimisation: Nelder–Mead over the free parameters, 1-D Brent along one,
//! and the profile χ² with some parameters held at given values and the others re-minimised.

use super::{MultipoleData, MultipoleModel, Parameter, Params};
use crate::error::{Error, Result};
use crate::linalg::{cholesky, invert_lower};
use argmin::core::{CostFunction, Executor, State};
use argmin::solver::brent::BrentOpt;
use argmin::solver::neldermead::NelderMead;

/// The data of one fit window (k_min ≤ k ≤ k_max) and its χ².
pub(super) struct Residuals<'a> {
    model: &'a MultipoleModel,
    /// Data indices of the model k (the model is built on the data grid).
    range: std::ops::Range<usize>,
    /// L⁻¹ of the Cholesky factor of the covariance window, or `None` for the diagonal σ.
    inverse_factor: Option<Vec<Vec<f64>>>,
    data_vector: Vec<f64>,
    sigma_vector: Vec<f64>,
}

impl<'a> Residuals<'a> {
    /// The window k ∈ [k_min, k_max] of `data` against `model` (on the data grid), for a fit with
    /// `n_free` free parameters.
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] if the window holds no more points than `n_free`, or its covariance
    /// block is not positive definite.
    pub(super) fn new(
        model: &'a MultipoleModel,
        data: &MultipoleData,
        k_min: f64,
        k_max: f64,
        n_free: usize,
    ) -> Result<Self> {
        let (start, end) = data.range(k_min, k_max);
        let points = (end - start) * data.ells.len();
        if points <= n_free {
            return Err(Error::InvalidParameter {
                name: "k_max [h/Mpc]",
                value: k_max,
                reason: "leaves no more data points than free parameters",
            });
        }
        let mut data_vector = Vec::with_capacity(points);
        let mut sigma_vector = Vec::with_capacity(points);
        for j in 0..data.ells.len() {
            data_vector.extend(&data.values[j][start..end]);
            sigma_vector.extend(&data.sigma[j][start..end]);
        }
        let inverse_factor = match &data.covariance {
            None => None,
            Some(c) => {
                let n_all = data.k.len();
                let ids: Vec<usize> = (0..data.ells.len())
                    .flat_map(|j| (start..end).map(move |i| j * n_all + i))
                    .collect();
                let sub: Vec<Vec<f64>> = ids
                    .iter()
                    .map(|&a| ids.iter().map(|&b| c[a][b]).collect())
                    .collect();
                crate::fit::covariance::check_conditioning(
                    &sub,
                    &format!("the {} fitted points", ids.len()),
                    &|r| {
                        let (j, i) = (ids[r] / n_all, ids[r] % n_all);
                        format!("P{} at k = {} h/Mpc", data.ells[j], data.k[i])
                    },
                )?;
                let l = cholesky(&sub).ok_or(Error::InvalidParameter {
                    name: "k_max [h/Mpc]",
                    value: k_max,
                    reason: "the covariance window is not positive definite",
                })?;
                Some(invert_lower(&l))
            }
        };
        Ok(Self {
            model,
            range: start..end,
            inverse_factor,
            data_vector,
            sigma_vector,
        })
    }

    /// The number of data points in the window.
    pub(super) fn points(&self) -> usize {
        self.data_vector.len()
    }

    /// χ² at `p`.
    pub(super) fn chi2(&self, p: &Params) -> f64 {
        let mut r = vec![0.0; self.data_vector.len()];
        self.model.multipoles_into(p, self.range.clone(), &mut r);
        for (r, d) in r.iter_mut().zip(&self.data_vector) {
            *r = d - *r;
        }
        match &self.inverse_factor {
            None => r
                .iter()
                .zip(&self.sigma_vector)
                .map(|(r, s)| (r / s).powi(2))
                .sum(),
            Some(l) => l
                .iter()
                .map(|row| row.iter().zip(&r).map(|(a, b)| a * b).sum::<f64>().powi(2))
                .sum(),
        }
    }
}

/// χ² as a function of the free parameters, the others at `base`.
pub(super) struct Window<'a> {
    pub(super) residuals: &'a Residuals<'a>,
    pub(super) base: Params,
    pub(super) free: Vec<Parameter>,
}

impl Window<'_> {
    /// `base` with the free parameters set to `x`.
    pub(super) fn params(&self, x: &[f64]) -> Params {
        let mut p = self.base;
        for (&name, &v) in self.free.iter().zip(x) {
            p.set(name, v);
        }
        p
    }

    fn chi2(&self, p: &Params) -> f64 {
        self.residuals.chi2(p)
    }

    /// The profile χ²: the parameters of `fixed` at their given values, the other free parameters
    /// minimised (none: a direct evaluation; one: 1-D Brent within 20 `steps` of `best`; more:
    /// Nelder–Mead from `best`). `steps[i]` is the starting step of the i-th free parameter. Returns the
    /// minimum and the point where it is reached.
    pub(super) fn profile(
        &self,
        fixed: &[(Parameter, f64)],
        best: &Params,
        steps: &[f64],
    ) -> (f64, Params) {
        let others: Vec<(usize, Parameter)> = self
            .free
            .iter()
            .copied()
            .enumerate()
            .filter(|&(_, p)| fixed.iter().all(|f| f.0 != p))
            .collect();
        let mut p = *best;
        for &(name, v) in fixed {
            p.set(name, v);
        }
        match others.len() {
            0 => (self.chi2(&p), p),
            1 => {
                let (i, other) = others[0];
                let centre = best.get(other);
                let span = 20.0 * steps[i];
                let line = Line {
                    window: self,
                    point: p,
                    parameter: other,
                };
                let solver =
                    BrentOpt::new(centre - span, centre + span).set_tolerance(1e-10, 1e-12);
                match Executor::new(line, solver)
                    .configure(|s| s.param(centre).max_iters(200))
                    .run()
                {
                    Ok(r) => {
                        let s = r.state();
                        p.set(other, s.get_best_param().copied().unwrap_or(centre));
                        (s.get_best_cost(), p)
                    }
                    Err(_) => (f64::INFINITY, p),
                }
            }
            _ => {
                let sub = Window {
                    residuals: self.residuals,
                    base: p,
                    free: others.iter().map(|o| o.1).collect(),
                };
                let x0: Vec<f64> = others.iter().map(|&(_, o)| best.get(o)).collect();
                let o_steps: Vec<f64> = others.iter().map(|&(i, _)| steps[i]).collect();
                let (x, chi2) = minimise(&sub, &x0, &o_steps);
                (chi2, sub.params(&x))
            }
        }
    }
}

/// χ² along one parameter with the others fixed.
struct Line<'a> {
    window: &'a Window<'a>,
    point: Params,
    parameter: Parameter,
}

impl CostFunction for Line<'_> {
    type Param = f64;
    type Output = f64;

    fn cost(&self, x: &f64) -> std::result::Result<f64, argmin::core::Error> {
        let mut p = self.point;
        p.set(self.parameter, *x);
        Ok(self.window.chi2(&p))
    }
}

/// Nelder–Mead from `x0` with initial simplex steps `steps`; (best point, χ²).
pub(super) fn minimise(window: &Window, x0: &[f64], steps: &[f64]) -> (Vec<f64>, f64) {
    let mut simplex = vec![x0.to_vec()];
    for (i, s) in steps.iter().enumerate() {
        let mut v = x0.to_vec();
        v[i] += s;
        simplex.push(v);
    }
    let solver = NelderMead::new(simplex)
        .with_sd_tolerance(1e-10)
        .expect("valid tolerance");
    match Executor::new(window, solver)
        .configure(|s| s.max_iters(2000))
        .run()
    {
        Ok(r) => {
            let s = r.state();
            (
                s.get_best_param().cloned().unwrap_or_else(|| x0.to_vec()),
                s.get_best_cost(),
            )
        }
        Err(_) => (x0.to_vec(), f64::INFINITY),
    }
}

impl CostFunction for &Window<'_> {
    type Param = Vec<f64>;
    type Output = f64;

    fn cost(&self, x: &Vec<f64>) -> std::result::Result<f64, argmin::core::Error> {
        Ok(self.chi2(&self.params(x)))
    }
}

/// The starting simplex steps of the free parameters `free` at their start values `x0`: 5% of each, at
/// least 0.005 (f, σ0, A_b) or 0.05 (Mpc/h)² (c_s², whose start is usually 0 and whose values are of
/// order 1 (Mpc/h)²: the interval search then reaches ±40 (Mpc/h)² in its 12 doublings).
pub(super) fn steps(free: &[Parameter], x0: &[f64]) -> Vec<f64> {
    free.iter()
        .zip(x0)
        .map(|(&p, v)| {
            let floor = if p == Parameter::Cs2 { 1.0 } else { 0.1 };
            0.05 * v.abs().max(floor)
        })
        .collect()
}
