#!/usr/bin/env python3
"""Fits the linear-spectrum emulator (pt_spectra::emulator) to CAMB spectra and writes linear_emulator.bin.

Usage:  python3 fit_emulator.py DATA_DIR [--degree D] [--pcs N_CB N_RATIO] [--out FILE] [--report FILE]

DATA_DIR holds the train_*.npz and test_*.npz files of make_emulator_training.py. Steps:
  1. Targets per cosmology on redshift nodes Z_NODES and on n_x = 500 nodes uniform in ln x, x = k r_d
     (r_d of Aubourg et al. 2015 eq. 16, in Mpc/h, so that the baryon oscillations of every cosmology
     line up): Y_cb = ln P_cb - ln A_s - (n_s - 1) ln(k h / 0.05) and Y_ratio = ln(P_m / P_cb), by a
     cubic spline in ln k of the CAMB table (the Rust code sets P_m = P_cb exactly for massless
     neutrinos), and Y_cb less 2 ln(D_md(z)/Omega_m) (growing mode of the background,
     growth_md: this takes out the strong dependence of the amplitude on w0, wa and Omega_m).
  2. Principal components of each target over the training set (mean subtracted).
  3. Each component's coefficient as a polynomial (Legendre products, least squares) in seven coordinates:
     the six shape parameters mapped to [-1, 1] by the prior box, and q = rho_DE/rho_m at a = 0.1 (as
     2 sqrt(q/q_max) - 1), on which the amplitude of large scales depends steeply when w0 + wa -> 0.
     Terms: total degree <= D (--degree 5), and up to --w-degree 6 in the dark-energy coordinates
     (w0, wa, q) alone.
  4. The test set (cosmologies drawn independently over the whole prior, at the nodes and at random
     redshifts) is predicted exactly as the Rust code does (four-node Lagrange interpolation in
     ln(1 + z)); the error table (worst, 99th percentile) is printed and written to --report, and the
     99th percentile of |Delta ln P| per x is stored in the file as the emulator's error estimate.
The binary layout is documented in pt-spectra/src/emulator/format.rs. Needs numpy and scipy.
"""
import argparse
import glob
import itertools
import struct
import sys
from pathlib import Path

import numpy as np
from scipy.integrate import solve_ivp
from scipy.interpolate import CubicSpline

sys.path.insert(0, str(Path(__file__).parent))
from make_emulator_training import K_GRID, NAMES, PRIOR, Z_NODES  # noqa: E402

LO = np.array([PRIOR[p][0] for p in NAMES])
HI = np.array([PRIOR[p][1] for p in NAMES])
N_X = 500
K_MIN = 1e-4


def load(data_dir, kind):
    files = sorted(glob.glob(f"{data_dir}/{kind}_*.npz"), key=lambda f: int(f.split("_")[-2]))
    ds = [np.load(f) for f in files]
    return {k: np.concatenate([d[k] for d in ds]) for k in ["params", "z", "pk_cb", "pk_m", "sigma8"]}


A_EARLY = 0.1


def early_dark_energy(x):
    """rho_DE/rho_m at a = A_EARLY: the amplitude of large scales depends on it steeply (w0 + wa -> 0)."""
    om, w0, wa = x[:, 1], x[:, 4], x[:, 5]
    return (1 - om) / om * A_EARLY ** (-3 * (w0 + wa)) * np.exp(-3 * wa * (1 - A_EARLY))


Q_MAX = float(early_dark_energy(np.array([[0, LO[1], 0, 0, HI[4], HI[5]]]))[0])


def unit(x):
    """The emulator's coordinates: the six shape parameters mapped to [-1, 1] by the prior box, and a
    seventh, 2 sqrt(q/q_max) - 1 with q = early_dark_energy (its largest value in the box is q_max)."""
    u = 2 * (x[:, :6] - LO[:6]) / (HI[:6] - LO[:6]) - 1
    return np.column_stack([u, 2 * np.sqrt(early_dark_energy(x) / Q_MAX) - 1])


def drag_horizon(x):
    """Mpc/h, Aubourg et al. 2015 eq. 16 (as pt_spectra::emulator::drag_horizon)."""
    ob, om, h, mnu = x[:, 0], x[:, 1], x[:, 2], x[:, 3]
    wnu = mnu / 93.14
    wb = ob * h * h
    wcb = om * h * h - wnu
    return 55.154 * np.exp(-72.3 * (wnu + 0.0006) ** 2) / (wcb**0.25351 * wb**0.12807) * h


def x_grid():
    """ln x nodes: every cosmology of the prior has data (1e-4 <= k <= 10) on all of them."""
    corners = np.array(list(itertools.product(*[PRIOR[p] for p in NAMES[:4]])))
    corners = np.hstack([corners, np.zeros((len(corners), 4))])
    r = drag_horizon(corners)
    return np.linspace(np.log(K_MIN * 1.001 * r.max()), np.log(10.0 * 0.999 * r.min()), N_X)


A_START = 1e-8


def growth_md(x, zs, return_rate=False):
    """D_md(z), the growing mode normalised to a deep in matter domination, of the flat w0-wa background
    with all matter (neutrinos included) as dust and no radiation: the ODE of
    pt_spectra::cosmology (g = D/a in ln a, same start with its first-order dark-energy correction)."""
    om, w0, wa = x[1], x[4], x[5]

    def rhs(t, y):
        a = np.exp(t)
        d = (1 - om) * a**3 * np.exp(-3 * (1 + w0 + wa) * t - 3 * wa * (1 - a))
        w = w0 + wa * (1 - a)
        two_e2 = 2 * (om + d)
        return [y[1], -(5 * om + (5 - 3 * w) * d) / two_e2 * y[1] - 3 * (1 - w) * d / two_e2 * y[0]]

    p = -3 * (w0 + wa)
    term = -(p + 3) / (p * (2 * p + 5)) * (1 - om) * np.exp(-3 * wa) / om * A_START**p
    t = -np.log1p(np.asarray(zs, float))
    order = np.argsort(t)
    sol = solve_ivp(rhs, (np.log(A_START), 0.0), [1 + term, p * term], method="DOP853", rtol=1e-12,
                    atol=1e-14, t_eval=t[order])
    g = np.empty(len(t))
    dg = np.empty(len(t))
    g[order] = sol.y[0]
    dg[order] = sol.y[1]
    if return_rate:
        return np.exp(t) * g, 1 + dg / g
    return np.exp(t) * g


def primordial(x, lnk):
    return x[6] - np.log(1e10) + (x[7] - 1) * (lnk + np.log(x[2] / 0.05))


def targets(d, lnx, nodes_only=True):
    n = len(d["params"])
    nz = len(Z_NODES) if nodes_only else d["z"].shape[1]
    r = drag_horizon(d["params"])
    lk = np.log(K_GRID)
    y_cb = np.empty((n, nz, len(lnx)))
    y_ratio = np.empty_like(y_cb)
    for i in range(n):
        x = d["params"][i]
        growth = 2 * np.log(growth_md(x, d["z"][i, :nz]) / x[1])
        a = np.log(d["pk_cb"][i, :nz]) - primordial(x, lk) - growth[:, None]
        b = np.log(d["pk_m"][i, :nz] / d["pk_cb"][i, :nz])
        src = lk + np.log(r[i])
        y_cb[i] = CubicSpline(src, a, axis=1)(lnx)
        y_ratio[i] = CubicSpline(src, b, axis=1)(lnx)
    return y_cb, y_ratio


def exponents(degree, w_degree=None, total=None):
    """Legendre degrees of the polynomial terms in the seven coordinates: total degree <= `degree`, and
    (the amplitude depends on the dark energy far more steeply than on the rest) terms of degree up to
    `w_degree` in the dark-energy coordinates (w0, wa, q) and up to total - w_degree in the others."""
    w_degree = degree if w_degree is None else w_degree
    total = degree if total is None else total
    rng = range(max(degree, w_degree) + 1)
    return [e for e in itertools.product(rng, repeat=7)
            if sum(e) <= degree
            or (e[4] + e[5] + e[6] <= w_degree and sum(e[:4]) <= max(total - w_degree, 0))]


def features(u, exps):
    deg = max(map(max, exps))
    L = [np.ones_like(u), u]
    for m in range(1, deg):
        L.append(((2 * m + 1) * u * L[m] - m * L[m - 1]) / (m + 1))
    L = np.stack(L[: deg + 1], -1)
    F = np.ones((len(u), len(exps)))
    for j, e in enumerate(exps):
        for a, p in enumerate(e):
            if p:
                F[:, j] *= L[:, a, p]
    return F


def lagrange(nodes, s, derivative=False):
    w = np.ones(4)
    dw = np.zeros(4)
    for j in range(4):
        others = [m for m in range(4) if m != j]
        den = np.prod([nodes[j] - nodes[m] for m in others])
        w[j] = np.prod([s - nodes[m] for m in others]) / den
        dw[j] = sum(np.prod([s - nodes[m] for m in others if m != skip]) for skip in others) / den
    return dw if derivative else w


def interpolate_z(y_nodes, z, derivative=False):
    """y_nodes (nz, nx) at redshift z (or its derivative in ln(1 + z)), as the Rust code does (add the
    growth back for P_cb)."""
    nodes = np.log1p(Z_NODES)
    s = np.log1p(z)
    interval = max(np.searchsorted(nodes, s, side="right") - 1, 0)
    first = min(max(interval - 1, 0), len(nodes) - 4)
    return lagrange(nodes[first:first + 4], s, derivative) @ y_nodes[first:first + 4]


def sigma8(k, p):
    """Trapezoid in ln k on uniform ln k, as the Rust code."""
    x = 8 * k
    w = 3 * (np.sin(x) - x * np.cos(x)) / x**3
    f = k**3 * p * w**2
    return np.sqrt((f.sum() - 0.5 * (f[0] + f[-1])) * np.log(k[1] / k[0]) / (2 * np.pi**2))


def fit(y, F, n_pc):
    n = len(y)
    flat = y.reshape(n, -1)
    mean = flat.mean(0)
    _, _, vt = np.linalg.svd(flat - mean, full_matrices=False)
    comps = vt[:n_pc].astype(np.float32)
    c = (flat - mean) @ comps.T.astype(np.float64)
    coef, *_ = np.linalg.lstsq(F, c, rcond=None)
    return mean, comps, coef


def predict(model, F):
    mean, comps, coef = model
    return (F @ coef) @ comps.astype(np.float64) + mean


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("data")
    ap.add_argument("--degree", type=int, default=5)
    ap.add_argument("--w-degree", type=int, default=6)
    ap.add_argument("--total", type=int, default=6)
    ap.add_argument("--pcs", type=int, nargs=2, default=[40, 20])
    ap.add_argument("--out", default=str(Path(__file__).parent / "linear_emulator.bin"))
    ap.add_argument("--report")
    args = ap.parse_args()
    train, test = load(args.data, "train"), load(args.data, "test")
    lnx = x_grid()
    nz, nx = len(Z_NODES), len(lnx)
    exps = exponents(args.degree, args.w_degree, args.total)
    F = features(unit(train["params"]), exps)
    print(f"{len(train['params'])} training and {len(test['params'])} test cosmologies; "
          f"{len(exps)} polynomial terms; x in [{np.exp(lnx[0]):.4g}, {np.exp(lnx[-1]):.4g}]")
    y_cb, y_ratio = targets(train, lnx)
    models = [fit(y_cb, F, args.pcs[0]), fit(y_ratio, F, args.pcs[1])]

    # the test set, every redshift (nodes and random), predicted as in Rust
    Ft = features(unit(test["params"]), exps)
    pred = [predict(m, Ft).reshape(-1, nz, nx) for m in models]
    t_cb, t_ratio = targets(test, lnx, nodes_only=False)
    r = drag_horizon(test["params"])
    err_cb, err_m, worst, s8err, f_err = [], [], [], [], []
    n_nodes = len(Z_NODES)
    for i in range(len(test["params"])):
        k = np.exp(lnx) / r[i]
        inside = (k >= 1e-3) & (k <= 1.0)
        for j, z in enumerate(test["z"][i]):
            p_cb = interpolate_z(pred[0][i], z)
            p_cb = p_cb + 2 * np.log(growth_md(test["params"][i], [z])[0] / test["params"][i][1])
            truth = t_cb[i, j] + 2 * np.log(growth_md(test["params"][i], [z])[0] / test["params"][i][1])
            p_ratio = interpolate_z(pred[1][i], z)
            e_cb = np.abs(p_cb - truth)
            e_m = np.abs(p_cb + p_ratio - truth - t_ratio[i, j])
            err_cb.append(e_cb)
            err_m.append(e_m)
            x = test["params"][i]
            primordial_k = primordial(x, np.log(k))
            s8err.append(sigma8(k, np.exp(p_cb + p_ratio + primordial_k)) / test["sigma8"][i, j] - 1)
            # f_cb(k, z) against CAMB's central differences at the random redshifts (z, z + dz, z - dz)
            extra = (test["z"].shape[1] - n_nodes) // 3
            if n_nodes <= j < n_nodes + extra:
                _, f_md = growth_md(x, [z], return_rate=True)
                f_emu = f_md[0] - 0.5 * interpolate_z(pred[0][i], z, derivative=True)
                up, down = j + extra, j + 2 * extra
                ln = [t_cb[i, jj] + 2 * np.log(growth_md(x, [test["z"][i, jj]])[0] / x[1]) for jj in (up, down)]
                f_camb = -(ln[0] - ln[1]) / (2 * (np.log1p(test["z"][i, up]) - np.log1p(test["z"][i, down])))
                f_err.append(np.abs(f_emu / f_camb - 1)[inside].max())
            worst.append((max(e_cb[inside].max(), e_m[inside].max()), i, z))
    err_cb, err_m = np.array(err_cb), np.array(err_m)
    k_all = np.exp(lnx[None, :]) / np.repeat(r, test["z"].shape[1])[:, None]
    inside = (k_all >= 1e-3) & (k_all <= 1.0)
    rows = []
    for name, e in (("P_cb", err_cb), ("P_m", err_m)):
        per_spectrum = np.where(inside, e, 0).max(1)
        rows.append(f"| {name} | {e[inside].max():.2e} | {np.percentile(per_spectrum, 99):.2e} | "
                    f"{np.percentile(e[inside], 99):.2e} | {np.median(per_spectrum):.2e} |")
    table = ("| spectrum | worst | 99th percentile of each spectrum's worst | 99th percentile of all points "
             "| median of each spectrum's worst |\n|---|---|---|---|---|\n" + "\n".join(rows))
    w = max(worst)
    s8err, f_err = np.abs(s8err), np.array(f_err)
    text = (f"{len(test['params'])} test cosmologies x {test['z'].shape[1]} redshifts, "
            f"|Delta ln P| for 1e-3 <= k <= 1 h/Mpc:\n\n{table}\n\nworst: cosmology {test['params'][w[1]].round(4)} "
            f"at z = {w[2]:.3f}\n\nsigma8(z) of P_m: worst {s8err.max():.2e}, 99th percentile "
            f"{np.percentile(s8err, 99):.2e}\n\nf_cb(k, z) against CAMB's central differences (dz = 0.01) at "
            f"{len(f_err)} random redshifts, 1e-3 <= k <= 1: worst {f_err.max():.2e}, 99th percentile "
            f"{np.percentile(f_err, 99):.2e}\n")
    print(text)
    if args.report:
        Path(args.report).write_text(text)
    # error estimate per x: 99th percentile over the test spectra, then a running maximum over 5 nodes
    est = [np.percentile(e, 99, axis=0) for e in (err_cb, err_m)]
    est = [np.array([v[max(0, i - 2):i + 3].max() for i in range(nx)]) for v in est]

    with open(args.out, "wb") as f:
        f.write(b"PTEMU001")
        f.write(struct.pack("<6I", len(exps), nz, nx, 1, args.pcs[0], args.pcs[1]))
        f.write(np.array([[LO[i], HI[i]] for i in range(8)], "<f8").tobytes())
        f.write(np.asarray(Z_NODES, "<f8").tobytes())
        f.write(np.array([lnx[0], lnx[-1], A_EARLY, Q_MAX], "<f8").tobytes())
        f.write(np.array(exps, np.uint8).tobytes())
        for mean, comps, coef in models:
            f.write(mean.astype("<f8").tobytes())
            f.write(comps.astype("<f4").tobytes())
            f.write(coef.astype("<f8").tobytes())
        for e in est:
            f.write(e.astype("<f8").tobytes())
    print("wrote", args.out, Path(args.out).stat().st_size, "bytes")


if __name__ == "__main__":
    main()
