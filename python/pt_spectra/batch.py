"""Real-space spectra of many cosmologies over MPI ranks: ``python -m pt_spectra.batch grid.toml``.

The toml (see ``python/examples/grid.toml``)::

    [run]
    output = "grid-out"        # directory, relative to the working directory (or --output)
    model = "2l-rpt-n2"        # as pt.real; default 2l-rpt-n2
    precision = "default"      # fast, default, reference
    q_range = [1e-4, 10.0]     # optional (QMIN, QMAX) [h/Mpc]
    linear = "eh"              # "eh" (Eisenstein & Hu with BAO), "eh-no-wiggle", or "camb"
    z = [0.0, 1.0]
    k = {min = 0.02, max = 0.3, n = 20}   # log-spaced [h/Mpc], or a list
    terms = false              # true: keep every loop term, not only P_lin, P_dd/dt/tt and errors
    threads = 1                # rayon threads per rank (default: RAYON_NUM_THREADS, else all cores)
    # also: two_loop_tolerance, cache_dir (angular tables), camb_k_max (h/Mpc, default 20),
    # two_loop ("auto"; "basis": 2-loop terms of every point from tensors built once for the k grid,
    # for CAMB batches of 2-loop models; Eisenstein & Hu spectra are computed directly anyway)
    [cosmology]                # the keys every point shares
    h = 0.7
    [grid]                     # varied keys: Cartesian product; a list or {min, max, n} (linear)
    omega_cdm = [0.11, 0.13]
    [[points]]                 # and/or explicit points (merged over [cosmology])
    omega_cdm = 0.12

Cosmology keys (those of ``pt.real(cosmology=dict)``): h, omega_b, omega_cdm, n_s, A_s or sigma8,
Omega_k, k_pivot [1/Mpc], w0_fld, wa_fld; ``Omega_m`` is accepted and turned into
omega_cdm = Omega_m h² − omega_b (massless neutrinos, as in the library). With ``linear = "camb"``
the spectrum of each point and z comes from CAMB (massless neutrinos, PPF dark energy for w0, wa;
with sigma8, A_s is scaled to match it); f and D are always those of the library's background.

Parallelism: point i goes to rank i % size (rank striping). Each rank builds ONE ``pt.RealPlan``
(the expensive set-up depends on the k grid, not on the cosmology) and writes ``rank<r>.npz``:
``index`` [n], ``z`` [nz], ``k`` [nk], every column (``P_dd``, ``err_P_dd``, …) as [n, nz, nk]
(k in h/Mpc, P in (Mpc/h)^3), ``f``, ``D`` [n, nz] and ``param_<key>`` [n]. Then rank 0 writes
``index.json`` (point → rank file and row, parameters, z, model, precision, q range, version) and
``all.npz`` (the same arrays for all points, in point order). Without mpi4py, under a single
process, or with ``--no-mpi`` the same files come from one serial run. Results do not depend on the
number of ranks or threads (the library is deterministic).

Ranks × threads: each rank runs its computations on a rayon pool of ``threads`` (or
RAYON_NUM_THREADS, or :func:`pt_spectra.set_num_threads`) threads. Keep ranks × threads ≤ cores,
e.g. on 64 cores ``mpiexec -n 16 python -m pt_spectra.batch grid.toml`` with ``threads = 4``; by
default every rank would use all cores (a warning says so).
"""

from __future__ import annotations

import argparse
import itertools
import json
import os
import sys
import time
import warnings

try:
    import tomllib
except ModuleNotFoundError:  # Python < 3.11
    try:
        import tomli as tomllib
    except ModuleNotFoundError:
        tomllib = None

import numpy as np

import pt_spectra as pt

__all__ = ["load_config", "run", "camb_linear", "main"]

COSMOLOGY_KEYS = ("h", "omega_b", "omega_cdm", "Omega_k", "n_s", "A_s", "sigma8", "k_pivot",
                  "w0_fld", "wa_fld")
RUN_KEYS = {"output": None, "model": "2l-rpt-n2", "precision": "default", "q_range": None,
            "two_loop_tolerance": None, "linear": "eh", "z": [0.0], "k": None, "terms": False,
            "threads": None, "cache_dir": None, "camb_k_max": 20.0, "two_loop": "auto"}
LINEAR = ("eh", "eh-no-wiggle", "camb")
TWO_LOOP = ("auto", "basis", "direct")
BASIC = ("P_lin", "P_dd", "P_dt", "P_tt", "err_P_dd", "err_P_dt", "err_P_tt")


def _values(key, spec):
    """The values of a [grid] entry: a list, or {min, max, n} (linearly spaced)."""
    if isinstance(spec, list) and spec:
        return [float(v) for v in spec]
    if isinstance(spec, dict) and set(spec) == {"min", "max", "n"} and int(spec["n"]) >= 1:
        return np.linspace(float(spec["min"]), float(spec["max"]), int(spec["n"])).tolist()
    raise ValueError(f"grid.{key}: expected a non-empty list or {{min, max, n}}, got {spec!r}")


def _cosmology(point, where):
    """The point with its keys checked, Omega_m turned into omega_cdm, all values floats."""
    point = {k: float(v) for k, v in point.items()}
    unknown = sorted(set(point) - set(COSMOLOGY_KEYS) - {"Omega_m"})
    if unknown:
        raise ValueError(f"{where}: unknown cosmology keys {unknown}; accepted: "
                         f"{', '.join(COSMOLOGY_KEYS)}, Omega_m")
    if "Omega_m" in point:
        if "omega_cdm" in point or "h" not in point or "omega_b" not in point:
            raise ValueError(f"{where}: Omega_m needs h and omega_b, and excludes omega_cdm")
        point["omega_cdm"] = point.pop("Omega_m") * point["h"] ** 2 - point["omega_b"]
    missing = [k for k in ("h", "omega_b", "omega_cdm", "n_s") if k not in point]
    if missing or ("A_s" in point) == ("sigma8" in point):
        raise ValueError(f"{where}: needs h, omega_b, omega_cdm (or Omega_m), n_s and one of A_s "
                         f"or sigma8 (missing {missing or ['A_s or sigma8']}): {point}")
    return point


def load_config(path):
    """The validated run options of a grid toml: a dict with ``points`` (a list of cosmology dicts),
    ``z``, ``k`` [h/Mpc] and the [run] options."""
    if tomllib is None:
        raise ImportError("pt_spectra.batch reads toml: use Python >= 3.11 or pip install tomli")
    with open(path, "rb") as fh:
        raw = tomllib.load(fh)
    unknown = sorted(set(raw) - {"run", "cosmology", "grid", "points"})
    if unknown:
        raise ValueError(f"{path}: unknown tables {unknown}; expected run, cosmology, grid, points")
    run_opts = raw.get("run", {})
    bad = sorted(set(run_opts) - set(RUN_KEYS))
    if bad:
        raise ValueError(f"{path}: unknown [run] options {bad}; known: {', '.join(RUN_KEYS)}")
    config = {**RUN_KEYS, **run_opts}
    if config["linear"] not in LINEAR:
        raise ValueError(f"run.linear: {config['linear']!r}; expected one of {', '.join(LINEAR)}")
    if config["two_loop"] not in TWO_LOOP:
        raise ValueError(f"run.two_loop: {config['two_loop']!r}; "
                         f"expected one of {', '.join(TWO_LOOP)}")
    config["z"] = [float(z) for z in np.atleast_1d(config["z"])]
    k = config["k"]
    if isinstance(k, dict) and set(k) == {"min", "max", "n"}:
        config["k"] = pt.log_grid(float(k["min"]), float(k["max"]), int(k["n"]))
    elif isinstance(k, list) and k:
        config["k"] = np.asarray(k, dtype=float)
    else:
        raise ValueError(f"run.k: expected a list of k [h/Mpc] or {{min, max, n}}, got {k!r}")
    if config["q_range"] is not None:
        config["q_range"] = tuple(float(q) for q in config["q_range"])
    base = raw.get("cosmology", {})
    grid = raw.get("grid", {})
    points = []
    if grid or not raw.get("points"):
        keys = list(grid)
        for values in itertools.product(*(_values(key, grid[key]) for key in keys)):
            points.append({**base, **dict(zip(keys, values))})
    points += [{**base, **p} for p in raw.get("points", [])]
    config["points"] = [_cosmology(p, f"point {i}") for i, p in enumerate(points)]
    return config


def camb_linear(cosmology, zs, k_max=20.0):
    """[(k [h/Mpc], P [(Mpc/h)^3])] of CAMB at each z, for a cosmology of :func:`load_config`."""
    import camb

    c = cosmology
    pars = camb.CAMBparams(WantCls=False, Want_CMB=False, WantTransfer=True)
    pars.set_cosmology(H0=100 * c["h"], ombh2=c["omega_b"], omch2=c["omega_cdm"],
                       omk=c.get("Omega_k", 0.0), mnu=0.0, num_massive_neutrinos=0)
    pars.InitPower.set_params(ns=c["n_s"], As=c.get("A_s", 2e-9),
                              pivot_scalar=c.get("k_pivot", 0.05))
    if c.get("w0_fld", -1.0) != -1.0 or c.get("wa_fld", 0.0) != 0.0:
        pars.set_dark_energy(w=c.get("w0_fld", -1.0), wa=c.get("wa_fld", 0.0),
                             dark_energy_model="ppf")
    pars.set_matter_power(redshifts=sorted(set(zs) | {0.0}, reverse=True), kmax=k_max * c["h"])
    results = camb.get_results(pars)
    kh, z_out, pk = results.get_linear_matter_power_spectrum(hubble_units=True, k_hunit=True)
    scale = (c["sigma8"] / results.get_sigma8_0()) ** 2 if "sigma8" in c else 1.0
    return [(kh, pk[int(np.argmin(np.abs(z_out - z)))] * scale) for z in zs]


def _threads(n, size):
    if n is not None:
        try:  # before anything asks rayon for its pool (num_threads() would build it)
            pt.set_num_threads(int(n))
        except RuntimeError as e:
            if pt.num_threads() != int(n):
                warnings.warn(f"run.threads = {n} not applied: {e}", pt.PtSpectraWarning,
                              stacklevel=3)
    elif size * pt.num_threads() > (os.cpu_count() or 1):
        warnings.warn(f"{size} ranks x {pt.num_threads()} threads > {os.cpu_count()} cores: set "
                      "run.threads or RAYON_NUM_THREADS so that ranks x threads <= cores",
                      pt.PtSpectraWarning, stacklevel=3)
    return pt.num_threads()


def _point_tables(plan, config, cosmology):
    """The tables of one cosmology at each z."""
    if config["linear"] == "camb":
        spectra = camb_linear(cosmology, config["z"], config["camb_k_max"])
        return [plan(p, z=z, z_input=z, cosmology=cosmology, terms=True)
                for p, z in zip(spectra, config["z"])]
    eh = "wiggle" if config["linear"] == "eh" else "no-wiggle"
    return [plan(z=z, cosmology=cosmology, terms=True, eh=eh) for z in config["z"]]


def _rank_arrays(config, indices):
    """The arrays of the points `indices` (one plan for all), and the metadata of the last table."""
    plan = pt.RealPlan(config["k"], config["model"], config["precision"], config["q_range"],
                       config["two_loop_tolerance"], config["cache_dir"], config["two_loop"])
    out, meta = {"index": np.asarray(indices, dtype=np.int64)}, {}
    nz = len(config["z"])
    for row, i in enumerate(indices):
        cosmology = config["points"][i]
        try:
            tables = _point_tables(plan, config, cosmology)
        except ValueError as e:
            raise ValueError(f"point {i} {cosmology}: {e}") from e
        shape = (len(indices), nz, len(config["k"]))
        if row == 0:  # the columns are known: the arrays are checked against the memory limit
            columns = [c for c in tables[0].columns if c != "k" and (config["terms"] or c in BASIC)]
            _check_memory(config, shape, len(columns))
        for j, t in enumerate(tables):
            for c in t.columns:
                if c != "k" and (config["terms"] or c in BASIC):
                    out.setdefault(c, np.full(shape, np.nan))[row, j] = t[c]
            for name in ("f", "D", "seconds"):
                out.setdefault(name, np.full(shape[:2], np.nan))[row, j] = t.meta.get(name, np.nan)
            meta = t.meta
    for key in sorted({k for p in config["points"] for k in p}):  # the same keys on every rank
        out[f"param_{key}"] = np.array([config["points"][i].get(key, np.nan) for i in indices])
    out["z"], out["k"] = np.asarray(config["z"]), np.asarray(config["k"])
    return out, meta


def _check_memory(config, shape, columns):
    """Refuses (``MemoryError``, with the estimate and the limit) a rank's arrays of `shape` for
    `columns` columns, with the merged arrays of every point that rank 0 holds at the end, above the
    memory limit ($PT_SPECTRA_MAX_MEMORY, else half the machine's memory), before they are
    allocated."""
    rank_bytes = 8.0 * np.prod(shape) * (columns + 3)
    merged = 2 * 8.0 * len(config["points"]) * shape[1] * shape[2] * (columns + 3)
    pt._core.check_memory(rank_bytes + merged,
                          f"the arrays of {shape[0]} points × {shape[1]} z × {shape[2]} k × "
                          f"{columns} columns and their merge over {len(config['points'])} points")


def _write_atomic(path, write):
    """Writes `path` whole or not at all: `write(file)` fills a temporary file in the same
    directory, which is flushed to the disk and renamed over `path` (a failure leaves the old file and
    no temporary file)."""
    directory, name = os.path.split(os.path.abspath(path))
    tmp = os.path.join(directory, f".{name}.{os.getpid()}.tmp")
    try:
        with open(tmp, "wb") as fh:
            write(fh)
            fh.flush()
            os.fsync(fh.fileno())
        os.replace(tmp, path)
    except BaseException:
        try:
            os.remove(tmp)
        except OSError:
            pass
        raise


def _merge(output, size, n_points):
    """all.npz: the arrays of every rank file, rows in point order."""
    parts = []
    for r in range(size):
        with np.load(os.path.join(output, f"rank{r}.npz")) as d:
            parts.append({k: d[k] for k in d.files})
    parts = [p for p in parts if p["index"].size]
    index = np.concatenate([p["index"] for p in parts])
    order = np.argsort(index)
    assert np.array_equal(index[order], np.arange(n_points))
    merged = {k: v for k, v in parts[0].items() if k in ("z", "k")}
    for key in parts[0]:
        if key not in ("z", "k"):
            merged[key] = np.concatenate([p[key] for p in parts])[order]
    _write_atomic(os.path.join(output, "all.npz"), lambda fh: np.savez(fh, **merged))


def run(config, output=None, comm=None):
    """Computes the grid of ``config`` (:func:`load_config`) on the ranks of ``comm`` (None: serial)
    and writes the rank files, ``index.json`` and ``all.npz`` to ``output`` (default run.output).
    Returns the index (on rank 0; None elsewhere)."""
    start = time.perf_counter()
    rank, size = (comm.Get_rank(), comm.Get_size()) if comm is not None else (0, 1)
    output = output or config["output"]
    if not output:
        raise ValueError("run.output (or --output): the output directory is not given")
    threads = _threads(config["threads"], size)
    n_points = len(config["points"])
    mine = list(range(rank, n_points, size))
    error = None
    try:
        os.makedirs(output, exist_ok=True)
        arrays, meta = _rank_arrays(config, mine)
        _write_atomic(os.path.join(output, f"rank{rank}.npz"), lambda fh: np.savez(fh, **arrays))
    except Exception as e:  # reported by every rank below, so that no rank waits forever
        error = f"rank {rank}: {type(e).__name__}: {e}"
        meta = {}
    errors = [error] if comm is None else comm.allgather(error)
    metas = [meta] if comm is None else comm.gather(meta, root=0)
    if any(errors):
        # A refusal for memory (or a failed allocation) on any rank stays a MemoryError.
        kind = MemoryError if any(": MemoryError: " in e for e in errors if e) else RuntimeError
        raise kind("batch failed: " + "; ".join(e for e in errors if e))
    if rank != 0:
        return None
    meta = next(m for m in metas if m)
    index = {
        "pt_spectra_version": pt.__version__, "model": config["model"],
        "precision": meta["precision"], "q_range": list(meta["q_range"]),
        "linear": config["linear"], "z": config["z"], "k": np.asarray(config["k"]).tolist(),
        "ranks": size, "threads_per_rank": threads, "merged": "all.npz",
        "points": [{"index": i, "rank": i % size, "file": f"rank{i % size}.npz", "row": i // size,
                    "cosmology": p} for i, p in enumerate(config["points"])],
    }
    _merge(output, size, n_points)
    index["seconds"] = time.perf_counter() - start
    text = json.dumps(index, indent=1).encode()
    _write_atomic(os.path.join(output, "index.json"), lambda fh: fh.write(text))
    return index


def _communicator(use_mpi):
    """COMM_WORLD if mpi4py is there and there are several processes, else None (serial)."""
    launched = max(int(os.environ.get(v, "1") or 1) for v in ("OMPI_COMM_WORLD_SIZE", "PMI_SIZE"))
    if not use_mpi:
        if launched > 1:
            raise SystemExit("--no-mpi under an MPI launch of several processes: each would write "
                             "the same files")
        return None
    try:
        from mpi4py import MPI
    except ImportError:
        if launched > 1:
            raise SystemExit(f"launched as {launched} MPI processes but mpi4py is not installed: "
                             "pip install mpi4py") from None
        return None
    comm = MPI.COMM_WORLD
    return comm if comm.Get_size() > 1 else None


def main(argv=None):
    parser = argparse.ArgumentParser(prog="python -m pt_spectra.batch",
                                     description="Real-space spectra of a grid of cosmologies "
                                                 "(MPI ranks x rayon threads); see the module docs")
    parser.add_argument("toml", help="the grid (see python/examples/grid.toml)")
    parser.add_argument("--output", help="output directory (default: run.output of the toml)")
    parser.add_argument("--no-mpi", action="store_true",
                        help="run serially without importing mpi4py")
    args = parser.parse_args(argv)
    comm = _communicator(not args.no_mpi)
    try:
        config = load_config(args.toml)
        index = run(config, args.output, comm)
    except (ValueError, RuntimeError, OSError) as e:  # the same on every rank (run gathers them)
        if comm is None or comm.Get_rank() == 0:
            print(f"pt_spectra.batch: {e}", file=sys.stderr)
        return 1
    if index is not None:
        print(f"{len(index['points'])} cosmologies x {len(index['z'])} z on {index['ranks']} "
              f"rank(s) x {index['threads_per_rank']} thread(s): {index['seconds']:.1f} s -> "
              f"{os.path.join(args.output or config['output'], 'index.json')}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
