"""Which fourth-order operators hold Gamma3 (issue 50): a least-squares fit at random configurations.

Gamma3 = G2(Phi_g) - G2(Phi_v) equals -(4/7) G2(phi2, phi1) at third order; its fourth-order remainder
R = Gamma3_4 + (4/7) G2(phi2, phi1)_4 must be a combination of the fourth-order operators (at their lowest
order). G2(phi2, phi1) is that of make_one_loop_galaxy_mc.py: the Lagrangian operator carried by the flow with
the number density (fourth order K(q12, q3) K(q1, q2) k.q4/q4^2, k the total). This script fits R over 60
random configurations of four vectors with the symmetrised kernels of make_one_loop_galaxy_mc.py (its own
unsymmetrised kernels averaged over orderings) and prints the largest residual for three candidate sets:
  1. the local four (delta^4, delta^2 G2, G2^2, delta G3), delta G21, G211, G22 and G2(phi3, phi1) with the
     3LPT potential and its transverse part (the kernel of make_one_loop_galaxy_mc.py, also Philcox et al.'s
     OneLoopBispectrum notebook's): (1/18) K(q1, q234)[(15/7) K(q23, q4) K(q2, q3) - L(q2, q3, q4)]
     + (1/14)[M(q1, q23, q4, q234) - M(q1, q234, q23, q4)] K(q2, q3): exact, with
     R = -(4/7) G211 + (16/49) G22 + 8 G31 (the CLASS-PT / velocileptors map of this crate);
  2. the same with its two pieces (longitudinal, transverse) free;
  3. the local four, delta G21, G211, G22 and the two potentials' Galileons C1 = K(q1, q234)K(q23, q4)K(q2, q3),
     C2 = K(q1, q234) L(q2, q3, q4) free, no transverse part: not enough (residual ~2% of R).

    python3 tests/data/bispectrum/check_gamma3_span.py   (numpy, scipy; seconds)
"""

import itertools

import numpy as np

import make_one_loop_galaxy_mc as g
from make_one_loop_mc import kernels_unsym

rng = np.random.default_rng(5)
N = 60
V = [rng.normal(size=(N, 3)) for _ in range(4)]
F = g.Fields(V)


def sym(fn):
    return sum(fn(p) for p in itertools.permutations(range(4))) / 24


def vecs(p):
    return [V[i] for i in p]


def mm(a, b, c, d):
    return g._cos(a, b)[0] * g._cos(b, c)[0] * g._cos(c, d)[0] * g._cos(d, a)[0]


def gamma3(p):
    total = 0.0
    for j in range(1, 4):
        a, b = p[:j], p[j:]
        fa, ga = kernels_unsym(a, F.memo)
        fb, gb = kernels_unsym(b, F.memo)
        total = total + g.kk(F.k(a), F.k(b)) * (fa * fb - ga * gb)
    return total


def c1(p):
    q1, q2, q3, q4 = vecs(p)
    return g.kk(q1, q2 + q3 + q4) * g.kk(q2 + q3, q4) * g.kk(q2, q3)


def c2(p):
    q1, q2, q3, q4 = vecs(p)
    return g.kk(q1, q2 + q3 + q4) * g.ll(q2, q3, q4)


def m_part(p):
    q1, q2, q3, q4 = vecs(p)
    q23, q234 = q2 + q3, q2 + q3 + q4
    return (mm(q1, q23, q4, q234) - mm(q1, q234, q23, q4)) * g.kk(q2, q3) / 14


R = sym(gamma3) + 4 / 7 * sym(lambda p: F.get("g21", p))
local = [np.ones(N), sym(lambda p: g.kk(V[p[2]], V[p[3]])),
         sym(lambda p: g.kk(V[p[0]], V[p[1]]) * g.kk(V[p[2]], V[p[3]])),
         sym(lambda p: g.ll(V[p[1]], V[p[2]], V[p[3]]))]
nonlocal_ = [sym(lambda p: F.get(name, p)) for name in ("dg21", "g211", "g22")]
C1, C2, M = sym(c1), sym(c2), sym(m_part)
notebook_g31 = (15 / 7 * C1 - C2) / 18 + M


def fit(columns, label):
    A = np.stack(columns, axis=1)
    beta = np.linalg.lstsq(A, R, rcond=None)[0]
    print(f"{label}: largest residual {np.max(np.abs(A @ beta - R)):.1e} (kernel scale {np.max(np.abs(R)):.2f})")
    return beta


beta = fit(local + nonlocal_ + [notebook_g31], "1. 3LPT G31 with its transverse part")
print("   coefficients of delta G21, G211, G22, G31:", *np.round(beta[4:], 12), "(0, -4/7, 16/49, 8 =",
      0, -4 / 7, 16 / 49, 8, ")")
fit(local + nonlocal_ + [(15 / 7 * C1 - C2) / 18, M], "2. its two pieces free")
fit(local + nonlocal_ + [C1, C2], "3. C1, C2 free, no transverse part")
