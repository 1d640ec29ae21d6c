# Makes linear_pk_camb_curved_wa_z0.5.dat (see README.md): CAMB's linear total-matter P(k) at z = 0.5 for a
# curved w0-wa cosmology outside the flat-LCDM family of the 2-loop basis's training set (Omega_k = 0.01,
# w0 = -0.9, wa = -0.3 with PPF dark energy, massless neutrinos), 1200 log-spaced k in [1e-4, 50] h/Mpc,
# the settings of make_planck2018.py. A spectrum not trained on, for the basis tests of the loop terms.
# And linear_pk_camb_closed_z0.0.dat: a closed LCDM cosmology (Omega_k = -0.01; the soft modes then
# lower P below 1e-3 h/Mpc, the opposite sign), z = 0, the same k sampling.
# Run with the `camb` Python package (2.0.5 made the committed files): python3 make_camb_curved.py
import camb


def write_table(name, z, description, cosmology, initial, dark_energy=None):
    """CAMB's linear total-matter P(k) at `z` on 1200 log-spaced k in [1e-4, 50] h/Mpc, to `name`."""
    pars = camb.CAMBparams()
    pars.set_cosmology(mnu=0.0, num_massive_neutrinos=0, nnu=3.046, **cosmology)
    if dark_energy:
        pars.set_dark_energy(**dark_energy)
    pars.InitPower.set_params(**initial)
    pars.set_matter_power(redshifts=[z], kmax=60.0)
    pars.NonLinear = camb.model.NonLinear_none
    res = camb.get_results(pars)
    kh, zs, pk = res.get_matter_power_spectrum(minkh=1e-4, maxkh=50, npoints=1200)
    with open(name, "w") as f:
        f.write(f"# CAMB {camb.__version__} linear total-matter P(k): {description}\n")
        f.write(f"# z = {zs[0]}  sigma8(z) = {res.get_sigma8()[0]:.6f}\n# k [h/Mpc]  P [(Mpc/h)^3]\n")
        for k, p in zip(kh, pk[0]):
            f.write(f"{k:.8e} {p:.8e}\n")


write_table("linear_pk_camb_curved_wa_z0.5.dat", 0.5,
            "H0=69 ombh2=0.0225 omch2=0.125 omk=0.01 w0=-0.9 wa=-0.3 (PPF) ns=0.955 As=2.2e-9, "
            "massless neutrinos (N_eff=3.046)",
            dict(H0=69.0, ombh2=0.0225, omch2=0.125, omk=0.01), dict(As=2.2e-9, ns=0.955),
            dict(w=-0.9, wa=-0.3, dark_energy_model="ppf"))
write_table("linear_pk_camb_closed_z0.0.dat", 0.0,
            "H0=67 ombh2=0.0222 omch2=0.121 omk=-0.01 (LCDM) ns=0.97 As=2.05e-9, massless neutrinos "
            "(N_eff=3.046)",
            dict(H0=67.0, ombh2=0.0222, omch2=0.121, omk=-0.01), dict(As=2.05e-9, ns=0.97))
