"""The cobaya theory PTMultipoles and likelihood MultipoleGaussian on the example's mock data.

Runs CAMB a few times (k_max 10/Mpc, ~2 s each on 2 cores); the PT part is 1-loop SPT + TNS with
the fast precision on 20 k.
"""

import copy
import importlib.util
import pathlib

import numpy as np
import pytest

cobaya = pytest.importorskip("cobaya", reason="cobaya is not installed (pip install cobaya camb)")
pytest.importorskip("camb", reason="camb is not installed (pip install camb)")

import pt_spectra as pt  # noqa: E402
from cobaya.model import get_model  # noqa: E402
from cobaya.yaml import yaml_load_file  # noqa: E402
from pt_spectra.likelihoods import read_multipoles  # noqa: E402

EXAMPLES = pathlib.Path(__file__).resolve().parents[1] / "examples"
Z = 0.5


def _make_mock_module():
    spec = importlib.util.spec_from_file_location("make_mock", EXAMPLES / "make_mock.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


@pytest.fixture(scope="module")
def setup(tmp_path_factory):
    """The example's input with the mock written to a temporary file, and its fiducial point."""
    info = yaml_load_file(str(EXAMPLES / "cobaya_mock.yaml"))
    info["theory"]["pt"].update(real="1l-spt", precision="fast", stop_at_error=True)
    path = str(tmp_path_factory.mktemp("mock") / "mock.npz")
    info["likelihood"]["mock"].update(data_file=path, stop_at_error=True)
    make_mock = _make_mock_module()
    np.savez(path, **make_mock.make_mock(info)[path])
    return info, make_mock.fiducial_point(info)


@pytest.fixture(scope="module")
def model(setup):
    info, _ = setup
    m = get_model(copy.deepcopy({k: v for k, v in info.items() if k != "sampler"}))
    m.add_requirements({"CAMBdata": None, "pt_pk_ell": None, "pt_growth": None, "pt_k": None})
    return m


def test_evaluate_sampler_at_the_fiducial_point_gives_chi2_zero(setup):
    info, _ = setup
    _, sampler = cobaya.run(copy.deepcopy(info))
    sample = sampler.products()["sample"]
    assert abs(float(sample["chi2__mock"][0])) < 1e-12


def test_chi2_zero_at_fiducial_and_large_when_b_moves_by_5_percent(setup, model):
    _, point = setup
    assert model.loglikes(point, as_dict=True)[0]["mock"] == pytest.approx(0.0, abs=1e-12)
    moved = dict(point, b_0=point["b_0"] * 1.05)
    chi2 = -2 * model.loglikes(moved, as_dict=True)[0]["mock"]
    assert chi2 > 100, chi2


def test_multipoles_equal_a_direct_rsd_plan_call_with_camb_spectrum_and_f(setup, model):
    _, point = setup
    point = dict(point, b_0=1.7, sigma0_0=5.0, P_shot_0=300.0)
    model.logposterior(point)
    got = np.asarray(model.provider.get_pt_pk_ell(z=Z))
    # CAMB's own h units and growth, independent of the theory's conversions
    results = model.provider.get_CAMBdata()
    kh, zs, pk = results.get_linear_matter_power_spectrum(hubble_units=True, k_hunit=True)
    z_tr = np.array(results.transfer_redshifts)
    iz, i0 = np.argmin(abs(z_tr - Z)), np.argmin(abs(z_tr))
    fs8, s8 = results.get_fsigma8(), results.get_sigma8()
    f, d = fs8[iz] / s8[iz], s8[iz] / s8[i0]
    plan = pt.RsdPlan(model.provider.get_pt_k(), real="1l-spt", rsd="tns", precision="fast")
    # z = z_input = 0: no rescaling and D_library = 1, so the FoG scale is (sigma0 D) f
    with pytest.warns(pt.PtSpectraWarning, match="no cosmology"):
        t = plan(linear=(kh, pk[np.argmin(abs(zs - Z))]), z=0.0, z_input=0.0, f=f, bias=1.7,
                 fog="lorentzian", sigma0=5.0 * d, ells=(0, 2, 4))
    want = np.array([t["P0"] + 300.0, t["P2"], t["P4"]])
    np.testing.assert_allclose(got, want, rtol=1e-10, atol=0)
    got_f, got_d = model.provider.get_pt_growth(z=Z)
    assert got_f == pytest.approx(f, rel=1e-12) and got_d == pytest.approx(d, rel=1e-12)


def test_a_counterterm_parameter_reaches_the_multipoles(setup, model):
    # cs2_0 declared (fixed) in `params`: the theory's multipoles are those of its RsdTerms at that
    # c_s^2, and differ from the run without it by the counterterm alone.
    info, point = setup
    info = copy.deepcopy({k: v for k, v in info.items() if k != "sampler"})
    info["params"]["cs2_0"] = 1.5
    with_ct = get_model(info)
    with_ct.add_requirements({"pt_pk_ell": None, "pt_growth": None})
    with_ct.logposterior(point)
    got = np.asarray(with_ct.provider.get_pt_pk_ell(z=Z))
    model.logposterior(point)
    base = np.asarray(model.provider.get_pt_pk_ell(z=Z))
    theory = with_ct.theory["pt"]
    terms = theory._terms[0][1]
    f, d = with_ct.provider.get_pt_growth(z=Z)
    nu = theory._nuisance(point, 0)
    with pytest.warns(pt.PtSpectraWarning, match="no cosmology"):  # as the theory, which filters it
        t = terms.multipoles(f=f, bias=nu["b"], amplitude=nu["A_b"], fog=theory.fog,
                             sigma0=nu["sigma0"], ells=theory.ells, growth_factor=d, cs2=1.5)
    want = np.array([t[f"P{ell}"] for ell in theory.ells])
    want[theory.ells.index(0)] += nu["P_shot"]
    np.testing.assert_allclose(got, want, rtol=1e-12, atol=0)
    assert np.all(np.abs(got - base) > 0)


def test_no_other_library_warning_is_raised(setup, model, recwarn):
    _, point = setup
    model.logposterior(dict(point, logA=3.0))
    assert not [w for w in recwarn if issubclass(w.category, pt.PtSpectraWarning)]


def test_a_missing_nuisance_parameter_is_named(setup):
    info, _ = setup
    info = copy.deepcopy(info)
    del info["params"]["sigma0_0"]
    with pytest.raises(Exception, match="sigma0_0"):
        get_model({k: v for k, v in info.items() if k != "sampler"})


def test_bad_options_are_named(setup):
    info, _ = setup
    for option, value, message in [("fog", "cauchy", "fog"), ("ells", [0, 3], "ells"),
                                   ("zs", None, "zs")]:
        bad = copy.deepcopy(info)
        bad["theory"]["pt"][option] = value
        with pytest.raises(Exception, match=message):
            get_model({k: v for k, v in bad.items() if k != "sampler"})


def test_text_data_files_are_read_like_npz(setup, tmp_path):
    info, _ = setup
    k, values, sigma = read_multipoles(info["likelihood"]["mock"]["data_file"])
    columns = [k] + [a for ell in (0, 2, 4) for a in (values[ell], sigma[ell])]
    np.savetxt(tmp_path / "mock.txt", np.column_stack(columns), fmt="%.17g")
    k2, values2, sigma2 = read_multipoles(tmp_path / "mock.txt")
    assert np.array_equal(k, k2)
    assert all(np.array_equal(values[ell], values2[ell]) for ell in values)
    with pytest.raises(ValueError, match="more than the 5 columns"):
        read_multipoles(tmp_path / "mock.txt", data_ells=(0, 2))
    # The library's reader: comments, a row of names and commas are read as by `fit --data`, and a
    # bad row is named by its line.
    text = (tmp_path / "mock.txt").read_text().splitlines()
    (tmp_path / "named.txt").write_text("# k P0 s0 P2 s2 P4 s4\nk,P0,s0,P2,s2,P4,s4\n"
                                        + "\n".join(l.replace(" ", ",") for l in text) + "\n")
    k3, values3, _ = read_multipoles(tmp_path / "named.txt")
    assert np.array_equal(k, k3) and np.array_equal(values[2], values3[2])
    (tmp_path / "bad.txt").write_text("\n".join(text[:3] + ["0.5 x 1 1 1 1 1"]) + "\n")
    with pytest.raises(ValueError, match="bad.txt:4"):
        read_multipoles(tmp_path / "bad.txt")


def test_k_from_the_likelihood_and_a_second_redshift(setup):
    info, point = setup
    info = copy.deepcopy({k: v for k, v in info.items() if k != "sampler"})
    for option in ("k_min", "k_max", "nk"):
        del info["theory"]["pt"][option]
    info["theory"]["pt"]["zs"] = [0.5, 1.0]
    info["params"].update(b_1=2.5, sigma0_1=3.0)
    model = get_model(info)
    # CAMB's P(z = 0.5) moves by ~1e-8 when z = 1 is computed too: chi2 ~ 1e-12, not exactly 0
    assert model.loglikes(point, as_dict=True)[0]["mock"] == pytest.approx(0.0, abs=1e-6)
    assert set(model.provider.get_pt_pk_ell()) == {0.5, 1.0}


def test_the_galaxy_model_takes_velocileptors_names(setup):
    """rsd: ept: nuisance b1_0, b2_0, …, sn_0; the multipoles equal a direct EptPlan call."""
    info, point = setup
    info = copy.deepcopy({k: v for k, v in info.items() if k != "sampler"})
    theory = info["theory"]["pt"]
    for key in ("real", "fog", "two_loop"):
        theory.pop(key, None)
    theory.update(rsd="ept", ir=False)
    params = info["params"]
    for name in [p for p in params if p.startswith(("b_", "sigma0_", "A_b_", "P_shot_", "cs2_"))]:
        params.pop(name)
    params.update(b1_0=1.9, b2_0=0.3, alpha0_0=5.0, sn_0=700.0)
    m = get_model(info)
    m.add_requirements({"CAMBdata": None, "pt_pk_ell": None, "pt_growth": None, "pt_k": None})
    point = {p: v for p, v in point.items() if p in m.parameterization.sampled_params()}
    m.logposterior(point)
    got = np.asarray(m.provider.get_pt_pk_ell(z=Z))
    results = m.provider.get_CAMBdata()
    kh, zs, pk = results.get_linear_matter_power_spectrum(hubble_units=True, k_hunit=True)
    f, _ = m.provider.get_pt_growth(z=Z)
    plan = pt.EptPlan(m.provider.get_pt_k(), ir=False, precision="fast")
    with pytest.warns(pt.PtSpectraWarning, match="no cosmology"):
        t = plan(linear=(kh, pk[np.argmin(abs(zs - Z))]), z=0.0, z_input=0.0, f=f, b1=1.9, b2=0.3,
                 alpha0=5.0, sn=700.0)
    want = np.array([t["P0"], t["P2"], t["P4"]])
    np.testing.assert_allclose(got, want, rtol=1e-6, atol=0)
    # bias_convention: classpt: the same bias (bs = 0.2, b3 = 0) named as CLASS-PT names it
    theory["bias_convention"] = "classpt"
    params.update(b2_0=0.3 + 4 / 3 * 0.2, bG2_0=0.2, bGamma3_0=-15 * 0.2 / 6)
    m = get_model(info)
    m.add_requirements({"pt_pk_ell": None})
    m.logposterior(point)
    classpt = np.asarray(m.provider.get_pt_pk_ell(z=Z))
    theory["bias_convention"] = "velocileptors"
    for n in ("bG2_0", "bGamma3_0"):
        params.pop(n)
    params.update(b2_0=0.3, bs_0=0.2)
    m = get_model(info)
    m.add_requirements({"pt_pk_ell": None})
    m.logposterior(point)
    np.testing.assert_allclose(classpt, np.asarray(m.provider.get_pt_pk_ell(z=Z)), rtol=1e-12)


def test_without_a_boltzmann_code_the_emulator_gives_the_linear_spectrum(setup, model):
    """emulator: true: no CAMB; the multipoles are those of the emulated P_cb and f_cb(k = 0.1), and
    within 2% of the CAMB run's (which uses P_m of one massive neutrino of 0.06 eV)."""
    info, point = setup
    info = copy.deepcopy({k: v for k, v in info.items() if k != "sampler"})
    info["theory"].pop("camb")
    info["theory"]["pt"]["emulator"] = True
    info["theory"]["pt"]["neutrinos"] = "three degenerate"  # mnu alone is CAMB's one massive species
    info["params"].pop("tau")
    m = get_model(info)
    m.add_requirements({"pt_pk_ell": None, "pt_growth": None, "pt_k": None})
    sampled = {p: v for p, v in point.items() if p in m.parameterization.sampled_params()}
    m.logposterior(sampled)
    got = np.asarray(m.provider.get_pt_pk_ell(z=Z))
    f, d = m.provider.get_pt_growth(z=Z)
    cosmology = {"ombh2": point["ombh2"], "omch2": 0.12, "H0": 67.36, "ns": 0.9649, "mnu": 0.06,
                 "neutrinos": "three degenerate", "As": 1e-10 * np.exp(point["logA"])}
    emulator = pt.LinearEmulator()
    s, s0 = emulator.spectra(cosmology, Z), emulator.spectra(cosmology, 0.0)
    assert f == pytest.approx(np.interp(np.log(0.1), np.log(s["k"]), s["f_cb"]), rel=1e-12)
    assert d == pytest.approx(s["sigma8"] / s0["sigma8"], rel=1e-12)
    plan = pt.RsdPlan(m.provider.get_pt_k(), real="1l-spt", rsd="tns", precision="fast")
    nu = {p: point[p] for p in ("b_0", "sigma0_0")}
    # z = z_input = 0: no rescaling and D_library = 1, so the FoG scale is (sigma0 D) f
    with pytest.warns(pt.PtSpectraWarning, match="no cosmology"):
        t = plan(linear=(s["k"], s["P_cb"]), z=0.0, z_input=0.0, f=f, bias=nu["b_0"],
                 fog="lorentzian", sigma0=nu["sigma0_0"] * d, ells=(0, 2, 4))
    want = np.array([t["P0"], t["P2"], t["P4"]])
    want[0] += point.get("P_shot_0", 0.0)
    np.testing.assert_allclose(got, want, rtol=1e-6, atol=0)
    model.logposterior({p: v for p, v in point.items()
                        if p in model.parameterization.sampled_params()})
    camb = np.asarray(model.provider.get_pt_pk_ell(z=Z))
    # P_cb/P_m ~ 1/f_cb^2 = 1.009 at small scales, and f_cb(k = 0.1) against CAMB's f of P_m
    assert np.max(np.abs(got[0] / camb[0] - 1)) < 0.02
    # outside the prior: zero likelihood, not an exception
    bad = dict(sampled, ombh2=0.035) if "ombh2" in sampled else None
    if bad is not None:
        assert m.logposterior(bad).logpost == -np.inf


def test_the_emulator_stops_on_a_neutrino_setting_it_does_not_emulate(setup):
    """emulator: true with mnu and no `neutrinos` option: mnu is CAMB's one massive species, which the
    emulator does not emulate; the run stops naming the setting (a zero likelihood at every point
    would hide it)."""
    info, point = setup
    info = copy.deepcopy({k: v for k, v in info.items() if k != "sampler"})
    info["theory"].pop("camb")
    info["theory"]["pt"]["emulator"] = True
    info["params"].pop("tau")
    m = get_model(info)
    sampled = {p: v for p, v in point.items() if p in m.parameterization.sampled_params()}
    with pytest.raises(ValueError, match="one massive species.*three degenerate"):
        m.logposterior(sampled)


def test_emulator_with_ap_fiducial_gives_camb_distances_and_derived_fsigma8(setup):
    """emulator: true with ap_fiducial (rsd: ept): the α's of the library's background equal those of
    the CAMB run within 1e-4 (3.0e-5 measured: CAMB's run has one massive neutrino and two massless ones,
    whose radiation the library's three degenerate massive ones do not have); the derived fsigma8_0 is f σ8(z) of the model and close to CAMB's."""
    info, point = setup
    info = copy.deepcopy({k: v for k, v in info.items() if k != "sampler"})
    theory = info["theory"]["pt"]
    for key in ("real", "fog", "two_loop"):
        theory.pop(key, None)
    theory.update(rsd="ept", ir=False, ap_fiducial={"Omega_m": 0.29})
    params = info["params"]
    for name in [p for p in params if p.startswith(("b_", "sigma0_", "A_b_", "P_shot_", "cs2_"))]:
        params.pop(name)
    params.update(b1_0=1.9, fsigma8_0=None, sigma8_0=None)
    runs = {}
    for emulated in (False, True):
        i = copy.deepcopy(info)
        if emulated:
            i["theory"].pop("camb")
            i["params"].pop("tau")
            i["theory"]["pt"]["emulator"] = True
            i["theory"]["pt"]["neutrinos"] = "three degenerate"  # mnu alone: CAMB's one massive species
        m = get_model(i)
        m.add_requirements({"pt_ap": None, "pt_growth": None})
        sampled = {p: v for p, v in point.items() if p in m.parameterization.sampled_params()}
        derived = m.logposterior(sampled).derived
        names = list(m.parameterization.derived_params())
        runs[emulated] = (m.provider.get_pt_ap(z=Z), m.provider.get_pt_growth(z=Z),
                          dict(zip(names, derived)))
    (ap_camb, _, d_camb), (ap_emu, (f, _), d_emu) = runs[False], runs[True]
    assert abs(ap_emu[0] - 1.0) > 0.01  # the fiducial differs: the α's are tested, not 1 = 1
    np.testing.assert_allclose(ap_emu, ap_camb, rtol=1e-4, atol=0)
    assert d_emu["fsigma8_0"] == pytest.approx(f * d_emu["sigma8_0"], rel=1e-12)
    # CAMB: one massive neutrino of 0.06 eV and P_m; emulator: three degenerate and f_cb(k = 0.1)
    assert d_emu["fsigma8_0"] == pytest.approx(d_camb["fsigma8_0"], rel=5e-3)
