#!/usr/bin/env python3
"""A first redshift-space N-body check of `eft2` (2-loop SPT in redshift space + IR resummation +
linear counterterms): the matter multipoles P0, P2 of single Quijote latin-hypercube boxes at z = 0.5
and z = 1, against eft2, the 1-loop EFT (`ept` at b1 = 1) and IR-resummed linear Kaiser, each with
its counterterms fitted by linear least squares.

Data (examples/data/nbody/quijote_lh_rsd/, see its README.md)
    github.com/murakoya/fsigma8_ML, commit f2309c7465ff62e1786fbc502f4a7eb73c133882 (files added in
    7691fcb694de7f7786ddcdee700aa845cc4afa1c, 2023-05-16), NN/input_data/dir<X>/Pk_m_RS<a>_z=<z>.txt:
    k [h/Mpc], P0, P2, P4 [(Mpc/h)^3] of the redshift-space matter field of Quijote LH realisation X
    (1 Gpc/h, 512^3 particles), line of sight along axis a = x, y, z; the first 80 rows (k < 0.51)
    are copied unchanged. dir<X> is LH row X: its fsigma8 labels (dir<X>/z05.dat, z1.dat) are
    reproduced to 1e-8 by the LCDM growth of row X of Quijote's latin_hypercube_params.txt and by no
    other row. Boxes: 3, 7, 8, 11, 13, 17, 24, the rows of the 30 published with 0.24 <= Omega_m <=
    0.42, 0.70 <= sigma8 <= 0.95, 0.55 <= h <= 0.80, 0.80 <= n_s <= 1.06 (none of the 30 is within
    Omega_m 0.27-0.36, sigma8 0.74-0.9, h 0.6-0.75, n_s 0.92-1.0 in all five parameters).
    Linear spectra: make_linear.py there (CAMB, sigma8 of the LH row at z = 0, LCDM growth to z;
    f = dlnD/dlna of that growth, which reproduces the repository's fsigma8 labels).

Measurement conventions (checked, not assumed): the k column is the mean |k| of the lattice modes
with i <= |k|/k_F < i + 1, k_F = 2 pi/1000 h/Mpc (reproduced to 1e-13), so Delta k = k_F and the
bins are counted exactly on the lattice here. Every model is put through the same mode average:
P_l(bin) = (2l+1) < L_l(mu_n) P(|k_n|, mu_n) >_modes (discrete mu at low k, k spread in the bin).

Errors: Gaussian, one box, per bin from the exact lattice modes (N_k = half the modes of the bin,
Delta k = k_F): Cov(P_l, P_l') = (2l+1)(2l'+1)/N_k < A_l A_l' >_modes with, for one line of sight,
A_l(n) = L_l(mu_n) P(k_n, mu_n) (the brief's (2l+1)^2/N_k int L_l^2 P^2 dmu on the lattice; note: with
N_k the independent modes the monopole variance is P^2/N_k = 2P^2/N_modes, not 2P^2/N_k), where
P(k, mu) = sum_l S_l(k) L_l(mu) + V/N, S_l the box's LOS-averaged multipoles smoothed (ratio to linear
Kaiser, running mean). The P0-P2 covariance per bin is kept; bins are independent. Three versions:
    baseline          one line of sight: no reduction for averaging the three (the upper bound of the
                      Gaussian variance of a mean of three equally distributed estimates);
    3-LOS Gaussian    A_l = (1/3) sum_a L_l(mu_a) P(k_n, mu_a), mu_a = n_a/|n|: the three lines of sight
    gain              as scaled copies of one real-space mode (exact in linear theory). Var(P0) drops
                      only to ~0.9 of one LOS, Var(P2) to ~0.05-0.1 (the isotropic part cancels,
                      sum_a L2(mu_a) = 0); nonlinear velocities decorrelate the lines of sight, which
                      lowers Var(P0) and raises Var(P2) of the mean;
    3-LOS calibrated  Var(mean) = Var_1 - (2/3) s^2, s^2 the expected scatter of the three lines of
                      sight about their mean, taken as q(k) x the fully correlated prediction with q
                      measured from the data (stacked over the boxes, +-8 bins), clipped to the
                      physical range; P0-P2 correlation coefficient of the fully correlated case.
Non-Gaussian covariance (trispectrum) is in none of them (at k ~ 0.2-0.25 it adds O(10-30%) to the
variance of a k_F bin of a 1 Gpc/h box).

Shot noise: V/N = 7.45 (Mpc/h)^3. The data are taken as noise-subtracted (sn = 0 in the baseline):
at z = 3 the same files give P0 = 4.5-6.0 (Mpc/h)^3 at k ~ 1.85 (5 boxes checked), below V/N, which a
mass-assignment-corrected spectrum with the Poisson noise left in cannot do (its noise term is >=
V/N), and P0 rises towards the corners of the grid (k > 3) as a subtracted, deconvolved noise does.
Variants: the model plus V/N (not subtracted), and sn free (a constant in P(k, mu)).

Fits: per box and z, jointly P0 and P2 on 0.01 <= k <= k_fit (k_fit = 0.15, 0.2, 0.25), linear least
squares in the counterterms (no priors):
    eft2 c=0  nothing (IR-resummed 2-loop SPT)
    eft2      c0, c2, c4                          (-2 k^2 mu^2n P_IR, pt.TwoLoopRsdPlan templates)
    eft2+ctilde  c0, c2, c4, ctilde                (ctilde: -k^4 f^4 mu^4 (1 + f mu^2)^2 P_IR)
    eft2+1l   c0, c2, c4, c0_1loop, c2_1loop, c4_1loop
    1-loop    alpha0, alpha2, alpha4              (pt.EptPlan at b1 = 1, b2 = bs = b3 = 0: REPT)
    Kaiser    c0, c2, c4 on (1 + f mu^2)^2 P_IR   (P_IR = P_nw + e^{-x} P_w, eft2's split and damping)
The cosmology and f are fixed to the box's (no fit of f or sigma8). Residuals: in bands k +- 0.01,
sum(model - data)/sum(data) per box; mean over the boxes +- scatter/sqrt(7) (independent boxes, which
also differ in cosmology).

Model evaluation: eft2 from the basis tensors cached for pt.log_grid(0.005, 0.4, 40) at precision
"fast" (the spectra the basis refuses, projection residual > 3e-4, are integrated directly by the
library, ~40 s each on one core; the tables are cached in examples/out/rsd_quijote_lh_cache/). To
evaluate between the 40 grid points without spline error on the BAO, the IR-resummed linear part
(1 + f mu^2)^2 [P_nw + e^{-x}(1 + x + x^2/2) P_w] and the counterterm templates are computed here
exactly at every k (P_nw recovered at the grid points from the library's own c-templates, which are
linear in P_nw and P_w, and splined in ln k), and only the smooth remainder (the loops) is splined.

Caveats: single boxes (Gaussian sigma(P0)/P0 of one k_F bin ~5% at k = 0.05, ~1.3% at 0.2); 512^3
particles in 1 Gpc/h (particle mass 6.2e11 (Omega_m/0.3) Msun/h; resolution effects on the matter
P(k) are expected toward k >~ 0.5 and are not checked here); the shot-noise status is inferred, not
documented; the three lines of sight are one box (see Errors); the counterterms absorb smooth-in-k
effects of all of these, so a good chi2 is a consistency check at the level of the errors, not a
per-cent accuracy test.

Usage: python examples/rsd_quijote_lh.py   (writes examples/out/rsd_quijote_lh.md and prints it;
needs the 2-loop basis tensors of pt.log_grid(0.005, 0.4, 40) at precision fast in the table store, or
builds them; 10 of the 14 spectra are refused by the basis (cosmologies outside its training box) and
integrated directly: ~7 min on one core the first time, then ~4 s from examples/out/rsd_quijote_lh_cache/)
"""
import hashlib
import os
import re
import sys
import time
import warnings

import numpy as np
from numpy.polynomial.legendre import leggauss, legval
from scipy.interpolate import CubicSpline

import pt_spectra as pt

T_START = time.time()
HERE = os.path.dirname(os.path.abspath(__file__))
DATA = os.path.join(HERE, "data", "nbody", "quijote_lh_rsd")
OUT = os.path.join(HERE, "out")
CACHE = os.path.join(OUT, "rsd_quijote_lh_cache")

BOXES = (3, 7, 8, 11, 13, 17, 24)
ZS = (0.5, 1.0)
BOX = 1000.0  # Mpc/h
KF = 2 * np.pi / BOX
P_SN = BOX**3 / 512**3  # 7.45 (Mpc/h)^3
K_MIN, K_MAX = 0.01, 0.3
K_FITS = (0.15, 0.2, 0.25)
BANDS = (0.05, 0.1, 0.15, 0.2, 0.25)  # band centres; width +-0.01 h/Mpc
HALF_BAND = 0.01
GRID = np.asarray(pt.log_grid(0.005, 0.4, 40))  # the grid of the cached eft2 basis tensors
ELLS_MODEL = (0, 2, 4, 6, 8)
ELLS_FIT = (0, 2)
CT = ("c0", "c2", "c4")
CT1 = ("c0_1loop", "c2_1loop", "c4_1loop")
MODELS = {  # name: (free templates, description)
    "eft2 c=0": ((), "IR-resummed 2-loop SPT (eft2 with every counterterm 0): nothing fitted"),
    "eft2": (CT, "2-loop EFT, c0 c2 c4"),
    "eft2+ctilde": (CT + ("ctilde",), "2-loop EFT, c0 c2 c4 + CLASS-PT's k^4 Fingers-of-God term ctilde"),
    "eft2+1l": (CT + CT1, "2-loop EFT, c0 c2 c4 + the 1-loop-inserted c0_1loop c2_1loop c4_1loop"),
    "1-loop": (("alpha0", "alpha2", "alpha4"), "1-loop EFT (ept at b1 = 1, velocileptors' REPT), alpha0 alpha2 alpha4"),
    "Kaiser": (CT, "linear Kaiser (IR-resummed, eft2's split and damping), c0 c2 c4"),
}
# error and shot-noise variants: (covariance, shot noise: a number fixed in the model or "free")
VARIANTS = {
    "baseline": ("single", 0.0),
    "3-LOS calibrated": ("calibrated", 0.0),
    "3-LOS Gaussian gain": ("avg", 0.0),
    "sn = V/N": ("single", P_SN),
    "sn free": ("single", "free"),
}
MU_NODES, MU_WEIGHTS = leggauss(48)  # on [-1, 1]; integrands are even in mu
MU_NODES, MU_WEIGHTS = MU_NODES[24:], MU_WEIGHTS[24:]  # [0, 1] half, weights sum to 1

pt.set_num_threads(1)
warnings.simplefilter("ignore", pt.PtSpectraWarning)  # f and z are given explicitly; headers kept


def legendre(ell, mu):
    c = np.zeros(ell + 1)
    c[ell] = 1.0
    return legval(mu, c)


# --------------------------------------------------------------------------------------------------
# the box's lattice: every mode with 1 <= |n| < imax + 1, grouped by sorted (nx^2, ny^2, nz^2)


def lattice(imax):
    n = np.arange(-imax - 1, imax + 2)
    nx, ny, nz = np.meshgrid(n, n, n, indexing="ij")
    sq = np.sort(np.stack([nx.ravel() ** 2, ny.ravel() ** 2, nz.ravel() ** 2]), axis=0)
    r2 = sq.sum(0)
    keep = (r2 >= 1) & (r2 < (imax + 1) ** 2)
    sq = sq[:, keep]
    key = (sq[0] * 10**4 + sq[1]) * 10**4 + sq[2]
    key, first, count = np.unique(key, return_index=True, return_counts=True)
    sq = sq[:, first].astype(float)
    r = np.sqrt(sq.sum(0))
    return {"bin": np.floor(r).astype(int), "k": r * KF, "mu2": sq / r**2, "count": count.astype(float)}


class Bins:
    """Mode averages over the bins [i, i+1) k_F of the lattice for every LOS-averaged template."""

    def __init__(self, imax):
        self.lat = lattice(imax)
        lat = self.lat
        self.nbin = imax + 1
        self.modes = np.bincount(lat["bin"], weights=lat["count"], minlength=self.nbin)
        self.kmean = np.bincount(lat["bin"], weights=lat["count"] * lat["k"], minlength=self.nbin) / np.maximum(
            self.modes, 1)
        mu = np.sqrt(lat["mu2"])  # (3, groups): the three lines of sight
        self.leg = {ell: legendre(ell, mu) for ell in range(0, 9, 2)}

    def average(self, pkmu, ells=ELLS_FIT):
        """(2l+1) <L_l(mu_a) P(k_n, mu_a)> over the modes of each bin and the three axes: pkmu(k, mu)."""
        lat = self.lat
        p = pkmu(np.broadcast_to(lat["k"], lat["mu2"].shape), np.sqrt(lat["mu2"]))
        out = {}
        for ell in ells:
            a = (self.leg[ell] * p).mean(0)
            out[ell] = (2 * ell + 1) * np.bincount(lat["bin"], weights=lat["count"] * a, minlength=self.nbin) / \
                np.maximum(self.modes, 1)
        return out

    def covariance(self, pkmu, ells=ELLS_FIT, single_los=False):
        """Gaussian Cov(P_l, P_l') per bin, the three lines of sight averaged (or one, z)."""
        lat = self.lat
        p = pkmu(np.broadcast_to(lat["k"], lat["mu2"].shape), np.sqrt(lat["mu2"]))
        if single_los:  # one axis: by the lattice's symmetry, the mean over the axes of A^2
            amp = {ell: (2 * ell + 1) * self.leg[ell] * p for ell in ells}
            prod = lambda a, b: (amp[a] * amp[b]).mean(0)
        else:
            amp = {ell: (2 * ell + 1) * (self.leg[ell] * p).mean(0) for ell in ells}
            prod = lambda a, b: amp[a] * amp[b]
        nk = np.maximum(self.modes / 2, 1)
        cov = np.zeros((self.nbin, len(ells), len(ells)))
        for i, a in enumerate(ells):
            for j, b in enumerate(ells):
                cov[:, i, j] = np.bincount(lat["bin"], weights=lat["count"] * prod(a, b),
                                           minlength=self.nbin) / np.maximum(self.modes, 1) / nk
        return cov


# --------------------------------------------------------------------------------------------------
# inputs


def load_box(x, z):
    zs = f"{z:g}"
    rows = [np.loadtxt(os.path.join(DATA, f"dir{x}", f"Pk_m_RS{a}_z={zs}.txt")) for a in range(3)]
    k = rows[0][:, 0]
    for r in rows:
        assert np.array_equal(r[:, 0], k)
    mean = np.mean(rows, axis=0)
    return k, {0: mean[:, 1], 2: mean[:, 2], 4: mean[:, 3]}, rows


def cosmologies():
    c = np.loadtxt(os.path.join(DATA, "cosmologies.txt"))
    names = "X Omega_m Omega_b h n_s sigma8 A_s D_z0.5 f_z0.5 fCAMB_z0.5 Pr_z0.5 D_z1 f_z1 fCAMB_z1 Pr_z1".split()
    return {int(r[0]): dict(zip(names, r)) for r in c}


def linear_table(x, z):
    path = os.path.join(DATA, f"plin_lh{x}_z{z:g}.dat")
    t = np.loadtxt(path)
    with open(path, "rb") as fh:
        digest = hashlib.sha1(fh.read()).hexdigest()
    return t[:, 0], t[:, 1], digest


def eft2_terms(x, z, f, plan_holder):
    """eft2's multipoles and templates on GRID (cached: the direct integration takes ~40 s)."""
    k_lin, p_lin, digest = linear_table(x, z)
    os.makedirs(CACHE, exist_ok=True)
    path = os.path.join(CACHE, f"eft2_lh{x}_z{z:g}.npz")
    if os.path.exists(path):
        c = np.load(path, allow_pickle=False)
        if str(c["digest"]) == digest and float(c["f"]) == f and np.array_equal(c["k"], GRID):
            cols = [str(s) for s in c["columns"]]
            return {n: c["values"][i] for i, n in enumerate(cols)}, [str(s) for s in c["header"]], 0.0
    if "plan" not in plan_holder:
        plan_holder["plan"] = pt.TwoLoopRsdPlan(GRID, "eft2", precision="fast", two_loop="basis")
    t0 = time.time()
    tab = plan_holder["plan"](linear=(k_lin, p_lin), f=f, terms=True, ells=ELLS_MODEL)
    seconds = time.time() - t0
    cols = list(tab.columns)
    np.savez(path, digest=digest, f=f, k=GRID, columns=np.array(cols), header=np.array(list(tab.header)),
             values=np.array([tab[c] for c in cols]))
    return {c: np.asarray(tab[c]) for c in cols}, list(tab.header), seconds


def header_value(header, pattern):
    for line in header:
        m = re.search(pattern, line)
        if m:
            return m.group(1)
    return None


# --------------------------------------------------------------------------------------------------
# models as functions P(k, mu)


def damping(k, mu, f, s2, ds2):
    return k**2 * ((1 + f * mu**2 * (2 + f)) * s2 + f**2 * mu**2 * (mu**2 - 1) * ds2)


def project(fun, k, ells):
    """(2l+1) int_0^1 L_l fun(k, mu) dmu on the nodes (fun vectorised over (k, mu))."""
    kk, mm = np.meshgrid(k, MU_NODES, indexing="ij")
    v = fun(kk, mm)
    return {ell: (2 * ell + 1) * (v * legendre(ell, mm)) @ MU_WEIGHTS for ell in ells}


class Eft2Model:
    """eft2 at any (k, mu): the IR-resummed linear part and the counterterm templates exactly, the
    loops (the rest of each multipole, smooth) as splines of the 40-point grid."""

    def __init__(self, cols, header, f, k_lin, p_lin):
        self.f = f
        self.s2 = float(header_value(header, r"Sigma\^2 = ([0-9.eE+-]+) \(Mpc/h\)\^2, dSigma"))
        self.ds2 = float(header_value(header, r"dSigma\^2 = ([0-9.eE+-]+)"))
        self.lnp = CubicSpline(np.log(k_lin), np.log(p_lin))
        k = GRID
        # P_nw and P_w at the grid points from the templates T_l_c2n = a P_nw + b P_w (exact: linear)
        rows_a, rows_b, rhs = [], [], []
        for n, name in enumerate(CT):
            for ell in (0, 2, 4):
                a = project(lambda kk, mm: -2 * kk**2 * mm ** (2 * n), k, [ell])[ell]
                b = project(lambda kk, mm: -2 * kk**2 * mm ** (2 * n) * np.exp(
                    -damping(kk, mm, f, self.s2, self.ds2)), k, [ell])[ell]
                rows_a.append(a)
                rows_b.append(b)
                rhs.append(cols[f"T{ell}_{name}"])
        a, b, rhs = np.array(rows_a), np.array(rows_b), np.array(rhs)
        sol = np.array([np.linalg.lstsq(np.column_stack([a[:, i], b[:, i]]), rhs[:, i], rcond=None)[0]
                        for i in range(len(k))])
        self.pnw_grid, self.pw_grid = sol[:, 0], sol[:, 1]
        fit = a * self.pnw_grid + b * self.pw_grid
        self.template_check = np.max(np.abs(fit - rhs) / np.max(np.abs(rhs), axis=1, keepdims=True))
        plin_grid = np.exp(self.lnp(np.log(k)))
        self.split_check = np.max(np.abs((self.pnw_grid + self.pw_grid) / plin_grid - 1)[k <= 0.35])
        self.lnpnw = CubicSpline(np.log(k), np.log(self.pnw_grid))
        lin_part = project(self.linear_ir2, k, ELLS_MODEL)
        self.rest = {ell: CubicSpline(np.log(k), cols[f"P{ell}"] - lin_part[ell]) for ell in ELLS_MODEL}
        self.ct1 = {name: {ell: CubicSpline(np.log(k), cols[f"T{ell}_{name}"]) for ell in ELLS_MODEL}
                    for name in CT1}
        # check: the analytic templates between the grid points against the library's at the grid
        self.ct_check = max(np.max(np.abs(project(self.template(name), k, [ell])[ell] - cols[f"T{ell}_{name}"])
                                   / np.max(np.abs(cols[f"T{ell}_{name}"])))
                            for name in CT + ("ctilde",) for ell in (0, 2, 4))

    def plin(self, k):
        return np.exp(self.lnp(np.log(k)))

    def pnw(self, k):
        return np.exp(self.lnpnw(np.log(k)))

    def p_ir(self, k, mu):
        pnw = self.pnw(k)
        return pnw + np.exp(-damping(k, mu, self.f, self.s2, self.ds2)) * (self.plin(k) - pnw)

    def linear_ir2(self, k, mu):
        x = damping(k, mu, self.f, self.s2, self.ds2)
        pnw = self.pnw(k)
        return (1 + self.f * mu**2) ** 2 * (pnw + np.exp(-x) * (1 + x + x * x / 2) * (self.plin(k) - pnw))

    def kaiser(self, k, mu):
        return (1 + self.f * mu**2) ** 2 * self.p_ir(k, mu)

    def base(self, k, mu):
        lnk = np.log(k)
        return self.linear_ir2(k, mu) + sum(self.rest[ell](lnk) * legendre(ell, mu) for ell in ELLS_MODEL)

    def template(self, name):
        if name in CT:
            n = CT.index(name)
            return lambda k, mu: -2 * k**2 * mu ** (2 * n) * self.p_ir(k, mu)
        if name in CT1:
            return lambda k, mu: sum(self.ct1[name][ell](np.log(k)) * legendre(ell, mu) for ell in ELLS_MODEL)
        if name == "ctilde":
            return lambda k, mu: -k**4 * self.f**4 * mu**4 * (1 + self.f * mu**2) ** 2 * self.p_ir(k, mu)
        if name == "sn":
            return lambda k, mu: np.ones_like(k)
        raise KeyError(name)


class EptModel:
    """The 1-loop EFT (pt.EptPlan, b1 = 1, other biases 0) on a fine grid, splined."""
    K = np.linspace(0.006, 0.32, 315)  # spacing 1e-3 h/Mpc: resolves the BAO

    def __init__(self, plan, f, k_lin, p_lin):
        terms = plan.terms(linear=(k_lin, p_lin))
        base = terms.multipoles(ells=ELLS_MODEL, b1=1.0, f=f)
        self.header = list(base.header)
        self.parts = {"base": {ell: np.asarray(base[f"P{ell}"]) for ell in ELLS_MODEL}}
        for name in ("alpha0", "alpha2", "alpha4"):
            t = terms.multipoles(ells=ELLS_MODEL, b1=1.0, f=f, **{name: 1.0})
            self.parts[name] = {ell: np.asarray(t[f"P{ell}"]) - self.parts["base"][ell] for ell in ELLS_MODEL}
        self.splines = {n: {ell: CubicSpline(self.K, v[ell]) for ell in ELLS_MODEL} for n, v in self.parts.items()}

    def function(self, name):
        if name == "sn":
            return lambda k, mu: np.ones_like(k)
        s = self.splines[name]
        return lambda k, mu: sum(s[ell](k) * legendre(ell, mu) for ell in ELLS_MODEL)


# --------------------------------------------------------------------------------------------------
# data: smoothed multipoles for the covariance


def running_mean(y, width):
    h = width // 2
    out = np.empty_like(y)
    for i in range(len(y)):
        lo, hi = max(0, i - h), min(len(y), i + h + 1)
        out[i] = y[lo:hi].mean()
    return out


def smooth_pkmu(kd, pd, kaiser_l, add):
    """P(k, mu) of the covariance: the measured multipoles as linear Kaiser x a running mean of
    their ratio to it (7 bins for P0, P2; 11 for P4), interpolated in k; plus `add` (shot noise)."""
    s = {}
    for ell, width in ((0, 7), (2, 7), (4, 11)):
        ratio = running_mean(pd[ell] / kaiser_l[ell], width)
        s[ell] = CubicSpline(kd, ratio * kaiser_l[ell])
    return lambda k, mu: sum(s[ell](k) * legendre(ell, mu) for ell in (0, 2, 4)) + add


# --------------------------------------------------------------------------------------------------
# fit


def fit(d, cov, base, temps, sel):
    """Linear least squares with the per-bin 2x2 covariance on the bins `sel`: parameters, their
    errors, chi2, dof and the model (with no templates: the chi2 of `base`)."""
    nb = np.flatnonzero(sel)
    a = np.zeros((2 * len(nb), len(temps)))
    y = np.zeros(2 * len(nb))
    for j, i in enumerate(nb):
        w = np.linalg.cholesky(np.linalg.inv(cov[i]))  # W W^T = C^-1: whitened rows W^T (d - m)
        y[2 * j:2 * j + 2] = w.T @ np.array([d[ell][i] - base[ell][i] for ell in ELLS_FIT])
        if temps:
            a[2 * j:2 * j + 2] = w.T @ np.array([[tp[ell][i] for tp in temps] for ell in ELLS_FIT])
    if not temps:
        return np.zeros(0), np.zeros(0), float(y @ y), len(y), base
    p = np.linalg.lstsq(a, y, rcond=None)[0]
    err = np.sqrt(np.diag(np.linalg.inv(a.T @ a)))
    r = y - a @ p
    model = {ell: base[ell] + sum(c * tp[ell] for c, tp in zip(p, temps)) for ell in ELLS_FIT}
    return p, err, float(r @ r), len(y) - len(p), model


def band_residual(kd, model, data, centre, sel_k):
    m = sel_k & (np.abs(kd - centre) <= HALF_BAND + 1e-9)
    return np.sum(model[m] - data[m]) / np.sum(data[m])


def chi2_sf(chi2, dof):
    from scipy.stats import chi2 as dist
    return float(dist.sf(chi2, dof))


# --------------------------------------------------------------------------------------------------


def main():
    cosmo = cosmologies()
    imax = int(np.floor(K_MAX / KF)) + 1  # bins 0 .. imax
    bins = Bins(imax)
    ept_plan = pt.EptPlan(EptModel.K, precision="fast", two_loop="direct")
    holder = {}
    lines = []
    say = lambda s="": (lines.append(s), print(s))
    info, results, gains, checks, boxes, lq = [], {}, {}, [], {}, {}
    eft2_seconds = 0.0

    for z in ZS:
        for x in BOXES:
            c = cosmo[x]
            f = float(c[f"f_z{z:g}"])
            k_lin, p_lin, _ = linear_table(x, z)
            kd, pd, _rows = load_box(x, z)
            assert np.allclose(kd[:imax], bins.kmean[1:imax + 1], rtol=1e-10), "bins are not [i, i+1) k_F"
            ib = np.arange(1, len(kd) + 1)  # bin index of each data row
            use = (kd >= K_MIN) & (kd <= K_MAX) & (ib <= imax)
            idx = ib[use]
            kk = kd[use]
            dat = {ell: pd[ell][use] for ell in (0, 2, 4)}

            cols, header, sec = eft2_terms(x, z, f, holder)
            eft2_seconds += sec
            method = "basis" if any("from basis tensors" in h for h in header) else "direct"
            resid = header_value(header, r"projection residual ([0-9.]+e-[0-9]+)") if method == "basis" else None
            em = Eft2Model(cols, header, f, k_lin, p_lin)
            checks.append((x, z, em.template_check, em.split_check, em.ct_check))
            ept = EptModel(ept_plan, f, k_lin, p_lin)

            # every template through the box's modes
            avg = lambda fun: {ell: v[idx] for ell, v in bins.average(fun).items()}
            tmpl = {"eft2": {"base": avg(em.base)}, "Kaiser": {"base": avg(em.kaiser)},
                    "1-loop": {"base": avg(ept.function("base"))}}
            for name in CT + CT1 + ("ctilde", "sn"):
                tmpl["eft2"][name] = avg(em.template(name))
            for name in CT + ("sn",):
                tmpl["Kaiser"][name] = tmpl["eft2"][name]
            for name in ("alpha0", "alpha2", "alpha4", "sn"):
                tmpl["1-loop"][name] = avg(ept.function(name))
            tmpl["eft2+1l"] = tmpl["eft2+ctilde"] = tmpl["eft2 c=0"] = tmpl["eft2"]

            # covariance: the box's smoothed multipoles, the Poisson noise V/N added (the data are
            # taken as noise-subtracted; see the docstring)
            kaiser_cont = project(em.kaiser, kk, (0, 2, 4))
            pk_cov = smooth_pkmu(kk, dat, kaiser_cont, P_SN)
            covs = {"single": bins.covariance(pk_cov, single_los=True)[idx], "avg": bins.covariance(pk_cov)[idx]}
            # the scatter of the three lines of sight about their mean, (1/2) sum_a (P^a - Pbar)^2,
            # measured and as the fully correlated Gaussian model predicts it, 3/2 (Var_1 - Var_avg)
            los = np.array([r[use][:, 1:3] for r in _rows])  # (3, bins, [P0, P2])
            scatter = ((los - los.mean(0)) ** 2).sum(0) / 2
            predicted = 1.5 * (np.diagonal(covs["single"], axis1=1, axis2=2) - np.diagonal(covs["avg"], axis1=1, axis2=2))
            boxes[(x, z)] = dict(kk=kk, dat=dat, tmpl=tmpl, covs=covs, scatter=scatter, predicted=predicted)
            info.append((x, z, f, method, resid, em.s2))

    # the 3-LOS covariance calibrated by the measured scatter of the lines of sight (per z, stacked
    # over the boxes): Var(Pbar) = Var_1 - (2/3) s^2 for three estimates of equal variance Var_1 whose
    # scatter about their mean has expectation s^2; s^2 = q(k) x the fully correlated prediction,
    # q the ratio measured / predicted summed over boxes and a window of +-8 bins; decorrelation
    # can only lower Var(P0bar) and raise Var(P2bar) below / above the fully correlated value, which
    # bounds the estimate (and the independent limit Var_1/3 and Var_1 bound it from both sides).
    for z in ZS:
        meas = sum(boxes[(x, z)]["scatter"] for x in BOXES)
        pred = sum(boxes[(x, z)]["predicted"] for x in BOXES)
        n = len(meas)
        q = np.array([[meas[max(0, i - 8):i + 9, j].sum() / pred[max(0, i - 8):i + 9, j].sum() for j in (0, 1)]
                      for i in range(n)])
        lq[z] = (boxes[(BOXES[0], z)]["kk"], q)
        for x in BOXES:
            bx = boxes[(x, z)]
            v1 = np.diagonal(bx["covs"]["single"], axis1=1, axis2=2)
            vfc = np.diagonal(bx["covs"]["avg"], axis1=1, axis2=2)
            v = v1 - (2 / 3) * q * bx["predicted"]
            v[:, 0] = np.clip(v[:, 0], v1[:, 0] / 3, vfc[:, 0])
            v[:, 1] = np.clip(v[:, 1], vfc[:, 1], v1[:, 1])
            fc = bx["covs"]["avg"]
            r = fc[:, 0, 1] / np.sqrt(fc[:, 0, 0] * fc[:, 1, 1])
            cal = np.zeros_like(fc)
            cal[:, 0, 0], cal[:, 1, 1] = v[:, 0], v[:, 1]
            cal[:, 0, 1] = cal[:, 1, 0] = r * np.sqrt(v[:, 0] * v[:, 1])
            bx["covs"]["calibrated"] = cal
            cov = bx["covs"]["single"]
            kk, dat, tmpl, covs = bx["kk"], bx["dat"], bx["tmpl"], bx["covs"]
            gains[(x, z)] = (kk, covs["avg"][:, 0, 0] / cov[:, 0, 0], covs["avg"][:, 1, 1] / cov[:, 1, 1],
                             cal[:, 0, 0] / cov[:, 0, 0], cal[:, 1, 1] / cov[:, 1, 1],
                             np.sqrt(cov[:, 0, 0]) / dat[0], np.sqrt(cov[:, 1, 1]) / np.abs(dat[2]))

            for vname, (cname, sn) in VARIANTS.items():
                for mname, (names, _) in MODELS.items():
                    tm = tmpl[mname]
                    if sn == "free":
                        names = names + ("sn",)
                        base = tm["base"]
                    else:
                        base = {ell: tm["base"][ell] + sn * tmpl["eft2"]["sn"][ell] for ell in ELLS_FIT}
                    for kfit in K_FITS:
                        sel = kk <= kfit + 1e-12
                        p, e, chi2, dof, model = fit(dat, covs[cname], base, [tm[n] for n in names], sel)
                        res = {ell: [band_residual(kk, model[ell], dat[ell], b, np.ones_like(kk, bool))
                                     for b in BANDS] for ell in ELLS_FIT}
                        results[(vname, mname, z, x, kfit)] = dict(p=dict(zip(names, p)), e=dict(zip(names, e)),
                                                                  chi2=chi2, dof=dof, res=res)

    # ---------------------------------------------------------------------------------------------
    say("# Quijote LH redshift-space matter multipoles vs eft2 (examples/rsd_quijote_lh.py)")
    say()
    say(f"pt-spectra {pt.__version__}; data github.com/murakoya/fsigma8_ML @ f2309c7 (Quijote LH boxes "
        f"{', '.join(map(str, BOXES))}, 1 Gpc/h, 512^3), P0 and P2 averaged over the three lines of sight; "
        f"fits on {K_MIN} <= k <= k_fit, P0 and P2 jointly, Gaussian covariance of one box and one line of "
        "sight (lattice modes), cosmology and f fixed.")
    say()
    say("## Boxes")
    say()
    say("| LH | Omega_m | Omega_b | h | n_s | sigma8 | f(0.5) | f(1) | eft2 2-loop terms | projection residual |")
    say("|---|---:|---:|---:|---:|---:|---:|---:|---|---:|")
    for x in BOXES:
        c = cosmo[x]
        m = [i for i in info if i[0] == x]
        say(f"| {x} | {c['Omega_m']:.4f} | {c['Omega_b']:.5f} | {c['h']:.4f} | {c['n_s']:.4f} | {c['sigma8']:.4f} | "
            f"{c['f_z0.5']:.4f} | {c['f_z1']:.4f} | {m[0][3]} | {m[0][4] or '> 3e-4'} |")
    say()
    say("Models (P(k, mu) through the box's modes; the templates fitted by linear least squares):")
    say()
    for mname, (names, desc) in MODELS.items():
        say(f"- **{mname}**: {desc}")
    say()
    say("Variants: **baseline** = Gaussian covariance of one line of sight (no reduction for the "
        "3-LOS average), the data taken as shot-noise subtracted (sn = 0); **3-LOS Gaussian gain** = the "
        "covariance of the 3-LOS mean of a Gaussian field with fully correlated amplitudes (linear-Kaiser "
        "limit: optimistic for P2, see Errors); **sn = V/N** = the model plus 7.45 (Mpc/h)^3 (the data "
        "not noise-subtracted); **sn free** = a free constant added to P(k, mu).")
    say()

    def stacked(vname, mname, z, kfit):
        r = [results[(vname, mname, z, x, kfit)] for x in BOXES]
        return r, sum(q["chi2"] for q in r), sum(q["dof"] for q in r)

    def per_box_table(title, vname, models, z):
        say(title)
        say()
        say("| model | k_fit | " + " | ".join(f"LH{x}" for x in BOXES) + " | stacked chi2/dof | p |")
        say("|---|---:|" + "---:|" * len(BOXES) + "---:|---:|")
        for mname in models:
            for kfit in K_FITS:
                r, chi2, dof = stacked(vname, mname, z, kfit)
                say(f"| {mname} | {kfit} | " + " | ".join(f"{q['chi2'] / q['dof']:.2f}" for q in r)
                    + f" | {chi2:.0f}/{dof} = {chi2 / dof:.2f} | {chi2_sf(chi2, dof):.2g} |")
        say()

    for z in ZS:
        say(f"## z = {z:g}")
        say()
        per_box_table("### chi2/dof per box (P0 + P2, baseline)", "baseline", MODELS, z)
        say("### stacked chi2/dof (all boxes) of the error and shot-noise variants")
        say()
        say("| variant | model | " + " | ".join(f"k_fit {kf}" for kf in K_FITS) + " |")
        say("|---|---|" + "---:|" * len(K_FITS))
        for v in VARIANTS:
            for mname in MODELS:
                cells = []
                for kfit in K_FITS:
                    _, chi2, dof = stacked(v, mname, z, kfit)
                    cells.append(f"{chi2:.0f}/{dof} = {chi2 / dof:.2f}")
                say(f"| {v} | {mname} | " + " | ".join(cells) + " |")
        say()
        per_box_table("### chi2/dof per box with the calibrated 3-LOS covariance", "3-LOS calibrated",
                      [m for m in MODELS if m != "eft2 c=0"], z)
        for vname, kfit in [("baseline", kf) for kf in K_FITS] + [("3-LOS calibrated", 0.2)]:
            say(f"### model/data - 1, mean over the {len(BOXES)} boxes +- scatter/sqrt({len(BOXES)}) "
                f"({vname}, k_fit = {kfit}; bands k +- {HALF_BAND}; * = beyond k_fit)")
            say()
            say("| model | ell | " + " | ".join(f"k = {b}" for b in BANDS) + " |")
            say("|---|---:|" + "---:|" * len(BANDS))
            for mname in MODELS:
                for ell in ELLS_FIT:
                    v = np.array([results[(vname, mname, z, x, kfit)]["res"][ell] for x in BOXES])
                    m, sd = v.mean(0), v.std(0, ddof=1) / np.sqrt(len(BOXES))
                    say(f"| {mname} | {ell} | " + " | ".join(
                        f"{100 * a:+.2f} +- {100 * b:.2f}%" + ("" if bc <= kfit + 1e-9 else " *")
                        for a, b, bc in zip(m, sd, BANDS)) + " |")
            say()
        say("### fitted parameters (baseline, k_fit = 0.2; sn from the 'sn free' variant): mean over boxes "
            "+- scatter/sqrt(N) [mean of the per-box fit errors]")
        say()
        say("| model | parameter | value |")
        say("|---|---|---|")
        for mname, (names, _) in MODELS.items():
            for vname, ns in (("baseline", names), ("sn free", ("sn",))):
                for n in ns:
                    v = np.array([results[(vname, mname, z, x, 0.2)]["p"][n] for x in BOXES])
                    e = np.array([results[(vname, mname, z, x, 0.2)]["e"][n] for x in BOXES])
                    unit = {"sn": "(Mpc/h)^3", "ctilde": "(Mpc/h)^4"}.get(n, "(Mpc/h)^2")
                    say(f"| {mname} | {n} | {v.mean():+.3g} +- {v.std(ddof=1) / np.sqrt(len(v)):.2g} "
                        f"[{e.mean():.2g}] {unit} |")
        say()

    say("## Errors: the line-of-sight average")
    say()
    say("Variance of the 3-LOS mean over that of one LOS: fully correlated Gaussian amplitudes (fc) and "
        "calibrated by the measured scatter of the three lines of sight (cal; q = measured / fc-predicted "
        "scatter, stacked over the boxes, +-8 bins); and the baseline (one-LOS) 1-sigma per k_F bin "
        "relative to the data (mean over boxes):")
    say()
    say("| z | k | q(P0) | q(P2) | Var(P0) fc | Var(P2) fc | Var(P0) cal | Var(P2) cal | sigma(P0)/P0 | sigma(P2)/P2 |")
    say("|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|")
    for z in ZS:
        kq, q = lq[z]
        for b in BANDS:
            rows = []
            for x in BOXES:
                kk, g0, g2, c0, c2, s0, s2 = gains[(x, z)]
                i = np.argmin(np.abs(kk - b))
                rows.append((kk[i], g0[i], g2[i], c0[i], c2[i], s0[i], s2[i]))
            r = np.mean(rows, axis=0)
            i = np.argmin(np.abs(kq - b))
            say(f"| {z:g} | {r[0]:.3f} | {q[i, 0]:.2f} | {q[i, 1]:.2f} | {r[1]:.2f} | {r[2]:.2f} | {r[3]:.2f} | "
                f"{r[4]:.2f} | {100 * r[5]:.1f}% | {100 * r[6]:.1f}% |")
    say()
    say(f"The baseline uses the one-LOS variance (an upper bound on the Gaussian variance of the mean "
        f"of three equally distributed estimates). The fc ratio assumes the three redshift-space "
        f"amplitudes of a mode are scaled copies (exact in linear theory); nonlinear velocities "
        f"decorrelate them, which lowers the P0 ratio but raises the P2 one (the isotropic part no "
        f"longer cancels in sum_a L2(mu_a) = 0): q(P0) > 1 and q(P2) < 1 measure that. The calibrated "
        f"covariance (Var_1 - 2/3 q s2_fc, clipped to the physical range, P0-P2 correlation of fc) "
        f"rests on the Gaussian one-LOS variance: non-Gaussian terms are in none of them. The "
        f"covariance's P(k, mu) includes the Poisson noise V/N = {P_SN:.2f} (Mpc/h)^3.")
    say()
    say("## Checks")
    say()
    worst = np.max(np.array([c[2:] for c in checks]), axis=0)
    say(f"- eft2's c-templates reproduced from the recovered P_nw, P_w to {worst[0]:.1e} (of max|T|) at the grid "
        f"points; P_nw + P_w = the linear table to {worst[1]:.1e} (k <= 0.35); analytic templates vs the "
        f"library's: {worst[2]:.1e}.")
    say(f"- the data's k column is the lattice mean of the bins [i, i+1) k_F (asserted to 1e-10).")
    say(f"- eft2: {sum(1 for i in info if i[3] == 'basis')} spectra from the basis tensors, "
        f"{sum(1 for i in info if i[3] == 'direct')} integrated directly (refused by the basis); "
        f"eft2 time this run {eft2_seconds:.0f} s (0 when cached); total {time.time() - T_START:.0f} s.")
    os.makedirs(OUT, exist_ok=True)
    with open(os.path.join(OUT, "rsd_quijote_lh.md"), "w") as fh:
        fh.write("\n".join(lines) + "\n")


if __name__ == "__main__":
    sys.exit(main())
