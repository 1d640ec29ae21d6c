"""A cobaya theory: redshift-space multipoles of pt-spectra from a CAMB or CLASS linear spectrum.

``pt_spectra.cobaya.PTMultipoles`` takes the linear matter spectrum, H0, fσ8 and σ8 from the
Boltzmann code of the run and provides ``pt_pk_ell``: the multipoles P_ℓ(k) [(Mpc/h)^3] at each
redshift of ``zs`` on its k grid [h/Mpc]. Its loop terms are planned once (``pt.RsdPlan``) in
``initialize``; each evaluation only integrates the new linear spectrum.

Options (yaml or class attributes):

- ``zs``: the redshifts (required).
- ``k``: the output k [h/Mpc], or ``k_min, k_max, nk`` (log-spaced); if none is given, the union of
  the k requested by the likelihoods (``pt_pk_ell: {k: [...]}``) is used.
- ``ells`` ([0, 2, 4]), ``rsd`` ("tns"), ``real`` ("1l-spt"), ``fog`` ("lorentzian"),
  ``precision`` ("default"; "fast" is ~3× cheaper for 2-loop models), ``q_range`` (QMIN, QMAX
  [h/Mpc]), ``cache_dir`` (the angular tables; default $PT_SPECTRA_CACHE or ~/.cache/pt-spectra).
- ``two_loop`` ("basis"): for 2-loop real-space models, the 2-loop terms of each step come from basis
  tensors (built once per k grid and cached, minutes; then milliseconds per step), or ``"direct"``
  (seconds per step). The basis is made of CAMB tables ending at 50 h/Mpc (it also takes tables ending
  from 15 to 50 h/Mpc), so with it the Boltzmann code is asked for k up to at least 35/Mpc (48 to
  57 h/Mpc over the prior's h); a step whose spectrum the basis does not represent is integrated
  directly, with a warning. With classy, give CLASS ``k_per_decade_for_pk: 40`` in the theory's
  ``extra_args``: its default sampling (10 per decade above the BAO range) leaves a projection residual
  of 1.1e-3 (a spline of 10 points per decade at 10 to 50 h/Mpc), which the basis accepts (limit 2e-3)
  with that much more in the loop terms' errors; with 40, 1.8e-4 (measured with classy 3.4.1, Planck
  2018 at z = 0).
- ``k_max_linear`` (10): the k_max [1/Mpc] asked of the Boltzmann code; as h < 1 this covers k up to
  ``k_max_linear`` h/Mpc. The library extends the spectrum beyond both ends by power laws. Raised to
  35 for 2-loop models with ``two_loop: basis``.
- ``var_pair`` (["delta_tot", "delta_tot"]): the Boltzmann spectrum; ["delta_nonu", "delta_nonu"]
  for the CDM + baryon spectrum with massive neutrinos.
- ``prefix`` (""): prefix of the nuisance parameter names, to run two tracers side by side.

Nuisance parameters, one set per redshift ``zs[i]`` (declare them in ``params``, fixed or sampled):

- ``b_i`` (required): the linear bias, constant in k.
- ``sigma0_i`` [Mpc/h] (required unless ``fog: none``): the z = 0 velocity dispersion of the
  Fingers-of-God damping, whose scale is σ = σ0 D(z) f(z) with D = σ8(z)/σ8(0) of the Boltzmann
  code.
- ``A_b_i`` (optional, default 1): the bias amplitude A_b; with a constant bias it multiplies b
  and so is degenerate with it: sample one of them.
- ``P_shot_i`` [(Mpc/h)^3] (optional, default 0): a constant residual shot noise added to the
  monopole. (The library's multipoles are noise-subtracted, as a measured P0 is after removing 1/n.)
- ``cs2_i`` [(Mpc/h)^2] (optional, default 0): the EFT counterterm c_s^2 at zs[i], added to the
  real-space P_dd, P_dt, P_tt as -2, -4, -6 c_s^2 k^2 P_lin before the RSD model (``pt.rsd``'s
  ``cs2``); a fast parameter like the others.

Alcock–Paczynski (``rsd: ept`` only): ``ap_fiducial: {Omega_m: 0.31}`` is the flat ΛCDM cosmology the
data were measured in (radiation neglected: ≲ 1e-4 in the α's at z < 3); at each step α∥ =
E_fid(z)/E(z) and α⊥ = D_M(z)/D_M,fid(z) (distances in Mpc/h; E, D_M of the Boltzmann code) distort the
model (plan built for 0.8 ≤ α ≤ 1.25; a step outside has zero likelihood, with a log message), and
``get_pt_ap(z)`` returns them.

The tree-level bispectrum (``bispectrum: true``, ``rsd: ept`` only): the theory also provides
``pt_bk_ell``, the bin-averaged B_ℓ(k₁, k₂, k₃) [(Mpc/h)^6] of :class:`pt_spectra.BispectrumPlan` at the
triangles a likelihood requests (``pt_bk_ell: {z, triangles, bin_width, ells}``; one triangle set per
redshift), with the spectrum, f and α∥, α⊥ of the multipoles, IR resummation as ``ir``, and b1, b2, bs
shared with them (velocileptors' convention in both). Its own parameters per redshift: ``c1_i``
[(Mpc/h)^2] (the k²μ² counterterm of every leg, default 0), ``b_shot_i`` (1), ``p_shot_i`` (0),
``a_shot_i`` (0) (the stochastic terms in units of 1/n̄, Ivanov et al. 2021; Poisson: 1, 0, 0); the
options ``n_bar`` [(h/Mpc)^3] (default none: no stochastic terms, logged), ``b_fog`` ("none",
"lorentzian", "gaussian") and ``b_sigma_fog`` [Mpc/h]. Each new spectrum, f or α costs the bispectrum
terms (about 11 ms for 62 bins on one core); a step in the biases or the B parameters alone costs
microseconds. ``get_pt_bk_ell(z)`` is an array [len(ells), n_triangles], ``get_pt_bk_ell_err(z)`` its
quadrature errors.

The multipoles requested by a likelihood (``pt_pk_ell: {ells: [...]}``, e.g. 0 … 8 for a window) are
added to ``ells``.

With ``rsd: ept`` the theory computes the galaxy model (:class:`pt_spectra.EptPlan`, velocileptors'
conventions; ``ir`` (true) switches the BAO resummation) and its nuisance parameters per redshift are
velocileptors' names with the suffix: ``b1_i`` (required), ``b2_i``, ``bs_i``, ``b3_i``,
``alpha0_i``, ``alpha2_i``, ``alpha4_i``, ``alpha6_i`` [(Mpc/h)^2], ``sn_i``, ``sn2_i``, ``sn4_i``
(default 0; sn is the constant stochastic term, so no separate P_shot); ``real``, ``fog``, ``two_loop``
do not apply. Bias conventions: ``bias_convention: classpt`` names the bias as CLASS-PT does,
``b1_i``, ``b2_i``, ``bG2_i``, ``bGamma3_i`` (CLASS-PT's b2, b_G2, b_Γ3), ``fastpt`` as FAST-PT does
(``bs_i`` its (bs/2)s², ``b3nl_i``); each step maps them exactly to velocileptors' (docs/reference.md,
"Bias conventions"), so priors are written as those codes' analyses publish them.

Without a Boltzmann code (``emulator: true``): the theory takes the cosmological parameters itself and
computes the linear spectrum with the library's emulator (:class:`pt_spectra.LinearEmulator`, 0.1 ms per
redshift; see the documentation for its prior and accuracy). Parameters (cobaya/CAMB or CLASS names, each
fixed or sampled in ``params``): ``ombh2``/``omega_b``, ``omch2``/``omega_cdm``, ``H0``/``h``,
``logA``/``As``/``A_s``, ``ns``/``n_s`` (required), ``mnu``/``m_ncdm`` (Σm_ν in eV, read as CAMB's
``mnu``: one massive species, CAMB's and cobaya's default, which the emulator refuses (it emulates three
degenerate species only: set the theory's ``neutrinos: three degenerate`` to use it with massive
neutrinos; see the documentation); default 0), ``w``/``w0_fld`` (-1), ``wa``/``wa_fld`` (0). The models use P_cb (cold dark matter +
baryons), f = f_cb(k = 0.1 h/Mpc, z) and D = σ8(z)/σ8(0) of P_m; a cosmology outside the prior gets zero
likelihood (logged). With ``ap_fiducial``, H(z) and D_M(z) of the sampled cosmology come from
:func:`pt_spectra.distances` (radiation as CAMB closes the budget; massive neutrinos as matter: within
2e-5 of CAMB's at z ≤ 3).

Derived parameters (declare them in ``params`` to have them in the chain): ``fsigma8_i`` = f σ8(zs[i])
with the f of the model, and ``sigma8_i`` = σ8(zs[i]) of all matter (Boltzmann code or emulator).

The linear spectrum is the Boltzmann code's own ``Pk_grid`` at exactly each z (k [1/Mpc] and P
[Mpc^3] converted to h/Mpc and (Mpc/h)^3 with its H0), rather than ``Pk_interpolator``: no second
interpolation, and no need for the ≥ 4 redshifts that the interpolator requires. The growth rate is
f = fσ8/σ8 of the Boltzmann code (for massive neutrinos an effective, scale-independent f).
"""

from __future__ import annotations

import hashlib
import warnings

import numpy as np

try:
    from cobaya.theory import Theory
except ImportError as e:  # pragma: no cover - depends on the environment
    raise ImportError(
        "pt_spectra.cobaya needs cobaya (and a Boltzmann code): pip install cobaya camb"
    ) from e

import pt_spectra as pt

__all__ = ["PTMultipoles", "NUISANCE", "EPT_NUISANCE", "BISPECTRUM_NUISANCE"]

#: The nuisance parameters of one redshift: name -> (required, default, unit).
NUISANCE = {
    "b": (True, None, ""),
    "sigma0": (True, None, "Mpc/h"),
    "A_b": (False, 1.0, ""),
    "P_shot": (False, 0.0, "(Mpc/h)^3"),
    "cs2": (False, 0.0, "(Mpc/h)^2"),
}

#: The cosmological parameters of ``emulator: true``: accepted names -> (ini key, required, default).
COSMOLOGY = {
    "ombh2": ("ombh2", True, None), "omega_b": ("ombh2", True, None),
    "omch2": ("omch2", True, None), "omega_cdm": ("omch2", True, None),
    "H0": ("H0", True, None), "h": ("h", True, None),
    "logA": ("ln10^{10}A_s", True, None), "As": ("As", True, None), "A_s": ("As", True, None),
    "ns": ("ns", True, None), "n_s": ("ns", True, None),
    "mnu": ("mnu", False, 0.0), "m_ncdm": ("mnu", False, 0.0),
    "w": ("w", False, -1.0), "w0_fld": ("w", False, -1.0),
    "wa": ("wa", False, 0.0), "wa_fld": ("wa", False, 0.0),
}

#: The k [h/Mpc] at which the emulator's scale-dependent f_cb(k, z) is taken as the model's f (the
#: library's, as the command line and pt.rsd take it).
K_GROWTH_RATE = pt._core.K_GROWTH_RATE

#: The nuisance parameters of one redshift with ``rsd: ept`` (velocileptors' names).
EPT_NUISANCE = {"b1": (True, None, "")} | {
    name: (False, 0.0, unit) for name, unit in (
        ("b2", ""), ("bs", ""), ("b3", ""), ("alpha0", "(Mpc/h)^2"), ("alpha2", "(Mpc/h)^2"),
        ("alpha4", "(Mpc/h)^2"), ("alpha6", "(Mpc/h)^2"), ("sn", "(Mpc/h)^3"), ("sn2", "(Mpc/h)^5"),
        ("sn4", "(Mpc/h)^7"))
}

#: The bias parameters' names in each ``bias_convention`` (the library's table).
_BIAS_NAMES = pt._BIAS_NAMES

#: The bispectrum's own parameters per redshift with ``bispectrum: true`` (b1, b2, bs are shared with
#: the galaxy model): name -> (required, default, unit).
BISPECTRUM_NUISANCE = {"c1": (False, 0.0, "(Mpc/h)^2"), "b_shot": (False, 1.0, ""),
                       "p_shot": (False, 0.0, ""), "a_shot": (False, 0.0, "")}

#: The bispectrum multipoles a plan computes, in the order of its columns.
B_ELLS = (0, 2, 4)

# The library warns that without a cosmology the growth of its gm2012 cosmology is used. It does
# not apply here: z_input = z (the spectrum is used as given, rescaling factor 1), f is passed, and
# the only other use of D(z), the FoG scale σ0 D(z) f, gets D_boltzmann(z) as `growth_factor`.
_NO_COSMOLOGY = "no cosmology was given for the linear spectrum"
_FALLBACK = r".*: direct \(fallback"


def _close_index(values, x, what):
    """The index of x in values (relative tolerance 1e-8), or a ValueError naming `what`."""
    values = np.asarray(values, dtype=float)
    hits = np.flatnonzero(np.isclose(values, x, rtol=1e-8, atol=1e-12))
    if hits.size == 0:
        raise ValueError(f"{what} = {x} is not among {list(values)}")
    return int(hits[0])


class PTMultipoles(Theory):
    """Redshift-space multipoles P_ℓ(k) [(Mpc/h)^3], k [h/Mpc], of pt-spectra (see the module)."""

    zs: list | None = None
    k: list | None = None
    k_min: float | None = None
    k_max: float | None = None
    nk: int | None = None
    ells: list = [0, 2, 4]
    rsd: str = "tns"
    real: str = "1l-spt"
    fog: str = "lorentzian"
    precision: str = "default"
    q_range: list | None = None
    cache_dir: str | None = None
    k_max_linear: float = 10.0
    two_loop: str = "basis"
    var_pair: list = ["delta_tot", "delta_tot"]
    prefix: str = ""
    ir: bool = True
    ap_fiducial: dict | None = None
    emulator: bool = False
    #: with ``emulator: true``, how Σm_ν is shared: None (``mnu``'s own convention, CAMB's one massive
    #: species) or "three degenerate" (the setting the emulator emulates)
    neutrinos: str | None = None
    #: provide ``pt_bk_ell``, the tree-level bispectrum multipoles (rsd: ept only; module docs)
    bispectrum: bool = False
    n_bar: float | None = None
    b_fog: str = "none"
    b_sigma_fog: float = 0.0
    #: rsd: ept: the names of the bias parameters (module docs, "Bias conventions")
    bias_convention: str = "velocileptors"

    # ---- set-up ------------------------------------------------------------------------------
    def initialize(self):
        if self.zs is None:
            raise ValueError("PTMultipoles: option `zs` (the list of redshifts) is required")
        self.zs = [float(z) for z in np.atleast_1d(self.zs)]
        if any(not np.isfinite(z) or z < 0 for z in self.zs) or len(set(self.zs)) != len(self.zs):
            raise ValueError(f"PTMultipoles: `zs` must be distinct redshifts >= 0, got {self.zs}")
        self.ells = [int(ell) for ell in np.atleast_1d(self.ells)]
        if not self.ells or any(ell < 0 or ell % 2 or ell > 8 for ell in self.ells):
            raise ValueError(f"PTMultipoles: `ells` must be even multipoles <= 8, got {self.ells}")
        self._ept = str(self.rsd).lower() == "ept"
        convention = str(self.bias_convention).lower().replace("-", "").replace("_", "")
        if convention not in _BIAS_NAMES:
            raise ValueError(f"PTMultipoles: unknown `bias_convention` {self.bias_convention!r}; "
                             f"available: {', '.join(_BIAS_NAMES)}")
        if convention != "velocileptors" and not self._ept:
            raise ValueError("PTMultipoles: `bias_convention` is an option of rsd: ept (the paper's "
                             "models take b, sigma0, A_b)")
        self._convention = convention
        if self.fog not in ("none", "lorentzian", "gaussian"):
            raise ValueError(f"PTMultipoles: unknown `fog` {self.fog!r}; "
                             "available: none, lorentzian, gaussian")
        if not self.k_max_linear > 0:
            raise ValueError(f"PTMultipoles: `k_max_linear` must be > 0, got {self.k_max_linear}")
        if len(self.var_pair) != 2:
            raise ValueError(f"PTMultipoles: `var_pair` must be two names, got {self.var_pair}")
        self._ap_omega_m = None
        self._emulator = pt.LinearEmulator() if self.emulator else None
        if self.ap_fiducial is not None:
            if not self._ept:
                raise ValueError("PTMultipoles: `ap_fiducial` is supported with rsd: ept only")
            om = dict(self.ap_fiducial).get("Omega_m")
            if om is None or not 0.0 < float(om) < 1.0:
                raise ValueError("PTMultipoles: `ap_fiducial` needs Omega_m in (0, 1) of the flat "
                                 f"fiducial, got {self.ap_fiducial}")
            self._ap_omega_m = float(om)
        if self.bispectrum:
            if not self._ept:
                raise ValueError("PTMultipoles: `bispectrum: true` needs rsd: ept (its bias convention)")
            if self.b_fog not in ("none", "lorentzian", "gaussian"):
                raise ValueError(f"PTMultipoles: unknown `b_fog` {self.b_fog!r}; "
                                 "available: none, lorentzian, gaussian")
            if not (np.isfinite(self.b_sigma_fog) and self.b_sigma_fog >= 0):
                raise ValueError(f"PTMultipoles: `b_sigma_fog` must be >= 0 [Mpc/h], got "
                                 f"{self.b_sigma_fog}")
            if self.n_bar is not None and not (np.isfinite(self.n_bar) and self.n_bar > 0):
                raise ValueError(f"PTMultipoles: `n_bar` must be > 0 [(h/Mpc)^3], got {self.n_bar}")
            if self.n_bar is None:
                self.log.info("bispectrum: no n_bar, so no stochastic terms (b_shot, p_shot, "
                              "a_shot have no effect)")
        # per z: the requested (triangles, bin_width, ells), its plan, and the cached terms
        self._b_requests = {}
        self._b_plans = {}
        self._b_terms = {}
        self._k = self._option_grid()
        self._requested_k: list[float] = []
        self._plan = None
        self._planned_k = None
        # Loop terms per redshift, kept while the linear spectrum is unchanged: a step that moves only
        # the nuisance parameters costs a multipole evaluation (microseconds), not the loops.
        self._terms = {}
        if self._k is not None:
            self._make_plan(self._k)

    def _option_grid(self):
        given = [self.k_min is not None, self.k_max is not None, self.nk is not None]
        if self.k is not None:
            if any(given):
                raise ValueError("PTMultipoles: give either `k` or `k_min, k_max, nk`, not both")
            k = np.asarray(self.k, dtype=float).ravel()
            if k.size == 0 or np.any(~np.isfinite(k)) or np.any(k <= 0) or np.any(np.diff(k) <= 0):
                raise ValueError("PTMultipoles: `k` must be increasing positive wavenumbers "
                                 "[h/Mpc]")
            return k
        if any(given) and not all(given):
            raise ValueError("PTMultipoles: `k_min`, `k_max` and `nk` go together")
        if not all(given):
            return None
        return pt.log_grid(float(self.k_min), float(self.k_max), int(self.nk))

    def _k_max_linear(self):
        """k_max [1/Mpc] of the Boltzmann spectrum: 35 at least with the 2-loop basis."""
        if str(self.real).startswith("2l-") and self.two_loop != "direct":
            return max(float(self.k_max_linear), 35.0)
        return float(self.k_max_linear)

    def _table(self):
        """The nuisance parameters of the model: name -> (required, default, unit); the bias named as
        `bias_convention` names it."""
        if not self._ept:
            return NUISANCE
        rename = dict(zip(_BIAS_NAMES["velocileptors"], _BIAS_NAMES[self._convention]))
        table = {rename.get(n, n): v for n, v in EPT_NUISANCE.items()}
        return table | BISPECTRUM_NUISANCE if self.bispectrum else table

    def _make_plan(self, k):
        if self._ept:
            self._plan = pt.EptPlan(k, ir=bool(self.ir), precision=self.precision,
                                    q_range=None if self.q_range is None else tuple(self.q_range),
                                    free_ap=self._ap_omega_m is not None)
            self._planned_k = np.asarray(k, dtype=float)
            return
        self._plan = pt.RsdPlan(k, real=self.real, rsd=self.rsd, precision=self.precision,
                                q_range=None if self.q_range is None else tuple(self.q_range),
                                cache_dir=self.cache_dir, two_loop=self.two_loop)
        self._planned_k = np.asarray(k, dtype=float)

    def param_name(self, name, i):
        """The name of nuisance parameter `name` (b, sigma0, A_b, P_shot, cs2) of redshift zs[i]."""
        return f"{self.prefix}{name}_{i}"

    def get_can_support_params(self):
        nuisance = [self.param_name(n, i) for i in range(len(self.zs)) for n in self._table()]
        return nuisance + (list(COSMOLOGY) if self.emulator else [])

    def get_can_provide_params(self):
        """Derived: ``fsigma8_i`` (f σ8(zs[i]) of the model's f) and ``sigma8_i`` (σ8 of all matter at
        zs[i]), with the prefix."""
        return [self.param_name(n, i) for i in range(len(self.zs)) for n in ("fsigma8", "sigma8")]

    def initialize_with_params(self):
        given = set(self.input_params)
        missing, defaulted = [], []
        if self.emulator:
            for key in ("ombh2", "omch2", "H0", "As", "ns"):
                names = [n for n, (k, _, _) in COSMOLOGY.items() if k == key or
                         (key == "H0" and k == "h") or (key == "As" and k == "ln10^{10}A_s")]
                if not given & set(names):
                    missing.append(" or ".join(names))
        for i in range(len(self.zs)):
            for name, (required, default, _) in self._table().items():
                p = self.param_name(name, i)
                if name == "sigma0" and self.fog == "none":
                    if p in given:
                        self.log.warning("%s has no effect with fog: none", p)
                    continue
                if p in given:
                    continue
                (missing if required else defaulted).append(p if required else f"{p} = {default}")
        if missing:
            raise ValueError(
                f"PTMultipoles: parameters {', '.join(missing)} are required (fixed or sampled in "
                "`params`); see pt_spectra.cobaya for their meaning")
        if defaulted:
            self.log.info("Nuisance parameters not given, fixed at: %s", ", ".join(defaulted))

    def get_requirements(self):
        if self.emulator:
            return {}
        zs = self.zs
        requirements = {
            "Pk_grid": {"z": zs, "k_max": self._k_max_linear(), "nonlinear": False,
                        "vars_pairs": [list(self.var_pair)]},
            "fsigma8": {"z": zs},
            "sigma8_z": {"z": sorted(set([0.0] + zs))},
            "H0": None,
        }
        if self._ap_omega_m is not None:
            requirements["Hubble"] = {"z": zs}
            requirements["angular_diameter_distance"] = {"z": zs}
        return requirements

    def _alphas(self, background):
        """{z: (α∥, α⊥)} against the flat fiducial of ``ap_fiducial`` from {z: (E(z), D_M(z) [Mpc/h])}
        of the sampled cosmology (module docs)."""
        om = self._ap_omega_m
        out = {}
        for z in self.zs:
            e, dm = background[z]
            zz = np.linspace(0.0, z, 2001)
            e_fid = np.sqrt(om * (1 + zz) ** 3 + 1 - om)
            # D_M,fid in Mpc/h: (c/100) ∫ dz/E_fid (Simpson).
            w = np.ones_like(zz)
            w[1:-1:2], w[2:-1:2] = 4.0, 2.0
            dm_fid = 2997.92458 * (zz[1] - zz[0]) / 3.0 * np.sum(w / e_fid) if z > 0 else 0.0
            out[z] = (e_fid[-1] / e, dm / dm_fid if z > 0 else e_fid[-1] / e)
        return out

    def must_provide(self, **requirements):
        super().must_provide(**requirements)
        options = requirements.get("pt_pk_ell") or {}
        for z in np.atleast_1d(options.get("z", [])):
            _close_index(self.zs, float(z), "requested pt_pk_ell z")
        for ell in options.get("ells") or []:
            ell = int(ell)
            if ell < 0 or ell % 2 or ell > 8:
                raise ValueError(f"PTMultipoles: requested multipole {ell} is not even and <= 8")
            if ell not in self.ells:
                self.ells = sorted(self.ells + [ell])
        self._request_bispectrum(requirements.get("pt_bk_ell"))
        k = np.atleast_1d(options.get("k", [])).astype(float)
        if k.size and self._k is not None:
            for ki in k:
                _close_index(self._k, ki, "requested pt_pk_ell k [h/Mpc]")
        elif k.size:
            self._requested_k = sorted(set(self._requested_k) | set(k.tolist()))
        return None

    def _request_bispectrum(self, options):
        """Records a likelihood's ``pt_bk_ell: {z, triangles, bin_width, ells}`` (one set per z)."""
        if options is None:
            return
        if not self.bispectrum:
            raise ValueError("PTMultipoles: a likelihood requires pt_bk_ell: set the theory's "
                             "`bispectrum: true` (with rsd: ept)")
        if "z" not in options or "triangles" not in options:
            raise ValueError("PTMultipoles: pt_bk_ell needs `z` and `triangles` (rows k1 k2 k3 "
                             "[h/Mpc])")
        z = self.zs[_close_index(self.zs, float(options["z"]), "requested pt_bk_ell z")]
        triangles = np.asarray(options["triangles"], dtype=float)
        if triangles.ndim != 2 or triangles.shape[1] != 3 or triangles.shape[0] == 0:
            raise ValueError(f"PTMultipoles: pt_bk_ell triangles must be rows of k1 k2 k3, got "
                             f"shape {triangles.shape}")
        width = options.get("bin_width")
        width = None if width is None else float(width)
        ells = [int(ell) for ell in options.get("ells", B_ELLS)]
        if not ells or any(ell not in B_ELLS for ell in ells):
            raise ValueError(f"PTMultipoles: pt_bk_ell ells must be among {list(B_ELLS)}, got {ells}")
        request = (triangles, width, ells)
        old = self._b_requests.get(z)
        if old is not None and not (np.array_equal(old[0], triangles) and old[1] == width):
            raise ValueError(f"PTMultipoles: two different triangle sets requested at z = {z}: "
                             "one bispectrum per redshift (give both likelihoods the same triangles)")
        if old is not None:
            request = (triangles, width, sorted(set(old[2]) | set(ells)))
        self._b_requests[z] = request
        # the plan (its nodes) depends only on the triangles and the width: made here, once
        self._b_plans[z] = pt.BispectrumPlan(triangles, bin_width=width)

    def initialize_with_provider(self, provider):
        super().initialize_with_provider(provider)
        k = self._k if self._k is not None else np.asarray(self._requested_k)
        if k.size == 0:
            raise ValueError("PTMultipoles: no k grid: give `k` (or `k_min, k_max, nk`), or "
                             "require pt_pk_ell with a `k` list from the likelihood")
        if self._planned_k is None or not np.array_equal(k, self._planned_k):
            self._make_plan(k)

    # ---- computation -------------------------------------------------------------------------
    def _nuisance(self, params, i):
        # the required ones are in `params` (checked in initialize_with_params), except sigma0
        # with fog: none, where it has no effect; the bias in velocileptors' convention
        values = {name: float(params.get(self.param_name(name, i), 0.0 if d is None else d))
                  for name, (_, d, _) in self._table().items()}
        if self._ept and self._convention != "velocileptors":
            given = {n: values.pop(n) for n in _BIAS_NAMES[self._convention]}
            values.update(pt.convert_bias(given, self._convention))
        return values

    def _emulated(self, params):
        """({z: (k, P_cb, f, D, σ8)}, {z: (α∥, α⊥)}) from the emulator and the library's background,
        or None outside the emulator's prior (logged)."""
        keys = {COSMOLOGY[n][0]: params[n] for n in COSMOLOGY if n in params}
        if self.neutrinos is not None:
            keys["neutrinos"] = self.neutrinos
        try:
            today = self._emulator.spectra(keys, 0.0)
            out = {}
            for z in self.zs:
                s = self._emulator.spectra(keys, z)
                f = float(np.interp(np.log(K_GROWTH_RATE), np.log(s["k"]), s["f_cb"]))
                out[z] = (s["k"], s["P_cb"], f, s["sigma8"] / today["sigma8"], s["sigma8"])
            alphas = {}
            if self._ap_omega_m is not None:
                background = {}
                for z in self.zs:
                    hubble, dm = pt.distances(z, keys)
                    background[z] = (hubble / 100.0, dm)
                alphas = self._alphas(background)
            return out, alphas
        except ValueError as e:
            if str(e).startswith("neutrinos:"):
                # A setting the emulator does not emulate is the same at every point of the chain: a
                # zero likelihood everywhere would hide it, so it stops the run with the library's words.
                raise ValueError(f"PTMultipoles (emulator: true): {e}") from e
            self.log.debug("emulator: %s", e)
            return None

    def calculate(self, state, want_derived=True, **params_values_dict):
        if self.emulator:
            emulated = self._emulated(params_values_dict)
            if emulated is None:
                return False
            linear, alphas = emulated
            return self._multipoles(state, params_values_dict, linear, alphas, want_derived)
        h = self.provider.get_param("H0") / 100.0
        k_mpc, z_grid, pk = self.provider.get_Pk_grid(var_pair=tuple(self.var_pair),
                                                      nonlinear=False)
        k_lin = np.asarray(k_mpc) / h
        fs8 = np.atleast_1d(self.provider.get_fsigma8(self.zs))
        s8 = np.atleast_1d(self.provider.get_sigma8_z(self.zs))
        s8_0 = float(np.atleast_1d(self.provider.get_sigma8_z([0.0]))[0])
        alphas = {}
        if self._ap_omega_m is not None:
            hubble = np.atleast_1d(self.provider.get_Hubble(self.zs))
            d_a = np.atleast_1d(self.provider.get_angular_diameter_distance(self.zs))
            alphas = self._alphas({z: (hubble[i] / (100.0 * h), (1 + z) * d_a[i] * h)
                                   for i, z in enumerate(self.zs)})
        linear = {}
        for i, z in enumerate(self.zs):
            p_lin = np.asarray(pk[_close_index(z_grid, z, "z of the Boltzmann P(k) grid")]) * h**3
            linear[z] = (k_lin, p_lin, fs8[i] / s8[i], s8[i] / s8_0, s8[i])
        return self._multipoles(state, params_values_dict, linear, alphas, want_derived)

    def _multipoles(self, state, params_values_dict, linear, alphas, want_derived=True):
        """The multipoles of each z from {z: (k [h/Mpc], P_lin [(Mpc/h)^3], f, D, σ8(z))}."""
        spectra, errors, growth, derived = {}, {}, {}, {}
        b_spectra, b_errors = {}, {}
        for i, z in enumerate(self.zs):
            k_lin, p_lin, f, d, s8 = linear[z]
            derived[self.param_name("fsigma8", i)] = f * s8
            derived[self.param_name("sigma8", i)] = s8
            nu = self._nuisance(params_values_dict, i)
            # the galaxy model's own parameters (the bispectrum's are used by _bispectrum only)
            nu_p = {n: v for n, v in nu.items() if n not in BISPECTRUM_NUISANCE}
            digest = hashlib.sha1(k_lin.tobytes() + p_lin.tobytes()).digest()
            with warnings.catch_warnings():
                # The spectrum is given at z (no rescaling), f and D come from the Boltzmann code:
                # the default-cosmology growth the warning is about is not used.
                warnings.filterwarnings("ignore", message=_NO_COSMOLOGY,
                                        category=pt.PtSpectraWarning)
                # a fallback to direct integrals is stated once in the log (below), not at every step
                warnings.filterwarnings("ignore", message=_FALLBACK, category=pt.PtSpectraWarning)
                cached = self._terms.get(i)
                if cached is None or cached[0] != digest:
                    cached = (digest, self._plan.terms(linear=(k_lin, p_lin), z=z, z_input=z))
                    self._terms[i] = cached
                if self._ept and z in alphas:
                    apar, aperp = alphas[z]
                    try:
                        t = cached[1].multipoles(ells=self.ells, f=f, apar=apar, aperp=aperp, **nu_p)
                    except ValueError as e:
                        self.log.debug("z = %g: alpha_par %.4f, alpha_perp %.4f outside the plan: %s",
                                       z, apar, aperp, e)
                        return False
                elif self._ept:
                    t = cached[1].multipoles(ells=self.ells, f=f, **nu_p)
                else:
                    t = cached[1].multipoles(f=f, bias=nu["b"], amplitude=nu["A_b"], fog=self.fog,
                                             sigma0=nu["sigma0"], ells=self.ells,
                                             growth_factor=d, cs2=nu["cs2"])
            self._note_fallbacks(t)
            if z in self._b_requests:
                ap = alphas.get(z, (1.0, 1.0))
                bk = self._bispectrum(z, digest, (k_lin, p_lin), f, ap, nu)
                b_spectra[z], b_errors[z] = bk
            p = np.array([t[f"P{ell}"] for ell in self.ells])
            if 0 in self.ells and not self._ept:
                p[self.ells.index(0)] += nu["P_shot"]
            spectra[z] = p
            errors[z] = np.array([t[f"err_P{ell}"] for ell in self.ells])
            growth[z] = (f, d)
        state["pt_pk_ell"] = spectra
        state["pt_pk_ell_err"] = errors
        state["pt_growth"] = growth
        state["pt_ap"] = alphas
        state["pt_bk_ell"] = b_spectra
        state["pt_bk_ell_err"] = b_errors
        if want_derived:
            state["derived"] = derived

    def _note_fallbacks(self, table):
        """States in the log, once per part and method, a part of the model integrated directly because
        the spectrum is not one the basis tensors represent (``meta["methods"]``; slower, same accuracy)."""
        noted = self.__dict__.setdefault("_fallbacks_noted", set())
        for part, method in table.meta.get("methods", {}).items():
            if "fallback" in method and (part, method) not in noted:
                noted.add((part, method))
                self.log.info("%s: %s (slower; stated once)", part, method)

    def _bispectrum(self, z, digest, linear, f, ap, nu):
        """(B, err) [len(ells), n_triangles] of the requested triangles at z: the terms are kept while
        the spectrum, f and the α's are unchanged, so a step in the biases alone costs microseconds."""
        _, _, ells = self._b_requests[z]
        key = (digest, float(f), float(ap[0]), float(ap[1]))
        cached = self._b_terms.get(z)
        if cached is None or cached[0] != key:
            with warnings.catch_warnings():
                warnings.filterwarnings("ignore", message=_NO_COSMOLOGY,
                                        category=pt.PtSpectraWarning)
                terms = self._b_plans[z].terms(linear=linear, z=z, z_input=z, f=f, q_par=ap[0],
                                               q_perp=ap[1], fog=self.b_fog,
                                               sigma_fog=float(self.b_sigma_fog), ir=bool(self.ir))
            cached = (key, terms)
            self._b_terms[z] = cached
        b, err = cached[1].multipoles(b1=nu["b1"], b2=nu["b2"], bs=nu["bs"], c1=nu["c1"],
                                      n_bar=self.n_bar, b_shot=nu["b_shot"], p_shot=nu["p_shot"],
                                      a_shot=nu["a_shot"])
        columns = [B_ELLS.index(ell) for ell in ells]
        return np.asarray(b)[:, columns].T, np.asarray(err)[:, columns].T

    # ---- products ----------------------------------------------------------------------------
    def _at(self, name, z):
        values = self.current_state[name]
        return values if z is None else values[self.zs[_close_index(self.zs, z, "z")]]

    def get_pt_pk_ell(self, z=None):
        """{z: array [len(ells), len(k)]} of P_ℓ(k) [(Mpc/h)^3], or the array of one z."""
        return self._at("pt_pk_ell", z)

    def get_pt_pk_ell_err(self, z=None):
        """The numerical error bounds of :meth:`get_pt_pk_ell` (loop integrals, μ quadrature)."""
        return self._at("pt_pk_ell_err", z)

    def get_pt_growth(self, z=None):
        """{z: (f, D)} with f = fσ8/σ8 and D = σ8(z)/σ8(0) of the Boltzmann code."""
        return self._at("pt_growth", z)

    def get_pt_ap(self, z=None):
        """{z: (α∥, α⊥)} against ``ap_fiducial`` (empty without it), or the pair of one z."""
        values = self.current_state["pt_ap"]
        return values if z is None else values[self.zs[_close_index(self.zs, z, "z")]]

    def get_pt_bk_ell(self, z=None):
        """{z: array [len(ells), n_triangles]} of the bispectrum multipoles B_ℓ [(Mpc/h)^6] at the
        requested triangles (``bispectrum: true``), or the array of one z; rows in the order of
        :meth:`get_pt_bk_ells`."""
        return self._at("pt_bk_ell", z)

    def get_pt_bk_ell_err(self, z=None):
        """The quadrature errors of :meth:`get_pt_bk_ell`."""
        return self._at("pt_bk_ell_err", z)

    def get_pt_bk_ells(self, z):
        """The bispectrum multipoles ℓ at z, in the order of the rows of :meth:`get_pt_bk_ell`."""
        return list(self._b_requests[self.zs[_close_index(self.zs, z, "z")]][2])

    def get_pt_k(self):
        """The k grid [h/Mpc] of the multipoles."""
        return self._planned_k.copy()

    def get_pt_ells(self):
        """The multipoles ℓ, in the order of the rows of :meth:`get_pt_pk_ell`."""
        return list(self.ells)
