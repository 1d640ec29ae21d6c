//! The linear-Kaiser Fisher forecast of fσ8 with the shape and geometry fixed (White, Song &
//! Percival 2009, arXiv:0810.1518; the method of the DESI Final Design Report's RSD forecasts,
//! arXiv:1611.00036, Tables 2.3 and 2.5): the model against which published forecasts of that kind
//! are reproduced ([`fisher_kaiser`]).
//!
//! Each bin has one or more tracers t of number density n̄_t and linear bias b_t sharing the volume V.
//! Their redshift-space spectra are linear Kaiser, P_ij(k, μ) = (b_i + fμ²)(b_j + fμ²) P_lin(k),
//! with no damping, no AP distortion and the linear spectrum's shape fixed. The covariance of the
//! tracers' modes is C_ij = P_ij + δ_ij/n̄_i and the Fisher matrix of the parameters θ = (f, b_1 …
//! b_T) is the Gaussian-field one (the full P(k, μ), not its multipoles):
//!
//! ```text
//! F_ab = V/(4π²) ∫_{k_min}^{k_max} k² dk ∫_0^1 dμ Tr[C⁻¹ ∂_a C C⁻¹ ∂_b C],
//! ```
//!
//! (V k² dk dμ/(4π²) independent complex modes with μ ∈ [0, 1]). With ∂_a C = P (u_a aᵀ + a u_aᵀ)
//! (a_i = b_i + fμ², u = μ²·1 for f, the unit vector e_t for b_t) the trace is
//! 2P²[(aᵀC⁻¹u_a)(aᵀC⁻¹u_b) + (aᵀC⁻¹a)(u_aᵀC⁻¹u_b)], with C⁻¹ from C's Cholesky factor. Because σ8 is fixed, σ(fσ8)/fσ8 = σ(f)/f and σ(b_tσ8)/
//! (b_tσ8) = σ(b_t)/b_t; σ(fσ8) = σ8(z) σ(f).
//!
//! Quadrature: Gauss–Legendre, 8 nodes on k panels of at most 0.005 h/Mpc (the BAO wiggles) and 24
//! nodes in μ on [0, 1] (the integrand is smooth in μ; converged to ≲ 1e-10, tested against closed
//! forms).

use crate::cosmology::Cosmology;
use crate::emulator::{LinearEmulator, K_GROWTH_RATE};
use crate::error::{Error, Result};
use crate::integrate::legendre_nodes;
use crate::linalg::{cholesky, invert_lower};

/// One tracer of a bin: number density [(h/Mpc)³] and linear bias.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct KaiserTracer {
    /// Number density [(h/Mpc)³].
    pub n_bar: f64,
    /// Linear bias.
    pub b1: f64,
}

/// One redshift bin of a linear-Kaiser forecast.
#[derive(Debug, Clone, PartialEq)]
pub struct KaiserBin {
    /// Redshift (of the linear spectrum, f and σ8).
    pub z: f64,
    /// Comoving volume [(Mpc/h)³].
    pub volume: f64,
    /// The smallest k [h/Mpc] (default 0.001: the result depends on it through k³ only).
    pub k_min: f64,
    /// The largest k [h/Mpc].
    pub k_max: f64,
    /// The tracers sharing the volume (their cross-spectra used: the multi-tracer forecast).
    pub tracers: Vec<KaiserTracer>,
}

impl KaiserBin {
    /// A bin of one tracer, k from 0.001 to `k_max`.
    pub fn new(z: f64, volume: f64, n_bar: f64, b1: f64, k_max: f64) -> Self {
        Self {
            z,
            volume,
            k_min: 0.001,
            k_max,
            tracers: vec![KaiserTracer { n_bar, b1 }],
        }
    }

    fn validate(&self, index: usize) -> Result<()> {
        let bad = |what: String, reason: &str| Error::InvalidChoice {
            what: format!("Kaiser bin {}: {what}", index + 1),
            reason: reason.into(),
        };
        if !(self.z.is_finite() && self.z >= 0.0) {
            return Err(bad(format!("z = {}", self.z), "must be finite and >= 0"));
        }
        if !(self.volume.is_finite() && self.volume > 0.0) {
            return Err(bad(format!("volume = {}", self.volume), "must be > 0"));
        }
        if !(self.k_min.is_finite() && self.k_min > 0.0 && self.k_max > self.k_min) {
            return Err(bad(
                format!("k range [{}, {}]", self.k_min, self.k_max),
                "needs 0 < k_min < k_max",
            ));
        }
        if self.tracers.is_empty() {
            return Err(bad("tracers".into(), "at least one tracer is needed"));
        }
        for (t, tr) in self.tracers.iter().enumerate() {
            if !(tr.n_bar.is_finite() && tr.n_bar > 0.0 && tr.b1.is_finite() && tr.b1 > 0.0) {
                return Err(bad(
                    format!("tracer {} (n_bar {}, b1 {})", t + 1, tr.n_bar, tr.b1),
                    "n_bar and b1 must be finite and > 0",
                ));
            }
        }
        Ok(())
    }
}

/// The result of [`fisher_kaiser`]: per bin the parameters `f_i`, then `b1_i` (one tracer) or
/// `b1.t_i` (tracer t of several), block-diagonal over bins.
#[derive(Debug, Clone, PartialEq)]
pub struct KaiserForecast {
    /// Parameter names, bin by bin.
    pub names: Vec<String>,
    /// Their fiducial values.
    pub fiducial: Vec<f64>,
    /// The Fisher matrix.
    pub fisher: Vec<Vec<f64>>,
    /// Its inverse.
    pub covariance: Vec<Vec<f64>>,
    /// √(covariance)ᵢᵢ.
    pub sigma: Vec<f64>,
    /// Per bin (σ(fσ8), fσ8) with σ8(z) of the fiducial's cb spectrum.
    pub fsigma8: Vec<(f64, f64)>,
}

/// The Fisher matrix of (f, b_1 … b_T) of one bin (module docs): `tracers` (n̄, b), growth rate `f`,
/// linear spectrum `p_lin` [(Mpc/h)³] of k [h/Mpc], volume [(Mpc/h)³], k range [h/Mpc].
pub fn kaiser_fisher(
    tracers: &[KaiserTracer],
    f: f64,
    p_lin: &dyn Fn(f64) -> f64,
    volume: f64,
    k_min: f64,
    k_max: f64,
) -> Vec<Vec<f64>> {
    let t = tracers.len();
    let np = t + 1;
    let (xk, wk) = legendre_nodes(8);
    let (xm, wm) = legendre_nodes(24);
    let panels = ((k_max - k_min) / 0.005).ceil().max(1.0) as usize;
    let width = (k_max - k_min) / panels as f64;
    // the μ part of the integrand at one k, for the spectrum value p
    let per_k = |p: f64| -> Vec<Vec<f64>> {
        let mut out = vec![vec![0.0; np]; np];
        for (&x, &w) in xm.iter().zip(&wm) {
            let mu = 0.5 * (1.0 + x);
            let mu2 = mu * mu;
            let a: Vec<f64> = tracers.iter().map(|tr| tr.b1 + f * mu2).collect();
            // C⁻¹ = L⁻ᵀL⁻¹ from the Cholesky factor of C = P aaᵀ + diag(1/n̄) (symmetric positive
            // definite for finite n̄; exact to rounding, also when n̄P ≫ 1)
            let c: Vec<Vec<f64>> = (0..t)
                .map(|i| {
                    (0..t)
                        .map(|j| {
                            p * a[i] * a[j] + if i == j { 1.0 / tracers[i].n_bar } else { 0.0 }
                        })
                        .collect()
                })
                .collect();
            let li = invert_lower(&cholesky(&c).expect("C is positive definite for n̄ > 0"));
            let g: Vec<Vec<f64>> = (0..t)
                .map(|i| {
                    (0..t)
                        .map(|j| (0..t).map(|m| li[m][i] * li[m][j]).sum())
                        .collect()
                })
                .collect();
            // u vectors: f → μ²·1, b_s → e_s
            let u = |par: usize| -> Vec<f64> {
                if par == 0 {
                    vec![mu2; t]
                } else {
                    (0..t)
                        .map(|i| if i + 1 == par { 1.0 } else { 0.0 })
                        .collect()
                }
            };
            let form = |x: &[f64], y: &[f64]| -> f64 {
                (0..t)
                    .map(|i| x[i] * (0..t).map(|j| g[i][j] * y[j]).sum::<f64>())
                    .sum()
            };
            let us: Vec<Vec<f64>> = (0..np).map(u).collect();
            let aga = form(&a, &a);
            let agu: Vec<f64> = us.iter().map(|v| form(&a, v)).collect();
            for i in 0..np {
                for j in i..np {
                    let tr = 2.0 * p * p * (agu[i] * agu[j] + aga * form(&us[i], &us[j]));
                    out[i][j] += 0.5 * w * tr;
                }
            }
        }
        out
    };
    let mut fisher = vec![vec![0.0; np]; np];
    for panel in 0..panels {
        let lo = k_min + panel as f64 * width;
        for (&x, &w) in xk.iter().zip(&wk) {
            let k = lo + 0.5 * width * (1.0 + x);
            let m = per_k(p_lin(k));
            let weight = 0.5 * width * w * k * k * volume / (4.0 * std::f64::consts::PI.powi(2));
            for i in 0..np {
                for j in i..np {
                    fisher[i][j] += weight * m[i][j];
                }
            }
        }
    }
    // the lower triangle from the upper
    (0..np)
        .map(|i| (0..np).map(|j| fisher[i.min(j)][i.max(j)]).collect())
        .collect()
}

/// The linear-Kaiser forecast of `bins` (module docs) in the `fiducial` cosmology: the linear cb
/// spectrum, f_cb (at k = 0.1 h/Mpc) and σ8 of the emulator at each bin's z.
///
/// # Errors
/// [`Error::InvalidChoice`] naming a bin's bad value; as the emulator (a fiducial outside its prior).
pub fn fisher_kaiser(bins: &[KaiserBin], fiducial: &Cosmology) -> Result<KaiserForecast> {
    if bins.is_empty() {
        return Err(Error::InvalidChoice {
            what: "survey".into(),
            reason: "no redshift bin given".into(),
        });
    }
    for (i, b) in bins.iter().enumerate() {
        b.validate(i)?;
    }
    let emulator = LinearEmulator::shared()?;
    let n: usize = bins.iter().map(|b| b.tracers.len() + 1).sum();
    let mut fisher = vec![vec![0.0; n]; n];
    let mut covariance = vec![vec![0.0; n]; n];
    let (mut names, mut fiducial_values, mut fsigma8) = (Vec::new(), Vec::new(), Vec::new());
    let mut offset = 0;
    for (i, bin) in bins.iter().enumerate() {
        let spectra = emulator.spectra(fiducial, bin.z)?;
        let cb = spectra.cb()?;
        let f = spectra.growth_rate_cb()?.eval(K_GROWTH_RATE);
        let block = kaiser_fisher(
            &bin.tracers,
            f,
            &|k| cb.eval(k),
            bin.volume,
            bin.k_min,
            bin.k_max,
        );
        let inverse = crate::linalg::solve_spd(&block, &vec![0.0; block.len()])
            .map(|(_, inv, _)| inv)
            .map_err(|_| Error::InvalidChoice {
                what: format!("Kaiser bin {}: the Fisher matrix", i + 1),
                reason: "it is not positive definite".into(),
            })?;
        names.push(format!("f_{}", i + 1));
        fiducial_values.push(f);
        for (t, tr) in bin.tracers.iter().enumerate() {
            names.push(if bin.tracers.len() == 1 {
                format!("b1_{}", i + 1)
            } else {
                format!("b1.{}_{}", t + 1, i + 1)
            });
            fiducial_values.push(tr.b1);
        }
        for a in 0..block.len() {
            for b in 0..block.len() {
                fisher[offset + a][offset + b] = block[a][b];
                covariance[offset + a][offset + b] = inverse[a][b];
            }
        }
        let s8 = cb.sigma8();
        fsigma8.push((s8 * inverse[0][0].sqrt(), s8 * f));
        offset += block.len();
    }
    let sigma = (0..n).map(|i| covariance[i][i].sqrt()).collect();
    Ok(KaiserForecast {
        names,
        fiducial: fiducial_values,
        fisher,
        covariance,
        sigma,
        fsigma8,
    })
}
