"""CLASS linear spectra for the 2-loop basis test of CLASS input (pt-spectra/tests/data/linear_pk_class_*.dat).

Planck 2018 (h 0.6766, omega_b 0.02242, omega_cdm 0.11933, n_s 0.9665, A_s 2.105e-9, massless
neutrinos N_ur 3.046), z = 0, written in h/Mpc and (Mpc/h)^3:
- ``_pk_lin``: 600 log-spaced k in [1e-4, 50) h/Mpc from classy's ``pk_lin`` (CLASS's own interpolation);
- ``_kpd10``, ``_kpd40``: CLASS's own k sampling (``get_pk_and_k_and_z``) at ``k_per_decade_for_pk`` 10
  (CLASS's default) and 40, ``P_k_max_1/Mpc`` 35, as cobaya's classy gives a ``Pk_grid``.

Needs classy (pip install classy scipy; measured with 3.4.1). Run from the repository root.
"""
import numpy as np
import classy

PLANCK = {"h": 0.6766, "omega_b": 0.02242, "omega_cdm": 0.11933, "n_s": 0.9665, "A_s": 2.105e-9,
          "N_ur": 3.046}
OUT = "pt-spectra/tests/data/linear_pk_class_planck2018_z0.0"


def pk_lin():
    c = classy.Class()
    c.set({"output": "mPk", "P_k_max_h/Mpc": 50.0, **PLANCK})
    c.compute()
    h = c.h()
    k = np.geomspace(1e-4, 50.0 * 0.999, 600)
    pk = np.array([c.pk_lin(x * h, 0.0) for x in k]) * h**3
    np.savetxt(f"{OUT}_pk_lin.dat", np.c_[k, pk],
               header="CLASS (classy 3.4.1) Planck 2018, z = 0, pk_lin at 600 log-spaced k: k [h/Mpc], P [(Mpc/h)^3]")


def native(per_decade):
    c = classy.Class()
    c.set({"output": "mPk", "P_k_max_1/Mpc": 35.0, "z_max_pk": 1.0, "k_per_decade_for_pk": per_decade,
           **PLANCK})
    c.compute()
    pk, k, z = c.get_pk_and_k_and_z(nonlinear=False)
    h, i = c.h(), int(np.argmin(np.abs(z)))
    np.savetxt(f"{OUT}_kpd{per_decade}.dat", np.c_[k / h, pk[:, i] * h**3],
               header=f"CLASS (classy 3.4.1) Planck 2018, z = 0, CLASS's own k sampling, "
                      f"k_per_decade_for_pk = {per_decade}: k [h/Mpc], P [(Mpc/h)^3]")


if __name__ == "__main__":
    pk_lin()
    native(10)
    native(40)
