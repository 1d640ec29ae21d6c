"""The 2-loop matter multipoles in redshift space from Python (spt2, eft2): the plan agrees with the
command line's library path, counterterms enter linearly through their templates, bad input raises."""

import numpy as np
import pytest

import pt_spectra as pt

K = np.array([0.05, 0.12, 0.2])


def test_eft2_is_linear_in_its_counterterms_and_spt2_parts_add_up():
    plan = pt.TwoLoopRsdPlan(K, "eft2", precision="fast", two_loop="direct")
    with pytest.warns(pt.PtSpectraWarning, match="every counterterm of eft2 is 0"):
        zero = plan(f=0.7, terms=True)
    with_ct = plan(f=0.7, c0=2.0, c2_1loop=-1.5)
    for ell in (0, 2, 4):
        want = zero[f"P{ell}"] + 2.0 * zero[f"T{ell}_c0"] - 1.5 * zero[f"T{ell}_c2_1loop"]
        np.testing.assert_allclose(with_ct[f"P{ell}"], want, rtol=1e-9)
        assert np.all(with_ct[f"err_P{ell}"] > 0)
    spt2 = pt.rsd(rsd="spt2", k=K, f=0.7, precision="fast", terms=True)
    for ell in (0, 2):
        parts = spt2[f"P{ell}_lin"] + spt2[f"P{ell}_1loop"] + spt2[f"P{ell}_2loop"]
        np.testing.assert_allclose(spt2[f"P{ell}"], parts, rtol=1e-9)
    assert spt2.meta["model"] == "spt2"


def test_bad_input_raises():
    with pytest.raises(ValueError, match="expected spt2 or eft2"):
        pt.TwoLoopRsdPlan(K, "tns")
    plan = pt.TwoLoopRsdPlan(K, "eft2", precision="fast", two_loop="direct")
    with pytest.raises(ValueError, match="unknown eft2 counterterm"):
        plan(c6=1.0)
    with pytest.raises(ValueError, match="multipole ell"):
        plan(ells=(0, 10), c0=1.0)
    with pytest.raises(ValueError, match="bias"):
        pt.rsd(rsd="eft2", k=K, bias=2.0)
    with pytest.raises(ValueError, match="counterterms are options of eft2"):
        pt.TwoLoopRsdPlan(K, "spt2", precision="fast", two_loop="direct")(c0=1.0)


def test_eft2_counterterm_fit_recovers_injected_values():
    plan = pt.TwoLoopRsdPlan(np.array([0.03, 0.06, 0.09, 0.12, 0.15]), "eft2", precision="fast",
                             two_loop="direct")
    truth = {"c0": -1.5, "c2": 4.0, "c0_1loop": 2.0}
    t = plan(f=0.7, **truth)
    data = {ell: (t[f"P{ell}"], 0.01 * np.abs(t[f"P{ell}"])) for ell in (0, 2, 4)}
    fit = plan.fit_counterterms(data, ["c0", "c2", "c0_1loop"], 0.2, f=0.7)
    for name, value in truth.items():
        assert abs(fit[name][0] - value) < 1e-5 * (1 + abs(value)), (name, fit[name])
        assert fit[name][1] > 0
    assert fit["ctilde"] == (0.0, 0.0)
    with pytest.raises(ValueError, match="unknown eft2 counterterm"):
        plan.fit_counterterms(data, ["c6"], 0.2, f=0.7)
