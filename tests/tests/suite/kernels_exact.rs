//! Exact verification of the generated kernels, in rational arithmetic.
//!
//! Every comparison here is an equality of rationals (or, at singular points of the reference, an exact
//! bound), against values computed without the generator: the brute-force n!-permutation reference, the
//! textbook closed forms of F_2^s, G_2^s and F_3^s, and FAST-PT's hard-coded Legendre tables.

use crate::common::*;
use num_traits::{One, Zero};
use proptest::prelude::*;
use pt_kernels::{gram, kernels, reference};
use pt_kernels::{
    mode_coupling_2, mode_coupling_3, mode_coupling_4, propagator_3, propagator_5, propagator_7,
};

/// Strategy: a non-zero vector with small rational components p/d, p in [−5, 5], d in 1..=3.
fn rational_vector() -> impl Strategy<Value = [Q; 3]> {
    (-5i64..=5, -5i64..=5, -5i64..=5, 1i64..=3)
        .prop_filter("non-zero", |(x, y, z, _)| (*x, *y, *z) != (0, 0, 0))
        .prop_map(|(x, y, z, d)| v(x, y, z, d))
}

fn exact_against_brute_force(qs: &[[Q; 3]]) -> Result<(), TestCaseError> {
    let generated = kernels(qs).expect("valid configuration");
    match reference::brute_force(qs) {
        Ok(brute) => prop_assert_eq!(generated, brute),
        // A run of arguments summing to zero: the unsymmetrised reference is singular there; such
        // configurations are covered by `zero_momentum_pairs_give_the_limit` below.
        Err(reference::ReferenceError::ZeroMomentumRun) => prop_assume!(false),
        Err(e) => return Err(TestCaseError::fail(e.to_string())),
    }
    Ok(())
}

macro_rules! brute_force_property {
    ($name:ident, $n:expr, $cases:expr) => {
        proptest! {
            #![proptest_config(ProptestConfig { cases: $cases, max_global_rejects: 10_000, failure_persistence: crate::regressions_beside_the_source(), ..ProptestConfig::default() })]
            #[test]
            fn $name(qs in proptest::collection::vec(rational_vector(), $n)) {
                exact_against_brute_force(&qs)?;
            }
        }
    };
}

brute_force_property!(order_2_equals_brute_force_exactly, 2, 64);
brute_force_property!(order_3_equals_brute_force_exactly, 3, 64);
brute_force_property!(order_4_equals_brute_force_exactly, 4, 32);
brute_force_property!(order_5_equals_brute_force_exactly, 5, 12);
brute_force_property!(order_6_equals_brute_force_exactly, 6, 4);
brute_force_property!(order_7_equals_brute_force_exactly, 7, 2);

/// Configurations with exactly cancelling pairs (k, q1, −q1, …): the generated kernel at the singular point
/// against the brute force moved off it by ε = 10⁻⁶ (−q → −q + εd). The symmetrised kernel is continuous
/// there, so the exact difference must be O(ε): measured ≤ 0.09ε for n = 2…7 (and the same multiple of ε
/// at ε = 10⁻¹⁵ and 10⁻³⁰, so it is the linear term), bound 100ε; a wrong limit is off by O(1). ε = 10⁻⁶
/// rather than 10⁻³⁰ keeps the rationals of the n = 7 brute force small (43 s instead of 215 s).
#[test]
#[ignore = "slow exhaustive check: `cargo test --release --workspace -- --ignored` (CI runs it)"]
fn zero_momentum_pairs_give_the_limit() {
    let eps = ten_to_minus(6);
    let k = v(3, -1, 2, 2);
    let qs = [v(1, 2, -1, 1), v(-2, 1, 1, 3), v(1, 1, 4, 2)];
    let d = v(1, -2, 3, 1);
    for n in 2..=7usize {
        // k, q1, −q1, q2, −q2, … truncated to n arguments (n even leaves a lone q at the end)
        let mut exact = vec![k.clone()];
        let mut shifted = vec![k.clone()];
        for i in 0..(n - 1) {
            let qi = &qs[i / 2];
            if i % 2 == 0 {
                exact.push(qi.clone());
                shifted.push(qi.clone());
            } else {
                exact.push(neg(qi));
                shifted.push(add(&neg(qi), &scale(&eps, &d)));
            }
        }
        let generated = kernels(&exact).unwrap();
        let brute = reference::brute_force(&shifted).unwrap();
        for (g, b) in generated.iter().zip(&brute) {
            let diff = f(&(g - b));
            assert!(
                diff.abs() < 100.0 * f(&eps),
                "n = {n}: generated {} vs brute force {} (diff {diff:e})",
                f(g),
                f(b)
            );
        }
    }
}

/// The specialised kernels are the general ones at their configuration, exactly.
#[test]
fn specialised_kernels_equal_the_general_ones() {
    let k = v(1, 2, 2, 3);
    let (q1, q2, q3) = (v(-1, 3, 1, 2), v(2, 0, -1, 1), v(1, 1, 1, 5));
    let gk = |vs: &[[Q; 3]]| gram(vs);
    let arr = |g: Vec<Q>| -> Vec<Q> { g };
    let general = |args: Vec<[Q; 3]>| kernels(&args).unwrap();

    let g2 = arr(gk(&[k.clone(), q1.clone()]));
    assert_eq!(
        propagator_3(&g2.clone().try_into().unwrap()),
        general(vec![k.clone(), q1.clone(), neg(&q1)])
    );
    let kmq = add(&k, &neg(&q1));
    assert_eq!(
        mode_coupling_2(&g2.try_into().unwrap()),
        general(vec![q1.clone(), kmq.clone()])
    );

    let g3: [Q; 6] = gk(&[k.clone(), q1.clone(), q2.clone()]).try_into().unwrap();
    assert_eq!(
        propagator_5(&g3),
        general(vec![k.clone(), q1.clone(), neg(&q1), q2.clone(), neg(&q2)])
    );
    let rest = add(&kmq, &neg(&q2));
    assert_eq!(
        mode_coupling_3(&g3),
        general(vec![q1.clone(), q2.clone(), rest])
    );
    assert_eq!(
        mode_coupling_4(&g3),
        general(vec![q1.clone(), kmq, q2.clone(), neg(&q2)])
    );

    let g4: [Q; 10] = gk(&[k.clone(), q1.clone(), q2.clone(), q3.clone()])
        .try_into()
        .unwrap();
    let p17_args = vec![
        k,
        q1.clone(),
        neg(&q1),
        q2.clone(),
        neg(&q2),
        q3.clone(),
        neg(&q3),
    ];
    assert_eq!(propagator_7(&g4), general(p17_args));
}

/// F_2^s = 5/7 + ½ μ (k1/k2 + k2/k1) + 2/7 μ², G_2^s = 3/7 + ½ μ (k1/k2 + k2/k1) + 4/7 μ², written with
/// μ k1 k2 = k1·k2 so that everything is rational.
fn f2_g2_closed(a: &[Q; 3], b: &[Q; 3]) -> [Q; 2] {
    let (aa, bb, ab) = (dot(a, a), dot(b, b), dot(a, b));
    let mu2 = &ab * &ab / (&aa * &bb);
    let cross = &ab * (aa.recip() + bb.recip()) / q(2, 1);
    [
        q(5, 7) + &cross + q(2, 7) * &mu2,
        q(3, 7) + cross + q(4, 7) * mu2,
    ]
}

#[test]
fn f2_and_g2_match_their_closed_forms() {
    let mut rng = <rand_chacha::ChaCha8Rng as rand::SeedableRng>::seed_from_u64(2);
    for _ in 0..200 {
        let (a, b) = (random_dyadic(&mut rng), random_dyadic(&mut rng));
        if dot(&add(&a, &b), &add(&a, &b)).is_zero() {
            continue;
        }
        assert_eq!(
            kernels(&[a.clone(), b.clone()]).unwrap(),
            f2_g2_closed(&a, &b)
        );
    }
}

/// α(k, k1) and β(k, k1, k2) of the paper.
fn alpha(k: &[Q; 3], k1: &[Q; 3]) -> Q {
    dot(k, k1) / dot(k1, k1)
}
fn beta(k: &[Q; 3], k1: &[Q; 3], k2: &[Q; 3]) -> Q {
    dot(k, k) * dot(k1, k2) / (q(2, 1) * dot(k1, k1) * dot(k2, k2))
}

/// The textbook symmetrised F_3^s (e.g. Bernardeau et al. 2002, eq. 45 written with F_2^s, G_2^s):
/// 54 F_3^s = Σ_i { 7 α(k, q_i) F_2^s(q_j, q_l) + [7 α(k, q_jl) + 4 β(k, q_i, q_jl)] G_2^s(q_j, q_l) }.
fn f3_closed(qs: &[[Q; 3]; 3]) -> Q {
    let k = add(&add(&qs[0], &qs[1]), &qs[2]);
    let mut sum = Q::zero();
    for i in 0..3 {
        let (j, l) = ((i + 1) % 3, (i + 2) % 3);
        let qjl = add(&qs[j], &qs[l]);
        let [f2, g2] = f2_g2_closed(&qs[j], &qs[l]);
        sum += q(7, 1) * alpha(&k, &qs[i]) * f2
            + (q(7, 1) * alpha(&k, &qjl) + q(4, 1) * beta(&k, &qs[i], &qjl)) * g2;
    }
    sum / q(54, 1)
}

#[test]
fn f3_matches_the_textbook_closed_form() {
    let mut rng = <rand_chacha::ChaCha8Rng as rand::SeedableRng>::seed_from_u64(3);
    let mut checked = 0;
    while checked < 100 {
        let qs = [
            random_dyadic(&mut rng),
            random_dyadic(&mut rng),
            random_dyadic(&mut rng),
        ];
        let pair_sums = [
            add(&qs[0], &qs[1]),
            add(&qs[1], &qs[2]),
            add(&qs[0], &qs[2]),
        ];
        if pair_sums
            .iter()
            .chain([add(&pair_sums[0], &qs[2])].iter())
            .any(|s| dot(s, s).is_zero())
        {
            continue;
        }
        assert_eq!(kernels(&qs).unwrap()[0], f3_closed(&qs));
        checked += 1;
    }
}

/// The paper's appendix form of the P13 kernel:
/// 6F_3^s(k,q,−q) = ⅑G_2^s(k,q)[7α(k,k+q) + 4β(k,k+q,−q)] + ⅑G_2^s(k,−q)[7α(k,k−q) + 4β(k,k−q,q)]
///                 + (7/9) α(k,q)[F_2^s(k,−q) − F_2^s(k,q)].
#[test]
fn p13_kernel_matches_the_papers_appendix_form() {
    let mut rng = <rand_chacha::ChaCha8Rng as rand::SeedableRng>::seed_from_u64(4);
    for _ in 0..100 {
        let (k, qv) = (random_dyadic(&mut rng), random_dyadic(&mut rng));
        let (kpq, kmq) = (add(&k, &qv), add(&k, &neg(&qv)));
        if dot(&kpq, &kpq).is_zero() || dot(&kmq, &kmq).is_zero() {
            continue;
        }
        let [f_kq, g_kq] = f2_g2_closed(&k, &qv);
        let [f_kmq, g_kmq] = f2_g2_closed(&k, &neg(&qv));
        let six_f3 =
            q(1, 9) * g_kq * (q(7, 1) * alpha(&k, &kpq) + q(4, 1) * beta(&k, &kpq, &neg(&qv)))
                + q(1, 9) * g_kmq * (q(7, 1) * alpha(&k, &kmq) + q(4, 1) * beta(&k, &kmq, &qv))
                + q(7, 9) * alpha(&k, &qv) * (f_kmq - f_kq);
        let g: [Q; 3] = gram(&[k, qv]).try_into().unwrap();
        assert_eq!(q(6, 1) * propagator_3(&g)[0].clone(), six_f3);
    }
}

/// Coefficients c[ℓ] of a polynomial in μ of degree ≤ 4 in the Legendre basis, from its values at
/// μ = 0, ±1/2, ±1 (exact interpolation, then the monomial → Legendre change of basis).
fn legendre_coefficients(p: impl Fn(&Q) -> Q) -> [Q; 5] {
    let nodes = [q(-1, 1), q(-1, 2), q(0, 1), q(1, 2), q(1, 1)];
    let values: Vec<Q> = nodes.iter().map(&p).collect();
    // Newton divided differences → monomial coefficients a0..a4.
    let mut coef = values.clone();
    for j in 1..5 {
        for i in (j..5).rev() {
            coef[i] = (&coef[i] - &coef[i - 1]) / (&nodes[i] - &nodes[i - j]);
        }
    }
    let mut mono = vec![Q::zero(); 5];
    for i in (0..5).rev() {
        // mono = mono·(μ − x_i) + coef[i]
        let mut next = vec![Q::zero(); 5];
        for d in 0..5 {
            if d + 1 < 5 {
                next[d + 1] += &mono[d];
            }
            next[d] -= &mono[d] * &nodes[i];
        }
        next[0] += &coef[i];
        mono = next;
    }
    // μ^0 = P0, μ = P1, μ² = (P0 + 2P2)/3, μ³ = (3P1 + 2P3)/5, μ⁴ = (7P0 + 20P2 + 8P4)/35
    let table: [[Q; 5]; 5] = [
        [q(1, 1), q(0, 1), q(0, 1), q(0, 1), q(0, 1)],
        [q(0, 1), q(1, 1), q(0, 1), q(0, 1), q(0, 1)],
        [q(1, 3), q(0, 1), q(2, 3), q(0, 1), q(0, 1)],
        [q(0, 1), q(3, 5), q(0, 1), q(2, 5), q(0, 1)],
        [q(7, 35), q(0, 1), q(20, 35), q(0, 1), q(8, 35)],
    ];
    let mut out: [Q; 5] = Default::default();
    for (d, row) in table.iter().enumerate() {
        for (l, t) in row.iter().enumerate() {
            out[l] += &mono[d] * t;
        }
    }
    out
}

/// The tables FAST-PT hard-codes as floats: the kernel products K(q1, q2) of P22, as functions of
/// μ = q̂1·q̂2 and r = q1/q2, split into r⁰, (r + 1/r) and (r² + 1/r²) parts, each in Legendre polynomials.
/// Built here from the generated F_2^s, G_2^s evaluated at rational invariants (q1² = r², q2² = 1,
/// q1·q2 = rμ), with exact interpolation in r and μ.
#[test]
fn p22_kernel_legendre_tables_match_fastpt_exactly() {
    // [r⁰: P0 P2 P4], [r^±1: P1 P3], [r^±2: P0 P2]; FAST-PT's coefficient lists divided by its factor 2
    let expected = [
        (
            "F2F2",
            [q(1219, 1470), q(671, 1029), q(32, 1715)],
            [q(31, 35), q(4, 35)],
            [q(1, 12), q(1, 6)],
        ),
        (
            "F2G2",
            [q(1003, 1470), q(803, 1029), q(64, 1715)],
            [q(29, 35), q(6, 35)],
            [q(1, 12), q(1, 6)],
        ),
        (
            "G2G2",
            [q(851, 1470), q(871, 1029), q(128, 1715)],
            [q(27, 35), q(8, 35)],
            [q(1, 12), q(1, 6)],
        ),
    ];
    for (name, r0, r1, r2) in expected {
        let product = |r: &Q, mu: &Q| -> Q {
            let g = [r * r, r * mu, Q::one()];
            let [f2, g2] = pt_kernels::general_from_gram(2, &g).unwrap();
            match name {
                "F2F2" => f2.clone() * f2,
                "F2G2" => f2 * g2,
                _ => g2.clone() * g2,
            }
        };
        // K(r) r² is a polynomial of degree 4 in r: K = c0 + c1 (r + 1/r) + c2 (r² + 1/r²) by symmetry r ↔ 1/r.
        // Evaluate at r = 1, 2, 3 and solve for c0, c1, c2 at each μ node.
        let part = |which: usize, mu: &Q| -> Q {
            let k: Vec<Q> = [1, 2, 3].iter().map(|&r| product(&q(r, 1), mu)).collect();
            let s = |r: i64| (q(r, 1) + q(1, r), q(r * r, 1) + q(1, r * r));
            // rows: c0 + s1 c1 + s2 c2 = K(r)
            let rows: Vec<(Q, Q, Q)> = [1, 2, 3]
                .iter()
                .map(|&r| (Q::one(), s(r).0, s(r).1))
                .collect();
            let solved = solve3(&rows, &k);
            solved[which].clone()
        };
        let c0 = legendre_coefficients(|mu| part(0, mu));
        let c1 = legendre_coefficients(|mu| part(1, mu));
        let c2 = legendre_coefficients(|mu| part(2, mu));
        assert_eq!(
            [c0[0].clone(), c0[2].clone(), c0[4].clone()],
            r0,
            "{name} r⁰"
        );
        assert_eq!([c1[1].clone(), c1[3].clone()], r1, "{name} r^±1");
        assert_eq!([c2[0].clone(), c2[2].clone()], r2, "{name} r^±2");
        // and nothing else: odd ℓ in even parts and even ℓ in the odd part vanish
        for z in [
            &c0[1], &c0[3], &c1[0], &c1[2], &c1[4], &c2[1], &c2[3], &c2[4],
        ] {
            assert!(z.is_zero(), "{name}: unexpected Legendre component {z}");
        }
    }
}

/// Solves a 3×3 linear system exactly (Cramer's rule).
fn solve3(rows: &[(Q, Q, Q)], rhs: &[Q]) -> [Q; 3] {
    let m = |i: usize, j: usize| -> Q {
        let r = &rows[i];
        match j {
            0 => r.0.clone(),
            1 => r.1.clone(),
            _ => r.2.clone(),
        }
    };
    let det = |c: &dyn Fn(usize, usize) -> Q| -> Q {
        c(0, 0) * (c(1, 1) * c(2, 2) - c(1, 2) * c(2, 1))
            - c(0, 1) * (c(1, 0) * c(2, 2) - c(1, 2) * c(2, 0))
            + c(0, 2) * (c(1, 0) * c(2, 1) - c(1, 1) * c(2, 0))
    };
    let d = det(&m);
    let col = |k: usize| det(&|i, j| if j == k { rhs[i].clone() } else { m(i, j) }) / &d;
    [col(0), col(1), col(2)]
}

/// The generated code in f64 agrees with the same code in exact rationals to 1e-12 at generic points
/// (dyadic inputs, so the f64 inputs are exact and only the arithmetic rounds).
#[test]
fn f64_agrees_with_exact_to_1e_12() {
    let mut rng = <rand_chacha::ChaCha8Rng as rand::SeedableRng>::seed_from_u64(5);
    let mut worst = 0.0f64;
    for n in 1..=7usize {
        for _ in 0..(if n >= 6 { 4 } else { 20 }) {
            let qs: Vec<[Q; 3]> = (0..n).map(|_| random_dyadic(&mut rng)).collect();
            let exact = kernels(&qs).unwrap();
            let fl = kernels(&qs.iter().map(to_f64).collect::<Vec<_>>()).unwrap();
            for (e, x) in exact.iter().zip(fl) {
                let scale = f(e).abs().max(1e-3);
                let err = (x - f(e)).abs() / scale;
                worst = worst.max(err);
                assert!(
                    err <= 1e-12,
                    "n = {n}: f64 {x} vs exact {} (rel {err:e})",
                    f(e)
                );
            }
        }
    }
    eprintln!("worst f64 vs exact relative difference: {worst:e}");
}

#[test]
fn order_and_zero_vector_errors() {
    let z = [q(0, 1), q(0, 1), q(0, 1)];
    assert_eq!(kernels::<Q>(&[]), Err(pt_kernels::KernelError::Order(0)));
    let eight: Vec<[Q; 3]> = (1..=8).map(|i| v(i, 1, 0, 1)).collect();
    assert_eq!(kernels(&eight), Err(pt_kernels::KernelError::Order(8)));
    assert_eq!(
        kernels(&[v(1, 0, 0, 1), z]),
        Err(pt_kernels::KernelError::ZeroVector(2))
    );
    assert_eq!(kernels(&[v(1, 2, 3, 1)]).unwrap(), [Q::one(), Q::one()]);
}
