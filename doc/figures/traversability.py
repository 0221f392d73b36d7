#!/usr/bin/python3
"""Draws doc/figures/traversability.png: the reliability diagram of P(untraversable) on the scoring
boards (both noise models, the score-mockup and score-walk scenarios) and, for one scenario, the
layer beside the truth's classes.

The data are the outputs of scripts/evaluate-traversability.sh (traversability.json and
eval_untraversable_{truth,multibin}.asc of each mapped scenario). Run from the source root:
  bash scripts/evaluate-traversability.sh
  /usr/bin/python3 doc/figures/traversability.py build/traversability   (Debian: python3-matplotlib)
"""
import json
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

# The mapper's reader of ESRI ASCII grids (row 0 north, NaN nodata, extent for imshow).
sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "../../apps/elevation-mapper"))
from plot_report import load_asc  # noqa: E402

out = sys.argv[1] if len(sys.argv) > 1 else "build/traversability"
shown = "score-mockup-matched"  # the scenario whose layer is drawn beside the truth


fig = plt.figure(figsize=(14, 4.4), dpi=100)
ax = fig.add_subplot(1, 3, 1)
ax.plot([0, 1], [0, 1], color="grey", lw=1, ls=":", label="calibrated")
for scenario in ("score-mockup", "score-walk"):
    for noise, style in (("matched", "-o"), ("independent", "--s")):
        path = os.path.join(out, f"{scenario}-{noise}-boards", "traversability.json")
        m = json.load(open(path))["methods"]["multibin"]
        rel = [b for b in m["reliability"] if b["cells"] >= 20]  # deciles with few cells are noise
        ax.plot([b["mean_p"] for b in rel], [b["observed"] for b in rel], style, ms=4,
                label=f"{scenario} {noise} (ECE {m['ece']:.3f})")
ax.set_xlabel("predicted P(untraversable), mean per decile")
ax.set_ylabel("share untraversable in truth")
ax.set_xlim(0, 1)
ax.set_ylim(0, 1)
ax.set_aspect("equal")
ax.legend(fontsize=7, loc="upper left")
ax.set_title("Reliability on the scoring boards", fontsize=10)

folder = os.path.join(out, f"{shown}-boards")
for k, (name, title) in enumerate((("truth", "truth: untraversable (yellow)"),
                                   ("multibin", "map: P(untraversable)"))):
    z, extent = load_asc(os.path.join(folder, f"eval_untraversable_{name}.asc"))
    ax = fig.add_subplot(1, 3, k + 2)
    im = ax.imshow(z, extent=extent, cmap="inferno", vmin=0, vmax=1, interpolation="nearest")
    ax.set_title(f"{shown}, {title}", fontsize=9)
    ax.set_xlabel("x [m]")
    if k == 0:
        ax.set_ylabel("y [m]")
fig.colorbar(im, ax=fig.axes[1:], fraction=0.03, label="untraversable (truth) / P (map)")
dest = os.path.join(os.path.dirname(os.path.abspath(__file__)), "traversability.png")
fig.savefig(dest, bbox_inches="tight")
print(dest)
