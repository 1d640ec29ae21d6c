"""The galaxy model ``ept`` from Python: velocileptors' REPT table (set A, z = 1, no IR) through
``pt.ept`` and the cheap-step ``EptTerms``, and the errors of unknown names and bad values."""

import pathlib
import warnings

import numpy as np
import pytest

import pt_spectra as pt

DATA = pathlib.Path(__file__).resolve().parents[2] / "pt-spectra" / "tests" / "data"
SET_A = dict(b1=1.8, b2=0.5, bs=-0.3, b3=0.1, alpha0=10, alpha2=-5, alpha4=3, alpha6=1, sn=1000,
             sn2=500, sn4=100)


@pytest.fixture(scope="module")
def reference():
    ref = np.loadtxt(DATA / "velocileptors_rept_planck2018_z1.0.dat")
    lin = np.loadtxt(DATA / "linear_pk_planck2018_z1.0.dat")
    return ref, (lin[:, 0], lin[:, 1])


def test_ept_matches_rept_and_terms_give_the_same(reference):
    ref, linear = reference
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", pt.PtSpectraWarning)
        t = pt.ept(k=ref[:, 0], linear=linear, ir=False, f=0.873875, **SET_A)
        for col, ell in ((1, "P0"), (2, "P2"), (3, "P4")):
            assert np.max(np.abs(t[ell] - ref[:, col]) / ref[:, 1]) < 2e-4
        plan = pt.EptPlan(ref[:, 0], ir=False)
        terms = plan.terms(linear=linear)
        again = terms.multipoles(f=0.873875, **SET_A)
    assert np.array_equal(again["P0"], t["P0"])


def test_ept_names_bad_input(reference):
    ref, linear = reference
    plan = pt.EptPlan(ref[:5, 0], ir=False)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", pt.PtSpectraWarning)
        terms = plan.terms(linear=linear)
        with pytest.raises(ValueError, match="alpha9"):
            terms.multipoles(alpha9=1.0)
        with pytest.raises(ValueError, match="f"):
            terms.multipoles(f=-1.0)
    with pytest.raises(ValueError, match="apar"):
        pt.EptPlan(ref[:5, 0], apar=1.02)


def test_fit_ept_recovers_its_own_multipoles():
    k = np.geomspace(0.02, 0.2, 25)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", pt.PtSpectraWarning)
        truth = dict(b1=2.0, b2=-0.4, alpha0=8.0, sn=900.0, f=0.7)
        m = pt.ept(k=k, precision="fast", **truth)
        s = 0.01 * m["P0"]
        data = {"k": k, "P0": m["P0"], "s0": s, "P2": m["P2"], "s2": s}
        t = pt.fit_ept(data, [0.2], free=("f", "b1", "b2"), marginalise=("alpha0", "sn"),
                       priors={"b2": (0.0, 2.0)}, precision="fast", b1=1.8, f=0.6)
    for name, value in truth.items():
        assert abs(t[name][0] - value) < 0.1 * t[f"err_{name}"][0], name
    with pytest.raises(ValueError, match="linearly"):
        pt.fit_ept(data, [0.2], marginalise=("b2",), precision="fast")
    with pytest.raises(ValueError, match="sigma"):
        pt.fit_ept(data, [0.2], priors={"b2": (0.0, -1.0)}, precision="fast")


def test_fit_ept_in_the_desi_physical_basis():
    # A change of variables of b1, b2, sn (the rest fixed): the same f and error as velocileptors'.
    k = np.geomspace(0.02, 0.2, 25)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", pt.PtSpectraWarning)
        m = pt.ept(k=k, precision="fast", b1=2.0, b2=-0.4, sn=900.0, f=0.7)
        s = 0.01 * m["P0"]
        data = {"k": k, "P0": m["P0"], "s0": s, "P2": m["P2"], "s2": s}
        kw = dict(precision="fast", b1=1.8, f=0.6, starts=2)
        vel = pt.fit_ept(data, [0.2], free=("f", "b1", "b2"), marginalise=("sn",), **kw)
        phys = pt.fit_ept(data, [0.2], free=("f", "b1p", "b2p"), marginalise=("sn0p",), basis="desi",
                          n_bar=3e-4, **kw)
    assert abs(vel["f"][0] - phys["f"][0]) < 0.01 * vel["err_f"][0]
    assert phys["b1p"][0] == pytest.approx(phys["b1"][0] * phys["sigma8_z"][0], rel=1e-9)
    assert phys["sn0p"][0] == pytest.approx(phys["sn"][0] * 3e-4, rel=1e-9)
    assert any("DESI DR1 physical" in line for line in phys.header)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", pt.PtSpectraWarning)
        t = pt.fit_ept(data, [0.2], free=("f", "b1p"), marginalise=("sn0p",), basis="desi",
                       n_bar=3e-4, desi_priors=True, **kw)
    assert any("b1p: U[0, 3]" in line and "sn0p: N(0, 2^2)" in line for line in t.header)
    with pytest.raises(ValueError, match="n_bar"):
        pt.fit_ept(data, [0.2], free=("f", "b1p"), basis="desi", precision="fast")
    with pytest.raises(ValueError, match="velocileptors name"):
        pt.fit_ept(data, [0.2], free=("f", "b1"), basis="desi", n_bar=3e-4, precision="fast")


def test_from_desi_physical_is_the_documented_map():
    p = pt.from_desi_physical(dict(b1p=1.2, b2p=0.3, bsp=-0.4, alpha0p=5.0, alpha2p=-3.0, alpha4p=2.0,
                                   sn0p=0.7, sn2p=-1.5, f=0.75), sigma8=0.6, n_bar=3e-4)
    b, f = 2.0, 0.75
    assert p["b1"] == pytest.approx(b)
    assert p["b2"] == pytest.approx(0.3 / 0.36 + 8 / 21 * (b - 1))
    assert p["bs"] == pytest.approx(-0.4 / 0.36)
    assert p["alpha0"] == pytest.approx(b * b * 5.0)
    assert p["alpha2"] == pytest.approx(f * b * (5.0 - 3.0))
    assert p["alpha4"] == pytest.approx(f * (f * -3.0 + b * 2.0))
    assert p["alpha6"] == pytest.approx(f * f * 2.0)
    assert p["sn"] == pytest.approx(0.7 / 3e-4)
    assert p["sn2"] == pytest.approx(-1.5 * 0.1 * 25 / 3e-4)
    with pytest.raises(ValueError, match="alpha4p"):
        pt.from_desi_physical(dict(alpha6p=1.0, f=0.7), 0.6, 3e-4)
    with pytest.raises(ValueError, match="need f"):
        pt.from_desi_physical(dict(b1p=1.2), 0.6, 3e-4)
    with pytest.raises(ValueError, match="physical basis"):
        pt.from_desi_physical(dict(b1=1.2, f=0.7), 0.6, 3e-4)


def test_rsd_and_fit_route_ept(reference):
    ref, linear = reference
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", pt.PtSpectraWarning)
        a = pt.rsd(rsd="ept", k=ref[:8, 0], linear=linear, bias=1.8, b2=0.5, f=0.8, ir=False,
                   alpha0=3.0, precision="fast")
        b = pt.ept(k=ref[:8, 0], linear=linear, b1=1.8, b2=0.5, f=0.8, ir=False, alpha0=3.0,
                   precision="fast")
        assert np.array_equal(a["P0"], b["P0"])
        c = pt.RsdPlan(ref[:8, 0], rsd="ept", precision="fast", ir=False)(
            linear=linear, bias=1.8, b2=0.5, f=0.8, alpha0=3.0)
        assert np.array_equal(c["P0"], b["P0"])
        with pytest.raises(ValueError, match="alpha0"):
            pt.rsd(rsd="tns", k=ref[:8, 0], alpha0=1.0)
        s = 0.01 * b["P0"]
        data = {"k": b["k"], "P0": b["P0"], "s0": s, "P2": b["P2"], "s2": s}
        t = pt.fit(data, [0.3], free=("f", "b1"), ells=(0, 2), rsd="ept", linear=linear, bias=1.7,
                   f=0.7, b2=0.5, alpha0=3.0, ir=False, precision="fast")
    assert abs(t["f"][0] - 0.8) < 1e-3 and abs(t["b1"][0] - 1.8) < 1e-3


def test_fit_ept_covariance_path_profile_model_and_derived(tmp_path):
    """Issue 48's faces: a covariance path gives the fit of the same array; the search reports its
    starts; the derived fsigma8 is f sigma8(z); profile="f" crosses delta = 1 at the fit's interval;
    model_out gives the best-fit multipoles; flat priors bound the fit."""
    k = np.geomspace(0.02, 0.2, 20)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", pt.PtSpectraWarning)
        truth = dict(b1=2.0, f=0.7, alpha0=5.0)
        m = pt.ept(k=k, precision="fast", **truth)
        s = 0.01 * m["P0"]
        data = {"k": k, "P0": m["P0"], "s0": s, "P2": m["P2"], "s2": s}
        cov = np.diag(np.concatenate([s, s]) ** 2)
        path = tmp_path / "cov.txt"
        np.savetxt(path, cov)
        args = dict(free=("f", "b1"), marginalise=("alpha0",), precision="fast", b1=1.8, f=0.6)
        a = pt.fit_ept(data, [0.2], covariance=cov, **args)
        b = pt.fit_ept(data, [0.2], covariance=str(path), **args)
        for name in ("f", "b1", "minus_2_ln_L", "err_f", "f_lo", "f_hi"):
            assert a[name][0] == pytest.approx(b[name][0], rel=1e-12), name
        assert a["starts"][0] == 8 and 1 <= a["starts_agree"][0] <= 8
        assert a["fsigma8"][0] == pytest.approx(a["f"][0] * a["sigma8_z"][0], rel=1e-14)
        assert a["err_fsigma8"][0] == pytest.approx(a["err_f"][0] * a["sigma8_z"][0], rel=1e-12)
        p = pt.fit_ept(data, [0.2], profile="f", profile_points=5, profile_span=1.0, **args)
        d = p["delta_minus_2_ln_L"]
        assert abs(d[2]) < 1e-3 and all(d > -1e-3)
        # Points 0 and 4 at -+1 fitted error: delta = 1 there (a near-Gaussian likelihood).
        assert d[0] == pytest.approx(1.0, abs=0.15) and d[4] == pytest.approx(1.0, abs=0.15)
        t, model = pt.fit_ept(data, [0.15, 0.2], model_out=True, **args)
        best = pt.ept(k=k, precision="fast", b1=t["b1"][1], f=t["f"][1], alpha0=t["alpha0"][1])
        assert np.allclose(model["P0_kmax0.2"], best["P0"], rtol=1e-10)
        flat = pt.fit_ept(data, [0.2], priors={"f": ("flat", 0.5, 0.65)}, **args)
        assert flat["f"][0] == 0.65
        with pytest.raises(ValueError, match="lognormal|flat"):
            pt.fit_ept(data, [0.2], priors={"f": ("beta", 0.5, 0.65)}, **args)
