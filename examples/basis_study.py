"""How many functions does a linear basis need to represent linear spectra over a prior?

A first step towards 2-loop spectra per cosmology from precomputed tensors (issue 18): every 2-loop term
is multilinear in P_lin, so with P_lin ≈ Σ_a c_a φ_a the terms become contractions of cosmology-
independent tensors with the coefficients c_a. This measures the basis size that the projection error
calls for. Eisenstein & Hu spectra with wiggles (pt.eisenstein_hu) at z = 0 are drawn uniformly from the
EuclidEmulator2 box in Ω_m, Ω_b, n_s, h (A_s and w0 only scale P at fixed z for this transfer
function): an SVD of 400 of them, weighted by 1/mean (relative residuals), and the projection of 100
others. Prints the largest and the median relative residual over q ∈ [1e-4, 10] h/Mpc per basis size.

    python examples/basis_study.py          # ~20 s

Measured (seed 1): N = 12: 2.3e-3 (median 4.3e-4); 16: 8.3e-4 (1.5e-4); 20: 4.2e-4 (5.1e-5);
24: 1.5e-4 (1.9e-5); 32: 2.7e-5 (5.3e-6); 40: 1.9e-5 (1.7e-6).

This was the first step only: such an Eisenstein-Hu basis leaves 1-3e-2 on CAMB tables, whose shape
differs from the fit's by percents, so the library's basis (pt_spectra::loops::basis) is built from CAMB
spectra instead (pt-spectra/data/make_two_loop_training.py; README, "2-loop terms per cosmology").
"""
import warnings

import numpy as np

import pt_spectra as pt

BOX = dict(Omega_m=(0.24, 0.40), Omega_b=(0.04, 0.06), n_s=(0.92, 1.00), h=(0.61, 0.73))


def spectra(q, n, rng):
    """n Eisenstein & Hu spectra at q [h/Mpc], parameters uniform in BOX."""
    out = []
    for u in rng.random((n, len(BOX))):
        c = {key: lo + r * (hi - lo) for (key, (lo, hi)), r in zip(BOX.items(), u)}
        c["Omega_cdm"] = c.pop("Omega_m") - c["Omega_b"]
        c["A_s"] = 2.1e-9
        out.append(pt.eisenstein_hu(q, 0.0, c, True))
    return np.array(out)


def main():
    warnings.simplefilter("ignore", pt.PtSpectraWarning)
    rng = np.random.default_rng(1)
    q = np.geomspace(1e-4, 10, 600)
    train, test = spectra(q, 400, rng), spectra(q, 100, rng)
    w = 1.0 / train.mean(axis=0)
    _, _, vt = np.linalg.svd(train * w, full_matrices=False)
    for n in (8, 12, 16, 20, 24, 32, 40):
        basis = vt[:n]
        fitted = ((test * w) @ basis.T) @ basis
        residual = np.abs(fitted / (test * w) - 1.0).max(axis=1)
        print(f"N = {n:2d}: largest relative residual {residual.max():.1e}, median {np.median(residual):.1e}")


if __name__ == "__main__":
    main()
