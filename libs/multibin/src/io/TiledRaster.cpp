/* Part of the multibin elevation-mapping library: rasters read tile by tile (bounds, known box,
 * block-reduced previews, the size limit of the dense outputs). */
#include "multibin/io/TiledRaster.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <stdexcept>

namespace multibin {

namespace {
int floorDiv(int a, int b) { return a >= 0 ? a / b : -((-a + b - 1) / b); }

/** The window of cells both windows hold (nx or ny 0 when none). */
CellWindow intersection(const CellWindow& a, const CellWindow& b) {
    const int x0 = std::max(a.ix0, b.ix0), y0 = std::max(a.iy0, b.iy0);
    const int x1 = std::min(a.ix0 + a.nx, b.ix0 + b.nx), y1 = std::min(a.iy0 + a.ny, b.iy0 + b.ny);
    return CellWindow{x0, y0, std::max(0, x1 - x0), std::max(0, y1 - y0)};
}
}  // namespace

CellWindow tileOfCell(int ix, int iy, int tileCells) {
    return CellWindow{floorDiv(ix, tileCells) * tileCells, floorDiv(iy, tileCells) * tileCells,
                      tileCells, tileCells};
}

CellWindow TiledRaster::tileBounds() const {
    if (tiles.empty()) return {};
    int x0 = std::numeric_limits<int>::max(), y0 = x0, x1 = std::numeric_limits<int>::min(),
        y1 = x1;
    for (const CellWindow& t : tiles) {
        x0 = std::min(x0, t.ix0), y0 = std::min(y0, t.iy0);
        x1 = std::max(x1, t.ix0 + t.nx), y1 = std::max(y1, t.iy0 + t.ny);
    }
    return CellWindow{x0, y0, x1 - x0, y1 - y0};
}

CellWindow TiledRaster::knownCells() const {
    int x0 = std::numeric_limits<int>::max(), y0 = x0, x1 = std::numeric_limits<int>::min(),
        y1 = x1;
    for (const CellWindow& t : tiles) {
        const EsriAsciiGrid g = samples(t);
        for (int r = 0; r < g.rows(); r++)
            for (int c = 0; c < g.cols(); c++)
                if (std::isfinite(g.heights_m(r, c))) {
                    x0 = std::min(x0, t.ix0 + c), x1 = std::max(x1, t.ix0 + c);
                    y0 = std::min(y0, t.iy0 + r), y1 = std::max(y1, t.iy0 + r);
                }
    }
    if (x1 < x0) return {};
    return CellWindow{x0, y0, x1 - x0 + 1, y1 - y0 + 1};
}

int blockFactorFor(const CellWindow& window, int maxSide_px) {
    const int side = std::max(window.nx, window.ny);
    return std::max(1, (side + maxSide_px - 1) / std::max(1, maxSide_px));
}

EsriAsciiGrid blockReduced(const TiledRaster& raster, const CellWindow& window, int factor,
                           BlockReduce how) {
    if (factor < 1) throw std::invalid_argument("blockReduced: the block side must be >= 1");
    const int cols = (window.nx + factor - 1) / factor, rows = (window.ny + factor - 1) / factor;
    EsriAsciiGrid out;
    out.cellsize_m = raster.cellSize_m * factor;
    // A block's sample sits at the block's centre (a partial last block included: its centre
    // as if whole, so the lattice stays regular).
    out.xllcenter_m = raster.originX_m + window.ix0 * raster.cellSize_m + 0.5 * out.cellsize_m;
    out.yllcenter_m = raster.originY_m + window.iy0 * raster.cellSize_m + 0.5 * out.cellsize_m;
    out.heights_m.setConstant(rows, cols, std::numeric_limits<float>::quiet_NaN());
    Eigen::MatrixXf count = Eigen::MatrixXf::Zero(how == BlockReduce::Mean ? rows : 0,
                                                  how == BlockReduce::Mean ? cols : 0);
    for (const CellWindow& t : raster.tiles) {
        const CellWindow part = intersection(t, window);
        if (part.nx == 0 || part.ny == 0) continue;
        const EsriAsciiGrid g = raster.samples(part);
        for (int r = 0; r < part.ny; r++)
            for (int c = 0; c < part.nx; c++) {
                const float v = g.heights_m(r, c);
                if (!std::isfinite(v)) continue;
                const int br = (part.iy0 + r - window.iy0) / factor;
                const int bc = (part.ix0 + c - window.ix0) / factor;
                float& o = out.heights_m(br, bc);
                if (how == BlockReduce::Max) {
                    o = std::isfinite(o) ? std::max(o, v) : v;
                } else {
                    const float n = ++count(br, bc);  // running mean: no second pass
                    o = std::isfinite(o) ? o + (v - o) / n : v;
                }
            }
    }
    return out;
}

void checkDenseOutputFits(const CellWindow& cells, double cellSize_m, const std::string& output,
                          const std::string& alternative) {
    if (cells.cellCount() <= kMaxDenseOutputCells) return;
    char text[256];
    std::snprintf(text, sizeof text,
                  ": the map's known area spans %d x %d cells (%.0f m x %.0f m), more than the "
                  "%llu cells a dense raster may hold; ",
                  cells.nx, cells.ny, cells.nx * cellSize_m, cells.ny * cellSize_m,
                  static_cast<unsigned long long>(kMaxDenseOutputCells));
    throw std::invalid_argument(output + text + alternative);
}

}  // namespace multibin
