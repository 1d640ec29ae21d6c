"""An independent plain Monte Carlo of the one-loop matter bispectrum terms in redshift space (issue 50).

Writes one_loop_rsd_mc_gm2012_z0.txt: for each triangle, at one line of sight n and growth rate f, the
tree level and B222, B321-I, B321-II, B411 [(Mpc/h)^6] with their Monte Carlo standard errors, for the
embedded CAMB spectrum pt-spectra/data/linear_pk_gm2012_z0.0.dat, loop momenta 1e-4 <= |q| <= 10 h/Mpc.

Independent of the Rust code: the redshift-space kernels Z_n are built here from the mapping
delta_s(k) = sum_m (f k mu)^m / m! [(delta + f mu^2 theta)(mu/k theta)^m](k) (Scoccimarro, Couchman &
Frieman 1999): for each ordering of the arguments, each cut into consecutive blocks B_0, ..., B_m
contributes D(B_0) U(B_1) ... U(B_m) / m!, D(S) = F_S + f mu_S^2 G_S, U(S) = f (k mu)(mu_S/k_S) G_S with the
unsymmetrised SPT kernels of make_one_loop_mc.py on each block, averaged over the orderings (the Rust code
uses the exact generated kernels of pt_kernels::redshift). The integrals are plain Monte Carlo over q
(ln|q| uniform, the direction uniform over the whole sphere: the line of sight breaks the triangle's
mirror symmetry), with no partition of unity.

Definitions (as pt_spectra::bispectrum::one_loop with F_n -> Z_n and Z1 on the linear legs):
  tree    = sum over pairs a < b of 2 Z2(k_a, k_b) Z1(k_a) Z1(k_b) P(k_a) P(k_b)
  B222    = 8 int_q Z2(-q, q+k1) Z2(-q-k1, q-k2) Z2(k2-q, q) P(q) P(|q+k1|) P(|k2-q|)
  B321-I  = sum over ordered a != b of 6 Z1(k_a) P(k_a) int_q Z3(-q, q-k_b, -k_a) Z2(q, k_b-q) P(q) P(|k_b-q|)
  B321-II = sum over ordered a != b of 6 Z2(k_a, k_b) Z1(k_b) P(k_a) P(k_b) int_q Z3(k_a, q, -q) P(q)
  B411    = sum over a of 12 Z1(k_b) Z1(k_c) P(k_b) P(k_c) int_q Z4(q, -q, -k_b, -k_c) P(q)

    python3 tests/data/bispectrum/make_one_loop_rsd_mc.py [--samples N]   (numpy, scipy; ~1 h on one core)
"""

import argparse
import itertools
import math
from pathlib import Path

import numpy as np

from make_one_loop_mc import HERE, Q_MAX, Q_MIN, dot, kernels_unsym, power, samples, triangle

F = 0.7
LOS = np.array([0.3, 0.4, 0.866])
LOS = LOS / np.linalg.norm(LOS)
TRIANGLES = [
    (0.05, 0.05, 0.05), (0.1, 0.1, 0.1), (0.15, 0.15, 0.15),
    (0.01, 0.1, 0.1), (0.02, 0.15, 0.15), (0.05, 0.05, 0.0999),
    (0.06, 0.08, 0.139), (0.05, 0.1, 0.12), (0.08, 0.1, 0.15),
    (0.04, 0.07, 0.09), (0.1, 0.12, 0.18), (0.15, 0.2, 0.25),
]


def compositions(n):
    if n == 0:
        return [[]]
    return [[first] + rest for first in range(1, n + 1) for rest in compositions(n - first)]


def z_sym(*vectors):
    """Z_n of the (N, 3) arrays at F, LOS (module docstring)."""
    n = len(vectors)
    memo = {"v": list(vectors)}
    k = sum(vectors)
    k_los = dot(k, LOS)  # k mu
    total = 0.0
    orders = list(itertools.permutations(range(n)))
    for order in orders:
        for parts in compositions(n):
            product = 1.0
            start = 0
            for j, length in enumerate(parts):
                block = tuple(order[start:start + length])
                start += length
                fs, gs = kernels_unsym(block, memo)
                ks = sum(memo["v"][i] for i in block)
                ks2 = dot(ks, ks)
                good = ks2 > 0  # a block of zero momentum: F_S, G_S ~ k_S^2, its limit is zero
                s2 = np.where(good, ks2, 1.0)
                ns = dot(ks, LOS)
                if j == 0:
                    piece = fs + F * ns * ns / s2 * gs
                else:
                    piece = F * k_los * ns / s2 * gs
                product = product * np.where(good, piece, 0.0)
            total = total + product / math.factorial(len(parts) - 1)
    return total / len(orders)


def terms(ks, rng, n_total, chunk):
    kv = triangle(*ks)
    pk = power(np.array(ks))
    tile = lambda v, n: np.broadcast_to(v, (n, 3))
    one = lambda a_: z_sym(kv[a_][None, :])[0]
    two = lambda a_, b_: z_sym(kv[a_][None, :], kv[b_][None, :])[0]
    sums = np.zeros((4, 2))
    done = 0
    while done < n_total:
        n = min(chunk, n_total - done)
        q, qn, w = samples(rng, n)
        pq = power(qn)
        k1, k2 = tile(kv[0], n), tile(kv[1], n)
        a, b = q + k1, k2 - q
        b222 = 8 * z_sym(-q, a) * z_sym(-a, -b) * z_sym(b, q) * pq * power(np.linalg.norm(a, axis=1)) \
            * power(np.linalg.norm(b, axis=1))
        b321i = 0.0
        b321ii = 0.0
        z3loop = [z_sym(tile(kv[a_], n), q, -q) * pq for a_ in range(3)]
        for a_ in range(3):
            for b_ in range(3):
                if a_ == b_:
                    continue
                d = tile(kv[b_], n) - q
                b321i = b321i + 6 * one(a_) * pk[a_] * z_sym(-q, -d, -tile(kv[a_], n)) * z_sym(q, d) * pq \
                    * power(np.linalg.norm(d, axis=1))
                b321ii = b321ii + 6 * two(a_, b_) * one(b_) * pk[a_] * pk[b_] * z3loop[a_]
        b411 = 0.0
        for a_ in range(3):
            b_, c_ = (a_ + 1) % 3, (a_ + 2) % 3
            b411 = b411 + 12 * one(b_) * one(c_) * pk[b_] * pk[c_] \
                * z_sym(q, -q, -tile(kv[b_], n), -tile(kv[c_], n)) * pq
        for i, x in enumerate([b222, b321i, b321ii, b411]):
            x = x * w
            sums[i, 0] += x.sum()
            sums[i, 1] += (x * x).sum()
        done += n
    mean = sums[:, 0] / n_total
    err = np.sqrt((sums[:, 1] / n_total - mean ** 2) / n_total)
    tree = sum(2 * two(a_, b_) * one(a_) * one(b_) * pk[a_] * pk[b_] for a_, b_ in [(0, 1), (1, 2), (2, 0)])
    return tree, mean, err


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--samples", type=int, default=2 ** 20)
    ap.add_argument("--seed", type=int, default=20261206)
    args = ap.parse_args()
    rng = np.random.default_rng(args.seed)
    lines = [
        "# one-loop matter bispectrum terms in redshift space by plain Monte Carlo "
        "(tests/data/bispectrum/make_one_loop_rsd_mc.py)",
        f"# spectrum: pt-spectra/data/linear_pk_gm2012_z0.0.dat (CAMB, z = 0); {Q_MIN} <= |q| <= {Q_MAX} h/Mpc; "
        f"{args.samples} samples per triangle (ln q uniform, direction uniform), seed {args.seed}",
        f"# f = {F}; line of sight {LOS[0]:.12g} {LOS[1]:.12g} {LOS[2]:.12g} (k1 along z, k2 in the x-z plane "
        "with positive x, k3 = -k1 - k2)",
        "# B in (Mpc/h)^6; err_ = Monte Carlo standard error (one sigma)",
        "# k1 k2 k3 tree B222 err_B222 B321I err_B321I B321II err_B321II B411 err_B411",
    ]
    for ks in TRIANGLES:
        tree, mean, err = terms(ks, rng, args.samples, 2 ** 15)
        row = [*ks, tree] + [x for pair in zip(mean, err) for x in pair]
        lines.append(" ".join(f"{x:.10g}" for x in row))
        print(lines[-1], flush=True)
    (HERE / "one_loop_rsd_mc_gm2012_z0.txt").write_text("\n".join(lines) + "\n")


if __name__ == "__main__":
    main()
