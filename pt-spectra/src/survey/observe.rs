//! From model multipoles to what a survey or a simulation measures: the window and the k bins of
//! this module chained in the order a measurement applies them (model → window → bins).
//!
//! The stages are planned backwards: the bins fix the output k (their effective k) and the k at which
//! they need the windowed multipoles, the window fixes the k at which it needs the model. Combinations:
//! a Q_ℓ window with k² bin averages or none; a window matrix alone (it maps onto its own output k,
//! binning included); box modes alone (a periodic box has no window).

use super::{
    BinAverage, BoxModes, BoxModesPlan, Mixing, WindowFormat, WindowMatrix, WindowMultipoles,
    WindowPlan, XiPlan,
};
use crate::error::{Error, Result};
use crate::estimate::Estimate;
use crate::linear::LogGrid;
use std::path::Path;

/// A window read from a file: Q_ℓ(s) multipoles or a matrix.
#[derive(Debug, Clone)]
pub enum Window {
    /// Configuration-space multipoles Q_ℓ(s) and how they mix the model's.
    Multipoles(WindowMultipoles, Mixing),
    /// A window matrix (observed (ℓ, k_o) by theory (ℓ', k_t)).
    Matrix(WindowMatrix),
}

impl Window {
    /// Reads `path`: a `.npy` matrix (with its `.txt` sidecar) or a text matrix (its header names
    /// `ells_out`), else Q_ℓ(s) multipoles laid out as `format` declares, mixed by `mixing`.
    ///
    /// # Errors
    /// As [`WindowMatrix::from_file`] and [`WindowMultipoles::from_file`]; [`Error::InvalidChoice`] for
    /// a `format` other than [`WindowFormat::header`] given with a matrix (it declares its own layout).
    pub fn read(path: &Path, mixing: Mixing, format: &WindowFormat) -> Result<Self> {
        let is_npy = path.extension().is_some_and(|e| e == "npy");
        let text_matrix = !is_npy
            && crate::table::read_text(path)
                .map(|t| t.lines().take(40).any(|l| l.contains("ells_out")))
                .unwrap_or(false);
        if (is_npy || text_matrix) && !format.is_header() {
            return Err(Error::InvalidChoice {
                what: format!("the window format {format}"),
                reason: format!(
                    "`{}` is a window matrix, which declares its own layout (`# ells_out` …): the \
                     format is for Q_ell(s) files only",
                    path.display()
                ),
            });
        }
        if is_npy || text_matrix {
            Ok(Self::Matrix(WindowMatrix::from_file(path)?))
        } else {
            Ok(Self::Multipoles(
                WindowMultipoles::from_file(path, format)?,
                mixing,
            ))
        }
    }
}

/// How the output is binned.
#[derive(Debug, Clone, PartialEq)]
pub enum Bins {
    /// The k²-weighted mean over each bin of these edges [h/Mpc].
    Edges(Vec<f64>),
    /// The mean over the discrete modes of a periodic box of side `side` [Mpc/h] in each bin.
    Box {
        /// The box side [Mpc/h].
        side: f64,
        /// The bin edges [h/Mpc].
        edges: Vec<f64>,
    },
}

impl Bins {
    /// The bins of `edges` [h/Mpc], of a periodic box of side `box_side` [Mpc/h] if given.
    ///
    /// # Errors
    /// [`Error::InvalidChoice`] for a box side without edges.
    pub fn of(edges: Option<Vec<f64>>, box_side: Option<f64>) -> Result<Option<Self>> {
        match (edges, box_side) {
            (None, None) => Ok(None),
            (Some(edges), None) => Ok(Some(Self::Edges(edges))),
            (Some(edges), Some(side)) => Ok(Some(Self::Box { side, edges })),
            (None, Some(_)) => Err(Error::InvalidChoice {
                what: "a periodic box (box side) without k bins".into(),
                reason: "the box modes are averaged over k bins: give their edges too".into(),
            }),
        }
    }
}

#[derive(Clone)]
enum WindowStage {
    Plan(WindowPlan),
    Matrix(WindowMatrix),
}

#[derive(Clone)]
enum BinStage {
    Average(BinAverage),
    Box(BoxModesPlan),
    /// Correlation-function multipoles at s (or s bins): no window, no k bins.
    Xi(XiPlan),
}

/// The planned chain (module docs).
#[derive(Clone)]
pub struct Observation {
    ells: Vec<usize>,
    k_out: Vec<f64>,
    k_model: Vec<f64>,
    model_ells: Vec<usize>,
    window: Option<WindowStage>,
    bins: Option<BinStage>,
    description: Vec<String>,
    /// [`Self::matrix`], made on first use.
    matrix: std::sync::OnceLock<(Vec<f64>, usize)>,
}

/// Model multipoles 0, 2, …, 8: what a window or the box modes need of a model with μ⁸ terms.
const ALL_ELLS: [usize; 5] = [0, 2, 4, 6, 8];

impl Observation {
    /// The chain for output multipoles `ells` at `k` [h/Mpc] (used when there are no bins), with the
    /// window and the bins given.
    ///
    /// # Errors
    /// [`Error::InvalidChoice`] for multipoles that are not distinct even ℓ ≤ 8, a window matrix with
    /// bins or box modes with a window; as the plans of [`crate::survey`].
    pub fn new(
        ells: &[usize],
        k: &[f64],
        window: Option<Window>,
        bins: Option<Bins>,
    ) -> Result<Self> {
        // every stage checks its multipoles, but without a window or bins there is none: ℓ = 3 or
        // [0, 0] then passed the model through under a wrong name (issue 45)
        super::check_ells("observed multipoles", ells)?;
        let refuse = |reason: &str| Error::InvalidChoice {
            what: "the window and bins".into(),
            reason: reason.into(),
        };
        let mut description = Vec::new();
        // Bins: the output k and where they need their input.
        let (k_out, bin_input, bins) = match bins {
            None => (k.to_vec(), k.to_vec(), None),
            Some(Bins::Edges(edges)) => {
                let b = BinAverage::new(&edges)?;
                description.push(format!(
                    "bins: the k^2-weighted mean over {} bins of edges {:e} ... {:e} h/Mpc (k = the \
                     bins' effective k)",
                    b.len(),
                    edges[0],
                    edges[edges.len() - 1]
                ));
                (b.k_eff(), b.k_theory().to_vec(), Some(BinStage::Average(b)))
            }
            Some(Bins::Box { side, edges }) => {
                if window.is_some() {
                    return Err(refuse(
                        "box modes are those of a periodic box, which has no window",
                    ));
                }
                let modes = BoxModes::new(side, &edges, ells)?;
                let distinct = modes.distinct_k();
                let (lo, hi) = (distinct[0], distinct[distinct.len() - 1]);
                let n = ((hi / lo).log10() * 400.0).ceil() as usize + 8;
                let grid = LogGrid::new(lo * 0.98, hi * 1.02, n)?.points();
                let plan = modes.plan(&grid, ALL_ELLS.len())?;
                description.push(format!(
                    "bins: the mean over the discrete modes of a periodic box of side {side} Mpc/h in \
                     {} bins of edges {:e} ... {:e} h/Mpc (k = the mean |k| of each bin's modes; the \
                     model's P_0 ... P_8 interpolated on {n} log-spaced k)",
                    edges.len() - 1,
                    edges[0],
                    edges[edges.len() - 1]
                ));
                let k_eff = modes.k_eff().to_vec();
                return Ok(Self {
                    ells: ells.to_vec(),
                    k_out: k_eff,
                    k_model: plan.k_theory().to_vec(),
                    model_ells: ALL_ELLS.to_vec(),
                    window: None,
                    bins: Some(BinStage::Box(plan)),
                    description,
                    matrix: std::sync::OnceLock::new(),
                });
            }
        };
        let (window, k_model, model_ells, k_out) = match window {
            None => (None, bin_input, ells.to_vec(), k_out),
            Some(Window::Multipoles(w, mixing)) => {
                let plan = WindowPlan::new(ells, &bin_input, &w, mixing)?;
                description.push(format!(
                    "window: Q_l(s) multipoles {:?} of `{}` (Q0(0) = {:.6}), {:?} mixing (Wilson et al. \
                     2017), FFTLog on {} points; wide-angle terms neglected",
                    w.ells(),
                    w.origin(),
                    w.normalisation(),
                    mixing,
                    plan.fft_points()
                ));
                if let Some(warning) = w.normalisation_warning() {
                    description.push(format!("warning: {warning}"));
                }
                let k_model = plan.k_theory().to_vec();
                (
                    Some(WindowStage::Plan(plan)),
                    k_model,
                    ALL_ELLS.to_vec(),
                    k_out,
                )
            }
            Some(Window::Matrix(m)) => {
                if bins.is_some() {
                    return Err(refuse(
                        "a window matrix maps onto its own (binned) output k",
                    ));
                }
                let k_t = m
                    .k_theory(m.ells_theory()[0])
                    .ok_or_else(|| refuse("the window matrix has no theory k"))?
                    .to_vec();
                for &l in ells {
                    if m.k_out(l).is_none() {
                        return Err(refuse(&format!(
                            "the window matrix has no output multipole {l}"
                        )));
                    }
                }
                let k_o = m.k_out(ells[0]).unwrap_or_default().to_vec();
                description.push(format!(
                    "window: matrix `{}` (observed l {:?} by theory l {:?} on {} k); wide-angle terms \
                     as the matrix has them",
                    m.origin(),
                    m.ells_out(),
                    m.ells_theory(),
                    k_t.len()
                ));
                let model_ells = m.ells_theory().to_vec();
                (Some(WindowStage::Matrix(m)), k_t, model_ells, k_o)
            }
        };
        Ok(Self {
            ells: ells.to_vec(),
            k_out,
            k_model,
            model_ells,
            window,
            bins,
            description,
            matrix: std::sync::OnceLock::new(),
        })
    }

    /// The chain for correlation-function multipoles ξ_ℓ at `s` [Mpc/h], or averaged over the s bins
    /// of `s_edges` ([`XiPlan`]: no window, as a Landy–Szalay estimate divides it out). The output
    /// "k" of the other methods are then s [Mpc/h].
    ///
    /// # Errors
    /// As [`XiPlan::new`].
    pub fn xi(ells: &[usize], s: &[f64], s_edges: Option<&[f64]>) -> Result<Self> {
        let plan = XiPlan::new(ells, s, s_edges)?;
        let mut description = vec![format!(
            "correlation-function multipoles xi_l(s) = i^l int k^2 dk/(2 pi^2) P_l(k) j_l(ks) by \
             FFTLog from the model on {} k in [{:e}, {:e}] h/Mpc (tapered to 0 above 2.25 h/Mpc); no \
             window (a Landy-Szalay estimate divides it out), wide-angle terms neglected",
            plan.k_theory().len(),
            plan.k_theory()[0],
            plan.k_theory()[plan.k_theory().len() - 1]
        )];
        if let Some(e) = s_edges {
            description.push(format!(
                "bins: the s^2-weighted mean over {} s bins of edges {} ... {} Mpc/h (s = the bins' \
                 effective s)",
                e.len() - 1,
                e[0],
                e[e.len() - 1]
            ));
        }
        Ok(Self {
            ells: ells.to_vec(),
            k_out: plan.s_out().to_vec(),
            k_model: plan.k_theory().to_vec(),
            model_ells: ells.to_vec(),
            window: None,
            bins: Some(BinStage::Xi(plan)),
            description,
            matrix: std::sync::OnceLock::new(),
        })
    }

    /// Whether the output is correlation-function multipoles (at s [Mpc/h]).
    pub fn is_xi(&self) -> bool {
        matches!(self.bins, Some(BinStage::Xi(_)))
    }

    /// The output multipoles.
    pub fn ells(&self) -> &[usize] {
        &self.ells
    }

    /// The k [h/Mpc] at which the model's multipoles are needed.
    pub fn k_model(&self) -> &[f64] {
        &self.k_model
    }

    /// The model multipoles needed, in the order [`Self::apply`] takes them.
    pub fn model_ells(&self) -> &[usize] {
        &self.model_ells
    }

    /// The output k [h/Mpc] (the bins' effective k, or the window matrix's).
    pub fn k_out(&self) -> &[f64] {
        &self.k_out
    }

    /// Header lines saying what the chain does.
    pub fn description(&self) -> &[String] {
        &self.description
    }

    /// The chain as one matrix, row-major, with its number of rows (output ℓ then output k) and
    /// columns (model ℓ then model k): the chain applied to each unit model vector, so that applying
    /// it is one matrix–vector product ([`apply_matrix`]) and its derivative is the matrix itself.
    /// The chain is linear in the model but for the resampling of a one-signed multipole, whose
    /// spline is of ln|P| ([`Self::apply_values`]); a unit vector takes the linear spline, so the
    /// matrix is the chain with a spline of P (the pipeline's tests bound the difference).
    ///
    /// # Errors
    /// As [`Self::apply_values`].
    pub fn matrix(&self) -> Result<(&[f64], usize)> {
        if self.matrix.get().is_none() {
            let made = self.make_matrix()?;
            // another thread may have set it meanwhile: the same matrix
            let _ = self.matrix.set(made);
        }
        let (m, rows) = self.matrix.get().expect("set above");
        Ok((m, *rows))
    }

    /// [`Self::matrix`], made.
    fn make_matrix(&self) -> Result<(Vec<f64>, usize)> {
        let (ells, k) = (self.model_ells(), self.k_model());
        let columns = ells.len() * k.len();
        let mut unit = vec![vec![0.0; k.len()]; ells.len()];
        let mut by_column: Vec<Vec<f64>> = Vec::with_capacity(columns);
        for c in 0..columns {
            unit[c / k.len()][c % k.len()] = 1.0;
            let out = self.apply_values(&unit)?;
            unit[c / k.len()][c % k.len()] = 0.0;
            by_column.push(out.into_iter().flatten().collect());
        }
        let rows = by_column.first().map_or(0, Vec::len);
        let mut matrix = vec![0.0; rows * columns];
        for (c, col) in by_column.iter().enumerate() {
            for (r, v) in col.iter().enumerate() {
                matrix[r * columns + c] = *v;
            }
        }
        Ok((matrix, rows))
    }

    /// The values of [`Self::apply`] without the error estimates of the window and the ξ transform
    /// (the cheaper path a fit takes at every step; bins and box modes cost little either way).
    ///
    /// # Errors
    /// As [`Self::apply`].
    pub fn apply_values(&self, model: &[Vec<f64>]) -> Result<Vec<Vec<f64>>> {
        let values = |rows: Vec<Vec<Estimate>>| -> Vec<Vec<f64>> {
            rows.into_iter()
                .map(|r| r.into_iter().map(|e| e.value).collect())
                .collect()
        };
        let windowed = match (&self.window, &self.bins) {
            (_, Some(BinStage::Xi(plan))) => return plan.apply_values(model),
            (_, Some(BinStage::Box(_))) | (Some(WindowStage::Matrix(_)), _) => {
                return Ok(values(self.apply(model)?))
            }
            (Some(WindowStage::Plan(plan)), _) => plan.apply_values(model)?,
            (None, _) => self.select(model),
        };
        match &self.bins {
            Some(BinStage::Average(b)) => windowed
                .iter()
                .map(|w| Ok(b.apply(w)?.into_iter().map(|e| e.value).collect()))
                .collect(),
            _ => Ok(windowed),
        }
    }

    /// The model's multipoles of the output ℓ (no window).
    fn select(&self, model: &[Vec<f64>]) -> Vec<Vec<f64>> {
        self.ells
            .iter()
            .map(|l| {
                let j = self.model_ells.iter().position(|m| m == l).unwrap_or(0);
                model[j].clone()
            })
            .collect()
    }

    /// The observed multipoles (one vector per output ℓ) from the model's multipoles
    /// [`Self::model_ells`] on [`Self::k_model`].
    ///
    /// # Errors
    /// As the stages' `apply`.
    pub fn apply(&self, model: &[Vec<f64>]) -> Result<Vec<Vec<Estimate>>> {
        match &self.bins {
            Some(BinStage::Box(plan)) => return plan.apply(model),
            Some(BinStage::Xi(plan)) => return plan.apply(model),
            _ => {}
        }
        let windowed: Vec<Vec<Estimate>> = match &self.window {
            None => self
                .select(model)
                .into_iter()
                .map(|r| r.into_iter().map(Estimate::exact).collect())
                .collect(),
            Some(WindowStage::Plan(plan)) => plan.apply(model)?,
            Some(WindowStage::Matrix(m)) => {
                let all = m.apply(model)?;
                self.ells
                    .iter()
                    .map(|l| {
                        let j = m.ells_out().iter().position(|o| o == l).unwrap_or(0);
                        all[j].clone()
                    })
                    .collect()
            }
        };
        match &self.bins {
            Some(BinStage::Average(b)) => windowed.iter().map(|w| b.apply_estimates(w)).collect(),
            _ => Ok(windowed),
        }
    }
}

/// `matrix` ([`Observation::matrix`]: row-major, model ℓ's × model k columns) times the model
/// multipoles (`model[j]`: model ℓ j on the model k): the observed data vector, output ℓ then k.
pub fn apply_matrix(matrix: &[f64], model: &[Vec<f64>]) -> Vec<f64> {
    let flat: Vec<f64> = model.iter().flatten().copied().collect();
    matrix
        .chunks_exact(flat.len())
        .map(|row| crate::simd::dot(row, &flat))
        .collect()
}

#[cfg(test)]
mod spec_tests {
    use super::*;

    /// Issue 45: without a window or bins, `Observation::new(&[0, 3], ..)` and `&[0, 0]` were
    /// accepted and applied (the model passed through under ℓ = 3, or twice).
    #[test]
    fn odd_or_repeated_multipoles_are_refused_without_a_window_too() {
        let k: Vec<f64> = (1..=10).map(|i| 0.02 * f64::from(i)).collect();
        for (ells, rule) in [
            (&[0, 3][..], "ℓ = 3"),
            (&[0, 0][..], "given twice"),
            (&[0, 10][..], "ℓ = 10"),
            (&[][..], "at least one"),
        ] {
            let e = Observation::new(ells, &k, None, None)
                .err()
                .unwrap_or_else(|| panic!("{ells:?} accepted"))
                .to_string();
            assert!(e.contains("observed multipoles") && e.contains(rule), "{e}");
        }
        assert!(Observation::new(&[0, 2, 4], &k, None, None).is_ok());
    }
}
