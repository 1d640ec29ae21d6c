#!/usr/bin/env python3
"""Independent numpy/scipy reference values of the tree-level galaxy bispectrum in redshift space.

Written from DEFINITIONS.md in this folder (not from FolpsD's or pt-spectra's code). Units: k in h/Mpc,
P in (Mpc/h)^3, B in (Mpc/h)^6, n_bar in (h/Mpc)^3, lengths in Mpc/h.

Tables (each with a '#' header stating every parameter, the linear spectrum and the accuracy):
  ref_unbinned.txt       B0, B2, B4 (Legendre on the largest side k3) at 24 triangles, several models
  ref_real_space.txt     f = 0: B0 against the closed form, B2 = B4 = 0
  ref_sugiyama.txt       B_{l1 l2 L}(k1, k2), 000 110 220 202 022 112 (+ 112 with FolpsD's weight)
  ref_bins_nseries.txt   bin averages over continuous shells of width 0.01 (the 62 Nseries bins)
  ref_box.txt            exact averages over the discrete modes of a periodic box, plain and as the
                         Philcox (2021) estimator normalises them (Delta_abc), and continuous shells
Usage: python3 make_reference.py [--only NAME ...] [--check-tripolar]
Needs numpy, scipy (and sympy for --check-tripolar).
"""
import argparse
import os
import sys
import time

import numpy as np
from scipy.interpolate import CubicSpline
from scipy.spatial import ConvexHull, Delaunay, HalfspaceIntersection
from scipy.optimize import linprog

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.normpath(os.path.join(HERE, "..", "..", ".."))
LINEAR = os.path.join(ROOT, "pt-spectra", "data", "linear_pk_gm2012_z0.5.dat")


# ----------------------------------------------------------------------------------------------
# Linear spectrum
# ----------------------------------------------------------------------------------------------
class Linear:
    """P(k) from a two-column table: cubic spline (not-a-knot) in (ln k, ln P); P(0) = 0; power laws
    outside the table (slope of the end intervals)."""

    def __init__(self, path=None, k=None, p=None):
        if path is not None:
            k, p = np.loadtxt(path, unpack=True)
            self.path = path
            self.header = [l.rstrip() for l in open(path) if l.startswith("#")]
        else:
            self.path, self.header = "(arrays)", []
        self.k, self.p = np.asarray(k, float), np.asarray(p, float)
        self.lk, self.lp = np.log(self.k), np.log(self.p)
        self.spline = CubicSpline(self.lk, self.lp)
        self.slope_lo = (self.lp[1] - self.lp[0]) / (self.lk[1] - self.lk[0])
        self.slope_hi = (self.lp[-1] - self.lp[-2]) / (self.lk[-1] - self.lk[-2])

    def __call__(self, k):
        k = np.asarray(k, float)
        out = np.zeros_like(k)
        pos = k > 0
        lk = np.log(np.where(pos, k, 1.0))
        lo = lk < self.lk[0]
        hi = lk > self.lk[-1]
        mid = ~(lo | hi)
        lp = np.empty_like(lk)
        lp[mid] = self.spline(lk[mid])
        lp[lo] = self.lp[0] + self.slope_lo * (lk[lo] - self.lk[0])
        lp[hi] = self.lp[-1] + self.slope_hi * (lk[hi] - self.lk[-1])
        out[pos] = np.exp(lp[pos])
        return out


def header_value(lin, key):
    for line in lin.header:
        for tok in line.replace("#", " ").split():
            if tok.startswith(key + "="):
                return float(tok.split("=")[1])
    raise KeyError(key)


# ----------------------------------------------------------------------------------------------
# Model (DEFINITIONS.md (a)-(c), (f))
# ----------------------------------------------------------------------------------------------
DEFAULTS = dict(b1=1.0, b2=0.0, bs=0.0, c1=0.0, f=0.0, b_shot=1.0, p_shot=0.0, a_shot=0.0,
                n_bar=np.inf, fog="none", sigma_fog=0.0, q_par=1.0, q_perp=1.0,
                fmu_shot=1.0, ir=None, fog_on_shot=False)


def model(**kw):
    m = dict(DEFAULTS)
    for key in kw:
        if key not in m:
            raise KeyError(f"unknown model parameter {key}")
    m.update(kw)
    return m


def describe(m):
    keys = ["b1", "b2", "bs", "c1", "f", "b_shot", "p_shot", "a_shot", "n_bar", "fog", "sigma_fog",
            "q_par", "q_perp"]
    s = ", ".join(f"{k} = {m[k]}" for k in keys)
    if m["fmu_shot"] != 1.0:
        s += f", f mu^2 shot coefficient = {m['fmu_shot']}"
    if m["fog_on_shot"]:
        s += ", FoG also on the (1/n_bar) Z1 P terms"
    s += ", IR: " + ("none" if m["ir"] is None else m["ir"]["describe"])
    return s


def bispectrum(lin, m, k1, k2, k3, km1, km2, km3, d12, d23, d31):
    """B at observed sides: magnitudes k_i, k_i*mu_i (km_i) and dot products d_ij = k_i.k_j, all in the
    observed (fiducial) frame; line of sight n. Returns B_obs [(Mpc/h)^6]."""
    qp, qt = m["q_par"], m["q_perp"]
    # true-frame quantities (DEFINITIONS (f)): k_par -> k_par/q_par, k_perp -> k_perp/q_perp
    def true_mag(k, km):
        return np.sqrt(km * km / qp**2 + (k * k - km * km) / qt**2)

    def true_dot(ka, kb, d):
        return ka * kb / qp**2 + (d - ka * kb) / qt**2

    K = [true_mag(k1, km1), true_mag(k2, km2), true_mag(k3, km3)]
    KM = [km1 / qp, km2 / qp, km3 / qp]               # k_i mu_i in the true frame
    D = {(0, 1): true_dot(km1, km2, d12), (1, 2): true_dot(km2, km3, d23), (2, 0): true_dot(km3, km1, d31)}
    f, b1 = m["f"], m["b1"]
    MU2 = [(KM[i] / K[i]) ** 2 for i in range(3)]
    # linear spectra per leg (IR: P_nw + exp(-k^2 Sigma_tot^2(mu)) (P - P_nw))
    P = []
    for i in range(3):
        p = lin(K[i])
        if m["ir"] is not None:
            ir = m["ir"]
            pnw = ir["pnw"](K[i])
            s2 = (1 + f * MU2[i] * (2 + f)) * ir["Sigma2"] + f * f * MU2[i] * (MU2[i] - 1) * ir["dSigma2"]
            p = pnw + np.exp(-K[i] ** 2 * s2) * (p - pnw)
        P.append(p)
    Z1 = [b1 + f * MU2[i] for i in range(3)]                       # inside Z2
    Z1e = [Z1[i] - m["c1"] * K[i] ** 2 * MU2[i] for i in range(3)]  # external legs

    def z2(i, j):
        ki, kj, d = K[i], K[j], D[(i, j)]
        x = d / (ki * kj)
        r = ki / kj + kj / ki
        F2 = 5.0 / 7.0 + 0.5 * x * r + 2.0 / 7.0 * x * x
        G2 = 3.0 / 7.0 + 0.5 * x * r + 4.0 / 7.0 * x * x
        kmu12 = KM[i] + KM[j]
        k12sq = ki * ki + kj * kj + 2.0 * d
        mu12sq = np.where(k12sq > 0, kmu12 * kmu12 / np.where(k12sq > 0, k12sq, 1.0), 0.0)
        S2 = x * x - 1.0 / 3.0
        return (b1 * F2 + f * mu12sq * G2
                + 0.5 * f * kmu12 * (KM[i] / ki**2 * Z1[j] + KM[j] / kj**2 * Z1[i])
                + 0.5 * m["b2"] + m["bs"] * S2)

    bdet = 2.0 * (z2(0, 1) * Z1e[0] * Z1e[1] * P[0] * P[1]
                  + z2(1, 2) * Z1e[1] * Z1e[2] * P[1] * P[2]
                  + z2(2, 0) * Z1e[2] * Z1e[0] * P[2] * P[0])
    x = sum(KM[i] ** 2 for i in range(3))
    s = m["sigma_fog"]
    if m["fog"] == "none":
        w = 1.0
    elif m["fog"] == "lorentzian2":
        w = (1.0 + 0.5 * x * s * s) ** -2
    elif m["fog"] == "lorentzian1":
        w = 1.0 / (1.0 + 0.5 * x * s * s)
    elif m["fog"] == "gaussian":
        w = np.exp(-0.5 * x * s * s)
    else:
        raise ValueError(m["fog"])
    b = w * bdet
    if np.isfinite(m["n_bar"]):
        nb = m["n_bar"]
        ws = w if m["fog_on_shot"] else 1.0
        for i in range(3):
            b = b + ws * (b1 * m["b_shot"] + m["fmu_shot"] * (1 + m["p_shot"]) * f * MU2[i]) * Z1e[i] * P[i] / nb
        b = b + (1 + m["a_shot"]) / nb**2
    return b / (qp * qt * qt) ** 2


# ----------------------------------------------------------------------------------------------
# Orientation averages
# ----------------------------------------------------------------------------------------------
def legendre(ell, x):
    if ell == 0:
        return np.ones_like(x)
    if ell == 2:
        return 0.5 * (3 * x * x - 1)
    if ell == 4:
        return (35 * x**4 - 30 * x * x + 3) / 8
    raise ValueError(ell)


def orientation_nodes(n_mu, n_phi):
    mu, wmu = np.polynomial.legendre.leggauss(n_mu)
    phi = 2 * np.pi * np.arange(n_phi) / n_phi
    wphi = np.full(n_phi, 1.0 / n_phi)
    MU, PHI = np.meshgrid(mu, phi, indexing="ij")
    W = np.outer(wmu / 2, wphi)
    return MU.ravel(), PHI.ravel(), W.ravel()   # weights sum to 1 (average over the sphere)


def triangle_frame(ka, kb, kc, mu, phi):
    """Side a along z', side b in the x'z' plane (k_a + k_b + k_c = 0); n at (mu, phi) about k_a.
    Returns (k_i mu_i) for a, b, c and the dot products d_ab, d_bc, d_ca."""
    xab = (kc * kc - ka * ka - kb * kb) / (2 * ka * kb)
    xab = np.clip(xab, -1.0, 1.0)
    sab = np.sqrt(1 - xab * xab)
    s = np.sqrt(np.clip(1 - mu * mu, 0, None))
    kma = ka * mu
    kmb = kb * (xab * mu + sab * s * np.cos(phi))
    kmc = -(kma + kmb)
    dab = ka * kb * xab
    dbc = -(dab + kb * kb)     # k_b.k_c = -k_b.(k_a + k_b)
    dca = -(ka * ka + dab)
    return kma, kmb, kmc, dab, dbc, dca


def multipoles_at(lin, m, k1, k2, k3, n_mu=48, n_phi=48, ells=(0, 2, 4)):
    """Scoccimarro B_ell with the Legendre polynomial on side k3 (DEFINITIONS (d)); k arrays (N,)."""
    k1, k2, k3 = (np.atleast_1d(np.asarray(v, float))[:, None] for v in (k1, k2, k3))
    MU, PHI, W = orientation_nodes(n_mu, n_phi)
    # frame: a = 3 (Legendre side), b = 1, c = 2
    km3, km1, km2, d31, d12, d23 = triangle_frame(k3, k1, k2, MU[None, :], PHI[None, :])
    B = bispectrum(lin, m, k1, k2, k3, km1, km2, km3, d12, d23, d31)
    return np.array([(2 * l + 1) * np.sum(B * legendre(l, MU)[None, :] * W[None, :], axis=1) for l in ells])


def sugiyama_at(lin, m, k1, k2, n_mu=24, n_phi=32, panels=48, per_panel=16, folpsd_112=False):
    """B_{l1 l2 L}(k1, k2) (DEFINITIONS (e)) for 000 110 220 202 022 112 (and FolpsD's 112 weight);
    the x = k1.k2 integral done over k3 in [|k1-k2|, k1+k2] (dx = k3 dk3/(k1 k2)) on Gauss-Legendre
    panels, mu1 Gauss-Legendre, phi trapezoid."""
    out = []
    mu, wmu = np.polynomial.legendre.leggauss(n_mu)
    phi = 2 * np.pi * np.arange(n_phi) / n_phi
    gx, gw = np.polynomial.legendre.leggauss(per_panel)
    for a, b in zip(np.atleast_1d(k1), np.atleast_1d(k2)):
        lo, hi = abs(a - b), a + b
        edges = lo + (hi - lo) * (np.arange(panels + 1) / panels) ** 2   # clustered at k3 -> |k1-k2|
        k3 = np.concatenate([0.5 * (edges[i + 1] - edges[i]) * gx + 0.5 * (edges[i + 1] + edges[i])
                             for i in range(panels)])
        w3 = np.concatenate([0.5 * (edges[i + 1] - edges[i]) * gw for i in range(panels)])
        x = (k3 * k3 - a * a - b * b) / (2 * a * b)
        wx = w3 * k3 / (a * b)                      # dx
        X, MU, PHI = np.meshgrid(x, mu, phi, indexing="ij")
        WT = (wx[:, None, None] * wmu[None, :, None] / n_phi) / 4.0   # (1/8pi) dx dmu dphi = (1/4) dx dmu dphi/(2pi)
        K3 = np.sqrt(a * a + b * b + 2 * a * b * X)
        s = np.sqrt(1 - MU * MU)
        sx = np.sqrt(np.clip(1 - X * X, 0, None))
        mu2 = MU * X + s * sx * np.cos(PHI)
        km1, km2 = a * MU, b * mu2
        km3 = -(km1 + km2)
        d12 = a * b * X
        d23 = -(d12 + b * b)
        d31 = -(a * a + d12)
        B = bispectrum(lin, m, a, b, K3, km1, km2, km3, d12, d23, d31)
        w = {"000": 1.0, "110": 3 * X, "220": 5 * legendre(2, X), "202": 5 * legendre(2, MU),
             "022": 5 * legendre(2, mu2), "112": 3 * (3 * MU * mu2 - X)}
        w["112F"] = 3 * ((3 * MU * MU - 1) * X + 2 * np.sqrt(3) * MU * s * sx * np.cos(PHI))
        out.append([np.sum(B * w[key] * WT) for key in ("000", "110", "220", "202", "022", "112", "112F")])
    return np.array(out)


# ----------------------------------------------------------------------------------------------
# Bin averages over continuous shells (DEFINITIONS (d)): polytope = box of shells cut by the
# triangle inequalities, split into tetrahedra, collapsed Gauss-Legendre on each.
# ----------------------------------------------------------------------------------------------
def bin_polytope(ea, eb, ec):
    (a0, a1), (b0, b1), (c0, c1) = ea, eb, ec
    # half-spaces A x + b <= 0
    hs = np.array([
        [-1, 0, 0, a0], [1, 0, 0, -a1], [0, -1, 0, b0], [0, 1, 0, -b1], [0, 0, -1, c0], [0, 0, 1, -c1],
        [-1, -1, 1, 0], [1, -1, -1, 0], [-1, 1, -1, 0]], float)
    A, bb = hs[:, :3], hs[:, 3]
    norm = np.linalg.norm(A, axis=1)
    res = linprog([0, 0, 0, -1], A_ub=np.hstack([A, norm[:, None]]), b_ub=-bb,
                  bounds=[(None, None)] * 3 + [(0, None)], method="highs")
    if res.status != 0 or res.x[3] <= 1e-12:
        return None
    inner = res.x[:3]
    verts = HalfspaceIntersection(hs, inner).intersections
    hull = ConvexHull(verts)
    verts = verts[hull.vertices]
    tets = Delaunay(verts).simplices
    return verts, tets


def tet_rule(n):
    """Collapsed (Duffy) Gauss-Legendre rule on the unit tetrahedron, n^3 nodes (barycentric-free)."""
    g, w = np.polynomial.legendre.leggauss(n)
    g, w = 0.5 * (g + 1), 0.5 * w
    U, V, Wc = np.meshgrid(g, g, g, indexing="ij")
    WU, WV, WW = np.meshgrid(w, w, w, indexing="ij")
    x = U
    y = V * (1 - U)
    z = Wc * (1 - U) * (1 - V)
    jac = (1 - U) ** 2 * (1 - V)
    return np.stack([x.ravel(), y.ravel(), z.ravel()], 1), (WU * WV * WW * jac).ravel()


def bin_nodes(ea, eb, ec, n):
    poly = bin_polytope(ea, eb, ec)
    if poly is None:
        return None
    verts, tets = poly
    ref, wref = tet_rule(n)
    pts, wts = [], []
    for t in tets:
        v0, v1, v2, v3 = verts[t]
        J = np.stack([v1 - v0, v2 - v0, v3 - v0], 1)
        pts.append(v0 + ref @ J.T)
        wts.append(wref * abs(np.linalg.det(J)))
    pts, wts = np.concatenate(pts), np.concatenate(wts)
    return pts, wts * pts[:, 0] * pts[:, 1] * pts[:, 2]


def bin_average(lin, m, ea, eb, ec, n_shell=6, n_mu=16, n_phi=20):
    nodes = bin_nodes(ea, eb, ec, n_shell)
    if nodes is None:
        return None
    pts, w = nodes
    out = np.zeros(3)
    chunk = 4000
    for s in range(0, len(w), chunk):
        bl = multipoles_at(lin, m, pts[s:s + chunk, 0], pts[s:s + chunk, 1], pts[s:s + chunk, 2],
                           n_mu=n_mu, n_phi=n_phi)
        out += bl @ w[s:s + chunk]
    return out / w.sum()


# ----------------------------------------------------------------------------------------------
# Periodic box: exact sums over discrete modes (DEFINITIONS (d))
# ----------------------------------------------------------------------------------------------
def box_modes(kf, lo, hi):
    nmax = int(np.ceil(hi / kf)) + 1
    r = np.arange(-nmax, nmax + 1)
    n = np.stack(np.meshgrid(r, r, r, indexing="ij"), -1).reshape(-1, 3)
    kk = kf * np.sqrt((n * n).sum(1))
    sel = (kk >= lo) & (kk < hi)
    return n[sel]


def box_bin(lin, m, kf, ea, eb, ec, ells=(0, 2, 4)):
    """Ordered triples k1 in a, k2 in b, k3 = -(k1+k2) in c (n = z). Returns the plain average
    (2l+1)<B L_l(mu3)>, the Philcox-estimator value p = F^-1 q with the Delta_abc templates, N0,
    N_l/N0 and the number of triples."""
    na, nb = box_modes(kf, *ea), box_modes(kf, *eb)
    iso_bc = ea != eb and eb == ec
    iso_ab = ea == eb and eb != ec
    equi = ea == eb == ec
    S = {}
    q = np.zeros(3)
    F = np.zeros((3, 3))
    Nl = np.zeros(3)
    N0 = 0
    plain = np.zeros(3)
    csize = max(1, 2_000_000 // max(len(nb), 1))
    for s in range(0, len(na), csize):
        v1 = na[s:s + csize][:, None, :]
        v2 = nb[None, :, :]
        v3 = -(v1 + v2)
        n3 = np.sqrt((v3 * v3).sum(-1)) * kf
        ok = (n3 >= ec[0]) & (n3 < ec[1])
        if not ok.any():
            continue
        v1 = np.broadcast_to(v1, v3.shape)[ok] * kf
        v2 = np.broadcast_to(v2, v3.shape)[ok] * kf
        v3 = v3[ok] * kf
        k1, k2, k3 = (np.sqrt((v * v).sum(-1)) for v in (v1, v2, v3))
        km1, km2, km3 = v1[:, 2], v2[:, 2], v3[:, 2]
        d12, d23, d31 = (v1 * v2).sum(-1), (v2 * v3).sum(-1), (v3 * v1).sum(-1)
        B = bispectrum(lin, m, k1, k2, k3, km1, km2, km3, d12, d23, d31)
        mu1, mu2, mu3 = km1 / k1, km2 / k2, km3 / k3
        x23 = d23 / (k2 * k3)
        x12 = d12 / (k1 * k2)
        x31 = d31 / (k3 * k1)
        N0 += len(B)
        T = []
        for i, l in enumerate(ells):
            plain[i] += (2 * l + 1) * np.sum(B * legendre(l, mu3))
            if equi:
                Nl[i] += np.sum(legendre(l, x23))
                T.append(2 * (legendre(l, mu1) + legendre(l, mu2) + legendre(l, mu3)))
            elif iso_bc:
                Nl[i] += np.sum(legendre(l, x23))
                T.append(legendre(l, mu2) + legendre(l, mu3))
            elif iso_ab:
                T.append(2 * legendre(l, mu3))
            else:
                T.append(legendre(l, mu3))
        T = np.array(T)
        q += T @ B
        F += T @ T.T
    if N0 == 0:
        return None
    ratio = Nl / N0
    if equi:
        delta = 2 * (1 + 2 * ratio)
    elif iso_bc:
        delta = 1 + ratio
    elif iso_ab:
        delta = np.full(3, 2.0)
    else:
        delta = np.ones(3)
    qd = q / delta
    Fd = F / np.outer(delta, delta)
    p = np.linalg.solve(Fd, qd)
    return plain / N0, p, N0, ratio


# ----------------------------------------------------------------------------------------------
# Table writers
# ----------------------------------------------------------------------------------------------
TRIANGLES = [  # k1 <= k2 <= k3 [h/Mpc], squeezed -> equilateral -> flattened
    (0.005, 0.05, 0.052), (0.005, 0.10, 0.101), (0.01, 0.10, 0.10), (0.01, 0.15, 0.155),
    (0.02, 0.08, 0.09), (0.02, 0.10, 0.11), (0.02, 0.02, 0.02), (0.03, 0.05, 0.07),
    (0.03, 0.12, 0.14), (0.04, 0.06, 0.08), (0.05, 0.05, 0.05), (0.05, 0.05, 0.07),
    (0.05, 0.08, 0.10), (0.05, 0.05, 0.0999), (0.06, 0.10, 0.12), (0.07, 0.07, 0.07),
    (0.08, 0.10, 0.15), (0.10, 0.10, 0.10), (0.10, 0.10, 0.15), (0.10, 0.12, 0.20),
    (0.12, 0.15, 0.16), (0.15, 0.15, 0.15), (0.10, 0.15, 0.249), (0.20, 0.20, 0.20),
]


def std_models(lin):
    f = header_value(lin, "growth_rate_f(z)")
    base = dict(b1=2.0, b2=-0.5, bs=-0.3, f=f)
    return f, [
        ("tree", model(**base)),
        ("tree_fog_lor2", model(**base, fog="lorentzian2", sigma_fog=4.0)),
        ("tree_fog_lor1", model(**base, fog="lorentzian1", sigma_fog=4.0)),
        ("tree_fog_gauss", model(**base, fog="gaussian", sigma_fog=4.0)),
        ("tree_ct_shot", model(**base, c1=5.0, n_bar=3e-4, b_shot=1.1, p_shot=0.2, a_shot=0.3)),
        ("tree_ap", model(**base, q_par=1.03, q_perp=0.98)),
        ("tree_all", model(**base, fog="lorentzian2", sigma_fog=4.0, c1=5.0, n_bar=3e-4, b_shot=1.1,
                           p_shot=0.2, a_shot=0.3, q_par=1.03, q_perp=0.98)),
        ("tree_all_fogshot", model(**base, fog="lorentzian2", sigma_fog=4.0, c1=5.0, n_bar=3e-4, b_shot=1.1,
                                   p_shot=0.2, a_shot=0.3, q_par=1.03, q_perp=0.98, fog_on_shot=True)),
    ]


def lin_header(lin):
    return [f"# linear spectrum: {os.path.relpath(lin.path, ROOT)} (first header lines below), cubic "
            "spline in (ln k, ln P), power-law ends"] + ["#   " + h.lstrip("# ") for h in lin.header[:3]]


def models_header(lin, f, models):
    """Header lines: the linear spectrum and every model's parameters."""
    return [*lin_header(lin), f"# models (bias in velocileptors' convention; f = {f}):"] + [
        f"#   {name}: {describe(m)}" for name, m in models]


def write(path, lines, rows, fmt):
    with open(path, "w") as fh:
        for l in lines:
            fh.write(l.rstrip() + "\n")
        for r in rows:
            fh.write(fmt.format(*r) + "\n")
    print("wrote", os.path.relpath(path, ROOT), len(rows), "rows", file=sys.stderr)


def triangle_rows(lin, models):
    """Rows (model, k1, k2, k3, B0, B2, B4, err x 3) at TRIANGLES, 64 x 64 orientation nodes, the error
    the change from 32 x 32; and the largest error / |B0| per model."""
    tri = np.array(TRIANGLES)
    rows, errs = [], {}
    for name, m in models:
        hi = multipoles_at(lin, m, tri[:, 0], tri[:, 1], tri[:, 2], n_mu=64, n_phi=64)
        lo = multipoles_at(lin, m, tri[:, 0], tri[:, 1], tri[:, 2], n_mu=32, n_phi=32)
        errs[name] = np.max(np.abs(hi - lo) / np.abs(hi[0])[None, :])
        for i, t in enumerate(TRIANGLES):
            rows.append((name, *t, *hi[:, i], *np.abs(hi - lo)[:, i]))
    return rows, errs


def table_unbinned(lin):
    f, models = std_models(lin)
    rows, errs = triangle_rows(lin, models)
    hdr = [
        "# Tree-level redshift-space galaxy bispectrum multipoles B0, B2, B4 (Scoccimarro et al. 1999) at",
        "# single triangles, Legendre polynomial on the LARGEST side k3, average over all orientations",
        "# (DEFINITIONS.md (a)-(d), (f) in this folder). Independent numpy code: make_reference.py.",
        *models_header(lin, f, models)]
    hdr += [
        "# fog: lorentzian2 = (1 + x s^2/2)^-2, lorentzian1 = (1 + x s^2/2)^-1 (FolpsD 'lor'),",
        "#   gaussian = exp(-x s^2/2), x = sum_i k_i^2 mu_i^2 (true frame), s = sigma_fog [Mpc/h]; on the deterministic",
        "#   part only (FolpsD), or also on the (1/n_bar) Z1 P terms where the model says so (pt-spectra c039246)",
        "# stochastic: (1/n_bar) sum_i [b1 b_shot + (1 + p_shot) f mu_i^2] Z1(k_i) P(k_i) + (1 + a_shot)/n_bar^2",
        "# c1 [(Mpc/h)^2]: Z1 -> Z1 - c1 k^2 mu^2 in the external legs; AP: q_par, q_perp, sides observed",
        "# quadrature: Gauss-Legendre 64 in mu3 x trapezoid 64 in phi; err_* = |64x64 - 32x32|",
        "#   (exact for the polynomial models; max err/|B0| per model: "
        + ", ".join(f"{k} {v:.1e}" for k, v in errs.items()) + ")",
        "# units: k [h/Mpc], B [(Mpc/h)^6]",
        "# columns: model k1 k2 k3 B0 B2 B4 err_B0 err_B2 err_B4",
    ]
    write(os.path.join(HERE, "ref_unbinned.txt"), hdr, rows,
          "{} {:.4f} {:.4f} {:.4f} {: .10e} {: .10e} {: .10e} {:.1e} {:.1e} {:.1e}")



NSERIES_BINS = ("111 112 122 123 133 134 144 145 155 156 166 167 177 222 223 224 233 234 235 244 245 246 "
                "255 256 257 266 267 277 333 334 335 336 344 345 346 347 355 356 357 366 367 377 444 445 "
                "446 447 455 456 457 466 467 477 555 556 557 566 567 577 666 667 677 777").split()
# shell j = [0.01 j, 0.01 (j + 1)) h/Mpc, centre 0.01 j + 0.005: the 62 triangle bins of the window-free
# Nseries files (oliverphilcox/Spectra-Without-Windows bk/data/nseries, commit f42142b0)


def table_real_space(lin):
    m = model(b1=2.0, b2=-0.5, bs=-0.3, f=0.0)
    tri = np.array(TRIANGLES)
    bl = multipoles_at(lin, m, tri[:, 0], tri[:, 1], tri[:, 2], n_mu=16, n_phi=16)
    k1, k2, k3 = tri.T

    def term(a, b, c):
        x = (c * c - a * a - b * b) / (2 * a * b)
        f2 = 5 / 7 + 0.5 * x * (a / b + b / a) + 2 / 7 * x * x
        return 2 * m["b1"] ** 2 * lin(a) * lin(b) * (m["b1"] * f2 + 0.5 * m["b2"] + m["bs"] * (x * x - 1 / 3))

    closed = term(k1, k2, k3) + term(k2, k3, k1) + term(k3, k1, k2)
    rel = np.max(np.abs(bl[0] / closed - 1))
    rows = [(*t, closed[i], bl[0, i], bl[1, i], bl[2, i]) for i, t in enumerate(TRIANGLES)]
    hdr = ["# Real space (f = 0): B = 2 b1^2 P(k1) P(k2) [b1 F2 + b2/2 + bs S2] + 2 cyclic (closed form) and the",
           "# orientation-averaged B0, B2, B4 of make_reference.py (must be B0 = closed form, B2 = B4 = 0).",
           *lin_header(lin),
           f"# model: {describe(m)}",
           f"# max |B0/closed - 1| = {rel:.1e}; |B2|, |B4| <= {np.max(np.abs(bl[1:])):.1e} (round-off)",
           "# units: k [h/Mpc], B [(Mpc/h)^6]",
           "# columns: k1 k2 k3 B_closed_form B0 B2 B4"]
    write(os.path.join(HERE, "ref_real_space.txt"), hdr, rows,
          "{:.4f} {:.4f} {:.4f} {: .12e} {: .12e} {: .3e} {: .3e}")


SUGIYAMA_PAIRS = [(k, k) for k in (0.01, 0.02, 0.03, 0.05, 0.07, 0.1, 0.13, 0.16, 0.2)] + [
    (0.01, 0.05), (0.02, 0.1), (0.03, 0.06), (0.05, 0.1), (0.05, 0.15), (0.08, 0.12), (0.1, 0.2)]


def sugiyama_models(lin):
    f, models = std_models(lin)
    keep = {"tree", "tree_fog_lor1", "tree_fog_gauss", "tree_ct_shot", "tree_ap"}
    return f, [(n, m) for n, m in models if n in keep]


def table_sugiyama(lin):
    f, models = sugiyama_models(lin)
    pairs = np.array(SUGIYAMA_PAIRS)
    rows, errs = [], {}
    for name, m in models:
        hi = sugiyama_at(lin, m, pairs[:, 0], pairs[:, 1])
        lo = sugiyama_at(lin, m, pairs[:, 0], pairs[:, 1], n_mu=16, n_phi=24, panels=24, per_panel=12)
        errs[name] = np.max(np.abs(hi - lo) / np.abs(hi[:, :1]))
        for i, pr in enumerate(SUGIYAMA_PAIRS):
            rows.append((name, *pr, *hi[i]))
    hdr = ["# Sugiyama et al. (2019) bispectrum multipoles B_{l1 l2 L}(k1, k2) of the tree-level redshift-space",
           "# galaxy bispectrum (DEFINITIONS.md (e)): B = H N int dk1^/4pi dk2^/4pi S_{l1l2L} B, H = (l1 l2 L; 0 0 0),",
           "# N = (2l1+1)(2l2+1)(2L+1); weights 000: 1, 110: 3x, 220: 5L2(x), 202: 5L2(mu1), 022: 5L2(mu2),",
           "# 112: 3(3 mu1 mu2 - x), x = k1^.k2^; B112F = 112 with FolpsD's azimuthal weight (2 sqrt3 instead of 3):",
           "# 3[(3mu1^2-1)x + 2 sqrt3 mu1 (1-mu1^2)^1/2 (1-x^2)^1/2 cos phi] (not the tripolar harmonic; for comparison).",
           *models_header(lin, f, models)]
    hdr += ["# quadrature: k3 on 48 Gauss-Legendre panels x 16 (quadratically clustered at |k1-k2|), mu1 GL 24,",
            "#   phi trapezoid 32; estimated error (vs 24x12, 16, 24) / |B000| <= "
            + ", ".join(f"{k} {v:.0e}" for k, v in errs.items()),
            "# units: k [h/Mpc], B [(Mpc/h)^6]",
            "# columns: model k1 k2 B000 B110 B220 B202 B022 B112 B112F"]
    write(os.path.join(HERE, "ref_sugiyama.txt"), hdr, rows,
          "{} {:.4f} {:.4f} " + " ".join(["{: .10e}"] * 7))


def nseries_edges(code):
    j = [int(c) for c in code]
    return [(0.01 * i, 0.01 * (i + 1)) for i in j]


def table_bins(lin):
    f, models = std_models(lin)
    models = [(n, m) for n, m in models if n in ("tree", "tree_all", "tree_all_fogshot")]
    rows, errs = [], {}
    for name, m in models:
        err = 0.0
        for code in NSERIES_BINS:
            ea, eb, ec = nseries_edges(code)
            hi = bin_average(lin, m, ea, eb, ec, n_shell=8, n_mu=20, n_phi=24)
            lo = bin_average(lin, m, ea, eb, ec, n_shell=6, n_mu=12, n_phi=16)
            cen = multipoles_at(lin, m, [np.mean(ea)], [np.mean(eb)], [np.mean(ec)])[:, 0]
            e = np.abs(hi - lo)
            err = max(err, np.max(e / abs(hi[0])))
            rows.append((name, *(np.mean(e_) for e_ in (ea, eb, ec)), *hi, *e, *cen))
        errs[name] = err
    hdr = ["# Bin averages of the tree-level B0, B2, B4 over continuous shells of width 0.01 h/Mpc (the 62 triangle",
           "# bins of the window-free Nseries files): B_l^bin = int k1 k2 k3 Theta(closed) B_l^(3) / int k1 k2 k3",
           "# Theta(closed) over k1 in shell a, k2 in b, k3 in c (DEFINITIONS.md (d)), Legendre on the side in",
           "# shell c (the largest); shells [k_c - 0.005, k_c + 0.005). B_l^(3) in the observed frame (AP, observed",
           "# shells). The Philcox (2021) estimator returns these (its Delta_abc normalisation, DEFINITIONS (d)).",
           *models_header(lin, f, models)]
    hdr += ["# quadrature: the closed part of the shell box split into tetrahedra, collapsed Gauss-Legendre 8^3",
            "#   per tetrahedron, orientations GL 20 x trapezoid 24; err_* = |that - (6^3, 12 x 16)|; max err/|B0|: "
            + ", ".join(f"{k} {v:.0e}" for k, v in errs.items()),
            "# B*_centre: the unbinned multipoles at the bin centres (to show the binning effect)",
            "# units: k [h/Mpc] (bin centres), B [(Mpc/h)^6]",
            "# columns: model k1 k2 k3 B0 B2 B4 err_B0 err_B2 err_B4 B0_centre B2_centre B4_centre"]
    write(os.path.join(HERE, "ref_bins_nseries.txt"), hdr, rows,
          "{} {:.4f} {:.4f} {:.4f} " + " ".join(["{: .9e}"] * 3) + " " + " ".join(["{:.1e}"] * 3)
          + " " + " ".join(["{: .9e}"] * 3))


BOX_L = 1000.0
BOX_EDGES = [1.5, 4.5, 7.5, 10.5, 13.5]   # shells in units of k_f = 2 pi / L


def table_box(lin):
    kf = 2 * np.pi / BOX_L
    f, models = std_models(lin)
    models = [(n, m) for n, m in models if n in ("tree", "tree_ct_shot")]
    shells = [(kf * BOX_EDGES[i], kf * BOX_EDGES[i + 1]) for i in range(len(BOX_EDGES) - 1)]
    rows = []
    stats = {}
    for name, m in models:
        dmax = np.zeros(3)
        for a in range(len(shells)):
            for b in range(a, len(shells)):
                for c in range(b, len(shells)):
                    res = box_bin(lin, m, kf, shells[a], shells[b], shells[c])
                    if res is None:
                        continue
                    plain, est, n0, ratio = res
                    cont = bin_average(lin, m, shells[a], shells[b], shells[c], n_shell=8, n_mu=16, n_phi=20)
                    scale = abs(plain[0])
                    dmax = np.maximum(dmax, np.abs(est - plain) / scale)
                    rows.append((name, a, b, c, n0, *plain, *est, *(cont if cont is not None else [np.nan] * 3),
                                 ratio[1], ratio[2]))
        stats[name] = dmax
    hdr = ["# Exact averages over the discrete modes of a periodic box, L = %g Mpc/h, k_f = 2 pi/L = %.8f h/Mpc," % (BOX_L, kf),
           "# shells i = 0..3: [%s) k_f, i.e. k_f n, n integer vectors, k_lo <= |k| < k_hi; line of sight z;" % ", ".join(str(e) for e in BOX_EDGES),
           "# every ordered triple k1 in a, k2 in b, k3 = -(k1 + k2) in c (a <= b <= c), N0 = their number.",
           "# plain: B_l = (2l+1) sum B L_l(k3^.z) / N0 (the FFT box estimator)",
           "# est:   the Philcox (2021) window-free estimator on these modes: p = F^-1 q over the l = 0, 2, 4 block,",
           "#        templates Phi/Delta_abc (DEFINITIONS.md (d)): L(mu3) (a<b<c), 2L(mu3)/2 (a=b<c),",
           "#        [L(mu2)+L(mu3)]/(1 + N_l/N0) (a<b=c), 2[L(mu1)+L(mu2)+L(mu3)]/(2(1 + 2N_l/N0)) (a=b=c),",
           "#        q_l = sum T_l B, F_ll' = sum T_l T_l'; N_l = sum L_l(k2^.k3^) over the triples",
           "# cont:  the same shells as continuous shells (make_reference.bin_average, 8^3 nodes per tetrahedron)",
           *models_header(lin, f, models)]
    hdr += ["# accuracy: exact sums (double precision, ~1e-13 relative); est - plain differs by the discreteness",
            "#   of the fixed-LOS box: max |est - plain| / |B0| per l (0, 2, 4): "
            + "; ".join(f"{k} " + ", ".join(f"{v:.1e}" for v in d) for k, d in stats.items()),
            "# units: B [(Mpc/h)^6]",
            "# columns: model a b c N0 B0_plain B2_plain B4_plain B0_est B2_est B4_est B0_cont B2_cont B4_cont N2/N0 N4/N0"]
    write(os.path.join(HERE, "ref_box.txt"), hdr, rows,
          "{} {} {} {} {} " + " ".join(["{: .10e}"] * 9) + " {: .6f} {: .6f}")



def eh_no_wiggle_shape(k, omega_m=0.27, h=0.7, omega_b_h2=0.023, n_s=0.95, t_cmb=2.7255):
    """Eisenstein & Hu (1998, ApJ 496, 605) eqs. 26-31: k^n_s T_0(k)^2 without wiggles (unnormalised)."""
    om_h2 = omega_m * h * h
    fb = omega_b_h2 / om_h2
    theta = t_cmb / 2.7
    s = 44.5 * np.log(9.83 / om_h2) / np.sqrt(1 + 10 * omega_b_h2**0.75)          # Mpc
    alpha = 1 - 0.328 * np.log(431 * om_h2) * fb + 0.38 * np.log(22.3 * om_h2) * fb * fb
    kmpc = k * h
    gamma = omega_m * h * (alpha + (1 - alpha) / (1 + (0.43 * kmpc * s) ** 4))
    q = k * theta * theta / gamma
    L0 = np.log(2 * np.e + 1.8 * q)
    C0 = 14.2 + 731 / (1 + 62.5 * q)
    T0 = L0 / (L0 + C0 * q * q)
    return k**n_s * T0 * T0


def no_wiggle(lin, width=0.25):
    """P_nw = P_EH,nw G[P/P_EH,nw]: Gaussian filter of width 0.25 in ln k on the table's grid (the
    gm2012 cosmology of the table; any smooth broadband would do, only the wiggles are removed)."""
    from scipy.ndimage import gaussian_filter1d
    ref = eh_no_wiggle_shape(lin.k)
    dlk = np.mean(np.diff(lin.lk))
    ratio = gaussian_filter1d(lin.p / ref, width / dlk, mode="nearest")
    return Linear(k=lin.k, p=ratio * ref)


def sigmas_bao(pnw, ell=110.0, k_s=0.2, n=20000):
    """Sigma^2 = (1/6pi^2) int dq P_nw [1 - j0 + 2 j2](q ell), dSigma^2 = (1/2pi^2) int dq P_nw j2(q ell),
    q from the table's first k to k_s (the project's ir module choices), Simpson in ln q."""
    from scipy.integrate import simpson
    from scipy.special import spherical_jn
    q = np.exp(np.linspace(np.log(pnw.k[0]), np.log(k_s), n + 1))
    x = q * ell
    j0, j2 = spherical_jn(0, x), spherical_jn(2, x)
    s2 = simpson(q * pnw(q) * (1 - j0 + 2 * j2), x=np.log(q)) / (6 * np.pi**2)
    ds2 = simpson(q * pnw(q) * j2, x=np.log(q)) / (2 * np.pi**2)
    return s2, ds2


def table_ir(lin):
    pnw = no_wiggle(lin)
    s2, ds2 = sigmas_bao(pnw)
    path = os.path.join(HERE, "linear_nw_gm2012_z0.5.txt")
    hdr = ["# The no-wiggle spectrum used by ref_ir.txt and compare_folpsd.py: P_nw = P_EH,nw G[P/P_EH,nw], Eisenstein &",
           "# Hu (1998) no-wiggle shape of the table's cosmology (Omega_m 0.27, h 0.7, Omega_b h^2 0.023, n_s 0.95,",
           "# T_CMB 2.7255), G a Gaussian filter of width 0.25 in ln k (make_reference.no_wiggle), on the grid of",
           *lin_header(lin),
           f"# Sigma^2 = {s2:.8f}, deltaSigma^2 = {ds2:.8f} (Mpc/h)^2 (make_reference.sigmas_bao: l = 110 Mpc/h, k_s = 0.2)",
           "# columns: k [h/Mpc] P [(Mpc/h)^3] P_nw [(Mpc/h)^3]"]
    write(path, hdr, list(zip(lin.k, lin.p, pnw.p)), "{:.8e} {:.8e} {:.8e}")
    f = header_value(lin, "growth_rate_f(z)")
    ir = dict(pnw=pnw, Sigma2=s2, dSigma2=ds2,
              describe=f"Sigma2 = {s2:.8f}, dSigma2 = {ds2:.8f} (Mpc/h)^2, P_nw of linear_nw_gm2012_z0.5.txt")
    base = dict(b1=2.0, b2=-0.5, bs=-0.3, f=f, ir=ir)
    models = [("tree_ir", model(**base)),
              ("tree_ir_all", model(**base, fog="lorentzian2", sigma_fog=4.0, c1=5.0, n_bar=3e-4, b_shot=1.1,
                                    p_shot=0.2, a_shot=0.3, q_par=1.03, q_perp=0.98))]
    rows, errs = triangle_rows(lin, models)
    hdr = ["# Tree-level B0, B2, B4 with IR resummation in every leg (DEFINITIONS.md (c)): P(k_i) -> P_nw + e^{-k_i^2",
           "# Sigma_tot^2(mu_i)} (P - P_nw), Sigma_tot^2 = [1 + f mu^2 (2 + f)] Sigma^2 + f^2 mu^2 (mu^2 - 1) dSigma^2,",
           "# in the deterministic and stochastic terms; Legendre on k3; P_nw tabulated in linear_nw_gm2012_z0.5.txt",
           *models_header(lin, f, models)]
    hdr += ["# quadrature: GL 64 x trapezoid 64; err = |64x64 - 32x32|, max/|B0|: "
            + ", ".join(f"{k} {v:.0e}" for k, v in errs.items()),
            "# units: k [h/Mpc], B [(Mpc/h)^6]",
            "# columns: model k1 k2 k3 B0 B2 B4 err_B0 err_B2 err_B4"]
    write(os.path.join(HERE, "ref_ir.txt"), hdr, rows,
          "{} {:.4f} {:.4f} {:.4f} {: .10e} {: .10e} {: .10e} {:.1e} {:.1e} {:.1e}")



def check_tripolar():
    """The weights of DEFINITIONS (e) against explicit sums of Wigner 3j x y_lm (sympy, scipy)."""
    from sympy.physics.wigner import wigner_3j
    from scipy.special import sph_harm_y

    def y(l, mm, v):
        th, ph = np.arccos(v[2]), np.arctan2(v[1], v[0])
        return np.sqrt(4 * np.pi / (2 * l + 1)) * sph_harm_y(l, mm, th, ph)

    def s_tri(l1, l2, L, a, b, n):
        tot = 0.0
        for m1 in range(-l1, l1 + 1):
            for m2 in range(-l2, l2 + 1):
                M = -m1 - m2
                if abs(M) <= L:
                    tot += float(wigner_3j(l1, l2, L, m1, m2, M)) * y(l1, m1, a) * y(l2, m2, b) * y(L, M, n)
        return tot.real

    rng = np.random.default_rng(49)
    worst = 0.0
    for _ in range(20):
        a, b, n = (v / np.linalg.norm(v) for v in rng.normal(size=(3, 3)))
        mu1, mu2, x = a @ n, b @ n, a @ b
        closed = {(0, 0, 0): 1, (1, 1, 0): 3 * x, (2, 2, 0): 5 * legendre(2, x), (2, 0, 2): 5 * legendre(2, mu1),
                  (0, 2, 2): 5 * legendre(2, mu2), (1, 1, 2): 3 * (3 * mu1 * mu2 - x)}
        for (l1, l2, L), w in closed.items():
            H = float(wigner_3j(l1, l2, L, 0, 0, 0))
            N = (2 * l1 + 1) * (2 * l2 + 1) * (2 * L + 1)
            worst = max(worst, abs(H * N * s_tri(l1, l2, L, a, b, n) - w))
    print(f"tripolar weights: max |H N S - w| over 20 random (k1^, k2^, n^) = {worst:.1e}")
    return worst


def self_test(lin):
    """Independent checks of the pieces (printed; the README quotes them)."""
    f = header_value(lin, "growth_rate_f(z)")
    m = model(b1=2.0, b2=-0.5, bs=-0.3, f=f, c1=5.0, fog="lorentzian2", sigma_fog=4.0, n_bar=3e-4,
              b_shot=1.1, p_shot=0.2, a_shot=0.3)
    # 1. orientation average in the triangle frame vs explicit vectors averaged over n on a product rule
    #    about a fixed lab axis (the triangle rotated arbitrarily)
    rng = np.random.default_rng(7)
    worst = 0.0
    for (k1, k2, k3) in TRIANGLES[::3]:
        x12 = (k3 * k3 - k1 * k1 - k2 * k2) / (2 * k1 * k2)
        v1 = np.array([k1, 0, 0.0])
        v2 = k2 * np.array([x12, np.sqrt(1 - x12 * x12), 0.0])
        Rm, _ = np.linalg.qr(rng.normal(size=(3, 3)))
        v1, v2 = Rm @ v1, Rm @ v2
        v3 = -(v1 + v2)
        mu, wmu = np.polynomial.legendre.leggauss(96)
        phi = 2 * np.pi * np.arange(96) / 96
        MU, PHI = np.meshgrid(mu, phi, indexing="ij")
        s = np.sqrt(1 - MU * MU)
        n = np.stack([s * np.cos(PHI), s * np.sin(PHI), MU], -1)
        W = (wmu[:, None] / 2 / 96) * np.ones_like(PHI)
        km = [n @ v for v in (v1, v2, v3)]
        B = bispectrum(lin, m, k1, k2, k3, km[0], km[1], km[2], v1 @ v2, v2 @ v3, v3 @ v1)
        direct = np.array([(2 * l + 1) * np.sum(B * legendre(l, km[2] / k3) * W) for l in (0, 2, 4)])
        frame = multipoles_at(lin, m, [k1], [k2], [k3], n_mu=64, n_phi=64)[:, 0]
        worst = max(worst, np.max(np.abs(direct - frame)) / abs(frame[0]))
    print(f"triangle frame vs explicit rotated vectors (FoG, counterterm, shot): max |diff|/|B0| = {worst:.1e}")
    # 2. AP: q = 1 identity, isotropic dilation B_obs(k) = B(k/q)/q^6
    tri = np.array(TRIANGLES)
    base = multipoles_at(lin, m, *tri.T, n_mu=32, n_phi=32)
    one = multipoles_at(lin, dict(m, q_par=1.0, q_perp=1.0), *tri.T, n_mu=32, n_phi=32)
    q = 1.04
    dil = multipoles_at(lin, dict(m, q_par=q, q_perp=q), *tri.T, n_mu=32, n_phi=32)
    # the stochastic constant and FoG scale differently under a dilation: compare deterministic, no FoG
    md = model(b1=2.0, b2=-0.5, bs=-0.3, f=f)
    d1 = multipoles_at(lin, dict(md, q_par=q, q_perp=q), *tri.T, n_mu=32, n_phi=32)
    d0 = multipoles_at(lin, md, *(tri / q).T, n_mu=32, n_phi=32) / q**6
    print(f"AP: q = 1 identity {np.max(np.abs(one - base)):.1e}; isotropic q = {q}: max |B(k/q)/q^6 - B_obs|/|B0| = "
          f"{np.max(np.abs(d1 - d0) / np.abs(d0[0])):.1e}")
    del dil
    # 3. discrete box -> continuous shells for a box 2x larger (more modes per shell)
    kf = 2 * np.pi / 2000.0
    e = [(0.03, 0.04), (0.04, 0.05)]
    mb = model(b1=2.0, b2=-0.5, bs=-0.3, f=f)
    plain, est, n0, _ = box_bin(lin, mb, kf, e[0], e[1], e[1])
    cont = bin_average(lin, mb, e[0], e[1], e[1], n_shell=8, n_mu=16, n_phi=20)
    print(f"box L = 2000 Mpc/h, bin [0.03,0.04)x[0.04,0.05)^2 ({n0} triples): plain vs continuous "
          f"{np.abs(plain - cont) / abs(cont[0])}, estimator vs continuous {np.abs(est - cont) / abs(cont[0])}")
    check_tripolar()



NSERIES_BOX = (1750.0, 3220.0, 1830.0)   # Mpc/h, the estimator's FFT box of the Nseries files (header)


def grid_shape_counts(box, k_max, width, k_min=0.01):
    """Exact counts of closed triangles of the modes k = 2 pi n / box (per axis) in sub-shells of the
    given width, with the mean |k_i| per sub-shell triple: Sum_x I_i I_j I_l on an FFT grid fine enough
    that k1 + k2 + k3 cannot alias (N k_f > 3 k_max per axis)."""
    kf = 2 * np.pi / np.asarray(box)
    n = [int(2 ** np.ceil(np.log2(3 * k_max / kf_i * 1.02))) if False else int(np.ceil(3.05 * k_max / kf_i / 8) * 8)
         for kf_i in kf]
    axes = [np.fft.fftfreq(n_i, 1.0 / n_i) * kf_i for n_i, kf_i in zip(n, kf)]
    KX, KY, KZ = np.meshgrid(*axes, indexing="ij")
    kk = np.sqrt(KX**2 + KY**2 + KZ**2)
    edges = k_min + width * np.arange(int(round((k_max - k_min) / width)) + 1)
    cells = np.prod(n)
    I, KI = [], []
    for lo, hi in zip(edges[:-1], edges[1:]):
        sel = ((kk >= lo) & (kk < hi)).astype(float)
        I.append(np.fft.ifftn(sel).real.ravel() * cells)
        KI.append(np.fft.ifftn(sel * kk).real.ravel() * cells)
    return edges, np.array(I), np.array(KI), cells, n


def table_nseries_grid(lin):
    f, models = std_models(lin)
    models = [(n_, m) for n_, m in models if n_ in ("tree", "tree_all")]
    results = {}
    for width in (0.001, 0.0005):
        edges, I, KI, cells, ngrid = grid_shape_counts(NSERIES_BOX, 0.08, width)
        per = int(round(0.01 / width))
        for code in NSERIES_BINS:
            j = [int(c) - 1 for c in code]                    # shell index from 0.01
            sa, sb, sc = (range(jj * per, (jj + 1) * per) for jj in j)
            pairs = [(i1, i2) for i1 in sa for i2 in sb]
            prod = np.array([I[i1] * I[i2] for i1, i2 in pairs])
            cnt = (prod @ I[list(sc)].T) / cells                         # (pairs, l)
            m3 = (prod @ KI[list(sc)].T) / cells
            m1 = (np.array([KI[i1] * I[i2] for i1, i2 in pairs]) @ I[list(sc)].T) / cells
            m2 = (np.array([I[i1] * KI[i2] for i1, i2 in pairs]) @ I[list(sc)].T) / cells
            ok = cnt > 0.5
            k1, k2, k3 = m1[ok] / cnt[ok], m2[ok] / cnt[ok], m3[ok] / cnt[ok]
            w = cnt[ok]
            for name, m in models:
                bl = multipoles_at(lin, m, k1, k2, k3, n_mu=20, n_phi=24)
                results[(width, code, name)] = (bl @ w / w.sum(), w.sum())
    rows, errs = [], {}
    cont = {}
    path = os.path.join(HERE, "ref_bins_nseries.txt")
    if os.path.exists(path):
        for line in open(path):
            if not line.startswith("#"):
                t = line.split()
                cont[(t[0], "".join(str(int(round((float(v) - 0.005) / 0.01))) for v in t[1:4]))] = np.array(t[4:7], float)
    for name, m in models:
        err = 0.0
        for code in NSERIES_BINS:
            fine, n0 = results[(0.0005, code, name)]
            coarse, _ = results[(0.001, code, name)]
            e = np.abs(fine - coarse) / 3.0
            err = max(err, np.max(e / abs(fine[0])))
            c = cont.get((name, code), np.full(3, np.nan))
            rows.append((name, *(0.01 * int(ch) + 0.005 for ch in code), int(round(n0)), *fine, *e, *((fine - c) / abs(c[0]))))
        errs[name] = err
    kf = 2 * np.pi / np.asarray(NSERIES_BOX)
    hdr = ["# The 62 Nseries triangle bins averaged over the DISCRETE modes of the estimator's FFT box (header of the",
           "# files: box [1750, 3220, 1830] Mpc/h, k_f = %.6f %.6f %.6f h/Mpc): every closed triangle of modes" % tuple(kf),
           "# k = 2 pi n / box in the three shells [0.01 j, 0.01 (j+1)), counted exactly (FFT of the shell indicators on",
           "# a non-aliasing grid); each triangle gets the ORIENTATION-AVERAGED B_l^(3)(k1, k2, k3) (the survey's line of",
           "# sight varies; the exact fixed-LOS sum is what ref_box.txt does for a small box). Counts and mean |k_i|",
           "# per sub-shell triple of width 0.0005 (err = |w 0.0005 - w 0.001|/3, Richardson for the O(w^2) error).",
           "# d*_cont = (grid - continuous-shell average of ref_bins_nseries.txt)/|B0_cont|: the discreteness effect.",
           *models_header(lin, f, models)]
    hdr += ["# max err/|B0|: " + ", ".join(f"{k} {v:.0e}" for k, v in errs.items()),
            "# units: k [h/Mpc] (bin centres), B [(Mpc/h)^6]",
            "# columns: model k1 k2 k3 N_triangles B0 B2 B4 err_B0 err_B2 err_B4 dB0_cont dB2_cont dB4_cont"]
    write(os.path.join(HERE, "ref_bins_nseries_grid.txt"), hdr, rows,
          "{} {:.4f} {:.4f} {:.4f} {} " + " ".join(["{: .9e}"] * 3) + " " + " ".join(["{:.1e}"] * 3)
          + " " + " ".join(["{: .2e}"] * 3))


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--only", nargs="*", default=None)
    ap.add_argument("--check-tripolar", action="store_true")
    ap.add_argument("--self-test", action="store_true")
    args = ap.parse_args()
    lin = Linear(LINEAR)
    if args.check_tripolar:
        check_tripolar()
        return
    if args.self_test:
        self_test(lin)
        return
    tables = {"unbinned": table_unbinned, "real_space": table_real_space, "sugiyama": table_sugiyama,
              "bins": table_bins, "box": table_box, "ir": table_ir, "nseries_grid": table_nseries_grid}
    for name, fn in tables.items():
        if args.only is None or name in args.only:
            t0 = time.time()
            fn(lin)
            print(f"{name}: {time.time() - t0:.1f} s", file=sys.stderr)


if __name__ == "__main__":
    main()
