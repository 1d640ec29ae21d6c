# Makes linear_pk_planck2018_z0.0.dat and _z1.0.dat (see README.md): CAMB's linear total-matter P(k)
# for the Planck 2018 cosmology of Cosmology::planck2018(), with sigma8(z) and f(z) in the headers.
# Run with the `camb` Python package (2.0.5 made the committed files): python3 make_planck2018.py
import camb, numpy as np
pars = camb.CAMBparams()
pars.set_cosmology(H0=67.66, ombh2=0.02242, omch2=0.11933, mnu=0.0, omk=0, num_massive_neutrinos=0, nnu=3.046)
pars.InitPower.set_params(As=2.105209e-9, ns=0.9665)
pars.set_matter_power(redshifts=[1.0, 0.0], kmax=60.0)
pars.NonLinear = camb.model.NonLinear_none
res = camb.get_results(pars)
kh, z, pk = res.get_matter_power_spectrum(minkh=1e-4, maxkh=50, npoints=1200)
s8 = res.get_sigma8()[::-1]; fs8 = res.get_fsigma8()[::-1]
print(z, s8, fs8, fs8/s8)
for i, zz in enumerate(z):
    with open(f"linear_pk_planck2018_z{zz:.1f}.dat", "w") as f:
        f.write(f"# CAMB {camb.__version__} linear total-matter P(k), Planck 2018: H0=67.66 ombh2=0.02242 omch2=0.11933 ns=0.9665 As=2.105209e-9, massless neutrinos (N_eff=3.046), flat\n")
        f.write(f"# z = {zz}  sigma8(z) = {s8[i]:.6f}  f(z) = fsigma8/sigma8 = {fs8[i]/s8[i]:.6f}\n# k [h/Mpc]  P [(Mpc/h)^3]\n")
        for k, p in zip(kh, pk[i]):
            f.write(f"{k:.8e} {p:.8e}\n")
