//! The one-loop matter bispectrum in real space (issue 50, part 1): the direct integrals of
//! `pt_spectra::bispectrum::one_loop` against an independent plain Monte Carlo of the same integrals
//! (tests/data/bispectrum/make_one_loop_mc.py: its own recursion for the kernels, no partition of unity,
//! no symmetry), against the project's own P13 (B321-II is F2 P P13), under permutations of the sides,
//! and on bad input.

use pt_spectra::bispectrum::one_loop::{one_loop_matter, OneLoopMatter, OneLoopRule};
use pt_spectra::linear::LinearSpectrum;
use pt_spectra::loops::{OneLoopPlan, Pair};
use pt_spectra::precision::Precision;

use crate::support;

/// The rule of the reference: loop momenta 1e-4 ≤ |q| ≤ 10 h/Mpc.
fn rule() -> OneLoopRule {
    OneLoopRule::default()
}

/// Rows of the Monte Carlo table: sides, tree, then (value, one-σ error) of B222, B321-I, B321-II, B411.
fn reference() -> Vec<[f64; 12]> {
    let text = include_str!("../../data/bispectrum/one_loop_mc_gm2012_z0.txt");
    text.lines()
        .filter(|l| !l.starts_with('#') && !l.trim().is_empty())
        .map(|l| {
            let v: Vec<f64> = l.split_whitespace().map(|x| x.parse().unwrap()).collect();
            v.try_into().unwrap()
        })
        .collect()
}

fn terms(b: &OneLoopMatter) -> [pt_spectra::loops::Estimate; 4] {
    [b.b222, b.b321_i, b.b321_ii, b.b411]
}

/// Every term of every triangle (22, squeezed 0.01:0.1:0.1 to equilateral and folded) within 3.5σ of
/// the Monte Carlo plus the direct integrals' own error (largest pull 2.9), and the χ² of all 88 terms
/// plausible (108; B321-II and B411 share samples, so their pulls are correlated); the direct errors
/// (≤ 1.3e-3 of a term, ≤ 1.8e-4 of B) are far below the Monte Carlo's (0.16% to 23% of a term).
#[test]
fn terms_agree_with_an_independent_plain_monte_carlo() {
    let p = LinearSpectrum::gm2012_z0();
    let rows = reference();
    assert!(rows.len() >= 20, "{} triangles", rows.len());
    let (mut chi2, mut n) = (0.0, 0);
    let names = ["B222", "B321-I", "B321-II", "B411"];
    for row in &rows {
        let k = [row[0], row[1], row[2]];
        let b = one_loop_matter(&p, k, &rule()).unwrap();
        assert!(
            (b.tree.value - row[3]).abs() <= 1e-6 * row[3].abs(),
            "{k:?}: tree {} vs {}",
            b.tree.value,
            row[3]
        );
        for (j, t) in terms(&b).iter().enumerate() {
            let (mc, sigma) = (row[4 + 2 * j], row[5 + 2 * j]);
            assert!(
                t.error <= 2e-3 * t.value.abs().max(1e-3 * b.tree.value.abs()),
                "{k:?} {}: direct error {} of {}",
                names[j],
                t.error,
                t.value
            );
            let pull = (t.value - mc) / sigma;
            assert!(
                (t.value - mc).abs() <= 3.5 * sigma + t.error,
                "{k:?} {}: direct {} vs Monte Carlo {mc} ± {sigma} ({pull:.1} sigma)",
                names[j],
                t.value
            );
            chi2 += pull * pull;
            n += 1;
        }
    }
    // χ² of n terms: mean n, σ = √(2n); 4σ above the mean fails (the terms of one triangle share samples).
    let bound = n as f64 + 4.0 * (2.0 * n as f64).sqrt();
    assert!(
        chi2 < bound,
        "chi2 = {chi2:.1} for {n} terms (bound {bound:.1})"
    );
}

/// B321-II = Σ_{a≠b} F2(k_a, k_b) P(k_b) P13(k_a) with the standard P13 = 2 × the paper's (the project's
/// 1-loop plan, an independent quadrature of the same F3 integral), over the same q range.
#[test]
fn b321_ii_is_f2_times_the_one_loop_propagator_term() {
    let p = LinearSpectrum::gm2012_z0();
    let r = rule();
    let precision = Precision::default().with_q_range(r.q_min, r.q_max).unwrap();
    for k in [[0.1, 0.1, 0.1], [0.02, 0.15, 0.16], [0.05, 0.1, 0.12]] {
        let b = one_loop_matter(&p, k, &r).unwrap();
        let mut sorted = k.to_vec();
        sorted.sort_by(f64::total_cmp);
        sorted.dedup();
        let plan = OneLoopPlan::new(&sorted, &precision).unwrap();
        let t = plan.evaluate(&p);
        let p13 = |x: f64| {
            let i = sorted.iter().position(|&s| s == x).unwrap();
            2.0 * t.p13[Pair::DeltaDelta][i].value
        };
        let v = pt_spectra::bispectrum::one_loop::triangle_vectors(k).unwrap();
        let f2 = |a: usize, b: usize| pt_kernels::kernels(&[v[a], v[b]]).unwrap()[0];
        let mut expected = 0.0;
        for a in 0..3 {
            for c in (0..3).filter(|&c| c != a) {
                expected += f2(a, c) * p.eval(k[c]) * p13(k[a]);
            }
        }
        let rel = (b.b321_ii.value - expected).abs() / expected.abs();
        assert!(
            rel < 2e-4,
            "{k:?}: {} vs {expected} ({rel:.1e})",
            b.b321_ii.value
        );
    }
}

/// The bispectrum is a symmetric function of its sides: every term the same (to the rules' errors) for
/// the six orders of a scalene triangle, though B222's partition and the ordered-pair sums see them in
/// a different orientation.
#[test]
fn every_term_is_symmetric_in_the_sides() {
    let p = LinearSpectrum::gm2012_z0();
    let base = one_loop_matter(&p, [0.05, 0.1, 0.12], &rule()).unwrap();
    for k in [[0.1, 0.05, 0.12], [0.12, 0.1, 0.05], [0.05, 0.12, 0.1]] {
        let b = one_loop_matter(&p, k, &rule()).unwrap();
        for (x, y) in terms(&base).iter().zip(terms(&b)) {
            let tol = 2.0 * (x.error + y.error) + 1e-9 * x.value.abs();
            assert!((x.value - y.value).abs() <= tol, "{k:?}: {x:?} vs {y:?}");
        }
        assert!((b.tree.value - base.tree.value).abs() <= 1e-12 * base.tree.value.abs());
    }
}

/// Sides that do not close, non-positive sides and rules without nodes are errors naming the problem.
#[test]
fn bad_triangles_and_rules_are_errors() {
    let p = LinearSpectrum::gm2012_z0();
    let e = one_loop_matter(&p, [0.1, 0.1, 0.3], &rule())
        .unwrap_err()
        .to_string();
    assert!(e.contains("does not close"), "{e}");
    let e = one_loop_matter(&p, [0.1, -0.1, 0.1], &rule())
        .unwrap_err()
        .to_string();
    assert!(e.contains("> 0"), "{e}");
    let bad = OneLoopRule { mu: 1, ..rule() };
    let e = one_loop_matter(&p, [0.1, 0.1, 0.1], &bad)
        .unwrap_err()
        .to_string();
    assert!(e.contains("at least 2 nodes"), "{e}");
    let bad = OneLoopRule {
        q_min: 0.0,
        ..rule()
    };
    assert!(one_loop_matter(&p, [0.1, 0.1, 0.1], &bad).is_err());
}

/// Infrared cancellation: power added on scales much larger than the triangle (a bump at q_b ≪ k, a
/// bulk flow of 1-D variance σ_d² ∝ ∫P dq) moves each loop term by ∝ k²σ_d² times the tree level, and
/// these shifts cancel in the sum (Jain & Bertschinger 1996; Scoccimarro 1997): what is left is the
/// bump's ∫P q² dq, smaller by (q_b/k)². Measured (bump amplitude ∝ q_b⁻³, so that the residual stays
/// and the shifts grow 4× per halving of q_b): the sum is 3.8e-3, 2.1e-3, 7.0e-4 of the largest shift at
/// q_b = 0.001 and a quarter of that at 0.0005. A wrong relative normalisation of the four terms (8, 6,
/// 6, 12), which the Monte Carlo shares, would leave O(1).
#[test]
fn long_wavelength_power_cancels_in_the_sum_of_the_loop_terms() {
    let p = LinearSpectrum::gm2012_z0();
    let (k_nodes, p_nodes) = p.nodes();
    let with_bump = |kb: f64| {
        let amplitude = 4e5 * (0.002 / kb).powi(3);
        let bump = |k: f64| amplitude * (-(k / kb).ln().powi(2) / (2.0 * 0.3f64.powi(2))).exp();
        LinearSpectrum::from_nodes(
            k_nodes.to_vec(),
            k_nodes
                .iter()
                .zip(p_nodes)
                .map(|(&k, &v)| v + bump(k))
                .collect(),
        )
        .unwrap()
    };
    let (near, far) = (with_bump(0.001), with_bump(0.0005));
    for k in [[0.1, 0.1, 0.1], [0.05, 0.1, 0.12], [0.15, 0.2, 0.25]] {
        let base = one_loop_matter(&p, k, &rule()).unwrap();
        let ratio = |bumped: &LinearSpectrum| {
            let b = one_loop_matter(bumped, k, &rule()).unwrap();
            let shifts: Vec<f64> = terms(&b)
                .iter()
                .zip(terms(&base))
                .map(|(x, y)| x.value - y.value)
                .collect();
            let largest = shifts.iter().fold(0.0f64, |m, s| m.max(s.abs()));
            assert!(
                largest > 0.2 * base.loop_correction().value.abs(),
                "{k:?}: {shifts:?}"
            );
            shifts.iter().sum::<f64>().abs() / largest
        };
        let (r_near, r_far) = (ratio(&near), ratio(&far));
        assert!(
            r_near < 1e-2,
            "{k:?}: the shifts cancel to {r_near:.1e} only"
        );
        assert!(
            r_far < 0.35 * r_near,
            "{k:?}: {r_far:.1e} at q_b = 0.0005 vs {r_near:.1e} at 0.001 (expected a quarter)"
        );
    }
}

/// The large-scale limit, sides λ(1, 1.5, 2) with λ = 1e-3 → 5e-4 h/Mpc (P ∝ k^0.95 there): B411 and
/// B321-II go as k² P P (a displacement's k²σ² times the tree: ratio 4 × the tree's, measured within
/// 0.4%), B321-I as k⁴ P (16 × P's ratio), B222 faster still (three F2 of nearly opposite momenta, each
/// ∝ k²), so the one-loop correction vanishes as k² relative to the tree (ratio 3.96).
#[test]
fn each_term_has_its_large_scale_limit() {
    let p = LinearSpectrum::gm2012_z0();
    let at = |lam: f64| one_loop_matter(&p, [lam, 1.5 * lam, 2.0 * lam], &rule()).unwrap();
    let (a, b) = (at(1e-3), at(5e-4));
    let tree = a.tree.value / b.tree.value;
    for (name, x, y) in [("B411", a.b411, b.b411), ("B321-II", a.b321_ii, b.b321_ii)] {
        let r = x.value / y.value / (4.0 * tree);
        assert!(
            (r - 1.0).abs() < 0.02,
            "{name}: ratio {r} of 4 x the tree's"
        );
    }
    let p_ratio = p.eval(1.5e-3) / p.eval(0.75e-3);
    let r = a.b321_i.value / b.b321_i.value / (16.0 * p_ratio);
    assert!((r - 1.0).abs() < 0.05, "B321-I: ratio {r} of 16 x P's");
    let r222 = a.b222.value / b.b222.value;
    let r321 = a.b321_i.value / b.b321_i.value;
    assert!(r222 > 1.4 * r321, "B222 falls by {r222}, B321-I by {r321}");
    let loop_ratio =
        (a.loop_correction().value / a.tree.value) / (b.loop_correction().value / b.tree.value);
    assert!(
        (loop_ratio - 4.0).abs() < 0.15,
        "loop/tree falls by {loop_ratio}, not k^2"
    );
}

/// The counterterms absorb the change of the loop cut-off: moving q_max from 1 to 10 h/Mpc changes the
/// one-loop correction by 1e5–2.4e6 (Mpc/h)⁶ over 16 triangles (squeezed, equilateral, folded, scalene);
/// the least-squares combination of the four shapes of `COUNTERTERMS` (one set of coefficients for all
/// triangles) takes it out to ≤ 1e-2 of the change (measured 3.6e-3), while the first shape alone (the
/// c_s²-type leg counterterm) leaves 55%.
#[test]
#[allow(clippy::needless_range_loop)] // Gauss–Jordan elimination reads best with indices
fn the_counterterms_absorb_the_change_of_the_cut_off() {
    let p = LinearSpectrum::gm2012_z0();
    let triangles = [
        [0.05, 0.05, 0.05],
        [0.1, 0.1, 0.1],
        [0.15, 0.15, 0.15],
        [0.2, 0.2, 0.2],
        [0.02, 0.1, 0.1],
        [0.03, 0.2, 0.2],
        [0.05, 0.05, 0.0999],
        [0.1, 0.1, 0.199],
        [0.05, 0.1, 0.12],
        [0.02, 0.15, 0.16],
        [0.08, 0.1, 0.15],
        [0.04, 0.07, 0.09],
        [0.1, 0.12, 0.18],
        [0.12, 0.15, 0.2],
        [0.05, 0.15, 0.18],
        [0.15, 0.2, 0.25],
    ];
    let mut rows = Vec::new();
    for k in triangles {
        let hi = one_loop_matter(&p, k, &rule()).unwrap();
        let lo = one_loop_matter(
            &p,
            k,
            &OneLoopRule {
                q_max: 1.0,
                ..rule()
            },
        )
        .unwrap();
        let change = hi.loop_correction().value - lo.loop_correction().value;
        assert!(change.abs() > 1e5, "{k:?}: {change}");
        assert_eq!(hi.counterterm_shapes, lo.counterterm_shapes);
        rows.push((change, hi.counterterm_shapes));
    }
    // Least squares in relative terms, by the normal equations of n ≤ 4 unknowns.
    let worst = |n: usize| {
        let mut a = vec![vec![0.0; n + 1]; n];
        for (y, s) in &rows {
            for i in 0..n {
                for j in 0..n {
                    a[i][j] += s[i] * s[j] / (y * y);
                }
                a[i][n] += s[i] * y / (y * y);
            }
        }
        for c in 0..n {
            let pivot = (c..n)
                .max_by(|&x, &y| a[x][c].abs().total_cmp(&a[y][c].abs()))
                .unwrap();
            a.swap(c, pivot);
            for r in 0..n {
                if r != c {
                    let m = a[r][c] / a[c][c];
                    for j in c..=n {
                        a[r][j] -= m * a[c][j];
                    }
                }
            }
        }
        let coef: Vec<f64> = (0..n).map(|i| a[i][n] / a[i][i]).collect();
        rows.iter()
            .map(|(y, s)| (y - (0..n).map(|i| coef[i] * s[i]).sum::<f64>()).abs() / y.abs())
            .fold(0.0f64, f64::max)
    };
    let (one, four) = (worst(1), worst(4));
    assert!(
        four < 1e-2,
        "the four shapes leave {four:.1e} of the change"
    );
    assert!(one > 0.2, "one shape should not suffice ({one:.2})");
}

/// Basis tensors (`bispectrum::one_loop_basis`) against the direct integrals on the same nodes, for
/// CAMB spectra not in the basis's training set (Planck 2018 at z = 0 and 1, three held-out
/// cosmologies of the prior, a flat w0–wa one at z = 1) and the gm2012 spectrum, at the 22 triangles
/// of the Monte Carlo table (squeezed to folded, k ≤ 0.3): each term within its reported error of
/// direct and the one-loop B within 1e-3 of itself; the cache file reads back the same tensors; an
/// Eisenstein–Hu spectrum (outside the span of CAMB spectra) is evaluated directly, and says so.
/// The comparison is node for node, so a rule with fewer nodes than the default tests the same
/// thing.
#[test]
fn basis_terms_match_the_direct_integrals_for_spectra_not_in_the_training_set() {
    use pt_spectra::bispectrum::one_loop_basis::{
        BispectrumLoopSource, OneLoopMatterBasis, OneLoopMatterPlan,
    };
    use pt_spectra::cosmology::{Cosmology, TransferKind};
    use pt_spectra::linear::LogGrid;
    use pt_spectra::progress::Silent;
    use pt_spectra::store::TableStore;
    let rule = OneLoopRule {
        radial: 6,
        mu: 12,
        phi: 8,
        ..rule()
    };
    let triangles: Vec<[f64; 3]> = reference().iter().map(|r| [r[0], r[1], r[2]]).collect();
    let dir = std::path::Path::new(env!("CARGO_TARGET_TMPDIR")).join("one_loop_bispectrum_basis");
    let _ = std::fs::remove_dir_all(&dir);
    let start = std::time::Instant::now();
    let build = |tick: &(dyn Fn(usize, usize) + Sync)| {
        OneLoopMatterBasis::build(&triangles, &rule, tick).unwrap()
    };
    let tensors = TableStore::new(&dir)
        .tensors::<OneLoopMatterBasis>((&triangles, &rule), build, &Silent)
        .unwrap();
    eprintln!(
        "tensors of {} triangles: {:.1} s",
        triangles.len(),
        start.elapsed().as_secs_f64()
    );
    let again = TableStore::new(&dir)
        .cached::<OneLoopMatterBasis>((&triangles, &rule), &Silent)
        .unwrap();
    assert!(*again == *tensors, "the cache file reads back the tensors");
    assert!(TableStore::new(&dir)
        .cached::<OneLoopMatterBasis>((&triangles[1..], &rule), &Silent)
        .is_none());
    let direct = OneLoopMatterPlan::new(triangles.clone(), rule).unwrap();
    let plan = direct.clone().with_basis(tensors.clone()).unwrap();
    // Tensors of other triangles or another rule are refused.
    let other = OneLoopMatterPlan::new(triangles[1..].to_vec(), rule).unwrap();
    assert!(other.with_basis(tensors.clone()).is_err());
    let camb =
        |name: &str| LinearSpectrum::parse(&support::data(name), name, Default::default()).unwrap();
    let mut spectra = vec![
        ("planck2018 z=0", camb("linear_pk_planck2018_z0.0.dat")),
        ("planck2018 z=1", camb("linear_pk_planck2018_z1.0.dat")),
        ("gm2012 z=0", LinearSpectrum::gm2012_z0()),
        ("flat w0-wa z=1", camb("linear_pk_camb_w0wa_z1.0.dat")),
    ];
    for i in 0..3 {
        spectra.push(("held-out", camb(&format!("linear_pk_camb_heldout_{i}.dat"))));
    }
    let (mut worst_total, mut worst_term): (f64, f64) = (0.0, 0.0);
    for (name, p) in &spectra {
        let (b, source) = plan.evaluate(p).unwrap();
        assert!(
            matches!(source, BispectrumLoopSource::Basis { .. }),
            "{name}: {source:?}"
        );
        let (d, _) = direct.evaluate(p).unwrap();
        for (x, y) in b.iter().zip(&d) {
            let at = format!("{name} {:?}", x.k);
            assert_eq!(x.tree, y.tree, "{at}");
            for (j, (s, t)) in terms(x).iter().zip(terms(y)).enumerate() {
                let diff = (s.value - t.value).abs();
                assert!(
                    diff <= s.error,
                    "{at} term {j}: {} vs {} (error {:.2e})",
                    s.value,
                    t.value,
                    s.error
                );
                worst_term = worst_term.max(diff / t.value.abs());
            }
            let total = y.total().value;
            let rel = (x.total().value - total).abs() / total.abs();
            assert!(
                rel <= 1e-3,
                "{at}: one-loop B {} vs {total} ({rel:.1e})",
                x.total().value
            );
            worst_total = worst_total.max(rel);
        }
    }
    eprintln!(
        "basis vs direct: one-loop B within {worst_total:.1e}, each term within {worst_term:.1e}"
    );
    let eh = Cosmology::planck2018()
        .eisenstein_hu_spectrum(TransferKind::Wiggle, 0.0, &LogGrid::default())
        .unwrap();
    let (_, source) = plan.evaluate(&eh).unwrap();
    assert!(
        matches!(source, BispectrumLoopSource::Fallback { .. }),
        "{source:?}"
    );
    assert!(
        source.describe().contains("direct integration"),
        "{}",
        source.describe()
    );
}

mod redshift {
    //! The one-loop matter bispectrum in redshift space (`bispectrum::one_loop_rsd`).
    use super::*;
    use pt_spectra::bispectrum::one_loop_rsd::{
        one_loop_matter_redshift, OneLoopRedshift, Orientation,
    };

    fn small() -> OneLoopRule {
        OneLoopRule {
            radial: 6,
            mu: 12,
            phi: 8,
            ..rule()
        }
    }

    fn rsd_terms(b: &OneLoopRedshift) -> [pt_spectra::loops::Estimate; 4] {
        [b.b222, b.b321_i, b.b321_ii, b.b411]
    }

    fn at(k: [f64; 3], f: f64, mu1: f64, phi: f64, r: &OneLoopRule) -> OneLoopRedshift {
        let p = LinearSpectrum::gm2012_z0();
        one_loop_matter_redshift(&p, k, f, Orientation { mu1, phi }, r).unwrap()
    }

    /// At f = 0 every term is the real-space one: to round-off with the line of sight in the
    /// triangle's plane (the same nodes), within the errors off it (φ over the whole circle).
    #[test]
    fn f_zero_is_real_space() {
        let p = LinearSpectrum::gm2012_z0();
        for k in [[0.1, 0.1, 0.1], [0.02, 0.15, 0.16], [0.05, 0.1, 0.12]] {
            let real = one_loop_matter(&p, k, &small()).unwrap();
            let same = at(k, 0.0, 0.3, 0.0, &small());
            let off = at(k, 0.0, 0.3, 1.0, &small());
            assert_eq!(same.tree.value, real.tree.value, "{k:?}");
            for ((s, o), r) in rsd_terms(&same)
                .iter()
                .zip(rsd_terms(&off))
                .zip(terms(&real))
            {
                assert!(
                    (s.value - r.value).abs() <= 1e-12 * r.value.abs(),
                    "{k:?}: {s:?} vs {r:?}"
                );
                let tol = o.error + r.error;
                assert!((o.value - r.value).abs() <= tol, "{k:?}: {o:?} vs {r:?}");
            }
        }
    }

    /// The tree level against the closed form of Z₂ (Scoccimarro, Couchman & Frieman 1999, eq. 11),
    /// written out here.
    #[test]
    fn tree_level_is_the_closed_form() {
        let p = LinearSpectrum::gm2012_z0();
        let (f, mu1, phi): (f64, f64, f64) = (0.7, 0.4, 0.9);
        for k in [[0.1, 0.1, 0.1], [0.02, 0.15, 0.16], [0.05, 0.1, 0.12]] {
            let v = pt_spectra::bispectrum::one_loop::triangle_vectors(k).unwrap();
            let s = (1.0 - mu1 * mu1).sqrt();
            let n = [s * phi.cos(), s * phi.sin(), mu1];
            let dot = |a: [f64; 3], b: [f64; 3]| a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
            let mu = |a: [f64; 3]| dot(a, n) / dot(a, a).sqrt();
            let z2 = |a: [f64; 3], b: [f64; 3]| {
                let (ka, kb) = (dot(a, a).sqrt(), dot(b, b).sqrt());
                let c = dot(a, b) / (ka * kb);
                let f2 = 5.0 / 7.0 + 0.5 * c * (ka / kb + kb / ka) + 2.0 / 7.0 * c * c;
                let g2 = 3.0 / 7.0 + 0.5 * c * (ka / kb + kb / ka) + 4.0 / 7.0 * c * c;
                let t = [a[0] + b[0], a[1] + b[1], a[2] + b[2]];
                let (kt, mt) = (dot(t, t).sqrt(), mu(t));
                f2 + f * mt * mt * g2
                    + 0.5
                        * f
                        * mt
                        * kt
                        * (mu(a) / ka * (1.0 + f * mu(b) * mu(b))
                            + mu(b) / kb * (1.0 + f * mu(a) * mu(a)))
            };
            let z1 = |a: [f64; 3]| 1.0 + f * mu(a) * mu(a);
            let mut closed = 0.0;
            for (a, b) in [(0, 1), (1, 2), (2, 0)] {
                closed += 2.0 * z2(v[a], v[b]) * z1(v[a]) * z1(v[b]) * p.eval(k[a]) * p.eval(k[b]);
            }
            let b = at(k, f, mu1, phi, &small());
            assert!(
                (b.tree.value - closed).abs() <= 1e-12 * closed.abs(),
                "{k:?}: {} vs {closed}",
                b.tree.value
            );
        }
    }

    /// Z_n is even in the line of sight, and the triangle's plane mirrors φ: B(μ₁, φ) = B(−μ₁, φ + π) =
    /// B(μ₁, −φ) to round-off (the same nodes); and a line of sight in the plane (the half-circle rule)
    /// agrees with one 1e-9 off it (the whole circle) within the errors.
    #[test]
    fn symmetries_of_the_orientation() {
        let k = [0.05, 0.1, 0.12];
        let base = at(k, 0.8, 0.4, 0.7, &small());
        let flipped = at(k, 0.8, -0.4, 0.7 + std::f64::consts::PI, &small());
        let mirrored = at(k, 0.8, 0.4, -0.7, &small());
        for other in [flipped, mirrored] {
            for (x, y) in rsd_terms(&base).iter().zip(rsd_terms(&other)) {
                assert!(
                    (x.value - y.value).abs() <= 1e-9 * x.value.abs(),
                    "{x:?} vs {y:?}"
                );
            }
        }
        let plane = at(k, 0.8, 0.4, 0.0, &small());
        let near = at(k, 0.8, 0.4, 1e-9, &small());
        for (x, y) in rsd_terms(&plane).iter().zip(rsd_terms(&near)) {
            assert!(
                (x.value - y.value).abs() <= x.error + y.error,
                "{x:?} vs {y:?}"
            );
        }
    }

    /// Every term of the 12 triangles of the independent Monte Carlo in redshift space
    /// (tests/data/bispectrum/make_one_loop_rsd_mc.py: its own Z_n from the mapping, plain Monte
    /// Carlo over the whole sphere; f = 0.7, a line of sight out of the triangle's plane) within
    /// 3.5σ of it plus the direct error, the tree level to 1e-6, and the χ² of the 48 terms plausible.
    /// A rule of 10 × 24 × 16 nodes per panel (its errors ≤ 2e-3 of a term, below the Monte Carlo's).
    #[test]
    fn terms_agree_with_an_independent_monte_carlo_in_redshift_space() {
        let text = include_str!("../../data/bispectrum/one_loop_rsd_mc_gm2012_z0.txt");
        let header = |key: &str| {
            text.lines()
                .find_map(|l| l.split_once(key).map(|(_, rest)| rest.to_string()))
                .unwrap_or_else(|| panic!("no `{key}` in the table's header"))
        };
        let f: f64 = header("# f = ")
            .split(';')
            .next()
            .unwrap()
            .trim()
            .parse()
            .unwrap();
        let los: Vec<f64> = header("line of sight ")
            .split_whitespace()
            .take(3)
            .map(|x| x.parse().unwrap())
            .collect();
        let orientation = Orientation {
            mu1: los[2],
            phi: los[1].atan2(los[0]),
        };
        let rows: Vec<Vec<f64>> = text
            .lines()
            .filter(|l| !l.starts_with('#') && !l.trim().is_empty())
            .map(|l| l.split_whitespace().map(|x| x.parse().unwrap()).collect())
            .collect();
        assert!(rows.len() >= 12, "{} triangles", rows.len());
        let r = OneLoopRule {
            radial: 10,
            mu: 24,
            phi: 16,
            ..rule()
        };
        let p = LinearSpectrum::gm2012_z0();
        let (mut chi2, mut n, mut largest) = (0.0, 0, 0.0f64);
        for row in &rows {
            let k = [row[0], row[1], row[2]];
            let b = one_loop_matter_redshift(&p, k, f, orientation, &r).unwrap();
            assert!(
                (b.tree.value - row[3]).abs() <= 1e-6 * row[3].abs(),
                "{k:?}: tree {} vs {}",
                b.tree.value,
                row[3]
            );
            for (j, t) in rsd_terms(&b).iter().enumerate() {
                let (mc, sigma) = (row[4 + 2 * j], row[5 + 2 * j]);
                assert!(
                    t.error <= 2e-3 * t.value.abs().max(1e-3 * b.tree.value.abs()),
                    "{k:?} term {j}: error {:?}",
                    t
                );
                let pull = (t.value - mc) / sigma;
                assert!(
                    (t.value - mc).abs() <= 3.5 * sigma + t.error,
                    "{k:?} term {j}: {} vs {mc} ± {sigma} ({pull:.1} sigma)",
                    t.value
                );
                chi2 += pull * pull;
                largest = largest.max(pull.abs());
                n += 1;
            }
        }
        eprintln!("chi2 = {chi2:.1} for {n} terms, largest pull {largest:.2}");
        let bound = n as f64 + 4.0 * (2.0 * n as f64).sqrt();
        assert!(
            chi2 < bound,
            "chi2 = {chi2:.1} for {n} terms (bound {bound:.1})"
        );
    }

    /// Bad growth rates and orientations are errors naming the parameter.
    #[test]
    fn bad_f_and_orientation_are_errors() {
        let p = LinearSpectrum::gm2012_z0();
        let k = [0.1, 0.1, 0.1];
        let o = |mu1, phi| Orientation { mu1, phi };
        let e = one_loop_matter_redshift(&p, k, -0.1, o(0.0, 0.0), &small()).unwrap_err();
        assert!(e.to_string().contains("f"), "{e}");
        let e = one_loop_matter_redshift(&p, k, 0.7, o(1.5, 0.0), &small()).unwrap_err();
        assert!(e.to_string().contains("mu1"), "{e}");
        let e = one_loop_matter_redshift(&p, k, 0.7, o(0.5, f64::NAN), &small()).unwrap_err();
        assert!(e.to_string().contains("phi"), "{e}");
    }
}
