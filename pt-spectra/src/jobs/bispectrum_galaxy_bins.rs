//! `bispectrum --loop 1 --multipoles` with bins (`--bin-width`, `--k-edges`): the one-loop galaxy
//! multipoles averaged over triangle bins: the effective triangle plus the bin average's departure from it
//! on a coarse loop rule ([`crate::bispectrum::one_loop_bins`]), as a table with its header.

use super::bispectrum_galaxy::{ir_line, multipole_columns, one_loop_ir_inputs};
use super::bispectrum_multipole_plan::{
    binned_plan_multipoles, describe_bin_source, one_loop_multipole_bin_tensors,
};
use super::VERSION;
use crate::bispectrum::bias_kernels::LoopBias;
use crate::bispectrum::galaxy_counterterms_rsd::{
    redshift_counterterm_multipoles, N_REDSHIFT_CT, REDSHIFT_COUNTERTERMS,
};
use crate::bispectrum::one_loop::{OneLoopRule, PARTITION_POWER};
use crate::bispectrum::one_loop_bins::{correction_rule, CORRECTION_NODES};
use crate::bispectrum::{LegendreSide, TriangleSet};
use crate::error::Result;
use crate::output::{MethodNote, Table, WAVENUMBER};
use crate::precision::TwoLoopMethod;
use crate::progress::Progress;
use crate::setup::Prepared;
use crate::store::TableStore;

/// The table of the multipoles of the one-loop galaxy bispectrum with `bias` averaged over the bins `set`
/// (shells) in redshift space at growth rate `f` (default f(z)), the Legendre polynomial on `side`, IR-resummed
/// with `ir`: the columns of [`super::one_loop_galaxy_multipoles_table`] (`k1 k2 k3` the bins' centres),
/// then the effective triangles `k1_eff k2_eff k3_eff`: the one-loop multipoles at each bin's effective
/// triangle plus their departure from the bin average on a coarse loop rule, with its error in `err_`, the
/// counterterm shapes' multipoles averaged over the bin ([`crate::bispectrum::one_loop_bins`]); each bin
/// reported to `progress`. `method` basis reads or builds the multipole bin tensors
/// ([`crate::bispectrum::multipole_bins`]), auto uses them if cached; where they do not represent the
/// spectrum the bins are integrated directly (the header says which).
///
/// # Errors
/// As [`binned_plan_multipoles`] and [`redshift_counterterm_multipoles`].
#[allow(clippy::too_many_arguments)]
pub fn one_loop_galaxy_binned_multipoles_table(
    prepared: &Prepared,
    set: &TriangleSet,
    bias: &LoopBias,
    f: Option<f64>,
    side: LegendreSide,
    ir: bool,
    rule: &OneLoopRule,
    (method, store): (TwoLoopMethod, &TableStore),
    progress: &dyn Progress,
) -> Result<Table> {
    let f = f.unwrap_or(prepared.growth_rate);
    crate::cosmology::check_growth_rate(f)?;
    let p = &prepared.spectrum;
    let ir = ir.then(|| one_loop_ir_inputs(prepared)).transpose()?;
    let tick = |done: usize, total: usize| {
        progress.update(crate::bispectrum::seam::ONE_LOOP_STAGE, done, total);
    };
    let tensors = one_loop_multipole_bin_tensors(set, side, rule, method, store, progress)?;
    let (binned, source) = binned_plan_multipoles(
        tensors.as_deref(),
        method == TwoLoopMethod::Auto,
        p,
        ir.as_ref(),
        set,
        f,
        side,
        rule,
        &tick,
    )?;
    let coarse = correction_rule(rule);
    let rows = binned.evaluate(bias)?;
    let n_shell = CORRECTION_NODES;
    let mut shapes = Vec::with_capacity(set.len());
    for i in 0..set.len() {
        let a = LegendreSide::Index(set.legendre_index(i, side));
        let mut mean = [[0.0; N_REDSHIFT_CT]; 3];
        for (k, w) in set.shapes(i, n_shell) {
            let s = redshift_counterterm_multipoles(p, k, bias, f, a)?;
            for (m, s) in mean.iter_mut().zip(s) {
                m.iter_mut().zip(s).for_each(|(m, s)| *m += w * s);
            }
        }
        shapes.push(mean);
    }
    let values: Vec<String> = LoopBias::NAMES
        .iter()
        .zip(bias.values())
        .map(|(n, v)| format!("{n} = {v}"))
        .collect();
    let mut header = vec![
        format!(
            "pt-spectra {VERSION} bispectrum --loop 1 --multipoles: multipoles B0, B2, B4 of the one-loop galaxy \
             bispectrum in redshift space averaged over {} bins of width {} h/Mpc, f = {f}, z = {}",
            set.len(),
            set.width().unwrap_or(0.0),
            prepared.z
        ),
        format!(
            "bias (the fourth-order basis of Eggemeier, Scoccimarro & Smith 2019; docs/bispectrum.md): {}",
            values.join(", ")
        ),
        format!(
            "bin average: B_l,bin = B_l(k_eff) + Delta_l, Delta_l = sum_n w_n B_l(k_n; coarse) - B_l(k_eff; coarse): \
             the one-loop multipoles at each bin's effective triangle (k_eff columns: its mean sides over the \
             closed triangles, weight k1 k2 k3) plus their departure from the bin average on the closed \
             triangles k_n ({CORRECTION_NODES} nodes per shell panel) with the coarse loop rule {} x {} x {} per \
             panel (the tree level's Delta is exact: the bin average of the tree); err_ adds 2 (|Delta - \
             Delta(one node fewer)| + |Delta - Delta(2 x 2 x 2 rule)|) to the loop terms, |Delta - Delta(one node \
             fewer)| to the tree (docs/bispectrum.md); Legendre polynomial on {}",
            coarse.radial,
            coarse.mu,
            coarse.phi,
            match side {
                LegendreSide::Largest => "the largest bin (as the window-free estimator)".to_string(),
                LegendreSide::Index(a) => format!("side k{}", a + 1),
            }
        ),
        "B{l} = B{l}_tree + B{l}_222 + B{l}_321_I + B{l}_321_II + B{l}_411 with the kernels Z_n^g; B321_II and \
         B411 renormalised (their q -> infinity constants times sigma^2 subtracted); no FoG or AP"
            .into(),
        ir_line(ir.as_ref()),
        format!(
            "loop integrals over {} <= |q| <= {} h/Mpc about each cusp (smooth partition of unity, power {}); \
             {} ln q x {} cos(theta) x {} phi nodes per panel, one pass for all orientations (exact rule); err_: \
             difference from the rule with half the nodes, plus the bin correction's",
            rule.q_min, rule.q_max, PARTITION_POWER, rule.radial, rule.mu, 2 * rule.phi
        ),
        format!(
            "counterterms and stochastic terms not in B{{l}}: B_ct = sum_c c_c shape_B{{l}}_c, the shapes' \
             multipoles averaged over the bin ({n_shell} nodes per shell panel) {} (docs/bispectrum.md)",
            REDSHIFT_COUNTERTERMS.join(", ")
        ),
        describe_bin_source(&source),
        "linear spectrum: all matter".into(),
    ];
    header.extend(prepared.description.iter().cloned());
    let mut t = Table::new(header);
    t.methods
        .push(MethodNote::new("loop terms", source.method()));
    multipole_columns(&mut t, set.triangles(), &rows, &shapes);
    for (i, name) in ["k1_eff", "k2_eff", "k3_eff"].iter().enumerate() {
        t.push(
            *name,
            WAVENUMBER,
            binned.effective.iter().map(|k| k[i]).collect(),
        );
    }
    Ok(t)
}
