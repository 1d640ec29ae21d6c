//! `rsd --rsd spt2` and `--rsd eft2`: the matter multipoles of 2-loop SPT in redshift space
//! ([`crate::rsd::spt2`]) and of the 2-loop EFT with IR resummation ([`crate::rsd::eft2`]) as tables.

use super::{describe_inputs, VERSION};
use crate::error::Result;
use crate::loops::Estimate;
use crate::output::{Table, POWER, WAVENUMBER};
use crate::precision::Precision;
use crate::rsd::eft2::{Eft2Plan, Eft2Terms, RsdCounterterm, RsdCounterterms};
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
    let header = vec![
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
             k^3.5, at least {} at every k), seed {}, 7 nodes in mu^2; errors are the shifts' \
             standard errors",
            settings.replicas,
            settings.points,
            crate::loops::rsd_two_loop::rsd_min_points(settings.points),
            settings.seed
        ),
        terms.source.clone(),
    ];
    let mut t = multipole_table(header, &terms.k, ells, &m.total, prepared, precision);
    t.methods.push(terms.method.clone());
    let values = |p: &[Estimate]| p.iter().map(|e| e.value).collect::<Vec<_>>();
    let errors = |p: &[Estimate]| p.iter().map(|e| e.error).collect::<Vec<_>>();
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

/// The multipole table of `eft2` at growth rate `f` (`None`: f(z) of the cosmology) with the
/// counterterms `ct`: columns `k P<l>… err_P<l>…` and, with `parts`, the multipoles of every
/// counterterm template, `T<l>_<name>` = ∂P_ℓ/∂X.
///
/// # Errors
/// As [`Eft2Terms::multipoles`].
#[allow(clippy::too_many_arguments)]
pub fn eft2_table(
    plan: &Eft2Plan,
    terms: &Eft2Terms,
    f: Option<f64>,
    ells: &[usize],
    ct: &RsdCounterterms,
    parts: bool,
    prepared: &Prepared,
    precision: &Precision,
) -> Result<Table> {
    let f = f.unwrap_or(prepared.growth_rate);
    super::rsd::check_growth_rate(f)?;
    let m = terms.multipoles(f, ells, ct)?;
    let settings = plan.two_loop_settings();
    let mut header = vec![
        format!(
            "pt-spectra {VERSION} rsd: eft2 (matter, 2-loop EFT in redshift space), z = {}, f = {f}, {}",
            prepared.z,
            ct.describe()
        ),
        "P(k,mu) = 2-loop SPT in redshift space (as spt2) - 2 k^2 (c0 + c2 mu^2 + c4 mu^4) P_IR - 2 k^2 \
         (c0_1loop + c2_1loop mu^2 + c4_1loop mu^4) P1_IR - ctilde k^4 f^4 mu^4 (1 + f mu^2)^2 P_IR"
            .into(),
    ];
    header.push(if terms.ir() {
        format!(
            "IR resummation: P_nw + loops of P_nw + exp(-k^2 Sigma^2(mu)) [(1 + x + x^2/2)(1 + f mu^2)^2 P_w \
             + (1 + x) P1_w + P2_w], x = k^2 Sigma^2(mu) = k^2 [(1 + f mu^2 (2 + f)) Sigma^2 + f^2 mu^2 \
             (mu^2 - 1) dSigma^2], Sigma^2 = {:.4} (Mpc/h)^2, dSigma^2 = {:.4} (Mpc/h)^2 (CLASS-PT's, \
             BAO scale {} Mpc/h, k_s = {}); P_IR = P_nw + exp(-x) P_w; --no-ir for plain SPT",
            terms.sigma2.0.value,
            terms.sigma2.1.value,
            crate::ir::BAO_SCALE,
            crate::ir::SIGMA_CUTOFF
        )
    } else {
        "no IR resummation (--no-ir): P_IR = P_lin, P1_IR = P1".into()
    });
    if ct.values.iter().all(|&v| v == 0.0) {
        header.push(
            "every counterterm is 0: this is (IR-resummed) 2-loop SPT; set them with --ct NAME=VALUE".into(),
        );
    }
    header.push(format!(
        "2-loop terms: randomised quasi-Monte Carlo over q1, q2 and the line-of-sight azimuth, {} shifts \
         x {} Sobol points at k = 0.16 (scaled as k^3.5, at least {} at every k), seed {}{}; \
         multipoles by {}-node Gauss-Legendre in mu (error from half as many)",
        settings.replicas,
        settings.points,
        crate::loops::rsd_two_loop::rsd_min_points(settings.points),
        settings.seed,
        if terms.ir() {
            ", the spectrum and its no-wiggle part on the same points"
        } else {
            ""
        },
        crate::rsd::eft2::MU_NODES
    ));
    header.push(terms.source.clone());
    let mut t = multipole_table(header, &terms.k, ells, &m.total, prepared, precision);
    t.methods.push(terms.method.clone());
    if parts {
        for (c, per_ell) in RsdCounterterm::ALL.iter().zip(&m.templates) {
            let unit = if *c == RsdCounterterm::Ctilde {
                "(Mpc/h)^-1"
            } else {
                "Mpc/h"
            };
            for (l, values) in ells.iter().zip(per_ell) {
                t.push(format!("T{l}_{c}"), unit, values.clone());
            }
        }
    }
    Ok(t)
}

/// The table of multipoles `total` (per ℓ of `ells`, per k) with `header`, then the line on massive
/// neutrinos and the inputs: columns `k P<l>… err_P<l>…`.
fn multipole_table(
    mut header: Vec<String>,
    k: &[f64],
    ells: &[usize],
    total: &[Vec<Estimate>],
    prepared: &Prepared,
    precision: &Precision,
) -> Table {
    if prepared.cold_fraction() < 1.0 {
        header.push(
            "massive neutrinos: the multipoles of cold dark matter + baryons (P_cb), not of total \
             matter"
                .into(),
        );
    }
    header.extend(describe_inputs(prepared, precision));
    let mut t = Table::new(header);
    t.push("k", WAVENUMBER, k.to_vec());
    for (l, p) in ells.iter().zip(total) {
        t.push(format!("P{l}"), POWER, p.iter().map(|e| e.value).collect());
    }
    for (l, p) in ells.iter().zip(total) {
        t.push(
            format!("err_P{l}"),
            POWER,
            p.iter().map(|e| e.error).collect(),
        );
    }
    t
}
