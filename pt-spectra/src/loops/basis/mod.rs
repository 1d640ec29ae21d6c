//! The 2-loop terms of a new linear spectrum in milliseconds: precomputed tensors on a basis of linear
//! spectra, contracted with the spectrum's projection on it.
//!
//! Every 2-loop term is a trilinear functional of the linear spectrum P (P15 is P(k) times a bilinear
//! one). With P ≈ P̂ = Σ_a c_a φ_a on a basis of N functions ([`LinearBasis`], built from
//! shipped CAMB spectra over the EuclidEmulator2 box, [`training`]), each term becomes a contraction of a
//! cosmology-independent tensor with c ⊗ c ⊗ c (or c ⊗ c). The tensors are made once per k grid and
//! [`Precision`] with the integrators of the direct path and cached ([`TableStore::for_method`]):
//! * P15 and the propagator part 2P15 − P33red: the angular table's radial sums as bilinear forms
//!   (`p15_forms`), with their error terms;
//! * the mode-coupling part 2P24 + P33irr + 2P33red, 2P24 and P33irr: the quasi-Monte-Carlo integral
//!   of [`super::two_loop`] on the same Sobol points, shifts and points per k as the direct path, each
//!   point adding the products of basis functions at its momenta (`tensors`); one tensor per random
//!   shift, so the error is the same standard error over the shifts.
//!
//! Because the points are the same, the basis result equals the direct result for the projected
//! spectrum P̂ (to round-off, and to the low-rank form of the mean tensors, whose bound is added to
//! the errors: module `low_rank`): the only other difference from `direct` is the response to the
//! projection residual P − P̂. That is taken as ε Σ|T| over the terms T that make up a result (P15, 2P24,
//! P33irr, P33red), with ε the largest relative residual smoothed over [`SMOOTHING`] in ln q
//! ([`PROJECTION_ERROR_FACTOR`], [`Projection`]); it is added to every error. At high k the terms
//! cancel to a small remainder (at k = 0.4, −114 of terms ±1.7e4), so there the projection error
//! dominates. Measured on 40 k in [0.005, 0.4] (`tests/benches/two_loop.rs`): the correction of six CAMB
//! tables not in the training set is within 8.4e-4 of `direct` for k ≤ 0.3; at k = 0.4 (gm2012, δδ)
//! within 4.8e-3, inside the reported error.
//! A spectrum whose residual exceeds [`TwoLoopBasis::max_residual`] is not evaluated on the basis
//! (the caller falls back to the direct integrals).
//!
//! The error of the mode coupling is the spread over the shifts, contracted with the first
//! [`ERROR_FUNCTIONS`] coefficients only (the tensors of each shift are kept on those, the mean on
//! all N): the spread of the spectrum's projection on the first 12 functions, which differs from the
//! spectrum by a few 1e-3 — immaterial for an error estimate from 8 shifts — at a fifteenth of the
//! memory and time.
//!
//! [`TableStore::for_method`]: crate::store::TableStore::for_method

mod cache_key;
mod forms;
mod linear_basis;
mod low_rank;
mod one_loop;
mod p15_forms;
mod redshift;
mod rsd_two_loop;
pub mod soft;
mod tensors;
mod thin;
mod tns;
pub mod training;

pub(crate) use cache_key::{
    after_key, after_points, cache_file_name, stored_count, MAX_STORED_BASIS,
};
pub(crate) use forms::{leading, pack_pairs, pack_triples, pair_products};
#[cfg(test)]
pub(crate) use linear_basis::wrapping_basis_size;
pub use linear_basis::{LinearBasis, Projection, SMOOTHING};
pub use one_loop::{BasisOneLoop, OneLoopBasis};
pub use redshift::{RedshiftBasis, RedshiftFamily, SpectrumFamily};
pub use rsd_two_loop::{RsdTwoLoopBasis, RSD_PROJECTION_FACTOR};
pub use tns::TnsBasis;

use super::lattice::Lattice;
use super::mode_coupling::ACC;
use super::two_loop::{
    integral_scale, points_at, random_shifts, replica_estimates, sobol_sequence,
};
use super::{
    assemble_two_loop, ByPair, Estimate, OneLoopTerms, P15Table, Pair, TwoLoopCorrection,
    TwoLoopSettings, TwoLoopTerms,
};
use crate::linear::LinearSpectrum;
use crate::precision::Precision;
use crate::simd::{dot, dot32};
use low_rank::{LowRank, TRIPLE_TOLERANCE};
use p15_forms::{p15_forms, FORM_KERNELS};
use rayon::prelude::*;
use std::f64::consts::PI;
use std::sync::atomic::{AtomicUsize, Ordering};

/// Basis functions: [`training::TAIL_FUNCTIONS`] tail functions and the rest chosen from the training
/// spectra. CAMB tables of the prior not in the training set project with a smoothed residual of
/// 5e-5 to 7e-5, and their 2-loop corrections for k ≤ 0.3 are then within 8.4e-4 of direct at the
/// same points (24 functions without tails: 1.1e-3); the contraction costs ~N³.
pub const BASIS_SIZE: usize = 36;

/// Basis functions on which the per-shift tensors (the error estimate) are kept.
pub const ERROR_FUNCTIONS: usize = 12;

/// The projection error of a term is taken as this times ε times the sum of the sizes |T| of the
/// terms it is made of (ε: the smoothed projection residual). Measured on CAMB tables not in the
/// training set, each term responds to the residual by 0.1–0.7 ε|T|.
pub const PROJECTION_ERROR_FACTOR: f64 = 1.0;

/// The largest (smoothed) projection residual ε for which a spectrum is evaluated on the basis, by
/// every plan with tensors and the pipeline; above it the terms are integrated directly and the
/// fallback is stated (header, Python `meta`, a warning). Every term's error carries
/// [`PROJECTION_ERROR_FACTOR`] ε |T|, so what the limit decides is speed, not silent accuracy.
///
/// 2e-3, twice the emulator's own worst |Δ ln P| (~1e-3): it admits what the basis spans to within
/// the accuracy of the spectrum itself. Measured residuals: CAMB tables of the prior ≤ 2e-4 (also
/// ending at 15 h/Mpc), CLASS from `pk_lin` 1.9e-4 and at its default 10 points per decade 1.1e-3,
/// emulated spectra 4e-4 to 8e-4 (the kink where the emulated table, ending at k ≈ 8.9 h/Mpc, meets
/// its power-law extension; their `ept` multipoles on the basis are within 1e-4 of P0 of the direct
/// integrals, test `emulated_spectra_use_the_basis_within_their_errors`); refused: Eisenstein–Hu fits
/// (3.8e-3) and spectra with features the CAMB set does not hold. It was 3e-4 until the emulated
/// spectra were measured to be as accurate on the basis as their own emulation error allows.
pub const MAX_RESIDUAL: f64 = 2e-3;

/// Version of the tensor layout and rules, part of the cache file name.
const VERSION: u32 = 2;

/// Index of the pair a ≤ b in the symmetric storage (pairs with b < n come first).
#[inline]
pub(crate) fn pair_index(a: usize, b: usize) -> usize {
    b * (b + 1) / 2 + a
}

/// Index of the triple a ≤ b ≤ c in the symmetric storage (triples with c < n come first).
#[inline]
pub(crate) fn triple_index(a: usize, b: usize, c: usize) -> usize {
    c * (c + 1) * (c + 2) / 6 + pair_index(a, b)
}

/// Basis functions of the per-shift tensors for a basis of `n`.
fn error_functions(n: usize) -> usize {
    ERROR_FUNCTIONS.min(n)
}

/// The number of triples a ≤ b ≤ c of n functions.
pub(crate) fn triples(n: usize) -> usize {
    n * (n + 1) * (n + 2) / 6
}

/// The 2-loop terms of a spectrum from the basis tensors.
#[derive(Debug, Clone, PartialEq)]
pub struct BasisTwoLoop {
    /// P15 of δδ, δθ, θθ (errors include the projection error).
    pub p15: ByPair<Vec<Estimate>>,
    /// The 2-loop terms and the whole correction (errors include the projection error).
    pub correction: TwoLoopCorrection,
    /// The spectrum's projection on the basis.
    pub projection: Projection,
}

/// The basis tensors of the 2-loop terms on one k grid for one [`Precision`] (cosmology independent).
#[derive(Debug, Clone, PartialEq)]
pub struct TwoLoopBasis {
    k: Vec<f64>,
    /// The settings the tensors were built with (their cache key).
    key: Vec<f64>,
    basis: LinearBasis,
    /// Points per shift at each k.
    points: Vec<usize>,
    replicas: usize,
    /// Per k: [type][kernel][pair] ([`p15_forms`]).
    forms: Vec<Vec<f64>>,
    /// The mean over shifts, row k × quantity, column triple, in low-rank form ([`LowRank`]:
    /// its truncation bound is added to the errors).
    mean: LowRank,
    /// Per k: each shift's deviation from the mean, [shift][quantity][triple < triples(n_err)].
    deviations: Vec<Vec<f32>>,
    max_residual: f64,
}

/// The settings that make the tensors: k grid and [`Precision`] fields, as a vector (file header),
/// and for the no-wiggle family a marker.
fn key(k: &[f64], precision: &Precision, family: SpectrumFamily) -> Vec<f64> {
    let radial_width = TwoLoopSettings::default().radial_width;
    let mut key = vec![
        f64::from(VERSION),
        BASIS_SIZE as f64,
        ERROR_FUNCTIONS as f64,
    ];
    key.extend(precision.two_loop_key());
    key.extend([radial_width, f64::from(training::VERSION), k.len() as f64]);
    key.extend(k);
    if family == SpectrumFamily::NoWiggle {
        key.push(1.0);
    }
    key
}

/// Bytes per output k of the 2-loop basis tensors (measured 0.9 MB, rounded up).
const TWO_LOOP_BYTES_PER_K: f64 = 1.0e6;

impl TwoLoopBasis {
    /// The estimated memory of the tensors on `nk` wavenumbers \[bytes\]; none when `precision`
    /// integrates the 2-loop terms directly.
    pub fn memory_estimate(nk: usize, precision: &Precision) -> f64 {
        if precision.two_loop == crate::precision::TwoLoopMethod::Direct {
            0.0
        } else {
            TWO_LOOP_BYTES_PER_K * nk as f64
        }
    }

    /// The cache file name of the tensors for `k`, `precision` and `family`:
    /// `two-loop-basis[-nw]-v<version>-<hash>.bin`.
    pub fn file_name(k: &[f64], precision: &Precision, family: SpectrumFamily) -> String {
        let name = match family {
            SpectrumFamily::Linear => "two-loop-basis",
            SpectrumFamily::NoWiggle => "two-loop-basis-nw",
        };
        cache_file_name(name, VERSION, &key(k, precision, family))
    }

    /// The lattice of the tensors for `precision` (what a family's basis is made on).
    pub(crate) fn lattice(precision: &Precision) -> Lattice {
        lattice_of(precision)
    }

    /// [`build`](Self::build) for linear spectra, on the CAMB basis of [`BASIS_SIZE`] functions.
    pub fn build_linear(
        k: &[f64],
        precision: &Precision,
        table: &P15Table,
        progress: &(dyn Fn(usize, usize) + Sync),
    ) -> Self {
        let basis = training::camb_basis(lattice_of(precision), BASIS_SIZE);
        Self::build(k, precision, table, SpectrumFamily::Linear, basis, progress)
    }

    /// Builds the tensors on `k` [h/Mpc] for `precision` with the P15 angular `table`, in parallel,
    /// on `basis` (of the spectra of `family`, on the tensors' lattice: the CAMB basis for
    /// linear spectra); `progress(done, total)` counts the quasi-Monte-Carlo points.
    pub fn build(
        k: &[f64],
        precision: &Precision,
        table: &P15Table,
        family: SpectrumFamily,
        basis: LinearBasis,
        progress: &(dyn Fn(usize, usize) + Sync),
    ) -> Self {
        let n = basis.len();
        let settings = TwoLoopSettings {
            points: precision.two_loop_points,
            replicas: precision.two_loop_replicas,
            seed: precision.two_loop_seed,
            ..TwoLoopSettings::default()
        };
        let points: Vec<usize> = k.iter().map(|&k| points_at(k, settings.points)).collect();
        let longest = points.iter().copied().max().unwrap_or(0);
        let sequence: Vec<[f64; 5]> = sobol_sequence().take(longest).collect();
        let shifts = random_shifts(&settings);
        let replicas = shifts.len();
        let ln_range = (precision.q_min.ln(), precision.q_max.ln());
        let total = replicas * points.iter().sum::<usize>();
        let done = AtomicUsize::new(0);
        let tick = |n: usize| progress(done.fetch_add(n, Ordering::Relaxed) + n, total);
        // Largest jobs first, so that the cores finish together.
        let mut jobs: Vec<usize> = (0..k.len() * replicas).collect();
        jobs.sort_by_key(|&j| std::cmp::Reverse(points[j / replicas]));
        let mut tensors: Vec<(usize, Vec<f64>)> = jobs
            .par_iter()
            .map(|&job| {
                let i = job / replicas;
                let t = tensors::shifted_tensor(
                    k[i],
                    &shifts[job % replicas],
                    &sequence[..points[i]],
                    &basis,
                    ln_range,
                    settings.radial_width,
                    &tick,
                );
                (job, t)
            })
            .collect();
        tensors.sort_by_key(|t| t.0);
        let (mean, deviations) =
            shift_statistics(&tensors, replicas, ACC, n, |i| integral_scale(points[i]));
        let sigma = training::coefficient_scale(&basis);
        let mean = LowRank::new(&mean.concat(), k.len() * ACC, 3, &sigma, TRIPLE_TOLERANCE);
        let forms = k.par_iter().map(|&k| p15_forms(table, k, &basis)).collect();
        Self {
            k: k.to_vec(),
            key: key(k, precision, family),
            basis,
            points,
            replicas,
            forms,
            mean,
            deviations,
            max_residual: MAX_RESIDUAL,
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

    /// The largest projection residual for which [`evaluate`](Self::evaluate) uses the basis.
    pub fn max_residual(&self) -> f64 {
        self.max_residual
    }

    /// The same tensors with another largest projection residual.
    pub fn with_max_residual(mut self, max_residual: f64) -> Self {
        self.max_residual = max_residual;
        self
    }

    /// The projection of `spectrum` on the basis (cut below the soft modes if it projects only so:
    /// [`LinearBasis::project_spectrum`]).
    pub fn project(&self, spectrum: &LinearSpectrum) -> Projection {
        self.basis.project_spectrum(spectrum, self.max_residual)
    }

    /// P15 and the 2-loop terms of `spectrum` (whose 1-loop terms on the same grid are `one_loop`),
    /// or, if its projection residual exceeds [`max_residual`](Self::max_residual), `Err` with the
    /// projection (compute those spectra directly).
    ///
    /// # Errors
    /// The projection, when the spectrum is not represented well enough by the basis.
    pub fn evaluate(
        &self,
        spectrum: &LinearSpectrum,
        one_loop: &OneLoopTerms,
    ) -> Result<BasisTwoLoop, Projection> {
        let projection = self.project(spectrum);
        // A NaN residual (a spectrum with non-positive values) is refused too.
        if projection.residual.is_nan() || projection.residual > self.max_residual {
            return Err(projection);
        }
        Ok(self.evaluate_projected(spectrum, projection, one_loop))
    }

    /// As [`evaluate`](Self::evaluate) with the spectrum's `projection` on [`basis`](Self::basis)
    /// already made (and accepted) by the caller.
    pub fn evaluate_projected(
        &self,
        spectrum: &LinearSpectrum,
        projection: Projection,
        one_loop: &OneLoopTerms,
    ) -> BasisTwoLoop {
        let c = &projection.coefficients;
        let n = c.len();
        let s2 = forms::pair_products(c);
        let s3 = triple_products(c);
        let z = self.mean.reduce(&s3);
        let scale = self.mean.norm(c);
        let mut p15_rows = Vec::with_capacity(self.k.len());
        let mut propagator = Vec::with_capacity(self.k.len());
        let mut rows = Vec::with_capacity(self.k.len());
        for (i, &k) in self.k.iter().enumerate() {
            let pairs = s2.len();
            let form = |kind: usize, m: usize| -> f64 {
                let f = &self.forms[i][(kind * FORM_KERNELS + m) * pairs..][..pairs];
                dot(f, &s2)
            };
            let norm = k.powi(6) / (4.0 * PI.powi(4)) * spectrum.eval(k);
            let kernel = |m: usize| {
                Estimate::new(
                    norm * form(0, m),
                    norm.abs() * (form(1, m).abs() + form(2, m)),
                )
            };
            let (dd, tt) = (kernel(0), kernel(1));
            p15_rows.push([dd, Estimate::mean(dd, tt), tt]);
            propagator.push([kernel(2), kernel(3), kernel(4)]);
            let mean: [f64; ACC] = std::array::from_fn(|v| self.mean.row(i * ACC + v, &z));
            let integrals: Vec<[f64; ACC]> =
                replica_contractions(mean, &self.deviations[i], &s3, n);
            let mut row = replica_estimates(&integrals);
            // The truncation of the low-rank mean: each accumulated quantity's bound, and for the
            // sums of two (the last VALUES − ACC) the sum of theirs.
            let bound = |v: usize| self.mean.bound(i * ACC + v, scale);
            for (v, r) in row.iter_mut().enumerate() {
                r.error += if v < ACC {
                    bound(v)
                } else {
                    bound(v - 6) + bound(v - 3)
                };
            }
            rows.push(row);
        }
        // Assembled as the direct path does (the same choice between its two estimates of the
        // total), then the projection error added: ε times the sum of the sizes of the terms of each
        // value. At high k the terms (2P24, P33irr ~ ±1.7e4 at k = 0.4) cancel to a small remainder,
        // and each responds to the residual in proportion to its own size.
        let mut p15 = ByPair::from_rows(&p15_rows);
        let mc = TwoLoopTerms::from_rows(&self.k, &rows, self.points.clone());
        // A spectrum cut below the soft modes ([`soft`]): the whole correction on the cut spectrum,
        // 1-loop terms included, so that its infrared-safe sum is the whole spectrum's up to
        // (q/k)². Each 2-loop term alone responds to the soft modes as a uniform displacement
        // would move it: by k²Δ times 1-loop terms (measured ≤ 0.18 k²|Δ|(|P22| + |P13|)).
        let soft = projection.soft.as_ref();
        let cut_one_loop = soft.map(|s| s.take_out(one_loop));
        let one_loop = cut_one_loop.as_ref().unwrap_or(one_loop);
        let mut correction = assemble_two_loop(one_loop, &p15, &propagator, mc);
        let eps = PROJECTION_ERROR_FACTOR * projection.residual;
        let soft_term = |pair: Pair, i: usize| {
            soft.map_or(0.0, |s| {
                let one = one_loop.p22[pair][i].value.abs() + one_loop.p13[pair][i].value.abs();
                soft::TWO_LOOP_FACTOR * self.k[i].powi(2) * s.delta_abs * one
            })
        };
        let eps_total = eps + soft.map_or(0.0, |s| soft::SOFT_CUT.powi(2) * s.delta_abs);
        for pair in Pair::ALL {
            let terms = &mut correction.pairs[pair];
            for i in 0..self.k.len() {
                // 2P15_δθ = P15_δδ + P15_θθ.
                let p15_size = match pair {
                    Pair::DeltaTheta => p15.dd[i].value.abs() + p15.tt[i].value.abs(),
                    _ => 2.0 * p15[pair][i].value.abs(),
                };
                let sizes = [
                    p15_size,
                    3.0 * one_loop.p33_reducible(pair, i).value,
                    2.0 * terms.p24[i].value,
                    terms.p33_2l[i].value,
                ];
                terms.total[i].error += eps_total * sizes.iter().map(|s| s.abs()).sum::<f64>();
                terms.p24[i].error += eps * terms.p24[i].value.abs() + soft_term(pair, i);
                terms.p33_2l[i].error += eps * terms.p33_2l[i].value.abs() + soft_term(pair, i);
            }
        }
        // P15_δθ is the mean of δδ and θθ (which may have opposite signs): the mean of their errors.
        for i in 0..self.k.len() {
            let (dd, tt) = (p15.dd[i].value.abs(), p15.tt[i].value.abs());
            p15.dd[i].error += eps * dd + soft_term(Pair::DeltaDelta, i);
            p15.dt[i].error += eps * 0.5 * (dd + tt) + soft_term(Pair::DeltaTheta, i);
            p15.tt[i].error += eps * tt + soft_term(Pair::ThetaTheta, i);
        }
        BasisTwoLoop {
            correction,
            p15,
            projection,
        }
    }

    /// The tensors as the values of their cache file.
    pub(crate) fn to_f64s(&self) -> Vec<f64> {
        let mut v = vec![self.key.len() as f64];
        v.extend(&self.key);
        v.extend(self.points.iter().map(|&p| p as f64));
        v.push(self.replicas as f64);
        v.extend(self.basis.to_f64s());
        for i in 0..self.k.len() {
            v.extend(&self.forms[i]);
            v.extend(self.deviations[i].iter().map(|&x| f64::from(x)));
        }
        v.extend(self.mean.to_f64s());
        v
    }

    /// The tensors for `k` and `precision` from the values of their file, or `None` if the file was
    /// made for other settings or does not fit them.
    pub(crate) fn from_f64s(
        values: &[f64],
        k: &[f64],
        precision: &Precision,
        family: SpectrumFamily,
    ) -> Option<Self> {
        let expected = key(k, precision, family);
        let rest = after_key(values, &expected)?;
        // The stored points are those the settings give; the replicas are the settings' own.
        let points: Vec<usize> = k
            .iter()
            .map(|&k| points_at(k, precision.two_loop_points))
            .collect();
        let replicas = precision.two_loop_replicas;
        let rest = after_points(rest, &points, replicas)?;
        let (basis, mut rest) = LinearBasis::from_f64s(lattice_of(precision), rest)?;
        let n = basis.len();
        let sizes = [
            3 * FORM_KERNELS * n * (n + 1) / 2,
            replicas.checked_mul(ACC * triples(error_functions(n)))?,
        ];
        let per_k = k.len().checked_mul(sizes[0].checked_add(sizes[1])?)?;
        if rest.len() < per_k {
            return None;
        }
        let (mut forms, mut deviations) = (Vec::new(), Vec::new());
        for _ in k {
            let (f, r) = rest.split_at(sizes[0]);
            let (d, r) = r.split_at(sizes[1]);
            forms.push(f.to_vec());
            deviations.push(d.iter().map(|&x| x as f32).collect());
            rest = r;
        }
        let (mean, rest) = LowRank::from_f64s(rest)?;
        if !rest.is_empty() || !mean.has_shape(k.len() * ACC, triples(n)) {
            return None;
        }
        Some(Self {
            k: k.to_vec(),
            key: expected,
            basis,
            points,
            replicas,
            forms,
            mean,
            deviations,
            max_residual: MAX_RESIDUAL,
        })
    }
}

/// Per k, from the summed tensors of each (k, shift) job in job order ([quantity][triple], `quantities`
/// of them on a basis of `n`), each times `scale(k index)`: the mean over the shifts, and each shift's
/// deviation from it kept on the first [`ERROR_FUNCTIONS`] functions ([shift][quantity][triple]).
///
/// The mean is returned in f64 (for its low-rank form, or to be rounded by the caller), the
/// deviations in f32 (summed in f64 when contracted, [`dot32`]): the contraction reads them from
/// memory at every evaluation, and half the bytes is what makes it fast. Rounding the tensors to f32
/// moved the 2-loop redshift-space multipoles of two held-out spectra by 3e-8 of the monopole (1e-5
/// of their Monte Carlo error).
pub(crate) fn shift_statistics(
    tensors: &[(usize, Vec<f64>)],
    replicas: usize,
    quantities: usize,
    n: usize,
    scale: impl Fn(usize) -> f64,
) -> (Vec<Vec<f64>>, Vec<Vec<f32>>) {
    let (t, t_err) = (triples(n), triples(error_functions(n)));
    let (mut mean, mut deviations) = (Vec::new(), Vec::new());
    for (i, shifts) in tensors.chunks(replicas).enumerate() {
        // Each shift's integral is its sum times the scale; the mean is over the shifts.
        let scale = scale(i);
        let mut m = vec![0.0; quantities * t];
        for (_, s) in shifts {
            m.iter_mut()
                .zip(s)
                .for_each(|(m, s)| *m += scale * s / replicas as f64);
        }
        let mut d = Vec::with_capacity(replicas * quantities * t_err);
        for (_, s) in shifts {
            for v in 0..quantities {
                let range = v * t..v * t + t_err;
                d.extend(
                    s[range.clone()]
                        .iter()
                        .zip(&m[range])
                        .map(|(s, m)| scale * s - m),
                );
            }
        }
        mean.push(m);
        deviations.push(d.iter().map(|&x| x as f32).collect());
    }
    (mean, deviations)
}

/// The products c_a c_b c_c on the triples a ≤ b ≤ c.
pub(crate) fn triple_products(c: &[f64]) -> Vec<f64> {
    let n = c.len();
    let mut s3 = vec![0.0; triples(n)];
    for b in 0..n {
        for a in 0..=b {
            for (i, cc) in c[b..].iter().enumerate() {
                s3[triple_index(a, b, b + i)] = c[a] * c[b] * cc;
            }
        }
    }
    s3
}

/// Each shift's integrals of the Q quantities at one k: the `mean` integrals (the mean tensor
/// contracted with the triple products `s3`) plus that shift's deviation tensor (from
/// [`shift_statistics`]) contracted with their first [`ERROR_FUNCTIONS`] functions.
pub(crate) fn replica_contractions<const Q: usize>(
    mean: [f64; Q],
    deviations: &[f32],
    s3: &[f64],
    n: usize,
) -> Vec<[f64; Q]> {
    let t_err = triples(error_functions(n));
    deviations
        .chunks_exact(Q * t_err)
        .map(|d| {
            std::array::from_fn(|v| mean[v] + dot32(&d[v * t_err..(v + 1) * t_err], &s3[..t_err]))
        })
        .collect()
}

/// The lattice of the loop integrals of `precision`.
fn lattice_of(precision: &Precision) -> Lattice {
    Lattice::new(precision.q_min, precision.q_max, precision.lattice_step)
}
