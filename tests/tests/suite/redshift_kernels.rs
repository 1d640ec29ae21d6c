//! The redshift-space kernels Z_n (n ≤ 5), generated as straight-line code by kernelgen, in exact
//! rationals: against the brute-force oracle (the unsymmetrised expansion averaged over all n! orderings),
//! the closed forms of Z_1 and Z_2 (Scoccimarro, Couchman & Frieman 1999), the limit f = 0, where
//! Z_n = F_n^s, and the highest power of f, a product of linear velocity terms.

use crate::common::*;
use num_traits::{ToPrimitive, Zero};
use proptest::prelude::*;
use pt_kernels::redshift::{brute_force_redshift, redshift_coefficients, redshift_kernel};
use pt_kernels::reference::ReferenceError;
use pt_kernels::{dot, kernels, KernelError};

fn rational_vector() -> impl Strategy<Value = [Q; 3]> {
    (-5i64..=5, -5i64..=5, -5i64..=5, 1i64..=3)
        .prop_filter("non-zero", |(x, y, z, _)| (*x, *y, *z) != (0, 0, 0))
        .prop_map(|(x, y, z, d)| v(x, y, z, d))
}

/// A line of sight (any non-zero direction) and f in [0, 2].
fn setting() -> impl Strategy<Value = ([Q; 3], Q)> {
    (rational_vector(), 0i64..=8).prop_map(|(los, f)| (los, q(f, 4)))
}

macro_rules! against_brute_force {
    ($name:ident, $n:expr, $cases:expr) => {
        proptest! {
            #![proptest_config(ProptestConfig { cases: $cases, max_global_rejects: 10_000, failure_persistence: crate::regressions_beside_the_source(), ..ProptestConfig::default() })]
            #[test]
            fn $name(qs in proptest::collection::vec(rational_vector(), $n), (los, f) in setting()) {
                let z = redshift_kernel(&qs, &f, &los).unwrap();
                match brute_force_redshift(&qs, &f, &los) {
                    Ok(brute) => prop_assert_eq!(z, brute),
                    Err(ReferenceError::ZeroMomentumRun) => prop_assume!(false),
                    Err(e) => return Err(TestCaseError::fail(e.to_string())),
                }
            }
        }
    };
}

against_brute_force!(z1_equals_brute_force_exactly, 1, 16);
against_brute_force!(z2_equals_brute_force_exactly, 2, 48);
against_brute_force!(z3_equals_brute_force_exactly, 3, 32);
against_brute_force!(z4_equals_brute_force_exactly, 4, 24);
against_brute_force!(z5_equals_brute_force_exactly, 5, 12);

/// Five rational vectors, no subset of which sums to zero.
fn five_vectors() -> [[Q; 3]; 5] {
    [
        v(1, 2, -1, 2),
        v(-1, 1, 3, 3),
        v(2, -1, 1, 1),
        v(0, 1, -2, 3),
        v(3, 0, 1, 2),
    ]
}

/// The coefficient of f^n in Z_n: only S_0 = {i} with the rest in singletons reaches it, so
/// Z^(n) = (kμ)^(n−1)/n! Σ_i μ_i² Π_{j≠i} μ_j/q_j (unit line of sight), exactly, n ≤ 5.
#[test]
fn the_highest_power_of_f_is_a_product_of_linear_velocity_terms() {
    let qs = five_vectors();
    let los = v(0, 3, 4, 5);
    for n in 1..=5 {
        let args = &qs[..n];
        let k = args.iter().fold(v(0, 0, 0, 1), |a, b| add(&a, b));
        let mu2 = |a: &[Q; 3]| dot(&los, a) * dot(&los, a) / dot(a, a);
        let mu_over = |a: &[Q; 3]| dot(&los, a) / dot(a, a);
        let mut sum = Q::zero();
        for i in 0..n {
            let mut term = mu2(&args[i]);
            for (j, a) in args.iter().enumerate() {
                if j != i {
                    term *= mu_over(a);
                }
            }
            sum += term;
        }
        let kmu = dot(&los, &k);
        let factorial: i64 = (1..=n as i64).product();
        let expected = (0..n - 1).fold(sum, |acc, _| acc * &kmu) / q(factorial, 1);
        let z = redshift_coefficients(args, &los).unwrap();
        assert_eq!(z.len(), n + 1);
        assert_eq!(z[n], expected, "n = {n}");
        assert_eq!(z[0], kernels(args).unwrap()[0], "n = {n}");
    }
}

/// Z_1 = 1 + fμ², Z_2 = F_2 + fμ²G_2 + (fμk/2)[μ_1/q_1 (1 + fμ_2²) + μ_2/q_2 (1 + fμ_1²)]
/// (SCF99 eq. 21 with b_1 = 1, b_2 = 0), with μ's along a unit line of sight.
#[test]
fn z1_and_z2_match_the_closed_forms() {
    let los = v(0, 3, 4, 5); // unit: 9/25 + 16/25
    let f = q(3, 4);
    let q1 = v(1, -2, 3, 2);
    let q2 = v(-2, 1, 1, 3);
    let mu_over = |a: &[Q; 3]| dot(&los, a) / dot(a, a); // μ_a/|a|
    let mu2 = |a: &[Q; 3]| dot(&los, a) * dot(&los, a) / dot(a, a);
    let z1 = redshift_kernel(std::slice::from_ref(&q1), &f, &los).unwrap();
    assert_eq!(z1, q(1, 1) + &f * mu2(&q1));
    let k = add(&q1, &q2);
    let [f2, g2] = kernels(&[q1.clone(), q2.clone()]).unwrap();
    let fmuk = &f * dot(&los, &k);
    let closed = f2
        + &f * mu2(&k) * g2
        + fmuk / q(2, 1)
            * (mu_over(&q1) * (q(1, 1) + &f * mu2(&q2)) + mu_over(&q2) * (q(1, 1) + &f * mu2(&q1)));
    assert_eq!(
        redshift_kernel(&[q1.clone(), q2.clone()], &f, &los).unwrap(),
        closed
    );
    // only the direction of the line of sight enters
    let long = scale(&q(7, 3), &los);
    assert_eq!(redshift_kernel(&[q1, q2], &f, &long).unwrap(), closed);
}

/// f = 0: real space, Z_n = F_n^s exactly, n ≤ 5.
#[test]
fn without_velocities_z_n_is_f_n() {
    let qs = five_vectors();
    for n in 1..=5 {
        let z = redshift_kernel(&qs[..n], &Q::zero(), &v(0, 0, 1, 1)).unwrap();
        assert_eq!(z, kernels(&qs[..n]).unwrap()[0], "n = {n}");
    }
}

/// A cancelling pair (k, q, −q, …) is the limit, not a NaN, and the f64 version agrees with the exact.
#[test]
fn zero_momentum_subsets_and_f64() {
    let qs = [v(1, 2, -1, 2), v(-1, 1, 3, 3), v(1, -1, -3, 3)];
    let z = redshift_kernel(&qs, &q(1, 2), &v(0, 0, 1, 1)).unwrap();
    let exact = z.to_f64().unwrap();
    let zf = redshift_kernel(
        &qs.iter().map(to_f64).collect::<Vec<_>>(),
        &0.5,
        &[0.0, 0.0, 1.0],
    )
    .unwrap();
    assert!(
        zf.is_finite() && (zf - exact).abs() < 1e-12 * exact.abs().max(1.0),
        "{zf} {exact}"
    );
    let qs6 = vec![v(1, 0, 0, 1); 6];
    assert_eq!(
        redshift_kernel(&qs6, &q(1, 2), &v(0, 0, 1, 1)),
        Err(KernelError::Order(6))
    );
    assert_eq!(
        redshift_kernel(&qs[..2], &q(1, 2), &v(0, 0, 0, 1)),
        Err(KernelError::ZeroLineOfSight)
    );
}
