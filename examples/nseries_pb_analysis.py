"""P alone and P + B of the Nseries mocks through the library's fit (issue 49, item 5): the likelihood of
examples/nseries_pb_fit.py (the same data, covariance, template, AP, priors and k ranges), written as
analysis files with a `[dataset.bispectrum]` table and fitted by `pt-spectra fit --analysis`: the
library's minimiser, its B terms at every f (no interpolation), the linear parameters profiled (as
the Python minimiser does) and their Gaussian priors in -2 ln L. The two implementations must agree.

Writes examples/out/nseries_pb_analysis.md (the table beside nseries_pb_fit.py's) and the inputs it
makes (nseries_pb_*.dat, nseries_true.ini, the analysis files).

    python3 examples/nseries_pb_analysis.py [--data DIR] [--cov FILE] [--bin PATH] [--out DIR]

--data, --cov: as examples/nseries_pb_fit.py (../shared/data/... next to the repository exist on the
project's machines only). Needs the Python module (for the AP distortion of the truth), numpy. About
1 minute on 2 cores.
"""

import argparse
import re
import subprocess
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from nseries_pb_fit import (DEFAULT_COV, DEFAULT_DATA, K_MAX_B, K_MAX_P, K_MIN_P, N_BAR,  # noqa: E402
                            N_PATCHY, PRIOR, TRUE, Z, ap_truth, read_data)

ROOT = Path(__file__).resolve().parent.parent
DEFAULT_BIN = ROOT / "target" / "release" / "pt-spectra"
DEFAULT_OUT = ROOT / "examples" / "out"
STARTS = 8


def log(msg):
    print(msg, file=sys.stderr, flush=True)


def analysis(out, name, qpar, qperp, k_max_b):
    """The analysis file: P0, P2 and, with `k_max_b`, B0 of the bins whose sides are all below it."""
    quote = lambda items: ", ".join(f'"{i}"' for i in items)  # noqa: E731
    marg = ["alpha0", "alpha2", "sn"] + (["b_shot", "a_shot"] if k_max_b else [])
    free = ["f", "b1", "b2", "bs"] + (["c1"] if k_max_b else [])
    priors = [f"{n}:{m},{s}" for n, (m, s) in PRIOR.items() if n in free + marg]
    text = [
        f"# Nseries mean, written by examples/nseries_pb_analysis.py ({name})",
        "[search]", f"starts = {STARTS}", "seed = 1", "profile_check = false", 'linear = "profiled"', "",
        "[[dataset]]", 'label = "nseries"', 'data = "nseries_pb_p.dat"', "data_ells = [0, 2, 4]",
        f"n_mocks = {N_PATCHY}", f"z = {Z}", "ells = [0, 2]", f"k_min = {K_MIN_P}", f"k_max = {K_MAX_P}",
        f"free = [{quote(free)}]", f"marginalise = [{quote(marg)}]", f"priors = [{quote(priors)}]",
        f"apar = {qpar!r}", f"aperp = {qperp!r}",
        "[dataset.start]", "b1 = 2.0", "f = 0.75",
    ]
    if k_max_b:
        text += ["[dataset.bispectrum]", 'data = "nseries_pb_b.dat"', "ells = [0]", f"k_max = {k_max_b + 1e-9}",
                 "bin_width = 0.01", 'covariance = "nseries_pb_cov.dat"', f"n_bar = {N_BAR}"]
    else:  # the power spectrum alone: the joint covariance's P block
        text.insert(text.index(f"n_mocks = {N_PATCHY}"), 'covariance = "nseries_pb_pcov.dat"')
    path = out / name
    path.write_text("\n".join(text) + "\n")
    return path


def run(binary, args):
    p = subprocess.run([str(binary)] + [str(a) for a in args], capture_output=True, text=True)
    if p.returncode != 0:
        sys.exit(f"failed: {args}\n{p.stderr}")
    return p.stdout


def table(text):
    lines = text.splitlines()
    names = [l for l in lines if l.startswith("# set ")][-1][1:].split()
    rows = [dict(zip(names, map(float, l.split()))) for l in lines if l.strip() and l[0] != "#"]
    return rows[0]


def python_results(out):
    """The table of nseries_pb_fit.py's report, if it was run: {label: (f, err_f)}."""
    path = out / "nseries_pb_fit.md"
    if not path.exists():
        path = ROOT / "docs" / "results" / "nseries_pb_fit.md"
    found = {}
    for line in path.read_text().splitlines():
        m = re.match(r"\| (P[^|]*) \| ([0-9.]+) ± ([0-9.]+) \|", line)
        if m:
            found[m.group(1).strip()] = (float(m.group(2)), float(m.group(3)))
    return found, path


def write_inputs(out, data, cov_file):
    """The analysis files' inputs in `out`: the mean P and B of the mocks, the joint covariance and its P
    block, the true cosmology."""
    pk, bk = read_data(data)
    # the sides as the files give them (the mean of 84 equal numbers can differ in the last bit, and the
    # one-loop block's tensors are keyed by the sides' exact values)
    bk[:, :3] = np.round(bk[:, :3], 10)
    cov = np.loadtxt(cov_file)
    n_k = len(pk)
    sigma = np.sqrt(np.diag(cov)[: 3 * n_k]).reshape(3, n_k)
    np.savetxt(out / "nseries_pb_p.dat",
               np.column_stack([pk[:, 0]] + [c for l in range(3) for c in (pk[:, 1 + l], sigma[l])]),
               header="mean of the 84 Nseries mocks: k P0 s0 P2 s2 P4 s4 (s from the Patchy covariance)")
    np.savetxt(out / "nseries_pb_b.dat", bk[:, :6], header="mean of the 84 Nseries mocks: k1 k2 k3 B0 B2 B4")
    np.savetxt(out / "nseries_pb_cov.dat", cov, header="Patchy NGC z3 P + B covariance (P0 P2 P4, B0 B2 B4)")
    np.savetxt(out / "nseries_pb_pcov.dat", cov[: 3 * n_k, : 3 * n_k], header="its P0 P2 P4 block")
    (out / "nseries_true.ini").write_text(
        "# the true cosmology of the Nseries mocks\n" + "".join(f"{k} = {v}\n" for k, v in TRUE.items()))


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
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
    results = {}
    for label, k_max_b in [("P", None)] + [(f"P+B0 (k_max,B = {k})", k) for k in K_MAX_B]:
        path = analysis(a.out, f"nseries_pb_{len(results)}.toml", qpar, qperp, k_max_b)
        t = time.time()
        text = run(a.bin, ["fit", "--analysis", path, "--cosmology", a.out / "nseries_true.ini",
                           "--precision", "fast"])
        results[label] = (table(text), time.time() - t)
        r = results[label][0]
        log(f"{label}: f = {r['f']:.4f} +- {r['err_f']:.4f} ({results[label][1]:.0f} s)")
    write_report(a.out, results, time.time() - t0)


def write_report(out, results, seconds):
    python, source = python_results(out)
    lines = [
        "# Nseries P alone and P + B0 through `fit --analysis`, against the Python minimiser",
        "",
        f"Made by `examples/nseries_pb_analysis.py` in {seconds:.0f} s on 2 cores: the likelihood of "
        "`examples/nseries_pb_fit.py` (mean of the 84 Nseries mocks, the Patchy P + B covariance of one NGC "
        "volume with its Hartlap factor, the true cosmology as template (emulated), AP fixed at the truth, "
        f"P0, P2 at {K_MIN_P} ≤ k ≤ {K_MAX_P}, B0 bin-averaged (width 0.01), n̄ = {N_BAR}, the same Gaussian "
        "priors) as analysis files with a `[dataset.bispectrum]` table, fitted by the library (linear "
        "parameters profiled with their priors, as the Python minimiser does; the B terms at every f, not "
        f"interpolated). Python: `{source.relative_to(ROOT) if source.is_relative_to(ROOT) else source}`.",
        "",
        "| data | f (library) | f (Python) | difference / σ | b1 | b2 | χ² | points | time |",
        "|---|---|---|---|---|---|---|---|---|",
    ]
    for label, (r, t) in results.items():
        py = python.get(label)
        py_text = f"{py[0]:.4f} ± {py[1]:.4f}" if py else "n/a"
        diff = f"{(r['f'] - py[0]) / r['err_f']:+.3f}" if py else ""
        lines.append(f"| {label} | {r['f']:.4f} ± {r['err_f']:.4f} | {py_text} | {diff} | "
                     f"{r['b1']:.3f} ± {r['err_b1']:.3f} | {r['b2']:.2f} ± {r['err_b2']:.2f} | "
                     f"{r['chi2']:.1f} | {int(r['points'])} | {t:.0f} s |")
    lines += [
        "",
        "χ² is the data's alone (the priors' terms not included). The errors are the Hessian's of −2 ln L "
        "(the library) and the Fisher matrix's (Python); the two "
        "minimisers are independent (bounded quasi-Newton with analytic profiling of the linear parameters; "
        "scipy least squares over every parameter).",
        "",
        "Reproduce: `cargo build --release -p pt-spectra --features cli && python3 "
        "examples/nseries_pb_analysis.py`.",
    ]
    (out / "nseries_pb_analysis.md").write_text("\n".join(lines) + "\n")
    print("\n".join(lines))


if __name__ == "__main__":
    main()
