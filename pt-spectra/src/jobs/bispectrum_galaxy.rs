//! `bispectrum --loop 1` with a bias: the one-loop GALAXY bispectrum at single triangles, in real space
//! or in redshift space at one orientation ([`crate::bispectrum::one_loop_galaxy`]), as a table with its
//! header; and the one place where the faces' bias options become the fourth-order bias basis.

use super::bispectrum::one_loop_columns;
use super::bispectrum::{BISPECTRUM, BISPECTRUM_SHAPE};
use super::VERSION;
use crate::bias::BiasParams;
use crate::bispectrum::bias_kernels::LoopBias;
use crate::bispectrum::galaxy_counterterms::{galaxy_counterterm_shapes, GALAXY_COUNTERTERMS};
use crate::bispectrum::galaxy_counterterms_rsd::{
    redshift_counterterm_multipoles, N_REDSHIFT_CT, REDSHIFT_COUNTERTERMS,
};
use crate::bispectrum::multipole_basis::MultipoleLoopBasis;
use crate::bispectrum::one_loop::{OneLoopRule, PARTITION_POWER};
use crate::bispectrum::one_loop_basis::BispectrumLoopSource;
use crate::bispectrum::one_loop_galaxy::{one_loop_galaxy, OneLoopGalaxy};
use crate::bispectrum::one_loop_galaxy_basis::GalaxyLoopBasis;
use crate::bispectrum::one_loop_galaxy_multipoles::{one_loop_galaxy_multipoles, ORIENTATION_RULE};
use crate::bispectrum::one_loop_ir::{
    galaxy_basis_ir, one_loop_galaxy_ir, one_loop_galaxy_multipoles_ir,
};
use crate::bispectrum::one_loop_rsd::Orientation;
use crate::bispectrum::{IrInputs, LegendreSide};
use crate::error::{Error, Result};
use crate::ir::WiggleSplit;
use crate::output::{MethodNote, Table, POWER, WAVENUMBER};
use crate::precision::TwoLoopMethod;
use crate::progress::Progress;
use crate::setup::Prepared;
use crate::store::TableStore;

/// The coefficients of the fourth-order basis that the faces set by name (`--loop-bias NAME=VALUE`,
/// Python `loop_bias={...}`): those that (b1, b2, bs) and b_Γ3 do not already fix. b1, b2 and g2 are
/// set through the bias of every command (velocileptors' b1, b2, bs, or another convention), whose
/// ESS19 b2 differs from velocileptors' b2: naming them here would be ambiguous.
pub const LOOP_BIAS_NAMES: [&str; 8] = ["b3", "g2x", "g3", "g21", "g21x", "g211", "g22", "g31"];

/// The one-loop bias of the faces' options: `bias` (velocileptors' b1, b2, bs; any convention is
/// converted before) and CLASS-PT's `b_gamma3` give the basis exactly through fourth order
/// ([`LoopBias::from_class_pt`] with b2 + (4/3) bs, b_G2 = bs); each of `overrides` then sets one
/// coefficient of [`LOOP_BIAS_NAMES`] in place of its mapped value.
///
/// # Errors
/// [`Error::InvalidChoice`] for a name not in [`LOOP_BIAS_NAMES`] or given twice;
/// [`Error::InvalidParameter`] for a value that is not finite.
pub fn loop_bias(
    bias: &BiasParams,
    b_gamma3: f64,
    overrides: &[(String, f64)],
) -> Result<LoopBias> {
    let mut values =
        LoopBias::from_class_pt(bias.b1, bias.b2 + 4.0 / 3.0 * bias.bs, bias.bs, b_gamma3).values();
    for (i, (name, value)) in overrides.iter().enumerate() {
        let slot = LOOP_BIAS_NAMES.contains(&name.as_str()).then(|| {
            LoopBias::NAMES
                .iter()
                .position(|n| n == name)
                .expect("every settable name is a coefficient")
        });
        let Some(slot) = slot else {
            return Err(Error::InvalidChoice {
                what: format!("one-loop bias coefficient {name:?}"),
                reason: format!(
                    "valid: {} (b1, b2, g2 = bs come from the bias options)",
                    LOOP_BIAS_NAMES.join(", ")
                ),
            });
        };
        if overrides[..i].iter().any(|(n, _)| n == name) {
            return Err(Error::InvalidChoice {
                what: format!("one-loop bias coefficient {name}"),
                reason: "is given twice".into(),
            });
        }
        values[slot] = *value;
    }
    let out = LoopBias::from_values(values);
    out.check_finite()?;
    Ok(out)
}

/// The table `k1 k2 k3 B_tree B222 B321_I B321_II B411 B_1loop`, their `err_` columns and the
/// amounts subtracted by the renormalisation (`uv_B321_II`, `uv_B411`: the bare terms are the
/// renormalised ones plus these) of the one-loop galaxy bispectrum with `bias` at `triangles`
/// (points), in real space (`redshift` None) or at the growth rate (default f(z)) and orientation of
/// `redshift`, for the linear spectrum of `prepared`, each triangle of a direct evaluation reported to
/// `progress`; in real space also the seven counterterm and stochastic shapes `shape_<name>`
/// ([`crate::bispectrum::galaxy_counterterms`]). The loop terms by `method` in real space: `basis` (the
/// tensors of [`crate::bispectrum::one_loop_galaxy_basis`] from `store`, built once, ~4 s per triangle and
/// core, and cached), `auto` (the tensors if cached) or `direct`; a spectrum the basis does not represent
/// is integrated directly, as the header says. Redshift space is direct. With `ir` the BAO are resummed
/// ([`crate::bispectrum::one_loop_ir`], the split and Σ² of [`one_loop_ir_inputs`]; the tensors then take the
/// resummed spectrum of the loops), as the tree level does by default.
///
/// # Errors
/// As [`one_loop_galaxy`], naming the triangle; [`Error::InvalidChoice`] for `basis` in redshift space.
#[allow(clippy::too_many_arguments)]
pub fn one_loop_galaxy_table(
    prepared: &Prepared,
    triangles: &[[f64; 3]],
    bias: &LoopBias,
    redshift: Option<(Option<f64>, Orientation)>,
    ir: bool,
    rule: &OneLoopRule,
    method: TwoLoopMethod,
    store: &TableStore,
    progress: &dyn Progress,
) -> Result<Table> {
    let redshift = redshift.map(|(f, o)| (f.unwrap_or(prepared.growth_rate), o));
    let ir = ir.then(|| one_loop_ir_inputs(prepared)).transpose()?;
    let (terms, source) = galaxy_terms(
        prepared,
        triangles,
        bias,
        redshift,
        ir.as_ref(),
        rule,
        method,
        store,
        progress,
    )?;
    let mut rows = Vec::with_capacity(triangles.len());
    let mut uv = Vec::with_capacity(triangles.len());
    let mut shapes = Vec::new();
    for (&k, b) in triangles.iter().zip(&terms) {
        rows.push((k, [b.tree, b.b222, b.b321_i, b.b321_ii, b.b411, b.total()]));
        uv.push([b.uv_b321_ii, b.uv_b411]);
        if redshift.is_none() {
            shapes.push(galaxy_counterterm_shapes(&prepared.spectrum, k, bias)?);
        }
    }
    let space = match redshift {
        None => "real space".to_string(),
        Some((f, o)) => format!(
            "redshift space, f = {f}, line of sight at mu1 = {} (cosine to k1), phi = {} rad (azimuth \
             about k1 from the triangle's plane, on the side of k2)",
            o.mu1, o.phi
        ),
    };
    let values: Vec<String> = LoopBias::NAMES
        .iter()
        .zip(bias.values())
        .map(|(n, v)| format!("{n} = {v}"))
        .collect();
    let mut header = vec![
        format!(
            "pt-spectra {VERSION} bispectrum --loop 1: one-loop galaxy bispectrum in {space}, z = {}",
            prepared.z
        ),
        format!(
            "bias (the fourth-order basis of Eggemeier, Scoccimarro & Smith 2019; docs/bispectrum.md): {}",
            values.join(", ")
        ),
        "B_1loop = B_tree + B222 + B321_I + B321_II + B411 with the galaxy kernels K_n (Z_n^g in redshift \
         space) in place of F_n (Z_n); B321_II and B411 renormalised: their q -> infinity constants times \
         sigma^2 = int P over the loop range subtracted (uv_B321_II, uv_B411; bare = renormalised + uv); \
         no orientation average or bins yet"
            .into(),
        ir_line(ir.as_ref()),
        format!(
            "loop integrals over {} <= |q| <= {} h/Mpc about each cusp (smooth partition of unity, power {}); \
             {} ln q x {} cos(theta) x {} phi nodes per panel; err_: difference from the rule with half the \
             nodes",
            rule.q_min, rule.q_max, PARTITION_POWER, rule.radial, rule.mu, rule.phi
        ),
        match source {
            BispectrumLoopSource::DirectUncached => "loop terms: direct integration (method auto: no basis \
                tensors cached for these triangles and rule; method basis builds them once, ~4 s per triangle \
                and core, then ~0.15 ms per triangle)"
                .into(),
            s => s.describe(),
        },
        "at the given triangles (not averaged over bins); linear spectrum: all matter".into(),
    ];
    header.extend(prepared.description.iter().cloned());
    let mut t = Table::new(header);
    t.methods
        .push(MethodNote::new("loop terms", source.method()));
    one_loop_columns(&mut t, &rows);
    for (j, name) in ["uv_B321_II", "uv_B411"].iter().enumerate() {
        t.push(*name, BISPECTRUM, uv.iter().map(|u| u[j]).collect());
    }
    if redshift.is_none() {
        t.header.push(
            "counterterms and stochastic terms not in B_1loop: B_ct = sum_c c_c shape_c, shape_ct_k2 = sum_cyc 2 \
             b1 K2 (ki^2 + kj^2) Pi Pj, shape_ct_k3 = ... 2 b1^2 kl^2 Pi Pj, shape_ct_kk = ... 2 b1^2 (ki^2 + kj^2) \
             Pi Pj, shape_ct_tidal = ... 2 b1^2 kl^2 (mu_ij^2 - 1/3) Pi Pj, shape_ct_f2k3 = ... 2 b1^2 F2 kl^2 Pi Pj \
             (coefficients in (Mpc/h)^2), shape_st_p = sum_a b1^2 Pa ((Mpc/h)^3), shape_st_1 = 1 ((Mpc/h)^6); \
             together they absorb the loops' cut-off (docs/bispectrum.md)"
                .into(),
        );
        for (j, name) in GALAXY_COUNTERTERMS.iter().enumerate() {
            let unit = match j {
                5 => POWER,
                6 => "1",
                _ => BISPECTRUM_SHAPE,
            };
            t.push(
                format!("shape_{name}"),
                unit,
                shapes.iter().map(|s| s[j]).collect(),
            );
        }
    }
    Ok(t)
}

/// The table of the multipoles of the one-loop galaxy bispectrum with `bias` at `triangles` (points) in
/// redshift space at growth rate `f` (default f(z)), the Legendre polynomial on `side`
/// ([`crate::bispectrum::one_loop_galaxy_multipoles`]: one pass over the loop nodes, the orientation rule
/// exact): `k1 k2 k3`, then per ℓ = 0, 2, 4 `B{ℓ}_tree B{ℓ}_222 B{ℓ}_321_I B{ℓ}_321_II B{ℓ}_411 B{ℓ}` (B{ℓ} the
/// one-loop total, as the tree level's column names), their `err_` columns, and the multipoles of the
/// redshift-space counterterm and stochastic shapes `shape_B{ℓ}_<name>`
/// ([`crate::bispectrum::galaxy_counterterms_rsd`]), each triangle reported to `progress`. With `ir` the BAO
/// are resummed ([`crate::bispectrum::one_loop_ir`], the inputs of [`one_loop_ir_inputs`]).
///
/// # Errors
/// As [`crate::bispectrum::one_loop_galaxy_multipoles::one_loop_galaxy_multipoles`], naming the triangle.
#[allow(clippy::too_many_arguments)]
pub fn one_loop_galaxy_multipoles_table(
    prepared: &Prepared,
    triangles: &[[f64; 3]],
    bias: &LoopBias,
    f: Option<f64>,
    side: LegendreSide,
    ir: bool,
    rule: &OneLoopRule,
    (method, store): (TwoLoopMethod, &TableStore),
    progress: &dyn Progress,
) -> Result<Table> {
    let f = f.unwrap_or(prepared.growth_rate);
    let p = &prepared.spectrum;
    let ir = ir.then(|| one_loop_ir_inputs(prepared)).transpose()?;
    let (tensor_rows, source) = multipole_tensor_rows(
        prepared,
        triangles,
        bias,
        f,
        side,
        ir.as_ref(),
        rule,
        method,
        store,
        progress,
    )?;
    let mut rows = Vec::with_capacity(triangles.len());
    let mut shapes = Vec::with_capacity(triangles.len());
    for (i, &k) in triangles.iter().enumerate() {
        let named = |e: Error| Error::InvalidChoice {
            what: format!("triangle {} ({}, {}, {})", i + 1, k[0], k[1], k[2]),
            reason: e.to_string(),
        };
        if tensor_rows.is_none() {
            let m = match &ir {
                None => one_loop_galaxy_multipoles(p, k, f, side, rule, None),
                Some(ir) => one_loop_galaxy_multipoles_ir(p, ir, k, f, side, rule, None),
            }
            .map_err(named)?;
            rows.push(m.evaluate(bias)?);
        }
        shapes.push(redshift_counterterm_multipoles(p, k, bias, f, side).map_err(named)?);
        progress.update(
            crate::bispectrum::seam::ONE_LOOP_STAGE,
            i + 1,
            triangles.len(),
        );
    }
    let values: Vec<String> = LoopBias::NAMES
        .iter()
        .zip(bias.values())
        .map(|(n, v)| format!("{n} = {v}"))
        .collect();
    let (n_mu, n_phi) = ORIENTATION_RULE;
    let mut header = vec![
        format!(
            "pt-spectra {VERSION} bispectrum --loop 1 --multipoles: multipoles B0, B2, B4 (Scoccimarro et al. \
             1999) of the one-loop galaxy bispectrum in redshift space, f = {f}, z = {}",
            prepared.z
        ),
        format!(
            "bias (the fourth-order basis of Eggemeier, Scoccimarro & Smith 2019; docs/bispectrum.md): {}",
            values.join(", ")
        ),
        format!(
            "Legendre polynomial on {}; orientations: Gauss-Legendre in mu1 ({} nodes in (0, 1)) x midpoints in \
             phi ({} in (0, pi)), exact for B(n) L_l (degree <= 16 in n): no orientation error",
            match side {
                LegendreSide::Largest => "the largest side (as the window-free estimator)".to_string(),
                LegendreSide::Index(a) => format!("side k{}", a + 1),
            },
            n_mu,
            n_phi
        ),
        "B{l} = B{l}_tree + B{l}_222 + B{l}_321_I + B{l}_321_II + B{l}_411 with the kernels Z_n^g; B321_II and \
         B411 renormalised (their q -> infinity constants times sigma^2 subtracted); no FoG, AP or bins"
            .into(),
        ir_line(ir.as_ref()),
        format!(
            "loop integrals over {} <= |q| <= {} h/Mpc about each cusp (smooth partition of unity, power {}); \
             {} ln q x {} cos(theta) x {} phi nodes per panel, one pass for all orientations; err_: difference \
             from the rule with half the nodes",
            rule.q_min, rule.q_max, PARTITION_POWER, rule.radial, rule.mu, 2 * rule.phi
        ),
        format!(
            "counterterms and stochastic terms not in B{{l}}: B_ct = sum_c c_c shape_B{{l}}_c, the multipoles of \
             the shapes {} (docs/bispectrum.md; coefficients ct_* in (Mpc/h)^2, st_p* in (Mpc/h)^3, st_1 in \
             (Mpc/h)^6)",
            REDSHIFT_COUNTERTERMS.join(", ")
        ),
        super::bispectrum_multipole_plan::describe_source(&source),
        "at the given triangles (not averaged over bins: --bin-width or --k-edges average them); linear spectrum: all matter".into(),
    ];
    if let Some(r) = tensor_rows {
        rows = r;
    }
    header.extend(prepared.description.iter().cloned());
    let mut t = Table::new(header);
    t.methods
        .push(MethodNote::new("loop terms", source.method()));
    multipole_columns(&mut t, triangles, &rows, &shapes);
    Ok(t)
}

/// The multipoles of `triangles` from the multipole tensors when `method` asks for them (basis: read or
/// built; auto: if cached) and the spectrum (P_LO with `ir`) is represented, with how the loop terms were
/// computed; `None` for the direct path.
#[allow(clippy::too_many_arguments)]
fn multipole_tensor_rows(
    prepared: &Prepared,
    triangles: &[[f64; 3]],
    bias: &LoopBias,
    f: f64,
    side: LegendreSide,
    ir: Option<&IrInputs>,
    rule: &OneLoopRule,
    method: TwoLoopMethod,
    store: &TableStore,
    progress: &dyn Progress,
) -> Result<(Option<Vec<[OneLoopGalaxy; 3]>>, BispectrumLoopSource)> {
    if method == TwoLoopMethod::Direct {
        return Ok((None, BispectrumLoopSource::Direct));
    }
    // the build checks what the direct path checks: name a bad triangle first
    super::bispectrum_multipole_plan::check_triangles(triangles, side, rule)?;
    crate::cosmology::check_growth_rate(f)?;
    let build = |tick: &(dyn Fn(usize, usize) + Sync)| {
        MultipoleLoopBasis::build(triangles, side, rule, tick)
            .expect("triangles, side and rule checked")
    };
    let Some(tensors) =
        store.for_method::<MultipoleLoopBasis>(method, (triangles, side, rule), build, progress)?
    else {
        return Ok((None, BispectrumLoopSource::DirectUncached));
    };
    super::bispectrum_multipole_plan::multipoles_from_tensors(
        &tensors,
        &prepared.spectrum,
        bias,
        f,
        ir,
    )
}

/// The columns of the multipoles' table: `k1 k2 k3` (`triangles`), per ℓ = 0, 2, 4 the terms of `rows`
/// and their `err_`, the counterterm shapes' multipoles `shapes`.
pub(super) fn multipole_columns(
    t: &mut Table,
    triangles: &[[f64; 3]],
    rows: &[[OneLoopGalaxy; 3]],
    shapes: &[[[f64; N_REDSHIFT_CT]; 3]],
) {
    for (i, name) in ["k1", "k2", "k3"].iter().enumerate() {
        t.push(*name, WAVENUMBER, triangles.iter().map(|k| k[i]).collect());
    }
    let terms = |b: &OneLoopGalaxy| [b.tree, b.b222, b.b321_i, b.b321_ii, b.b411, b.total()];
    let suffix = ["_tree", "_222", "_321_I", "_321_II", "_411", ""];
    for err in [false, true] {
        for (l, ell) in [0, 2, 4].iter().enumerate() {
            for (j, s) in suffix.iter().enumerate() {
                let name = format!("{}B{ell}{s}", if err { "err_" } else { "" });
                let column = rows.iter().map(|r| {
                    let e = terms(&r[l])[j];
                    if err {
                        e.error
                    } else {
                        e.value
                    }
                });
                t.push(name, BISPECTRUM, column.collect());
            }
        }
    }
    for (l, ell) in [0, 2, 4].iter().enumerate() {
        for (j, name) in REDSHIFT_COUNTERTERMS.iter().enumerate() {
            let unit = match *name {
                "st_1" => "1",
                n if n.starts_with("st_p") => POWER,
                _ => BISPECTRUM_SHAPE,
            };
            t.push(
                format!("shape_B{ell}_{name}"),
                unit,
                shapes.iter().map(|s| s[l][j]).collect(),
            );
        }
    }
}

/// The IR inputs of the one-loop galaxy bispectrum: the no-wiggle split and Σ², δΣ² of `prepared`'s
/// spectrum, as the tree level computes them ([`IrInputs::split`] with the default q_min).
///
/// # Errors
/// As [`IrInputs::split`].
pub fn one_loop_ir_inputs(prepared: &Prepared) -> Result<IrInputs> {
    IrInputs::split(
        &prepared.spectrum,
        &WiggleSplit::new()?,
        crate::precision::Precision::default().q_min,
    )
}

/// The header line of the IR resummation (on, with its Σ², or off).
pub(super) fn ir_line(ir: Option<&IrInputs>) -> String {
    match ir {
        Some(ir) => crate::bispectrum::one_loop_ir::describe(ir),
        None => "no IR resummation (--no-ir / ir=False): the linear spectrum in every leg and loop"
            .into(),
    }
}

/// The terms of every triangle and how they were computed ([`one_loop_galaxy_table`]).
#[allow(clippy::too_many_arguments)]
fn galaxy_terms(
    prepared: &Prepared,
    triangles: &[[f64; 3]],
    bias: &LoopBias,
    redshift: Option<(f64, Orientation)>,
    ir: Option<&IrInputs>,
    rule: &OneLoopRule,
    method: TwoLoopMethod,
    store: &TableStore,
    progress: &dyn Progress,
) -> Result<(Vec<OneLoopGalaxy>, BispectrumLoopSource)> {
    let name = |i: usize, k: [f64; 3]| format!("triangle {} ({}, {}, {})", i + 1, k[0], k[1], k[2]);
    let mut source = BispectrumLoopSource::Direct;
    if redshift.is_some() {
        if method == TwoLoopMethod::Basis {
            return Err(Error::InvalidChoice {
                what: "the one-loop galaxy bispectrum's basis tensors".into(),
                reason: "are built for real space only (give method direct or auto)".into(),
            });
        }
    } else if method != TwoLoopMethod::Direct {
        // the tensors' build checks what the direct path checks: name a bad triangle first
        for (i, &k) in triangles.iter().enumerate() {
            crate::bispectrum::one_loop::triangle_vectors(k).map_err(|e| Error::InvalidChoice {
                what: name(i, k),
                reason: e.to_string(),
            })?;
        }
        rule.validate()?;
        let build = |tick: &(dyn Fn(usize, usize) + Sync)| {
            GalaxyLoopBasis::build(triangles, rule, tick).expect("triangles and rule checked")
        };
        match store.for_method::<GalaxyLoopBasis>(method, (triangles, rule), build, progress)? {
            None => source = BispectrumLoopSource::DirectUncached,
            Some(tensors) => {
                let (polys, projection) = match ir {
                    None => (
                        tensors.evaluate(&prepared.spectrum),
                        tensors.project(&prepared.spectrum),
                    ),
                    Some(ir) => galaxy_basis_ir(&tensors, &prepared.spectrum, ir)?,
                };
                let max = crate::loops::basis::MAX_RESIDUAL;
                if projection.residual <= max {
                    let terms = polys
                        .iter()
                        .map(|p| p.evaluate(bias))
                        .collect::<Result<Vec<_>>>()?;
                    let functions = projection.coefficients.len();
                    let residual = projection.residual;
                    return Ok((
                        terms,
                        BispectrumLoopSource::Basis {
                            functions,
                            residual,
                        },
                    ));
                }
                source = BispectrumLoopSource::Fallback {
                    residual: projection.residual,
                    max_residual: max,
                };
            }
        }
    }
    let mut terms = Vec::with_capacity(triangles.len());
    for (i, &k) in triangles.iter().enumerate() {
        let b = match ir {
            None => one_loop_galaxy(&prepared.spectrum, k, bias, redshift, rule),
            Some(ir) => one_loop_galaxy_ir(&prepared.spectrum, ir, k, bias, redshift, rule),
        }
        .map_err(|e| Error::InvalidChoice {
            what: name(i, k),
            reason: e.to_string(),
        })?;
        terms.push(b);
        progress.update(
            crate::bispectrum::seam::ONE_LOOP_STAGE,
            i + 1,
            triangles.len(),
        );
    }
    Ok((terms, source))
}

#[cfg(test)]
mod tests {
    use super::{loop_bias, LOOP_BIAS_NAMES};
    use crate::bias::BiasParams;
    use crate::bispectrum::bias_kernels::LoopBias;

    #[test]
    fn the_faces_bias_is_the_velocileptors_map_with_named_coefficients_in_place() {
        let bias = BiasParams {
            b1: 2.0,
            b2: 0.5,
            bs: -0.3,
            b3: 0.0,
        };
        // without b_Γ3 or overrides: the library's map from velocileptors' (b1, b2, bs)
        assert_eq!(
            loop_bias(&bias, 0.0, &[]).unwrap(),
            LoopBias::from_velocileptors(2.0, 0.5, -0.3)
        );
        // each settable name replaces its coefficient and nothing else
        let base = loop_bias(&bias, 0.1, &[]).unwrap().values();
        for name in LOOP_BIAS_NAMES {
            let set = loop_bias(&bias, 0.1, &[(name.to_string(), 7.5)])
                .unwrap()
                .values();
            for (i, (s, b)) in set.iter().zip(base).enumerate() {
                let expected = if LoopBias::NAMES[i] == name { 7.5 } else { b };
                assert_eq!(*s, expected, "{name}: slot {}", LoopBias::NAMES[i]);
            }
        }
        for bad in ["b1", "b2", "g2", "bs", "g4"] {
            let e = loop_bias(&bias, 0.0, &[(bad.to_string(), 1.0)]).unwrap_err();
            assert!(e.to_string().contains("valid: b3, g2x"), "{e}");
        }
        let twice = [("g21".to_string(), 1.0), ("g21".to_string(), 2.0)];
        assert!(loop_bias(&bias, 0.0, &twice).is_err());
        assert!(loop_bias(&bias, f64::NAN, &[]).is_err());
    }
}
