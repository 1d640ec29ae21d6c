"""Values of the galaxy kernels K_n and Z_n^g (n = 2, 3, 4) at fixed configurations, from the independent
implementation of make_one_loop_galaxy_mc.py (unsymmetrised operator kernels on consecutive blocks of every
ordering, averaged over orderings; its own SPT recursion), for the Rust kernels' test (issue 50).

Writes galaxy_kernel_values.txt: per line f, n, the n vectors (3n numbers), the kernel at the bias BIAS of
make_one_loop_galaxy_mc.py and the line of sight LOS of make_one_loop_rsd_mc.py (f = 0: real space).

    python3 tests/data/bispectrum/make_galaxy_kernel_values.py   (numpy, scipy; seconds)
"""

import numpy as np

from make_one_loop_galaxy_mc import BIAS, HERE, z_gal
from make_one_loop_rsd_mc import LOS

rng = np.random.default_rng(20261206)
lines = [
    "# galaxy kernels K_n (f = 0) and Z_n^g (f = 0.7) by make_galaxy_kernel_values.py (independent of the Rust code)",
    "# bias: " + " ".join(f"{k}={v}" for k, v in BIAS.items()),
    f"# line of sight {LOS[0]:.17g} {LOS[1]:.17g} {LOS[2]:.17g}",
    "# f n q1x q1y q1z ... qnx qny qnz kernel",
]
for f in (0.0, 0.7):
    for n in (2, 3, 4):
        for _ in range(8):
            vs = [rng.normal(size=3) * rng.uniform(0.05, 2.0) for _ in range(n)]
            value = z_gal(f, BIAS, *[v[None, :] for v in vs])[0]
            row = [f, n] + [x for v in vs for x in v] + [value]
            lines.append(" ".join(f"{x:.17g}" for x in row))
(HERE / "galaxy_kernel_values.txt").write_text("\n".join(lines) + "\n")
