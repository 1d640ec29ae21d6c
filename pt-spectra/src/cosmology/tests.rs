use super::*;

/// CAMB includes radiation and scale-dependent baryon effects that the ΛCDM growth integral neglects.
const CAMB_GROWTH_TOL: f64 = 1e-3;

#[test]
fn rescaling_follows_growth_squared() {
    let c = Cosmology::gm2012();
    let p0 = LinearSpectrum::gm2012_z0();
    let p1 = c.rescale(&p0, 0.0, 1.0).unwrap();
    let camb1 = LinearSpectrum::gm2012(1.0).unwrap();
    for k in [1e-3, 0.05, 0.2] {
        assert!(
            (p1.eval(k) / camb1.eval(k) - 1.0).abs() < 2.0 * CAMB_GROWTH_TOL,
            "k {k}"
        );
    }
    assert!(c.rescale(&p0, -1.0, 0.0).is_err());
}

#[test]
fn invalid_cosmologies_are_rejected() {
    assert!(Cosmology::gm2012().validate().is_ok());
    assert!(Cosmology::flat(-0.1, 0.7, 0.02, 0.96, 0.8).is_err());
    assert!(Cosmology::flat(0.3, 0.7, 0.5, 0.96, 0.8).is_err());
    assert!(Cosmology::flat(0.3, f64::NAN, 0.02, 0.96, 0.8).is_err());
    assert!(Cosmology::new(0.1, 3.0, 0.7, 0.002, 0.96, 0.8).is_err()); // bounce
    let e = Cosmology::flat(0.3, 0.7, 0.02, 0.96, -0.8).unwrap_err();
    assert!(e.to_string().contains("sigma8 = -0.8"), "{e}");
    let flat = Cosmology::flat(0.3, 0.7, 0.02, 0.96, 0.8).unwrap();
    assert!(flat.with_dark_energy(-0.9, 0.3).is_ok());
    let e = flat.with_dark_energy(-0.5, 0.75).unwrap_err();
    assert!(e.to_string().contains("w0 + wa = 0.25"), "{e}");
    assert!(flat.with_dark_energy(f64::INFINITY, -2.0).is_err());
    // Closed: with Λ, a²E² = 0.3/a − 0.8 + 1.5a² > 0.16; with phantom w = −2 dark energy,
    // a²E² = 0.3/a − 0.8 + 1.5a⁵ < 0 near a = 0.5.
    let closed = Cosmology::new(0.3, 1.5, 0.7, 0.02, 0.96, 0.8).unwrap();
    let e = closed.with_dark_energy(-2.0, 0.0).unwrap_err();
    assert!(e.to_string().contains("bouncing"), "{e}");
}

fn ratios(kind: TransferKind) -> (LinearSpectrum, LinearSpectrum) {
    let c = Cosmology::gm2012();
    let eh = c
        .eisenstein_hu_spectrum(kind, 0.0, &LogGrid::default())
        .unwrap();
    (eh, LinearSpectrum::gm2012_z0())
}

#[test]
fn eisenstein_hu_broadband_matches_camb() {
    let (nw, camb) = ratios(TransferKind::NoWiggle);
    let (w, _) = ratios(TransferKind::Wiggle);
    assert!((nw.sigma8() - 0.8).abs() < 1e-9 && (w.sigma8() - 0.8).abs() < 1e-9);
    let (mut worst_nw, mut worst_w) = (0.0_f64, 0.0_f64);
    for k in LogGrid::new(0.01, 0.3, 100).unwrap().points() {
        worst_nw = worst_nw.max((nw.eval(k) / camb.eval(k) - 1.0).abs());
        worst_w = worst_w.max((w.eval(k) / camb.eval(k) - 1.0).abs());
    }
    println!("max |P_EH/P_CAMB - 1| on 0.01-0.3: no-wiggle {worst_nw:.4}, wiggle {worst_w:.4}");
    assert!(worst_nw < 0.08, "{worst_nw}");
    assert!(worst_w < 0.05, "{worst_w}");
}

/// The CAMB 2.0.5 Planck 2018 tables of `tests/data/` (see the README there), at z = 0 and 1.
const PLANCK2018_TABLES: [(f64, &str); 2] = [
    (
        0.0,
        concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/tests/data/linear_pk_planck2018_z0.0.dat"
        ),
    ),
    (
        1.0,
        concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/tests/data/linear_pk_planck2018_z1.0.dat"
        ),
    ),
];
/// Acceptance tolerance on f(z) and on P(k) rescaled by D² against CAMB. CAMB includes radiation and the
/// baryons' scale-dependent growth, which the growth here neglects (measured: ≤ 3e-4).
const CAMB_ACCEPTANCE_TOL: f64 = 2e-3;
/// σ8 from A_s through the Eisenstein & Hu fit against CAMB's: the fit's transfer function is good to a
/// few per cent (the broadband test above finds up to 4% in P).
const EH_SIGMA8_TOL: f64 = 0.03;

/// The number after the last `=` of the first header field (fields are separated by two blanks) that
/// contains `key`, e.g. `f(z) =`.
fn header_value(p: &LinearSpectrum, key: &str) -> f64 {
    let line = p
        .header()
        .iter()
        .flat_map(|l| l.split("  "))
        .find(|l| l.contains(key))
        .unwrap_or_else(|| panic!("no `{key}` in the header of {}", p.origin()));
    let value = line.rsplit('=').next().unwrap().trim();
    value
        .parse()
        .unwrap_or_else(|_| panic!("`{value}` ({key}) in {}", p.origin()))
}

/// (z, spectrum, σ8(z), f(z)) of the CAMB Planck 2018 tables.
fn planck2018_camb() -> Vec<(f64, LinearSpectrum, f64, f64)> {
    PLANCK2018_TABLES
        .iter()
        .map(|&(z, path)| {
            let p = LinearSpectrum::from_file(path).unwrap();
            assert_eq!(header_value(&p, "z = "), z, "{path}");
            let (s8, f) = (header_value(&p, "sigma8(z) ="), header_value(&p, "f(z) ="));
            (z, p, s8, f)
        })
        .collect()
}

#[test]
fn planck2018_growth_rate_and_rescaling_match_camb() {
    let c = Cosmology::planck2018();
    let camb = planck2018_camb();
    for (z, _, _, f_camb) in &camb {
        let f = c.growth_rate(*z);
        println!(
            "Planck 2018 f({z}) = {f:.6}, CAMB {f_camb}: {:+.2e}",
            f / f_camb - 1.0
        );
        assert!(
            (f / f_camb - 1.0).abs() < CAMB_ACCEPTANCE_TOL,
            "f({z}) = {f}"
        );
    }
    let (p0, p1) = (&camb[0].1, &camb[1].1);
    let rescaled = c.rescale(p0, 0.0, 1.0).unwrap();
    let mut worst = 0.0_f64;
    for k in LogGrid::new(0.01, 0.3, 200).unwrap().points() {
        worst = worst.max((rescaled.eval(k) / p1.eval(k) - 1.0).abs());
    }
    let d_camb = camb[1].2 / camb[0].2;
    println!(
        "Planck 2018 P(z=0) rescaled to z = 1 vs CAMB z = 1, 0.01-0.3 h/Mpc: worst |ratio - 1| = {worst:.2e} \
         (D(1) = {:.6}, CAMB sigma8 ratio {d_camb:.6})",
        c.growth_factor(1.0)
    );
    assert!(worst < CAMB_ACCEPTANCE_TOL, "{worst}");
}

#[test]
fn a_s_normalisation_gives_camb_sigma8() {
    let grid = LogGrid::default();
    // Planck 2018 against the CAMB table's header.
    let camb = planck2018_camb();
    let c = Cosmology::planck2018();
    for (z, _, s8_camb, _) in &camb {
        let s8 = c
            .eisenstein_hu_spectrum(TransferKind::Wiggle, *z, &grid)
            .unwrap()
            .sigma8();
        println!(
            "Planck 2018 (A_s) EH sigma8(z = {z}) = {s8:.6}, CAMB {s8_camb}: {:+.2e}",
            s8 / s8_camb - 1.0
        );
        assert!((s8 / s8_camb - 1.0).abs() < EH_SIGMA8_TOL, "{s8}");
    }
    // gm2012: the embedded CAMB table's header gives the A_s that CAMB normalised to σ8 = 0.8.
    let p = LinearSpectrum::gm2012_z0();
    let a_s = header_value(&p, " As=");
    let gm = Cosmology::gm2012()
        .with_amplitude(Amplitude::a_s(a_s))
        .unwrap();
    let s8 = gm
        .eisenstein_hu_spectrum(TransferKind::Wiggle, 0.0, &grid)
        .unwrap()
        .sigma8();
    println!(
        "gm2012 with A_s = {a_s:e}: EH sigma8 = {s8:.6}, CAMB 0.8: {:+.2e}",
        s8 / 0.8 - 1.0
    );
    assert!((s8 / 0.8 - 1.0).abs() < EH_SIGMA8_TOL, "{s8}");
}

#[test]
fn a_s_normalisation_scales_as_expected() {
    let grid = LogGrid::new(1e-4, 10.0, 400).unwrap();
    let c = Cosmology::planck2018();
    let p = c
        .eisenstein_hu_spectrum(TransferKind::NoWiggle, 0.0, &grid)
        .unwrap();
    // P ∝ A_s, and the pivot enters as (k/k_pivot)^{n_s−1}.
    let Amplitude::As { a_s, k_pivot } = c.amplitude else {
        panic!("planck2018 is normalised by A_s")
    };
    let doubled = c
        .with_amplitude(Amplitude::As {
            a_s: 2.0 * a_s,
            k_pivot: 2.0 * k_pivot,
        })
        .unwrap()
        .eisenstein_hu_spectrum(TransferKind::NoWiggle, 0.0, &grid)
        .unwrap();
    let expected = 2.0 * 2f64.powf(1.0 - c.n_s);
    assert!((doubled.eval(0.1) / p.eval(0.1) / expected - 1.0).abs() < 1e-12);
    // Normalising by the σ8 that A_s gives reproduces the spectrum.
    let by_sigma8 = c
        .with_amplitude(Amplitude::Sigma8(p.sigma8()))
        .unwrap()
        .eisenstein_hu_spectrum(TransferKind::NoWiggle, 0.0, &grid)
        .unwrap();
    for k in [1e-3, 0.1, 1.0] {
        assert!((by_sigma8.eval(k) / p.eval(k) - 1.0).abs() < 1e-9, "k {k}");
    }
    // Dynamical dark energy only changes D_md(1): a w0 > −1 model has less growth since matter domination.
    let de = c.with_dark_energy(-0.8, 0.0).unwrap();
    let p_de = de
        .eisenstein_hu_spectrum(TransferKind::NoWiggle, 0.0, &grid)
        .unwrap();
    let ratio = (de.growth_md(1.0, de.method()) / c.growth_md(1.0, c.method())).powi(2);
    assert!(ratio < 1.0);
    assert!((p_de.eval(0.1) / p.eval(0.1) / ratio - 1.0).abs() < 1e-12);
}

#[test]
fn presets_are_known_by_name() {
    for name in PRESETS {
        let c = Cosmology::preset(name).unwrap();
        assert!(c.validate().is_ok(), "{name}");
    }
    assert_eq!(Cosmology::preset("gm2012").unwrap(), Cosmology::gm2012());
    assert_eq!(Cosmology::default(), Cosmology::gm2012());
    let p = Cosmology::preset("planck2018").unwrap();
    assert_eq!(p, Cosmology::planck2018());
    assert!((p.omega_m - 0.309_641_441_5).abs() < 1e-10);
    assert_eq!(p.omega_k(), 0.0);
    let e = Cosmology::preset("planck2015").unwrap_err();
    let message = e.to_string();
    assert!(
        message.contains("`planck2015`") && message.contains("gm2012, planck2018"),
        "{message}"
    );
}

#[test]
fn describe_gives_one_line_of_parameters() {
    assert_eq!(
        Cosmology::planck2018().describe(),
        "Omega_m = 0.309641, Omega_DE = 0.690359, Omega_k = 0, h = 0.6766, omega_b = 0.02242, \
         n_s = 0.9665, A_s = 2.105209e-09, w0 = -1, wa = 0"
    );
    assert_eq!(
        Cosmology::gm2012().describe(),
        "Omega_m = 0.27, Omega_DE = 0.73, Omega_k = 0, h = 0.7, omega_b = 0.023, n_s = 0.95, \
         sigma8 = 0.8, w0 = -1, wa = 0"
    );
    let c = Cosmology::new(0.3, 0.6, 0.7, 0.022, 0.96, 0.8)
        .unwrap()
        .with_dark_energy(-0.9, 0.1)
        .unwrap()
        .with_amplitude(Amplitude::As {
            a_s: 2.1e-9,
            k_pivot: 0.002,
        })
        .unwrap();
    assert_eq!(
        c.describe(),
        "Omega_m = 0.3, Omega_DE = 0.6, Omega_k = 0.1, h = 0.7, omega_b = 0.022, n_s = 0.96, \
         A_s = 2.1e-09, k_pivot = 0.002/Mpc, w0 = -0.9, wa = 0.1"
    );
    assert!(!c.describe().contains('\n'));
    assert_eq!(number(1.5e12), "1.5e+12");
    assert_eq!(number(-3e-7), "-3e-07");
    assert_eq!(number(f64::NAN), "NaN");
}

#[test]
fn invalid_amplitudes_are_rejected() {
    let c = Cosmology::gm2012();
    for (amplitude, name) in [
        (Amplitude::a_s(-2e-9), "A_s = -2e-9"),
        (Amplitude::a_s(f64::NAN), "A_s = NaN"),
        (
            Amplitude::As {
                a_s: 2e-9,
                k_pivot: 0.0,
            },
            "k_pivot [1/Mpc] = 0",
        ),
        (Amplitude::Sigma8(f64::INFINITY), "sigma8 = inf"),
    ] {
        let e = c.with_amplitude(amplitude).unwrap_err();
        assert!(e.to_string().contains(name), "{e}");
    }
}
