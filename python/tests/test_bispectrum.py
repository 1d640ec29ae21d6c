"""pt.bispectrum and pt.BispectrumPlan: the real-space closed form, the plan against the function, errors."""

from pathlib import Path

import numpy as np
import pytest

import pt_spectra as pt

DATA = Path(__file__).resolve().parents[2] / "pt-spectra" / "tests" / "data"

TRIANGLES = np.array([[0.02, 0.03, 0.04], [0.05, 0.05, 0.05], [0.01, 0.1, 0.105]])


def closed_form(t, p, b1, b2, bs):
    total = 0.0
    for i in range(3):
        j, l = (i + 1) % 3, (i + 2) % 3
        c = (t[l] ** 2 - t[i] ** 2 - t[j] ** 2) / (2 * t[i] * t[j])
        f2 = 5 / 7 + 0.5 * c * (t[i] / t[j] + t[j] / t[i]) + 2 / 7 * c * c
        total += 2 * b1 * b1 * (b1 * f2 + 0.5 * b2 + bs * (c * c - 1 / 3)) * p(t[i]) * p(t[j])
    return total


def test_real_space_limit_is_the_closed_form():
    k = np.unique(TRIANGLES)
    lin = pt.real(model="linear", k=k)
    p = dict(zip(k, lin["P_lin"]))
    with pytest.warns(pt.PtSpectraWarning, match="bin_width"):
        t = pt.bispectrum(TRIANGLES, f=0.0, ir=False, b1=1.8, b2=0.4, bs=-0.2)
    for row, b0, b2 in zip(TRIANGLES, t["B0"], t["B2"]):
        assert b0 == pytest.approx(closed_form(row, p.__getitem__, 1.8, 0.4, -0.2), rel=1e-12)
        assert abs(b2) < 1e-12 * b0
    assert t.meta["model"] == "bispectrum tree"


def test_the_plan_gives_the_table_and_parameter_steps_are_polynomial():
    bins = np.array([[0.015, 0.025, 0.035], [0.045, 0.055, 0.065], [0.035, 0.035, 0.055]])
    kwargs = dict(b1=2.0, b2=0.3, bs=-0.1, c1=2.0, n_bar=3e-4, b_shot=0.9, p_shot=0.1)
    table = pt.bispectrum(bins, bin_width=0.01, z=0.5, fog="lorentzian", sigma_fog=4.0, **kwargs)
    terms = pt.BispectrumPlan(bins, bin_width=0.01).terms(z=0.5, fog="lorentzian", sigma_fog=4.0)
    b, err = terms.multipoles(**kwargs)
    assert b.shape == (3, 3) and err.shape == (3, 3)
    np.testing.assert_allclose(b[:, 0], table["B0"], rtol=1e-9)
    np.testing.assert_allclose(err[:, 2], table["err_B4"], rtol=1e-6, atol=1e-3)
    assert terms.f == pytest.approx(table.meta["f"])
    # B is linear in b2: the midpoint of two steps is the step at the mid value
    b_lo = terms.multipoles(**{**kwargs, "b2": 0.0})[0]
    b_hi = terms.multipoles(**{**kwargs, "b2": 0.6})[0]
    np.testing.assert_allclose(b, 0.5 * (b_lo + b_hi), rtol=1e-12)


def test_the_effective_triangle_shortcut_states_its_error():
    bins = np.array([[0.015, 0.015, 0.015], [0.015, 0.025, 0.035], [0.045, 0.055, 0.065]])
    kwargs = dict(b1=1.8, b2=0.2, bs=-0.1)
    average = pt.BispectrumPlan(bins, bin_width=0.01).terms(z=0.5, q_par=1.02, q_perp=0.99)
    shortcut = pt.BispectrumPlan(bins, bin_width=0.01, effective=True).terms(
        z=0.5, q_par=1.02, q_perp=0.99)
    (a, ea), (s, es) = average.multipoles(**kwargs), shortcut.multipoles(**kwargs)
    assert np.all(np.abs(s - a) <= es + ea)
    assert np.any(np.abs(s[:, 0] - a[:, 0]) > 10 * ea[:, 0])
    with pytest.raises(ValueError, match="bin_width"):
        pt.BispectrumPlan(bins, effective=True)


@pytest.mark.filterwarnings("ignore::pt_spectra.PtSpectraWarning")
@pytest.mark.parametrize("kwargs, needle", [
    (dict(triangles=[[0.01, 0.02, 0.05]]), "does not close"),
    (dict(triangles=[[0.01, 0.02]]), "k1, k2, k3"),
    (dict(triangles=TRIANGLES, fog="lorentz"), "valid: none, lorentzian, gaussian"),
    (dict(triangles=TRIANGLES, legendre_side="4"), "valid: largest, 1, 2, 3"),
    (dict(triangles=TRIANGLES, n_bar=-1.0), "n_bar"),
    (dict(triangles=TRIANGLES, bin_width=0.0), "width"),
])
def test_bad_input_raises_naming_the_problem(kwargs, needle):
    with pytest.raises(ValueError, match=needle):
        pt.bispectrum(**kwargs)


def test_the_plan_refuses_an_implausible_growth_rate_as_the_function_does():
    plan = pt.BispectrumPlan(TRIANGLES)
    for call in (lambda: plan.terms(f=5.0), lambda: pt.bispectrum(TRIANGLES, bin_width=0.005, f=5.0)):
        with pytest.raises(ValueError, match=r"f = 5.*\[0, 2\]"):
            call()


PAIRS = np.array([[0.05, 0.05], [0.02, 0.1]])


def test_sugiyama_basis_in_real_space_and_the_plan():
    t = pt.bispectrum(basis="sugiyama", pairs=PAIRS, f=0.0, ir=False, b1=1.8, b2=0.4)
    assert t.meta["model"] == "bispectrum tree sugiyama"
    for name in ("B202", "B022", "B112"):     # f = 0: no dependence on the line of sight
        np.testing.assert_allclose(t[name], 0.0, atol=1e-10 * np.max(t["B000"]))
    assert np.all(t["err_B000"] <= 1e-4 * t["B000"])
    kwargs = dict(b1=2.0, b2=-0.5, bs=-0.3, c1=3.0, n_bar=4e-4)
    table = pt.bispectrum(basis="sugiyama", pairs=PAIRS, z=0.5, fog="gaussian", sigma_fog=3.0, **kwargs)
    terms = pt.SugiyamaPlan(PAIRS).terms(z=0.5, fog="gaussian", sigma_fog=3.0)
    b, err = terms.multipoles(**kwargs)
    assert b.shape == (2, 6) and err.shape == (2, 6)
    assert pt.SugiyamaPlan.multipole_names == ["000", "110", "202", "022", "112", "220"]
    for m, name in enumerate(pt.SugiyamaPlan.multipole_names):
        np.testing.assert_allclose(b[:, m], table["B" + name], rtol=1e-9)
        np.testing.assert_allclose(err[:, m], table["err_B" + name], rtol=1e-6, atol=1e-3)
    b_lo = terms.multipoles(**{**kwargs, "bs": 0.0})[0]
    b_hi = terms.multipoles(**{**kwargs, "bs": -0.6})[0]
    np.testing.assert_allclose(b, 0.5 * (b_lo + b_hi), rtol=1e-12)


@pytest.mark.filterwarnings("ignore::pt_spectra.PtSpectraWarning")
@pytest.mark.parametrize("kwargs, needle", [
    (dict(basis="sugiyama"), "needs pairs"),
    (dict(basis="sugiyama", pairs=PAIRS, triangles=TRIANGLES), "not triangles"),
    (dict(basis="sugiyama", pairs=[[0.05, 0.05, 0.1]]), "k1, k2"),
    (dict(basis="sugiyama", pairs=[[0.05, -0.1]]), "finite and > 0"),
    (dict(basis="tripolar", pairs=PAIRS), "valid: scoccimarro, sugiyama"),
    (dict(), "give triangles"),
])
def test_bad_sugiyama_input_raises_naming_the_problem(kwargs, needle):
    with pytest.raises(ValueError, match=needle):
        pt.bispectrum(**kwargs)


def test_box_averages_are_the_exact_sums_over_the_modes_of_a_periodic_box():
    # tests/data/bispectrum/ref_box.txt (made by make_reference.py): L = 1000 Mpc/h, shells
    # [1.5 + 3i, 4.5 + 3i) k_f, the plain FFT-estimator average over every ordered triple of modes,
    # model "tree" on the embedded gm2012 spectrum at z = 0.5 without IR
    path = Path(__file__).resolve().parents[2] / "tests" / "data" / "bispectrum" / "ref_box.txt"
    rows = [line.split() for line in path.read_text().splitlines() if line.startswith("tree ")]
    idx = np.array([[float(x) for x in r[1:4]] for r in rows])
    ref = np.array([[float(x) for x in r[5:8]] for r in rows])
    kf = 2 * np.pi / 1000.0
    bins = (3.0 + 3.0 * idx) * kf
    t = pt.bispectrum(bins, bin_width=3 * kf, box_size=1000.0, z=0.5, f=0.723472, ir=False, b1=2.0,
                      b2=-0.5, bs=-0.3)
    got = np.column_stack([t["B0"], t["B2"], t["B4"]])
    assert np.max(np.abs(got - ref) / np.abs(ref[:, :1])) < 1e-6
    # the continuous shells differ from the discrete modes by about 1% on these few-mode shells
    shells = pt.bispectrum(bins, bin_width=3 * kf, z=0.5, f=0.723472, ir=False, b1=2.0, b2=-0.5, bs=-0.3)
    assert np.max(np.abs(shells["B0"] / t["B0"] - 1)) > 1e-3
    with pytest.raises(ValueError, match="box"):
        pt.bispectrum(bins[:1], box_size=1000.0, z=0.5)


def test_one_loop_matter_bispectrum_terms_sum_and_errors():
    tri = np.array([[0.1, 0.1, 0.1], [0.05, 0.1, 0.12]])
    k = np.unique(tri)
    lin = pt.real(model="linear", k=k)
    p = dict(zip(k, lin["P_lin"]))
    t = pt.one_loop_bispectrum(tri)
    assert t.meta["model"] == "bispectrum one-loop matter"
    for row, tree in zip(tri, t["B_tree"]):
        assert tree == pytest.approx(closed_form(row, p.__getitem__, 1.0, 0.0, 0.0), rel=1e-10)
    terms = sum(t[c] for c in ["B_tree", "B222", "B321_I", "B321_II", "B411"])
    np.testing.assert_allclose(t["B_1loop"], terms, rtol=1e-12)
    assert np.all(t["err_B_1loop"] > 0) and np.all(t["err_B_1loop"] < 1e-3 * np.abs(t["B_1loop"]))
    # the equilateral k = 0.1 terms of the independent Monte Carlo (tests/data/bispectrum), within 3 sigma
    mc = {"B222": (2.1708e7, 3.2e5), "B321_I": (1.94134e7, 1.8e5), "B321_II": (-1.37937e7, 2.4e4),
          "B411": (-5.9212e6, 1.5e4)}
    for name, (value, sigma) in mc.items():
        assert abs(t[name][0] - value) < 3 * sigma, name


def test_one_loop_bispectrum_through_the_basis_tensors_agrees_with_direct(tmp_path):
    tri = np.array([[0.1, 0.1, 0.1], [0.05, 0.1, 0.12], [0.02, 0.15, 0.16]])
    rule = dict(radial=6, mu=12, phi=8)  # node for node, so a small rule tests the same thing
    direct = pt.one_loop_bispectrum(tri, two_loop="direct", **rule)
    assert any(line.startswith("loop terms: direct") for line in direct.header)
    for _ in range(2):  # built, then read from the cache
        basis = pt.one_loop_bispectrum(tri, two_loop="basis", cache_dir=tmp_path, **rule)
        assert any("basis tensors on 36 functions" in line for line in basis.header)
        for name in ["B222", "B321_I", "B321_II", "B411", "B_1loop"]:
            assert np.all(np.abs(basis[name] - direct[name]) <= basis["err_" + name]), name
        np.testing.assert_allclose(basis["B_1loop"], direct["B_1loop"], rtol=1e-3)
    # The plan keeps its tensors: a call per spectrum returns the same numbers as the table.
    plan = pt.OneLoopBispectrumPlan(tri, two_loop="basis", cache_dir=tmp_path, **rule)
    out = plan(z=0.5)
    assert "basis tensors" in out["loop_terms"]
    at_z = pt.one_loop_bispectrum(tri, z=0.5, two_loop="basis", cache_dir=tmp_path, **rule)
    for name in ["B_tree", "B222", "B_1loop", "err_B_1loop"]:
        np.testing.assert_allclose(out[name], at_z[name], rtol=1e-12)
    np.testing.assert_array_equal(out["k3"], tri[:, 2])
    direct = pt.OneLoopBispectrumPlan(tri, two_loop="direct", **rule)(z=0.5)
    assert direct["loop_terms"].startswith("loop terms: direct")
    np.testing.assert_allclose(direct["B_1loop"], out["B_1loop"], rtol=1e-3)
    auto = pt.one_loop_bispectrum(tri, two_loop="auto", cache_dir=tmp_path, **rule)
    assert any("basis tensors" in line for line in auto.header)
    with pytest.raises(ValueError, match="two_loop|method|valid"):
        pt.one_loop_bispectrum(tri, two_loop="fast", **rule)


def test_one_loop_bispectrum_in_redshift_space_at_one_orientation():
    tri = np.array([[0.1, 0.1, 0.1], [0.05, 0.1, 0.12]])
    rule = dict(radial=6, mu=12, phi=8)
    real = pt.one_loop_bispectrum(tri, two_loop="direct", **rule)
    zero = pt.one_loop_bispectrum(tri, mu1=0.4, f=0.0, **rule)  # f = 0 is real space
    for name in ["B_tree", "B222", "B321_I", "B321_II", "B411"]:
        np.testing.assert_allclose(zero[name], real[name], rtol=1e-10)
    rsd = pt.one_loop_bispectrum(tri, mu1=0.4, phi_los=0.3, f=0.7, **rule)
    assert any("redshift space" in line and "mu1 = 0.4" in line for line in rsd.header)
    assert np.all(rsd["B_tree"] > real["B_tree"])
    with pytest.raises(ValueError, match="real space only"):
        pt.one_loop_bispectrum(tri, mu1=0.4, two_loop="basis", **rule)
    with pytest.raises(ValueError, match="give mu1"):
        pt.one_loop_bispectrum(tri, f=0.7, **rule)


def test_one_loop_galaxy_multipoles_through_the_python_face():
    tri = np.array([[0.1, 0.1, 0.1], [0.05, 0.08, 0.1]])
    rule = dict(radial=2, mu=2, phi=2)
    bias = dict(b1=2.0, b2=0.3, bs=-0.2)
    real = pt.one_loop_bispectrum(tri, two_loop="direct", **bias, **rule)
    zero = pt.one_loop_bispectrum(tri, multipoles=True, f=0.0, **bias, **rule)  # f = 0: B0 is real space
    assert zero.meta["model"] == "bispectrum one-loop galaxy multipoles"
    for name, mono in [("B_tree", "B0_tree"), ("B222", "B0_222"), ("B321_I", "B0_321_I")]:
        np.testing.assert_allclose(zero[mono], real[name], rtol=1e-10)
    np.testing.assert_allclose(zero["B0"], real["B_1loop"], rtol=1e-7)  # B411's UV constant: round-off
    assert np.all(np.abs(zero["B2"]) < 1e-12 * np.abs(zero["B0"]))
    rsd = pt.one_loop_bispectrum(tri, multipoles=True, f=0.7, legendre_side="1", **bias, **rule)
    assert np.all(rsd["B0"] > zero["B0"]) and np.all(rsd["err_B0"] >= 0)
    assert "shape_B2_ct_fog" in rsd.columns
    with pytest.raises(ValueError, match="no mu1"):
        pt.one_loop_bispectrum(tri, multipoles=True, mu1=0.3, **rule)
    with pytest.raises(ValueError, match="legendre side|valid"):
        pt.one_loop_bispectrum(tri, multipoles=True, legendre_side="4", **rule)


def test_one_loop_galaxy_multipoles_from_tensors_through_the_python_face(tmp_path):
    # two_loop="basis" builds the multipole tensors (16 templates, f free) once into the cache; auto then
    # uses them; both agree with the direct pass within 1e-3 of B0 and their stated errors. With the IR
    # resummation the default spectrum's P_LO (residual 2.5e-3, under IR_MAX_RESIDUAL 1e-2) is represented;
    # a curved-space CAMB table (P_LO residual 0.17) is not: the direct fallback is stated
    tri = np.array([[0.05, 0.07, 0.1], [0.03, 0.03, 0.03]])
    rule = dict(radial=2, mu=2, phi=2)
    bias = dict(b1=2.0, b2=0.3, bs=-0.2)
    direct = pt.one_loop_bispectrum(tri, multipoles=True, f=0.7, ir=False, two_loop="direct", **bias, **rule)
    fast = pt.one_loop_bispectrum(tri, multipoles=True, f=0.7, ir=False, two_loop="basis",
                                  cache_dir=str(tmp_path), **bias, **rule)
    assert any("multipole tensors on 16 SVD templates" in line for line in fast.header), fast.header
    assert "direct" in str(direct.meta["methods"]) and "basis" in str(fast.meta["methods"])
    for ell in ["B0", "B2", "B4"]:
        diff = np.abs(fast[ell] - direct[ell])
        assert np.all(diff < 1e-3 * np.abs(direct["B0"])), (ell, diff / np.abs(direct["B0"]))
        assert np.all(diff <= fast["err_" + ell])
    auto = pt.one_loop_bispectrum(tri, multipoles=True, f=0.7, ir=False, cache_dir=str(tmp_path), **bias, **rule)
    np.testing.assert_allclose(auto["B0"], fast["B0"], rtol=1e-12)
    resummed = pt.one_loop_bispectrum(tri, multipoles=True, f=0.7, two_loop="basis",
                                      cache_dir=str(tmp_path), **bias, **rule)
    assert "basis" in str(resummed.meta["methods"]), resummed.header
    curved = np.loadtxt(DATA / "linear_pk_camb_curved_wa_z0.5.dat")
    with pytest.warns(pt.PtSpectraWarning, match="fallback"):
        outside = pt.one_loop_bispectrum(tri, linear=(curved[:, 0], curved[:, 1]), multipoles=True, f=0.7,
                                         two_loop="basis", cache_dir=str(tmp_path), **bias, **rule)
    assert any("residual on the basis" in line and "exceeds 1.0e-2" in line for line in outside.header)


def test_one_loop_multipoles_over_bins_from_tensors(tmp_path):
    # a bin of width 0.01 through the multipole bin tensors (built once at a tiny rule into the cache): within
    # 1e-3 of B0 of the direct bin on the same rules and within the stated errors, without and with IR; the
    # plan with bin_width gives the table's numbers and the effective triangle
    tri = np.array([[0.045, 0.055, 0.065]])
    rule = dict(radial=2, mu=2, phi=2)
    bias = dict(b1=2.0, b2=0.3, bs=-0.2)
    common = dict(multipoles=True, bin_width=0.01, f=0.7, z=0.5, **bias, **rule)
    plan = pt.OneLoopMultipolePlan(tri, bin_width=0.01, cache_dir=str(tmp_path), **rule)
    assert len(plan) == 1
    for ir in [False, True]:
        direct = pt.one_loop_bispectrum(tri, ir=ir, two_loop="direct", **common)
        fast = pt.one_loop_bispectrum(tri, ir=ir, two_loop="basis", cache_dir=str(tmp_path), **common)
        assert any("multipole bin tensors" in line for line in fast.header), fast.header
        assert "basis" in str(fast.meta["methods"]) and "direct" in str(direct.meta["methods"])
        for ell in ["B0", "B2", "B4"]:
            diff = np.abs(fast[ell] - direct[ell])
            assert np.all(diff < 1e-3 * np.abs(direct["B0"])), (ir, ell, diff / np.abs(direct["B0"]))
            assert np.all(diff <= fast["err_" + ell]), (ir, ell, diff, fast["err_" + ell])
        got = plan(z=0.5, f=0.7, ir=ir, **bias)
        assert "multipole bin tensors" in got["loop_terms"]
        for name in ["B0", "B2", "B4", "err_B0", "k1_eff", "k3_eff"]:
            np.testing.assert_allclose(got[name], fast[name], rtol=1e-9)


def test_one_loop_multipole_plan(tmp_path):
    # the plan reads the tensors once (here built at a tiny rule); each call then takes a new spectrum, f and
    # bias: the same multipoles as the table function on the same rule, resummed within 1e-3 of B0 of the
    # direct pass, direct where the spectrum is not represented (a curved-space table), and f's default is f(z)
    tri = np.array([[0.05, 0.07, 0.1], [0.03, 0.03, 0.03]])
    rule = dict(radial=2, mu=2, phi=2)
    plan = pt.OneLoopMultipolePlan(tri, cache_dir=str(tmp_path), **rule)
    assert len(plan) == 2
    bias = dict(b1=2.0, b2=0.3, bs=-0.2)
    for z, f in [(0.5, 0.7), (1.0, 0.9)]:
        got = plan(z=z, f=f, **bias)
        table = pt.one_loop_bispectrum(tri, z=z, multipoles=True, f=f, ir=False, two_loop="basis",
                                       cache_dir=str(tmp_path), **bias, **rule)
        assert "multipole tensors" in got["loop_terms"]
        for name in ["B0", "B2", "B4", "B0_222", "err_B2"]:
            np.testing.assert_allclose(got[name], table[name], rtol=1e-12)
    default_f = plan(z=0.5, **bias)
    assert 0.5 < default_f["f"] < 1.0
    for z in [0.0, 0.5]:  # P_LO's residual on the templates: 2.5e-3, 1.5e-3 (under IR_MAX_RESIDUAL 1e-2)
        resummed = plan(z=z, f=0.7, ir=True, **bias)
        direct = pt.one_loop_bispectrum(tri, z=z, multipoles=True, f=0.7, two_loop="direct", **bias, **rule)
        assert "multipole tensors" in resummed["loop_terms"], resummed["loop_terms"]
        assert np.all(np.abs(resummed["B0"] - direct["B0"]) < 1e-3 * np.abs(direct["B0"]))
    curved = np.loadtxt(DATA / "linear_pk_camb_curved_wa_z0.5.dat")
    linear = (curved[:, 0], curved[:, 1])
    outside = plan(linear=linear, f=0.7, ir=True, **bias)
    direct = pt.one_loop_bispectrum(tri, linear=linear, multipoles=True, f=0.7, two_loop="direct", **bias, **rule)
    assert "direct integration, since" in outside["loop_terms"], outside["loop_terms"]
    np.testing.assert_allclose(outside["B0"], direct["B0"], rtol=1e-10)
    with pytest.raises(ValueError, match="f"):
        plan(z=0.5, f=3.0, **bias)
    with pytest.raises(ValueError, match="triangle 1"):
        pt.OneLoopMultipolePlan([[0.1, 0.01, 0.01]], cache_dir=str(tmp_path), **rule)


def test_the_bispectrum_plan_with_loop_1_is_the_one_loop_multipole_plan(tmp_path):
    # pt.BispectrumPlan(..., loop=1) plans the one-loop multipoles (the face); loop=0 (the default)
    # stays the tree-level plan; a wrong order or a one-loop option at tree level is refused, named
    tri = np.array([[0.05, 0.07, 0.1], [0.03, 0.03, 0.03]])
    rule = dict(radial=2, mu=2, phi=2)
    one_loop = pt.BispectrumPlan(tri, loop=1, cache_dir=str(tmp_path), **rule)
    assert isinstance(one_loop, pt.OneLoopMultipolePlan)
    bias = dict(b1=2.0, b2=0.3, bs=-0.2)
    got = one_loop(z=0.5, f=0.7, **bias)
    want = pt.OneLoopMultipolePlan(tri, cache_dir=str(tmp_path), **rule)(z=0.5, f=0.7, **bias)
    for name in ["B0", "B2", "B4"]:
        np.testing.assert_array_equal(got[name], want[name])
    tree = pt.BispectrumPlan(tri)
    assert isinstance(tree, pt.BispectrumPlan)
    b, _ = tree.terms(z=0.5, f=0.7, ir=False).multipoles(**bias)
    np.testing.assert_allclose(b[:, 0], got["B0_tree"], rtol=1e-9)
    with pytest.raises(ValueError, match="loop = 2"):
        pt.BispectrumPlan(tri, loop=2)
    with pytest.raises(TypeError, match="cache_dir"):
        pt.BispectrumPlan(tri, cache_dir=str(tmp_path))
    with pytest.raises(ValueError, match="effective"):
        pt.BispectrumPlan(tri, bin_width=0.01, effective=True, loop=1)


def test_one_loop_galaxy_multipoles_over_bins_through_the_python_face():
    # two Nseries bins at a tiny loop rule: without IR the tree columns are the tree-level bin averages,
    # the loops are the effective triangle's (its columns inside the shells) corrected by a few per cent,
    # the correction's error in err_
    tri = np.array([[0.035, 0.055, 0.065], [0.045, 0.045, 0.045]])
    rule = dict(radial=2, mu=2, phi=2)
    bias = dict(b1=2.0, b2=0.3, bs=-0.2)
    t = pt.one_loop_bispectrum(tri, multipoles=True, bin_width=0.01, f=0.7, ir=False, **bias, **rule)
    assert t.meta["model"] == "bispectrum one-loop galaxy multipoles over bins"
    assert any("effective triangle" in line for line in t.header)
    tree = pt.bispectrum(tri, bin_width=0.01, f=0.7, ir=False, **bias)
    for ell in ["B0", "B2"]:
        np.testing.assert_allclose(t[ell + "_tree"], tree[ell], rtol=1e-8, atol=1e-9 * np.abs(tree["B0"]).max())
    for i, side in enumerate(["k1_eff", "k2_eff", "k3_eff"]):
        assert np.all(np.abs(t[side] - tri[:, i]) < 0.005)
    at = pt.one_loop_bispectrum(np.stack([t["k1_eff"], t["k2_eff"], t["k3_eff"]], axis=1), multipoles=True,
                                f=0.7, ir=False, legendre_side="3", **bias, **rule)
    assert np.all(np.abs(t["B0_222"] - at["B0_222"]) < 0.2 * np.abs(at["B0_222"]))
    assert np.all(t["B0_222"] != at["B0_222"]) and np.all(t["err_B0_222"] > at["err_B0_222"])
    with pytest.raises(ValueError, match="multipoles=True"):
        pt.one_loop_bispectrum(tri, bin_width=0.01, **bias, **rule)


def test_one_loop_galaxy_bispectrum_through_the_python_face(tmp_path):
    tri = np.array([[0.1, 0.1, 0.1], [0.05, 0.1, 0.12]])
    rule = dict(radial=6, mu=12, phi=8, two_loop="direct")
    k = np.unique(tri)
    p = dict(zip(k, pt.real(model="linear", k=k)["P_lin"]))
    matter = pt.one_loop_bispectrum(tri, **rule)
    # b1 = 1 alone, without the IR resummation (the galaxy bispectrum's default, not the matter table's):
    # the galaxy kernels are F_n (the galaxy code against the matter code)
    unit = pt.one_loop_bispectrum(tri, b1=1.0, ir=False, **rule)
    assert unit.meta["model"] == "bispectrum one-loop galaxy"
    for name in ["B_tree", "B222", "B321_I", "B321_II", "B411"]:
        np.testing.assert_allclose(unit[name], matter[name], rtol=1e-12)
    # the tree level of a biased tracer is the closed form b1^2 [b1 F2 + b2/2 + bs (mu^2 - 1/3)] P P + cyclic
    plain = pt.one_loop_bispectrum(tri, b1=2.0, b2=0.4, bs=-0.3, ir=False, **rule)
    assert any(line.startswith("no IR resummation") for line in plain.header)
    for row, tree in zip(tri, plain["B_tree"]):
        assert tree == pytest.approx(closed_form(row, p.__getitem__, 2.0, 0.4, -0.3), rel=1e-10)
    # resummed by default: the header states it with Sigma^2, every term moves
    g = pt.one_loop_bispectrum(tri, b1=2.0, b2=0.4, bs=-0.3, **rule)
    assert any(line.startswith("IR resummation of the BAO") and "Sigma^2 = " in line for line in g.header)
    for name in ["B_tree", "B222", "B321_I", "B321_II", "B411"]:
        assert np.all(np.abs(g[name] - plain[name]) > 1e-6 * np.abs(plain[name])), name
    with pytest.raises(ValueError, match="plain SPT"):
        pt.one_loop_bispectrum(tri, ir=True, **rule)
    assert any("b1 = 2, b2 = 0" in line for line in g.header)  # the ESS19 b2 = b2 + (4/3) bs, stated
    assert np.all(g["uv_B411"] != 0)
    # CLASS-PT's convention: bs is b_G2 = velocileptors' bs, b2 is b2 + (4/3) bs
    c = pt.one_loop_bispectrum(tri, b1=2.0, b2=0.4 + 4 / 3 * -0.3, bs=-0.3, bias_convention="classpt", **rule)
    np.testing.assert_allclose(c["B_1loop"], g["B_1loop"], rtol=1e-12)
    # b_gamma3 and the fourth-order coefficients move the loops only
    h = pt.one_loop_bispectrum(tri, b1=2.0, b_gamma3=0.2, loop_bias={"g2x": 0.1}, **rule)
    assert np.all(h["B411"] != pt.one_loop_bispectrum(tri, b1=2.0, **rule)["B411"])
    # f = 0 at an orientation is real space
    zero = pt.one_loop_bispectrum(tri, b1=2.0, b2=0.4, bs=-0.3, mu1=0.4, f=0.0, **rule)
    for name in ["B_tree", "B222", "B321_I", "B321_II", "B411"]:
        np.testing.assert_allclose(zero[name], g[name], rtol=1e-10, err_msg=name)
    with pytest.raises(ValueError, match="valid: b3, g2x"):
        pt.one_loop_bispectrum(tri, b1=2.0, loop_bias={"b2": 1.0}, **rule)
    # through the basis tensors (real space): the same terms within their errors, the method stated
    small = dict(radial=6, mu=12, phi=8)
    basis = pt.one_loop_bispectrum(tri, b1=2.0, b2=0.4, bs=-0.3, two_loop="basis", cache_dir=tmp_path, **small)
    assert basis.meta["methods"] == {"loop terms": "basis"} and g.meta["methods"] == {"loop terms": "direct"}
    assert any(line.startswith("loop terms: basis tensors") for line in basis.header)
    for name in ["B222", "B321_I", "B321_II", "B411", "B_1loop"]:
        assert np.all(np.abs(basis[name] - g[name]) <= basis["err_" + name] + g["err_" + name]), name
    np.testing.assert_allclose(basis["shape_ct_k2"], g["shape_ct_k2"], rtol=1e-12)
    with pytest.raises(ValueError, match="real space only"):
        pt.one_loop_bispectrum(tri, b1=2.0, mu1=0.4, two_loop="basis", **small)


@pytest.mark.parametrize("kwargs, needle", [
    (dict(triangles=[[0.1, 0.1, 0.3]]), "does not close"),
    (dict(triangles=[[0.1, 0.1]]), "k1, k2, k3"),
    (dict(triangles=[[0.1, 0.1, 0.1]], mu=1), "at least 2 nodes"),
])
def test_one_loop_bad_input_raises_naming_the_problem(kwargs, needle):
    with pytest.raises(ValueError, match=needle):
        pt.one_loop_bispectrum(**kwargs)


def test_the_bias_in_other_conventions_is_converted_and_stated():
    """CLASS-PT's (b2, b_G2) and FAST-PT's bs given with bias_convention equal velocileptors'
    b2 = b2 - (4/3) b_G2, bs = b_G2 and bs = bs_FAST-PT / 2, in pt.bispectrum (header line) and
    in BispectrumTerms.multipoles; an unknown convention is a ValueError naming the valid ones."""
    kw = dict(f=0.7, ir=False, b1=1.9)
    with pytest.warns(pt.PtSpectraWarning, match="bin_width"):
        ours = pt.bispectrum(TRIANGLES, b2=0.4 - 4 / 3 * (-0.3), bs=-0.3, **kw)
        classpt = pt.bispectrum(TRIANGLES, b2=0.4, bs=-0.3, bias_convention="classpt", **kw)
        fastpt = pt.bispectrum(TRIANGLES, b2=0.4, bs=2 * 0.25, bias_convention="fastpt", **kw)
        ours_f = pt.bispectrum(TRIANGLES, b2=0.4, bs=0.25, **kw)
    np.testing.assert_allclose(classpt["B0"], ours["B0"], rtol=1e-12)
    np.testing.assert_allclose(fastpt["B2"], ours_f["B2"], rtol=1e-12)
    assert any("given in CLASS-PT" in line for line in classpt.header)
    terms = pt.BispectrumPlan(TRIANGLES).terms(f=0.7, ir=False)
    a, _ = terms.multipoles(b1=1.9, b2=0.4, bs=-0.3, bias_convention="classpt")
    b, _ = terms.multipoles(b1=1.9, b2=0.4 + 0.4, bs=-0.3)
    np.testing.assert_allclose(a, b, rtol=1e-12)
    with pytest.raises(ValueError, match="classpt"):
        terms.multipoles(b1=1.9, bias_convention="pybird")


def test_a_plan_states_what_it_computes_its_method_and_memory():
    plan = pt.BispectrumPlan(TRIANGLES)
    info = plan.plan_info
    assert info["method"] == "direct"
    assert f"of {len(TRIANGLES)} configurations" in info["what"]
    # the process's own memory and the orientation nodes; one spectrum's slots (2 rules, 3 ells, 43)
    assert info["memory_bytes"] > 20e6
    assert info["terms_bytes"] == 2 * len(TRIANGLES) * 3 * 43 * 8
