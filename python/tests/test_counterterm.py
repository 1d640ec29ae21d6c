"""The EFT counterterm ``cs2`` of pt.real, pt.rsd, the plans and pt.fit: closed forms, c_s^2 = 0
unchanged, the command line's text, and a fit that recovers an injected c_s^2."""

import math

import numpy as np
import pytest

import pt_spectra as pt
from test_core import cli

K = np.geomspace(0.02, 0.25, 12)
FACTORS = {"dd": 2.0, "dt": 4.0, "tt": 6.0}


def test_cs2_in_real_adds_minus_2_4_6_cs2_k2_p_lin():
    base = pt.real(model="1l-spt", k=K, terms=True, precision="fast")
    with_ct = pt.real(model="1l-spt", k=K, terms=True, precision="fast", cs2=1.5)
    for pair, factor in FACTORS.items():
        want = -factor * 1.5 * K**2 * base["P_lin"]
        shift = with_ct[f"P_{pair}"] - base[f"P_{pair}"]
        atol = 1e-12 * np.abs(base["P_lin"]).max()
        np.testing.assert_allclose(shift, want, rtol=1e-12, atol=atol)
        np.testing.assert_allclose(with_ct[f"P_ct_{pair}"], want, rtol=1e-14)
        # Exact: the errors do not move.
        np.testing.assert_array_equal(with_ct[f"err_P_{pair}"], base[f"err_P_{pair}"])
    assert any("cs2 = 1.5 (Mpc/h)^2" in line for line in with_ct.header)
    assert not any("counterterm" in line for line in base.header)
    # c_s^2 = 0 is the run without it, to the byte; a plan call takes cs2 as pt.real does.
    zero = pt.real(model="1l-spt", k=K, terms=True, precision="fast", cs2=0.0)
    assert zero.to_text() == base.to_text()
    plan = pt.RealPlan(K, model="1l-spt", precision="fast")
    assert plan(terms=True, cs2=1.5).to_text() == with_ct.to_text()


def test_cs2_tables_equal_the_command_line_text():
    args = ["--nk", "8", "--k-min", "0.02", "--k-max", "0.25", "--precision", "fast", "--z", "1"]
    t = pt.real(model="1l-rpt-n1", terms=True, precision="fast", z=1.0, k_min=0.02, k_max=0.25,
                nk=8, cs2=-0.8)
    assert t.to_text() == cli("real", "--model", "1l-rpt-n1", "--terms", "--cs2", "-0.8", *args)
    m = pt.rsd(rsd="tns", real="1l-spt", fog="lorentzian", sigma0=3.0, precision="fast", z=1.0,
               k_min=0.02, k_max=0.25, nk=8, cs2=2.0)
    assert m.to_text() == cli("rsd", "--rsd", "tns", "--real", "1l-spt", "--fog", "lorentzian",
                              "--sigma0", "3", "--cs2", "2", *args)


def test_cs2_reaches_the_redshift_space_pairs():
    # Scoccimarro with linear spectra, no FoG: the closed form of the shifted pairs
    # P_dd = P(1 - 2x), P_dt = P(1 - 4x), P_tt = P(1 - 6x), x = cs2 k^2.
    b, f, c = 2.0, 0.7, 1.1
    p = pt.real(model="linear", k=K)["P_lin"]
    x = c * K**2
    dd, dt, tt = p * (1 - 2 * x), p * (1 - 4 * x), p * (1 - 6 * x)
    m = pt.rsd(rsd="scoccimarro", real="linear", k=K, f=f, bias=b, cs2=c)
    p0 = b * b * dd + 2 * b * f * dt / 3 + f * f * tt / 5
    np.testing.assert_allclose(m["P0"], p0, rtol=1e-13)
    np.testing.assert_allclose(m["P2"], 4 * b * f * dt / 3 + 4 * f * f * tt / 7, rtol=1e-13)
    np.testing.assert_allclose(m["P4"], 8 * f * f * tt / 35, rtol=1e-13)
    # The cheap path of a chain gives the full call's multipoles at any c_s^2.
    plan = pt.RsdPlan(K, real="1l-spt", rsd="tns", precision="fast")
    terms = plan.terms()
    for cs2 in (0.0, 0.9, -1.3):
        full = plan(fog="gaussian", sigma0=2.0, bias=1.4, cs2=cs2)
        fast = terms.multipoles(fog="gaussian", sigma0=2.0, bias=1.4, cs2=cs2)
        for name in full.columns:
            np.testing.assert_array_equal(full[name], fast[name])


def test_fit_frees_cs2_beside_f():
    # A Scoccimarro mock of linear spectra, c_s^2 = 1.7 (Mpc/h)^2, f = 0.55, no noise, 0.5% errors.
    mock = pt.rsd(rsd="scoccimarro", real="linear", k=K, f=0.55, bias=1.5, cs2=1.7,
                  ells=(0, 2, 4))
    data = {"k": K}
    for ell in (0, 2, 4):
        data[f"P{ell}"] = mock[f"P{ell}"]
        data[f"s{ell}"] = 0.005 * mock["P0"]
    r = pt.fit(data, k_max=0.25, free=("f", "cs2"), ells=(0, 2, 4), rsd="scoccimarro",
               real="linear", fog="none", bias=1.5, f=0.5)
    assert r.columns[:8] == ["k_max", "points", "f", "f_lo", "f_hi", "cs2", "cs2_lo", "cs2_hi"]
    assert r.units["cs2"] == "(Mpc/h)^2"
    np.testing.assert_allclose(r["f"], 0.55, rtol=1e-7)
    np.testing.assert_allclose(r["cs2"], 1.7, rtol=1e-6)
    assert r["cs2_lo"][0] < 1.7 < r["cs2_hi"][0]
    # Held at its value instead of free, c_s^2 still enters the model.
    held = pt.fit(data, k_max=0.25, free=("f",), ells=(0, 2, 4), rsd="scoccimarro", real="linear",
                  fog="none", bias=1.5, f=0.5, cs2=1.7)
    np.testing.assert_allclose(held["f"], 0.55, rtol=1e-7)


@pytest.mark.parametrize("bad", [math.nan, math.inf, -math.inf])
def test_non_finite_cs2_raises_value_error_naming_it(bad):
    with pytest.raises(ValueError, match="cs2.*must be finite"):
        pt.real(model="linear", k=K, cs2=bad)
    with pytest.raises(ValueError, match="cs2.*must be finite"):
        pt.rsd(real="linear", rsd="kaiser", k=K, cs2=bad)
    with pytest.raises(ValueError, match="cs2"):
        pt.fit({"k": K, "P0": K, "s0": K}, k_max=0.2, free=("f",), real="linear", rsd="kaiser",
               fog="none", cs2=bad)


def test_two_loop_eft_takes_its_counterterms_as_a_dict_and_prints_their_templates():
    k = [0.05, 0.1, 0.2]
    with pytest.warns(pt.PtSpectraWarning, match="every counterterm of 2l-eft is 0"):
        zero = pt.real(model="2l-eft", k=k, precision="fast", terms=True)
    ct = {"cs2": 1.2, "cs2_1loop": 0.4, "c4": -3.0}
    with_ct = pt.real(model="2l-eft", k=k, precision="fast", terms=True, ct=ct)
    for pair in ("dd", "dt", "tt"):
        want = sum(v * np.asarray(zero[f"T_{pair}_{c}"]) for c, v in ct.items())
        got = np.asarray(with_ct[f"P_{pair}"]) - np.asarray(zero[f"P_{pair}"])
        np.testing.assert_allclose(got, want, rtol=1e-9, atol=1e-9)
    # T_dd_cs2 = -2 k^2 P_lin; the plan call takes the same dict.
    np.testing.assert_allclose(zero["T_dd_cs2"], -2 * np.asarray(k) ** 2 * zero["P_lin"], rtol=1e-12)
    plan = pt.RealPlan(k, model="2l-eft", precision="fast")
    np.testing.assert_allclose(plan(ct=ct)["P_dd"], with_ct["P_dd"], rtol=1e-12)
    for bad, needle in (({"cs3": 1.0}, "cs2_1loop"), ({"c4": float("nan")}, "finite")):
        with pytest.raises(ValueError, match=needle):
            pt.real(model="2l-eft", k=k, precision="fast", ct=bad)
    with pytest.raises(ValueError, match="2l-eft and 2l-eft-ir"):
        pt.real(model="2l-spt", k=k, precision="fast", ct={"c4": 1.0})
    with pytest.raises(ValueError, match="given twice"):
        pt.real(model="2l-eft", k=k, precision="fast", ct={"cs2": 1.0}, cs2=2.0)
