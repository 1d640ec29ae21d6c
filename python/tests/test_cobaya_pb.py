"""The cobaya P + B likelihood PowerBispectrum with PTMultipoles(bispectrum: true), on the emulator.

The mock data are made by direct library calls (pt.LinearEmulator, pt.EptPlan, pt.BispectrumPlan) at
the fiducial point, with α∥, α⊥ computed here from pt.distances and a fiducial flat ΛCDM integrated
with numpy; the likelihood must give χ² = 0 there and move when any shared or B-only parameter moves.
"""

import copy
import warnings

import numpy as np
import pytest

pytest.importorskip("cobaya", reason="cobaya is not installed (pip install cobaya)")

import pt_spectra as pt  # noqa: E402
from cobaya.model import get_model  # noqa: E402

Z = 0.5
OMEGA_M_FID = 0.29
COSMO = {"ombh2": 0.02237, "omch2": 0.12, "H0": 67.36, "ns": 0.9649, "As": 2.1e-9}
NUIS = {"b1": 2.0, "b2": 0.4, "bs": -0.3, "alpha0": 5.0, "sn": 400.0,
        "c1": 3.0, "b_shot": 0.8, "a_shot": 0.3}
N_BAR = 3e-4
WIDTH = 0.01
K = np.arange(0.0125, 0.2, 0.01)
TRIANGLES = np.array([[0.025, 0.025, 0.035], [0.035, 0.045, 0.065], [0.055, 0.055, 0.055],
                      [0.045, 0.075, 0.105], [0.085, 0.095, 0.105], [0.025, 0.105, 0.115]])


def _alphas():
    """α∥ = E_fid/E, α⊥ = D_M/D_M,fid from the library's distances of COSMO and a flat fiducial."""
    hubble, dm = pt.distances(Z, COSMO)
    zz = np.linspace(0.0, Z, 20001)
    e_fid = np.sqrt(OMEGA_M_FID * (1 + zz) ** 3 + 1 - OMEGA_M_FID)
    dm_fid = 2997.92458 * np.trapezoid(1.0 / e_fid, zz)
    return e_fid[-1] / (hubble / 100.0), dm / dm_fid


@pytest.fixture(scope="module")
def mock(tmp_path_factory):
    """Files p.txt, b.txt, cov.txt of the model at the fiducial point, and the cobaya info."""
    emulator = pt.LinearEmulator()
    s = emulator.spectra(COSMO, Z)
    f = float(np.interp(np.log(0.1), np.log(s["k"]), s["f_cb"]))
    apar, aperp = _alphas()
    linear = (s["k"], s["P_cb"])
    with warnings.catch_warnings():
        # the spectrum is given at z with f: the default cosmology's growth is not used
        warnings.filterwarnings("ignore", message="no cosmology", category=pt.PtSpectraWarning)
        terms = pt.EptPlan(K, free_ap=True).terms(linear=linear, z=Z, z_input=Z)
        p = terms.multipoles(ells=[0, 2, 4], f=f, apar=apar, aperp=aperp,
                             **{n: NUIS[n] for n in ("b1", "b2", "bs", "alpha0", "sn")})
        bterms = pt.BispectrumPlan(TRIANGLES, bin_width=WIDTH).terms(
            linear=linear, z=Z, z_input=Z, f=f, q_par=apar, q_perp=aperp)
    b, _ = bterms.multipoles(b1=NUIS["b1"], b2=NUIS["b2"], bs=NUIS["bs"], c1=NUIS["c1"],
                             n_bar=N_BAR, b_shot=NUIS["b_shot"], a_shot=NUIS["a_shot"])
    folder = tmp_path_factory.mktemp("pb")
    np.savetxt(folder / "p.txt", np.column_stack([K, p["P0"], p["P2"], p["P4"]]),
               header="k P0 P2 P4")
    np.savetxt(folder / "b.txt", np.column_stack([TRIANGLES, b]), header="k1 k2 k3 B0 B2 B4")
    data = np.concatenate([p["P0"], p["P2"], p["P4"], b[:, 0], b[:, 1], b[:, 2]])
    sigma = 0.02 * np.abs(data) + 1e-3 * np.max(np.abs(data[:3 * K.size]))
    sigma[3 * K.size:] = 0.05 * np.abs(data[3 * K.size:]) + 1e6
    corr = np.eye(data.size) + 0.3 * (np.eye(data.size, k=1) + np.eye(data.size, k=-1))
    np.savetxt(folder / "cov.txt", corr * np.outer(sigma, sigma))
    params = {name: value for name, value in COSMO.items()}
    params.update({f"{n}_0": v for n, v in NUIS.items()})
    info = {
        "theory": {"pt": {
            "class": "pt_spectra.cobaya.PTMultipoles", "zs": [Z], "rsd": "ept", "emulator": True, "bispectrum": True, "n_bar": N_BAR,
            "ap_fiducial": {"Omega_m": OMEGA_M_FID}, "stop_at_error": True}},
        "likelihood": {"pb": {
            "class": "pt_spectra.likelihoods.PowerBispectrum",
            "p_file": str(folder / "p.txt"), "b_file": str(folder / "b.txt"),
            "covariance_file": str(folder / "cov.txt"), "z": Z, "bin_width": WIDTH,
            "p_ells": [0, 2], "b_ells": [0, 2], "k_max": 0.15, "stop_at_error": True}},
        "params": params,
    }
    return info, folder, (apar, aperp)


def _loglike(info, **change):
    i = copy.deepcopy(info)
    i["params"].update(change)
    m = get_model(i)
    m.add_requirements({"pt_ap": None, "pt_bk_ell": None, "pt_bk_ell_err": None})
    return m.loglike({}, return_derived=False), m


def test_chi2_is_zero_at_the_mock_and_every_parameter_moves_it(mock):
    info, _, (apar, aperp) = mock
    logl, m = _loglike(info)
    assert abs(apar - 1.0) > 0.01  # the fiducial differs: AP is in the test
    # not exactly 0: the theory's AP grid is made for the fitted k only (interpolation ~1e-7)
    assert -2 * float(np.sum(logl)) < 1e-6
    assert m.provider.get_pt_ap(z=Z) == pytest.approx((apar, aperp), rel=1e-6)
    # shared (b1, b2, bs), P-only (alpha0) and B-only (c1, b_shot, a_shot) parameters all reach χ²
    for name, step in (("b1_0", 0.02), ("b2_0", 0.2), ("bs_0", 0.2), ("alpha0_0", 2.0),
                       ("c1_0", 3.0), ("b_shot_0", 0.3), ("a_shot_0", 3.0)):
        moved, _ = _loglike(info, **{name: NUIS[name[:-2]] + step})
        assert -2 * float(np.sum(moved)) > 0.05, name


def test_the_bispectrum_product_is_the_plan_at_the_points_triangles(mock):
    info, folder, (apar, aperp) = mock
    _, m = _loglike(info)
    got = np.asarray(m.provider.get_pt_bk_ell(z=Z))
    assert got.shape == (2, TRIANGLES.shape[0])
    want = np.loadtxt(folder / "b.txt")[:, [3, 4]].T
    np.testing.assert_allclose(got, want, rtol=1e-9)
    err = np.asarray(m.provider.get_pt_bk_ell_err(z=Z))
    assert np.all(err >= 0) and np.all(err < 1e-2 * np.abs(want[0]))


def test_bad_inputs_are_named(mock, tmp_path):
    info, folder, _ = mock
    bad = copy.deepcopy(info)
    bad["likelihood"]["pb"]["covariance_file"] = str(tmp_path / "small.txt")
    np.savetxt(tmp_path / "small.txt", np.eye(5))
    with pytest.raises(Exception, match=r"is \(5, 5\), expected"):
        get_model(bad)
    rows = (folder / "b.txt").read_text().splitlines()
    rows[3] = rows[3] + " 7.0"
    (tmp_path / "b.txt").write_text("\n".join(rows) + "\n")
    bad = copy.deepcopy(info)
    bad["likelihood"]["pb"]["b_file"] = str(tmp_path / "b.txt")
    with pytest.raises(Exception, match="line 4: 7 columns, expected 6"):
        get_model(bad)
    bad = copy.deepcopy(info)
    bad["theory"]["pt"]["bispectrum"] = False
    for name in ("c1_0", "b_shot_0", "a_shot_0"):
        bad["params"].pop(name)
    with pytest.raises(Exception, match="bispectrum: true"):
        get_model(bad)
