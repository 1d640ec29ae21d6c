//! The one-loop GALAXY bispectrum (issue 50, `bispectrum::one_loop_galaxy`) against the matter terms,
//! its f = 0 limit, the renormalisation of b3, and an independent plain Monte Carlo
//! (tests/data/bispectrum/make_one_loop_galaxy_mc.py).

use pt_spectra::bispectrum::bias_kernels::LoopBias;
use pt_spectra::bispectrum::one_loop::{one_loop_matter, OneLoopRule};
use pt_spectra::bispectrum::one_loop_galaxy::{one_loop_galaxy, OneLoopGalaxy};
use pt_spectra::bispectrum::one_loop_rsd::{one_loop_matter_redshift, Orientation};
use pt_spectra::linear::LinearSpectrum;

use crate::bispectrum_galaxy_kernels::{close, galaxy_bias};

fn small() -> OneLoopRule {
    OneLoopRule {
        radial: 6,
        mu: 12,
        phi: 8,
        ..OneLoopRule::default()
    }
}

/// Non-finite coefficients, a growth rate outside [0, 2] and sides that do not close are errors.
#[test]
fn bad_input_is_an_error() {
    let p = LinearSpectrum::gm2012_z0();
    let bad = LoopBias {
        g22: f64::NAN,
        ..galaxy_bias()
    };
    let e = one_loop_galaxy(&p, [0.1, 0.1, 0.1], &bad, None, &small()).unwrap_err();
    assert!(e.to_string().contains("g22"), "{e}");
    let o = Orientation { mu1: 0.3, phi: 0.0 };
    assert!(one_loop_galaxy(
        &p,
        [0.1, 0.1, 0.1],
        &galaxy_bias(),
        Some((3.0, o)),
        &small()
    )
    .is_err());
    assert!(one_loop_galaxy(&p, [0.1, 0.1, 0.5], &galaxy_bias(), None, &small()).is_err());
}

fn terms(b: &OneLoopGalaxy) -> [pt_spectra::loops::Estimate; 5] {
    [b.tree, b.b222, b.b321_i, b.b321_ii, b.b411]
}

/// b1 = 1 and the others zero: every term is the matter one, in real space and in redshift space (a line
/// of sight out of the triangle's plane); nothing is subtracted.
#[test]
fn matter_coefficients_give_the_matter_terms() {
    let p = LinearSpectrum::gm2012_z0();
    let k = [0.05, 0.1, 0.12];
    let g = one_loop_galaxy(&p, k, &LoopBias::matter(), None, &small()).unwrap();
    let m = one_loop_matter(&p, k, &small()).unwrap();
    let want = [m.tree, m.b222, m.b321_i, m.b321_ii, m.b411];
    for (i, (a, b)) in terms(&g).iter().zip(want).enumerate() {
        assert!(close(a.value, b.value, 1e-12), "real {i}: {a:?} vs {b:?}");
    }
    assert_eq!((g.uv_b321_ii, g.uv_b411), (0.0, 0.0));
    let o = Orientation { mu1: 0.4, phi: 0.7 };
    let g = one_loop_galaxy(&p, k, &LoopBias::matter(), Some((0.7, o)), &small()).unwrap();
    let m = one_loop_matter_redshift(&p, k, 0.7, o, &small()).unwrap();
    let want = [m.tree, m.b222, m.b321_i, m.b321_ii, m.b411];
    let mut worst = 0.0f64;
    for (i, (a, b)) in terms(&g).iter().zip(want).enumerate() {
        let rel = (a.value - b.value).abs() / b.value.abs();
        worst = worst.max(rel);
        assert!(rel < 1e-12, "redshift {i}: {a:?} vs {b:?}");
    }
    eprintln!("redshift space: largest relative difference from the matter terms {worst:.1e}");
}

/// f = 0 in redshift space is the real-space galaxy bispectrum (line of sight in the triangle's plane:
/// the same nodes).
#[test]
fn f_zero_is_the_real_space_galaxy_bispectrum() {
    let p = LinearSpectrum::gm2012_z0();
    let k = [0.02, 0.1, 0.1];
    let real = one_loop_galaxy(&p, k, &galaxy_bias(), None, &small()).unwrap();
    let o = Orientation { mu1: 0.3, phi: 0.0 };
    let rsd = one_loop_galaxy(&p, k, &galaxy_bias(), Some((0.0, o)), &small()).unwrap();
    for (i, (a, b)) in terms(&rsd).iter().zip(terms(&real)).enumerate() {
        assert!(close(a.value, b.value, 1e-12), "{i}: {a:?} vs {b:?}");
    }
}

/// δ³'s contributions to B321-II (a constant kernel) and B411 ((1/12)Σ F₂ over pairs, whose angular
/// average is constant in q) are pure renormalisations: adding b3 to matter leaves the renormalised
/// B321-II and B411 the matter ones to 1e-10 of the amounts subtracted (measured 1e-16 and 4.5e-11: the
/// subtracted 2.3e9 and 9.4e9 (Mpc/h)⁶ cancel the bare parts to round-off), and changes B321-I.
#[test]
fn b3_renormalises_away_from_b321_ii_and_b411() {
    let p = LinearSpectrum::gm2012_z0();
    let k = [0.05, 0.1, 0.12];
    let b = LoopBias {
        b3: 1.0,
        ..LoopBias::matter()
    };
    let g = one_loop_galaxy(&p, k, &b, None, &small()).unwrap();
    let m = one_loop_matter(&p, k, &small()).unwrap();
    let (d_ii, d_411) = (
        g.b321_ii.value - m.b321_ii.value,
        g.b411.value - m.b411.value,
    );
    eprintln!(
        "subtracted {:.3e}, {:.3e}; left {d_ii:.1e}, {d_411:.1e} (B321-II, B411)",
        g.uv_b321_ii, g.uv_b411
    );
    assert!(
        d_ii.abs() <= 1e-10 * g.uv_b321_ii.abs(),
        "{:?} vs {:?}",
        g.b321_ii,
        m.b321_ii
    );
    assert!(
        d_411.abs() <= 1e-10 * g.uv_b411.abs(),
        "{:?} vs {:?}",
        g.b411,
        m.b411
    );
    assert!(
        g.uv_b321_ii.abs() > 1e-2 * m.b321_ii.value.abs(),
        "{}",
        g.uv_b321_ii
    );
    assert!(g.uv_b411.abs() > 1e-2 * m.b411.value.abs(), "{}", g.uv_b411);
    assert!((g.b321_i.value - m.b321_i.value).abs() > 1e-2 * m.b321_i.value.abs());
}

/// CLASS-PT's b_Γ3 (mapped: g21 = −(4/7)b_Γ3, …) changes B321-II by Σ_{a≠b} 6 F₂(k_a, k_b) P_a P_b J_a with
/// J_a = ∫_q K₃^Γ₃(k_a, q, −q) P(q) = −sig3nl(k_a)/P(k_a), the power spectrum's Γ₃ term (bias.rs: its angular
/// average is −3 times sig3nl's), here from `loops::bias::sig3nl_kernel` on a 1-D rule over the same cut:
/// another code path and quadrature for the galaxy kernels' third order, Γ₃'s needing no subtraction
/// (measured 2.5e-5 to 3.7e-5 at three triangles).
#[test]
fn b_gamma3_changes_b321_ii_by_the_power_spectrum_term() {
    let p = LinearSpectrum::gm2012_z0();
    let (xs, ws) = pt_spectra::integrate::legendre_nodes(16);
    let r = OneLoopRule {
        radial: 10,
        mu: 24,
        phi: 16,
        ..OneLoopRule::default()
    };
    // sig3nl(k)/P(k) = k³/(2π²) ∫ dr r² P(kr) A(r) over q_min ≤ kr ≤ q_max, panels in ln r broken at r = 1.
    let s3 = |k: f64| -> f64 {
        let (lo, hi) = ((r.q_min / k).ln(), (r.q_max / k).ln());
        let edges: Vec<f64> = (0..=60)
            .map(|i| lo + (hi - lo) * i as f64 / 60.0)
            .chain([0.0])
            .filter(|x| *x >= lo && *x <= hi)
            .collect();
        let mut e = edges;
        e.sort_by(f64::total_cmp);
        let mut sum = 0.0;
        for w in e.windows(2) {
            let (a, h) = (w[0], 0.5 * (w[1] - w[0]));
            for (x, wx) in xs.iter().zip(&ws) {
                let rr = (a + h * (x + 1.0)).exp();
                sum += wx
                    * h
                    * rr.powi(3)
                    * p.eval(k * rr)
                    * pt_spectra::loops::bias::sig3nl_kernel(rr);
            }
        }
        k.powi(3) / (2.0 * std::f64::consts::PI.powi(2)) * sum
    };
    let b_gamma3 = 0.8;
    for k in [[0.1, 0.1, 0.1], [0.05, 0.1, 0.12], [0.02, 0.1, 0.1]] {
        let g = one_loop_galaxy(
            &p,
            k,
            &LoopBias::from_class_pt(1.0, 0.0, 0.0, b_gamma3),
            None,
            &r,
        )
        .unwrap();
        let m = one_loop_galaxy(&p, k, &LoopBias::matter(), None, &r).unwrap();
        let kv = pt_spectra::bispectrum::one_loop::triangle_vectors(k).unwrap();
        let pk = k.map(|x| p.eval(x));
        let mut want = 0.0;
        for a in 0..3 {
            for b in (0..3).filter(|&b| b != a) {
                let f2 = pt_kernels::kernels(&[kv[a], kv[b]]).unwrap()[0];
                want += 6.0 * f2 * pk[a] * pk[b] * b_gamma3 * (-s3(k[a]));
            }
        }
        let got = g.b321_ii.value - m.b321_ii.value;
        let rel = (got - want).abs() / want.abs();
        eprintln!(
            "{k:?}: ΔB321-II {got:.6e} vs {want:.6e} ({rel:.1e}); subtracted {:.1e}",
            g.uv_b321_ii
        );
        assert!(rel < 2e-4, "{k:?}: {got} vs {want}");
    }
}

/// The subtraction takes out the cut's σ²: moving q_max from 5 to 10 h/Mpc changes the bare B321-II and
/// B411 by far more than the renormalised ones, whose change is the k²/q²-suppressed UV part left to the
/// counterterms (real and redshift space; measured 1.3e-4, 1.3e-4 real and 4.9e-5, 2.9e-4 redshift).
#[test]
fn renormalised_terms_hardly_depend_on_the_cut() {
    let p = LinearSpectrum::gm2012_z0();
    let k = [0.05, 0.1, 0.12];
    let o = Orientation { mu1: 0.4, phi: 0.7 };
    for redshift in [None, Some((0.7, o))] {
        let at = |q_max: f64| {
            let r = OneLoopRule { q_max, ..small() };
            one_loop_galaxy(&p, k, &galaxy_bias(), redshift, &r).unwrap()
        };
        let (a, b) = (at(5.0), at(10.0));
        let ratio = |ren: f64, bare: f64| ren.abs() / bare.abs();
        let ii = ratio(
            b.b321_ii.value - a.b321_ii.value,
            b.bare_b321_ii().value - a.bare_b321_ii().value,
        );
        let four = ratio(
            b.b411.value - a.b411.value,
            b.bare_b411().value - a.bare_b411().value,
        );
        eprintln!(
            "f = {:?}: renormalised/bare change B321-II {ii:.1e}, B411 {four:.1e}",
            redshift.map(|r| r.0)
        );
        assert!(ii < 1e-2 && four < 1e-2, "{ii:e} {four:e}");
    }
}

/// The line of sight of the galaxy Monte Carlo tables and their rows: f, the sides, the tree level, then
/// (value, one-σ error) of B222, B321-I, B321-II, B411 (the last two renormalised); real space (f = 0)
/// first, then f = 0.7.
fn galaxy_monte_carlo() -> (Orientation, Vec<[f64; 13]>) {
    let text = [
        include_str!("../../data/bispectrum/one_loop_galaxy_mc_gm2012_z0_f0.txt"),
        include_str!("../../data/bispectrum/one_loop_galaxy_mc_gm2012_z0_f0.7.txt"),
    ]
    .join("\n");
    let los: Vec<f64> = text
        .lines()
        .find_map(|l| l.split_once("line of sight ").map(|(_, r)| r.to_string()))
        .unwrap()
        .split_whitespace()
        .take(3)
        .map(|x| x.parse().unwrap())
        .collect();
    let orientation = Orientation {
        mu1: los[2],
        phi: los[1].atan2(los[0]),
    };
    let rows = text
        .lines()
        .filter(|l| !l.starts_with('#') && !l.trim().is_empty())
        .map(|l| {
            let v: Vec<f64> = l.split_whitespace().map(|x| x.parse().unwrap()).collect();
            v.try_into().unwrap()
        })
        .collect();
    (orientation, rows)
}

/// The triangles of the matter Monte Carlo table (22, squeezed (0.01, 0.1, 0.1) through equilateral to
/// folded), sorted.
fn matter_monte_carlo_triangles() -> Vec<[f64; 3]> {
    let mut t: Vec<[f64; 3]> = include_str!("../../data/bispectrum/one_loop_mc_gm2012_z0.txt")
        .lines()
        .filter(|l| !l.starts_with('#') && !l.trim().is_empty())
        .map(|l| {
            let v: Vec<f64> = l.split_whitespace().map(|x| x.parse().unwrap()).collect();
            [v[0], v[1], v[2]]
        })
        .collect();
    t.sort_by(|a, b| a.partial_cmp(b).unwrap());
    t
}

/// Every term (B321-II and B411 renormalised) against the independent plain Monte Carlo
/// (make_one_loop_galaxy_mc.py: its own unsymmetrised operator kernels averaged over orderings, its own
/// UV constants, the whole sphere) at the 22 triangles of the matter table, squeezed (0.01, 0.1, 0.1)
/// through equilateral to folded, in real space and at f = 0.7 with a line of sight out of the plane: 176
/// terms. Each within 4σ plus the direct error: for Gaussian pulls P(|pull| > 4) = 6.3e-5, so a correct
/// code fails somewhere among the 176 with probability 1.1% (3.5σ would be 8%). The χ² of all terms, and
/// that of each term over the 44 rows, below n + 4√(2n); the mean pull of each term over its 44 rows (the
/// rows have independent samples) |Σ pull|/√44 ≤ 4, which sees a common offset of a term down to 0.6σ per
/// row — how the renormalised B321-II, whose Monte Carlo errors are 20% to several times its value (the
/// subtraction leaves the kernel's angular fluctuation at large q), is held beyond its loose single
/// pulls (B321-II and B411 of one row share samples: their pulls are correlated). The tree level to 1e-6.
/// A rule of 8 × 16 × 12 nodes per panel (errors ≤ 5e-3 of the tree, far below the Monte Carlo's).
/// Measured: χ² = 177.1 for 176 (75.4 for 88 real, 101.7 for 88 redshift), largest pull 2.40 real, 3.15
/// redshift (B321-I, equilateral 0.1); Σ pull/√44 +0.66, +0.61, −1.63, −1.61 (B222, B321-I, B321-II,
/// B411); 33.5 s for the 44 rows (load 3 on 2 cores), a third of it real space. It fails with B321-I × 1.05
/// (pull 5.9), B411 × 1.1 (11), B321-II × 1.3 (18), g31 × 1.3 (B411's χ² 88.8 > 81.5, Σ pull/√44 = −5.6),
/// g2 × 1.05 (tree). Real space runs in the quick suite, redshift space (two thirds of the time) in the slow
/// checks (`-- --ignored`), each with its own χ² and mean-pull bounds.
#[test]
fn terms_agree_with_an_independent_monte_carlo_in_real_space() {
    compare_with_the_monte_carlo(0.0);
}

/// [`terms_agree_with_an_independent_monte_carlo_in_real_space`] at f = 0.7 (ignored: the slow checks).
#[test]
#[ignore = "slow exhaustive check (20 s): `cargo test --release --workspace -- --ignored`"]
fn terms_agree_with_an_independent_monte_carlo_in_redshift_space() {
    compare_with_the_monte_carlo(0.7);
}

/// The comparison of the two tests above for the rows of growth rate `only`.
fn compare_with_the_monte_carlo(only: f64) {
    let (orientation, rows) = galaxy_monte_carlo();
    let rows: Vec<_> = rows.into_iter().filter(|r| r[0] == only).collect();
    let want = matter_monte_carlo_triangles();
    assert!(want.len() >= 20, "{} matter triangles", want.len());
    let mut got: Vec<[f64; 3]> = rows.iter().map(|r| [r[1], r[2], r[3]]).collect();
    got.sort_by(|a, b| a.partial_cmp(b).unwrap());
    assert_eq!(got, want, "f = {only}: not the matter table's triangles");
    let r = OneLoopRule {
        radial: 8,
        mu: 16,
        phi: 12,
        ..OneLoopRule::default()
    };
    let p = LinearSpectrum::gm2012_z0();
    let names = ["B222", "B321-I", "B321-II", "B411"];
    // Pulls by space (0 real, 1 redshift) and term.
    let mut pulls = [
        [Vec::new(), Vec::new(), Vec::new(), Vec::new()],
        Default::default(),
    ];
    let start = std::time::Instant::now();
    for row in &rows {
        let (f, k) = (row[0], [row[1], row[2], row[3]]);
        let space = usize::from(f > 0.0);
        let redshift = (f > 0.0).then_some((f, orientation));
        let b = one_loop_galaxy(&p, k, &galaxy_bias(), redshift, &r).unwrap();
        assert!(
            close(b.tree.value, row[4], 1e-6),
            "{k:?}: tree {} vs {}",
            b.tree.value,
            row[4]
        );
        let mut line = format!("f = {f}, {k:?}:");
        for (j, t) in terms(&b)[1..].iter().enumerate() {
            let (mc, sigma) = (row[5 + 2 * j], row[6 + 2 * j]);
            let pull = (t.value - mc) / sigma;
            line += &format!(" {} {pull:+.2}", names[j]);
            assert!(
                (t.value - mc).abs() <= 4.0 * sigma + t.error,
                "f = {f}, {k:?} {}: {} ± {} vs {mc} ± {sigma} ({pull:.1} sigma)",
                names[j],
                t.value,
                t.error
            );
            pulls[space][j].push(pull);
        }
        eprintln!("{line}");
    }
    eprintln!(
        "{} rows in {:.1} s",
        rows.len(),
        start.elapsed().as_secs_f64()
    );
    let chi2 = |x: &[f64]| x.iter().map(|p| p * p).sum::<f64>();
    let bound = |n: usize| n as f64 + 4.0 * (2.0 * n as f64).sqrt();
    let (mut all, mut n) = (0.0, 0);
    for (space, by_term) in pulls.iter().enumerate() {
        let flat: Vec<f64> = by_term.iter().flatten().copied().collect();
        let largest = flat.iter().fold(0.0f64, |m, p| m.max(p.abs()));
        eprintln!(
            "{}: chi2 = {:.1} for {} terms ({:.2} per term), largest pull {largest:.2}",
            ["real space", "f = 0.7"][space],
            chi2(&flat),
            flat.len(),
            chi2(&flat) / flat.len() as f64
        );
        all += chi2(&flat);
        n += flat.len();
    }
    for (j, name) in names.iter().enumerate() {
        let x: Vec<f64> = pulls.iter().flat_map(|s| s[j].iter().copied()).collect();
        let mean = x.iter().sum::<f64>() / (x.len() as f64).sqrt();
        eprintln!(
            "{name}: chi2 = {:.1} for {}, sum of pulls / sqrt(n) = {mean:+.2}",
            chi2(&x),
            x.len()
        );
        assert!(
            chi2(&x) < bound(x.len()),
            "{name}: chi2 = {:.1} for {} (bound {:.1})",
            chi2(&x),
            x.len(),
            bound(x.len())
        );
        assert!(
            mean.abs() <= 4.0,
            "{name}: a common offset, mean pull × sqrt(n) = {mean:.2}"
        );
    }
    eprintln!(
        "chi2 = {all:.1} for {n} terms ({:.2} per term)",
        all / n as f64
    );
    assert!(
        all < bound(n),
        "chi2 = {all:.1} for {n} terms (bound {:.1})",
        bound(n)
    );
}

/// Infrared safety of the galaxy terms (the bias operators are Galilean invariant): power added far above
/// the triangle (a bump at q_b ≪ k, as the matter test `long_wavelength_power_cancels_in_the_sum_of_the_loop_terms`)
/// shifts each term by ∝ k²σ_d² times the tree level, and the shifts cancel in the sum down to the (q_b/k)²
/// remainder: a quarter of it when q_b halves. Real space and f = 0.7 out of the plane, every coefficient
/// non-zero. An operator that is not Galilean invariant, or a wrong weight of a term, would leave O(1).
/// G₂(φ₂, φ₁)'s carried fourth order is not seen here (one factor k·q/q² on the legs q, −q pairs to O(1), no
/// 1/q²: without it the figures are 5.5e-3, 3.6e-3, 2.3e-3); `a_long_mode_is_a_uniform_displacement` checks it.
/// Measured: 5.6e-3, 3.6e-3, 2.3e-3 of the largest shift at q_b = 0.001, 1.4e-3, 9.1e-4, 5.7e-4 at 0.0005.
#[test]
fn long_wavelength_power_cancels_in_the_sum_of_the_galaxy_terms() {
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
    let r = OneLoopRule {
        radial: 8,
        mu: 16,
        phi: 12,
        ..OneLoopRule::default()
    };
    let (near, far) = (with_bump(0.001), with_bump(0.0005));
    let o = Orientation { mu1: 0.4, phi: 0.7 };
    for (k, redshift) in [
        ([0.1, 0.1, 0.1], None),
        ([0.05, 0.1, 0.12], None),
        ([0.05, 0.1, 0.12], Some((0.7, o))),
    ] {
        let at = |spectrum: &LinearSpectrum| {
            one_loop_galaxy(spectrum, k, &galaxy_bias(), redshift, &r).unwrap()
        };
        let base = at(&p);
        let ratio = |bumped: &LinearSpectrum| {
            let b = at(bumped);
            let shifts: Vec<f64> = terms(&b)[1..]
                .iter()
                .zip(&terms(&base)[1..])
                .map(|(x, y)| x.value - y.value)
                .collect();
            let largest = shifts.iter().fold(0.0f64, |m, s| m.max(s.abs()));
            eprintln!(
                "{k:?} f = {:?}: shifts {shifts:.3?}, loop {:.3e}",
                redshift.map(|r| r.0),
                base.loop_correction().value
            );
            assert!(
                largest > 0.05 * base.loop_correction().value.abs(),
                "{k:?}: {shifts:?}"
            );
            shifts.iter().sum::<f64>().abs() / largest
        };
        let (r_near, r_far) = (ratio(&near), ratio(&far));
        eprintln!("  sum / largest shift: {r_near:.1e} (q_b = 0.001), {r_far:.1e} (0.0005)");
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

/// The large-scale limits of the galaxy terms, sides λ(1, 1.5, 2), λ = 1e-3 → 5e-4 h/Mpc: the renormalised
/// B411 and B321-II go as k² times the tree level (the subtraction leaves no constant: ratio 4 × the
/// tree's), while B222 and B321-I tend to the shapes of the stochastic terms they renormalise, a constant
/// (b2³∫P³) and Σ_a P(k_a) (b1 b2 ∫P² K₃), as the module docs state (measured ratios 1.004, 0.991,
/// 1.003, 1.001).
#[test]
fn each_galaxy_term_has_its_large_scale_limit() {
    let p = LinearSpectrum::gm2012_z0();
    let r = OneLoopRule {
        radial: 8,
        mu: 16,
        phi: 12,
        ..OneLoopRule::default()
    };
    let at = |lam: f64| {
        one_loop_galaxy(&p, [lam, 1.5 * lam, 2.0 * lam], &galaxy_bias(), None, &r).unwrap()
    };
    let (a, b) = (at(1e-3), at(5e-4));
    let tree = a.tree.value / b.tree.value;
    let sum_p = |lam: f64| p.eval(lam) + p.eval(1.5 * lam) + p.eval(2.0 * lam);
    let checks = [
        (
            "B411 / (4 tree)",
            a.b411.value / b.b411.value / (4.0 * tree),
        ),
        (
            "B321-II / (4 tree)",
            a.b321_ii.value / b.b321_ii.value / (4.0 * tree),
        ),
        ("B222", a.b222.value / b.b222.value),
        (
            "B321-I / ΣP",
            a.b321_i.value / b.b321_i.value / (sum_p(1e-3) / sum_p(5e-4)),
        ),
    ];
    for (name, ratio) in checks {
        eprintln!("{name}: {ratio:.4}");
    }
    for (name, ratio) in checks {
        assert!((ratio - 1.0).abs() < 0.02, "{name}: {ratio}");
    }
}
