//! The Alcock–Paczynski effect: multipoles as measured in a fiducial cosmology.
//!
//! A survey turns redshifts and angles into distances with a fiducial cosmology; where it differs from
//! the true one, separations along and across the line of sight are scaled by
//!   α∥ = H^fid(z)/H(z) = D_H(z)/D_H^fid(z),   α⊥ = D_M(z)/D_M^fid(z)
//! (velocileptors' `apar`, `aperp`; Ballinger, Peacock & Heavens 1996). The observed spectrum at the
//! fiducial wavevector (k, μ) is the true one at
//!   k' = (k/α⊥) [1 + μ²(F⁻² − 1)]^½,   μ' = (μ/F) [1 + μ²(F⁻² − 1)]^−½,   F = α∥/α⊥,
//! times the volume factor 1/(α∥α⊥²), and its multipoles are
//!   P̂_ℓ(k) = (2ℓ + 1) ∫_0^1 dμ L_ℓ(μ) P^s(k', μ')/(α∥α⊥²).
//!
//! Numerics: the model's P^s(k, μ) (a polynomial in μ² per k, and its Fingers-of-God damping) is
//! computed on an internal log-uniform grid ([`Distortion::internal_grid`], [`POINTS_PER_DECADE`]
//! per decade over the k' that the output needs) and interpolated in ln k by a cubic B-spline
//! ([`spline`]: the μ² coefficients prefiltered once per evaluation by a tridiagonal solve planned
//! once per grid, not-a-knot ends, four weights per cell). The spline is C², so the exact
//! derivatives in α∥, α⊥ (the ept template and cosmological Jacobians) are continuous where k'
//! crosses a cell edge and agree with finite differences to ≤ 7.3e-8 of each column's largest
//! element (the four-point Lagrange polynomials it replaced jumped there: 1.3e-6 for w0); on the
//! BAO-wiggled CAMB spectrum its mid-cell error is 2.4e-5 against Lagrange's 7.3e-5. The grid's
//! error estimates are carried to k by the same weights on their spline coefficients in absolute
//! value. The μ integral is a [`MU_NODES`]-point Gauss–Legendre rule, its error the difference
//! from half as many nodes. Every ℓ ≤ 8 of the true spectrum enters (the polynomial is complete), so
//! the hexadecapole is exact to the interpolation. Wide-angle effects are neglected.

use super::{legendre_coefficients, Fog, MuPolynomial, MAX_MU_POWER};
use crate::cosmology::background::Background;
use crate::cosmology::Cosmology;
use crate::dual::Real;
use crate::error::{Error, Result};
use crate::estimate::Estimate;
use crate::integrate::legendre_nodes;
use spline::UniformSpline;

pub mod spline;

/// Points per decade of the internal k grid.
pub const POINTS_PER_DECADE: f64 = 100.0;
/// Gauss–Legendre nodes of the μ integral on [0, 1] (the error estimate uses half as many).
pub const MU_NODES: usize = 32;
/// The range of α∥, α⊥ of fits and pipelines that free them: [`AP_FIT_RANGE`].0 … .1 (their plans'
/// internal grids cover every distortion in it).
pub const AP_FIT_RANGE: (f64, f64) = (0.8, 1.25);
/// The accepted range of α∥ and α⊥.
pub const ALPHA_RANGE: (f64, f64) = (0.5, 2.0);

/// The scaling parameters α∥ (`apar`) and α⊥ (`aperp`) of the fiducial cosmology.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Distortion {
    /// α∥ = H^fid(z)/H(z).
    pub apar: f64,
    /// α⊥ = D_M(z)/D_M^fid(z).
    pub aperp: f64,
}

impl Distortion {
    /// The distortion of `apar`, `aperp`.
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] unless both are finite and in [`ALPHA_RANGE`].
    pub fn new(apar: f64, aperp: f64) -> Result<Self> {
        for (name, v) in [("apar", apar), ("aperp", aperp)] {
            if !(v.is_finite() && (ALPHA_RANGE.0..=ALPHA_RANGE.1).contains(&v)) {
                return Err(Error::InvalidParameter {
                    name,
                    value: v,
                    reason: "must be in [0.5, 2] (the ratio of a true to a fiducial distance)",
                });
            }
        }
        Ok(Self { apar, aperp })
    }

    /// The distortion of a measurement in the `fiducial` cosmology of the `truth` at redshift `z`:
    /// α∥ = H^fid(z)/H(z), α⊥ = D_M(z)/D_M^fid(z), distances in Mpc/h of each cosmology
    /// ([`crate::cosmology::distance`]; velocileptors' and desilike's convention), by
    /// [`ap_parameters`].
    ///
    /// # Errors
    /// As [`new`](Self::new) for the ratios; [`Error::InvalidParameter`] for z ≤ 0.
    pub fn from_cosmologies(truth: &Cosmology, fiducial: &Cosmology, z: f64) -> Result<Self> {
        let (apar, aperp) = ap_parameters(&truth.background(), fiducial, z)?;
        Self::new(apar, aperp)
    }

    /// (k', μ') of the true spectrum at the observed (k, μ) (module docs).
    pub fn true_coordinates(&self, k: f64, mu: f64) -> (f64, f64) {
        let f = self.apar / self.aperp;
        let stretch = (1.0 + mu * mu * (1.0 / (f * f) - 1.0)).sqrt();
        (k / self.aperp * stretch, mu / (f * stretch))
    }

    /// The volume factor 1/(α∥α⊥²).
    pub fn volume(&self) -> f64 {
        1.0 / (self.apar * self.aperp * self.aperp)
    }

    /// The log-uniform grid [h/Mpc] on which the true spectrum is computed for the observed `k`:
    /// every k' of every μ, two points beyond each end for the interpolation stencil, at least
    /// [`POINTS_PER_DECADE`] per decade and 8 points.
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] for an empty or non-positive `k`.
    pub fn internal_grid(&self, k: &[f64]) -> Result<Vec<f64>> {
        let (lo, hi) = k
            .iter()
            .fold((f64::INFINITY, 0.0_f64), |(a, b), &v| (a.min(v), b.max(v)));
        if !(lo > 0.0 && hi.is_finite()) {
            return Err(Error::InvalidParameter {
                name: "k [h/Mpc]",
                value: lo,
                reason: "the output grid must be non-empty and positive",
            });
        }
        let scale = [1.0 / self.aperp, 1.0 / self.apar];
        let k_min = lo * scale[0].min(scale[1]);
        let k_max = hi * scale[0].max(scale[1]);
        let decades = (k_max / k_min).log10();
        let intervals = ((decades * POINTS_PER_DECADE).ceil() as usize).max(4);
        let step = (k_max / k_min).ln() / intervals as f64;
        Ok((0..intervals + 5)
            .map(|i| (k_min.ln() + step * (i as f64 - 2.0)).exp())
            .collect())
    }
}

/// The Alcock–Paczynski distortion a face asks for (the options `--apar/--aperp`, `--fiducial`, the
/// Python keywords `apar`, `aperp`, an analysis file's `ap`/`fiducial`): the one place where they become
/// a [`Distortion`] (part of [`crate::jobs::ObservationSpec`]).
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub enum ApSpec {
    /// No distortion: the data were measured in the true cosmology.
    #[default]
    None,
    /// α∥, α⊥ given.
    Scalings(Distortion),
    /// α∥, α⊥ of the true cosmology against this fiducial one, at the prediction's redshift.
    Fiducial(Cosmology),
}

impl ApSpec {
    /// The distortion of a face's options: α∥ and α⊥ (both or neither), or a fiducial cosmology, not
    /// both.
    ///
    /// # Errors
    /// [`Error::InvalidChoice`] for one of α∥, α⊥ alone or scalings beside a fiducial cosmology; as
    /// [`Distortion::new`].
    pub fn from_options(
        apar: Option<f64>,
        aperp: Option<f64>,
        fiducial: Option<Cosmology>,
    ) -> Result<Self> {
        let refuse = |reason: &str| Error::InvalidChoice {
            what: "the Alcock-Paczynski distortion".into(),
            reason: reason.into(),
        };
        match (apar, aperp, fiducial) {
            (None, None, None) => Ok(Self::None),
            (None, None, Some(fiducial)) => Ok(Self::Fiducial(fiducial)),
            (Some(a), Some(b), None) => Ok(Self::Scalings(Distortion::new(a, b)?)),
            (Some(_), Some(_), Some(_)) => Err(refuse(
                "give apar and aperp or a fiducial cosmology, not both",
            )),
            _ => Err(refuse("give both apar and aperp (or neither)")),
        }
    }

    /// The distortion of a prediction for the `truth` at redshift `z` (`None` without one).
    ///
    /// # Errors
    /// As [`Distortion::from_cosmologies`].
    pub fn distortion(&self, truth: &Cosmology, z: f64) -> Result<Option<Distortion>> {
        match self {
            Self::None => Ok(None),
            Self::Scalings(d) => Ok(Some(*d)),
            Self::Fiducial(fiducial) => Ok(Some(Distortion::from_cosmologies(truth, fiducial, z)?)),
        }
    }

    /// Whether a fit frees α∥ or α⊥ (`free` names the free parameters), checked to have a distortion
    /// to start from.
    ///
    /// # Errors
    /// [`Error::InvalidChoice`] if `free` holds `apar` or `aperp` and there is no distortion.
    pub fn check_free(distortion: Option<&Distortion>, free: &[String]) -> Result<bool> {
        let free_ap = free.iter().any(|n| n == "apar" || n == "aperp");
        if free_ap && distortion.is_none() {
            return Err(Error::InvalidChoice {
                what: "free apar/aperp".into(),
                reason: "they need the measurement's distortion: apar and aperp, or a fiducial \
                         cosmology"
                    .into(),
            });
        }
        Ok(free_ap)
    }
}

/// The scaling parameters (α∥, α⊥) = (H^fid(z)/H(z), D_M(z)/D_M^fid(z)) of a measurement in the
/// `fiducial` cosmology of the `truth` at redshift `z` (module docs), distances in Mpc/h of each
/// cosmology ([`crate::cosmology::distance`]). Generic over the [`Real`] type of the truth's
/// parameters: on [`Cosmology::seeded`] they carry their exact derivatives with respect to the
/// sampled parameters (the fiducial cosmology is fixed). [`Distortion::from_cosmologies`] is this
/// on `f64`, with the range check of [`Distortion::new`].
///
/// # Errors
/// [`Error::InvalidParameter`] for z ≤ 0 or not finite (there is no distortion at z = 0).
pub fn ap_parameters<T: Real>(
    truth: &Background<T>,
    fiducial: &Cosmology,
    z: f64,
) -> Result<(T, T)> {
    if !(z.is_finite() && z > 0.0) {
        return Err(Error::InvalidParameter {
            name: "z",
            value: z,
            reason: "must be positive for the Alcock-Paczynski distortion (none at z = 0)",
        });
    }
    let fiducial = fiducial.background();
    Ok((
        T::cst(fiducial.hubble(z)) / truth.hubble(z),
        truth.transverse_comoving_distance(z) / fiducial.transverse_comoving_distance(z),
    ))
}

/// The observed multipoles `ells` at `k_out` of the model whose P^s(k, μ) before damping is `polys`
/// on the log-uniform `grid` (from [`Distortion::internal_grid`]), with the damping `fog` of scale
/// `sigma` [Mpc/h]: `out[j][i]` for the j-th ℓ at the i-th k, with its error (the coefficients'
/// errors, propagated, plus the μ quadrature's).
///
/// # Errors
/// [`Error::LengthMismatch`] if `polys` is not on `grid`; [`Error::OutOfRange`] if an output k needs
/// the spectrum outside the grid; [`Error::InvalidParameter`] for ℓ > 8 or odd.
pub fn observed_multipoles(
    grid: &[f64],
    polys: &[MuPolynomial],
    fog: Fog,
    sigma: f64,
    ap: &Distortion,
    ells: &[usize],
    k_out: &[f64],
) -> Result<Vec<Vec<Estimate>>> {
    if grid.len() != polys.len() {
        return Err(Error::LengthMismatch {
            what: "model polynomials and their k grid",
            left: polys.len(),
            right: grid.len(),
        });
    }
    if grid.len() < 4 {
        return Err(Error::TooFewPoints {
            origin: "the internal k grid of the Alcock-Paczynski projection".into(),
            found: grid.len(),
            min: 4,
        });
    }
    super::check_ells(ells)?;
    let (x0, step) = (
        grid[0].ln(),
        (grid[grid.len() - 1] / grid[0]).ln() / (grid.len() - 1) as f64,
    );
    // The spline coefficients (module spline) of the polynomials' value and error coefficients.
    let spline = UniformSpline::new(grid.len());
    let prefilter = |column: fn(&MuPolynomial) -> &[f64; MAX_MU_POWER + 1]| {
        let mut c: Vec<[f64; MAX_MU_POWER + 1]> = polys.iter().map(|p| *column(p)).collect();
        spline.prefilter(&mut c);
        c
    };
    let (values, errors) = (prefilter(|p| &p.value), prefilter(|p| &p.error));
    // The polynomial (value and error coefficients) at ln k = x: the cubic B-spline on the grid,
    // the errors' spline coefficients in absolute value (the grid's error estimates carried to k as
    // the values are).
    let at = |k: f64| -> Result<MuPolynomial> {
        let (b, t) = spline
            .cell((k.ln() - x0) / step)
            .ok_or_else(|| Error::OutOfRange {
                what: "the true spectrum of the Alcock-Paczynski projection".into(),
                k,
                min: grid[1],
                max: grid[grid.len() - 2],
            })?;
        let w = spline::weights(t);
        let mut p = MuPolynomial::default();
        for (j, wj) in w.iter().enumerate() {
            for n in 0..p.value.len() {
                p.value[n] += wj * values[b + j][n];
                p.error[n] += wj * errors[b + j][n].abs();
            }
        }
        Ok(p)
    };
    let rules = [MU_NODES, MU_NODES / 2].map(|n| {
        let (x, w) = legendre_nodes(n);
        // On [0, 1].
        let nodes: Vec<(f64, f64)> = x
            .iter()
            .zip(&w)
            .map(|(&x, &w)| (0.5 * (x + 1.0), 0.5 * w))
            .collect();
        nodes
    });
    let legendre: Vec<Vec<f64>> = ells.iter().map(|&l| legendre_coefficients(l)).collect();
    let volume = ap.volume();
    let mut out = vec![Vec::with_capacity(k_out.len()); ells.len()];
    for &k in k_out {
        let mut sums = [vec![0.0; ells.len()], vec![0.0; ells.len()]];
        let mut spread = vec![0.0; ells.len()];
        for (r, nodes) in rules.iter().enumerate() {
            for &(mu, w) in nodes {
                let (kt, mt) = ap.true_coordinates(k, mu);
                let p = at(kt)?;
                let damping = fog.damping_squared(kt * mt * sigma);
                let m2 = mt * mt;
                let value =
                    p.value.iter().rev().fold(0.0, |acc, c| acc * m2 + c) * damping * volume;
                let error =
                    p.error.iter().rev().fold(0.0, |acc, c| acc * m2 + c) * damping * volume;
                for (j, l) in ells.iter().enumerate() {
                    let lj = polynomial(&legendre[j], mu);
                    sums[r][j] += w * (2 * l + 1) as f64 * lj * value;
                    if r == 0 {
                        spread[j] += w * (2 * l + 1) as f64 * lj.abs() * error;
                    }
                }
            }
        }
        for j in 0..ells.len() {
            let quadrature = (sums[0][j] - sums[1][j]).abs();
            out[j].push(Estimate::new(sums[0][j], spread[j] + quadrature));
        }
    }
    Ok(out)
}

/// Σ_j c_j μ^j.
fn polynomial(c: &[f64], mu: f64) -> f64 {
    c.iter().rev().fold(0.0, |acc, c| acc * mu + c)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn coordinates_map_back_and_the_identity_is_the_identity() {
        let id = Distortion::new(1.0, 1.0).unwrap();
        assert_eq!(id.true_coordinates(0.1, 0.3), (0.1, 0.3));
        let d = Distortion::new(1.1, 0.95).unwrap();
        // Along the line of sight k' = k/α∥, across k' = k/α⊥, and μ' = ±1 at μ = ±1.
        let (k, m) = d.true_coordinates(0.2, 1.0);
        assert!((k - 0.2 / 1.1).abs() < 1e-15 && (m - 1.0).abs() < 1e-15);
        let (k, m) = d.true_coordinates(0.2, 0.0);
        assert!((k - 0.2 / 0.95).abs() < 1e-15 && m == 0.0);
        // k'∥ = kμ/α∥ and k'⊥ = k√(1 − μ²)/α⊥.
        let (k, m) = d.true_coordinates(0.2, 0.6);
        assert!((k * m - 0.2 * 0.6 / 1.1).abs() < 1e-15);
        assert!((k * (1.0 - m * m).sqrt() - 0.2 * 0.8 / 0.95).abs() < 1e-15);
        for bad in [0.0, -1.0, f64::NAN, 3.0] {
            assert!(Distortion::new(bad, 1.0).is_err() && Distortion::new(1.0, bad).is_err());
        }
    }

    /// A μ-independent constant P (Kaiser with b = 1, f = 0 of a flat spectrum): P̂_ℓ = P/(α∥α⊥²) δ_ℓ0.
    #[test]
    fn a_constant_isotropic_spectrum_only_changes_volume() {
        let d = Distortion::new(1.2, 0.9).unwrap();
        let grid = d.internal_grid(&[0.05, 0.1]).unwrap();
        let mut c = MuPolynomial::default();
        c.value[0] = 1000.0;
        let polys = vec![c; grid.len()];
        let m = observed_multipoles(&grid, &polys, Fog::None, 0.0, &d, &[0, 2, 4], &[0.05, 0.1])
            .unwrap();
        for ((p0, p2), p4) in m[0].iter().zip(&m[1]).zip(&m[2]) {
            assert!((p0.value - 1000.0 * d.volume()).abs() < 1e-10);
            assert!(p2.value.abs() < 1e-10 && p4.value.abs() < 1e-10);
        }
    }

    /// The exact (dual) derivatives of α∥ and α⊥ with respect to the eight sampled parameters of the
    /// truth against Richardson-extrapolated finite differences of [`Distortion::from_cosmologies`],
    /// at ΛCDM, w0–wa, open, closed and massless-neutrino truths (at Σm_ν = 0 without the Σm_ν
    /// derivative, as for the distances); the `f64` path is [`ap_parameters`] exactly.
    #[test]
    fn dual_ap_derivatives_match_finite_differences() {
        use crate::cosmology::finite_difference::{check_derivatives, derivative_cosmologies};
        let fiducial = Cosmology::flat(0.31, 0.676, 0.022, 0.965, 0.8).unwrap();
        for (label, truth) in derivative_cosmologies() {
            check_derivatives(
                label,
                &truth,
                &["alpha_par", "alpha_perp"],
                |b, z| {
                    let (apar, aperp) = ap_parameters(b, &fiducial, z).unwrap();
                    vec![apar, aperp]
                },
                |c, z| {
                    let d = Distortion::from_cosmologies(c, &fiducial, z).unwrap();
                    vec![d.apar, d.aperp]
                },
                true,
            );
            let d = Distortion::from_cosmologies(&truth, &fiducial, 1.0).unwrap();
            let (apar, aperp) = ap_parameters(&truth.background(), &fiducial, 1.0).unwrap();
            assert_eq!((d.apar, d.aperp), (apar, aperp));
        }
        let seeded = Cosmology::planck2018().seeded().unwrap();
        assert!(ap_parameters(&seeded, &fiducial, 0.0).is_err());
    }

    #[test]
    fn a_face_asks_for_the_distortion_one_way_and_gets_it_from_one_place() {
        let (truth, fiducial) = (Cosmology::planck2018(), Cosmology::gm2012());
        assert_eq!(
            ApSpec::from_options(None, None, None).unwrap(),
            ApSpec::None
        );
        assert_eq!(ApSpec::None.distortion(&truth, 0.5).unwrap(), None);
        let given = ApSpec::from_options(Some(1.02), Some(0.98), None).unwrap();
        assert_eq!(
            given.distortion(&truth, 0.5).unwrap(),
            Some(Distortion::new(1.02, 0.98).unwrap())
        );
        let from_fiducial = ApSpec::from_options(None, None, Some(fiducial)).unwrap();
        assert_eq!(
            from_fiducial.distortion(&truth, 0.5).unwrap(),
            Some(Distortion::from_cosmologies(&truth, &fiducial, 0.5).unwrap())
        );
        for (apar, aperp, fid) in [
            (Some(1.0), None, None),
            (None, Some(1.0), None),
            (Some(1.0), Some(1.0), Some(fiducial)),
            (Some(1.0), None, Some(fiducial)),
        ] {
            let err = ApSpec::from_options(apar, aperp, fid)
                .unwrap_err()
                .to_string();
            assert!(err.contains("apar"), "{err}");
        }
        assert!(ApSpec::from_options(Some(3.0), Some(1.0), None).is_err());
        let free = |names: &[&str]| names.iter().map(|s| s.to_string()).collect::<Vec<_>>();
        let d = Distortion::new(1.0, 1.0).unwrap();
        assert!(!ApSpec::check_free(None, &free(&["f", "b1"])).unwrap());
        assert!(ApSpec::check_free(Some(&d), &free(&["f", "aperp"])).unwrap());
        let err = ApSpec::check_free(None, &free(&["apar"]))
            .unwrap_err()
            .to_string();
        assert!(err.contains("distortion"), "{err}");
    }
}
