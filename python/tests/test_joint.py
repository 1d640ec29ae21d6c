"""Joint fits of several data sets from Python (``pt.fit_joint``, an analysis file): one set is
``fit_ept`` exactly; two sets with different b1 and one f recover both b1 and the shared f; the file's
mistakes are ValueErrors naming the key."""

import warnings

import numpy as np
import pytest

import pt_spectra as pt

K = np.geomspace(0.02, 0.2, 25)


def _data(tmp_path, name, b1):
    m = pt.ept(k=K, precision="fast", b1=b1, b2=-0.4, alpha0=8.0, sn=900.0, f=0.7)
    s = 0.01 * m["P0"]
    rows = np.column_stack([K, m["P0"], s, m["P2"], s, m["P4"], s])
    path = tmp_path / name
    np.savetxt(path, rows, fmt="%.17g")
    return path


def _set(label, path):
    return (f'[[dataset]]\nlabel = "{label}"\ndata = "{path.name}"\nz = 0.0\nells = [0, 2]\n'
            'k_max = 0.2\nfree = ["f", "b1"]\nmarginalise = ["alpha0", "sn"]\n'
            '[dataset.start]\nb1 = 1.9\nb2 = -0.4\nf = 0.6\n\n')


SEARCH = "[search]\nstarts = 4\nprofile_check = false\n\n"


def test_one_set_is_fit_ept(tmp_path):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", pt.PtSpectraWarning)
        path = _data(tmp_path, "a.dat", 2.0)
        (tmp_path / "one.toml").write_text(SEARCH + _set("a", path))
        joint = pt.fit_joint(tmp_path / "one.toml", precision="fast")
        single = pt.fit_ept(str(path), [0.2], free=("f", "b1"), marginalise=("alpha0", "sn"),
                            precision="fast", b1=1.9, b2=-0.4, f=0.6, starts=4,
                            profile_check=False)
    assert len(joint["f"]) == 1
    for name in ("f", "err_f", "b1", "err_b1", "alpha0", "err_sn", "chi2", "minus_2_ln_L",
                 "fsigma8", "err_fsigma8"):
        assert joint[name][0] == single[name][0], name


def test_two_sets_recover_their_b1_and_the_shared_f(tmp_path):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", pt.PtSpectraWarning)
        low, high = _data(tmp_path, "low.dat", 1.8), _data(tmp_path, "high.dat", 2.2)
        (tmp_path / "two.toml").write_text(SEARCH + _set("low", low) + _set("high", high))
        t = pt.fit_joint(tmp_path / "two.toml", precision="fast")
    assert list(t["set"]) == [1, 2]
    for row, b1 in ((0, 1.8), (1, 2.2)):
        assert abs(t["b1"][row] - b1) < 0.1 * t["err_b1"][row]
        assert abs(t["f"][row] - 0.7) < 0.1 * t["err_f"][row]
    assert t["f"][0] == t["f"][1] and t["err_f"][0] == t["err_f"][1]


def test_analysis_file_mistakes_name_the_key(tmp_path):
    path = _data(tmp_path, "a.dat", 2.0)
    (tmp_path / "bad.toml").write_text(_set("a", path).replace("k_max", "kmax"))
    with pytest.raises(ValueError, match=r"bad.toml: `dataset\[1\].kmax`: unknown key"):
        pt.fit_joint(tmp_path / "bad.toml")
    (tmp_path / "shared.toml").write_text('shared = ["bs"]\n' + _set("a", path))
    with pytest.raises(ValueError, match="`bs` is declared shared but no data set has it free"):
        pt.fit_joint(tmp_path / "shared.toml")


def test_a_set_with_its_bispectrum_recovers_the_truth(tmp_path):
    """``[dataset.bispectrum]`` from Python: noise-free P (``pt.ept``) and B0, B2 (``pt.bispectrum``) of
    one truth with a diagonal joint covariance; f, b1, b2, c1 free, b_shot marginalised, all recovered
    within 0.1 sigma; the bispectrum's parameters are columns of the result."""
    tri = np.array([[0.03, 0.03, 0.03], [0.05, 0.05, 0.05], [0.08, 0.08, 0.08], [0.04, 0.05, 0.06],
                    [0.06, 0.08, 0.1], [0.02, 0.08, 0.09], [0.05, 0.1, 0.1], [0.03, 0.06, 0.08]])
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", pt.PtSpectraWarning)
        p = _data(tmp_path, "p.dat", 2.0)
        b = pt.bispectrum(tri, b1=2.0, b2=-0.4, f=0.7, c1=4.0, n_bar=3e-4, b_shot=1.3)
        np.savetxt(tmp_path / "b.dat", np.column_stack([tri, b["B0"], b["B2"], b["B4"]]), fmt="%.17g")
        sigma_p = np.loadtxt(p)[:, 2]
        variances = np.concatenate([np.tile(sigma_p ** 2, 3), np.tile((0.02 * b["B0"]) ** 2, 3)])
        np.savetxt(tmp_path / "joint.dat", np.diag(variances), fmt="%.17g")
        (tmp_path / "pb.toml").write_text(
            SEARCH + '[[dataset]]\nlabel = "pb"\ndata = "p.dat"\nz = 0.0\nells = [0, 2]\nk_max = 0.2\n'
            'free = ["f", "b1", "b2", "c1"]\nmarginalise = ["alpha0", "sn", "b_shot"]\n'
            '[dataset.start]\nb1 = 1.9\nb2 = 0.0\nf = 0.6\n'
            '[dataset.bispectrum]\ndata = "b.dat"\nells = [0, 2]\nk_max = 0.1\n'
            'covariance = "joint.dat"\nn_bar = 3e-4\n')
        t = pt.fit_joint(tmp_path / "pb.toml", precision="fast")
    for name, truth in (("f", 0.7), ("b1", 2.0), ("b2", -0.4), ("c1", 4.0), ("b_shot", 1.3)):
        assert abs(t[name][0] - truth) < 0.1 * t[f"err_{name}"][0], name
    assert t["points"][0] == 50 + 16


def test_the_analysis_likelihood_is_what_fit_joint_minimises(tmp_path):
    """``pt.AnalysisLikelihood``: at the joint best fit its -2 ln L is the fit's sum; loglike is -1/2
    of it by name; its gradient matches differences; values outside the bounds and unknown names are
    ValueErrors."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", pt.PtSpectraWarning)
        low, high = _data(tmp_path, "low.dat", 1.8), _data(tmp_path, "high.dat", 2.2)
        (tmp_path / "two.toml").write_text(SEARCH + _set("low", low) + _set("high", high))
        t = pt.fit_joint(tmp_path / "two.toml", precision="fast")
        lik = pt.AnalysisLikelihood(tmp_path / "two.toml", precision="fast")
    assert lik.names == ["f", "b1[low]", "b1[high]"] and lik.exact_gradient
    best = [t["f"][0], t["b1"][0], t["b1"][1]]
    total = t["minus_2_ln_L"][0] + t["minus_2_ln_L"][1]
    assert lik(best) == pytest.approx(total, rel=1e-9)
    by_name = dict(zip(lik.names, best))
    assert lik.loglike(by_name) == pytest.approx(-0.5 * total, rel=1e-9)
    assert lik(**by_name) == lik(best)
    x = np.array(best) * 1.01
    value, g = lik.gradient(x)
    assert value == pytest.approx(lik(x), rel=1e-9)
    for j in range(3):
        h = 1e-4
        up, down = x.copy(), x.copy()
        up[j] += h
        down[j] -= h
        assert g[j] == pytest.approx((lik(up) - lik(down)) / (2 * h), rel=1e-4, abs=1e-3)
    assert set(lik.sigma8_z) == {"low", "high"}
    with pytest.raises(ValueError, match="outside the likelihood's range"):
        lik([5.0, 2.0, 2.0])
    with pytest.raises(ValueError, match="unknown: b2"):
        lik(**by_name, b2=0.0)


def test_the_cobaya_likelihood_of_an_analysis_file(tmp_path):
    """``pt_spectra.likelihoods.AnalysisFile``: cobaya's log-likelihood at the joint best fit is -1/2
    of the fit's -2 ln L, fσ8 is derived, and a point outside the bounds has zero likelihood."""
    from cobaya.model import get_model

    with warnings.catch_warnings():
        warnings.simplefilter("ignore", pt.PtSpectraWarning)
        low, high = _data(tmp_path, "low.dat", 1.8), _data(tmp_path, "high.dat", 2.2)
        (tmp_path / "two.toml").write_text(SEARCH + _set("low", low) + _set("high", high))
        t = pt.fit_joint(tmp_path / "two.toml", precision="fast")
        info = {"likelihood": {"joint": {"class": "pt_spectra.likelihoods.AnalysisFile",
                                         "analysis": str(tmp_path / "two.toml"), "precision": "fast"}},
                "params": {"f": {"prior": {"min": 0.0, "max": 2.0}},
                           "b1_low": {"prior": {"min": 0.5, "max": 4.0}},
                           "b1_high": {"prior": {"min": 0.5, "max": 4.0}},
                           "fsigma8_low": None, "fsigma8_high": None}}
        model = get_model(info)
    point = {"f": t["f"][0], "b1_low": t["b1"][0], "b1_high": t["b1"][1]}
    total = t["minus_2_ln_L"][0] + t["minus_2_ln_L"][1]
    loglike, derived = model.loglike(point, return_derived=True)
    assert loglike == pytest.approx(-0.5 * total, rel=1e-9)
    s8 = dict(zip(t["set"], t["sigma8_z"]))
    assert derived[0] == pytest.approx(t["f"][0] * s8[1], rel=1e-12)
    assert model.loglike({**point, "b1_low": 0.5})[0] < -0.5 * total
