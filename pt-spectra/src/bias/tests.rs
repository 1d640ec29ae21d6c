use super::*;
use crate::integrate::legendre_nodes;
use crate::loops::bias::sig3nl_kernel;

const SAMPLE: BiasParams = BiasParams {
    b1: 1.9,
    b2: -0.7,
    bs: 0.45,
    b3: 0.3,
};

/// Every convention's values map back to the same bias, and the Jacobian is that map.
#[test]
fn conventions_round_trip_through_their_jacobians() {
    for c in BiasConvention::ALL {
        let v = SAMPLE.in_convention(c);
        let back = BiasParams::from_convention(c, v);
        for (a, b) in back.values().iter().zip(SAMPLE.values()) {
            assert!((a - b).abs() < 1e-14, "{c}: {back:?}");
        }
        let again = BiasParams::from_convention(c, back.in_convention(c)).in_convention(c);
        for (a, b) in again.iter().zip(v) {
            assert!((a - b).abs() < 1e-14, "{c}");
        }
    }
    assert_eq!(
        BiasParams::from_convention(BiasConvention::Velocileptors, SAMPLE.values()),
        SAMPLE
    );
}

/// FAST-PT's (bs/2)s² against bs s², and CLASS-PT's quadratic terms against ours as the second-order
/// kernels of δ_g: (b2/2) + bs S₂(μ) = (b2'/2) + b_G2 (μ² − 1) at every angle μ of the pair.
#[test]
fn the_quadratic_kernels_agree_across_conventions() {
    let fast = SAMPLE.in_convention(BiasConvention::FastPt);
    let [_, b2c, bg2, _] = SAMPLE.in_convention(BiasConvention::ClassPt);
    for mu in [-1.0, -0.4, 0.0, 0.3, 0.8, 1.0_f64] {
        let s2 = mu * mu - 1.0 / 3.0;
        let ours = 0.5 * SAMPLE.b2 + SAMPLE.bs * s2;
        assert!((0.5 * fast[1] + 0.5 * fast[2] * s2 - ours).abs() < 1e-14);
        assert!(
            (0.5 * b2c + bg2 * (mu * mu - 1.0) - ours).abs() < 1e-14,
            "mu {mu}"
        );
    }
}

/// The angular average over q̂ of 3 K₃(k, q, −q), the symmetrised cubic kernel of the operator
/// 2 X(p₁, p₂₃) Y(p₂, p₃) with X = μ² − 1 (G₂ acting on a linear and a second-order potential) and Y
/// the second-order kernel `y`, at r = q/k, by Gauss–Legendre in the cosine.
fn cubic_average(r: f64, y: impl Fn(&[[f64; 3]; 2]) -> f64) -> f64 {
    let (x, w) = legendre_nodes(200);
    let cos2 = |a: [f64; 3], b: [f64; 3]| {
        let ab: f64 = (0..3).map(|i| a[i] * b[i]).sum();
        let n = |v: [f64; 3]| v.iter().map(|c| c * c).sum::<f64>();
        ab * ab / (n(a) * n(b))
    };
    let k = [0.0, 0.0, 1.0];
    x.iter()
        .zip(&w)
        .map(|(&c, &wi)| {
            let s = (1.0 - c * c).sqrt();
            let q = [r * s, 0.0, r * c];
            let mq = q.map(|v| -v);
            let k_minus_q = [-q[0], 0.0, 1.0 - q[2]];
            let k_plus_q = [q[0], 0.0, 1.0 + q[2]];
            // the K₃ terms whose linear leg is q or −q (the one with leg k has Y(q, −q) = 0)
            let v = 2.0 * (cos2(q, k_minus_q) - 1.0) * y(&[k, mq])
                + 2.0 * (cos2(mq, k_plus_q) - 1.0) * y(&[k, q]);
            0.5 * wi * v
        })
        .sum()
}

/// CLASS-PT's cubic terms are 2 b1 (−(15/2) b_G2 − 3 b_Γ3) sig3nl in P_gg (module docs): the cubic parts of
/// G₂ (Y = F₂) and Γ₃ (Y = F₂ − G₂), from the generated kernels, against sig3nl's closed-form
/// average. Neither has a k → 0 constant (a renormalisation of b1): both vanish as (k/q)².
#[test]
fn class_pt_cubic_terms_are_sig3nl_shaped() {
    let f2 = |p: &[[f64; 3]; 2]| pt_kernels::kernels(p).unwrap()[0];
    let f2_minus_g2 = |p: &[[f64; 3]; 2]| {
        let [f, g] = pt_kernels::kernels(p).unwrap();
        f - g
    };
    let m = BiasConvention::ClassPt.jacobian();
    for (y, want, name) in [
        // P_gg ⊃ b1 b3 sig3nl = 2 b1 b_O ⟨3K₃⟩ P: the average is half the map's coefficient
        (&f2 as &dyn Fn(&[[f64; 3]; 2]) -> f64, 0.5 * m[3][2], "G2"),
        (&f2_minus_g2, 0.5 * m[3][3], "Gamma3"),
    ] {
        let far = cubic_average(1e3, y);
        assert!(far.abs() < 1e-5, "{name}: {far} at k/q = 1e-3");
        for r in [0.05, 0.3, 0.7, 0.95, 1.3, 3.0, 12.0] {
            let ratio = cubic_average(r, y) / sig3nl_kernel(r);
            assert!(
                (ratio - want).abs() < 2e-6,
                "{name} r = {r}: {ratio} vs {want}"
            );
        }
    }
}

/// The local Lagrangian (coevolution) biases in CLASS-PT's convention, b_G2 = −(2/7)(b1 − 1) and
/// b_Γ3 = (23/42)(b1 − 1) (Eggemeier et al. 2019), give FAST-PT's b3nl = (b1 − 1)/2: Saito et al.
/// (2014)'s b3nl = (32/315)(b1 − 1) of σ₃² = (315/64) sig3nl/P_lin, a value from another paper.
#[test]
fn coevolution_agrees_with_saito_et_al() {
    for b1 in [1.0, 1.5, 2.3] {
        let e = b1 - 1.0;
        let v = [b1, 0.2, -2.0 / 7.0 * e, 23.0 / 42.0 * e];
        let b = BiasParams::from_convention(BiasConvention::ClassPt, v);
        let saito = 32.0 / 315.0 * e * (315.0 / 64.0);
        let b3nl = b.in_convention(BiasConvention::FastPt)[3];
        assert!((b3nl - saito).abs() < 1e-14, "b1 {b1}: {b3nl} vs {saito}");
        assert!((b.bs + 2.0 / 7.0 * e).abs() < 1e-15);
    }
}

#[test]
fn names_parse_and_unknown_ones_list_the_choices() {
    for c in BiasConvention::ALL {
        assert_eq!(c.name().parse::<BiasConvention>().unwrap(), c);
        assert_eq!(c.to_string().parse::<BiasConvention>().unwrap(), c);
    }
    assert_eq!(
        "CLASS-PT".parse::<BiasConvention>().unwrap(),
        BiasConvention::ClassPt
    );
    assert_eq!(
        "Fast_PT".parse::<BiasConvention>().unwrap(),
        BiasConvention::FastPt
    );
    let e = "pybird".parse::<BiasConvention>().unwrap_err().to_string();
    assert!(e.contains("velocileptors, fastpt, classpt"), "{e}");
    let nan = BiasParams {
        b3: f64::NAN,
        ..SAMPLE
    };
    assert!(nan.check_finite().unwrap_err().to_string().contains("b3"));
}

#[test]
fn the_header_states_both_conventions() {
    let d = SAMPLE.describe(BiasConvention::ClassPt);
    assert!(
        d.contains("bs = 0.45") && d.contains("CLASS-PT's") && d.contains("bG2 = 0.45"),
        "{d}"
    );
    assert!(!SAMPLE
        .describe(BiasConvention::Velocileptors)
        .contains("given in"));
}
