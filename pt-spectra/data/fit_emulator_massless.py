#!/usr/bin/env python3
"""Adds the massless head to the linear-spectrum emulator and measures its error at Sigma m_nu = 0.

Usage:  python3 fit_emulator_massless.py DATA_DIR [--degree D] [--pcs N] [--in FILE] [--out FILE]
                                          [--report FILE]

Why. The base emulator is trained on three degenerate massive neutrinos with 0 <= Sigma m_nu <= 0.5 eV;
Sigma m_nu = 0 is the edge of its training box, where a polynomial is least accurate, and CAMB's massless
run is not the limit of its massive runs (up to 9e-4 apart: CAMB treats massless neutrinos as radiation
only). At the massless corners of the stated prior the base emulator was 3.0e-3 off CAMB.

What. DATA_DIR holds the npz files of make_emulator_neutrinos.py: massless_train_* (the Sobol set with
Sigma m_nu = 0 over the training box of the other five shape parameters, A_s = 2e-9, n_s = 1, at the
base emulator's redshift nodes) and the check sets massless_* (the 32 corners of the stated box with
Sigma m_nu = 0), massless_random_* (uniform draws inside the stated box with Sigma m_nu = 0) and light_*
(corners with a small mass), corners_* and random_* (three degenerate massive species in the stated box):
the base emulator is unchanged, but its stored worst error (the header's figure) is measured again
over the massive sets alone (it had been set by the massless corners).
  1. The target: Y = ln P_cb(CAMB, massless) - ln P_cb(base emulator at Sigma m_nu = 0) on the base
     emulator's nodes (x = k r_d, its redshift nodes), by a cubic spline in ln k of CAMB's table; training
     cosmologies beyond 1.2 times the prior's early dark-energy bound are left out.
  2. The head: principal components of Y; each coefficient a polynomial (Legendre products of total
     degree --degree) of the base emulator's seven coordinates without the neutrino mass (constant here).
     P_m = P_cb without massive neutrinos, so the head's two targets are both Y.
  3. The check: every spectrum of the check sets inside the bounded prior, predicted as the Rust code does
     (base + head, growth and primordial factors), |Delta ln P| of P_cb and P_m for 1e-3 <= k <= 1 h/Mpc.
     The worst over the check sets is the head's stored error (the header prints it).
Output: the input file (PTEMU002, layout in pt-spectra/src/emulator/format.rs) with the massless head
(setting code 2) added, or replaced if it had one. Needs numpy, scipy.
"""
import argparse
import struct
import sys
from pathlib import Path

import numpy as np
from scipy.interpolate import CubicSpline

sys.path.insert(0, str(Path(__file__).parent))
from fit_emulator import (drag_horizon, early_dark_energy, exponents, features, fit,  # noqa: E402
                          growth_md, interpolate_z, predict, primordial)
from fit_emulator_neutrinos import coordinates, load, read_v1  # noqa: E402

HERE = Path(__file__).parent
SETTING_MASSLESS = 2  # the code of the massless head in the file
MASS = 3  # the column of Sigma m_nu in params and of its coordinate


def split_tail(emu):
    """The PTEMU002 tail after the base body: (stated box + bound + worst bytes, [(setting, bytes)])."""
    b = emu["file"]
    at = len(emu["raw"])
    fixed = b[at:at + 15 * 8]
    at += 15 * 8
    (n_heads,) = struct.unpack_from("<I", b, at)
    at += 4
    nodes = len(emu["z_nodes"]) * len(emu["lnx"])
    heads = []
    for _ in range(n_heads):
        start = at
        setting, n_terms, pc0, pc1 = struct.unpack_from("<4I", b, at)
        at += 16 + 7 * n_terms
        for npc in (pc0, pc1):
            at += 8 * nodes + 4 * npc * nodes + 8 * n_terms * npc
        at += 16
        heads.append((setting, b[start:at]))
    assert at == len(b), "bytes left after the heads"
    return fixed, heads


def base_cb(emu, x):
    """The base emulator's G_cb (ln P_cb less the growth and primordial factors) on its nodes, (n, nz, nx)."""
    F = features(coordinates(emu, x), emu["exps"])
    return predict(emu["models"][0], F).reshape(len(x), len(emu["z_nodes"]), len(emu["lnx"]))


def residual_on_nodes(emu, d):
    """Y = ln P_cb(CAMB) - base prediction on the nodes, for the cosmologies of d (all massless)."""
    x = d["params"]
    nz = len(emu["z_nodes"])
    r = drag_horizon(x)
    lk = np.log(d["k"])
    base = base_cb(emu, x)
    y = np.empty_like(base)
    for i in range(len(x)):
        growth = 2 * np.log(growth_md(x[i], emu["z_nodes"]) / x[i, 1])
        a = np.log(d["pk_cb_degenerate"][i, :nz]) - primordial(x[i], lk) - growth[:, None]
        y[i] = CubicSpline(lk + np.log(r[i]), a, axis=1)(emu["lnx"]) - base[i]
    return y


def check(emu, head, d, q_limit):
    """[(|dlnP_cb|.max, |dlnP_m|.max, params, z, k at the worst)] over the spectra of d inside the bound,
    with the massless `head` added where Sigma m_nu = 0 (None: the base emulator alone)."""
    x = d["params"]
    inside = early_dark_energy(x) <= q_limit * (1 + 1e-12)
    U = coordinates(emu, x)
    F = features(U, emu["exps"])
    nz, nx = len(emu["z_nodes"]), len(emu["lnx"])
    base = [predict(m, F).reshape(-1, nz, nx) for m in emu["models"]]
    if head is not None:
        h_exps, h_model = head
        corr = predict(h_model, features(U, h_exps)).reshape(-1, nz, nx)
    r = drag_horizon(x)
    lk = np.log(d["k"])
    rows = []
    for i in np.flatnonzero(inside):
        k = np.exp(emu["lnx"]) / r[i]
        keep = (k >= 1e-3) & (k <= 1.0)
        massive = x[i, MASS] > 0
        for j, z in enumerate(d["z"]):
            g = 2 * np.log(growth_md(x[i], [z])[0] / x[i, 1]) + primordial(x[i], np.log(k))
            cb = interpolate_z(base[0][i], z) + g
            if not massive and head is not None:
                cb = cb + interpolate_z(corr[i], z)
            m = cb + (interpolate_z(base[1][i], z) if massive else 0.0)
            t_cb = CubicSpline(lk, np.log(d["pk_cb_degenerate"][i, j]))(np.log(k))
            t_m = CubicSpline(lk, np.log(d["pk_m_degenerate"][i, j]))(np.log(k))
            e_m = np.abs(m - t_m)[keep]
            rows.append((np.abs(cb - t_cb)[keep].max(), e_m.max(), x[i], z, k[keep][np.argmax(e_m)]))
    return rows


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("data")
    ap.add_argument("--degree", type=int, default=3)
    ap.add_argument("--pcs", type=int, default=12)
    ap.add_argument("--in", dest="inp", default=str(HERE / "linear_emulator.bin"))
    ap.add_argument("--out")
    ap.add_argument("--report")
    ap.add_argument("--q-train", type=float, default=1.2, help="training cosmologies up to this times the q bound")
    ap.add_argument("--kinds", default="massless-0.8,massless_random-0.8",
                    help="massless check sets (file prefixes, with make_emulator_neutrinos.py's shrink tag)")
    ap.add_argument("--massive-kinds", default="corners-0.8,random-0.8,light-0.8",
                    help="check sets of three degenerate massive species: the base emulator's worst")
    args = ap.parse_args()
    emu = read_v1(args.inp)
    emu["file"] = Path(args.inp).read_bytes()
    assert emu["file"][:8] == b"PTEMU002", "needs a PTEMU002 file (fit_emulator_neutrinos.py)"
    fixed, heads = split_tail(emu)
    q_bound = np.frombuffer(fixed, "<f8", 15)[12]
    q_limit = q_bound * emu["q_max"]
    train = load(args.data, "massless_train")
    assert train is not None and np.all(train["params"][:, MASS] == 0), "no massless training set"
    keep = early_dark_energy(train["params"]) <= args.q_train * q_limit
    train = {k: (v[keep] if k == "params" or k.startswith("pk_") else v) for k, v in train.items()}
    y = residual_on_nodes(emu, train)
    h_exps = [e for e in exponents(args.degree) if e[MASS] == 0]
    F = features(coordinates(emu, train["params"]), h_exps)
    model = fit(y, F, args.pcs)
    fitted = predict(model, F).reshape(y.shape)
    lines = [f"massless head: {len(F)} training cosmologies (q <= {args.q_train} x bound), {len(h_exps)} terms "
             f"(degree {args.degree}), {args.pcs} PCs; |Y| on the nodes up to {np.abs(y).max():.2e}, "
             f"training residual up to {np.abs(fitted - y).max():.2e}"]
    worst = [0.0, 0.0]
    for kind in args.kinds.split(","):
        d = load(args.data, kind)
        if d is None:
            continue
        for label, head in (("base", None), ("with head", (h_exps, model))):
            rows = [r for r in check(emu, head, d, q_limit) if r[2][MASS] == 0]
            cbw = max(rows, key=lambda r: r[0])
            mw = max(rows, key=lambda r: r[1])
            lines.append(f"{kind:16s} {label:9s} {len(rows):4d} spectra: worst P_cb {cbw[0]:.2e} "
                         f"(params {np.round(cbw[2], 4).tolist()}, z {cbw[3]}), worst P_m {mw[1]:.2e} "
                         f"(params {np.round(mw[2], 4).tolist()}, z {mw[3]}, k {mw[4]:.3g})")
            if head is not None:
                worst = [max(worst[0], cbw[0]), max(worst[1], mw[1])]
    lines.append(f"WORST massless: P_cb {worst[0]:.2e}, P_m {worst[1]:.2e}")
    massive = [0.0, 0.0]
    for kind in args.massive_kinds.split(","):
        d = load(args.data, kind)
        assert d is not None, f"no check set {kind}"
        rows = [r for r in check(emu, None, d, q_limit) if r[2][MASS] > 0]
        cbw, mw = max(rows, key=lambda r: r[0]), max(rows, key=lambda r: r[1])
        lines.append(f"{kind:16s} base      {len(rows):4d} spectra: worst P_cb {cbw[0]:.2e} "
                     f"(params {np.round(cbw[2], 4).tolist()}, z {cbw[3]}), worst P_m {mw[1]:.2e} "
                     f"(params {np.round(mw[2], 4).tolist()}, z {mw[3]}, k {mw[4]:.3g})")
        massive = [max(massive[0], cbw[0]), max(massive[1], mw[1])]
    lines.append(f"WORST three degenerate (Sigma m_nu > 0): P_cb {massive[0]:.2e}, P_m {massive[1]:.2e}")
    fixed = fixed[:13 * 8] + np.array(massive, "<f8").tobytes()
    text = "\n".join(lines)
    print(text)
    if args.report:
        Path(args.report).write_text(text + "\n")
    if args.out:
        mean, comps, coef = model
        head = struct.pack("<4I", SETTING_MASSLESS, len(h_exps), len(comps), len(comps))
        head += np.array(h_exps, np.uint8).tobytes()
        for _ in range(2):  # P_cb and P_m: the same correction
            head += mean.astype("<f8").tobytes() + comps.astype("<f4").tobytes() + coef.astype("<f8").tobytes()
        head += np.array(worst, "<f8").tobytes()
        kept = [h for s, h in heads if s != SETTING_MASSLESS]
        with open(args.out, "wb") as f:
            f.write(emu["file"][:len(emu["raw"])] + fixed)
            f.write(struct.pack("<I", len(kept) + 1))
            f.write(b"".join(kept) + head)
        print("wrote", args.out, Path(args.out).stat().st_size, "bytes")


if __name__ == "__main__":
    main()
