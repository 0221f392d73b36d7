/* Part of the multibin elevation-mapping library. */
#include "multibin/map/CellSurface.h"

#include <algorithm>
#include <cmath>
#include <utility>

#include "multibin/map/BinUpdate.h"

namespace multibin {

bool cellSurface(const BinGrid& grid, int ix, int iy, const BinUpdateParams& p, CellSurface& out) {
    const Bin* win = grid.winningBin(ix, iy);
    if (!win) return false;
    const double floor_m2 = p.varianceFloor_m2;
    HeightInformation surface;
    surface.add(win->height_m, std::max<double>(win->variance_m2, floor_m2));
    out.certainty = win->certainty;
    out.firstBin = out.lastBin = win->index;
    for (const int dir : {-1, 1}) {
        for (int n = win->index + dir;; n += dir) {
            const Bin* next = nullptr;
            grid.forEachBin(ix, iy, [&](const Bin& b) {
                if (b.index == n && b.certainty > 0) next = &b;
            });
            if (!next) break;
            const double v = std::max<double>(next->variance_m2, floor_m2);
            const double h = surface.height_m(), vNow = surface.variance_m2();
            if ((next->height_m - h) * (next->height_m - h) > 9.0 * (v + vNow)) break;
            surface.add(next->height_m, v);
            out.certainty += next->certainty;
            (dir < 0 ? out.firstBin : out.lastBin) = n;
        }
    }
    out.height_m = surface.height_m();
    out.variance_m2 = std::max(surface.variance_m2(), floor_m2);
    return true;
}

void addReliefVariance(const BinGrid& grid, double x_m, double y_m, const BinUpdateParams& p,
                       CellSurface& cell) {
    // Without it sigma is a few mm on 45 degree rock faces where the cell's height is uncertain
    // by a centimetre. The slope from central differences, one-sided at gaps.
    const double s = grid.cellSize_m();
    double slope2 = 0;
    for (const auto& [dx, dy] : {std::pair<double, double>{s, 0.0}, {0.0, s}}) {
        CellSurface lo, hi;
        const bool haveLo = cellSurface(grid, x_m - dx, y_m - dy, p, lo);
        const bool haveHi = cellSurface(grid, x_m + dx, y_m + dy, p, hi);
        double g = 0;
        if (haveLo && haveHi)
            g = (hi.height_m - lo.height_m) / (2 * s);
        else if (haveLo)
            g = (cell.height_m - lo.height_m) / s;
        else if (haveHi)
            g = (hi.height_m - cell.height_m) / s;
        slope2 += g * g;
    }
    cell.variance_m2 += slope2 * s * s / 12.0;
    // Certain bins outside the surface: the cell also holds surfaces at other heights (a step
    // inside the cell, its top and its foot seen from different places). The truth of the cell,
    // the mean over its area, lies between them: their spread around the reported height,
    // weighted by each bin's share of the cell's certainty, is part of the cell's uncertainty.
    double otherCertainty = 0, otherSpread_m2 = 0;
    grid.forEachBin(grid.cellIndex(x_m), grid.cellIndex(y_m), [&](const Bin& b) {
        if (b.certainty <= 0 || (b.index >= cell.firstBin && b.index <= cell.lastBin)) return;
        otherCertainty += b.certainty;
        otherSpread_m2 += b.certainty * (b.height_m - cell.height_m) * (b.height_m - cell.height_m);
    });
    if (otherCertainty > 0) cell.variance_m2 += otherSpread_m2 / (otherCertainty + cell.certainty);
}

bool surfaceAt(const BinGrid& grid, const BinGrid* local, double x_m, double y_m,
               const BinUpdateParams& p, bool reliefSigma, CellSurface& out) {
    CellSurface g, l;
    const bool haveG = cellSurface(grid, x_m, y_m, p, g);
    const bool haveL = local && cellSurface(*local, x_m, y_m, p, l);
    if (!haveG && !haveL) return false;
    if (reliefSigma) {
        if (haveG) addReliefVariance(grid, x_m, y_m, p, g);
        if (haveL) addReliefVariance(*local, x_m, y_m, p, l);
    }
    if (!haveG || !haveL) {
        out = haveG ? g : l;
        return true;
    }
    const double d = l.height_m - g.height_m;
    if (d * d <= 9.0 * (g.variance_m2 + l.variance_m2)) {
        HeightInformation both;
        both.add(g.height_m, g.variance_m2);
        both.add(l.height_m, l.variance_m2);
        out = l;
        out.height_m = both.height_m();
        out.variance_m2 = both.variance_m2();
        out.certainty = g.certainty + l.certainty;
    } else {
        out = l.certainty >= g.certainty ? l : g;
    }
    return true;
}

}  // namespace multibin
