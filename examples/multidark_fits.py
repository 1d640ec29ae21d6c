"""The growth rate f from real N-body haloes (issue 24, part 6): the MultiDark-Planck halo multipoles P0 and
P2 at z = 0.5 and 1 fitted with three models of `pt-spectra fit`/`rsd`, f against its true value as k_max
grows. Writes examples/out/multidark_fits.md (settings, table, conclusions), .png (f/f_true - 1 and
chi2/dof versus k_max, one column per z) and .dat (every fit).

    python3 examples/multidark_fits.py [--data DIR] [--bin PATH] [--out DIR] [--keep DIR [--reuse]]

--data is the folder of the MultiDark measurements (README there; from nebblu/HyPk, MIT). The default,
../shared/data/multidark_haloes next to the repository, exists on the project's machines only: a clone
has no ../shared/, so give --data the folder holding pofk_z0.500.txt, pofk_z1.000.txt, p02_z1.dat and
linear_pofk_DM_z{0.5,1}.txt. --bin is the pt-spectra binary (default target/release/pt-spectra; build it
with `cargo build --release -p pt-spectra`). Needs numpy, scipy and matplotlib; about 3 minutes on 2
cores (the 2-loop spectra at --precision fast dominate). --keep DIR keeps the intermediate tables;
--keep DIR --reuse rewrites the outputs from them without running pt-spectra.

The three models (the markdown states every setting):
* ept: `fit --rsd ept` (velocileptors' REPT), f, b1, b2, bs free, alpha0, alpha2 and sn marginalised
  analytically (sn, a constant, absorbs the shot noise that the measurements do not subtract);
* TNS + nonlinear bias (Beutler et al. 2017, `rsd --rsd tns --b2 --bs --b3 --bias-convention fastpt`, real-space 2L-RPT-N1):
  b1, b2 and a constant noise N from the real-space P_hh (bs, b3nl on the coevolution relations), then f
  and the Lorentzian sigma0 fitted to P0 - N and P2. `fit` does not take --b2/--bs with --rsd tns, so the
  no-FoG multipoles P0..P8 from `rsd` at five f (the model is a polynomial of degree 4 in f and 8 in mu)
  give the model at any f exactly, the FoG factor is applied here, and chi2 is minimised here;
* the paper's TNS (Gil-Marin et al. 2012): TNS + 2L-RPT-N1 with b(k) = sqrt((P_hh - P_eps)/P_mm),
  P_mm the 2L-RPT-N1 matter spectrum, `fit --free f,sigma0,ab` on P0 - P_eps and P2.
"""

import argparse
import concurrent.futures as cf
import os
import pickle
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np
from numpy.polynomial.legendre import leggauss, legval
from scipy.optimize import brentq, least_squares, minimize, minimize_scalar

ROOT = Path(__file__).resolve().parent.parent
DEFAULT_DATA = ROOT.parent / "shared" / "data" / "multidark_haloes"
DEFAULT_BIN = ROOT / "target" / "release" / "pt-spectra"

# MultiDark-Planck (arXiv:1911.04391; the data README): flat LCDM.
H, OMEGA_M, OMEGA_B, N_S, SIGMA8 = 0.6777, 0.307115, 0.048206, 0.96, 0.8228
L_BOX = 2500.0  # Mpc/h, periodic
DK = 2 * np.pi / L_BOX  # the bin width of the measurements
K_DATA_MAX = 0.302  # the 120 bins k <= 0.3016 (the rows of p02_z1.dat)
K_MAX = np.round(np.arange(0.05, 0.3001, 0.025), 3)
K_REAL = 0.2  # the real-space bias fit uses k <= K_REAL
F_NODES = [0.4, 0.6, 0.8, 1.0, 1.2]  # f of the no-FoG TNS tables (degree 4 in f: exact)
REAL = "2l-rpt-n1"  # the real-space model of both TNS variants
P_EPS_SOURCE = 1100.0  # the source's shot noise at z = 1 (HyPk.ipynb), for the sensitivity test
REDSHIFTS = {
    "0.5": dict(z=0.5, pofk="pofk_z0.500.txt", lin="linear_pofk_DM_z0.5.txt", f_true=0.7549, b1=2.04),
    "1": dict(z=1.0, pofk="pofk_z1.000.txt", lin="linear_pofk_DM_z1.txt", f_true=0.8728, b1=2.77,
              errors="p02_z1.dat"),
}
MODELS = ["ept", "tns_nlb", "tns_paper"]
LABELS = {"ept": "ept (REPT, 1-loop EFT)", "tns_nlb": "TNS + nonlinear bias (2L-RPT-N1)",
          "tns_paper": "paper's TNS (2L-RPT-N1, b(k))"}
SHORT = {"ept": "ept", "tns_nlb": "TNS + nonlinear bias", "tns_paper": "the paper's TNS"}
COLOURS = {"ept": "C0", "tns_nlb": "C1", "tns_paper": "C2"}


def log(msg):
    print(msg, file=sys.stderr, flush=True)


def run(binary, args):
    """Runs `pt-spectra ARGS`; stops with its message on failure."""
    cmd = [str(binary)] + [str(a) for a in args]
    p = subprocess.run(cmd, capture_output=True, text=True)
    if p.returncode != 0:
        sys.exit(f"failed ({p.returncode}): {' '.join(cmd)}\n{p.stderr}")
    return p.stderr


def parallel(binary, jobs):
    """Runs several pt-spectra commands at once (one per core; each is mostly single-threaded)."""
    with cf.ThreadPoolExecutor(max_workers=max(1, os.cpu_count() or 1)) as pool:
        return list(pool.map(lambda a: run(binary, a), jobs))


def read_table(path):
    """(column names from the `# k …` / `# k_max …` line, data, header lines) of a pt-spectra table."""
    lines = Path(path).read_text().splitlines()
    header = [l for l in lines if l.startswith("#")]
    names = [l[1:].split() for l in header if l[1:].split()[:1] in (["k"], ["k_max"])][-1]
    data = np.loadtxt(path, ndmin=2)
    return {n: data[:, i] for i, n in enumerate(names)}, header


def header_value(header, key):
    """The number after `key = ` in a header line (e.g. `f(z)`)."""
    for line in header:
        if key + " = " in line:
            return float(line.split(key + " = ")[1].split()[0].rstrip(",;"))
    raise KeyError(key)


# ----------------------------------------------------------------------------------------------------
# Data and covariance


def gaussian_covariance(k, p0, p2):
    """Gaussian covariance of (P0, P2) per k bin of a periodic box from the measured P(k, mu) = P0 + P2 L2
    (shot noise included, as measured; P4 left out, its measurement is noise at low k):
    C_ll'(k) = (2l+1)(2l'+1)/N_k int_-1^1 dmu P(k, mu)^2 L_l L_l', N_k = 4 pi k^2 dk V/(2 pi)^3 = V k^2 dk/(2 pi^2)
    (N_k counts k and -k; for l = l' = 0 and constant P it is Var P0 = 2 P^2/N_k)."""
    x, w = leggauss(40)
    l2 = 0.5 * (3 * x * x - 1)
    pmu = p0[:, None] + p2[:, None] * l2[None, :]
    nk = L_BOX ** 3 * k * k * DK / (2 * np.pi ** 2)
    leg = {0: np.ones_like(x), 2: l2}
    return {(a, b): (2 * a + 1) * (2 * b + 1) / nk * np.sum(w * pmu ** 2 * leg[a] * leg[b], axis=1)
            for a, b in [(0, 0), (0, 2), (2, 2)]}


def load_data(folder, zk):
    """k, P_hh, P0, P2 (k <= K_DATA_MAX) and the covariance blocks c[(l, l')](k) used for the fits."""
    spec = REDSHIFTS[zk]
    d = np.loadtxt(folder / spec["pofk"])
    p0_tail = float(np.mean(d[-20:, 2]))  # P0 near k = 1 h/Mpc: an upper bound on a constant noise
    d = d[d[:, 0] <= K_DATA_MAX]
    k, phh, p0, p2 = d[:, 0], d[:, 1], d[:, 2], d[:, 3]
    gauss = gaussian_covariance(k, p0, p2)
    info = {}
    if "errors" in spec:
        # p02_z1.dat: k, P0, P2, then (C^-1)_00, (C^-1)_02, (C^-1)_22 per bin: the inverse of the 2x2
        # covariance of (P0, P2) of errors.nb in nebblu/HyPk (Gaussian, linear Kaiser with b = 2.77,
        # f = 0.8729, P_lin, n = 2.2e-4 (h/Mpc)^3, V = 2500^3). Checked: its k, P0, P2 are the pofk columns.
        e = np.loadtxt(folder / spec["errors"])
        if len(e) != len(k) or np.max(np.abs(e[:, 0] / k - 1)) > 1e-9 or \
                np.max(np.abs(e[:, 1] / p0 - 1)) > 1e-9 or np.max(np.abs(e[:, 2] / p2 - 1)) > 1e-9:
            sys.exit(f"{spec['errors']}: its k, P0, P2 are not those of {spec['pofk']} (k <= {K_DATA_MAX})")
        det = e[:, 3] * e[:, 5] - e[:, 4] ** 2
        cov = {(0, 0): e[:, 5] / det, (0, 2): -e[:, 4] / det, (2, 2): e[:, 3] / det}
        ratio = np.sqrt(cov[(0, 0)] / gauss[(0, 0)])
        info["p02_over_gauss"] = {kk: float(np.interp(kk, k, ratio)) for kk in (0.03, 0.1, 0.2, 0.3)}
        info["errors"] = f"`{spec['errors']}` (inverse covariance per bin, inverted)"
        info["p0_tail"] = p0_tail
    else:
        cov = gauss
        info["errors"] = "Gaussian, from the measured P0 and P2"
    return dict(k=k, phh=phh, p0=p0, p2=p2, cov=cov, gauss=gauss, info=info)


def full_covariance(cov):
    """The 2n x 2n covariance of (P0(k_1..n), P2(k_1..n)), l-major, block diagonal in k."""
    n = len(cov[(0, 0)])
    c = np.zeros((2 * n, 2 * n))
    i = np.arange(n)
    c[i, i], c[n + i, n + i] = cov[(0, 0)], cov[(2, 2)]
    c[i, n + i] = c[n + i, i] = cov[(0, 2)]
    return c


def write_data(path, k, p0, p2, cov):
    np.savetxt(path, np.column_stack([k, p0, np.sqrt(cov[(0, 0)]), p2, np.sqrt(cov[(2, 2)])]),
               header="k P0 err_P0 P2 err_P2")


# ----------------------------------------------------------------------------------------------------
# Real-space bias: P_hh = b1^2 P_dd + b1 b2 Pd1d2 + b2^2/4 Pd2d2 + b1 bs Pd1s2 + b2 bs/2 Pd2s2 + bs^2/4 Ps2s2
# + 2 b1 b3nl sig3nl + N (FAST-PT's terms and convention as `real --bias-terms` prints them), bs = -4/7 (b1 - 1)
# and b3nl = (b1 - 1)/2 (coevolution, Saito et al. 2014: their b3nl = 32/315 (b1 - 1) multiplies
# sigma3^2 P_lin = (315/64) sig3nl; docs/reference.md, "Bias conventions"), b1, b2, N free.


def coevolution(b1):
    return -4.0 / 7.0 * (b1 - 1.0), 0.5 * (b1 - 1.0)


def bias_model(c, b1, b2, n):
    bs, b3 = coevolution(b1)
    return (b1 ** 2 * c["P_dd"] + b1 * b2 * c["Pd1d2"] + 0.25 * b2 ** 2 * c["Pd2d2"] + b1 * bs * c["Pd1s2"]
            + 0.5 * b2 * bs * c["Pd2s2"] + 0.25 * bs ** 2 * c["Ps2s2"] + 2 * b1 * b3 * c["sig3nl"] + n)


def fit_real_space(k, phh, c, b1_start):
    """b1, b2, N by least squares on k <= K_REAL with Var P_hh = 2 P_hh^2/N_k; several starts (the b2-N
    degeneracy has local minima), the best kept."""
    nk = L_BOX ** 3 * k * k * DK / (2 * np.pi ** 2)
    sigma = np.sqrt(2.0 / nk) * phh
    m = k <= K_REAL
    best = None
    for b1 in (b1_start - 0.2, b1_start, b1_start + 0.2):
        for b2 in (-1.0, 0.5, 2.0):
            for n in (-2000.0, 0.0, 2000.0):
                r = least_squares(lambda p: ((bias_model(c, *p) - phh) / sigma)[m], [b1, b2, n])
                if best is None or r.cost < best.cost:
                    best = r
    err = np.sqrt(np.diag(np.linalg.inv(best.jac.T @ best.jac)))
    b1, b2, n = best.x
    bs, b3 = coevolution(b1)
    # The k -> 0 constant of the bias terms (Pd2d2 -> 2 sigma4 etc.; FAST-PT subtracts none).
    const = 0.25 * b2 ** 2 * c["Pd2d2"][0] + 0.5 * b2 * bs * c["Pd2s2"][0] + 0.25 * bs ** 2 * c["Ps2s2"][0]
    return dict(b1=b1, b2=b2, bs=bs, b3=b3, N=n, err=dict(b1=err[0], b2=err[1], N=err[2]),
                chi2=2 * best.cost, points=int(m.sum()), const=const)


# ----------------------------------------------------------------------------------------------------
# TNS + nonlinear bias from the no-FoG multipoles at F_NODES


def ell_tables(tables):
    """[P_l(k) at each f of F_NODES] -> coefficients c[l][n](k) of P_l = sum_n c_n f^n (n = 0..4)."""
    v = np.vander(np.array(F_NODES), len(F_NODES), increasing=True)
    vi = np.linalg.inv(v)
    return {l: np.einsum("nf,fk->nk", vi, np.array([t[f"P{l}"] for t in tables])) for l in (0, 2, 4, 6, 8)}


class TnsNlb:
    """P0, P2 of TNS + nonlinear bias with a Lorentzian FoG, D^2 = (1 + (k mu sigma)^2/2)^-2,
    sigma = sigma0 D(z) f (as `rsd`), P_l = (2l+1) int_0^1 dmu P^s(k, mu) L_l(mu) by Gauss-Legendre."""

    def __init__(self, k, coeffs, growth_factor):
        self.k, self.c, self.d = k, coeffs, growth_factor
        x, w = leggauss(64)
        self.mu, self.w = 0.5 * (x + 1), 0.5 * w
        self.leg = {l: legval(self.mu, [0] * l + [1]) for l in (0, 2, 4, 6, 8)}

    def multipoles(self, f, sigma0):
        powers = f ** np.arange(len(F_NODES))
        pmu = sum(np.einsum("n,nk->k", powers, self.c[l])[:, None] * self.leg[l][None, :]
                  for l in (0, 2, 4, 6, 8))
        x = self.k[:, None] * self.mu[None, :] * abs(sigma0) * self.d * f
        pmu = pmu / (1 + 0.5 * x * x) ** 2
        return [(2 * l + 1) * np.sum(self.w * pmu * self.leg[l], axis=1) for l in (0, 2)]


def fit_tns_nlb(model, data_vec, cinv_by_kmax, f_true):
    """f and sigma0 minimising chi2 at each k_max; f's error where the profile chi2 (sigma0 re-minimised)
    reaches chi2_min + 1."""
    out = []
    for kmax, (sel, cinv) in cinv_by_kmax.items():
        def chi2(p):
            m0, m2 = model.multipoles(p[0], p[1])
            r = (data_vec - np.concatenate([m0, m2]))[sel]
            return float(r @ cinv @ r)

        best = None
        for start in ([f_true, 4.0], [1.15 * f_true, 2.0], [0.85 * f_true, 6.0]):
            r = minimize(chi2, start, method="Nelder-Mead", options=dict(xatol=1e-6, fatol=1e-6, maxiter=4000))
            if best is None or r.fun < best.fun:
                best = r
        f0, s0 = best.x[0], abs(best.x[1])

        def profile(f):
            return minimize_scalar(lambda s: chi2([f, s]), bounds=(0.0, 20.0), method="bounded",
                                   options=dict(xatol=1e-5)).fun - best.fun - 1.0

        lo = hi = np.nan
        try:
            lo = brentq(profile, max(f0 - 0.6, 0.05), f0, xtol=1e-5)
            hi = brentq(profile, f0, f0 + 0.6, xtol=1e-5)
        except ValueError:
            pass
        out.append(dict(k_max=kmax, points=int(sel.sum()), f=f0, err_f=0.5 * (hi - lo), sigma0=s0,
                        chi2=best.fun, dof=int(sel.sum()) - 2))
    return out


def kaiser_check(folder, zk, d, p_eps, k_lo=0.01, k_hi=0.05):
    """f of linear Kaiser from the largest scales: b^2 = <P_hh - P_eps>/<P_lin> and beta from
    P2/(P_hh - P_eps) = 4/3 beta + 4/7 beta^2, averages over k_lo < k < k_hi weighted by the modes (k^2)."""
    lin = np.loadtxt(folder / REDSHIFTS[zk]["lin"])
    k = d["k"]
    plin = np.exp(np.interp(np.log(k), np.log(lin[:, 0]), np.log(lin[:, 1])))
    m = (k > k_lo) & (k < k_hi)
    w = k[m] ** 2
    phh = np.sum(w * (d["phh"][m] - p_eps))
    b = np.sqrt(phh / np.sum(w * plin[m]))
    beta = brentq(lambda x: 4 / 3 * x + 4 / 7 * x * x - np.sum(w * d["p2"][m]) / phh, 0.0, 3.0)
    return dict(f=beta * b, b=b, k_lo=k_lo, k_hi=k_hi)


# ----------------------------------------------------------------------------------------------------


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0],
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--data", type=Path, default=DEFAULT_DATA,
                    help=f"folder of the MultiDark tables (default {DEFAULT_DATA}; a clone has no ../shared/)")
    ap.add_argument("--bin", type=Path, default=DEFAULT_BIN, help="the pt-spectra binary")
    ap.add_argument("--out", type=Path, default=ROOT / "examples" / "out", help="output folder")
    ap.add_argument("--keep", type=Path, help="keep the intermediate tables (and the fits, results.pkl) here")
    ap.add_argument("--reuse", action="store_true",
                    help="with --keep: rewrite the outputs from the results.pkl of an earlier run there")
    args = ap.parse_args()
    if args.reuse:
        if args.keep is None or not (args.keep / "results.pkl").is_file():
            sys.exit("--reuse needs --keep DIR holding the results.pkl of an earlier run")
        with open(args.keep / "results.pkl", "rb") as fh:
            res, seconds = pickle.load(fh)
        args.out.mkdir(parents=True, exist_ok=True)
        write_outputs(args, res, seconds)
        return
    if not (args.data / "pofk_z1.000.txt").is_file():
        sys.exit(f"no MultiDark tables in {args.data}: give --data DIR (see the README there)")
    if not args.bin.is_file():
        sys.exit(f"no binary {args.bin}: cargo build --release -p pt-spectra, or give --bin")
    t_start = time.time()
    work = Path(tempfile.mkdtemp(prefix="multidark_")) if args.keep is None else args.keep
    work.mkdir(parents=True, exist_ok=True)
    args.out.mkdir(parents=True, exist_ok=True)
    B = args.bin.resolve()

    ini = work / "multidark_planck.ini"
    ini.write_text(f"# MultiDark-Planck (arXiv:1911.04391), flat LCDM\nh = {H}\n"
                   f"omega_b = {OMEGA_B * H * H:.8f}\nomega_cdm = {(OMEGA_M - OMEGA_B) * H * H:.8f}\n"
                   f"n_s = {N_S}\nsigma8 = {SIGMA8}\n")

    def spectrum(zk):
        s = REDSHIFTS[zk]
        return ["--cosmology", ini, "--linear", args.data / s["lin"], "--z", s["z"], "--z-input", s["z"]]

    res = {}
    # Stage 1, per z: data files; the real-space spectra with bias terms (REAL); ept fits.
    jobs = []
    for zk, s in REDSHIFTS.items():
        d = load_data(args.data, zk)
        res[zk] = dict(data=d)
        np.savetxt(work / f"k_z{zk}.txt", d["k"])
        write_data(work / f"data_z{zk}.dat", d["k"], d["p0"], d["p2"], d["cov"])
        np.savetxt(work / f"cov_z{zk}.dat", full_covariance(d["cov"]))
        jobs.append(["real", "--model", REAL, "--precision", "fast", "--bias-terms", "--k-file",
                     work / f"k_z{zk}.txt", "--out", work / f"real_z{zk}.dat"] + spectrum(zk))
        fit_common = ["--data-columns", "1,2,3,4,5", "--data-ells", "0,2", "--ells", "0,2",
                      "--covariance", work / f"cov_z{zk}.dat",
                      "--k-max", ",".join(f"{x:g}" for x in K_MAX)]
        res[zk]["fit_common"] = fit_common
        jobs.append(["fit", "--rsd", "ept", "--data", work / f"data_z{zk}.dat"] + fit_common +
                    ["--free", "f,b1,b2,bs", "--marginalise", "alpha0,alpha2,sn", "--prior", "b2:0,2",
                     "--prior", "bs:0,2", "--bias", s["b1"], "--out", work / f"ept_z{zk}.dat"] + spectrum(zk))
    log(f"[{time.time() - t_start:.0f} s] stage 1: {len(jobs)} commands (real-space 2-loop spectra, ept fits)")
    parallel(B, jobs)

    jobs = []
    for zk, s in REDSHIFTS.items():
        r, d = res[zk], res[zk]["data"]
        t, header = read_table(work / f"ept_z{zk}.dat")
        r["f_tool"] = header_value(header, "f(z)")
        r["D"] = header_value(header, "D(z)/D(0)")
        r["ept"] = [dict(k_max=t["k_max"][i], points=int(t["points"][i]), f=t["f"][i], err_f=t["err_f"][i],
                         chi2=t["chi2"][i], dof=int(t["points"][i]) - 7, b1=t["b1"][i], b2=t["b2"][i],
                         bs=t["bs"][i], sn=t["sn"][i]) for i in range(len(t["k_max"]))]
        c, _ = read_table(work / f"real_z{zk}.dat")
        bias = fit_real_space(d["k"], d["phh"], c, s["b1"])
        r["bias"] = bias
        log(f"z = {zk}: real space b1 = {bias['b1']:.3f}, b2 = {bias['b2']:.2f}, N = {bias['N']:.0f}")
        # Stage 2 inputs: TNS + nonlinear bias without FoG at each f of F_NODES.
        for f in F_NODES:
            jobs.append(["rsd", "--rsd", "tns", "--real", REAL, "--precision", "fast", "--bias", bias["b1"],
                         "--b2", bias["b2"], "--bs", bias["bs"], "--b3", bias["b3"], "--bias-convention", "fastpt",
                         "--f", f, "--fog", "none",
                         "--ells", "0,2,4,6,8", "--k-file", work / f"k_z{zk}.txt",
                         "--out", work / f"tns_nlb_f{f}_z{zk}.dat"] + spectrum(zk))
        # Diagnostic: ept with b2, bs, b3 fixed to the real-space values (velocileptors' bs s^2 and b3 =
        # 2 b3nl against FAST-PT's (bs/2) s^2 and b3nl), f, b1 free.
        jobs.append(["fit", "--rsd", "ept", "--data", work / f"data_z{zk}.dat"] + r["fit_common"][:-2] +
                    ["--k-max", "0.1,0.15,0.2", "--free", "f,b1", "--b2", bias["b2"], "--bs", bias["bs"] / 2,
                     "--b3", 2 * bias["b3"], "--marginalise", "alpha0,alpha2,sn", "--bias", bias["b1"],
                     "--out", work / f"ept_fixed_z{zk}.dat"] + spectrum(zk))
        # The paper's TNS: b(k) from P_hh minus its whole k -> 0 constant, P_eps = N + the constant of the
        # bias terms (the paper's P_hh = b^2 P_mm + P_eps); P_eps subtracted from P0 here (as
        # --shot-noise does, which takes positive values only).
        pmm = c
        variants = {"": bias["N"] + bias["const"]}
        if zk == "1":
            variants["_src"] = P_EPS_SOURCE
        r["p_eps"] = variants
        for tag, pe in variants.items():
            b = np.sqrt((d["phh"] - pe) / pmm["P_dd"])
            np.savetxt(work / f"bk{tag}_z{zk}.dat", np.column_stack([d["k"], b]), header="k b", comments="# ")
            write_data(work / f"data_sub{tag}_z{zk}.dat", d["k"], d["p0"] - pe, d["p2"], d["cov"])
            kmax = ",".join(f"{x:g}" for x in K_MAX) if tag == "" else "0.1,0.15,0.2"
            jobs.append(["fit", "--rsd", "tns", "--real", REAL, "--precision", "fast", "--fog", "lorentzian",
                         "--free", "f,sigma0,ab", "--bias-file", work / f"bk{tag}_z{zk}.dat",
                         "--data", work / f"data_sub{tag}_z{zk}.dat"] + r["fit_common"][:-2] +
                        ["--k-max", kmax, "--out", work / f"tns_paper{tag}_z{zk}.dat"] + spectrum(zk))
    log(f"[{time.time() - t_start:.0f} s] stage 2: {len(jobs)} commands (TNS + nonlinear bias tables, the paper's TNS fits)")
    parallel(B, jobs)

    jobs = []
    for zk, s in REDSHIFTS.items():
        r, d = res[zk], res[zk]["data"]
        tables = [read_table(work / f"tns_nlb_f{f}_z{zk}.dat")[0] for f in F_NODES]
        model = TnsNlb(d["k"], ell_tables(tables), r["D"])
        n = len(d["k"])
        cfull = full_covariance(d["cov"])
        cinv = {}
        for kmax in K_MAX:
            sel = np.concatenate([d["k"] <= kmax + 1e-9] * 2)
            cinv[kmax] = (sel, np.linalg.inv(cfull[np.ix_(sel, sel)]))
        vec = np.concatenate([d["p0"] - r["bias"]["N"], d["p2"]])
        r["tns_nlb"] = fit_tns_nlb(model, vec, cinv, s["f_true"])
        r["tns_model"] = model
        # Check of the reconstruction: `rsd` itself with the FoG at the k_max = 0.2 best fit.
        b = next(x for x in r["tns_nlb"] if abs(x["k_max"] - 0.2) < 1e-9)
        bias = r["bias"]
        jobs.append(["rsd", "--rsd", "tns", "--real", REAL, "--precision", "fast", "--bias", bias["b1"],
                     "--b2", bias["b2"], "--bs", bias["bs"], "--b3", bias["b3"], "--bias-convention", "fastpt",
                     "--f", b["f"], "--fog", "lorentzian",
                     "--sigma0", b["sigma0"], "--ells", "0,2", "--k-file", work / f"k_z{zk}.txt",
                     "--out", work / f"tns_nlb_check_z{zk}.dat"] + spectrum(zk))
        for tag in r["p_eps"]:
            t, header = read_table(work / f"tns_paper{tag}_z{zk}.dat")
            # `fit` reports where the profile chi2 reaches chi2_min + 3.53 (3 free parameters); the
            # 1-sigma error of f alone is that half-width over sqrt(3.53) (exact for a quadratic chi2).
            scale = 1.0 / np.sqrt(3.53)
            assert any("3.53" in h for h in header), "fit's error convention changed: check the scale"
            r["tns_paper" + tag] = [dict(k_max=t["k_max"][i], points=int(t["points"][i]), f=t["f"][i],
                                         err_f=0.5 * (t["f_hi"][i] - t["f_lo"][i]) * scale, chi2=t["chi2"][i],
                                         dof=int(t["dof"][i]), sigma0=t["sigma0"][i], ab=t["ab"][i])
                                    for i in range(len(t["k_max"]))]
        t, _ = read_table(work / f"ept_fixed_z{zk}.dat")
        r["ept_fixed"] = {round(t["k_max"][i], 3): t["f"][i] for i in range(len(t["k_max"]))}
        r["kaiser"] = kaiser_check(args.data, zk, d, r["p_eps"][""])
    log(f"[{time.time() - t_start:.0f} s] stage 3: the check of the TNS + nonlinear bias reconstruction")
    parallel(B, jobs)
    for zk in REDSHIFTS:
        r = res[zk]
        b = next(x for x in r["tns_nlb"] if abs(x["k_max"] - 0.2) < 1e-9)
        chk, _ = read_table(work / f"tns_nlb_check_z{zk}.dat")
        m0, m2 = r["tns_model"].multipoles(b["f"], b["sigma0"])
        r["check"] = max(np.max(np.abs(m0 / chk["P0"] - 1)), np.max(np.abs(m2 / chk["P2"] - 1)))

    for zk in REDSHIFTS:
        del res[zk]["tns_model"]
    if args.keep is not None:
        with open(work / "results.pkl", "wb") as fh:
            pickle.dump((res, time.time() - t_start), fh)
    write_outputs(args, res, time.time() - t_start)
    if args.keep is None:
        shutil.rmtree(work)
    log(f"done in {time.time() - t_start:.0f} s")


# ----------------------------------------------------------------------------------------------------
# Outputs


K_REACH = 0.1  # reaches count from this k_max: below it sigma_f >= 3% and every fit is within 1 sigma


def reach(rows, test):
    """The largest k_max >= K_REACH up to which every fit from K_REACH on passes `test` (None: fails at
    K_REACH)."""
    last = None
    for x in rows:
        if x["k_max"] < K_REACH - 1e-9:
            continue
        if not (np.isfinite(x["f"]) and np.isfinite(x["err_f"]) and test(x)):
            break
        last = x["k_max"]
    return last


def fmt_reach(v):
    return "none" if v is None else f"{v:.3g}"


def write_outputs(args, res, seconds):
    out = args.out
    # The table of every fit.
    with open(out / "multidark_fits.dat", "w") as fh:
        fh.write("# MultiDark haloes: f from P0 and P2 (examples/multidark_fits.py); dev = f/f_true - 1\n")
        fh.write("# z model k_max points f err_f dev chi2 dof\n")
        for zk, s in REDSHIFTS.items():
            for m in MODELS:
                for x in res[zk][m]:
                    fh.write(f"{s['z']:g} {m} {x['k_max']:.3f} {x['points']} {x['f']:.6f} {x['err_f']:.6f} "
                             f"{x['f'] / s['f_true'] - 1:+.6f} {x['chi2']:.3f} {x['dof']}\n")
    plot(out / "multidark_fits.png", res)

    lines = []
    w = lines.append
    w("# The growth rate from MultiDark haloes: ept, TNS + nonlinear bias and the paper's TNS\n")
    w("Written by `examples/multidark_fits.py` (issue 24, part 6; "
      f"{seconds:.0f} s on {os.cpu_count()} cores). The halo multipoles P0 and P2 of the MultiDark-Planck "
      "simulation (one periodic box of 2500 Mpc/h, shot noise not subtracted; nebblu/HyPk, the data "
      "README) are fitted jointly for k ≤ k_max with f free; the table and `multidark_fits.png` give f "
      "against the true f(z) of the simulation's cosmology.\n")
    w("![f/f_true − 1 and χ²/dof versus k_max](multidark_fits.png)\n")
    w("f/f_true − 1 with its 1σ error (none where `fit` reports NaN: the Hessian of −2 ln L is not "
      "positive definite at ept's smallest k_max at z = 0.5, b2 and bs being unconstrained there) and "
      "χ²/dof, versus k_max; the grey band is ±2%.\n")
    w("## Settings\n")
    fz = ", ".join(f"{res[zk]['f_tool']:.6f} at z = {zk}" for zk in REDSHIFTS)
    w(f"- Cosmology: a CLASS-style `.ini` (h = {H}, ω_b = Ω_b h² = {OMEGA_B * H * H:.6f}, ω_cdm = "
      f"{(OMEGA_M - OMEGA_B) * H * H:.6f} for Ω_m = {OMEGA_M}, Ω_b = {OMEGA_B}; n_s = {N_S}, σ8 = {SIGMA8}) "
      f"with the simulation's linear spectrum at each z (`--linear`, `--z-input` = `--z`). The tool's f(z): {fz} "
      "(the README's true values 0.7549 and 0.8728).")
    d1 = res["1"]["data"]["info"]
    ratio = ", ".join(f"{v:.2f} at k = {kk:g}" for kk, v in d1["p02_over_gauss"].items())
    w(f"- Data: the 120 bins k ≤ 0.3016 h/Mpc (Δk = 2π/2500); k_max from {K_MAX[0]:g} to {K_MAX[-1]:g} in "
      "steps of 0.025, no k_min.")
    w("- Errors at z = 1: `p02_z1.dat`, whose last three columns are the inverse of the 2×2 covariance of "
      "(P0, P2) per bin ((C⁻¹)₀₀, (C⁻¹)₀₂, (C⁻¹)₂₂; errors.nb in nebblu/HyPk: Gaussian, linear Kaiser with "
      "b = 2.77, f = 0.8729, n = 2.2×10⁻⁴ (h/Mpc)³, V = 2500³): inverted per bin, the P0–P2 covariance "
      "kept, passed as `--covariance` (ℓ-major, block diagonal in k). Its σ(P0) is "
      f"({ratio}) times the Gaussian one from the measured spectra below: its Poisson term 1/n = 4545 "
      f"(Mpc/h)³ exceeds even the measured P0 near k = 1 h/Mpc ({d1['p0_tail']:.0f} (Mpc/h)³), so these "
      "errors are conservative at high k.")
    w("- Errors at z = 0.5 (none given): Gaussian for the periodic box from the measured multipoles, "
      "C_ℓℓ′(k) = (2ℓ+1)(2ℓ′+1)/N_k ∫₋₁¹ dμ P(k,μ)² L_ℓ L_ℓ′ with P(k,μ) = P0 + P2 L2 (measured, shot "
      "noise included; P4 left out, noise at low k) and N_k = 4πk²Δk V/(2π)³, V = 2500³ (Mpc/h)³ "
      "(N_k counts k and −k: Var P0 = 2P²/N_k for constant P); P0–P2 covariance kept.")
    w("- **ept**: `fit --rsd ept` (velocileptors' REPT, IR resummed), free f, b1, b2, bs (priors b2, bs: "
      "N(0, 2²)), b3 = 0, α0, α2 and sn marginalised analytically (flat); sn, a constant, absorbs the "
      "shot noise left in P0. σ_f from the Hessian of −2 ln L; dof = points − 7.")
    bl = []
    for zk in REDSHIFTS:
        b = res[zk]["bias"]
        bl.append(f"z = {zk}: b1 = {b['b1']:.3f} ± {b['err']['b1']:.3f}, b2 = {b['b2']:.2f} ± {b['err']['b2']:.2f}, "
                  f"bs = {b['bs']:.3f}, b3nl = {b['b3']:.3f}, N = {b['N']:.0f} ± {b['err']['N']:.0f} (Mpc/h)³, "
                  f"χ² = {b['chi2']:.0f} for {b['points']} points")
    w("- **TNS + nonlinear bias** (Beutler et al. 2017 as `rsd --rsd tns --b2 --bs --b3 --bias-convention fastpt`, real space "
      "2L-RPT-N1 as the paper's TNS below, `--precision fast`): b1, b2 and a constant N fitted to the real-space P_hh for k ≤ "
      f"{K_REAL} (P_gg of `real --bias-terms` + N, Var P_hh = 2P_hh²/N_k; in FAST-PT's convention bs = "
      "−4/7 (b1 − 1), b3nl = (b1 − 1)/2 (Saito et al.'s 32/315 (b1 − 1) of σ₃² = (315/64) sig3nl/P_lin), "
      "the coevolution values, because P_hh alone does not separate bs from b2): "
      + "; ".join(bl) + ". Then f and the Lorentzian σ0 (σ = σ0 D(z) f, as `rsd`) fitted to P0 − N and P2 "
      "with b1, b2, bs, b3nl, N fixed. `fit` refuses --b2/--bs with --rsd tns, so the script takes the "
      f"no-FoG multipoles P0…P8 from `rsd` at f = {', '.join(map(str, F_NODES))} (the model is a "
      "polynomial of degree 4 in f and 8 in μ, so these give it exactly at any f), applies the FoG by "
      "Gauss–Legendre in μ and minimises χ² itself; σ_f where the profile χ² (σ0 re-minimised) rises by 1. "
      "Check against `rsd` with the FoG at the k_max = 0.2 best fit: the reconstruction differs by ≤ "
      + ", ".join(f"{res[zk]['check']:.1e} (z = {zk})" for zk in REDSHIFTS) + " of P0, P2.")
    pe = "; ".join(f"z = {zk}: P_eps = {res[zk]['p_eps']['']:.0f} (Mpc/h)³" for zk in REDSHIFTS)
    w("- **The paper's TNS** (Gil-Marín et al. 2012; `fit --rsd tns --real 2l-rpt-n1 --fog lorentzian "
      "--free f,sigma0,ab --bias-file`, `--precision fast`): b(k) = √((P_hh − P_eps)/P_mm) per bin with "
      "P_mm of 2L-RPT-N1 (of the RPT models, the one closest to EuclidEmulator2 at z = 0.5 and 1 in "
      "`out/emulator_study.md`), P_eps = N plus the "
      f"k → 0 constant of the fitted bias terms ({pe}), subtracted from P0 (as `--shot-noise` does, which "
      "refuses P_eps ≤ 0). `fit` reports where the profile χ² rises by 3.53 (3 free); σ_f here is that "
      "half-width / √3.53. Because b(k) is measured on the same modes as P0 and P2, their sample "
      "variance largely cancels: χ²/dof ≪ 1 and these σ_f overstate the error.")
    src = res["1"]["tns_paper_src"]
    base = {round(x["k_max"], 3): x["f"] for x in res["1"]["tns_paper"]}
    shift = ", ".join(f"{x['f'] / base[round(x['k_max'], 3)] - 1:+.2%} at k_max = {x['k_max']:g}" for x in src)
    w(f"- Shot noise: the real-space fit does not pin N (b2 and N are degenerate); f hardly depends on it: "
      f"the paper's TNS with the source's P_eps = {P_EPS_SOURCE:.0f} (Mpc/h)³ at z = 1 moves f by {shift}.\n")

    w("## f ± σ_f (f/f_true − 1) versus k_max\n")
    for zk, s in REDSHIFTS.items():
        w(f"z = {zk}, f_true = {s['f_true']}; χ²/dof in brackets:\n")
        w("| k_max | " + " | ".join(LABELS[m] for m in MODELS) + " |")
        w("|---|" + "---|" * len(MODELS))
        for i, kmax in enumerate(K_MAX):
            cells = []
            for m in MODELS:
                x = res[zk][m][i]
                e = f"{x['err_f']:.3f}" if np.isfinite(x["err_f"]) else "n/a"
                cells.append(f"{x['f']:.3f} ± {e} ({x['f'] / s['f_true'] - 1:+.1%}) [{x['chi2'] / x['dof']:.2f}]")
            w(f"| {kmax:.3f} | " + " | ".join(cells) + " |")
        w("")
    w(f"The largest k_max up to which every fit from k_max = {K_REACH} on has |f − f_true| ≤ σ_f, and ≤ 2% "
      "of f_true (\"none\": already fails at 0.1):\n")
    w("| model | z = 0.5, 1σ | z = 0.5, 2% | z = 1, 1σ | z = 1, 2% |")
    w("|---|---|---|---|---|")
    reaches = {}
    for m in MODELS:
        cells = []
        for zk, s in REDSHIFTS.items():
            a = reach(res[zk][m], lambda x: abs(x["f"] - s["f_true"]) <= x["err_f"])
            b = reach(res[zk][m], lambda x: abs(x["f"] / s["f_true"] - 1) <= 0.02)
            reaches[m, zk] = (a, b)
            cells += [fmt_reach(a), fmt_reach(b)]
        w(f"| {LABELS[m]} | " + " | ".join(cells) + " |")
    w("")
    w("## Conclusions\n")
    for line in conclusions(res, reaches):
        w(f"- {line}")
    w("")
    (out / "multidark_fits.md").write_text("\n".join(lines))
    log(f"wrote {out / 'multidark_fits.md'}, {out / 'multidark_fits.png'}, {out / 'multidark_fits.dat'}")


def row(res, zk, m, kmax):
    return next(x for x in res[zk][m] if abs(x["k_max"] - kmax) < 1e-9)


def conclusions(res, reaches):
    zs = list(REDSHIFTS)

    def dev(m, zk, kmax):
        x, ft = row(res, zk, m, kmax), REDSHIFTS[zk]["f_true"]
        return f"{x['f'] / ft - 1:+.1%} ± {x['err_f'] / ft:.1%}"

    def both(m, kmax):
        return " and ".join(dev(m, zk, kmax) for zk in zs)

    low = [x for zk in zs for m in MODELS for x in res[zk][m] if x["k_max"] < K_REACH - 1e-9]
    low_ok = all(abs(x["f"] / REDSHIFTS[zk]["f_true"] - 1) <= x["err_f"] / REDSHIFTS[zk]["f_true"]
                 for zk in zs for m in MODELS for x in res[zk][m]
                 if x["k_max"] < K_REACH - 1e-9 and np.isfinite(x["err_f"]))
    sig = [row(res, zk, m, K_REACH)["err_f"] / REDSHIFTS[zk]["f_true"] for zk in zs for m in MODELS]
    one_sigma = "; ".join(f"{SHORT[m]} to " + " and ".join(
        fmt_reach(reaches[m, zk][0]) for zk in zs) for m in MODELS)
    first = []  # where sigma_f first falls below 2% of f_true, and f's deviation there
    exceptions = []  # fits with sigma_f < 2% and |f/f_true - 1| <= 2%
    for m in MODELS:
        cells = []
        for zk in zs:
            ft = REDSHIFTS[zk]["f_true"]
            tight = [x for x in res[zk][m] if np.isfinite(x["err_f"]) and x["err_f"] < 0.02 * ft]
            cells.append(f"{tight[0]['k_max']:g} ({tight[0]['f'] / ft - 1:+.1%})" if tight else "never")
            exceptions += [f"{SHORT[m]} at z = {zk}, k_max = {x['k_max']:g}" for x in tight
                           if abs(x["f"] / ft - 1) <= 0.02]
        first.append(" and ".join(cells) + f" for {SHORT[m]}")
    yield (f"Within 1σ (z = 0.5 and 1, counted from k_max = {K_REACH}): {one_sigma} h/Mpc"
           + (f"; every fit at k_max < {K_REACH} is within 1σ too" if low and low_ok else "")
           + f". Within 2%: only where σ_f > 2% (at k_max = {K_REACH} σ_f is {min(sig):.0%}–{max(sig):.0%}); "
           "σ_f first falls below 2% at k_max = " + "; ".join(first)
           + ", f's offset there in brackets"
           + (" — no fit gets f to 2% with a 2% error except " + ", ".join(exceptions)
              + ", where f crosses f_true on a steady drift." if exceptions
              else " — no fit gets f to 2% with a 2% error."))
    yield ("Beyond k_max ≈ 0.1 all three overestimate f, by more than σ_f: at k_max = 0.15 (z = 0.5 and 1) "
           f"ept {both('ept', 0.15)}, TNS + nonlinear bias {both('tns_nlb', 0.15)}, the paper's TNS "
           f"{both('tns_paper', 0.15)}; at 0.2 ept {both('ept', 0.2)}.")
    fixed = " and ".join(f"{res[zk]['ept_fixed'][0.15] / REDSHIFTS[zk]['f_true'] - 1:+.1%}" for zk in zs)
    bs = [x["bs"] for zk in zs for x in res[zk]["ept"] if 0.15 - 1e-9 <= x["k_max"] <= 0.2 + 1e-9]
    sn = [x["sn"] for zk in zs for x in res[zk]["ept"] if 0.15 - 1e-9 <= x["k_max"] <= 0.2 + 1e-9]
    yield ("ept is the most biased, and its nuisance parameters take unphysical values (bs from "
           f"{min(bs):.1f} to {max(bs):.1f} at k_max = 0.15–0.2, against the coevolution −2/7 (b1 − 1) ≈ −0.3 "
           f"to −0.5; sn from {min(sn):.0f} to {max(sn):.0f} (Mpc/h)³ though the noise left in P0 is ≥ 0), but "
           f"freeing them is not the cause: with b2, bs, b3 fixed to the real-space values ept gives {fixed} at "
           "k_max = 0.15.")
    kai = " and ".join(f"{res[zk]['kaiser']['f'] / REDSHIFTS[zk]['f_true'] - 1:+.1%}" for zk in zs)
    yield ("Not a fitting artefact: linear Kaiser on the largest scales (P2/(P_hh − P_eps) and "
           f"(P_hh − P_eps)/P_lin, {res['1']['kaiser']['k_lo']} < k < {res['1']['kaiser']['k_hi']}) recovers f "
           f"({kai} from f_true; Kaiser omits the damping, which lowers it); χ² recomputed from `rsd --rsd ept` at a best fit equals `fit`'s, and the ept "
           "multipoles agree with velocileptors' REPT on this linear spectrum (z = 1, b1 = 2.77, k ≤ 0.3; REPT at N = 8000, as tests/data) to ≤ 5.7e-5 of P0 without IR and ≤ 3.3e-4 with it (the χ² check by hand at z = 1, k_max = 0.2). "
           "The shared excess is a property of these halo multipoles against PT with a k²μ²-counterterm or "
           "Lorentzian FoG at k ≈ 0.1–0.2 h/Mpc, not of one model.")
    chi = []
    for m in ("ept", "tns_nlb"):
        lims = []
        for zk in zs:
            lim = None
            for x in res[zk][m]:
                if x["chi2"] / x["dof"] > 1.0:
                    break
                lim = x["k_max"]
            lims.append(fmt_reach(lim))
        chi.append(" and ".join(lims) + f" for {SHORT[m]}")
    yield ("χ²/dof stays ≤ 1 up to k_max = " + ", ".join(chi) + " (z = 0.5 and 1). At z = 0.5 TNS + "
           "nonlinear bias fails above k_max = 0.2 (χ²/dof > 1 and f falling by 5–22%): 2L-RPT-N1 does not "
           "follow these spectra there. The paper's TNS has χ²/dof ≪ 1 throughout because b(k) comes from "
           "the same realisation. At small k_max χ²/dof ≈ 0.5–0.6 for the other two: the Gaussian (z = 0.5) "
           "and `p02_z1.dat` (z = 1) errors overstate the scatter of these multipoles, so the offsets are, "
           "if anything, more significant than the σ_f quoted.")


def plot(path, res):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(2, 2, figsize=(11, 7), sharex=True, gridspec_kw=dict(height_ratios=[2, 1]))
    for j, (zk, s) in enumerate(REDSHIFTS.items()):
        ax, ax2 = axes[0, j], axes[1, j]
        ax.axhspan(-0.02, 0.02, color="0.9")
        ax.axhline(0, color="k", lw=0.8)
        for n, m in enumerate(MODELS):
            rows = res[zk][m]
            k = np.array([x["k_max"] for x in rows]) + (n - 1) * 0.004
            dev = np.array([x["f"] / s["f_true"] - 1 for x in rows])
            err = np.array([x["err_f"] / s["f_true"] for x in rows])
            ax.errorbar(k, dev, yerr=np.where(np.isfinite(err), err, 0), fmt="o", ms=4, capsize=2,
                        color=COLOURS[m], label=LABELS[m])
            ax2.plot(k, [x["chi2"] / x["dof"] for x in rows], "o-", ms=3, color=COLOURS[m])
        ax.set_title(f"z = {zk}: f_true = {s['f_true']}")
        ax.set_ylim(-0.25, 0.35)
        ax.set_ylabel("f / f_true − 1")
        ax2.axhline(1, color="k", lw=0.8)
        ax2.set_yscale("log")
        ax2.set_ylabel("χ² / dof")
        ax2.set_xlabel("k_max [h/Mpc]")
    axes[0, 0].legend(loc="upper left", fontsize=8)
    fig.suptitle("MultiDark haloes: f from P0 + P2 (grey: ±2%)")
    fig.tight_layout()
    fig.savefig(path, dpi=120)


if __name__ == "__main__":
    main()
