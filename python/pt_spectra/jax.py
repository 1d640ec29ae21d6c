"""The JAX face of pt-spectra: its likelihoods and data vectors as JAX functions with exact derivatives.

Gradient samplers (numpyro's or blackjax's NUTS, HMC, MCLMC) and gradient minimisers need d/dθ of
the log-likelihood. The library computes it exactly (no finite differences); this module hands it
to JAX, so that the functions below work under ``jax.jit``, ``jax.grad``, ``jax.jvp``,
``jax.vjp`` and ``jax.vmap``:

- :func:`log_likelihood`: ln L(x) of a :class:`pt_spectra.AnalysisLikelihood` (the likelihood of an
  analysis file: data sets summed, the linear parameters marginalised analytically, every prior of
  the file included), x in the order of its ``names``; the gradient is the library's exact one.
- :func:`data_vector`: the data vector of a :class:`pt_spectra.Pipeline` as a function of its
  nuisance parameters, f and the sampled cosmological parameters (by name); the Jacobian is the
  pipeline's exact one (``pipeline(..., jacobian=True)``, ``pipeline.cosmology_jacobian``).

Each is a ``jax.custom_jvp`` around ``jax.pure_callback``: the value and the derivative are computed
by the library on the host (one core; not traced, not on an accelerator), the tangent is linear in
the input tangent, so JAX transposes it for reverse mode. ``vmap`` calls the library once per batch
member. The library computes in float64: enable JAX's 64-bit mode first
(``jax.config.update("jax_enable_x64", True)``, or ``numpyro.enable_x64()``); building a function
without it raises ``ValueError``.

Not differentiable here: likelihoods and pipelines with a bispectrum (their gradient is not
exact; both functions refuse them).

JAX is an optional dependency: ``pip install "./python[jax]"`` (jax; numpyro for the example
``examples/nuts_vs_cobaya.py``).
"""

from __future__ import annotations

import numpy as np

try:
    import jax
    import jax.numpy as jnp
except ImportError as error:  # pragma: no cover - exercised only without jax
    raise ImportError(
        "pt_spectra.jax needs JAX: pip install jax (or the extra: pip install './python[jax]')"
    ) from error

__all__ = ["log_likelihood", "data_vector"]


def _require_x64():
    if not jax.config.jax_enable_x64:
        raise ValueError(
            "pt_spectra.jax computes in float64 and JAX's 64-bit mode is off: call "
            "jax.config.update('jax_enable_x64', True) (numpyro: numpyro.enable_x64()) first"
        )


def _checked(x, n, what):
    """x as a float64 vector of length n (a trace-time error naming `what` otherwise)."""
    x = jnp.asarray(x, dtype=jnp.float64)
    if x.shape != (n,):
        raise ValueError(f"{what}: expected a vector of {n} values, got shape {x.shape}")
    return x


def _host_function(value, value_and_derivative, shape, derivative_shape, n, what):
    """A JAX function of a vector of n values computed on the host: ``value(x)`` (an array of
    ``shape``), its tangent ``t @ D`` from ``value_and_derivative(x)`` = (value, D), D of
    ``derivative_shape`` (rows: the inputs); a ``jax.custom_jvp`` around ``jax.pure_callback``."""
    out = jax.ShapeDtypeStruct(shape, jnp.float64)
    derivative = jax.ShapeDtypeStruct(derivative_shape, jnp.float64)

    @jax.custom_jvp
    def f(x):
        return jax.pure_callback(value, out, x, vmap_method="sequential")

    @f.defjvp
    def _(primals, tangents):
        (x,), (t,) = primals, tangents
        v, d = jax.pure_callback(value_and_derivative, (out, derivative), x, vmap_method="sequential")
        return v, t @ d

    def function(x):
        return f(_checked(x, n, what))

    return function


def log_likelihood(likelihood):
    """ln L(x) = -(-2 ln L)/2 of ``likelihood`` (a :class:`pt_spectra.AnalysisLikelihood`) as a JAX
    function of x, a vector in the order of ``likelihood.names``, with its exact gradient.

    The value is the likelihood's (up to the constant the fit also omits); a point outside
    ``likelihood.bounds`` raises ``ValueError`` from the library when evaluated (sample inside the
    bounds: a uniform prior on them, as the cobaya likelihood has).

    Raises ``ValueError`` if JAX's 64-bit mode is off or the likelihood has no exact gradient (a data
    set with a bispectrum).
    """
    _require_x64()
    if not likelihood.exact_gradient:
        raise ValueError("this likelihood has no exact gradient (a data set with a bispectrum): "
                         "pt_spectra.jax differentiates only exact gradients")
    n = len(likelihood.names)

    def value(x):
        return np.float64(-0.5 * likelihood(np.asarray(x, dtype=float)))

    def value_and_gradient(x):
        v, g = likelihood.gradient(np.asarray(x, dtype=float))
        return np.float64(-0.5 * v), -0.5 * np.asarray(g, dtype=np.float64)

    function = _host_function(value, value_and_gradient, (), (n,), n, "log_likelihood")
    function.names = list(likelihood.names)
    function.bounds = list(likelihood.bounds)
    return function


def data_vector(pipeline, names, cosmology=None, linear=None, z_input=None, **fixed):
    """The data vector of ``pipeline`` (a :class:`pt_spectra.Pipeline` without a bispectrum block)
    at one cosmology or linear spectrum (``cosmology``, ``linear``, ``z_input`` as a call takes them)
    as a JAX function of the values of ``names`` (a vector in that order), the other parameters
    fixed by ``fixed`` (by name; unset nuisance parameters are 0, f defaults to f(z)), with its
    exact Jacobian.

    ``names`` are from ``pipeline.nuisance`` (the nuisance parameters and f) and from
    ``pipeline.cosmological_parameters`` (h, omega_b, omega_cdm, ln10^{10}A_s, n_s, m_nu, w0, wa:
    through the emulator, the growth, the loops, AP; ``Pipeline.cosmology_jacobian``). With
    cosmological names, ``cosmology`` is a dict of CLASS names (the values of the names not free,
    e.g. ``{"h": 0.68, "omega_b": 0.0224, "omega_cdm": 0.12, "ln10^{10}A_s": 3.04, "n_s": 0.965}``)
    and ``linear`` is not given; f, unless free or fixed, follows the cosmology.

    Raises ``ValueError`` if JAX's 64-bit mode is off, a name is unknown or repeated, a name is both
    free and fixed, or a free cosmological parameter is also spelled otherwise in ``cosmology``
    (e.g. ``H0`` with ``h`` free).
    """
    _require_x64()
    nuisance = list(pipeline.nuisance)
    sampled = list(pipeline.cosmological_parameters)
    names = list(names)
    unknown = [n for n in names if n not in nuisance + sampled]
    if unknown or len(set(names)) != len(names):
        raise ValueError(f"data_vector: names must be distinct, from {', '.join(nuisance + sampled)}"
                         + (f"; unknown: {', '.join(unknown)}" if unknown else ""))
    both = sorted(set(names) & set(fixed))
    if both:
        raise ValueError(f"data_vector: {', '.join(both)} both free (names) and fixed")
    if pipeline.meta["bispectrum"]:
        raise ValueError("data_vector: the pipeline has a bispectrum block, whose Jacobian is not "
                         "exact; build the pipeline without triangles")
    free_cosmology = [n for n in names if n in sampled]
    if free_cosmology:
        if linear is not None or not isinstance(cosmology, dict):
            raise ValueError("data_vector: free cosmological parameters need `cosmology` as a dict "
                             "of CLASS names (and no `linear`)")
        spellings = {"h": ("H0", "hubble"), "omega_b": ("Omega_b", "ombh2"),
                     "omega_cdm": ("Omega_cdm", "omch2"),
                     "ln10^{10}A_s": ("A_s", "As", "scalar_amp(1)", "sigma8"),
                     "n_s": ("ns", "scalar_spectral_index(1)"),
                     "m_nu": ("mnu", "m_ncdm", "omnuh2"), "w0": ("w0_fld", "w"), "wa": ("wa_fld",)}
        clash = [f"{o} (with {n} free)" for n in free_cosmology for o in spellings[n] if o in cosmology]
        if clash:
            raise ValueError(f"data_vector: cosmology also gives {', '.join(clash)}: spell the free "
                             "parameters by their CLASS names only")
    nuisance_rows = [(i, nuisance.index(n)) for i, n in enumerate(names) if n in nuisance]
    cosmology_rows = [i for i, n in enumerate(names) if n in sampled]  # the order of free_cosmology

    def split(x):
        x = np.asarray(x, dtype=float)
        params = {**fixed, **{names[i]: float(x[i]) for i, _ in nuisance_rows}}
        if not free_cosmology:
            return cosmology, params
        return {**cosmology, **{names[i]: float(x[i]) for i in cosmology_rows}}, params

    where = dict(linear=linear, z_input=z_input)
    m = len(pipeline(cosmology=cosmology, **where, **fixed))

    def value(x):
        c, params = split(x)
        return np.asarray(pipeline(cosmology=c, **where, **params), dtype=np.float64)

    def value_and_jacobian(x):
        c, params = split(x)
        jacobian = np.zeros((len(names), m))
        if cosmology_rows:
            # one step for both sets of rows, the free cosmological columns only
            v, n, j = pipeline.full_jacobian(c, derivatives=free_cosmology, **params)
            for row, i in enumerate(cosmology_rows):
                jacobian[i] = j[row]
        else:
            v, n = pipeline(cosmology=c, **where, jacobian=True, **params)
        for i, r in nuisance_rows:
            jacobian[i] = n[r]
        return np.asarray(v, dtype=np.float64), jacobian

    function = _host_function(value, value_and_jacobian, (m,), (len(names), m), len(names),
                              "data_vector")
    function.names = names
    return function
