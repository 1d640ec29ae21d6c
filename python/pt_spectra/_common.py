"""What the modules of the Python face share: the defaults spelled once in the library, the warning
class and how a table's warnings are raised, the model's parameter names."""

from __future__ import annotations

import warnings as _warnings

from . import _core
from ._core import Table, log_grid

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


EPT_PARAMETERS = ("b1", "b2", "bs", "b3", "alpha0", "alpha2", "alpha4", "alpha6", "sn", "sn2",
                  "sn4", "f")


def _ept_params(params):
    """The model parameters of ``params`` that are not None (velocileptors' names, or those of
    ``bias_convention``)."""
    return {name: v if name == "bias_convention" else float(v) for name, v in params.items()
            if v is not None}
