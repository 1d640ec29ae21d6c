"""Which fourth-order bias basis is complete: the φ₃ convention of G₂(φ₃, φ₁) and the fourth-order content of
G₂(φ₂, φ₁) (issue 50 follow-up). Own EdS recursion and operator kernels (symmetrised by averaging over all
orderings of the arguments, every product on consecutive blocks), 80 random configurations.

Two conventions for the pair (G₂(φ₂, φ₁) at fourth order, G₂(φ₃, φ₁)):
  E (Eulerian): G₂(φ₂, φ₁) of the nonlinear Eulerian fields (∇²φ₁ = δ, ∇²φ₂ = G₂(φ₁) with δ = Σ F_n), as
    in Philcox et al.'s OneLoopBispectrum `Kernels.nb`; ∇²φ₃ = G₃(φ₁) − (24/7) G₂(φ₂, φ₁) (the one G₃₁ that
    holds Γ₃ in E).
  L (Lagrangian potentials; pt_spectra::bispectrum::bias_kernels, make_one_loop_galaxy_mc.py): G₂(φ₂, φ₁)
    built from the linear (Lagrangian) potentials and carried to x by the flow with the number density,
    FT = ∫d³q e^{−ik·(q+Ψ)} O(q) (fourth order: its kernel times k·q₄/q₄²);
    φ₃ the 3LPT potential, the `Kernels.nb` G₃₁ kernel (1/18)K(q₁, q₂₃₄)[(15/7)K(q₂₃, q₄)K(q₂, q₃) −
    L(q₂, q₃, q₄)] + (1/14)[M(q₁, q₂₃, q₄, q₂₃₄) − M(q₁, q₂₃₄, q₂₃, q₄)]K(q₂, q₃) (with the transverse part).

Checks printed:
  1. 1LPT+2LPT+3LPT with k·L₃ = (1/18)[(15/7)KK − L] (1/n!-free kernels) reproduce SPT F₃: the `Kernels.nb`
     bracket is the 3LPT longitudinal displacement potential, normalisation included.
  2. Lagrangian local bias b₁ᴸ to third order in the basis: g2 = −(2/7)b₁ᴸ, g21 = −(22/147)b₁ᴸ
     (= −(4/7)(b_G2 + b_Γ3) at b_G2 = −(2/7)b₁ᴸ, b_Γ3 = (23/42)b₁ᴸ).
  3. Fourth-order remainders, after the lower orders are fitted, of three generated Galilean-invariant fields:
     Γ₃ = G₂(Φ_g) − G₂(Φ_v), Γ₃' = G₂(Φ_g, Φ_v) − G₂(Φ_v) and δ − θ, against the eight fourth-order operators
     (δ⁴, δ²G₂, G₂², δG₃, δG₂₁, G₂₁₁, G₂₂, G₃₁) of each convention. L holds all three exactly; E holds Γ₃ and
     Γ₃' but not δ − θ (largest residual 1.2% of the remainder): E's span is not the generated one.
  4. In E, with C1 = K(q₁, q₂₃₄)K(q₂₃, q₄)K(q₂, q₃), C2 = K(q₁, q₂₃₄)L(q₂, q₃, q₄) and M free: Γ₃ needs
     C2 − (24/7)C1 and no M, δ − θ needs C1/C2 = −41/14 and M ≠ 0, so no single G₃₁ completes E.

    python3 tests/data/bispectrum/check_bias_basis_conventions.py   (numpy; a second)
"""

import itertools
from fractions import Fraction

import numpy as np

rng = np.random.default_rng(11)
N = 80
Q = [rng.normal(size=(N, 3)) for _ in range(4)]


def dot(a, b):
    return np.sum(a * b, axis=1)


def kk(a, b):
    return dot(a, b) ** 2 / (dot(a, a) * dot(b, b)) - 1


def ll(a, b, c):
    A, B, C = dot(a, a), dot(b, b), dot(c, c)
    ab, bc, ca = dot(a, b), dot(b, c), dot(c, a)
    return 1 - ab**2 / (A * B) - bc**2 / (B * C) - ca**2 / (C * A) + 2 * ab * bc * ca / (A * B * C)


def cos(a, b):
    return dot(a, b) / np.sqrt(dot(a, a) * dot(b, b))


MEMO = {}


def fg(vs):
    """Unsymmetrised EdS F_n, G_n on the arguments `vs` (indices)."""
    key = tuple(vs)
    if key not in MEMO:
        n = len(vs)
        if n == 1:
            MEMO[key] = (np.ones(N), np.ones(N))
        else:
            F, G = np.zeros(N), np.zeros(N)
            for m in range(1, n):
                k1, k2 = ks(vs[:m]), ks(vs[m:])
                k = k1 + k2
                al = 1 + dot(k1, k2) / dot(k1, k1)
                be = dot(k, k) * dot(k1, k2) / (2 * dot(k1, k1) * dot(k2, k2))
                Fa, Ga = fg(vs[:m])
                Fb, Gb = fg(vs[m:])
                F = F + Ga * ((2 * n + 1) * al * Fb + 2 * be * Gb) / ((2 * n + 3) * (n - 1))
                G = G + Ga * (3 * al * Fb + 2 * n * be * Gb) / ((2 * n + 3) * (n - 1))
            MEMO[key] = (F, G)
    return MEMO[key]


def ks(vs):
    return sum(Q[i] for i in vs)


def sym(fn, n=4):
    perms = list(itertools.permutations(range(n)))
    return sum(fn(p) for p in perms) / len(perms)


def cuts(vs):
    for j in range(1, len(vs)):
        yield vs[:j], vs[j:]


def triples(vs):
    for i in range(1, len(vs)):
        for j in range(i + 1, len(vs)):
            yield vs[:i], vs[i:j], vs[j:]


def p2(vs):  # ∇²φ₂ = G₂(φ₁), nonlinear
    return sum(kk(ks(a), ks(b)) * fg(a)[0] * fg(b)[0] for a, b in cuts(vs))


def g21_e(vs):  # G₂(φ₂, φ₁), nonlinear Eulerian fields
    return sum(kk(ks(a), ks(b)) * p2(a) * fg(b)[0] for a, b in cuts(vs) if len(a) >= 2)


def g21_l(p):  # fourth order of the Lagrangian G₂(φ₂, φ₁) carried by the flow with the number density
    q = [Q[i] for i in p]
    return kk(q[0], q[1] + q[2]) * kk(q[1], q[2]) * dot(ks(p), q[3]) / dot(q[3], q[3])


def dd(p):
    return 0.5 * sum(fg(a)[0] * fg(b)[0] for a, b in cuts(p))


def g2v(p):
    return sum(kk(ks(a), ks(b)) * fg(a)[1] * fg(b)[1] for a, b in cuts(p))


def ddd(p):
    return sum(fg(a)[0] * fg(b)[0] * fg(c)[0] for a, b, c in triples(p)) / 6


def dg2v(p):
    return sum(fg(a)[0] * g2v(b) for a, b in cuts(p) if len(b) >= 2)


def g3v(p):
    return sum(ll(ks(a), ks(b), ks(c)) * fg(a)[1] * fg(b)[1] * fg(c)[1] for a, b, c in triples(p))


def rat(x):
    return str(Fraction(float(x)).limit_denominator(100000))


# 1. 3LPT
def kl1(k, p):
    return dot(k, p) / dot(p, p)


def lpt3(p):
    a, b, c = [Q[i] for i in p]
    k = a + b + c
    kl3 = (15 / 7 * kk(a, b) * kk(a + b, c) - ll(a, b, c)) / 18
    kl2 = -3 / 14 * kk(b, c) * kl1(k, b + c)
    return kl3 + kl1(k, a) * kl2 + kl1(k, a) * kl1(k, b) * kl1(k, c) / 6


F3 = sym(lambda p: fg(p)[0], 3)
print(f"1. F3 from 3LPT with k.L3 = (1/18)[(15/7)KK - L]: largest difference {np.max(np.abs(sym(lpt3, 3) - F3)):.1e}"
      f" (F3 up to {np.max(np.abs(F3)):.1f})")


# 2. Lagrangian local bias to third order
def lagr_local(p):  # the b1L δ_L(q) part of ∫d³q e^{-ik·(q+Ψ)}(1 + b1L δ_L(q)), b1L = 1
    q = [Q[i] for i in p]
    k = sum(q)
    if len(p) == 2:
        return kl1(k, q[1])
    return -3 / 14 * kk(q[1], q[2]) * kl1(k, q[1] + q[2]) + kl1(k, q[1]) * kl1(k, q[2]) / 2


def lower(n, g21_4=None):
    cols = [sym(dd, n), sym(g2v, n)]
    if n >= 3:
        cols += [sym(ddd, n), sym(dg2v, n), sym(g3v, n), sym(g21_e, n) if n == 3 else g21_4]
    return np.stack(cols, 1)


def lstsq(A, y):
    c = np.linalg.lstsq(A, y, rcond=None)[0]
    return c, np.max(np.abs(A @ c - y))


def lower_fit(field):
    """b2, g2 at second order, b3, g2x, g3, g21 at third (b1 = 1 + b1L or 0 as the field's first order)."""
    f1 = field(1)
    c2, r2 = lstsq(lower(2), field(2) - f1 * sym(lambda p: fg(p)[0], 2))
    A3 = lower(3)
    y3 = field(3) - f1 * F3 - A3[:, :2] @ c2
    c3, r3 = lstsq(A3[:, 2:], y3)
    return f1, np.concatenate([c2, c3]), max(r2, r3)


def llb(n):
    if n == 1:
        return 2.0  # b1 = 1 + b1L
    return sym(lambda p: fg(p)[0], n) + sym(lagr_local, n)


_, c, r = lower_fit(llb)
print(f"2. Lagrangian local bias b1L = 1: g2 = {rat(c[1])}, g21 = {rat(c[5])} (residual {r:.1e}); "
      f"-4/7 (b_G2 + b_Gamma3) at b_G2 = -2/7, b_Gamma3 = 23/42: {rat(-4 / 7 * (-2 / 7 + 23 / 42))}")

# 3. fourth-order remainders in the two conventions
P = lambda p: [Q[i] for i in p]  # noqa: E731
local = [np.ones(N), sym(lambda p: kk(*P(p[2:]))), sym(lambda p: kk(*P(p[:2])) * kk(*P(p[2:]))),
         sym(lambda p: ll(*P(p[1:])))]
dg21 = sym(lambda p: kk(Q[p[1]], Q[p[2]] + Q[p[3]]) * kk(Q[p[2]], Q[p[3]]))
g211 = sym(lambda p: ll(Q[p[0]], Q[p[1]], Q[p[2]] + Q[p[3]]) * kk(Q[p[2]], Q[p[3]]))
g22 = sym(lambda p: kk(Q[p[0]] + Q[p[1]], Q[p[2]] + Q[p[3]]) * kk(Q[p[0]], Q[p[1]]) * kk(Q[p[2]], Q[p[3]]))
C1 = sym(lambda p: kk(Q[p[0]], ks(p[1:])) * kk(Q[p[1]] + Q[p[2]], Q[p[3]]) * kk(Q[p[1]], Q[p[2]]))
C2 = sym(lambda p: kk(Q[p[0]], ks(p[1:])) * ll(*P(p[1:])))


def m_part(p):
    q1, q2, q3, q4 = P(p)
    q23, q234 = q2 + q3, q2 + q3 + q4
    m = lambda a, b, c, d: cos(a, b) * cos(b, c) * cos(c, d) * cos(d, a)  # noqa: E731
    return (m(q1, q23, q4, q234) - m(q1, q234, q23, q4)) * kk(q2, q3) / 14


G31 = {"E": C2 - 24 / 7 * C1, "L": (15 / 7 * C1 - C2) / 18 + sym(m_part)}
G21_4 = {"E": sym(g21_e), "L": sym(g21_l)}


def pair_field(w):  # Σ_cuts K (F_A F_B, F_A G_B sym, G_A G_B) weights w: G₂(Φ_g)-type combinations
    def f(n):
        if n == 1:
            return 0.0
        return sym(lambda p: sum(kk(ks(a), ks(b)) * (w[0] * fg(a)[0] * fg(b)[0]
                                                     + w[1] * 0.5 * (fg(a)[0] * fg(b)[1] + fg(a)[1] * fg(b)[0])
                                                     + w[2] * fg(a)[1] * fg(b)[1]) for a, b in cuts(p)), n)
    return f


fields = {
    "Gamma3 = G2(Phi_g) - G2(Phi_v)": pair_field((1, 0, -1)),
    "G2(Phi_g, Phi_v) - G2(Phi_v)": pair_field((0, 1, -1)),
    "delta - theta": lambda n: 0.0 if n == 1 else sym(lambda p: fg(p)[0] - fg(p)[1], n),
}
names = ["delta^4", "delta^2 G2", "G2^2", "delta G3", "delta G21", "G211", "G22", "G31"]
print("3. fourth-order remainders (lower orders fitted) against the eight fourth-order operators:")
for label, field in fields.items():
    f1, c, r = lower_fit(field)
    F4 = sym(lambda p: fg(p)[0])
    for conv in ("E", "L"):
        A4 = lower(4, G21_4[conv])
        rem = field(4) - f1 * F4 - A4 @ c
        coef, res = lstsq(np.stack(local + [dg21, g211, g22, G31[conv]], 1), rem)
        nz = ", ".join(f"{nm} {rat(x)}" for nm, x in zip(names, coef) if abs(x) > 1e-10)
        print(f"   {label:32s} {conv}: residual {res:.1e} of {np.max(np.abs(rem)):.1e}"
              + (f"  [{nz}]" if res < 1e-12 else ""))
print("4. convention E with the three Galileons C1 = K(q1, q234)K(q23, q4)K(q2, q3), C2 = K(q1, q234)L(q2, q3, q4)"
      " and the transverse M part free (in place of G31):")
Mp = sym(m_part)
for label, field in fields.items():
    f1, c, r = lower_fit(field)
    rem = field(4) - f1 * sym(lambda p: fg(p)[0]) - lower(4, G21_4["E"]) @ c
    coef, res = lstsq(np.stack(local + [dg21, g211, g22, C1, C2, Mp], 1), rem)
    print(f"   {label:32s} residual {res:.1e}; C1, C2, M = {', '.join(rat(x) for x in coef[-3:])}"
          f"  (C1/C2 = {coef[-3] / coef[-2]:.6f})")
print("   Gamma3 and delta - theta need different (C1, C2, M) directions: E needs a ninth fourth-order operator.")
