//! The galaxy bias parameters, written once: [`BiasParams`] (named fields, velocileptors'
//! convention) and the conventions of the other codes, [`BiasConvention`], with exact maps.
//!
//! Every model of this crate takes the bias in one convention, velocileptors' (Chen, Vlah &
//! White 2020; the `ept` model's own):
//!
//! ```text
//! δ_g = b1 δ + (b2/2)(δ² − ⟨δ²⟩) + bs (s² − ⟨s²⟩) + b3 O₃,
//! ```
//!
//! with s² = s_ij s_ij, s_ij = (∂_i∂_j/∇² − δ_ij/3)δ (kernel S₂ = μ₁₂² − 1/3), and b3 the
//! coefficient of the one cubic shape that survives renormalisation at one loop,
//! P_gg ⊃ b1 b3 sig3nl(k) (FAST-PT's sig3nl, [`crate::loops::bias`]; [`crate::loops::redshift`]
//! writes Z₁ b3 sig3nl in redshift space). The other conventions:
//!
//! * FAST-PT, McDonald & Roy (2009), Saito et al. (2014), Beutler et al. (2017)'s TNS model
//!   (`fastpt`: b1, b2, bs, b3nl): δ_g ⊃ (bs/2)s² and P_gg ⊃ 2 b1 b3nl sig3nl, so
//!   bs^FAST-PT = 2 bs and b3nl = b3/2; b2 as here.
//! * CLASS-PT (Ivanov et al. 2019, arXiv:1909.05277; Chudaykin et al. 2020, arXiv:2004.10607) and
//!   PyBird's EFT basis before its own reparametrisation (`classpt`: b1, b2, bG2, bGamma3):
//!   δ_g ⊃ (b2/2)δ² + b_G2 G₂ + b_Γ3 Γ₃ with G₂ = (∂_i∂_jΦ)² − (∇²Φ)² (kernel μ₁₂² − 1) and
//!   Γ₃ = G₂(Φ_g) − G₂(Φ_v). As G₂ = s² − (2/3)δ² at every order,
//!
//!   ```text
//!   bs = b_G2,   b2 = b2^CLASS-PT − (4/3) b_G2,   b3 = −15 b_G2 − 6 b_Γ3.
//!   ```
//!
//!   The last line: the cubic parts of G₂ and Γ₃ give P_gg ⊃ 2 b1 b_O 3∫K₃(k, q, −q)P(q) P(k), whose
//!   angular averages are −(15/2) and −3 times sig3nl's exactly (neither renormalises b1): the
//!   4 b1 (b_G2 + (2/5) b_Γ3) F_G2 P of CLASS-PT. The tests integrate both kernels from the
//!   generated F₂, G₂. Check: coevolution from a local Lagrangian bias, b_G2 = −(2/7)(b1 − 1),
//!   b_Γ3 = (23/42)(b1 − 1), gives b3nl = b3/2 = (b1 − 1)/2, which is Saito et al.'s
//!   b3nl = (32/315)(b1 − 1) in their σ₃² = (315/64) sig3nl/P_lin.
//!
//! The DESI DR1 "physical" basis (b1σ₈, b2σ₈², …, which needs σ₈(z) and n̄) is a fit basis of the
//! `ept` model: [`crate::rsd::ept::physical`].

use crate::error::{Error, Result};
use std::fmt;
use std::str::FromStr;

/// The bias b1, b2, bs, b3 in velocileptors' convention (module docs): what every model takes.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct BiasParams {
    /// Linear bias b1.
    pub b1: f64,
    /// Second-order local bias: (b2/2)δ².
    pub b2: f64,
    /// Tidal bias: bs s².
    pub bs: f64,
    /// Cubic bias: b1 b3 sig3nl in P_gg (twice FAST-PT's b3nl).
    pub b3: f64,
}

impl BiasParams {
    /// The values in velocileptors' order (b1, b2, bs, b3).
    pub fn values(&self) -> [f64; 4] {
        [self.b1, self.b2, self.bs, self.b3]
    }

    /// The bias of `values` given in `convention` (in the order of its
    /// [`BiasConvention::names`]).
    pub fn from_convention(convention: BiasConvention, values: [f64; 4]) -> Self {
        let m = convention.jacobian();
        let [b1, b2, bs, b3] = std::array::from_fn(|i| (0..4).map(|j| m[i][j] * values[j]).sum());
        Self { b1, b2, bs, b3 }
    }

    /// The values in `convention` (the inverse of [`Self::from_convention`]).
    pub fn in_convention(&self, convention: BiasConvention) -> [f64; 4] {
        let Self { b1, b2, bs, b3 } = *self;
        match convention {
            BiasConvention::Velocileptors => [b1, b2, bs, b3],
            BiasConvention::FastPt => [b1, b2, 2.0 * bs, 0.5 * b3],
            BiasConvention::ClassPt => {
                // b_G2 = bs; b_Γ3 = −(b3 + 15 bs)/6
                [b1, b2 + 4.0 / 3.0 * bs, bs, -(b3 + 15.0 * bs) / 6.0]
            }
        }
    }

    /// Checks that every value is finite.
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] naming the first value that is not.
    pub fn check_finite(&self) -> Result<()> {
        for (name, value) in BiasConvention::Velocileptors
            .names()
            .iter()
            .zip(self.values())
        {
            if !value.is_finite() {
                return Err(Error::InvalidParameter {
                    name,
                    value,
                    reason: "a bias parameter must be finite",
                });
            }
        }
        Ok(())
    }

    /// One header line: the values in velocileptors' convention and, if `given` is another, as given.
    pub fn describe(&self, given: BiasConvention) -> String {
        self.line(given, 0)
    }

    /// [`Self::describe`] without b1 (the nonlinear bias of a model whose b1 is given apart).
    pub fn describe_nonlinear(&self, given: BiasConvention) -> String {
        self.line(given, 1)
    }

    fn line(&self, given: BiasConvention, from: usize) -> String {
        let list = |c: BiasConvention| {
            c.names()
                .iter()
                .zip(self.in_convention(c))
                .skip(from)
                .map(|(n, v)| format!("{n} = {}", tidy(v)))
                .collect::<Vec<_>>()
                .join(", ")
        };
        let ours = list(BiasConvention::Velocileptors);
        let what = "bias (velocileptors' convention, as every model takes it: (b2/2)d^2 + bs s^2 + b3 O3, b3 = 2 b3nl)";
        if given == BiasConvention::Velocileptors {
            format!("{what}: {ours}")
        } else {
            format!(
                "{what}: {ours}; given in {}'s: {}",
                given.label(),
                list(given)
            )
        }
    }
}

/// The warning for a model whose bs and b3 were FAST-PT's before they meant one thing for every model
/// (`real`, `scoccimarro`, `tns`), given without a convention; `options` is how the face spells bs
/// and b3 (`--bs and --b3`, `bs and b3`), `fastpt` that convention (`--bias-convention fastpt`,
/// `bias_convention='fastpt'`).
pub fn implicit_convention_warning(model: &str, options: &str, fastpt: &str) -> String {
    format!(
        "{options} of {model} are velocileptors' bs (bs s^2) and b3 (b1 b3 sig3nl), as for every \
         model; FAST-PT's bs is twice this bs and its b3nl half this b3: give {fastpt} to write \
         FAST-PT's values (the header states both)"
    )
}

/// A convention of the bias parameters (module docs).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
pub enum BiasConvention {
    /// velocileptors' (b1, b2, bs, b3): this crate's own.
    #[default]
    Velocileptors,
    /// FAST-PT's (b1, b2, bs, b3nl): (bs/2)s², 2 b1 b3nl sig3nl.
    FastPt,
    /// CLASS-PT's (b1, b2, bG2, bGamma3).
    ClassPt,
}

impl BiasConvention {
    /// Every convention, in the order of the error messages and `--help`.
    pub const ALL: [Self; 3] = [Self::Velocileptors, Self::FastPt, Self::ClassPt];

    /// The name on the command line and in Python.
    pub fn name(self) -> &'static str {
        match self {
            Self::Velocileptors => "velocileptors",
            Self::FastPt => "fastpt",
            Self::ClassPt => "classpt",
        }
    }

    /// The code's own spelling, for headers.
    pub fn label(self) -> &'static str {
        match self {
            Self::Velocileptors => "velocileptors",
            Self::FastPt => "FAST-PT",
            Self::ClassPt => "CLASS-PT",
        }
    }

    /// The names of the four parameters in this convention.
    pub fn names(self) -> [&'static str; 4] {
        match self {
            Self::Velocileptors => ["b1", "b2", "bs", "b3"],
            Self::FastPt => ["b1", "b2", "bs", "b3nl"],
            Self::ClassPt => ["b1", "b2", "bG2", "bGamma3"],
        }
    }

    /// ∂(b1, b2, bs, b3)/∂(this convention's values): the maps are linear, so this is the map.
    pub fn jacobian(self) -> [[f64; 4]; 4] {
        match self {
            Self::Velocileptors => identity(),
            Self::FastPt => {
                let mut m = identity();
                m[2][2] = 0.5;
                m[3][3] = 2.0;
                m
            }
            Self::ClassPt => [
                [1.0, 0.0, 0.0, 0.0],
                [0.0, 1.0, -4.0 / 3.0, 0.0],
                [0.0, 0.0, 1.0, 0.0],
                [0.0, 0.0, -15.0, -6.0],
            ],
        }
    }

    /// The choices as `--help` and the error messages list them.
    pub fn choices() -> String {
        Self::ALL.map(Self::name).join(", ")
    }
}

/// `v` to 12 decimals without trailing zeros: the maps' rounding (0.30000000000000004) left out of
/// headers.
fn tidy(v: f64) -> String {
    let s = format!("{v:.12}");
    let s = s.trim_end_matches('0').trim_end_matches('.');
    match s {
        "-0" | "" => "0".into(),
        _ => s.into(),
    }
}

fn identity() -> [[f64; 4]; 4] {
    std::array::from_fn(|i| std::array::from_fn(|j| f64::from(u8::from(i == j))))
}

impl fmt::Display for BiasConvention {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

impl FromStr for BiasConvention {
    type Err = Error;

    /// `velocileptors`, `fastpt` or `classpt` (ASCII case and `-`, `_` ignored).
    ///
    /// # Errors
    /// [`Error::InvalidChoice`] listing the choices.
    fn from_str(s: &str) -> Result<Self> {
        let key: String = s
            .trim()
            .chars()
            .filter(|c| !matches!(c, '-' | '_'))
            .collect::<String>()
            .to_ascii_lowercase();
        Self::ALL
            .into_iter()
            .find(|c| c.name() == key)
            .ok_or_else(|| Error::InvalidChoice {
                what: format!("bias convention `{s}`"),
                reason: format!("the conventions are {}", Self::choices()),
            })
    }
}

#[cfg(test)]
mod tests;
