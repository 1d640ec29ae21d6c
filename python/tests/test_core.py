"""The pt_spectra module against the command line, the FAST-PT reference tables and its own contracts.

Run from the repository: ``pytest python/tests`` after ``pip install ./python`` and
``cargo build --release -p pt-spectra`` (the CLI comparisons run ``target/release/pt-spectra``, or
``$PT_SPECTRA_BIN``).
"""

import os
import subprocess
import threading
import time
import warnings
from fractions import Fraction
from pathlib import Path

import numpy as np
import pytest

import pt_spectra as pt

ROOT = Path(__file__).resolve().parents[2]
DATA = ROOT / "tests" / "data"
SPECTRA = ROOT / "pt-spectra" / "tests" / "data"  # the linear spectra the library's tests share
CLI = Path(os.environ.get("PT_SPECTRA_BIN", ROOT / "target" / "release" / "pt-spectra"))


def cli(*args):
    """The command line's standard output."""
    if not CLI.exists():
        pytest.fail(f"the pt-spectra binary is not at {CLI}: cargo build --release -p pt-spectra")
    out = subprocess.run([str(CLI), *args], capture_output=True, text=True, check=True)
    return out.stdout


def planck(z):
    d = np.loadtxt(SPECTRA / f"linear_pk_planck2018_z{z:.1f}.dat")
    return d[:, 0], d[:, 1]


def test_python_tables_equal_the_command_line_text():
    # The same library job writes both: header, names and every value, to the last printed digit.
    args = ["--nk", "12", "--k-min", "0.01", "--k-max", "0.4", "--precision", "fast", "--z", "0.5"]
    t = pt.real(model="1l-rpt-n1", terms=True, precision="fast", z=0.5, k_min=0.01, k_max=0.4, nk=12)
    assert t.to_text() == cli("real", "--model", "1l-rpt-n1", "--terms", *args)
    m = pt.rsd(rsd="tns", real="1l-spt", fog="lorentzian", sigma0=3.5, bias=2.0, shot_noise=2e3,
               terms=True, precision="fast", z=0.5, k_min=0.01, k_max=0.4, nk=12)
    text = cli("rsd", "--rsd", "tns", "--real", "1l-spt", "--fog", "lorentzian", "--sigma0", "3.5",
               "--bias", "2", "--shot-noise", "2e3", "--terms", *args)
    assert m.to_text() == text
    # Columns and values as parsed from the text.
    rows = np.loadtxt([line for line in text.splitlines() if not line.startswith("#")])
    names = [line for line in text.splitlines() if line.startswith("# k ")][0].split()[1:]
    assert m.columns == names
    for j, name in enumerate(names):
        np.testing.assert_allclose(m[name], rows[:, j], rtol=1e-9)
    path = str(SPECTRA / "linear_pk_planck2018_z0.0.dat")
    t = pt.real(model="1l-spt", linear=path, cosmology="planck2018", z=1.0, precision="fast",
                k_min=0.01, k_max=0.3, nk=5)
    assert t.to_text() == cli("real", "--linear", path, "--cosmology", "planck2018", "--z", "1",
                              "--precision", "fast", "--k-min", "0.01", "--k-max", "0.3", "--nk", "5")


def test_one_loop_terms_match_fastpt():
    # tests/data/README.md: columns 8 and 9 are FAST-PT 4.1.1's P22 and 2 P13 of delta-delta, good to
    # ~1e-5 (brute force); ours agree to <= 9e-6 (P22) and 1.5e-6 (2 P13) in the Rust tests.
    ref = np.loadtxt(DATA / "fastpt_1loop_gm2012_z0.0.dat")
    ref = ref[(ref[:, 0] >= 0.01) & (ref[:, 0] <= 0.5)]
    t = pt.real(model="1l-spt", k=ref[:, 0], terms=True)
    np.testing.assert_allclose(t["P_lin"], ref[:, 1], rtol=1e-6)
    np.testing.assert_allclose(t["P22_dd"], ref[:, 7], rtol=2e-5)
    np.testing.assert_allclose(2 * t["P13_dd"], ref[:, 8], rtol=2e-5)
    # The reported errors are honest bounds at this level.
    assert np.all(t["err_P22_dd"] < 2e-4 * np.abs(t["P22_dd"]))
    assert t.units["P22_dd"] == "(Mpc/h)^3" and t.units["k"] == "h/Mpc"
    assert t.meta["cosmology"] == "gm2012" and t.meta["q_range"] == (1e-5, 1e3)


def test_a_plan_is_reused_across_spectra():
    k = np.geomspace(0.01, 0.3, 15)
    plan = pt.RealPlan(k, model="1l-spt", precision="fast")
    np.testing.assert_array_equal(plan.k, k)
    kl, pl = planck(0.0)
    for z in (0.0, 1.0):
        with warnings.catch_warnings():
            warnings.simplefilter("error")
            a = plan(linear=(kl, pl), z=z, cosmology="planck2018")
        b = pt.real(model="1l-spt", k=k, linear=(kl, pl), z=z, cosmology="planck2018",
                    precision="fast")
        for name in a.columns:
            np.testing.assert_array_equal(a[name], b[name])
    # P22 scales as D^4 between the two redshifts (the same linear shape).
    a0 = plan(linear=(kl, pl), z=0.0, cosmology="planck2018")
    a1 = plan(linear=(kl, pl), z=1.0, cosmology="planck2018", terms=True)
    d = a1.meta["D"]
    np.testing.assert_allclose(a1["P_lin"], d**2 * a0["P_lin"], rtol=1e-12)
    assert abs(a1.meta["f"] / 0.873875 - 1) < 2e-3


def test_bad_input_raises_value_error_naming_the_problem():
    k = [0.05, 0.1]
    cases = [
        (lambda: pt.real(model="3l-spt", k=k), "3l-spt"),
        (lambda: pt.real(k=[0.1, -0.2]), "k"),
        (lambda: pt.real(k=k, linear=([0.1, 0.2], [1.0])), "k and P"),
        (lambda: pt.real(k=k, linear="/nonexistent/pk.dat"), "/nonexistent/pk.dat"),
        (lambda: pt.real(k=k, cosmology="planck2013"), "planck2013"),
        (lambda: pt.real(k=k, cosmology={"h": 0.7, "H0": 68, "omega_b": 0.022, "omega_cdm": 0.12,
                                         "n_s": 0.96, "A_s": 2e-9}), "H0"),
        (lambda: pt.real(k=k, precision="best"), "best"),
        (lambda: pt.real(k=k, q_range=(10.0, 1.0)), "q_max"),
        (lambda: pt.real(k=k, z=-2.0), "z = -2"),
        (lambda: pt.rsd(k=k, fog="cauchy"), "cauchy"),
        (lambda: pt.rsd(k=k, ells=(0, 3)), "ell"),
        (lambda: pt.rsd(k=k, sigma0="maybe"), "maybe"),
        (lambda: pt.rsd(k=k, bias=([0.01, 0.02], [2.0, 2.0])), "b(k)"),
        (lambda: pt.kernel("F", [[1e200, 0, 0], [-1e200, 1e-200, 0], [0, 1e200, 0]]), "overflow"),
        (lambda: pt.kernel("H", [[1, 0, 0]]), "H"),
        (lambda: pt.kernel("F", [[1, 0]]), "three components"),
    ]
    for call, needle in cases:
        with pytest.raises(ValueError, match=None) as e:
            call()
        assert needle in str(e.value), (needle, str(e.value))


def test_guards_name_the_problem(monkeypatch):
    """Never a silently wrong number: implausible parameters, a memory limit, tiny kernel vectors."""
    k = np.geomspace(0.01, 0.3, 5)
    h_percent = dict(h=67.66, omega_b=0.022, omega_cdm=0.12, n_s=0.96, A_s=2.1e-9)
    with pytest.raises(ValueError, match="looks like H0"):
        pt.real(k=k, cosmology=h_percent)
    with pytest.raises(ValueError, match=r"f = -1: must be in \[0, 2\]"):
        pt.rsd(k=k, f=-1.0)
    assert pt.kernel("F", [[1e-170, 0, 0], [0, 1e-170, 0]]) == pytest.approx(5 / 7, rel=1e-15)
    with pytest.warns(RuntimeWarning, match="lengths differ"):
        pt.kernel("F", [[1e-6, 0, 0], [0, 1, 0]])
    monkeypatch.setenv("PT_SPECTRA_MAX_MEMORY", "1M")
    with pytest.raises(MemoryError, match=r"needs about .* of memory, above 1.0 MB"):
        pt.real(k=k)


def test_bias_terms_and_galaxy_spectra_mirror_the_command_line():
    k = np.geomspace(0.02, 0.2, 4)
    t = pt.real(model="1l-spt", k=k, precision="fast", bias_terms=True, bias=2.0, b2=0.5)
    for name in ("Pd1d2", "err_Pd1d2", "Ps2s2", "Pt1d2", "sig3nl", "P_gg", "err_P_gg", "P_gm"):
        assert name in t.columns, name
    expected = 4.0 * t["P_dd"] + 2.0 * 0.5 * t["Pd1d2"] + 0.25 * 0.25 * t["Pd2d2"]
    np.testing.assert_allclose(t["P_gg"], expected, rtol=1e-12)
    with pytest.raises(ValueError, match="need bias"):
        pt.real(k=k, b2=1.0)
    # TNS with nonlinear bias: b2 = 0 is linear bias; b2 moves P4 not at all without FoG.
    common = dict(rsd="tns", real="1l-spt", k=k, precision="fast", bias=2.0, f=0.7)
    linear = pt.rsd(**common)
    np.testing.assert_array_equal(pt.rsd(**common, b2=0.0)["P0"], linear["P0"])
    moved = pt.rsd(**common, b2=0.8)
    np.testing.assert_allclose(moved["P4"], linear["P4"], rtol=1e-12)
    assert np.all(np.abs(moved["P0"] - linear["P0"]) > 1e-6 * linear["P0"])
    with pytest.raises(ValueError, match="Kaiser is linear"):
        pt.rsd(**dict(common, rsd="kaiser"), b2=1.0)


def test_kernels_exact_and_float():
    assert pt.kernel("F", [[1, 0, 0], [0, 1, 0]]) == pytest.approx(5 / 7, rel=1e-15)
    assert pt.kernel("G", [[1, 2, 3], [0, 1, 0], [0, -1, 0]], exact=True) == "-20452/30723"
    # F_2(q1, q2) = 5/7 + (1/2) mu (q1/q2 + q2/q1) + (2/7) mu^2, exactly.
    q1, q2 = [Fraction(1, 2), 0, 0], [Fraction(1, 3), Fraction(1, 4), 0]
    n1, n2 = Fraction(1, 4), Fraction(1, 9) + Fraction(1, 16)
    dot = Fraction(1, 6)
    f2 = Fraction(5, 7) + dot / 2 * (1 / n1 + 1 / n2) + Fraction(2, 7) * dot**2 / (n1 * n2)
    assert pt.kernel("F", [q1, q2], exact=True) == f"{f2.numerator}/{f2.denominator}"


def test_warnings_for_defaults_that_may_not_fit():
    kl, pl = planck(0.0)
    with pytest.warns(pt.PtSpectraWarning, match="gm2012"):
        t = pt.real(k=[0.1], linear=(kl, pl), z=1.0, precision="fast")
    assert any("gm2012" in line for line in t.header)
    # a cosmology without a spectrum is emulated (no warning; the header says so), CAMB's to 0.2%
    t = pt.real(k=[0.1], model="linear", cosmology="planck2018")
    assert any("emulator" in line for line in t.header)
    assert abs(t["P_lin"][0] / np.interp(0.1, kl, pl) - 1) < 2e-3
    with pytest.raises(ValueError, match="m_nu = 0.8"):
        pt.real(k=[0.1], model="linear", cosmology={"h": 0.67, "omega_b": 0.022, "omega_cdm": 0.12,
                                                   "n_s": 0.96, "A_s": 2.1e-9, "m_nu": 0.8})


def test_the_gil_is_released_during_a_computation():
    # A long computation in a thread; the main thread keeps running Python meanwhile. With the GIL
    # held, no Python line could run between the start and the end of the computation.
    k = np.geomspace(0.001, 1.0, 4000)
    stamps, done = [], {}

    def work():
        done["start"] = time.perf_counter()
        pt.real(model="1l-spt", k=k, precision="default")
        done["end"] = time.perf_counter()

    thread = threading.Thread(target=work)
    thread.start()
    while thread.is_alive():
        stamps.append(time.perf_counter())
    thread.join()
    inside = [s for s in stamps if done["start"] + 0.05 < s < done["end"] - 0.05]
    assert done["end"] - done["start"] > 0.2, "the computation is too short to tell"
    assert len(inside) > 1000, len(inside)


def test_fit_from_arrays_recovers_f():
    # A linear Kaiser mock (exact, 1% errors, no noise): the fit of f must return its true value.
    k = np.geomspace(0.02, 0.2, 15)
    mock = pt.rsd(rsd="kaiser", real="linear", k=k, f=0.6, bias=1.5, ells=(0, 2))
    data = {"k": k, "P0": mock["P0"], "s0": 0.01 * mock["P0"], "P2": mock["P2"],
            "s2": 0.01 * mock["P2"]}
    r = pt.fit(data, k_max=[0.1, 0.2], free=("f",), ells=(0, 2), rsd="kaiser", real="linear",
               fog="none", bias=1.5, f=0.5)
    assert r.columns[:5] == ["k_max", "points", "f", "f_lo", "f_hi"]
    np.testing.assert_allclose(r["f"], 0.6, rtol=1e-5)
    assert np.all(r["chi2"] < 1e-6)


def test_rsd_terms_give_the_multipoles_of_a_full_call_at_any_nuisance_point():
    k = np.geomspace(0.02, 0.25, 10)
    kl, pl = planck(0.0)
    plan = pt.RsdPlan(k, real="1l-spt", rsd="tns", precision="fast")
    terms = plan.terms(linear=(kl, pl), z=0.5, cosmology="planck2018")
    for b, s0, d in [(1.5, 2.0, None), (2.3, 4.0, 0.7)]:
        full = plan(linear=(kl, pl), z=0.5, cosmology="planck2018", bias=b, fog="lorentzian",
                    sigma0=s0, growth_factor=d)
        fast = terms.multipoles(bias=b, fog="lorentzian", sigma0=s0, growth_factor=d)
        for name in full.columns:
            np.testing.assert_array_equal(full[name], fast[name])
    # A growth factor given by the caller enters sigma = sigma0 D f (stated in the header).
    a = terms.multipoles(fog="gaussian", sigma0=4.0, growth_factor=0.5)
    b = terms.multipoles(fog="gaussian", sigma0=2.0, growth_factor=1.0)
    np.testing.assert_allclose(a["P0"], b["P0"], rtol=1e-13)
    assert any("growth factor D(z) = 0.5" in line for line in a.header)
    with pytest.raises(ValueError, match="growth_factor"):
        terms.multipoles(growth_factor=-1.0)


def test_signal_to_noise_halo_tables_and_theory_sigma0(tmp_path):
    # SN = b^2 P_lin/P_eps (real space), SN_s = P0/P_eps; a noise or bias path is read by the column
    # names of a `pt-spectra halo` table; fit takes sigma0 = "lin" as rsd does.
    k = np.geomspace(0.02, 0.2, 6)
    b, f = 2.6, 0.48
    m = pt.rsd(rsd="kaiser", real="linear", k=k, f=f, bias=b, shot_noise=3e4, no_wiggle=True)
    lin = pt.real(model="linear", k=k)
    np.testing.assert_allclose(m["SN"], b * b * lin["P_lin"] / 3e4, rtol=1e-12)
    np.testing.assert_allclose(m["SN_s"], m["P0"] / 3e4, rtol=1e-12)
    assert {"P0_nw", "P2_nw", "P4_nw"} <= set(m.columns)
    halo = tmp_path / "halo.dat"
    halo.write_text("# k b P_eps P_eps_n\n0.01 2.0 4e4 0.7\n0.5 2.0 4e4 0.7\n")
    h = pt.rsd(rsd="kaiser", real="linear", k=k, f=f, bias=str(halo), noise_table=str(halo))
    np.testing.assert_allclose(h["P_eps"], 4e4, rtol=1e-12)
    np.testing.assert_allclose(h["SN"], 4.0 * lin["P_lin"] / 4e4, rtol=1e-12)
    mock = pt.rsd(rsd="kaiser", real="linear", k=k, f=f, fog="lorentzian", sigma0="lin")
    data = {"k": k, "P0": mock["P0"], "s0": 0.01 * mock["P0"]}
    r = pt.fit(data, k_max=[0.2], free=("f",), rsd="kaiser", real="linear", sigma0="lin", f=0.4)
    np.testing.assert_allclose(r["f"], f, rtol=1e-5)
    assert r["sigma0_1l"][0] < r["sigma0_lin"][0]


def test_growth_matches_camb_for_planck2018():
    # CAMB 2.0.5 headers of pt-spectra/tests/data/linear_pk_planck2018_z*.dat: sigma8(z) and f(z).
    d, f = pt.growth(1.0, "planck2018")
    assert abs(f / 0.873875 - 1) < 2e-3
    assert abs(d / (0.500091 / 0.821734) - 1) < 2e-3
    assert pt.growth(0.0, "planck2018")[0] == 1.0
    with pytest.raises(ValueError, match="redshift"):
        pt.growth(-1.0)


def test_halo_recovers_bias_and_noise_and_feeds_rsd(tmp_path):
    # Synthetic spectra with a known b(k) and P_eps: P_mh = b P_mm, P_hh = b^2 P_mm + P_eps.
    k = np.geomspace(0.02, 0.2, 8)
    pmm = pt.real(model="linear", k=k)["P_lin"]
    b = 2.0 + 3.0 * k**2
    p_eps = np.full_like(k, 2.5e3)
    sigma = 0.01 * pmm
    t = pt.halo((k, pmm, sigma), (k, b * pmm), (k, b * b * pmm + p_eps), number_density=2e-4)
    assert t.columns == ["k", "b", "P_eps", "P_eps_n", "err_b", "err_P_eps", "err_P_eps_n"]
    np.testing.assert_allclose(t["b"], b, rtol=1e-13)
    np.testing.assert_allclose(t["P_eps"], p_eps, rtol=1e-9)
    np.testing.assert_allclose(t["P_eps_n"], p_eps * 2e-4, rtol=1e-9)
    # err_b = b s_mm/P_mm with only P_mm's error given (first-order propagation).
    np.testing.assert_allclose(t["err_b"], b * 0.01, rtol=1e-12)
    path = tmp_path / "halo.dat"
    path.write_text(t.to_text())
    m = pt.rsd(rsd="kaiser", real="linear", k=k, f=0.5, bias=str(path), noise_table=str(path))
    np.testing.assert_allclose(m["P_eps"], p_eps, rtol=1e-6)
    with pytest.raises(ValueError, match="P_mh"):
        pt.halo((k, pmm), (k[:-1], pmm[:-1]), (k, pmm))
    with pytest.raises(ValueError, match="P_hh"):
        pt.halo((k, pmm), (k, pmm), (k,))


def test_fit_tables_give_the_model_and_a_contour_that_is_the_chi2_of_direct_calls():
    # A linear Kaiser mock, f and A_b free: the model table reproduces the data at the best fit, and the
    # chi2 column of the contour equals the chi2 of the multipoles of pt.rsd at the grid point.
    k = np.geomspace(0.02, 0.2, 15)
    mock = pt.rsd(rsd="kaiser", real="linear", k=k, f=0.6, bias=1.5, ells=(0, 2))
    data = {"k": k, "P0": mock["P0"], "s0": 0.02 * mock["P0"], "P2": mock["P2"],
            "s2": 0.02 * mock["P2"]}
    kw = dict(free=("f", "ab"), ells=(0, 2), rsd="kaiser", real="linear", fog="none", bias=1.5,
              f=0.5)
    t = pt.fit_tables(data, k_max=0.15, model=True, contour=("f", "ab"), contour_points=5, **kw)
    assert set(t) == {"fit", "model", "contour"}
    np.testing.assert_allclose(t["fit"]["f"], 0.6, rtol=1e-5)
    m = t["model"]
    assert "P0_data" in m.columns and "P0_nw" in m.columns
    model_p0 = [c for c in m.columns if c.startswith("P0_kmax")]
    assert len(model_p0) == 1
    np.testing.assert_allclose(m[model_p0[0]], mock["P0"], rtol=1e-5)
    c = t["contour"]
    assert c.columns[:7] == ["k_max", "i", "j", "f", "ab", "chi2", "delta_chi2"]
    assert len(c) == 25 and min(c["delta_chi2"]) < 1e-8
    used = k <= 0.15
    for row in (0, 7, 24):
        f, ab = c["f"][row], c["ab"][row]
        p = pt.rsd(rsd="kaiser", real="linear", k=k, f=f, bias=1.5, amplitude=ab, ells=(0, 2))
        chi2 = sum(np.sum(((p[f"P{l}"] - data[f"P{l}"]) / data[f"s{l}"])[used] ** 2) for l in (0, 2))
        np.testing.assert_allclose(c["chi2"][row], chi2, rtol=1e-7)
    with pytest.raises(ValueError, match="contour"):
        pt.fit_tables(data, k_max=0.15, contour=("f", "sigma0"), **kw)
    with pytest.raises(ValueError, match="contour points"):
        pt.fit_tables(data, k_max=0.15, contour=("f", "ab"), contour_points=2, **kw)
    assert pt.fit_tables(data, k_max=0.15, **kw)["model"] is None


def test_two_loop_basis_matches_direct_and_bad_methods_raise():
    # A grid of its own (no other test caches tensors for it); `fast` keeps the build to seconds.
    k = [0.0402, 0.0707, 0.1102]
    planck0 = planck(0.0)
    basis = pt.real(model="2l-spt", k=k, linear=planck0, cosmology="planck2018", precision="fast",
                    two_loop="basis", terms=True)
    direct = pt.real(model="2l-spt", k=k, linear=planck0, cosmology="planck2018", precision="fast",
                     two_loop="direct", terms=True)
    assert any("basis tensors on 36 functions" in line for line in basis.header)
    assert any(line == "2-loop terms: direct integration" for line in direct.header)
    # meta["methods"] says the same, part by part (1-loop: basis with two_loop="basis")
    assert basis.meta["methods"] == {"2-loop terms": "basis", "1-loop terms": "basis"}
    assert direct.meta["methods"] == {"2-loop terms": "direct", "1-loop terms": "direct"}
    ir = pt.real(model="1l-spt-ir", k=k, linear=planck0, cosmology="planck2018", precision="fast")
    methods = ir.meta["methods"]
    assert set(methods) == {"1-loop terms", "no-wiggle 1-loop terms"}
    nw_direct = "no-wiggle spectrum: 1-loop terms: direct integration" in ir.header
    assert (methods["no-wiggle 1-loop terms"] == "direct") == nw_direct
    for x in ("dd", "dt", "tt"):
        b, d, e = basis[f"P2loop_{x}"], direct[f"P2loop_{x}"], basis[f"err_P2loop_{x}"]
        assert np.all(np.abs(b - d) <= 1e-3 * np.abs(d)) and np.all(np.abs(b - d) <= e)
    with pytest.raises(ValueError, match="two-loop|2-loop method"):
        pt.RealPlan(k, "2l-spt", two_loop="sometimes")


def test_theory_sigma0_of_rsd_terms_is_computed_once_and_equals_a_direct_call():
    """RsdTerms keeps the theory σ0 of its spectrum: repeated calls give what pt.rsd computes from
    scratch (the first call 0.16 s, the next ones 0.1 ms here)."""
    k = np.linspace(0.02, 0.2, 8)
    terms = pt.RsdPlan(k, real="1l-spt", rsd="tns", precision="fast").terms()
    direct = pt.rsd(k=k, real="1l-spt", rsd="tns", precision="fast", f=0.5, bias=2.0, fog="lorentzian",
                    sigma0="1l-spt")
    for _ in range(2):
        t = terms.multipoles(f=0.5, bias=2.0, fog="lorentzian", sigma0="1l-spt")
        np.testing.assert_array_equal(t["P0"], direct["P0"])
        np.testing.assert_array_equal(t["P2"], direct["P2"])
    # σ = σ0 D f with σ0 = σ_v/D: the theory value does not depend on the growth factor given.
    half = terms.multipoles(f=0.5, bias=2.0, fog="lorentzian", sigma0="1l-spt", growth_factor=0.5)
    np.testing.assert_allclose(half["P0"], direct["P0"], rtol=1e-12)


def test_exact_kernel_strings_parse_as_the_command_line_and_huge_inputs_are_refused():
    """Decimal strings are exact (0.1 = 1/10), as `pt-spectra kernel --exact` parses them; numbers too
    large for the exact kernel to finish are refused with the command line's guard."""
    a = pt.kernel("F", [["0.5", "0", "0"], ["1e-1", "1/3", "0"]], exact=True)
    b = pt.kernel("F", [[Fraction(1, 2), 0, 0], [Fraction(1, 10), Fraction(1, 3), 0]], exact=True)
    assert a == b
    with pytest.raises(ValueError, match="at most 300 for n = 7"):
        pt.kernel("F", [["1/" + "3" * 400, "0", "0"]] * 7, exact=True)
    with pytest.raises(ValueError, match="zero denominator"):
        pt.kernel("F", [["1/0", "0", "0"]], exact=True)


def test_emulated_growth_is_the_ode_growth_without_neutrinos_and_scale_dependent_with():
    """LinearEmulator.growth_cb: massless neutrinos give the scale-independent D(z)/D(0) of pt.growth
    (to the emulator's 2e-3); 0.3 eV slow the small scales (D larger at high k since z = 1)."""
    emulator = pt.LinearEmulator()
    base = {"ombh2": 0.0224, "omch2": 0.12, "H0": 67.5, "As": 2.1e-9, "ns": 0.965}
    g = emulator.growth_cb(base, 1.0)
    d, _ = pt.growth(1.0, base)
    assert np.max(np.abs(g["D_cb"] / d - 1)) < 2e-3
    heavy = emulator.growth_cb(dict(base, mnu=0.3, neutrinos="three degenerate"), 1.0)
    small = np.interp(1.0, heavy["k"], heavy["D_cb"]) / np.interp(1e-3, heavy["k"], heavy["D_cb"])
    assert small > 1.005
    with pytest.raises(ValueError, match="m_nu"):
        emulator.growth_cb(dict(base, mnu=0.9), 1.0)
    hubble, dm = pt.distances(1.0, base)
    assert hubble > 100 and 2000 < dm < 3000  # h km/s/Mpc, Mpc/h


def test_redshift_kernel_z2_closed_form_and_errors():
    """kernel("Z"): Z_1 = 1 + f mu^2 exactly; Z_2 of two vectors against the SCF99 closed form; f is
    required, and n <= 5."""
    from fractions import Fraction as Fr
    assert pt.kernel("Z", [[0, 3, 4]], exact=True, f="1/2", los=[0, 0, 1]) == "33/25"  # 1 + 16/50
    q1, q2 = np.array([0.3, -0.2, 0.5]), np.array([-0.1, 0.4, 0.2])
    f, n = 0.7, np.array([0.0, 0.0, 1.0])
    k = q1 + q2
    mu = lambda v: v @ n / np.sqrt(v @ v)  # noqa: E731
    f2, g2 = pt.kernel("F", [q1, q2]), pt.kernel("G", [q1, q2])
    closed = (f2 + f * mu(k) ** 2 * g2 + f * mu(k) * np.sqrt(k @ k) / 2 * (
        mu(q1) / np.sqrt(q1 @ q1) * (1 + f * mu(q2) ** 2)
        + mu(q2) / np.sqrt(q2 @ q2) * (1 + f * mu(q1) ** 2)))
    assert pt.kernel("Z", [q1, q2], f=f) == pytest.approx(closed, rel=1e-13)
    assert Fr(pt.kernel("Z", [[1, 0, 0], [0, 1, 0]], exact=True, f=0)) == Fr(5, 7)
    with pytest.raises(ValueError, match="growth rate f"):
        pt.kernel("Z", [[1, 0, 0]])
    with pytest.raises(ValueError, match="at most 5"):
        pt.kernel("Z", [[1, 0, 0]] * 6, f=0.5)
    with pytest.raises(ValueError, match="for Z, not F"):
        pt.kernel("F", [[1, 0, 0]], f=0.5)


def test_a_cosmology_dict_with_an_unknown_key_raises_naming_it():
    # a misspelt m_ncdm was ignored (2.6% off); now every dict reader raises
    c = {"h": 0.67, "omega_b": 0.022, "omega_cdm": 0.12, "n_s": 0.96, "A_s": 2.1e-9}
    with pytest.raises(ValueError, match="m_ncmd"):
        pt.LinearEmulator().spectra(dict(c, m_ncmd=0.06), 0.5)
    # the neutrino setting is stated, and one massive species (CAMB's mnu alone) is refused
    s = pt.LinearEmulator().spectra(dict(c, m_nu=0.06), 0.5)
    assert s["neutrinos"] == "three degenerate"
    with pytest.raises(ValueError, match="one massive species"):
        pt.LinearEmulator().spectra(dict(c, mnu=0.06), 0.5)
