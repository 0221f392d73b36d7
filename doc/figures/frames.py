#!/usr/bin/python3
"""Draws doc/frames.png: the frames the library uses (MRPT conventions).

Run: /usr/bin/python3 doc/figures/frames.py   (Debian: python3-matplotlib)
Map / robot frame: +x forward, +y left, +z up. Laser scan frame: beam at angle 0 along +x, scan
plane = its x-y plane; the URG-04LX is pitched 45 deg down at 0.26 m. Camera frame: +z forward
(optical axis), +x right, +y down; the left camera is pitched 35 deg down at 0.48 m.
"""
import os

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402


def rot_y(a):
    c, s = np.cos(a), np.sin(a)
    return np.array([[c, 0, s], [0, 1, 0], [-s, 0, c]])


def draw_frame(ax, origin, R, name, length=0.12, labels=("x", "y", "z")):
    for k, colour in enumerate(("tab:red", "tab:green", "tab:blue")):
        d = R[:, k] * length
        ax.quiver(*origin, *d, color=colour, arrow_length_ratio=0.2, lw=2)
        ax.text(*(origin + d * 1.15), labels[k], color=colour, fontsize=9)
    ax.text(*(origin + np.array([0, 0, 0.03])), name, fontsize=9)


fig = plt.figure(figsize=(8, 6))
ax = fig.add_subplot(projection="3d")
draw_frame(ax, np.zeros(3), np.eye(3), "map / robot\n(+x fwd, +y left, +z up)", 0.2)
# Laser: MRPT pitch > 0 turns +x downwards (rotation about +y).
laser_R = rot_y(np.radians(45))
laser_o = np.array([0.1, 0, 0.26])
draw_frame(ax, laser_o, laser_R, "laser (pitch 45 deg)")
beam = laser_o + laser_R[:, 0] * (0.26 / np.sin(np.radians(45)))
ax.plot(*zip(laser_o, beam), "k--", lw=1)
# Camera: optical axis +z. Camera-from-robot rotation for a level camera looking along +x:
# camera x = -robot y (right), camera y = -robot z (down), camera z = robot x (forward).
level = np.array([[0, 0, 1], [-1, 0, 0], [0, -1, 0]], dtype=float)
cam_R = rot_y(np.radians(35)) @ level
cam_o = np.array([0.05, 0.0, 0.48])
draw_frame(ax, cam_o, cam_R, "left camera (pitch 35 deg)\n(+z optical axis, +x right, +y down)")
ray = cam_o + cam_R[:, 2] * (0.48 / np.sin(np.radians(35)))
ax.plot(*zip(cam_o, ray), "k:", lw=1)
xx, yy = np.meshgrid(np.linspace(-0.1, 0.9, 2), np.linspace(-0.3, 0.3, 2))
ax.plot_surface(xx, yy, 0 * xx, alpha=0.15, color="grey")
ax.set_xlabel("x [m]")
ax.set_ylabel("y [m]")
ax.set_zlabel("z [m]")
ax.set_box_aspect((1.0, 0.6, 0.6))
ax.view_init(elev=20, azim=-60)
ax.set_title("Frames (MRPT conventions); dashed: laser beam 0, dotted: camera axis")
out = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "frames.png")
fig.savefig(out, dpi=110, bbox_inches="tight")
print("wrote", os.path.normpath(out))
