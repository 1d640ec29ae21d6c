//! The sums of [`super::Blocks`] with the instructions of AVX2 and FMA (pulp's `V3`): the lane type
//! [`X`], the vectorised exponential [`exp`], a side's true-frame quantities and power, a node's slots
//! and a triangle's sums.

use super::{Blocks, Fog, IrInputs, Sampled, Settings, L, SLOTS};
use pulp::{f64x4, x86::V3};
use std::ops::{Add, Div, Mul, Range, Sub};

/// Four f64 lanes with the instructions of AVX2 and FMA.
#[derive(Clone, Copy)]
pub(super) struct X(V3, f64x4);

impl X {
    #[inline(always)]
    fn splat(simd: V3, v: f64) -> Self {
        Self(simd, simd.splat_f64x4(v))
    }
    #[inline(always)]
    pub(super) fn load(simd: V3, v: [f64; L]) -> Self {
        Self(simd, pulp::cast(v))
    }
    #[inline(always)]
    pub(super) fn lanes(self) -> [f64; L] {
        pulp::cast(self.1)
    }
    /// self × b + c, rounded once.
    #[inline(always)]
    fn mul_add(self, b: Self, c: Self) -> Self {
        Self(self.0, self.0.mul_add_f64x4(self.1, b.1, c.1))
    }
    #[inline(always)]
    fn sqrt(self) -> Self {
        Self(self.0, self.0.sqrt_f64x4(self.1))
    }
    #[inline(always)]
    fn max(self, b: f64) -> Self {
        Self(self.0, self.0.max_f64x4(self.1, self.0.splat_f64x4(b)))
    }
    #[inline(always)]
    fn min(self, b: f64) -> Self {
        Self(self.0, self.0.min_f64x4(self.1, self.0.splat_f64x4(b)))
    }
    #[inline(always)]
    fn trunc(self) -> Self {
        Self(self.0, self.0.truncate_f64x4(self.1))
    }
}

macro_rules! binary {
    ($trait:ident, $method:ident, $op:ident) => {
        impl $trait for X {
            type Output = X;
            #[inline(always)]
            fn $method(self, b: X) -> X {
                X(self.0, self.0.$op(self.1, b.1))
            }
        }
        impl $trait<f64> for X {
            type Output = X;
            #[inline(always)]
            fn $method(self, b: f64) -> X {
                X(self.0, self.0.$op(self.1, self.0.splat_f64x4(b)))
            }
        }
    };
}
binary!(Add, add, add_f64x4);
binary!(Sub, sub, sub_f64x4);
binary!(Mul, mul, mul_f64x4);
binary!(Div, div, div_f64x4);

/// 1/j!, j = 0 … 13.
const INV_FACTORIAL: [f64; 14] = {
    let mut out = [1.0; 14];
    let mut j = 1;
    while j < 14 {
        out[j] = out[j - 1] / j as f64;
        j += 1;
    }
    out
};

/// eˣ to within two units in the last place for x ∈ [−708, 709] (clamped to it): x = n ln 2 + r,
/// |r| ≤ ln 2 / 2 (Cody–Waite, ln 2 in two parts), e^r by its Taylor series to r¹³ (remainder below
/// 5e-18), times 2ⁿ made in the exponent bits.
#[inline(always)]
pub(super) fn exp(x: X) -> X {
    const SHIFT: f64 = 6_755_399_441_055_744.0; // 1.5 × 2⁵², whose last bits hold n
                                                // ln 2 = LN2_HI + LN2_LO, LN2_HI with 21 trailing zero bits (n LN2_HI exact; fdlibm's)
    const LN2_HI: f64 = f64::from_bits(0x3fe6_2e42_fee0_0000);
    const LN2_LO: f64 = f64::from_bits(0x3dea_39ef_3579_3c76);
    let simd = x.0;
    let x = x.max(-708.0).min(709.0);
    let t = x.mul_add(
        X::splat(simd, std::f64::consts::LOG2_E),
        X::splat(simd, SHIFT),
    );
    let n = t - SHIFT;
    let r = n.mul_add(X::splat(simd, -LN2_HI), x);
    let r = n.mul_add(X::splat(simd, -LN2_LO), r);
    let mut p = X::splat(simd, INV_FACTORIAL[13]);
    for j in (0..13).rev() {
        p = p.mul_add(r, X::splat(simd, INV_FACTORIAL[j]));
    }
    // 2ⁿ: (bits(t) − bits(SHIFT) + 1023) << 52
    let bits: pulp::u64x4 = pulp::cast(t.1);
    let bias = simd.splat_u64x4(1023_u64.wrapping_sub(SHIFT.to_bits()));
    let scale = simd.shl_const_u64x4::<52>(simd.wrapping_add_u64x4(bits, bias));
    p * X(simd, pulp::cast(scale))
}

/// The cubics of coefficients `o` … `o` + 3 of the lanes' `rows` at `u`.
#[inline(always)]
fn horner(simd: V3, rows: [&[f64; 8]; L], o: usize, u: X) -> X {
    // the four lanes' rows transposed: coefficient j of every lane in one vector
    let c = transpose(simd, rows.map(|r| [r[o], r[o + 1], r[o + 2], r[o + 3]]));
    c[3].mul_add(u, c[2]).mul_add(u, c[1]).mul_add(u, c[0])
}

/// The 4 × 4 transpose: lane l of vector j is `rows[l][j]`.
#[inline(always)]
fn transpose(simd: V3, rows: [[f64; L]; 4]) -> [X; 4] {
    use core::arch::x86_64::__m256d;
    let r: [__m256d; 4] = [
        pulp::cast(rows[0]),
        pulp::cast(rows[1]),
        pulp::cast(rows[2]),
        pulp::cast(rows[3]),
    ];
    let avx = simd.avx;
    let (lo01, hi01) = (
        avx._mm256_unpacklo_pd(r[0], r[1]),
        avx._mm256_unpackhi_pd(r[0], r[1]),
    );
    let (lo23, hi23) = (
        avx._mm256_unpacklo_pd(r[2], r[3]),
        avx._mm256_unpackhi_pd(r[2], r[3]),
    );
    [
        X(
            simd,
            pulp::cast(avx._mm256_permute2f128_pd::<0x20>(lo01, lo23)),
        ),
        X(
            simd,
            pulp::cast(avx._mm256_permute2f128_pd::<0x20>(hi01, hi23)),
        ),
        X(
            simd,
            pulp::cast(avx._mm256_permute2f128_pd::<0x31>(lo01, lo23)),
        ),
        X(
            simd,
            pulp::cast(avx._mm256_permute2f128_pd::<0x31>(hi01, hi23)),
        ),
    ]
}

/// The per-spectrum constants of the sums.
pub(super) struct Consts<'a> {
    table: &'a Sampled,
    f: f64,
    inv_qp: f64,
    inv_qp2: f64,
    inv_qt2: f64,
    volume: f64,
    fog: Fog,
    /// Σ², δΣ² with IR resummation.
    ir: Option<(f64, f64)>,
}

impl<'a> Consts<'a> {
    pub(super) fn new(table: &'a Sampled, s: &Settings, ir: Option<&IrInputs>) -> Self {
        let (inv_qp2, inv_qt2) = (1.0 / (s.q_par * s.q_par), 1.0 / (s.q_perp * s.q_perp));
        Self {
            table,
            f: s.f,
            inv_qp: 1.0 / s.q_par,
            inv_qp2,
            inv_qt2,
            volume: inv_qp2 * inv_qt2 * inv_qt2,
            fog: s.fog,
            ir: ir.map(|ir| (ir.sigma2, ir.delta_sigma2)),
        }
    }
}

/// One side in the true frame, four lanes.
#[derive(Clone, Copy)]
struct Side {
    /// Line-of-sight component.
    par: X,
    k: X,
    inv_k: X,
    /// μ².
    mu2: X,
    /// μ/k.
    mu_k: X,
    /// The (resummed) linear power.
    p: X,
}

/// The true line-of-sight component and squared length of the side of observed squared length
/// `k2` and line-of-sight component `par`.
#[inline(always)]
fn true_side(c: &Consts, par: X, k2: X) -> (X, X) {
    let par_true = par * c.inv_qp;
    let perp2 = (k2 - par * par).max(0.0);
    (par_true, par_true.mul_add(par_true, perp2 * c.inv_qt2))
}

/// The side of true line-of-sight component `par_true`, length `k` and inverse length `inv_k`.
#[inline(always)]
fn side(c: &Consts, par_true: X, k: X, inv_k: X) -> Side {
    let simd = k.0;
    let mu = par_true * inv_k;
    let mu2 = mu * mu;
    // the cubic of the interval (Sampled::eval): row i − 1 at u = t − i
    let t = (k - c.table.k0) * c.table.inv_h;
    let i = t.trunc().max(1.0).min(c.table.last());
    let u = t - i;
    let i: [i32; L] = pulp::cast(simd.convert_f64x4_to_i32x4(i.1));
    let rows = i.map(|i| &c.table.rows[i as usize - 1]);
    let mut p = horner(simd, rows, 0, u);
    if let Some((sigma2, delta_sigma2)) = c.ir {
        // P_nw + e^{−k²Σ²_tot(μ)}(P − P_nw), Σ²_tot as crate::ir::sigma2_total
        let p_nw = horner(simd, rows, 4, u);
        let f = c.f;
        let sigma_tot = (mu2 * (f * (2.0 + f)))
            .mul_add(X::splat(simd, sigma2), X::splat(simd, sigma2))
            + mu2 * (mu2 - 1.0) * (f * f * delta_sigma2);
        let damping = exp(X::splat(simd, 0.0) - k * k * sigma_tot);
        p = damping.mul_add(p - p_nw, p_nw);
    }
    Side {
        par: par_true,
        k,
        inv_k,
        mu2,
        mu_k: mu * inv_k,
        p,
    }
}

/// The slots that are not 0: all but those of Z₁Z₁Z₂ (β, α), α < β.
const USED: [usize; SLOTS - 12] = {
    let mut out = [0; SLOTS - 12];
    let (mut s, mut n) = (0, 0);
    while s < SLOTS {
        let (al, be) = (s / 12, s / 4 % 3);
        if s >= 36 || al <= be {
            out[n] = s;
            n += 1;
        }
        s += 1;
    }
    out
};

/// Slot of Z₁Z₁Z₂ (α, β, g).
const fn slot(al: usize, be: usize) -> usize {
    (al * 3 + be) * 4
}

/// Adds the slots of one node (four lanes) to `sums`: observed line-of-sight components `par`,
/// dot products `dots` over q⊥², true sides `t`, FoG factor `fog`.
#[inline(always)]
fn node(c: &Consts, t: [Side; 3], par: [X; 3], dots: [X; 3], fog: X, sums: &mut [X; SLOTS]) {
    let simd = par[0].0;
    let f = c.f;
    let scale = fog * c.volume;
    let ps = t.map(|s| s.p * scale);
    // a_i = (fμ², 1, −k²μ²)
    let a0 = t.map(|s| s.mu2 * f);
    let a2 = t.map(|s| X::splat(simd, 0.0) - s.par * s.par);
    // per pair (i, j): pp_i c_i[g] (g = 0, 1, 3; c_i[2] = 1/2) and the symmetrised a_i[α]a_j[β]
    let mut q = [[X::splat(simd, 0.0); 4]; 3];
    let mut w = [[X::splat(simd, 0.0); 6]; 3];
    for i in 0..3 {
        let (j, l) = ((i + 1) % 3, (i + 2) % 3);
        let (ti, tj) = (&t[i], &t[j]);
        // k_i·k_j in the true frame: n̂-parts over q∥², the rest over q⊥²
        let dot = (par[i] * par[j]).mul_add(X::splat(simd, c.inv_qp2 - c.inv_qt2), dots[i]);
        let cos = dot * ti.inv_k * tj.inv_k;
        let ratio = ti.k.mul_add(tj.inv_k, tj.k * ti.inv_k);
        let half = cos * 0.5 * ratio;
        let cc = cos * cos;
        let f2 = cc.mul_add(X::splat(simd, 2.0 / 7.0), half + 5.0 / 7.0);
        let g2 = cc.mul_add(X::splat(simd, 4.0 / 7.0), half + 3.0 / 7.0);
        let k_par = ti.par + tj.par; // n̂·(kᵢ + kⱼ) = −n̂·k_l
        let mu12_sq = k_par * k_par * t[l].inv_k * t[l].inv_k;
        let c0 = (mu12_sq * f).mul_add(
            g2,
            k_par * (0.5 * f * f) * ti.mu_k.mul_add(tj.mu2, tj.mu_k * ti.mu2),
        );
        let c1 = (k_par * (0.5 * f)).mul_add(ti.mu_k + tj.mu_k, f2);
        let pp_half = ps[i] * tj.p;
        let pp = pp_half + pp_half;
        q[i] = [pp * c0, pp * c1, pp_half, pp * (cc - 1.0 / 3.0)];
        w[i] = [
            a0[i] * a0[j],
            X::splat(simd, 1.0),
            a2[i] * a2[j],
            a0[i] + a0[j],
            a0[i].mul_add(a2[j], a2[i] * a0[j]),
            a2[i] + a2[j],
        ];
    }
    // (α, β) of each symmetrised weight
    const PAIRS: [(usize, usize); 6] = [(0, 0), (1, 1), (2, 2), (0, 1), (0, 2), (1, 2)];
    for (n, &(al, be)) in PAIRS.iter().enumerate() {
        for g in 0..4 {
            let s = &mut sums[slot(al, be) + g];
            *s = q[0][g].mul_add(
                w[0][n],
                q[1][g].mul_add(w[1][n], q[2][g].mul_add(w[2][n], *s)),
            );
        }
    }
    // 1/n̄: Σᵢ Pᵢ a_i[β] and Σᵢ Pᵢ a_i[0] a_i[β]
    let b0 = ps[0].mul_add(a0[0], ps[1].mul_add(a0[1], ps[2] * a0[2]));
    sums[36] = sums[36] + b0;
    sums[37] = sums[37] + (ps[0] + ps[1] + ps[2]);
    sums[38] = sums[38] + ps[0].mul_add(a2[0], ps[1].mul_add(a2[1], ps[2] * a2[2]));
    sums[39] = sums[39]
        + (ps[0] * a0[0]).mul_add(a0[0], (ps[1] * a0[1]).mul_add(a0[1], ps[2] * a0[2] * a0[2]));
    sums[40] = sums[40] + b0;
    sums[41] = sums[41]
        + (ps[0] * a0[0]).mul_add(a2[0], (ps[1] * a0[1]).mul_add(a2[1], ps[2] * a0[2] * a2[2]));
    sums[42] = sums[42] + c.volume;
}

/// The slots of the triangle of `blocks` in `range` (lanes summed), as a function that
/// [`V3::vectorize`] compiles with AVX2 and FMA (a closure would not be inlined into it).
pub(super) struct Triangle<'a> {
    pub(super) simd: V3,
    pub(super) blocks: &'a Blocks,
    pub(super) range: Range<usize>,
    pub(super) c: &'a Consts<'a>,
}

impl pulp::NullaryFnOnce for Triangle<'_> {
    type Output = [[f64; SLOTS]; 3];

    #[inline(always)]
    fn call(self) -> Self::Output {
        triangle(self.simd, self.blocks, self.range, self.c)
    }
}

/// The slots of the triangle of `b` in `range` (lanes summed).
#[inline(always)]
fn triangle(simd: V3, b: &Blocks, range: Range<usize>, c: &Consts) -> [[f64; SLOTS]; 3] {
    let zero = X::splat(simd, 0.0);
    let mut acc = [[zero; SLOTS]; 3];
    for n in range {
        let block = &b.blocks[n];
        let ld = |v: [f64; L]| X::load(simd, v);
        let k2 = block.k2.map(ld);
        let dots = block.dots.map(|d| ld(d) * c.inv_qt2);
        let par0 = ld(block.par0);
        let (par_true, k_sq) = true_side(c, par0, k2[0]);
        let k = k_sq.sqrt();
        let side0 = side(c, par_true, k, X::splat(simd, 1.0) / k);
        let mut sums = [zero; SLOTS];
        for par in &b.par[n * b.n_phi..(n + 1) * b.n_phi] {
            let (p1, p2) = (ld(par[0]), ld(par[1]));
            let ((t1, s1), (t2, s2)) = (true_side(c, p1, k2[1]), true_side(c, p2, k2[2]));
            let (k1, k2) = (s1.sqrt(), s2.sqrt());
            // FoG at x = Σᵢkᵢ²μᵢ²; the Lorentzian's 1/D² and the sides' 1/k in one division
            let x = side0.par.mul_add(side0.par, t1.mul_add(t1, t2 * t2));
            let d2 = match c.fog {
                Fog::Lorentzian { sigma } => {
                    let d = x.mul_add(X::splat(simd, 0.5 * sigma * sigma), X::splat(simd, 1.0));
                    d * d
                }
                _ => X::splat(simd, 1.0),
            };
            let inv = X::splat(simd, 1.0) / (k1 * k2 * d2);
            let fog = match c.fog {
                Fog::None => X::splat(simd, 1.0),
                Fog::Lorentzian { .. } => inv * k1 * k2,
                Fog::Gaussian { sigma } => exp(x * (-0.5 * sigma * sigma)),
            };
            let t = [
                side0,
                side(c, t1, k1, inv * k2 * d2),
                side(c, t2, k2, inv * k1 * d2),
            ];
            node(c, t, [par0, p1, p2], dots, fog, &mut sums);
        }
        for (acc, lambda) in acc.iter_mut().zip(block.lambda) {
            let lambda = ld(lambda);
            for s in USED {
                acc[s] = lambda.mul_add(sums[s], acc[s]);
            }
        }
    }
    acc.map(|acc| {
        let mut out = [0.0; SLOTS];
        for s in USED {
            let v = acc[s].lanes();
            out[s] = (v[0] + v[1]) + (v[2] + v[3]);
        }
        out
    })
}
