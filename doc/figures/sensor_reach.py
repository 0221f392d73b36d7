#!/usr/bin/python3
"""Draws doc/sensor-reach.png: 3 sigma of a ground point's height against its distance from a
VLP-16 2 m above the ground, for four attitude sigmas of the robot pose, with eq 13 limits.

The data come from the library's own propagation (test RealSensors.ReachIsTheEq13LimitOver-
ThreeAttitudeSigmas writes BUILD/sensor_reach.csv). Run from the source root:
  ./build/tests/sensors/test_real_sensors --gtest_filter='*Reach*'
  /usr/bin/python3 doc/figures/sensor_reach.py build/sensor_reach.csv   (Debian: python3-matplotlib)
"""
import csv
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

path = sys.argv[1] if len(sys.argv) > 1 else "build/sensor_reach.csv"
with open(path) as f:
    rows = list(csv.reader(f))
header, data = rows[0], [[float(v) for v in r] for r in rows[1:]]
distance = [r[0] for r in data]
fig, ax = plt.subplots(figsize=(7, 4.2), dpi=110)
for k, name in enumerate(header[1:], start=1):
    mrad = 1000 * float(name.rsplit("_at_", 1)[1].split("_")[0])
    ax.plot(distance, [r[k] for r in data], label=f"attitude sigma {mrad:g} mrad")
for limit, style in ((0.1, ":"), (0.3, "-."), (1.0, "--")):
    ax.axhline(limit, color="grey", ls=style, lw=1)
    ax.text(101, limit, f"{limit:g} m", va="center", fontsize=8, color="grey")
ax.set_xlim(0, 100)
ax.set_ylim(0, 1.6)
ax.set_xlabel("distance of the ground point from the sensor [m]")
ax.set_ylabel("3 sigma of its height [m]")
ax.set_title("Eq 13 keeps a point while 3 sigma <= the limit (grey lines)", fontsize=10)
ax.legend(fontsize=8, loc="upper left")
ax.grid(alpha=0.3)
fig.tight_layout()
out = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "sensor-reach.png")
fig.savefig(out)
print("wrote", os.path.normpath(out))
