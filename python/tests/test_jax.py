"""pt_spectra.jax (issue 47, part 4): the likelihood and the data vector as JAX functions whose
derivatives are the library's exact ones, under jit, grad, jvp and vmap; checked against the library
and against differences where the model is exactly linear or quadratic."""

import warnings
from pathlib import Path

import numpy as np
import pytest

jax = pytest.importorskip("jax")
jax.config.update("jax_enable_x64", True)
import jax.numpy as jnp  # noqa: E402

import pt_spectra as pt  # noqa: E402
import pt_spectra.jax as ptj  # noqa: E402
from test_joint import SEARCH, _data, _set  # noqa: E402

WINDOW = Path(__file__).resolve().parents[2] / "examples/data/boss_dr12_cmass_ngc/window_BOSS_CMASS_NGC_z057.dat"
COSMO = dict(h=0.69, omega_b=0.0224, omega_cdm=0.295 * 0.69**2 - 0.0224, n_s=0.955, sigma8=0.83)


@pytest.fixture(scope="module")
def likelihood(tmp_path_factory):
    tmp = tmp_path_factory.mktemp("jax")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", pt.PtSpectraWarning)
        low, high = _data(tmp, "low.dat", 1.8), _data(tmp, "high.dat", 2.2)
        (tmp / "two.toml").write_text(SEARCH + _set("low", low) + _set("high", high))
        return pt.AnalysisLikelihood(tmp / "two.toml", precision="fast")


def test_the_log_likelihood_and_its_gradient_are_the_library_s(likelihood):
    ln_l = ptj.log_likelihood(likelihood)
    assert ln_l.names == ["f", "b1[low]", "b1[high]"]
    x = np.array([0.68, 1.83, 2.15])
    value, g = likelihood.gradient(x)
    assert float(ln_l(x)) == pytest.approx(-0.5 * likelihood(x), rel=1e-12)
    # reverse mode, jitted, and forward mode along a direction: all the library's exact gradient
    np.testing.assert_allclose(jax.grad(ln_l)(x), -0.5 * g, rtol=1e-12)
    np.testing.assert_allclose(jax.jit(jax.grad(ln_l))(x), -0.5 * g, rtol=1e-12)
    t = np.array([0.3, -1.0, 2.0])
    v, dv = jax.jvp(ln_l, (jnp.asarray(x),), (jnp.asarray(t),))
    assert float(v) == pytest.approx(-0.5 * value, rel=1e-12)
    assert float(dv) == pytest.approx(-0.5 * g @ t, rel=1e-12)
    # and it is the derivative of the value: central differences of the library's -2 ln L
    for j in range(3):
        h = 1e-5
        up, down = x.copy(), x.copy()
        up[j] += h
        down[j] -= h
        assert -0.5 * g[j] == pytest.approx(-0.25 * (likelihood(up) - likelihood(down)) / h, rel=1e-5, abs=1e-6)
    # a batch: one library call per member, the same numbers
    xs = np.stack([x, x * 1.01])
    np.testing.assert_allclose(jax.vmap(ln_l)(xs), [-0.5 * likelihood(r) for r in xs], rtol=1e-12)


def test_wrong_inputs_are_value_errors(likelihood):
    ln_l = ptj.log_likelihood(likelihood)
    with pytest.raises(ValueError, match="3 values"):
        ln_l(np.ones(2))
    jax.config.update("jax_enable_x64", False)
    try:
        with pytest.raises(ValueError, match="64-bit"):
            ptj.log_likelihood(likelihood)
    finally:
        jax.config.update("jax_enable_x64", True)


@pytest.fixture(scope="module")
def pipeline(tmp_path_factory):
    cache = tmp_path_factory.mktemp("store")
    k = 0.015 * (0.38 / 0.015) ** (np.arange(20) / 19)
    obs = pt.Observation([0, 2], k, window=str(WINDOW))
    return pt.Pipeline(obs, 0.57, precision="fast", cache_dir=cache)


def test_the_data_vector_s_jacobian_is_exact(pipeline):
    names = ["b1", "b2", "alpha0", "sn", "f"]
    d = ptj.data_vector(pipeline, names, cosmology=COSMO, bs=0.3)
    x = np.array([2.1, -0.4, 12.0, 1500.0, 0.75])
    v = np.asarray(d(x))
    np.testing.assert_allclose(v, pipeline(COSMO, bs=0.3, **dict(zip(names, x))), rtol=1e-12)
    jac = np.asarray(jax.jacfwd(d)(x))  # (len(v), 5)
    np.testing.assert_allclose(jax.jacrev(d)(x), jac, rtol=1e-12, atol=0)
    scale = np.abs(jac).max(axis=0)
    # alpha0 and sn enter linearly, b1 and b2 quadratically: central differences are exact for
    # them up to rounding, an independent check of each column
    for j, h in ((0, 1e-3), (1, 1e-2), (2, 1.0), (3, 10.0)):
        up, down = x.copy(), x.copy()
        up[j] += h
        down[j] -= h
        diff = (np.asarray(d(up)) - np.asarray(d(down))) / (2 * h)
        assert np.max(np.abs(jac[:, j] - diff)) <= 1e-7 * scale[j], names[j]
    # f (IR damping: not a polynomial): fourth-order differences
    h = 1e-3
    fx = [np.asarray(d(x + s * h * np.eye(5)[4])) for s in (-2, -1, 1, 2)]
    diff = (fx[0] - 8 * fx[1] + 8 * fx[2] - fx[3]) / (12 * h)
    assert np.max(np.abs(jac[:, 4] - diff)) <= 1e-6 * scale[4]


def test_the_data_vector_refuses_unknown_or_doubled_names(pipeline):
    with pytest.raises(ValueError, match="unknown: c0"):
        ptj.data_vector(pipeline, ["b1", "c0"], cosmology=COSMO)
    with pytest.raises(ValueError, match="both free"):
        ptj.data_vector(pipeline, ["b1"], cosmology=COSMO, b1=2.0)


COSMO_AS = {"h": 0.69, "omega_b": 0.0224, "omega_cdm": 0.118, "ln10^{10}A_s": 3.0, "n_s": 0.96,
            "m_nu": 0.06}


def test_the_cosmological_parameters_are_differentiable_through_jax(pipeline):
    assert pipeline.cosmological_parameters == ["h", "omega_b", "omega_cdm", "ln10^{10}A_s", "n_s",
                                                "m_nu", "w0", "wa"]
    names = ["b1", "h", "omega_cdm", "n_s"]
    d = ptj.data_vector(pipeline, names, cosmology=COSMO_AS, b2=0.3, sn=900.0)
    x = np.array([2.0, 0.69, 0.118, 0.96])
    v, jc = pipeline.cosmology_jacobian(COSMO_AS, b1=2.0, b2=0.3, sn=900.0)
    assert jc.shape == (8, len(v))
    np.testing.assert_allclose(np.asarray(d(x)), v, rtol=1e-12)
    jac = np.asarray(jax.jacfwd(d)(x))
    np.testing.assert_allclose(jax.jacrev(d)(x), jac, rtol=1e-12, atol=0)
    for i, name in enumerate(names[1:], start=1):
        np.testing.assert_allclose(jac[:, i], jc[pipeline.cosmological_parameters.index(name)], rtol=1e-12)
    # each cosmological column against fourth-order differences of the library's data vector
    for i, h in ((1, 2e-3), (2, 1e-3), (3, 2e-3)):
        at = [np.asarray(pipeline({**COSMO_AS, names[i]: x[i] + s * h}, b1=2.0, b2=0.3, sn=900.0))
              for s in (-2, -1, 1, 2)]
        diff = (at[0] - 8 * at[1] + 8 * at[2] - at[3]) / (12 * h)
        assert np.max(np.abs(jac[:, i] - diff)) <= 1e-5 * np.abs(diff).max(), names[i]
    # a free parameter also spelled otherwise, a sigma8 amplitude: errors
    with pytest.raises(ValueError, match="H0"):
        ptj.data_vector(pipeline, ["h"], cosmology={**COSMO_AS, "H0": 69.0})
    with pytest.raises(ValueError, match="sigma8"):
        pipeline.cosmology_jacobian(COSMO, b1=2.0)


def test_the_cosmological_rows_asked_for_are_those_of_all_eight(pipeline):
    # derivatives= computes only the rows a sampler needs (a flat-LCDM chain: five): the same numbers
    # as the full call's rows, with the same data vector and nuisance rows; unknown or doubled names refused
    kw = dict(b1=2.0, b2=0.3, sn=900.0)
    v, n, j = pipeline.full_jacobian(COSMO_AS, **kw)
    asked = ["n_s", "h", "ln10^{10}A_s"]
    v5, n5, j5 = pipeline.full_jacobian(COSMO_AS, derivatives=asked, **kw)
    assert j5.shape == (3, len(v))
    np.testing.assert_array_equal(v5, v)
    np.testing.assert_array_equal(n5, n)
    for row, name in enumerate(asked):
        np.testing.assert_array_equal(j5[row], j[pipeline.cosmological_parameters.index(name)])
    _, jc = pipeline.cosmology_jacobian(COSMO_AS, derivatives=asked, **kw)
    np.testing.assert_array_equal(jc, j5)
    with pytest.raises(ValueError, match="not a sampled parameter"):
        pipeline.cosmology_jacobian(COSMO_AS, derivatives=["sigma8"], **kw)
    with pytest.raises(ValueError, match="twice"):
        pipeline.full_jacobian(COSMO_AS, derivatives=["h", "h"], **kw)
