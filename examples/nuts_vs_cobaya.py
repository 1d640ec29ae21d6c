"""NUTS on the library's exact gradient against cobaya's MCMC, one likelihood (issue 47, part 6), on
one of two data sets (--data):

- ngc (default): BOSS DR12 CMASS NGC, the analysis of examples/posterior_vs_profile.py (f, b1, b2, bs,
  alpha_par, alpha_perp free; alpha0, alpha2, sn, sn2 marginalised analytically; the survey window;
  P0, P2, k in [0.01, 0.2] h/Mpc);
- nseries: the mean P0, P2, P4 of the 84 Nseries mocks (window-free) with the covariance of one mock
  (examples/nseries_fits.py's structured covariance and its inverse-bias factor), k in [0.02, 0.15]
  h/Mpc, the true cosmology's template (CAMB), AP against the measurement's fiducial; f, b1, b2, bs,
  alpha_par, alpha_perp free; alpha0, alpha2, alpha4, sn, sn2 marginalised analytically; the priors
  of the NGC analysis.

numpyro's NUTS samples `pt_spectra.jax.log_likelihood` of `pt.AnalysisLikelihood` (JAX calls the library
for the value and its exact gradient), with uniform priors on the likelihood's bounds, as cobaya's run
of examples/posterior_vs_profile.py has; several chains from dispersed starts, two at a time in
separate processes; the split R - 1 of every parameter against the target. The two posteriors must
agree: means within 0.1 sigma, widths within 10%.

Writes examples/out/nuts_vs_cobaya.md (settings, table, verdict) and .png (the marginals of both);
with --data nseries nuts_vs_cobaya_nseries.md, .png and the inputs it makes (nuts_nseries_*).

    python3 examples/nuts_vs_cobaya.py [--data ngc|nseries] [--nseries DIR] [--out DIR] [--chains 4]
                                       [--warmup 500] [--samples 1500] [--workers 2] [--rminus1 0.01]
                                       [--cobaya-chain FILE] [--seed S]

--nseries: the folder of pk_nseries<i>_fkp.txt, i = 1..84 (default ../shared/data/nseries next to the
repository, on the project's machines only). --cobaya-chain: the .dat examples/posterior_vs_profile.py
(or a previous run of this script, OUT/<report>_cobaya.dat) writes (weight, minuslogpost, parameters,
fsigma8); without it cobaya's chain is run here (about 2 minutes) and saved as <report>_cobaya.dat.
Needs numpy, scipy, matplotlib, camb (the template), jax and numpyro (`pip install "./python[jax]"`),
cobaya without --cobaya-chain. NGC: about 12 minutes on 2 cores with the defaults (712 s measured with
the cobaya chain read: 4 chains of 2000 steps, 19 leapfrog steps per draw at 3.9 ms each), 2 more to
run cobaya's chain. Nseries: about 1-2 minutes (60 s measured, quiet: cobaya's chain 17 s, NUTS
41 s, 12 leapfrog steps per draw at 0.5 ms each; 101 s under load).
"""

import argparse
import os
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from boss_cmass_fit import DEFAULT_OUT, log  # noqa: E402
from posterior_vs_profile import (LABELS, hessian, minimise, ngc_likelihood, sample,  # noqa: E402
                                  weighted_stats)

import nseries_fits as ns  # noqa: E402
import pt_spectra as pt  # noqa: E402

NSERIES_K = (0.02, 0.15)  # the fitted k range of the Nseries analysis [h/Mpc]
NSERIES_MARG = ["alpha0", "alpha2", "alpha4", "sn", "sn2"]


def label_of(name):
    """A parameter's label in the tables: b1[nseries] as b1[ngc] is, b1."""
    return LABELS.get(name, name.split("[")[0])


def ngc(out, _):
    """The BOSS DR12 CMASS NGC analysis of examples/posterior_vs_profile.py and its report's words."""
    path, common, lik, _ = ngc_likelihood(out)
    return dict(
        path=path, common=common, lik=lik, label="ngc", stem="nuts_vs_cobaya", truth=None,
        title="BOSS DR12 CMASS NGC",
        source="`pt.AnalysisLikelihood` of `examples/posterior_vs_profile.py`",
        likelihood="P0, P2 of BOSS DR12 CMASS NGC at 0.01 ≤ k ≤ 0.2 h/Mpc, MD-Patchy covariance "
                   "(Hartlap), the survey window, AP from the BOSS fiducial; free f, b1, b2, bs, α∥, α⊥; "
                   "α0, α2, sn, sn2 marginalised analytically; the file's Gaussian priors inside it")


def nseries(out, folder):
    """The Nseries analysis: the mean P0, P2, P4 of the 84 mocks (k <= 0.2 in the file) with one mock's
    structured covariance (examples/nseries_fits.py) times its inverse-bias factor for the fitted
    block, the true cosmology's CAMB template, AP against the fiducial of the measurement, the NGC
    analysis's free and marginalised parameters (alpha4 with P4) and priors."""
    plin = out / "nuts_nseries_plin_z0.56.dat"
    true_ini, fid_ini = out / "nuts_nseries_true.ini", out / "nuts_nseries_fiducial.ini"
    truth = ns.camb_truth(plin)
    ns.write_ini(true_ini, ns.TRUE, "Nseries true cosmology (README): flat, massless neutrinos")
    ns.write_ini(fid_ini, ns.FID, "Nseries fiducial (Omega_m = 0.310, h = 0.676): only H(z), D_M(z) matter")
    k, p = ns.load_mocks(folder)
    keep = k <= ns.K_CUT + 1e-9
    k, p = k[keep], p[:, keep, :]
    c1, _ = ns.structured_covariance(p)
    fitted = np.tile((k >= NSERIES_K[0]) & (k <= NSERIES_K[1]), 3)
    factor, factor_err = ns.inverse_bias(c1, len(k), fitted, np.random.default_rng(25))
    data, cov = out / "nuts_nseries_mean.dat", out / "nuts_nseries_cov_mock_l024.dat"
    ns.write_data(data, k, p.mean(0), np.sqrt(np.diag(c1)).reshape(3, -1).T,
                  f"mean of the {ns.N_MOCKS} Nseries mocks, k <= {ns.K_CUT}; errors: one mock's scatter")
    ns.write_matrix(cov, c1 * factor)
    quote = lambda items: ", ".join(f'"{i}"' for i in items)  # noqa: E731
    free = ns.FREE.split(",") + ["apar", "aperp"]
    priors = [q for q in ns.PRIORS if q.split(":")[0] in free + NSERIES_MARG]
    path = out / "nuts_nseries.toml"
    path.write_text("\n".join([
        "# The mean of the 84 Nseries mocks with one mock's covariance, written by "
        "examples/nuts_vs_cobaya.py", "",
        "[search]", "starts = 8", "seed = 1", 'linear = "marginalised"', "",
        "[[dataset]]", 'label = "nseries"', f'data = "{data}"', "data_ells = [0, 2, 4]",
        f'covariance = "{cov}"', f"z = {ns.Z}", 'tracer = "CMASS"', "ells = [0, 2, 4]",
        f"k_min = {NSERIES_K[0]}", f"k_max = {NSERIES_K[1]}", f"free = [{quote(free)}]",
        f"marginalise = [{quote(NSERIES_MARG)}]", f"priors = [{quote(priors)}]",
        f'fiducial = "{fid_ini}"', "[dataset.start]", "b1 = 2.0", ""]))
    common = dict(linear=str(plin), z_input=ns.Z, cosmology=str(true_ini), precision="fast")
    lik = pt.AnalysisLikelihood(path, **common)
    return dict(
        path=path, common=common, lik=lik, label="nseries", stem="nuts_vs_cobaya_nseries", truth=truth,
        title="Nseries mocks (mean of 84, one mock's covariance)",
        source="`pt.AnalysisLikelihood` of the analysis file it writes, `nuts_nseries.toml`",
        likelihood=f"the mean P0, P2, P4 of the {ns.N_MOCKS} Nseries mocks (window-free, z = {ns.Z}) at "
                   f"{NSERIES_K[0]} ≤ k ≤ {NSERIES_K[1]} h/Mpc ({lik.points} points), the covariance of "
                   "one mock (the structured covariance of `examples/nseries_fits.py` times its "
                   f"inverse-bias factor {factor:.3f} ± {factor_err:.3f} for the fitted block), no "
                   "window, the true cosmology's CAMB template, AP from the measurement's fiducial "
                   "(Ω_m = 0.310, h = 0.676); free f, b1, b2, bs, α∥, α⊥; α0, α2, α4, sn, sn2 "
                   "marginalised analytically; priors N(0, 5²) on b2, bs and the NGC file's on the "
                   "marginalised ones, inside −2 ln L")


DATA = {"ngc": ngc, "nseries": nseries}


def nuts_chain(job):
    """One NUTS chain (a worker process: its own library object and JAX) from `start`, dense mass
    matrix and step size adapted in the warm-up: (draws (samples, parameters), leapfrog steps of the
    sampling phase, divergences, seconds)."""
    analysis_path, common, start, warmup, samples, seed = job
    import jax

    jax.config.update("jax_enable_x64", True)
    import jax.numpy as jnp
    import numpyro
    import numpyro.distributions as dist
    from numpyro.infer import MCMC, NUTS, init_to_value

    import pt_spectra.jax as ptj

    lik = pt.AnalysisLikelihood(analysis_path, **common)
    ln_l = ptj.log_likelihood(lik)

    def model():
        x = [numpyro.sample(n, dist.Uniform(a, b)) for n, (a, b) in zip(lik.names, lik.bounds)]
        numpyro.factor("ln_L", ln_l(jnp.stack(x)))

    kernel = NUTS(model, dense_mass=True, init_strategy=init_to_value(values=dict(zip(lik.names, start))))
    mcmc = MCMC(kernel, num_warmup=warmup, num_samples=samples, num_chains=1, progress_bar=False)
    t = time.time()
    mcmc.run(jax.random.PRNGKey(seed), extra_fields=("num_steps", "diverging"))
    extra = mcmc.get_extra_fields()
    s = mcmc.get_samples()
    return (np.column_stack([np.asarray(s[n]) for n in lik.names]), int(np.sum(extra["num_steps"])),
            int(np.sum(extra["diverging"])), time.time() - t)


def nuts(path, common, lik, best, sigma, chains, warmup, samples, seed, workers):
    """`chains` NUTS chains from the best fit displaced by up to 2 Hessian sigma (inside the bounds),
    `workers` at a time in separate processes (one core each): draws (chains, samples, parameters),
    leapfrog steps per chain, divergences."""
    import concurrent.futures as cf
    import multiprocessing as mp

    rng = np.random.default_rng(seed)
    lo = np.array([a for a, _ in lik.bounds])
    hi = np.array([b for _, b in lik.bounds])
    jobs = []
    for c in range(chains):
        start = np.clip(best + 2.0 * sigma * rng.uniform(-1, 1, len(best)), lo + 1e-3 * (hi - lo),
                        hi - 1e-3 * (hi - lo))
        jobs.append((str(path), common, start, warmup, samples, seed * 100 + c))
    os.environ.setdefault("RAYON_NUM_THREADS", "1")  # the workers' library: one thread each
    with cf.ProcessPoolExecutor(workers, mp_context=mp.get_context("spawn")) as pool:
        results = list(pool.map(nuts_chain, jobs))
    for c, (_, steps, div, secs) in enumerate(results):
        log(f"NUTS chain {c + 1}/{chains}: {secs:.0f} s, {steps} leapfrog steps after the warm-up, "
            f"{div} divergent")
    return (np.stack([r[0] for r in results]), [r[1] for r in results], sum(r[2] for r in results))


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--data", default="ngc", choices=sorted(DATA))
    ap.add_argument("--nseries", default=ns.DEFAULT_DATA, type=Path,
                    help="the folder of pk_nseries<i>_fkp.txt (with --data nseries)")
    ap.add_argument("--out", default=DEFAULT_OUT, type=Path)
    ap.add_argument("--chains", default=4, type=int)
    ap.add_argument("--warmup", default=500, type=int)
    ap.add_argument("--samples", default=1500, type=int)
    ap.add_argument("--workers", default=2, type=int)
    ap.add_argument("--rminus1", default=0.01, type=float)
    ap.add_argument("--cobaya-chain", type=Path)
    ap.add_argument("--seed", default=1, type=int)
    args = ap.parse_args()
    if args.chains < 2:
        sys.exit("--chains: R - 1 needs at least 2 chains")
    args.out.mkdir(parents=True, exist_ok=True)
    from numpyro.diagnostics import effective_sample_size, split_gelman_rubin

    t0 = time.time()
    spec = DATA[args.data](args.out, args.nseries)
    path, common, lik, label = spec["path"], spec["common"], spec["lik"], spec["label"]
    s8 = lik.sigma8_z[label]
    log(f"likelihood: {', '.join(lik.names)}; {lik.points} points; exact gradient {lik.exact_gradient}")
    x, m_best = minimise(lik, lik.start)
    for start in (x, np.array([2.0 if n.startswith("b1") else v for n, v in zip(lik.names, lik.start)])):
        y, m = minimise(lik, start)
        if m < m_best:
            x, m_best = y, m
    cov = hessian(lik, x)
    sigma = np.sqrt(np.diag(cov))
    log(f"best fit -2 ln L = {m_best:.4f}; Hessian sigma {np.round(sigma, 4)}")

    # cobaya's posterior (read, or run as examples/posterior_vs_profile.py runs it)
    t = time.time()
    if args.cobaya_chain:
        table = np.loadtxt(args.cobaya_chain)
        names = open(args.cobaya_chain).readline().lstrip("#").split()
        w = table[:, 0]
        chain = {n: table[:, names.index(n)] for n in lik.names + ["fsigma8"]}
        cobaya_note = f"read from {args.cobaya_chain.name}"
    else:
        w, mlp, chain = sample(lik, x, cov, dict(analysis=str(path), **common), args.rminus1, args.seed,
                               label)
        cobaya_note = f"run here in {time.time() - t:.0f} s"
        saved = args.out / f"{spec['stem']}_cobaya.dat"
        np.savetxt(saved, np.column_stack([w, mlp] + [chain[n] for n in lik.names + ["fsigma8"]]),
                   header="weight minuslogpost " + " ".join(lik.names + ["fsigma8"]))
        log(f"cobaya's chain: {saved} (give it to --cobaya-chain to reuse)")
    n_eff_cobaya = w.sum() ** 2 / (w ** 2).sum()

    # NUTS: the library's gradient timed, then the chains
    t = time.time()
    for _ in range(20):
        lik.gradient(x)
    ms_gradient = (time.time() - t) / 20 * 1e3
    t = time.time()
    draws, steps, divergent = nuts(path, common, lik, x, sigma, args.chains, args.warmup, args.samples,
                                   args.seed, args.workers)
    t_nuts = time.time() - t
    fs8 = draws[:, :, lik.names.index("f")] * s8
    full = np.concatenate([draws, fs8[:, :, None]], axis=2)
    rhat = np.array([split_gelman_rubin(full[:, :, j]) for j in range(full.shape[2])])
    ess = np.array([effective_sample_size(full[:, :, j]) for j in range(full.shape[2])])
    names = lik.names + ["fsigma8"]
    rows = []
    for j, n in enumerate(names):
        v = full[:, :, j].ravel()
        m_n, s_n = v.mean(), v.std()
        m_c, s_c, *_ = weighted_stats(chain[n], w)
        rows.append((n, m_n, s_n, m_c, s_c, (m_n - m_c) / s_c, s_n / s_c - 1, rhat[j] - 1, ess[j],
                     cobaya_ess(chain[n], w, effective_sample_size)))
    report(args, spec, rows, dict(nuts=t_nuts, total=time.time() - t0, gradient=ms_gradient), cobaya_note,
           n_eff_cobaya, steps, divergent, s8)
    plot(args, spec, full, names, chain, w)


def cobaya_ess(x, w, effective_sample_size):
    """The effective sample size of cobaya's chain of x from its autocorrelation, each point repeated
    by its weight (cobaya's weights count the steps a point was kept); the weights' own ESS, an upper
    bound, if they are not integers."""
    if np.all(w == np.round(w)):
        return float(effective_sample_size(np.repeat(x, w.astype(int))[None, :]))
    return float(w.sum() ** 2 / (w ** 2).sum())


def report(args, spec, rows, times, cobaya_note, n_eff_cobaya, steps, divergent, s8):
    worst_mean = max(abs(r[5]) for r in rows)
    worst_width = max(abs(r[6]) for r in rows)
    grads = sum(steps)
    stem = spec["stem"]
    option = "" if args.data == "ngc" else f" --data {args.data}"
    out = [f"# NUTS on the exact gradient against cobaya's MCMC: {spec['title']}\n",
           f"Written by `examples/nuts_vs_cobaya.py{option}` (issue 47, part 6; {times['total']:.0f} s on "
           f"2 cores, NUTS {times['nuts']:.0f} s). One likelihood ({spec['source']}), two samplers: "
           "numpyro's NUTS through "
           "`pt_spectra.jax.log_likelihood` (the library's value and exact gradient as a JAX function) "
           "and cobaya's Metropolis MCMC (`pt_spectra.likelihoods.AnalysisFile`).\n",
           f"![NUTS and cobaya]({stem}.png)\n",
           "## Settings\n",
           f"- Likelihood: {spec['likelihood']}; σ8(z) = {s8:.4f}.",
           f"- NUTS: {args.chains} chains ({args.workers} processes at a time, one core each) from the best "
           "fit displaced by up to 2 Hessian σ, uniform priors on the likelihood's bounds, "
           f"{args.warmup} warm-up steps (step size and dense mass matrix adapted), {args.samples} draws "
           f"each, seed {args.seed}; {grads} leapfrog steps after the warm-up "
           f"({grads / (args.chains * args.samples):.1f} per draw), each one call of the library's value "
           f"and exact gradient ({times['gradient']:.1f} ms measured here); {divergent} divergent "
           "transitions; split R − 1 over the chains.",
           f"- cobaya: `mcmc` as in `examples/posterior_vs_profile.py` (R − 1 < {args.rminus1} on the means), "
           f"{cobaya_note}; effective sample size {n_eff_cobaya:.0f} (of the weights).\n",
           "## The table\n",
           "| parameter | NUTS mean ± std | cobaya mean ± std | (mean difference)/σ | width ratio − 1 | "
           "NUTS R − 1 | NUTS ESS | cobaya ESS |",
           "|---|---|---|---|---|---|---|---|"]
    for n, m_n, s_n, m_c, s_c, dm, dw, r1, ess, ess_c in rows:
        out.append(f"| {label_of(n)} | {m_n:.4f} ± {s_n:.4f} | {m_c:.4f} ± {s_c:.4f} | {dm:+.3f} | "
                   f"{100 * dw:+.1f}% | {r1:.4f} | {ess:.0f} | {ess_c:.0f} |")
    out.append("")
    ok = worst_mean <= 0.1 and worst_width <= 0.1
    out.append("## Verdict\n")
    out.append(f"- Means agree to {worst_mean:.3f}σ at worst and widths to {100 * worst_width:.1f}% "
               f"(the bound: 0.1σ and 10%): {'met' if ok else 'NOT met'}; max split R − 1 of NUTS "
               f"{max(r[7] for r in rows):.4f}.")
    noise = max(np.sqrt(1 / r[8] + 1 / r[9]) for r in rows)
    out.append("- The Monte Carlo error of a mean difference is σ √(1/ESS_NUTS + 1/ESS_cobaya), at most "
               f"{noise:.3f}σ here, and of a width ratio about √(1/(2 ESS_NUTS) + 1/(2 ESS_cobaya)), at "
               f"most {100 * noise / np.sqrt(2):.1f}% (cobaya's ESS from the autocorrelation of its chain, "
               f"each point repeated by its weight; the weights' own ESS, {n_eff_cobaya:.0f}, is an upper "
               "bound).")
    if spec["truth"]:
        t = spec["truth"]
        by = {r[0]: r for r in rows}
        pulls = ", ".join(f"{label_of(n)} {t[key]:.4f} ({(by[n][3] - t[key]) / by[n][4]:+.2f}σ)"
                          for n, key in (("fsigma8", "fsigma8"), ("apar", "apar"), ("aperp", "aperp")))
        out.append("- Against the truth of the mocks (CAMB, the true and fiducial cosmologies; the cobaya "
                   f"mean's distance in σ of one mock): {pulls}. Not a criterion here: the mean of the 84 "
                   "mocks (7 independent boxes) has noise of about σ/√7 ≈ 0.38σ of one mock, so offsets "
                   "of this size are not a model error (`examples/nseries_fits.py` tests the model "
                   "against the truth).")
    text = "\n".join(out) + "\n"
    (args.out / f"{stem}.md").write_text(text)
    print(text)
    log(f"wrote {args.out / stem}.md, .png")


def plot(args, spec, full, names, chain, w):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(2, 3, figsize=(10.5, 5.6))
    shown = ["fsigma8", "apar", "aperp"] + [f"{b}[{spec['label']}]" for b in ("b1", "b2", "bs")]
    for ax, n in zip(axes.ravel(), shown):
        j = names.index(n)
        v = full[:, :, j].ravel()
        lo, hi = np.percentile(np.concatenate([v, chain[n]]), [0.2, 99.8])
        bins = np.linspace(lo, hi, 40)
        ax.hist(chain[n], bins=bins, weights=w, density=True, histtype="step", color="C0", label="cobaya MCMC")
        ax.hist(v, bins=bins, density=True, histtype="step", color="C3", label="NUTS (pt_spectra.jax)")
        ax.set_xlabel(label_of(n))
        ax.set_yticks([])
    axes[0, 0].legend(fontsize=7, loc="upper left")
    fig.suptitle(f"{spec['title']}: NUTS on the exact gradient against cobaya's MCMC", fontsize=9)
    fig.tight_layout()
    fig.savefig(args.out / f"{spec['stem']}.png", dpi=120)


if __name__ == "__main__":
    main()
