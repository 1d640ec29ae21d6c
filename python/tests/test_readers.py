"""Issue 45 from Python: a window's columns are declared (names line or ``window_format``), never guessed,
and a covariance given as an array or a file is checked as ``fit --covariance`` checks it (symmetric,
positive definite, condition number of its correlation matrix <= 1e6, no variance absurdly small)."""

import numpy as np
import pytest

import pt_spectra as pt
from pt_spectra import _core


def _window(path, header=True, duplicate=None):
    s = np.geomspace(0.01, 3000.0, 200)
    rows = np.column_stack([s, np.exp(-(s / 400.0) ** 2), 0 * s, 0 * s])
    if duplicate is not None:
        rows = np.insert(rows, duplicate, rows[duplicate], axis=0)
    np.savetxt(path, rows, header="s Q0 Q2 Q4" if header else "")
    return path


def test_a_window_without_names_needs_its_format(tmp_path):
    k = np.linspace(0.02, 0.2, 10)
    bare = _window(tmp_path / "bare.txt", header=False)
    with pytest.raises(ValueError, match="no names line"):
        pt.Observation([0, 2], k, window=bare)
    declared = pt.Observation([0, 2], k, window=bare, window_format="s,Q0,Q2,Q4")
    named = pt.Observation([0, 2], k, window=_window(tmp_path / "named.txt"))
    p = np.ones((len(named.model_ells), len(named.k_model))) * 1e4
    np.testing.assert_array_equal(declared.apply_values(p), named.apply_values(p))
    with pytest.raises(ValueError, match="boss"):
        pt.Observation([0, 2], k, window=bare, window_format="Q0,Q2,Q4")
    with pytest.raises(ValueError, match="window_format needs a window"):
        pt.Observation([0, 2], k, window_format="boss")


def test_a_duplicated_window_row_is_refused_naming_its_line(tmp_path):
    w = _window(tmp_path / "dup.txt", duplicate=50)
    # Line 1 is the names line, data row i on line i + 2: the repeat is row 51, line 53.
    with pytest.raises(ValueError, match=r"dup.txt:53: s \[Mpc/h\] = .*strictly increasing"):
        pt.Observation([0, 2], np.linspace(0.02, 0.2, 10), window=w)


def _ar1(n, rho=0.5):
    s = np.linspace(100.0, 10.0, n)
    i = np.arange(n)
    return np.outer(s, s) * rho ** np.abs(i[:, None] - i[None, :])


def test_covariance_arrays_are_checked():
    values = [np.full(5, 1e4), np.full(5, 3e3)]
    good = _ar1(10)
    np.testing.assert_array_equal(_core.check_covariance(good, values), good)
    equal = good.copy()
    equal[6], equal[:, 6] = equal[5], equal[:, 5]
    with pytest.raises(ValueError, match="positive definite|condition number"):
        _core.check_covariance(np.array([[float(f"{x:.5e}") for x in r] for r in equal]), values)
    tiny = good.copy()
    tiny[3], tiny[:, 3] = 0.0, 0.0
    tiny[3, 3] = 1e-10
    with pytest.raises(ValueError, match="covariance row 4: the variance 1e-10"):
        _core.check_covariance(tiny, values, "c.txt")
    asym = good.copy()
    asym[2, 1] *= 1.01
    with pytest.raises(ValueError, match="symmetric"):
        _core.check_covariance(asym, values)
