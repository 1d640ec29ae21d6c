//! The 1-loop plan: cosmology-independent weights for P22, P13 and σ_v² on a fixed k grid.

use super::lattice::Lattice;
use super::p13::{p13_weights, sigma_v2_weights, P13Weights};
use super::p22::{Layout, P22Nodes};
use super::{ByPair, Estimate, OneLoopTerms};
use crate::error::{Error, Result};
use crate::integrate::legendre_nodes;
use crate::linear::LinearSpectrum;
use crate::precision::Precision;
use crate::simd::dot_fixed as dot;
use rayon::prelude::*;

/// The half-resolution rule of the error estimates lowers every P22 Gauss–Legendre order by this.
pub(crate) const COARSE_ORDER_DROP: usize = 2;

/// P_lin, then [P13_F/P, P13_G/P, P22_δδ, P22_δθ, P22_θθ] with the fine and the half-resolution rule.
type Row = (f64, [f64; 5], [f64; 5]);

/// The spectrum sampled on the fine lattice and on every other point of it.
struct Samples {
    fine: Vec<f64>,
    coarse: Vec<f64>,
}

impl Samples {
    fn new(lattice: &Lattice, spectrum: &LinearSpectrum) -> Self {
        let fine = lattice.sample(spectrum);
        let coarse = fine.iter().step_by(2).copied().collect();
        Self { fine, coarse }
    }
}

/// Weights of one lattice (fine or half-resolution).
#[derive(Debug, Clone)]
pub(crate) struct Rule {
    pub lattice: Lattice,
    pub sigma_v2: Vec<f64>,
    pub p13: Vec<P13Weights>,
    pub p22: P22Nodes,
}

impl Rule {
    /// The rule on `lattice`; `drop` lowers the P22 Gauss–Legendre orders (the half-resolution rule:
    /// `drop` for the full order, `drop / 2` for the narrow-range order, whose integrand is a
    /// polynomial of degree ~5 that a 3-point rule still integrates well).
    fn new(ks: &[f64], lattice: Lattice, precision: &Precision, drop: usize) -> Self {
        let (nodes, weights) = legendre_nodes(precision.p13_cell_order);
        let rule = (nodes.as_slice(), weights.as_slice());
        let layout = Layout::new(precision, drop);
        Self {
            sigma_v2: sigma_v2_weights(&lattice, rule),
            p13: ks
                .par_iter()
                .map(|&k| p13_weights(&lattice, k, rule))
                .collect(),
            p22: P22Nodes::p22(ks, &lattice, &layout),
            lattice,
        }
    }

    /// [σ_v²] and, at k index i, [P13_F/P, P13_G/P, P22_δδ, P22_δθ, P22_θθ].
    fn terms(&self, i: usize, samples: &[f64]) -> [f64; 5] {
        let w = &self.p13[i];
        let [a, b, c] = self.p22.evaluate(i, &self.lattice, samples);
        [dot(&w.f, samples), dot(&w.g, samples), a, b, c]
    }
}

/// Checks `precision` and that `k` is a grid ([`crate::table::check_k_values`]: non-empty, finite,
/// positive, strictly increasing) inside (q_min, q_max).
pub(crate) fn validate_grid(k: &[f64], precision: &Precision) -> Result<()> {
    precision.validate()?;
    crate::table::check_k_values("k", k)?;
    if let Some(&bad) = k
        .iter()
        .find(|&&v| !(v.is_finite() && v > precision.q_min && v < precision.q_max))
    {
        return Err(Error::InvalidParameter {
            name: "k [h/Mpc]",
            value: bad,
            reason: "must be finite and inside the integration range (q_min, q_max)",
        });
    }
    Ok(())
}

/// A plan for the 1-loop terms on a fixed k grid: all quadrature weights, built once, independent of the
/// linear spectrum. [`evaluate`](Self::evaluate) then costs one lattice sampling of P plus dot products.
///
/// ```
/// use pt_spectra::{linear::LinearSpectrum, loops::{OneLoopPlan, Pair}, precision::Precision};
/// let p = LinearSpectrum::gm2012(0.0)?;
/// let plan = OneLoopPlan::new(&[0.05, 0.1, 0.2], &Precision::fast())?;
/// let t = plan.evaluate(&p);
/// // 1-loop δδ correction at k = 0.1 h/Mpc, z = 0: P22 + 2 P13 ≈ 1854 − 1501, about 7% of P_lin.
/// let one_loop = t.one_loop(Pair::DeltaDelta, 1).value;
/// assert!((one_loop / t.p_lin[1] - 0.066).abs() < 0.005);
/// assert!(t.p22.dd[1].relative_error() < 1e-4);
/// # Ok::<(), pt_spectra::error::Error>(())
/// ```
#[derive(Debug, Clone)]
pub struct OneLoopPlan {
    k: Vec<f64>,
    precision: Precision,
    fine: Rule,
    coarse: Rule,
}

/// Bytes per output k of the plan at the default node density (measured 0.32 MB, `fast` 0.125,
/// `reference` 4.7, rounded up).
const BYTES_PER_K: f64 = 0.4e6;

impl OneLoopPlan {
    /// The estimated memory of a plan on `nk` wavenumbers with `precision` \[bytes\] (its rules at
    /// `BYTES_PER_K` per k, scaled with the node density), which the plans that hold it
    /// ([`crate::real::RealPlan`], [`crate::rsd::RsdPlan`]) check against the limit before they allocate.
    pub fn memory_estimate(nk: usize, precision: &Precision) -> f64 {
        BYTES_PER_K * crate::memory::node_density(precision) * nk as f64
    }

    /// The plan for wavenumbers `k` [h/Mpc] (strictly increasing).
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] for invalid `precision` (see [`Precision::validate`]) or a k not
    /// inside (q_min, q_max); [`Error::InvalidChoice`] for an empty grid or a k that is not finite,
    /// positive and above the previous one.
    pub fn new(k: &[f64], precision: &Precision) -> Result<Self> {
        validate_grid(k, precision)?;
        let lattice = Lattice::new(precision.q_min, precision.q_max, precision.lattice_step);
        let coarse_lattice = lattice.coarse();
        let (coarse, fine) = rayon::join(
            || Rule::new(k, coarse_lattice, precision, COARSE_ORDER_DROP),
            || Rule::new(k, lattice, precision, 0),
        );
        Ok(Self {
            k: k.to_vec(),
            precision: precision.clone(),
            coarse,
            fine,
        })
    }

    /// The wavenumbers [h/Mpc].
    pub fn k(&self) -> &[f64] {
        &self.k
    }

    /// The settings the plan was built with.
    pub fn precision(&self) -> &Precision {
        &self.precision
    }

    /// The fine rule and the half-resolution rule of the error estimates (the basis tensors of
    /// [`super::basis::OneLoopBasis`] are made from them).
    pub(crate) fn rules(&self) -> (&Rule, &Rule) {
        (&self.fine, &self.coarse)
    }

    /// Number of P22 quadrature nodes (fine rule, all k), a measure of the cost of an evaluation.
    pub fn p22_nodes(&self) -> usize {
        self.fine.p22.len()
    }

    /// All 1-loop terms for `spectrum`, one k after the other on the calling thread.
    ///
    /// The spectrum is used on [q_min, q_max] of the plan's [`Precision`], through its power-law
    /// extrapolation outside its table (see [`LinearSpectrum::extrapolation_in`]).
    pub fn evaluate(&self, spectrum: &LinearSpectrum) -> OneLoopTerms {
        let samples = Samples::new(&self.fine.lattice, spectrum);
        let rows: Vec<_> = (0..self.k.len())
            .map(|i| self.row(i, spectrum, &samples))
            .collect();
        self.assemble(&samples, rows)
    }

    /// As [`evaluate`](Self::evaluate), with the k values shared out over rayon's thread pool. Every k
    /// is still summed sequentially, so the result is bit-identical to [`evaluate`](Self::evaluate).
    pub fn par_evaluate(&self, spectrum: &LinearSpectrum) -> OneLoopTerms {
        let samples = Samples::new(&self.fine.lattice, spectrum);
        let rows: Vec<_> = (0..self.k.len())
            .into_par_iter()
            .with_min_len(4)
            .map(|i| self.row(i, spectrum, &samples))
            .collect();
        self.assemble(&samples, rows)
    }

    /// (P_lin, fine terms, coarse terms) at k index i.
    fn row(&self, i: usize, spectrum: &LinearSpectrum, samples: &Samples) -> Row {
        (
            spectrum.eval(self.k[i]),
            self.fine.terms(i, &samples.fine),
            self.coarse.terms(i, &samples.coarse),
        )
    }

    fn assemble(&self, samples: &Samples, rows: Vec<Row>) -> OneLoopTerms {
        let sv = dot(&self.fine.sigma_v2, &samples.fine);
        let sv_coarse = dot(&self.coarse.sigma_v2, &samples.coarse);
        let n = rows.len();
        let mut out = OneLoopTerms {
            k: self.k.clone(),
            p_lin: Vec::with_capacity(n),
            sigma_v2: Estimate::new(sv, (sv - sv_coarse).abs()),
            p22: ByPair::from_fn(|_| Vec::with_capacity(n)),
            p13: ByPair::from_fn(|_| Vec::with_capacity(n)),
        };
        for (p, fine, coarse) in rows {
            let floor = self.precision.p22_error_floor;
            let e = |j: usize, scale: f64| {
                let mut error = (fine[j] - coarse[j]).abs();
                if j >= 2 {
                    error = error.max(floor * fine[j].abs());
                }
                Estimate::new(scale * fine[j], scale * error)
            };
            let (f13, g13) = (e(0, p), e(1, p));
            out.p_lin.push(p);
            out.p13.dd.push(f13);
            out.p13.tt.push(g13);
            out.p13.dt.push(Estimate::mean(f13, g13));
            out.p22.dd.push(e(2, 1.0));
            out.p22.dt.push(e(3, 1.0));
            out.p22.tt.push(e(4, 1.0));
        }
        out
    }
}
