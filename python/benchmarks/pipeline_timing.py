"""Timing of ``pt_spectra.Pipeline`` (issue 47): the BOSS CMASS NGC windowed ``ept`` data vector
(P0, P2, P4 at 38 k from 0.015 to 0.38 h/Mpc through the Q_l window, AP against a fiducial), a new
cosmology at every call (emulator), a cosmology preset, a CAMB-like table, and the nuisance-only
step with its Jacobian. Prints ms per call; set RAYON_NUM_THREADS=1 for one core.

    python python/benchmarks/pipeline_timing.py [--calls 50]
"""

import argparse
import time
from pathlib import Path

import numpy as np

import pt_spectra as pt

WINDOW = Path(__file__).resolve().parents[2] / "examples/data/boss_dr12_cmass_ngc/window_BOSS_CMASS_NGC_z057.dat"
Z = 0.57
PARAMS = dict(b1=2.1, b2=-0.4, bs=0.3, alpha0=12.0, alpha2=-20.0, sn=1500.0)


def per_call(f, n):
    f(0)
    t = time.perf_counter()
    for i in range(n):
        f(i)
    return 1e3 * (time.perf_counter() - t) / n


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--calls", type=int, default=50)
    args = ap.parse_args()
    k = 0.015 * (0.38 / 0.015) ** (np.arange(38) / 37)
    obs = pt.Observation([0, 2, 4], k, window=str(WINDOW))
    fid = dict(h=0.676, omega_b=0.022, omega_cdm=0.31 * 0.676**2 - 0.022, n_s=0.97, sigma8=0.8)
    t = time.perf_counter()
    pipe = pt.Pipeline(obs, Z, fiducial=fid)
    print(f"build: {time.perf_counter() - t:.2f} s; data vector {pipe.meta['len']}")

    def cosmo(i):
        om = 0.28 + 0.04 * (i % 97) / 97
        return dict(h=0.69, omega_b=0.0224, omega_cdm=om * 0.69**2 - 0.0224, n_s=0.965, sigma8=0.81)

    print(f"emulator, new cosmology each call: {per_call(lambda i: pipe(cosmo(i), **PARAMS), args.calls):.3f} ms")
    print("  " + pipe.meta["loop_terms"])
    print(f"preset planck2018: {per_call(lambda i: pipe('planck2018', **PARAMS), args.calls):.3f} ms")
    print("  " + pipe.meta["loop_terms"])
    camb = Path(__file__).resolve().parents[2] / "pt-spectra/data/linear_pk_gm2012_z0.5.dat"
    kk, pp = np.loadtxt(camb, usecols=(0, 1), unpack=True)
    # resampled on another grid (the case: a CAMB table on the emulator's grid)
    kr = np.geomspace(kk[0], 8.9, 300)
    pr = np.exp(np.interp(np.log(kr), np.log(kk), np.log(pp)))
    print(f"CAMB table (gm2012 z = 0.5, resampled): "
          f"{per_call(lambda i: pipe('gm2012', linear=(kr, pr), z_input=0.5, **PARAMS), args.calls):.3f} ms")
    print("  " + pipe.meta["loop_terms"])
    print(f"with the nuisance Jacobian: {per_call(lambda i: pipe(cosmo(i), jacobian=True, **PARAMS), max(args.calls // 5, 3)):.3f} ms")


if __name__ == "__main__":
    main()
