#!/usr/bin/env python3
"""Held-out CAMB spectra with massless and light neutrinos at the emulator's worst points
(emulator_massless.dat).

Sigma m_nu = 0 is the edge of the base emulator's training box, and CAMB's massless run is not the limit
of its massive runs; the massless head (pt-spectra/data/fit_emulator_massless.py) corrects it. The
cosmologies are those pt-spectra/data/fit_emulator_massless.py found worst (none is a training point):
  0  the massless corner where the base emulator was worst (3.0e-3 before the head)
  1  the massless random draw where the base emulator was worst (2.75e-3)
  2  the massless corner worst with the head (8.1e-4)
  3  the massless random draw worst with the head (1.06e-3)
  4  the light corner (Sigma m_nu = 0.03 eV) worst for the base emulator (1.31e-3)
  5  a light corner with Sigma m_nu = 0.01 eV at the dark-energy corner of row 0
Three degenerate species where massive (make_emulator_training.camb_spectra: PPF dark energy, flat,
N_eff 3.046), at z = 0, 0.5, 1, 3; CAMB run to k = 2 h/Mpc. Rows: cosmology index, the eight parameters
(Omega_b Omega_m h m_nu w0 wa ln10^10A_s n_s), z, k [h/Mpc], P_cb, P_m [(Mpc/h)^3]; 12 k log-spaced in
[1e-3, 1] h/Mpc.   Usage: OMP_NUM_THREADS=1 python3 make_emulator_massless.py
"""
import sys
from pathlib import Path

import camb
import numpy as np
from scipy.interpolate import CubicSpline

sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "data"))
import make_emulator_training as t  # noqa: E402

t.K_GRID = t.K_GRID[t.K_GRID <= 2.0]
PLANCK = [np.log(21.0), 0.965]
PARAMS = [  # Omega_b, Omega_m, h, m_nu, w0, wa, ln10^10 A_s, n_s
    [0.042, 0.256, 0.622, 0.0, -1.24, 0.38, *PLANCK],
    [0.0571, 0.2568, 0.6303, 0.0, -0.9021, -0.5612, 2.7178, 0.9647],
    [0.058, 0.256, 0.622, 0.0, -0.76, -0.58, *PLANCK],
    [0.0558, 0.3032, 0.6938, 0.0, -0.946, -0.3331, 2.8227, 0.959],
    [0.058, 0.256, 0.622, 0.03, -1.24, -0.58, *PLANCK],
    [0.042, 0.256, 0.622, 0.01, -1.24, 0.38, *PLANCK],
]
ZS = [0.0, 0.5, 1.0, 3.0]
k_out = np.geomspace(1e-3, 1.0, 12)
rows = []
for i, p in enumerate(PARAMS):
    x = np.array(p)
    cb, m, _ = t.camb_spectra(x, ZS)
    for j, z in enumerate(ZS):
        ln = lambda q: CubicSpline(np.log(t.K_GRID), np.log(q[j]))(np.log(k_out))  # noqa: E731
        for kk, a, b in zip(k_out, np.exp(ln(cb)), np.exp(ln(m))):
            rows.append([i, *x, z, kk, a, b])
header = (f"CAMB {camb.__version__} spectra with massless and light neutrinos at the emulator's worst "
          "points (make_emulator_massless.py)\n"
          "index Omega_b Omega_m h m_nu w0 wa ln10^10A_s n_s z k P_cb P_m")
np.savetxt(Path(__file__).parent / "emulator_massless.dat", rows, header=header,
           fmt=["%d"] + ["%.10g"] * 12)
