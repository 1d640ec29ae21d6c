"""f sigma8 from both caps of a real survey in one likelihood (issue 48): BOSS DR12 CMASS NGC and SGC
(z_eff = 0.57; Gil-Marin et al. 2016), each with its MD-Patchy covariance and its own survey window
(Beutler), as PyBird shipped them (MIT; examples/data/boss_dr12_cmass_{ngc,sgc}/README.md), fitted
with `pt-spectra fit --analysis`: f, alpha_par, alpha_perp shared by the caps, the biases free per cap,
the counterterms and shot noise marginalised analytically per cap. Each cap alone with the same
settings beside it, and the published NGC + SGC f sigma8.

Writes examples/out/boss_cmass_ngc_sgc.md (settings, table, comparison) and the inputs it makes
(boss_cmass_{ngc,sgc}_*.dat, the three analysis files, boss_fiducial.ini, the template).

    python3 examples/boss_cmass_ngc_sgc.py [--bin PATH] [--out DIR] [--jobs J]

--bin is the pt-spectra binary (default target/release/pt-spectra; `cargo build --release -p
pt-spectra`). Needs numpy and camb (`pip install camb`: the template, as in boss_cmass_fit.py).
About 20 s on 2 cores (measured). The report goes to standard output and the .md file, progress to
standard error.
"""

import argparse
import concurrent.futures as cf
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from boss_cmass_fit import (DATA, DEFAULT_BIN, DEFAULT_OUT, FREE, K_MIN, MARG, N_MOCKS,  # noqa: E402
                            PRIORS, PUBLISHED, Z, data_files, fmt, log, parse_table, run, template)

K_MAX = 0.2
STARTS = 8
# The data files hold every bin. The SGC covariance's first bins (k < 0.005, a few modes each, 0.99
# correlated through the smaller cap's window) make its ell = 0, 2 block nearly singular as a whole
# (correlation condition number 2.0e7); `fit` checks the degeneracy of the points it fits (K_MIN = 0.01
# to K_MAX: 8.4e2), so the file is used as it is.


def dataset(cap, data, cov, ini):
    """One [[dataset]] table of the analysis file: the cap's data, covariance and window."""
    window = DATA.parent / f"boss_dr12_cmass_{cap.lower()}" / f"window_BOSS_CMASS_{cap}_z057.dat"
    quote = lambda items: ", ".join(f'"{i}"' for i in items)  # noqa: E731
    return "\n".join([
        "[[dataset]]",
        f'label = "{cap.lower()}"',
        f'data = "{data}"',
        "data_ells = [0, 2, 4]",
        f'covariance = "{cov}"',
        f"n_mocks = {N_MOCKS}",
        f"z = {Z}",
        'tracer = "CMASS"',
        "ells = [0, 2]",
        f"k_min = {K_MIN}",
        f"k_max = {K_MAX}",
        f"free = [{quote(FREE.split(','))}]",
        f"marginalise = [{quote(MARG.split(','))}]",
        f"priors = [{quote(p for p in PRIORS if p.split(':')[0] in FREE.split(',') + MARG.split(','))}]",
        f'fiducial = "{ini}"',
        f'window = "{window}"',
        'window_mixing = "wilson"',
        "[dataset.start]",
        "b1 = 2.0",
        "",
    ])


def analysis(out, name, caps, files, ini):
    """Writes the analysis file `name` with the data sets of `caps`; f, apar, aperp shared (the default
    for sets of one z and tracer)."""
    text = [f"# BOSS DR12 CMASS {' + '.join(caps)}, written by examples/boss_cmass_ngc_sgc.py",
            "", "[search]", f"starts = {STARTS}", "seed = 1", "profile_check = true",
            'linear = "marginalised"', ""]
    for cap in caps:
        data, covs = files[cap]
        text.append(dataset(cap, data, covs[2], ini))
    path = out / name
    path.write_text("\n".join(text))
    return path


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--bin", default=DEFAULT_BIN, type=Path)
    ap.add_argument("--out", default=DEFAULT_OUT, type=Path)
    ap.add_argument("--jobs", default=2, type=int)
    args = ap.parse_args()
    args.out.mkdir(parents=True, exist_ok=True)
    t0 = time.time()
    plin, ini, truth = template(args.out)
    files = {}
    for cap in ("NGC", "SGC"):
        data, covs, *_ = data_files(args.out, cap)
        files[cap] = (data, covs)
    fits = {
        "NGC": analysis(args.out, "boss_cmass_ngc.toml", ["NGC"], files, ini),
        "SGC": analysis(args.out, "boss_cmass_sgc.toml", ["SGC"], files, ini),
        "NGC + SGC": analysis(args.out, "boss_cmass_ngc_sgc.toml", ["NGC", "SGC"], files, ini),
    }
    common = ["--linear", plin, "--z-input", Z, "--cosmology", ini, "--precision", "fast"]
    version = run(args.bin, ["--version"]).strip()
    log(f"{len(fits)} fits with {version} ...")

    def one(path):
        t = time.time()
        text = run(args.bin, ["fit", "--analysis", path, *common])
        return text, time.time() - t

    with cf.ThreadPoolExecutor(max_workers=args.jobs) as pool:
        outputs = dict(zip(fits, pool.map(one, fits.values())))
    (args.out / "boss_cmass_ngc_sgc.dat").write_text(
        "".join(f"# ==== {name}\n{text}" for name, (text, _) in outputs.items()))
    rows = {name: parse_table(text)[0] for name, (text, _) in outputs.items()}
    write_report(args, rows, outputs, truth, version, time.time() - t0)


def write_report(args, rows, outputs, truth, version, seconds):
    s8 = truth["sigma8_z"]
    lines = [
        "# BOSS DR12 CMASS NGC + SGC: f σ8 from both caps in one likelihood (`fit --analysis`)",
        "",
        f"Written by `examples/boss_cmass_ngc_sgc.py` (issue 48; {seconds:.0f} s on 2 cores, {version}). "
        "The power-spectrum multipoles of BOSS DR12 CMASS, z_eff = 0.57, in the North and the South "
        "Galactic Cap (Gil-Marín et al. 2016), each with its MD-Patchy covariance and its own survey "
        "window Q0, Q2, Q4 (Beutler), as PyBird shipped them (MIT; `examples/data/boss_dr12_cmass_ngc/`, "
        "`examples/data/boss_dr12_cmass_sgc/`), fitted with the galaxy model `ept` convolved with each "
        "cap's window.",
        "",
        "## Settings",
        "",
        "- Template, fiducial, priors, window treatment and precision: those of "
        "[the NGC fit](boss_cmass_fit.md) (BOSS DR12 fiducial cosmology; CAMB "
        f"{truth['camb']}; σ8(z = {Z}) = {s8:.5f}; fσ8 = f × σ8(z)).",
        f"- Each cap: P0, P2, {K_MIN} ≤ k ≤ {K_MAX} h/Mpc, its full covariance with the Hartlap factor "
        f"for {N_MOCKS} mocks, its window (Wilson et al. mixing). The files hold every bin: the SGC "
        "covariance's first bins (k < 0.005 h/Mpc) are 0.99 correlated (the smaller cap's window), its "
        "ℓ = 0, 2 correlation matrix's condition number 2.0e7 as a whole; `fit` checks the points it "
        f"fits ({K_MIN} ≤ k ≤ {K_MAX}: 8.4e2).",
        f"- Free: {FREE}; marginalised analytically per cap: {MARG}.",
        "- Joint: one likelihood, the sum of the caps' (independent: no cross-covariance). f, α∥, α⊥ "
        "are shared (the default for data sets of one z and tracer); b1, b2, bs are free per cap "
        "(`b1[ngc]`, `b1[sgc]`), and each cap has its own marginalised counterterms and shot noise, "
        "as PyBird's BOSS likelihood has its own b1, c2 per cap.",
        f"- Search: {STARTS} starts (the start, then seeded draws), the Hessian errors checked on the "
        "profile likelihood (`err_f_from_profile`).",
        "",
        "## Results",
        "",
        "| fit | fσ8 ± σ | f ± σ | f: Hessian σ, profile interval | α∥ ± σ | α⊥ ± σ | b1 ± σ | χ² / points | starts agreeing | time |",
        "|---|---|---|---|---|---|---|---|---|---|",
    ]
    for name, rs in rows.items():
        t = outputs[name][1]
        for r in rs:
            cap = ["NGC", "SGC"][int(r["set"]) - 1] if name == "NGC + SGC" else name
            label = f"{name} ({cap} row)" if name == "NGC + SGC" else name
            lines.append(
                f"| {label} | {fmt(r['fsigma8'], r['err_fsigma8'])} | {fmt(r['f'], r['err_f'])} | "
                f"{r['err_f_hessian']:.3f}, [{r['f_lo']:.3f}, {r['f_hi']:.3f}] | "
                f"{fmt(r['apar'], r['err_apar'])} | {fmt(r['aperp'], r['err_aperp'])} | "
                f"{fmt(r['b1'], r['err_b1'], 2)} | {r['chi2']:.1f} / {int(r['points'])} | "
                f"{int(r['starts_agree'])}/{int(r['starts'])} | {t:.0f} s |")
    joint = rows["NGC + SGC"][0]
    err = {name: rs[0]["err_fsigma8"] for name, rs in rows.items()}
    combined = 1 / np.sqrt(1 / err["NGC"] ** 2 + 1 / err["SGC"] ** 2)
    lines += [
        "",
        f"The joint σ(fσ8) = {err['NGC + SGC']:.4f} is smaller than either cap's ({err['NGC']:.4f} NGC, "
        f"{err['SGC']:.4f} SGC); the inverse-variance combination of the two would be {combined:.4f}, "
        "which ignores that f is correlated with α∥, α⊥ differently in each cap. In the joint rows the "
        "shared parameters have one value and error; b1 is each cap's. Every reported minimum is the "
        "lowest of the 8 starts (`starts agreeing`: those within Δχ² = 0.01 of it; the others stopped "
        "higher, in the b2–bs–α degeneracies of the smaller cap).",
        "",
        "## Against the published f σ8 (NGC + SGC)",
        "",
        "| measurement | fσ8(z = 0.57) | this fit − published |",
        "|---|---|---|",
        f"| this fit: NGC + SGC, ℓ = 0, 2, k_max = {K_MAX} | {fmt(joint['fsigma8'], joint['err_fsigma8'])} | |",
    ]
    fs8, e0 = joint["fsigma8"], joint["err_fsigma8"]
    for label, v, e in PUBLISHED:
        lines.append(f"| {label} | {v:.3f} ± {e:.3f} | {fs8 - v:+.3f} ({(fs8 - v) / np.hypot(e0, e):+.1f}σ "
                     "of the two errors in quadrature) |")
    lines += [
        "",
        "The published analyses use other models, k ranges and (the second) the bispectrum and BAO: the "
        "differences are to be read against errors that are largely shared (the same data), so "
        "these σ overstate how far apart they may be.",
        "",
        "Reproduce: `cargo build --release -p pt-spectra && python3 examples/boss_cmass_ngc_sgc.py`; the "
        "raw tables of the three fits are in `boss_cmass_ngc_sgc.dat`, the analysis files beside them.",
    ]
    (args.out / "boss_cmass_ngc_sgc.md").write_text("\n".join(lines) + "\n")
    print("\n".join(lines))  # the report on stdout; progress on stderr


if __name__ == "__main__":
    main()
