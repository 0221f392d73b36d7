#!/usr/bin/env python3
"""Fits the traversability calibration (doc/traversability.md) on the cells of tuning runs.

By least squares over the cells of every CSV given (traversability_cells.csv of runs mapped
without calibration): truth step = bias + gain x step + step_roughness_gain x roughness +
step_slope_gain x slope (relief finer than the lattice shows in the map's roughness, a tilt in its
slope, where outliers make the map's own step), truth slope = bias + gain x slope, truth
roughness = bias + gain x roughness; each model_sigma is the RMS of its residuals. Prints the
ini keys.
Usage: python3 scripts/fit-traversability.py RUN/traversability_cells.csv [...]
"""
import csv
import math
import sys


def least_squares(columns, y):
    """Coefficients c minimising |sum_k c_k columns_k - y|^2 (normal equations), and the RMS
    residual (n - len(c) degrees of freedom)."""
    m = len(columns)
    a = [[sum(p * q for p, q in zip(columns[i], columns[j])) for j in range(m)] +
         [sum(p * q for p, q in zip(columns[i], y))] for i in range(m)]
    for i in range(m):  # Gauss-Jordan with partial pivoting
        pivot = max(range(i, m), key=lambda k: abs(a[k][i]))
        a[i], a[pivot] = a[pivot], a[i]
        for k in range(m):
            if k != i:
                f = a[k][i] / a[i][i]
                a[k] = [u - f * v for u, v in zip(a[k], a[i])]
    c = [a[i][m] / a[i][i] for i in range(m)]
    residual = [yy - sum(ck * col[n] for ck, col in zip(c, columns)) for n, yy in enumerate(y)]
    return c, math.sqrt(sum(e * e for e in residual) / (len(y) - m))


rows = [r for path in sys.argv[1:] for r in csv.DictReader(open(path))]
if len(rows) < 10:
    sys.exit("fit-traversability.py: fewer than 10 cells in " + " ".join(sys.argv[1:]))
print(f"; fitted on {len(rows)} cells of " + ", ".join(sys.argv[1:]))
one = [1.0] * len(rows)
col = {k: [float(r[k]) for r in rows] for k in rows[0] if k != "x_m" and k != "y_m"}
(b, g, gr, gs), s = least_squares([one, col["step_m"], col["roughness_m"], col["slope_deg"]],
                                  col["truth_step_m"])
print(f"step_bias_m = {b:.4g}\nstep_gain = {g:.4g}\nstep_roughness_gain = {gr:.4g}\n"
      f"step_slope_gain = {gs:.4g}\nstep_model_sigma_m = {s:.4g}")
for name, unit in (("slope", "deg"), ("roughness", "m")):
    (b, g), s = least_squares([one, col[f"{name}_{unit}"]], col[f"truth_{name}_{unit}"])
    print(f"{name}_bias_{unit} = {b:.4g}\n{name}_gain = {g:.4g}\n"
          f"{name}_model_sigma_{unit} = {s:.4g}")
