//! The one-loop galaxy bispectrum per bias monomial (issue 50, `bispectrum::one_loop_galaxy_poly`) against
//! the direct terms at random coefficients, the matter terms, and monomial counts derived here.

use std::collections::BTreeSet;

use pt_spectra::bispectrum::bias_kernels::{
    galaxy_kernel, galaxy_kernel_parts, galaxy_redshift_kernel, operator_kernels, LoopBias,
    LOWEST_ORDER, N_BIAS,
};
use pt_spectra::bispectrum::one_loop::{one_loop_matter, OneLoopRule};
use pt_spectra::bispectrum::one_loop_galaxy::{one_loop_galaxy, OneLoopGalaxy};
use pt_spectra::bispectrum::one_loop_galaxy_poly::{
    monomial_name, one_loop_galaxy_polynomial, GalaxyLoopPolynomial,
};
use pt_spectra::bispectrum::one_loop_rsd::{one_loop_matter_redshift, Orientation};
use pt_spectra::linear::LinearSpectrum;
use pt_spectra::loops::Estimate;

use crate::bispectrum_galaxy_kernels::{galaxy_bias, vectors};

fn small() -> OneLoopRule {
    OneLoopRule {
        radial: 6,
        mu: 12,
        phi: 8,
        ..OneLoopRule::default()
    }
}

/// Eleven coefficients, all non-zero, from a fixed pseudo-random sequence: b1 in [1, 3), the others in
/// [−2, 2) away from zero.
fn random_bias(seed: u64) -> LoopBias {
    let v: Vec<f64> = vectors(seed, 4).into_iter().flatten().collect();
    let mut b = [0.0; N_BIAS];
    for (i, x) in b.iter_mut().enumerate() {
        let r = v[i];
        *x = if i == 0 {
            2.0 + r
        } else {
            2.0 * r + 0.1 * r.signum()
        };
    }
    LoopBias::from_values(b)
}

fn terms(b: &OneLoopGalaxy) -> [Estimate; 5] {
    [b.tree, b.b222, b.b321_i, b.b321_ii, b.b411]
}

const NAMES: [&str; 5] = ["tree", "B222", "B321-I", "B321-II", "B411"];

/// The polynomial evaluated at five random coefficient vectors (all 11 non-zero) equals the direct terms,
/// values and errors, to 1e-13 of the term's scale (the largest |value| of the term over the vectors, for the
/// renormalised B321-II and B411 that of the bare term: they are differences of it and the subtracted amount),
/// the subtracted amounts too; real space and redshift space with a line of sight out of the triangle's
/// plane, two triangles (measured: 5.7e-15).
#[test]
fn polynomial_equals_the_direct_terms_at_random_coefficients() {
    let p = LinearSpectrum::gm2012_z0();
    let o = Orientation { mu1: 0.4, phi: 0.7 };
    let mut worst = 0.0f64;
    for k in [[0.05, 0.1, 0.12], [0.02, 0.1, 0.1]] {
        for redshift in [None, Some((0.7, o))] {
            let start = std::time::Instant::now();
            let poly = one_loop_galaxy_polynomial(&p, k, redshift, &small()).unwrap();
            let t_poly = start.elapsed().as_secs_f64();
            let mut t_direct = 0.0;
            let pairs: Vec<(OneLoopGalaxy, OneLoopGalaxy)> = (0..5)
                .map(|seed| {
                    let bias = random_bias(seed + 11);
                    let start = std::time::Instant::now();
                    let d = one_loop_galaxy(&p, k, &bias, redshift, &small()).unwrap();
                    t_direct += start.elapsed().as_secs_f64();
                    (poly.evaluate(&bias).unwrap(), d)
                })
                .collect();
            eprintln!(
                "{k:?} f = {:?}: one pass {t_poly:.3} s, direct {:.3} s per bias",
                redshift.map(|r| r.0),
                t_direct / 5.0
            );
            for t in 0..7 {
                let get = |g: &OneLoopGalaxy| match t {
                    5 => Estimate::exact(g.uv_b321_ii),
                    6 => Estimate::exact(g.uv_b411),
                    _ => terms(g)[t],
                };
                // The renormalised terms are differences of the bare ones and the subtracted amounts.
                let bare = |g: &OneLoopGalaxy| match t {
                    3 => g.bare_b321_ii().value.abs(),
                    4 => g.bare_b411().value.abs(),
                    _ => 0.0,
                };
                let scale = pairs
                    .iter()
                    .map(|(_, d)| get(d).value.abs().max(bare(d)))
                    .fold(0.0, f64::max);
                assert!(scale > 0.0, "term {t}");
                for (a, b) in &pairs {
                    let (a, b) = (get(a), get(b));
                    let dv = (a.value - b.value).abs() / scale;
                    let de = (a.error - b.error).abs() / scale;
                    worst = worst.max(dv).max(de);
                    assert!(dv < 1e-13 && de < 1e-13, "{k:?} term {t}: {a:?} vs {b:?}");
                }
            }
        }
    }
    eprintln!("largest difference from direct: {worst:.1e} of the term's scale");
}

/// b1 = 1 and the others zero: the matter terms (real space: one_loop_matter; redshift space:
/// one_loop_matter_redshift), nothing subtracted.
#[test]
fn matter_coefficients_give_the_matter_terms() {
    let p = LinearSpectrum::gm2012_z0();
    let k = [0.05, 0.1, 0.12];
    let g = one_loop_galaxy_polynomial(&p, k, None, &small())
        .unwrap()
        .evaluate(&LoopBias::matter())
        .unwrap();
    let m = one_loop_matter(&p, k, &small()).unwrap();
    let real = [m.tree, m.b222, m.b321_i, m.b321_ii, m.b411];
    let o = Orientation { mu1: 0.4, phi: 0.7 };
    let gz = one_loop_galaxy_polynomial(&p, k, Some((0.7, o)), &small())
        .unwrap()
        .evaluate(&LoopBias::matter())
        .unwrap();
    let m = one_loop_matter_redshift(&p, k, 0.7, o, &small()).unwrap();
    let rsd = [m.tree, m.b222, m.b321_i, m.b321_ii, m.b411];
    let mut worst = 0.0f64;
    for (g, want) in [(g, real), (gz, rsd)] {
        assert_eq!((g.uv_b321_ii, g.uv_b411), (0.0, 0.0));
        for (i, (a, b)) in terms(&g).iter().zip(want).enumerate() {
            let rel = (a.value - b.value).abs() / b.value.abs();
            worst = worst.max(rel);
            assert!(rel < 1e-12, "{}: {a:?} vs {b:?}", NAMES[i]);
        }
    }
    eprintln!("largest relative difference from the matter terms {worst:.1e}");
}

/// The parts of a kernel: x·parts is K_n and Z_n^g (to 1e-13 of the largest |x_p parts_p|), parts[0] is zero
/// in real space, and each operator's part vanishes below its LOWEST_ORDER and not at it.
#[test]
fn kernel_parts_reassemble_the_kernels() {
    let bias = galaxy_bias();
    let mut x = [1.0; N_BIAS + 1];
    x[1..].copy_from_slice(&bias.values());
    let los = [0.3, -0.4, 0.866];
    for n in 1..=4 {
        for seed in 0..5 {
            let q = vectors(100 * n as u64 + seed, n);
            let real = galaxy_kernel_parts(&q, None).unwrap();
            assert_eq!(real[0], 0.0);
            let ops = operator_kernels(&q).unwrap();
            assert_eq!(&real[1..], &ops[..]);
            for (i, o) in ops.iter().enumerate() {
                assert_eq!(
                    *o == 0.0,
                    n < LOWEST_ORDER[i],
                    "{} at order {n}",
                    LoopBias::NAMES[i]
                );
            }
            let rsd = galaxy_kernel_parts(&q, Some((0.8, &los))).unwrap();
            for (parts, want) in [
                (real, galaxy_kernel(&bias, &q).unwrap()),
                (rsd, galaxy_redshift_kernel(&bias, &q, 0.8, &los).unwrap()),
            ] {
                let sum: f64 = parts.iter().zip(&x).map(|(a, b)| a * b).sum();
                let scale = parts
                    .iter()
                    .zip(&x)
                    .map(|(a, b)| (a * b).abs())
                    .fold(0.0, f64::max);
                assert!(
                    (sum - want).abs() <= 1e-13 * scale,
                    "n = {n}: {sum} vs {want}"
                );
            }
        }
    }
    assert!(galaxy_kernel_parts(&[[0.1, 0.0, 0.0]], Some((0.5, &[0.0; 3]))).is_err());
    assert!(galaxy_kernel_parts(&[[0.0; 3]], None).is_err());
}

/// The monomials of every term are the products that the kernels' orders allow, derived here from the
/// operators' lowest orders written out (b1 first order; b2, g2 second; b3, g2x, g3, g21 third; g21x, g211,
/// g22, g31 fourth; the constant first order in redshift space only): the counts, and closed forms for the
/// real space ones (B222 cubic in 3 parts: C(5, 3) = 10; B321: b1 × (pairs within the 3 second-order parts,
/// 6, plus those × the 4 third-order ones, 12) = 18; B411: b1² × 11).
#[test]
fn monomials_are_those_the_kernel_orders_allow() {
    let p = LinearSpectrum::gm2012_z0();
    let k = [0.05, 0.1, 0.12];
    let order = [1, 1, 2, 2, 3, 3, 3, 3, 4, 4, 4, 4];
    let o = Orientation { mu1: 0.4, phi: 0.7 };
    for redshift in [None, Some((0.7, o))] {
        let s = |n: usize| -> Vec<u8> {
            (0u8..12)
                .filter(|&i| order[i as usize] <= n && (i > 0 || redshift.is_some()))
                .collect()
        };
        let products = |a: &[u8], b: &[u8], c: &[u8]| -> BTreeSet<[u8; 3]> {
            let mut set = BTreeSet::new();
            for &x in a {
                for &y in b {
                    for &z in c {
                        let mut m = [x, y, z];
                        m.sort();
                        set.insert(m);
                    }
                }
            }
            set
        };
        let ops = |n: usize| -> Vec<u8> { s(n).into_iter().filter(|&i| i >= 2).collect() };
        let want = [
            products(&s(2), &s(1), &s(1)),
            products(&s(2), &s(2), &s(2)),
            products(&s(1), &s(3), &s(2)),
            products(&s(2), &s(1), &s(3)),
            products(&s(1), &s(1), &s(4)),
            products(&s(2), &s(1), &ops(3)),
            products(&s(1), &s(1), &ops(4)),
        ];
        let poly: GalaxyLoopPolynomial =
            one_loop_galaxy_polynomial(&p, k, redshift, &small()).unwrap();
        let counts: Vec<usize> = poly.terms().iter().map(|t| t.len()).collect();
        eprintln!("f = {:?}: monomials {counts:?}", redshift.map(|r| r.0));
        for (t, w) in poly.terms().iter().zip(&want) {
            let got: BTreeSet<[u8; 3]> = t.monomials.iter().copied().collect();
            assert_eq!(&got, w);
            assert!(t.values.iter().all(|v| v.is_finite()));
        }
        if redshift.is_none() {
            assert_eq!(counts, [3, 10, 18, 18, 11, 17, 10]);
            assert_eq!(monomial_name(&poly.b411.monomials[0]), "b1 b1 b1");
        } else {
            assert_eq!(counts, [10, 20, 44, 44, 34, 40, 30]);
            assert_eq!(monomial_name(&poly.tree.monomials[0]), "1");
        }
    }
}

/// Bad input is an error: a coefficient that is not finite at evaluation, f outside [0, 2], sides that do
/// not close (also for the basis tensors), a rule without nodes to halve.
#[test]
fn bad_input_is_an_error() {
    let p = LinearSpectrum::gm2012_z0();
    let poly = one_loop_galaxy_polynomial(&p, [0.1, 0.1, 0.1], None, &small()).unwrap();
    let bad = LoopBias {
        g31: f64::INFINITY,
        ..galaxy_bias()
    };
    let e = poly.evaluate(&bad).unwrap_err();
    assert!(e.to_string().contains("g31"), "{e}");
    let o = Orientation { mu1: 0.3, phi: 0.0 };
    assert!(one_loop_galaxy_polynomial(&p, [0.1, 0.1, 0.1], Some((-0.1, o)), &small()).is_err());
    assert!(one_loop_galaxy_polynomial(&p, [0.1, 0.1, 0.5], None, &small()).is_err());
    use pt_spectra::bispectrum::one_loop_galaxy_basis::GalaxyLoopBasis;
    let tick = |_, _| {};
    assert!(GalaxyLoopBasis::build(&[[0.1, 0.1, 0.1], [0.1, 0.1, 0.5]], &small(), &tick).is_err());
    let no_nodes = OneLoopRule { mu: 1, ..small() };
    assert!(GalaxyLoopBasis::build(&[[0.1, 0.1, 0.1]], &no_nodes, &tick).is_err());
}

/// Basis tensors per monomial (`bispectrum::one_loop_galaxy_basis`, real space) against the direct
/// polynomials on the same nodes, for CAMB spectra not in the basis's training set (Planck 2018 at z = 0, a
/// held-out cosmology of the prior) at three triangles, evaluated at three random 11-coefficient biases:
/// every loop term within its error (quadrature plus the matter bound 3ε Σ|loop terms|, ε the projection
/// residual), the one-loop B within 1e-3 of itself, the tree level exact; the same monomials; for P̂ itself
/// every coefficient as direct to 1e-6 of its term (measured 2.2e-7); the cache
/// file reads back the same tensors, and not for other triangles.
#[test]
fn basis_polynomials_match_the_direct_ones_for_spectra_not_in_the_training_set() {
    use crate::support;
    use pt_spectra::bispectrum::one_loop_galaxy_basis::GalaxyLoopBasis;
    use pt_spectra::progress::Silent;
    use pt_spectra::store::TableStore;
    let rule = OneLoopRule {
        radial: 4,
        mu: 8,
        phi: 6,
        ..OneLoopRule::default()
    };
    let triangles = vec![[0.05, 0.1, 0.12], [0.02, 0.1, 0.1], [0.1, 0.1, 0.1]];
    let dir = std::path::Path::new(env!("CARGO_TARGET_TMPDIR")).join("one_loop_galaxy_basis");
    let _ = std::fs::remove_dir_all(&dir);
    let start = std::time::Instant::now();
    let build = |tick: &(dyn Fn(usize, usize) + Sync)| {
        GalaxyLoopBasis::build(&triangles, &rule, tick).unwrap()
    };
    let basis = TableStore::new(&dir)
        .tensors::<GalaxyLoopBasis>((&triangles, &rule), build, &Silent)
        .unwrap();
    eprintln!(
        "galaxy tensors of {} triangles: {:.1} s, {} values",
        triangles.len(),
        start.elapsed().as_secs_f64(),
        basis.values()
    );
    let again = TableStore::new(&dir)
        .cached::<GalaxyLoopBasis>((&triangles, &rule), &Silent)
        .unwrap();
    assert!(*again == *basis, "the cache file reads back the tensors");
    assert!(TableStore::new(&dir)
        .cached::<GalaxyLoopBasis>((&triangles[1..], &rule), &Silent)
        .is_none());
    let camb =
        |name: &str| LinearSpectrum::parse(&support::data(name), name, Default::default()).unwrap();
    let spectra = [
        ("planck2018 z=0", camb("linear_pk_planck2018_z0.0.dat")),
        ("held-out 0", camb("linear_pk_camb_heldout_0.dat")),
    ];
    let (mut worst_total, mut worst_term, mut worst_bound): (f64, f64, f64) = (0.0, 0.0, 0.0);
    for (name, p) in &spectra {
        let start = std::time::Instant::now();
        let polys = basis.evaluate(p);
        eprintln!(
            "{name}: {:.2} ms for {} triangles, 3 x residual {:.1e}",
            start.elapsed().as_secs_f64() * 1e3,
            triangles.len(),
            polys[0].projection
        );
        for (poly, &k) in polys.iter().zip(&triangles) {
            assert!(poly.projection > 0.0 && poly.projection < 1e-3);
            let direct = one_loop_galaxy_polynomial(p, k, None, &rule).unwrap();
            for (a, b) in poly.terms().iter().zip(direct.terms()) {
                assert_eq!(a.monomials, b.monomials, "{name} {k:?}");
            }
            for seed in 0..3 {
                let bias = random_bias(seed + 40);
                let (x, y) = (
                    poly.evaluate(&bias).unwrap(),
                    direct.evaluate(&bias).unwrap(),
                );
                assert_eq!(x.tree.error, 0.0);
                assert!((x.tree.value - y.tree.value).abs() <= 1e-12 * y.tree.value.abs());
                for (j, (s, t)) in terms(&x).iter().zip(terms(&y)).enumerate().skip(1) {
                    let diff = (s.value - t.value).abs();
                    let bound = s.error;
                    assert!(
                        diff <= bound,
                        "{name} {k:?} {}: {} vs {} (bound {bound:.2e})",
                        NAMES[j],
                        s.value,
                        t.value
                    );
                    worst_term = worst_term.max(diff / t.value.abs());
                    worst_bound = worst_bound.max(diff / bound);
                }
                let total = y.total().value;
                let rel = (x.total().value - total).abs() / total.abs();
                assert!(rel <= 1e-3, "{name} {k:?}: {} vs {total}", x.total().value);
                worst_total = worst_total.max(rel);
            }
        }
    }
    eprintln!(
        "basis vs direct: one-loop B within {worst_total:.1e}, each term within {worst_term:.1e} \
         ({worst_bound:.2} of its bound)"
    );
    // For P̂ itself the tensors' loop terms are the direct ones on the same nodes, coefficient by
    // coefficient, up to the two interpolations of the lattice (the basis's four-point Lagrange, the
    // spectrum's own): each coefficient within 1e-6 of the largest of its term.
    let (name, p) = &spectra[1];
    let hat = basis.projected_spectrum(p).unwrap();
    let polys = basis.evaluate(p);
    let mut worst: f64 = 0.0;
    for (poly, &k) in polys.iter().zip(&triangles) {
        let direct = one_loop_galaxy_polynomial(&hat, k, None, &rule).unwrap();
        for (j, (a, b)) in poly.terms().iter().zip(direct.terms()).enumerate().skip(1) {
            let scale = b.values.iter().map(|v| v.abs()).fold(0.0, f64::max);
            for (x, y) in a.values.iter().zip(&b.values) {
                let d = (x - y).abs() / scale;
                worst = worst.max(d);
                assert!(d < 1e-6, "{name} {k:?} term {j}: {x} vs {y} ({d:.1e})");
            }
        }
    }
    eprintln!(
        "basis vs direct for P-hat: every coefficient within {worst:.1e} of its term's largest"
    );
}
