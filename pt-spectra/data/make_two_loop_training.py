"""Makes the training spectra of the 2-loop basis (pt-spectra/data/two_loop_training_camb.f32) and
held-out CAMB test spectra (pt-spectra/tests/data/linear_pk_camb_heldout_*.dat).

CAMB linear total-matter P(k) at z = 0 with the settings of pt-spectra/tests/data/make_planck2018.py (massless
neutrinos, N_eff = 3.046, kmax = 60/Mpc, 1200 log-spaced k in [1e-4, 50] h/Mpc), for cosmologies drawn
uniformly (numpy default_rng, fixed seeds) from the EuclidEmulator2 box: Omega_m 0.24-0.40, Omega_b
0.04-0.06, n_s 0.92-1.00, h 0.61-0.73, w0 -1.3 to -0.7 (PPF dark energy); A_s = 2.1e-9 (it only
scales P). The library builds its basis from these tables exactly as it reads any table (spline in
ln k, power-law extrapolation), so the basis represents tables made the same way.

File layout (little-endian float32): the 1200 k [h/Mpc], then 1200 P [(Mpc/h)^3] per spectrum.

    python pt-spectra/data/make_two_loop_training.py train 0 50 a.npz &   # two halves in parallel,
    python pt-spectra/data/make_two_loop_training.py train 50 100 b.npz    # ~4 s per spectrum each
    python pt-spectra/data/make_two_loop_training.py write a.npz b.npz     # -> pt-spectra/data/
    python pt-spectra/data/make_two_loop_training.py heldout               # -> pt-spectra/tests/data/ (3 tables)
"""
import os
import sys

import camb
import numpy as np

BOX = [(0.24, 0.40), (0.04, 0.06), (0.92, 1.00), (0.61, 0.73), (-1.3, -0.7)]
HERE = os.path.dirname(os.path.abspath(__file__))


def draws(seed, n):
    rng = np.random.default_rng(seed)
    return [[lo + r * (hi - lo) for (lo, hi), r in zip(BOX, u)] for u in rng.random((n, len(BOX)))]


def spectrum(om, ob, ns, h, w0, a_s=2.1e-9, z=0.0):
    pars = camb.CAMBparams()
    pars.set_cosmology(H0=100 * h, ombh2=ob * h * h, omch2=(om - ob) * h * h, mnu=0.0, omk=0,
                       num_massive_neutrinos=0, nnu=3.046)
    pars.set_dark_energy(w=w0, dark_energy_model="ppf")
    pars.InitPower.set_params(As=a_s, ns=ns)
    pars.set_matter_power(redshifts=[z], kmax=60.0)
    pars.NonLinear = camb.model.NonLinear_none
    res = camb.get_results(pars)
    kh, _, pk = res.get_matter_power_spectrum(minkh=1e-4, maxkh=50, npoints=1200)
    return kh, pk[0]


def main():
    mode = sys.argv[1]
    if mode == "train":
        lo, hi, out = int(sys.argv[2]), int(sys.argv[3]), sys.argv[4]
        params = draws(18, 100)[lo:hi]
        rows = []
        for i, p in enumerate(params):
            k, pk = spectrum(*p)
            rows.append(pk)
            print(f"{lo + i + 1}/100", flush=True)
        np.savez(out, k=k, P=np.array(rows), params=np.array(params))
    elif mode == "write":
        parts = [np.load(f) for f in sys.argv[2:]]
        k = parts[0]["k"]
        p = np.vstack([d["P"] for d in parts])
        out = os.path.join(HERE, "two_loop_training_camb.f32")
        np.concatenate([k, p.ravel()]).astype("<f4").tofile(out)
        print(out, p.shape)
    elif mode == "heldout":
        # Three cosmologies of the box that are not training points, one at z = 0.5 with another A_s.
        for i, (p, a_s, z) in enumerate(zip(draws(7, 3), [2.1e-9, 1.8e-9, 2.4e-9], [0.0, 0.5, 0.0])):
            k, pk = spectrum(*p, a_s=a_s, z=z)
            name = os.path.join(HERE, "..", "tests", "data", f"linear_pk_camb_heldout_{i}.dat")
            with open(name, "w") as f:
                f.write(f"# CAMB {camb.__version__} linear total-matter P(k) (pt-spectra/data/make_two_loop_training.py "
                        f"heldout): Omega_m={p[0]:.6f} Omega_b={p[1]:.6f} n_s={p[2]:.6f} h={p[3]:.6f} "
                        f"w0={p[4]:.6f} (PPF) As={a_s:.3e}, massless neutrinos, flat, z = {z}\n")
                f.write("# k [h/Mpc]  P [(Mpc/h)^3]\n")
                for kk, pp in zip(k, pk):
                    f.write(f"{kk:.8e} {pp:.8e}\n")
            print(name)


if __name__ == "__main__":
    main()
