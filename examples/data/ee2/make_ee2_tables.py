#!/usr/bin/env python3
"""Nonlinear matter power-spectrum reference tables from EuclidEmulator2 (EE2).

For each cosmology below this writes, next to this script:

  ee2_<name>.dat      k, then for z = 0, 0.5, 1, 1.5: Plin_z, Pnl_z, B_z
                      on 120 log-spaced k in [0.01, 0.6] h/Mpc, where
                      Plin = CAMB linear total-matter spectrum,
                      B    = EE2 boost P_nl/P_lin at (k, z),
                      Pnl  = B * Plin.
  plin_<name>_z0.dat  k, P: CAMB linear total-matter spectrum at z = 0 on
                      800 log-spaced k in [1e-5, 50] h/Mpc (input for the
                      perturbation-theory code), with linear growth ratios
                      D(z)/D(0) = sqrt(Plin(0.05, z) / Plin(0.05, 0)) in the header.

Units: k in h/Mpc, P in (Mpc/h)^3.
Usage: python examples/data/ee2/make_ee2_tables.py   (needs camb, euclidemu2)
"""
import os
import sys
from importlib.metadata import version

import numpy as np
from scipy.interpolate import CubicSpline

import camb
import euclidemu2 as ee2

OUTDIR = os.path.dirname(os.path.abspath(__file__))
ZS = [0.0, 0.5, 1.0, 1.5]
K_TAB = np.logspace(np.log10(0.01), np.log10(0.6), 120)  # h/Mpc, inside EE2 range
K_WIDE = np.logspace(-5, np.log10(50.0), 800)             # h/Mpc
K_GROWTH = 0.05                                           # h/Mpc
NNU = 3.046   # EE2's internal N_eff (cosmo.cxx); all neutrinos massless
EE2_KMIN, EE2_KMAX = 8.73e-3, 9.41  # h/Mpc, emulated k range of EE2

# Flat, w0 = -1, wa = 0, massless neutrinos (EE2 allows Sum m_nu in [0, 0.15] eV).
COSMOLOGIES = {
    "quijote": dict(h=0.6711, Omega_m=0.3175, Omega_b=0.049, n_s=0.9624,
                    sigma8_target=0.834),
    "planck2018": dict(h=0.6736, ombh2=0.02237, omch2=0.1200, n_s=0.9649,
                       A_s=2.1e-9),
}


def complete(c):
    """Fill in Omega_m/Omega_b <-> omega_b/omega_c."""
    c = dict(c)
    h2 = c["h"] ** 2
    if "Omega_m" in c:
        c["ombh2"] = c["Omega_b"] * h2
        c["omch2"] = (c["Omega_m"] - c["Omega_b"]) * h2
    else:
        c["Omega_b"] = c["ombh2"] / h2
        c["Omega_m"] = (c["ombh2"] + c["omch2"]) / h2
    return c


def run_camb(c, A_s):
    h = c["h"]
    pars = camb.set_params(
        H0=100.0 * h, ombh2=c["ombh2"], omch2=c["omch2"], omk=0.0,
        mnu=0.0, num_massive_neutrinos=0, nnu=NNU,
        As=A_s, ns=c["n_s"], w=-1.0, wa=0.0,
        WantCls=False, WantTransfer=True,
        NonLinear=camb.model.NonLinear_none,       # linear only, no halofit
        redshifts=sorted(ZS, reverse=True),
        kmax=1.5 * K_WIDE[-1] * h,                  # 1/Mpc, i.e. 75 h/Mpc
        k_per_logint=30, AccuracyBoost=2.0,
    )
    pars.Transfer.high_precision = True
    res = camb.get_results(pars)
    return pars, res


def linear_interpolators(res):
    """Log-log cubic splines of CAMB's linear delta_tot spectrum, per z."""
    k, z, pk = res.get_linear_matter_power_spectrum(
        var1="delta_tot", var2="delta_tot", hubble_units=True, k_hunit=True)
    out = {}
    for zi, row in zip(z, pk):
        spl = CubicSpline(np.log(k), np.log(row))
        out[round(float(zi), 6)] = (lambda kk, s=spl: np.exp(s(np.log(kk))))
    return k, out


def find_As(c, target, A0=2.1e-9):
    """sigma8 scales as sqrt(A_s) in linear theory: iterate to convergence."""
    A = A0
    for _ in range(5):
        _, res = run_camb(c, A)
        s8 = res.get_sigma8_0()
        if abs(s8 / target - 1) < 1e-7:
            break
        A *= (target / s8) ** 2
    return A


def main():
    emu = ee2.PyEuclidEmulator()
    versions = dict(euclidemu2=version("euclidemu2"), camb=camb.__version__,
                    numpy=np.__version__, python=sys.version.split()[0])
    vline = ", ".join(f"{k} {v}" for k, v in versions.items())
    assert K_TAB.min() >= EE2_KMIN and K_TAB.max() <= EE2_KMAX

    for name, c0 in COSMOLOGIES.items():
        c = complete(c0)
        if "A_s" in c:
            A_s, As_note = c["A_s"], "input"
        else:
            A_s = find_As(c, c["sigma8_target"])
            As_note = f"tuned with CAMB to give sigma8 = {c['sigma8_target']}"
        pars, res = run_camb(c, A_s)
        sigma8 = float(res.get_sigma8_0())
        kc, plin = linear_interpolators(res)
        assert kc.min() <= K_WIDE[0] and kc.max() >= K_WIDE[-1]

        ee2_pars = {"Omega_b": c["Omega_b"], "Omega_m": c["Omega_m"],
                    "m_ncdm": 0.0, "n_s": c["n_s"], "h": c["h"],
                    "w0_fld": -1.0, "wa_fld": 0.0, "A_s": A_s}
        emu.check_param_range(ee2_pars)
        kb, B = emu.get_boost(ee2_pars, ZS, custom_kvec=K_TAB)
        assert np.allclose(kb, K_TAB)

        cosmo_lines = [
            f"cosmology '{name}': flat LCDM, w0 = -1, wa = 0, massless neutrinos "
            f"(Sum m_nu = 0, N_eff = {NNU}), T_CMB = {pars.TCMB} K",
            f"h = {c['h']}  Omega_m = {c['Omega_m']:.6f}  Omega_b = {c['Omega_b']:.6f}  "
            f"omega_b = {c['ombh2']:.6f}  omega_c = {c['omch2']:.6f}  n_s = {c['n_s']}",
            f"A_s = {A_s:.6e} ({As_note})  sigma8(z=0, CAMB linear) = {sigma8:.5f}",
        ]
        # growth ratios at K_GROWTH
        growth = {z: float(np.sqrt(plin[z](K_GROWTH) / plin[0.0](K_GROWTH))) for z in ZS}

        # ---- table with EE2 boosts
        cols = [K_TAB]
        names = ["k"]
        for i, z in enumerate(ZS):
            pl = plin[z](K_TAB)
            b = np.asarray(B[i])
            cols += [pl, b * pl, b]
            zt = f"{z:g}"
            names += [f"Plin_z{zt}", f"Pnl_z{zt}", f"B_z{zt}"]
        header = "\n".join([
            "Nonlinear matter power spectrum reference table: EuclidEmulator2 boost x CAMB linear P(k)",
            f"codes: {vline}",
            *cosmo_lines,
            "Plin = CAMB linear total-matter (delta_tot) power spectrum, halofit off,",
            "       AccuracyBoost = 2, high_precision transfer, log-log cubic spline in k",
            "B    = EuclidEmulator2 boost P_nl/P_lin (get_boost; emulated range 8.73e-3 <= k <= 9.41 h/Mpc,",
            "       z <= 10; stated accuracy ~1% vs its N-body suite for k <= 10 h/Mpc; an emulator, not simulations)",
            "Pnl  = B * Plin",
            "units: k in h/Mpc, P in (Mpc/h)^3; redshifts z = " + ", ".join(f"{z:g}" for z in ZS),
            "generated by examples/data/ee2/make_ee2_tables.py",
            "  ".join(names),
        ])
        path = os.path.join(OUTDIR, f"ee2_{name}.dat")
        np.savetxt(path, np.column_stack(cols), fmt="%.8e", header=header)
        print("wrote", path)

        # ---- wide linear z=0 spectrum
        header = "\n".join([
            "Linear matter power spectrum at z = 0 from CAMB (delta_tot, halofit off)",
            f"codes: {vline}",
            *cosmo_lines,
            "AccuracyBoost = 2, high_precision transfer, log-log cubic spline of CAMB's k grid",
            f"linear growth D(z)/D(0) = sqrt(Plin(k={K_GROWTH} h/Mpc, z) / Plin(k={K_GROWTH}, 0)):",
            *[f"  z = {z:g}: {growth[z]:.6f}" for z in ZS],
            "units: k in h/Mpc, P in (Mpc/h)^3",
            "generated by examples/data/ee2/make_ee2_tables.py",
            "k  P",
        ])
        path = os.path.join(OUTDIR, f"plin_{name}_z0.dat")
        np.savetxt(path, np.column_stack([K_WIDE, plin[0.0](K_WIDE)]), fmt="%.8e", header=header)
        print("wrote", path)

        # ---- sanity numbers
        i03 = np.argmin(abs(K_TAB - 0.3))
        print(f"[{name}] A_s = {A_s:.6e}  sigma8 = {sigma8:.5f}")
        print(f"[{name}] growth D(z)/D(0): " + ", ".join(f"z={z:g}: {growth[z]:.5f}" for z in ZS))
        for i, z in enumerate(ZS):
            b = np.asarray(B[i])
            print(f"[{name}] z={z:g}: B(k={K_TAB[0]:.3f}) = {b[0]:.5f}   "
                  f"B(k={K_TAB[i03]:.4f}) = {b[i03]:.4f}   B(k=0.6) = {b[-1]:.4f}")
        b0 = np.asarray(B[0])
        if abs(b0[0] - 1) > 0.01 or not (1.3 <= b0[i03] <= 1.6):
            print(f"[{name}] WARNING: sanity check outside expected range")


if __name__ == "__main__":
    main()
