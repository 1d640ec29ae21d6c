//! The 2-loop redshift-space terms ([`crate::loops::rsd_two_loop`]) of a new linear spectrum from
//! basis tensors: the same quasi-Monte-Carlo points, shifts and legs as the direct integral, each point
//! adding the products of basis functions φ_a(q₁)φ_b(q₂)φ_c(z) of its legs, per coefficient of
//! f^m μ^{2j} (j ≤ m: 28 of them), so that the contraction with c ⊗ c ⊗ c of the spectrum's projection
//! gives the direct result for the projected spectrum to round-off.
//!
//! The error is the spread over the shifts (contracted on the first [`ERROR_FUNCTIONS`] coefficients,
//! as the real-space tensors, each shift's deviation from the mean stored in bfloat16: a rounding of
//! ≤ 0.4% of each entry, in an estimate of the error, for half the bytes a new spectrum streams)
//! plus the projection error ε|value| with ε = [`RSD_PROJECTION_FACTOR`] × the smoothed projection
//! residual; spectra whose residual exceeds [`MAX_RESIDUAL`] are refused (the caller integrates them
//! directly).

use super::low_rank::{LowRank, TRIPLE_TOLERANCE};
use super::tensors::{fold, rank_update};
use super::{
    after_key, cache_file_name, error_functions, pair_index, shift_statistics, triple_products,
    triples, LinearBasis, Projection, SpectrumFamily, BASIS_SIZE, ERROR_FUNCTIONS, MAX_RESIDUAL,
};
use crate::linear::LinearSpectrum;
use crate::loops::lattice::Lattice;
use crate::loops::rsd_two_loop::{
    rsd_points_at, to_coefficients, RsdTwoLoopTerms, Sampling, COEFFICIENTS,
};
use crate::loops::two_loop::integral_scale;
use crate::loops::TwoLoopSettings;
use crate::simd::{from_bf16, matvec_bf16, to_bf16};
use rayon::prelude::*;
use std::sync::atomic::{AtomicUsize, Ordering};

/// Version of the layout, part of the cache file name.
const VERSION: u32 = 3;

/// Points per batch of the rank update.
const BATCH: usize = 32;

/// The projection error of a 2-loop redshift-space value is this times the smoothed projection
/// residual times its size: on two CAMB and one CLASS spectrum outside the training set the basis
/// multipoles differed from direct by at most 5.1 times residual × |value| (CLASS Planck 2018 at
/// k = 0.2, residual 1.9e-4; tests/tests/suite/rsd_two_loop.rs, which fails above this factor); about
/// twice that, to be safe.
pub const RSD_PROJECTION_FACTOR: f64 = 10.0;

/// The basis tensors of the 2-loop redshift-space terms on one k grid (cosmology independent).
#[derive(Debug, Clone, PartialEq)]
pub struct RsdTwoLoopBasis {
    k: Vec<f64>,
    key: Vec<f64>,
    basis: LinearBasis,
    points: Vec<usize>,
    replicas: usize,
    /// The mean over shifts, row k × coefficient, column triple, in low-rank form ([`LowRank`]: its
    /// truncation bound is added to the errors).
    mean: LowRank,
    /// Per k: each shift's deviation from the mean, [shift][coefficient][triple < triples(n_err)], in
    /// bfloat16 ([`crate::simd::to_bf16`]).
    deviations: Vec<Vec<u16>>,
}

/// The settings that make the tensors (their file header).
fn key(
    k: &[f64],
    q_range: (f64, f64),
    lattice_step: f64,
    settings: &TwoLoopSettings,
    family: SpectrumFamily,
) -> Vec<f64> {
    let mut key = vec![
        f64::from(VERSION),
        BASIS_SIZE as f64,
        ERROR_FUNCTIONS as f64,
        q_range.0,
        q_range.1,
        lattice_step,
        settings.points as f64,
        settings.replicas as f64,
        settings.seed as f64,
        settings.radial_width,
        f64::from(super::training::VERSION),
        f64::from(u8::from(family == SpectrumFamily::NoWiggle)),
        k.len() as f64,
    ];
    key.extend(k);
    key
}

/// The sum over `sampling`'s points of k index `i` moved by `shift` of the basis tensor
/// [coefficient][a ≤ b ≤ c]; `tick(points)` after each batch.
fn shifted_tensor(
    k: f64,
    i: usize,
    shift: &[f64; 6],
    sampling: &Sampling,
    basis: &LinearBasis,
    tick: &dyn Fn(usize),
) -> Vec<f64> {
    let n = basis.len();
    let pairs = n * (n + 1) / 2;
    let row = COEFFICIENTS * n;
    let mut acc = vec![0.0; pairs * row];
    // two rows (propagator and mode-coupling parts) per point
    let mut left = vec![0.0; 2 * BATCH * pairs];
    let mut right = vec![0.0; 2 * BATCH * row];
    let (mut phi1, mut phi2, mut phiz) = (vec![0.0; n], vec![0.0; n], vec![0.0; n]);
    let samplers = sampling.samplers(k);
    for chunk in sampling.points[..sampling.counts[i]].chunks(BATCH) {
        let mut used = 0;
        for unit in chunk {
            for legs in sampling.legs(k, unit, shift, &samplers) {
                basis.at_ln(legs.ln_q[0], &mut phi1);
                basis.at_ln(legs.ln_q[1], &mut phi2);
                let l = &mut left[used * pairs..(used + 1) * pairs];
                for b in 0..n {
                    for a in 0..b {
                        l[pair_index(a, b)] = phi1[a] * phi2[b] + phi1[b] * phi2[a];
                    }
                    l[pair_index(b, b)] = phi1[b] * phi2[b];
                }
                let r = &mut right[used * row..(used + 1) * row];
                r.iter_mut().for_each(|x| *x = 0.0);
                for (ln_z, coef) in &legs.legs {
                    basis.at_ln(*ln_z, &mut phiz);
                    for (v, c) in to_coefficients(coef).iter().enumerate() {
                        if *c != 0.0 {
                            let rv = &mut r[v * n..(v + 1) * n];
                            rv.iter_mut().zip(&phiz).for_each(|(x, z)| *x += c * z);
                        }
                    }
                }
                used += 1;
            }
        }
        rank_update(&mut acc, &left, &right, used, pairs, row);
        tick(chunk.len());
    }
    fold(&acc, n, COEFFICIENTS)
}

impl RsdTwoLoopBasis {
    /// The cache file name for these settings: `rsd-two-loop-basis[-nw]-v<version>-<hash>.bin`.
    pub fn file_name(
        k: &[f64],
        q_range: (f64, f64),
        lattice_step: f64,
        settings: &TwoLoopSettings,
        family: SpectrumFamily,
    ) -> String {
        let name = match family {
            SpectrumFamily::Linear => "rsd-two-loop-basis",
            SpectrumFamily::NoWiggle => "rsd-two-loop-basis-nw",
        };
        cache_file_name(
            name,
            VERSION,
            &key(k, q_range, lattice_step, settings, family),
        )
    }

    /// The lattice of the tensors (what a family's basis is made on).
    pub(crate) fn lattice(q_range: (f64, f64), lattice_step: f64) -> Lattice {
        Lattice::new(q_range.0, q_range.1, lattice_step)
    }

    /// Builds the tensors on `k` [h/Mpc] for the integration `settings` over `q_range` on `basis` (of
    /// the spectra of `family`, on the tensors' lattice of q_range and lattice_step), in parallel; `progress(done, total)`
    /// counts the points.
    pub fn build(
        k: &[f64],
        q_range: (f64, f64),
        lattice_step: f64,
        settings: &TwoLoopSettings,
        family: SpectrumFamily,
        basis: LinearBasis,
        progress: &(dyn Fn(usize, usize) + Sync),
    ) -> Self {
        let n = basis.len();
        let sampling = Sampling::new(k, q_range, settings);
        let replicas = sampling.shifts.len();
        let total = replicas * sampling.counts.iter().sum::<usize>();
        let done = AtomicUsize::new(0);
        let tick = |m: usize| progress(done.fetch_add(m, Ordering::Relaxed) + m, total);
        let mut jobs: Vec<usize> = (0..k.len() * replicas).collect();
        jobs.sort_by_key(|&j| std::cmp::Reverse(sampling.counts[j / replicas]));
        let mut tensors: Vec<(usize, Vec<f64>)> = jobs
            .par_iter()
            .map(|&job| {
                let i = job / replicas;
                let shift = &sampling.shifts[job % replicas];
                (
                    job,
                    shifted_tensor(k[i], i, shift, &sampling, &basis, &tick),
                )
            })
            .collect();
        tensors.sort_by_key(|t| t.0);
        let (mean, deviations) = shift_statistics(&tensors, replicas, COEFFICIENTS, n, |i| {
            integral_scale(sampling.counts[i])
        });
        let deviations = deviations
            .iter()
            .map(|d| d.iter().map(|&x| to_bf16(x)).collect())
            .collect();
        let sigma = super::training::coefficient_scale(&basis);
        let mean = LowRank::new(
            &mean.concat(),
            k.len() * COEFFICIENTS,
            3,
            &sigma,
            TRIPLE_TOLERANCE,
        );
        Self {
            k: k.to_vec(),
            key: key(k, q_range, lattice_step, settings, family),
            basis,
            points: sampling.counts,
            replicas,
            mean,
            deviations,
        }
    }

    /// [`build`](Self::build) for linear spectra, on the CAMB basis of [`BASIS_SIZE`] functions.
    pub fn build_linear(
        k: &[f64],
        q_range: (f64, f64),
        lattice_step: f64,
        settings: &TwoLoopSettings,
        progress: &(dyn Fn(usize, usize) + Sync),
    ) -> Self {
        let basis = super::training::camb_basis(Self::lattice(q_range, lattice_step), BASIS_SIZE);
        let family = SpectrumFamily::Linear;
        Self::build(k, q_range, lattice_step, settings, family, basis, progress)
    }

    /// The wavenumbers [h/Mpc].
    pub fn k(&self) -> &[f64] {
        &self.k
    }

    /// The basis the spectra are projected on.
    pub fn basis(&self) -> &LinearBasis {
        &self.basis
    }

    /// The projection of `spectrum` on the basis (cut below the soft modes if it projects only so:
    /// [`LinearBasis::project_spectrum`]).
    pub fn project(&self, spectrum: &LinearSpectrum) -> Projection {
        self.basis.project_spectrum(spectrum, MAX_RESIDUAL)
    }

    /// The 2-loop redshift-space terms of `spectrum`, or `Err` with its projection if the residual
    /// exceeds [`MAX_RESIDUAL`] (integrate such spectra directly).
    ///
    /// # Errors
    /// The projection, when the basis does not represent the spectrum well enough.
    pub fn evaluate(&self, spectrum: &LinearSpectrum) -> Result<RsdTwoLoopTerms, Projection> {
        let projection = self.project(spectrum);
        if !Self::accepts(&projection) {
            return Err(projection);
        }
        Ok(self.evaluate_projected(&projection))
    }

    /// Whether a spectrum with this projection is evaluated on the basis: its residual is at most
    /// [`MAX_RESIDUAL`] (a NaN residual, from non-positive values, is refused).
    pub fn accepts(projection: &Projection) -> bool {
        projection.residual <= MAX_RESIDUAL
    }

    /// As [`evaluate`](Self::evaluate) with the spectrum's `projection` made (and accepted) by the
    /// caller.
    pub fn evaluate_projected(&self, projection: &Projection) -> RsdTwoLoopTerms {
        let n = projection.coefficients.len();
        let s3 = triple_products(&projection.coefficients);
        let s3_single: Vec<f32> = s3.iter().map(|&x| x as f32).collect();
        let z = self.mean.reduce_f32(&s3_single);
        let scale = self.mean.norm(&projection.coefficients);
        let row = |i: usize, v: usize| i * COEFFICIENTS + v;
        let s3_err = &s3_single[..triples(error_functions(n))];
        let replicas: Vec<Vec<[f64; COEFFICIENTS]>> = (0..self.k.len())
            .into_par_iter()
            .map(|i| {
                let mean: [f64; COEFFICIENTS] =
                    std::array::from_fn(|v| self.mean.row(row(i, v), &z));
                let mut deviation = vec![0.0; self.replicas * COEFFICIENTS];
                matvec_bf16(&self.deviations[i], s3_err, &mut deviation);
                deviation
                    .chunks_exact(COEFFICIENTS)
                    .map(|d| std::array::from_fn(|v| mean[v] + d[v]))
                    .collect()
            })
            .collect();
        let truncation = (0..self.k.len())
            .map(|i| std::array::from_fn(|v| self.mean.bound(row(i, v), scale)))
            .collect();
        // A spectrum cut below the soft modes (module `soft`): the coefficients, infrared-safe sums
        // of diagrams, are the whole spectrum's up to (q/k)² of the diagrams' soft responses.
        let soft = projection
            .soft
            .as_ref()
            .map_or(0.0, |s| super::soft::SOFT_CUT.powi(2) * s.delta_abs);
        RsdTwoLoopTerms::from_coefficients(
            &self.k,
            self.points.clone(),
            &replicas,
            RSD_PROJECTION_FACTOR * projection.residual + soft,
            truncation,
        )
    }

    /// The tensors as the values of their cache file.
    pub(crate) fn to_f64s(&self) -> Vec<f64> {
        let mut v = vec![self.key.len() as f64];
        v.extend(&self.key);
        v.extend(self.points.iter().map(|&p| p as f64));
        v.push(self.replicas as f64);
        v.extend(self.basis.to_f64s());
        for i in 0..self.k.len() {
            v.extend(self.deviations[i].iter().map(|&x| f64::from(from_bf16(x))));
        }
        v.extend(self.mean.to_f64s());
        v
    }

    /// The tensors from the values of their file, or `None` for a file made for other settings.
    pub(crate) fn from_f64s(
        values: &[f64],
        k: &[f64],
        q_range: (f64, f64),
        lattice_step: f64,
        settings: &TwoLoopSettings,
        family: SpectrumFamily,
    ) -> Option<Self> {
        let expected = key(k, q_range, lattice_step, settings, family);
        let rest = after_key(values, &expected)?;
        // The stored points are those the settings give; the replicas are the settings' own.
        let points: Vec<usize> = k
            .iter()
            .map(|&k| rsd_points_at(k, settings.points))
            .collect();
        let replicas = settings.replicas;
        let rest = super::after_points(rest, &points, replicas)?;
        let (basis, mut rest) = LinearBasis::from_f64s(Self::lattice(q_range, lattice_step), rest)?;
        let n = basis.len();
        let size = replicas.checked_mul(COEFFICIENTS * triples(error_functions(n)))?;
        if rest.len() < k.len().checked_mul(size)? {
            return None;
        }
        let mut deviations = Vec::new();
        for _ in k {
            let (d, r) = rest.split_at(size);
            deviations.push(d.iter().map(|&x| to_bf16(x as f32)).collect());
            rest = r;
        }
        let (mean, rest) = LowRank::from_f64s(rest)?;
        if !rest.is_empty() || !mean.has_shape(k.len() * COEFFICIENTS, triples(n)) {
            return None;
        }
        Some(Self {
            k: k.to_vec(),
            key: expected,
            basis,
            points,
            replicas,
            mean,
            deviations,
        })
    }
}
