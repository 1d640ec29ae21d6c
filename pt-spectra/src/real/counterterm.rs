//! The leading EFT counterterm (the effective sound speed c_s² of the EFT of large-scale structure;
//! Baumann, Nicolis, Senatore & Zaldarriaga 2012, arXiv:1004.2488; Carrasco, Hertzberg & Senatore 2012,
//! arXiv:1206.2926), added to any real-space model:
//!
//!   P_δδ,ct = −2 c_s² k² P_lin,   P_δθ,ct = −4 c_s² k² P_lin,   P_θθ,ct = −6 c_s² k² P_lin,
//!
//! c_s² in (Mpc/h)², k in h/Mpc, P_lin the linear input at the output redshift. A positive c_s²
//! lowers the power, as the UV part of 2P13 does (the sign of the EFT literature).
//!
//! **The pair factors.** The counterterm is the response to the effective stress in the Euler equation:
//! a field δ_ct(k) = −c_s² k² δ_lin(k), so that P_δδ,ct = 2⟨δ_ct δ_lin⟩ = −2 c_s² k² P_lin. Its
//! velocity follows from mass conservation, linearised in the counterterm (products of δ_ct with δ or
//! v are of 2-loop order): ∂δ_ct/∂τ = −∇·v_ct, and with θ ≡ −∇·v/(aHf) (θ_lin = δ_lin, [`crate::loops`])
//! θ_ct = ∂δ_ct/∂ln D. With the Einstein–de Sitter time dependence of the EFT literature, c_s² ∝ D²
//! (the counterterm grows as the P13 whose UV part it renormalises: P_ct ∝ D⁴), δ_ct ∝ D³, so
//! θ_ct = 3 δ_ct. Hence P_δθ,ct = ⟨δ_ct θ_lin⟩ + ⟨δ_lin θ_ct⟩ = (1 + 3)(−c_s² k² P_lin) and
//! P_θθ,ct = 2·3 (−c_s² k² P_lin): the factors 2, 4, 6 ([`counterterm_factor`]; for δ_ct ∝ Dⁿ they
//! would be 2, 1 + n, 2n). In redshift space (Scoccimarro, TNS) the sum is
//! −2 c_s² k² P_lin (b² + 4bfμ² + 3f²μ⁴), which for b = 1 is (1 + fμ²)(1 + 3fμ²), the real-space
//! counterterm carried through δ_s = δ + fμ²θ; Kaiser uses P_δδ only.
//!
//! **What this leaves out.** One c_s² cannot cancel the q_max dependence of all three 2P13 exactly:
//! their UV limits are −(61/105, 25/21, 9/5) k²σ_v² P_lin (the P13 kernels of
//! [`crate::loops::p13_kernels`], tested in tests/tests/suite/one_loop.rs), in the ratios
//! 1 : 125/61 : 189/61 = 1 : 2.05 : 3.10, not 1 : 2 : 3.
//! The EFT literature renormalises that remainder of the velocity with counterterms of its own
//! (Mercolli & Pajer 2014, arXiv:1307.3220: the velocity is not a conserved density and needs
//! counterterms "that fix its definition"), and EFT codes fit them as further free parameters
//! (velocileptors' α_v; CLASS-PT and velocileptors in redshift space a counterterm per power of μ²).
//! Here one parameter is kept, with the pair factors that mass conservation fixes; the velocity
//! counterterms, the EFT redshift-space counterterms (Senatore & Zaldarriaga 2014, arXiv:1409.1225) and
//! halo derivative bias are not modelled. The counterterm is added to the output of every model as it
//! is (SPT, RPT, RegPT: outside the propagator factors; the IR-resummed models: on the IR-resummed
//! P_nw + e^{−k²Σ²} P_w, [`super::eft`]). The 2-loop counterterms of `2l-eft` are in [`super::eft`].
//!
//! The counterterm is exact: it adds nothing to the error estimates. With c_s² = 0 nothing is added
//! and every value is bit-identical to a run without it.

use super::RealSpectra;
use crate::error::{Error, Result};
use crate::loops::Pair;

/// The factor c_XY of P_XY,ct = −c_XY c_s² k² P_lin: 2 (δδ), 4 (δθ), 6 (θθ) (module docs).
pub fn counterterm_factor(pair: Pair) -> f64 {
    match pair {
        Pair::DeltaDelta => 2.0,
        Pair::DeltaTheta => 4.0,
        Pair::ThetaTheta => 6.0,
    }
}

/// The counterterm P_XY,ct = −c_XY c_s² k² P_lin [(Mpc/h)^3] of `pair` at wavenumber `k` [h/Mpc] for
/// c_s² = `cs2` [(Mpc/h)²] and the linear spectrum `p_lin` [(Mpc/h)^3] at k.
///
/// ```
/// use pt_spectra::{loops::Pair, real::counterterm};
/// // c_s² = 1 (Mpc/h)², k = 0.1 h/Mpc, P_lin = 6000 (Mpc/h)³: −2·0.01·6000 = −120 for δδ.
/// assert!((counterterm(Pair::DeltaDelta, 1.0, 0.1, 6000.0) + 120.0).abs() < 1e-12);
/// assert!((counterterm(Pair::ThetaTheta, 1.0, 0.1, 6000.0) + 360.0).abs() < 1e-12);
/// ```
pub fn counterterm(pair: Pair, cs2: f64, k: f64, p_lin: f64) -> f64 {
    -counterterm_factor(pair) * cs2 * k * k * p_lin
}

/// Checks a counterterm coefficient c_s² [(Mpc/h)²]: any finite value (negative ones too, which a fit
/// may need).
///
/// # Errors
/// [`Error::InvalidParameter`] for a NaN or infinite `cs2`.
pub fn check_cs2(cs2: f64) -> Result<()> {
    if cs2.is_finite() {
        Ok(())
    } else {
        Err(Error::InvalidParameter {
            name: "EFT counterterm cs2 [(Mpc/h)^2]",
            value: cs2,
            reason: "must be finite",
        })
    }
}

/// The header line of an EFT counterterm c_s² = `cs2` ≠ 0 [(Mpc/h)²].
pub fn counterterm_line(cs2: f64) -> String {
    format!(
        "EFT counterterm cs2 = {cs2} (Mpc/h)^2 added to P_dd, P_dt, P_tt: -2, -4, -6 cs2 k^2 P_lin \
         (delta_ct = -cs2 k^2 delta_lin growing as D^3, theta_ct = 3 delta_ct by mass conservation; \
         exact, no error added)"
    )
}

impl RealSpectra {
    /// The spectra with the EFT counterterm of c_s² = `cs2` [(Mpc/h)²] added to P_δδ, P_δθ and P_θθ
    /// ([`counterterm`]; module docs), [`counterterms`](Self::counterterms)`.cs2` increased by `cs2`:
    /// [`with_counterterms`](Self::with_counterterms) with c_s² alone. The errors are unchanged (the
    /// counterterm is exact); `cs2` = 0 returns the spectra untouched.
    ///
    /// ```
    /// use pt_spectra::{linear::LinearSpectrum, loops::Pair, precision::Precision, store::TableStore};
    /// use pt_spectra::real::{real_space, RealModel};
    /// let p = LinearSpectrum::gm2012(0.0)?;
    /// let s = real_space(RealModel::OneLoopSpt, &p, &[0.1], &Precision::fast(), &TableStore::in_memory())?;
    /// let with = s.clone().with_counterterm(2.0)?;
    /// let shift = with.pair(Pair::DeltaTheta)[0].value - s.pair(Pair::DeltaTheta)[0].value;
    /// assert!((shift / (-4.0 * 2.0 * 0.01 * s.p_lin[0]) - 1.0).abs() < 1e-9);
    /// assert_eq!(with.counterterms.cs2, 2.0);
    /// # Ok::<(), pt_spectra::error::Error>(())
    /// ```
    ///
    /// # Errors
    /// As [`check_cs2`].
    pub fn with_counterterm(self, cs2: f64) -> Result<Self> {
        check_cs2(cs2)?;
        self.with_counterterms(&super::Counterterms::cs2(cs2))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::linear::LinearSpectrum;
    use crate::precision::Precision;
    use crate::real::{real_space, RealModel};
    use crate::store::TableStore;

    #[test]
    fn the_counterterm_adds_minus_2_4_6_cs2_k2_p_lin_and_nothing_to_the_errors() {
        let p = LinearSpectrum::gm2012(0.5).unwrap();
        let k = [0.02, 0.1, 0.25];
        let store = TableStore::in_memory();
        for model in [
            RealModel::Linear,
            RealModel::OneLoopSpt,
            RealModel::OneLoopRptN1,
        ] {
            let base = real_space(model, &p, &k, &Precision::fast(), &store).unwrap();
            for cs2 in [1.5, -0.7] {
                let with = base.clone().with_counterterm(cs2).unwrap();
                assert_eq!(with.counterterms.cs2, cs2);
                for (pair, factor) in Pair::ALL.into_iter().zip([2.0, 4.0, 6.0]) {
                    for (i, &ki) in k.iter().enumerate() {
                        // Closed form, with P_lin read from the input spectrum itself.
                        let want = -factor * cs2 * ki * ki * p.eval(ki);
                        let (a, b) = (base.spectra[pair][i], with.spectra[pair][i]);
                        let got = b.value - a.value;
                        // Rounding of the sum: a few ulp of the larger of the two values.
                        let ulp = 4.0 * f64::EPSILON * a.value.abs().max(b.value.abs());
                        assert!((got - want).abs() <= ulp, "{model} {pair:?} k={ki}");
                        assert_eq!(a.error, b.error);
                        assert!((with.counterterm(pair)[i] - want).abs() <= 1e-12 * want.abs());
                    }
                }
            }
        }
    }

    #[test]
    fn zero_changes_nothing_and_non_finite_values_are_refused() {
        let p = LinearSpectrum::gm2012(0.0).unwrap();
        let store = TableStore::in_memory();
        let base = real_space(
            RealModel::OneLoopSpt,
            &p,
            &[0.05, 0.2],
            &Precision::fast(),
            &store,
        )
        .unwrap();
        assert_eq!(base.counterterms.cs2, 0.0);
        assert_eq!(base.clone().with_counterterm(0.0).unwrap(), base);
        for bad in [f64::NAN, f64::INFINITY, f64::NEG_INFINITY] {
            let e = base.clone().with_counterterm(bad).unwrap_err().to_string();
            assert!(e.contains("cs2") && e.contains("finite"), "{e}");
        }
        // Two counterterms add up.
        let twice = base.clone().with_counterterm(1.0).unwrap();
        let twice = twice.with_counterterm(0.5).unwrap();
        let once = base.with_counterterm(1.5).unwrap();
        assert_eq!(twice.counterterms.cs2, 1.5);
        for pair in Pair::ALL {
            for (a, b) in twice.spectra[pair].iter().zip(&once.spectra[pair]) {
                assert!((a.value - b.value).abs() < 1e-12 * a.value.abs());
            }
        }
    }
}
