//! Unit tests of the window plan: the mixing, the model grid, a window that changes nothing, errors.

use super::*;

fn flat_window(s_max: f64) -> WindowMultipoles {
    let s: Vec<f64> = (0..64)
        .map(|i| 0.01 * (s_max / 0.01f64).powf(i as f64 / 63.0))
        .collect();
    let n = s.len();
    WindowMultipoles::from_columns(s, vec![0, 2], vec![vec![1.0; n], vec![0.0; n]]).unwrap()
}

#[test]
fn mixings_differ_by_the_dropped_terms() {
    let w = |l, a, b| mixing_coefficient(Mixing::Wilson, l, a, b);
    let c = |l, a, b| mixing_coefficient(Mixing::ClassPtBoss, l, a, b);
    assert_eq!(Mixing::default(), Mixing::Wilson);
    // CLASS-PT: ξ̂0 = ξ0Q0 + ξ2Q2/5, ξ̂2 = ξ0Q2 + ξ2(Q0 + 2(Q2 + Q4)/7).
    assert_eq!((c(0, 0, 0), c(0, 2, 2), c(0, 4, 4)), (1.0, 0.2, 0.0));
    assert_eq!((c(2, 0, 2), c(2, 2, 0)), (1.0, 1.0));
    assert!((c(2, 2, 2) - 2.0 / 7.0).abs() < 1e-16 && (c(2, 2, 4) - 2.0 / 7.0).abs() < 1e-16);
    assert_eq!((c(2, 4, 2), c(2, 2, 6), c(4, 2, 6)), (0.0, 0.0, 0.0));
    // ξ̂4 keeps its ξ4 terms (truncated at Q4).
    assert!((c(4, 4, 0) - 1.0).abs() < 1e-16 && (c(4, 4, 4) - 162.0 / 1001.0).abs() < 1e-16);
    assert_eq!(c(4, 4, 6), 0.0);
    assert!((w(0, 4, 4) - 1.0 / 9.0).abs() < 1e-16);
    assert!((w(2, 4, 4) - 100.0 / 693.0).abs() < 1e-16);
    assert!((w(4, 4, 4) - 162.0 / 1001.0).abs() < 1e-16);
    assert!(w(2, 2, 6) == 0.0 && w(4, 2, 6) > 0.0 && w(8, 8, 8) > 0.0);
}

#[test]
fn model_grid_is_fine_over_the_output_range() {
    let o = WindowOptions::default();
    let k_out: Vec<f64> = (0..48).map(|i| 0.0025 + 0.005 * i as f64).collect();
    let g = theory_grid(&k_out, 3.0 * o.dk, &o);
    assert_eq!((g[0], g[g.len() - 1]), (o.k_min, o.k_max));
    assert!(g.windows(2).all(|w| w[1] > w[0]));
    for w in g.windows(2) {
        if w[0] >= k_out[0] - 2.0 * o.dk && w[1] <= k_out[47] + 3.0 * o.dk {
            assert!(w[1] - w[0] <= o.dk * (1.0 + 1e-12), "{w:?}");
        }
        assert!(w[1] / w[0] <= 10f64.powf(1.0 / o.points_per_decade) * (1.0 + 1e-12) + 0.25);
    }
    assert!(g.len() < 150, "{} model points", g.len());
}

#[test]
fn a_window_that_keeps_everything_changes_nothing() {
    // Q0 = 1, Q2 = 0 out to 1e6 Mpc/h: R = 0 wherever the FFTLog grid reaches (s ≤ 1e5).
    let w = flat_window(1e6);
    let k_out = [0.01, 0.05, 0.1, 0.2];
    let plan = WindowPlan::new(&[0, 2, 4], &k_out, &w, Mixing::Wilson).unwrap();
    let model = |k: f64| 1e4 * k / (1.0 + (k / 0.02).powi(2));
    let p: Vec<Vec<f64>> = [1.0, 0.5, -0.1]
        .iter()
        .map(|c| plan.k_theory().iter().map(|&k| c * model(k)).collect())
        .collect();
    let out = plan.apply(&p).unwrap();
    for (j, &k) in k_out.iter().enumerate() {
        for (o, c) in [1.0, 0.5, -0.1].iter().enumerate() {
            let e = out[o][j];
            assert!(
                (e.value - c * model(k)).abs() < 1e-6 * model(k),
                "{o} {k}: {e:?}"
            );
            assert!(e.error < 1e-5 * model(k));
        }
    }
    // The values-only path of fits gives the same numbers.
    let values = plan.apply_values(&p).unwrap();
    for (o, row) in out.iter().enumerate() {
        let want: Vec<f64> = row.iter().map(|e| e.value).collect();
        assert_eq!(values[o], want);
    }
}

#[test]
fn mixings_agree_without_q4_and_xi4() {
    // A sphere of radius 200 Mpc/h with a small smooth Q2: Wilson and CLASS-PT differ only by Q4 and ξ4.
    let r = 200.0;
    let s: Vec<f64> = (0..128)
        .map(|i| 0.01 * (2.0 * r / 0.01f64).powf(i as f64 / 127.0))
        .collect();
    let q0 = s
        .iter()
        .map(|&s| 1.0 - 0.75 * s / r + (s / r).powi(3) / 16.0)
        .collect();
    let q2 = s
        .iter()
        .map(|&s| -0.1 * (s / r).powi(2) * (1.0 - s / (2.0 * r)).powi(2))
        .collect();
    let w = WindowMultipoles::from_columns(s, vec![0, 2], vec![q0, q2]).unwrap();
    let k_out = [0.02, 0.1, 0.2];
    let model = |k: f64| 1e4 * k / (1.0 + (k / 0.02).powi(2));
    let run = |mixing| {
        let plan = WindowPlan::new(&[0, 2, 4], &k_out, &w, mixing).unwrap();
        let p: Vec<Vec<f64>> = [1.0, 0.5]
            .iter()
            .map(|c| plan.k_theory().iter().map(|&k| c * model(k)).collect())
            .collect();
        plan.apply(&p).unwrap()
    };
    let (a, b) = (run(Mixing::Wilson), run(Mixing::ClassPtBoss));
    for (x, y) in a.iter().flatten().zip(b.iter().flatten()) {
        assert!(
            (x.value - y.value).abs() < 1e-12 * x.value.abs().max(1.0),
            "{x:?} {y:?}"
        );
    }
    // The window does something: P̂0 < P0 at low k.
    assert!(a[0][0].value < 0.9 * model(0.02), "{:?}", a[0][0]);
}

#[test]
fn bad_input_is_refused() {
    let w = flat_window(1000.0);
    let new = |ells: &[usize], k: &[f64]| WindowPlan::new(ells, k, &w, Mixing::Wilson);
    assert!(matches!(
        new(&[0, 3], &[0.1]),
        Err(Error::InvalidChoice { .. })
    ));
    assert!(matches!(new(&[0], &[]), Err(Error::TooFewPoints { .. })));
    assert!(matches!(
        new(&[0], &[0.2, 0.1]),
        Err(Error::NonIncreasingK { .. })
    ));
    assert!(matches!(new(&[0], &[5.0]), Err(Error::OutOfRange { .. })));
    assert!(matches!(new(&[0], &[1e-5]), Err(Error::OutOfRange { .. })));
    let options = WindowOptions {
        dk: 0.0,
        ..WindowOptions::default()
    };
    assert!(WindowPlan::with_options(&[0], &[0.1], &w, Mixing::Wilson, &options).is_err());
    let coarse = WindowOptions {
        k_min: 0.01,
        k_max: 0.5,
        points_per_decade: 4.0,
        ..WindowOptions::default()
    };
    let e = WindowPlan::with_options(&[0], &[0.1], &w, Mixing::Wilson, &coarse);
    assert!(matches!(e, Err(Error::InvalidParameter { .. })));
    let plan = new(&[0], &[0.1]).unwrap();
    let n = plan.k_theory().len();
    assert!(plan.apply(&[]).is_err());
    assert!(plan.apply(&[vec![1.0; n - 1]]).is_err());
    assert!(plan.apply(&vec![vec![1.0; n]; 6]).is_err());
    let mut bad = vec![1.0; n];
    bad[3] = f64::NAN;
    assert!(matches!(
        plan.apply(&[bad]),
        Err(Error::InvalidValue { line: 4, .. })
    ));
}
