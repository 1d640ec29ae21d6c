"""Times FAST-PT's 1-loop P_dd and its TNS A and B terms (RSD_components) on the embedded gm2012 z = 0 CAMB spectrum, for the README's comparison.

Not part of the build or the tests (the project needs no Python). Run with `pip install fast-pt` and
`python3 tests/benches/external/fastpt_timing.py`. FAST-PT works on its input grid, which must be log-uniform: we
time it on the 1200-point CAMB table (its normal use, and how the reference tables were made) and on a
100-point log grid in [1e-3, 1] h/Mpc resampled from it (the grid of our benchmark; far too coarse for
FAST-PT's accuracy, shown for the timing only).
"""
import os
import timeit

import numpy as np
import fastpt

here = os.path.dirname(os.path.abspath(__file__))
table = np.loadtxt(os.path.join(here, "..", "..", "..", "pt-spectra", "data", "linear_pk_gm2012_z0.0.dat"))
k, p = table[:, 0], table[:, 1]

def measure(k, p, label):
    fpt = fastpt.FASTPT(k, low_extrap=-5, high_extrap=3, n_pad=len(k) // 2)
    # FAST-PT 4 caches results per input array: scale P by a new factor on every call to time real work.
    scale = iter(1.0 + 1e-9 * np.arange(10**6))
    run = lambda: fpt.one_loop_dd(p * next(scale), P_window=np.array([0.2, 0.2]), C_window=0.75)
    run()
    times = timeit.repeat(run, number=20, repeat=5)
    best = min(times) / 20
    print(f"{label}: one_loop_dd {best * 1e3:.2f} ms per call (best of 5x20)")
    run = lambda: fpt.RSD_components(p * next(scale), 0.483135, P_window=np.array([0.2, 0.2]), C_window=0.75)
    run()
    best = min(timeit.repeat(run, number=5, repeat=5)) / 5
    print(f"{label}: RSD_components (TNS A, B) {best * 1e3:.2f} ms per call (best of 5x5)")

measure(k, p, "FAST-PT, 1200-point CAMB grid")
kk = np.logspace(-3, 0, 100)
measure(kk, np.exp(np.interp(np.log(kk), np.log(k), np.log(p))), "FAST-PT, 100 k in [1e-3, 1]")
