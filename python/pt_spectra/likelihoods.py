"""cobaya likelihoods for the multipoles of :mod:`pt_spectra.cobaya`.

``SurveyMultipoles``: a survey measurement, as analyses of BOSS or DESI fit it: a data vector of any
multipoles P_ℓ(k) (or ξ_ℓ(s)) with a full covariance (its inverse scaled by the Hartlap factor with
``n_mocks``), the model taken through the survey window and the k bins (:class:`pt_spectra.Observation`)
and, with the theory's ``ap_fiducial``, distorted by AP; a k range per multipole. Below it,
``MultipoleGaussian``, the simplest case (diagonal errors, the model at the data's k).

``AnalysisFile``: the likelihood of a TOML analysis file (docs/analysis.md) with its template spectrum
fixed, the function ``fit --analysis`` minimises (linear parameters marginalised analytically, every
prior of the file included), needing no theory: posteriors beside the fit's profile likelihoods.

``PowerBispectrum``: the joint likelihood of window-free power-spectrum and bispectrum multipoles with
one covariance (P + B analyses: BOSS, DESI), the bispectrum from the theory's ``pt_bk_ell``
(``bispectrum: true``), sharing its spectrum, f, α's and b1, b2, bs with the power spectrum.

``MultipoleGaussian``: a Gaussian likelihood with diagonal errors of measured multipoles at one
redshift, logp = -χ²/2 with χ² = Σ_ℓ Σ_k [(P_ℓ^model - P_ℓ^data) / σ_ℓ]². The model is
``pt_pk_ell`` of a :class:`pt_spectra.cobaya.PTMultipoles` theory at the same k.

Options:

- ``data_file``: an ``.npz`` with arrays ``k`` [h/Mpc] and, for each multipole ℓ, ``P<ℓ>`` and
  ``s<ℓ>`` [(Mpc/h)^3] (value and 1σ error, e.g. ``P0``, ``s0``); or a text file with columns
  ``k P_ℓ σ_ℓ …`` for the multipoles ``data_ells`` (default [0, 2, 4], the layout of
  ``pt-spectra fit``). Relative paths are relative to the working directory.
- ``z``: the redshift of the data (one of the theory's ``zs``).
- ``ells``: the multipoles used (default: all in the file); ``k_min``, ``k_max`` [h/Mpc]: cuts.

The theory's k grid must contain the data's k (to relative 1e-8); if the theory has no ``k``
option it takes the data's.
"""

from __future__ import annotations

import os

import numpy as np

import pt_spectra as pt
from pt_spectra import _core

try:
    from cobaya.likelihood import Likelihood
except ImportError as e:  # pragma: no cover - depends on the environment
    raise ImportError("pt_spectra.likelihoods needs cobaya: pip install cobaya camb") from e

__all__ = ["AnalysisFile", "MultipoleGaussian", "PowerBispectrum", "SurveyMultipoles",
           "read_multipoles", "read_columns", "cobaya_name"]


def read_multipoles(path, data_ells=(0, 2, 4)):
    """``(k, {ℓ: P_ℓ}, {ℓ: σ_ℓ})`` from an npz (``k``, ``P<ℓ>``, ``s<ℓ>``) or a text file with
    columns ``k P_ℓ σ_ℓ …`` for the multipoles ``data_ells``. k in h/Mpc, P and σ in (Mpc/h)^3."""
    path = os.fspath(path)
    if not os.path.isfile(path):
        raise ValueError(f"data_file: no file {path!r}")
    if path.endswith(".npz"):
        with np.load(path) as d:
            if "k" not in d:
                raise ValueError(f"data_file {path!r}: no array `k`")
            ells = sorted(int(n[1:]) for n in d.files if n[:1] == "P" and n[1:].isdigit())
            missing = [f"s{ell}" for ell in ells if f"s{ell}" not in d]
            if not ells or missing:
                raise ValueError(f"data_file {path!r}: needs P<l> and s<l> arrays for each "
                                 f"multipole (found {d.files}; missing {missing})")
            k = np.asarray(d["k"], dtype=float)
            values = {ell: np.asarray(d[f"P{ell}"], dtype=float) for ell in ells}
            sigma = {ell: np.asarray(d[f"s{ell}"], dtype=float) for ell in ells}
    else:
        # The library's reader (the one `fit --data` uses): every error names the file and line.
        k, values, sigma = _core.read_multipoles(path, [int(ell) for ell in data_ells])
    for ell in values:
        if values[ell].shape != k.shape or sigma[ell].shape != k.shape:
            raise ValueError(f"data_file {path!r}: P{ell} or s{ell} has not the length of k")
        if np.any(~(sigma[ell] > 0)):
            raise ValueError(f"data_file {path!r}: the errors s{ell} must be > 0")
    return k, values, sigma


def _columns_of(theory_k, data_k, who):
    """The index of each data k [h/Mpc] on the theory's k grid (relative tolerance 1e-8), or a
    ValueError naming the likelihood and the k."""
    theory_k = np.asarray(theory_k)
    cols = []
    for kd in data_k:
        hit = np.flatnonzero(np.isclose(theory_k, kd, rtol=1e-8, atol=0.0))
        if hit.size == 0:
            raise ValueError(f"{who}: data k = {kd} h/Mpc is not on the theory's k grid (give the "
                             "theory no `k` option: it takes the requested k)")
        cols.append(int(hit[0]))
    return np.array(cols)


class MultipoleGaussian(Likelihood):
    """Gaussian likelihood of measured multipoles with diagonal errors: see the module docs."""

    data_file: str | None = None
    z: float | None = None
    ells: list | None = None
    data_ells: list = [0, 2, 4]
    k_min: float = 0.0
    k_max: float = np.inf

    def initialize(self):
        if self.data_file is None:
            raise ValueError("MultipoleGaussian: option `data_file` is required")
        if self.z is None:
            raise ValueError("MultipoleGaussian: option `z` (the redshift of the data) is required")
        self.z = float(self.z)
        k, values, sigma = read_multipoles(self.data_file, [int(ell) for ell in self.data_ells])
        ells = sorted(values) if self.ells is None else [int(ell) for ell in self.ells]
        absent = [ell for ell in ells if ell not in values]
        if absent:
            raise ValueError(f"MultipoleGaussian: `ells` {absent} are not in {self.data_file}")
        keep = (k >= float(self.k_min)) & (k <= float(self.k_max))
        if not keep.any():
            raise ValueError(f"MultipoleGaussian: no data k in [k_min, k_max] = "
                             f"[{self.k_min}, {self.k_max}] h/Mpc")
        self.ells = ells
        self.k_data = k[keep]
        self.data = np.array([values[ell][keep] for ell in ells])
        self.inv_sigma = 1.0 / np.array([sigma[ell][keep] for ell in ells])
        self._rows = self._cols = None
        self.log.info("%d multipoles x %d k in [%g, %g] h/Mpc at z = %g", len(ells),
                      self.k_data.size, self.k_data[0], self.k_data[-1], self.z)

    def get_requirements(self):
        return {"pt_pk_ell": {"z": [self.z], "k": self.k_data.tolist(), "ells": list(self.ells)},
                "pt_k": None, "pt_ells": None}

    def _select(self):
        self._cols = _columns_of(self.provider.get_pt_k(), self.k_data, "MultipoleGaussian")
        theory_ells = list(self.provider.get_pt_ells())
        self._rows = [theory_ells.index(ell) for ell in self.ells]

    def model(self):
        """The model multipoles at the data's (ℓ, k), shape [len(ells), len(k)], (Mpc/h)^3."""
        if self._rows is None:
            self._select()
        p = np.asarray(self.provider.get_pt_pk_ell(z=self.z))
        return p[self._rows][:, self._cols]

    def logp(self, **params_values):
        chi2 = float(np.sum(((self.model() - self.data) * self.inv_sigma) ** 2))
        return -0.5 * chi2


class SurveyMultipoles(Likelihood):
    """Gaussian likelihood of survey multipoles with a full covariance, window and bins.

    Options:

    - ``data_file``, ``data_ells`` as :class:`MultipoleGaussian` (k [h/Mpc]; with ``xi: true`` the
      first column is s [Mpc/h] and the values ξ_ℓ); ``z``; ``ells`` (the fitted multipoles, default
      all in the file).
    - ``covariance_file``: the full covariance of the data vector (text or ``.npy``), ℓ-major over
      ``data_ells`` and every k of the file (the P0, P2, P4 blocks); default: the files' σ², diagonal.
      ``n_mocks``: the number of mocks it was estimated from; C⁻¹ is scaled by (N − p − 2)/(N − 1), p
      the fitted points (Hartlap et al. 2007).
    - ``k_min``, ``k_max`` [h/Mpc] (s [Mpc/h] with ``xi``) and ``k_ranges`` ``{ℓ: [min, max]}``,
      narrowing the range of one multipole.
    - ``window``: a window file (Q_ℓ(s) multipoles ``s Q0 Q2 Q4 …`` or the BOSS format, or a window
      matrix, as ``pt-spectra rsd --window``), ``window_mixing`` ("wilson", default, or
      "classpt-boss"), ``window_format`` (the columns of a Q_ℓ(s) file without a names line:
      ``"s,Q0,Q2,Q4"`` or ``"boss"``, as ``--window-format``; default: the file's names line); ``k_edges`` [h/Mpc]: the data are k²-weighted bin means over these edges (then
      the data's k column only labels the rows); ``box`` [Mpc/h] with ``k_edges``: the mean over the
      modes of a periodic box. Wide-angle terms are neglected.
    - ``xi: true``: the data are correlation-function multipoles; ``s_edges`` [Mpc/h]: s-bin means.

    The theory (``pt_spectra.cobaya.PTMultipoles``, without its own ``k``) is asked for the model
    multipoles the window needs (ℓ ≤ 8) on the window's k grid. ``logp = −χ²/2`` with χ² = rᵀ C⁻¹ r.
    """

    data_file: str | None = None
    z: float | None = None
    ells: list | None = None
    data_ells: list = [0, 2, 4]
    k_min: float = 0.0
    k_max: float = np.inf
    k_ranges: dict | None = None
    covariance_file: str | None = None
    n_mocks: int | None = None
    window: str | None = None
    window_mixing: str = "wilson"
    window_format: str | None = None
    k_edges: list | None = None
    box: float | None = None
    xi: bool = False
    s_edges: list | None = None

    def initialize(self):
        if self.data_file is None or self.z is None:
            raise ValueError("SurveyMultipoles: options `data_file` and `z` are required")
        self.z = float(self.z)
        data_ells = [int(ell) for ell in self.data_ells]
        k, values, sigma = read_multipoles(self.data_file, data_ells)
        ells = sorted(values) if self.ells is None else [int(ell) for ell in self.ells]
        absent = [ell for ell in ells if ell not in values]
        if absent:
            raise ValueError(f"SurveyMultipoles: `ells` {absent} are not in {self.data_file}")
        if self.xi:
            if self.window is not None or self.k_edges is not None or self.box is not None:
                raise ValueError("SurveyMultipoles: xi takes s_edges, not window, k_edges or box")
            self.observation = pt.Observation.xi(ells, k, s_edges=self.s_edges)
        else:
            self.observation = pt.Observation(ells, k, window=self.window,
                                              window_mixing=self.window_mixing,
                                              k_edges=self.k_edges, box=self.box,
                                              window_format=self.window_format)
        k_out = np.asarray(self.observation.k_out)
        if k_out.size != k.size:
            raise ValueError(f"SurveyMultipoles: the window and bins give {k_out.size} k, the data "
                             f"file has {k.size} rows")
        # The fitted points: per ℓ, its range.
        ranges = {int(l): tuple(map(float, r)) for l, r in (self.k_ranges or {}).items()}
        for ell in ranges:
            if ell not in ells:
                raise ValueError(f"SurveyMultipoles: k_ranges names multipole {ell}, not fitted")
        mask = []
        for ell in ells:
            lo, hi = ranges.get(ell, (-np.inf, np.inf))
            mask.append((k >= max(float(self.k_min), lo)) & (k <= min(float(self.k_max), hi)))
        mask = np.array(mask)
        points = int(mask.sum())
        if points == 0:
            raise ValueError("SurveyMultipoles: no data point in the fitted ranges")
        n_k = k.size
        fitted = mask  # over every k of the file: selects the data and covariance
        if not self.xi and self.window is None and self.k_edges is None:
            # No window and no bins: the model is needed at the fitted k only (the theory's cost
            # grows with its k grid), so the observation is rebuilt on them.
            used = mask.any(axis=0)
            self.observation = pt.Observation(ells, k[used], box=self.box)
            mask = mask[:, used]
        index = np.concatenate([data_ells.index(ell) * n_k + np.flatnonzero(m)
                                for ell, m in zip(ells, fitted)])
        if self.covariance_file is not None:
            path = str(self.covariance_file)
            cov = np.load(path) if path.endswith(".npy") else np.loadtxt(path)
            n = len(data_ells) * n_k
            if cov.shape != (n, n):
                raise ValueError(f"SurveyMultipoles: covariance {path!r} is {cov.shape}, expected "
                                 f"({n}, {n}) (data_ells x every k of the data file)")
            # The library's checks (as `fit --covariance`): symmetric, positive definite, not nearly
            # singular, no variance absurdly small for its data; each refusal names the row.
            cov = _core.check_covariance(np.ascontiguousarray(cov, dtype=float),
                                         [values[ell] for ell in data_ells], path)
            cov = cov[np.ix_(index, index)]
        else:
            cov = np.diag(np.concatenate([sigma[ell][m]
                                          for ell, m in zip(ells, fitted)]) ** 2)
        if self.n_mocks is not None:
            n_mocks = int(self.n_mocks)
            if n_mocks < points + 3:
                raise ValueError(f"SurveyMultipoles: n_mocks = {n_mocks} needs to exceed the "
                                 f"{points} fitted points + 2 (Hartlap factor)")
            cov = cov * (n_mocks - 1) / (n_mocks - points - 2)
        try:
            chol = np.linalg.cholesky(cov)
        except np.linalg.LinAlgError as e:
            raise ValueError("SurveyMultipoles: the fitted covariance block is not positive "
                             "definite") from e
        self._whiten = np.linalg.inv(chol)
        self.ells, self._mask, self.points = ells, mask, points
        self.data = np.concatenate([values[ell][m] for ell, m in zip(ells, fitted)])
        self._cols = None
        self.log.info("%d points (multipoles %s) at z = %g; %s", points, ells, self.z,
                      "; ".join(self.observation.description) or "no window, no bins")

    def get_requirements(self):
        return {"pt_pk_ell": {"z": [self.z], "k": np.asarray(self.observation.k_model).tolist(),
                              "ells": list(self.observation.model_ells)},
                "pt_k": None, "pt_ells": None}

    def _select(self):
        theory_k = np.asarray(self.provider.get_pt_k())
        want = np.asarray(self.observation.k_model)
        cols = np.searchsorted(theory_k, want)
        cols = np.clip(cols, 0, theory_k.size - 1)
        bad = ~np.isclose(theory_k[cols], want, rtol=1e-8, atol=0.0)
        if bad.any():
            raise ValueError("SurveyMultipoles: the theory's k grid lacks the window's k (give the "
                             "theory no `k` option: it then takes the k the likelihoods ask for)")
        theory_ells = list(self.provider.get_pt_ells())
        self._rows = [theory_ells.index(ell) for ell in self.observation.model_ells]
        self._cols = cols

    def model(self):
        """The observed model at the fitted points (the data vector's order)."""
        if self._cols is None:
            self._select()
        p = np.asarray(self.provider.get_pt_pk_ell(z=self.z))[self._rows][:, self._cols]
        observed = np.asarray(self.observation.apply_values(np.ascontiguousarray(p)))
        return np.concatenate([observed[j][m] for j, m in enumerate(self._mask)])

    def logp(self, **params_values):
        r = self._whiten @ (self.data - self.model())
        return -0.5 * float(r @ r)


def read_columns(path, names, what):
    """The columns `names` of a whitespace text table (``#`` comments), as float arrays; every error
    names the file, the line and the value."""
    path = os.fspath(path)
    if not os.path.isfile(path):
        raise ValueError(f"{what}: no file {path!r}")
    rows = []
    with open(path, encoding="utf-8") as handle:
        for line_no, line in enumerate(handle, start=1):
            text = line.split("#", 1)[0].strip()
            if not text:
                continue
            fields = text.split()
            if len(fields) != len(names):
                raise ValueError(f"{what} {path!r} line {line_no}: {len(fields)} columns, expected "
                                 f"{len(names)} ({' '.join(names)})")
            try:
                values = [float(x) for x in fields]
            except ValueError as e:
                raise ValueError(f"{what} {path!r} line {line_no}: {e}") from e
            if not np.all(np.isfinite(values)):
                raise ValueError(f"{what} {path!r} line {line_no}: a value is not finite")
            rows.append(values)
    if not rows:
        raise ValueError(f"{what} {path!r}: no data rows")
    table = np.array(rows)
    return {name: table[:, j] for j, name in enumerate(names)}


class PowerBispectrum(Likelihood):
    """Joint Gaussian likelihood of window-free P_ℓ(k) and B_ℓ(k₁, k₂, k₃) with one covariance.

    Options:

    - ``p_file``: text columns ``k P_ℓ …`` for the multipoles ``p_data_ells`` (default [0, 2, 4]; the
      layout of the window-free estimators' files, e.g. the Nseries ``pk_*.txt``), k [h/Mpc], P
      [(Mpc/h)^3]; ``b_file``: columns ``k1 k2 k3 B_ℓ …`` for ``b_data_ells`` (default [0, 2, 4]), the
      bin centres [h/Mpc] and B [(Mpc/h)^6].
    - ``covariance_file`` (required; text or ``.npy``): the joint covariance in one declared layout:
      the P block ℓ-major over ``p_data_ells`` and every k of ``p_file``, then the B block ℓ-major over
      ``b_data_ells`` and every triangle of ``b_file`` (the layout of the Patchy P + B covariance).
      ``covariance_scale`` (1): the covariance is divided by it (e.g. the effective number of volumes
      of a mean of mocks); ``n_mocks``: C⁻¹ is scaled by the Hartlap factor (N − p − 2)/(N − 1), p the
      fitted points. It is whitened through its correlation matrix (the P and B blocks differ by ~1e5
      in scale).
    - ``z``; ``p_ells`` ([0, 2]) and ``k_min``, ``k_max`` [h/Mpc]: the fitted P points;
      ``b_ells`` ([0]) and ``b_k_min``, ``b_k_max`` [h/Mpc]: the fitted triangles, all of whose sides
      lie in [b_k_min, b_k_max].
    - ``bin_width`` [h/Mpc]: the shell width of the measured triangle bins, whose closed triangles the
      model averages (the Nseries and Patchy files: 0.01); ``null`` evaluates the model at the
      triangles themselves, which is logged (the bin average changes B by up to ~10% at low k).

    The theory (``pt_spectra.cobaya.PTMultipoles`` with ``rsd: ept`` and ``bispectrum: true``) is asked
    for P_ℓ at the fitted k and B_ℓ at the fitted triangles. ``logp = −χ²/2``, χ² = rᵀ C⁻¹ r over the
    fitted P then B points.
    """

    p_file: str | None = None
    b_file: str | None = None
    covariance_file: str | None = None
    covariance_scale: float = 1.0
    n_mocks: int | None = None
    z: float | None = None
    p_data_ells: list = [0, 2, 4]
    b_data_ells: list = [0, 2, 4]
    p_ells: list = [0, 2]
    b_ells: list = [0]
    k_min: float = 0.0
    k_max: float = np.inf
    b_k_min: float = 0.0
    b_k_max: float = np.inf
    bin_width: float | None = None

    def initialize(self):
        name = "PowerBispectrum"
        for option in ("p_file", "b_file", "covariance_file", "z"):
            if getattr(self, option) is None:
                raise ValueError(f"{name}: option `{option}` is required")
        self.z = float(self.z)
        p_data_ells = [int(ell) for ell in self.p_data_ells]
        b_data_ells = [int(ell) for ell in self.b_data_ells]
        p_ells = [int(ell) for ell in self.p_ells]
        b_ells = [int(ell) for ell in self.b_ells]
        for fitted, data, what in ((p_ells, p_data_ells, "p_ells"), (b_ells, b_data_ells, "b_ells")):
            absent = [ell for ell in fitted if ell not in data]
            if absent or not fitted:
                raise ValueError(f"{name}: `{what}` {fitted} must be a non-empty subset of the "
                                 f"file's multipoles {data}")
        p = read_columns(self.p_file, ["k"] + [f"P{ell}" for ell in p_data_ells], f"{name} p_file")
        b = read_columns(self.b_file, ["k1", "k2", "k3"] + [f"B{ell}" for ell in b_data_ells],
                         f"{name} b_file")
        k = p["k"]
        if np.any(k <= 0) or np.any(np.diff(k) <= 0):
            raise ValueError(f"{name} p_file {self.p_file!r}: k must be positive and increasing")
        triangles = np.column_stack([b["k1"], b["k2"], b["k3"]])
        if np.any(triangles <= 0):
            raise ValueError(f"{name} b_file {self.b_file!r}: every side must be > 0")
        p_keep = (k >= float(self.k_min)) & (k <= float(self.k_max))
        b_keep = ((triangles.min(axis=1) >= float(self.b_k_min))
                  & (triangles.max(axis=1) <= float(self.b_k_max)))
        if not p_keep.any():
            raise ValueError(f"{name}: no P point in [k_min, k_max] = [{self.k_min}, {self.k_max}]")
        if not b_keep.any():
            raise ValueError(f"{name}: no triangle with all sides in [b_k_min, b_k_max] = "
                             f"[{self.b_k_min}, {self.b_k_max}] h/Mpc")
        n_k, n_t = k.size, triangles.shape[0]
        index = np.concatenate(
            [p_data_ells.index(ell) * n_k + np.flatnonzero(p_keep) for ell in p_ells]
            + [len(p_data_ells) * n_k + b_data_ells.index(ell) * n_t + np.flatnonzero(b_keep)
               for ell in b_ells])
        path = str(self.covariance_file)
        if not os.path.isfile(path):
            raise ValueError(f"{name}: no covariance file {path!r}")
        cov = np.load(path) if path.endswith(".npy") else np.loadtxt(path)
        n = len(p_data_ells) * n_k + len(b_data_ells) * n_t
        if cov.shape != (n, n):
            raise ValueError(f"{name}: covariance {path!r} is {cov.shape}, expected ({n}, {n}): P "
                             f"{p_data_ells} x {n_k} k, then B {b_data_ells} x {n_t} triangles")
        if not (np.isfinite(self.covariance_scale) and self.covariance_scale > 0):
            raise ValueError(f"{name}: `covariance_scale` must be > 0, got {self.covariance_scale}")
        values = ([p[f"P{ell}"] for ell in p_data_ells] + [b[f"B{ell}"] for ell in b_data_ells])
        cov = _core.check_covariance(np.ascontiguousarray(cov, dtype=float), values, path)
        cov = np.asarray(cov)[np.ix_(index, index)] / float(self.covariance_scale)
        points = index.size
        if self.n_mocks is not None:
            n_mocks = int(self.n_mocks)
            if n_mocks < points + 3:
                raise ValueError(f"{name}: n_mocks = {n_mocks} needs to exceed the {points} fitted "
                                 "points + 2 (Hartlap factor)")
            cov = cov * (n_mocks - 1) / (n_mocks - points - 2)
        scale = np.sqrt(np.diag(cov))
        try:
            chol = np.linalg.cholesky(cov / np.outer(scale, scale))
        except np.linalg.LinAlgError as e:
            raise ValueError(f"{name}: the fitted covariance block is not positive definite") from e
        self._whiten = np.linalg.inv(chol) / scale
        self.p_ells, self.b_ells, self.points = p_ells, b_ells, points
        self.k_data = k[p_keep]
        self.triangles = triangles[b_keep]
        self.data = np.concatenate([p[f"P{ell}"][p_keep] for ell in p_ells]
                                   + [b[f"B{ell}"][b_keep] for ell in b_ells])
        self._cols = None
        if self.bin_width is None:
            self.log.warning("bin_width not given: B is evaluated at the triangles, not averaged over "
                             "the measurement's bins (up to ~10%% off at low k)")
        self.log.info("%d P points (multipoles %s, %g <= k <= %g h/Mpc) and %d B points "
                      "(multipoles %s, %d triangles) at z = %g", p_keep.sum() * len(p_ells), p_ells,
                      self.k_data[0], self.k_data[-1], b_keep.sum() * len(b_ells), b_ells,
                      self.triangles.shape[0], self.z)

    def get_requirements(self):
        return {"pt_pk_ell": {"z": [self.z], "k": self.k_data.tolist(), "ells": list(self.p_ells)},
                "pt_bk_ell": {"z": self.z, "triangles": self.triangles.tolist(),
                              "bin_width": self.bin_width, "ells": list(self.b_ells)},
                "pt_k": None, "pt_ells": None, "pt_bk_ells": None}

    def _select(self):
        cols = _columns_of(self.provider.get_pt_k(), self.k_data, "PowerBispectrum")
        theory_ells = list(self.provider.get_pt_ells())
        self._rows = [theory_ells.index(ell) for ell in self.p_ells]
        b_ells = list(self.provider.get_pt_bk_ells(self.z))
        self._b_rows = [b_ells.index(ell) for ell in self.b_ells]
        self._cols = cols

    def model(self):
        """The model at the fitted points: P_ℓ at the fitted k, then B_ℓ at the fitted triangles."""
        if self._cols is None:
            self._select()
        p = np.asarray(self.provider.get_pt_pk_ell(z=self.z))[self._rows][:, self._cols]
        b = np.asarray(self.provider.get_pt_bk_ell(z=self.z))[self._b_rows]
        return np.concatenate([p.ravel(), b.ravel()])

    def logp(self, **params_values):
        r = self._whiten @ (self.data - self.model())
        return -0.5 * float(r @ r)


def cobaya_name(name):
    """A likelihood parameter's name as cobaya takes it: ``b1[ngc]`` → ``b1_ngc``."""
    return name.replace("[", "_").replace("]", "")


class AnalysisFile(Likelihood):
    """The likelihood of a TOML analysis file (docs/analysis.md): the very function ``pt-spectra fit
    --analysis`` minimises (:class:`pt_spectra.AnalysisLikelihood`), with its template spectrum fixed
    (f, α∥, α⊥, the biases free; each set's linear parameters marginalised analytically with their
    ln det F, or profiled, as the file says), as a cobaya likelihood that needs no theory.

    Options: ``analysis`` (the file, required), ``linear``, ``z_input``, ``cosmology``, ``precision``,
    ``q_range`` as :func:`pt_spectra.fit_joint`. Its input parameters are the file's free ones with
    cobaya's names: ``f``, ``b1_ngc`` for ``b1[ngc]``, … (declare each in ``params`` with a flat prior
    inside the fit's bounds, :attr:`bounds`: the file's own priors are already in the likelihood).
    Derived: ``fsigma8_<label>`` = f σ8(z) of each data set whose f is free. A point outside the
    bounds has zero likelihood.
    """

    analysis: str | None = None
    linear = None
    z_input: float = 0.0
    cosmology = None
    precision: str = "default"
    q_range = None

    def initialize(self):
        if not self.analysis:
            raise ValueError("AnalysisFile: option `analysis` (a TOML analysis file) is required")
        self.lik = pt.AnalysisLikelihood(self.analysis, linear=self.linear, z_input=float(self.z_input),
                                         cosmology=self.cosmology, precision=self.precision,
                                         q_range=None if self.q_range is None else tuple(self.q_range))
        self.names = [cobaya_name(n) for n in self.lik.names]
        self.bounds = dict(zip(self.names, self.lik.bounds))
        self._fsigma8 = {}
        for label, s8 in self.lik.sigma8_z.items():
            for n in ("f", f"f[{label}]"):
                if n in self.lik.names:
                    self._fsigma8[f"fsigma8_{label}"] = (self.lik.names.index(n), s8)
        self.log.info("%s: %s; %d points", self.analysis, ", ".join(self.names), self.lik.points)

    def get_can_support_params(self):
        return self.names

    def get_can_provide_params(self):
        return list(self._fsigma8)

    def logp(self, **params_values):
        x = [params_values[n] for n in self.names]
        derived = params_values.get("_derived")
        if derived is not None:
            for name, (j, s8) in self._fsigma8.items():
                derived[name] = x[j] * s8
        try:
            return -0.5 * self.lik(x)
        except ValueError as e:
            self.log.debug("zero likelihood: %s", e)
            return -np.inf
