#!/usr/bin/python3
"""Draws elevation-mapper's evaluation figures with matplotlib (Debian: python3-matplotlib).

Usage: plot_report.py DIR [RASTER_DIR [FIGURE_DIR]]

Reads DIR/report.json, DIR/profile.csv and the rasters elevation_*.asc that elevation-mapper
wrote (in RASTER_DIR, default DIR), and writes into FIGURE_DIR (default DIR):
  fig_pi.png       the paper's Fig. 8: Performance Index (eq 17) per method, bars
  fig_profile.png  the paper's Fig. 3: a height profile with the +-3 sigma band and the truth
  layers.png       height, sigma, certainty and filled cells of the map, with colour bars
"""
import csv
import json
import math
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402


def load_asc(path):
    """ESRI ASCII grid -> (array with row 0 = north, extent [xmin, xmax, ymin, ymax])."""
    header = {}
    with open(path) as f:
        for _ in range(6):
            key, value = f.readline().split()
            header[key.lower()] = float(value)
        data = np.loadtxt(f, ndmin=2)
    nodata = header.get("nodata_value", -9999.0)
    data[data == nodata] = np.nan
    cs = header["cellsize"]
    x0 = header.get("xllcenter", header.get("xllcorner", 0.0) + cs / 2) - cs / 2
    y0 = header.get("yllcenter", header.get("yllcorner", 0.0) + cs / 2) - cs / 2
    return data, [x0, x0 + cs * header["ncols"], y0, y0 + cs * header["nrows"]]


def plot_pi(report, out):
    names, values = [], []
    for name, m in report["methods"].items():
        if name.startswith("raw_") or m.get("pi") is None:
            continue
        names.append(name)
        values.append(m["pi"])
    fig, ax = plt.subplots(figsize=(7, 4))
    # The reference line passes behind the bars, and each value is written inside its bar's top,
    # so no label crosses the line whatever the values.
    ax.axhline(1.0, color="k", lw=0.8, ls="--", label="raw map (PI = 1)", zorder=1)
    bars = ax.bar(range(len(names)), values, color="tab:blue", zorder=2)
    top = max(values + [1.0])
    for b, v in zip(bars, values):
        inside = v > 0.12 * top
        ax.text(b.get_x() + b.get_width() / 2, v - 0.02 * top if inside else v + 0.02 * top,
                f"{v:.3f}", ha="center", va="top" if inside else "bottom",
                color="white" if inside else "black", fontsize=9, zorder=3)
    ax.set_ylim(0, 1.2 * top)
    ax.set_xticks(range(len(names)))
    ax.set_xticklabels(names, rotation=20, ha="right")
    ax.set_ylabel("Performance Index (eq 17), lower is better")
    ax.set_title("PI per method against ground truth")
    ax.legend()
    fig.tight_layout()
    fig.savefig(out, dpi=120)
    plt.close(fig)


def plot_profile(path, out):
    cols = {}
    with open(path) as f:
        for row in csv.DictReader(f):
            for k, v in row.items():
                cols.setdefault(k, []).append(float(v) if v != "" else math.nan)
    if not cols:
        return
    s = np.array(cols["s_m"])
    truth = np.array(cols["truth_m"])
    h = np.array(cols["filled_m"])
    sig = np.array(cols["filled_sigma_m"])
    measured = np.array(cols["multibin_m"])
    fig, ax = plt.subplots(figsize=(8, 4))
    ax.fill_between(s, h - 3 * sig, h + 3 * sig, color="tab:orange", alpha=0.3,
                    label="map +- 3 sigma")
    ax.plot(s, h, color="tab:orange", lw=1, label="map (filled cells included)")
    ax.plot(s, measured, ".", color="tab:red", ms=3, label="measured cells")
    ax.plot(s, truth, color="k", lw=1, label="ground truth")
    ax.set_xlabel("distance along the profile [m]")
    ax.set_ylabel("height [m]")
    ax.set_title(f"Height profile from ({cols['x_m'][0]:.2f}, {cols['y_m'][0]:.2f}) "
                 f"to ({cols['x_m'][-1]:.2f}, {cols['y_m'][-1]:.2f}) m")
    ax.legend(loc="best", fontsize=8)
    fig.tight_layout()
    fig.savefig(out, dpi=120)
    plt.close(fig)


# Categories of the source layer (CMultiBinElevationMap::HeightSource) and their colours, the
# same as elevation_source.png's.
SOURCES = [(1, "measured", "tab:blue"), (2, "filled: median", "tab:orange"),
           (3, "filled: surface", "tab:green")]
UNKNOWN_GREY = (200 / 255, 200 / 255, 200 / 255)


def plot_layers(directory, out):
    from matplotlib.colors import BoundaryNorm, ListedColormap
    from matplotlib.patches import Patch

    layers = [("height", "height [m]", "viridis"), ("sigma", "sigma [m]", "inferno"),
              ("certainty", "certainty c [-]", "cividis"), ("source", None, None)]
    fig, axes = plt.subplots(2, 2, figsize=(10, 9))
    for ax, (name, label, cmap) in zip(axes.flat, layers):
        path = os.path.join(directory, f"elevation_{name}.asc")
        if not os.path.exists(path):
            ax.set_axis_off()
            continue
        data, extent = load_asc(path)
        ax.set_facecolor(UNKNOWN_GREY)  # NaN cells are not drawn: unknown shows grey
        if name == "source":  # categorical: a legend, not a colour bar
            cmap = ListedColormap([c for _, _, c in SOURCES])
            norm = BoundaryNorm([0.5, 1.5, 2.5, 3.5], cmap.N)
            ax.imshow(data, extent=extent, origin="upper", cmap=cmap, norm=norm,
                      interpolation="nearest")
            handles = [Patch(color=c, label=n) for _, n, c in SOURCES]
            handles.append(Patch(facecolor=UNKNOWN_GREY, edgecolor="k", label="unknown"))
            ax.legend(handles=handles, loc="upper left", bbox_to_anchor=(1.02, 1.0),
                      fontsize=8, title="source of the height", title_fontsize=8)
        else:
            im = ax.imshow(data, extent=extent, origin="upper", cmap=cmap,
                           interpolation="nearest")
            fig.colorbar(im, ax=ax, label=label + " (grey: unknown)", shrink=0.8)
        ax.set_title(name)
        ax.set_xlabel("x [m]")
        ax.set_ylabel("y [m]")
    fig.tight_layout()
    fig.savefig(out, dpi=110)
    plt.close(fig)


def main():
    if len(sys.argv) not in (2, 3, 4):
        sys.exit(__doc__)
    d = sys.argv[1]
    rasters = sys.argv[2] if len(sys.argv) >= 3 else d
    figures = sys.argv[3] if len(sys.argv) == 4 else d
    with open(os.path.join(d, "report.json")) as f:
        report = json.load(f)
    plot_pi(report, os.path.join(figures, "fig_pi.png"))
    plot_profile(os.path.join(d, "profile.csv"), os.path.join(figures, "fig_profile.png"))
    plot_layers(rasters, os.path.join(figures, "layers.png"))
    print(f"figures: {figures}/fig_pi.png, {figures}/fig_profile.png, {figures}/layers.png")


if __name__ == "__main__":
    main()
