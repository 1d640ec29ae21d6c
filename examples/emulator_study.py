"""Every real-space model against N-body: the ratio of each model's P_δδ to EuclidEmulator2 (EE2) for the
paper's cosmology gm2012 at z = 0, 0.5, 1, 1.5, and the k where each ratio first leaves ±1% (issue 17,
part 5). Writes a Markdown table and a figure (one panel per z); the README's section "The models
against N-body (EuclidEmulator2)" is its output.

    python examples/emulator_study.py [BINARY] [--ee2-table FILE] [--out DIR]

BINARY is the pt-spectra command line (default target/release/pt-spectra; build it with
`cargo build --release -p pt-spectra`). Needs numpy, and matplotlib for the figure. Runs
`BINARY real --model all` once per z (the 2-loop models take from seconds to a few minutes per z; the
first run on a machine also builds the P15 and P17 angular tables) and takes every model from the
header of that table, so models added to `--model all` appear in the study without a change here.

EE2 is not a dependency: its boost B(k, z) = P_nl/P_lin is read from a table (default
examples/data/ee2_boost_gm2012.dat, committed, its header says how it was made). With `euclidemu2` and
`camb` importable, `--make-ee2-table` (re)makes that table: A_s for σ8 = 0.8 from CAMB, then EE2's boost
(its own spline between its k nodes) on 400 log-spaced k in [0.009, 1] h/Mpc. The N-body spectrum is P_EE2 = B × P_lin with P_lin the embedded CAMB spectrum the
models themselves use (the `linear` column of `--model all`), so that model/P_EE2 = model/(B P_lin)
compares the nonlinear physics only, not two linear spectra.
"""

import argparse
import math
import subprocess
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
DEFAULT_EE2 = ROOT / "examples" / "data" / "ee2_boost_gm2012.dat"

# gm2012 (Gil-Marín et al. 2012; the embedded spectra): flat, massless neutrinos, sigma8 = 0.8.
GM2012 = dict(h=0.7, ombh2=0.023, omega_m=0.27, n_s=0.95, sigma8=0.8)
# EE2's parameter box (euclidemu2's PyEuclidEmulator.bounds).
EE2_BOX = {"Omega_b": (0.04, 0.06), "Omega_m": (0.24, 0.40), "Sum_m_nu": (0.0, 0.15), "n_s": (0.92, 1.00),
           "h": (0.61, 0.73), "w_0": (-1.3, -0.7), "w_a": (-0.7, 0.5), "A_s": (1.7e-9, 2.5e-9)}
# The paper's claim (its conclusions): 2L-RPT-N2 within 1% of its N-body spectra up to these k.
PAPER_CLAIM = {0.0: 0.10, 0.5: 0.15, 1.0: 0.20, 1.5: 0.25}


def log(msg):
    print(msg, file=sys.stderr, flush=True)


# ----------------------------------------------------------------------------------------------------
# EE2 boost table


def derive_as(sigma8):
    """A_s giving sigma8 with CAMB for gm2012, massless neutrinos (N_eff = 3.046), as the embedded spectra."""
    import camb

    h = GM2012["h"]
    omch2 = GM2012["omega_m"] * h * h - GM2012["ombh2"]

    def s8(a_s):
        p = camb.CAMBparams()
        p.set_cosmology(H0=100 * h, ombh2=GM2012["ombh2"], omch2=omch2, mnu=0.0, omk=0,
                        num_massive_neutrinos=0, nnu=3.046)
        p.InitPower.set_params(As=a_s, ns=GM2012["n_s"])
        p.set_matter_power(redshifts=[0.0], kmax=60.0)
        p.NonLinear = camb.model.NonLinear_none
        return camb.get_results(p).get_sigma8_0()

    a_s = 2e-9 * (sigma8 / s8(2e-9)) ** 2  # the linear spectrum is proportional to A_s
    return a_s, s8(a_s), camb.__version__


def make_ee2_table(path, zs):
    import euclidemu2

    a_s, s8, camb_version = derive_as(GM2012["sigma8"])
    h = GM2012["h"]
    pars = {"Omega_b": GM2012["ombh2"] / h**2, "Omega_m": GM2012["omega_m"], "Sum_m_nu": 0.0,
            "n_s": GM2012["n_s"], "h": h, "w_0": -1.0, "w_a": 0.0, "A_s": a_s}
    outside = [f"{n} = {v:g} outside [{EE2_BOX[n][0]:g}, {EE2_BOX[n][1]:g}]"
               for n, v in pars.items() if not EE2_BOX[n][0] <= v <= EE2_BOX[n][1]]
    if outside:
        sys.exit("gm2012 is outside EE2's parameter box: " + "; ".join(outside))
    emu = euclidemu2.PyEuclidEmulator()
    # euclidemu2's dictionary spells the neutrino mass m_nu and w_0, w_a as w0_fld, wa_fld.
    ee2_dict = {"Omega_b": pars["Omega_b"], "Omega_m": pars["Omega_m"], "m_nu": pars["Sum_m_nu"],
                "n_s": pars["n_s"], "h": h, "w0_fld": -1.0, "wa_fld": 0.0, "A_s": a_s}
    # EE2's nodes are 6.3e-3 h/Mpc apart at k < 0.3 (the fundamental mode of its 1 Gpc/h boxes), too coarse
    # for linear interpolation across its BAO features: tabulate its own cubic spline (in log k of log B)
    k_dense = np.geomspace(0.009, 1.0, 400)
    k, boost = emu.get_boost(ee2_dict, list(zs), k_dense)
    k = np.asarray(k)
    keep = k <= 1.0
    try:
        from importlib.metadata import version
        ee2_version = version("euclidemu2")
    except Exception:
        ee2_version = "?"
    path.parent.mkdir(parents=True, exist_ok=True)
    with open(path, "w") as f:
        f.write("# EuclidEmulator2 boost B(k, z) = P_nl/P_lin (Knabenhans et al. 2021, arXiv:2010.11288) for gm2012,\n")
        f.write(f"# made by examples/emulator_study.py --make-ee2-table with euclidemu2 {ee2_version} (emulator v1.0.1)\n")
        f.write("# EE2 parameters: " + " ".join(f"{n}={v:.7g}" for n, v in pars.items()) + "\n")
        f.write(f"# (Omega_b = 0.023/0.7^2; Sum_m_nu = 0, the lower end of EE2's box: massless neutrinos, N_eff = 3.046 in EE2)\n")
        f.write(f"# A_s from CAMB {camb_version} for sigma8 = 0.8 (massless neutrinos, kmax 60): sigma8 = {s8:.6f};\n")
        f.write("# the embedded linear tables used As = 2.252275e-09. Every parameter is inside EE2's box.\n")
        f.write("# k: 400 log-spaced points in [0.009, 1] h/Mpc (EE2 covers 8.73e-3..9.41) from euclidemu2's get_boost(custom_kvec),\n")
        f.write("# i.e. EE2's cubic spline of log B in log k between its nodes (6.3e-3 h/Mpc apart below k = 0.3); interpolate linearly in ln k.\n")
        f.write("# columns: k [h/Mpc] " + " ".join(f"B_z{z:g}" for z in zs) + "\n")
        for i in np.flatnonzero(keep):
            f.write(f"{k[i]:.8e} " + " ".join(f"{boost[j][i]:.8e}" for j in range(len(zs))) + "\n")
    log(f"wrote {path}: A_s = {a_s:.7g} (sigma8 = {s8:.6f}), {keep.sum()} k values")


def read_ee2_table(path):
    names = None
    with open(path) as f:
        for line in f:
            if line.startswith("# columns:"):
                names = line.split(":", 1)[1].replace("[h/Mpc]", "").split()
    if names is None:
        sys.exit(f"{path}: no '# columns:' line")
    data = np.loadtxt(path, ndmin=2)
    boosts = {float(n[3:]): data[:, i] for i, n in enumerate(names) if n.startswith("B_z")}
    return data[:, 0], boosts


def ee2_boost(k_table, boosts, z, k):
    if z not in boosts:
        sys.exit(f"the EE2 table has no z = {z:g} (it has {sorted(boosts)}); remake it with --make-ee2-table")
    if k.min() < k_table[0] or k.max() > k_table[-1]:
        sys.exit(f"k outside the EE2 table's range [{k_table[0]:g}, {k_table[-1]:g}]")
    return np.interp(np.log(k), np.log(k_table), boosts[z])


# ----------------------------------------------------------------------------------------------------
# pt-spectra


def read_models(path):
    """The columns of a `real --model all` table by name (its header line '# k …'), and the names of the
    model columns: those of unit [1] (P_dd(model)/P_nw) other than the err_ columns."""
    names, units = None, {}
    with open(path) as f:
        for line in f:
            if not line.startswith("#"):
                break
            words = line[1:].split()
            if words and words[0] == "k":
                names = words
            elif len(words) >= 4 and words[0] == "column" and words[1].endswith(":"):
                units[words[2]] = " ".join(words[3:])
    if names is None:
        sys.exit(f"{path}: no header line naming the columns")
    data = np.loadtxt(path, ndmin=2)
    cols = {n: data[:, i] for i, n in enumerate(names)}
    models = [n for n in names if n not in ("k", "P_nw") and not n.startswith("err_")
              and units.get(n, "[1]") == "[1]"]
    return cols, models


def run_models(binary, z, grid, out_path, extra):
    cmd = [str(binary), "real", "--model", "all", "--z", f"{z:g}", "--k-min", f"{grid[0]:g}",
           "--k-max", f"{grid[1]:g}", "--nk", str(grid[2]), "--out", str(out_path)] + extra
    log("  $ " + " ".join(cmd))
    subprocess.run(cmd, check=True)  # its progress bars go to our standard error


# ----------------------------------------------------------------------------------------------------
# analysis


def first_exit(k, ratio, tol):
    """(k, side, at_start): the first k (interpolated linearly in ln k) at which |ratio - 1| > tol, side
    +1 above and -1 below; (None, 0, False) if never on the grid; (k[0], side, True) if out at k[0]."""
    dev = np.abs(ratio - 1.0) - tol
    out = np.flatnonzero(dev > 0)
    if out.size == 0:
        return None, 0, False
    i = out[0]
    side = 1 if ratio[i] > 1 else -1
    if i == 0:
        return k[0], side, True
    t = dev[i - 1] / (dev[i - 1] - dev[i])
    return math.exp(math.log(k[i - 1]) + t * math.log(k[i] / k[i - 1])), side, False


def at_k(k, y, k0):
    return float(np.interp(math.log(k0), np.log(k), y))


def fmt_exit(res, k_max, flag=""):
    kx, side, below = res
    if kx is None:
        return f"> {k_max:g}"
    arrow = "↑" if side > 0 else "↓"
    return (f"< {kx:.3f} {arrow}" if below else f"{kx:.3f} {arrow}") + flag


def reach_table(results, zs, models, tol, args, title):
    lines = [title, "", "| model | " + " | ".join(f"z = {z:g}" for z in zs) + " |", "|---|" + "---|" * len(zs)]
    flagged = False
    for m in models:
        cells = []
        for z in zs:
            k, ratio, err, _ = results[z]
            if m not in ratio:
                cells.append("—")
                continue
            res = first_exit(k, ratio[m], tol / 100)
            upto = k <= (res[0] if res[0] is not None else k[-1])
            # the model's own numerical error, if it could move the crossing: > a tenth of the tolerance
            flag = "*" if np.max(err[m][upto] / ratio[m][upto]) > tol / 1000 else ""
            flagged |= bool(flag)
            cells.append(fmt_exit(res, args.k_max, flag))
        lines.append(f"| {m} | " + " | ".join(cells) + " |")
    if flagged:
        lines += ["", f"\\* the model's own numerical error exceeds {tol / 10:g}% of P below that k."]
    return lines + [""]


def study(args):
    zs = [float(z) for z in args.z.split(",")]
    grid = (args.k_min, args.k_max, args.nk)
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    ee2_path = Path(args.ee2_table)
    if args.make_ee2_table or not ee2_path.exists():
        try:
            make_ee2_table(ee2_path, sorted(set(zs) | {0.0, 0.5, 1.0, 1.5}))
        except ImportError as e:
            sys.exit(f"{ee2_path} is missing and cannot be made ({e}); `pip install euclidemu2 camb`")
    k_ee2, boosts = read_ee2_table(ee2_path)
    binary = Path(args.binary)
    if not binary.exists():
        sys.exit(f"{binary} not found; build it with `cargo build --release -p pt-spectra` or give its path")

    t0 = time.time()
    results = {}  # z -> (k, {model: ratio}, {model: err}, B)
    for n, z in enumerate(zs, 1):
        table = out / f"models_z{z:g}.dat"
        log(f"[{n}/{len(zs)}] z = {z:g}")
        t = time.time()
        if args.reuse and table.exists():
            log(f"  reusing {table}")
        else:
            run_models(binary, z, grid, table, args.pt_arg)
            log(f"  z = {z:g} done in {time.time() - t:.0f} s")
        cols, models = read_models(table)
        if "linear" not in cols or "P_nw" not in cols:
            sys.exit(f"{table}: needs the columns P_nw and linear (the models' P_lin/P_nw)")
        k = cols["k"]
        boost = ee2_boost(k_ee2, boosts, z, k)
        # model/P_EE2 = (P_model/P_nw) / (B P_lin/P_nw): the same embedded P_lin as the models.
        ratio = {m: cols[m] / (boost * cols["linear"]) for m in models}
        err = {m: cols.get("err_" + m, np.zeros_like(k)) / (boost * cols["linear"]) for m in models}
        results[z] = (k, ratio, err, boost)
        with open(out / f"ratio_ee2_z{z:g}.dat", "w") as f:
            f.write(f"# P_dd(model)/P_EE2 at z = {z:g}, P_EE2 = B_EE2 x P_lin (embedded gm2012 CAMB); from {table.name}, {ee2_path.name}\n")
            f.write("# k B_EE2 " + " ".join(models) + "\n")
            np.savetxt(f, np.column_stack([k, boost] + [ratio[m] for m in models]), fmt="%.7e")
    elapsed = time.time() - t0
    models = list(results[zs[0]][1])  # the order of --model all
    for z in zs[1:]:
        models += [m for m in results[z][1] if m not in models]

    lines = []
    for tol in args.tolerance:
        lines += reach_table(results, zs, models, tol, args,
                             f"k [h/Mpc] where P_dd(model)/P_EE2 first leaves ±{tol:g}% (from k = {args.k_min:g}; "
                             f"↑ above, ↓ below; {args.nk} log-spaced k up to {args.k_max:g}, interpolated in ln k):")
    # EE2's boost sits below 1 at its lowest k (0.991 at z = 0), where the nonlinear correction is < 0.1%:
    # the same first table with B divided by its value at the table's first k, to show what that offset does.
    b0 = {z: ee2_boost(k_ee2, boosts, z, np.array([k_ee2[0]]))[0] for z in zs}
    shifted = {z: (k, {m: r * b0[z] for m, r in ratio.items()}, {m: e * b0[z] for m, e in err.items()}, b)
               for z, (k, ratio, err, b) in results.items()}
    lines += reach_table(shifted, zs, models, args.tolerance[0], args,
                         f"The same at ±{args.tolerance[0]:g}% with EE2's large-scale offset removed, B → B/B(k = {k_ee2[0]:.3g}) "
                         "(B(" + f"{k_ee2[0]:.3g}" + ") = " + ", ".join(f"{b0[z]:.4f}" for z in zs) + " at z = "
                         + ", ".join(f"{z:g}" for z in zs) + "):")
    claim = [z for z in zs if z in PAPER_CLAIM]
    if claim:
        lines.append("P_dd(model)/P_EE2 at the k to which the paper claims 2L-RPT-N2 is within 1% of its simulations:")
        lines.append("")
        lines.append("| model | " + " | ".join(f"z = {z:g}, k = {PAPER_CLAIM[z]:.2f}" for z in claim) + " |")
        lines.append("|---|" + "---|" * len(claim))
        for m in models:
            cells = [f"{at_k(results[z][0], results[z][1][m], PAPER_CLAIM[z]):.4f}" if m in results[z][1] else "—"
                     for z in claim]
            lines.append(f"| {m} | " + " | ".join(cells) + " |")
        lines.append("")
    text = "\n".join(lines)
    (out / "emulator_study.md").write_text(text)
    print(text)
    log(f"wrote {out / 'emulator_study.md'}; pt-spectra took {elapsed:.0f} s for {len(zs)} redshifts")
    plot(results, zs, models, args, out / "emulator_study.png")


# ----------------------------------------------------------------------------------------------------
# figure


def style(m):
    """Line style by family (linear dotted, 1-loop solid, 2-loop dashed), colour by model kind."""
    ls = ":" if m == "linear" else ("--" if m.startswith("2l") else "-")
    kind = m.split("-", 1)[1] if "-" in m else m
    return ls, kind


def plot(results, zs, models, args, path):
    try:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
        import matplotlib.ticker
    except ImportError:
        log("matplotlib is not importable: no figure")
        return
    kinds = []
    for m in models:
        kind = style(m)[1]
        if kind not in kinds:
            kinds.append(kind)
    colours = {kd: plt.get_cmap("tab10")(i % 10) for i, kd in enumerate(kinds)}
    colours["linear"] = "black"
    ncol = 2 if len(zs) > 1 else 1
    nrow = (len(zs) + ncol - 1) // ncol
    fig, axes = plt.subplots(nrow, ncol, figsize=(11, 4.2 * nrow), sharex=True, sharey=True, squeeze=False)
    tol = args.tolerance[0] / 100
    for ax, z in zip(axes.flat, zs):
        k, ratio, _, _ = results[z]
        ax.axhspan(1 - tol, 1 + tol, color="0.88", zorder=0)
        ax.axhline(1, color="0.5", lw=0.6)
        for m in models:
            if m in ratio:
                ls, kind = style(m)
                ax.plot(k, ratio[m], ls=ls, color=colours[kind], lw=1.3, label=m)
        if z in PAPER_CLAIM:
            ax.axvline(PAPER_CLAIM[z], color="C1", lw=0.8, ls="-.")
        ax.set_xscale("log")
        ticks = [t for t in (0.01, 0.02, 0.03, 0.05, 0.1, 0.15, 0.2, 0.3) if args.k_min <= t <= args.k_max]
        ax.set_xticks(ticks, [f"{t:g}" for t in ticks])
        ax.xaxis.set_minor_formatter(matplotlib.ticker.NullFormatter())
        ax.set_ylim(0.94, 1.06)
        ax.set_xlim(args.k_min, args.k_max)
        ax.set_title(f"z = {z:g}", fontsize=10)
        ax.grid(alpha=0.3, which="both", lw=0.4)
    for ax in axes[-1]:
        ax.set_xlabel("k [h/Mpc]")
    for ax in axes[:, 0]:
        ax.set_ylabel("P_dd(model) / P_EE2")
    for ax in list(axes.flat)[len(zs):]:
        ax.set_visible(False)
    handles, labels = axes.flat[0].get_legend_handles_labels()
    fig.legend(handles, labels, loc="lower center", ncol=min(8, len(labels)), fontsize=8, frameon=False)
    fig.suptitle(f"gm2012: models over EuclidEmulator2 (B_EE2 × embedded P_lin); band ±{args.tolerance[0]:g}%, "
                 "dash-dot: the paper's 1% reach of 2L-RPT-N2", fontsize=10)
    fig.tight_layout(rect=(0, 0.035 * (1 + (len(labels) - 1) // 8), 1, 0.97))
    fig.savefig(path, dpi=args.dpi)
    try:  # a 128-colour palette: a third of the size, no visible change
        from PIL import Image
        Image.open(path).convert("RGB").quantize(colors=128).save(path, optimize=True)
    except ImportError:
        pass
    log(f"wrote {path}")


def main():
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0], formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("binary", nargs="?", default=str(ROOT / "target" / "release" / "pt-spectra"),
                   help="the pt-spectra command line (default target/release/pt-spectra)")
    p.add_argument("--ee2-table", default=str(DEFAULT_EE2), help="EE2 boost table (default examples/data/ee2_boost_gm2012.dat)")
    p.add_argument("--make-ee2-table", action="store_true", help="(re)make the EE2 table (needs euclidemu2 and camb)")
    p.add_argument("--out", default=str(ROOT / "examples" / "out"), help="output directory (default examples/out)")
    p.add_argument("--z", default="0,0.5,1,1.5", help="redshifts, comma-separated")
    p.add_argument("--k-min", type=float, default=0.01)
    p.add_argument("--k-max", type=float, default=0.3)
    p.add_argument("--nk", type=int, default=60)
    p.add_argument("--tolerance", type=lambda s: [float(x) for x in s.split(",")], default=[1.0, 2.0],
                   help="tolerances in percent, comma-separated; the first is the figure's band (default 1,2)")
    p.add_argument("--pt-arg", action="append", default=[],
                   help="extra argument passed to `pt-spectra real` (repeat; e.g. --pt-arg=--precision --pt-arg=fast)")
    p.add_argument("--reuse", action="store_true",
                   help="reuse the models_z*.dat already in the output directory (made on the same k grid)")
    p.add_argument("--dpi", type=int, default=100)
    study(p.parse_args())


if __name__ == "__main__":
    main()
