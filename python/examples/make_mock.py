"""Mock multipoles for cobaya_mock.yaml: the yaml's own theory at its fiducial (``ref``) point.

    python make_mock.py [cobaya_mock.yaml] [--rel-error 0.02]

For every ``pt_spectra.likelihoods.MultipoleGaussian`` likelihood of the yaml, writes its
``data_file`` (npz: ``k`` [h/Mpc], ``P<l>``, ``s<l>`` [(Mpc/h)^3]) with the multipoles of the
yaml's ``PTMultipoles`` theory at the likelihood's z, computed through cobaya exactly as in a run,
so that χ² = 0 at the fiducial point. Errors: ``rel_error`` × |P_ℓ|, floored at ``rel_error`` ×
0.1 |P_0| so that the zero crossings of P_2 and P_4 do not get vanishing errors. Relative
``data_file`` paths are relative to the working directory (as in the likelihood).
"""

from __future__ import annotations

import argparse
import copy

import numpy as np

LIKELIHOOD = "pt_spectra.likelihoods.MultipoleGaussian"


def fiducial_point(info):
    """The sampled parameters of a cobaya input dict at their ``ref`` values (numbers)."""
    point = {}
    for name, p in info["params"].items():
        if isinstance(p, dict) and "prior" in p:
            ref = p.get("ref")
            if not isinstance(ref, (int, float)):
                raise ValueError(f"parameter {name}: the fiducial point needs a number as `ref`")
            point[name] = float(ref)
    return point


def mock_likelihoods(info):
    """{name: options} of the MultipoleGaussian likelihoods of a cobaya input dict."""
    found = {n: o for n, o in info["likelihood"].items()
             if (o or {}).get("class", n) == LIKELIHOOD}
    if not found:
        raise ValueError(f"no likelihood of class {LIKELIHOOD} in the input")
    return found


def make_mock(info, rel_error=0.02, point=None):
    """{data_file: {"k", "P<l>", "s<l>"}} of every MultipoleGaussian likelihood of ``info`` (a
    cobaya input dict), the theory evaluated at ``point`` (default: the ``ref`` values)."""
    from cobaya.model import get_model

    likes = mock_likelihoods(info)
    theory_info = copy.deepcopy({k: v for k, v in info.items() if k in ("theory", "params")})
    # a likelihood of 0 that only asks the theory for the multipoles of each z
    requires = {"pt_pk_ell": {"z": [float(o["z"]) for o in likes.values()]},
                "pt_k": None, "pt_ells": None}
    model = get_model({**theory_info, "likelihood": {
        "mock_maker": {"external": lambda _self=None: 0.0, "requires": requires}}})
    point = fiducial_point(info) if point is None else point
    logpost = model.logposterior(point)
    if not np.isfinite(logpost.logpost):
        raise ValueError(f"the fiducial point {point} has zero prior or failed")
    k = np.asarray(model.provider.get_pt_k())
    ells = model.provider.get_pt_ells()
    mocks = {}
    for options in likes.values():
        p = np.asarray(model.provider.get_pt_pk_ell(z=float(options["z"])))
        floor = rel_error * 0.1 * np.abs(p[ells.index(0)]) if 0 in ells else 0.0
        data = {"k": k}
        for row, ell in zip(p, ells):
            data[f"P{ell}"] = row
            data[f"s{ell}"] = np.maximum(rel_error * np.abs(row), floor)
        mocks[options["data_file"]] = data
    return mocks


def main(argv=None):
    from cobaya.yaml import yaml_load_file

    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("yaml", nargs="?", default="cobaya_mock.yaml")
    parser.add_argument("--rel-error", type=float, default=0.02)
    args = parser.parse_args(argv)
    for path, data in make_mock(yaml_load_file(args.yaml), args.rel_error).items():
        np.savez(path, **data)
        print(f"wrote {path}: k in [{data['k'][0]:.4g}, {data['k'][-1]:.4g}] h/Mpc, "
              f"{len(data['k'])} points, multipoles {sorted(k for k in data if k[0] == 'P')}")


if __name__ == "__main__":
    main()
