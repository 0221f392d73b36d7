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

RasterReadCounters& rasterReadCounters() {
    thread_local RasterReadCounters counters;
    return counters;
}

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
    if (knownSamples) {  // sparse: every known sample once
        int x0 = std::numeric_limits<int>::max(), y0 = x0, x1 = std::numeric_limits<int>::min(),
            y1 = x1;
        for (const CellWindow& t : tiles)
            knownSamples(t, t, [&](int ix, int iy, float v) {
                if (!std::isfinite(v)) return;
                x0 = std::min(x0, ix), x1 = std::max(x1, ix);
                y0 = std::min(y0, iy), y1 = std::max(y1, iy);
            });
        if (x1 < x0) return {};
        return CellWindow{x0, y0, x1 - x0 + 1, y1 - y0 + 1};
    }
    // Per tile, read once: the box of its known samples {x0, y0, x1, y1}, or none.
    struct Box {
        bool read = false, any = false;
        int x0 = 0, y0 = 0, x1 = 0, y1 = 0;
    };
    std::vector<Box> boxes(tiles.size());
    int x0 = std::numeric_limits<int>::max(), y0 = x0, x1 = std::numeric_limits<int>::min(),
        y1 = x1;
    const auto read = [&](size_t k) {
        Box& b = boxes[k];
        if (b.read) return;
        b.read = true;
        const CellWindow& t = tiles[k];
        const EsriAsciiGrid g = samples(t);
        for (int r = 0; r < g.rows(); r++)
            for (int c = 0; c < g.cols(); c++)
                if (std::isfinite(g.heights_m(r, c))) {
                    if (!b.any) b = {true, true, t.ix0 + c, t.iy0 + r, t.ix0 + c, t.iy0 + r};
                    b.x0 = std::min(b.x0, t.ix0 + c), b.x1 = std::max(b.x1, t.ix0 + c);
                    b.y0 = std::min(b.y0, t.iy0 + r), b.y1 = std::max(b.y1, t.iy0 + r);
                }
        if (b.any)
            x0 = std::min(x0, b.x0), y0 = std::min(y0, b.y0), x1 = std::max(x1, b.x1),
            y1 = std::max(y1, b.y1);
    };
    // From each side inwards: key(t) is how far tile t reaches that way (smaller: further), and
    // once a tile reaches no further than the edge found, the tiles after it cannot either.
    std::vector<size_t> order(tiles.size());
    for (int side = 0; side < 4; side++) {
        const auto key = [side](const CellWindow& t) {
            return side == 0   ? t.ix0
                   : side == 1 ? t.iy0
                   : side == 2 ? -(t.ix0 + t.nx - 1)
                               : -(t.iy0 + t.ny - 1);
        };
        const auto edge = [&] { return side == 0 ? x0 : side == 1 ? y0 : side == 2 ? -x1 : -y1; };
        for (size_t k = 0; k < order.size(); k++) order[k] = k;
        std::sort(order.begin(), order.end(),
                  [&](size_t a, size_t b) { return key(tiles[a]) < key(tiles[b]); });
        for (const size_t k : order) {
            if (x1 >= x0 && key(tiles[k]) >= edge()) break;
            read(k);
        }
    }
    if (x1 < x0) return {};
    return CellWindow{x0, y0, x1 - x0 + 1, y1 - y0 + 1};
}

int blockFactorFor(const CellWindow& window, int maxSide_px) {
    const int side = std::max(window.nx, window.ny);
    return std::max(1, (side + maxSide_px - 1) / std::max(1, maxSide_px));
}

std::vector<EsriAsciiGrid> blockReduced(const std::vector<TiledRaster>& rasters,
                                        const CellWindow& window, int factor,
                                        const std::vector<BlockReduce>& how) {
    if (factor < 1) throw std::invalid_argument("blockReduced: the block side must be >= 1");
    if (rasters.empty() || how.size() != rasters.size())
        throw std::invalid_argument("blockReduced: one way of merging per raster");
    const int cols = (window.nx + factor - 1) / factor, rows = (window.ny + factor - 1) / factor;
    const TiledRaster& first = rasters.front();
    EsriAsciiGrid blank;
    blank.cellsize_m = first.cellSize_m * factor;
    // A block's sample sits at the block's centre (a partial last block included: its centre
    // as if whole, so the lattice stays regular).
    blank.xllcenter_m = first.originX_m + window.ix0 * first.cellSize_m + 0.5 * blank.cellsize_m;
    blank.yllcenter_m = first.originY_m + window.iy0 * first.cellSize_m + 0.5 * blank.cellsize_m;
    std::vector<EsriAsciiGrid> out(rasters.size(), blank);
    for (EsriAsciiGrid& o : out)
        o.heights_m.setConstant(rows, cols, std::numeric_limits<float>::quiet_NaN());
    // Per mean raster of blocks larger than one cell: samples per block. A block of one cell
    // takes its one sample: no counts (a raster's worth of memory, first touched here).
    std::vector<Eigen::MatrixXf> counts(rasters.size());
    for (size_t k = 0; k < rasters.size(); k++)
        if (how[k] == BlockReduce::Mean && factor > 1) counts[k].setZero(rows, cols);
    for (const CellWindow& t : first.tiles) {
        const CellWindow part = intersection(t, window);
        if (part.nx == 0 || part.ny == 0) continue;
        for (size_t k = 0; k < rasters.size(); k++) {
            EsriAsciiGrid& o = out[k];
            const auto add = [&](int ix, int iy, float v) {
                if (!std::isfinite(v)) return;
                const int br = (iy - window.iy0) / factor, bc = (ix - window.ix0) / factor;
                float& b = o.heights_m(br, bc);
                if (how[k] == BlockReduce::Max) {
                    b = std::isfinite(b) ? std::max(b, v) : v;
                } else if (factor == 1) {
                    b = v;
                } else {
                    const float n = ++counts[k](br, bc);  // running mean: one pass
                    b = n == 1 ? v : b + (v - b) / n;
                }
            };
            if (rasters[k].knownSamples) {  // the same samples in the same order, sparse
                rasters[k].knownSamples(t, part, add);
                continue;
            }
            const EsriAsciiGrid g = rasters[k].samples(part);
            for (int r = 0; r < part.ny; r++)
                for (int c = 0; c < part.nx; c++)
                    add(part.ix0 + c, part.iy0 + r, g.heights_m(r, c));
        }
    }
    return out;
}

EsriAsciiGrid blockReduced(const TiledRaster& raster, const CellWindow& window, int factor,
                           BlockReduce how) {
    return std::move(blockReduced(std::vector<TiledRaster>{raster}, window, factor, {how}).front());
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
