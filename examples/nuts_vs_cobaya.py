"""NUTS on the library's exact gradient against cobaya's MCMC, one likelihood (issue 47, part 6): BOSS
DR12 CMASS NGC, the analysis of examples/posterior_vs_profile.py (f, b1, b2, bs, alpha_par, alpha_perp
free; alpha0, alpha2, sn, sn2 marginalised analytically; the survey window; k in [0.01, 0.2] h/Mpc).

numpyro's NUTS samples `pt_spectra.jax.log_likelihood` of `pt.AnalysisLikelihood` (JAX calls the library
for the value and its exact gradient), with uniform priors on the likelihood's bounds, as cobaya's run
of examples/posterior_vs_profile.py has; several chains from dispersed starts, two at a time in
separate processes; the split R - 1 of every parameter against the target. The two posteriors must
agree: means within 0.1 sigma, widths within 10%.

Writes examples/out/nuts_vs_cobaya.md (settings, table, verdict) and .png (the marginals of both).

    python3 examples/nuts_vs_cobaya.py [--out DIR] [--chains 4] [--warmup 500] [--samples 1500]
                                       [--workers 2] [--rminus1 0.01] [--cobaya-chain FILE] [--seed S]

--cobaya-chain: the .dat examples/posterior_vs_profile.py writes (weight, minuslogpost, parameters,
fsigma8); without it cobaya's chain is run here (about 2 minutes) and saved as nuts_vs_cobaya_cobaya.dat. Needs numpy, scipy, matplotlib, camb
(the template), jax and numpyro (`pip install "./python[jax]"`), cobaya without --cobaya-chain. About
12 minutes on 2 cores with the defaults (712 s measured with the cobaya chain read: 4 chains of 2000
steps, 19 leapfrog steps per draw at 3.9 ms each), 2 more to run cobaya's chain.
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

import pt_spectra as pt  # noqa: E402

SHOWN = ["fsigma8", "apar", "aperp", "b1[ngc]", "b2[ngc]", "bs[ngc]"]


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
    path, common, lik, _ = ngc_likelihood(args.out)
    s8 = lik.sigma8_z["ngc"]
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
        w, mlp, chain = sample(lik, x, cov, dict(analysis=str(path), **common), args.rminus1, args.seed)
        cobaya_note = f"run here in {time.time() - t:.0f} s"
        saved = args.out / "nuts_vs_cobaya_cobaya.dat"
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
        rows.append((n, m_n, s_n, m_c, s_c, (m_n - m_c) / s_c, s_n / s_c - 1, rhat[j] - 1, ess[j]))
    report(args, rows, dict(nuts=t_nuts, total=time.time() - t0, gradient=ms_gradient), cobaya_note,
           n_eff_cobaya, steps, divergent, s8)
    plot(args, full, names, chain, w)


def report(args, rows, times, cobaya_note, n_eff_cobaya, steps, divergent, s8):
    worst_mean = max(abs(r[5]) for r in rows)
    worst_width = max(abs(r[6]) for r in rows)
    grads = sum(steps)
    out = ["# NUTS on the exact gradient against cobaya's MCMC: BOSS DR12 CMASS NGC\n",
           f"Written by `examples/nuts_vs_cobaya.py` (issue 47, part 6; {times['total']:.0f} s on 2 cores, "
           f"NUTS {times['nuts']:.0f} s). One likelihood (`pt.AnalysisLikelihood` of "
           "`examples/posterior_vs_profile.py`), two samplers: numpyro's NUTS through "
           "`pt_spectra.jax.log_likelihood` (the library's value and exact gradient as a JAX function) "
           "and cobaya's Metropolis MCMC (`pt_spectra.likelihoods.AnalysisFile`).\n",
           "![NUTS and cobaya](nuts_vs_cobaya.png)\n",
           "## Settings\n",
           "- Likelihood: P0, P2 of BOSS DR12 CMASS NGC at 0.01 ≤ k ≤ 0.2 h/Mpc, MD-Patchy covariance "
           "(Hartlap), the survey window, AP from the BOSS fiducial; free f, b1, b2, bs, α∥, α⊥; α0, α2, "
           f"sn, sn2 marginalised analytically; the file's Gaussian priors inside it; σ8(z) = {s8:.4f}.",
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
           "NUTS R − 1 | NUTS ESS |",
           "|---|---|---|---|---|---|---|"]
    for n, m_n, s_n, m_c, s_c, dm, dw, r1, ess in rows:
        out.append(f"| {LABELS.get(n, n)} | {m_n:.4f} ± {s_n:.4f} | {m_c:.4f} ± {s_c:.4f} | {dm:+.3f} | "
                   f"{100 * dw:+.1f}% | {r1:.4f} | {ess:.0f} |")
    out.append("")
    ok = worst_mean <= 0.1 and worst_width <= 0.1
    out.append("## Verdict\n")
    out.append(f"- Means agree to {worst_mean:.3f}σ at worst and widths to {100 * worst_width:.1f}% "
               f"(the bound: 0.1σ and 10%): {'met' if ok else 'NOT met'}; max split R − 1 of NUTS "
               f"{max(r[7] for r in rows):.4f}.")
    out.append("- The Monte Carlo error of a mean is σ/√ESS: about "
               f"{1 / np.sqrt(min(r[8] for r in rows)):.3f}σ for NUTS and {1 / np.sqrt(n_eff_cobaya):.3f}σ "
               "for cobaya (its weights' ESS, an upper bound on its independent samples).")
    text = "\n".join(out) + "\n"
    (args.out / "nuts_vs_cobaya.md").write_text(text)
    print(text)
    log(f"wrote {args.out / 'nuts_vs_cobaya.md'}, .png")


def plot(args, full, names, chain, w):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(2, 3, figsize=(10.5, 5.6))
    for ax, n in zip(axes.ravel(), SHOWN):
        j = names.index(n)
        v = full[:, :, j].ravel()
        lo, hi = np.percentile(np.concatenate([v, chain[n]]), [0.2, 99.8])
        bins = np.linspace(lo, hi, 40)
        ax.hist(chain[n], bins=bins, weights=w, density=True, histtype="step", color="C0", label="cobaya MCMC")
        ax.hist(v, bins=bins, density=True, histtype="step", color="C3", label="NUTS (pt_spectra.jax)")
        ax.set_xlabel(LABELS.get(n, n))
        ax.set_yticks([])
    axes[0, 0].legend(fontsize=7, loc="upper left")
    fig.suptitle("BOSS DR12 CMASS NGC: NUTS on the exact gradient against cobaya's MCMC", fontsize=9)
    fig.tight_layout()
    fig.savefig(args.out / "nuts_vs_cobaya.png", dpi=120)


if __name__ == "__main__":
    main()
