"""cobaya likelihoods for the multipoles of :mod:`pt_spectra.cobaya`.

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

try:
    from cobaya.likelihood import Likelihood
except ImportError as e:  # pragma: no cover - depends on the environment
    raise ImportError("pt_spectra.likelihoods needs cobaya: pip install cobaya camb") from e

__all__ = ["MultipoleGaussian", "read_multipoles"]


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
        table = np.atleast_2d(np.loadtxt(path))
        if table.shape[1] != 1 + 2 * len(data_ells):
            raise ValueError(f"data_file {path!r}: {table.shape[1]} columns, expected "
                             f"{1 + 2 * len(data_ells)} (k, then P_l, sigma_l for data_ells = "
                             f"{list(data_ells)})")
        k = table[:, 0]
        values = {int(ell): table[:, 1 + 2 * j] for j, ell in enumerate(data_ells)}
        sigma = {int(ell): table[:, 2 + 2 * j] for j, ell in enumerate(data_ells)}
    for ell in values:
        if values[ell].shape != k.shape or sigma[ell].shape != k.shape:
            raise ValueError(f"data_file {path!r}: P{ell} or s{ell} has not the length of k")
        if np.any(~(sigma[ell] > 0)):
            raise ValueError(f"data_file {path!r}: the errors s{ell} must be > 0")
    return k, values, sigma


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
        theory_k = np.asarray(self.provider.get_pt_k())
        theory_ells = list(self.provider.get_pt_ells())
        cols = []
        for kd in self.k_data:
            hit = np.flatnonzero(np.isclose(theory_k, kd, rtol=1e-8, atol=0.0))
            if hit.size == 0:
                raise ValueError(f"MultipoleGaussian: data k = {kd} h/Mpc is not on the "
                                 "theory's k grid")
            cols.append(int(hit[0]))
        self._rows = [theory_ells.index(ell) for ell in self.ells]
        self._cols = np.array(cols)

    def model(self):
        """The model multipoles at the data's (ℓ, k), shape [len(ells), len(k)], (Mpc/h)^3."""
        if self._rows is None:
            self._select()
        p = np.asarray(self.provider.get_pt_pk_ell(z=self.z))
        return p[self._rows][:, self._cols]

    def logp(self, **params_values):
        chi2 = float(np.sum(((self.model() - self.data) * self.inv_sigma) ** 2))
        return -0.5 * chi2
