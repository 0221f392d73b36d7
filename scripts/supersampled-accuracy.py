#!/usr/bin/env python3
# RMSE of the supersampled export (elevation-mapper --export-resolution) and of the map-resolution
# raster (each sample given its cell's value) against a finer truth raster, bilinear, over an area:
#   supersampled-accuracy.py TRUTH.asc elevation_height.asc elevation_height_supersampled.asc XMIN,XMAX,YMIN,YMAX
# (doc/sub-cell-surface.md). Plain Python, no packages.
import math, sys
def load(p):
    f = open(p); h = {}
    for _ in range(6):
        k, v = f.readline().split(); h[k.lower()] = float(v)
    rows = [list(map(float, l.split())) for l in f if l.strip()]
    rows.reverse()  # row 0 = south
    nd = h['nodata_value']
    return h, [[math.nan if v == nd else v for v in r] for r in rows]
def interp(g, x, y):
    h, a = g; fc = (x - h['xllcenter']) / h['cellsize']; fr = (y - h['yllcenter']) / h['cellsize']
    c0, r0 = int(fc), int(fr)
    if fc < 0 or fr < 0 or c0 + 1 >= h['ncols'] or r0 + 1 >= h['nrows']: return math.nan
    tx, ty = fc - c0, fr - r0
    return (1-ty)*((1-tx)*a[r0][c0] + tx*a[r0][c0+1]) + ty*((1-tx)*a[r0+1][c0] + tx*a[r0+1][c0+1])
def cell(g, x, y):
    h, a = g; c = math.floor((x - h['xllcenter']) / h['cellsize'] + 0.5); r = math.floor((y - h['yllcenter']) / h['cellsize'] + 0.5)
    if c < 0 or r < 0 or c >= h['ncols'] or r >= h['nrows']: return math.nan
    return a[r][c]
truth = load(sys.argv[1]); coarse = load(sys.argv[2]); fine = load(sys.argv[3])
x0, x1, y0, y1 = map(float, sys.argv[4].split(','))
hf, af = fine; se = [0, 0]; n = 0
for r in range(int(hf['nrows'])):
    y = hf['yllcenter'] + r * hf['cellsize']
    if not (y0 <= y < y1): continue
    for c in range(int(hf['ncols'])):
        x = hf['xllcenter'] + c * hf['cellsize']
        if not (x0 <= x < x1): continue
        t = interp(truth, x, y); vf = af[r][c]; vc = cell(coarse, x, y)
        if any(math.isnan(v) for v in (t, vf, vc)): continue
        se[0] += (vc - t) ** 2; se[1] += (vf - t) ** 2; n += 1
print("%d samples: RMSE [mm] map-resolution raster (its cell's value) %.2f, supersampled %.2f" % (n, 1e3 * math.sqrt(se[0] / n), 1e3 * math.sqrt(se[1] / n)))
