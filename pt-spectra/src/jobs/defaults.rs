//! The defaults of the requests, spelled once: the command line's options and the Python functions'
//! keyword arguments take them from here (Python through `pt_spectra._core.DEFAULTS`).

/// `real`: the real-space model.
pub const REAL_MODEL: &str = "1l-spt";
/// `rsd`: the real-space model under the redshift-space one.
pub const RSD_REAL_MODEL: &str = "1l-rpt-n1";
/// `rsd` and `fit`: the redshift-space model.
pub const RSD_MODEL: &str = "tns";
/// `rsd`: the Fingers-of-God damping.
pub const RSD_FOG: &str = "none";
/// `fit`: the real-space model.
pub const FIT_REAL_MODEL: &str = "1l-spt";
/// `fit`: the Fingers-of-God damping.
pub const FIT_FOG: &str = "lorentzian";
/// `fit`: the start (or fixed) σ0 [Mpc/h].
pub const FIT_SIGMA0: f64 = 3.0;
/// `fit`: the start σ0 as the command line spells it.
pub const FIT_SIGMA0_TEXT: &str = "3";
/// Every job: the precision preset.
pub const PRECISION: &str = "default";
/// Every job: how the 2-loop terms are computed.
pub const TWO_LOOP: &str = "auto";

/// The defaults by name, for the Python module.
pub const ALL: [(&str, &str); 9] = [
    ("real_model", REAL_MODEL),
    ("rsd_real_model", RSD_REAL_MODEL),
    ("rsd_model", RSD_MODEL),
    ("rsd_fog", RSD_FOG),
    ("fit_real_model", FIT_REAL_MODEL),
    ("fit_fog", FIT_FOG),
    ("fit_sigma0", FIT_SIGMA0_TEXT),
    ("precision", PRECISION),
    ("two_loop", TWO_LOOP),
];

#[cfg(test)]
mod tests {
    /// The text spelling of σ0 is the number, and every model name parses.
    #[test]
    fn defaults_are_consistent_and_valid() {
        assert_eq!(
            super::FIT_SIGMA0_TEXT.parse::<f64>().unwrap(),
            super::FIT_SIGMA0
        );
        for m in [super::RSD_REAL_MODEL, super::FIT_REAL_MODEL] {
            assert!(m.parse::<crate::real::RealModel>().is_ok(), "{m}");
        }
        assert!(super::REAL_MODEL
            .parse::<crate::real::RealSelection>()
            .is_ok());
        assert!(super::RSD_MODEL.parse::<crate::rsd::RsdModel>().is_ok());
        for fog in [super::RSD_FOG, super::FIT_FOG] {
            assert!(fog.parse::<crate::rsd::Fog>().is_ok(), "{fog}");
        }
        assert!(crate::precision::Precision::preset(super::PRECISION).is_ok());
        assert!(super::TWO_LOOP
            .parse::<crate::precision::TwoLoopMethod>()
            .is_ok());
    }
}
