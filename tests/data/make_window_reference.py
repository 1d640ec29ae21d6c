# Makes window_boss_ellipsoid.dat and window_boss_reference.dat (see README.md and tests/tests/suite/window.rs):
# a window in the BOSS DR12 format of the CLASS-PT likelihoods, and the windowed multipoles of a Kaiser
# model through it, computed with numpy/scipy independently of pt-spectra (no FFTLog: direct quadrature).
# Run from this folder: python3 make_window_reference.py   (numpy and scipy; about two minutes)
#
# 1. The window: a uniform ellipsoid with semi-axes A, A across and C along the line of sight (z). Its
#    pair window Q(s, mu) is the overlap fraction of the ellipsoid and its translate by s, i.e. that of
#    the unit sphere at the stretched separation x = s sqrt((1 - mu^2)/A^2 + mu^2/C^2):
#    Q = 1 - 3x/4 + x^3/16 for x < 2, 0 otherwise. Q_l(s) = (2l+1)/2 int_{-1}^{1} Q(s, mu) L_l(mu) dmu by
#    Gauss-Legendre quadrature split at the mu where x = 2. Written as BOSS files are: columns Q0 Q2 Q4,
#    no s column, 128 rows on s_i = 0.01 (1e5)^(i/127) Mpc/h, Q0(0) = 1. The ellipsoid reaches s = 2A =
#    1400 Mpc/h, beyond the file's last s (1000): there the file's convention (Q = 0) cuts it.
# 2. The model: Kaiser multipoles of (1 + beta mu^2)^2 P(k) with P = P_lin(k) exp(-(k/KD)^2), P_lin the
#    embedded gm2012 z = 0 table (not-a-knot cubic spline of ln P against ln k, as pt-spectra does).
# 3. xi_l(s) = i^l int_0^KMAX k^2 dk/(2 pi^2) P_l(k) j_l(ks): Simpson on a uniform k grid, on NS
#    log-spaced s in [0.01, 1000] Mpc/h, a cubic spline in ln s between them (xi(0.01) below).
# 4. The convention of the file: Q_l(s) a not-a-knot cubic spline in ln s of the 128 values, Q(s_0)
#    below s_0 = 0.01, 0 beyond 1000 Mpc/h. Mixing: xi^_l = sum (2l+1) (l l' l''; 0 0 0)^2 xi_l' Q_l''
#    (3j symbols from exact fractions), Wilson (all l' <= 4, l'' <= 4) and CLASS-PT (no xi_4 in
#    xi^_0, xi^_2; xi^_4 as Wilson's).
# 5. P^_l(k) = 4 pi (-i)^l int_0^1000 s^2 ds xi^_l(s) j_l(ks): Simpson on a uniform s grid.
# Convergence (halving the k step, the s step and the xi node spacing) is written to the header.
import platform
import sys
from fractions import Fraction
from math import factorial

import numpy as np
import scipy
from scipy.interpolate import CubicSpline
from scipy.special import roots_legendre, spherical_jn

A, C = 700.0, 450.0  # Mpc/h
BETA, KD = 0.5, 1.0
KMAX, DK = 6.0, 1e-4
NS = 1251  # xi nodes, 250 per decade
DS = 0.01
K_OUT = 0.0025 + 0.005 * np.arange(60)
PLIN = "../../pt-spectra/data/linear_pk_gm2012_z0.0.dat"


def q_sphere(x):
    return np.where(x < 2.0, 1.0 - 0.75 * x + x**3 / 16.0, 0.0)


def legendre(l, mu):
    return {0: np.ones_like(mu), 2: 0.5 * (3 * mu**2 - 1), 4: (35 * mu**4 - 30 * mu**2 + 3) / 8}[l]


def window_multipoles(s):
    """Q0, Q2, Q4 of the ellipsoid at s (Gauss-Legendre in mu on [0, 1], split where x = 2)."""
    nodes, weights = roots_legendre(96)
    out = np.zeros((3, len(s)))
    a2, c2 = 1 / A**2, 1 / C**2
    for i, si in enumerate(s):
        # x(mu) increases with mu (C < A): x = 2 at mu_star.
        m2 = (4 / si**2 - a2) / (c2 - a2)
        top = 1.0 if m2 >= 1 else (np.sqrt(m2) if m2 > 0 else 0.0)
        if top == 0.0:
            continue
        mu = 0.5 * top * (nodes + 1)
        w = 0.5 * top * weights
        x = si * np.sqrt((1 - mu**2) * a2 + mu**2 * c2)
        for j, l in enumerate((0, 2, 4)):
            out[j, i] = (2 * l + 1) * np.sum(w * q_sphere(x) * legendre(l, mu))
    return out


def three_j_squared(l1, l2, l3):
    if (l1 + l2 + l3) % 2 or l3 > l1 + l2 or l1 > l2 + l3 or l2 > l1 + l3:
        return Fraction(0)
    g = (l1 + l2 + l3) // 2
    root = Fraction(factorial(g), factorial(g - l1) * factorial(g - l2) * factorial(g - l3))
    return Fraction(factorial(2 * g - 2 * l1) * factorial(2 * g - 2 * l2) * factorial(2 * g - 2 * l3),
                    factorial(2 * g + 1)) * root**2


def mixing(l, lp, lq):
    return (2 * l + 1) * three_j_squared(l, lp, lq)


# Wilson et al. (2017) to l = 4, as printed: a check of the 3j symbols.
PRINTED = {(0, 0, 0): 1, (0, 2, 2): Fraction(1, 5), (0, 4, 4): Fraction(1, 9), (2, 0, 2): 1, (2, 2, 0): 1,
           (2, 2, 2): Fraction(2, 7), (2, 2, 4): Fraction(2, 7), (2, 4, 2): Fraction(2, 7),
           (2, 4, 4): Fraction(100, 693), (4, 0, 4): 1, (4, 2, 2): Fraction(18, 35),
           (4, 2, 4): Fraction(20, 77), (4, 4, 0): 1, (4, 4, 2): Fraction(20, 77),
           (4, 4, 4): Fraction(162, 1001)}
for l in (0, 2, 4):
    for lp in (0, 2, 4):
        for lq in (0, 2, 4):
            assert mixing(l, lp, lq) == PRINTED.get((l, lp, lq), 0), (l, lp, lq)


def p_lin():
    k, p = np.loadtxt(PLIN, unpack=True)
    spline = CubicSpline(np.log(k), np.log(p), bc_type="not-a-knot")
    return lambda q: np.exp(spline(np.log(np.clip(q, k[0], k[-1])))) * np.where(q < k[0], q / k[0], 1.0)


def kaiser():
    return [1 + 2 * BETA / 3 + BETA**2 / 5, 4 * BETA / 3 + 4 * BETA**2 / 7, 8 * BETA**2 / 35]


def simpson_weights(n, h):
    w = np.full(n, 2.0)
    w[1::2] = 4.0
    w[0] = w[-1] = 1.0
    return w * h / 3


def xi_multipoles(s, dk):
    plin = p_lin()
    k = np.arange(0.0, KMAX + dk / 2, dk)
    if len(k) % 2 == 0:
        k = k[:-1]
    pk = np.zeros_like(k)
    pk[1:] = plin(k[1:]) * np.exp(-((k[1:] / KD) ** 2))
    wk = simpson_weights(len(k), dk) * k**2 * pk / (2 * np.pi**2)
    out = np.zeros((3, len(s)))
    for j, l in enumerate((0, 2, 4)):
        sign = (-1) ** (l // 2)
        for i0 in range(0, len(s), 50):
            block = s[i0:i0 + 50]
            out[j, i0:i0 + 50] = sign * kaiser()[j] * (spherical_jn(l, np.outer(block, k)) @ wk)
    return out


def windowed(xi_nodes, s_nodes, q_file, s_file, ds):
    """P^_l at K_OUT for both mixings, from xi on s_nodes and the file's Q on s_file."""
    s = np.arange(0.0, 1000.0 + ds / 2, ds)
    if len(s) % 2 == 0:
        s = s[:-1]
    ws = simpson_weights(len(s), ds)
    ln_s = np.log(np.clip(s, s_nodes[0], None))
    xi = [CubicSpline(np.log(s_nodes), x, bc_type="not-a-knot")(ln_s) for x in xi_nodes]
    ln_q = np.log(np.clip(s, s_file[0], None))
    q = [np.where(s <= s_file[-1], CubicSpline(np.log(s_file), c, bc_type="not-a-knot")(ln_q), 0.0)
         for c in q_file]
    ells = (0, 2, 4)
    results = {}
    for name in ("wilson", "classpt"):
        hat = []
        for l in ells:
            total = np.zeros_like(s)
            for jp, lp in enumerate(ells):
                if name == "classpt" and l <= 2 and lp > 2:
                    continue
                for jq, lq in enumerate(ells):
                    c = mixing(l, lp, lq)
                    if c:
                        total += float(c) * xi[jp] * q[jq]
            hat.append(total)
        p = np.zeros((3, len(K_OUT)))
        for j, l in enumerate(ells):
            sign = (-1) ** (l // 2)
            for i, k in enumerate(K_OUT):
                p[j, i] = sign * 4 * np.pi * np.sum(ws * s**2 * hat[j] * spherical_jn(l, k * s))
        results[name] = p
    return results


def main():
    s_file = 0.01 * 1e5 ** (np.arange(128) / 127)
    q_file = window_multipoles(s_file)
    s_nodes = 0.01 * 1e5 ** (np.arange(NS) / (NS - 1))
    xi = xi_multipoles(s_nodes, DK)
    res = windowed(xi, s_nodes, q_file, s_file, DS)
    # Convergence: k step halved, s step halved, xi nodes doubled (every other new node computed).
    xi_dk = xi_multipoles(s_nodes, DK / 2)
    res_dk = windowed(xi_dk, s_nodes, q_file, s_file, DS)
    res_ds = windowed(xi, s_nodes, q_file, s_file, DS / 2)
    s_fine = 0.01 * 1e5 ** (np.arange(2 * NS - 1) / (2 * NS - 2))
    xi_fine = np.zeros((3, len(s_fine)))
    xi_fine[:, ::2] = xi
    xi_fine[:, 1::2] = xi_multipoles(s_fine[1::2], DK)
    res_ns = windowed(xi_fine, s_fine, q_file, s_file, DS)
    p0 = res["wilson"][0]
    conv = {name: max(np.max(np.abs(other[m] - res[m]) / np.abs(p0)) for m in res)
            for name, other in (("k step / 2", res_dk), ("s step / 2", res_ds), ("xi nodes x 2", res_ns))}
    versions = f"python {platform.python_version()}, numpy {np.__version__}, scipy {scipy.__version__}"

    with open("window_boss_ellipsoid.dat", "w") as f:
        f.write("# A window in the BOSS DR12 format of the CLASS-PT likelihoods (made by make_window_reference.py):\n")
        f.write(f"# a uniform ellipsoid, semi-axes {A:g}, {A:g} Mpc/h across and {C:g} Mpc/h along the line of sight;\n")
        f.write("# columns: Q0, Q2, Q4 (no s column) on s_i = 0.01 (1e5)^(i/127) Mpc/h, i = 0..127, Q0(0) = 1\n")
        for row in q_file.T:
            f.write(" ".join(f"{v:.16e}" for v in row) + "\n")

    pk = p_lin()(K_OUT) * np.exp(-((K_OUT / KD) ** 2))
    with open("window_boss_reference.dat", "w") as f:
        f.write("# Windowed Kaiser multipoles through window_boss_ellipsoid.dat, by make_window_reference.py\n")
        f.write(f"# ({versions}): direct quadrature, no FFTLog (see the script's header).\n")
        f.write(f"# model: P_l = c_l(beta) P_lin(k) exp(-(k/{KD:g})^2), beta = {BETA:g}, P_lin the gm2012 z = 0 table\n")
        f.write("#   c_0 = 1 + 2 beta/3 + beta^2/5, c_2 = 4 beta/3 + 4 beta^2/7, c_4 = 8 beta^2/35\n")
        f.write(f"# quadrature: k in [0, {KMAX:g}] step {DK:g}; xi on {NS} log s in [0.01, 1000]; s in [0, 1000] step {DS:g}\n")
        f.write("# convergence, max |change| / P0_wilson: " + ", ".join(f"{n} {v:.1e}" for n, v in conv.items()) + "\n")
        f.write("# columns: k [h/Mpc], P0 P2 P4 windowed with Wilson et al.'s mixing (xi_0,2,4 x Q_0,2,4),\n")
        f.write("#   P0 P2 P4 windowed with the CLASS-PT mixing (no xi_4 in P0, P2), P0 P2 P4 of the model [(Mpc/h)^3]\n")
        for i, k in enumerate(K_OUT):
            cols = [k, *res["wilson"][:, i], *res["classpt"][:, i], *(c * pk[i] for c in kaiser())]
            f.write(" ".join(f"{v:.12e}" for v in cols) + "\n")
    print("convergence:", conv, file=sys.stderr)


if __name__ == "__main__":
    main()
