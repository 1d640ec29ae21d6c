#!/usr/bin/env python3
"""Held-out CAMB spectra at small neutrino masses (emulator_small_masses.dat): how P_m/P_cb goes to 1.

Four cosmologies inside the emulator's stated prior (docs/emulator.md), each with three degenerate
neutrinos of total mass m_nu = 0, 0.005, 0.01, 0.02, 0.04, 0.06, 0.1 eV (make_emulator_training.camb_spectra:
PPF dark energy, flat, N_eff 3.046; Omega_m includes the neutrinos), A_s = 2.1e-9, n_s = 0.965, at z = 0
and 1; CAMB run to k = 2 h/Mpc. Rows: cosmology index, the eight parameters (Omega_b Omega_m h m_nu w0
wa ln10^10A_s n_s), z, k [h/Mpc], P_cb, P_m [(Mpc/h)^3]; 12 k log-spaced in [1e-3, 1] h/Mpc.
Usage: OMP_NUM_THREADS=1 python3 make_emulator_small_masses.py   (about a minute)
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
PARAMS = [  # Omega_b, Omega_m, h, w0, wa: Planck-like, and three spread over the stated box
    [0.049, 0.315, 0.674, -1.0, 0.0],
    [0.044, 0.27, 0.64, -1.15, 0.2],
    [0.055, 0.36, 0.70, -0.85, -0.4],
    [0.046, 0.30, 0.66, -0.9, 0.1],
]
MASSES = [0.0, 0.005, 0.01, 0.02, 0.04, 0.06, 0.1]
ZS = [0.0, 1.0]
k_out = np.geomspace(1e-3, 1.0, 12)
rows = []
for i, p in enumerate(PARAMS):
    for m_nu in MASSES:
        ob, om, h, w0, wa = p
        x = np.array([ob, om, h, m_nu, w0, wa, LN_AS, N_S])
        cb, m, _ = t.camb_spectra(x, ZS)
        for j, z in enumerate(ZS):
            ln = lambda q: CubicSpline(np.log(t.K_GRID), np.log(q[j]))(np.log(k_out))  # noqa: E731
            for kk, a, b in zip(k_out, np.exp(ln(cb)), np.exp(ln(m))):
                rows.append([i, *x, z, kk, a, b])
        print(f"cosmology {i}, m_nu = {m_nu}", flush=True)
header = (f"CAMB {camb.__version__} spectra at small neutrino masses (make_emulator_small_masses.py)\n"
          "index Omega_b Omega_m h m_nu w0 wa ln10^10A_s n_s z k P_cb P_m")
np.savetxt(Path(__file__).parent / "emulator_small_masses.dat", rows, header=header,
           fmt=["%d"] + ["%.10g"] * 12)
