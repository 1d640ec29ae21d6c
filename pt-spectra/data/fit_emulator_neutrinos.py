#!/usr/bin/env python3
"""Adds the neutrino head and the early-dark-energy bound to the linear-spectrum emulator, and measures
its worst error over the stated prior on cosmologies it was not trained on.

Usage:  python3 fit_emulator_neutrinos.py DATA_DIR [--q-bound Q] [--in FILE] [--out FILE] [--report FILE]

DATA_DIR holds the npz files of make_emulator_neutrinos.py (train_*, corners_*, edge_*, random_*).
  1. The head: Y = ln(P_one / P_degenerate) of P_cb and of P_m (one massive species against three
     degenerate, same Sigma m_nu, Omega_m, ...) on the base emulator's nodes (x = k r_d, Z_NODES), by a
     cubic spline in ln k of CAMB's tables; principal components; each coefficient a polynomial
     (Legendre products of total degree --degree) of the base emulator's seven coordinates.
  2. The bound: the early dark-energy density q = rho_DE/rho_m at a = 0.1 (the emulator's seventh
     coordinate) must not exceed --q-bound times q_max, and the six shape parameters must lie in the
     box shrunk about its centre by --shrink (the corners of the training box are beyond the stated
     accuracy); beyond, the emulator refuses.
  3. The check: every spectrum of corners_*, edge_*, random_* inside the bounded prior (each at z = 0,
     0.5, 1, 2, 3) predicted as the Rust code does, |Delta ln P| of P_cb and P_m for 1e-3 <= k <= 1
     h/Mpc, per setting; the worst is written into the file (the header prints it) and the report.
The output layout (PTEMU002) is documented in pt-spectra/src/emulator/format.rs. Needs numpy, scipy.
"""
import argparse
import glob
import struct
import sys
from pathlib import Path

import numpy as np
from scipy.interpolate import CubicSpline

sys.path.insert(0, str(Path(__file__).parent))
from fit_emulator import (drag_horizon, early_dark_energy, exponents, features, growth_md,  # noqa: E402
                          interpolate_z, primordial)

HERE = Path(__file__).parent
SETTING_ONE = 1  # the code of "one massive species" in the file


def read_v1(path):
    """The base emulator (PTEMU001, or the same part of a PTEMU002 file) as a dict (layout: pt-spectra/src/emulator/format.rs)."""
    b = Path(path).read_bytes()
    assert b[:8] in (b"PTEMU001", b"PTEMU002"), "not an emulator file"
    at = 8
    n_terms, nz, nx, rescale, pc_cb, pc_ratio = struct.unpack_from("<6I", b, at)
    at += 24

    def f64(n):
        nonlocal at
        v = np.frombuffer(b, "<f8", n, at)
        at += 8 * n
        return v

    def f32(n):
        nonlocal at
        v = np.frombuffer(b, "<f4", n, at)
        at += 4 * n
        return v

    prior = f64(16).reshape(8, 2)
    z_nodes = f64(nz)
    lx0, lx1, a_e, q_max = f64(4)
    exps = np.frombuffer(b, np.uint8, n_terms * 7, at).reshape(n_terms, 7)
    at += n_terms * 7
    models = []
    for npc in (pc_cb, pc_ratio):
        mean = f64(nz * nx)
        comps = f32(npc * nz * nx).reshape(npc, nz * nx)
        coef = f64(n_terms * npc).reshape(n_terms, npc)
        models.append((mean, comps, coef))
    err = [f64(nx), f64(nx)]
    assert at == len(b) or b[:8] == b"PTEMU002"
    return dict(raw=b[:at], prior=prior, z_nodes=z_nodes, lnx=np.linspace(lx0, lx1, nx), a_e=a_e,
                q_max=q_max, exps=[tuple(e) for e in exps], models=models, err=err)


def coordinates(emu, x):
    lo, hi = emu["prior"][:6, 0], emu["prior"][:6, 1]
    u = 2 * (x[:, :6] - lo) / (hi - lo) - 1
    q = early_dark_energy(x)
    return np.column_stack([u, np.clip(2 * np.sqrt(q / emu["q_max"]) - 1, -1, 1)])


def predict(model, F):
    mean, comps, coef = model
    return (F @ coef) @ comps.astype(np.float64) + mean


def load(data_dir, kind):
    files = sorted(glob.glob(f"{data_dir}/{kind}_*.npz"), key=lambda f: int(f.split("_")[-2]))
    if not files:
        return None
    ds = [np.load(f) for f in files]
    out = {k: np.concatenate([d[k] for d in ds]) for k in ds[0].files if k.startswith("pk_") or k == "params"}
    out["z"] = ds[0]["z"]
    out["k"] = ds[0]["k"]
    return out


def on_nodes(d, lnx, name, nz):
    """ln(P_one/P_degenerate) of spectrum `name` (cb or m) on the nodes (x, z)."""
    r = drag_horizon(d["params"])
    y = np.log(d[f"pk_{name}_one"][:, :nz] / d[f"pk_{name}_degenerate"][:, :nz])
    lk = np.log(d["k"])
    return np.array([CubicSpline(lk + np.log(r[i]), y[i], axis=1)(lnx) for i in range(len(y))])


def fit_head(train, emu, degree, n_pc):
    nz, nx = len(emu["z_nodes"]), len(emu["lnx"])
    exps = exponents(degree)
    F = features(coordinates(emu, train["params"]), exps)
    heads = []
    for name in ("cb", "m"):
        y = on_nodes(train, emu["lnx"], name, nz).reshape(len(F), -1)
        mean = y.mean(0)
        _, _, vt = np.linalg.svd(y - mean, full_matrices=False)
        comps = vt[:n_pc].astype(np.float32)
        c = (y - mean) @ comps.T.astype(np.float64)
        coef, *_ = np.linalg.lstsq(F, c, rcond=None)
        heads.append((mean, comps, coef))
    return exps, heads


def errors(emu, head, d, q_bound):
    """Per setting, [(|dlnP_cb|.max, |dlnP_m|.max, params, z)] over the spectra of d inside the bound."""
    nz_nodes, nx = len(emu["z_nodes"]), len(emu["lnx"])
    x = d["params"]
    inside = early_dark_energy(x) <= q_bound * emu["q_max"] * (1 + 1e-12)
    U = coordinates(emu, x)
    F = features(U, emu["exps"])
    base = [predict(m, F).reshape(-1, nz_nodes, nx) for m in emu["models"]]
    if head is not None:
        h_exps, h_models = head
        Fh = features(U, h_exps)
        nu = [predict(m, Fh).reshape(-1, nz_nodes, nx) for m in h_models]
    r = drag_horizon(x)
    out = {"degenerate": [], "one": []}
    lk = np.log(d["k"])
    for i in np.flatnonzero(inside):
        k = np.exp(emu["lnx"]) / r[i]
        keep = (k >= 1e-3) & (k <= 1.0)
        massive = 1.0 if x[i, 3] > 0 else 0.0
        for j, z in enumerate(d["z"]):
            g = 2 * np.log(growth_md(x[i], [z])[0] / x[i, 1]) + primordial(x[i], np.log(k))
            cb = interpolate_z(base[0][i], z) + g
            m = cb + massive * interpolate_z(base[1][i], z)
            for s in out:
                if f"pk_cb_{s}" not in d:
                    continue
                if s == "one":
                    if head is None:
                        continue
                    cb_s = cb + massive * interpolate_z(nu[0][i], z)
                    m_s = m + massive * interpolate_z(nu[1][i], z)
                else:
                    cb_s, m_s = cb, m
                t_cb = CubicSpline(lk, np.log(d[f"pk_cb_{s}"][i, j]))(np.log(k))
                t_m = CubicSpline(lk, np.log(d[f"pk_m_{s}"][i, j]))(np.log(k))
                out[s].append((np.abs(cb_s - t_cb)[keep].max(), np.abs(m_s - t_m)[keep].max(), x[i], z,
                               k[keep][np.argmax(np.abs(m_s - t_m)[keep])]))
    return out


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("data")
    ap.add_argument("--q-bound", type=float, default=1.0)
    ap.add_argument("--degree", type=int, default=3)
    ap.add_argument("--pcs", type=int, default=12)
    ap.add_argument("--in", dest="inp", default=str(HERE / "linear_emulator.bin"))
    ap.add_argument("--out")
    ap.add_argument("--report")
    ap.add_argument("--train-limit", type=int, default=None)
    ap.add_argument("--kinds", default="corners,edge,random", help="check sets (file prefixes)")
    ap.add_argument("--shrink", type=float, default=1.0,
                    help="the stated box of the six shape parameters: centre +- shrink x half-width")
    ap.add_argument("--no-head", action="store_true", help="write no neutrino head")
    args = ap.parse_args()
    emu = read_v1(args.inp)
    train = load(args.data, "train")
    head = None
    if train is not None:
        if args.train_limit:
            train = {k: (v[: args.train_limit] if k != "z" else v) for k, v in train.items()}
        head = fit_head(train, emu, args.degree, args.pcs)
        print(f"head: {len(train['params'])} training cosmologies, {len(head[0])} terms, {args.pcs} PCs")
    lines = [f"q bound: q <= {args.q_bound} q_max (q_max = {emu['q_max']:.6g}, a = {emu['a_e']})"]
    worst = {}
    for kind in args.kinds.split(","):
        d = load(args.data, kind)
        if d is None:
            continue
        e = errors(emu, head, d, args.q_bound)
        for s, rows in e.items():
            if not rows:
                continue
            cbw = max(rows, key=lambda r: r[0])
            mw = max(rows, key=lambda r: r[1])
            lines.append(f"{kind:8s} {s:10s} {len(rows):4d} spectra: worst P_cb {cbw[0]:.2e} "
                         f"(params {np.round(cbw[2], 4).tolist()}, z {cbw[3]}), worst P_m {mw[1]:.2e} "
                         f"(params {np.round(mw[2], 4).tolist()}, z {mw[3]}, k {mw[4]:.3g})")
            w = worst.setdefault(s, [0.0, 0.0])
            w[0], w[1] = max(w[0], cbw[0]), max(w[1], mw[1])
    for s, w in worst.items():
        lines.append(f"WORST {s}: P_cb {w[0]:.2e}, P_m {w[1]:.2e}")
    text = "\n".join(lines)
    print(text)
    if args.report:
        Path(args.report).write_text(text + "\n")
    if args.out:
        write(args.out, emu, None if args.no_head else head, args.q_bound, args.shrink, worst)


def write(path, emu, head, q_bound, shrink, worst):
    """PTEMU002: the PTEMU001 body, then the stated box, the bound, the measured worst errors and the
    heads."""
    centre, half = emu["prior"][:6].mean(1), (emu["prior"][:6, 1] - emu["prior"][:6, 0]) / 2
    box = np.column_stack([centre - shrink * half, centre + shrink * half])
    box[3, 0] = emu["prior"][3, 0]  # massless neutrinos stay inside (checked by the massless set)
    with open(path, "wb") as f:
        f.write(b"PTEMU002")
        f.write(emu["raw"][8:])
        f.write(np.asarray(box, "<f8").tobytes())
        f.write(np.array([q_bound, *worst["degenerate"]], "<f8").tobytes())
        f.write(struct.pack("<I", 0 if head is None else 1))
        if head is None:
            print("wrote", path, Path(path).stat().st_size, "bytes")
            return
        h_exps, h_models = head
        f.write(struct.pack("<4I", SETTING_ONE, len(h_exps), h_models[0][1].shape[0],
                            h_models[1][1].shape[0]))
        f.write(np.array(h_exps, np.uint8).tobytes())
        for mean, comps, coef in h_models:
            f.write(mean.astype("<f8").tobytes())
            f.write(comps.astype("<f4").tobytes())
            f.write(coef.astype("<f8").tobytes())
        f.write(np.array(worst["one"], "<f8").tobytes())
    print("wrote", path, Path(path).stat().st_size, "bytes")


if __name__ == "__main__":
    main()
