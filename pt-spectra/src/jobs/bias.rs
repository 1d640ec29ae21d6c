//! The galaxy bias expansion in `real` tables: the bias terms and P_gg, P_gm.

use crate::bias::{BiasConvention, BiasParams};
use crate::error::{Error, Result};
use crate::loops::bias::{BiasPlan, BiasTerms, GalaxyBias, PAIR_NAMES};
use crate::loops::{Estimate, Pair};
use crate::output::{Table, POWER};
use crate::real::{RealPlan, RealSelection, RealSpectra};
use crate::setup::Prepared;

/// What a `real` table adds of the galaxy bias expansion ([`crate::loops::bias`]).
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct BiasOutput {
    /// The bias terms Pd1d2 … sig3nl as columns, with their errors.
    pub terms: bool,
    /// P_gg and P_gm of these bias parameters (velocileptors' convention, as every model takes
    /// them: [`crate::bias`]; evaluated through FAST-PT's expansion with the mapped values).
    pub galaxy: Option<BiasParams>,
    /// The convention the user wrote the bias in (for the header).
    pub given: BiasConvention,
}

impl BiasOutput {
    /// Whether anything is asked for.
    pub fn any(&self) -> bool {
        self.terms || self.galaxy.is_some()
    }

    /// Checks the request against the model selection before any plan is built.
    ///
    /// # Errors
    /// [`Error::InvalidChoice`] for bias output with `all`; [`Error::InvalidParameter`] for a bias that
    /// is not finite.
    pub fn validate(&self, selection: RealSelection) -> Result<()> {
        if self.any() && selection == RealSelection::All {
            return Err(Error::InvalidChoice {
                what: "bias terms with model all".into(),
                reason: "the galaxy spectra need one matter model: choose it with --model".into(),
            });
        }
        self.galaxy
            .as_ref()
            .map_or(Ok(()), BiasParams::check_finite)
    }
}

/// The bias terms of the prepared spectrum if `output` asks for any.
pub(super) fn terms(
    plan: &RealPlan,
    bias_plan: Option<&BiasPlan>,
    selection: RealSelection,
    prepared: &Prepared,
    output: BiasOutput,
) -> Result<Option<BiasTerms>> {
    output.validate(selection)?;
    if !output.any() {
        return Ok(None);
    }
    let Some(bias_plan) = bias_plan else {
        return Err(Error::MissingTerm {
            term: "the bias terms",
            needed_by: "the galaxy bias output".into(),
            hint: " (BiasPlan)",
        });
    };
    if bias_plan.k() != plan.k() {
        return Err(Error::GridMismatch {
            what: "bias plan and real-space plan",
            expected: format!("{} k", plan.k().len()),
            found: format!("{} k", bias_plan.k().len()),
        });
    }
    Ok(Some(bias_plan.evaluate(prepared.tracer_spectrum())))
}

/// Appends the columns and header lines of `output` to the table `t` of `spectra`.
pub(super) fn push_columns(
    t: &mut Table,
    spectra: &RealSpectra,
    b: &BiasTerms,
    output: BiasOutput,
) {
    let s4 = b.sigma4;
    t.header.push(format!(
        "bias terms (McDonald & Roy 2009, FAST-PT's one_loop_dd_bias_b3nl normalisation, no constant \
         subtracted): Pd1d2 = 2 int F2 P P, Pd2d2 = 2 int P P, Pd1s2 = 2 int F2 S2 P P, Pd2s2 = 2 int \
         S2 P P, Ps2s2 = 2 int S2^2 P P, Pt1d2 = 2 int G2 P P, Pt1s2 = 2 int G2 S2 P P, sig3nl = \
         (64/315) sigma3^2(k) P_lin(k); k -> 0: Pd2d2 -> 2 sigma4, Pd2s2 -> 4/3 sigma4, Ps2s2 -> 8/9 \
         sigma4, sigma4 = int P^2 = {:.8e} +- {:.1e} (Mpc/h)^3",
        s4.value, s4.error
    ));
    if output.terms {
        for (name, v) in PAIR_NAMES.iter().zip(&b.pairs) {
            t.push_estimates(name, POWER, v);
        }
        t.push_estimates("sig3nl", POWER, &b.sig3nl);
    }
    if let Some(bias) = output.galaxy {
        let g = GalaxyBias::from(bias);
        t.header.push(bias.describe(output.given));
        t.header.push(format!(
            "galaxies, in FAST-PT's convention: b1 = {}, b2 = {}, bs = {}, b3nl = {}; P_gg = b1^2 P_dd + b1 b2 Pd1d2 + 1/4 b2^2 \
             Pd2d2 + b1 bs Pd1s2 + 1/2 b2 bs Pd2s2 + 1/4 bs^2 Ps2s2 + 2 b1 b3nl sig3nl, P_gm = b1 P_dd + \
             1/2 b2 Pd1d2 + 1/2 bs Pd1s2 + b3nl sig3nl (P_dd of the model above; no shot noise)",
            g.b1, g.b2, g.bs, g.b3nl
        ));
        let dd = spectra.pair(Pair::DeltaDelta);
        let (gg, gm): (Vec<Estimate>, Vec<Estimate>) = (0..dd.len())
            .map(|i| {
                let [gg, gm] = g.spectra(i, dd[i], b);
                (gg, gm)
            })
            .unzip();
        t.push_estimates("P_gg", POWER, &gg);
        t.push_estimates("P_gm", POWER, &gm);
    }
}
