//! The bispectrum block in a forecast: its triangle bins' volume, and B0 beside the power spectrum.

use crate::bispectrum::block::KIND;
use crate::cosmology::Cosmology;
use crate::forecast::{fisher, Forecast, Parameters, SurveyBin};
use crate::progress::Silent;
use crate::store::TableStore;

/// The template forecast of `bins` in Planck 2018, no shared priors.
fn template(bins: &[SurveyBin]) -> Forecast {
    fisher(
        bins,
        &Cosmology::planck2018(),
        Parameters::Template,
        &[],
        &TableStore::new(std::env::temp_dir().join("pt-spectra-forecast-tests")),
        &Silent,
    )
    .unwrap()
}

#[test]
fn the_triangle_bin_volume_counts_the_triangles_of_a_box() {
    // in units of k_f: the number of ordered pairs of integer modes (n1, n2) with |n1|, |n2|,
    // |n1 + n2| in shells of width 2 about 10, 12, 14 (a general triangle) and 12, 12, 12
    // (equilateral) is the bin volume 8π² k1 k2 k3 Δk³ to the discreteness of the shells
    let shell = |c: f64| -> Vec<[i64; 3]> {
        let m = (c + 1.0).ceil() as i64;
        let mut out = Vec::new();
        for x in -m..=m {
            for y in -m..=m {
                for z in -m..=m {
                    let r = ((x * x + y * y + z * z) as f64).sqrt();
                    if r >= c - 1.0 && r < c + 1.0 {
                        out.push([x, y, z]);
                    }
                }
            }
        }
        out
    };
    for k in [[10.0, 12.0, 14.0], [12.0, 12.0, 12.0]] {
        let (a, b) = (shell(k[0]), shell(k[1]));
        let mut count = 0usize;
        for p in &a {
            for q in &b {
                let s = [p[0] + q[0], p[1] + q[1], p[2] + q[2]];
                let r = ((s[0] * s[0] + s[1] * s[1] + s[2] * s[2]) as f64).sqrt();
                if r >= k[2] - 1.0 && r < k[2] + 1.0 {
                    count += 1;
                }
            }
        }
        let v = crate::bispectrum::block::triangle_bin_volume(k, 2.0);
        assert!(
            (count as f64 / v - 1.0).abs() < 0.03,
            "{k:?}: {count} vs {v}"
        );
    }
}

#[test]
fn the_bispectrum_monopole_adds_information_and_keeps_the_volume_scaling() {
    let bin = SurveyBin::new(0.6, 2e9, 3e-4, 0.12, 2.0);
    let p_only = template(std::slice::from_ref(&bin));
    let with_b = bin.clone().with_block(&KIND, 0.08);
    let pb = template(std::slice::from_ref(&with_b));
    for name in ["c1_1", "b_shot_1", "a_shot_1"] {
        assert!(pb.names.iter().any(|n| n == name), "{name}");
    }
    // B shares f, the α's, b1, b2, bs: every shared error shrinks
    for name in ["f_1", "apar_1", "aperp_1", "b1_1", "b2_1", "bs_1"] {
        let at = |f: &Forecast| f.names.iter().position(|n| n == name).unwrap();
        assert!(pb.sigma[at(&pb)] < p_only.sigma[at(&p_only)], "{name}");
    }
    assert!(pb.derivative_error < 1e-3, "{}", pb.derivative_error);
    let mut big = with_b.clone();
    big.volume *= 4.0;
    let four = template(std::slice::from_ref(&big));
    for (a, b) in pb.sigma.iter().zip(&four.sigma) {
        assert!((a / b - 2.0).abs() < 1e-9, "{a} {b}");
    }
}
