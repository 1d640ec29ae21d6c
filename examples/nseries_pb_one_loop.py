"""P + B0 of the Nseries mocks with the one-loop bispectrum (issue 50, item 4): the likelihood of
examples/nseries_pb_analysis.py (the same data, Patchy P + B covariance, template, AP fixed at the truth, P
priors and k ranges) with `[dataset.one_loop_bispectrum]` in place of `[dataset.bispectrum]`, fitted by
`pt-spectra fit --analysis`, beside the tree-level fits of the same script.

The one-loop block reads the multipole tensors of the 62 Nseries bins from --tensors; build them once
(~40 min on 2 cores on the rule 6 x 16 x 12, whose B0 is within 6e-5 and B2 within 2e-4 of B0 of the
default rule's on two Nseries triangles):

    python3 -c "import numpy as np, pt_spectra as pt; pt.OneLoopMultipolePlan(np.loadtxt(
        'tests/data/bispectrum/nseries_triangles.txt'), bin_width=0.01, radial=6, mu=16, phi=12,
        cache_dir='TENSORS')"
    python3 examples/nseries_pb_one_loop.py --tensors TENSORS [--data DIR] [--cov FILE] [--bin PATH]

Model of B0: the one-loop galaxy multipole (IR resummed, AP: its isotropic dilation exact, the anisotropic rest
on the tree level) with b1, b2, bs shared,
b_gamma3 and the leading counterterms and stochastic terms marginalised with Gaussian priors: b_gamma3 0 ± 1,
ct_k2, ct_k2_mu2 0 ± 50 (Mpc/h)^2, st_p (1/n) ± (1/n), st_1 (1/n^2) ± (1/n^2); st_p_mu2 fixed at Poisson 1/n
(as the tree-level fit's p_shot = 0); the other own parameters 0. Writes examples/out/nseries_pb_one_loop.md.
"""

import argparse
import sys
import time
from pathlib import Path

import pt_spectra as pt

sys.path.insert(0, str(Path(__file__).resolve().parent))
from nseries_pb_analysis import DEFAULT_BIN, DEFAULT_OUT, STARTS, log, run, table, write_inputs  # noqa: E402
from nseries_pb_fit import (DEFAULT_COV, DEFAULT_DATA, K_MAX_B, K_MAX_P, K_MIN_P, N_BAR,  # noqa: E402
                            N_PATCHY, PRIOR, TRUE, Z, ap_truth)

RULE = (6, 16, 12)
LOOP_PRIOR = {"b_gamma3": (0.0, 1.0), "ct_k2": (0.0, 50.0), "ct_k2_mu2": (0.0, 50.0),
              "st_p": (1 / N_BAR, 1 / N_BAR), "st_1": (1 / N_BAR ** 2, 1 / N_BAR ** 2)}


def analysis(out, name, qpar, qperp, k_max_b, tensors, one_loop):
    """The analysis file of P0, P2 and B0 (tree level or one loop) of the bins below `k_max_b`."""
    quote = lambda items: ", ".join(f'"{i}"' for i in items)  # noqa: E731
    if one_loop:
        marg = ["alpha0", "alpha2", "sn"] + list(LOOP_PRIOR)
        free = ["f", "b1", "b2", "bs"]
        prior = {**PRIOR, **LOOP_PRIOR}
    else:
        marg = ["alpha0", "alpha2", "sn", "b_shot", "a_shot"]
        free = ["f", "b1", "b2", "bs", "c1"]
        prior = PRIOR
    priors = [f"{n}:{m!r},{s!r}" for n, (m, s) in prior.items() if n in free + marg]
    text = [
        f"# Nseries mean, written by examples/nseries_pb_one_loop.py ({name})",
        "[search]", f"starts = {STARTS}", "seed = 1", "profile_check = false", 'linear = "profiled"', "",
        "[[dataset]]", 'label = "nseries"', 'data = "nseries_pb_p.dat"', "data_ells = [0, 2, 4]",
        f"n_mocks = {N_PATCHY}", f"z = {Z}", "ells = [0, 2]", f"k_min = {K_MIN_P}", f"k_max = {K_MAX_P}",
        f"free = [{quote(free)}]", f"marginalise = [{quote(marg)}]", f"priors = [{quote(priors)}]",
        f"apar = {qpar!r}", f"aperp = {qperp!r}",
        "[dataset.start]", "b1 = 2.0", "f = 0.75",
    ]
    if one_loop:
        text.insert(text.index("[dataset.start]") + 1, f"st_p_mu2 = {1 / N_BAR!r}")
        text += ["[dataset.one_loop_bispectrum]", 'data = "nseries_pb_b.dat"', "ells = [0]",
                 f"k_max = {k_max_b + 1e-9}", "bin_width = 0.01", 'covariance = "nseries_pb_cov.dat"',
                 f"rule = [{', '.join(map(str, RULE))}]", f'cache_dir = "{tensors}"']
    else:
        text += ["[dataset.bispectrum]", 'data = "nseries_pb_b.dat"', "ells = [0]", f"k_max = {k_max_b + 1e-9}",
                 "bin_width = 0.01", 'covariance = "nseries_pb_cov.dat"', f"n_bar = {N_BAR}"]
    path = out / name
    path.write_text("\n".join(text) + "\n")
    return path


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--tensors", type=Path, required=True)
    ap.add_argument("--data", type=Path, default=DEFAULT_DATA)
    ap.add_argument("--cov", type=Path, default=DEFAULT_COV)
    ap.add_argument("--bin", type=Path, default=DEFAULT_BIN)
    ap.add_argument("--out", type=Path, default=DEFAULT_OUT)
    a = ap.parse_args()
    for p in (a.data, a.cov):
        if not p.exists():
            sys.exit(f"{p} not found: see examples/nseries_pb_fit.py for where the data come from")
    a.out.mkdir(parents=True, exist_ok=True)
    t0 = time.time()
    write_inputs(a.out, a.data, a.cov)
    qpar, qperp = ap_truth()
    f_true = pt.growth(Z, TRUE)[1]
    rows = []
    for k_max_b in K_MAX_B:
        for one_loop in (False, True):
            name = f"nseries_pb_{'loop' if one_loop else 'tree'}_{k_max_b}.toml"
            path = analysis(a.out, name, qpar, qperp, k_max_b, a.tensors.resolve(), one_loop)
            t = time.time()
            r = table(run(a.bin, ["fit", "--analysis", path, "--cosmology", a.out / "nseries_true.ini",
                                  "--precision", "fast"]))
            rows.append((k_max_b, "one loop" if one_loop else "tree level", r, time.time() - t))
            log(f"k_max,B = {k_max_b} {rows[-1][1]}: f = {r['f']:.4f} +- {r['err_f']:.4f} "
                f"chi2 {r['chi2']:.1f} ({rows[-1][3]:.0f} s)")
    write_report(a.out, rows, f_true, qpar, qperp, time.time() - t0)


def write_report(out, rows, f_true, qpar, qperp, seconds):
    lines = [
        "# Nseries P + B0 with the one-loop bispectrum, beside the tree level",
        "",
        f"Made by `examples/nseries_pb_one_loop.py` in {seconds:.0f} s on 2 cores: the likelihood of "
        "`examples/nseries_pb_analysis.py` (mean of the 84 Nseries mocks, the Patchy P + B covariance of one "
        "NGC volume with its Hartlap factor, the true cosmology as template, AP fixed at the truth "
        f"(apar = {qpar:.4f}, aperp = {qperp:.4f}), P0, P2 at {K_MIN_P} ≤ k ≤ {K_MAX_P}, B0 bin-averaged) with "
        "B0 from the tree-level block or the one-loop block (tensors on the rule "
        f"{' x '.join(map(str, RULE))}, IR resummed, AP isotropic exact, anisotropic on the tree; b_gamma3, ct_k2, ct_k2_mu2, "
        "st_p, st_1 marginalised with Gaussian priors, st_p_mu2 at Poisson). Truth: "
        f"f = {f_true:.4f} (the mocks' cosmology at z = {Z}).",
        "",
        "| k_max,B | B0 model | f | (f − f_true)/σ | b1 | b2 | bs | χ² | points | time |",
        "|---|---|---|---|---|---|---|---|---|---|",
    ]
    for k_max_b, model, r, t in rows:
        lines.append(f"| {k_max_b} | {model} | {r['f']:.4f} ± {r['err_f']:.4f} | {(r['f'] - f_true) / r['err_f']:+.2f} "
                     f"| {r['b1']:.3f} ± {r['err_b1']:.3f} | {r['b2']:.2f} ± {r['err_b2']:.2f} | "
                     f"{r['bs']:.2f} ± {r['err_bs']:.2f} | {r['chi2']:.1f} | {int(r['points'])} | {t:.0f} s |")
    lines += ["", "χ² is the data's alone (the priors' terms not included); the errors are the Hessian's of "
              "−2 ln L."]
    (out / "nseries_pb_one_loop.md").write_text("\n".join(lines) + "\n")
    print("\n".join(lines))


if __name__ == "__main__":
    main()
