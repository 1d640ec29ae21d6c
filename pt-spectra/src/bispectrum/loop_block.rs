//! The one-loop bispectrum block of a data vector (issue 50, item 4): the one-loop galaxy bispectrum
//! multipoles B₀, B₂, B₄ of a triangle set (points, or bins of shells) beside the power spectrum's, from the
//! same linear spectrum, growth rate and IR setting, sharing b1, b2, bs with the galaxy model and adding
//! its own higher-order biases and the counterterm and stochastic coefficients ([`LOOP_NAMES`]).
//!
//! - **Loops**: the multipole tensors of the set ([`super::multipole_basis`], [`super::multipole_bins`]),
//!   read from the cache when the block is planned (never built there: a build takes ~190 s per triangle
//!   and core at the default rule, with its progress shown by `pt-spectra bispectrum --loop 1 --multipoles
//!   --two-loop basis` or `pt.OneLoopMultipolePlan`). A spectrum the tensors do not represent is an error,
//!   not a silent fallback: the direct integrals take ~30 s per triangle.
//! - **Counterterms and stochastic terms**: planned once ([`super::counterterm_plan`]), exact.
//! - **Bias**: b1, b2, bs in velocileptors' convention mapped exactly to the fourth-order basis
//!   ([`LoopBias::from_class_pt`] with b2 + (4/3)bs, b_G2 = bs) with CLASS-PT's b_Γ3 (`b_gamma3`) and the
//!   coefficients b3, g2x, g3, g21x of Eggemeier, Scoccimarro & Smith (2019) as own parameters.
//! - **Alcock–Paczynski**: the tensors are at fixed triangles, but a loop at the sides k/α of P is α⁻³ times
//!   the loop at k of P(k/α) (q → q/α in ∫d³q; a counterterm shape with k^d: α^−d; the tree level: 1), so
//!   the isotropic part α = (α∥α⊥²)^{1/3} is exact on every term: the tensors and the counterterm plan
//!   take the dilated spectrum ([`LinearSpectrum::dilated`], IR's Σ² with it, [`IrInputs::dilated`]) and
//!   B = α⁻⁶[B_tree + α⁻³ B_loop + Σ c_s α^−d_s S_s](P(·/α)) + [B_tree(α∥, α⊥) − B_tree(α, α)], the
//!   anisotropic rest from the tree-level plan ([`super::BispectrumPlan`]: the same bins, IR and bias).
//!   The loop rule's cut-offs move with the sides (q_max/α in the true frame: a change the counterterms
//!   absorb). Neglected: the anisotropic change of the loops' shape, of order |α∥/α⊥ − 1|/3 times the loop
//!   correction (docs/bispectrum.md gives its measured size). At α∥ = α⊥ = 1 the block is the one-loop
//!   multipoles exactly. The spectrum must be represented by the templates as at α = 1
//!   ([`super::loop_tensors::tensor_source`]: P, or P_LO with IR); its dilation moves
//!   the BAO out of their span, so the dilated one may reach [`DILATED_MAX_RESIDUAL`] (measured: the
//!   loops' error ≤ 0.4 × the residual of B₀, far below the undistorted loops' error).
//! - **Not here**: Fingers of God beyond the counterterm ct_fog.
//!
//! Every own parameter enters B linearly (the higher biases through one kernel Z₃ or Z₄ of each term), so a
//! fit marginalises all of them analytically. A step: new terms per (spectrum, f), ~10 ms for the 62
//! Nseries bins on one core; a new bias, a contraction.

use super::bias_kernels::LoopBias;
use super::counterterm_plan::{CountertermPlan, CountertermTerms};
use super::galaxy_counterterms_rsd::{
    N_REDSHIFT_CT, REDSHIFT_COUNTERTERMS, REDSHIFT_COUNTERTERM_K_POWERS,
};
use super::loop_tensors::tensor_source;
use super::multipole_basis::MultipoleLoopBasis;
use super::multipole_bins::{correction_rules, MultipoleBinBasis};
use super::one_loop::OneLoopRule;
use super::one_loop_basis::BispectrumLoopSource;
use super::one_loop_bins::BinnedLoopMultipoles;
use super::one_loop_galaxy::OneLoopGalaxy;
use super::one_loop_galaxy_multipoles::GalaxyLoopMultipoles;
use super::{
    BispectrumParams, BispectrumPlan, BispectrumTerms, Fog, IrInputs, LegendreSide, PlanRules,
    Settings, TriangleSet,
};
use crate::error::{Error, Result};
use crate::ir::WiggleSplit;
use crate::linear::LinearSpectrum;
use crate::progress::Silent;
use crate::statistic::{foreign, Block, Kind, Prepared, Range, Shared, Spec, Survey, Terms};
use crate::store::TableStore;
use std::path::PathBuf;
use std::sync::{Arc, OnceLock};

mod faces;

/// The largest projection residual of the dilated spectrum P(k/α) that the block contracts (module docs):
/// the templates' [`MAX_RESIDUAL`](crate::loops::basis::MAX_RESIDUAL) is for the spectrum itself, and a
/// dilation moves the BAO out of the templates' span (residual to 1.1e-2 at |α − 1| = 0.1 on CAMB tables
/// not trained on). Measured: the loops' error ≤ 0.4 × the residual of B₀, where keeping the loops of P
/// undistorted was 3e-3 to 4e-2 off (`the_dilated_loops_are_the_loops_of_the_true_sides`).
pub const DILATED_MAX_RESIDUAL: f64 = 2e-2;

/// The block's own bias coefficients (before the counterterms of [`REDSHIFT_COUNTERTERMS`]).
pub const LOOP_BIASES: [&str; 5] = ["b_gamma3", "b3", "g2x", "g3", "g21x"];

/// The block's own parameters: [`LOOP_BIASES`], then the counterterm and stochastic coefficients in the
/// order of [`REDSHIFT_COUNTERTERMS`] (ct_* in (Mpc/h)², st_p* in (Mpc/h)³, st_1 in (Mpc/h)⁶).
pub const LOOP_NAMES: [&str; 25] = concat(LOOP_BIASES, REDSHIFT_COUNTERTERMS);

/// `a` then `b`.
const fn concat(a: [&'static str; 5], b: [&'static str; N_REDSHIFT_CT]) -> [&'static str; 25] {
    let mut out = [""; 25];
    let mut i = 0;
    while i < 25 {
        out[i] = if i < 5 { a[i] } else { b[i - 5] };
        i += 1;
    }
    out
}

const BIAS_RANGE: Range = (-50.0, 50.0, -1.0, 1.0, 1.0);
const CT_RANGE: Range = (-1e5, 1e5, -10.0, 10.0, 10.0);
const ST_P_RANGE: Range = (-1e7, 1e7, -1e3, 1e3, 1e3);
const ST_1_RANGE: Range = (-1e12, 1e12, -1e6, 1e6, 1e6);

/// The one-loop bispectrum's [`Kind`]: [`LOOP_NAMES`], all 0 when not given, all linear.
pub const KIND: Kind = Kind {
    name: "one_loop_bispectrum",
    own: &LOOP_NAMES,
    defaults: &[0.0; 25],
    units: &[
        "1",
        "1",
        "1",
        "1",
        "1",
        "(Mpc/h)^2",
        "(Mpc/h)^2",
        "(Mpc/h)^2",
        "(Mpc/h)^2",
        "(Mpc/h)^2",
        "(Mpc/h)^3",
        "(Mpc/h)^6",
        "(Mpc/h)^2",
        "(Mpc/h)^2",
        "(Mpc/h)^2",
        "(Mpc/h)^2",
        "(Mpc/h)^2",
        "(Mpc/h)^2",
        "(Mpc/h)^2",
        "(Mpc/h)^2",
        "(Mpc/h)^3",
        "(Mpc/h)^3",
        "(Mpc/h)^2",
        "(Mpc/h)^2",
        "(Mpc/h)^2",
    ],
    linear: &LOOP_NAMES,
    ranges: &[
        BIAS_RANGE, BIAS_RANGE, BIAS_RANGE, BIAS_RANGE, BIAS_RANGE, CT_RANGE, CT_RANGE, CT_RANGE,
        CT_RANGE, CT_RANGE, ST_P_RANGE, ST_1_RANGE, CT_RANGE, CT_RANGE, CT_RANGE, CT_RANGE,
        CT_RANGE, CT_RANGE, CT_RANGE, CT_RANGE, ST_P_RANGE, ST_P_RANGE, CT_RANGE, CT_RANGE,
        CT_RANGE,
    ],
    forecast_free: &[],
    faces: faces::FACES,
};

/// What the one-loop bispectrum block is built from.
#[derive(Debug, Clone)]
pub struct LoopBispectrumBlock {
    /// The triangles (bins of shells, or points) in the order of the data vector.
    pub triangles: TriangleSet,
    /// The side that carries the Legendre polynomial.
    pub side: LegendreSide,
    /// The loop rule the tensors were built on.
    pub rule: OneLoopRule,
    /// The multipoles in the data vector: a subset of 0, 2, 4, increasing.
    pub ells: Vec<usize>,
    /// Where the tensors are cached (`None`: [`TableStore::from_env`]).
    pub cache_dir: Option<PathBuf>,
    /// The triangles in the data vector, by index into `triangles` (`None`: all): a fit of some bins of
    /// a file whose tensors were built for all of them.
    pub fitted: Option<Vec<usize>>,
}

impl LoopBispectrumBlock {
    /// The block planned with bin tensors held in memory (e.g. built on other correction rules than
    /// the cache's): their set, side and rule replace `self`'s, `self.cache_dir` is not read.
    ///
    /// # Errors
    /// As [`Spec::plan`] but for the cache.
    pub fn plan_with_bins(&self, tensors: Arc<MultipoleBinBasis>) -> Result<Box<dyn Block>> {
        let main = tensors.effective();
        let block = Self {
            triangles: tensors.set().clone(),
            side: main.side(),
            rule: *main.rule(),
            ..self.clone()
        };
        Ok(Box::new(PlannedLoop::with_tensors(
            Tensors::Bins(tensors),
            &block,
        )?))
    }
}

impl Spec for LoopBispectrumBlock {
    fn plan(&self) -> Result<Box<dyn Block>> {
        Ok(Box::new(PlannedLoop::new(self)?))
    }
}

/// The tensors of the loops.
#[derive(Debug, Clone)]
enum Tensors {
    Points(Arc<MultipoleLoopBasis>),
    Bins(Arc<MultipoleBinBasis>),
}

/// The block planned: the loops' tensors, the counterterms' plan, the multipoles' indices into [`super::ELLS`].
#[derive(Debug, Clone)]
struct PlannedLoop {
    tensors: Tensors,
    /// The tree level's plan on the same triangles: its change under the distortion.
    tree: BispectrumPlan,
    counterterms: Arc<CountertermPlan>,
    /// The triangles in the data vector.
    triangles: Vec<[f64; 3]>,
    /// Their indices among the planned ones.
    fitted: Vec<usize>,
    ells: Vec<usize>,
    description: String,
}

impl PlannedLoop {
    /// Reads the tensors of `block` from its cache and plans the counterterms.
    ///
    /// # Errors
    /// [`Error::InvalidChoice`] for multipoles that are not an increasing subset of 0, 2, 4, or tensors not
    /// cached (saying how to build them); as the counterterm plan.
    fn new(block: &LoopBispectrumBlock) -> Result<Self> {
        super::block::ell_indices(&block.ells)?;
        let set = &block.triangles;
        let (side, rule) = (block.side, &block.rule);
        super::loop_tensors::check_triangles(set.triangles(), side, rule)?;
        let store = match &block.cache_dir {
            Some(dir) => TableStore::new(dir),
            None => TableStore::from_env(),
        };
        let tensors = if set.width().is_some() {
            let key = (set, side, rule, &correction_rules(rule));
            store
                .cached::<MultipoleBinBasis>(key, &Silent)
                .map(Tensors::Bins)
        } else {
            store
                .cached::<MultipoleLoopBasis>((set.triangles(), side, rule), &Silent)
                .map(Tensors::Points)
        };
        let what = if set.width().is_some() {
            "bins"
        } else {
            "triangles"
        };
        let tensors = tensors.ok_or_else(|| Error::InvalidChoice {
            what: format!(
                "the one-loop bispectrum block of {} {what} on the loop rule {} x {} x {} (q in [{}, {}] \
                 h/Mpc)",
                set.len(),
                rule.radial,
                rule.mu,
                rule.phi,
                rule.q_min,
                rule.q_max
            ),
            reason: format!(
                "its multipole tensors are not cached in {}: build them once (~190 s per {} and core at \
                 the default rule) with `pt-spectra bispectrum --loop 1 --multipoles --two-loop basis \
                 --triangles FILE{}` or Python's pt.OneLoopMultipolePlan, with the same cache directory",
                store
                    .dir()
                    .map_or("(no cache directory)".into(), |d| d.display().to_string()),
                &what[..what.len() - 1],
                set.width()
                    .map_or(String::new(), |w| format!(" --bin-width {w}"))
            ),
        })?;
        Self::with_tensors(tensors, block)
    }

    /// The block of `block`'s settings with the loops' `tensors` (of its triangles, side and rule).
    ///
    /// # Errors
    /// As [`Self::new`] but for the cache.
    fn with_tensors(tensors: Tensors, block: &LoopBispectrumBlock) -> Result<Self> {
        let ells = super::block::ell_indices(&block.ells)?;
        let set = &block.triangles;
        let (side, rule) = (block.side, &block.rule);
        let fitted = match &block.fitted {
            None => (0..set.len()).collect(),
            Some(f) => {
                if f.is_empty() || f.windows(2).any(|w| w[0] >= w[1]) || f[f.len() - 1] >= set.len()
                {
                    return Err(Error::InvalidChoice {
                        what: format!("the fitted triangles {f:?} of a one-loop bispectrum block"),
                        reason: format!("give increasing indices below {}", set.len()),
                    });
                }
                f.clone()
            }
        };
        let what = if set.width().is_some() {
            "bins"
        } else {
            "triangles"
        };
        let description = format!(
            "one-loop bispectrum: B_l for l in {:?} of {} {what}{} (of {} planned; Legendre side {:?}), one-loop galaxy \
             multipoles from tensors on the loop rule {} x {} x {} (q in [{}, {}] h/Mpc), the redshift-space \
             counterterm and stochastic shapes exact; b1, b2, bs shared (velocileptors' map to the \
             fourth-order basis), own: {}; AP: the isotropic dilation (apar aperp^2)^(1/3) exact on every \
             term (the loops and counterterms of the dilated spectrum), the anisotropic rest on the tree \
             level only, no FoG beyond ct_fog",
            block.ells,
            fitted.len(),
            set.width()
                .map_or(String::new(), |w| format!(" of width {w} h/Mpc")),
            set.len(),
            side,
            rule.radial,
            rule.mu,
            rule.phi,
            rule.q_min,
            rule.q_max,
            LOOP_NAMES.join(", ")
        );
        Ok(Self {
            tensors,
            tree: BispectrumPlan::new(set.clone(), side, PlanRules::default())?,
            counterterms: Arc::new(CountertermPlan::new(set, side)?),
            triangles: fitted.iter().map(|&i| set.triangles()[i]).collect(),
            fitted,
            ells,
            description,
        })
    }
}

impl Block for PlannedLoop {
    fn kind(&self) -> &'static Kind {
        &KIND
    }

    /// Multipoles × triangles.
    fn len(&self) -> usize {
        self.ells.len() * self.triangles.len()
    }

    /// Entry `j` (multipole, then triangle).
    fn entry(&self, j: usize) -> String {
        super::block::entry_words("one-loop ", &self.ells, &self.triangles, j)
    }

    fn describe(&self) -> String {
        self.description.clone()
    }

    /// The IR resummation's inputs of `spectrum` (the default split and q_min; `None` without), and room for
    /// its own projection residual, made when a distortion first needs it.
    fn prepare(&self, spectrum: &LinearSpectrum, ir: bool) -> Result<Prepared> {
        let inputs: Option<IrInputs> = if ir {
            Some(IrInputs::split(
                spectrum,
                &WiggleSplit::new()?,
                crate::precision::Precision::default().q_min,
            )?)
        } else {
            None
        };
        Ok(Arc::new(PreparedLoop {
            ir: inputs,
            own_residual: OnceLock::new(),
        }))
    }

    /// The loops per bias monomial from the tensors and the counterterm shapes per bias monomial.
    ///
    /// # Errors
    /// [`Error::InvalidChoice`] for a spectrum the tensors do not represent; f outside [0, 2], a distortion
    /// that is not finite and > 0 (as the tree-level plan's).
    fn terms(
        &self,
        spectrum: &LinearSpectrum,
        prepared: &Prepared,
        f: f64,
        (q_par, q_perp): (f64, f64),
    ) -> Result<Box<dyn Terms>> {
        let prepared = prepared
            .downcast_ref::<PreparedLoop>()
            .ok_or_else(|| foreign(&KIND))?;
        let ir = prepared.ir.as_ref();
        // the isotropic part of the distortion, exact on every term: the sides k/α_iso seen as the sides k
        // of P(k/α_iso) (module docs)
        let alpha = (q_par * q_perp * q_perp).cbrt();
        let dilated = if q_par == 1.0 && q_perp == 1.0 {
            None
        } else {
            let s = 1.0 / alpha;
            Some((
                spectrum.dilated(s)?,
                ir.map(|ir| ir.dilated(s)).transpose()?,
            ))
        };
        let (at, ir_at) = match &dilated {
            Some((p, ir)) => (p, ir.as_ref()),
            None => (spectrum, ir),
        };
        let (loops, residual) = match &self.tensors {
            Tensors::Points(t) => {
                let (m, p) = t.evaluate_projected(at, f, ir_at)?;
                (Loops::Points(m), p.residual)
            }
            Tensors::Bins(t) => {
                let (m, p) = t.evaluate_projected(at, f, ir_at)?;
                (Loops::Bins(m), p.residual)
            }
        };
        // the cosmology's own spectrum represented, as at α = 1 (when dilated, its projection alone,
        // made once per prepared spectrum: a template fit varies f and α on one spectrum)
        let own = match (&dilated, prepared.own_residual.get()) {
            (None, _) => residual,
            (Some(_), Some(&r)) => r,
            (Some(_), None) => {
                let main = match &self.tensors {
                    Tensors::Points(t) => t.as_ref(),
                    Tensors::Bins(t) => t.effective(),
                };
                let r = match ir {
                    Some(ir) => {
                        main.project(&super::ir_legs::leading_order_spectrum(spectrum, ir)?)
                    }
                    None => main.project(spectrum),
                }
                .1
                .residual;
                // set by another thread in between: the same number
                let _ = prepared.own_residual.set(r);
                r
            }
        };
        if let s @ BispectrumLoopSource::Fallback { .. } = tensor_source(own, ir.is_some()) {
            return Err(Error::InvalidChoice {
                what: "the linear spectrum of the one-loop bispectrum block".into(),
                reason: format!(
                    "{}; the block does not fall back to the direct integrals (~30 s per triangle): \
                     compute this spectrum's table with `pt-spectra bispectrum --loop 1 --multipoles \
                     --two-loop direct`",
                    s.describe()
                ),
            });
        }
        if dilated.is_some() && residual > DILATED_MAX_RESIDUAL {
            return Err(Error::InvalidChoice {
                what: format!(
                    "the linear spectrum of the one-loop bispectrum block at k/{alpha} (AP's isotropic \
                     dilation)"
                ),
                reason: format!(
                    "its projection on the tensors' templates leaves a residual of {residual:.1e}, above \
                     {DILATED_MAX_RESIDUAL:.0e}: the distortion is too large for the tensors"
                ),
            });
        }
        // the anisotropic rest on the tree level: B_tree(α∥, α⊥) − B_tree(α_iso, α_iso)
        let anisotropic = if q_par == q_perp {
            None
        } else {
            let tree = |q_par: f64, q_perp: f64| {
                let settings = Settings {
                    f,
                    q_par,
                    q_perp,
                    fog: Fog::None,
                    ir: ir.is_some(),
                };
                match ir {
                    Some(ir) => self.tree.terms_with_ir(spectrum, &settings, ir),
                    None => self.tree.terms(spectrum, &settings),
                }
            };
            Some((tree(q_par, q_perp)?, tree(alpha, alpha)?))
        };
        Ok(Box::new(LoopTerms {
            loops,
            counterterms: self.counterterms.evaluate(at, f)?,
            ells: self.ells.clone(),
            fitted: self.fitted.clone(),
            alpha: if dilated.is_some() { alpha } else { 1.0 },
            anisotropic,
        }))
    }

    fn gaussian_variances(&self, _: &Survey) -> Result<Vec<f64>> {
        Err(Error::InvalidChoice {
            what: "the Gaussian covariance of the one-loop bispectrum block".into(),
            reason: "not implemented: a forecast holds the tree-level bispectrum block".into(),
        })
    }
}

/// What the block prepares of a spectrum: its IR inputs (`None` without IR), and its own projection
/// residual on the templates once a distortion needs it (the loops then contract the dilated spectrum).
struct PreparedLoop {
    ir: Option<IrInputs>,
    own_residual: OnceLock<f64>,
}

/// The loops per bias monomial at one (spectrum, f).
enum Loops {
    Points(Vec<GalaxyLoopMultipoles>),
    Bins(BinnedLoopMultipoles),
}

/// The block's terms at one (spectrum, f, distortion).
struct LoopTerms {
    /// The loops and counterterms of P(k/α_iso).
    loops: Loops,
    counterterms: CountertermTerms,
    ells: Vec<usize>,
    fitted: Vec<usize>,
    /// α_iso = (α∥α⊥²)^{1/3} (1: none).
    alpha: f64,
    /// The tree level at (α∥, α⊥) and at (α_iso, α_iso), if α∥ ≠ α⊥.
    anisotropic: Option<(BispectrumTerms, BispectrumTerms)>,
}

/// The fourth-order bias of the shared b1, b2, bs (velocileptors') and the own [`LOOP_BIASES`].
pub fn loop_bias(shared: Shared, own: &[f64]) -> LoopBias {
    let mut bias = LoopBias::from_class_pt(
        shared.b1,
        shared.b2 + 4.0 / 3.0 * shared.bs,
        shared.bs,
        own[0],
    );
    bias.b3 = own[1];
    bias.g2x = own[2];
    bias.g3 = own[3];
    bias.g21x = own[4];
    bias
}

impl Terms for LoopTerms {
    /// The entries (multipole, then triangle) at b1, b2, bs and [`LOOP_NAMES`].
    fn values(&self, shared: Shared, own: &[f64]) -> Result<Vec<f64>> {
        if own.len() != LOOP_NAMES.len() {
            return Err(Error::InvalidChoice {
                what: format!("{} own one-loop bispectrum parameters", own.len()),
                reason: format!("they are {}", LOOP_NAMES.join(", ")),
            });
        }
        let bias = loop_bias(shared, own);
        let rows: Vec<[OneLoopGalaxy; 3]> = match &self.loops {
            Loops::Points(m) => m.iter().map(|m| m.evaluate(&bias)).collect::<Result<_>>()?,
            Loops::Bins(b) => b.evaluate(&bias)?,
        };
        let shapes = self.counterterms.at(&bias);
        let ct: &[f64; N_REDSHIFT_CT] =
            own[LOOP_BIASES.len()..].try_into().expect("length checked");
        // the tree's anisotropic change, per triangle and ℓ (none: zero)
        let change: Vec<[f64; 3]> = match &self.anisotropic {
            None => vec![[0.0; 3]; rows.len()],
            Some((at, iso)) => {
                let b = BispectrumParams {
                    b1: shared.b1,
                    b2: shared.b2,
                    bs: shared.bs,
                    c1: 0.0,
                    b_shot: 0.0,
                    p_shot: 0.0,
                    a_shot: 0.0,
                    n_bar: f64::INFINITY,
                };
                let (at, iso) = (at.multipoles(&b)?, iso.multipoles(&b)?);
                at.iter()
                    .zip(&iso)
                    .map(|(a, o)| std::array::from_fn(|l| a[l].value - o[l].value))
                    .collect()
            }
        };
        // the isotropic dilation s = 1/α_iso: the volume 1/α_iso⁶, s³ on the loops, s^d on a shape with k^d
        let s = 1.0 / self.alpha;
        let volume = s.powi(6);
        let ct: Vec<f64> = ct
            .iter()
            .zip(REDSHIFT_COUNTERTERM_K_POWERS)
            .map(|(c, d)| c * s.powi(d))
            .collect();
        Ok(self
            .ells
            .iter()
            .flat_map(|&l| {
                let (rows, shapes, change, ct) = (&rows, &shapes, &change, &ct);
                self.fitted.iter().map(move |&i| {
                    let (row, shape) = (&rows[i], &shapes[i]);
                    let ct: f64 = ct.iter().zip(&shape[l]).map(|(c, s)| c * s).sum();
                    let tree = row[l].tree.value;
                    let loops = row[l].total().value - tree;
                    volume * (tree + s.powi(3) * loops + ct) + change[i][l]
                })
            })
            .collect())
    }
}

#[cfg(test)]
mod tests;
