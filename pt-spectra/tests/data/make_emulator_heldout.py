#!/usr/bin/env python3
"""Held-out CAMB spectra for the tests of the linear-spectrum emulator (emulator_heldout.dat).

16 cosmologies drawn uniformly (seed 11, not the seeds of the training or test sets) over the emulator's
prior (pt-spectra/data/make_emulator_training.py: PRIOR, computed by its camb_spectra: three degenerate
neutrinos, PPF dark energy, flat), each at one random redshift in [0.02, 2.98] and at z +- 0.01. Rows:
cosmology index, the eight parameters (Omega_b Omega_m h m_nu w0 wa ln10^10A_s n_s), z, k [h/Mpc],
P_cb, P_m [(Mpc/h)^3], f_cb = -d ln P_cb / (2 d ln(1+z)) by central differences, sigma8(z) of P_m;
40 k log-spaced in [1e-3, 1] h/Mpc.   Usage: OMP_NUM_THREADS=1 python3 make_emulator_heldout.py
"""
import sys
from pathlib import Path

import camb
import numpy as np
from scipy.interpolate import CubicSpline

sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "data"))
from make_emulator_training import K_GRID, NAMES, PRIOR, camb_spectra  # noqa: E402

DZ = 0.01
lo = np.array([PRIOR[p][0] for p in NAMES])
hi = np.array([PRIOR[p][1] for p in NAMES])
rng = np.random.default_rng(11)
params = lo + rng.random((16, 8)) * (hi - lo)
zs = rng.uniform(0.02, 2.98, 16)
k_out = np.geomspace(1e-3, 1.0, 40)
rows = []
for i, (x, z) in enumerate(zip(params, zs)):
    cb, m, s8 = camb_spectra(x, [z, z + DZ, z - DZ])
    # on the output k by a cubic spline of CAMB's table in ln k
    ln = lambda p: CubicSpline(np.log(K_GRID), np.log(p))(np.log(k_out))  # noqa: E731
    f = -(ln(cb[1]) - ln(cb[2])) / (2 * (np.log1p(z + DZ) - np.log1p(z - DZ)))
    p_cb, p_m = np.exp(ln(cb[0])), np.exp(ln(m[0]))
    for j, k in enumerate(k_out):
        rows.append([i, *x, z, k, p_cb[j], p_m[j], f[j], s8[0]])
header = (f"CAMB {camb.__version__} held-out spectra for the emulator tests (make_emulator_heldout.py)\n"
          "index Omega_b Omega_m h m_nu w0 wa ln10^10A_s n_s z k P_cb P_m f_cb sigma8_m(z)")
np.savetxt(Path(__file__).parent / "emulator_heldout.dat", rows, header=header,
           fmt=["%d"] + ["%.10g"] * 14)
