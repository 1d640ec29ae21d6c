//! The redshift-space kernels Z_n (n ≤ 5) in `f64`, as polynomials in the growth rate f, for the
//! integrands of [`super`]: one pass of the symmetrised recursion over the subsets of a configuration's
//! vectors gives F_S, G_S of every subset at once; Z_n of any group of those vectors, for any line of
//! sight, is then assembled from them (Scoccimarro, Couchman & Frieman 1999; the expansion of
//! [`pt_kernels::redshift`], whose exact [`pt_kernels::redshift::redshift_kernel`] is the test oracle).
//!
//! The symmetrised recursion (Goroff et al. 1986) over subsets: for a set S of m ≥ 2 vectors with
//! k_S = Σ_{i∈S} q_i, summing over the ordered splits S = A ∪ B (A, B non-empty),
//!
//! ```text
//! F_S = Σ_A [|A|!|B|!/m!] G_A [(2m+1) α(k_A, k_B) F_B + 2β(k_A, k_B) G_B] / ((2m+3)(m−1)),
//! G_S = Σ_A [|A|!|B|!/m!] G_A [3α(k_A, k_B) F_B + 2m β(k_A, k_B) G_B] / ((2m+3)(m−1)),
//! α(k₁, k₂) = k₁₂·k₁/k₁²,  β(k₁, k₂) = k₁₂² (k₁·k₂)/(2k₁²k₂²),
//! ```
//!
//! with F, G of a subset of exactly zero total momentum set to their limit, zero (they vanish like
//! k_S², faster than α and β grow), as the generated kernels do. With D(S) = F_S + fμ_S²G_S,
//! U(S) = f(n̂·k)(n̂·k_S)/k_S² G_S and E(R) = Σ over set partitions of R of Π_B |B|! U(B),
//! Z_n = (1/n!) Σ_{S₀≠∅} |S₀|! D(S₀) E(rest): every U carries one f, so E(R) is a polynomial in f
//! whose degree is its number of blocks, and Z_n one of degree n.

use crate::vec3::dot;

/// Most vectors in a configuration.
pub(crate) const MAX_VECTORS: usize = 5;
const SUBSETS: usize = 1 << MAX_VECTORS;
/// Coefficients of f⁰ … f⁵ of a kernel (f⁶ for products of two).
pub(crate) type FPoly = [f64; 7];
const FACTORIAL: [f64; 6] = [1.0, 1.0, 2.0, 6.0, 24.0, 120.0];

/// F_S, G_S of every subset S (a bitmask) of up to [`MAX_VECTORS`] vectors.
pub(crate) struct SubsetKernels {
    /// k_S.
    v: [[f64; 3]; SUBSETS],
    /// k_S².
    norm: [f64; SUBSETS],
    /// [F_S, G_S].
    fg: [[f64; 2]; SUBSETS],
}

impl SubsetKernels {
    /// The kernels of every subset of `q` (at most [`MAX_VECTORS`] vectors).
    pub fn new(q: &[[f64; 3]]) -> Self {
        debug_assert!(q.len() <= MAX_VECTORS);
        let full = (1usize << q.len()) - 1;
        let mut s = Self {
            v: [[0.0; 3]; SUBSETS],
            norm: [0.0; SUBSETS],
            fg: [[0.0; 2]; SUBSETS],
        };
        for mask in 1..=full {
            // exact sums: a subset {q, −q, …} whose vectors cancel gives exactly zero
            let low = mask.trailing_zeros() as usize;
            let rest = s.v[mask & (mask - 1)];
            let v = [
                rest[0] + q[low][0],
                rest[1] + q[low][1],
                rest[2] + q[low][2],
            ];
            s.v[mask] = v;
            s.norm[mask] = dot(&v, &v);
        }
        for mask in 1..=full {
            let m = mask.count_ones() as usize;
            if m == 1 {
                s.fg[mask] = [1.0, 1.0];
                continue;
            }
            if s.norm[mask] == 0.0 {
                continue;
            }
            let (mut f, mut g) = (0.0, 0.0);
            // proper non-empty subsets A of mask, B its complement
            let mut a = (mask - 1) & mask;
            while a != 0 {
                let b = mask ^ a;
                let (na, nb) = (s.norm[a], s.norm[b]);
                let ga = s.fg[a][1];
                if na != 0.0 && nb != 0.0 && ga != 0.0 {
                    let alpha = dot(&s.v[mask], &s.v[a]) / na;
                    let beta = s.norm[mask] * dot(&s.v[a], &s.v[b]) / (2.0 * na * nb);
                    let w = FACTORIAL[a.count_ones() as usize]
                        * FACTORIAL[b.count_ones() as usize]
                        * ga;
                    let [fb, gb] = s.fg[b];
                    f += w * ((2 * m + 1) as f64 * alpha * fb + 2.0 * beta * gb);
                    g += w * (3.0 * alpha * fb + (2 * m) as f64 * beta * gb);
                }
                a = (a - 1) & mask;
            }
            let norm = FACTORIAL[m] * ((2 * m + 3) * (m - 1)) as f64;
            s.fg[mask] = [f / norm, g / norm];
        }
        s
    }

    /// Z_n of the vectors in `args` (a bitmask, n = its size) along the unit line of sight `los`, as
    /// coefficients of f⁰ … fⁿ (the rest zero).
    pub fn redshift(&self, args: usize, los: &[f64; 3]) -> FPoly {
        redshift_polynomial(&self.v, &self.norm, args, los, |s| self.fg[s])
    }
}

/// Z_n of the vectors in `args` (a bitmask, n = its size) along the unit line of sight `los`, as
/// coefficients of f⁰ … fⁿ, from every subset S's total momentum `v[S]`, its square `norm[S]` and
/// `dg(S)` = [density kernel, G_S] (the module's D(S) = density + fμ_S²G_S; F_S for matter, a
/// tracer's kernel for galaxies): the set-partition sums E(R) of the module docs. A subset of zero
/// total momentum contributes nothing.
pub(crate) fn redshift_polynomial(
    v: &[[f64; 3]],
    norm: &[f64],
    args: usize,
    los: &[f64; 3],
    dg: impl Fn(usize) -> [f64; 2],
) -> FPoly {
    let nk = dot(los, &v[args]);
    // D(S) = d0 + f d1 and U(S) = f u of every subset of args
    let (mut d0, mut d1, mut u) = ([0.0; SUBSETS], [0.0; SUBSETS], [0.0; SUBSETS]);
    let mut sub = args;
    while sub != 0 {
        let n2 = norm[sub];
        if n2 != 0.0 {
            let ns = dot(los, &v[sub]);
            let [f, g] = dg(sub);
            d0[sub] = f;
            d1[sub] = ns * ns / n2 * g;
            u[sub] = FACTORIAL[sub.count_ones() as usize] * nk * ns / n2 * g;
        }
        sub = (sub - 1) & args;
    }
    let e = partition_sums(&u, args);
    let mut z = [0.0; 7];
    let n = args.count_ones() as usize;
    let mut s0 = args;
    while s0 != 0 {
        let c = FACTORIAL[s0.count_ones() as usize] / FACTORIAL[n];
        let (a, b) = (c * d0[s0], c * d1[s0]);
        if a != 0.0 || b != 0.0 {
            let er = &e[args ^ s0];
            for (j, e) in er.iter().enumerate() {
                z[j] += a * e;
                z[j + 1] += b * e;
            }
        }
        s0 = (s0 - 1) & args;
    }
    z
}

/// E(R) of the module docs for every subset R of `args`, as coefficients of f⁰ … f⁵, from U(S) = f `u[S]`:
/// smaller masks first, the block holding R's lowest member, then the partitions of the rest.
#[inline]
fn partition_sums(u: &[f64; SUBSETS], args: usize) -> [[f64; 6]; SUBSETS] {
    let mut e = [[0.0; 6]; SUBSETS];
    e[0][0] = 1.0;
    for r in 1..=args {
        if r & !args != 0 {
            continue;
        }
        let low = r & r.wrapping_neg();
        let rest = r ^ low;
        let mut sub = rest;
        let mut er = [0.0; 6];
        loop {
            let block = sub | low;
            let c = u[block];
            if c != 0.0 {
                let other = &e[r ^ block];
                for j in 0..5 {
                    er[j + 1] += c * other[j];
                }
            }
            if sub == 0 {
                break;
            }
            sub = (sub - 1) & rest;
        }
        e[r] = er;
    }
    e
}

/// Z_n of [`redshift_polynomial`] split by what multiplies the density kernels, at `f`: Z_n = Σ_{S₀}
/// `weights[S₀]` × density(S₀) + `velocity`, with `weights[S₀]` = (|S₀|!/n!) E(args∖S₀) (zero for S₀ of zero
/// total momentum) and `velocity` = Σ_{S₀} (|S₀|!/n!) fμ_{S₀}²G_{S₀} E(args∖S₀), from G_S = `g(S)`. Z_n is
/// linear in the density kernels: a tracer's kernel affine in its bias coefficients gives Z_n^g affine in them.
/// (The galaxy bispectrum uses its four-argument form, `bispectrum::redshift_weights`, tested against this.)
#[cfg(test)]
pub(crate) fn redshift_weights(
    v: &[[f64; 3]],
    norm: &[f64],
    args: usize,
    los: &[f64; 3],
    g: impl Fn(usize) -> f64,
    f: f64,
) -> ([f64; SUBSETS], f64) {
    let nk = dot(los, &v[args]);
    let (mut d1, mut u) = ([0.0; SUBSETS], [0.0; SUBSETS]);
    let mut sub = args;
    while sub != 0 {
        let n2 = norm[sub];
        if n2 != 0.0 {
            let ns = dot(los, &v[sub]);
            let gs = g(sub);
            d1[sub] = ns * ns / n2 * gs;
            u[sub] = FACTORIAL[sub.count_ones() as usize] * nk * ns / n2 * gs;
        }
        sub = (sub - 1) & args;
    }
    let e = partition_sums(&u, args);
    let at_f = |p: &[f64; 6]| p.iter().rev().fold(0.0, |acc, &c| acc * f + c);
    let n = args.count_ones() as usize;
    let (mut weights, mut velocity) = ([0.0; SUBSETS], 0.0);
    let mut s0 = args;
    while s0 != 0 {
        if norm[s0] != 0.0 {
            let c = FACTORIAL[s0.count_ones() as usize] / FACTORIAL[n] * at_f(&e[args ^ s0]);
            weights[s0] = c;
            velocity += c * f * d1[s0];
        }
        s0 = (s0 - 1) & args;
    }
    (weights, velocity)
}

/// The value at f of a kernel's polynomial (Horner).
pub(crate) fn at(p: &FPoly, f: f64) -> f64 {
    p.iter().rev().fold(0.0, |acc, &c| acc * f + c)
}

/// The product of two kernels' polynomials in f (degrees adding to at most 6).
#[inline]
pub(crate) fn product(a: &FPoly, b: &FPoly) -> FPoly {
    let mut p = [0.0; 7];
    for (i, &x) in a.iter().enumerate() {
        if x != 0.0 {
            for (j, &y) in b[..7 - i].iter().enumerate() {
                p[i + j] += x * y;
            }
        }
    }
    p
}

#[cfg(test)]
mod tests {
    use super::*;
    use pt_kernels::redshift::redshift_kernel;

    fn eval(p: &FPoly, f: f64) -> f64 {
        p.iter().rev().fold(0.0, |acc, c| acc * f + c)
    }

    /// Every group of vectors of a configuration, at several f and lines of sight, against the exact
    /// expansion of pt-kernels evaluated in f64.
    #[test]
    fn z_n_of_every_group_matches_the_pt_kernels_expansion() {
        let q = [
            [0.3, -0.2, 0.9],
            [-0.7, 0.4, 0.1],
            [0.2, 0.8, -0.5],
            [1.1, -0.3, 0.4],
            [-0.4, -0.6, -0.2],
        ];
        let s = SubsetKernels::new(&q);
        let norm = (0.2f64 * 0.2 + 0.5 * 0.5 + 0.7 * 0.7).sqrt();
        let los = [0.2 / norm, -0.5 / norm, 0.7 / norm];
        for args in 1..32usize {
            let members: Vec<[f64; 3]> = (0..5)
                .filter(|i| args >> i & 1 == 1)
                .map(|i| q[i])
                .collect();
            let z = s.redshift(args, &los);
            for f in [0.0, 0.55, 1.3] {
                let exact = redshift_kernel(&members, &f, &los).unwrap();
                let got = eval(&z, f);
                assert!(
                    (got - exact).abs() <= 1e-12 * (1.0 + exact.abs()),
                    "{args:b} f={f}: {got} vs {exact}"
                );
            }
        }
    }

    /// Configurations with cancelling pairs (k, q, −q, p, −p), the propagator of P15, where subsets of
    /// zero momentum must take their limit.
    #[test]
    fn cancelling_pairs_take_the_limit_of_the_generated_kernels() {
        let (k, q, p) = ([0.0, 0.0, 0.1], [0.05, 0.02, -0.03], [-0.2, 0.1, 0.15]);
        let neg = |v: [f64; 3]| v.map(|x| -x);
        let vectors = [k, q, neg(q), p, neg(p)];
        let s = SubsetKernels::new(&vectors);
        let los = [0.6, 0.0, 0.8];
        for args in [0b11111usize, 0b00111, 0b11001, 0b01001] {
            let members: Vec<[f64; 3]> = (0..5)
                .filter(|i| args >> i & 1 == 1)
                .map(|i| vectors[i])
                .collect();
            let z = s.redshift(args, &los);
            let f = 0.7;
            let exact = redshift_kernel(&members, &f, &los).unwrap();
            let got = eval(&z, f);
            assert!(
                (got - exact).abs() <= 1e-11 * (1.0 + exact.abs()),
                "{args:b}: {got} vs {exact}"
            );
        }
        // f = 0: the real-space kernel F_5 of pt-kernels
        let [f5, _] = pt_kernels::kernels(&vectors).unwrap();
        let z = s.redshift(0b11111, &los);
        assert!(
            (z[0] - f5).abs() <= 1e-12 * (1.0 + f5.abs()),
            "{} vs {f5}",
            z[0]
        );
    }

    #[test]
    fn products_of_polynomials_in_f() {
        let a = [1.0, 2.0, 0.0, 0.0, 0.0, 0.0, 0.0];
        let b = [3.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0];
        assert_eq!(product(&a, &b), [3.0, 6.0, 1.0, 2.0, 0.0, 0.0, 0.0]);
    }
}
