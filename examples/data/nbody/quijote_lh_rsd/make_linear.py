#!/usr/bin/env python3
"""Linear matter power spectra (CAMB) of the Quijote latin-hypercube cosmologies used by
examples/rsd_quijote_lh.py, at z = 0.5 and z = 1, and their growth rates.

Writes, next to this script:

- plin_lh<X>_z<z>.dat: k [h/Mpc], P [(Mpc/h)^3] on 1200 log-spaced k in [1e-4, 50] h/Mpc (the k range
  and sampling of pt-spectra's 2-loop training spectra; a log-log cubic spline of CAMB's own k grid);
- cosmologies.txt: one row per LH realisation: X, Omega_m, Omega_b, h, n_s, sigma8, A_s, then for
  z = 0.5 and 1: D(z)/D(0), f(z) (the ones used), CAMB's f = fsigma8/sigma8, and CAMB's own
  P(k = 0.1, z)/P(k = 0.1, 0) divided by D(z)^2 (a check).

Conventions (as Quijote's initial conditions): CAMB's linear total-matter spectrum (delta_tot, halofit
off) at z = 0 with A_s tuned so that sigma8(z = 0) is the LH value; flat LCDM, w = -1, massless
neutrinos (N_eff = 3.046), T_CMB = 2.7255 K; AccuracyBoost = 2, high_precision transfer,
k_per_logint = 30 (as ../quijote_hr/make_linear.py). Quijote's 2LPT initial conditions (z = 127) are
this z = 0 spectrum rescaled with the linear growth of the N-body run (matter + Lambda, no
radiation), so the linear spectrum of the simulation at z is P(k, 0) [D(z)/D(0)]^2 with that growth:
that is what is written (D from the exact LCDM growth integral with Omega_Lambda = 1 - Omega_m).
f(z) = dlnD/dlna of the same growth; it reproduces the fsigma8 labels in the upstream files
(dir<X>/z05.dat, z1.dat) to 1e-8. CAMB's own P(k, z)/P(k, 0) (with radiation) differs from
D(z)^2 by <= 0.03 per cent at k = 0.1 and its fsigma8/sigma8 from f by <= 0.05 per cent (both in
cosmologies.txt): the choice does not matter here.

Usage: python examples/data/nbody/quijote_lh_rsd/make_linear.py   (needs camb; ~13 s per cosmology, 1.5 min)
"""
import os
import sys

import numpy as np
from scipy.integrate import quad
from scipy.interpolate import CubicSpline

import camb

OUTDIR = os.path.dirname(os.path.abspath(__file__))
K_OUT = np.logspace(-4, np.log10(50.0), 1200)  # h/Mpc
NNU = 3.046
ZS = (0.5, 1.0)
# Rows X of Quijote's latin_hypercube_params.txt (Omega_m, Omega_b, h, n_s, sigma8): the LH
# realisations of examples/rsd_quijote_lh.py (see README.md).
LH = {
    3: (0.3271, 0.06875, 0.6313, 0.8135, 0.8939),
    7: (0.2423, 0.06275, 0.5675, 0.8305, 0.7145),
    8: (0.3215, 0.05487, 0.6429, 1.0531, 0.7509),
    11: (0.4195, 0.04627, 0.7635, 1.0415, 0.8047),
    13: (0.2965, 0.04883, 0.7613, 0.9025, 0.9441),
    17: (0.2475, 0.04437, 0.7861, 0.9407, 0.7411),
    24: (0.3925, 0.03625, 0.5513, 0.9809, 0.7975),
}


def lcdm_growth(om, z):
    """D(z)/D(0) and f(z) = dlnD/dlna of flat LCDM without radiation (the exact growing mode
    D(a) = 5/2 Omega_m E(a) I(a), I(a) = int_0^a dx / (x E(x))^3)."""
    e = lambda a: np.sqrt(om / a**3 + 1 - om)
    i = lambda a: quad(lambda x: 1 / (x * e(x)) ** 3, 0, a, epsabs=0, epsrel=1e-12)[0]
    a = 1 / (1 + z)
    d = e(a) * i(a) / (e(1.0) * i(1.0))
    f = -1.5 * om / (a**3 * e(a) ** 2) + 1 / (a**2 * e(a) ** 3 * i(a))
    return d, f


def run(om, ob, h, ns, a_s):
    pars = camb.set_params(H0=100 * h, ombh2=ob * h * h, omch2=(om - ob) * h * h, omk=0.0, mnu=0.0,
                           num_massive_neutrinos=0, nnu=NNU, As=a_s, ns=ns, WantCls=False,
                           WantTransfer=True, NonLinear=camb.model.NonLinear_none,
                           redshifts=[max(ZS), min(ZS), 0.0], kmax=1.5 * K_OUT[-1] * h,
                           k_per_logint=30, AccuracyBoost=2.0)
    pars.Transfer.high_precision = True
    return pars, camb.get_results(pars)


def main():
    rows = []
    for x, (om, ob, h, ns, s8) in LH.items():
        a_s0 = 2.1e-9
        pars, res = run(om, ob, h, ns, a_s0)
        scale = (s8 / float(res.get_sigma8_0())) ** 2  # linear: P and sigma8^2 are proportional to A_s
        a_s = a_s0 * scale
        k, zs, pk = res.get_linear_matter_power_spectrum(var1="delta_tot", var2="delta_tot",
                                                         hubble_units=True, k_hunit=True)
        assert k.min() <= K_OUT[0] and k.max() >= K_OUT[-1]
        zs = list(np.round(zs, 6))
        p0 = scale * pk[zs.index(0.0)]
        p0_out = np.exp(CubicSpline(np.log(k), np.log(p0))(np.log(K_OUT)))
        fs8 = res.get_fsigma8()[::-1]  # CAMB orders the redshifts high to low; reversed: 0, ZS[0], ZS[1]
        s8z = res.get_sigma8()[::-1]
        row = [x, om, ob, h, ns, s8, a_s]
        for z in ZS:
            d, f = lcdm_growth(om, z)
            j = zs.index(z)
            i01 = np.argmin(abs(k - 0.1))
            camb_ratio = pk[j][i01] / pk[zs.index(0.0)][i01] / d**2
            f_camb = (fs8 / s8z)[1 + ZS.index(z)]
            row += [d, f, f_camb, camb_ratio]
            header = "\n".join([
                f"Linear matter power spectrum of Quijote LH realisation {x} at z = {z} (CAMB delta_tot at z = 0, "
                "halofit off, times [D(z)/D(0)]^2 of flat LCDM without radiation)",
                f"codes: camb {camb.__version__}, numpy {np.__version__}, python {sys.version.split()[0]}",
                f"flat LCDM, w = -1, massless neutrinos (N_eff = {NNU}), T_CMB = {pars.TCMB} K",
                f"Omega_m = {om}  Omega_b = {ob}  h = {h}  n_s = {ns}  sigma8(z=0) = {s8}",
                f"A_s = {a_s:.6e} (tuned with CAMB to give sigma8(z=0) = {s8}; pivot 0.05/Mpc)",
                f"D(z)/D(0) = {d:.8f}  f(z) = {f:.8f} (LCDM growth, no radiation; CAMB fsigma8/sigma8 = {f_camb:.6f}; "
                f"CAMB P(0.1,z)/P(0.1,0)/D^2 = {camb_ratio:.6f})",
                "AccuracyBoost = 2, high_precision transfer, k_per_logint = 30, log-log cubic spline of CAMB's k grid",
                "units: k in h/Mpc, P in (Mpc/h)^3",
                "generated by examples/data/nbody/quijote_lh_rsd/make_linear.py",
                "k  P",
            ])
            name = f"plin_lh{x}_z{z:g}.dat"
            np.savetxt(os.path.join(OUTDIR, name), np.column_stack([K_OUT, p0_out * d * d]), fmt="%.8e",
                       header=header)
        rows.append(row)
        print(f"LH {x}: A_s = {a_s:.6e}, " + ", ".join(
            f"z = {z:g}: D = {row[7 + 4 * i]:.6f} f = {row[8 + 4 * i]:.6f} (CAMB {row[9 + 4 * i]:.6f})"
            for i, z in enumerate(ZS)), flush=True)
    cols = "X Omega_m Omega_b h n_s sigma8 A_s " + " ".join(
        f"D_z{z:g} f_z{z:g} fCAMB_z{z:g} PCAMBratio_z{z:g}" for z in ZS)
    np.savetxt(os.path.join(OUTDIR, "cosmologies.txt"), np.array(rows),
               fmt=["%d"] + ["%.5g"] * 5 + ["%.6e"] + ["%.8f"] * 8,
               header="Quijote LH cosmologies of examples/rsd_quijote_lh.py and their growth "
                      "(make_linear.py)\n" + cols)


if __name__ == "__main__":
    main()
