#!/usr/bin/env python3
"""Prints the inverse-CDF table of the Blackman-Harris pixel filter for shaders/shared/pixel_filter.h.

Entry i is the t in [0, 0.5] whose window CDF is 0.5 * (i / N)^3: the table is spaced evenly
in the cube root of the CDF, which the window's flat tails (its density is 1.7e-4 at the edge)
make nearly linear in t, so that linear interpolation plus two Newton steps lands within float
rounding of the exact inverse everywhere (tests/render/test_pixel_filter.cpp checks both).
Bisection in double precision; no dependencies beyond the standard library.

Usage: tools/gen_pixel_filter_table.py [N]   (default 32)
"""
import math
import sys

A0, A1, A2, A3 = 0.35875, 0.48829, 0.14128, 0.01168
K = 2.0 * math.pi


def cdf(t):
    return (A0 * t - A1 / K * math.sin(K * t) + A2 / (2 * K) * math.sin(2 * K * t)
            - A3 / (3 * K) * math.sin(3 * K * t)) / A0


def inverse(u):
    lo, hi = 0.0, 1.0
    for _ in range(200):
        mid = 0.5 * (lo + hi)
        if cdf(mid) > u:
            hi = mid
        else:
            lo = mid
    return 0.5 * (lo + hi)


def main():
    n = int(sys.argv[1]) if len(sys.argv) > 1 else 32
    values = [inverse(0.5 * (i / n) ** 3) for i in range(n + 1)]
    values[0], values[n] = 0.0, 0.5  # exact ends: CDF(0) = 0, and CDF(0.5) = 0.5 by symmetry
    items = [("%.9g" % v if "." in "%.9g" % v else "%.1f" % v) + "f" for v in values]
    lines, line = [], "   "
    for item in items:
        if len(line) + len(item) + 2 > 96:
            lines.append(line.rstrip())
            line = "   "
        line += " " + item + ","
    lines.append(line.rstrip().rstrip(","))
    print("#define OSR_BH_INVERSE_TABLE \\")
    print(" \\\n".join(lines))


if __name__ == "__main__":
    main()
