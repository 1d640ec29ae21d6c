//! Results as tables: the presentation of the typed results of the numeric modules (real-space spectra,
//! redshift-space multipoles, Δχ² surfaces), kept apart from the numerics that produce them.

use crate::estimate::Estimate;
use crate::fit::{Contour, Parameter};
use crate::loops::Pair;
use crate::output::{Table, POWER, WAVENUMBER};
use crate::real::{RealModel, RealSpectra};
use crate::rsd::RsdMultipoles;

/// The error columns `err_P_dd err_P_dt err_P_tt` of the spectra (after the spectra with `--terms`;
/// at the end of the default table, so that the columns before them keep their places).
pub fn push_spectrum_errors(t: &mut Table, r: &RealSpectra) {
    for (pair, s) in r.spectra.iter() {
        t.push(format!("err_P_{}", pair.suffix()), POWER, errors(s));
    }
}

/// The spectra as a table with `header` lines: `k P_lin P_dd P_dt P_tt`, and with `terms` also
/// their errors, every loop term the model uses with its error (`P22_xx`, `P13_xx`, then `P15_xx`,
/// `P17_xx`, `P24_xx P33_xx P33_2L_xx P2loop_xx` as the model needs them), σ_v² and, for RPT, the
/// factors `N_xx` (xx = dd, dt, tt); for the EFT models the counterterm templates `T_xx_X` = ∂P_xx/∂X
/// of each counterterm X ([`crate::real::eft`]).
pub fn real_spectra_table(r: &RealSpectra, header: Vec<String>, terms: bool) -> Table {
    let mut t = Table::new(header);
    t.push("k", WAVENUMBER, r.k.clone());
    t.push("P_lin", POWER, r.p_lin.clone());
    for (pair, s) in r.spectra.iter() {
        t.push(format!("P_{}", pair.suffix()), POWER, values(s));
    }
    if !terms {
        return t;
    }
    push_spectrum_errors(&mut t, r);
    let one = &r.terms.one_loop;
    for pair in Pair::ALL {
        t.push_estimates(&format!("P22_{}", pair.suffix()), POWER, &one.p22[pair]);
        t.push_estimates(&format!("P13_{}", pair.suffix()), POWER, &one.p13[pair]);
    }
    let model = r.model;
    for (name, term, needed) in [
        ("P15", &r.terms.p15, model.needs_p15()),
        ("P17", &r.terms.p17, model.needs_p17()),
    ] {
        if let (Some(term), true) = (term, needed) {
            for (pair, v) in term.iter() {
                t.push_estimates(&format!("{name}_{}", pair.suffix()), POWER, v);
            }
        }
    }
    if let (Some(two), true) = (&r.terms.two_loop, model.needs_two_loop()) {
        for (pair, p) in two.pairs.iter() {
            let s = pair.suffix();
            let p33: Vec<Estimate> = (0..r.k.len())
                .map(|i| one.p33_reducible(pair, i) + p.p33_2l[i])
                .collect();
            t.push_estimates(&format!("P24_{s}"), POWER, &p.p24);
            t.push_estimates(&format!("P33_{s}"), POWER, &p33);
            t.push_estimates(&format!("P33_2L_{s}"), POWER, &p.p33_2l);
            t.push_estimates(&format!("P2loop_{s}"), POWER, &p.total);
        }
    }
    t.push_estimates("sigma_v2", "(Mpc/h)^2", &vec![one.sigma_v2; r.k.len()]);
    if let (Some(sigma_d2), RealModel::OneLoopRegPt | RealModel::TwoLoopRegPt) =
        (&r.terms.sigma_d2, model)
    {
        t.push_estimates("sigma_d2", "(Mpc/h)^2", sigma_d2);
    }
    if let (Some(g), true) = (&r.terms.gamma2, model.needs_gamma2()) {
        for (pair, v) in g.p24.iter() {
            t.push_estimates(&format!("P24_Gamma2_{}", pair.suffix()), POWER, v);
        }
        for (pair, v) in g.p_gamma2.iter() {
            t.push_estimates(&format!("PGamma2_{}", pair.suffix()), POWER, v);
        }
    }
    if let (Some(ir), true) = (&r.terms.ir, model.needs_ir()) {
        t.push("P_nw", POWER, ir.no_wiggle.one_loop.p_lin.clone());
        t.push_estimates("Sigma2_bao", "(Mpc/h)^2", &vec![ir.sigma2; r.k.len()]);
    }
    if model.is_eft() {
        for c in crate::real::Counterterm::ALL {
            let unit = if c == crate::real::Counterterm::C4 {
                "(Mpc/h)^-1"
            } else {
                "Mpc/h"
            };
            for (pair, v) in r.counterterm_template(c).iter() {
                t.push_estimates(&format!("T_{}_{c}", pair.suffix()), unit, v);
            }
        }
    }
    if let Some(factors) = &r.factors {
        for (pair, f) in factors.iter() {
            t.push_estimates(&format!("N_{}", pair.suffix()), "1", f);
        }
    }
    t
}

/// The multipoles as a table with `header` lines: `k P<l>…`, with the parts `P<l>_sc P<l>_A
/// P<l>_B` if computed, `P_eps SN SN_s` with a noise (SN = b² P_δδ/P_εε, SN_s = P0/P_εε), and the
/// errors `err_P<l>`.
pub fn rsd_multipoles_table(m: &RsdMultipoles, header: Vec<String>) -> Table {
    let mut t = Table::new(header);
    t.push("k", WAVENUMBER, m.k.clone());
    let values = |e: &Vec<Estimate>| e.iter().map(|e| e.value).collect::<Vec<f64>>();
    for (l, p) in m.ells.iter().zip(&m.total) {
        t.push(format!("P{l}"), POWER, values(p));
    }
    if let Some(parts) = &m.parts {
        for (name, part) in ["sc", "A", "B"].into_iter().zip(parts) {
            for (l, p) in m.ells.iter().zip(part) {
                t.push(format!("P{l}_{name}"), POWER, values(p));
            }
        }
    }
    if let (Some(noise), Some(sn), Some(sn_s)) =
        (&m.noise, &m.signal_to_noise, &m.signal_to_noise_s)
    {
        t.push("P_eps", POWER, noise.clone());
        t.push("SN", "1", sn.clone());
        t.push("SN_s", "1", sn_s.clone());
    }
    for (l, p) in m.ells.iter().zip(&m.total) {
        t.push(
            format!("err_P{l}"),
            POWER,
            p.iter().map(|e| e.error).collect(),
        );
    }
    t
}

/// Δχ² surfaces as one table with `header` lines, a row per grid point (i outer, j inner, k_max
/// outermost): `k_max i j <x> <y> chi2 delta_chi2`, then the re-minimised value of each other free
/// parameter of `free`.
pub fn contour_table(contours: &[Contour], free: &[Parameter], header: Vec<String>) -> Table {
    let mut t = Table::new(header);
    let Some(first) = contours.first() else {
        return t;
    };
    let (x, y) = (first.x, first.y);
    let others: Vec<Parameter> = free.iter().copied().filter(|&p| p != x && p != y).collect();
    let rows = || {
        contours.iter().flat_map(|c| {
            (0..c.points.len()).flat_map(move |i| (0..c.points[i].len()).map(move |j| (c, i, j)))
        })
    };
    let column = |f: &dyn Fn(&Contour, usize, usize) -> f64| -> Vec<f64> {
        rows().map(|(c, i, j)| f(c, i, j)).collect()
    };
    t.push("k_max", WAVENUMBER, column(&|c, _, _| c.k_max));
    t.push("i", "1", column(&|_, i, _| i as f64));
    t.push("j", "1", column(&|_, _, j| j as f64));
    t.push(x.name(), x.unit(), column(&|c, i, j| c.points[i][j].0));
    t.push(y.name(), y.unit(), column(&|c, i, j| c.points[i][j].1));
    t.push("chi2", "1", column(&|c, i, j| c.chi2[i][j]));
    t.push(
        "delta_chi2",
        "1",
        column(&|c, i, j| c.chi2[i][j] - c.chi2_min),
    );
    for p in others {
        t.push(p.name(), p.unit(), column(&|c, i, j| c.at[i][j].get(p)));
    }
    t
}

fn values(e: &[Estimate]) -> Vec<f64> {
    e.iter().map(|e| e.value).collect()
}

fn errors(e: &[Estimate]) -> Vec<f64> {
    e.iter().map(|e| e.error).collect()
}
