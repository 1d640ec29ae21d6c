//! The training spectra of the basis: CAMB linear spectra over the EuclidEmulator2 prior, shipped
//! with the crate (`pt-spectra/data/two_loop_training_camb.f32`, made by
//! `pt-spectra/data/make_two_loop_training.py`).
//!
//! [`TRAINING_SPECTRA`] CAMB tables at z = 0 (1200 log-spaced k in [1e-4, 50] h/Mpc, the settings of
//! the test tables: massless neutrinos, N_eff = 3.046) for cosmologies drawn uniformly from the box
//! Ω_m ∈ [0.24, 0.40], Ω_b ∈ [0.04, 0.06], n_s ∈ [0.92, 1.00], h ∈ [0.61, 0.73],
//! w0 ∈ [−1.3, −0.7] (PPF dark energy). A_s and the redshift only rescale P (the growth is scale
//! independent for massless neutrinos) and a basis spans every amplitude, so they need no training
//! points. Each table becomes a [`LinearSpectrum`] exactly as a user's table does (spline in ln k,
//! power laws beyond its ends), so the basis represents tables made this way, extrapolation included.
//!
//! Tables end anywhere from ~10 to 100 h/Mpc and are extended by power laws beyond, so their tails
//! differ; the basis therefore starts with [`TAIL_FUNCTIONS`] smooth functions of q ≥ 3 h/Mpc, and
//! every fourth training table is also taken cut to other ranges. CAMB tables ending between 15 and
//! 50 h/Mpc then project to ≤ 2e-4; one ending at 100 h/Mpc (CAMB run with a larger kmax, whose own
//! k sampling differs) to 5e-4, one ending at 5 h/Mpc to ~1e-3: those are computed directly.
//!
//! Eisenstein–Hu spectra are not in the span (their shape differs from CAMB's by percents; an
//! Eisenstein–Hu basis leaves 1–3e-2 on CAMB tables): they, and tables of other codes, ranges or
//! physics (massive neutrinos), are computed directly when their projection residual is too large.

use super::LinearBasis;
use crate::linear::LinearSpectrum;
use crate::loops::lattice::Lattice;

/// Version of the training set, part of the cache key of the tensors.
pub const VERSION: u32 = 3;

/// Number of training spectra.
pub const TRAINING_SPECTRA: usize = 100;

/// k values per training table.
const TABLE_LEN: usize = 1200;

/// The training tables: k, then P of each spectrum (little-endian f32).
const DATA: &[u8] = include_bytes!("../../../data/two_loop_training_camb.f32");

/// The training spectra (k [h/Mpc], P [(Mpc/h)^3]) as tables.
pub fn camb_training() -> Vec<LinearSpectrum> {
    let values: Vec<f64> = DATA
        .chunks_exact(4)
        .map(|b| f64::from(f32::from_le_bytes([b[0], b[1], b[2], b[3]])))
        .collect();
    assert_eq!(
        values.len(),
        TABLE_LEN * (TRAINING_SPECTRA + 1),
        "the shipped training tables have their documented size"
    );
    let k = values[..TABLE_LEN].to_vec();
    values[TABLE_LEN..]
        .chunks_exact(TABLE_LEN)
        .map(|p| {
            LinearSpectrum::from_nodes(k.clone(), p.to_vec())
                .expect("the shipped training tables are valid")
        })
        .collect()
}

/// Table ranges [h/Mpc] of the cut variants: a user's table may end at 10–30 h/Mpc or start at
/// 1e-3 h/Mpc, and is then extended by power laws, whose tails differ from CAMB's by tens of per cent
/// at q ~ 1e3; every fourth training table is also taken cut to each of these ranges.
const CUTS: [(f64, f64); 4] = [(1e-4, 10.0), (1e-4, 20.0), (1e-4, 30.0), (1e-3, 50.0)];

/// The training spectra on `lattice`: the tables of [`camb_training`], and every fourth of them cut to
/// each range of [`CUTS`] (power-law ends beyond, as the library extends any table).
pub(crate) fn camb_samples(lattice: &Lattice) -> Vec<Vec<f64>> {
    samples_with(lattice, &|p| p.clone())
}

/// As [`camb_samples`] with every table (and cut) first turned into `transform(table)`: e.g. its
/// no-wiggle part, for a basis of the spectra the galaxy model's IR resummation integrates.
fn samples_with(
    lattice: &Lattice,
    transform: &(dyn Fn(&LinearSpectrum) -> LinearSpectrum + Sync),
) -> Vec<Vec<f64>> {
    let tables = camb_training();
    let mut samples: Vec<Vec<f64>> = tables
        .iter()
        .map(|p| lattice.sample(&transform(p)))
        .collect();
    for p in tables.iter().step_by(4) {
        for (lo, hi) in CUTS {
            let cut = p
                .restricted(lo, hi)
                .expect("a cut of a valid table is valid");
            samples.push(lattice.sample(&transform(&cut)));
        }
    }
    samples
}

/// Where the tail functions start [h/Mpc] ([`tail_functions`]).
const TAIL_START: f64 = 3.0;

/// Number of tail functions.
pub const TAIL_FUNCTIONS: usize = 6;

/// Functions that give the basis any smooth tail beyond [`TAIL_START`]: P̄(q) B_i(ln q), P̄ the mean
/// training spectrum and B_i cubic B-splines on knots spaced (ln q_max − ln 3)/6 from ln 3 (zero
/// below it, C² at it). Tables end anywhere from 10 to 100 h/Mpc and are extended by power laws
/// beyond, so their tails differ from one another (and from CAMB's) by up to tens of per cent at
/// q ~ 1e3, a smooth difference that no set of training spectra spans but these do.
fn tail_functions(lattice: &Lattice, mean: &[f64]) -> Vec<Vec<f64>> {
    let (start, end) = (TAIL_START.ln(), lattice.x_end());
    let h = (end - start) / TAIL_FUNCTIONS as f64;
    (0..TAIL_FUNCTIONS)
        .map(|i| {
            (0..lattice.len)
                .map(|j| mean[j] * cubic_b_spline((lattice.x(j) - start) / h - i as f64))
                .collect()
        })
        .collect()
}

/// The uniform cubic B-spline on [0, 4] (zero outside).
fn cubic_b_spline(t: f64) -> f64 {
    match t {
        t if !(0.0..4.0).contains(&t) => 0.0,
        t if t < 1.0 => t * t * t / 6.0,
        t if t < 2.0 => (-3.0 * t * t * t + 12.0 * t * t - 12.0 * t + 4.0) / 6.0,
        t if t < 3.0 => (3.0 * t * t * t - 24.0 * t * t + 60.0 * t - 44.0) / 6.0,
        t => (4.0 - t).powi(3) / 6.0,
    }
}

/// The basis of `n` functions on `lattice`: the [`TAIL_FUNCTIONS`] tail functions, then the greedy
/// choice from [`camb_samples`].
pub(crate) fn camb_basis(lattice: Lattice, n: usize) -> LinearBasis {
    let training = camb_samples(&lattice);
    basis_of(lattice, training, n)
}

/// The basis of `n` functions for the training tables (and cuts) each turned into
/// `transform(table)` first, with the tail functions: the basis of a family of spectra derived from
/// the training set (the galaxy model's no-wiggle spectra, [`crate::rsd::ept::EptPlan`]).
pub(crate) fn transformed_basis(
    lattice: &Lattice,
    n: usize,
    transform: &(dyn Fn(&LinearSpectrum) -> LinearSpectrum + Sync),
) -> LinearBasis {
    basis_of(lattice.clone(), samples_with(lattice, transform), n)
}

/// σ_a: the largest |c_a| of the training spectra (and cuts, [`camb_samples`]) projected on `basis`,
/// the scale of each coefficient for the low-rank tensors ([`super::low_rank`]). For a basis of
/// another family (no-wiggle parts) the linear spectra give the same scales to a few per cent.
pub(crate) fn coefficient_scale(basis: &LinearBasis) -> Vec<f64> {
    let mut sigma = vec![0.0_f64; basis.len()];
    for samples in camb_samples(basis.lattice()) {
        let c = basis.project(&samples).coefficients;
        sigma
            .iter_mut()
            .zip(&c)
            .for_each(|(s, c)| *s = s.max(c.abs()));
    }
    sigma
}

fn basis_of(lattice: Lattice, training: Vec<Vec<f64>>, n: usize) -> LinearBasis {
    let mean: Vec<f64> = (0..lattice.len)
        .map(|j| training.iter().map(|t| t[j]).sum::<f64>() / training.len() as f64)
        .collect();
    let tails = tail_functions(&lattice, &mean);
    LinearBasis::greedy(lattice, &tails, &training, n)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The table `name` of tests/data cut to k ∈ [lo, hi] (then extended by power laws).
    fn cut(name: &str, lo: f64, hi: f64) -> LinearSpectrum {
        let dir = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/data/");
        let p = LinearSpectrum::from_file(format!("{dir}{name}")).unwrap();
        p.restricted(lo, hi).unwrap()
    }

    #[test]
    fn tables_of_other_ranges_project_and_short_ones_less_well() {
        // CAMB tables not in the training set, ending at 15 or 50 h/Mpc, starting at 1e-4 or 3e-4:
        // measured 5e-5 to 1.9e-4 (without the tail functions, ending at 15 gave 1e-3).
        // Ending at 5 h/Mpc, the power law beyond is farther from any CAMB tail: 8.9e-4, within the
        // limit (its terms carry ε|T| in their errors) but above every complete table.
        let lattice = Lattice::new(1e-5, 1e3, 0.01);
        let basis = camb_basis(lattice.clone(), super::super::BASIS_SIZE);
        assert_eq!(basis.len(), super::super::BASIS_SIZE);
        for name in [
            "linear_pk_planck2018_z0.0.dat",
            "linear_pk_camb_heldout_1.dat",
        ] {
            for (lo, hi) in [(1e-4, 50.0), (1e-4, 15.0), (3e-4, 50.0)] {
                let r = basis.project(&lattice.sample(&cut(name, lo, hi))).residual;
                assert!(r < 2.5e-4, "{name} [{lo}, {hi}]: {r:.2e}");
            }
            let r = basis
                .project(&lattice.sample(&cut(name, 1e-4, 5.0)))
                .residual;
            assert!(
                r > 2.5e-4 && r < super::super::MAX_RESIDUAL,
                "{name} to 5 h/Mpc: {r:.2e}"
            );
        }
    }

    #[test]
    fn emulated_spectra_project_within_the_limit() {
        // The embedded emulator's tables end at ~9 h/Mpc (a power law beyond): within the limit
        // (measured 4e-4 to 8e-4): the whole spectrum is projected, not its soft-mode cut.
        let lattice = Lattice::new(1e-5, 1e3, 0.01);
        let basis = camb_basis(lattice.clone(), super::super::BASIS_SIZE);
        let emulator = crate::emulator::LinearEmulator::shared().unwrap();
        for (om, z) in [(0.26, 0.0), (0.31, 0.5), (0.36, 2.0)] {
            let c = crate::cosmology::Cosmology::flat(om, 0.68, 0.0224, 0.965, 0.8).unwrap();
            let p = emulator.spectra(&c, z).unwrap().matter().unwrap();
            let whole = basis.project(&basis.sample(&p));
            assert!(
                whole.residual > 2.5e-4 && whole.residual < super::super::MAX_RESIDUAL,
                "Ω_m {om} z {z}: {:.2e}",
                whole.residual
            );
            let chosen = basis.project_spectrum(&p, super::super::MAX_RESIDUAL);
            assert!(chosen.soft.is_none() && chosen.residual == whole.residual);
        }
    }

    #[test]
    fn class_tables_project_when_class_samples_k_densely() {
        // CLASS (not CAMB, which made the training set), Planck 2018 at z = 0: from `pk_lin` on 600
        // points, or CLASS's own k sampling at k_per_decade_for_pk = 40 (measured 1.9e-4, 1.8e-4);
        // at CLASS's default 10 per decade the spline between 10 and 50 h/Mpc projects less well
        // (1.1e-3), still within the limit: the basis is used and the errors carry ε|T|.
        let lattice = Lattice::new(1e-5, 1e3, 0.01);
        let basis = camb_basis(lattice.clone(), super::super::BASIS_SIZE);
        let residual = |suffix: &str| {
            let name = format!("linear_pk_class_planck2018_z0.0_{suffix}.dat");
            let p = cut(&name, 0.0, f64::INFINITY);
            basis.project(&lattice.sample(&p)).residual
        };
        for suffix in ["pk_lin", "kpd40"] {
            let r = residual(suffix);
            assert!(r < 2.5e-4, "{suffix}: {r:.2e}");
        }
        let r = residual("kpd10");
        assert!(r > 5e-4 && r < super::super::MAX_RESIDUAL, "kpd10: {r:.2e}");
    }

    #[test]
    fn the_cubic_b_spline_is_a_smooth_partition_of_unity() {
        // Σ_i B(t − i) = 1 for every t (in the interior of the knots), and B is C² at its knots.
        for t in [0.3, 1.7, 2.5, 3.99] {
            let sum: f64 = (-4..=4).map(|i| cubic_b_spline(t + f64::from(i))).sum();
            assert!((sum - 1.0).abs() < 1e-14, "{t}: {sum}");
        }
        let h = 1e-5;
        for knot in [1.0, 2.0, 3.0] {
            let d2 = |t: f64| {
                (cubic_b_spline(t + h) - 2.0 * cubic_b_spline(t) + cubic_b_spline(t - h)) / (h * h)
            };
            assert!(
                (d2(knot - 3.0 * h) - d2(knot + 3.0 * h)).abs() < 1e-3,
                "{knot}"
            );
        }
    }
}
