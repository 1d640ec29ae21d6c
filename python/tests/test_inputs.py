"""Property-based tests of the Python array entry points (issue 45): random valid arrays work; a k
array that is not a grid (decreasing, repeated, NaN, infinite, zero or negative, empty, 2-D) and bad
linear, measured, data and covariance arrays raise ``ValueError`` naming the argument, never a
result. Plus the fault of an ``EptPlan`` whose k has its internal AP grid's length.

The examples are bounded (``max_examples``) and no example database is written, so the file runs in
seconds."""

import re
import warnings

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import pt_spectra as pt

FEW = settings(max_examples=12, deadline=None, database=None,
               suppress_health_check=[HealthCheck.too_slow])

# Valid k [h/Mpc]: inside every plan's integration range, strictly increasing.
valid_k = st.lists(st.floats(1e-3, 1.0), min_size=1, max_size=6, unique=True).map(sorted)
valid_k2 = st.lists(st.floats(1e-3, 1.0), min_size=2, max_size=6, unique=True).map(sorted)

CORRUPTIONS = ("reversed", "repeated", "nan", "inf", "zero", "negative", "empty", "2-D column",
               "2-D rows")


def corrupt(k, how, i):
    """`k` (sorted, >= 2 values) made invalid by `how` at index `i`."""
    k = np.array(k, dtype=float)
    i %= len(k)
    if how == "reversed":
        return k[::-1].copy()
    if how == "repeated":
        j = max(i, 1)
        k[j] = k[j - 1]
        return k
    if how in ("nan", "inf", "zero", "negative"):
        k[i] = {"nan": np.nan, "inf": np.inf, "zero": 0.0, "negative": -k[i]}[how]
        return k
    if how == "empty":
        return np.array([], dtype=float)
    if how == "2-D column":
        return k[:, None]
    return np.vstack([k, k])


bad_k = st.builds(corrupt, valid_k2, st.sampled_from(CORRUPTIONS), st.integers(0, 5))


def refused(call, argument):
    """`call()` raises ValueError whose message names `argument` (as `argument[` or `argument:`)."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        with pytest.raises(ValueError) as e:
            call()
    message = str(e.value)
    assert re.match(re.escape(argument) + r"(\[\d+\]|:)", message), message
    return message


# The entry points that take an output k grid, each built cheaply (precision fast, linear models).
K_ENTRY_POINTS = {
    "RealPlan": lambda k: pt.RealPlan(k, model="linear", precision="fast"),
    "EptPlan": lambda k: pt.EptPlan(k, ir=False, precision="fast"),
    "EptPlan(free_ap)": lambda k: pt.EptPlan(k, free_ap=True, precision="fast"),
    "RsdPlan": lambda k: pt.RsdPlan(k, real="linear", rsd="kaiser", precision="fast"),
    "TwoLoopRsdPlan": lambda k: pt.TwoLoopRsdPlan(k, precision="fast", two_loop="direct"),
    "real": lambda k: pt.real(model="linear", k=k),
    "rsd": lambda k: pt.rsd(rsd="kaiser", real="linear", k=k),
    "ept": lambda k: pt.ept(k=k, ir=False, precision="fast"),
    "eisenstein_hu": lambda k: pt.eisenstein_hu(k),
    "Observation": lambda k: pt.Observation([0], k=k),
}


@pytest.mark.parametrize("entry", sorted(K_ENTRY_POINTS))
@FEW
@given(k=bad_k)
def test_a_k_that_is_not_a_grid_is_refused_naming_k(entry, k):
    refused(lambda: K_ENTRY_POINTS[entry](k), "k")


@pytest.mark.parametrize("k, rule", [
    ([0.2, 0.1, 0.05], r"^k\[1\] = 0\.1 h/Mpc: does not exceed k\[0\] = 0\.2 h/Mpc \(k must be strictly"),
    ([0.1, 0.1, 0.1], r"^k\[1\] = 0\.1 h/Mpc: does not exceed k\[0\]"),
    ([0.1, np.nan], r"^k\[1\] = NaN h/Mpc: every k must be finite and positive"),
    ([], r"^k: the k grid is empty"),
    (np.ones((2, 2)), r"^k: expected a 1-D array, got a 2-D one"),
])
def test_the_issues_k_arrays_get_the_rule(k, rule):
    for entry in ("RealPlan", "EptPlan", "eisenstein_hu"):
        message = refused(lambda: K_ENTRY_POINTS[entry](k), "k")
        assert re.match(rule, message), message


@FEW
@given(k=valid_k)
def test_valid_k_arrays_give_results_on_them(k):
    table = pt.real(model="linear", k=np.array(k))
    assert np.array_equal(table["k"], k)
    assert np.all(np.isfinite(table["P_dd"])) and np.all(table["P_dd"] > 0)
    p = pt.eisenstein_hu(k)
    assert p.shape == (len(k),) and np.all(np.isfinite(p)) and np.all(p > 0)
    assert np.array_equal(pt.RealPlan(list(k), model="linear", precision="fast").k, k)


def power_law(n, slope):
    k = np.geomspace(1e-3, 1.0, n)
    return k, 1e4 * (k / 0.1) ** slope


@FEW
@given(n=st.integers(20, 60), slope=st.floats(-2.5, 1.0))
def test_valid_linear_arrays_are_used(n, slope):
    k, p = power_law(n, slope)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", pt.PtSpectraWarning)
        table = pt.real(model="linear", k=k[5:8], linear=(k, p))
    assert np.allclose(table["P_lin"], p[5:8], rtol=1e-9)


@FEW
@given(how=st.sampled_from(CORRUPTIONS), i=st.integers(0, 40))
def test_a_linear_k_that_is_not_a_grid_is_refused(how, i):
    k, p = power_law(30, -1.5)
    refused(lambda: pt.real(model="linear", k=[0.1], linear=(corrupt(k, how, i), p)), "linear k")


@FEW
@given(how=st.sampled_from(("nan", "inf", "zero", "negative", "2-D column")), i=st.integers(0, 40))
def test_a_linear_p_that_is_not_positive_is_refused(how, i):
    k, p = power_law(30, -1.5)
    refused(lambda: pt.real(model="linear", k=[0.1], linear=(k, corrupt(p, how, i))), "linear P")


@FEW
@given(k=bad_k)
def test_batches_bias_tables_measured_spectra_and_data_check_their_k(k):
    plan = pt.RealPlan([0.1], model="linear", precision="fast")
    p = np.ones((1, max(np.size(k), 1)))
    refused(lambda: plan.batch(k, p), "k_lin")
    measured = (k, np.ones(np.shape(k)))
    refused(lambda: pt.halo(measured, measured, measured), "P_mm k")
    refused(lambda: pt.rsd(rsd="kaiser", real="linear", k=[0.1], bias=measured), "b(k) k")
    ones = np.ones(np.shape(k))
    data = {"k": k, "P0": ones, "s0": ones, "P2": ones, "s2": ones}
    refused(lambda: pt.fit_ept(data, [0.2], precision="fast"), "data['k']")


def good_data(n=6):
    k = np.geomspace(0.02, 0.2, n)
    p0 = 2e4 * (k / 0.1) ** -1.0
    return {"k": k, "P0": p0, "s0": 0.05 * p0, "P2": 0.5 * p0, "s2": 0.05 * p0}


@FEW
@given(how=st.sampled_from(("nan", "negative diagonal", "asymmetric", "1-D", "wrong size",
                            "not square")),
       i=st.integers(0, 11))
def test_a_bad_covariance_is_refused_naming_it(how, i):
    data = good_data()
    n = 2 * len(data["k"])
    c = np.diag(np.concatenate([data["s0"], data["s2"]]) ** 2)
    i %= n
    j = (i + 1) % n
    if how == "nan":
        c[i, j] = np.nan
    elif how == "negative diagonal":
        c[i, i] = -c[i, i]
    elif how == "asymmetric":
        c[i, j] = 0.5 * np.sqrt(c[i, i] * c[j, j])
    elif how == "1-D":
        c = np.diag(c)
    elif how == "wrong size":
        c = c[:-1, :-1]
    else:
        c = c[:-1, :]
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        with pytest.raises(ValueError, match="covariance"):
            pt.fit_ept(data, [0.2], data_ells=(0, 2), covariance=c, precision="fast")


def test_a_free_ap_plan_on_a_grid_of_its_internal_length_evaluates_at_its_k():
    """155 k in [0.01, 0.2] is the length of the free-AP internal grid: the plan once read its
    terms at the internal grid's k (P0 22.6% off at k = 0.133, with errors of 3e-4)."""
    k = np.geomspace(0.01, 0.2, 155)
    params = dict(b1=2.0, f=0.7)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", pt.PtSpectraWarning)
        free_ap = pt.EptPlan(k, free_ap=True, precision="fast")(**params)
        plain = pt.EptPlan(k, precision="fast")(**params)
    assert np.max(np.abs(free_ap["P0"] / plain["P0"] - 1)) < 1e-3


def test_a_prior_on_a_fixed_parameter_is_refused():
    with pytest.raises(ValueError, match=r"the prior on b2: b2 is fixed.*\(free: f, b1; marginalised: none\)"):
        pt.fit_ept(good_data(), [0.2], data_ells=(0, 2), priors={"b2": (0.0, 1.0)},
                   precision="fast")


# Issue 45, fault sweep 2 -------------------------------------------------------------------------

_C45 = {"h": 0.67, "omega_b": 0.022, "omega_cdm": 0.12, "n_s": 0.965, "A_s": 2.1e-9}


def test_every_face_refuses_a_cosmology_dict_with_an_unknown_key():
    # pt.real/rsd/ept warned, the Pipeline (call, batch, cosmology_jacobian) ignored the key silently
    # and returned the massless spectrum; every dict reader now raises naming the key
    import numpy as np
    k = np.geomspace(0.02, 0.2, 6)
    bad = dict(_C45, m_ncmd=0.06)
    for call in (lambda: pt.real("linear", k=k, cosmology=bad),
                 lambda: pt.rsd(k=k, cosmology=bad, precision="fast"),
                 lambda: pt.LinearEmulator().spectra(bad, 0.5)):
        with pytest.raises(ValueError, match="m_ncmd"):
            call()
    p = pt.Pipeline(pt.Observation([0, 2], k), 0.5, precision="fast")
    with pytest.raises(ValueError, match="m_ncmd"):
        p(cosmology=bad, b1=2.0)
    with pytest.raises(ValueError, match="m_ncmd"):
        p.batch([bad], [dict(b1=2.0)])
    with pytest.raises(ValueError, match="m_ncmd"):
        p.cosmology_jacobian(bad, b1=2.0)
    # a key CLASS reads another way is refused naming it, not dropped
    with pytest.raises(ValueError, match="T_ncdm"):
        p(cosmology=dict(_C45, N_ncdm=1, m_ncdm=0.02, deg_ncdm=3, N_ur=0.00641, T_ncdm=0.8), b1=2.0)
    with pytest.raises(ValueError, match="N_ncdm is not given"):
        pt.LinearEmulator().spectra(dict(_C45, m_ncdm=0.02, deg_ncdm=3, N_ur=0.00641), 0.5)


def test_m_ncdm_as_a_python_list_is_read_as_class_writes_it():
    import numpy as np
    three = dict(_C45, N_ncdm=3, N_ur=0.00641)
    ref = pt.LinearEmulator().spectra(dict(three, m_ncdm="0.02, 0.02, 0.02"), 0.5)
    for masses in ([0.02, 0.02, 0.02], (0.02, 0.02, 0.02), np.array([0.02, 0.02, 0.02])):
        s = pt.LinearEmulator().spectra(dict(three, m_ncdm=masses), 0.5)
        assert s["neutrinos"] == "three degenerate"
        assert np.array_equal(s["P_m"], ref["P_m"])


def test_an_observation_refuses_odd_or_repeated_multipoles_without_a_window():
    import numpy as np
    k = np.geomspace(0.02, 0.2, 6)
    for ells, rule in (([0, 3], "3"), ([0, 0], "twice")):
        with pytest.raises(ValueError, match=rule):
            pt.Observation(ells, k)


def test_the_growth_far_in_z_is_refused_and_warned_about_in_between():
    with pytest.raises(ValueError, match="radiation"):
        pt.growth(1e6)
    with pytest.warns(UserWarning, match="radiation"):
        pt.growth(5.0)
