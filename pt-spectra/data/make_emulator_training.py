#!/usr/bin/env python3
"""CAMB spectra that train and test the linear-spectrum emulator (pt_spectra::emulator).

Usage:  OMP_NUM_THREADS=1 python3 make_emulator_training.py {train|test} START STOP OUTDIR

Each cosmology is drawn from the emulator's prior (the box of EuclidEmulator2 widened in Sigma m_nu and
ln 10^10 A_s, see PRIOR) and computed by CAMB (version printed in the output) with:
  * three degenerate massive neutrinos of total mass m_nu (N_eff = 3.046, CAMB's default splitting of
    massless/massive), T_CMB = 2.7255 K, flat;
  * w0-wa dark energy in CAMB's PPF model (which may cross w = -1);
  * the linear P(k) of cold dark matter + baryons ('delta_nonu', P_cb) and of all matter ('delta_tot', P_m)
    in (Mpc/h)^3 on K_GRID (h/Mpc), through CAMB's own interpolation of its transfer functions.
Training set ('train'): a scrambled Sobol sequence (seed 2026) over the six parameters that shape the
transfer functions (Omega_b, Omega_m, h, m_nu, w0, wa), at A_s = 2e-9, n_s = 1: the primordial factor
A_s (k h / 0.05)^(n_s - 1) is exact and divided out by the emulator. Redshifts: Z_NODES.
Test set ('test'): uniform random draws (seed 7) over all eight parameters, each at Z_NODES and three
random redshifts in [0.02, 2.98], each of those also at z +- DZ for the growth rate by finite differences.
The shipped linear_emulator.bin was fitted to train 0..3072 (in chunks of 256 or 512; the Sobol points
do not depend on the chunking) and tested on test 0..240; about 1.5 s per cosmology on one core.
Output: OUTDIR/{train|test}_START_STOP.npz with params (n, 8: Omega_b, Omega_m, h, m_nu, w0, wa,
ln10^10 A_s, n_s), z (n, nz), pk_cb and pk_m (n, nz, nk), sigma8 (n, nz: CAMB's sigma8 of delta_tot), k.
"""
import sys
import time

import camb
import numpy as np
from scipy.stats import qmc

PRIOR = {  # name: (min, max); the emulator's documented prior
    "Omega_b": (0.04, 0.06),
    "Omega_m": (0.24, 0.40),
    "h": (0.61, 0.73),
    "m_nu": (0.0, 0.5),
    "w0": (-1.3, -0.7),
    "wa": (-0.7, 0.5),
    "logA": (2.5, 3.5),
    "n_s": (0.92, 1.00),
}
NAMES = list(PRIOR)
K_GRID = np.geomspace(1e-4, 10.0, 500)
Z_NODES = np.expm1(np.linspace(0.0, np.log(4.0), 9))
DZ = 0.01


def draws(kind, n):
    lo = np.array([PRIOR[p][0] for p in NAMES])
    hi = np.array([PRIOR[p][1] for p in NAMES])
    if kind == "train":
        u = qmc.Sobol(d=6, scramble=True, seed=2026).random(n)
        u = np.hstack([u, np.zeros((n, 2))])
        x = lo + u * (hi - lo)
        x[:, 6] = np.log(10 * 2.0)  # A_s = 2e-9
        x[:, 7] = 1.0
        return x
    rng = np.random.default_rng(7)
    return lo + rng.random((n, 8)) * (hi - lo)


def redshifts(kind, i):
    if kind == "train":
        return Z_NODES
    rng = np.random.default_rng(1000 + i)
    extra = rng.uniform(2 * DZ, 3.0 - 2 * DZ, 3)
    extra = np.concatenate([extra, extra + DZ, extra - DZ])
    return np.concatenate([Z_NODES, extra])


# CAMB's neutrino settings by the names of pt_spectra::cosmology::Neutrinos: (num_massive_neutrinos,
# neutrino_hierarchy); N_eff = 3.046 in all
NEUTRINOS = {
    "degenerate": (3, "degenerate"),  # three degenerate massive species (the emulator's base)
    "one": (1, "degenerate"),  # one massive species and N_eff - 1.0153 massless (CAMB's default)
    "normal": (3, "normal"),
    "inverted": (3, "inverted"),
}


def camb_spectra(x, zs, neutrinos="degenerate"):
    ob, om, h, mnu, w0, wa, loga, ns = x
    n_massive, hierarchy = NEUTRINOS[neutrinos]
    nu = dict(mnu=mnu, num_massive_neutrinos=n_massive, neutrino_hierarchy=hierarchy, omk=0,
              TCMB=2.7255, nnu=3.046)
    p = camb.CAMBparams()
    p.set_cosmology(H0=100 * h, ombh2=ob * h * h, omch2=0.1, **nu)
    omnuh2 = p.omnuh2
    p.set_cosmology(H0=100 * h, ombh2=ob * h * h, omch2=(om - ob) * h * h - omnuh2, **nu)
    p.set_dark_energy(w=w0, wa=wa, dark_energy_model="ppf")
    p.InitPower.set_params(As=np.exp(loga) * 1e-10, ns=ns)
    order = np.argsort(zs)[::-1]
    p.set_matter_power(redshifts=list(np.asarray(zs)[order]), kmax=1.2 * K_GRID[-1] * h,
                       nonlinear=False)
    p.NonLinear = camb.model.NonLinear_none
    p.WantCls = False
    r = camb.get_results(p)
    out = {}
    for name, var in (("cb", "delta_nonu"), ("m", "delta_tot")):
        kh, z, pk = r.get_matter_power_spectrum(minkh=K_GRID[0], maxkh=K_GRID[-1], npoints=len(K_GRID),
                                                var1=var, var2=var)
        assert np.allclose(kh, K_GRID, rtol=1e-10)
        zz = np.asarray(z)  # CAMB returns increasing z: back to the order asked for
        idx = [int(np.argmin(np.abs(zz - zi))) for zi in zs]
        out[name] = pk[idx]
    s8 = np.asarray(r.get_sigma8())
    s8 = s8[[int(np.argmin(np.abs(np.asarray(r.transfer_redshifts) - zi))) for zi in zs]]
    return out["cb"], out["m"], s8


def main():
    kind, start, stop, outdir = sys.argv[1], int(sys.argv[2]), int(sys.argv[3]), sys.argv[4]
    x = draws(kind, max(stop, 4096 if kind == "train" else 256))[start:stop]
    zs_all, cb_all, m_all, s8_all = [], [], [], []
    t0 = time.time()
    for j, xi in enumerate(x):
        zs = redshifts(kind, start + j)
        cb, m, s8 = camb_spectra(xi, zs)
        zs_all.append(zs); cb_all.append(cb); m_all.append(m); s8_all.append(s8)
        print(f"{kind} {start + j}: {time.time() - t0:.0f} s", flush=True)
    np.savez(f"{outdir}/{kind}_{start}_{stop}.npz", params=x, z=np.array(zs_all), k=K_GRID,
             pk_cb=np.array(cb_all), pk_m=np.array(m_all), sigma8=np.array(s8_all),
             camb_version=camb.__version__)


if __name__ == "__main__":
    main()
