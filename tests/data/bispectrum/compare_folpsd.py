#!/usr/bin/env python3
"""FolpsD reference tables of the tree-level redshift-space bispectrum, and their agreement with the
independent numpy code make_reference.py (DEFINITIONS.md). FolpsD is not vendored: give the path of a
checkout of github.com/cosmodesi/FolpsD (BSD-3-Clause; tables made at commit 2e082583) with --folpsd.

  FOLPS_BACKEND=numpy python3 compare_folpsd.py --folpsd /path/to/FolpsD

FolpsD needs numpy and scipy only with the numpy backend; its package __init__ imports classy, so this
script imports folps/folps.py as a module from inside folps/ (as FolpsD's own notebooks do).

Writes folpsd_scoccimarro.txt, folpsd_sugiyama.txt and folpsd_mathematica_setup.txt. Conventions mapped
(DEFINITIONS.md): FolpsD bs2 = 2 b_s; Scoccimarro Legendre on the FIRST side, so triplets are passed
largest first; its Scoccimarro always damps with 'lor' = (1 + x (f X sigma_v)^2/2)^-1, X = sigma/(f sigma_v);
stochastic [b1 Bshot + 2 Pshot f mu^2] Z1 P + Pshot^2 = ours with n_bar = 1/Pshot, b_shot = Bshot/Pshot,
p_shot = 1, a_shot = 0; B112 compared with our FolpsD-weight column 112F.
"""
import argparse
import os
import sys

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
import make_reference as R  # noqa: E402


def load_folpsd(path):
    os.environ.setdefault("FOLPS_BACKEND", "numpy")
    sys.path.insert(0, os.path.join(path, "folps"))
    import folps  # noqa: E402  (folps/folps.py as a module)
    return folps


def dense(lin, n=20000):
    k = np.logspace(-4, np.log10(50.0), n)
    return k, lin(k)


def folpsd_bpars(m, f, sigma_v):
    """FolpsD [b1, b2, bs2, c1, c2, Bshot, Pshot, X_FoG] of our model (no-shot or FolpsD-form shot)."""
    if np.isfinite(m["n_bar"]):
        pshot = 1.0 / m["n_bar"]
        bshot = m["b_shot"] * pshot
        assert m["p_shot"] == 1.0 and m["a_shot"] == 0.0, "FolpsD's stochastic family: p_shot = 1, a_shot = 0"
    else:
        pshot = bshot = 0.0
    X = 0.0 if m["fog"] == "none" else m["sigma_fog"] / (f * sigma_v)
    return [m["b1"], m["b2"], 2.0 * m["bs"], m["c1"], 0.0, bshot, pshot, X]


def models(lin, sigma2v, Sigma2, dSigma2, pnw):
    f = R.header_value(lin, "growth_rate_f(z)")
    base = dict(b1=2.0, b2=-0.5, bs=-0.3, f=f)
    ir = dict(pnw=pnw, Sigma2=Sigma2, dSigma2=dSigma2,
              describe=f"FolpsD's: Sigma2 = {Sigma2:.6f}, dSigma2 = {dSigma2:.6f} (Mpc/h)^2, P_nw of make_reference")
    shot = dict(n_bar=1.0 / 2500.0, b_shot=1.2, p_shot=1.0, a_shot=0.0)
    return f, [
        ("tree", R.model(**base), "none"),
        ("tree_fog_lor1", R.model(**base, fog="lorentzian1", sigma_fog=4.0), "lor"),
        ("tree_fog_gauss", R.model(**base, fog="gaussian", sigma_fog=4.0), "exp"),
        ("tree_ct_shot", R.model(**base, c1=5.0, **shot), "none"),
        ("tree_ap", R.model(**base, q_par=1.03, q_perp=0.98), "none"),
        ("tree_ir", R.model(**base, ir=ir), "none"),
        ("tree_ir_all", R.model(**base, ir=ir, fog="lorentzian1", sigma_fog=4.0, c1=5.0, q_par=1.03,
                                q_perp=0.98, **shot), "lor"),
    ]


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--folpsd", required=True, help="path of a FolpsD checkout")
    ap.add_argument("--commit", default="2e0825832bf53f8426d6c5caf0e3dee593237bb5")
    args = ap.parse_args()
    F = load_folpsd(args.folpsd)
    lin = R.Linear(R.LINEAR)
    k, pk = dense(lin)
    pnw_lin = R.no_wiggle(lin)
    pkn = pnw_lin(k)
    bc = F.BispectrumCalculator(model="FOLPSD")
    sigma2v, Sigma2, dSigma2 = (float(v) for v in bc.sigmas(k, pk))
    f, mods = models(lin, sigma2v, Sigma2, dSigma2, pnw_lin)
    sv = np.sqrt(sigma2v)
    tri = np.array(R.TRIANGLES)
    common = [
        f"# FolpsD (github.com/cosmodesi/FolpsD, BSD-3-Clause, commit {args.commit}), numpy backend, class",
        "# BispectrumCalculator(model='FOLPSD'), bias_scheme='folps', interpolation_method='cubic' on a dense",
        "# 20000-point log grid of our spline of the linear table (so FolpsD's interpolation adds < 1e-9).",
        *R.lin_header(lin),
        f"# FolpsD's sigmas(): sigma_v^2 = {sigma2v:.6f}, Sigma^2 = {Sigma2:.6f}, deltaSigma^2 = {dSigma2:.6f} (Mpc/h)^2;",
        "# without IR FolpsD gets P_nw = P (so its IR factor acts on zero); with IR P_nw = make_reference.no_wiggle",
        "# (the file linear_nw_gm2012_z0.5.txt) and FolpsD's Sigma's, which our code then uses too.",
        f"# models (our parameters, velocileptors bias; FolpsD gets bs2 = 2 bs; f = {f}; FolpsD FoG X = sigma_fog/(f sigma_v)):",
    ]
    for name, m, damp in mods:
        common.append(f"#   {name} (FolpsD damping '{damp}'): {R.describe(m)}")

    # --- Scoccimarro ------------------------------------------------------------------------------
    rows, agree = [], {}
    for name, m, damp in mods:
        if damp == "exp":
            continue  # FolpsD's Scoccimarro_B024 always uses 'lor'
        kpp = np.array([k, pk, pkn if m["ir"] is not None else pk])
        bp = folpsd_bpars(m, f, sv)
        out = bc.Scoccimarro_Bell(tri[:, ::-1], f, bp, m["q_par"], m["q_perp"], kpp, precision=[40, 40],
                                  interpolation_method="cubic")
        fb = np.array(out[:3])
        ours = R.multipoles_at(lin, m, tri[:, 0], tri[:, 1], tri[:, 2], n_mu=64, n_phi=64)
        agree[name] = np.max(np.abs(fb - ours) / np.abs(ours[0])[None, :])
        for i, t in enumerate(R.TRIANGLES):
            rows.append((name, *t, *fb[:, i], *ours[:, i]))
    hdr = ["# FolpsD Scoccimarro_Bell: tree-level B0, B2, B4 with the Legendre polynomial on the LARGEST side",
           "# (triplets passed as (k3, k2, k1)), precision [N_phi, N_mu] = [40, 40] Gauss-Legendre.",
           *common,
           "# agreement FolpsD - make_reference (64 x 64), max over triangles and l of |diff|/|B0|: "
           + ", ".join(f"{k_} {v:.1e}" for k_, v in agree.items()),
           "# units: k [h/Mpc], B [(Mpc/h)^6]",
           "# columns: model k1 k2 k3 B0_folpsd B2_folpsd B4_folpsd B0_ours B2_ours B4_ours"]
    R.write(os.path.join(HERE, "folpsd_scoccimarro.txt"), hdr, rows,
            "{} {:.4f} {:.4f} {:.4f} " + " ".join(["{: .10e}"] * 6))
    print("Scoccimarro agreement", agree, file=sys.stderr)

    # --- Sugiyama ---------------------------------------------------------------------------------
    pairs = np.array(R.SUGIYAMA_PAIRS)
    names = ["B000", "B110", "B220", "B202", "B022", "B112"]
    rows, agree = [], {}
    for name, m, damp in mods:
        kpp = np.array([k, pk, pkn if m["ir"] is not None else pk])
        bp = folpsd_bpars(m, f, sv)
        out = bc.Sugiyama_Bell(f, bp, kpp, pairs, m["q_par"], m["q_perp"], precision=[24, 400, 24],
                               damping=damp if damp != "none" else "lor", multipoles=names,
                               renormalize=True, interpolation_method="cubic")
        fb = np.array(out).T
        ours = R.sugiyama_at(lin, m, pairs[:, 0], pairs[:, 1])[:, [0, 1, 2, 3, 4, 6]]
        agree[name] = np.max(np.abs(fb - ours) / np.abs(ours[:, :1]))
        for i, pr in enumerate(R.SUGIYAMA_PAIRS):
            rows.append((name, *pr, *fb[i], *ours[i]))
    hdr = ["# FolpsD Sugiyama_Bell (renormalize=True): B000 B110 B220 B202 B022 B112 of the tree-level bispectrum,",
           "# precision [N_phi, N_x, N_mu] = [24, 400, 24] Gauss-Legendre. FolpsD's B112 uses a non-tripolar",
           "# azimuthal weight (DEFINITIONS.md (e)); *_ours 112 here is our column 112F (same weight).",
           *common,
           "# agreement FolpsD - make_reference, max over pairs and multipoles of |diff|/|B000|: "
           + ", ".join(f"{k_} {v:.1e}" for k_, v in agree.items()),
           "# (FolpsD's Gauss-Legendre in x = k1^.k2^ converges slowly for k1 = k2, where k3 -> 0 at x = -1)",
           "# units: k [h/Mpc], B [(Mpc/h)^6]",
           "# columns: model k1 k2 " + " ".join(n + "_folpsd" for n in names) + " " + " ".join(n + "_ours" for n in names)]
    R.write(os.path.join(HERE, "folpsd_sugiyama.txt"), hdr, rows,
            "{} {:.4f} {:.4f} " + " ".join(["{: .10e}"] * 12))
    print("Sugiyama agreement", agree, file=sys.stderr)

    # --- FolpsD's Mathematica test setup, converged ------------------------------------------------
    tests = os.path.join(args.folpsd, "_tests")
    km, pm = np.loadtxt(os.path.join(tests, "pk_linear_simtocmass.txt"), unpack=True)
    M = np.loadtxt(os.path.join(tests, "M_Bl1l2L_mathematica.txt"))
    om = (0.117 + 0.02242) / 0.67**2
    f0 = float(F.get_f0(0.57, om))
    linm = R.Linear(k=km, p=pm)
    m = R.model(b1=1.0, f=f0)
    ours = R.sugiyama_at(linm, m, M[:, 0], M[:, 0])
    kpp = np.array([km, pm, pm])
    pr = np.vstack([M[:, 0], M[:, 0]]).T
    lo = np.array(bc.Sugiyama_Bell(f0, [1, 0, 0, 0, 0, 0, 0, 0], kpp, pr, 1, 1, precision=[10, 10, 10],
                                   damping="lor", multipoles=names, renormalize=True,
                                   interpolation_method="cubic")).T
    hi = np.array(bc.Sugiyama_Bell(f0, [1, 0, 0, 0, 0, 0, 0, 0], kpp, pr, 1, 1, precision=[24, 400, 24],
                                   damping="lor", multipoles=names, renormalize=True,
                                   interpolation_method="cubic")).T
    ours6 = ours[:, [0, 1, 2, 3, 4, 6]]
    d_lo = np.max(np.abs(lo - M[:, 1:]) / np.abs(M[:, 1:2]))
    d_math = np.max(np.abs(ours6 - M[:, 1:]) / np.abs(ours6[:, :1]), axis=0)
    d_hi = np.max(np.abs(hi - ours6) / np.abs(ours6[:, :1]))
    rows = [(M[i, 0], *M[i, 1:], *ours[i, :6], ours[i, 6]) for i in range(len(M))]
    hdr = ["# FolpsD's own Sugiyama test (_tests/M_compare_to_mathematica.ipynb): k1 = k2 = k, b1 = 1, b2 = bs2 = 0,",
           f"# no FoG, no shot, no IR, f = FolpsD get_f0(z = 0.57, Omega_m = {om:.6f}) = {f0!r},",
           "# P = FolpsD _tests/pk_linear_simtocmass.txt (cubic spline in ln k, ln P here).",
           "# Columns B*_math: FolpsD's _tests/M_Bl1l2L_mathematica.txt (BSD-3-Clause, FolpsD authors), a Mathematica",
           f"# evaluation with 10-node Gauss-Legendre rules: FolpsD at precision [10,10,10] reproduces it to {d_lo:.1e} of B000,",
           "# but it is NOT converged: it differs from the converged integral (*_ours) by, per multipole, max |diff|/|B000| = "
           + ", ".join(f"{v:.1e}" for v in d_math) + ";",
           f"# FolpsD at [24, 400, 24] agrees with *_ours to {d_hi:.1e} of B000. Its B112 is FolpsD's weight (= our 112F).",
           "# *_ours: make_reference.sugiyama_at (converged to ~1e-10); B112_ours is the tripolar 112.",
           "# columns: k B000_math B110_math B220_math B202_math B022_math B112F_math B000_ours B110_ours B220_ours",
           "#   B202_ours B022_ours B112_ours B112F_ours"]
    R.write(os.path.join(HERE, "folpsd_mathematica_setup.txt"), hdr, rows,
            "{:.8f} " + " ".join(["{: .10e}"] * 13))
    print("Mathematica", d_lo, d_math, d_hi, file=sys.stderr)


if __name__ == "__main__":
    main()
