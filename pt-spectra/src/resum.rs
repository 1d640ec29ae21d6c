//! Renormalised-perturbation-theory (RPT) propagators and the resummed spectra built from them.
//!
//! Gil-Marín et al. (2012, arXiv:1209.3771), eq. RPT: P_XY = [P_lin + P22_XY + P33^{2L}_XY + …] N_X(k) N_Y(k),
//! truncated at one loop (P_lin + P22) or two (+ P33^{2L}). The propagators (the paper's N_i, Crocce & Scoccimarro 2006, astro-ph/0509418):
//! * N0 = exp(−k²σ_v²/2), the same for δ and θ;
//! * N1 = exp(P13/P_lin), with P13 = P13_δδ for δ and P13_θθ for θ (paper normalisation, the 1-loop
//!   correction being P22 + 2P13), so that N1² = 1 + 2P13/P_lin + … reproduces 1-loop SPT;
//! * N2 (eq. theory_N2) = cosh√s + a sinh(√s)/√s with a = P13/P_lin, s = 2P15/P_lin; for P15 < 0 the
//!   same entire function of s is cos√−s + a sin(√−s)/√−s. Its expansion 1 + a + s/2 + … reproduces the
//!   propagator to two loops, and it equals N1 when s = a² (2P15 = (P13/P)² P, factorised kernels);
//! * N3 (eq. N3) = Σ_j [t^j/(3j)! + a t^j/(3j+1)! + s t^j/(3j+2)!] with t = 6P17/P_lin, the paper's
//!   (1/3)[A(x) + (a/x)C(x) + (s/x²)B(x)] with x = ∛t (the real cube root when P17 < 0); N3 = N1 when
//!   s = a², t = a³. **Typo in the paper:** eq. N3 pairs B with P13 and C with P15, which breaks both
//!   limits; B and C must be interchanged.
//!
//! δθ uses N_δ N_θ. Errors are propagated linearly from the loop terms' estimates:
//! δN0 = N0 k² δσ_v²/2, δN1 = N1 δP13/P_lin, and δ(A·M) = |M| δA + |A| δM.

#[cfg(doc)]
use crate::error::Error;
use crate::loops::{ByPair, Estimate, OneLoopTerms, Pair, TwoLoopCorrection};

/// Which resummed propagator.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[non_exhaustive]
pub enum Propagator {
    /// N0 = exp(−k²σ_v²/2).
    N0,
    /// N1 = exp(P13/P_lin).
    N1,
    /// N2 from P13 and P15 (eq. theory_N2).
    N2,
    /// N3 from P13, P15 and P17 (eq. N3).
    N3,
}

/// N0(k) = exp(−k²σ_v²/2) with its error, k in h/Mpc, σ_v² in (Mpc/h)².
///
/// ```
/// use pt_spectra::{loops::Estimate, resum::n0};
/// let n = n0(0.1, Estimate::new(36.9, 1e-6));
/// assert!((n.value - (-0.5f64 * 0.01 * 36.9).exp()).abs() < 1e-15);
/// ```
pub fn n0(k: f64, sigma_v2: Estimate) -> Estimate {
    let half = 0.5 * k * k;
    let value = (-half * sigma_v2.value).exp();
    Estimate::new(value, value * half * sigma_v2.error)
}

/// N1 = exp(P13/P_lin) with its error (P13 in the paper's normalisation, (Mpc/h)^3).
///
/// ```
/// use pt_spectra::{loops::Estimate, resum::n1};
/// let n = n1(Estimate::new(-50.0, 0.01), 5000.0);
/// assert!((n.value - (-0.01f64).exp()).abs() < 1e-15);
/// ```
pub fn n1(p13: Estimate, p_lin: f64) -> Estimate {
    let value = (p13.value / p_lin).exp();
    Estimate::new(value, value * p13.error / p_lin)
}

/// C(s) = cosh√s (cos√−s for s < 0) and S(s) = sinh(√s)/√s (sin(√−s)/√−s), with their derivatives
/// C′ = S/2 and S′ = (C − S)/(2s) (series near s = 0).
fn cosh_sinh(s: f64) -> [f64; 4] {
    if s.abs() < 1e-3 {
        let c = 1.0 + s / 2.0 + s * s / 24.0 + s * s * s / 720.0;
        let sh = 1.0 + s / 6.0 + s * s / 120.0 + s * s * s / 5040.0;
        return [c, sh, sh / 2.0, 1.0 / 6.0 + s / 60.0 + s * s / 1680.0];
    }
    let (c, sh) = if s > 0.0 {
        let r = s.sqrt();
        (r.cosh(), r.sinh() / r)
    } else {
        let r = (-s).sqrt();
        (r.cos(), r.sin() / r)
    };
    [c, sh, sh / 2.0, (c - sh) / (2.0 * s)]
}

/// N2 = C(s) + a S(s) with a = P13/P_lin, s = 2P15/P_lin (both branches), with its error
/// |S| δa + |C′ + a S′| δs.
///
/// ```
/// use pt_spectra::{loops::Estimate, resum::{n1, n2}};
/// // Factorised kernels, 2P15 = (P13/P)² P: N2 = N1 = e^a.
/// let (p, p13) = (1000.0, Estimate::new(-300.0, 0.0));
/// let p15 = Estimate::new(0.5 * 0.09 * p, 0.0);
/// assert!((n2(p13, p15, p).value - n1(p13, p).value).abs() < 1e-15);
/// ```
pub fn n2(p13: Estimate, p15: Estimate, p_lin: f64) -> Estimate {
    let (a, s) = (p13.value / p_lin, 2.0 * p15.value / p_lin);
    let [c, sh, dc, dsh] = cosh_sinh(s);
    let value = c + a * sh;
    let error = sh.abs() * p13.error / p_lin + (dc + a * dsh).abs() * 2.0 * p15.error / p_lin;
    Estimate::new(value, error)
}

/// The three series Σ_j t^j/(3j + m)!, m = 0, 1, 2, of N3; closed forms through x = ∛t (real root) for
/// |t| > 1: A(x)/3, C(x)/(3x), B(x)/(3x²) with the paper's A, B, C. (The paper pairs B with P13 and C
/// with P15; as printed N3 then does not expand to 1 + a + s/2 + t/6 nor reduce to e^a for factorised
/// kernels: B and C are interchanged there.)
fn triple_series(t: f64) -> [f64; 3] {
    if t.abs() <= 1.0 {
        let mut out = [0.0; 3];
        let mut term = [1.0, 1.0, 0.5]; // t^j/(3j+m)! at j = 0
        for j in 0..30 {
            for m in 0..3 {
                out[m] += term[m];
                let n = (3 * j + m) as f64;
                term[m] *= t / ((n + 1.0) * (n + 2.0) * (n + 3.0));
            }
        }
        return out;
    }
    let x = t.cbrt();
    let (e, h) = (x.exp(), (-0.5 * x).exp());
    let (c, sn) = ((0.75f64.sqrt() * x).cos(), (0.75f64.sqrt() * x).sin());
    let r3 = 3f64.sqrt();
    [
        (e + 2.0 * h * c) / 3.0,
        (e - h * (c - r3 * sn)) / (3.0 * x),
        (e - h * (c + r3 * sn)) / (3.0 * x * x),
    ]
}

/// N3 = A₃(t) + a B₃(t) + s C₃(t) with a = P13/P_lin, s = 2P15/P_lin, t = 6P17/P_lin (eq. N3), with its
/// error |B₃| δa + |C₃| δs + |∂N3/∂t| δt (the t-derivative by a central difference).
///
/// ```
/// use pt_spectra::{loops::Estimate, resum::{n1, n3}};
/// // Factorised kernels (2P15 = a²P, 6P17 = a³P): N3 = e^a, on both branches of the cube root.
/// for a in [-0.3f64, -2.5, 1.7] {
///     let p = 1000.0;
///     let n = n3(Estimate::new(a * p, 0.0), Estimate::new(0.5 * a * a * p, 0.0), Estimate::new(a.powi(3) * p / 6.0, 0.0), p);
///     assert!((n.value / a.exp() - 1.0).abs() < 1e-12, "{a}");
/// }
/// ```
pub fn n3(p13: Estimate, p15: Estimate, p17: Estimate, p_lin: f64) -> Estimate {
    let (a, s, t) = (
        p13.value / p_lin,
        2.0 * p15.value / p_lin,
        6.0 * p17.value / p_lin,
    );
    let f = |t: f64| {
        let [x, y, z] = triple_series(t);
        x + a * y + s * z
    };
    let [_, y, z] = triple_series(t);
    let h = 1e-4 * t.abs().max(1e-2);
    let dt = (f(t + h) - f(t - h)) / (2.0 * h);
    let error = y.abs() * p13.error / p_lin
        + z.abs() * 2.0 * p15.error / p_lin
        + dt.abs() * 6.0 * p17.error / p_lin;
    Estimate::new(f(t), error)
}

/// An RPT propagator with the terms it is made of.
#[derive(Debug, Clone, Copy)]
pub enum PropagatorTerms<'a> {
    /// N0 = exp(−k²σ_v²/2).
    N0,
    /// N1 from P13.
    N1,
    /// N2 from P13 and P15.
    N2 {
        /// P15 of δδ, δθ, θθ.
        p15: &'a ByPair<Vec<Estimate>>,
    },
    /// N3 from P13, P15 and P17.
    N3 {
        /// P15 of δδ, δθ, θθ.
        p15: &'a ByPair<Vec<Estimate>>,
        /// P17 of δδ, δθ, θθ.
        p17: &'a ByPair<Vec<Estimate>>,
    },
}

/// The propagators (N_δ, N_θ) at every k of `t` (P_lin, P13, σ_v²) and the terms of `kind`.
pub fn propagators(kind: PropagatorTerms<'_>, t: &OneLoopTerms) -> (Vec<Estimate>, Vec<Estimate>) {
    let n = t.k.len();
    let (p13, p_lin) = (&t.p13, &t.p_lin);
    match kind {
        PropagatorTerms::N3 { p15, p17 } => {
            let of = |pair: Pair| -> Vec<Estimate> {
                (0..n)
                    .map(|i| n3(p13[pair][i], p15[pair][i], p17[pair][i], p_lin[i]))
                    .collect()
            };
            (of(Pair::DeltaDelta), of(Pair::ThetaTheta))
        }
        PropagatorTerms::N2 { p15 } => {
            let of = |pair: Pair| -> Vec<Estimate> {
                (0..n)
                    .map(|i| n2(p13[pair][i], p15[pair][i], p_lin[i]))
                    .collect()
            };
            (of(Pair::DeltaDelta), of(Pair::ThetaTheta))
        }
        PropagatorTerms::N0 => {
            let n: Vec<Estimate> = t.k.iter().map(|&k| n0(k, t.sigma_v2)).collect();
            (n.clone(), n)
        }
        PropagatorTerms::N1 => {
            let of = |p13: &[Estimate]| -> Vec<Estimate> {
                p13.iter().zip(p_lin).map(|(&p, &lin)| n1(p, lin)).collect()
            };
            (of(&p13.dd), of(&p13.tt))
        }
    }
}

/// RegPT's running damping scale σ_d²(k) = (1/6π²)∫_{q_min}^{k/2} P(q) dq [(Mpc/h)²] at each k
/// (Taruya, Bernardeau, Nishimichi & Codis 2012, arXiv:1208.1191, eq. 17), from the q_min of
/// `precision` to min(k/2, q_max): composite Simpson in ln q with 512 intervals, error |S − S_half|.
pub fn sigma_d2(
    spectrum: &crate::linear::LinearSpectrum,
    k: &[f64],
    precision: &crate::precision::Precision,
) -> Vec<Estimate> {
    const INTERVALS: usize = 512;
    let norm = 1.0 / (6.0 * std::f64::consts::PI.powi(2));
    k.iter()
        .map(|&k| {
            let (a, b) = (precision.q_min.ln(), (0.5 * k).min(precision.q_max).ln());
            let integrand = |ln_q: f64| {
                let q = ln_q.exp();
                q * spectrum.eval(q)
            };
            let (value, error) = crate::integrate::simpson_ln(integrand, a, b, INTERVALS);
            Estimate::new(norm * value, norm * error)
        })
        .collect()
}

/// The 1-loop RegPT spectrum of `pair` at k index `i` (Taruya et al. 2012, arXiv:1208.1191, eqs.
/// 23–24, as pyregpt writes it): with x = k²σ_d²/2 and Γ_X = P13_XX/P_lin (the 1-loop propagator
/// correction; X = δ, θ),
/// P_XY = e^{−2x} [(1 + x + Γ_X)(1 + x + Γ_Y) P_lin + P22_XY].
pub fn regpt_one_loop(terms: &OneLoopTerms, pair: Pair, i: usize, sigma_d2: Estimate) -> Estimate {
    let k = terms.k[i];
    let x = 0.5 * k * k * sigma_d2;
    let p = terms.p_lin[i];
    let (a, b) = legs(pair);
    let gamma = |leg: Pair| terms.p13[leg][i] / p;
    regpt_damping(x) * ((1.0 + x + gamma(a)) * (1.0 + x + gamma(b)) * p + terms.p22[pair][i])
}

/// The auto pairs (XX, YY) of the fields X, Y of `pair`: the propagators of δθ are those of δ and θ.
fn legs(pair: Pair) -> (Pair, Pair) {
    match pair {
        Pair::DeltaDelta => (Pair::DeltaDelta, Pair::DeltaDelta),
        Pair::DeltaTheta => (Pair::DeltaDelta, Pair::ThetaTheta),
        Pair::ThetaTheta => (Pair::ThetaTheta, Pair::ThetaTheta),
    }
}

/// RegPT's damping e^{−2x} with its error 2e^{−2x}δx.
fn regpt_damping(x: Estimate) -> Estimate {
    let e = (-2.0 * x.value).exp();
    Estimate::new(e, 2.0 * e * x.error)
}

/// What the 2-loop RegPT spectrum is made of, on one k grid.
#[derive(Debug, Clone, Copy)]
pub struct RegPtTwoLoop<'a> {
    /// P_lin, P22, P13.
    pub one_loop: &'a OneLoopTerms,
    /// σ_d²(k) ([`sigma_d2`]).
    pub sigma_d2: &'a [Estimate],
    /// P15 (the 2-loop propagator).
    pub p15: &'a ByPair<Vec<Estimate>>,
    /// The 2-loop SPT terms, for P33irr.
    pub two_loop: &'a TwoLoopCorrection,
    /// P24 and PΓ2 from the 1-loop vertex.
    pub gamma2: &'a crate::loops::Gamma2Terms,
}

impl RegPtTwoLoop<'_> {
    /// The 2-loop RegPT spectrum of `pair` at k index `i` (Taruya et al. 2012, arXiv:1208.1191, eqs.
    /// 23–24, as pyregpt writes it): with x = k²σ_d²/2, Γ1_X = P13_XX/P_lin and Γ2_X = P15_XX/P_lin
    /// (the 1- and 2-loop propagator corrections; X = δ, θ),
    /// P_XY = e^{−2x} {A_X A_Y P_lin + P22_XY (1 + x)² + P24_XY (1 + x) + PΓ2_XY + P33irr_XY},
    /// A_X = 1 + x + x²/2 + Γ1_X (1 + x) + Γ2_X, with RegPT's P24 = 2P24 of the paper and PΓ2
    /// ([`crate::loops::Gamma2Terms`]).
    pub fn spectrum(&self, pair: Pair, i: usize) -> Estimate {
        let t = self.one_loop;
        let (k, p) = (t.k[i], t.p_lin[i]);
        let x = 0.5 * k * k * self.sigma_d2[i];
        let propagator = |x_pair: Pair| {
            1.0 + x + x * x * 0.5 + t.p13[x_pair][i] / p * (1.0 + x) + self.p15[x_pair][i] / p
        };
        let (a, b) = legs(pair);
        let one_plus = 1.0 + x;
        regpt_damping(x)
            * (propagator(a) * propagator(b) * p
                + t.p22[pair][i] * one_plus * one_plus
                + self.gamma2.p24[pair][i] * one_plus
                + self.gamma2.p_gamma2[pair][i]
                + self.two_loop.pairs[pair].p33_2l[i])
    }
}

/// Product of two estimates, errors propagated linearly (as `a * b`).
pub fn product(a: Estimate, b: Estimate) -> Estimate {
    a * b
}

/// The damping factors N_X N_Y of δδ, δθ and θθ at k index `i`, from (N_δ, N_θ).
pub fn factors(n: &(Vec<Estimate>, Vec<Estimate>), i: usize) -> ByPair<Estimate> {
    let (d, t) = (n.0[i], n.1[i]);
    ByPair {
        dd: d * d,
        dt: d * t,
        tt: t * t,
    }
}

/// The RPT spectrum of `pair` at k index `i`: [P_lin + P22] N_X N_Y at one loop, and
/// [P_lin + P22 + P33^{2L}] N_X N_Y at two loops (`two_loop`: the 2-loop terms).
pub fn rpt(
    terms: &OneLoopTerms,
    two_loop: Option<&TwoLoopCorrection>,
    n: &(Vec<Estimate>, Vec<Estimate>),
    pair: Pair,
    i: usize,
) -> Estimate {
    let mut base = terms.p22[pair][i] + terms.p_lin[i];
    if let Some(t) = two_loop {
        base += t.pairs[pair].p33_2l[i];
    }
    base * factors(n, i)[pair]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn n2_branches_and_series_agree_with_the_closed_forms() {
        let p = 1.0;
        for (a, s) in [
            (-0.4, 0.3),
            (-0.4, -0.3),
            (0.2, 2e-4),
            (0.2, -2e-4),
            (-3.0, 5.0),
            (-3.0, -5.0),
        ] {
            let n = n2(Estimate::new(a, 0.0), Estimate::new(0.5 * s, 0.0), p).value;
            let f64_sqrt = f64::sqrt;
            let expected = if s > 0.0 {
                f64_sqrt(s).cosh() + a * f64_sqrt(s).sinh() / f64_sqrt(s)
            } else {
                f64_sqrt(-s).cos() + a * f64_sqrt(-s).sin() / f64_sqrt(-s)
            };
            assert!((n - expected).abs() < 1e-12, "a={a} s={s}: {n} {expected}");
        }
        // Continuity across s = 0 and the derivative used for the error: δN2/δs = C′ + aS′.
        let [_, _, dc, ds] = cosh_sinh(0.0);
        assert_eq!((dc, ds), (0.5, 1.0 / 6.0));
        let e = n2(Estimate::new(-0.4, 0.0), Estimate::new(0.15, 1e-3), 1.0).error;
        let num = (n2(Estimate::new(-0.4, 0.0), Estimate::new(0.151, 0.0), 1.0).value
            - n2(Estimate::new(-0.4, 0.0), Estimate::new(0.149, 0.0), 1.0).value)
            / 2.0;
        assert!((e - num.abs()).abs() < 1e-9, "{e} {num}");
    }

    #[test]
    fn n3_series_and_closed_form_join() {
        for t in [-1.0, 1.0] {
            let series = triple_series(t);
            let closed = triple_series(t * (1.0 + 1e-12) + t.signum() * 1e-15);
            for m in 0..3 {
                assert!((series[m] - closed[m]).abs() < 1e-9, "t={t} m={m}");
            }
        }
        // N3 expands to 1 + a + s/2 + t/6 + … (the propagator to three loops).
        let (a, s, t) = (1e-3, 2e-3, 3e-3);
        let n = n3(
            Estimate::new(a, 0.0),
            Estimate::new(0.5 * s, 0.0),
            Estimate::new(t / 6.0, 0.0),
            1.0,
        );
        // Next terms: a t/24 + s t/120 + t²/720 ≈ 2e-7.
        assert!((n.value - (1.0 + a + s / 2.0 + t / 6.0)).abs() < 3e-7);
    }

    #[test]
    fn errors_propagate_linearly() {
        let a = Estimate::new(2.0, 0.1);
        let b = Estimate::new(-3.0, 0.2);
        let p = product(a, b);
        assert_eq!(p.value, -6.0);
        assert!((p.error - (2.0 * 0.2 + 3.0 * 0.1)).abs() < 1e-15);
        let n = n1(Estimate::new(-10.0, 1.0), 100.0);
        assert!((n.error - n.value / 100.0).abs() < 1e-15);
    }
}
