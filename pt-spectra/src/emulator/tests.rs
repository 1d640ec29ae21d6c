use super::nodes::lagrange;
use super::*;
use crate::cosmology::{Amplitude, Neutrinos};
use crate::error::Error;

/// One held-out CAMB cosmology of `tests/data/emulator_heldout.dat`.
struct Heldout {
    params: [f64; 8],
    z: f64,
    k: Vec<f64>,
    p_cb: Vec<f64>,
    p_m: Vec<f64>,
    f_cb: Vec<f64>,
    sigma8: f64,
}

fn heldout() -> Vec<Heldout> {
    let path = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/tests/data/emulator_heldout.dat"
    );
    let text = std::fs::read_to_string(path).expect("held-out table");
    let mut out: Vec<Heldout> = Vec::new();
    for line in text.lines().filter(|l| !l.starts_with('#')) {
        let v: Vec<f64> = line
            .split_whitespace()
            .map(|x| x.parse().unwrap())
            .collect();
        let index = v[0] as usize;
        if out.len() == index {
            out.push(Heldout {
                params: v[1..9].try_into().unwrap(),
                z: v[9],
                k: Vec::new(),
                p_cb: Vec::new(),
                p_m: Vec::new(),
                f_cb: Vec::new(),
                sigma8: v[14],
            });
        }
        let h = &mut out[index];
        h.k.push(v[10]);
        h.p_cb.push(v[11]);
        h.p_m.push(v[12]);
        h.f_cb.push(v[13]);
    }
    out
}

/// The embedded emulator with its stated prior widened to the training box and no early dark-energy
/// bound: the held-out sets below were drawn over the training box and check the fit there (its corners
/// are beyond the stated accuracy and refused by the emulator itself, tested further below).
fn on_the_training_box() -> LinearEmulator {
    let mut e = LinearEmulator::embedded().unwrap();
    e.file.stated = e.file.prior[..SHAPE_PARAMETERS].to_vec();
    e.file.q_bound = 1.0;
    e
}

fn cosmology(p: &[f64; 8]) -> Cosmology {
    let [ob, om, h, m_nu, w0, wa, ln_as, n_s] = *p;
    let mut c = Cosmology::planck2018();
    c.omega_m = om;
    c.omega_lambda = 1.0 - om;
    c.h = h;
    c.omega_b_h2 = ob * h * h;
    c.n_s = n_s;
    c.amplitude = Amplitude::a_s(ln_as.exp() * 1e-10);
    c.w0 = w0;
    c.wa = wa;
    c.m_nu = m_nu;
    c.validate().unwrap();
    c
}

#[test]
fn held_out_camb_spectra_growth_rates_and_sigma8() {
    let emulator = on_the_training_box();
    let (mut worst_p, mut worst_f, mut worst_s8) = (0.0_f64, 0.0_f64, 0.0_f64);
    let mut checked = 0;
    for h in heldout() {
        // drawn over the training box: those outside the stated prior are refused (tested below)
        let e = match emulator.spectra(&cosmology(&h.params), h.z) {
            Err(Error::OutsidePrior { .. }) => continue,
            e => e.unwrap(),
        };
        checked += 1;
        let (m, cb) = (e.matter().unwrap(), e.cb().unwrap());
        let f = LinearSpectrum::from_nodes(e.k.clone(), e.f_cb.iter().map(|v| v + 1.0).collect())
            .unwrap();
        for i in 0..h.k.len() {
            worst_p = worst_p
                .max((m.eval(h.k[i]) / h.p_m[i] - 1.0).abs())
                .max((cb.eval(h.k[i]) / h.p_cb[i] - 1.0).abs());
            worst_f = worst_f.max(((f.eval(h.k[i]) - 1.0) / h.f_cb[i] - 1.0).abs());
        }
        worst_s8 = worst_s8.max((e.sigma8 / h.sigma8 - 1.0).abs());
    }
    eprintln!("held out ({checked}): P {worst_p:.2e}, f_cb {worst_f:.2e}, sigma8 {worst_s8:.2e}");
    assert_eq!(checked, 16);
    assert!(worst_p < 2e-3, "P: {worst_p}");
    assert!(worst_f < 3e-3, "f_cb: {worst_f}");
    assert!(worst_s8 < 1e-3, "sigma8: {worst_s8}");
}

#[test]
fn sigma8_normalisation_matches_a_s_and_the_library_integral() {
    let emulator = LinearEmulator::embedded().unwrap();
    let c = Cosmology::planck2018().with_neutrinos(0.2).unwrap();
    let by_as = emulator.spectra(&c, 0.5).unwrap();
    // σ8 of the emulator's own quadrature against LinearSpectrum::sigma_r on the same nodes
    let (s, err) = by_as.matter().unwrap().sigma_r(8.0).unwrap();
    assert!(
        (by_as.sigma8 / s - 1.0).abs() < 1e-4 + err / s,
        "{} {s}",
        by_as.sigma8
    );
    // normalising by σ8(z = 0) instead gives back A_s
    let today = emulator.spectra(&c, 0.0).unwrap().sigma8;
    let by_s8 = emulator
        .spectra(&c.with_amplitude(Amplitude::Sigma8(today)).unwrap(), 0.5)
        .unwrap();
    assert!(
        (by_s8.a_s / 2.105209e-9 - 1.0).abs() < 1e-10,
        "{}",
        by_s8.a_s
    );
    assert!((by_s8.p_m[200] / by_as.p_m[200] - 1.0).abs() < 1e-10);
}

#[test]
fn massless_neutrinos_give_p_cb_equal_to_p_m_and_the_ode_growth_rate() {
    let emulator = LinearEmulator::embedded().unwrap();
    let c = Cosmology::planck2018();
    for z in [0.0, 0.7, 2.0] {
        let e = emulator.spectra(&c, z).unwrap();
        for i in (0..e.k.len()).step_by(25) {
            // the ODE neglects radiation: 2e-3 at these redshifts
            if (1e-3..1.0).contains(&e.k[i]) {
                // the emulated ratio is the emulator's error here (exactly 1 in CAMB)
                assert!((e.p_m[i] / e.p_cb[i] - 1.0).abs() < 1e-3, "{z} {}", e.k[i]);
                let f = c.growth_rate(z);
                assert!(
                    (e.f_cb[i] / f - 1.0).abs() < 3e-3,
                    "{z} {} {}",
                    e.f_cb[i],
                    f
                );
            }
        }
    }
}

#[test]
fn neutrinos_suppress_small_scales_by_the_free_streaming_limit() {
    // Linear theory: P_m(k ≫ k_fs)/P_m(m_nu = 0) → ≈ 1 − 8 f_ν at z = 0 (Hu, Eisenstein & Tegmark 1998)
    let emulator = LinearEmulator::embedded().unwrap();
    let c0 = Cosmology::planck2018();
    let c = c0.with_neutrinos(0.3).unwrap();
    let f_nu = c.omega_nu() / (c.omega_m * c.h * c.h);
    let (a, b) = (
        emulator.spectra(&c, 0.0).unwrap(),
        emulator.spectra(&c0, 0.0).unwrap(),
    );
    let i = a.k.iter().position(|&k| k > 2.0).unwrap();
    let ratio = a.p_m[i] / b.matter().unwrap().eval(a.k[i]);
    assert!((ratio - (1.0 - 8.0 * f_nu)).abs() < 0.03, "{ratio} {f_nu}");
    // large scales unchanged (same A_s, Omega_m)
    let j = a.k.iter().position(|&k| k > 2e-4).unwrap();
    assert!((a.p_m[j] / b.matter().unwrap().eval(a.k[j]) - 1.0).abs() < 0.02);
}

#[test]
fn outside_the_prior_names_the_parameter() {
    let emulator = LinearEmulator::embedded().unwrap();
    let c = Cosmology::planck2018().with_neutrinos(0.7).unwrap();
    let e = emulator.spectra(&c, 0.0).unwrap_err().to_string();
    assert!(e.contains("m_nu = 0.7") && e.contains("[0, 0.45]"), "{e}");
    let curved = Cosmology::new(0.3, 0.65, 0.7, 0.022, 0.96, 0.8).unwrap();
    let e = emulator.spectra(&curved, 0.0).unwrap_err().to_string();
    assert!(e.contains("Omega_k"), "{e}");
    let e = emulator
        .spectra(&Cosmology::planck2018(), 3.5)
        .unwrap_err()
        .to_string();
    assert!(e.contains("z = 3.5"), "{e}");
}

#[test]
fn a_broken_file_is_an_error_with_the_offset() {
    let e = LinearEmulator::from_bytes(b"PTEMU001\x01", "test file").unwrap_err();
    assert!(
        e.to_string().contains("test file: malformed at byte 8"),
        "{e}"
    );
    let e = LinearEmulator::from_bytes(b"NOTEMU01", "x").unwrap_err();
    assert!(e.to_string().contains("not an emulator file"), "{e}");
}

#[test]
fn lagrange_weights_reproduce_a_cubic_and_its_derivative() {
    let nodes = [0.1, 0.3, 0.5, 0.7];
    let cubic = |s: f64| 2.0 - s + 3.0 * s * s - 0.5 * s * s * s;
    let d_cubic = |s: f64| -1.0 + 6.0 * s - 1.5 * s * s;
    let (w, dw) = lagrange(&nodes, 0.42);
    let v: f64 = (0..4).map(|j| w[j] * cubic(nodes[j])).sum();
    let d: f64 = (0..4).map(|j| dw[j] * cubic(nodes[j])).sum();
    assert!((v - cubic(0.42)).abs() < 1e-13 && (d - d_cubic(0.42)).abs() < 1e-12);
}

#[test]
fn class_spectra_of_six_cosmologies_agree() {
    // A second Boltzmann code: CLASS with the same neutrinos and PPF dark energy
    // (tests/data/make_emulator_class.py). CAMB and CLASS themselves, both at default precision,
    // differ on these by 0.7e-3 (Planck, massless) to 5.7e-3 (m_nu = 0.45 eV): the bound is theirs.
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/data/emulator_class.dat");
    let text = std::fs::read_to_string(path).expect("CLASS table");
    let emulator = on_the_training_box();
    let mut worst = 0.0_f64;
    let mut current: Option<(usize, EmulatedSpectra)> = None;
    for line in text.lines().filter(|l| !l.starts_with('#')) {
        let v: Vec<f64> = line
            .split_whitespace()
            .map(|x| x.parse().unwrap())
            .collect();
        let index = v[0] as usize;
        if current.as_ref().map(|c| c.0) != Some(index) {
            let params: [f64; 8] = v[1..9].try_into().unwrap();
            current = Some((index, emulator.spectra(&cosmology(&params), v[9]).unwrap()));
        }
        let e = &current.as_ref().unwrap().1;
        let (m, cb) = (e.matter().unwrap(), e.cb().unwrap());
        let d = (cb.eval(v[10]) / v[11] - 1.0)
            .abs()
            .max((m.eval(v[10]) / v[12] - 1.0).abs());
        worst = worst.max(d);
    }
    eprintln!("CLASS: worst {worst:.2e}");
    assert!(worst < 7e-3, "{worst}");
}

#[test]
fn scale_dependent_growth_agrees_with_camb_transfer_functions() {
    // CAMB's D_cb(k, z) = T_cb(k, z)/T_cb(k, 0) for Σm_ν = 0.06 … 0.5 eV at z = 0.5 … 3
    // (tests/data/emulator_growth.dat, make_emulator_growth.py); the issue asks for 0.3%.
    let path = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/tests/data/emulator_growth.dat"
    );
    let text = std::fs::read_to_string(path).expect("growth table");
    let emulator = on_the_training_box();
    let (mut worst, mut spread) = (0.0_f64, 0.0_f64);
    let mut current: Option<((usize, u64), ScaleDependentGrowth)> = None;
    for line in text.lines().filter(|l| !l.starts_with('#')) {
        let v: Vec<f64> = line
            .split_whitespace()
            .map(|x| x.parse().unwrap())
            .collect();
        let key = (v[0] as usize, v[9].to_bits());
        if current.as_ref().map(|c| c.0) != Some(key) {
            let g = emulator
                .growth_cb(&cosmology(&v[1..9].try_into().unwrap()), v[9])
                .unwrap();
            current = Some((key, g));
        }
        let g = &current.as_ref().unwrap().1;
        let i = g.k.partition_point(|&k| k < v[10]);
        let t = (v[10].ln() - g.k[i - 1].ln()) / (g.k[i].ln() - g.k[i - 1].ln());
        let d = g.d_cb[i - 1] + t * (g.d_cb[i] - g.d_cb[i - 1]);
        worst = worst.max((d / v[11] - 1.0).abs());
        spread = spread.max(g.d_cb[i] / g.d_cb[0] - 1.0);
    }
    println!(
        "D_cb(k, z): worst |emulated/CAMB − 1| {worst:.1e}; D(1)/D(1e-3) − 1 up to {spread:.3}"
    );
    assert!(worst < 3e-3, "{worst}");
    // the scale dependence is resolved: since z, the small scales grew less (free streaming) by percents
    assert!(spread > 0.01, "{spread}");
}

/// |Δ ln P| allowed against CAMB over the stated prior (the accuracy the issue asks for; measured
/// worst 1.3e-3 with massive neutrinos, 1.1e-3 massless, docs/emulator.md).
const STATED_ACCURACY: f64 = 2e-3;

#[test]
fn corners_of_the_stated_prior_agree_with_camb() {
    // pt-spectra/tests/data/emulator_corners.dat: CAMB at three corners of the stated box
    let path = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/tests/data/emulator_corners.dat"
    );
    let text = std::fs::read_to_string(path).expect("corner table");
    let emulator = LinearEmulator::embedded().unwrap();
    let mut worst = 0.0_f64;
    let mut rows = 0;
    for line in text.lines().filter(|l| !l.starts_with('#')) {
        let v: Vec<f64> = line
            .split_whitespace()
            .map(|x| x.parse().unwrap())
            .collect();
        let e = emulator
            .spectra(&cosmology(&v[1..9].try_into().unwrap()), v[9])
            .unwrap();
        let (m, cb) = (e.matter().unwrap(), e.cb().unwrap());
        worst = worst
            .max((cb.eval(v[10]) / v[11]).ln().abs())
            .max((m.eval(v[10]) / v[12]).ln().abs());
        rows += 1;
    }
    eprintln!("corners: worst |dln P| {worst:.2e} on {rows} rows");
    assert!(rows >= 100, "{rows}");
    assert!(worst <= STATED_ACCURACY, "{worst}");
    // and the header's figure is the measured worst case, not below what this table shows
    let w = emulator.worst(Neutrinos::ThreeDegenerate).unwrap();
    assert!(w[0].max(w[1]) >= worst && w[1] <= STATED_ACCURACY, "{w:?}");
}

#[test]
fn massless_and_light_neutrinos_at_the_worst_points_agree_with_camb() {
    // pt-spectra/tests/data/emulator_massless.dat (make_emulator_massless.py): CAMB at the massless
    // corner where the emulator without its massless head was 3.0e-3 off, the massless random draw
    // where it was 2.75e-3 off, the worst points with the head, and two light corners (0.01, 0.03 eV)
    let path = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/tests/data/emulator_massless.dat"
    );
    let text = std::fs::read_to_string(path).expect("massless table");
    let emulator = LinearEmulator::embedded().unwrap();
    let (mut massless, mut light, mut rows) = (0.0_f64, 0.0_f64, 0);
    for line in text.lines().filter(|l| !l.starts_with('#')) {
        let v: Vec<f64> = line
            .split_whitespace()
            .map(|x| x.parse().unwrap())
            .collect();
        let e = emulator
            .spectra(&cosmology(&v[1..9].try_into().unwrap()), v[9])
            .unwrap();
        let d = (e.cb().unwrap().eval(v[10]) / v[11])
            .ln()
            .abs()
            .max((e.matter().unwrap().eval(v[10]) / v[12]).ln().abs());
        if v[4] == 0.0 {
            massless = massless.max(d);
            // the spectra carry the massless head's measured worst case
            assert_eq!(e.worst, emulator.worst_massless().unwrap());
        } else {
            light = light.max(d);
        }
        rows += 1;
    }
    eprintln!("massless: worst |dln P| {massless:.2e}, light {light:.2e} on {rows} rows");
    assert_eq!(rows, 6 * 4 * 12);
    assert!(
        massless <= STATED_ACCURACY && light <= STATED_ACCURACY,
        "{massless} {light}"
    );
    // the stated figures are the measured worst cases, not below what this table shows
    let w = emulator.worst_massless().unwrap();
    assert!(
        w[0].max(w[1]) >= massless && w[1] <= STATED_ACCURACY,
        "{w:?}"
    );
    let w = emulator.worst(Neutrinos::ThreeDegenerate).unwrap();
    assert!(w[0].max(w[1]) >= light && w[1] <= STATED_ACCURACY, "{w:?}");
}

#[test]
fn the_corners_beyond_the_stated_prior_are_refused() {
    let emulator = LinearEmulator::embedded().unwrap();
    // the case: w0 = -0.7, wa = 0.5 (9.9e-3 off CAMB) is outside the stated box
    let mut c = Cosmology::planck2018().with_neutrinos(0.06).unwrap();
    c.w0 = -0.7;
    c.wa = 0.5;
    let e = emulator.spectra(&c, 0.0).unwrap_err().to_string();
    assert!(e.contains("w0 = -0.7") && e.contains("prior"), "{e}");
    // inside the box but with too much early dark energy: refused naming the bound
    c.w0 = -0.76;
    c.wa = 0.38;
    c.omega_m = 0.26;
    c.omega_lambda = 0.74;
    c.omega_b_h2 = 0.05 * c.h * c.h;
    let e = emulator.spectra(&c, 0.0).unwrap_err().to_string();
    assert!(
        e.contains("rho_DE/rho_m at a = 0.1") && e.contains("w0, wa"),
        "{e}"
    );
    assert!(
        emulator.describe().contains("rho_DE/rho_m at a = 0.1"),
        "{}",
        emulator.describe()
    );
}

#[test]
fn neutrino_settings_that_are_not_emulated_are_refused_naming_them() {
    let emulator = LinearEmulator::embedded().unwrap();
    let c = Cosmology::planck2018().with_neutrinos(0.39).unwrap();
    assert!(emulator.spectra(&c, 0.0).is_ok());
    for (setting, name) in [
        (Neutrinos::OneMassive, "one massive species"),
        (Neutrinos::NormalHierarchy, "normal hierarchy"),
        (Neutrinos::InvertedHierarchy, "inverted hierarchy"),
    ] {
        let e = emulator
            .spectra(&c.with_neutrino_species(setting), 0.0)
            .unwrap_err()
            .to_string();
        assert!(e.contains(name) && e.contains("three degenerate"), "{e}");
    }
    // massless: how a zero mass is shared does not matter
    let c = Cosmology::planck2018().with_neutrino_species(Neutrinos::OneMassive);
    assert!(emulator.spectra(&c, 0.0).is_ok());
    // the CLASS file of the issue, with its N_ur: refused, not emulated as three species
    let text = "h = 0.67\nomega_b = 0.022445\nomega_cdm = 0.1207\nn_s = 0.965\nA_s = 2.1e-9\n\
                N_ncdm = 1\nm_ncdm = 0.39\nN_ur = 2.0328\n";
    let c = Cosmology::from_ini_str(text, "nu.ini").unwrap().cosmology;
    assert_eq!(c.neutrinos, Neutrinos::OneMassive);
    let e = emulator.spectra(&c, 0.0).unwrap_err().to_string();
    assert!(e.contains("one massive species"), "{e}");
}

#[test]
fn a_file_of_layout_two_is_validated() {
    let good = EMBEDDED.to_vec();
    let parsed = LinearEmulator::from_bytes(&good, "x").unwrap().file;
    // the end of the PTEMU001 body (layout in format.rs), where the PTEMU002 tail begins
    let (n_x, n_terms) = (parsed.n_x, parsed.exponents.len());
    let nodes = parsed.z_nodes.len() * n_x;
    let body = 8
        + 6 * 4
        + 16 * 8
        + 8 * parsed.z_nodes.len()
        + 4 * 8
        + 7 * n_terms
        + parsed
            .targets
            .iter()
            .map(|t| 8 * nodes + 4 * t.n_pc * nodes + 8 * n_terms * t.n_pc)
            .sum::<usize>()
        + 2 * 8 * n_x;
    // a stated box wider than the training box
    let mut bad = good.clone();
    let at = body; // the stated box
    bad[at..at + 8].copy_from_slice(&0.0f64.to_le_bytes());
    let e = LinearEmulator::from_bytes(&bad, "x")
        .unwrap_err()
        .to_string();
    assert!(e.contains("stated prior"), "{e}");
    // a bound beyond (0, 1]
    let mut bad = good.clone();
    let at = body + 12 * 8;
    bad[at..at + 8].copy_from_slice(&2.0f64.to_le_bytes());
    let e = LinearEmulator::from_bytes(&bad, "x")
        .unwrap_err()
        .to_string();
    assert!(e.contains("prior bound"), "{e}");
    // the massless head given twice (the count of heads raised, the head's bytes repeated)
    let heads = body + 15 * 8;
    let mut twice = good[..heads].to_vec();
    twice.extend(2u32.to_le_bytes());
    twice.extend(&good[heads + 4..]);
    twice.extend(&good[heads + 4..]);
    assert_eq!(
        u32::from_le_bytes(good[heads..heads + 4].try_into().unwrap()),
        1
    );
    let e = LinearEmulator::from_bytes(&twice, "x")
        .unwrap_err()
        .to_string();
    assert!(e.contains("two heads"), "{e}");
    // a head of an unknown kind
    let mut bad = good.clone();
    bad[heads + 4..heads + 8].copy_from_slice(&7u32.to_le_bytes());
    let e = LinearEmulator::from_bytes(&bad, "x")
        .unwrap_err()
        .to_string();
    assert!(e.contains("x") && e.contains("implausibly large"), "{e}");
}

/// The rows of `pt-spectra/tests/data/emulator_small_masses.dat` (CAMB, three degenerate species of
/// Σm_ν = 0 … 0.1 eV, four cosmologies, z = 0 and 1): (parameters, z, k, P_cb, P_m).
fn small_masses() -> Vec<([f64; 8], f64, f64, f64, f64)> {
    let path = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/tests/data/emulator_small_masses.dat"
    );
    let text = std::fs::read_to_string(path).expect("small-mass table");
    text.lines()
        .filter(|l| !l.starts_with('#'))
        .map(|line| {
            let v: Vec<f64> = line
                .split_whitespace()
                .map(|x| x.parse().unwrap())
                .collect();
            (v[1..9].try_into().unwrap(), v[9], v[10], v[11], v[12])
        })
        .collect()
}

#[test]
fn p_m_is_continuous_as_the_neutrino_mass_goes_to_zero() {
    // issue 45: P_m jumped by 7e-4 to 1.2e-3 between Σm_ν = 0 (P_m = P_cb) and 0⁺ (the emulated
    // ratio's offset); now P_m(Σm_ν) → P_cb(0) = P_m(0) continuously, and P_m/P_cb → 1
    let emulator = LinearEmulator::embedded().unwrap();
    let mut checked = 0;
    for (params, z, ..) in small_masses().into_iter().step_by(12 * 2 * 7) {
        let mut p = params;
        p[3] = 0.0;
        let massless = emulator.spectra(&cosmology(&p), z).unwrap();
        for (m_nu, bound) in [(1e-6, 2e-6), (1e-4, 1.5e-4)] {
            p[3] = m_nu;
            let e = emulator.spectra(&cosmology(&p), z).unwrap();
            for i in (0..e.k.len()).step_by(25) {
                let jump = (e.p_m[i] / massless.p_m[i]).ln().abs();
                let ratio = (e.p_m[i] / e.p_cb[i]).ln().abs();
                assert!(
                    jump < bound && ratio < bound,
                    "{m_nu} eV, k {}: {jump:e} {ratio:e}",
                    e.k[i]
                );
            }
        }
        checked += 1;
    }
    assert_eq!(checked, 4);
}

#[test]
fn small_neutrino_masses_agree_with_camb() {
    // CAMB at Σm_ν = 0, 0.005, …, 0.1 eV (make_emulator_small_masses.py). Measured: ≤ 6.3e-4 for
    // Σm_ν ≥ 0.005 eV; 2.5e-4 at exactly 0 (1.0e-3 to 2.1e-3 before the massless head: CAMB's
    // massless run lies up to 9e-4 from the limit of its massive runs, which the base follows)
    let emulator = LinearEmulator::embedded().unwrap();
    let (mut massive, mut massless) = (0.0_f64, 0.0_f64);
    for (params, z, k, p_cb, p_m) in small_masses() {
        let e = emulator.spectra(&cosmology(&params), z).unwrap();
        let d = (e.cb().unwrap().eval(k) / p_cb)
            .ln()
            .abs()
            .max((e.matter().unwrap().eval(k) / p_m).ln().abs());
        if params[3] > 0.0 {
            massive = massive.max(d);
        } else {
            massless = massless.max(d);
        }
    }
    eprintln!("small masses: worst |dln P| {massive:.2e} (massive), {massless:.2e} (massless)");
    assert!(massive < 8e-4, "{massive}");
    assert!(massless < 5e-4, "{massless}");
}

/// The shared emulator is parsed once (the same object at every call) and emulates as a freshly
/// parsed one does, to the bit.
#[test]
fn the_shared_emulator_is_parsed_once_and_equals_a_fresh_one() {
    let (a, b) = (
        LinearEmulator::shared().unwrap(),
        LinearEmulator::shared().unwrap(),
    );
    assert!(std::ptr::eq(a, b));
    let c = Cosmology::planck2018().with_neutrinos(0.1).unwrap();
    let fresh = LinearEmulator::embedded()
        .unwrap()
        .spectra(&c, 0.7)
        .unwrap();
    let shared = a.spectra(&c, 0.7).unwrap();
    assert_eq!(
        (fresh.k, fresh.p_m, fresh.p_cb),
        (shared.k, shared.p_m, shared.p_cb)
    );
}
