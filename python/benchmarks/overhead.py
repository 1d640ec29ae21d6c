"""The cost of the Python face: wall time of a call from Python against the library call inside it.

Each Table's ``meta["seconds"]`` is the wall time of the library job alone (measured in Rust, GIL
released); the rest of a call (argument conversion, the linear spectrum's spline from the arrays, the
Table and its numpy columns) is the overhead. One run measures both, over the same calls:

    python python/benchmarks/overhead.py

Cases (the issue's): 1-loop SPT with terms on 100 k; TNS multipoles (1L-SPT, Lorentzian FoG, b, noise)
on 50 k, both through a plan built once, with P_lin given as numpy arrays as a chain would.
"""

import time
from pathlib import Path

import numpy as np

import pt_spectra as pt

ROOT = Path(__file__).resolve().parents[2]


def measure(call, repeats):
    call()  # warm up
    wall, inner = [], []
    for _ in range(repeats):
        start = time.perf_counter()
        table = call()
        wall.append(time.perf_counter() - start)
        inner.append(table.meta["seconds"])
    wall, inner = np.median(wall), np.median(inner)
    return wall, inner, (wall - inner) / inner


def main():
    d = np.loadtxt(ROOT / "pt-spectra" / "tests" / "data" / "linear_pk_planck2018_z0.0.dat")
    linear = (d[:, 0], d[:, 1])
    real = pt.RealPlan(np.geomspace(0.001, 1.0, 100), model="1l-spt")
    rsd = pt.RsdPlan(np.geomspace(0.01, 0.3, 50), real="1l-spt", rsd="tns")
    cases = {
        "1-loop SPT with terms, 100 k": lambda: real(linear=linear, cosmology="planck2018",
                                                     terms=True),
        "TNS multipoles (0, 2, 4), 50 k": lambda: rsd(linear=linear, cosmology="planck2018",
                                                     f=0.52, bias=2.0, fog="lorentzian",
                                                     sigma0=3.5, shot_noise=1e3),
    }
    print(f"{'case':34} {'python call':>12} {'library call':>13} {'overhead':>9}")
    for name, call in cases.items():
        wall, inner, overhead = measure(call, 200)
        print(f"{name:34} {wall * 1e3:9.3f} ms {inner * 1e3:10.3f} ms {overhead:8.1%}")


if __name__ == "__main__":
    main()
