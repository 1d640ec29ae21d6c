"""Per-spectrum cost through Python with the basis tensors (issue: every spectrum of a new cosmology
in under a millisecond), one core, a new CAMB spectrum at every call, tensors cached:

    python python/benchmarks/basis_timing.py            # needs camb; fast-pt for the comparison

* 1-loop SPT δδ, δθ, θθ with all terms, 100 k in [1e-3, 1]: ``RealPlan.batch`` (arrays) and the
  ``RealPlan`` call (a Table with its header), against FAST-PT's ``one_loop_dd`` on its 1200-point
  grid in the same run;
* TNS multipoles ℓ = 0, 2, 4 from 1L-SPT, 50 k; the galaxy model ``ept`` with IR, 50 k (both with
  ``two_loop="basis"``: the real-space, TNS and galaxy-model terms from their basis tensors);
* 2L-SPT and 2L-RegPT, 40 k in [0.005, 0.4] (1- and 2-loop terms from the basis tensors, RegPT's
  vertex Γ2 from linear forms on the basis), ``RealPlan.batch`` with terms;
* a batch of 100 spectra on 1 and on 2 threads (separate processes: the pool is set once);
* 1-loop and 2L-SPT again for curved cosmologies (Ω_k in ±0.01: projected cut below 1e-3 h/Mpc, the
  soft modes put back; module ``loops::basis::soft``).

Medians over the calls; the spectra are CAMB's for 8 cosmologies inside the EuclidEmulator2 box.
"""

import subprocess
import sys
import time
from pathlib import Path

import numpy as np

import pt_spectra as pt


def camb_spectra(n=8, seed=3, omk=0.0):
    import camb
    rng = np.random.default_rng(seed)
    out = []
    for _ in range(n):
        h = rng.uniform(0.62, 0.74)
        pars = camb.set_params(H0=100 * h, ombh2=rng.uniform(0.040, 0.055) * h**2,
                               omch2=(rng.uniform(0.26, 0.36) - 0.048) * h**2,
                               ns=rng.uniform(0.93, 1.0), As=rng.uniform(1.8e-9, 2.4e-9),
                               omk=rng.uniform(-omk, omk),
                               mnu=0.0, num_massive_neutrinos=0, WantTransfer=True,
                               kmax=60.0, redshifts=[0.0])
        res = camb.get_results(pars)
        k, _, p = res.get_matter_power_spectrum(minkh=1e-4, maxkh=50, npoints=700)
        out.append((k, p[0]))
    return out


def median_ms(call, spectra, repeats=200):
    call(*spectra[0])
    times = []
    for i in range(repeats):
        k, p = spectra[i % len(spectra)]
        p = p * (1 + 1e-6 * i)  # a new array every call
        start = time.perf_counter()
        call(k, p)
        times.append(time.perf_counter() - start)
    return 1e3 * np.median(times)


def batch_throughput(threads, spectra):
    """ms per spectrum of a batch of 100 on `threads` threads (run in a child process)."""
    code = f"""
import numpy as np, pt_spectra as pt, time, pickle, sys
pt.set_num_threads({threads})
k_lin, P = pickle.load(sys.stdin.buffer)
plan = pt.RealPlan(np.geomspace(1e-3, 1, 100), model="1l-spt", two_loop="basis")
plan.batch(k_lin, P, terms=True)
best = min((lambda s: (plan.batch(k_lin, P, terms=True), time.perf_counter() - s)[1])(time.perf_counter())
           for _ in range(5))
print(1e3 * best / len(P))
"""
    import pickle
    k = spectra[0][0]
    P = np.stack([np.interp(k, s[0], s[1]) * (1 + 1e-3 * i)
                  for i, s in enumerate(spectra * 13)][:100])
    out = subprocess.run([sys.executable, "-c", code], input=pickle.dumps((k, P)),
                         capture_output=True, check=True)
    return float(out.stdout)


def main():
    spectra = camb_spectra()
    real = pt.RealPlan(np.geomspace(1e-3, 1, 100), model="1l-spt", two_loop="basis")
    tns = pt.RsdPlan(np.geomspace(0.01, 0.3, 50), real="1l-spt", rsd="tns", two_loop="basis")
    ept = pt.EptPlan(np.geomspace(0.01, 0.3, 50), ir=True, two_loop="basis")
    two_loop_k = np.geomspace(0.005, 0.4, 40)
    spt2l = pt.RealPlan(two_loop_k, model="2l-spt", two_loop="basis")
    regpt = pt.RealPlan(two_loop_k, model="2l-regpt", two_loop="basis")
    rows = [
        ("1-loop SPT + terms, 100 k: batch (arrays)",
         median_ms(lambda k, p: real.batch(k, p, terms=True), spectra)),
        ("1-loop SPT + terms, 100 k: RealPlan call (Table)",
         median_ms(lambda k, p: real(linear=(k, p), cosmology="planck2018", terms=True), spectra)),
        ("TNS P0 P2 P4 from 1L-SPT, 50 k",
         median_ms(lambda k, p: tns(linear=(k, p), cosmology="planck2018", f=0.52, bias=2.0,
                                    fog="lorentzian", sigma0=3.5), spectra, 50)),
        ("ept (IR on), 50 k",
         median_ms(lambda k, p: ept(linear=(k, p), cosmology="planck2018", b1=2.0), spectra, 50)),
        ("2L-SPT + terms, 40 k: batch (arrays)",
         median_ms(lambda k, p: spt2l.batch(k, p, terms=True), spectra, 50)),
        ("2L-RegPT + terms, 40 k: batch (arrays)",
         median_ms(lambda k, p: regpt.batch(k, p, terms=True), spectra, 50)),
    ]
    try:
        import fastpt
        k, p = spectra[0]
        kk = np.geomspace(k[0], k[-1], 1200)
        pp = np.exp(np.interp(np.log(kk), np.log(k), np.log(p)))
        fpt = fastpt.FASTPT(kk, low_extrap=-5, high_extrap=3, n_pad=600)
        rows.append(("FAST-PT one_loop_dd (1200-point grid)",
                     median_ms(lambda _k, p: fpt.one_loop_dd(
                         np.exp(np.interp(np.log(kk), np.log(_k), np.log(p))),
                         P_window=np.array([0.2, 0.2]), C_window=0.75),
                         spectra, 50)))
    except ImportError:
        pass
    for threads in (1, 2):
        rows.append((f"batch of 100, 1-loop + terms, {threads} thread(s), per spectrum",
                     batch_throughput(threads, spectra)))
    curved = camb_spectra(seed=5, omk=0.01)
    rows += [
        ("curved (|Omega_k| <= 0.01): 1-loop SPT + terms, 100 k, batch",
         median_ms(lambda k, p: real.batch(k, p, terms=True), curved)),
        ("curved (|Omega_k| <= 0.01): 2L-SPT + terms, 40 k, batch",
         median_ms(lambda k, p: spt2l.batch(k, p, terms=True), curved, 50)),
    ]
    for name, ms in rows:
        print(f"{name:58} {ms:8.3f} ms")


if __name__ == "__main__":
    main()
