"""pt.Pipeline (issue 47): equals pt.EptPlan + Observation, states the loop terms' source, names bad
parameters, gives exact nuisance Jacobians."""

from pathlib import Path

import numpy as np
import pytest

import pt_spectra as pt

WINDOW = Path(__file__).resolve().parents[2] / "examples/data/boss_dr12_cmass_ngc/window_BOSS_CMASS_NGC_z057.dat"
Z = 0.57
PARAMS = dict(b1=2.1, b2=-0.4, bs=0.3, alpha0=12.0, sn=1500.0)
COSMO = dict(h=0.69, omega_b=0.0224, omega_cdm=0.295 * 0.69**2 - 0.0224, n_s=0.955, sigma8=0.83)


@pytest.fixture(scope="module")
def setup(tmp_path_factory):
    cache = tmp_path_factory.mktemp("store")
    k = 0.015 * (0.38 / 0.015) ** (np.arange(20) / 19)
    obs = pt.Observation([0, 2], k, window=str(WINDOW))
    pipe = pt.Pipeline(obs, Z, precision="fast", cache_dir=cache)
    return obs, pipe, cache


def test_the_pipeline_equals_the_plan_and_the_observation(setup):
    obs, pipe, cache = setup
    got = pipe(COSMO, **PARAMS)
    assert pipe.meta["loop_terms"].startswith("loop terms: basis")
    assert not pipe.meta["fallback"] and pipe.meta["residual"] <= pipe.meta["max_residual"]
    # the same without AP by the existing faces (plan on the observation's model k, same residual)
    plan = pt.EptPlan(obs.k_model, precision="fast", two_loop="basis", cache_dir=cache)
    table = plan(cosmology=COSMO, z=Z, ells=list(obs.model_ells), **PARAMS)
    model = [np.asarray(table[f"P{l}"]) for l in obs.model_ells]
    expected = np.asarray(obs.apply_values(model)).ravel()
    # the plan takes the emulated spectrum on the basis too (the limit is one, 2e-3): the two agree
    # to the pipeline's loop range (<= 1e-5 of each multipole's largest value) and its thinned tensors
    assert table.meta["methods"]["loop terms"] == "basis"
    assert np.max(np.abs(got - expected)) / np.max(np.abs(expected)) < 1e-4


def test_a_bad_name_is_refused_naming_the_valid_ones(setup):
    _, pipe, _ = setup
    with pytest.raises(ValueError, match="alpha0"):
        pipe(COSMO, c0=1.0)


def test_a_spectrum_outside_the_span_falls_back_with_a_warning(setup):
    obs, _, cache = setup
    strict = pt.Pipeline(obs, Z, precision="fast", cache_dir=cache, max_residual=1e-6)
    with pytest.warns(UserWarning, match="fallback"):
        strict(COSMO, **PARAMS)
    assert strict.meta["fallback"]


def test_the_nuisance_jacobian_matches_differences(setup):
    _, pipe, _ = setup
    values, jac = pipe(COSMO, jacobian=True, **PARAMS)
    assert jac.shape == (len(pipe.nuisance), values.size)
    assert pipe.nuisance[-1] == "f"
    # the same cosmology again: from its nuisance polynomial (made with its f-derivative), the same
    # rows to rounding
    again, jac_again = pipe(COSMO, jacobian=True, **PARAMS)
    np.testing.assert_allclose(again, values, rtol=1e-10)
    assert np.max(np.abs(jac_again - jac)) <= 1e-9 * np.max(np.abs(jac))
    for i, name in enumerate(pipe.nuisance):
        x = pipe.meta["f"] if name == "f" else PARAMS.get(name, 0.0)
        # the polynomial parameters exactly by wide steps; f (through the BAO damping) by small ones
        h = 1e-3 * x if name == "f" else 0.5 * max(abs(x), 1.0)
        at = lambda x: pipe(COSMO, **{**PARAMS, name: x})
        fd = (8 * (at(x + h) - at(x - h)) - (at(x + 2 * h) - at(x - 2 * h))) / (12 * h)
        assert np.max(np.abs(jac[i] - fd)) <= 1e-6 * np.max(np.abs(fd)) + 1e-12, name


def test_a_batch_gives_the_single_calls(setup):
    _, pipe, _ = setup
    other = dict(COSMO, sigma8=0.78)
    rows = pipe.batch([COSMO, other], [PARAMS, dict(b1=1.5)])
    # a call repeating the last cosmology is its nuisance polynomial: equal to rounding (~1e-13)
    np.testing.assert_allclose(rows[0], pipe(COSMO, **PARAMS), rtol=1e-12)
    np.testing.assert_allclose(rows[1], pipe(other, b1=1.5), rtol=1e-12)


def test_a_bispectrum_block_follows_the_power_spectrum(setup):
    obs, pipe, cache = setup
    bins = np.array([[0.015, 0.025, 0.035], [0.045, 0.055, 0.065]])
    joint = pt.Pipeline(obs, Z, precision="fast", cache_dir=cache, triangles=bins, bin_width=0.01,
                        b_ells=[0, 2], n_bar=3e-4)
    b = dict(c1=1.0, b_shot=0.8)
    got = joint(COSMO, **PARAMS, **b)
    n = joint.meta["power_len"]
    assert len(got) == n + 4 and joint.meta["bispectrum"]
    np.testing.assert_allclose(got[:n], pipe(COSMO, **PARAMS), rtol=1e-12)
    # the block is the bispectrum plan on the same spectrum at f(z) (no AP: no fiducial)
    f = joint.meta["f"]
    terms = pt.BispectrumPlan(bins, bin_width=0.01).terms(cosmology=COSMO, z=Z, f=f)
    ref, _ = terms.multipoles(b1=2.1, b2=-0.4, bs=0.3, n_bar=3e-4, **b)
    np.testing.assert_allclose(got[n:], np.concatenate([ref[:, 0], ref[:, 1]]), rtol=1e-6)
    # a given f is the step at that f
    at_f = joint(COSMO, f=f + 0.05, **PARAMS, **b)
    ref_f, _ = pt.BispectrumPlan(bins, bin_width=0.01).terms(cosmology=COSMO, z=Z, f=f + 0.05).multipoles(
        b1=2.1, b2=-0.4, bs=0.3, n_bar=3e-4, **b)
    np.testing.assert_allclose(at_f[n:], np.concatenate([ref_f[:, 0], ref_f[:, 1]]), rtol=1e-6)
    assert "b_shot" in joint.parameters
    with pytest.raises(ValueError, match="bispectrum"):
        joint(COSMO, jacobian=True, **PARAMS)
    with pytest.raises(ValueError, match="triangles"):
        pt.Pipeline(obs, Z, precision="fast", cache_dir=cache, n_bar=3e-4)
    # the block by its name with a dict of its options: the same data vector
    named = pt.Pipeline(obs, Z, precision="fast", cache_dir=cache,
                        bispectrum=dict(triangles=bins, bin_width=0.01, b_ells=[0, 2], n_bar=3e-4))
    np.testing.assert_allclose(named(COSMO, **PARAMS, **b), got, rtol=1e-12)
    # a keyword of no block names the blocks and their keywords
    with pytest.raises(TypeError, match="bispectrum"):
        pt.Pipeline(obs, Z, precision="fast", cache_dir=cache, trinagles=bins)


def test_a_one_loop_bispectrum_block_follows_the_power_spectrum(setup):
    """The one-loop block reads the multipole tensors cached by pt.OneLoopMultipolePlan (refused before,
    saying how to build them) and equals the plan's B0, B2 at the pipeline's f, IR setting and bias; a
    counterterm adds its shape (st_1: a constant in B0 only); AP moves it."""
    obs, _, cache = setup
    tri = np.array([[0.05, 0.07, 0.1], [0.04, 0.04, 0.06]])
    opts = dict(triangles=tri, rule=[2, 2, 2], ells=[0, 2], cache_dir=str(cache))
    with pytest.raises(ValueError, match="not cached"):
        pt.Pipeline(obs, Z, precision="fast", cache_dir=cache, one_loop_bispectrum=opts)
    plan = pt.OneLoopMultipolePlan(tri, radial=2, mu=2, phi=2, cache_dir=cache)
    for ir in [False, True]:
        joint = pt.Pipeline(obs, Z, precision="fast", cache_dir=cache, ir=ir, one_loop_bispectrum=opts)
        n = joint.meta["power_len"]
        got = joint(COSMO, **PARAMS)
        assert len(got) == n + 4 and joint.meta["one_loop_bispectrum"]
        assert "one-loop bispectrum" in joint.meta["blocks"][0]
        ref = plan(cosmology=COSMO, z=Z, f=joint.meta["f"], b1=2.1, b2=-0.4, bs=0.3, ir=ir)
        assert ref["loop_terms"].startswith("loop terms: multipole tensors")
        np.testing.assert_allclose(got[n:], np.concatenate([ref["B0"], ref["B2"]]), rtol=1e-6)
        st = joint(COSMO, **PARAMS, st_1=1e6)
        np.testing.assert_allclose(st[n:n + 2] - got[n:n + 2], 1e6, rtol=1e-9)
        np.testing.assert_array_equal(st[n + 2:], got[n + 2:])
    assert "ct_k2" in joint.parameters and "b_gamma3" in joint.parameters
    # AP against a fiducial: its isotropic dilation exact on every term, the anisotropic rest on the tree
    # level only, stated; the entries move by the distortion
    fid = dict(COSMO, omega_cdm=COSMO["omega_cdm"] * 1.05)
    ap = pt.Pipeline(obs, Z, fiducial=fid, precision="fast", cache_dir=cache, one_loop_bispectrum=opts)
    assert "the anisotropic rest on the tree level only" in ap.meta["blocks"][0]
    moved = ap(COSMO, **PARAMS)[n:]
    assert 1e-3 < np.max(np.abs(moved / got[n:] - 1)) < 0.2


def test_the_loop_range_is_stated_and_can_be_switched_off(setup):
    """The BOSS window reaches 1e-4 ... 4 h/Mpc; the loops are computed on about 3e-3 ... 0.6 h/Mpc, the
    change measured at construction (<= 1e-5 of each multipole's largest value) is in meta, and
    restrict_loops=False gives the same data vector to that level."""
    obs, pipe, cache = setup
    (lo, hi), change = pipe.meta["loop_range"]
    assert obs.k_model[0] < lo < 0.015 and 0.38 < hi < obs.k_model[-1]
    assert 0 <= change <= 1e-5 and "loop terms on true k" in pipe.meta["loop_range_note"]
    # the rule in mu, chosen at construction by the same kind of measurement, is stated too: without
    # AP the integrand is a polynomial in mu^2 times the BAO damping, and 12 points give 24's to rounding
    note = pipe.meta["mu_rule_note"]
    assert note.startswith("multipoles: 12-point Gauss-Legendre rule in mu") and "without AP" in note
    everywhere = pt.Pipeline(obs, Z, precision="fast", cache_dir=cache, restrict_loops=False)
    assert everywhere.meta["loop_range"] is None
    a, b = pipe(COSMO, **PARAMS), everywhere(COSMO, **PARAMS)
    n = len(a) // 2
    for block in (slice(0, n), slice(n, 2 * n)):
        assert np.max(np.abs(a[block] - b[block])) <= 3e-5 * np.max(np.abs(b[block]))


def test_a_repeated_cosmology_is_the_nuisance_polynomial(setup):
    """The same cosmology again with new nuisance parameters: the step's nuisance polynomial (exact to
    rounding) instead of the step; the same numbers as a fresh call, and its Jacobian too."""
    obs, pipe, cache = setup
    other = dict(COSMO, n_s=0.96)
    sets = [PARAMS, dict(PARAMS, b1=1.7, b2=0.5, sn2=-300.0), dict(PARAMS, alpha2=4.0, b3=0.3)]
    got = [pipe(other, **p) for p in sets]
    _, jac = pipe(other, jacobian=True, **sets[1])
    for p, g in zip(sets, got):
        fresh = pt.Pipeline(obs, Z, precision="fast", cache_dir=cache)(other, **p)
        np.testing.assert_allclose(g, fresh, rtol=1e-9, atol=1e-9 * np.max(np.abs(fresh)))
    fresh_jac = pt.Pipeline(obs, Z, precision="fast", cache_dir=cache)(other, jacobian=True, **sets[1])[1]
    np.testing.assert_allclose(jac, fresh_jac, rtol=1e-9, atol=1e-9 * np.max(np.abs(fresh_jac)))
    # a given f different from f(z) is its own polynomial
    with_f = pipe(other, f=0.7, **PARAMS)
    np.testing.assert_allclose(with_f, pt.Pipeline(obs, Z, precision="fast", cache_dir=cache)(
        other, f=0.7, **PARAMS), rtol=1e-9)


def test_the_template_jacobian_matches_differences(setup):
    """d(data vector)/d(f, apar, aperp), exact: f's against fourth-order differences (the alpha rows
    are tested against differences in Rust, tests/tests/suite/pipeline.rs, where alpha can be set)."""
    obs, _, cache = setup
    fiducial = dict(h=0.676, omega_b=0.022, omega_cdm=0.31 * 0.676**2 - 0.022, n_s=0.97, sigma8=0.8)
    pipe = pt.Pipeline(obs, Z, fiducial=fiducial, precision="fast", cache_dir=cache)
    # with AP, the rule in mu is measured at the corners of the AP range as well
    assert "the AP range's corners" in pipe.meta["mu_rule_note"]
    jac = pipe.template_jacobian(COSMO, **PARAMS)
    values = pipe(COSMO, **PARAMS)
    assert jac.shape == (3, values.size)
    f0 = pipe.meta["f"]
    h = 1e-4 * f0
    at = lambda f: pipe(COSMO, **{**PARAMS, "f": f})
    fd = (8 * (at(f0 + h) - at(f0 - h)) - (at(f0 + 2 * h) - at(f0 - 2 * h))) / (12 * h)
    assert np.max(np.abs(jac[0] - fd)) <= 1e-6 * np.max(np.abs(fd))
    assert np.all(np.isfinite(jac)) and np.max(np.abs(jac[1])) > 0 and np.max(np.abs(jac[2])) > 0
