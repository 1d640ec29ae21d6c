"""pt-spectra: perturbation-theory power spectra of matter and haloes, with error estimates.

The Python face of the Rust library: the same entry points, names and columns as the command line
``pt-spectra``. Units: k in h/Mpc, P in (Mpc/h)^3.

>>> import numpy as np, pt_spectra as pt
>>> t = pt.real(model="1l-spt", k=np.geomspace(0.01, 0.3, 20), terms=True, precision="fast")
>>> bool(t["P_dd"][0] > t["P_lin"][0] * 0.99)
True

Every function returns a :class:`Table`: ``t.columns`` (the command line's column names), ``t[name]``
(numpy arrays), ``t.units``, ``t.header``, ``t.meta`` (z, f, D, cosmology, precision, q range, model, methods)
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
from ._common import _D, EPT_PARAMETERS, PtSpectraWarning, _ept_params, _grid, _warn
from ._core import (BispectrumTerms, LinearEmulator, Observation, OneLoopBispectrumPlan, OneLoopMultipolePlan,
                    Pipeline,
                    SugiyamaPlan, SugiyamaTerms, Table, distances, eisenstein_hu, fisher, fisher_kaiser,
                    growth, log_grid,
                    num_threads, set_num_threads)

__all__ = [
    "BispectrumPlan",
    "OneLoopBispectrumPlan",
    "OneLoopMultipolePlan",
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

class BispectrumPlan(_core.BispectrumPlan):
    """The bispectrum planned for a set of triangles ([h/Mpc], rows k1 k2 k3; ``bin_width`` [h/Mpc]: bins
    of three shells).

    ``BispectrumPlan(triangles, bin_width=None, legendre_side="largest", effective=False)``: the tree level;
    ``plan.terms(...)`` per linear spectrum (f, AP, FoG, IR), then ``terms.multipoles(b1=..., ...)`` per
    parameter step (microseconds).

    ``BispectrumPlan(triangles, ..., loop=1, cache_dir=None, radial=12, mu=32, phi=24, q_min=1e-4,
    q_max=10.0)``: the one-loop galaxy multipoles B0, B2, B4 from their tensors (built once per triangle set
    and loop rule, ~190 s per triangle and core at the default rule, cached): a :class:`OneLoopMultipolePlan`,
    whose call takes the spectrum, f and bias.
    """

    def __new__(cls, triangles, bin_width=None, legendre_side="largest", effective=False, loop=0,
                **one_loop):
        if loop == 1:
            if effective:
                raise ValueError("effective=True is the tree level's shortcut; the one-loop bins average "
                                 "their own way (loop=1 without effective)")
            return OneLoopMultipolePlan(triangles, legendre_side=legendre_side, bin_width=bin_width,
                                        **one_loop)
        if loop != 0:
            raise ValueError(f"loop = {loop!r}: give 0 (tree level) or 1 (one loop)")
        if one_loop:
            raise TypeError(f"{', '.join(sorted(one_loop))}: options of loop=1 only")
        return super().__new__(cls, triangles, bin_width, legendre_side, effective)


class _PlanInfo:
    """What every plan says about itself (the library's one ``Plan`` seam)."""

    @property
    def plan_info(self):
        """What the plan computes (``what``), how a new spectrum's terms are computed (``method``:
        ``"direct"`` or ``"basis"``) and its memory estimates in bytes (``memory_bytes``: the plan;
        ``terms_bytes``: one spectrum's terms)."""
        plan = getattr(self, "_ept", None) or self._plan
        return plan.plan_info


class RealPlan(_PlanInfo):
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


class EptPlan(_PlanInfo):
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


class TwoLoopRsdPlan(_PlanInfo):
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


def convert_bias(values, from_convention, to_convention="velocileptors"):
    """The galaxy bias ``values`` (a dict, named as ``from_convention`` names them; a missing one is
    0) in ``to_convention``: ``"velocileptors"`` (b1, b2, bs, b3: the convention of every function
    here), ``"fastpt"`` (b1, b2, bs, b3nl: (bs/2)s^2, b3nl = b3/2) or ``"classpt"`` (b1, b2, bG2,
    bGamma3: bs = bG2, b2 = b2^CLASS-PT - (4/3) bG2, b3 = -15 bG2 - 6 bGamma3). Exact (linear maps;
    docs/reference.md, "Bias conventions"). E.g. CLASS-PT's values for :func:`bispectrum`:
    ``pt.convert_bias({"b1": 2, "b2": 0.1, "bG2": -0.3, "bGamma3": 0.5}, "classpt")``."""
    return dict(_core.convert_bias({k: float(v) for k, v in dict(values).items()}, from_convention,
                                   to_convention))


class RsdPlan(_PlanInfo):
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
                        phi_los=0.0, f=None, b1=None, b2=0.0, bs=0.0, b_gamma3=0.0, bias_convention=None,
                        loop_bias=None, multipoles=False, legendre_side="largest", ir=None, bin_width=None):
    """One-loop matter or galaxy bispectrum (SPT) [(Mpc/h)^6] at single triangles.

    ``triangles``: an (n, 3) array of k1, k2, k3 [h/Mpc] (points, not bins). The linear spectrum as in
    ``bispectrum`` (all matter). The loop integrals run over q_min <= |q| <= q_max [h/Mpc] with
    ``radial`` x ``mu`` x ``phi`` nodes per panel (errors: the difference from half the nodes; about
    0.25 s per triangle on 2 cores). Returns a ``Table``: k1 k2 k3 B_tree B222 B321_I B321_II B411
    B_1loop, their err_ columns, and the four EFT counterterm shapes shape_ct_f2, shape_ct_k3,
    shape_ct_tidal, shape_ct_f2k3 [(Mpc/h)^4] (B_ct = sum of ct_c * shape_ct_c, ct_c in (Mpc/h)^2, not
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
    per triangle on 2 cores; no counterterm shapes or multipoles yet).

    Galaxies: any of ``b1``, ``b2``, ``bs`` (in ``bias_convention``, velocileptors' by default, as every
    function), CLASS-PT's ``b_gamma3``, or ``loop_bias`` (a dict of the fourth-order coefficients of
    Eggemeier, Scoccimarro & Smith 2019 by name: b3, g2x, g3, g21, g21x, g211, g22, g31, each in place
    of the value mapped from bs and b_gamma3) gives the one-loop galaxy bispectrum, real space or at
    ``mu1``, directly (2.8-3.3 s per triangle in real space, 6 s in redshift space on 2 cores): the same
    columns, uv_B321_II, uv_B411 (the renormalisation's subtracted amounts) and, in real space, the seven
    counterterm and stochastic shapes shape_ct_k2, shape_ct_k3, shape_ct_kk, shape_ct_tidal, shape_ct_f2k3
    [(Mpc/h)^4], shape_st_p [(Mpc/h)^3], shape_st_1 (not included in B_1loop) (docs/bispectrum.md).

    ``multipoles=True``: the multipoles B0, B2, B4 in redshift space at ``f`` (default f(z)), the Legendre
    polynomial on ``legendre_side`` ("largest", "1", "2", "3"), of the galaxies (or matter without a bias),
    all orientations in one pass over the loop nodes (the orientation rule is exact; about 6 times one
    orientation's cost, ~35 s per triangle at the default rule on 2 cores): columns k1 k2 k3, B{l}_tree,
    B{l}_222, B{l}_321_I, B{l}_321_II, B{l}_411, B{l} (the total) for l = 0, 2, 4, their err_ columns, and
    the multipoles of the 20 redshift-space counterterm and stochastic shapes shape_B{l}_<name>. With
    ``bin_width`` [h/Mpc] (and ``multipoles=True``) each triangle is a bin of three shells of that width: the
    multipoles at its effective triangle (columns k1_eff, k2_eff, k3_eff) plus the departure of the bin
    average from them on a coarse loop rule (exact for the tree level), its error in the err_ columns, the
    shapes averaged over the bin (docs/bispectrum.md).

    ``ir``: the IR resummation of the BAO of the galaxy bispectrum and of the multipoles, on by default as
    the tree level's (``ir=False`` for plain SPT): B_tree with P_nw + exp(-x)(1 + x) P_w in every leg,
    x = k^2 Sigma_tot^2(mu), the loops with P_nw + exp(-q^2 Sigma^2) P_w in every leg (the header states
    Sigma^2 and what the prescription neglects). The matter tables without a bias are plain SPT (``ir=True``
    there is refused; ``b1=1`` gives matter through the galaxy code).
    """
    return _warn(_core.one_loop_bispectrum(triangles, linear, z, z_input, cosmology, eh, q_min, q_max,
                                           radial, mu, phi, two_loop, cache_dir, mu1, phi_los, f, b1, b2,
                                           bs, b_gamma3, bias_convention, loop_bias, multipoles,
                                           legendre_side, ir, bin_width))


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


from .fits import AnalysisLikelihood, fit, fit_ept, fit_joint, fit_tables  # noqa: E402
