# Makes camb_distances.dat (see README.md): CAMB background-only H(z), transverse comoving distance D_M and
# angular diameter distance D_A for five cosmologies (flat LCDM, w0-wa PPF, open and closed LCDM), all with
# massless neutrinos, plus an independent scipy integration of the same Friedmann equation as a check.
# Run with the `camb` Python package (2.0.5 made the committed file): python3 make_camb_distances.py
# The output goes next to this script, whatever the working directory.
import os
import camb
import numpy as np
import scipy
from scipy.integrate import quad

C_KMS = 299792.458  # speed of light [km/s], CAMB's const_c / 1e3
TCMB = 2.7255
NNU = 3.046  # set explicitly (CAMB 2.0.5's default nnu is 3.044); all massless
ZS = [0.1, 0.38, 0.5, 0.61, 1.0, 1.5, 2.0, 3.0]

# name, set_cosmology arguments (besides the neutrino / T_CMB ones below), dark energy (None = CAMB default)
COSMOS = [
    ("Planck 2018-like flat LCDM", dict(H0=67.66, ombh2=0.02242, omch2=0.11933, omk=0.0), None),
    ("gm2012 flat LCDM (Omega_m = 0.27, h = 0.7)", dict(H0=70.0, ombh2=0.023, omch2=0.27 * 0.49 - 0.023, omk=0.0), None),
    ("flat w0-wa (PPF)", dict(H0=68.0, ombh2=0.0224, omch2=0.12, omk=0.0), dict(w=-0.9, wa=0.3, dark_energy_model="ppf")),
    ("open curved LCDM", dict(H0=70.0, ombh2=0.022, omch2=0.12, omk=0.05), None),
    ("closed curved LCDM", dict(H0=65.0, ombh2=0.022, omch2=0.13, omk=-0.05), None),
]
NU = dict(mnu=0.0, num_massive_neutrinos=0, nnu=NNU, TCMB=TCMB)


def f_de(z, w0, wa):
    """rho_DE(z)/rho_DE(0) for w(a) = w0 + wa (1 - a) (CPL)."""
    a = 1.0 / (1.0 + z)
    return np.exp(3.0 * wa * (a - 1.0)) * a ** (-3.0 * (1.0 + w0 + wa))


def independent(H0, Om, Or, Ok, Ode, w0, wa, z):
    """H(z) [km/s/Mpc] and D_M(z) [Mpc] from the Friedmann equation, by scipy quad."""
    def H(zz):
        return H0 * np.sqrt(Or * (1 + zz) ** 4 + Om * (1 + zz) ** 3 + Ok * (1 + zz) ** 2 + Ode * f_de(zz, w0, wa))
    chi = C_KMS * quad(lambda zz: 1.0 / H(zz), 0.0, z, epsabs=0.0, epsrel=1e-13, limit=200)[0]
    if Ok == 0.0:
        dm = chi
    else:
        rc = C_KMS / (H0 * np.sqrt(abs(Ok)))  # curvature radius [Mpc]
        dm = rc * (np.sinh(chi / rc) if Ok > 0 else np.sin(chi / rc))
    return H(z), dm


header_cosmo, header_check, rows = [], [], []
scal = 0.0
for i, (name, cosmo, de) in enumerate(COSMOS):
    pars = camb.CAMBparams()
    pars.set_cosmology(**cosmo, **NU)
    if de is not None:
        pars.set_dark_energy(**de)
    res = camb.get_background(pars)
    z = np.array(ZS)
    H = res.hubble_parameter(z)  # km/s/Mpc
    DA = res.angular_diameter_distance(z)  # Mpc
    DM = DA * (1.0 + z)  # transverse comoving distance, Mpc
    # CAMB's scalar-z call integrates each z separately (Romberg); the array call used here is more precise
    scal = max(scal, float(np.max(np.abs(np.array([res.angular_diameter_distance(float(zz)) for zz in ZS]) / DA - 1))))
    Om = float(res.get_Omega("cdm", 0.0) + res.get_Omega("baryon", 0.0) + res.get_Omega("nu", 0.0))
    Og, Onu = float(res.get_Omega("photon", 0.0)), float(res.get_Omega("neutrino", 0.0))
    Or = Og + Onu
    Ok, Ode = float(res.get_Omega("K", 0.0)), float(res.get_Omega("de", 0.0))
    w0 = de["w"] if de else -1.0
    wa = de["wa"] if de else 0.0
    dea = (f"set_dark_energy(w={de['w']!r}, wa={de['wa']!r}, dark_energy_model='ppf') [DarkEnergyPPF, cs2={pars.DarkEnergy.cs2!r}]"
           if de else f"default {type(pars.DarkEnergy).__name__} w={pars.DarkEnergy.w!r} wa={pars.DarkEnergy.wa!r} (= Lambda)")
    header_cosmo.append(f"# cosmo {i}: {name}: set_cosmology(" + ", ".join(f"{k}={v!r}" for k, v in {**cosmo, **NU}.items())
                        + f"); dark energy: {dea}")
    header_cosmo.append(f"#   CAMB derived (z = 0): h = {pars.h!r}  Omega_b = {pars.omegab!r}  Omega_c = {pars.omegac!r}"
                        f"  Omega_m = {Om!r}  Omega_k = {Ok!r}")
    header_cosmo.append(f"#   Omega_photon = {Og!r}  Omega_nu_massless = {Onu!r}  Omega_r = {Or!r}"
                        f"  Omega_DE = {Ode!r}  (sum - 1 = {Om + Or + Ok + Ode - 1:.1e})")
    # independent check: with all radiation, photons only, and no radiation (other densities unchanged)
    for rad, lab in ((Or, "with Omega_r"), (Og, "photons only, massless nu dropped"), (0.0, "radiation dropped (Omega_DE kept)")):
        ind = np.array([independent(pars.H0, Om, rad, Ok, Ode, w0, wa, zz) for zz in ZS])
        dH = np.max(np.abs(ind[:, 0] / H - 1))
        dD = np.max(np.abs(ind[:, 1] / DM - 1))
        line = f"#   cosmo {i} {lab}: max |H_ind/H_CAMB - 1| = {dH:.2e}, max |D_M_ind/D_M_CAMB - 1| = {dD:.2e}"
        header_check.append(line)
        print(line[2:])
    for zz, h_, dm, da in zip(ZS, H, DM, DA):
        rows.append(f"{i} {zz:.2f} {h_:.10e} {dm:.10e} {da:.10e}")

out = os.path.join(os.path.dirname(os.path.abspath(__file__)), "camb_distances.dat")
with open(out, "w") as f:
    f.write(f"# CAMB {camb.__version__} (Python, pip wheel), numpy {np.__version__}, scipy {scipy.__version__}: background only\n")
    f.write("# made by make_camb_distances.py: pars = camb.CAMBparams(); pars.set_cosmology(...); [pars.set_dark_energy(...)];"
            " results = camb.get_background(pars)\n")
    f.write(f"# CAMB settings: all neutrinos massless (mnu=0, num_massive_neutrinos=0, nnu={NNU} given explicitly, not CAMB's"
            f" default 3.044; CAMB num_nu_massless = N_eff = {pars.num_nu_massless!r}), TCMB = {TCMB} K;"
            f" Accuracy.AccuracyBoost = {pars.Accuracy.AccuracyBoost!r}; everything else CAMB's default (YHe from BBN,"
            f" no effect on H(z)); c = {C_KMS} km/s\n")
    f.write("# CAMB sets Omega_DE = 1 - Omega_m - Omega_k - Omega_r with Omega_r = Omega_photon + Omega_nu_massless, i.e. radiation"
            " IS counted in the closure; Omega_photon = (8 pi G/3H0^2) a_rad TCMB^4 / c^2 and"
            " Omega_nu_massless = N_eff (7/8) (4/11)^(4/3) Omega_photon (from results.get_Omega('photon'|'neutrino', 0))\n")
    f.write("\n".join(header_cosmo) + "\n")
    f.write("# Independent check: scipy quad (epsrel 1e-13) of H(z) = H0 sqrt(Omega_r (1+z)^4 + Omega_m (1+z)^3 + Omega_k (1+z)^2"
            " + Omega_DE f_DE(z)) with CAMB's densities above, f_DE = 1 (Lambda) or exp(3 wa (a-1)) a^(-3(1+w0+wa)) (cosmo 2),"
            " D_M = R_c sinh(chi/R_c) (Omega_k > 0) or R_c sin(chi/R_c) (Omega_k < 0), R_c = c/(H0 sqrt|Omega_k|),"
            " chi = c int_0^z dz/H; largest relative differences over the 8 redshifts:\n")
    f.write("\n".join(header_check) + "\n")
    f.write(f"# (CAMB's scalar-z angular_diameter_distance(z) differs from the array call used here by <= {scal:.1e} relative)\n")
    f.write("# columns: cosmo (index above)  z  H(z) [km/s/Mpc]  D_M(z) = transverse comoving distance [Mpc]"
            "  D_A(z) = D_M/(1+z) [Mpc]  (Mpc, not Mpc/h; D_A from results.angular_diameter_distance, D_M = (1+z) D_A,"
            " H from results.hubble_parameter)\n")
    f.write("\n".join(rows) + "\n")
print("wrote", out)
