//! `rsd --rsd spt2`: the matter multipoles of 2-loop SPT in redshift space ([`crate::rsd::spt2`]) as a
//! table.

use super::{describe_inputs, VERSION};
use crate::error::Result;
use crate::output::{Table, POWER, WAVENUMBER};
use crate::precision::Precision;
use crate::rsd::spt2::{Spt2Plan, Spt2Terms, POINTS_DIVISOR};
use crate::setup::Prepared;

/// The multipole table of `terms` at growth rate `f` (`None`: f(z) of the cosmology): columns
/// `k P<l>… err_P<l>…` and, with `parts`, `P<l>_lin P<l>_1loop P<l>_2loop` and the errors of the two
/// loop parts.
///
/// # Errors
/// As [`Spt2Terms::multipoles`].
pub fn spt2_table(
    plan: &Spt2Plan,
    terms: &Spt2Terms,
    f: Option<f64>,
    ells: &[usize],
    parts: bool,
    prepared: &Prepared,
    precision: &Precision,
) -> Result<Table> {
    let f = f.unwrap_or(prepared.growth_rate);
    super::rsd::check_growth_rate(f)?;
    let m = terms.multipoles(f, ells)?;
    let settings = plan.two_loop_settings();
    let mut header = vec![
        format!(
            "pt-spectra {VERSION} rsd: spt2 (matter, 2-loop SPT in redshift space), z = {}, f = {f}",
            prepared.z
        ),
        "P(k,mu) = (1 + f mu^2)^2 P_lin + [P22 + 2 P13](Z2, Z3) + [2 P15 + 2 P24 + P33](Z4, Z5); no \
         Fingers of God, no IR resummation, no counterterms"
            .into(),
        format!(
            "2-loop terms: randomised quasi-Monte Carlo over q1, q2 and the line-of-sight azimuth, {} \
             shifts x {} Sobol points at k = 0.16 (real-space points / {POINTS_DIVISOR}, scaled as \
             k^3.5), seed {}, 7 nodes in mu^2; errors are the shifts' standard errors",
            settings.replicas, settings.points, settings.seed
        ),
    ];
    if prepared.cold_fraction() < 1.0 {
        header.push(
            "massive neutrinos: the multipoles of cold dark matter + baryons (P_cb), not of total \
             matter"
                .into(),
        );
    }
    header.extend(describe_inputs(prepared, precision));
    let mut t = Table::new(header);
    t.push("k", WAVENUMBER, terms.k.clone());
    let values = |p: &[crate::loops::Estimate]| p.iter().map(|e| e.value).collect::<Vec<_>>();
    let errors = |p: &[crate::loops::Estimate]| p.iter().map(|e| e.error).collect::<Vec<_>>();
    for (l, p) in ells.iter().zip(&m.total) {
        t.push(format!("P{l}"), POWER, values(p));
    }
    for (l, p) in ells.iter().zip(&m.total) {
        t.push(format!("err_P{l}"), POWER, errors(p));
    }
    if parts {
        for (l, ((lin, one), two)) in ells
            .iter()
            .zip(m.linear.iter().zip(&m.one_loop).zip(&m.two_loop))
        {
            t.push(format!("P{l}_lin"), POWER, values(lin));
            t.push(format!("P{l}_1loop"), POWER, values(one));
            t.push(format!("err_P{l}_1loop"), POWER, errors(one));
            t.push(format!("P{l}_2loop"), POWER, values(two));
            t.push(format!("err_P{l}_2loop"), POWER, errors(two));
        }
    }
    Ok(t)
}
