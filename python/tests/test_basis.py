"""RealPlan.batch and the 1-loop basis tensors: many spectra at once, each equal to its own call,
and within 1e-4 of the direct integrals for a CAMB spectrum the basis was not trained on."""

from pathlib import Path

import warnings
import numpy as np
import pytest

import pt_spectra as pt

DATA = Path(__file__).resolve().parents[2] / "pt-spectra" / "tests" / "data"


@pytest.fixture(scope="module")
def camb():
    d = np.loadtxt(DATA / "linear_pk_camb_heldout_0.dat")
    return d[:, 0], d[:, 1]


def test_batch_rows_equal_single_calls_and_basis_is_close_to_direct(camb, tmp_path):
    k_lin, p = camb
    k = np.geomspace(0.01, 0.3, 12)
    plan = pt.RealPlan(k, model="1l-spt", precision="fast", two_loop="basis", cache_dir=tmp_path)
    direct = pt.RealPlan(k, model="1l-spt", precision="fast", two_loop="direct")
    P = np.stack([p * a for a in (0.8, 1.0, 1.3)])
    out = plan.batch(k_lin, P, terms=True)
    assert out["P_dd"].shape == (3, 12) and np.array_equal(out["k"], k)
    for i, row in enumerate(P):
        one = plan(linear=(k_lin, row), cosmology="planck2018", terms=True)
        assert any("basis tensors" in line for line in one.header)
        assert one.meta["methods"] == {"1-loop terms": "basis"}
        for name in ("P_dd", "P_dt", "P_tt", "err_P_dd", "P22_dd", "P13_tt"):
            assert np.array_equal(out[name][i], one[name]), name
        ref = direct(linear=(k_lin, row), cosmology="planck2018", terms=True)
        assert ref.meta["methods"] == {"1-loop terms": "direct"}
        for name in ("P_dd", "P_dt", "P_tt", "P22_dd", "P13_dd"):
            assert np.abs(out[name][i] / ref[name] - 1).max() < 1e-4, name
    # A 1-D P is one spectrum.
    assert plan.batch(k_lin, p)["P_dd"].shape == (1, 12)


def test_batch_names_a_bad_row(camb):
    k_lin, p = camb
    plan = pt.RealPlan(np.geomspace(0.01, 0.3, 4), model="1l-spt", precision="fast")
    bad = np.stack([p, p])
    bad[1, 5] = -1.0
    with pytest.raises(ValueError, match="row 1 of P"):
        plan.batch(k_lin, bad)
    with pytest.raises(ValueError, match="columns"):
        plan.batch(k_lin[:-1], bad)


def test_tns_multipoles_through_the_basis_match_direct(camb, tmp_path):
    k_lin, p = camb
    k = np.geomspace(0.01, 0.3, 10)
    args = dict(real="1l-spt", rsd="tns", precision="fast")
    on_basis = pt.RsdPlan(k, two_loop="basis", cache_dir=tmp_path, **args)
    direct = pt.RsdPlan(k, two_loop="direct", **args)
    call = dict(linear=(k_lin, p), cosmology="planck2018", f=0.6, bias=1.8, fog="lorentzian",
                sigma0=3.0)
    a, d = on_basis(**call), direct(**call)
    assert any("TNS A and B: basis tensors" in line for line in a.header)
    assert any("1-loop terms (P22" in line for line in a.header)
    assert a.meta["methods"] == {"1-loop terms": "basis", "TNS A and B": "basis"}
    assert d.meta["methods"] == {"1-loop terms": "direct", "TNS A and B": "direct"}
    for ell in ("P0", "P2"):
        assert np.abs(a[ell] - d[ell]).max() < 1e-4 * np.abs(d["P0"]).max(), ell
        assert (np.abs(a[ell] - d[ell]) <= a["err_" + ell] + d["err_" + ell]).all(), ell


def test_ept_through_the_basis_matches_direct(camb, tmp_path):
    k_lin, p = camb
    k = np.geomspace(0.01, 0.3, 10)
    on_basis = pt.EptPlan(k, precision="fast", two_loop="basis", cache_dir=tmp_path)
    direct = pt.EptPlan(k, precision="fast", two_loop="direct")
    call = dict(linear=(k_lin, p), cosmology="planck2018", b1=1.9, b2=0.4, bs=-0.3, sn=500.0)
    a, d = on_basis(**call), direct(**call)
    assert any("loop terms: basis tensors" in line for line in a.header)
    assert not any("basis tensors" in line for line in d.header)
    assert a.meta["methods"] == {"loop terms": "basis"} and d.meta["methods"] == {"loop terms": "direct"}
    # the plans say so themselves, from the library's one Plan seam
    assert on_basis.plan_info["method"] == "basis" and direct.plan_info["method"] == "direct"
    assert on_basis.plan_info["memory_bytes"] > direct.plan_info["memory_bytes"] > 20e6
    for ell in ("P0", "P2", "P4"):
        assert np.abs(a[ell] - d[ell]).max() < 1e-4 * np.abs(d["P0"]).max(), ell
        assert (np.abs(a[ell] - d[ell]) <= a["err_" + ell] + d["err_" + ell]).all(), ell


def test_emulated_cosmologies_use_the_basis_and_match_direct(tmp_path):
    # a cosmology dict or preset is emulated (its table ends at ~9 h/Mpc, projection residual 4-8e-4):
    # within the one limit of every plan (2e-3), so the tensors are used, not the direct integrals
    k = np.geomspace(0.01, 0.3, 10)
    on_basis = pt.EptPlan(k, precision="fast", two_loop="basis", cache_dir=tmp_path)
    direct = pt.EptPlan(k, precision="fast", two_loop="direct")
    cosmo = dict(omega_cdm=0.118, h=0.68, omega_b=0.0223, n_s=0.965, sigma8=0.79)
    for c in (cosmo, "planck2018"):
        call = dict(cosmology=c, z=0.6, b1=2.0, b2=-0.3, bs=0.2)
        with warnings.catch_warnings():
            warnings.simplefilter("error", pt.PtSpectraWarning)
            a = on_basis(**call)
        d = direct(**call)
        assert a.meta["methods"] == {"loop terms": "basis"}, c
        for ell in ("P0", "P2", "P4"):
            assert np.abs(a[ell] - d[ell]).max() < 2e-4 * np.abs(d["P0"]).max(), (c, ell)


def test_a_spectrum_outside_the_basis_falls_back_to_direct_and_says_so(camb, tmp_path):
    # wiggles of 30% in ln k are far outside the span of the CAMB basis: the plan integrates directly,
    # and the table states it in its header, in meta["methods"] and as a warning
    k_lin, p = camb
    odd = p * (1 + 0.3 * np.sin(12 * np.log(k_lin)))
    plan = pt.EptPlan(np.geomspace(0.01, 0.3, 6), precision="fast", two_loop="basis", cache_dir=tmp_path)
    with pytest.warns(pt.PtSpectraWarning, match="loop terms: direct \\(fallback"):
        t = plan(linear=(k_lin, odd), cosmology="planck2018", b1=1.9)
    assert t.meta["methods"]["loop terms"].startswith("direct (fallback")
    assert not any("loop terms: basis tensors" in line for line in t.header)
