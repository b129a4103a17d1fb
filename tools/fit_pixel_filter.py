#!/usr/bin/python3
"""Fits the first guess of the Blackman-Harris pixel filter's inverse CDF in shaders/shared/pixel_filter.h.

Over t in [0, 0.5] the window's CDF C(t) is tabulated, and t is fitted by least squares as a
polynomial in s = cbrt(2 C(t)): the cube root of the CDF is nearly linear in t, since the
window's density is almost flat (1.7e-4) at its edge and grows as t^2. Prints the coefficients,
lowest degree first, and the fit's largest error in t. Needs numpy (Debian: python3-numpy).

Usage: tools/fit_pixel_filter.py [DEGREE]   (default 4)
"""
import math
import sys

import numpy as np

A0, A1, A2, A3 = 0.35875, 0.48829, 0.14128, 0.01168
K = 2.0 * math.pi


def cdf(t):
    return (A0 * t - A1 / K * np.sin(K * t) + A2 / (2 * K) * np.sin(2 * K * t)
            - A3 / (3 * K) * np.sin(3 * K * t)) / A0


def main():
    degree = int(sys.argv[1]) if len(sys.argv) > 1 else 4
    t = np.linspace(0.0, 0.5, 20001)
    s = np.cbrt(2.0 * cdf(t))
    coefficients = np.polynomial.polynomial.polyfit(s, t, degree)
    error = np.max(np.abs(np.polynomial.polynomial.polyval(s, coefficients) - t))
    print("coefficients:", ", ".join("%.9gf" % c for c in coefficients))
    print("largest error in t: %.3g" % error)


if __name__ == "__main__":
    main()
