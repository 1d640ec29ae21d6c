#!/usr/bin/env python3
"""Held-out CAMB spectra at corners of the emulator's stated prior (emulator_corners.dat).

Three corners of the box the emulator states (the training box shrunk by 0.8 about its centre, see
docs/emulator.md), among them the worst found by pt-spectra/data/fit_emulator_neutrinos.py, with
A_s = 2.1e-9, n_s = 0.965, three degenerate neutrinos (make_emulator_training.camb_spectra: PPF dark
energy, flat, N_eff 3.046), at z = 0, 1, 3; CAMB run to k = 2 h/Mpc. Rows: cosmology index, the eight
parameters (Omega_b Omega_m h m_nu w0 wa ln10^10A_s n_s), z, k [h/Mpc], P_cb, P_m [(Mpc/h)^3]; 12 k
log-spaced in [1e-3, 1] h/Mpc.   Usage: OMP_NUM_THREADS=1 python3 make_emulator_corners.py
"""
import sys
from pathlib import Path

import camb
import numpy as np
from scipy.interpolate import CubicSpline

sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "data"))
import make_emulator_training as t  # noqa: E402

t.K_GRID = t.K_GRID[t.K_GRID <= 2.0]
LN_AS, N_S = np.log(21.0), 0.965
PARAMS = [  # Omega_b, Omega_m, h, m_nu, w0, wa: corners of the stated box
    [0.058, 0.384, 0.718, 0.45, -0.76, -0.58],
    [0.042, 0.256, 0.622, 0.05, -1.24, -0.58],
    [0.042, 0.384, 0.622, 0.05, -0.76, 0.38],
]
ZS = [0.0, 1.0, 3.0]
k_out = np.geomspace(1e-3, 1.0, 12)
rows = []
for i, p in enumerate(PARAMS):
    x = np.array([*p, LN_AS, N_S])
    cb, m, _ = t.camb_spectra(x, ZS)
    for j, z in enumerate(ZS):
        ln = lambda q: CubicSpline(np.log(t.K_GRID), np.log(q[j]))(np.log(k_out))  # noqa: E731
        for kk, a, b in zip(k_out, np.exp(ln(cb)), np.exp(ln(m))):
            rows.append([i, *x, z, kk, a, b])
header = (f"CAMB {camb.__version__} spectra at corners of the emulator's stated prior "
          "(make_emulator_corners.py)\nindex Omega_b Omega_m h m_nu w0 wa ln10^10A_s n_s z k P_cb P_m")
np.savetxt(Path(__file__).parent / "emulator_corners.dat", rows, header=header,
           fmt=["%d"] + ["%.10g"] * 12)
