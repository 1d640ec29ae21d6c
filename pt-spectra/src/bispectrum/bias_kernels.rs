//! The galaxy (biased tracer) kernels K_n, n ≤ 4, of the one-loop galaxy bispectrum, in real space and in
//! redshift space (Z_n^g), as linear combinations of operator kernels with the bias coefficients.
//!
//! **Basis** ([`LoopBias`]): the fourth-order Galilean-invariant "split" basis of Eggemeier, Scoccimarro &
//! Smith 2019 (ESS19, arXiv:1812.03208), the one Philcox et al. 2022 (arXiv:2206.02800) use for the one-loop
//! galaxy bispectrum, with δ the nonlinear matter density, θ the velocity divergence (θ₁ = δ₁), the potentials
//! ∇²φ₁ = δ, ∇²Φ_v = θ, ∇²φ₂ = G₂(φ₁), the Galileons G₂(a, b) = ∂_i∂_j a ∂_i∂_j b − ∇²a ∇²b (kernel
//! K(p₁, p₂) = (p̂₁·p̂₂)² − 1) and G₃(a, b, c), the symmetric trilinear Galileon with G₃(φ, φ, φ) = G₃(φ)
//! (kernel L = 1 − μ₁₂² − μ₂₃² − μ₃₁² + 2μ₁₂μ₂₃μ₃₁):
//!
//! ```text
//! δ_g = b1 δ + (b2/2) δ² + g2 G₂(Φ_v)
//!     + (b3/6) δ³ + g2x δ G₂(Φ_v) + g3 G₃(Φ_v) + g21 G₂(φ₂, φ₁)
//!     + g21x δ G₂(φ₂, φ₁) + g211 G₃(φ₂, φ₁, φ₁) + g22 G₂(φ₂, φ₂) + g31 G₂(φ₃, φ₁),
//! ```
//!
//! with two operators defined in Lagrangian space (the "L" convention of
//! `tests/data/bispectrum/check_bias_basis_conventions.py`):
//!
//! - (L21) G₂(φ₂, φ₁) is the operator of the linear (Lagrangian) potentials carried to x by the flow with the
//!   number density, FT = ∫d³q e^{−ik·(q+Ψ)} O(q): third-order kernel sym K(q₁, q₂₃)K(q₂, q₃) (the same as
//!   the Eulerian one), fourth-order kernel sym K(q₁, q₂₃)K(q₂, q₃) k·q₄/q₄² (k the total momentum; the
//!   Zel'dovich displacement −ik·Ψ₁ of the fourth argument);
//! - (L31) φ₃ is the 3LPT potential with its transverse part, ∇²φ₃ = −∇_q·Ψ⁽³⁾ = (1/18)[(15/7)G₂(φ₂, φ₁) −
//!   G₃(φ₁)] (1LPT–3LPT with it reproduce F₃ to 5e-15), so G₂(φ₃, φ₁) is of fourth order only, kernel
//!   sym (1/18)K(q₁, q₂₃₄)[(15/7)K(q₂₃, q₄)K(q₂, q₃) − L(q₂, q₃, q₄)] + (1/14)[M(q₁, q₂₃, q₄, q₂₃₄) −
//!   M(q₁, q₂₃₄, q₂₃, q₄)]K(q₂, q₃), M(a, b, c, d) = (â·b̂)(b̂·ĉ)(ĉ·d̂)(d̂·â): Philcox et al.'s `Kernels.nb`
//!   G₃₁ kernel.
//!
//! The other operators are products and Galileons of the nonlinear Eulerian fields (δ = Σ F_n, θ = Σ G_n);
//! the fourth-order ones g21x, g211, g22 at their lowest order (the same in either convention).
//!
//! **Against ESS19** (their text was not readable here, so no equation numbers; checked instead against the
//! kernels of Philcox et al.'s `Kernels.nb`, which "follows 1812.03208", Eggemeier's talk slides for G₂, G₃
//! and γ₂, and own derivations, `check_bias_basis_conventions.py`): G₂ = (∇_ijΦ)² − (∇²Φ)² and G₃ = (∇²Φ)³ +
//! 2∇_ijΦ∇_jkΦ∇_kiΦ − 3(∇_ijΦ)²∇²Φ give the kernels K and L used here; ∇²φ₁ = δ, ∇²φ₂ = G₂(φ₁) (not the 2LPT
//! potential's −(3/14)G₂(φ₁)); the kernels of b2, g2, b3, g2x, g3, g21 (third order), g21x, g211, g22 and
//! g31 are the notebook's; its G₂(φ₂, φ₁) at fourth order is the Eulerian one (δ = Σ F_n inside φ₁, φ₂),
//! not (L21). Lagrangian local bias b₁ᴸ gives g2 = −(2/7)b₁ᴸ and g21 = −(22/147)b₁ᴸ, which the map below
//! reproduces from CLASS-PT's b_G2 = −(2/7)b₁ᴸ, b_Γ3 = (23/42)b₁ᴸ. Whether ESS19's own prescription is
//! exactly (L21), (L31) is unchecked.
//!
//! **Completeness.** The fourth-order remainders (after their lower orders) of three generated Galilean
//! invariant fields are exactly in this basis (`check_bias_basis_conventions.py`, 80 configurations,
//! residuals ≤ 9e-16 of remainders 0.03–0.4; `check_gamma3_span.py`; the Rust tests
//! `the_maps_are_exact_through_fourth_order`, `delta_minus_theta_is_in_the_span`), through fourth order:
//!
//! ```text
//! Γ₃ = G₂(Φ_g) − G₂(Φ_v) = −(4/7)G₂(φ₂, φ₁) − (4/7)G₃(φ₂, φ₁, φ₁) + (16/49)G₂(φ₂, φ₂) + 8 G₂(φ₃, φ₁),
//! G₂(Φ_g, Φ_v) − G₂(Φ_v) = −(2/7)G₂(φ₂, φ₁) − (2/7)G₃(φ₂, φ₁, φ₁) + (6/49)G₂(φ₂, φ₂) + 4 G₂(φ₃, φ₁),
//! δ − θ = −(2/7)G₂(Φ_v) + (4/63)G₃(Φ_v) − (8/147)G₂(φ₂, φ₁)
//!         − (16/539)G₃(φ₂, φ₁, φ₁) + (72/3773)G₂(φ₂, φ₂) + (48/77)G₂(φ₃, φ₁).
//! ```
//!
//! With the Eulerian fourth order of G₂(φ₂, φ₁) instead, no single G₂(φ₃, φ₁) holds both Γ₃ and δ − θ
//! (residual 1.2% of δ − θ's remainder). The four local fourth-order operators (δ⁴, δ²G₂, G₂², δG₃) are not
//! here: at one loop they enter only B₄₁₁, as pure renormalisations of b2 and g2 (ESS19; Philcox et al.), so
//! eleven parameters remain (as D'Amico et al. 2022, arXiv:2206.08327, count in their basis).
//!
//! **Map to this crate's convention** (velocileptors': (b2/2)δ² + bs s², s² = G₂(Φ_g) + (2/3)δ² at every
//! order; CLASS-PT's (b2/2)δ² + b_G2 G₂(Φ_g) + b_Γ3 Γ₃, Γ₃ = G₂(Φ_g) − G₂(Φ_v)): G₂(Φ_g) = G₂(Φ_v) + Γ₃ and Γ₃
//! as above through fourth order, so, exactly for the one-loop bispectrum ([`LoopBias::from_velocileptors`],
//! [`LoopBias::from_class_pt`]):
//!
//! ```text
//! g2 = b_G2 = bs,   b2 = b2^CLASS-PT = b2^velocileptors + (4/3) bs,
//! (g21, g211, g22, g31) = (−4/7, −4/7, 16/49, 8) × (b_G2 + b_Γ3)   [× bs from velocileptors],
//! ```
//!
//! the others zero.
//!
//! **Kernels.** Every field's symmetrised kernel on a set S of arguments is built from its subsets: a product
//! ab is Σ_{A ⊂ S} [|A|!|S∖A|!/|S|!] a_A b_{S∖A} (the average over orderings of the cut into consecutive
//! blocks), a Galileon G₂(a, b) the same with K(k_A, k_{S∖A}), G₃ over ordered triples with L; F_S, G_S are
//! the exact generated SPT kernels ([`pt_kernels::kernels`]). A set of zero total momentum contributes zero
//! (normal ordering: δ² − ⟨δ²⟩ and so on). In redshift space (Scoccimarro, Couchman & Frieman 1999) the
//! mapping of [`pt_kernels::redshift`] with D(S) = K_S + fμ_S²G_S (the galaxy density replaces the
//! matter's; the velocity is the matter's, no velocity bias):
//! Z_n^g = (1/n!) Σ_{S₀ ≠ ∅} |S₀|! D(S₀) E(N∖S₀), E(R) = Σ over set partitions of R of Π_B |B|! U(B),
//! U(B) = f(kμ)(μ_B/k_B)G_B, so Z₁ = b1 + fμ² and Z_n^g is affine in the bias coefficients.

use super::redshift_weights::{redshift_weights_4, velocity_over_k2};
use crate::error::{Error, Result};
use crate::loops::rsd_two_loop::{kernel_at, redshift_polynomial};
use crate::vec3::{add, dot};

type Vec3 = [f64; 3];

/// The coefficients of the bias expansion of the one-loop galaxy bispectrum (module docs; ESS19's names,
/// γ → g).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct LoopBias {
    /// b1 δ.
    pub b1: f64,
    /// (b2/2) δ².
    pub b2: f64,
    /// γ₂ G₂(Φ_v).
    pub g2: f64,
    /// (b3/6) δ³.
    pub b3: f64,
    /// γ₂ˣ δ G₂(Φ_v).
    pub g2x: f64,
    /// γ₃ G₃(Φ_v).
    pub g3: f64,
    /// γ₂₁ G₂(φ₂, φ₁).
    pub g21: f64,
    /// γ₂₁ˣ δ G₂(φ₂, φ₁).
    pub g21x: f64,
    /// γ₂₁₁ G₃(φ₂, φ₁, φ₁).
    pub g211: f64,
    /// γ₂₂ G₂(φ₂, φ₂).
    pub g22: f64,
    /// γ₃₁ G₂(φ₃, φ₁).
    pub g31: f64,
}

/// The number of bias coefficients of [`LoopBias`].
pub const N_BIAS: usize = 11;

impl LoopBias {
    /// The names, in the order of [`LoopBias::values`] and [`operator_kernels`].
    pub const NAMES: [&'static str; N_BIAS] = [
        "b1", "b2", "g2", "b3", "g2x", "g3", "g21", "g21x", "g211", "g22", "g31",
    ];

    /// Matter: b1 = 1, the others zero.
    pub fn matter() -> Self {
        Self {
            b1: 1.0,
            ..Self::default()
        }
    }

    /// The coefficients in the order of [`LoopBias::NAMES`].
    pub fn values(&self) -> [f64; N_BIAS] {
        [
            self.b1, self.b2, self.g2, self.b3, self.g2x, self.g3, self.g21, self.g21x, self.g211,
            self.g22, self.g31,
        ]
    }

    /// From the coefficients in the order of [`LoopBias::NAMES`].
    pub fn from_values(v: [f64; N_BIAS]) -> Self {
        let [b1, b2, g2, b3, g2x, g3, g21, g21x, g211, g22, g31] = v;
        Self {
            b1,
            b2,
            g2,
            b3,
            g2x,
            g3,
            g21,
            g21x,
            g211,
            g22,
            g31,
        }
    }

    /// From velocileptors' (b1, b2, bs) (this crate's convention; exact through fourth order, module
    /// docs): CLASS-PT's with b_G2 = bs, b_Γ3 = 0 and b2 + (4/3)bs.
    pub fn from_velocileptors(b1: f64, b2: f64, bs: f64) -> Self {
        Self::from_class_pt(b1, b2 + 4.0 / 3.0 * bs, bs, 0.0)
    }

    /// From CLASS-PT's (b1, b2, b_G2, b_Γ3) (exact through fourth order, module docs).
    pub fn from_class_pt(b1: f64, b2: f64, b_g2: f64, b_gamma3: f64) -> Self {
        let gamma = b_g2 + b_gamma3;
        Self {
            b1,
            b2,
            g2: b_g2,
            g21: -4.0 / 7.0 * gamma,
            g211: -4.0 / 7.0 * gamma,
            g22: 16.0 / 49.0 * gamma,
            g31: 8.0 * gamma,
            ..Self::default()
        }
    }

    /// b1 alone (the others zero): the part of the kernels whose UV limit vanishes.
    pub fn linear_only(&self) -> Self {
        Self {
            b1: self.b1,
            ..Self::default()
        }
    }

    /// # Errors
    /// [`Error::InvalidParameter`] for a coefficient that is not finite.
    pub fn check_finite(&self) -> Result<()> {
        for (v, name) in self.values().iter().zip(Self::NAMES) {
            if !v.is_finite() {
                return Err(Error::InvalidParameter {
                    name,
                    value: *v,
                    reason: "bias coefficients must be finite",
                });
            }
        }
        Ok(())
    }
}

/// The largest order of the galaxy kernels.
pub const MAX_BIAS_ORDER: usize = 4;

const FACT: [f64; 5] = [1.0, 1.0, 2.0, 6.0, 24.0];

/// K(a, b) = (â·b̂)² − 1, zero if either vector vanishes.
fn kk(a: &Vec3, b: &Vec3, a2: f64, b2: f64) -> f64 {
    if a2 == 0.0 || b2 == 0.0 {
        return 0.0;
    }
    let ab = dot(a, b);
    ab * ab / (a2 * b2) - 1.0
}

/// L(a, b, c) = 1 − μ_ab² − μ_bc² − μ_ca² + 2 μ_ab μ_bc μ_ca, zero if a vector vanishes.
fn ll(v: [&Vec3; 3], n2: [f64; 3]) -> f64 {
    if n2.contains(&0.0) {
        return 0.0;
    }
    let [a, b, c] = v;
    let (ab, bc, ca) = (dot(a, b), dot(b, c), dot(c, a));
    let (x, y, z) = (n2[0] * n2[1], n2[1] * n2[2], n2[2] * n2[0]);
    1.0 - ab * ab / x - bc * bc / y - ca * ca / z + 2.0 * ab * bc * ca / (x * n2[2])
}

/// The fields of every subset (bit mask) of the arguments.
struct Table {
    n: usize,
    ks: [Vec3; 16],
    ks2: [f64; 16],
    /// F_S, G_S.
    f: [f64; 16],
    g: [f64; 16],
    /// ∇²φ₂, G₂(Φ_v), G₂(φ₂, φ₁) (the fields nested in others).
    p2: [f64; 16],
    g2v: [f64; 16],
    g21: [f64; 16],
    /// The operator kernels of each subset, in the order of [`LoopBias::NAMES`] (with the 1/2, 1/6).
    ops: [[f64; N_BIAS]; 16],
}

/// Proper non-empty submasks of `s`.
fn submasks(s: usize) -> impl Iterator<Item = usize> {
    let mut a = s;
    std::iter::from_fn(move || {
        a = (a.wrapping_sub(1)) & s;
        (a != 0).then_some(a)
    })
}

fn count(s: usize) -> usize {
    s.count_ones() as usize
}

impl Table {
    fn new(q: &[Vec3]) -> Result<Self> {
        let n = q.len();
        if n == 0 || n > MAX_BIAS_ORDER {
            return Err(Error::InvalidChoice {
                what: format!("a galaxy kernel of order {n}"),
                reason: format!("orders 1..={MAX_BIAS_ORDER}"),
            });
        }
        if let Some(i) = q.iter().position(|v| v.iter().all(|x| *x == 0.0)) {
            return Err(Error::InvalidChoice {
                what: format!("argument {} of a galaxy kernel", i + 1),
                reason: "the arguments must be non-zero vectors".into(),
            });
        }
        let mut t = Self {
            n,
            ks: [[0.0; 3]; 16],
            ks2: [0.0; 16],
            f: [0.0; 16],
            g: [0.0; 16],
            p2: [0.0; 16],
            g2v: [0.0; 16],
            g21: [0.0; 16],
            ops: [[0.0; N_BIAS]; 16],
        };
        let full = (1usize << n) - 1;
        for size in 1..=n {
            for s in (1..=full).filter(|&s| count(s) == size) {
                t.fill(q, s);
            }
        }
        Ok(t)
    }

    fn fill(&mut self, q: &[Vec3], s: usize) {
        let members: Vec<Vec3> = (0..self.n)
            .filter(|i| s >> i & 1 == 1)
            .map(|i| q[i])
            .collect();
        let ks = members.iter().fold([0.0; 3], |a, v| add(a, *v));
        self.ks[s] = ks;
        self.ks2[s] = dot(&ks, &ks);
        let m = members.len();
        if m == 1 {
            self.f[s] = 1.0;
            self.g[s] = 1.0;
            self.ops[s][0] = 1.0;
            return;
        }
        if self.ks2[s] > 0.0 {
            let [f, g] = pt_kernels::kernels(&members).unwrap_or([0.0, 0.0]);
            self.f[s] = f;
            self.g[s] = g;
        }
        let k = |a: usize, b: usize| kk(&self.ks[a], &self.ks[b], self.ks2[a], self.ks2[b]);
        let (mut p2, mut g2v, mut dd, mut dg2v, mut g21, mut dg21, mut g22) =
            (0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0);
        for a in submasks(s) {
            let b = s ^ a;
            let w = FACT[count(a)] * FACT[count(b)] / FACT[m];
            let kab = k(a, b);
            p2 += w * kab * self.f[a] * self.f[b];
            g2v += w * kab * self.g[a] * self.g[b];
            dd += w * self.f[a] * self.f[b];
            dg2v += w * self.f[a] * self.g2v[b];
            g21 += w * kab * self.p2[a] * self.f[b];
            dg21 += w * self.f[a] * self.g21[b];
            g22 += w * kab * self.p2[a] * self.p2[b];
        }
        let (mut ddd, mut g3v, mut g211) = (0.0, 0.0, 0.0);
        for a in submasks(s) {
            let r = s ^ a;
            for b in submasks(r) {
                let c = r ^ b;
                let w = FACT[count(a)] * FACT[count(b)] * FACT[count(c)] / FACT[m];
                let l = ll(
                    [&self.ks[a], &self.ks[b], &self.ks[c]],
                    [self.ks2[a], self.ks2[b], self.ks2[c]],
                );
                ddd += w * self.f[a] * self.f[b] * self.f[c];
                g3v += w * l * self.g[a] * self.g[b] * self.g[c];
                g211 += w * l * self.p2[a] * self.f[b] * self.f[c];
            }
        }
        self.p2[s] = p2;
        self.g2v[s] = g2v;
        // G₂(φ₂, φ₁) is the Lagrangian operator carried by the flow with the number density (module docs):
        // its fourth order is the third order of three arguments times the Zel'dovich displacement of the
        // fourth, the product Σ_A [3!1!/4!] G21_A (k_S·k_B/k_B²) over the three-element subsets A, B = S∖A.
        let (g21, g31) = if m == 4 {
            (self.g21_carried(s), g31_kernel(&members))
        } else {
            (g21, 0.0)
        };
        self.g21[s] = g21;
        self.ops[s] = [
            self.f[s],
            0.5 * dd,
            g2v,
            ddd / 6.0,
            dg2v,
            g3v,
            g21,
            dg21,
            g211,
            g22,
            g31,
        ];
    }

    /// G₂(φ₂, φ₁)'s fourth order on the four-element set `s` (module docs, eq. (L21)): the average over
    /// orderings of K(q₁, q₂₃)K(q₂, q₃) k·q₄/q₄², k = k_S, as the subset product of the third-order operator
    /// (zero on a block of zero momentum: normal ordering) and the first-order displacement −ik·Ψ₁.
    fn g21_carried(&self, s: usize) -> f64 {
        let ks = &self.ks[s];
        let mut sum = 0.0;
        for a in submasks(s).filter(|&a| count(a) == 3 && self.ks2[a] > 0.0) {
            let b = s ^ a;
            sum += self.g21[a] * dot(ks, &self.ks[b]) / self.ks2[b];
        }
        sum * FACT[3] * FACT[1] / FACT[4]
    }

    /// The galaxy kernel of the subset `s` (zero if its momentum vanishes).
    fn galaxy(&self, b: &[f64; N_BIAS], s: usize) -> f64 {
        if self.ks2[s] == 0.0 {
            return 0.0;
        }
        let o = &self.ops[s];
        let mut sum = b[0] * o[0];
        for i in 1..N_BIAS {
            sum += b[i] * o[i];
        }
        sum
    }
}

/// â·b̂, zero if either vector vanishes.
fn cosine(a: &Vec3, b: &Vec3) -> f64 {
    let (a2, b2) = (dot(a, a), dot(b, b));
    if a2 == 0.0 || b2 == 0.0 {
        return 0.0;
    }
    dot(a, b) / (a2 * b2).sqrt()
}

/// M(a, b, c, d) = (â·b̂)(b̂·ĉ)(ĉ·d̂)(d̂·â), zero if a vector vanishes.
fn mm(a: &Vec3, b: &Vec3, c: &Vec3, d: &Vec3) -> f64 {
    cosine(a, b) * cosine(b, c) * cosine(c, d) * cosine(d, a)
}

/// G₂(φ₃, φ₁)'s symmetrised kernel at fourth order, φ₃ the 3LPT potential with its transverse part (module
/// docs, eq. (L31)): the average over the 24 orderings of (1/18)K(q₁, q₂₃₄)[(15/7)K(q₂₃, q₄)K(q₂, q₃) −
/// L(q₂, q₃, q₄)] + (1/14)[M(q₁, q₂₃, q₄, q₂₃₄) − M(q₁, q₂₃₄, q₂₃, q₄)]K(q₂, q₃).
fn g31_kernel(q: &[Vec3]) -> f64 {
    let n2 = |v: &Vec3| dot(v, v);
    let mut sum = 0.0;
    for p in PERMS4 {
        let [a, b, c, d] = p.map(|i| q[i]);
        let (bc, bcd) = (add(b, c), add(add(b, c), d));
        let kbc = kk(&b, &c, n2(&b), n2(&c));
        let longitudinal = kk(&a, &bcd, n2(&a), n2(&bcd))
            * (15.0 / 7.0 * kk(&bc, &d, n2(&bc), n2(&d)) * kbc
                - ll([&b, &c, &d], [n2(&b), n2(&c), n2(&d)]))
            / 18.0;
        let transverse = (mm(&a, &bc, &d, &bcd) - mm(&a, &bcd, &bc, &d)) * kbc / 14.0;
        sum += longitudinal + transverse;
    }
    sum / 24.0
}

const PERMS4: [[usize; 4]; 24] = [
    [0, 1, 2, 3],
    [0, 1, 3, 2],
    [0, 2, 1, 3],
    [0, 2, 3, 1],
    [0, 3, 1, 2],
    [0, 3, 2, 1],
    [1, 0, 2, 3],
    [1, 0, 3, 2],
    [1, 2, 0, 3],
    [1, 2, 3, 0],
    [1, 3, 0, 2],
    [1, 3, 2, 0],
    [2, 0, 1, 3],
    [2, 0, 3, 1],
    [2, 1, 0, 3],
    [2, 1, 3, 0],
    [2, 3, 0, 1],
    [2, 3, 1, 0],
    [3, 0, 1, 2],
    [3, 0, 2, 1],
    [3, 1, 0, 2],
    [3, 1, 2, 0],
    [3, 2, 0, 1],
    [3, 2, 1, 0],
];

/// The symmetrised kernels of the eleven operators at order n = `q.len()` (1..=4), in the order of
/// [`LoopBias::NAMES`], including the 1/2 of δ² and the 1/6 of δ³: K_n = Σ_i b_i O_i. O₀ = F_n.
///
/// # Errors
/// [`Error::InvalidChoice`] for an order outside 1..=4 or a zero argument.
pub fn operator_kernels(q: &[Vec3]) -> Result<[f64; N_BIAS]> {
    let t = Table::new(q)?;
    Ok(t.ops[(1 << t.n) - 1])
}

/// The number of parts of a galaxy kernel ([`galaxy_kernel_parts`]): the bias-independent part and one per
/// coefficient.
pub const N_PARTS: usize = N_BIAS + 1;

/// The lowest order at which each operator's kernel is non-zero, in the order of [`LoopBias::NAMES`]: b1 at
/// first order, b2 and g2 at second, b3, g2x, g3 and g21 at third, the rest at fourth (so a product of
/// kernels of orders n₁, n₂, … holds only the coefficients whose lowest orders fit).
pub const LOWEST_ORDER: [usize; N_BIAS] = [1, 2, 2, 3, 3, 3, 3, 4, 4, 4, 4];

/// The galaxy kernel of order n = `q.len()` (1..=4) split by bias coefficient: K_n (real space, `redshift`
/// None) or Z_n^g at (f, line of sight `los`, any non-zero vector along it) is `parts[0]` + Σ_i b_i `parts[1 + i]`
/// (i in the order of [`LoopBias::NAMES`]). `parts[0]`, the part without bias, is zero in real space and the
/// velocities' in redshift space (fμ² at first order); in real space `parts[1 + i]` is [`operator_kernels`]'s
/// O_i; zero where the q's sum to zero.
///
/// # Errors
/// As [`operator_kernels`]; as [`galaxy_redshift_kernel`] for a bad line of sight or f.
pub fn galaxy_kernel_parts(q: &[Vec3], redshift: Option<(f64, &Vec3)>) -> Result<[f64; N_PARTS]> {
    if let Some((f, los)) = redshift {
        check_line_of_sight(f, los)?;
    }
    let t = Table::new(q)?;
    Ok(parts_from_table(&t, redshift))
}

/// [`galaxy_kernel_parts`] from the subsets' fields.
fn parts_from_table(t: &Table, redshift: Option<(f64, &Vec3)>) -> [f64; N_PARTS] {
    let full = (1usize << t.n) - 1;
    let mut parts = [0.0; N_PARTS];
    match redshift {
        None if t.ks2[full] != 0.0 => parts[1..].copy_from_slice(&t.ops[full]),
        None => {}
        Some((f, los)) => {
            let norm = dot(los, los).sqrt();
            let unit = los.map(|x| x / norm);
            parts = redshift_parts(t, &velocity_over_k2(&t.ks2, &t.g), f, &unit);
        }
    }
    parts
}

/// The redshift-space parts at `f` along the unit line of sight `unit`, with `h` = G_S/k_S² of the table.
fn redshift_parts(t: &Table, h: &[f64; 16], f: f64, unit: &Vec3) -> [f64; N_PARTS] {
    let full = (1usize << t.n) - 1;
    let mut parts = [0.0; N_PARTS];
    let (weights, velocity) = redshift_weights_4(&t.ks, &t.ks2, h, full, unit, f);
    parts[0] = velocity;
    for (s, w) in weights.iter().enumerate().take(full + 1) {
        if *w != 0.0 {
            for (p, o) in parts[1..].iter_mut().zip(&t.ops[s]) {
                *p += w * o;
            }
        }
    }
    parts
}

/// The real-space galaxy kernel K_n(q₁, …, q_n), n = 1..=4 (module docs); zero if the q's sum to zero.
///
/// # Errors
/// As [`operator_kernels`].
pub fn galaxy_kernel(bias: &LoopBias, q: &[Vec3]) -> Result<f64> {
    let t = Table::new(q)?;
    Ok(t.galaxy(&bias.values(), (1 << t.n) - 1))
}

/// The redshift-space galaxy kernel Z_n^g(q₁, …, q_n; f, n̂), n = 1..=4 (module docs); `los` any non-zero
/// vector along the line of sight.
///
/// # Errors
/// As [`operator_kernels`]; [`Error::InvalidParameter`] for a zero or non-finite line of sight or f.
pub fn galaxy_redshift_kernel(bias: &LoopBias, q: &[Vec3], f: f64, los: &Vec3) -> Result<f64> {
    let n2 = check_line_of_sight(f, los)?;
    let t = Table::new(q)?;
    Ok(redshift_from_table(&t, &bias.values(), f, los, n2))
}

/// |`los`|² if `los` is a finite non-zero line of sight and `f` finite.
///
/// # Errors
/// [`Error::InvalidParameter`] otherwise.
fn check_line_of_sight(f: f64, los: &Vec3) -> Result<f64> {
    let n2 = dot(los, los);
    if !(n2 > 0.0 && n2.is_finite() && f.is_finite()) {
        return Err(Error::InvalidParameter {
            name: "line of sight, f",
            value: n2,
            reason: "need a finite non-zero line of sight and a finite f",
        });
    }
    Ok(n2)
}

/// Z_n^g from the subsets' fields: the redshift-space assembly of the matter kernels
/// ([`redshift_polynomial`], Scoccimarro et al.'s set-partition sums) with the tracer's kernel in place
/// of F_S, along the unit line of sight `los`/|los| (`n2` = |los|²), evaluated at `f`.
fn redshift_from_table(t: &Table, b: &[f64; N_BIAS], f: f64, los: &Vec3, n2: f64) -> f64 {
    let norm = n2.sqrt();
    let unit = los.map(|x| x / norm);
    let full = (1usize << t.n) - 1;
    let z = redshift_polynomial(&t.ks, &t.ks2, full, &unit, |s| [t.galaxy(b, s), t.g[s]]);
    kernel_at(&z, f)
}

/// [`galaxy_kernel_parts`] in the loop integrands (`los` a unit vector): zero where it is not defined (a node
/// never is).
pub(super) fn loop_kernel_parts(redshift: Option<(f64, Vec3)>, q: &[Vec3]) -> [f64; N_PARTS] {
    let Ok(t) = Table::new(q) else {
        return [0.0; N_PARTS];
    };
    parts_from_table(&t, redshift.as_ref().map(|(f, los)| (*f, los)))
}

/// [`loop_kernel_parts`] in redshift space at each growth rate of `fs` along each UNIT line of sight of
/// `los`, the subsets' fields built once (the multipoles' orientation average; the multipole tensors'
/// nodes in f): `out[j × los.len() + o]` for `fs[j]`, `los[o]`.
pub(super) fn loop_kernel_parts_los(
    fs: &[f64],
    los: &[Vec3],
    q: &[Vec3],
    out: &mut [[f64; N_PARTS]],
) {
    match Table::new(q) {
        Ok(t) => {
            let h = velocity_over_k2(&t.ks2, &t.g);
            for (out, &f) in out.chunks_exact_mut(los.len()).zip(fs) {
                for (o, n) in out.iter_mut().zip(los) {
                    *o = redshift_parts(&t, &h, f, n);
                }
            }
        }
        Err(_) => out.iter_mut().for_each(|o| *o = [0.0; N_PARTS]),
    }
}

/// The kernel of the loop integrands: real space (`redshift` None) or Z_n^g at (f, line of sight); zero
/// where it is not defined (a node never is: the rules avoid the loops' centres).
pub(super) fn loop_kernel(bias: &[f64; N_BIAS], redshift: Option<(f64, Vec3)>, q: &[Vec3]) -> f64 {
    let Ok(t) = Table::new(q) else { return 0.0 };
    match redshift {
        None => t.galaxy(bias, (1 << t.n) - 1),
        Some((f, los)) => redshift_from_table(&t, bias, f, &los, dot(&los, &los)),
    }
}
