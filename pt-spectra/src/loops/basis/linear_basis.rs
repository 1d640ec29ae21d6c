//! A basis for linear spectra on the loop lattice, and the projection of a spectrum on it.
//!
//! The functions φ_a are orthonormal in the weighted inner product ⟨f, g⟩ = Σ_j ω_j f_j g_j over the
//! lattice points q_j, with ω_j = Δln q / P̄(q_j)² (P̄: the mean training spectrum), so that the
//! projection c_a = ⟨φ_a, P⟩ minimises the relative residual in the least-squares sense over the whole
//! lattice (tails included: the loop integrals use them), and costs one pass over the lattice.
//!
//! The residual that matters for loop integrals is not the pointwise one: CAMB tables carry
//! uncorrelated kinks of a few 1e-4 from one k to the next (its internal k sampling), which no small
//! basis follows and which integrals average out. The projection therefore reports the largest
//! relative residual after smoothing with a Gaussian of width [`SMOOTHING`] in ln q (the residual
//! the integrals see), and the pointwise one. The basis is built greedily (a reduced basis): from a training set of
//! spectra, each step adds the (orthonormalised) training spectrum that the basis so far represents
//! worst, so the first n functions of a basis are the basis of size n, and its worst training residual
//! falls step by step.

use crate::linalg::dot;
use crate::loops::lattice::Lattice;

/// Width (standard deviation in ln q) of the Gaussian with which the relative residual is smoothed.
pub const SMOOTHING: f64 = 0.1;

/// The projection of a spectrum on a [`LinearBasis`].
#[derive(Debug, Clone, PartialEq)]
pub struct Projection {
    /// The coefficients c_a, P ≈ Σ_a c_a φ_a.
    pub coefficients: Vec<f64>,
    /// The projected samples Σ_a c_a φ_a(q_j) on the lattice.
    pub samples: Vec<f64>,
    /// The largest relative residual (P̂ − P)/P over the lattice after smoothing with a Gaussian of
    /// width [`SMOOTHING`] in ln q: the residual the loop integrals see.
    pub residual: f64,
    /// The largest pointwise relative residual |P̂ − P|/P over the lattice.
    pub pointwise: f64,
    /// For a spectrum projected cut below [`super::soft::SOFT_CUT`]
    /// ([`LinearBasis::project_spectrum`]): what the cut changed, which the evaluations put back.
    pub soft: Option<super::soft::SoftModes>,
}

impl Projection {
    /// Δ [(Mpc/h)²] of the soft modes if the spectrum was projected cut ([`Self::soft`]), for headers.
    pub fn soft_delta(&self) -> Option<f64> {
        self.soft.as_ref().map(|s| s.delta)
    }

    /// The error of an infrared-safe sum of 1-loop diagrams at `k` (linear spectrum `p` there)
    /// evaluated on the cut spectrum: [`super::soft::RESPONSE_FACTOR`] × k² P |Δ|, 0 if the spectrum
    /// was projected whole.
    pub(crate) fn soft_response_error(&self, k: f64, p: f64) -> f64 {
        self.soft
            .as_ref()
            .map_or(0.0, |s| super::soft::RESPONSE_FACTOR * s.error(k, p))
    }
}

/// Basis functions sampled on a loop lattice, orthonormal in the weighted inner product.
#[derive(Debug, Clone, PartialEq)]
pub struct LinearBasis {
    lattice: Lattice,
    /// ω_j.
    weights: Vec<f64>,
    /// φ_a(q_j) at row j: `phi[j * n + a]`.
    phi: Vec<f64>,
    /// The same by function: `columns[a * len + j]` (what the projection reads, contiguously).
    columns: Vec<f64>,
    n: usize,
}

impl LinearBasis {
    /// The greedy basis of at most `n` functions for the `training` spectra, starting from the `fixed`
    /// functions (all samples on `lattice`), which the basis then spans whatever the training set;
    /// it stops early if the training set is represented to round-off.
    ///
    /// # Panics
    /// If the training set is empty or a spectrum's length differs from the lattice.
    pub(crate) fn greedy(
        lattice: Lattice,
        fixed: &[Vec<f64>],
        training: &[Vec<f64>],
        n: usize,
    ) -> Self {
        assert!(!training.is_empty(), "an empty training set");
        let len = lattice.len;
        assert!(training.iter().all(|t| t.len() == len), "training length");
        let weights: Vec<f64> = (0..len)
            .map(|j| {
                let mean = training.iter().map(|t| t[j]).sum::<f64>() / training.len() as f64;
                lattice.step / (mean * mean)
            })
            .collect();
        // Work with y = √ω P, orthonormal in the plain inner product.
        let root: Vec<f64> = weights.iter().map(|w| w.sqrt()).collect();
        let mut residuals: Vec<Vec<f64>> = training
            .iter()
            .map(|t| t.iter().zip(&root).map(|(p, r)| p * r).collect())
            .collect();
        let first_norm = residuals.iter().map(|r| norm2(r)).fold(0.0, f64::max);
        let mut basis: Vec<Vec<f64>> = Vec::new();
        let mut fixed = fixed.iter().map(|f| {
            f.iter()
                .zip(&root)
                .map(|(p, r)| p * r)
                .collect::<Vec<f64>>()
        });
        while basis.len() < n {
            let mut e = if let Some(f) = fixed.next() {
                f
            } else {
                let (worst, norm) = residuals
                    .iter()
                    .enumerate()
                    .map(|(m, r)| (m, norm2(r)))
                    .fold((0, -1.0), |a, b| if b.1 > a.1 { b } else { a });
                if norm <= 1e-28 * first_norm {
                    break;
                }
                residuals[worst].clone()
            };
            // Orthogonalised twice against the basis (modified Gram–Schmidt) for round-off.
            for _ in 0..2 {
                for b in &basis {
                    let d = dot(&e, b);
                    e.iter_mut().zip(b).for_each(|(x, y)| *x -= d * y);
                }
            }
            let s = norm2(&e).sqrt();
            e.iter_mut().for_each(|x| *x /= s);
            for r in &mut residuals {
                let d = dot(r, &e);
                r.iter_mut().zip(&e).for_each(|(x, y)| *x -= d * y);
            }
            basis.push(e);
        }
        let n = basis.len();
        let mut phi = vec![0.0; len * n];
        for (a, e) in basis.iter().enumerate() {
            for j in 0..len {
                phi[j * n + a] = e[j] / root[j];
            }
        }
        Self::new(lattice, weights, phi, n)
    }

    /// The basis from its weights and its functions by row, with the columns made from them.
    fn new(lattice: Lattice, weights: Vec<f64>, phi: Vec<f64>, n: usize) -> Self {
        let len = lattice.len;
        let columns = (0..n)
            .flat_map(|a| (0..len).map(move |j| (j, a)))
            .map(|(j, a)| phi[j * n + a])
            .collect();
        Self {
            lattice,
            weights,
            phi,
            columns,
            n,
        }
    }

    /// Number of functions.
    pub fn len(&self) -> usize {
        self.n
    }

    /// Whether the basis has no functions (never, for a built basis).
    pub fn is_empty(&self) -> bool {
        self.n == 0
    }

    /// The lattice points q_j [h/Mpc] the functions are sampled on.
    pub fn q(&self) -> Vec<f64> {
        (0..self.lattice.len)
            .map(|j| self.lattice.x(j).exp())
            .collect()
    }

    /// The mean training spectrum P̄ on the lattice (the weights are ω_j = Δln q / P̄_j²).
    pub(crate) fn mean_samples(&self) -> Vec<f64> {
        self.weights
            .iter()
            .map(|w| (self.lattice.step / w).sqrt())
            .collect()
    }

    /// The lattice the functions are sampled on.
    pub(crate) fn lattice(&self) -> &Lattice {
        &self.lattice
    }

    /// The lattice row j: φ_a(q_j) for every a.
    pub(crate) fn row(&self, j: usize) -> &[f64] {
        &self.phi[j * self.n..(j + 1) * self.n]
    }

    /// The functions f(φ_a), f a linear map of lattice samples (e.g. a filter), by row as
    /// [`row`](Self::row): `out[j * n + a]` = f(φ_a)(q_j). The coefficients of a spectrum on this
    /// basis are those of f(spectrum) on these functions.
    pub(crate) fn transformed_rows(&self, f: &dyn Fn(&[f64]) -> Vec<f64>) -> Vec<f64> {
        let (len, n) = (self.lattice.len, self.n);
        let mut rows = vec![0.0; len * n];
        for (a, column) in self.columns.chunks_exact(len).enumerate() {
            for (j, v) in f(column).into_iter().enumerate().take(len) {
                rows[j * n + a] = v;
            }
        }
        rows
    }

    /// The functions' lattice interpolants at ln q = `x` into `out` (length n), zero outside the
    /// lattice (as the loop integrals take the spectrum).
    #[inline]
    pub(crate) fn at_ln(&self, x: f64, out: &mut [f64]) {
        out.iter_mut().for_each(|o| *o = 0.0);
        let l = &self.lattice;
        let u = (x - l.x0) / l.step;
        if !(0.0..=(l.len - 1) as f64).contains(&u) {
            return;
        }
        let (b, t) = l.stencil(u);
        let w = crate::integrate::lagrange4(t);
        for (i, wi) in w.iter().enumerate() {
            for (o, p) in out.iter_mut().zip(self.row(b + i)) {
                *o += wi * p;
            }
        }
    }

    /// The samples of `spectrum` on the basis's lattice (what [`project`](Self::project) takes).
    pub fn sample(&self, spectrum: &crate::linear::LinearSpectrum) -> Vec<f64> {
        spectrum.eval_ln_many((0..self.lattice.len).map(|j| self.lattice.x(j)))
    }

    /// The projection of the lattice `samples` of a spectrum: c_a = ⟨φ_a, P⟩ and the residual.
    pub fn project(&self, samples: &[f64]) -> Projection {
        let len = self.lattice.len;
        let wp: Vec<f64> = samples
            .iter()
            .zip(&self.weights)
            .map(|(p, w)| w * p)
            .collect();
        let columns = self.columns.chunks_exact(len);
        let c: Vec<f64> = columns.map(|phi| crate::simd::dot(phi, &wp)).collect();
        self.with_coefficients(samples, c)
    }

    /// The projection of `samples` on the first `n` functions alone: [`project`](Self::project)'s
    /// coefficients with those of the functions from `n` on set to zero (the coefficients of an
    /// orthonormal basis do not depend on the others), the samples and residuals of that sum. The
    /// basis is nested (greedy), so this is the projection on the basis of `n` functions, and a loop
    /// term evaluated from tensors with these coefficients is the term of that basis's P̂ (the tensor
    /// entries with an index ≥ n are multiplied by zero). The first
    /// [`TAIL_FUNCTIONS`](super::training::TAIL_FUNCTIONS) functions of the CAMB basis are its tail
    /// functions (zero below 3 h/Mpc).
    pub fn project_first(&self, samples: &[f64], n: usize) -> Projection {
        self.project_on(samples, |a| a < n)
    }

    /// The projection of `samples` on the functions a with `keep(a)` alone (the others' coefficients
    /// zero), as [`project_first`](Self::project_first) on any subset.
    pub fn project_on(&self, samples: &[f64], keep: impl Fn(usize) -> bool) -> Projection {
        let mut c = self.coefficients_many(&[samples]).remove(0);
        c.iter_mut()
            .enumerate()
            .filter(|(a, _)| !keep(*a))
            .for_each(|(_, x)| *x = 0.0);
        self.with_coefficients(samples, c)
    }

    /// The projected samples of `projection` (of a spectrum on this basis) as a spectrum on the lattice
    /// (what loop terms from tensors integrate in place of P), for direct integrals of it.
    ///
    /// # Errors
    /// As [`LinearSpectrum::from_nodes`](crate::linear::LinearSpectrum::from_nodes): a projection that
    /// is not positive on the lattice.
    pub fn spectrum_of(
        &self,
        projection: &Projection,
    ) -> crate::error::Result<crate::linear::LinearSpectrum> {
        crate::linear::LinearSpectrum::from_nodes(self.q(), projection.samples.clone())
    }

    /// The projection of `samples` with the coefficients `c` (one per function; e.g. the projection's
    /// coefficients mapped onto a subspace): Σ_a c_a φ_a on the lattice and its residuals relative to
    /// `samples`.
    pub fn with_coefficients(&self, samples: &[f64], c: Vec<f64>) -> Projection {
        let len = self.lattice.len;
        let mut projected = vec![0.0; len];
        for (phi, &ca) in self.columns.chunks_exact(len).zip(&c) {
            crate::simd::axpy(&mut projected, ca, phi);
        }
        let relative: Vec<f64> = projected
            .iter()
            .zip(samples)
            .map(|(p, s)| p / s - 1.0)
            .collect();
        let finite = |r: f64| if r.is_nan() { f64::INFINITY } else { r };
        let pointwise = relative.iter().map(|r| r.abs()).fold(0.0, f64::max);
        let residual = smoothed(&relative, SMOOTHING / self.lattice.step, RESIDUAL_STRIDE)
            .iter()
            .map(|r| r.abs())
            .fold(0.0, f64::max);
        Projection {
            coefficients: c,
            samples: projected,
            residual: finite(residual),
            pointwise: finite(pointwise),
            soft: None,
        }
    }

    /// The coefficients alone of [`Self::project`] of each of `samples` (e.g. directions of a
    /// spectrum's tangent, for which a residual relative to the samples means nothing), the basis
    /// functions read once for all.
    pub fn coefficients_many(&self, samples: &[&[f64]]) -> Vec<Vec<f64>> {
        let weighted: Vec<Vec<f64>> = samples
            .iter()
            .map(|s| s.iter().zip(&self.weights).map(|(p, w)| w * p).collect())
            .collect();
        let mut c = vec![Vec::with_capacity(self.columns.len() / self.lattice.len); samples.len()];
        for phi in self.columns.chunks_exact(self.lattice.len) {
            for (c, wp) in c.iter_mut().zip(&weighted) {
                c.push(crate::simd::dot(phi, wp));
            }
        }
        c
    }

    /// The projection of `spectrum`; if its residual exceeds `max_residual` (or is NaN), that of the
    /// spectrum cut below [`super::soft::SOFT_CUT`] with what the cut changed
    /// ([`super::soft`]), if that one is within `max_residual` (else the first).
    pub fn project_spectrum(
        &self,
        spectrum: &crate::linear::LinearSpectrum,
        max_residual: f64,
    ) -> Projection {
        self.project_spectrum_sampled(spectrum, &self.sample(spectrum), max_residual)
    }

    /// As [`project_spectrum`](Self::project_spectrum) with the spectrum's lattice `samples`
    /// ([`sample`](Self::sample)) already made.
    pub fn project_spectrum_sampled(
        &self,
        spectrum: &crate::linear::LinearSpectrum,
        samples: &[f64],
        max_residual: f64,
    ) -> Projection {
        let whole = self.project(samples);
        if whole.residual <= max_residual {
            return whole;
        }
        let Some(cut) = super::soft::cut(spectrum) else {
            return whole;
        };
        let cut_samples = self.sample(&cut);
        let mut projection = self.project(&cut_samples);
        if projection.residual.is_nan() || projection.residual > max_residual {
            return whole;
        }
        projection.soft = Some(super::soft::soft_modes(
            &self.lattice,
            samples,
            &cut_samples,
        ));
        projection
    }

    /// The basis as values for a cache file: n, then ω, then φ row by row.
    pub(crate) fn to_f64s(&self) -> Vec<f64> {
        let mut v = vec![self.n as f64];
        v.extend(&self.weights);
        v.extend(&self.phi);
        v
    }

    /// The basis on `lattice` from [`to_f64s`](Self::to_f64s) values (the rest of the slice
    /// returned), or `None` if they do not fit.
    pub(crate) fn from_f64s(lattice: Lattice, values: &[f64]) -> Option<(Self, &[f64])> {
        let n = super::stored_count(*values.first()?, super::MAX_STORED_BASIS)?;
        let len = lattice.len;
        let size = len.checked_mul(n)?.checked_add(1 + len)?;
        if n == 0 || values.len() < size {
            return None;
        }
        let basis = Self::new(
            lattice,
            values[1..1 + len].to_vec(),
            values[1 + len..size].to_vec(),
            n,
        );
        Some((basis, &values[size..]))
    }
}

/// A crafted basis size for a lattice of `len` points (odd, as every [`Lattice`]) that an f64 holds
/// exactly and whose product with `len` wraps to 2048 in 64 bits: n = 2^11 m with m·len ≡ 1 mod
/// 2^53. Unchecked, such a file passes the length check and panics when the basis is sliced.
#[cfg(test)]
pub(crate) fn wrapping_basis_size(len: usize) -> f64 {
    let len = len as u64;
    // Newton's iteration for the inverse of an odd number modulo 2^64 (each step doubles the bits).
    let mut inverse = len;
    for _ in 0..6 {
        inverse = inverse.wrapping_mul(2u64.wrapping_sub(len.wrapping_mul(inverse)));
    }
    let n = (inverse & ((1 << 53) - 1)) << 11;
    assert_eq!(n.wrapping_mul(len), 2048);
    n as f64
}

/// The smoothed residual is evaluated at every this many lattice points (0.4 of the smoothing width
/// apart at the lattice step 0.01): a peak of the smoothed residual, at least the smoothing width wide,
/// is then underestimated by at most 1 − e^{−0.2²/2} = 2%, for a quarter of the work.
const RESIDUAL_STRIDE: usize = 4;

/// `values` smoothed with a Gaussian of `width` points (standard deviation), truncated at 3 widths
/// and renormalised at the ends, at every `stride`-th point (and the last).
fn smoothed(values: &[f64], width: f64, stride: usize) -> Vec<f64> {
    let reach = (3.0 * width).ceil() as usize;
    let g: Vec<f64> = (0..=reach)
        .map(|d| (-0.5 * (d as f64 / width).powi(2)).exp())
        .collect();
    let len = values.len();
    // Interior points: one dot product with the whole symmetric kernel, normalised once.
    let kernel: Vec<f64> = (0..=2 * reach).map(|i| g[i.abs_diff(reach)]).collect();
    let norm = 1.0 / kernel.iter().sum::<f64>();
    (0..len)
        .step_by(stride)
        .chain((len > 0 && !(len - 1).is_multiple_of(stride)).then(|| len - 1))
        .map(|j| {
            if j >= reach && j + reach < len {
                return norm * crate::simd::dot(&values[j - reach..=j + reach], &kernel);
            }
            let (lo, hi) = (j.saturating_sub(reach), (j + reach).min(len - 1));
            let (mut s, mut w) = (0.0, 0.0);
            for (i, v) in values.iter().enumerate().take(hi + 1).skip(lo) {
                let gi = g[i.abs_diff(j)];
                s += gi * v;
                w += gi;
            }
            s / w
        })
        .collect()
}

fn norm2(a: &[f64]) -> f64 {
    dot(a, a)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Power laws q^n e^{−q}: a 3-parameter family spanned by few functions.
    fn family(lattice: &Lattice, n: f64, a: f64) -> Vec<f64> {
        (0..lattice.len)
            .map(|j| {
                let q = lattice.x(j).exp();
                a * q.powf(n) / (1.0 + q * q)
            })
            .collect()
    }

    #[test]
    fn a_spectrum_in_the_span_projects_exactly_and_others_nearly() {
        let lattice = Lattice::new(1e-5, 1e3, 0.05);
        // Two exponents: the span of two functions holds every amplitude of them exactly.
        let training: Vec<Vec<f64>> = [(1.0, 1.0), (0.9, 2.0), (1.0, 3.0)]
            .iter()
            .map(|&(n, a)| family(&lattice, n, a))
            .collect();
        let basis = LinearBasis::greedy(lattice.clone(), &[], &training, 10);
        assert_eq!(basis.len(), 2, "the training set spans two dimensions");
        let p = family(&lattice, 0.9, 7.5);
        let proj = basis.project(&p);
        assert!(proj.residual < 1e-12, "{}", proj.residual);
        // Orthonormal in the weighted inner product.
        let gram = |a: usize, b: usize| -> f64 {
            (0..lattice.len)
                .map(|j| basis.weights[j] * basis.row(j)[a] * basis.row(j)[b])
                .sum()
        };
        assert!((gram(0, 0) - 1.0).abs() < 1e-12 && gram(0, 1).abs() < 1e-12);
        // An exponent between the trained ones is not in the span: a small but non-zero residual.
        let q = basis.project(&family(&lattice, 0.95, 1.0));
        assert!(q.residual > 1e-6 && q.residual < 0.1, "{}", q.residual);
        // Interpolated functions match the samples at lattice points.
        let mut out = vec![0.0; 2];
        basis.at_ln(lattice.x(100), &mut out);
        assert!((out[1] - basis.row(100)[1]).abs() < 1e-15);
    }

    /// A basis size read from a cache file (whose checksum is valid: a crafted or mis-written file) is
    /// bounded before use: a huge, negative, non-integer or non-finite count, or one above
    /// [`super::super::MAX_STORED_BASIS`], gives `None` (the file is rebuilt), never a panic or a
    /// huge allocation ([`wrapping_basis_size`]: the size that panicked at the slicing of φ).
    #[test]
    fn a_crafted_basis_size_is_refused() {
        let lattice = Lattice::new(1e-5, 1e3, 0.05);
        let training: Vec<Vec<f64>> = [(1.0, 1.0), (0.9, 2.0)]
            .iter()
            .map(|&(n, a)| family(&lattice, n, a))
            .collect();
        let good = LinearBasis::greedy(lattice.clone(), &[], &training, 10).to_f64s();
        let (back, rest) = LinearBasis::from_f64s(lattice.clone(), &good).unwrap();
        assert!(back.len() == 2 && rest.is_empty());
        let mut long = good.clone();
        long.resize(good.len() + 4096, 0.5);
        for n in [
            wrapping_basis_size(lattice.len),
            2f64.powi(63),
            1e18,
            1e300,
            f64::INFINITY,
            f64::NAN,
            -1.0,
            2.5,
            1025.0,
        ] {
            let mut v = long.clone();
            v[0] = n;
            assert!(LinearBasis::from_f64s(lattice.clone(), &v).is_none(), "{n}");
        }
    }

    #[test]
    fn smoothing_keeps_straight_lines_and_spreads_a_spike_over_its_width() {
        // A symmetric window keeps a linear function exactly away from the ends.
        let line: Vec<f64> = (0..200).map(|j| 0.3 - 0.01 * j as f64).collect();
        let s = smoothed(&line, 10.0, 1);
        for j in 30..170 {
            assert!((s[j] - line[j]).abs() < 1e-14, "{j}");
        }
        // A unit spike becomes the normalised Gaussian: at the spike 1/Σ_d e^{−d²/2w²} ≈ 1/(w√(2π)),
        // one width away e^{−1/2} of that.
        let mut spike = vec![0.0; 200];
        spike[100] = 1.0;
        let s = smoothed(&spike, 10.0, 1);
        assert!((s[100] * 10.0 * (2.0 * std::f64::consts::PI).sqrt() - 1.0).abs() < 3e-3);
        assert!((s[110] / s[100] - (-0.5f64).exp()).abs() < 1e-14);
        // Every fourth point, and the last: the same values there.
        let every = smoothed(&spike, 10.0, 4);
        assert_eq!(every.len(), 51);
        assert_eq!(every[25], s[100]);
        assert_eq!(every[50], s[199]);
    }
}
