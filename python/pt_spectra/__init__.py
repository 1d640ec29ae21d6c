"""pt-spectra: perturbation-theory power spectra of matter and haloes, with error estimates.

The Python face of the Rust library: the same entry points, names and columns as the command line
``pt-spectra``. Units: k in h/Mpc, P in (Mpc/h)^3.

>>> import numpy as np, pt_spectra as pt
>>> t = pt.real(model="1l-spt", k=np.geomspace(0.01, 0.3, 20), terms=True, precision="fast")
>>> bool(t["P_dd"][0] > t["P_lin"][0] * 0.99)
True

Every function returns a :class:`Table`: ``t.columns`` (the command line's column names), ``t[name]``
(numpy arrays), ``t.units``, ``t.header``, ``t.meta`` (z, f, D, cosmology, precision, q range, model)
and ``t.to_text()``. Bad input raises ``ValueError`` with the library's message: every k array (``k``,
the ``k`` of ``linear``, ``k_lin``, the k of tables and measured spectra, ``data["k"]``) must be 1-D,
non-empty, finite, positive and strictly increasing, and the message names the argument, the index
and the rule (``k[1] = 0.1 h/Mpc: does not exceed k[0] = 0.2 h/Mpc ...``); defaults that may not
fit the input (e.g. the gm2012 growth for a spectrum given without a cosmology) raise a
:class:`PtSpectraWarning`.

Computations release the GIL and run on rayon's thread pool: its size is ``RAYON_NUM_THREADS`` or
:func:`set_num_threads` (before the first computation).
"""

from __future__ import annotations

import warnings as _warnings
import numpy as np

from . import _core
from ._core import (BispectrumPlan, BispectrumTerms, LinearEmulator, Observation, OneLoopBispectrumPlan,
                    Pipeline,
                    SugiyamaPlan, SugiyamaTerms, Table, distances, eisenstein_hu, fisher, fisher_kaiser,
                    growth, log_grid,
                    num_threads, set_num_threads)

__all__ = [
    "BispectrumPlan",
    "OneLoopBispectrumPlan",
    "BispectrumTerms",
    "EptPlan",
    "Observation",
    "Pipeline",
    "EptTerms",
    "LinearEmulator",
    "PtSpectraWarning",
    "RealPlan",
    "RsdPlan",
    "RsdTerms",
    "SugiyamaPlan",
    "SugiyamaTerms",
    "Table",
    "TwoLoopRsdPlan",
    "eisenstein_hu",
    "ept",
    "fit",
    "fit_ept",
    "fit_joint",
    "fisher",
    "fisher_kaiser",
    "fit_tables",
    "bispectrum",
    "one_loop_bispectrum",
    "from_desi_physical",
    "AnalysisLikelihood",
    "convert_bias",
    "distances",
    "growth",
    "halo",
    "kernel",
    "log_grid",
    "num_threads",
    "real",
    "rsd",
    "set_num_threads",
]

__version__ = _core.__version__

#: The defaults of the keyword arguments, spelled once in the library (``pt_spectra::jobs::defaults``).
_D = _core.DEFAULTS


class PtSpectraWarning(UserWarning):
    """A default or an input that may not be what you meant (also stated in the table header)."""


def _warn(table: Table) -> Table:
    for message in table.warnings:
        _warnings.warn(message, PtSpectraWarning, stacklevel=3)
    return table


def _grid(k, k_min, k_max, nk):
    return log_grid(k_min, k_max, nk) if k is None else k


class RealPlan:
    """A real-space model prepared for one k grid: build once, call for every linear spectrum.

    ``RealPlan(k, model="1l-spt", precision="default", q_range=None, two_loop_tolerance=None,
    cache_dir=None, two_loop="auto")``; models ``linear, 1l-spt, 2l-spt, 1l-rpt-n0..n3,
    2l-rpt-n0..n3``, ``1l-regpt``, ``2l-regpt``, ``1l-spt-ir``, ``2l-spt-ir``, ``2l-eft``, ``2l-eft-ir`` or
    ``all``. ``two_loop``: ``"basis"`` computes the 2-loop terms of every spectrum
    from precomputed tensors on a basis of CAMB spectra (built and cached once per k grid, minutes;
    then milliseconds per spectrum: the choice for chains), ``"direct"`` integrates them for every
    spectrum (seconds), ``"auto"`` uses the tensors if they are already cached. A spectrum the basis
    does not represent (e.g. Eisenstein & Hu) is integrated directly, with a warning.
    ``plan(linear=None, z=0.0, z_input=0.0, cosmology=None, terms=False, eh=None, cs2=0.0,
    bias_terms=False, bias=None, b2=0.0, bs=0.0, b3=0.0, ct=None, bias_convention=None)`` returns a
    :class:`Table` with no
    set-up cost beyond the computation itself (``cs2``, ``ct``: the EFT counterterms; the bias
    arguments: the galaxy bias terms and spectra; all as in :func:`real`).
    """

    def __init__(self, k, model=_D["real_model"], precision=_D["precision"], q_range=None,
                 two_loop_tolerance=None, cache_dir=None, two_loop=_D["two_loop"]):
        self._plan = _core.RealPlan(k, model, precision, q_range, two_loop_tolerance, cache_dir,
                                    two_loop)
        self.model = model

    @property
    def k(self):
        """The k grid [h/Mpc]."""
        return self._plan.k

    def __call__(self, linear=None, z=0.0, z_input=0.0, cosmology=None, terms=False, eh=None,
                 cs2=0.0, bias_terms=False, bias=None, b2=0.0, bs=0.0, b3=0.0, ct=None,
                 bias_convention=None):
        return _warn(self._plan(linear, z, z_input, cosmology, terms, eh, cs2, bias_terms, bias, b2,
                                bs, b3, ct, bias_convention))

    def batch(self, k_lin, P, terms=False):
        """The model for many linear spectra at once, spread over the threads
        (:func:`set_num_threads`): ``P`` of shape (n_spectra, len(k_lin)) [(Mpc/h)^3] tabulated at
        ``k_lin`` [h/Mpc], each already at the output redshift. Returns a dict of arrays of shape
        (n_spectra, n_k) named as the columns of :func:`real` (``P_lin``, ``P_dd``, ``P_dt``,
        ``P_tt``; with ``terms`` their errors and the loop terms) and ``k``. No header and no
        :class:`Table` per spectrum: the path for chains and training sets. A 1-D ``P`` is one
        spectrum (leading axis of length 1).
        """
        P = np.asarray(P, dtype=float)
        if P.ndim == 1:
            P = P[None, :]
        return _core.real_batch(self._plan, np.asarray(k_lin, dtype=float), P, terms)


EPT_PARAMETERS = ("b1", "b2", "bs", "b3", "alpha0", "alpha2", "alpha4", "alpha6", "sn", "sn2",
                  "sn4", "f")


def _ept_params(params):
    """The model parameters of ``params`` that are not None (velocileptors' names, or those of
    ``bias_convention``)."""
    return {name: v if name == "bias_convention" else float(v) for name, v in params.items()
            if v is not None}


class EptPlan:
    """The galaxy model ``ept`` planned for one k grid (1-loop Eulerian PT of biased tracers in
    redshift space with the BAO resummed, velocileptors' ``REPT`` conventions).

    ``EptPlan(k, ir=True, apar=None, aperp=None, precision="default", q_range=None,
    free_ap=False, two_loop="auto", cache_dir=None)`` (``two_loop="basis"``: the loop terms of every
    spectrum from basis tensors, built once per k grid in seconds and cached, as for
    :class:`RealPlan`); calling it
    takes the linear spectrum (``linear``, ``z``, ``z_input``, ``cosmology``, ``eh`` as in
    :func:`real`), ``ells`` and the parameters by name: b1, b2, bs, b3, alpha0, alpha2, alpha4,
    alpha6 [(Mpc/h)^2], sn [(Mpc/h)^3], sn2 [(Mpc/h)^5], sn4 [(Mpc/h)^7], f (default f(z)); an
    unknown name is an error. ``bias_convention="classpt"`` takes the bias as CLASS-PT names it
    (b1, b2, bG2, bGamma3), ``"fastpt"`` as FAST-PT does (b1, b2, bs, b3nl); it is mapped exactly
    to velocileptors' (docs/reference.md, "Bias conventions") and the header gives both. ``terms(...)`` returns the loop terms of one spectrum
    (:class:`EptTerms`), after which each parameter step costs microseconds. ``free_ap=True`` builds
    the plan for any distortion with 0.8 <= apar, aperp <= 1.25, given per call to
    :meth:`EptTerms.multipoles` (a chain that varies the cosmology against a fiducial).
    """

    def __init__(self, k, ir=True, apar=None, aperp=None, precision=_D["precision"], q_range=None,
                 free_ap=False, two_loop=_D["two_loop"], cache_dir=None):
        self._plan = _core.EptPlan(k, ir, apar, aperp, precision, q_range, free_ap, two_loop,
                                   cache_dir)

    def __call__(self, linear=None, z=0.0, z_input=0.0, cosmology=None, eh=None, ells=(0, 2, 4),
                 **params):
        return _warn(self._plan(linear, z, z_input, cosmology, eh, list(ells),
                                **_ept_params(params)))

    def terms(self, linear=None, z=0.0, z_input=0.0, cosmology=None, eh=None):
        """The loop terms of one linear spectrum (the expensive part), as :class:`EptTerms`."""
        return EptTerms(self._plan.terms(linear, z, z_input, cosmology, eh))


class EptTerms:
    """The loop terms of one linear spectrum on an :class:`EptPlan`'s grid:
    ``terms.multipoles(ells=(0, 2, 4), apar=None, aperp=None, **params)`` with the parameters of
    :class:`EptPlan`; apar, aperp: a distortion replacing the plan's (a plan with ``free_ap=True``)."""

    def __init__(self, core):
        self._terms = core

    def multipoles(self, ells=(0, 2, 4), **params):
        return _warn(self._terms.multipoles(list(ells), **_ept_params(params)))


def ept(k=None, linear=None, z=0.0, z_input=0.0, cosmology=None, eh=None, ells=(0, 2, 4), ir=True,
        apar=None, aperp=None, precision=_D["precision"], q_range=None, k_min=1e-3, k_max=1.0, nk=100,
        **params) -> Table:
    """The galaxy model's multipoles (``pt-spectra rsd --rsd ept``): columns ``k P0 P2 P4 …
    err_P0 …``. Parameters by velocileptors' names (see :class:`EptPlan`); ``ir=False`` for plain
    1-loop SPT; ``apar``, ``aperp`` for the Alcock-Paczynski distortion."""
    plan = EptPlan(_grid(k, k_min, k_max, nk), ir, apar, aperp, precision, q_range)
    return plan(linear, z, z_input, cosmology, eh, ells, **params)


class TwoLoopRsdPlan:
    """2-loop matter multipoles in redshift space planned for one k grid: ``model="spt2"`` (plain
    2-loop SPT, kernels Z_2 … Z_5) or ``"eft2"`` (with the BAO resummed, ``ir=False`` to switch it
    off, and the counterterms c0, c2, c4, c0_1loop, c2_1loop, c4_1loop [(Mpc/h)^2], ctilde
    [(Mpc/h)^4]; see docs/reference.md).

    ``TwoLoopRsdPlan(k, model="eft2", ir=True, precision="default", q_range=None, two_loop="auto",
    cache_dir=None)``: ``two_loop="basis"`` builds the 2-loop basis tensors once per k grid and
    precision (minutes; cached), after which a new spectrum costs milliseconds; ``"direct"``
    integrates every spectrum (about a second per k at the default precision). Calling it takes the
    linear spectrum (``linear``, ``z``, ``z_input``, ``cosmology``, ``eh`` as in :func:`real`), ``f``
    (default f(z)), ``ells`` (even, <= 8), ``terms`` (spt2: the parts ``P<l>_lin P<l>_1loop
    P<l>_2loop``; eft2: the templates ``T<l>_<name>`` = dP_l/d<name>) and the counterterms by name.
    """

    def __init__(self, k, model="eft2", ir=True, precision=_D["precision"], q_range=None,
                 two_loop=_D["two_loop"], cache_dir=None):
        self._plan = _core.TwoLoopRsdPlan(k, model, ir, precision, q_range, two_loop, cache_dir)

    def __call__(self, linear=None, z=0.0, z_input=0.0, cosmology=None, eh=None, f=None,
                 ells=(0, 2, 4), terms=False, **counterterms):
        return _warn(self._plan(linear, z, z_input, cosmology, eh, f, list(ells), terms,
                                **counterterms))

    def fit_counterterms(self, data, free, k_max, linear=None, z=0.0, z_input=0.0, cosmology=None,
                         eh=None, f=None, **fixed):
        """eft2's counterterms ``free`` (names) fitted by weighted least squares to measured
        multipoles ``data`` = ``{ell: (P_ell, sigma)}`` at the plan's k, over k <= ``k_max``; the
        others held at ``fixed``'s values (default 0). Exact (the model is linear in them). Returns
        ``{name: (value, error)}`` for every counterterm (error 0 for the fixed ones)."""
        data = {int(ell): ([float(x) for x in v], [float(x) for x in s])
                for ell, (v, s) in data.items()}
        return self._plan.fit_counterterms(data, list(free), k_max, linear, z, z_input, cosmology,
                                           eh, f, **fixed)


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

def convert_bias(values, from_convention, to_convention="velocileptors"):
    """The galaxy bias ``values`` (a dict, named as ``from_convention`` names them; a missing one is
    0) in ``to_convention``: ``"velocileptors"`` (b1, b2, bs, b3: the convention of every function
    here), ``"fastpt"`` (b1, b2, bs, b3nl: (bs/2)s^2, b3nl = b3/2) or ``"classpt"`` (b1, b2, bG2,
    bGamma3: bs = bG2, b2 = b2^CLASS-PT - (4/3) bG2, b3 = -15 bG2 - 6 bGamma3). Exact (linear maps;
    docs/reference.md, "Bias conventions"). E.g. CLASS-PT's values for :func:`bispectrum`:
    ``pt.convert_bias({"b1": 2, "b2": 0.1, "bG2": -0.3, "bGamma3": 0.5}, "classpt")``."""
    return dict(_core.convert_bias({k: float(v) for k, v in dict(values).items()}, from_convention,
                                   to_convention))


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


class RsdPlan:
    """The loop terms of a redshift-space model prepared for one k grid.

    ``RsdPlan(k, real="1l-rpt-n1", rsd="tns", precision="default", q_range=None, cache_dir=None,
    two_loop="auto")``; calling it takes the arguments of :func:`rsd` after ``k`` (linear, z,
    cosmology, f, bias, fog, sigma0, noise, ells, terms, cs2) and returns the multipoles.
    ``two_loop`` as in :class:`RealPlan`. ``rsd="ept"`` plans the galaxy model (an
    :class:`EptPlan`; ``ir``, ``apar``, ``aperp`` as keyword arguments): calling it takes ``bias``
    (b1), ``b2``, ``bs``, ``b3``, ``f`` and velocileptors' other names; ``terms`` gives
    :class:`EptTerms`.
    """

    def __init__(self, k, real=_D["rsd_real_model"], rsd=_D["rsd_model"], precision=_D["precision"],
                 q_range=None, cache_dir=None, two_loop=_D["two_loop"], **ept_settings):
        self._ept = None
        if str(rsd).lower() == "ept":
            self._ept = EptPlan(k, precision=precision, q_range=q_range, **ept_settings)
            return
        if ept_settings:
            raise ValueError(f"{', '.join(ept_settings)}: options of rsd='ept', not of rsd={rsd!r}")
        self._plan = _core.RsdPlan(k, real, rsd, precision, q_range, cache_dir, two_loop)

    def __call__(self, linear=None, z=0.0, z_input=0.0, cosmology=None, f=None, bias=1.0,
                 amplitude=1.0, fog="none", sigma0=0.0, shot_noise=None, number_density=None,
                 noise_table=None, ells=(0, 2, 4), terms=False, eh=None, growth_factor=None,
                 no_wiggle=False, cs2=0.0, b2=None, bs=None, b3=None, bias_convention=None,
                 **ept_params):
        if self._ept is not None:
            return self._ept(linear, z, z_input, cosmology, eh, ells, f=f, **ept_params,
                             **_bias_kwargs(bias, b2, bs, b3, bias_convention))
        if ept_params:
            raise ValueError(f"{', '.join(ept_params)}: parameters of rsd='ept'")
        return _warn(self._plan(linear, z, z_input, cosmology, f, bias, amplitude, fog, sigma0,
                                shot_noise, number_density, noise_table, list(ells), terms, eh,
                                growth_factor, no_wiggle, cs2, b2, bs, b3, bias_convention))

    def terms(self, linear=None, z=0.0, z_input=0.0, cosmology=None, eh=None):
        """The loop terms of one linear spectrum (the expensive part), as :class:`RsdTerms`
        (:class:`EptTerms` for ``rsd="ept"``)."""
        if self._ept is not None:
            return self._ept.terms(linear, z, z_input, cosmology, eh)
        return RsdTerms(self._plan.terms(linear, z, z_input, cosmology, eh))


class RsdTerms:
    """The loop terms of one linear spectrum on an :class:`RsdPlan`'s grid.

    ``terms.multipoles(f=None, bias=1.0, amplitude=1.0, fog="none", sigma0=0.0, shot_noise=None,
    number_density=None, noise_table=None, ells=(0, 2, 4), terms=False, growth_factor=None,
    no_wiggle=False, cs2=0.0)`` costs microseconds: the step of a chain in which only f, the bias,
    sigma0, the noise or the EFT counterterm ``cs2`` change.
    ``growth_factor`` replaces D(z) of the cosmology in the FoG scale sigma0 D(z) f (e.g. with a
    Boltzmann code's sigma8(z)/sigma8(0)).
    """

    def __init__(self, core):
        self._terms = core

    def multipoles(self, f=None, bias=1.0, amplitude=1.0, fog="none", sigma0=0.0, shot_noise=None,
                   number_density=None, noise_table=None, ells=(0, 2, 4), terms=False,
                   growth_factor=None, no_wiggle=False, cs2=0.0):
        return _warn(self._terms.multipoles(f, bias, amplitude, fog, sigma0, shot_noise,
                                            number_density, noise_table, list(ells), terms,
                                            growth_factor, no_wiggle, cs2))


#: The bias parameters' names in each convention, as the library names them (velocileptors' first:
#: the model's own).
_BIAS_NAMES = {c: tuple(n for n, _ in _core.convert_bias({}, c, c))
               for c in ("velocileptors", "fastpt", "classpt")}


def _bias_kwargs(b1, b2, bs, b3, bias_convention):
    """The ``ept`` keyword arguments of b1 and the b2, bs, b3 slots of :func:`rsd`, named as
    ``bias_convention`` names them."""
    key = "velocileptors" if bias_convention is None else \
        str(bias_convention).lower().replace("-", "").replace("_", "")
    if key not in _BIAS_NAMES:
        raise ValueError(f"bias convention {bias_convention!r}: the conventions are velocileptors, "
                         "fastpt, classpt")
    out = {name: v for name, v in zip(_BIAS_NAMES[key], (b1, b2, bs, b3)) if v is not None}
    if bias_convention is not None:
        out["bias_convention"] = key
    return out


def real(model=_D["real_model"], k=None, linear=None, z=0.0, z_input=0.0, cosmology=None, terms=False,
         precision=_D["precision"], q_range=None, two_loop_tolerance=None, cache_dir=None, eh=None,
         k_min=1e-3, k_max=1.0, nk=100, cs2=0.0, two_loop=_D["two_loop"], bias_terms=False, bias=None,
         b2=0.0, bs=0.0, b3=0.0, ct=None, bias_convention=None) -> Table:
    """Real-space P_dd, P_dt, P_tt of a model (``pt-spectra real``).

    model: ``linear``, ``1l-spt``, ``2l-spt``, ``1l-rpt-n0`` … ``1l-rpt-n3``, ``2l-rpt-n0`` …
    ``2l-rpt-n3``, ``1l-regpt``, ``2l-regpt``, ``1l-spt-ir``, ``2l-spt-ir``, ``2l-eft``, ``2l-eft-ir``
    (2-loop SPT with the EFT counterterms of ``ct``), or ``all`` (P_dd/P_nw of every model).
    k: wavenumbers [h/Mpc] (default ``nk`` log-spaced in [k_min, k_max]).
    linear: ``None`` (the embedded gm2012 CAMB spectra), a file path, or ``(k_lin, p_lin)`` arrays at
    ``z_input``; rescaled to ``z`` with D(z) of ``cosmology``.
    cosmology: ``None`` (gm2012), a preset (``gm2012``, ``planck2018``), a CLASS/CAMB ini path, or a
    dict of ini keys (e.g. ``{"h": 0.68, "omega_b": 0.0224, "omega_cdm": 0.12, "n_s": 0.96,
    "A_s": 2.1e-9}``).
    terms: add every loop term with its error (``P22_dd``, ``err_P22_dd``, …).
    precision: ``fast``, ``default`` or ``reference``; q_range: (QMIN, QMAX) of the loop integrals.
    two_loop: ``"auto"``, ``"basis"`` or ``"direct"`` (see :class:`RealPlan`).
    eh: ``"wiggle"`` or ``"no-wiggle"`` for the Eisenstein & Hu spectrum of the cosmology.
    cs2: the EFT counterterm c_s^2 [(Mpc/h)^2] added to the model: P_dd - 2 cs2 k^2 P_lin,
    P_dt - 4 cs2 k^2 P_lin, P_tt - 6 cs2 k^2 P_lin (delta_ct grows as D^3 and theta_ct = 3 delta_ct by
    mass conservation); exact; stated in the header, and with ``terms`` the columns ``P_ct_dd P_ct_dt
    P_ct_tt``.
    ct: the EFT counterterms as a dict, e.g. ``{"cs2": 1.0, "cs2_1loop": 0.3, "c4": -2.0}``: ``cs2``
    as above (any model; give it once), and for ``2l-eft``, ``2l-eft-ir`` ``cs2_1loop`` [(Mpc/h)^2]
    (P_dd - 2 cs2_1loop k^2 P_1loop) and ``c4`` [(Mpc/h)^4] (P_dd - 2 c4 k^4 P_lin); docs/eft.md.
    With ``terms`` the EFT models add ``T_dd_X``, ``T_dt_X``, ``T_tt_X`` = dP/dX for each X, so that
    P = P(ct = 0) + sum_X X T_X: a least-squares fit of the counterterms is linear.
    bias_terms: add the 1-loop bias terms ``Pd1d2 Pd2d2 Pd1s2 Pd2s2 Ps2s2`` (FAST-PT's names and
    normalisation, no constant subtracted), ``Pt1d2 Pt1s2`` (their velocity counterparts) and
    ``sig3nl``, each with ``err_``. bias: b1; with it, ``P_gg`` and ``P_gm`` of the bias expansion
    (Saito et al. 2014, evaluated with FAST-PT's terms) on the model's P_dd. b2, bs, b3 mean one
    thing for every model: velocileptors' (b2/2)delta^2 + bs s^2 + b3 O3 (FAST-PT's bs is 2 bs, its
    b3nl b3/2), unless ``bias_convention`` is ``"fastpt"`` (b2, bs, b3 are then FAST-PT's b2, bs,
    b3nl) or ``"classpt"`` (CLASS-PT's b2, b_G2, b_Gamma3); the header gives both. bs or b3 without
    a ``bias_convention`` warns once that they are no longer FAST-PT's.
    """
    plan = RealPlan(_grid(k, k_min, k_max, nk), model, precision, q_range, two_loop_tolerance,
                    cache_dir, two_loop)
    return plan(linear, z, z_input, cosmology, terms, eh, cs2, bias_terms, bias, b2, bs, b3, ct,
                bias_convention)


def rsd(rsd=_D["rsd_model"], real=_D["rsd_real_model"], k=None, linear=None, z=0.0, z_input=0.0,
        cosmology=None,
        f=None, bias=1.0, amplitude=1.0, fog=_D["rsd_fog"], sigma0=0.0, shot_noise=None,
        number_density=None, noise_table=None, ells=(0, 2, 4), terms=False, precision=_D["precision"],
        q_range=None, cache_dir=None, eh=None, k_min=1e-3, k_max=1.0, nk=100,
        no_wiggle=False, cs2=0.0, b2=None, bs=None, b3=None, bias_convention=None,
        **ept_params) -> Table:
    """Redshift-space multipoles (``pt-spectra rsd``): columns ``k P0 P2 P4 … err_P0 …``.

    ``rsd="ept"`` is the galaxy model (:func:`ept`): ``bias`` is b1, ``b2``, ``bs``, ``b3`` and the
    keyword arguments ``alpha0`` … ``sn4``, ``ir``, ``apar``, ``aperp`` in velocileptors' conventions.
    ``rsd="spt2"`` and ``"eft2"`` are the 2-loop matter multipoles (:class:`TwoLoopRsdPlan`; eft2's
    counterterms ``c0=…`` and ``ir`` as keyword arguments; the bias, noise and FoG options do not
    apply).

    rsd: ``kaiser``, ``scoccimarro`` or ``tns``; real: the real-space model (as :func:`real`).
    f: growth rate (default f(z) of the cosmology). bias: a number, a path or ``(k, b)`` arrays;
    amplitude: A_b. fog: ``none``, ``lorentzian`` or ``gaussian``; sigma0 [Mpc/h] (z = 0 value) or
    ``"lin"`` / ``"1l-spt"`` (the theory value). Noise: one of shot_noise [(Mpc/h)^3],
    number_density [(h/Mpc)^3] (Poisson) or noise_table (path or ``(k, P_eps)``; a path is read by
    the column names ``b`` and ``P_eps`` of a ``pt-spectra halo`` table, else column 2). The models
    are of the noise-subtracted spectrum, so the noise changes no P_l: it adds ``P_eps SN SN_s``, SN =
    b^2 P_dd/P_eps (real space, the paper's signal-to-noise) and SN_s = P0/P_eps. ells: even
    multipoles up to 8. terms: add the parts ``P<l>_sc P<l>_A P<l>_B``. no_wiggle: add ``P<l>_nw``,
    the linear Kaiser multipoles of the no-wiggle spectrum. cs2: the EFT counterterm added to the
    real-space spectra before the RSD model (as in :func:`real`). b2, bs, b3: the nonlinear galaxy
    bias of the ``scoccimarro`` and ``tns`` models (the BOSS DR12 model of Beutler et al. 2017, with
    the bias terms of :func:`real`'s ``bias_terms``; ``bias`` is b1, a number), in velocileptors'
    convention as for every model unless ``bias_convention`` says otherwise (see :func:`real`). The
    other arguments are those of :func:`real`.
    """
    if str(rsd).lower() == "ept":
        return ept(k=_grid(k, k_min, k_max, nk), linear=linear, z=z, z_input=z_input,
                   cosmology=cosmology, eh=eh, ells=ells, precision=precision, q_range=q_range,
                   f=f, **ept_params, **_bias_kwargs(bias, b2, bs, b3, bias_convention))
    if str(rsd).lower() in ("spt2", "eft2"):
        given = [name for name, value, default in [
            ("real", real, _D["rsd_real_model"]), ("bias", bias, 1.0), ("amplitude", amplitude, 1.0),
            ("fog", str(fog).lower(), "none"), ("sigma0", sigma0, 0.0), ("shot_noise", shot_noise, None),
            ("number_density", number_density, None), ("noise_table", noise_table, None),
            ("no_wiggle", no_wiggle, False), ("cs2", cs2, 0.0), ("b2", b2, None), ("bs", bs, None),
            ("b3", b3, None)] if not (value is default or value == default)]
        if given:
            raise ValueError(f"{', '.join(given)}: not options of rsd={rsd!r} (matter multipoles of "
                             "2-loop perturbation theory: f, ells, terms; eft2: counterterms, ir)")
        counterterms = dict(ept_params)
        ir = counterterms.pop("ir", True)
        plan = TwoLoopRsdPlan(_grid(k, k_min, k_max, nk), str(rsd).lower(), ir, precision, q_range,
                              cache_dir=cache_dir)
        return plan(linear, z, z_input, cosmology, eh, f, ells, terms, **counterterms)
    if ept_params:
        raise ValueError(f"{', '.join(ept_params)}: options of rsd='ept', not of rsd={rsd!r}")
    plan = RsdPlan(_grid(k, k_min, k_max, nk), real, rsd, precision, q_range, cache_dir)
    return plan(linear, z, z_input, cosmology, f, bias, amplitude, fog, sigma0, shot_noise,
                number_density, noise_table, ells, terms, eh, no_wiggle=no_wiggle, cs2=cs2, b2=b2,
                bs=bs, b3=b3, bias_convention=bias_convention)


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


def halo(pmm, pmh, phh, number_density=None) -> Table:
    """Scale-dependent bias and stochasticity from measured spectra (``pt-spectra halo``).

    pmm, pmh, phh: tuples ``(k, P)`` or ``(k, P, sigma)`` of arrays on one k grid [h/Mpc,
    (Mpc/h)^3]: the matter, matter-halo and halo spectra (P_hh with its noise). Returns ``k b P_eps``
    with b = P_mh/P_mm and P_eps = P_hh - P_mh^2/P_mm, ``P_eps_n`` = P_eps n_h for a
    ``number_density`` n_h [(h/Mpc)^3], and the propagated errors ``err_b err_P_eps`` where sigmas
    are given. The table's ``to_text()`` feeds ``bias``/``noise_table`` of :func:`rsd` and :func:`fit`.
    """
    return _core.halo(tuple(pmm), tuple(pmh), tuple(phh), number_density)


def kernel(which, vectors, exact=False, f=None, los=None):
    """The symmetrised kernel F_n^s or G_n^s (``which`` = "F" or "G", n <= 7) at the vectors [x, y, z],
    or the redshift-space kernel Z_n (``which`` = "Z", n <= 5) with growth rate ``f`` along the line of
    sight ``los`` (default [0, 0, 1]).

    With ``exact=True`` the components (and f, los) may be ints, ``fractions.Fraction`` or "p/q" strings
    and the result is the reduced fraction as a string; otherwise a float.

    >>> kernel("F", [[1, 0, 0], [0, 1, 0]])
    0.7142857142857143
    >>> kernel("Z", [[0, 0, 1]], exact=True, f="1/2")
    '3/2'
    """
    return _core.kernel(which, [list(v) for v in vectors], exact, f,
                        None if los is None else list(los))


def bispectrum(triangles=None, bin_width=None, linear=None, z=0.0, z_input=0.0, cosmology=None, eh=None,
               b1=1.0, b2=0.0, bs=0.0, c1=0.0, n_bar=None, b_shot=1.0, p_shot=0.0, a_shot=0.0, f=None,
               q_par=1.0, q_perp=1.0, fog="none", sigma_fog=0.0, ir=True, legendre_side="largest",
               basis="scoccimarro", pairs=None, box_size=None, bias_convention=None):
    """Tree-level galaxy bispectrum multipoles B0, B2, B4 [(Mpc/h)^6] in redshift space.

    ``triangles``: an (n, 3) array of k1, k2, k3 [h/Mpc]; with ``bin_width`` [h/Mpc] each row is a bin
    of three shells averaged over all its closed triangles (what a measurement is), else a point.
    Bias as velocileptors (b1, b2, bs), or with ``bias_convention="classpt"`` CLASS-PT's (b1, b2, b_G2 as
    ``bs``) or ``"fastpt"`` (the header states both; also ``BispectrumTerms.multipoles(..., bias_convention=)``),
    counterterm c1 [(Mpc/h)^2], stochastic
    terms (1/n_bar)[b1 b_shot + f mu^2 (1 + p_shot)] Z1 P + cyclic + (1 + a_shot)/n_bar^2 (none without
    ``n_bar``), f (default f(z)), AP q_par, q_perp, FoG none | lorentzian | gaussian with ``sigma_fog``
    [Mpc/h], IR resummation, the Legendre polynomial on the largest side (or "1", "2", "3").
    Returns a ``Table``: k1 k2 k3 B0 B2 B4 err_B0 err_B2 err_B4, its header and ``meta``.
    For many parameter steps on one spectrum use ``BispectrumPlan(triangles).terms(...).multipoles(...)``.
    ``box_size`` L [Mpc/h] (with ``bin_width``): the bins averaged exactly over the discrete modes
    k = (2 pi/L) n of a periodic box, line of sight z, as the FFT box estimator measures them (errors 0).

    ``basis="sugiyama"`` with ``pairs`` (an (n, 2) array of k1, k2 [h/Mpc]) gives instead the Sugiyama
    et al. (2019) multipoles B000 B110 B202 B022 B112 B220 (the angle between k1 and k2 integrated;
    B112 the tripolar one), columns k1 k2 B000 … err_B000 …; ``SugiyamaPlan(pairs)`` for many steps.
    """
    if triangles is not None and bin_width is None and np.ndim(triangles) == 2:
        _warnings.warn("bispectrum: triangles without bin_width are points; a measurement's bins need "
                       "bin_width (their shell width) to be averaged over", PtSpectraWarning, stacklevel=2)
    return _warn(_core.bispectrum(triangles, bin_width, linear, z, z_input, cosmology, eh, b1, b2, bs,
                                  c1, n_bar, b_shot, p_shot, a_shot, f, q_par, q_perp, fog, sigma_fog, ir,
                                  legendre_side, basis, pairs, box_size, bias_convention))


def one_loop_bispectrum(triangles, linear=None, z=0.0, z_input=0.0, cosmology=None, eh=None, q_min=1e-4,
                        q_max=10.0, radial=12, mu=32, phi=24, two_loop="auto", cache_dir=None, mu1=None,
                        phi_los=0.0, f=None):
    """One-loop matter bispectrum in real space (SPT) [(Mpc/h)^6] at single triangles.

    ``triangles``: an (n, 3) array of k1, k2, k3 [h/Mpc] (points, not bins). The linear spectrum as in
    ``bispectrum`` (all matter). The loop integrals run over q_min <= |q| <= q_max [h/Mpc] with
    ``radial`` x ``mu`` x ``phi`` nodes per panel (errors: the difference from half the nodes; about
    0.25 s per triangle on 2 cores). Returns a ``Table``: k1 k2 k3 B_tree B222 B321_I B321_II B411
    B_1loop, their err_ columns, and the four EFT counterterm shapes shape_ct_f2, shape_ct_k3,
    shape_ct_tidal, shape_ct_f2k3 [(Mpc/h)^8] (B_ct = sum of ct_c * shape_ct_c, ct_c in (Mpc/h)^2, not
    included in B_1loop). No bias or redshift space yet (docs/bispectrum.md).

    ``two_loop`` says how the loop terms are computed, as for the power spectra: ``"basis"`` (tensors
    built once per triangle set and rule, ~0.7 s per triangle and core, cached in ``cache_dir``
    (default: $PT_SPECTRA_CACHE, else ~/.cache/pt-spectra); then ~10 us per triangle for any linear
    spectrum, their projection error included in the errors; a spectrum the basis does not represent
    is integrated directly, as the header says), ``"direct"`` or ``"auto"`` (the tensors if cached,
    else direct). The header line ``loop terms: ...`` says which was used.

    ``mu1`` (and ``phi_los`` [rad], ``f``, default f(z)): the matter bispectrum in redshift space at one
    orientation of the triangles to the line of sight (the cosine between k1 and it, its azimuth about
    k1 from the triangle's plane), with the exact redshift-space kernels Z1..Z4, directly (about 1.3 s
    per triangle on 2 cores; no counterterm shapes, bias or multipoles yet).
    """
    return _warn(_core.one_loop_bispectrum(triangles, linear, z, z_input, cosmology, eh, q_min, q_max,
                                           radial, mu, phi, two_loop, cache_dir, mu1, phi_los, f))


def from_desi_physical(physical, sigma8, n_bar, satellites=None):
    """The ``ept`` model's parameters (velocileptors' names, a dict) of values in the DESI DR1 physical
    basis (``fit_ept(basis="desi")``; docs/reference.md): ``physical`` a dict of b1p, b2p, bsp, b3p,
    alpha0p, alpha2p, alpha4p, sn0p, sn2p, sn4p (missing ones 0) and f (required), at ``sigma8`` =
    sigma8(z), number density ``n_bar`` [(h/Mpc)^3] and ``satellites`` = (f_sat, sigma_v [Mpc/h])
    (default (0.1, 5)). E.g. a cobaya likelihood sampling the physical basis passes the result to
    ``ept(...)`` or ``Pipeline``.
    """
    return _core.from_desi_physical(dict(physical), float(sigma8), float(n_bar),
                                    None if satellites is None else tuple(map(float, satellites)))
