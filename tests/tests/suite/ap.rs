//! The Alcock–Paczynski projection and the background distances behind `--fiducial`.
//!
//! Distances against CAMB 2.0.5 (`tests/data/camb_distances.dat`, made by
//! `tests/data/make_camb_distances.py`); the projection against its limits (identity, isotropic
//! dilation) and an independent quadrature of a case in closed form.

use pt_spectra::cosmology::Cosmology;
use pt_spectra::linear::{LinearSpectrum, LogGrid};
use pt_spectra::precision::Precision;
use pt_spectra::real::{real_space, RealModel};
use pt_spectra::rsd::ap::Distortion;
use pt_spectra::rsd::{multipoles, Fog, Observed, RsdModel, RsdMultipoles, RsdSettings};
use pt_spectra::store::TableStore;

use crate::support::*;

/// H(z) and D_M(z) against CAMB, with its radiation (photons and 3.046 massless neutrinos): measured
/// 3.5e-11 (the table's 11 digits); without the neutrinos' radiation it would be 2.3e-4.
const CAMB_TOL: f64 = 1e-9;

#[test]
fn distances_agree_with_camb() {
    let cosmologies = [
        [
            ("h", "0.6766"),
            ("omega_b", "0.02242"),
            ("omega_cdm", "0.11933"),
            ("Omega_k", "0"),
            ("w0_fld", "-1"),
            ("wa_fld", "0"),
        ],
        [
            ("h", "0.7"),
            ("omega_b", "0.023"),
            ("omega_cdm", "0.1093"),
            ("Omega_k", "0"),
            ("w0_fld", "-1"),
            ("wa_fld", "0"),
        ],
        [
            ("h", "0.68"),
            ("omega_b", "0.0224"),
            ("omega_cdm", "0.12"),
            ("Omega_k", "0"),
            ("w0_fld", "-0.9"),
            ("wa_fld", "0.3"),
        ],
        [
            ("h", "0.7"),
            ("omega_b", "0.022"),
            ("omega_cdm", "0.12"),
            ("Omega_k", "0.05"),
            ("w0_fld", "-1"),
            ("wa_fld", "0"),
        ],
        [
            ("h", "0.65"),
            ("omega_b", "0.022"),
            ("omega_cdm", "0.13"),
            ("Omega_k", "-0.05"),
            ("w0_fld", "-1"),
            ("wa_fld", "0"),
        ],
    ];
    let cosmologies: Vec<Cosmology> = cosmologies
        .iter()
        .map(|keys| {
            let mut keys = keys.to_vec();
            keys.extend([("n_s", "0.96"), ("sigma8", "0.8")]);
            Cosmology::from_keys(keys, "test").unwrap().cosmology
        })
        .collect();
    let mut worst = [0.0_f64; 2];
    for row in rows(&data("camb_distances.dat")) {
        let (c, z, h_camb, dm_camb) = (&cosmologies[row[0] as usize], row[1], row[2], row[3]);
        // CAMB: km/s/Mpc and Mpc; ours: h km/s/Mpc and Mpc/h.
        let h = c.hubble(z) * c.h;
        let dm = c.transverse_comoving_distance(z) / c.h;
        worst[0] = worst[0].max((h / h_camb - 1.0).abs());
        worst[1] = worst[1].max((dm / dm_camb - 1.0).abs());
        assert!(
            (c.angular_diameter_distance(z) * (1.0 + z) / c.transverse_comoving_distance(z) - 1.0)
                .abs()
                < 1e-15
        );
    }
    println!(
        "worst |ours/CAMB − 1|: H {:.1e}, D_M {:.1e}",
        worst[0], worst[1]
    );
    assert!(worst[0] < CAMB_TOL && worst[1] < CAMB_TOL, "{worst:?}");
}

/// With three degenerate massive neutrinos (Σm_ν = 0.06, 0.3, 0.5 eV, part of Ω_m) against CAMB
/// (`camb_distances_mnu.dat`): the neutrinos are matter at z ≤ 3 and the photons the only radiation,
/// measured ≤ 2e-5 (counting the neutrinos as massless radiation too would be 2.3e-4 off).
#[test]
fn distances_with_massive_neutrinos_agree_with_camb() {
    let mut worst = [0.0_f64; 2];
    for row in rows(&data("camb_distances_mnu.dat")) {
        let (z, m_nu, h_camb, dm_camb) = (row[1], row[2], row[3], row[4]);
        let keys = [
            ("h", "0.675".to_string()),
            ("omega_b", "0.0224".to_string()),
            ("omega_cdm", "0.12".to_string()),
            ("N_ncdm", "1".to_string()),
            ("m_ncdm", (m_nu / 3.0).to_string()),
            ("deg_ncdm", "3".to_string()),
            ("N_ur", "0.00641".to_string()), // N_eff = 3.046 with three massive species (CLASS)
            ("n_s", "0.96".to_string()),
            ("sigma8", "0.8".to_string()),
        ];
        let keys: Vec<(&str, &str)> = keys.iter().map(|(k, v)| (*k, v.as_str())).collect();
        let c = Cosmology::from_keys(keys, "test").unwrap().cosmology;
        assert!((c.m_nu - m_nu).abs() < 1e-9, "{}", c.m_nu);
        worst[0] = worst[0].max((c.hubble(z) * c.h / h_camb - 1.0).abs());
        worst[1] = worst[1].max((c.transverse_comoving_distance(z) / c.h / dm_camb - 1.0).abs());
    }
    println!(
        "massive neutrinos, worst |ours/CAMB − 1|: H {:.1e}, D_M {:.1e}",
        worst[0], worst[1]
    );
    assert!(worst[0] < 3e-5 && worst[1] < 3e-5, "{worst:?}");
}

fn settings(model: RsdModel, bias: f64, f: f64, fog: Fog, sigma: f64, n: usize) -> RsdSettings {
    RsdSettings {
        model,
        f,
        bias: vec![bias; n],
        fog,
        sigma,
        noise: None,
        ells: vec![0, 2, 4, 6, 8],
        parts: false,
        cs2: 0.0,
        galaxy: None,
        ap: None,
    }
}

/// The multipoles of the 1-loop Scoccimarro model with Lorentzian FoG on `k`, with `ap` if any.
fn scoccimarro(k: &[f64], ap: Option<Distortion>) -> RsdMultipoles {
    let p = LinearSpectrum::gm2012(0.5).unwrap();
    let grid = match ap {
        Some(d) => d.internal_grid(k).unwrap(),
        None => k.to_vec(),
    };
    let real = real_space(
        RealModel::OneLoopSpt,
        &p,
        &grid,
        &Precision::fast(),
        &TableStore::in_memory(),
    )
    .unwrap();
    let mut s = settings(
        RsdModel::Scoccimarro,
        1.9,
        0.75,
        Fog::Lorentzian,
        4.0,
        grid.len(),
    );
    s.ap = ap.map(|distortion| Observed {
        distortion,
        k: k.to_vec(),
    });
    multipoles(&real, None, &s).unwrap()
}

/// α∥ = α⊥ = 1 reproduces the direct multipoles (the interpolation on the internal grid and the μ
/// rule are the only differences); an isotropic α gives α⁻³ P_ℓ(k/α) exactly in the model.
#[test]
fn identity_and_isotropic_dilation() {
    let k = [0.02, 0.047, 0.09, 0.13, 0.21];
    let direct = scoccimarro(&k, None);
    let identity = scoccimarro(&k, Some(Distortion::new(1.0, 1.0).unwrap()));
    let alpha = 1.04;
    let dilated = scoccimarro(&k, Some(Distortion::new(alpha, alpha).unwrap()));
    let shifted: Vec<f64> = k.iter().map(|k| k / alpha).collect();
    let reference = scoccimarro(&shifted, None);
    let mut worst = [0.0_f64; 2];
    for j in 0..5 {
        for i in 0..k.len() {
            let scale = direct.total[0][i].value;
            let d = (identity.total[j][i].value - direct.total[j][i].value).abs() / scale;
            let r = reference.total[j][i].value / alpha.powi(3);
            let e = (dilated.total[j][i].value - r).abs() / scale;
            worst = [worst[0].max(d), worst[1].max(e)];
        }
    }
    println!(
        "identity {:.1e}, isotropic dilation {:.1e} (relative to P0)",
        worst[0], worst[1]
    );
    assert!(worst[0] < 1e-5 && worst[1] < 1e-5, "{worst:?}");
}

/// A flat spectrum P = A through linear Kaiser: the observed P(k, μ) = A (b + f μ'²)²/(α∥α⊥²) with
/// μ'² = μ²/(F² + μ²(1 − F²)), integrated here by composite Simpson on 20,000 intervals.
#[test]
fn anisotropic_distortion_of_a_flat_kaiser_spectrum() {
    let a = 5000.0;
    let flat = LinearSpectrum::from_fn(&LogGrid::new(1e-5, 1e3, 400).unwrap(), |_| a).unwrap();
    let d = Distortion::new(1.1, 0.93).unwrap();
    let k = [0.05, 0.1, 0.2];
    let grid = d.internal_grid(&k).unwrap();
    let real = real_space(
        RealModel::Linear,
        &flat,
        &grid,
        &Precision::fast(),
        &TableStore::in_memory(),
    )
    .unwrap();
    let (b, f) = (2.1, 0.8);
    let mut s = settings(RsdModel::Kaiser, b, f, Fog::None, 0.0, grid.len());
    s.ap = Some(Observed {
        distortion: d,
        k: k.to_vec(),
    });
    let m = multipoles(&real, None, &s).unwrap();
    let f_ratio = d.apar / d.aperp;
    let observed = |mu: f64| {
        let m2 = mu * mu / (f_ratio * f_ratio + mu * mu * (1.0 - f_ratio * f_ratio));
        a * (b + f * m2).powi(2) * d.volume()
    };
    let legendre = |l: usize, mu: f64| {
        let (mut p0, mut p1) = (1.0, mu);
        if l == 0 {
            return 1.0;
        }
        for j in 1..l {
            let p2 = ((2 * j + 1) as f64 * mu * p1 - j as f64 * p0) / (j + 1) as f64;
            (p0, p1) = (p1, p2);
        }
        p1
    };
    let n = 20_000;
    for (j, l) in [0, 2, 4, 6, 8].into_iter().enumerate() {
        let h = 1.0 / n as f64;
        let simpson: f64 = (0..=n)
            .map(|i| {
                let mu = i as f64 * h;
                let w = if i == 0 || i == n {
                    1.0
                } else if i % 2 == 1 {
                    4.0
                } else {
                    2.0
                };
                w * legendre(l, mu) * observed(mu)
            })
            .sum::<f64>()
            * h
            / 3.0
            * (2 * l + 1) as f64;
        for i in 0..k.len() {
            let got = m.total[j][i];
            assert!(
                (got.value - simpson).abs() < 1e-9 * observed(0.0),
                "l = {l}: {} vs {simpson}",
                got.value
            );
            assert!(
                got.error >= 0.0 && got.error < 1e-6 * observed(0.0),
                "l = {l}: error {}",
                got.error
            );
        }
    }
}

#[test]
fn fiducial_cosmology_gives_the_distance_ratios() {
    let truth = Cosmology::planck2018();
    let fid = Cosmology::gm2012();
    let z = 0.61;
    let d = Distortion::from_cosmologies(&truth, &fid, z).unwrap();
    assert!((d.apar - fid.hubble(z) / truth.hubble(z)).abs() < 1e-15);
    assert!(
        (d.aperp - truth.transverse_comoving_distance(z) / fid.transverse_comoving_distance(z))
            .abs()
            < 1e-15
    );
    let same = Distortion::from_cosmologies(&truth, &truth, z).unwrap();
    assert_eq!((same.apar, same.aperp), (1.0, 1.0));
    assert!(Distortion::from_cosmologies(&truth, &fid, 0.0).is_err());
}
