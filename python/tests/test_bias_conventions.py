"""One meaning of b2, bs, b3 for every model (velocileptors' convention), and the exact maps of the
other conventions (``bias_convention``): the same spectra whichever way the bias is written."""
import warnings

import numpy as np
import pytest

import pt_spectra as pt

K = np.array([0.05, 0.1, 0.2])
# one bias in the three conventions: velocileptors (b2, bs, b3), FAST-PT (b2, 2 bs, b3/2),
# CLASS-PT (b2 + 4/3 bs, bs, -(b3 + 15 bs)/6)
OURS = dict(b2=0.5, bs=-0.15, b3=0.4)
FAST = dict(b2=0.5, bs=-0.3, b3=0.2)
CLASS = dict(b2=0.3, bs=-0.15, b3=-(0.4 - 15 * 0.15) / 6)


def test_real_galaxy_spectra_agree_across_conventions():
    ours = pt.real(model="1l-spt", k=K, precision="fast", bias=2.0, bias_convention="velocileptors",
                   **OURS)
    for conv, b in (("fastpt", FAST), ("classpt", CLASS)):
        t = pt.real(model="1l-spt", k=K, precision="fast", bias=2.0, bias_convention=conv, **b)
        np.testing.assert_allclose(t["P_gg"], ours["P_gg"], rtol=1e-12)
        assert any("given in" in h for h in t.header)


def test_tns_and_ept_take_the_same_convention():
    fast = pt.rsd(rsd="tns", real="1l-spt", k=K, precision="fast", bias=2.0, bias_convention="fastpt",
                  **FAST)
    ours = pt.rsd(rsd="tns", real="1l-spt", k=K, precision="fast", bias=2.0,
                  bias_convention="velocileptors", **OURS)
    np.testing.assert_allclose(fast["P0"], ours["P0"], rtol=1e-12)
    a = pt.ept(k=K, b1=2.0, **OURS)
    b = pt.ept(k=K, b1=2.0, b2=CLASS["b2"], bG2=CLASS["bs"], bGamma3=CLASS["b3"],
               bias_convention="classpt")
    c = pt.rsd(rsd="ept", k=K, bias=2.0, bias_convention="classpt", **CLASS)
    np.testing.assert_allclose(b["P0"], a["P0"], rtol=1e-12)
    np.testing.assert_allclose(c["P2"], a["P2"], rtol=1e-12)


def test_an_implicit_convention_warns_and_bad_names_are_refused():
    with warnings.catch_warnings(record=True) as w:
        warnings.simplefilter("always")
        pt.real(model="1l-spt", k=K, precision="fast", bias=2.0, bs=-0.15)
    assert any("bias_convention='fastpt'" in str(x.message) for x in w)
    with pytest.raises(ValueError, match="velocileptors, fastpt, classpt"):
        pt.real(k=K, bias=2.0, bias_convention="pybird")
    with pytest.raises(ValueError, match="bG2, bGamma3"):
        pt.ept(k=K, b1=2.0, bs=0.1, bias_convention="classpt")


def test_fit_ept_in_the_class_pt_basis(tmp_path):
    """basis="classpt": free/marginalise name CLASS-PT's bias; the table maps it to the model's."""
    k = np.linspace(0.02, 0.2, 10)
    t = pt.ept(k=k, b1=2.0, b2=0.4, bs=-0.3, f=0.7, sn=500.0)
    path = tmp_path / "d.txt"
    np.savetxt(path, np.column_stack([k, t["P0"], 0.02 * t["P0"], t["P2"], 0.02 * np.abs(t["P0"])]),
               header="k P0 err_P0 P2 err_P2")
    r = pt.fit_ept(str(path), [0.2], free=("f", "b1", "b2", "bG2"), marginalise=("sn",),
                   basis="classpt", ells=(0, 2), data_ells=(0, 2), b1=1.8, f=0.6)
    assert r["bG2"][0] == pytest.approx(r["bs"][0], abs=1e-12)
    # bGamma3 stays at its start, 0: then b3 = -15 bG2 (not b3 = 0, the velocileptors fit's default)
    assert r["b3"][0] == pytest.approx(-15 * r["bG2"][0], rel=1e-9, abs=1e-12)
    assert r["b2_velocileptors"][0] == pytest.approx(r["b2"][0] - 4 / 3 * r["bG2"][0], rel=1e-9)
    with pytest.raises(ValueError, match="bG2 and bGamma3"):
        pt.fit_ept(str(path), [0.2], free=("f", "bs"), basis="classpt", ells=(0, 2), data_ells=(0, 2))


def test_convert_bias_maps_and_inverts():
    ours = dict(b1=2.0, b2=0.5, bs=-0.15, b3=0.4)
    classpt = pt.convert_bias(ours, "velocileptors", "classpt")
    assert classpt == pytest.approx(dict(b1=2.0, b2=0.3, bG2=-0.15, bGamma3=CLASS["b3"]))
    assert pt.convert_bias(classpt, "classpt") == pytest.approx(ours)
    assert pt.convert_bias(ours, "velocileptors", "fastpt") == pytest.approx(
        dict(b1=2.0, b2=0.5, bs=-0.3, b3nl=0.2))
    with pytest.raises(ValueError, match="b1, b2, bG2, bGamma3"):
        pt.convert_bias(dict(bs=1.0), "classpt")
