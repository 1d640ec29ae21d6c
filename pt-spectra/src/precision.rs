//! Every accuracy knob of the loop integrals in one place, with presets.
//!
//! [`Precision::default`] reaches ≲ 3e-6 relative on the 1-loop terms for 1e-3 ≤ k ≤ 1 h/Mpc on the
//! CAMB spectra, with error estimates ≲ 4e-5 (see the tests and the README); [`Precision::fast`] is about
//! twice as fast at ≲ 3e-5; [`Precision::reference`] doubles every resolution and is what convergence
//! tests compare with. Presets override the default only where they differ. The struct is `#[non_exhaustive]`: start from a preset and
//! change fields, e.g.
//!
//! ```
//! use pt_spectra::precision::Precision;
//! let mut p = Precision::default();
//! p.q_max = 100.0;
//! assert!(p.validate().is_ok());
//! ```

use crate::error::{Error, Result};

/// Accuracy settings of the loop integrals. Wavenumbers in h/Mpc.
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub struct Precision {
    /// The preset these settings started from (`fast`, `default`, `reference`); headers print
    /// [`label`](Precision::label), which also says which of its fields were changed.
    preset: &'static str,
    /// Lower limit of every loop integral over q [h/Mpc]; P = 0 below. Default 1e-5, as FAST-PT's
    /// `low_extrap = −5` with which the reference tables were made; below the linear table the
    /// spectrum's power-law extrapolation is used.
    pub q_min: f64,
    /// Upper limit of every loop integral over q [h/Mpc]; P = 0 above. Default 1e3, as FAST-PT's
    /// `high_extrap = 3`. The tails beyond the CAMB tables (q < 1e-4 and q > 50 h/Mpc) change σ_v² and
    /// P13 by ~5e-5 and P22 at k = 0.01 h/Mpc by ~2e-4, so do not cut them unless the spectrum is cut.
    pub q_max: f64,
    /// Largest step Δln q of the lattice on which the linear spectrum is sampled and interpolated (cubic
    /// Lagrange in ln q). Default 0.01 (the CAMB tables have 0.011).
    pub lattice_step: f64,
    /// Gauss–Legendre nodes per lattice cell when building the P13 and σ_v² weights (the integrand is a
    /// cubic times a smooth kernel). Default 4.
    pub p13_cell_order: usize,
    /// Gauss–Legendre nodes per panel of the P22 integral, outer (ln q) and inner (p). Default 6.
    pub p22_order: usize,
    /// Gauss–Legendre nodes of inner P22 ranges narrower than
    /// [`p22_narrow_width`](Self::p22_narrow_width) in ln p (q ≪ k or q ≫ k, where the integrand is
    /// nearly polynomial). Default 4.
    pub p22_narrow_order: usize,
    /// See [`p22_narrow_order`](Self::p22_narrow_order). Default 0.05.
    pub p22_narrow_width: f64,
    /// Largest P22 panel width in ln q for q ~ k (outer) and in ln p (inner). Default 0.3.
    pub p22_ln_width: f64,
    /// Growth of the outer panel width away from q ~ k: the width in ln q is
    /// `p22_ln_width · max(1, p22_tail_growth · |ln(q/k)|)`, since the kernel is a smooth power law in
    /// the tails. Default 0.3; 0 keeps the width constant.
    pub p22_tail_growth: f64,
    /// Largest P22 panel width in q and p [h/Mpc] below [`p22_band_end`](Self::p22_band_end), which
    /// resolves the BAO wiggles (period 2π/r_s ≈ 0.06 h/Mpc). Default 0.05.
    pub p22_linear_width: f64,
    /// Upper end of the band where [`p22_linear_width`](Self::p22_linear_width) applies [h/Mpc]; the BAO
    /// are Silk-damped beyond it. Default 1.
    pub p22_band_end: f64,
    /// Relative floor of the P22 error estimates. The Gauss–Legendre rules converge erratically below
    /// ~1e-6 relative on tabulated spectra (a C² spline through a table with percent-level BAO wiggles
    /// and round-off in its last digits, power-law joins at the table ends), so the order-lowering
    /// estimate can fall below the actual error there; the floor covers that. Default 3e-6, from the
    /// convergence study in the tests (default against reference settings on the CAMB tables).
    pub p22_error_floor: f64,
    /// Sobol points per random shift of the 2-loop mode-coupling integral at k = 0.16 h/Mpc (P24 +
    /// P33irr and its infrared-safe combination, see [`crate::loops::two_loop`]; scaled ∝ k^3.5 between
    /// ½ and 32 times; each point is evaluated at its four images q_i → ±q_i). Default 2^14; the error
    /// falls as points^−0.6 to points^−1.
    pub two_loop_points: usize,
    /// Random shifts of the 2-loop integral (its error is their standard error). Default 8.
    pub two_loop_replicas: usize,
    /// Target relative error of the 2-loop SPT correction 2P15 + 2P24 + P33 of each pair and k: where
    /// the error estimate after [`two_loop_points`](Self::two_loop_points) exceeds it, points are added
    /// (up to [`REFINE_LIMIT`](crate::loops::REFINE_LIMIT) times as many) until it does not. Default
    /// 1e-3; 0 keeps the points fixed (the `fast` and `reference` presets).
    pub two_loop_tolerance: f64,
    /// Seed of the 2-loop integral's random shifts; another seed gives an independent estimate.
    /// Default 2.
    pub two_loop_seed: u64,
    /// How the 2-loop terms (P15 and the 2-loop correction) of a spectrum are computed: from basis
    /// tensors or by direct integration ([`TwoLoopMethod`]). Default [`TwoLoopMethod::Auto`].
    pub two_loop: TwoLoopMethod,
    /// The most memory \[bytes\] a plan may take: a plan whose estimate ([`crate::memory`]) exceeds it
    /// is refused before it allocates. Default `None`: half of the machine's memory.
    pub max_memory: Option<f64>,
}

/// How the plans compute the loop terms of a spectrum: the 2-loop terms of a
/// [`RealPlan`](crate::real::RealPlan), and the 1-loop, TNS and galaxy-model terms of `RealPlan`,
/// [`RsdPlan`](crate::rsd::RsdPlan) and [`EptPlan`](crate::rsd::ept::EptPlan) (their tensors take
/// seconds to build).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum TwoLoopMethod {
    /// From the basis tensors ([`crate::loops::basis`]) if they are already cached for the k grid and
    /// these settings, else [`Direct`](Self::Direct): a one-off run never waits for a tensor build.
    #[default]
    Auto,
    /// From the basis tensors, built and cached on first use for the k grid (minutes; then ~ms per
    /// spectrum): for fits and chains over cosmologies. A spectrum that the basis does not represent
    /// well enough is computed directly, with a warning.
    Basis,
    /// Direct integration for every spectrum (seconds for 40 k).
    Direct,
}

impl TwoLoopMethod {
    /// The names accepted by [`FromStr`](std::str::FromStr).
    pub const NAMES: &'static str = "auto, basis, direct";

    /// The method's name.
    pub fn name(self) -> &'static str {
        match self {
            Self::Auto => "auto",
            Self::Basis => "basis",
            Self::Direct => "direct",
        }
    }
}

impl std::fmt::Display for TwoLoopMethod {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

impl std::str::FromStr for TwoLoopMethod {
    type Err = Error;
    fn from_str(s: &str) -> Result<Self> {
        match s {
            "auto" => Ok(Self::Auto),
            "basis" => Ok(Self::Basis),
            "direct" => Ok(Self::Direct),
            _ => Err(Error::UnknownName {
                what: "2-loop method",
                name: s.to_string(),
                available: Self::NAMES,
            }),
        }
    }
}

/// The range [h/Mpc] in which [`Precision::q_min`] and [`Precision::q_max`] must lie.
pub const Q_LIMITS: (f64, f64) = (1e-8, 1e6);

impl Default for Precision {
    fn default() -> Self {
        Self {
            preset: "default",
            q_min: 1e-5,
            q_max: 1e3,
            lattice_step: 0.01,
            p13_cell_order: 4,
            p22_order: 6,
            p22_narrow_order: 4,
            p22_narrow_width: 0.05,
            p22_ln_width: 0.3,
            p22_tail_growth: 0.3,
            p22_linear_width: 0.05,
            p22_band_end: 1.0,
            p22_error_floor: 3e-6,
            two_loop_points: 1 << 14,
            two_loop_replicas: 8,
            two_loop_tolerance: 1e-3,
            two_loop_seed: 2,
            two_loop: TwoLoopMethod::Auto,
            max_memory: None,
        }
    }
}

/// The fields of a [`Precision`] that shape cached tensors, in the two groups the tensors' cache keys
/// take ([`Precision::one_loop_key`], [`Precision::two_loop_key`]).
struct TensorFields {
    one_loop: [f64; 12],
    two_loop: [f64; 6],
}

impl Precision {
    /// Every field placed in a group of the cache keys, or named as not shaping any tensor. The
    /// destructuring names every field: a field added to [`Precision`] does not compile until it is
    /// placed here, so no cache key can miss it and reuse stale tensors.
    fn tensor_fields(&self) -> TensorFields {
        let Self {
            // not tensors' settings: the label, how the terms are computed (basis or direct), the
            // direct 2-loop integral's adaptive target (the 2-loop tensors use the fixed points),
            // the memory limit
            preset: _,
            two_loop_tolerance: _,
            two_loop: _,
            max_memory: _,
            q_min,
            q_max,
            lattice_step,
            p13_cell_order,
            p22_order,
            p22_narrow_order,
            p22_narrow_width,
            p22_ln_width,
            p22_tail_growth,
            p22_linear_width,
            p22_band_end,
            p22_error_floor,
            two_loop_points,
            two_loop_replicas,
            two_loop_seed,
        } = *self;
        TensorFields {
            one_loop: [
                q_min,
                q_max,
                lattice_step,
                p13_cell_order as f64,
                p22_order as f64,
                p22_narrow_order as f64,
                p22_narrow_width,
                p22_ln_width,
                p22_tail_growth,
                p22_linear_width,
                p22_band_end,
                p22_error_floor,
            ],
            two_loop: [
                q_min,
                q_max,
                lattice_step,
                two_loop_points as f64,
                two_loop_replicas as f64,
                two_loop_seed as f64,
            ],
        }
    }

    /// The settings of the 1-loop integrals (q range, lattice, P13 and P22 rules), as the cache keys
    /// of tensors built from them take them: the one place that lists them.
    pub(crate) fn one_loop_key(&self) -> [f64; 12] {
        self.tensor_fields().one_loop
    }

    /// The settings of the 2-loop mode-coupling integral that its basis tensors are built with (q
    /// range, lattice, Sobol points, replicas, seed), as their cache key takes them.
    pub(crate) fn two_loop_key(&self) -> [f64; 6] {
        self.tensor_fields().two_loop
    }
}

impl Precision {
    /// About twice as fast as the default, ≲ 3e-5 relative (error estimates ≲ 2e-4): coarser lattice
    /// and wider P22 panels.
    pub fn fast() -> Self {
        Self {
            preset: "fast",
            lattice_step: 0.02,
            p13_cell_order: 3,
            p22_ln_width: 0.5,
            p22_tail_growth: 0.5,
            p22_linear_width: 0.08,
            p22_error_floor: 3e-5,
            two_loop_points: 1 << 12,
            two_loop_tolerance: 0.0,
            ..Self::default()
        }
    }

    /// Every resolution of the default doubled; for convergence checks.
    pub fn reference() -> Self {
        let d = Self::default();
        Self {
            preset: "reference",
            lattice_step: d.lattice_step / 2.0,
            p13_cell_order: 2 * d.p13_cell_order,
            p22_order: 2 * d.p22_order,
            p22_narrow_order: 2 * d.p22_narrow_order,
            p22_ln_width: d.p22_ln_width / 2.0,
            p22_tail_growth: d.p22_tail_growth / 2.0,
            p22_linear_width: d.p22_linear_width / 2.0,
            p22_band_end: 2.0 * d.p22_band_end,
            p22_error_floor: d.p22_error_floor / 10.0,
            two_loop_points: 4 * d.two_loop_points,
            two_loop_tolerance: 0.0,
            ..d
        }
    }

    /// The names of the presets.
    pub const PRESETS: [&'static str; 3] = ["fast", "default", "reference"];

    /// The preset called `name` (`fast`, `default` or `reference`, ASCII case ignored).
    ///
    /// # Errors
    /// [`Error::UnknownName`] listing the presets.
    pub fn preset(name: &str) -> Result<Self> {
        match name.trim().to_ascii_lowercase().as_str() {
            "fast" => Ok(Self::fast()),
            "default" => Ok(Self::default()),
            "reference" => Ok(Self::reference()),
            _ => Err(Error::UnknownName {
                what: "precision preset",
                name: name.to_string(),
                available: "fast, default, reference",
            }),
        }
    }

    /// The preset these settings started from (`fast`, `default` or `reference`).
    pub fn preset_name(&self) -> &'static str {
        self.preset
    }

    /// What table headers say: the preset's name, followed by ` (modified: …)` with the fields that
    /// differ from it, except those stated on their own in headers or not about accuracy (q_min, q_max,
    /// two_loop, two_loop_tolerance, max_memory).
    pub fn label(&self) -> String {
        let base = Self::preset(self.preset).unwrap_or_default();
        let changed: Vec<&str> = [
            ("lattice_step", self.lattice_step != base.lattice_step),
            ("p13_cell_order", self.p13_cell_order != base.p13_cell_order),
            ("p22_order", self.p22_order != base.p22_order),
            (
                "p22_narrow_order",
                self.p22_narrow_order != base.p22_narrow_order,
            ),
            (
                "p22_narrow_width",
                self.p22_narrow_width != base.p22_narrow_width,
            ),
            ("p22_ln_width", self.p22_ln_width != base.p22_ln_width),
            (
                "p22_tail_growth",
                self.p22_tail_growth != base.p22_tail_growth,
            ),
            (
                "p22_linear_width",
                self.p22_linear_width != base.p22_linear_width,
            ),
            ("p22_band_end", self.p22_band_end != base.p22_band_end),
            (
                "p22_error_floor",
                self.p22_error_floor != base.p22_error_floor,
            ),
            (
                "two_loop_points",
                self.two_loop_points != base.two_loop_points,
            ),
            (
                "two_loop_replicas",
                self.two_loop_replicas != base.two_loop_replicas,
            ),
            ("two_loop_seed", self.two_loop_seed != base.two_loop_seed),
        ]
        .into_iter()
        .filter_map(|(name, differs)| differs.then_some(name))
        .collect();
        if changed.is_empty() {
            self.preset.to_string()
        } else {
            format!("{} (modified: {})", self.preset, changed.join(", "))
        }
    }

    /// These settings with the loop integrals over q ∈ [`q_min`, `q_max`] h/Mpc.
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] unless 0 < q_min < q_max < ∞ with room for the lattice.
    pub fn with_q_range(mut self, q_min: f64, q_max: f64) -> Result<Self> {
        (self.q_min, self.q_max) = (q_min, q_max);
        self.validate()?;
        Ok(self)
    }

    /// Checks the settings.
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] unless 0 < q_min < q_max < ∞, both in [`Q_LIMITS`], every width and
    /// step is finite and positive, the lattice has at least 8 points, and every order is ≥ 1.
    pub fn validate(&self) -> Result<()> {
        let bad = |name, value: f64, reason| {
            Err(Error::InvalidParameter {
                name,
                value,
                reason,
            })
        };
        let positive = "must be finite and positive";
        for (name, v) in [
            ("q_min [h/Mpc]", self.q_min),
            ("q_max [h/Mpc]", self.q_max),
            ("lattice_step", self.lattice_step),
            ("p22_ln_width", self.p22_ln_width),
            ("p22_narrow_width", self.p22_narrow_width),
            ("p22_linear_width [h/Mpc]", self.p22_linear_width),
            ("p22_band_end [h/Mpc]", self.p22_band_end),
        ] {
            if !(v.is_finite() && v > 0.0) {
                return bad(name, v, positive);
            }
        }
        for (name, v) in [
            ("p22_tail_growth", self.p22_tail_growth),
            ("p22_error_floor", self.p22_error_floor),
            ("two_loop_tolerance", self.two_loop_tolerance),
        ] {
            if !(v.is_finite() && v >= 0.0) {
                return bad(name, v, "must be finite and non-negative");
            }
        }
        if self.q_max <= self.q_min {
            return bad("q_max [h/Mpc]", self.q_max, "must exceed q_min");
        }
        if !(Q_LIMITS.0..=Q_LIMITS.1).contains(&self.q_min) {
            return bad(
                "q_min [h/Mpc]",
                self.q_min,
                "must be in [1e-8, 1e6] h/Mpc (below 1e-8 the power of any CDM spectrum is \
                 negligible; the lattice spans the range in steps of lattice_step in ln q)",
            );
        }
        if !(Q_LIMITS.0..=Q_LIMITS.1).contains(&self.q_max) {
            return bad(
                "q_max [h/Mpc]",
                self.q_max,
                "must be in [1e-8, 1e6] h/Mpc (beyond 1e6 the loop integrands overflow or \
                 underflow in f64 for a CDM spectrum extended as a power law)",
            );
        }
        if (self.q_max / self.q_min).ln() < 8.0 * self.lattice_step {
            return bad(
                "lattice_step",
                self.lattice_step,
                "gives fewer than 8 lattice points",
            );
        }
        for (name, v) in [
            ("p13_cell_order", self.p13_cell_order),
            ("p22_order", self.p22_order),
            ("p22_narrow_order", self.p22_narrow_order),
            ("two_loop_points", self.two_loop_points),
        ] {
            if v == 0 {
                return bad(name, 0.0, "must be at least 1");
            }
        }
        if let Some(m) = self.max_memory {
            if !(m.is_finite() && m > 0.0) {
                return bad("max_memory [bytes]", m, positive);
            }
        }
        if self.two_loop_replicas < 2 {
            return bad(
                "two_loop_replicas",
                self.two_loop_replicas as f64,
                "must be at least 2 (the error is their spread)",
            );
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn presets_validate_and_bad_values_are_named() {
        for p in [
            Precision::default(),
            Precision::fast(),
            Precision::reference(),
        ] {
            p.validate().unwrap();
        }
        let p = Precision {
            q_max: 1e-6,
            ..Precision::default()
        };
        assert!(p.validate().unwrap_err().to_string().contains("q_max"));
        let p = Precision {
            p22_order: 0,
            ..Precision::default()
        };
        assert!(p.validate().unwrap_err().to_string().contains("p22_order"));
        for name in Precision::PRESETS {
            assert_eq!(Precision::preset(name).unwrap().preset_name(), name);
            assert_eq!(Precision::preset(name).unwrap().label(), name);
        }
        assert!(Precision::preset("best")
            .unwrap_err()
            .to_string()
            .contains("fast, default"));
        let p = Precision::fast().with_q_range(1e-4, 10.0).unwrap();
        assert_eq!((p.q_min, p.q_max, p.label().as_str()), (1e-4, 10.0, "fast"));
        let mut q = Precision::fast();
        q.lattice_step = 0.005;
        q.two_loop_replicas = 4;
        assert_eq!(
            q.label(),
            "fast (modified: lattice_step, two_loop_replicas)"
        );
        assert!(Precision::fast().with_q_range(1.0, 0.5).is_err());
        assert!(Precision::fast().with_q_range(f64::NAN, 0.5).is_err());
    }

    #[test]
    fn every_tensor_setting_changes_a_cache_key_and_the_others_do_not() {
        let base = Precision::default();
        let keys = |p: &Precision| (p.one_loop_key().to_vec(), p.two_loop_key().to_vec());
        type Change = Box<dyn Fn(&mut Precision)>;
        let changed: [(&str, Change); 15] = [
            ("q_min", Box::new(|p| p.q_min *= 2.0)),
            ("q_max", Box::new(|p| p.q_max /= 2.0)),
            ("lattice_step", Box::new(|p| p.lattice_step /= 2.0)),
            ("p13_cell_order", Box::new(|p| p.p13_cell_order += 1)),
            ("p22_order", Box::new(|p| p.p22_order += 1)),
            ("p22_narrow_order", Box::new(|p| p.p22_narrow_order += 1)),
            ("p22_narrow_width", Box::new(|p| p.p22_narrow_width *= 2.0)),
            ("p22_ln_width", Box::new(|p| p.p22_ln_width /= 2.0)),
            ("p22_tail_growth", Box::new(|p| p.p22_tail_growth /= 2.0)),
            ("p22_linear_width", Box::new(|p| p.p22_linear_width /= 2.0)),
            ("p22_band_end", Box::new(|p| p.p22_band_end *= 2.0)),
            ("p22_error_floor", Box::new(|p| p.p22_error_floor *= 2.0)),
            ("two_loop_points", Box::new(|p| p.two_loop_points *= 2)),
            ("two_loop_replicas", Box::new(|p| p.two_loop_replicas += 1)),
            ("two_loop_seed", Box::new(|p| p.two_loop_seed += 1)),
        ];
        for (name, change) in &changed {
            let mut p = base.clone();
            change(&mut p);
            assert_ne!(keys(&p), keys(&base), "{name} must be in a cache key");
        }
        // how the terms are computed, the direct integral's target and the memory limit shape no tensor
        let mut p = base.clone();
        p.preset = "mine";
        p.two_loop_tolerance = 0.0;
        p.two_loop = TwoLoopMethod::Basis;
        p.max_memory = Some(1e9);
        assert_eq!(keys(&p), keys(&base));
    }
}
