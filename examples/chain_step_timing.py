"""The chain step through Python, timed (issue 47): the BOSS DR12 CMASS NGC windowed `ept` data vector
(P0, P2, P4 in 38 bins through the Q_l window, AP against a fiducial), a new cosmology at every call.

    RAYON_NUM_THREADS=1 python3 examples/chain_step_timing.py [--calls 300]

Prints the median time per call of: a new cosmology through the emulator; the same with the nuisance
Jacobian (jacobian=True: the 11 nuisance parameters and f); the same cosmology again with new nuisance parameters
(a nuisance-only step through Python); a new cosmology from a given linear table (the emulator's own
spectrum, passed as arrays), against which the emulated steps are timed in turn (σ8- and
A_s-normalised: σ8 needs the emulated shape at z = 0 as well); a new cosmology with the exact derivatives in the eight sampled
cosmological parameters (`cosmology_jacobian`, the cosmology given with ln10^{10}A_s), and with those
and the nuisance rows of the same step (`full_jacobian`). Needs numpy and the Python module (`pip install ./python`); the basis tensors
are built on the first run (minutes) and cached. The issue's targets: 0.5 ms per call through Python
(0.3 ms in Rust), 2 ms with the full Jacobian, 20 us per nuisance step.
"""

import argparse
import statistics
import time
from pathlib import Path

import numpy as np

import pt_spectra as pt

WINDOW = Path(__file__).resolve().parent / "data/boss_dr12_cmass_ngc/window_BOSS_CMASS_NGC_z057.dat"
Z = 0.57
PARAMS = dict(b1=2.1, b2=-0.4, bs=0.3, alpha0=12.0, alpha2=-20.0, sn=1500.0)
FIDUCIAL = dict(h=0.676, omega_b=0.022, omega_cdm=0.31 * 0.676**2 - 0.022,
                n_s=0.97, sigma8=0.8)


def cosmology(i):
    """A new cosmology at every call: ω_cdm moves along the prior."""
    return dict(h=0.69, omega_b=0.0224, omega_cdm=0.115 + 0.01 * ((i % 97) / 97.0), n_s=0.965,
                sigma8=0.81)


def with_a_s(c):
    """The cosmology normalised by ln10^{10}A_s (what the cosmological derivatives are taken in)."""
    c = dict(c)
    c.pop("sigma8")
    return dict(c, **{"ln10^{10}A_s": 3.0})


def median_ms(f, calls):
    times = []
    for i in range(calls):
        t0 = time.perf_counter()
        f(i)
        times.append(time.perf_counter() - t0)
    return 1e3 * statistics.median(times)


def interleaved_ms(fs, calls, block=25):
    """The median times of the calls `fs`, made in turn in blocks of `block` calls each (so that a
    change of the machine's load reaches each alike, while each path keeps its caches warm within a
    block as a chain does: one call of each in turn would let each evict the other's data)."""
    times = [[] for _ in fs]
    for start in range(0, calls, block):
        for f, t in zip(fs, times):
            for i in range(start, min(start + block, calls)):
                t0 = time.perf_counter()
                f(i)
                t.append(time.perf_counter() - t0)
    return [1e3 * statistics.median(t) for t in times]


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--calls", type=int, default=300)
    a = ap.parse_args()
    k = 0.015 * (0.38 / 0.015) ** (np.arange(38) / 37)
    obs = pt.Observation([0, 2, 4], k, window=str(WINDOW))
    t0 = time.perf_counter()
    pipe = pt.Pipeline(obs, Z, fiducial=FIDUCIAL)
    print(f"built in {time.perf_counter() - t0:.1f} s; {pipe.meta['loop_range_note']}")
    pipe(cosmology(0), **PARAMS)
    emulator = pt.LinearEmulator()
    tables = [emulator.spectra(cosmology(i), Z) for i in range(97)]
    rows = [
        ("new cosmology (emulator)", lambda i: pipe(cosmology(i), **PARAMS)),
        ("new cosmology + nuisance Jacobian",
         lambda i: pipe(cosmology(i), jacobian=True, **PARAMS)),
        ("nuisance-only step (same cosmology)",
         lambda i: pipe(cosmology(0), **dict(PARAMS, b1=2.0 + 1e-3 * (i % 50)))),
        ("new cosmology + cosmological Jacobian",
         lambda i: pipe.cosmology_jacobian(with_a_s(cosmology(i)), **PARAMS)),
        ("new cosmology + full Jacobian (8 + 12 rows)",
         lambda i: pipe.full_jacobian(with_a_s(cosmology(i)), **PARAMS)),
        ("new cosmology from a table (arrays)",
         lambda i: pipe(cosmology(i), linear=(tables[i % 97]["k"], tables[i % 97]["P_cb"]),
                        z_input=Z, **PARAMS)),
    ]
    print(f"median of {a.calls} calls, one thread (set RAYON_NUM_THREADS=1):")
    for name, f in rows:
        print(f"  {name:40s} {median_ms(f, a.calls):7.3f} ms")
    print(f"  last call: {pipe.meta['loop_terms']}")
    # sigma8 normalises by the emulated shape at z = 0 too; ln10^{10}A_s (what chains sample) does not
    by_a_s = lambda i: pipe(with_a_s(cosmology(i)), **PARAMS)
    emulated, emulated_a_s, tabled = interleaved_ms([rows[0][1], by_a_s, rows[-1][1]], a.calls)
    print(f"  emulator against table, in turn by blocks of 25 calls: {emulated:.3f} (sigma8), "
          f"{emulated_a_s:.3f} (A_s) against {tabled:.3f} ms ({100 * (emulated / tabled - 1):+.1f}%, "
          f"{100 * (emulated_a_s / tabled - 1):+.1f}%; the issue's bound 10%)")


if __name__ == "__main__":
    main()
