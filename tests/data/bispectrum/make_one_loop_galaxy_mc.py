"""An independent plain Monte Carlo of the one-loop GALAXY bispectrum terms (issue 50), real and redshift space.

Writes one_loop_galaxy_mc_gm2012_z0_f{F}.txt for the growth rate F of --f (0: real space; the tests use 0 and
0.7, at the line of sight of make_one_loop_rsd_mc.py): for each triangle the tree level and B222, B321-I and the
renormalised B321-II, B411 [(Mpc/h)^6] with their Monte Carlo standard errors, for the
bias values BIAS below, the CAMB spectrum pt-spectra/data/linear_pk_gm2012_z0.0.dat, 1e-4 <= |q| <= 10 h/Mpc.

The bias expansion (Eggemeier, Scoccimarro & Smith 2019, arXiv:1812.03208; as Philcox et al. 2022,
arXiv:2206.02800), with delta the nonlinear matter density, theta the velocity divergence (theta_1 = delta_1),
the potentials nabla^2 phi_1 = delta, nabla^2 Phi_v = theta, nabla^2 phi_2 = G2(phi_1), and the Galileons
G2(a, b) = d_ij a d_ij b - nabla^2 a nabla^2 b (kernel K(p1, p2) = (p1.p2)^2/(p1^2 p2^2) - 1) and the
trilinear G3(a, b, c) (kernel L = 1 - mu12^2 - mu23^2 - mu31^2 + 2 mu12 mu23 mu31):

  delta_g = b1 delta + b2/2 delta^2 + g2 G2(Phi_v)
          + b3/6 delta^3 + g2x delta G2(Phi_v) + g3 G3(Phi_v) + g21 G2(phi_2, phi_1)
          + g21x delta G2(phi_2, phi_1) + g211 G3(phi_2, phi_1, phi_1) + g22 G2(phi_2, phi_2) + g31 G2(phi_3, phi_1),

in the Lagrangian convention of check_bias_basis_conventions.py ("L", complete at fourth order):
  G2(phi_2, phi_1) is the operator of the linear potentials carried by the flow with the number density,
    FT = int d^3q e^{-ik.(q + Psi)} O(q): unsymmetrised third order K(q12, q3) K(q1, q2), fourth order the same
    on (q1, q2, q3) times k.q4/q4^2 (k the total momentum: the Zel'dovich displacement of q4);
  phi_3 is the 3LPT potential with its transverse part, G2(phi_3, phi_1) of fourth order only, unsymmetrised
    kernel (q1 | q2 q3 q4) (1/18) K(q1, q234) [(15/7) K(q23, q4) K(q2, q3) - L(q2, q3, q4)]
    + (1/14) [M(q1, q23, q4, q234) - M(q1, q234, q23, q4)] K(q2, q3), M(a, b, c, d) = (a.b)(b.c)(c.d)(d.a) of
    the unit vectors.

Independent of the Rust code (pt_spectra::bispectrum::bias_kernels builds symmetrised kernels on subsets with
factorial weights): here every operator's kernel is built UNSYMMETRISED on an ordering of its arguments, each
product or Galileon of fields summing over the cuts of the ordering into consecutive blocks, with the
unsymmetrised SPT F_n, G_n of make_one_loop_mc.py inside, and the galaxy kernel is the average over all
orderings. A block of zero total momentum contributes zero (normal ordering: the operators' means are
subtracted; F_S, G_S vanish there). Renormalised: in B321-II and B411 the kernels K3(k_a, q, -q) and
K4(q, -q, -k_b, -k_c) less their q -> infinity angular averages of the non-b1 part (uv_limit: its own angular
rule over the whole sphere, Richardson from q = 1e3 and 2e3 k_max). In redshift space the mapping of make_one_loop_rsd_mc.py with
D(S) = K_S + f mu_S^2 G_S (the galaxy density replaces the matter's, the velocity is unbiased).

    python3 tests/data/bispectrum/make_one_loop_galaxy_mc.py --f 0 --samples 131072     (numpy; 22 triangles:
    python3 tests/data/bispectrum/make_one_loop_galaxy_mc.py --f 0.7 --samples 65536    32.6 and 30.0 min wall,
                                                                                        13.1 and 10.6 min CPU)
(both runs at once on 2 cores at load 3-10). --out FILE writes elsewhere; the file is rewritten after every
triangle.
"""

import argparse
import itertools
import math
from pathlib import Path

import numpy as np

from make_one_loop_mc import HERE, Q_MAX, Q_MIN, dot, kernels_unsym, power, samples, triangle
from make_one_loop_mc import TRIANGLES as MATTER_TRIANGLES
from make_one_loop_rsd_mc import LOS, compositions

BIAS = dict(b1=1.8, b2=0.6, g2=-0.3, b3=0.4, g2x=0.5, g3=-0.2, g21=0.35, g21x=0.3, g211=-0.4, g22=0.25,
            g31=0.6)
# The 22 triangles of the matter table (make_one_loop_mc.py), squeezed (0.01, 0.1, 0.1) through equilateral to
# folded; the first four are the earlier four-triangle table's, in its order, so that one generator run from the
# seed reproduces those rows bit for bit, then the other 18 in the matter table's order.
FIRST = [(0.05, 0.05, 0.05), (0.1, 0.1, 0.1), (0.02, 0.1, 0.1), (0.06, 0.08, 0.139)]
TRIANGLES = FIRST + [t for t in MATTER_TRIANGLES if t not in FIRST]


def _cos(a, b):
    a2, b2 = dot(a, a), dot(b, b)
    good = (a2 > 0) & (b2 > 0)
    return np.where(good, dot(a, b) / np.sqrt(np.where(good, a2 * b2, 1.0)), 0.0), good


def kk(a, b):
    c, good = _cos(a, b)
    return np.where(good, c * c - 1.0, 0.0)


def ll(a, b, c):
    x, g1 = _cos(a, b)
    y, g2 = _cos(b, c)
    z, g3 = _cos(c, a)
    return np.where(g1 & g2 & g3, 1.0 - x * x - y * y - z * z + 2.0 * x * y * z, 0.0)


class Fields:
    """Unsymmetrised kernels of the fields on ordered tuples of ids into v (numpy arrays of samples)."""

    def __init__(self, v):
        self.v = v
        self.memo = {"v": v}
        self.cache = {}

    def k(self, vs):
        return sum(self.v[i] for i in vs)

    def d(self, vs):
        return kernels_unsym(vs, self.memo)[0]

    def t(self, vs):
        return kernels_unsym(vs, self.memo)[1]

    def cuts2(self, vs):
        return [(vs[:j], vs[j:]) for j in range(1, len(vs))]

    def cuts3(self, vs):
        n = len(vs)
        return [(vs[:i], vs[i:j], vs[j:]) for i in range(1, n) for j in range(i + 1, n)]

    def get(self, name, vs):
        key = (name, vs)
        if key not in self.cache:
            self.cache[key] = getattr(self, "_" + name)(vs)
        return self.cache[key]

    def _p2(self, vs):  # nabla^2 phi_2 = G2(phi_1)
        return sum((kk(self.k(a), self.k(b)) * self.d(a) * self.d(b) for a, b in self.cuts2(vs)), 0.0)

    def _g2v(self, vs):
        return sum((kk(self.k(a), self.k(b)) * self.t(a) * self.t(b) for a, b in self.cuts2(vs)), 0.0)

    def _dd(self, vs):
        return sum((self.d(a) * self.d(b) for a, b in self.cuts2(vs)), 0.0)

    def _ddd(self, vs):
        return sum((self.d(a) * self.d(b) * self.d(c) for a, b, c in self.cuts3(vs)), 0.0)

    def _g3v(self, vs):
        return sum((ll(self.k(a), self.k(b), self.k(c)) * self.t(a) * self.t(b) * self.t(c)
                    for a, b, c in self.cuts3(vs)), 0.0)

    def _dg2v(self, vs):
        return sum((self.d(a) * self.get("g2v", b) for a, b in self.cuts2(vs)), 0.0)

    def _g21(self, vs):
        """G2(phi_2, phi_1) of the linear (Lagrangian) potentials, carried to x by the flow with the number
        density: FT = int d^3q e^{-ik.(q + Psi)} O(q). Third order: the operator itself (K(q12, q3) K(q1, q2)
        on this ordering); fourth order: the third order of the first three arguments times the Zel'dovich
        displacement of the last, -ik.Psi_1(q4) -> k.q4/q4^2 (k the total momentum)."""
        if len(vs) < 3:
            return 0.0
        q = [self.v[i] for i in vs]
        lagrangian = kk(q[0] + q[1], q[2]) * kk(q[0], q[1])
        if len(vs) == 3:
            return lagrangian
        inner, q4 = q[0] + q[1] + q[2], q[3]
        block = dot(inner, inner) > 0  # a zero-momentum operator block is normal-ordered away
        return np.where(block, lagrangian * dot(inner + q4, q4) / dot(q4, q4), 0.0)

    def _dg21(self, vs):
        return sum((self.d(a) * self.get("g21", b) for a, b in self.cuts2(vs)), 0.0)

    def _g211(self, vs):
        return sum((ll(self.k(a), self.k(b), self.k(c)) * self.get("p2", a) * self.d(b) * self.d(c)
                    for a, b, c in self.cuts3(vs)), 0.0)

    def _g22(self, vs):
        return sum((kk(self.k(a), self.k(b)) * self.get("p2", a) * self.get("p2", b)
                    for a, b in self.cuts2(vs)), 0.0)

    def _g31(self, vs):
        if len(vs) != 4:
            return 0.0
        q1, q2, q3, q4 = (self.v[i] for i in vs)
        q23, q234 = q2 + q3, q2 + q3 + q4
        longitudinal = kk(q1, q234) * (15.0 / 7.0 * kk(q23, q4) * kk(q2, q3) - ll(q2, q3, q4)) / 18.0

        def m(a, b, c, d):  # (a.b)(b.c)(c.d)(d.a) of the unit vectors, zero if one vanishes
            return _cos(a, b)[0] * _cos(b, c)[0] * _cos(c, d)[0] * _cos(d, a)[0]

        transverse = (m(q1, q23, q4, q234) - m(q1, q234, q23, q4)) * kk(q2, q3) / 14.0
        return longitudinal + transverse

    def galaxy(self, vs, bias):
        """The unsymmetrised galaxy kernel of the ordered block vs (zero if its momentum vanishes)."""
        if ("galaxy", vs) in self.cache:
            return self.cache[("galaxy", vs)]
        self.cache[("galaxy", vs)] = self._galaxy(vs, bias)
        return self.cache[("galaxy", vs)]

    def _galaxy(self, vs, bias):
        b = bias
        if len(vs) == 1:
            return b["b1"] * np.ones(self.v[vs[0]].shape[0])
        total = (b["b1"] * self.d(vs) + 0.5 * b["b2"] * self.get("dd", vs) + b["g2"] * self.get("g2v", vs)
                 + b["b3"] / 6.0 * self.get("ddd", vs) + b["g2x"] * self.get("dg2v", vs)
                 + b["g3"] * self.get("g3v", vs) + b["g21"] * self.get("g21", vs)
                 + b["g21x"] * self.get("dg21", vs) + b["g211"] * self.get("g211", vs)
                 + b["g22"] * self.get("g22", vs) + b["g31"] * self.get("g31", vs))
        ks = self.k(vs)
        return np.where(dot(ks, ks) > 0, total, 0.0)


def z_gal(f, bias, *vectors):
    """The symmetrised galaxy Z_n (K_n at f = 0) of the (N, 3) arrays: the average over orderings."""
    n = len(vectors)
    fields = Fields(list(vectors))
    k = sum(vectors)
    k_los = dot(k, LOS)
    total = 0.0
    orders = list(itertools.permutations(range(n)))
    for order in orders:
        for parts in compositions(n):
            if f == 0.0 and len(parts) > 1:
                continue
            product = 1.0
            start = 0
            for j, length in enumerate(parts):
                block = tuple(order[start:start + length])
                start += length
                ks = fields.k(block)
                ks2 = dot(ks, ks)
                good = ks2 > 0
                s2 = np.where(good, ks2, 1.0)
                ns = dot(ks, LOS)
                gs = fields.t(block)
                if j == 0:
                    piece = fields.galaxy(block, bias) + f * ns * ns / s2 * gs
                else:
                    piece = f * k_los * ns / s2 * gs
                product = product * np.where(good, piece, 0.0)
            total = total + product / math.factorial(len(parts) - 1)
    return total / len(orders)


def uv_limit(f, args, k_max):
    """lim_{q -> inf} of the angular average of Z^g(args(q)) minus its b1-only part: Gauss-Legendre in mu
    (24 nodes) times 48 uniform azimuths over the whole circle, at q = 1e3 and 2e3 k_max, Richardson."""
    x, wx = np.polynomial.legendre.leggauss(24)
    phi = (np.arange(48) + 0.5) * 2 * np.pi / 48
    mu = np.repeat(x, phi.size)
    w = np.repeat(wx, phi.size) / (2 * phi.size)
    ph = np.tile(phi, x.size)
    s = np.sqrt(1 - mu * mu)
    u = np.stack([s * np.cos(ph), s * np.sin(ph), mu], axis=1)
    lin = dict((key, 0.0) for key in BIAS)
    lin["b1"] = BIAS["b1"]
    avg = [np.sum(w * (z_gal(f, BIAS, *args(big * u)) - z_gal(f, lin, *args(big * u))))
           for big in (1e3 * k_max, 2e3 * k_max)]
    return (4 * avg[1] - avg[0]) / 3


def terms(ks, f, rng, n_total, chunk):
    kv = triangle(*ks)
    pk = power(np.array(ks))
    z = lambda *v: z_gal(f, BIAS, *v)
    tile = lambda v, n: np.broadcast_to(v, (n, 3))
    k_max = max(ks)
    c3 = [uv_limit(f, lambda q, a_=a_: (tile(kv[a_], q.shape[0]), q, -q), k_max) for a_ in range(3)]
    c4 = [uv_limit(f, lambda q, a_=a_: (q, -q, -tile(kv[(a_ + 1) % 3], q.shape[0]),
                                        -tile(kv[(a_ + 2) % 3], q.shape[0])), k_max) for a_ in range(3)]
    one = lambda a_: z(kv[a_][None, :])[0]
    two = lambda a_, b_: z(kv[a_][None, :], kv[b_][None, :])[0]
    sums = np.zeros((4, 2))
    done = 0
    while done < n_total:
        n = min(chunk, n_total - done)
        q, qn, w = samples(rng, n)
        pq = power(qn)
        k1, k2 = tile(kv[0], n), tile(kv[1], n)
        a, b = q + k1, k2 - q
        b222 = 8 * z(-q, a) * z(-a, -b) * z(b, q) * pq * power(np.linalg.norm(a, axis=1)) \
            * power(np.linalg.norm(b, axis=1))
        b321i = 0.0
        b321ii = 0.0
        z3loop = [(z(tile(kv[a_], n), q, -q) - c3[a_]) * pq for a_ in range(3)]
        for a_ in range(3):
            for b_ in range(3):
                if a_ == b_:
                    continue
                d = tile(kv[b_], n) - q
                b321i = b321i + 6 * one(a_) * pk[a_] * z(-q, -d, -tile(kv[a_], n)) * z(q, d) * pq \
                    * power(np.linalg.norm(d, axis=1))
                b321ii = b321ii + 6 * two(a_, b_) * one(b_) * pk[a_] * pk[b_] * z3loop[a_]
        b411 = 0.0
        for a_ in range(3):
            b_, c_ = (a_ + 1) % 3, (a_ + 2) % 3
            b411 = b411 + 12 * one(b_) * one(c_) * pk[b_] * pk[c_] \
                * (z(q, -q, -tile(kv[b_], n), -tile(kv[c_], n)) - c4[a_]) * pq
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
    ap.add_argument("--f", type=float, default=0.0)
    ap.add_argument("--samples", type=int, default=2 ** 17)
    ap.add_argument("--seed", type=int, default=20261206)
    ap.add_argument("--out", default=None, help="output file (default one_loop_galaxy_mc_gm2012_z0_f{F}.txt here)")
    args = ap.parse_args()
    out = Path(args.out) if args.out else HERE / f"one_loop_galaxy_mc_gm2012_z0_f{args.f:g}.txt"
    rng = np.random.default_rng(args.seed)
    lines = [
        "# one-loop GALAXY bispectrum terms (B321-II, B411 renormalised: UV constants subtracted) by plain Monte Carlo "
        "(tests/data/bispectrum/make_one_loop_galaxy_mc.py)",
        f"# spectrum: pt-spectra/data/linear_pk_gm2012_z0.0.dat (CAMB, z = 0); {Q_MIN} <= |q| <= {Q_MAX} h/Mpc; "
        f"{args.samples} samples per triangle (ln q uniform, direction uniform), seed {args.seed}",
        "# bias: " + " ".join(f"{k}={v}" for k, v in BIAS.items()),
        f"# line of sight {LOS[0]:.12g} {LOS[1]:.12g} {LOS[2]:.12g} (k1 along z, k2 in the x-z plane with "
        "positive x); f = 0 is real space",
        "# B in (Mpc/h)^6; err_ = Monte Carlo standard error (one sigma)",
        "# f k1 k2 k3 tree B222 err_B222 B321I err_B321I B321II err_B321II B411 err_B411",
    ]
    for ks in TRIANGLES:
        tree, mean, err = terms(ks, args.f, rng, args.samples, 2 ** 14)
        row = [args.f, *ks, tree] + [x for pair in zip(mean, err) for x in pair]
        lines.append(" ".join(f"{x:.10g}" for x in row))
        print(lines[-1], flush=True)
        out.write_text("\n".join(lines) + "\n")  # after every triangle: a partial run leaves its rows


if __name__ == "__main__":
    main()
