mod fits;
mod forecast;
mod loop_fits;

use super::terms::tree_level_at;
use super::*;
use crate::estimate::Estimate;
use crate::linear::LinearSpectrum;
use crate::survey::legendre;

fn spectrum() -> LinearSpectrum {
    LinearSpectrum::gm2012(0.5).unwrap()
}

fn settings(f: f64) -> Settings {
    Settings {
        f,
        q_par: 1.0,
        q_perp: 1.0,
        fog: Fog::None,
        ir: false,
    }
}

/// A galaxy sample's parameters with every slot non-zero (shared by the lanes' test).
pub(super) fn galaxy() -> BispectrumParams {
    BispectrumParams {
        b1: 2.1,
        b2: 0.7,
        bs: -0.31,
        c1: 3.0,
        b_shot: 0.8,
        p_shot: 0.2,
        a_shot: -0.1,
        n_bar: 3e-4,
    }
}

fn shape_vectors(k: [f64; 3]) -> [[f64; 3]; 3] {
    // k0 along a tilted axis, k1 in a tilted plane, k2 = −k0 − k1 (not the plan's frame)
    let cos01 = (k[2] * k[2] - k[0] * k[0] - k[1] * k[1]) / (2.0 * k[0] * k[1]);
    let sin01 = (1.0 - cos01 * cos01).max(0.0).sqrt();
    let e1 = [0.6, 0.0, 0.8];
    let e2 = [0.0, 1.0, 0.0];
    let k0 = e1.map(|x| k[0] * x);
    let k1 = [0, 1, 2].map(|i| k[1] * (cos01 * e1[i] + sin01 * e2[i]));
    let k2 = [0, 1, 2].map(|i| -k0[i] - k1[i]);
    [k0, k1, k2]
}

/// B0, B2, B4 of the one triangle or bin of `set` with the Legendre polynomial on `side`.
fn first_multipoles(
    set: TriangleSet,
    side: LegendreSide,
    p_lin: &LinearSpectrum,
    s: &Settings,
    b: &BispectrumParams,
) -> [Estimate; 3] {
    BispectrumPlan::new(set, side, PlanRules::default())
        .unwrap()
        .terms(p_lin, s)
        .unwrap()
        .multipoles(b)
        .unwrap()[0]
}

const TRIANGLES: [[f64; 3]; 4] = [
    [0.05, 0.05, 0.05],
    [0.02, 0.1, 0.11],
    [0.04, 0.07, 0.1],
    [0.03, 0.06, 0.09],
];

#[test]
fn matter_kernels_are_the_exact_redshift_space_kernels() {
    let f = 0.77;
    let los = [0.3, -0.4, 1.1];
    let p = [1.0, 1.0, 1.0];
    for t in TRIANGLES {
        let v = shape_vectors(t);
        let mut expected = 0.0;
        for i in 0..3 {
            let j = (i + 1) % 3;
            let z1 = |q: [f64; 3]| pt_kernels::redshift::redshift_kernel(&[q], &f, &los).unwrap();
            let z2 = pt_kernels::redshift::redshift_kernel(&[v[i], v[j]], &f, &los).unwrap();
            expected += 2.0 * z1(v[i]) * z1(v[j]) * z2 * p[i] * p[j];
        }
        let got = tree_level_at(v, los, p, f, &BispectrumParams::default());
        assert!(
            (got / expected - 1.0).abs() < 1e-12,
            "{t:?}: {got} vs {expected}"
        );
    }
}

#[test]
fn real_space_limit_is_the_closed_form_with_b2_and_bs() {
    let p_lin = spectrum();
    let b = BispectrumParams {
        c1: 0.0,
        n_bar: f64::INFINITY,
        ..galaxy()
    };
    let plan = BispectrumPlan::new(
        TriangleSet::points(TRIANGLES.to_vec()).unwrap(),
        LegendreSide::Largest,
        PlanRules::default(),
    )
    .unwrap();
    let b_l = plan
        .terms(&p_lin, &settings(0.0))
        .unwrap()
        .multipoles(&b)
        .unwrap();
    for (t, b_l) in TRIANGLES.iter().zip(b_l) {
        let mut closed = 0.0;
        for i in 0..3 {
            let j = (i + 1) % 3;
            let l = (i + 2) % 3;
            let cos = (t[l] * t[l] - t[i] * t[i] - t[j] * t[j]) / (2.0 * t[i] * t[j]);
            let f2 = 5.0 / 7.0 + 0.5 * cos * (t[i] / t[j] + t[j] / t[i]) + 2.0 / 7.0 * cos * cos;
            let z2 = b.b1 * f2 + 0.5 * b.b2 + b.bs * (cos * cos - 1.0 / 3.0);
            closed += 2.0 * b.b1 * b.b1 * z2 * p_lin.eval(t[i]) * p_lin.eval(t[j]);
        }
        assert!((b_l[0].value / closed - 1.0).abs() < 1e-12, "{t:?}");
        assert!(b_l[1].value.abs() < 1e-12 * closed && b_l[2].value.abs() < 1e-12 * closed);
    }
}

/// B_ℓ by brute force: a 60 × 120 product rule over the whole sphere of lines of sight, in a frame
/// other than the plan's, with FoG and shot noise, the Legendre polynomial on the largest side.
fn brute_force_multipoles(
    t: [f64; 3],
    p_lin: &LinearSpectrum,
    f: f64,
    fog: Fog,
    b: &BispectrumParams,
) -> [f64; 3] {
    let v = shape_vectors(t);
    let p = t.map(|k| p_lin.eval(k));
    let (x, w) = crate::integrate::legendre_nodes(60);
    let n_phi = 120;
    let mut out = [0.0; 3];
    for (&c, &w) in x.iter().zip(&w) {
        let s = (1.0 - c * c).sqrt();
        for m in 0..n_phi {
            let phi = 2.0 * std::f64::consts::PI * m as f64 / n_phi as f64;
            let los = [s * phi.cos(), s * phi.sin(), c];
            let par: Vec<f64> = v
                .iter()
                .map(|v| v[0] * los[0] + v[1] * los[1] + v[2] * los[2])
                .collect();
            let x2: f64 = par.iter().map(|p| p * p).sum();
            let with_shot = tree_level_at(v, los, p, f, b);
            let constant = (1.0 + b.a_shot) / (b.n_bar * b.n_bar);
            let value = fog.factor(x2) * (with_shot - constant) + constant;
            let mu = par[2] / t[2];
            for (l, o) in ELLS.iter().zip(&mut out) {
                *o += (2 * l + 1) as f64 * legendre(*l, mu) * value * 0.5 * w / n_phi as f64;
            }
        }
    }
    out
}

#[test]
fn multipoles_match_a_brute_force_average_over_the_sphere() {
    let p_lin = spectrum();
    let f = 0.74;
    let b = galaxy();
    for fog in [
        Fog::None,
        Fog::Lorentzian { sigma: 4.0 },
        Fog::Gaussian { sigma: 6.0 },
    ] {
        let plan = BispectrumPlan::new(
            TriangleSet::points(TRIANGLES.to_vec()).unwrap(),
            LegendreSide::Largest,
            PlanRules::default(),
        )
        .unwrap();
        let s = Settings { fog, ..settings(f) };
        let got = plan.terms(&p_lin, &s).unwrap().multipoles(&b).unwrap();
        for (t, got) in TRIANGLES.iter().zip(got) {
            let want = brute_force_multipoles(*t, &p_lin, f, fog, &b);
            for l in 0..3 {
                let diff = (got[l].value - want[l]).abs();
                let scale = want[0].abs();
                assert!(
                    diff < 1e-9 * scale + 2.0 * got[l].error,
                    "{fog:?} {t:?} ℓ{}: {} vs {} (±{})",
                    ELLS[l],
                    got[l].value,
                    want[l],
                    got[l].error
                );
                assert!(
                    got[l].error < 1e-4 * scale,
                    "{fog:?} {t:?}: error {}",
                    got[l].error
                );
            }
        }
    }
}

#[test]
fn poisson_shot_noise_is_the_galaxy_power_over_n_bar_plus_one_over_n_bar_squared() {
    let t = [0.04, 0.07, 0.1];
    let v = shape_vectors(t);
    let los = [0.2, 0.5, -0.7];
    let p = [2e4, 1.5e4, 1.1e4];
    let f = 0.7;
    let b = BispectrumParams {
        b1: 1.9,
        n_bar: 2e-4,
        ..BispectrumParams::default()
    };
    let shot = tree_level_at(v, los, p, f, &b)
        - tree_level_at(
            v,
            los,
            p,
            f,
            &BispectrumParams {
                n_bar: f64::INFINITY,
                ..b
            },
        );
    let n = (los[0] * los[0] + los[1] * los[1] + los[2] * los[2]).sqrt();
    let mut expected = 1.0 / (b.n_bar * b.n_bar);
    for i in 0..3 {
        let mu = (v[i][0] * los[0] + v[i][1] * los[1] + v[i][2] * los[2]) / (n * t[i]);
        let z1 = b.b1 + f * mu * mu;
        expected += z1 * z1 * p[i] / b.n_bar;
    }
    assert!((shot / expected - 1.0).abs() < 1e-12);
}

#[test]
fn an_isotropic_dilation_rescales_k_and_the_volume() {
    let p_lin = spectrum();
    let alpha: f64 = 1.07;
    let b = galaxy();
    let s = Settings {
        fog: Fog::Lorentzian { sigma: 3.0 },
        ir: true,
        ..settings(0.75)
    };
    let observed = TriangleSet::points(TRIANGLES.to_vec()).unwrap();
    let truth =
        TriangleSet::points(TRIANGLES.iter().map(|t| t.map(|k| k / alpha)).collect()).unwrap();
    let plan = |set| BispectrumPlan::new(set, LegendreSide::Largest, PlanRules::default()).unwrap();
    let dilated = plan(observed.clone())
        .terms(
            &p_lin,
            &Settings {
                q_par: alpha,
                q_perp: alpha,
                ..s
            },
        )
        .unwrap()
        .multipoles(&b)
        .unwrap();
    let identity = plan(observed)
        .terms(
            &p_lin,
            &Settings {
                q_par: 1.0,
                q_perp: 1.0,
                ..s
            },
        )
        .unwrap();
    let direct = plan(truth)
        .terms(&p_lin, &s)
        .unwrap()
        .multipoles(&b)
        .unwrap();
    let unscaled = identity.multipoles(&b).unwrap();
    for ((d, t), u) in dilated.iter().zip(&direct).zip(&unscaled) {
        for l in 0..3 {
            let want = t[l].value / alpha.powi(6);
            assert!(
                (d[l].value - want).abs() < 1e-10 * t[0].value.abs(),
                "{} vs {want}",
                d[l].value
            );
        }
        assert!(
            (u[0].value - d[0].value).abs() > 1e-3 * u[0].value.abs(),
            "AP must change B"
        );
    }
}

#[test]
fn an_anisotropic_dilation_is_the_brute_force_in_the_true_frame() {
    // one triangle, q∥ ≠ q⊥: the plan against sides mapped to the true frame and averaged by brute force
    let p_lin = spectrum();
    let (qp, qt) = (1.05, 0.97);
    let t = [0.04, 0.07, 0.1];
    let f = 0.7;
    let b = BispectrumParams {
        n_bar: f64::INFINITY,
        c1: 0.0,
        ..galaxy()
    };
    let plan = BispectrumPlan::new(
        TriangleSet::points(vec![t]).unwrap(),
        LegendreSide::Largest,
        PlanRules {
            n_shell: 1,
            n_mu: 24,
            n_phi: 48,
            effective: false,
        },
    )
    .unwrap();
    let got = plan
        .terms(
            &p_lin,
            &Settings {
                q_par: qp,
                q_perp: qt,
                ..settings(f)
            },
        )
        .unwrap()
        .multipoles(&b)
        .unwrap()[0];
    let v = shape_vectors(t);
    let (x, w) = crate::integrate::legendre_nodes(60);
    let n_phi = 120;
    let mut want = [0.0; 3];
    for (&c, &w) in x.iter().zip(&w) {
        let s = (1.0 - c * c).sqrt();
        for m in 0..n_phi {
            let phi = 2.0 * std::f64::consts::PI * m as f64 / n_phi as f64;
            let los = [s * phi.cos(), s * phi.sin(), c];
            let true_sides = v.map(|v| {
                let par = v[0] * los[0] + v[1] * los[1] + v[2] * los[2];
                [0, 1, 2].map(|i| (v[i] - par * los[i]) / qt + par * los[i] / qp)
            });
            let p =
                true_sides.map(|s| p_lin.eval((s[0] * s[0] + s[1] * s[1] + s[2] * s[2]).sqrt()));
            let value = tree_level_at(true_sides, los, p, f, &b) / (qp * qp * qt.powi(4));
            let mu = (v[2][0] * los[0] + v[2][1] * los[1] + v[2][2] * los[2]) / t[2];
            for (l, o) in ELLS.iter().zip(&mut want) {
                *o += (2 * l + 1) as f64 * legendre(*l, mu) * value * 0.5 * w / n_phi as f64;
            }
        }
    }
    for l in 0..3 {
        assert!(
            (got[l].value - want[l]).abs() < 1e-8 * want[0].abs(),
            "ℓ{}: {} vs {}",
            ELLS[l],
            got[l].value,
            want[l]
        );
    }
}

#[test]
fn bin_averages_converge_to_a_fine_rule_within_their_error() {
    let p_lin = spectrum();
    let centres = vec![
        [0.015, 0.015, 0.025],
        [0.015, 0.055, 0.065],
        [0.045, 0.075, 0.105],
        [0.105, 0.105, 0.105],
    ];
    let s = Settings {
        fog: Fog::Lorentzian { sigma: 5.0 },
        ir: true,
        ..settings(0.75)
    };
    let b = galaxy();
    let run = |n_shell| {
        BispectrumPlan::new(
            TriangleSet::shells(centres.clone(), 0.01).unwrap(),
            LegendreSide::Largest,
            PlanRules {
                n_shell,
                ..PlanRules::default()
            },
        )
        .unwrap()
        .terms(&p_lin, &s)
        .unwrap()
        .multipoles(&b)
        .unwrap()
    };
    let (default, fine) = (run(3), run(12));
    let points = BispectrumPlan::new(
        TriangleSet::points(centres.clone()).unwrap(),
        LegendreSide::Largest,
        PlanRules::default(),
    )
    .unwrap()
    .terms(&p_lin, &s)
    .unwrap()
    .multipoles(&b)
    .unwrap();
    for ((d, f), p) in default.iter().zip(&fine).zip(&points) {
        for l in 0..3 {
            let diff = (d[l].value - f[l].value).abs();
            assert!(
                diff <= d[l].error + 1e-6 * f[0].value.abs(),
                "ℓ{}: {} vs {} ± {}",
                ELLS[l],
                d[l].value,
                f[l].value,
                d[l].error
            );
        }
        // the bin average is not the value at the centres (the reason to average)
        assert!((p[0].value / f[0].value - 1.0).abs() > 1e-4);
    }
}

#[test]
fn triangle_sets_refuse_what_does_not_close() {
    assert!(TriangleSet::points(vec![[0.01, 0.02, 0.04]]).is_err());
    assert!(TriangleSet::points(vec![[0.01, f64::NAN, 0.02]]).is_err());
    assert!(TriangleSet::shells(vec![[0.005, 0.05, 0.05]], 0.01).is_err());
    assert!(TriangleSet::shells(vec![[0.015, 0.015, 0.055]], 0.01).is_err());
    let edges: Vec<f64> = (1..=11).map(|i| 0.01 * i as f64).collect();
    let set = TriangleSet::from_edges(&edges).unwrap();
    assert_eq!(set.len(), 150);
    assert!(TriangleSet::from_edges(&[0.01, 0.02, 0.04]).is_err());
}

#[test]
fn bias_conventions_round_trip() {
    let b = BispectrumParams::from_class_pt(2.0, -0.5, -0.3);
    assert!((b.bs + 0.3).abs() < 1e-15 && (b.b2 - (-0.5 + 0.4)).abs() < 1e-15);
    let (b2, bg2) = b.to_class_pt();
    assert!((b2 + 0.5).abs() < 1e-15 && (bg2 + 0.3).abs() < 1e-15);
    let s8 = 0.6;
    let (x, y, z) = b.to_physical(s8);
    let back = BispectrumParams::from_physical(x, y, z, s8);
    assert!(
        (back.b1 - b.b1).abs() < 1e-15
            && (back.b2 - b.b2).abs() < 1e-15
            && (back.bs - b.bs).abs() < 1e-15
    );
    assert!(Fog::by_name("lorentz", 1.0).is_err() && Fog::by_name("gaussian", -1.0).is_err());
}

#[test]
fn a_chosen_legendre_side_is_the_same_side_wherever_it_is_listed() {
    // the largest side of (0.04, 0.07, 0.1) is the same side as side 1 of (0.1, 0.04, 0.07) and side 2 of
    // (0.07, 0.1, 0.04); side 1 of the first triangle is another side, with other B2, B4
    let p_lin = spectrum();
    let s = Settings {
        ir: true,
        ..settings(0.7)
    };
    let b = galaxy();
    let run = |t: [f64; 3], side| {
        first_multipoles(TriangleSet::points(vec![t]).unwrap(), side, &p_lin, &s, &b)
    };
    let largest = run([0.04, 0.07, 0.1], LegendreSide::Largest);
    for (t, side) in [([0.1, 0.04, 0.07], 0), ([0.07, 0.1, 0.04], 1)] {
        let chosen = run(t, LegendreSide::Index(side));
        for l in 0..3 {
            assert!((chosen[l].value - largest[l].value).abs() < 1e-10 * largest[0].value.abs());
        }
    }
    let other = run([0.04, 0.07, 0.1], LegendreSide::Index(0));
    // B0 does not depend on the side: equal within the orientation rules' stated errors (the damping
    // is not a polynomial; 1.6e-10 of B0 apart, errors 2e-8 and 2e-9)
    assert!((other[0].value - largest[0].value).abs() <= other[0].error + largest[0].error);
    assert!((other[1].value - largest[1].value).abs() > 1e-3 * largest[1].value.abs());
    assert!(LegendreSide::by_name("largest").is_ok() && LegendreSide::by_name("4").is_err());
}

#[test]
fn the_effective_triangle_is_the_bins_mean_triangle_and_its_error_covers_the_bin_average() {
    let p_lin = spectrum();
    let centres = vec![
        [0.015, 0.015, 0.015],
        [0.015, 0.015, 0.025],
        [0.025, 0.045, 0.065],
        [0.075, 0.075, 0.075],
    ];
    let s = Settings {
        fog: Fog::Lorentzian { sigma: 4.0 },
        ir: true,
        q_par: 1.02,
        q_perp: 0.99,
        ..settings(0.75)
    };
    let b = galaxy();
    let run = |set: TriangleSet, effective, n_shell| {
        BispectrumPlan::new(
            set,
            LegendreSide::Largest,
            PlanRules {
                effective,
                n_shell,
                ..PlanRules::default()
            },
        )
        .unwrap()
        .terms(&p_lin, &s)
        .unwrap()
        .multipoles(&b)
        .unwrap()
    };
    let shells = || TriangleSet::shells(centres.clone(), 0.01).unwrap();
    let effective = run(shells(), true, 3);
    let average = run(shells(), false, 10);
    // the mean sides of a bin, by hand: k₁k₂k₃-weighted over a 40³ midpoint grid of its closed triangles
    let means: Vec<[f64; 3]> = centres
        .iter()
        .map(|c| {
            let (mut sum, mut total) = ([0.0; 3], 0.0);
            let n = 40;
            let at = |c: f64, i: usize| c - 0.005 + 0.01 * (i as f64 + 0.5) / n as f64;
            for i in 0..n {
                for j in 0..n {
                    for l in 0..n {
                        let k = [at(c[0], i), at(c[1], j), at(c[2], l)];
                        if k[2] <= k[0] + k[1] && k[2] >= (k[0] - k[1]).abs() {
                            let w = k[0] * k[1] * k[2];
                            total += w;
                            for a in 0..3 {
                                sum[a] += w * k[a];
                            }
                        }
                    }
                }
            }
            sum.map(|s| s / total)
        })
        .collect();
    let at_means = run(TriangleSet::points(means).unwrap(), false, 3);
    for ((e, a), m) in effective.iter().zip(&average).zip(&at_means) {
        // the shortcut is B at the mean triangle (to the midpoint grid's accuracy, ~1e-5 in k)...
        assert!(
            (e[0].value / m[0].value - 1.0).abs() < 1e-4,
            "{} {}",
            e[0].value,
            m[0].value
        );
        for l in 0..3 {
            // ...and its stated error covers its distance from the bin average
            let miss = (e[l].value - a[l].value).abs();
            assert!(
                miss <= e[l].error,
                "ℓ{}: {miss:e} > {:e}",
                ELLS[l],
                e[l].error
            );
        }
        // not a trivial bound: the shortcut is off the average by more than the average's own error
        assert!((e[0].value - a[0].value).abs() > a[0].error);
    }
}

#[test]
fn on_a_bin_with_two_equal_shells_either_equal_side_may_carry_the_legendre_polynomial() {
    // The window-free estimator (Philcox 2021) attaches L_ℓ to the field of the third bin and divides
    // by the symmetry factor Δ_abc (2 for two equal bins, 6 for three): on a bin with two equal shells
    // it averages L_ℓ over both equal sides. The bin average is symmetric under the exchange of the
    // two sides, so that average is the plan's value with L_ℓ on either one: the model needs no extra
    // factor on isosceles or equilateral bins. Checked with anisotropic AP, IR and FoG, which break
    // every other symmetry of the orientation average.
    let p_lin = spectrum();
    let s = Settings {
        q_par: 1.04,
        q_perp: 0.97,
        fog: Fog::Lorentzian { sigma: 4.0 },
        ir: true,
        ..settings(0.75)
    };
    let b = galaxy();
    let run = |t: [f64; 3], side| {
        first_multipoles(
            TriangleSet::shells(vec![t], 0.01).unwrap(),
            side,
            &p_lin,
            &s,
            &b,
        )
    };
    let equal_sides: [([f64; 3], [usize; 2]); 4] = [
        ([0.015, 0.035, 0.035], [1, 2]),
        ([0.035, 0.035, 0.055], [0, 1]),
        ([0.045, 0.045, 0.045], [0, 2]),
        ([0.045, 0.045, 0.045], [1, 2]),
    ];
    for (t, [i, j]) in equal_sides {
        let (a, c) = (
            run(t, LegendreSide::Index(i)),
            run(t, LegendreSide::Index(j)),
        );
        for l in 1..3 {
            let tol = a[l].error + c[l].error + 1e-12 * a[0].value.abs();
            assert!(
                (a[l].value - c[l].value).abs() <= tol,
                "{t:?} ℓ{}: side {i} {} side {j} {}",
                ELLS[l],
                a[l].value,
                c[l].value
            );
        }
    }
    // and a side of another shell carries another multipole (the test can tell sides apart)
    let (a, c) = (
        run([0.015, 0.035, 0.035], LegendreSide::Index(0)),
        run([0.015, 0.035, 0.035], LegendreSide::Index(2)),
    );
    assert!((a[1].value - c[1].value).abs() > 1e-2 * c[1].value.abs());
}
