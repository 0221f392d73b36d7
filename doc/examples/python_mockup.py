#!/usr/bin/env python3
"""Maps the shipped mock-up with the Python module, plots the height and sigma layers and scores
the map against the shipped ground truth. Run from the project folder after the build:

    PYTHONPATH=build/python/module /usr/bin/python3 doc/examples/python_mockup.py [OUT.png]

The score is this example's own: the map's height() at every ground-truth sample inside the
truth raster (elevation-mapper --ground-truth scores cell means instead, doc/evaluation.md).
"""
import pathlib
import sys

import matplotlib

matplotlib.use("Agg")  # files only: no display needed
import matplotlib.pyplot as plt
import numpy as np

import multibin

ROOT = pathlib.Path(__file__).resolve().parents[2]


def load_esri_ascii(path):
    """An ESRI ASCII grid: (heights with NaN for NODATA, row 0 the southernmost; x and y of the
    sample centres)."""
    header = {}
    with open(path) as f:
        for _ in range(6):
            key, value = f.readline().split()
            header[key.lower()] = float(value)
        z = np.loadtxt(f)
    z[z == header["nodata_value"]] = np.nan
    z = z[::-1]  # the file's first row is the northernmost
    rows, cols = z.shape
    x = header["xllcenter"] + header["cellsize"] * np.arange(cols)
    y = header["yllcenter"] + header["cellsize"] * np.arange(rows)
    return z, x, y


# 1. Map the rawlog with the scenario's configuration, then fill the gaps.
m = multibin.ElevationMap(str(ROOT / "ini" / "mockup.ini"))
counts = m.map_rawlog(str(ROOT / "rawlogs" / "mockup.rawlog"))
print(counts["report"], end="")
print("points fused:", counts["points"]["accepted"])
print("cells filled:", m.fill())

# 2. Score height() against the truth at its samples.
truth, tx, ty = load_esri_ascii(ROOT / "rawlogs" / "mockup_gt.asc")
gx, gy = np.meshgrid(tx, ty)
h, sigma, source = m.height(gx, gy)
scored = np.isfinite(truth)
known = scored & np.isfinite(h)
measured = known & (source == multibin.SOURCE_MEASURED)
error = h - truth
print(f"coverage: {known.sum() / scored.sum():.3f} of the truth's samples "
      f"({measured.sum() / scored.sum():.3f} measured)")
for name, sel in [("measured", measured), ("filled", known & ~measured), ("all", known)]:
    rmse_mm = 1e3 * np.sqrt(np.mean(error[sel]**2))
    within = np.mean(np.abs(error[sel]) <= 3 * sigma[sel])
    print(f"{name:9s} RMSE {rmse_mm:5.1f} mm, within 3 sigma {within:.3f} ({sel.sum()} samples)")

# 3. Plot the height and sigma layers: imshow with the layers' extent, row 0 at the bottom.
layers = m.layers()
rows, cols = np.nonzero(np.isfinite(layers["height"]))  # the known cells' bounds
x0, y0 = layers["origin"]
cell = layers["cell_size"]
xlim = (x0 + cell * cols.min(), x0 + cell * (cols.max() + 1))
ylim = (y0 + cell * rows.min(), y0 + cell * (rows.max() + 1))
fig, axes = plt.subplots(1, 2, figsize=(9, 7), constrained_layout=True)
for ax, name, unit, cmap in [(axes[0], "height", "m", "terrain"), (axes[1], "sigma", "m",
                                                                    "magma")]:
    im = ax.imshow(layers[name], origin="lower", extent=layers["extent"], cmap=cmap)
    ax.set_xlim(*xlim)
    ax.set_ylim(*ylim)
    ax.set_title(f"{name} [{unit}]")
    ax.set_xlabel("x [m]")
    ax.set_ylabel("y [m]")
    fig.colorbar(im, ax=ax, shrink=0.8)
out = sys.argv[1] if len(sys.argv) > 1 else "python_mockup.png"
fig.savefig(out, dpi=100)
print("wrote", out)
