# Makes camb_distances_mnu.dat (see README.md): CAMB background-only H(z) and transverse comoving distance
# D_M(z) of flat LCDM with three degenerate massive neutrinos (sum m_nu = 0.06, 0.3, 0.5 eV, N_eff = 3.046,
# no massless species), the check of pt-spectra's background with massive neutrinos (counted as matter at
# z <= 3, photons as the only radiation). Run with the `camb` Python package (2.0.5 made the committed
# file): python3 make_camb_distances_mnu.py. The output goes next to this script.
import os

import camb
import numpy as np

ZS = [0.1, 0.5, 1.0, 2.0, 3.0]
COSMO = dict(H0=67.5, ombh2=0.0224, omch2=0.12, omk=0.0, num_massive_neutrinos=3, nnu=3.046, TCMB=2.7255)
MNU = [0.06, 0.3, 0.5]

rows, header = [], []
for i, mnu in enumerate(MNU):
    pars = camb.CAMBparams()
    pars.set_cosmology(mnu=mnu, **COSMO)
    res = camb.get_background(pars)
    z = np.array(ZS)
    H = res.hubble_parameter(z)
    DM = res.angular_diameter_distance(z) * (1.0 + z)
    header.append(f"# cosmo {i}: set_cosmology(mnu={mnu!r}, " + ", ".join(f"{k}={v!r}" for k, v in COSMO.items())
                  + f"); CAMB omnuh2 = {res.get_Omega('nu', 0.0) * pars.h ** 2!r}")
    rows += [f"{i} {zz:.2f} {mnu} {h_:.10e} {dm:.10e}" for zz, h_, dm in zip(ZS, H, DM)]

out = os.path.join(os.path.dirname(os.path.abspath(__file__)), "camb_distances_mnu.dat")
with open(out, "w") as f:
    f.write(f"# CAMB {camb.__version__} background only, made by make_camb_distances_mnu.py; dark energy Lambda\n")
    f.write("\n".join(header) + "\n")
    f.write("# columns: cosmo  z  m_nu [eV]  H(z) [km/s/Mpc]  D_M(z) [Mpc]\n")
    f.write("\n".join(rows) + "\n")
print("wrote", out)
