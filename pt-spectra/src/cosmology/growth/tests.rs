use super::*;

/// CAMB 2.0.5 values from the headers of `data/linear_pk_gm2012_z*.dat`: (z, σ8(z), f(z)).
const CAMB: [(f64, f64, f64); 4] = [
    (0.0, 0.800000, 0.483135),
    (0.5, 0.625851, 0.723472),
    (1.0, 0.498294, 0.852382),
    (1.5, 0.408845, 0.916082),
];
/// CAMB includes radiation and scale-dependent baryon effects that the ΛCDM growth integral neglects.
const CAMB_GROWTH_TOL: f64 = 1e-3;
/// Simpson error of the growth integral (≈ 1.5e-12 in EdS, where the integrand is 2u⁴).
const QUADRATURE_TOL: f64 = 1e-10;
/// Required agreement of the growth ODE with exact results (its global error is ~1e-11).
const ODE_TOL_TEST: f64 = 1e-8;
/// Truncation error h²f'''/6 of a centred difference with h = 1e-4 in ln a.
const FINITE_DIFFERENCE_TOL: f64 = 1e-7;
/// Redshifts at which the growth paths are compared (including the future, z < 0).
const REDSHIFTS: [f64; 8] = [-0.5, 0.0, 0.3, 1.0, 3.0, 10.0, 100.0, 1000.0];

/// |x/y − 1|.
fn rel(x: f64, y: f64) -> f64 {
    (x / y - 1.0).abs()
}

#[test]
fn growth_matches_camb() {
    let c = Cosmology::gm2012();
    for (z, s8, f_camb) in CAMB {
        let d_camb = s8 / 0.8;
        let (d, f) = (c.growth_factor(z), c.growth_rate(z));
        println!(
            "z = {z}: D = {d:.6} (CAMB {d_camb:.6}, {:+.1e}), f = {f:.6} (CAMB {f_camb}, {:+.1e})",
            d / d_camb - 1.0,
            f / f_camb - 1.0
        );
        assert!(rel(d, d_camb) < CAMB_GROWTH_TOL, "D({z}) = {d}");
        assert!(rel(f, f_camb) < CAMB_GROWTH_TOL, "f({z}) = {f}");
    }
}

/// Flat ΛCDM closed form D ∝ a ₂F₁(1/3, 1; 11/6; −a³Ω_Λ/Ω_m), evaluated after the Pfaff
/// transformation ₂F₁(a,b;c;x) = (1−x)^−b ₂F₁(c−a, b; c; x/(x−1)), whose series converges for x < 0.
fn growth_hypergeometric(omega_m: f64, a: f64) -> f64 {
    let x = -a.powi(3) * (1.0 - omega_m) / omega_m;
    let w = x / (x - 1.0);
    let (mut term, mut sum) = (1.0, 1.0);
    for n in 0..2000 {
        let n = f64::from(n);
        term *= (1.5 + n) / (11.0 / 6.0 + n) * w;
        sum += term;
    }
    a * sum / (1.0 - x)
}

#[test]
fn growth_matches_hypergeometric_closed_form() {
    let mut worst_ode = 0.0_f64;
    for om in [0.27, 0.5, 0.05] {
        let c = Cosmology::flat(om, 0.7, 0.02, 0.96, 0.8).unwrap();
        for z in [0.0, 0.3, 1.0, 3.0, 20.0] {
            let a = 1.0 / (1.0 + z);
            let exact = growth_hypergeometric(om, a) / growth_hypergeometric(om, 1.0);
            assert!(
                rel(c.growth_factor(z), exact) < QUADRATURE_TOL,
                "om {om} z {z}"
            );
            let ode = c.normalised_growth(a, Method::Ode);
            worst_ode = worst_ode.max(rel(ode, exact));
            assert!(rel(ode, exact) < ODE_TOL_TEST, "ODE: om {om} z {z}");
            // f against a centred finite difference of the closed form in ln a.
            let h = 1e-4;
            let lnd = |la: f64| growth_hypergeometric(om, la.exp()).ln();
            let f_fd = (lnd(a.ln() + h) - lnd(a.ln() - h)) / (2.0 * h);
            for method in [Method::Heath, Method::Ode] {
                let f = c.rate(a, method);
                assert!(
                    rel(f, f_fd) < FINITE_DIFFERENCE_TOL,
                    "{method:?}: om {om} z {z}"
                );
            }
        }
    }
    println!("growth ODE against the hypergeometric closed form: worst |D/D_exact - 1| = {worst_ode:.1e}");
}

#[test]
fn einstein_de_sitter_and_open_limits() {
    let eds = Cosmology::new(1.0, 0.0, 0.7, 0.02, 1.0, 0.8).unwrap();
    for z in [0.0, 0.5, 2.0, 10.0] {
        let a = 1.0 / (1.0 + z);
        let (d, f) = (eds.growth_factor(z), eds.growth_rate(z));
        let (d_ode, f_ode) = (
            eds.normalised_growth(a, Method::Ode),
            eds.rate(a, Method::Ode),
        );
        println!(
            "EdS z = {z}: D(1+z) - 1 = {:.1e} (ODE {:.1e}), f - 1 = {:.1e} (ODE {:.1e})",
            d / a - 1.0,
            d_ode / a - 1.0,
            f - 1.0,
            f_ode - 1.0
        );
        assert!((d / a - 1.0).abs() < QUADRATURE_TOL);
        assert!((f - 1.0).abs() < QUADRATURE_TOL);
        assert!((d_ode / a - 1.0).abs() < ODE_TOL_TEST);
        assert!((f_ode - 1.0).abs() < ODE_TOL_TEST);
        assert!((eds.growth_md(a, Method::Ode) / a - 1.0).abs() < ODE_TOL_TEST);
    }
    // Open, Λ = 0: f(z=0) ≈ Ω_m^0.6 (Peebles 1980) to ~1%.
    let open = Cosmology::new(0.3, 0.0, 0.7, 0.02, 1.0, 0.8).unwrap();
    assert!((open.growth_rate(0.0) / 0.3f64.powf(0.6) - 1.0).abs() < 0.02);
    assert!(eds.growth_factor(-1.0).is_nan() && eds.growth_rate(f64::NAN).is_nan());
}

/// Worst relative differences (D(z)/D(0), f(z), D_md(z)) between the ODE and Heath's integral.
fn ode_against_heath(c: &Cosmology) -> [f64; 3] {
    let mut worst = [0.0_f64; 3];
    for z in REDSHIFTS {
        let a = 1.0 / (1.0 + z);
        let pairs = [
            (
                c.normalised_growth(a, Method::Ode),
                c.normalised_growth(a, Method::Heath),
            ),
            (c.rate(a, Method::Ode), c.rate(a, Method::Heath)),
            (c.growth_md(a, Method::Ode), c.growth_md(a, Method::Heath)),
        ];
        for (w, (ode, heath)) in worst.iter_mut().zip(pairs) {
            *w = w.max(rel(ode, heath));
        }
    }
    worst
}

#[test]
fn growth_ode_matches_heath_for_flat_and_curved_lambda_cdm() {
    let cases = [
        ("gm2012", Cosmology::gm2012()),
        (
            "Planck 2018",
            Cosmology::flat(0.3096, 0.6766, 0.02242, 0.9665, 0.81).unwrap(),
        ),
        (
            "flat Ω_m 0.05",
            Cosmology::flat(0.05, 0.7, 0.02, 0.96, 0.8).unwrap(),
        ),
        (
            "open Ω_m 0.3 Ω_Λ 0.6",
            Cosmology::new(0.3, 0.6, 0.7, 0.02, 0.96, 0.8).unwrap(),
        ),
        (
            "closed Ω_m 0.3 Ω_Λ 0.8",
            Cosmology::new(0.3, 0.8, 0.7, 0.02, 0.96, 0.8).unwrap(),
        ),
        (
            "open Ω_m 0.3 Ω_Λ 0",
            Cosmology::new(0.3, 0.0, 0.7, 0.02, 0.96, 0.8).unwrap(),
        ),
    ];
    for (name, c) in cases {
        assert_eq!(c.method(), Method::Heath);
        let [d, f, d_md] = ode_against_heath(&c);
        println!(
            "{name}: ODE vs Heath, worst |ΔD/D| {d:.1e}, |Δf/f| {f:.1e}, |ΔD_md/D_md| {d_md:.1e}"
        );
        assert!(
            d < ODE_TOL_TEST && f < ODE_TOL_TEST && d_md < ODE_TOL_TEST,
            "{name}"
        );
    }
}

/// w = −1/3 dark energy dilutes like curvature: E² = Ω_m a⁻³ + (1 − Ω_m) a⁻², the open universe with
/// Ω_Λ = 0, where Heath's integral is exact.
#[test]
fn constant_w_minus_one_third_acts_as_curvature() {
    for om in [0.3, 0.7] {
        let de = Cosmology::flat(om, 0.7, 0.02, 0.96, 0.8)
            .unwrap()
            .with_dark_energy(-1.0 / 3.0, 0.0)
            .unwrap();
        let open = Cosmology::new(om, 0.0, 0.7, 0.02, 0.96, 0.8).unwrap();
        assert_eq!(de.method(), Method::Ode);
        let mut worst = [0.0_f64; 2];
        for z in REDSHIFTS {
            let pairs = [
                (de.growth_factor(z), open.growth_factor(z)),
                (de.growth_rate(z), open.growth_rate(z)),
            ];
            for (w, (x, y)) in worst.iter_mut().zip(pairs) {
                *w = w.max(rel(x, y));
            }
        }
        println!(
            "w = -1/3, Ω_m {om} vs open Heath: worst |ΔD/D| {:.1e}, |Δf/f| {:.1e}",
            worst[0], worst[1]
        );
        assert!(worst.iter().all(|&w| w < ODE_TOL_TEST), "{worst:?}");
    }
}

/// Brute-force growth for any w0, wa: classical RK4 on (D, dD/d ln a) with many fixed steps in ln a,
/// from D = D′ = a at a = 1e-6 (an integrator independent of the one under test). Returns (D, f) at `a`.
fn brute_force(c: &Cosmology, a: f64) -> (f64, f64) {
    let e2 = |a: f64| c.a2e2(a) / (a * a);
    let rhs = |x: f64, [d, dd]: [f64; 2]| {
        let a = x.exp();
        let h = 1e-6;
        let dln_e = ((e2(a * (1.0 + h))).ln() - (e2(a * (1.0 - h))).ln()) / (4.0 * h);
        [
            dd,
            -(2.0 + dln_e) * dd + 1.5 * c.omega_m / (a.powi(3) * e2(a)) * d,
        ]
    };
    let (x0, x1, n) = (1e-6_f64.ln(), a.ln(), 20_000);
    let h = (x1 - x0) / f64::from(n);
    let mut y = [1e-6, 1e-6];
    for i in 0..n {
        let x = x0 + h * f64::from(i);
        let add = |y: [f64; 2], k: [f64; 2], s: f64| [y[0] + s * k[0], y[1] + s * k[1]];
        let k1 = rhs(x, y);
        let k2 = rhs(x + h / 2.0, add(y, k1, h / 2.0));
        let k3 = rhs(x + h / 2.0, add(y, k2, h / 2.0));
        let k4 = rhs(x + h, add(y, k3, h));
        for j in 0..2 {
            y[j] += h / 6.0 * (k1[j] + 2.0 * k2[j] + 2.0 * k3[j] + k4[j]);
        }
    }
    (y[0], y[1] / y[0])
}

/// Dynamical dark energy (CPL w0–wa, quintessence-like and phantom, flat and curved): D against an
/// independent brute-force integration, and f against a finite difference of ln D in ln a.
#[test]
fn dynamical_dark_energy_growth_is_consistent() {
    /// RK4 with 2e4 steps plus the centred difference for d ln E/d ln a: ~1e-9.
    const BRUTE_FORCE_TOL: f64 = 1e-7;
    let cases = [
        (-0.9, 0.0, 0.0),
        (-0.8, -0.5, 0.0),
        (-1.2, 0.4, 0.0),
        (-0.9, -0.3, 0.05),
    ];
    for (w0, wa, omega_k) in cases {
        let c = Cosmology::new(0.31, 0.69 - omega_k, 0.68, 0.022, 0.965, 0.8)
            .unwrap()
            .with_dark_energy(w0, wa)
            .unwrap();
        let (d_today, f_today) = brute_force(&c, 1.0);
        let (mut worst_d, mut worst_f, mut worst_fd) = (0.0_f64, 0.0_f64, 0.0_f64);
        for z in [0.0, 0.5, 1.0, 3.0] {
            let a = 1.0 / (1.0 + z);
            let (d_bf, f_bf) = brute_force(&c, a);
            worst_d = worst_d.max(rel(c.growth_factor(z), d_bf / d_today));
            worst_f = worst_f.max(rel(c.growth_rate(z), f_bf));
            let h = 1e-4;
            let lnd = |la: f64| c.normalised_growth(la.exp(), Method::Ode).ln();
            let f_fd = (lnd(a.ln() + h) - lnd(a.ln() - h)) / (2.0 * h);
            worst_fd = worst_fd.max(rel(c.growth_rate(z), f_fd));
        }
        println!(
            "w0 {w0} wa {wa} Ω_k {omega_k}: f(0) = {:.6} (brute force {f_today:.6}); worst vs brute force \
             |ΔD/D| {worst_d:.1e}, |Δf/f| {worst_f:.1e}; f vs finite difference {worst_fd:.1e}",
            c.growth_rate(0.0)
        );
        assert!(worst_d < BRUTE_FORCE_TOL && worst_f < BRUTE_FORCE_TOL);
        assert!(worst_fd < FINITE_DIFFERENCE_TOL);
    }
}

#[test]
fn growth_evaluation_is_cheap() {
    let heath = Cosmology::planck2018();
    let c = heath.with_dark_energy(-0.9, -0.2).unwrap();
    let n = 200;
    let start = std::time::Instant::now();
    let mut sum = 0.0;
    for i in 0..n {
        let z = f64::from(i) / f64::from(n);
        sum += c.growth_factor(z) + c.growth_rate(z);
    }
    let per_call = start.elapsed().as_secs_f64() / f64::from(2 * n);
    let start = std::time::Instant::now();
    for i in 0..n {
        let z = f64::from(i) / f64::from(n);
        sum += heath.growth_factor(z) + heath.growth_rate(z);
    }
    let per_call_heath = start.elapsed().as_secs_f64() / f64::from(2 * n);
    println!(
        "growth evaluation: ODE {:.1} µs, Heath {:.1} µs per call (checksum {sum:.3})",
        per_call * 1e6,
        per_call_heath * 1e6
    );
    assert!(sum.is_finite());
}

#[test]
fn growth_md_and_rate_equals_the_separate_calls() {
    // one integration for both (Heath for Λ, the ODE otherwise) gives what the separate calls give
    for c in [
        Cosmology::planck2018(),
        Cosmology::planck2018().with_dark_energy(-0.9, 0.3).unwrap(),
    ] {
        let (d0, _) = c.growth_md_and_rate(0.0);
        for z in [0.0, 0.5, 2.0] {
            let (d, f) = c.growth_md_and_rate(z);
            assert!((f / c.growth_rate(z) - 1.0).abs() < 1e-12, "{z}");
            assert!((d / d0 / c.growth_factor(z) - 1.0).abs() < 1e-12, "{z}");
        }
    }
}

#[test]
fn growth_factor_and_rate_equals_the_separate_calls() {
    // D(z)/D(0) and f(z) from one integral at z, for Λ (Heath) and w0–wa with curvature (the ODE)
    for c in [
        Cosmology::planck2018(),
        Cosmology::planck2018().with_dark_energy(-0.9, 0.3).unwrap(),
    ] {
        for z in [0.0, 0.5, 2.0] {
            let (d, f) = c.growth_factor_and_rate(z);
            assert!((f / c.growth_rate(z) - 1.0).abs() < 1e-12, "{z}");
            assert!((d / c.growth_factor(z) - 1.0).abs() < 1e-12, "{z}");
        }
        let (d, f) = c.growth_factor_and_rate(-1.0);
        assert!(d.is_nan() && f.is_nan());
    }
}

/// The exact (dual) derivatives of E(z), D_md(z), f(z) and D(z)/D(0) with respect to the eight sampled
/// parameters against Richardson-extrapolated finite differences of the `f64` path, at ΛCDM, w0–wa,
/// open, closed and massless-neutrino cosmologies (`finite_difference`; E here is without radiation,
/// so the Σm_ν = 0 case is differentiated from above).
#[test]
fn dual_growth_derivatives_match_finite_differences() {
    use crate::cosmology::finite_difference::{check_derivatives, derivative_cosmologies};
    for (label, c) in derivative_cosmologies() {
        check_derivatives(
            label,
            &c,
            &["E", "D_md", "f", "D/D(0)"],
            |b, z| {
                let (d_md, f) = b.growth_md_and_rate(z);
                vec![b.e_of_z(z), d_md, f, b.growth_factor_and_rate(z).0]
            },
            |c, z| {
                let (d_md, f) = c.growth_md_and_rate(z);
                vec![c.e_of_z(z), d_md, f, c.growth_factor_and_rate(z).0]
            },
            false,
        );
    }
}

/// At a cosmological constant the seeded background (w0, wa carry derivatives) takes the ODE, whose
/// values equal Heath's integral of the `f64` path; with w0, wa constant the duals take Heath's
/// integral too, and its derivatives equal the ODE's.
#[test]
fn dual_growth_at_lambda_equals_heath() {
    /// The ODE's global error (~1e-11), with a margin.
    const HEATH_TOL: f64 = 1e-9;
    let c = Cosmology::planck2018().with_neutrinos(0.06).unwrap();
    let seeded = c.seeded().unwrap();
    assert_eq!(c.method(), Method::Heath);
    assert_eq!(seeded.method(), Method::Ode);
    let constant_de = crate::cosmology::background::Background {
        w0: Real::cst(-1.0),
        wa: Real::cst(0.0),
        ..seeded
    };
    assert_eq!(constant_de.method(), Method::Heath);
    let mut worst = [0.0_f64; 2];
    // Per z: (ODE, Heath) duals of D_md, f, D/D(0).
    let mut pairs = Vec::new();
    for z in [0.0, 0.5, 1.0, 2.0, 10.0] {
        let (d_md, f) = c.growth_md_and_rate(z);
        let d = c.growth_factor(z);
        let (dual_md, dual_f) = seeded.growth_md_and_rate(z);
        let dual_d = seeded.growth_factor_and_rate(z).0;
        for (dual, heath) in [(dual_md, d_md), (dual_f, f), (dual_d, d)] {
            worst[0] = worst[0].max(rel(dual.v, heath));
        }
        let (heath_md, heath_f) = constant_de.growth_md_and_rate(z);
        let heath_d = constant_de.growth_factor_and_rate(z).0;
        for (ode, heath) in [(dual_md, heath_md), (dual_f, heath_f), (dual_d, heath_d)] {
            assert!(rel(heath.v, ode.v) < HEATH_TOL, "z {z}");
        }
        pairs.push([(dual_md, heath_md), (dual_f, heath_f), (dual_d, heath_d)]);
    }
    // Heath's integral has no w0, wa derivatives: the first six, relative to their largest over z.
    for q in 0..3 {
        let scale = pairs.iter().fold(0.0_f64, |s, p| {
            p[q].1.d[..6].iter().fold(s, |s, d| s.max(d.abs()))
        });
        for p in &pairs {
            for (a, b) in p[q].0.d.iter().zip(&p[q].1.d).take(6) {
                worst[1] = worst[1].max((a - b).abs() / scale);
            }
        }
    }
    println!(
        "Λ: dual ODE vs f64 Heath, worst relative {:.1e}; derivatives of the ODE vs Heath's {:.1e}",
        worst[0], worst[1]
    );
    assert!(worst.iter().all(|&w| w < HEATH_TOL), "{worst:?}");
}
