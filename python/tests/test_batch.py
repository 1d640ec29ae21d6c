"""python -m pt_spectra.batch: serial and 2 MPI ranks give the numbers of pt.real, bit for bit."""

import importlib.util
import json
import os
import shutil
import subprocess
import sys

import numpy as np
import pytest

import pt_spectra as pt
from pt_spectra import batch

# 3 points so that the striping is uneven (rank 0: points 0, 2; rank 1: point 1); 1-loop SPT needs
# no angular tables, so a cold cache costs nothing.
GRID = """
[run]
output = "out"
model = "1l-spt"
precision = "fast"
linear = "eh"
z = [0.0, 1.0]
k = {min = 0.02, max = 0.3, n = 8}
threads = 1

[cosmology]
h = 0.7
omega_b = 0.0224
n_s = 0.96

[grid]
omega_cdm = [0.11, 0.13]
sigma8 = [0.8]

[[points]]
Omega_m = 0.3
A_s = 2.1e-9
w0_fld = -0.9
"""
pytestmark = pytest.mark.skipif(batch.tomllib is None, reason="needs Python >= 3.11 or tomli")
COLUMNS = ("P_lin", "P_dd", "P_dt", "P_tt", "err_P_dd", "err_P_dt", "err_P_tt")


@pytest.fixture
def grid(tmp_path):
    path = tmp_path / "grid.toml"
    path.write_text(GRID)
    return path


@pytest.fixture(scope="module")
def expected(tmp_path_factory):
    """The grid's options, and the spectra of each point and z from single pt.real calls."""
    path = tmp_path_factory.mktemp("expected") / "grid.toml"
    path.write_text(GRID)
    config = batch.load_config(path)
    out = {}
    for i, cosmology in enumerate(config["points"]):
        for j, z in enumerate(config["z"]):
            t = pt.real(model="1l-spt", k=config["k"], z=z, cosmology=cosmology, terms=True,
                        precision="fast", eh="wiggle")
            out[i, j] = {c: t[c] for c in COLUMNS} | {"f": t.meta["f"], "D": t.meta["D"]}
    return config, out


def _check(directory, expected, ranks):
    config, want = expected
    with open(directory / "index.json") as fh:
        index = json.load(fh)
    assert index["ranks"] == ranks and index["model"] == "1l-spt"
    assert index["precision"] == "fast" and index["z"] == [0.0, 1.0]
    assert index["pt_spectra_version"] == pt.__version__ and len(index["q_range"]) == 2
    assert [p["cosmology"] for p in index["points"]] == config["points"]
    files = sorted(f.name for f in directory.glob("rank*.npz"))
    assert files == [f"rank{r}.npz" for r in range(ranks)]
    with np.load(directory / "all.npz") as merged:
        assert np.array_equal(merged["index"], np.arange(3))
        assert np.array_equal(merged["k"], config["k"])
        assert np.array_equal(merged["param_omega_cdm"][:2], [0.11, 0.13])
        for (i, j), w in want.items():
            for c in COLUMNS:
                assert np.array_equal(merged[c][i, j], w[c]), (i, j, c)
            assert merged["f"][i, j] == w["f"] and merged["D"][i, j] == w["D"]
    for p in index["points"]:  # every point is in its rank file at its row
        with np.load(directory / p["file"]) as part:
            assert part["index"][p["row"]] == p["index"]
            assert np.array_equal(part["P_dd"][p["row"], 1], want[p["index"], 1]["P_dd"])


def _run(args, cwd, env=None, timeout=600):
    result = subprocess.run(args, cwd=cwd, env=env, capture_output=True, text=True, timeout=timeout)
    assert result.returncode == 0, result.stdout + result.stderr
    return result


def test_plain_run_equals_pt_real(grid, tmp_path, expected):
    _run([sys.executable, "-m", "pt_spectra.batch", str(grid)], cwd=tmp_path)
    _check(tmp_path / "out", expected, ranks=1)


def test_two_mpi_ranks_equal_pt_real(grid, tmp_path, expected):
    mpiexec = shutil.which("mpiexec")
    if mpiexec is None:
        pytest.skip("mpiexec is not installed (apt-get install openmpi-bin libopenmpi-dev)")
    if importlib.util.find_spec("mpi4py") is None:
        pytest.skip("mpi4py is not installed (pip install mpi4py)")
    version = subprocess.run([mpiexec, "--version"], capture_output=True, text=True).stdout
    flags = ["--oversubscribe"] if ("Open MPI" in version or "OpenRTE" in version) else []
    env = dict(os.environ, OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1")
    _run([mpiexec, *flags, "-n", "2", sys.executable, "-m", "pt_spectra.batch", str(grid),
          "--output", "mpi"], cwd=tmp_path, env=env)
    _check(tmp_path / "mpi", expected, ranks=2)


def test_in_process_run(grid, tmp_path, expected):
    config = dict(batch.load_config(grid), threads=None)  # the pool of this process is built
    index = batch.run(config, str(tmp_path / "direct"))
    assert index["ranks"] == 1
    _check(tmp_path / "direct", expected, ranks=1)


def test_a_failing_point_is_named(grid, tmp_path):
    config = dict(batch.load_config(grid), threads=None)
    config["points"][1] = dict(config["points"][1], omega_cdm=-0.5)
    with pytest.raises(RuntimeError, match=r"rank 0: ValueError: point 1 .*omega_cdm"):
        batch.run(config, str(tmp_path / "bad"))


@pytest.mark.parametrize("text, message", [
    ("[run]\nmodel = '1l-spt'\nk = [0.1]\nlinearr = 'eh'\n", "linearr"),
    ("[run]\nk = [0.1]\nlinear = 'class'\n", "linear"),
    ("[run]\nk = [0.1]\ntwo_loop = 'sometimes'\n", "two_loop"),
    ("[run]\nk = [0.1]\n[cosmology]\nh = 0.7\nomega_b = 0.02\nomega_cdm = 0.1\nn_s = 1\n",
     "sigma8"),
    ("[run]\nk = [0.1]\n[cosmology]\nh = 0.7\nomega_b = 0.02\nomega_cdm = 0.1\nn_s = 1\n"
     "sigma8 = 0.8\nOmega_cdm = 0.2\n", "Omega_cdm"),
    ("[run]\nk = [0.1]\n[grid]\nh = {min = 0.6}\n", "grid.h"),
    ("[run]\n[cosmology]\nh = 0.7\n", "run.k"),
    ("[runn]\n", "runn"),
])
def test_bad_grids_are_named(tmp_path, text, message):
    path = tmp_path / "bad.toml"
    path.write_text(text)
    with pytest.raises(ValueError, match=message):
        batch.load_config(path)


def test_camb_linear_spectra(tmp_path):
    pytest.importorskip("camb", reason="camb is not installed (pip install camb)")
    path = tmp_path / "camb.toml"
    path.write_text("""
[run]
model = "1l-spt"
precision = "fast"
linear = "camb"
camb_k_max = 5.0
z = [0.5]
k = {min = 0.02, max = 0.3, n = 8}
[cosmology]
h = 0.7
omega_b = 0.0224
Omega_m = 0.3
n_s = 0.96
sigma8 = 0.8
w0_fld = -0.9
""")
    config = batch.load_config(path)
    assert batch.run(config, str(tmp_path / "camb"))["linear"] == "camb"
    cosmology = config["points"][0]
    linear = batch.camb_linear(cosmology, [0.5], k_max=5.0)[0]
    t = pt.real(model="1l-spt", k=config["k"], linear=linear, z=0.5, z_input=0.5,
                cosmology=cosmology, terms=True, precision="fast")
    with np.load(tmp_path / "camb" / "all.npz") as got:
        assert np.array_equal(got["P_dd"][0, 0], t["P_dd"])
        # CAMB with sigma8 = 0.8 against Eisenstein & Hu with the same sigma8: a few per cent
        eh = pt.eisenstein_hu(config["k"], 0.5, cosmology)
        np.testing.assert_allclose(got["P_lin"][0, 0], eh, rtol=0.1)
