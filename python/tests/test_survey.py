"""The survey layer from Python: pt.Observation (window, bins, xi), fit_ept through it, and the cobaya
likelihood SurveyMultipoles with the theory's Alcock-Paczynski distortion."""

import warnings

import numpy as np
import pytest

import pt_spectra as pt


def _nothing_cut(path):
    """A window file that cuts nothing: Q0 = 1, Q2 = Q4 = 0 out to s = 1e9 Mpc/h."""
    s = np.geomspace(1e-3, 1e9, 600)
    np.savetxt(path, np.column_stack([s, np.ones_like(s), 0 * s, 0 * s]), header="s Q0 Q2 Q4")
    return path


def test_a_window_that_cuts_nothing_and_fine_bins_leave_the_model(tmp_path):
    """Q0 = 1: the windowed multipoles are the model's own (the two transforms are inverses)."""
    k = np.linspace(0.02, 0.25, 24)
    obs = pt.Observation([0, 2, 4], k, window=_nothing_cut(tmp_path / "w.txt"))
    assert obs.model_ells == [0, 2, 4, 6, 8]
    plan = pt.EptPlan(obs.k_model, ir=False, precision="fast")
    t = plan(ells=obs.model_ells, b1=2.0, f=0.6, alpha0=3.0)
    model = np.array([t[f"P{l}"] for l in obs.model_ells])
    values, errors = obs.apply(model)
    np.testing.assert_array_equal(obs.apply_values(model), values)
    direct = pt.EptPlan(k, ir=False, precision="fast")(b1=2.0, f=0.6, alpha0=3.0)
    for j, ell in enumerate((0, 2, 4)):
        np.testing.assert_allclose(values[j], direct[f"P{ell}"], rtol=0, atol=2e-5 * direct["P0"].max())
    assert np.all(errors >= 0) and np.all(np.isfinite(errors))


def test_a_window_not_normalised_is_warned_about(tmp_path):
    """Q0(0) = 3: the windowed multipoles tend to 3 times the model; the header says so and Python
    warns (a normalised window does not)."""
    s = np.geomspace(1e-3, 1e9, 600)
    path = tmp_path / "w3.txt"
    np.savetxt(path, np.column_stack([s, 3 * np.ones_like(s), 0 * s, 0 * s]), header="s Q0 Q2 Q4")
    k = np.linspace(0.02, 0.25, 24)
    with pytest.warns(UserWarning, match="is 3, not 1"):
        pt.Observation([0, 2, 4], k, window=path)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        pt.Observation([0, 2, 4], k, window=_nothing_cut(tmp_path / "w1.txt"))


def test_xi_of_a_gaussian_is_the_closed_form():
    """P_2(k) = k² e^{−k²R²/2} has ξ_2(s) = −s² e^{−s²/2R²} / ((2π)^{3/2} R⁷)."""
    r, s = 10.0, np.linspace(10.0, 120.0, 23)
    obs = pt.Observation.xi([2], s)
    k = np.asarray(obs.k_model)
    xi, _ = obs.apply(np.array([k**2 * np.exp(-0.5 * (k * r) ** 2)]))
    exact = -s**2 * np.exp(-0.5 * (s / r) ** 2) / ((2 * np.pi) ** 1.5 * r**7)
    np.testing.assert_allclose(xi[0], exact, rtol=0, atol=1e-5 * abs(exact).max())
    with pytest.raises(ValueError, match="ℓ = 3|even"):
        pt.Observation.xi([3], s)


def test_fit_ept_through_a_window_and_bins_recovers_its_own_model(tmp_path):
    """Data made through pt.Observation (BOSS-like ellipsoidal window, 0.01-wide bins) are fitted by
    pt.fit_ept with the same window and bins and a range per multipole."""
    s = np.geomspace(0.01, 3000.0, 400)
    q0 = np.exp(-(s / 400.0) ** 2)
    q2 = -0.1 * (s / 400.0) ** 2 * q0
    window = tmp_path / "window.txt"
    np.savetxt(window, np.column_stack([s, q0, q2, 0.3 * q2]), header="s Q0 Q2 Q4")
    edges = np.round(np.arange(0.0, 0.2001, 0.01), 10)
    obs = pt.Observation([0, 2, 4], window=window, k_edges=edges)
    truth = dict(b1=2.0, f=0.7, alpha0=5.0)
    t = pt.EptPlan(obs.k_model, precision="fast")(ells=obs.model_ells, **truth)
    values, _ = obs.apply(np.array([t[f"P{l}"] for l in obs.model_ells]))
    k = np.asarray(obs.k_out)
    data = {"k": k}
    for j, ell in enumerate((0, 2, 4)):
        data[f"P{ell}"], data[f"s{ell}"] = values[j], 0.01 * values[0]
    fit = pt.fit_ept(data, k_max=[0.2], free=("f", "b1"), marginalise=("alpha0",), ells=(0, 2, 4),
                     window=window, k_edges=edges, k_ranges={4: (0.0, 0.1)}, precision="fast",
                     b1=1.8, f=0.6)
    assert fit["points"][0] == 2 * k.size + np.count_nonzero(k <= 0.1)
    for name, want in truth.items():
        assert abs(fit[name][0] - want) < 0.05 * fit[f"err_{name}"][0], name
    with pytest.raises(ValueError, match="s_edges"):
        pt.fit_ept(data, k_max=[0.2], xi=True, window=window)


cobaya = pytest.importorskip("cobaya", reason="cobaya is not installed (pip install cobaya camb)")
camb = pytest.importorskip("camb", reason="camb is not installed (pip install camb)")


def test_survey_likelihood_with_window_covariance_and_ap(tmp_path):
    """SurveyMultipoles + PTMultipoles(rsd: ept, ap_fiducial): data made independently (CAMB's
    spectrum and distances, the α's from scipy's quadrature of the fiducial, EptPlan, Observation)
    give chi2 ~ 0 at their own point, and a 3% move of b1 costs chi2 > 20."""
    from cobaya.model import get_model
    from scipy.integrate import quad

    z, om_fid = 0.5, 0.28
    h, ombh2, omch2, a_s, n_s = 0.6766, 0.02242, 0.11933, 2.105e-9, 0.9665
    pars = camb.CAMBparams()
    pars.set_cosmology(H0=100 * h, ombh2=ombh2, omch2=omch2, mnu=0.0, num_massive_neutrinos=0)
    pars.InitPower.set_params(As=a_s, ns=n_s)
    pars.set_matter_power(redshifts=[z], kmax=10.0)
    res = camb.get_results(pars)
    kh, _, pk = res.get_linear_matter_power_spectrum(hubble_units=True, k_hunit=True)
    f = float(res.get_fsigma8()[0] / res.get_sigma8()[0])
    e_fid = lambda x: np.sqrt(om_fid * (1 + x) ** 3 + 1 - om_fid)  # noqa: E731
    dm_fid = 2997.92458 * quad(lambda x: 1 / e_fid(x), 0, z, epsabs=0, epsrel=1e-12)[0]
    apar = e_fid(z) / (res.hubble_parameter(z) / (100 * h))
    aperp = res.comoving_radial_distance(z) * h / dm_fid
    s = np.geomspace(0.01, 3000.0, 300)
    window = tmp_path / "window.txt"
    np.savetxt(window, np.column_stack([s, np.exp(-(s / 500.0) ** 2), 0 * s, 0 * s]),
               header="s Q0 Q2 Q4")
    k = np.linspace(0.02, 0.18, 17)
    obs = pt.Observation([0, 2], k, window=window)
    nu = dict(b1=2.1, b2=0.4, alpha0=4.0, sn=500.0)
    plan = pt.EptPlan(obs.k_model, precision="fast", free_ap=True)
    terms = plan.terms(linear=(kh, pk[0]), z=z, z_input=z)
    with warnings.catch_warnings():  # "no cosmology": the spectrum is at z and f is given
        warnings.simplefilter("ignore", pt.PtSpectraWarning)
        t = terms.multipoles(ells=obs.model_ells, f=f, apar=apar, aperp=aperp, **nu)
    values, _ = obs.apply(np.array([t[f"P{l}"] for l in obs.model_ells]))
    sigma = 0.01 * values[0]
    data = tmp_path / "data.txt"
    np.savetxt(data, np.column_stack([k, values[0], sigma, values[1], sigma]))
    cov = np.diag(np.concatenate([sigma, sigma]) ** 2)
    cov += 0.3 * np.sqrt(np.outer(np.diag(cov), np.diag(cov))) * (1 - np.eye(cov.shape[0]))
    np.savetxt(tmp_path / "cov.txt", cov)
    info = {
        "theory": {
            "camb": {"extra_args": {"num_massive_neutrinos": 0}},
            "pt": {"class": "pt_spectra.cobaya.PTMultipoles", "zs": [z], "rsd": "ept",
                   "precision": "fast", "ap_fiducial": {"Omega_m": om_fid}},
        },
        "likelihood": {"survey": {"class": "pt_spectra.likelihoods.SurveyMultipoles",
                                  "data_file": str(data), "data_ells": [0, 2], "z": z,
                                  "covariance_file": str(tmp_path / "cov.txt"), "n_mocks": 1000,
                                  "window": str(window)}},
        "params": {"H0": 100 * h, "ombh2": ombh2, "omch2": omch2, "As": a_s, "ns": n_s, "mnu": 0.0,
                   "tau": 0.055, "b1_0": {"prior": {"min": 1, "max": 3}},
                   **{f"{n}_0": v for n, v in nu.items() if n != "b1"}},
    }
    model = get_model(info)
    model.add_requirements({"pt_ap": None})
    chi2_true = -2 * model.loglikes({"b1_0": nu["b1"]}, as_dict=True)[0]["survey"]
    got_apar, got_aperp = model.provider.get_pt_ap(z)
    assert got_apar == pytest.approx(apar, rel=2e-4)
    assert got_aperp == pytest.approx(aperp, rel=2e-4)
    assert chi2_true < 0.05
    chi2_off = -2 * model.loglikes({"b1_0": 1.03 * nu["b1"]}, as_dict=True)[0]["survey"]
    assert chi2_off > 20


def test_a_covariance_over_all_the_files_multipoles_gives_the_fitted_blocks(tmp_path):
    """fit_ept of P0, P2 from a file of P0, P2, P4: the covariance of all three (as surveys ship it)
    gives the same fit as its P0, P2 blocks."""
    k = np.linspace(0.02, 0.2, 10)
    t = pt.EptPlan(k, precision="fast")(b1=2.0, f=0.7, alpha0=5.0)
    sig = 0.01 * t["P0"]
    path = tmp_path / "data.txt"
    np.savetxt(path, np.column_stack([k, t["P0"], sig, t["P2"], sig, t["P4"], sig]))
    n = k.size
    full = np.diag(np.tile(sig, 3) ** 2)
    full += 0.2 * np.sqrt(np.outer(np.diag(full), np.diag(full))) * (1 - np.eye(3 * n))
    args = dict(k_max=[0.2], free=("f", "b1"), ells=(0, 2), precision="fast", b1=1.8, f=0.6)
    a = pt.fit_ept(str(path), covariance=full, **args)
    b = pt.fit_ept(str(path), covariance=full[: 2 * n, : 2 * n], **args)
    for name in ("f", "b1", "chi2", "err_f"):
        assert a[name][0] == pytest.approx(b[name][0], rel=1e-12), name


def test_without_a_window_the_theory_is_asked_only_for_the_fitted_k(tmp_path):
    """SurveyMultipoles without window or bins: the theory computes the model at the fitted k only
    (k_max and the k_ranges of each multipole), not at every k of the file; the χ² is unchanged (data
    made by EptPlan at every k from the same emulated spectrum: χ² ≈ 0, and > 20 for b1 3% off)."""
    from cobaya.model import get_model

    z = 0.5
    cosmo = {"ombh2": 0.0224, "omch2": 0.12, "H0": 67.5, "As": 2.1e-9, "ns": 0.965}
    s = pt.LinearEmulator().spectra(cosmo, z)
    f = float(np.interp(np.log(0.1), np.log(s["k"]), s["f_cb"]))
    k = np.linspace(0.01, 0.3, 30)
    plan = pt.EptPlan(k, precision="fast")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", pt.PtSpectraWarning)
        t = plan.terms(linear=(s["k"], s["P_cb"]), z=z, z_input=z).multipoles(
            ells=(0, 2), f=f, b1=2.0, alpha0=3.0)
    sigma = 0.01 * t["P0"]
    data = tmp_path / "data.txt"
    np.savetxt(data, np.column_stack([k, t["P0"], sigma, t["P2"], sigma]))
    info = {
        "theory": {"pt": {"class": "pt_spectra.cobaya.PTMultipoles", "zs": [z], "rsd": "ept",
                          "precision": "fast", "emulator": True}},
        "likelihood": {"survey": {"class": "pt_spectra.likelihoods.SurveyMultipoles",
                                  "data_file": str(data), "data_ells": [0, 2], "z": z,
                                  "k_max": 0.2, "k_ranges": {2: [0.05, 0.15]}}},
        "params": {**cosmo, "b1_0": {"prior": {"min": 1, "max": 3}}, "alpha0_0": 3.0},
    }
    model = get_model(info)
    model.add_requirements({"pt_k": None})
    chi2 = -2 * model.loglikes({"b1_0": 2.0}, as_dict=True)[0]["survey"]
    np.testing.assert_allclose(model.provider.get_pt_k(), k[k <= 0.2 + 1e-12])
    assert chi2 < 1e-8
    assert -2 * model.loglikes({"b1_0": 2.06}, as_dict=True)[0]["survey"] > 20
