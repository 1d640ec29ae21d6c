# Makes linear_pk_camb_w0wa_z1.0.dat (see README.md): CAMB's linear total-matter P(k) at z = 1 for a flat
# w0-wa cosmology outside the family of the 2-loop basis's training set (w0 = -0.8, wa = -0.7 with PPF dark
# energy, Omega_m ~ 0.31, massless neutrinos), 1200 log-spaced k in [1e-4, 50] h/Mpc, the settings of
# make_planck2018.py. A spectrum not trained on, for the basis tests of the loop terms.
# Run with the `camb` Python package (2.0.5 made the committed file): python3 make_camb_w0wa.py
import camb
pars = camb.CAMBparams()
pars.set_cosmology(H0=67.0, ombh2=0.0223, omch2=0.121, mnu=0.0, omk=0.0, num_massive_neutrinos=0,
                   nnu=3.046)
pars.set_dark_energy(w=-0.8, wa=-0.7, dark_energy_model="ppf")
pars.InitPower.set_params(As=2.0e-9, ns=0.97)
pars.set_matter_power(redshifts=[1.0], kmax=60.0)
pars.NonLinear = camb.model.NonLinear_none
res = camb.get_results(pars)
kh, z, pk = res.get_matter_power_spectrum(minkh=1e-4, maxkh=50, npoints=1200)
with open("linear_pk_camb_w0wa_z1.0.dat", "w") as f:
    f.write(f"# CAMB {camb.__version__} linear total-matter P(k): H0=67 ombh2=0.0223 omch2=0.121 flat "
            "w0=-0.8 wa=-0.7 (PPF) ns=0.97 As=2.0e-9, massless neutrinos (N_eff=3.046)\n")
    f.write(f"# z = {z[0]}  sigma8(z) = {res.get_sigma8()[0]:.6f}\n# k [h/Mpc]  P [(Mpc/h)^3]\n")
    for k, p in zip(kh, pk[0]):
        f.write(f"{k:.8e} {p:.8e}\n")
