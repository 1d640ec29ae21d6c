#!/usr/bin/env python3
"""Resample cosPT's input spectrum the way cosPT reads it (standard library only).

cosPT interpolates `pk_lin.dat` with GSL's natural cubic spline in linear (k, P)
(`Interpolation1D`, gsl_interp_cspline). pt-spectra's table reader interpolates differently; on this
139-row table that alone changes P_lin by up to 1e-3 (k > 1 h/Mpc) and the 1-loop term by up to 5e-4
(k = 0.046). Feeding pt-spectra this dense resampling makes both codes integrate the same function
(P_lin then agrees with cosPT's P_lin column to <= 4e-7).

    python3 resample_cspline.py pk_lin.dat > pk_lin_cspline_fine.dat    # 6000 log-spaced rows, not rescaled
"""
import math
import sys


def natural_cubic_spline(x, y):
    n = len(x)
    h = [x[i + 1] - x[i] for i in range(n - 1)]
    a, b, c, r = [0.0] * n, [1.0] * n, [0.0] * n, [0.0] * n
    for i in range(1, n - 1):
        a[i], b[i], c[i] = h[i - 1], 2 * (h[i - 1] + h[i]), h[i]
        r[i] = 6 * ((y[i + 1] - y[i]) / h[i] - (y[i] - y[i - 1]) / h[i - 1])
    cp, rp = [0.0] * n, [0.0] * n
    for i in range(n):  # Thomas algorithm, M[0] = M[n-1] = 0
        den = b[i] - (a[i] * cp[i - 1] if i else 0.0)
        cp[i] = c[i] / den
        rp[i] = (r[i] - (a[i] * rp[i - 1] if i else 0.0)) / den
    m = [0.0] * n
    for i in range(n - 1, -1, -1):
        m[i] = rp[i] - (cp[i] * m[i + 1] if i < n - 1 else 0.0)

    def spline(t):
        lo, hi = 0, n - 1
        while hi - lo > 1:
            mid = (lo + hi) // 2
            lo, hi = (lo, mid) if x[mid] > t else (mid, hi)
        d = h[lo]
        p, q = (x[lo + 1] - t) / d, (t - x[lo]) / d
        return p * y[lo] + q * y[lo + 1] + ((p**3 - p) * m[lo] + (q**3 - q) * m[lo + 1]) * d * d / 6

    return spline


def main(path, rows=6000):
    data = [tuple(map(float, l.split()[:2])) for l in open(path) if l.strip() and not l.startswith("#")]
    k, p = [d[0] for d in data], [d[1] for d in data]
    s = natural_cubic_spline(k, p)
    l0, l1 = math.log(k[0]), math.log(k[-1])
    print(f"# {path} resampled by a natural cubic spline in linear (k, P) (GSL cspline, as cosPT); k [h/Mpc], P [(Mpc/h)^3], not rescaled")
    for i in range(rows):
        t = min(max(math.exp(l0 + (l1 - l0) * i / (rows - 1)), k[0]), k[-1])
        print(f"{t:.12e} {s(t):.12e}")


if __name__ == "__main__":
    main(sys.argv[1])
