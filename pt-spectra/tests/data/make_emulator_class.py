#!/usr/bin/env python3
"""CLASS spectra of six cosmologies inside the emulator's prior (emulator_class.dat), to check the
emulator (trained on CAMB) against a second Boltzmann code.

Same physics as the training set: three degenerate massive neutrinos of total mass m_nu (CLASS: N_ncdm = 1,
deg_ncdm = 3, m_ncdm = m_nu/3, N_ur = 0.00641 so that N_eff = 3.046), T_CMB = 2.7255 K, flat, w0-wa dark
energy as a PPF fluid (Omega_Lambda = 0, use_ppf = yes). Rows: index, Omega_b Omega_m h m_nu w0 wa
ln10^10A_s n_s, z, k [h/Mpc], P_cb, P_m [(Mpc/h)^3]; 30 k log-spaced in [1e-3, 1] h/Mpc.
Usage: python3 make_emulator_class.py   (needs classy)
"""
from pathlib import Path

import classy
import numpy as np

COSMOLOGIES = [  # Omega_b Omega_m h m_nu w0 wa ln10^10A_s n_s, z
    ([0.049, 0.31, 0.677, 0.06, -1.0, 0.0, 3.047, 0.9665], 0.0),
    ([0.049, 0.31, 0.677, 0.0, -1.0, 0.0, 3.047, 0.9665], 1.0),
    ([0.045, 0.28, 0.70, 0.25, -0.9, -0.2, 3.0, 0.96], 0.5),
    ([0.055, 0.35, 0.64, 0.45, -1.1, 0.3, 2.8, 0.98], 1.5),
    ([0.050, 0.26, 0.72, 0.15, -0.8, -0.5, 3.3, 0.94], 2.5),
    ([0.042, 0.38, 0.62, 0.35, -1.25, 0.1, 3.1, 0.99], 0.8),
]
k_h = np.geomspace(1e-3, 1.0, 30)
rows = []
for i, (x, z) in enumerate(COSMOLOGIES):
    ob, om, h, mnu, w0, wa, loga, ns = x
    params = {
        "output": "mPk", "P_k_max_h/Mpc": 5.0, "z_pk": z, "h": h, "omega_b": ob * h * h,
        "N_ur": 0.00641 if mnu > 0 else 3.046, "N_ncdm": 1 if mnu > 0 else 0, "T_cmb": 2.7255,
        "ln10^{10}A_s": loga, "n_s": ns, "Omega_k": 0.0,
    }
    if mnu > 0:
        params.update({"m_ncdm": mnu / 3, "deg_ncdm": 3})
    if (w0, wa) != (-1.0, 0.0):
        params.update({"Omega_Lambda": 0.0, "w0_fld": w0, "wa_fld": wa, "use_ppf": "yes"})
    c = classy.Class()
    # Omega_m of all matter: CDM is what remains after baryons and neutrinos
    c.set(params)
    c.set({"omega_cdm": 0.1})
    c.compute()
    omega_nu = c.Omega_nu * h * h if mnu > 0 else 0.0
    c.struct_cleanup()
    c = classy.Class()
    c.set(params)
    c.set({"omega_cdm": om * h * h - ob * h * h - omega_nu})
    c.compute()
    for k in k_h:
        p_m = c.pk_lin(k * h, z) * h**3
        p_cb = c.pk_cb_lin(k * h, z) * h**3 if mnu > 0 else p_m
        rows.append([i, *x, z, k, p_cb, p_m])
    print(i, "Omega_m", c.Omega_m(), "sigma8", c.sigma8())
    c.struct_cleanup()
header = (f"CLASS {classy.__version__} spectra for the emulator tests (make_emulator_class.py)\n"
          "index Omega_b Omega_m h m_nu w0 wa ln10^10A_s n_s z k P_cb P_m")
np.savetxt(Path(__file__).parent / "emulator_class.dat", rows, header=header, fmt=["%d"] + ["%.10g"] * 12)
