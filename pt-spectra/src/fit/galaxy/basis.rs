//! The parameter basis of a galaxy fit: the names that `free`, `marginalise` and the priors use, and
//! the map of those slots to the model's parameters (velocileptors' convention).
//!
//! * [`FitBasis::Velocileptors`]: the model's own parameters.
//! * [`FitBasis::ClassPt`]: the bias as CLASS-PT writes it (b1, b2, bG2, bGamma3; the exact linear map
//!   of [`crate::bias`]), the counterterms and stochastic terms as velocileptors' (CLASS-PT's are
//!   defined on the multipoles, which no map of P(k, μ) reproduces exactly).
//! * [`FitBasis::Desi`]: the DESI DR1 physical basis ([`crate::rsd::ept::physical`]).

use super::LINEAR;
use crate::bias::{BiasConvention, BiasParams};
use crate::error::Result;
use crate::rsd::ept::physical::{
    check_physical_name, PhysicalBasis, PHYSICAL_LINEAR, PHYSICAL_NAMES,
};
use crate::rsd::ept::{EptParams, PARAM_NAMES};

/// The slot names of [`FitBasis::ClassPt`], slot for slot with [`PARAM_NAMES`].
pub const CLASSPT_NAMES: [&str; 12] = [
    "b1", "b2", "bG2", "bGamma3", "alpha0", "alpha2", "alpha4", "alpha6", "sn", "sn2", "sn4", "f",
];

/// The parameter basis of a fit (module docs).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub enum FitBasis {
    /// velocileptors' (the model's own).
    #[default]
    Velocileptors,
    /// CLASS-PT's bias, velocileptors' counterterms and stochastic terms.
    ClassPt,
    /// The DESI DR1 physical basis of one sample.
    Desi(PhysicalBasis),
}

impl FitBasis {
    /// The names of the model's slots in this basis.
    pub fn names(&self) -> &'static [&'static str; 12] {
        match self {
            Self::Velocileptors => &PARAM_NAMES,
            Self::ClassPt => &CLASSPT_NAMES,
            Self::Desi(_) => &PHYSICAL_NAMES,
        }
    }

    /// The parameters that enter the model linearly (marginalisable), in this basis.
    pub fn linear_names(&self) -> &'static [&'static str] {
        match self {
            Self::Velocileptors | Self::ClassPt => &LINEAR,
            Self::Desi(_) => &PHYSICAL_LINEAR,
        }
    }

    /// Whether the slots are the model's parameters (velocileptors' basis).
    pub fn is_model(&self) -> bool {
        matches!(self, Self::Velocileptors)
    }

    /// The name in headers and messages.
    pub fn label(&self) -> &'static str {
        match self {
            Self::Velocileptors => "velocileptors",
            Self::ClassPt => "CLASS-PT bias",
            Self::Desi(_) => "DESI physical",
        }
    }

    /// The model's parameters of the slot values `v`.
    pub fn to_ept(&self, v: &[f64; 12]) -> EptParams {
        match self {
            Self::Velocileptors => EptParams { values: *v },
            Self::ClassPt => {
                let mut p = EptParams { values: *v };
                p.set_bias(&BiasParams::from_convention(
                    BiasConvention::ClassPt,
                    [v[0], v[1], v[2], v[3]],
                ));
                p
            }
            Self::Desi(b) => b.to_ept(v),
        }
    }

    /// The slot values of the model's parameters `p` (the inverse of [`Self::to_ept`]; the DESI basis
    /// as [`PhysicalBasis::from_ept`]).
    pub fn from_ept(&self, p: &EptParams) -> [f64; 12] {
        match self {
            Self::Velocileptors => p.values,
            Self::ClassPt => {
                let mut v = p.values;
                v[..4].copy_from_slice(&p.bias().in_convention(BiasConvention::ClassPt));
                v
            }
            Self::Desi(b) => b.from_ept(p),
        }
    }

    /// ∂p_i/∂v_j of [`Self::to_ept`] at the slot values `v` (row: the model's parameter, column: the
    /// slot).
    pub fn jacobian(&self, v: &[f64; 12]) -> [[f64; 12]; 12] {
        let mut j = [[0.0; 12]; 12];
        match self {
            Self::Desi(b) => return b.jacobian(v),
            Self::Velocileptors | Self::ClassPt => {
                for (i, row) in j.iter_mut().enumerate() {
                    row[i] = 1.0;
                }
            }
        }
        if let Self::ClassPt = self {
            let m = BiasConvention::ClassPt.jacobian();
            for (row, m_row) in j.iter_mut().zip(m) {
                row[..4].copy_from_slice(&m_row);
            }
        }
        j
    }

    /// Checks that `name` (a slot of this basis or a block's) may be used: the DESI basis has
    /// no `alpha6p` of its own.
    ///
    /// # Errors
    /// As [`check_physical_name`].
    pub fn check_name(&self, name: &str) -> Result<()> {
        match self {
            Self::Desi(_) if crate::blocks::owner(name).is_none() => check_physical_name(name),
            _ => Ok(()),
        }
    }

    /// A hint for `name`, which is not a slot of this basis, if another basis has it.
    pub fn hint(&self, name: &str) -> &'static str {
        if self.names().contains(&name) {
            return "";
        }
        if PARAM_NAMES.contains(&name) {
            match self {
                Self::Desi(_) => " (a velocileptors name: the physical basis's names end in p)",
                _ => " (a velocileptors name: this basis names the bias as CLASS-PT does, bG2 and bGamma3)",
            }
        } else if PHYSICAL_NAMES.contains(&name) {
            " (a name of the DESI physical basis: choose that basis to use it)"
        } else if CLASSPT_NAMES.contains(&name) {
            " (a name of the CLASS-PT bias basis: choose that basis to use it)"
        } else {
            ""
        }
    }

    /// One header line stating the basis, if it is not the model's.
    pub fn describe(&self) -> Option<String> {
        match self {
            Self::Velocileptors => None,
            Self::ClassPt => Some(
                "parameter basis: CLASS-PT's bias (b1, b2, bG2, bGamma3: bs = bG2, b2 = b2^CLASS-PT - \
                 (4/3) bG2, b3 = -15 bG2 - 6 bGamma3, exact); counterterms and stochastic terms as \
                 velocileptors'"
                    .into(),
            ),
            Self::Desi(b) => Some(b.describe()),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The CLASS-PT basis maps the bias only, inverts exactly, and its Jacobian is the map.
    #[test]
    fn class_pt_basis_maps_the_bias_and_inverts() {
        let v = [
            1.9, 0.3, -0.2, 0.25, 5.0, -3.0, 2.0, 1.0, 700.0, -100.0, 30.0, 0.78,
        ];
        let b = FitBasis::ClassPt;
        let p = b.to_ept(&v);
        assert_eq!(p.values[4..], v[4..]);
        assert!((p.values[2] + 0.2).abs() < 1e-15);
        assert!((p.values[1] - (0.3 + 4.0 / 3.0 * 0.2)).abs() < 1e-14);
        assert!((p.values[3] - (3.0 - 6.0 * 0.25)).abs() < 1e-14);
        let back = b.from_ept(&p);
        for (x, y) in back.iter().zip(&v) {
            assert!((x - y).abs() < 1e-13 * y.abs().max(1.0), "{back:?}");
        }
        let jac = b.jacobian(&v);
        for j in 0..12 {
            let (mut up, mut down) = (v, v);
            up[j] += 0.5;
            down[j] -= 0.5;
            let (pu, pd) = (b.to_ept(&up).values, b.to_ept(&down).values);
            for i in 0..12 {
                assert!((jac[i][j] - (pu[i] - pd[i])).abs() < 1e-12, "{i} {j}");
            }
        }
        assert!(FitBasis::Velocileptors.hint("bG2").contains("CLASS-PT"));
        assert!(b.hint("bs").contains("bG2"));
        assert!(b.describe().unwrap().contains("-15 bG2"));
    }
}
