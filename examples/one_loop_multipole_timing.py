"""The one-loop galaxy multipoles B0, B2, B4 of the 62 Nseries triangles through Python, timed (issue 50):
`pt.OneLoopMultipolePlan` with a new linear spectrum (through the emulator) and growth rate at every call.

    RAYON_NUM_THREADS=1 python3 examples/one_loop_multipole_timing.py [--calls 200] [--bins]

The tensors are built on a 2 x 2 x 2 loop rule (the contraction's cost does not depend on the rule; one
triangle at the default rule takes ~190 s on one core) and cached in --cache-dir. Without --bins the plan is
at the triangles (the bins' centres; ~2 min to build on two cores); with --bins over the bins of width 0.01
h/Mpc (each bin's ~64 node triangles on the correction's 3 x 4 x 3 rule as well: ~25 min on two cores, once).
Prints the median time per call; the issue's target is 10 ms for the binned B0, B2, B4 of a new spectrum.
"""

import argparse
import statistics
import time
from pathlib import Path

import numpy as np

import pt_spectra as pt

TRIANGLES = Path(__file__).resolve().parents[1] / "tests/data/bispectrum/nseries_triangles.txt"
BIAS = dict(b1=2.0, b2=0.3, bs=-0.2)


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--calls", type=int, default=200)
    parser.add_argument("--bins", action="store_true", help="the bins of width 0.01 h/Mpc")
    parser.add_argument("--cache-dir", default=str(Path.home() / ".cache/pt-spectra"))
    args = parser.parse_args()
    triangles = np.loadtxt(TRIANGLES)[:, :3]
    start = time.perf_counter()
    plan = pt.OneLoopMultipolePlan(triangles, radial=2, mu=2, phi=2, cache_dir=args.cache_dir,
                                   bin_width=0.01 if args.bins else None)
    print(f"plan of {len(plan)} {'bins' if args.bins else 'triangles'}: {time.perf_counter() - start:.1f} s "
          "(built or read from the cache)")
    emulator = pt.LinearEmulator()
    spectra = []
    for i in range(20):
        c = dict(h=0.69, omega_b=0.0224, omega_cdm=0.115 + 0.01 * i / 20, n_s=0.965, sigma8=0.81)
        s = emulator.spectra(c, z=0.5)
        spectra.append((s["k"], s["P_m"]))
    times = []
    for i in range(args.calls):
        linear = spectra[i % len(spectra)]
        t0 = time.perf_counter()
        out = plan(linear=linear, f=0.6 + 0.01 * (i % 30), ir=False, **BIAS)
        times.append(time.perf_counter() - t0)
    print(f"median per call: {1e3 * statistics.median(times):.2f} ms "
          f"(10th-90th percentile {1e3 * np.percentile(times, 10):.2f}-{1e3 * np.percentile(times, 90):.2f}); "
          f"loop terms: {out['loop_terms'][:60]}...")


if __name__ == "__main__":
    main()
