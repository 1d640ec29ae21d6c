"""An independent plain Monte Carlo of the one-loop matter bispectrum terms (issue 50, part 1).

Writes one_loop_mc_gm2012_z0.txt: for each triangle the tree level and B222, B321-I, B321-II, B411
[(Mpc/h)^6] with their Monte Carlo standard errors, for the embedded CAMB spectrum
pt-spectra/data/linear_pk_gm2012_z0.0.dat at z = 0, loop momenta 1e-4 <= |q| <= 10 h/Mpc.

Independent of the Rust code: the kernels F_n come from the SPT recursion (Goroff et al. 1986; Jain &
Bertschinger 1994) written here in numpy and symmetrised over all permutations of their arguments (the
Rust code uses the exact generated kernels of pt_kernels); the integrals are plain Monte Carlo over q
with ln|q| uniform and the direction uniform, with no partition of unity and no symmetry used (the Rust
code: Gauss rules about each cusp). P(k) is a cubic spline in (ln k, ln P) of the same table.

Definitions, int_q = int d^3q/(2 pi)^3 (as pt_spectra::bispectrum::one_loop):
  B222    = 8 int_q F2(-q, q+k1) F2(-q-k1, q-k2) F2(k2-q, q) P(q) P(|q+k1|) P(|k2-q|)
  B321-I  = sum over ordered pairs a != b of 6 P(k_a) int_q F3(-q, q-k_b, -k_a) F2(q, k_b-q) P(q) P(|k_b-q|)
  B321-II = sum over ordered pairs a != b of 6 F2(k_a, k_b) P(k_a) P(k_b) int_q F3(k_a, q, -q) P(q)
  B411    = sum over a of 12 P(k_b) P(k_c) int_q F4(q, -q, -k_b, -k_c) P(q)   (b, c the other sides)

    python3 tests/data/bispectrum/make_one_loop_mc.py [--samples N]   (needs numpy, scipy; ~30 min on one core)
"""

import argparse
import itertools
from pathlib import Path

import numpy as np
from scipy.interpolate import CubicSpline

HERE = Path(__file__).resolve().parent
TABLE = HERE.parents[2] / "pt-spectra" / "data" / "linear_pk_gm2012_z0.0.dat"
Q_MIN, Q_MAX = 1e-4, 10.0
TRIANGLES = [
    (0.05, 0.05, 0.05), (0.1, 0.1, 0.1), (0.15, 0.15, 0.15), (0.2, 0.2, 0.2),
    (0.01, 0.1, 0.1), (0.02, 0.1, 0.1), (0.02, 0.15, 0.15), (0.03, 0.2, 0.2),
    (0.05, 0.05, 0.0999), (0.1, 0.1, 0.199), (0.06, 0.08, 0.139),
    (0.05, 0.1, 0.12), (0.02, 0.15, 0.16), (0.08, 0.1, 0.15), (0.04, 0.07, 0.09),
    (0.1, 0.12, 0.18), (0.12, 0.15, 0.2), (0.05, 0.15, 0.18), (0.07, 0.07, 0.05),
    (0.15, 0.2, 0.25), (0.03, 0.05, 0.06), (0.09, 0.11, 0.13),
]

data = np.loadtxt(TABLE)
_spline = CubicSpline(np.log(data[:, 0]), np.log(data[:, 1]))


def power(k):
    k = np.asarray(k, dtype=float)
    out = np.zeros_like(k)
    ok = k > 0
    out[ok] = np.exp(_spline(np.log(k[ok])))
    return out


def dot(a, b):
    return np.sum(a * b, axis=-1)


def kernels_unsym(vs, memo):
    """(F_n, G_n) of the ordered vectors vs (a tuple of ids into memo['v']), unsymmetrised."""
    if vs in memo:
        return memo[vs]
    n = len(vs)
    v = memo["v"]
    if n == 1:
        one = np.ones(v[vs[0]].shape[0])
        memo[vs] = (one, one)
        return memo[vs]
    f = 0.0
    g = 0.0
    for m in range(1, n):
        k1 = sum(v[i] for i in vs[:m])
        k2 = sum(v[i] for i in vs[m:])
        k1sq, k2sq = dot(k1, k1), dot(k2, k2)
        ksum = k1 + k2
        good = (k1sq > 0) & (k2sq > 0)  # a zero partial sum: the kernels vanish there (limit)
        s1 = np.where(good, k1sq, 1.0)
        s2 = np.where(good, k2sq, 1.0)
        alpha = np.where(good, dot(ksum, k1) / s1, 0.0)
        beta = np.where(good, dot(ksum, ksum) * dot(k1, k2) / (2 * s1 * s2), 0.0)
        fl, gl = kernels_unsym(vs[:m], memo)
        fr, gr = kernels_unsym(vs[m:], memo)
        norm = (2 * n + 3) * (n - 1)
        f = f + gl / norm * ((2 * n + 1) * alpha * fr + 2 * beta * gr)
        g = g + gl / norm * (3 * alpha * fr + 2 * n * beta * gr)
    memo[vs] = (f, g)
    return memo[vs]


def f_sym(*vectors):
    """The symmetrised F_n of the (N, 3) arrays."""
    n = len(vectors)
    memo = {"v": list(vectors)}
    total = 0.0
    perms = list(itertools.permutations(range(n)))
    for p in perms:
        total = total + kernels_unsym(tuple(p), memo)[0]
    return total / len(perms)


def triangle(k1, k2, k3):
    c = (k3 ** 2 - k1 ** 2 - k2 ** 2) / (2 * k1 * k2)
    s = np.sqrt(max(0.0, 1 - c * c))
    v1 = np.array([0.0, 0.0, k1])
    v2 = np.array([k2 * s, 0.0, k2 * c])
    return [v1, v2, -(v1 + v2)]


def samples(rng, n):
    lnq = rng.uniform(np.log(Q_MIN), np.log(Q_MAX), n)
    q = np.exp(lnq)
    mu = rng.uniform(-1, 1, n)
    phi = rng.uniform(0, 2 * np.pi, n)
    s = np.sqrt(1 - mu * mu)
    vec = np.stack([q * s * np.cos(phi), q * s * np.sin(phi), q * mu], axis=1)
    # 1/pdf = 4 pi q^3 ln(q_max/q_min); d^3q/(2 pi)^3
    weight = 4 * np.pi * q ** 3 * np.log(Q_MAX / Q_MIN) / (2 * np.pi) ** 3
    return vec, q, weight


def terms(ks, rng, n_total, chunk):
    kv = triangle(*ks)
    pk = power(np.array(ks))
    tile = lambda v, n: np.broadcast_to(v, (n, 3))
    sums = np.zeros((4, 2))
    done = 0
    while done < n_total:
        n = min(chunk, n_total - done)
        q, qn, w = samples(rng, n)
        pq = power(qn)
        k1, k2 = tile(kv[0], n), tile(kv[1], n)
        # B222
        a, b = q + k1, k2 - q
        b222 = 8 * f_sym(-q, a) * f_sym(-a, -b) * f_sym(b, q) * pq * power(np.linalg.norm(a, axis=1)) \
            * power(np.linalg.norm(b, axis=1))
        # B321-I and B321-II
        b321i = 0.0
        b321ii = 0.0
        f3loop = [f_sym(tile(kv[a_], n), q, -q) * pq for a_ in range(3)]
        for a_ in range(3):
            for b_ in range(3):
                if a_ == b_:
                    continue
                d = tile(kv[b_], n) - q
                b321i = b321i + 6 * pk[a_] * f_sym(-q, -d, -tile(kv[a_], n)) * f_sym(q, d) * pq \
                    * power(np.linalg.norm(d, axis=1))
                f2ab = f_sym(kv[a_][None, :], kv[b_][None, :])[0]
                b321ii = b321ii + 6 * f2ab * pk[a_] * pk[b_] * f3loop[a_]
        # B411
        b411 = 0.0
        for a_ in range(3):
            b_, c_ = (a_ + 1) % 3, (a_ + 2) % 3
            b411 = b411 + 12 * pk[b_] * pk[c_] * f_sym(q, -q, -tile(kv[b_], n), -tile(kv[c_], n)) * pq
        for i, x in enumerate([b222, b321i, b321ii, b411]):
            x = x * w
            sums[i, 0] += x.sum()
            sums[i, 1] += (x * x).sum()
        done += n
    mean = sums[:, 0] / n_total
    var = sums[:, 1] / n_total - mean ** 2
    err = np.sqrt(var / n_total)
    f2 = lambda a_, b_: f_sym(kv[a_][None, :], kv[b_][None, :])[0]
    tree = 2 * (f2(0, 1) * pk[0] * pk[1] + f2(1, 2) * pk[1] * pk[2] + f2(2, 0) * pk[2] * pk[0])
    return tree, mean, err


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--samples", type=int, default=2 ** 21)
    ap.add_argument("--seed", type=int, default=20261205)
    args = ap.parse_args()
    rng = np.random.default_rng(args.seed)
    lines = [
        "# one-loop matter bispectrum terms by plain Monte Carlo (tests/data/bispectrum/make_one_loop_mc.py)",
        f"# spectrum: pt-spectra/data/linear_pk_gm2012_z0.0.dat (CAMB, z = 0); {Q_MIN} <= |q| <= {Q_MAX} h/Mpc; "
        f"{args.samples} samples per triangle (ln q uniform, direction uniform), seed {args.seed}",
        "# B in (Mpc/h)^6; err_ = Monte Carlo standard error (one sigma)",
        "# k1 k2 k3 tree B222 err_B222 B321I err_B321I B321II err_B321II B411 err_B411",
    ]
    for ks in TRIANGLES:
        tree, mean, err = terms(ks, rng, args.samples, 2 ** 17)
        row = [*ks, tree] + [x for pair in zip(mean, err) for x in pair]
        lines.append(" ".join(f"{x:.10g}" for x in row))
        print(lines[-1], flush=True)
    (HERE / "one_loop_mc_gm2012_z0.txt").write_text("\n".join(lines) + "\n")


if __name__ == "__main__":
    main()
