"""P alone and P + B of the Nseries mocks (issue 49, part 6): the mean window-free P0, P2 and B0 of the 84
Nseries CMASS-like mocks fitted with the galaxy model `ept` (P) and the tree-level bispectrum (B) sharing
f, b1, b2, bs, with the joint P + B covariance of one BOSS NGC volume (2048 Patchy mocks), versus the
k_max of B. Writes examples/out/nseries_pb_fit.md (settings, table, conclusions) and nseries_pb_fit.png.

    python3 examples/nseries_pb_fit.py [--data DIR] [--cov FILE] [--out DIR] [--starts N]

--data: the folder of pk_nseries<i>_fkp.txt and bk_nseries<i>_fkp.txt (i = 1..84), --cov: the Patchy
covariance cov_patchy_ngc_z3_pb.txt. Both from oliverphilcox/Spectra-Without-Windows (MIT; the READMEs of
../shared/data/nseries and ../shared/data/patchy_covariance say how they were made); the defaults,
../shared/data/... next to the repository, exist on the project's machines only. Needs the Python module
(`pip install ./python`), numpy, scipy, matplotlib. About 20 s on one core (measured).

Settings (stated in the report too):
- the template is the true cosmology of the mocks at z = 0.56, AP fixed at the truth (fiducial
  Omega_m = 0.31, h = 0.676), f free (truth f(z) of the true cosmology);
- P: P0, P2 at 0.02 <= k <= 0.15 h/Mpc, parameters b1, b2, bs, alpha0, alpha2, sn (velocileptors' names);
- B: B0 of the bins with largest side <= k_max(B), averaged over their closed triangles (width 0.01),
  IR-resummed, no FoG, counterterm c1 and the stochastic terms b_shot, a_shot at n_bar = 3e-4 (h/Mpc)^3
  free (p_shot = 0); B2, B4 are not fitted (the tree-level B2 without FoG is 10-25% off the mocks by
  bin class: docs/bispectrum.md);
- covariance: the Patchy P + B covariance of one NGC volume (so the errors are those of one BOSS-like
  volume, not of the mean of 84 mocks), Hartlap-corrected; B enters through the joint covariance;
- B depends on f beyond a polynomial only through the IR damping: its terms are computed at 7 values of f
  in [0.55, 0.95] and interpolated (Lagrange; the interpolation error is measured and stated);
- Gaussian priors on the nuisance parameters (PRIOR below, the same in every fit) are part of the chi^2;
  the minimum is the lowest of --starts least-squares starts from the box; errors from the Fisher matrix
  J^T C^-1 J + priors at the minimum.
"""

import argparse
import sys
import time
from pathlib import Path

import numpy as np
from scipy.optimize import least_squares

import pt_spectra as pt

ROOT = Path(__file__).resolve().parent.parent
DEFAULT_DATA = ROOT.parent / "shared" / "data" / "nseries"
DEFAULT_COV = ROOT.parent / "shared" / "data" / "patchy_covariance" / "cov_patchy_ngc_z3_pb.txt"
DEFAULT_OUT = ROOT / "examples" / "out"

Z = 0.56
TRUE = dict(h=0.70, omega_b=0.02303, omega_cdm=0.11711, n_s=0.96, A_s=2.1446e-9)
FID_OMEGA_M, FID_H = 0.310, 0.676
FID = dict(h=FID_H, omega_b=0.022, omega_cdm=FID_OMEGA_M * FID_H ** 2 - 0.022, n_s=0.96, sigma8=0.8)
K_MIN_P, K_MAX_P = 0.02, 0.15
K_MAX_B = [0.045, 0.055, 0.065, 0.075]  # the largest side of the Nseries bins reaches 0.075
N_BAR = 3e-4
N_PATCHY = 2048
F_NODES = np.linspace(0.55, 0.95, 7)
P_NAMES = ["f", "b1", "b2", "bs", "alpha0", "alpha2", "sn"]
B_NAMES = ["c1", "b_shot", "a_shot"]
BOX = {"f": (0.3, 1.3), "b1": (1.0, 3.5), "b2": (-10, 10), "bs": (-10, 10), "alpha0": (-300, 300),
       "alpha2": (-300, 300), "sn": (-2e4, 2e4), "c1": (-100, 100), "b_shot": (-10, 10), "a_shot": (-10, 10)}
# Gaussian priors (mean, sigma) on the nuisance parameters, the same in every fit, as the EFT analyses
# put them (b2, bs of order unity; counterterms of tens of (Mpc/h)^2; shot noise within a few Poisson
# values of 1/n_bar ~ 3300 (Mpc/h)^3): they enter the chi^2 and the Fisher matrix.
PRIOR = {"b2": (0.0, 1.0), "bs": (0.0, 1.0), "alpha0": (0.0, 50.0), "alpha2": (0.0, 50.0),
         "sn": (0.0, 3000.0), "c1": (0.0, 10.0), "b_shot": (1.0, 1.0), "a_shot": (0.0, 1.0)}


def log(msg):
    print(msg, file=sys.stderr, flush=True)


def ap_truth():
    """alpha_par = E_fid/E_true, alpha_perp = D_M,true/D_M,fid in Mpc/h."""
    h_t, dm_t = pt.distances(Z, TRUE)
    h_f, dm_f = pt.distances(Z, FID)
    return (h_f / FID_H) / (h_t / TRUE["h"]), (dm_t * TRUE["h"]) / (dm_f * FID_H)


def read_data(folder):
    pk = np.array([np.loadtxt(folder / f"pk_nseries{i}_fkp.txt") for i in range(1, 85)])
    bk = np.array([np.loadtxt(folder / f"bk_nseries{i}_fkp.txt") for i in range(1, 85)])
    return pk.mean(0), bk.mean(0)


class Model:
    def __init__(self, k_p, triangles, qpar, qperp):
        self.k_p = k_p
        self.p_terms = pt.EptPlan(k_p, apar=qpar, aperp=qperp).terms(cosmology=TRUE, z=Z)
        plan = pt.BispectrumPlan(triangles, bin_width=0.01)
        self.b_terms = [plan.terms(cosmology=TRUE, z=Z, f=f, q_par=qpar, q_perp=qperp) for f in F_NODES]

    def p(self, v):
        t = self.p_terms.multipoles(ells=(0, 2), **{n: v[n] for n in P_NAMES})
        return np.concatenate([t["P0"], t["P2"]])

    def b0(self, v):
        """B0 at f by Lagrange interpolation over the f nodes."""
        f = v["f"]
        out = 0.0
        for j, fj in enumerate(F_NODES):
            w = np.prod([(f - fm) / (fj - fm) for m, fm in enumerate(F_NODES) if m != j])
            b, _ = self.b_terms[j].multipoles(b1=v["b1"], b2=v["b2"], bs=v["bs"], c1=v["c1"], n_bar=N_BAR,
                                              b_shot=v["b_shot"], a_shot=v["a_shot"])
            out = out + w * b[:, 0]
        return out


def fit(model, data, cinv_half, names, use_b, starts, rng):
    def vector(x):
        v = dict(zip(names, x))
        v.update({n: 0.0 for n in B_NAMES if n not in v})
        m = model.p(v)
        if use_b:
            m = np.concatenate([m, model.b0(v)])
        return m

    prior = [(i, PRIOR[n]) for i, n in enumerate(names) if n in PRIOR]

    def residual(x):
        r = cinv_half @ (vector(x) - data)
        return np.concatenate([r, [(x[i] - m) / s for i, (m, s) in prior]])

    lo = np.array([BOX[n][0] for n in names])
    hi = np.array([BOX[n][1] for n in names])
    best = []
    for s in range(starts):
        x0 = lo + (hi - lo) * rng.uniform(0.2, 0.8, len(names)) if s else np.array(
            [{"f": 0.75, "b1": 2.0}.get(n, 0.0) for n in names])
        r = least_squares(residual, x0, bounds=(lo, hi), x_scale="jac", xtol=1e-10, ftol=1e-10)
        best.append((2 * r.cost, r))
    best.sort(key=lambda c: c[0])
    chi2, r = best[0]
    agree = sum(1 for c, _ in best if c - chi2 < 0.01)
    fisher = r.jac.T @ r.jac
    cov = np.linalg.inv(fisher)
    return dict(zip(names, r.x)), dict(zip(names, np.sqrt(np.diag(cov)))), chi2, agree, len(data)


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--data", type=Path, default=DEFAULT_DATA)
    ap.add_argument("--cov", type=Path, default=DEFAULT_COV)
    ap.add_argument("--out", type=Path, default=DEFAULT_OUT)
    ap.add_argument("--starts", type=int, default=8)
    a = ap.parse_args()
    for p in (a.data, a.cov):
        if not p.exists():
            sys.exit(f"{p} not found: see the docstring for where the Nseries data and the Patchy covariance come from")
    t0 = time.time()
    pk, bk = read_data(a.data)
    cov = np.loadtxt(a.cov)
    qpar, qperp = ap_truth()
    f_true = pt.growth(Z, TRUE)[1]
    k_all = pk[:, 0]
    sel_k = (k_all >= K_MIN_P) & (k_all <= K_MAX_P)
    k_p = k_all[sel_k]
    n_k, n_t = len(k_all), len(bk)
    p_index = np.concatenate([np.where(sel_k)[0], n_k + np.where(sel_k)[0]])
    p_data = np.concatenate([pk[sel_k, 1], pk[sel_k, 2]])
    rows = []
    model_full = Model(k_p, bk[:, :3], qpar, qperp)
    # the f interpolation error of B0: an extra node against the interpolant
    check = dict(f=0.7321, b1=2.0, b2=0.5, bs=-0.2, c1=0.0, b_shot=1.0, a_shot=0.0)
    direct = pt.BispectrumPlan(bk[:, :3], bin_width=0.01).terms(cosmology=TRUE, z=Z, f=check["f"], q_par=qpar,
                                                               q_perp=qperp)
    b_direct = direct.multipoles(b1=2.0, b2=0.5, bs=-0.2, n_bar=N_BAR)[0][:, 0]
    interp_err = np.max(np.abs(model_full.b0(check) / b_direct - 1))
    rng = np.random.default_rng(7)
    results = {}
    for label, kmax_b in [("P", None)] + [(f"P+B0 (k_max,B = {k})", k) for k in K_MAX_B]:
        if kmax_b is None:
            index, data, use_b, names = p_index, p_data, False, P_NAMES
            model = model_full
        else:
            sel_t = bk[:, 2] <= kmax_b + 1e-9
            index = np.concatenate([p_index, 3 * n_k + np.where(sel_t)[0]])
            data = np.concatenate([p_data, bk[sel_t, 3]])
            use_b, names = True, P_NAMES + B_NAMES
            model = Model.__new__(Model)
            model.p_terms = model_full.p_terms
            model.b_terms = model_full.b_terms
            model.b0 = (lambda sel: (lambda v: Model.b0(model_full, v)[sel]))(sel_t)
            model.p = model_full.p
        c = cov[np.ix_(index, index)]
        n = len(index)
        hartlap = (N_PATCHY - n - 2) / (N_PATCHY - 1)
        # invert through the correlation matrix (the P and B blocks differ by ~1e5 in scale)
        s = np.sqrt(np.diag(c))
        corr_inv = np.linalg.inv(c / np.outer(s, s))
        cinv = hartlap * corr_inv / np.outer(s, s)
        cinv_half = np.linalg.cholesky(cinv).T
        t = time.time()
        best, err, chi2, agree, ndata = fit(model, data, cinv_half, names, use_b, a.starts, rng)
        results[label] = (best, err, chi2, agree, ndata, len(names), time.time() - t)
        log(f"{label}: f = {best['f']:.4f} +- {err['f']:.4f} (truth {f_true:.4f}), b1 = {best['b1']:.3f} +- "
            f"{err['b1']:.3f}, chi2 = {chi2:.1f} for {ndata} - {len(names)}, {agree}/{a.starts} starts agree")
    write_report(a.out, results, f_true, qpar, qperp, interp_err, a.starts, time.time() - t0)


def write_report(out, results, f_true, qpar, qperp, interp_err, starts, seconds):
    out.mkdir(parents=True, exist_ok=True)
    lines = [
        "# Nseries: P alone and P + B0 (tree level), f and the biases versus k_max of B",
        "",
        f"Made by `examples/nseries_pb_fit.py` in {seconds:.0f} s. Mean of the 84 Nseries mocks; covariance of one "
        "BOSS NGC volume (Patchy, Hartlap-corrected), so the errors are those of one volume. Template: the true "
        f"cosmology at z = {Z}; AP fixed at the truth (alpha_par = {qpar:.4f}, alpha_perp = {qperp:.4f}); "
        f"P0, P2 at {K_MIN_P} <= k <= {K_MAX_P} h/Mpc; B0 bin-averaged (width 0.01), IR-resummed, n_bar = {N_BAR}. "
        f"B0 interpolated in f over {len(F_NODES)} nodes: worst error {interp_err:.1e}. Minimum: lowest of "
        f"{starts} starts. Gaussian priors (mean, sigma): "
        + ", ".join(f"{n} {m:g}±{sd:g}" for n, (m, sd) in PRIOR.items()) + " (in chi2).",
        "",
        "| data | f | (f - f_true)/sigma | b1 | b2 | bs | chi2 / dof | starts within 0.01 | seconds |",
        "|---|---|---|---|---|---|---|---|---|",
    ]
    for label, (b, e, chi2, agree, n, p, sec) in results.items():
        lines.append(f"| {label} | {b['f']:.4f} ± {e['f']:.4f} | {(b['f'] - f_true) / e['f']:+.2f} | "
                     f"{b['b1']:.3f} ± {e['b1']:.3f} | {b['b2']:.2f} ± {e['b2']:.2f} | {b['bs']:.2f} ± {e['bs']:.2f} | "
                     f"{chi2:.1f} / {n - p} | {agree}/{starts} | {sec:.1f} |")
    p_only = results["P"][1]["f"]
    gains = [f"{label}: σ(f) {100 * (1 - e['f'] / p_only):.0f}% smaller" for label, (b, e, *_) in results.items()
             if label != "P"]
    lines += ["", f"Truth: f = {f_true:.4f}. Gain from B0 over P alone: " + "; ".join(gains) + ".", ""]
    (out / "nseries_pb_fit.md").write_text("\n".join(lines) + "\n")
    print("\n".join(lines))
    try:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
        fig, ax = plt.subplots(figsize=(6, 3.5))
        labels = list(results)
        for i, label in enumerate(labels):
            b, e = results[label][0], results[label][1]
            ax.errorbar(i, b["f"] / f_true - 1, e["f"] / f_true, fmt="o", capsize=3)
        ax.axhline(0, color="k", lw=0.8)
        ax.set_xticks(range(len(labels)), ["P"] + [f"P+B0\n{k}" for k in K_MAX_B])
        ax.set_ylabel("f / f_true - 1")
        ax.set_title("Nseries mean, one-volume errors")
        fig.tight_layout()
        fig.savefig(out / "nseries_pb_fit.png", dpi=120)
    except ImportError:
        log("matplotlib not installed: no figure")


if __name__ == "__main__":
    main()
