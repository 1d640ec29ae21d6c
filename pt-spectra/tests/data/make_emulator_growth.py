#!/usr/bin/env python3
"""CAMB's scale-dependent growth of cold dark matter + baryons for the emulator tests (emulator_growth.dat).

Four cosmologies drawn uniformly (seed 13) over the emulator's prior with Sigma m_nu set to 0.06, 0.2, 0.35
and 0.5 eV (pt-spectra/data/make_emulator_training.py: PRIOR, camb_spectra: three degenerate neutrinos, PPF
dark energy, flat). D_cb(k, z) = T_cb(k, z)/T_cb(k, 0) = sqrt(P_cb(k, z)/P_cb(k, 0)) at z = 0.5, 1, 2, 3.
Rows: cosmology index, the eight parameters (Omega_b Omega_m h m_nu w0 wa ln10^10A_s n_s), z, k [h/Mpc],
D_cb; 30 k log-spaced in [1e-3, 1] h/Mpc.   Usage: OMP_NUM_THREADS=1 python3 make_emulator_growth.py
"""
import sys
from pathlib import Path

import camb
import numpy as np
from scipy.interpolate import CubicSpline

sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "data"))
from make_emulator_training import K_GRID, NAMES, PRIOR, camb_spectra  # noqa: E402

ZS = [0.5, 1.0, 2.0, 3.0]
lo = np.array([PRIOR[p][0] for p in NAMES])
hi = np.array([PRIOR[p][1] for p in NAMES])
rng = np.random.default_rng(13)
params = lo + rng.random((4, 8)) * (hi - lo)
params[:, NAMES.index("m_nu")] = [0.06, 0.2, 0.35, 0.5]
k_out = np.geomspace(1e-3, 1.0, 30)
rows = []
for i, x in enumerate(params):
    cb, _, _ = camb_spectra(x, [0.0] + ZS)
    ln = lambda p: CubicSpline(np.log(K_GRID), np.log(p))(np.log(k_out))  # noqa: E731
    for j, z in enumerate(ZS):
        d = np.exp(0.5 * (ln(cb[j + 1]) - ln(cb[0])))
        rows += [[i, *x, z, k, dk] for k, dk in zip(k_out, d)]
header = (f"CAMB {camb.__version__} D_cb(k, z) = sqrt(P_cb(k, z)/P_cb(k, 0)) for the emulator tests "
          "(make_emulator_growth.py)\nindex Omega_b Omega_m h m_nu w0 wa ln10^10A_s n_s z k D_cb")
np.savetxt(Path(__file__).parent / "emulator_growth.dat", rows, header=header, fmt=["%d"] + ["%.10g"] * 11)
