//! The DESI DR1 "physical" parameter basis of the `ept` model (Maus et al. 2024, arXiv:2404.07312;
//! DESI 2024 V, arXiv:2411.12021; desilike's velocileptors REPT theory): biases scaled by σ₈(z),
//! counterterms as fractions of linear theory, stochastic terms in units of 1/n̄, with the priors of
//! the DESI DR1 full-shape analysis (`crate::fit::galaxy::desi_priors`).
//!
//! With b = b1p/σ₈ (σ₈ = σ₈(z) of the linear matter spectrum at the redshift of the fit) and f:
//!
//! ```text
//! b1 = b1p/σ₈,                 b2 = b2p/σ₈² + (8/21)(b1 − 1),   bs = bsp/σ₈²,   b3 = b3p/σ₈³,
//! α₀ = b² α₀p,                 α₂ = f b (α₀p + α₂p),
//! α₄ = f (f α₂p + b α₄p),      α₆ = f² α₄p,
//! sn = sn0p/n̄,                 sn2 = sn2p f_sat σ_v²/n̄,         sn4 = sn4p f_sat σ_v⁴/n̄.
//! ```
//!
//! The counterterms are those of P_ct = (b + fμ²)(b α₀p + f α₂p μ² + f α₄p μ⁴) k² P: the α's are
//! fractional corrections to linear theory (|α| k_max² ≲ 0.5 at 50%). b1p is (1 + b₁^L)σ₈ in the
//! Lagrangian words of the papers; b2p and bsp are the Lagrangian b₂^L σ₈² and b_s^L σ₈² (the shift
//! (8/21)(b1 − 1) is the Eulerian b2 of a Lagrangian b₂^L, so that b2p = 0 is coevolution, as
//! desilike's REPT map; bs = b_s^L as there). σ_v [Mpc/h] and f_sat are the satellites' velocity
//! dispersion and fraction of the halo-model estimate of the stochastic terms (desilike's generic
//! defaults 5 Mpc/h and 0.1: [`DEFAULT_SIGMA_V`], [`DEFAULT_F_SAT`]). α₆ is not a parameter of this
//! basis (it is f²α₄p): its slot `alpha6p` must stay 0.

use super::{EptParams, PARAM_NAMES};
use crate::error::{Error, Result};

/// The names of the physical basis, slot for slot with [`PARAM_NAMES`] (`alpha6p` is not a
/// parameter: module docs).
pub const PHYSICAL_NAMES: [&str; 12] = [
    "b1p", "b2p", "bsp", "b3p", "alpha0p", "alpha2p", "alpha4p", "alpha6p", "sn0p", "sn2p", "sn4p",
    "f",
];

/// The parameters of the physical basis that enter the model linearly (marginalisable).
pub const PHYSICAL_LINEAR: [&str; 6] = ["alpha0p", "alpha2p", "alpha4p", "sn0p", "sn2p", "sn4p"];

/// desilike's generic satellite fraction of the stochastic terms.
pub const DEFAULT_F_SAT: f64 = 0.1;

/// desilike's generic satellite velocity dispersion of the stochastic terms [Mpc/h].
pub const DEFAULT_SIGMA_V: f64 = 5.0;

/// The slot of `alpha6p`.
const ALPHA6: usize = 7;

/// The physical basis of one sample: σ₈(z) of its redshift, its number density and the halo-model
/// scales of its stochastic terms.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PhysicalBasis {
    /// σ₈(z) of the linear matter spectrum at the sample's redshift.
    pub sigma8: f64,
    /// n̄ [(h/Mpc)³].
    pub n_bar: f64,
    /// The satellite fraction f_sat.
    pub f_sat: f64,
    /// The satellites' velocity dispersion σ_v [Mpc/h].
    pub sigma_v: f64,
}

impl PhysicalBasis {
    /// The basis at σ₈(z) `sigma8` and number density `n_bar` [(h/Mpc)³], with f_sat, σ_v.
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] for a value that is not finite and > 0 (f_sat ≥ 0).
    pub fn new(sigma8: f64, n_bar: f64, f_sat: f64, sigma_v: f64) -> Result<Self> {
        for (name, value) in [("sigma8_z", sigma8), ("n_bar", n_bar), ("sigma_v", sigma_v)] {
            if !(value.is_finite() && value > 0.0) {
                return Err(Error::InvalidParameter {
                    name,
                    value,
                    reason: "the physical basis needs a finite value > 0",
                });
            }
        }
        if !(f_sat.is_finite() && f_sat >= 0.0) {
            return Err(Error::InvalidParameter {
                name: "f_sat",
                value: f_sat,
                reason: "the satellite fraction must be finite and >= 0",
            });
        }
        Ok(Self {
            sigma8,
            n_bar,
            f_sat,
            sigma_v,
        })
    }

    /// The model's parameters (velocileptors' basis) of the physical values `v` (in the order of
    /// [`PHYSICAL_NAMES`]; `alpha6p` ignored: module docs).
    pub fn to_ept(&self, v: &[f64; 12]) -> EptParams {
        let s = self.sigma8;
        let f = v[11];
        let b = v[0] / s;
        let (a0, a2, a4) = (v[4], v[5], v[6]);
        let sat = self.f_sat / self.n_bar;
        let mut p = EptParams::new(b, f);
        p.values[1] = v[1] / (s * s) + 8.0 / 21.0 * (b - 1.0);
        p.values[2] = v[2] / (s * s);
        p.values[3] = v[3] / (s * s * s);
        p.values[4] = b * b * a0;
        p.values[5] = f * b * (a0 + a2);
        p.values[6] = f * (f * a2 + b * a4);
        p.values[7] = f * f * a4;
        p.values[8] = v[8] / self.n_bar;
        p.values[9] = v[9] * sat * self.sigma_v.powi(2);
        p.values[10] = v[10] * sat * self.sigma_v.powi(4);
        p
    }

    /// The Jacobian ∂p_i/∂v_j of [`Self::to_ept`] at the physical values `v` (row i: the model's
    /// parameter in the order of [`PARAM_NAMES`], column j: the physical one).
    pub fn jacobian(&self, v: &[f64; 12]) -> [[f64; 12]; 12] {
        let s = self.sigma8;
        let (f, b) = (v[11], v[0] / s);
        let (a0, a2, a4) = (v[4], v[5], v[6]);
        let sat = self.f_sat / self.n_bar;
        let db = 1.0 / s;
        let mut j = [[0.0; 12]; 12];
        j[0][0] = db;
        j[1][1] = 1.0 / (s * s);
        j[1][0] = 8.0 / 21.0 * db;
        j[2][2] = 1.0 / (s * s);
        j[3][3] = 1.0 / (s * s * s);
        // α₀ = b² α₀p
        j[4][0] = 2.0 * b * a0 * db;
        j[4][4] = b * b;
        // α₂ = f b (α₀p + α₂p)
        j[5][0] = f * (a0 + a2) * db;
        j[5][4] = f * b;
        j[5][5] = f * b;
        j[5][11] = b * (a0 + a2);
        // α₄ = f (f α₂p + b α₄p)
        j[6][0] = f * a4 * db;
        j[6][5] = f * f;
        j[6][6] = f * b;
        j[6][11] = 2.0 * f * a2 + b * a4;
        // α₆ = f² α₄p
        j[7][6] = f * f;
        j[7][11] = 2.0 * f * a4;
        j[8][8] = 1.0 / self.n_bar;
        j[9][9] = sat * self.sigma_v.powi(2);
        j[10][10] = sat * self.sigma_v.powi(4);
        j[11][11] = 1.0;
        j
    }

    /// The physical values of the model's parameters `p` (the inverse of [`Self::to_ept`] where one
    /// exists: α₆ is not free in this basis, so its value in `p` is dropped, and α₀p, α₂p, α₄p are
    /// solved from α₀, α₂, α₄). With b = 0 or f = 0 a counterterm the map leaves undetermined is 0
    /// where that reproduces α₀, α₂, α₄ (e.g. all zero: a start at f = 0), and NaN where no value does.
    pub fn from_ept(&self, p: &EptParams) -> [f64; 12] {
        let s = self.sigma8;
        let v = &p.values;
        let (b, f) = (v[0], v[11]);
        let sat = self.f_sat / self.n_bar;
        // x = (α − rest)/scale, or 0 where the scale vanishes and α − rest does too (NaN otherwise)
        let solve = |num: f64, scale: f64| match (scale == 0.0, num == 0.0) {
            (false, _) => num / scale,
            (true, true) => 0.0,
            (true, false) => f64::NAN,
        };
        let a0 = solve(v[4], b * b);
        let a2 = solve(v[5] - f * b * a0, f * b);
        let a4 = solve(v[6] - f * f * a2, f * b);
        let mut out = [0.0; 12];
        out[0] = b * s;
        out[1] = (v[1] - 8.0 / 21.0 * (b - 1.0)) * s * s;
        out[2] = v[2] * s * s;
        out[3] = v[3] * s * s * s;
        out[4] = a0;
        out[5] = a2;
        out[6] = a4;
        out[8] = v[8] * self.n_bar;
        out[9] = v[9] / (sat * self.sigma_v.powi(2));
        out[10] = v[10] / (sat * self.sigma_v.powi(4));
        out[11] = f;
        out
    }

    /// One header line stating the basis and its scales.
    pub fn describe(&self) -> String {
        format!(
            "parameter basis: DESI DR1 physical (Maus et al. 2024): b1 = b1p/sigma8_z, b2 = b2p/sigma8_z^2 + \
             (8/21)(b1 - 1), bs = bsp/sigma8_z^2, alpha0 = b1^2 alpha0p, alpha2 = f b1 (alpha0p + alpha2p), \
             alpha4 = f (f alpha2p + b1 alpha4p), alpha6 = f^2 alpha4p, sn = sn0p/n_bar, sn2 = sn2p f_sat \
             sigma_v^2/n_bar, sn4 = sn4p f_sat sigma_v^4/n_bar; sigma8_z = {:.6}, n_bar = {:e} (h/Mpc)^3, \
             f_sat = {}, sigma_v = {} Mpc/h",
            self.sigma8, self.n_bar, self.f_sat, self.sigma_v
        )
    }
}

/// Checks that `name` may be used in the physical basis: `alpha6p` is not a parameter.
///
/// # Errors
/// [`Error::InvalidChoice`] for `alpha6p`.
pub fn check_physical_name(name: &str) -> Result<()> {
    if name == PHYSICAL_NAMES[ALPHA6] {
        return Err(Error::InvalidChoice {
            what: "parameter `alpha6p`".into(),
            reason: "the physical basis has no alpha6 of its own (alpha6 = f^2 alpha4p): free, \
                     marginalise or set a prior on alpha4p"
                .into(),
        });
    }
    Ok(())
}

const _: () = assert!(PHYSICAL_NAMES.len() == PARAM_NAMES.len());

#[cfg(test)]
mod tests {
    use super::*;

    fn basis() -> PhysicalBasis {
        PhysicalBasis::new(0.6, 3e-4, DEFAULT_F_SAT, DEFAULT_SIGMA_V).unwrap()
    }

    /// The Jacobian against central differences of the map (which is a polynomial of degree ≤ 3
    /// in each value: the differences are exact to rounding).
    #[test]
    fn jacobian_is_the_derivative_of_the_map() {
        let b = basis();
        let v = [
            1.3, 0.4, -0.2, 0.1, 2.0, -1.5, 0.7, 0.0, 0.3, 1.1, -0.6, 0.78,
        ];
        let jac = b.jacobian(&v);
        for j in 0..12 {
            let h = 1e-3;
            let (mut up, mut down) = (v, v);
            up[j] += h;
            down[j] -= h;
            let (pu, pd) = (b.to_ept(&up).values, b.to_ept(&down).values);
            for i in 0..12 {
                let fd = (pu[i] - pd[i]) / (2.0 * h);
                let scale = 1.0 + fd.abs();
                assert!(
                    (jac[i][j] - fd).abs() < 1e-6 * scale,
                    "d{i}/d{j}: {} {fd}",
                    jac[i][j]
                );
            }
        }
    }

    /// The counterterms are (b + fμ²)(b α₀p + f α₂p μ² + f α₄p μ⁴): the polynomial in μ² expanded
    /// independently here at four μ; the biases and stochastic terms as the module docs write them.
    #[test]
    fn map_is_the_documented_one() {
        let v = [
            1.2, 0.3, -0.4, 0.1, 5.0, -3.0, 2.0, 0.0, 0.7, -1.5, 2.5, 0.75,
        ];
        let p = basis().to_ept(&v);
        let (b, f) = (2.0, 0.75);
        assert!((p.values[0] - b).abs() < 1e-15);
        assert!((p.values[1] - (0.3 / 0.36 + 8.0 / 21.0)).abs() < 1e-14);
        assert!((p.values[2] + 0.4 / 0.36).abs() < 1e-14);
        assert!((p.values[3] - 0.1 / 0.216).abs() < 1e-14);
        for mu in [0.0, 0.3, 0.7, 1.0_f64] {
            let m2 = mu * mu;
            let ours: f64 = (0..4).map(|n| p.values[4 + n] * m2.powi(n as i32)).sum();
            let want = (b + f * m2) * (b * 5.0 - f * 3.0 * m2 + f * 2.0 * m2 * m2);
            assert!((ours - want).abs() < 1e-12 * want.abs().max(1.0), "mu {mu}");
        }
        assert!((p.values[8] - 0.7 / 3e-4).abs() < 1e-9);
        assert!((p.values[9] + 1.5 * 0.1 * 25.0 / 3e-4).abs() < 1e-8);
        assert!((p.values[10] - 2.5 * 0.1 * 625.0 / 3e-4).abs() < 1e-6);
        assert_eq!(p.f(), f);
    }

    /// from_ept inverts to_ept (alpha6p aside).
    #[test]
    fn the_inverse_round_trips() {
        let v = [
            1.2, 0.3, -0.4, 0.1, 5.0, -3.0, 2.0, 0.0, 0.7, -1.5, 2.5, 0.75,
        ];
        let back = basis().from_ept(&basis().to_ept(&v));
        for (a, b) in v.iter().zip(&back) {
            assert!(
                (a - b).abs() < 1e-12 * a.abs().max(1.0),
                "{v:?} vs {back:?}"
            );
        }
    }

    /// At f = 0 or b1 = 0 the counterterms the map leaves undetermined are 0 where that reproduces
    /// the model's (a start with no counterterms: finite, and back to it), NaN where nothing does.
    #[test]
    fn f_or_b_zero_is_finite_where_the_map_allows_it() {
        for (b1p, f) in [(1.2, 0.0), (0.0, 0.75)] {
            let v = [b1p, 0.3, -0.4, 0.1, 0.0, 0.0, 0.0, 0.0, 0.7, -1.5, 2.5, f];
            let p = basis().to_ept(&v);
            let back = basis().from_ept(&p);
            assert!(back.iter().all(|x| x.is_finite()), "{back:?}");
            let again = basis().to_ept(&back).values;
            for (a, b) in again.iter().zip(&p.values) {
                assert!(
                    (a - b).abs() <= 1e-12 * b.abs(),
                    "{again:?} vs {:?}",
                    p.values
                );
            }
        }
        // α2 ≠ 0 at f = 0 is not a point of the physical basis (α2 = f b1 (α0p + α2p))
        let mut p = EptParams::new(2.0, 0.0);
        p.values[5] = 3.0;
        assert!(basis().from_ept(&p)[5].is_nan());
    }

    #[test]
    fn bad_scales_and_alpha6p_are_errors() {
        assert!(PhysicalBasis::new(0.0, 3e-4, 0.1, 5.0).is_err());
        assert!(PhysicalBasis::new(0.6, -1.0, 0.1, 5.0).is_err());
        assert!(PhysicalBasis::new(0.6, 3e-4, -0.1, 5.0).is_err());
        let e = check_physical_name("alpha6p").unwrap_err().to_string();
        assert!(e.contains("alpha4p"), "{e}");
        assert!(check_physical_name("alpha4p").is_ok());
    }
}
