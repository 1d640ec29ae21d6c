"""Resources (issue 45, item 7): RealPlan.batch planned against the memory limit before it allocates
(chunks that fit give the same numbers; a batch that cannot fit is a MemoryError with the estimate and
the limit, also under an address-space limit, where the interpreter used to abort); the grid runner's
files written whole or not at all."""

import os
import re
import subprocess
import sys
import textwrap

import numpy as np
import pytest

import pt_spectra as pt
from pt_spectra import batch

K = np.geomspace(0.01, 0.3, 12)


def spectra(n):
    """n linear spectra: Eisenstein & Hu's scaled by 0.5 … 1.5, on a table of 300 k."""
    k_lin = np.geomspace(1e-4, 10.0, 300)
    p = pt.eisenstein_hu(k_lin)
    return k_lin, np.stack([p * (0.5 + i / n) for i in range(n)])


def test_a_batch_within_the_limit_runs_in_chunks_with_the_same_numbers(monkeypatch):
    k_lin, P = spectra(3000)
    plan = pt.RealPlan(K, model="1l-spt", precision="fast")
    free = plan.batch(k_lin, P, terms=True)
    # The estimate of the whole batch in one chunk, from the refusal under a tiny limit; 5% (~1.5 MB)
    # more leaves room for a few hundred of the 3000 spectra (7 kB each) in flight at a time.
    monkeypatch.setenv("PT_SPECTRA_MAX_MEMORY", "1k")
    with pytest.raises(MemoryError, match="needs about") as refused:
        plan.batch(k_lin, P, terms=True)
    needed = float(re.search(r"needs about ([0-9.]+) MB", str(refused.value)).group(1))
    monkeypatch.setenv("PT_SPECTRA_MAX_MEMORY", f"{needed * 1.05 + 0.5}M")
    chunked = plan.batch(k_lin, P, terms=True)
    assert free.keys() == chunked.keys()
    for name in free:
        assert np.array_equal(free[name], chunked[name]), name


def test_a_batch_above_the_limit_is_a_memory_error_with_both_figures(monkeypatch):
    k_lin, P = spectra(2)
    plan = pt.RealPlan(K, model="1l-spt", precision="fast")
    monkeypatch.setenv("PT_SPECTRA_MAX_MEMORY", "20.1M")
    with pytest.raises(MemoryError, match=r"a batch of 2 spectra on 12 k .* needs about .* of "
                                          r"memory, above 20 MB"):
        plan.batch(k_lin, P)
    # 50 million spectra of results are refused before anything is allocated (P is a broadcast view).
    monkeypatch.delenv("PT_SPECTRA_MAX_MEMORY")
    huge = np.broadcast_to(P[0], (50_000_000, len(k_lin)))
    with pytest.raises(MemoryError, match="a batch of 50000000 spectra"):
        plan.batch(k_lin, huge)


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="RLIMIT_AS and /proc: Linux")
def test_under_an_address_space_limit_a_batch_raises_memory_error_not_an_abort():
    script = textwrap.dedent("""
        import resource, numpy as np, pt_spectra as pt
        k_lin = np.geomspace(1e-4, 10.0, 300)
        p = pt.eisenstein_hu(k_lin)
        plan = pt.RealPlan(np.geomspace(0.01, 0.3, 200), model="1l-spt", precision="fast")
        P = np.broadcast_to(p, (200_000, len(k_lin)))  # results: 7 columns, 2.2 GB
        size = int(open("/proc/self/status").read().split("VmSize:")[1].split()[0]) * 1024
        resource.setrlimit(resource.RLIMIT_AS, (size + 400_000_000, resource.RLIM_INFINITY))
        try:
            plan.batch(k_lin, P)
        except MemoryError as e:
            print("MemoryError:", e)
    """)
    run = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True,
                         timeout=600, env=dict(os.environ, PT_SPECTRA_MAX_MEMORY="100G"))
    assert run.returncode == 0, (run.returncode, run.stderr[-2000:])
    assert "MemoryError: a batch of 200000 spectra" in run.stdout, run.stdout + run.stderr
    assert "ulimit -v" in run.stdout


def test_a_failing_write_leaves_the_old_file_intact(tmp_path):
    path = tmp_path / "all.npz"
    batch._write_atomic(path, lambda fh: np.savez(fh, a=np.arange(3)))
    old = path.read_bytes()

    def half_then_full_disk(fh):
        fh.write(old[: len(old) // 2])
        raise OSError(28, "No space left on device")

    with pytest.raises(OSError, match="No space"):
        batch._write_atomic(path, half_then_full_disk)
    assert path.read_bytes() == old
    assert [p.name for p in tmp_path.iterdir()] == ["all.npz"]


def test_the_grid_runner_checks_its_arrays_against_the_limit(monkeypatch):
    monkeypatch.setenv("PT_SPECTRA_MAX_MEMORY", "1G")
    config = {"points": [{}] * 1000}
    batch._check_memory(config, (1000, 2, 100), 7)  # 16 MB: fine
    with pytest.raises(MemoryError, match=r"the arrays of 100000 points .* above 1.0 GB"):
        batch._check_memory({"points": [{}] * 100_000}, (100_000, 4, 200), 7)
