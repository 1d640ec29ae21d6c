#!/usr/bin/env python3
"""CAMB spectra for the emulator's neutrino head and for its accuracy over the corners of the prior.

Usage:  OMP_NUM_THREADS=1 python3 make_emulator_neutrinos.py KIND START STOP OUTDIR [SHRINK [SETTINGS]]

Every cosmology is computed by make_emulator_training.camb_spectra (PPF dark energy, flat, N_eff = 3.046,
T_CMB = 2.7255 K, Omega_m including the neutrinos fixed) once per neutrino setting of NEUTRINOS there:
"degenerate" (three degenerate massive species, the emulator's base) and "one" (one massive species of
mass Sigma m_nu and 2.0307 massless: CAMB's default num_massive_neutrinos=1, CLASS's N_ncdm = 1).
KIND:
  train    a scrambled Sobol sequence (seed 2027, not the base emulator's 2026) over the six shape
           parameters of the prior, A_s = 2e-9, n_s = 1, at the base emulator's Z_NODES; fit_emulator.py
           --neutrinos fits ln(P_one/P_degenerate) (of P_cb and of P_m) to it.
  corners  the 64 corners of the six shape parameters' box (A_s = 2.1e-9, n_s = 0.965) at Z_CHECK.
  massless the 32 corners of the box with Sigma m_nu = 0 (the lower end of m_nu is not shrunk).
  light    the 64 corners of the box (SHRINK applies) with Sigma m_nu = 0.01 or 0.03 eV: light masses
           between the massless set and the box's lower end.
  massless_train  a scrambled Sobol sequence (seed 2028) over the five shape parameters other than m_nu
           (the training box), Sigma m_nu = 0, A_s = 2e-9, n_s = 1, at Z_NODES: fit_emulator_massless.py
           fits the massless head (CAMB's massless spectrum over the base emulator's at Sigma m_nu = 0).
  massless_random  uniform draws (seed 19) over the box (SHRINK applies) with Sigma m_nu = 0 and A_s,
           n_s drawn too, at Z_CHECK.
  edge     the early-dark-energy edge: w0 + wa in EDGE_SUMS on its two ends (w0 = -0.7, or wa = 0.5),
           the other four shape parameters at the 16 corners of their box, at Z_CHECK.
  random   uniform draws (seed 17) over all eight parameters, each at Z_CHECK.
SHRINK (default 1) scales the box of the six shape parameters about its centre (corners, edge,
random), SETTINGS (default degenerate,one) lists the neutrino settings to compute.
None of these is a training or test point of the base emulator. Output: OUTDIR/KIND[-SHRINK]_START_STOP.npz with
params (n, 8: Omega_b, Omega_m, h, m_nu, w0, wa, ln10^10 A_s, n_s), z (nz), k (h/Mpc), and per setting S
pk_cb_S, pk_m_S (n, nz, nk) in (Mpc/h)^3 (k to 10 h/Mpc for train, K_CHECK_MAX for the others). About 2 x 1.5 s per cosmology on one free core.
"""
import itertools
import sys
import time

import camb
import make_emulator_training
import numpy as np
from scipy.stats import qmc

from make_emulator_training import K_GRID, NAMES, PRIOR, Z_NODES, camb_spectra

# The checks need k <= 1 h/Mpc only: CAMB runs to 2 h/Mpc for them (1.9x faster; ln P for
# 1e-3 <= k <= 1 differs from a run to the training's 10 h/Mpc by 6e-6)
K_CHECK_MAX = 2.0

SETTINGS = ["degenerate", "one"]
Z_CHECK = [0.0, 0.5, 1.0, 2.0, 3.0]
EDGE_SUMS = [-0.25, -0.3, -0.35, -0.4, -0.45]
LO = np.array([PRIOR[p][0] for p in NAMES])
HI = np.array([PRIOR[p][1] for p in NAMES])
PLANCK_AS = (np.log(21.0), 0.965)  # ln 10^10 A_s, n_s of the corner and edge sets


def cosmologies(kind, shrink=1.0):
    """(params (n, 8), redshifts) of a kind; `shrink` scales the box of the six shape parameters about
    its centre (corners, edge, random)."""
    lo, hi = LO.copy(), HI.copy()
    centre, half = (LO + HI) / 2, (HI - LO) / 2
    lo[:6], hi[:6] = centre[:6] - shrink * half[:6], centre[:6] + shrink * half[:6]
    box = {p: (lo[i], hi[i]) for i, p in enumerate(NAMES)}
    if kind == "train":
        u = qmc.Sobol(d=6, scramble=True, seed=2027).random(256)
        x = LO[:6] + u * (HI[:6] - LO[:6])
        return np.hstack([x, np.tile([np.log(20.0), 1.0], (len(x), 1))]), Z_NODES
    if kind == "corners":
        x = np.array(list(itertools.product(*[box[p] for p in NAMES[:6]])))
        return np.hstack([x, np.tile(PLANCK_AS, (len(x), 1))]), Z_CHECK
    if kind == "massless":  # the 32 corners of the box with Sigma m_nu = 0 (its lower end, unshrunk)
        b = dict(box, m_nu=(0.0,))
        x = np.array(list(itertools.product(*[b[p] for p in NAMES[:6]])))
        return np.hstack([x, np.tile(PLANCK_AS, (len(x), 1))]), Z_CHECK
    if kind == "light":
        b = dict(box, m_nu=(0.01, 0.03))
        x = np.array(list(itertools.product(*[b[p] for p in NAMES[:6]])))
        return np.hstack([x, np.tile(PLANCK_AS, (len(x), 1))]), Z_CHECK
    if kind == "massless_train":
        u = qmc.Sobol(d=5, scramble=True, seed=2028).random(1024)
        five = [0, 1, 2, 4, 5]
        x = np.zeros((len(u), 8))
        x[:, five] = LO[five] + u * (HI[five] - LO[five])
        x[:, 6:] = [np.log(20.0), 1.0]
        return x, Z_NODES
    if kind == "massless_random":
        rng = np.random.default_rng(19)
        x = lo + rng.random((256, 8)) * (hi - lo)
        x[:, 3] = 0.0
        return x, Z_CHECK
    if kind == "edge":
        rows = []
        for s in EDGE_SUMS:
            for w0, wa in ((-0.7, s + 0.7), (s - 0.5, 0.5)):
                for rest in itertools.product(*[box[p] for p in NAMES[:4]]):
                    rows.append([*rest, w0, wa, *PLANCK_AS])
        return np.array(rows), Z_CHECK
    if kind == "random":
        rng = np.random.default_rng(17)
        return lo + rng.random((256, 8)) * (hi - lo), Z_CHECK
    raise SystemExit(f"unknown kind {kind!r}: train, corners, massless, light, massless_train, "
                     "massless_random, edge or random")


def main():
    kind, start, stop, outdir = sys.argv[1], int(sys.argv[2]), int(sys.argv[3]), sys.argv[4]
    shrink = float(sys.argv[5]) if len(sys.argv) > 5 else 1.0
    settings = sys.argv[6].split(",") if len(sys.argv) > 6 else SETTINGS
    params, zs = cosmologies(kind, shrink)
    params = params[start:stop]
    if kind not in ("train", "massless_train"):
        make_emulator_training.K_GRID = K_GRID[K_GRID <= K_CHECK_MAX]
    out = {f"pk_{t}_{s}": [] for t in ("cb", "m") for s in settings}
    t0 = time.time()
    for j, x in enumerate(params):
        for s in settings:
            cb, m, _ = camb_spectra(x, zs, s)
            out[f"pk_cb_{s}"].append(cb)
            out[f"pk_m_{s}"].append(m)
        print(f"{kind} {start + j}: {time.time() - t0:.0f} s", flush=True)
    tag = "" if shrink == 1.0 else f"-{shrink}"
    np.savez(f"{outdir}/{kind}{tag}_{start}_{stop}.npz", params=params, z=np.asarray(zs),
             k=make_emulator_training.K_GRID,
             camb_version=camb.__version__, **{k: np.array(v) for k, v in out.items()})


if __name__ == "__main__":
    main()
