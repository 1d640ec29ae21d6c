"""The fits of the Python face: ``fit_ept``, ``fit_joint``, ``fit``, ``fit_tables`` and the analysis
likelihood kept between calls (re-exported by :mod:`pt_spectra`)."""

from __future__ import annotations

import numpy as np

from . import _core
from ._common import _D, _ept_params, _warn
from ._core import Table

__all__ = ["AnalysisLikelihood", "fit", "fit_ept", "fit_joint", "fit_tables"]


def fit_ept(data, k_max, free=("f", "b1"), marginalise=(), priors=None, ells=(0, 2),
            data_ells=(0, 2, 4), data_columns=None, covariance=None, k_min=0.0, ir=True, apar=None,
            aperp=None, linear=None, z=0.0, z_input=0.0, cosmology=None, precision=_D["precision"],
            q_range=None, eh=None, n_mocks=None, k_ranges=None, window=None,
            window_mixing="wilson", k_edges=None, box=None, xi=False, s_edges=None, window_format=None,
            starts=8, seed=1, profile_check=True, profile_linear=False, profile=None,
            profile_points=21, profile_span=3.0, model_out=False, basis="velocileptors", n_bar=None,
            satellites=None, desi_priors=False, **start):
    """Fits of the galaxy model ``ept`` (``pt-spectra fit --rsd ept``), one row per k_max.

    data, data_ells, data_columns, k_min as :func:`fit`; covariance: a path (as ``--covariance``)
    or a 2-D array; k_max: a list. free: any of
    the model's parameters (see :class:`EptPlan`); marginalise: linear ones (alpha0, alpha2, alpha4,
    alpha6, sn, sn2, sn4) marginalised analytically; priors: ``{"b2": (0.0, 1.0), …}`` Gaussian
    (mean, sigma), ``{"f": ("flat", 0.0, 2.0)}`` or ``("lognormal", mu, sigma)`` (of ln x), or the
    command line's text ``"flat,0,2"``. ``start``: start values of the free parameters and values of
    the fixed ones
    (e.g. ``b1=2.0, f=0.7``; f defaults to f(z)). n_mocks: the Hartlap factor of a covariance from
    that many mocks. apar, aperp: the measurement's distortion (free with ``free=(…, "apar",
    "aperp")``). k_ranges: ``{4: (0.02, 0.1)}`` narrows the range of a multipole. window (a file of
    Q_ℓ(s) or a window matrix, as ``rsd --window``), window_mixing ("wilson" or "classpt-boss"),
    window_format (the columns of a Q_ℓ(s) file without a names line: ``"s,Q0,Q2,Q4"``, ``"boss"``,
    as ``--window-format``; default: the file's names line ``# s Q0 Q2 Q4``), k_edges [h/Mpc] (k²-weighted bins; with box [Mpc/h] the modes of a periodic box): the model
    goes through them before the comparison. xi=True: the data are ξ_ℓ(s) (s [Mpc/h] in place of k;
    k_min, k_max, k_ranges in s), optionally averaged over s_edges.

    The minimiser (as ``fit --starts --seed --no-profile-check --profile-linear``): ``starts``
    starts (the start given, then seeded draws from the priors or the start box), the lowest
    minimum taken; ``profile_check`` checks the Hessian errors on the profile likelihood;
    ``profile_linear`` profiles the linear parameters instead of marginalising them.

    ``basis="desi"`` (with ``n_bar`` [(h/Mpc)^3], optionally ``satellites=(f_sat, sigma_v)``, default
    (0.1, 5 Mpc/h)): free, marginalise and priors name the DESI DR1 physical basis (b1p = b1 sigma8(z),
    b2p, bsp, b3p, alpha0p, alpha2p, alpha4p, sn0p, sn2p, sn4p; docs/reference.md) and the table gives
    them, then the model's parameters they map to; ``desi_priors=True`` adds the DR1 priors of the
    free and marginalised ones that have none. ``basis="classpt"``: the bias as CLASS-PT names it
    (b1, b2, bG2, bGamma3, mapped exactly: docs/reference.md, "Bias conventions"), the counterterms
    and stochastic terms velocileptors'. The start keywords stay the model's (b1=, f=, ...).

    Columns: ``k_max`` (``s_max``) ``points chi2 minus_2_ln_L``, each parameter with ``err_<p>``
    for the free and marginalised ones; per free parameter ``err_<p>_hessian <p>_lo <p>_hi
    err_<p>_from_profile`` (the Δ(−2 ln L) = 1 interval; err_<p> is its half-width where it differs
    from the Hessian's by > 10%); ``starts starts_agree starts_spread``; the derived ``fsigma8
    sigma8_z`` and, with a distortion, ``alpha_iso alpha_ap DM_over_DH DV_over_rd`` with errors.

    ``profile="f"`` (one k_max): the profile likelihood of that free parameter instead, on
    ``profile_points`` values over ± ``profile_span`` fitted errors (columns ``<p> minus_2_ln_L
    delta_minus_2_ln_L chi2`` and the others there). ``model_out=True`` returns ``(table, model)``,
    the model the best-fit multipoles of every k_max (``--model-out``).
    """
    table, model = _core.fit_ept(data, list(k_max), list(free), list(marginalise), priors, list(ells),
                                 list(data_ells), None if data_columns is None else list(data_columns),
                                 covariance, k_min, ir, apar, aperp, linear, z, z_input, cosmology,
                                 precision, q_range, eh, n_mocks,
                                 None if k_ranges is None else {int(l): tuple(map(float, r))
                                                                for l, r in k_ranges.items()},
                                 None if window is None else str(window), window_mixing,
                                 k_edges, box, bool(xi), s_edges, window_format, int(starts), int(seed),
                                 bool(profile_check), bool(profile_linear), profile, int(profile_points),
                                 float(profile_span), bool(model_out), str(basis),
                                 None if n_bar is None else float(n_bar),
                                 None if satellites is None else tuple(map(float, satellites)),
                                 bool(desi_priors), **_ept_params(start))
    if model_out:
        return _warn(table), _warn(model)
    return _warn(table)


def fit_joint(analysis, linear=None, z_input=0.0, cosmology=None, precision=_D["precision"],
              q_range=None, eh=None):
    """The joint fit of the galaxy model ``ept`` to several data sets (``pt-spectra fit --analysis``).

    analysis: the path of a TOML analysis file (docs/analysis.md): per ``[[dataset]]`` its data,
    covariance, window, z, multipoles, k range, free and marginalised parameters, priors and start;
    ``shared``: the parameters with one value across the sets (default f, apar, aperp when every set
    has the same z and tracer); ``[search]``: the minimiser (starts, seed, profile_check, linear).
    linear, z_input, cosmology, precision, q_range, eh as :func:`fit_ept`; each set is at its own z.

    Returns a :class:`Table` with a row per data set: ``set z`` then the columns of :func:`fit_ept`
    for that set at the joint best fit (a shared parameter has the same value and error in every
    row); the header states every set and the sharing.
    """
    return _warn(_core.fit_joint(str(analysis), linear, z_input, cosmology, precision, q_range, eh))


class AnalysisLikelihood:
    """The likelihood of an analysis file (docs/analysis.md), kept between calls: the function
    :func:`fit_joint` minimises, for samplers (cobaya, an MCMC, HMC/NUTS on its exact gradient).

    ``AnalysisLikelihood(analysis, linear=None, z_input=0.0, cosmology=None, precision="default",
    q_range=None, eh=None)`` loads every data set once (arguments as :func:`fit_joint`). Then:

    - ``names``: the free parameters (a shared one by its name, a set's own as ``name[label]``);
      ``bounds``: their (lower, upper) ranges, the fit's (a value outside raises ``ValueError``);
      ``start``: the file's start values; ``sigma8_z``: ``{label: sigma8(z)}`` of each set's template
      (f sigma8 = f sigma8(z)); ``header``: what it is; ``exact_gradient``, ``points``.
    - ``lik(x)`` or ``lik(**params)``: -2 ln L (the sets' sum; linear parameters marginalised
      analytically with their ln det F, or profiled, as the file's ``[search] linear``; every prior
      of the file included), x in the order of ``names``.
    - ``lik.loglike(params)``: ln L = -(-2 ln L)/2 of a dict by name, for cobaya's external
      likelihoods (ln L up to the constant the fit also omits).
    - ``lik.gradient(x)``: (-2 ln L, its exact gradient as an array) (``ValueError`` for a
      likelihood with a bispectrum, whose gradient is not exact).
    """

    def __init__(self, analysis, linear=None, z_input=0.0, cosmology=None, precision=_D["precision"],
                 q_range=None, eh=None):
        self._lik = _core.AnalysisLikelihood(str(analysis), linear, z_input, cosmology, precision,
                                             q_range, eh)
        self.names = list(self._lik.names)
        self.bounds = [tuple(b) for b in self._lik.bounds]
        self.start = np.array(self._lik.start)
        self.sigma8_z = dict(self._lik.sigma8_z)
        self.header = list(self._lik.header)
        self.exact_gradient = self._lik.exact_gradient
        self.points = self._lik.points

    def _vector(self, x, params):
        if x is not None and params:
            raise ValueError("give the values either as a sequence or by name, not both")
        if x is None:
            unknown = sorted(set(params) - set(self.names))
            missing = [n for n in self.names if n not in params]
            if unknown or missing:
                raise ValueError(f"the likelihood's parameters are {', '.join(self.names)}"
                                 + (f"; unknown: {', '.join(unknown)}" if unknown else "")
                                 + (f"; missing: {', '.join(missing)}" if missing else ""))
            x = [params[n] for n in self.names]
        return [float(v) for v in np.asarray(x, dtype=float).ravel()]

    def __call__(self, x=None, **params):
        return self._lik.minus_two_log_l(self._vector(x, params))

    def loglike(self, params):
        return -0.5 * self._lik.minus_two_log_l(self._vector(None, dict(params)))

    def gradient(self, x=None, **params):
        found = self._lik.value_and_gradient(self._vector(x, params))
        if found is None:
            raise ValueError("this likelihood has no exact gradient (a data set with a bispectrum)")
        return found[0], np.array(found[1])


def fit(data, k_max, free=("f", "sigma0"), ells=(0,), data_ells=(0, 2, 4), data_columns=None,
        covariance=None, rsd=_D["rsd_model"], real=_D["fit_real_model"], fog=_D["fit_fog"], f=None,
        sigma0=float(_D["fit_sigma0"]), bias=1.0, amplitude=1.0, shot_noise=None,
        number_density=None, noise_table=None, k_min=0.0, linear=None, z=0.0, z_input=0.0,
        cosmology=None, precision=_D["precision"], q_range=None,
        cache_dir=None, eh=None, cs2=0.0, **ept_options) -> Table:
    """Fits of f, sigma0, A_b and the EFT counterterm c_s^2 (``free``, of ``"f"``, ``"sigma0"``,
    ``"ab"``, ``"cs2"``) to measured multipoles (``pt-spectra fit``). ``rsd="ept"`` fits the galaxy
    model (:func:`fit_ept`: ``bias`` is the start b1; ``marginalise``, ``priors``, ``n_mocks``, ``ir``,
    ``apar``, ``aperp`` and start values by name as keyword arguments).

    data: a file (columns ``k P0 s0 P2 s2 P4 s4``, or ``data_columns`` 1-based for ``data_ells``) or a
    dict ``{"k": …, "P0": …, "s0": …, …}`` with the multipoles of ``ells``. k_max: a list of k_max
    [h/Mpc], one fit (one row) each. covariance: the full covariance of the fitted data vector
    (ell-major), default diagonal. f, sigma0, amplitude, cs2 [(Mpc/h)^2, as in :func:`real`]: start
    values if free, values if fixed;
    sigma0 may be ``"lin"`` or ``"1l-spt"`` (the theory value, as in :func:`rsd`). With a fog, the
    columns ``sigma0_lin sigma0_1l`` give the theory sigma0.
    Returns ``k_max points <p> <p>_lo <p>_hi … chi2 dof chi2_dof``.
    """
    if str(rsd).lower() == "ept":
        return fit_ept(data, k_max, free=free, ells=ells, data_ells=data_ells,
                       data_columns=data_columns, covariance=covariance, k_min=k_min, linear=linear,
                       z=z, z_input=z_input, cosmology=cosmology, precision=precision,
                       q_range=q_range, eh=eh, b1=bias, f=f, **ept_options)
    if ept_options:
        raise ValueError(f"{', '.join(ept_options)}: options of rsd='ept', not of rsd={rsd!r}")
    return fit_tables(data, k_max, free, ells, data_ells, data_columns, covariance, rsd, real, fog, f,
                      sigma0, bias, amplitude, shot_noise, number_density, noise_table, k_min, linear,
                      z, z_input, cosmology, precision, q_range, cache_dir, eh, cs2)["fit"]


def fit_tables(data, k_max, free=("f", "sigma0"), ells=(0,), data_ells=(0, 2, 4), data_columns=None,
               covariance=None, rsd=_D["rsd_model"], real=_D["fit_real_model"],
               fog=_D["fit_fog"], f=None, sigma0=float(_D["fit_sigma0"]), bias=1.0, amplitude=1.0,
               shot_noise=None, number_density=None, noise_table=None, k_min=0.0, linear=None,
               z=0.0, z_input=0.0, cosmology=None, precision=_D["precision"],
               q_range=None, cache_dir=None, eh=None, cs2=0.0, model=False, contour=None,
               contour_points=41, contour_span=2.5) -> dict:
    """:func:`fit` with the command line's ``--model-out`` and ``--contour`` tables.

    Returns ``{"fit": Table, "model": Table or None, "contour": Table or None}``. model=True adds
    ``k P<l>_data err_P<l>_data P<l>_nw P<l>_kmax<K>``: the fitted data, the no-wiggle reference and the
    best-fit multipoles of each k_max over the whole data grid. contour=("f", "sigma0") (two free
    parameters) adds the Delta chi^2 surface ``k_max i j <p1> <p2> chi2 delta_chi2 <other free>`` on a
    ``contour_points`` x ``contour_points`` grid along the axes of the Delta chi^2 = 2.3 ellipse,
    ``contour_span`` semi-axes each way, the other free parameters re-minimised at each point.
    """
    if isinstance(k_max, (int, float)):
        k_max = [k_max]
    tables = _core.fit(data, list(k_max), list(free), list(ells), list(data_ells),
                       None if data_columns is None else list(data_columns), covariance, rsd, real,
                       fog, f, sigma0, bias, amplitude, shot_noise, number_density, noise_table,
                       k_min, linear, z, z_input, cosmology, precision, q_range, cache_dir, eh, cs2,
                       bool(model), None if contour is None else list(contour), contour_points,
                       contour_span)
    return {name: None if t is None else _warn(t)
            for name, t in zip(("fit", "model", "contour"), tables)}
