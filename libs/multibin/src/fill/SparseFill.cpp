/* Part of the multibin elevation-mapping library. */
#include "multibin/fill/SparseFill.h"

#include <algorithm>
#include <array>
#include <climits>
#include <cmath>
#include <stdexcept>
#include <type_traits>
#include <utility>

#include "multibin/fill/GapLabelling.h"
#include "multibin/fill/detail/MedianFiller.h"
#include "multibin/fill/detail/OneGap.h"
#include "multibin/fill/detail/ResultSetup.h"

namespace multibin::fill {

namespace {

bool measuredCell(const MeasuredCell& c) {
    return c.certainty > 0 && std::isfinite(c.height_m) && std::isfinite(c.sigma_m) &&
           c.sigma_m > 0;
}

/** Reads cells of a TiledCells, keeping the last tile found: a flood stays in one tile mostly.
 * The pointer kept stays valid: only this cursor adds tiles, and only when it moves to one. */
template <typename Cells, typename TilePtr>
class Cursor {
public:
    explicit Cursor(Cells& c) : m_c(c) {}
    /** Cell (ix, iy)'s tile, allocated if `Cells` is writable; nullptr if absent (read only). */
    TilePtr tileOf(int ix, int iy) {
        const int tx = ix >> TiledCells<int>::kShift, ty = iy >> TiledCells<int>::kShift;
        if (tx != m_tx || ty != m_ty || !m_valid) {
            m_tx = tx, m_ty = ty, m_valid = true;
            if constexpr (std::is_const_v<Cells>)
                m_tile = m_c.findTile(tx, ty);
            else
                m_tile = m_c.tile(tx, ty);
        }
        return m_tile;
    }

private:
    Cells& m_c;
    int m_tx = 0, m_ty = 0;
    bool m_valid = false;
    TilePtr m_tile = nullptr;
};

constexpr int kUnvisited = -1, kLarge = -2, kFlooding = -3;

/** One gap: its cells (absolute), row by row. */
using GapCells = std::vector<std::array<int, 2>>;  // (iy, ix): sorts row-major

/** The gaps of at most o.maxGapCells cells, in the whole-window path's label order (by first
 * cell, row-major), each sorted row-major. Counts the floods' cells and the larger regions. */
std::vector<GapCells> findGaps(const SparseHeights& in, const FillOptions& o,
                               FillResult::Stats& s) {
    const CellWindow& w = in.lattice.window;
    TiledCells<int> label(kUnvisited);
    label.reserve(in.cells.tileCount());  // the floods stay in the data's tiles, mostly
    Cursor<const TiledCells<MeasuredCell>, const MeasuredCell*> data(in.cells);
    Cursor<TiledCells<int>, int*> labels(label);
    auto measured = [&](int ix, int iy) {
        const auto* t = data.tileOf(ix, iy);
        return t && measuredCell(t[TiledCells<int>::inTile(ix, iy)]);
    };
    auto labelOf = [&](int ix, int iy) -> int& {
        return labels.tileOf(ix, iy)[TiledCells<int>::inTile(ix, iy)];
    };
    // A tile without data whole inside the window is kTileCells connected unmeasured cells: a
    // flood that enters one is in a region larger than maxGapCells when kTileCells is, and stops
    // there instead of flooding maxGapCells cells first (the open sides of a wall).
    const bool emptyTileIsLarge = TiledCells<int>::kTileCells > size_t(o.maxGapCells);
    constexpr int kSide = TiledCells<int>::kSide;
    auto inEmptyWholeTile = [&](int ix, int iy) {
        if (!emptyTileIsLarge || data.tileOf(ix, iy)) return false;
        const int x0 = (ix >> TiledCells<int>::kShift) * kSide,
                  y0 = (iy >> TiledCells<int>::kShift) * kSide;
        return w.contains(x0, y0) && w.contains(x0 + kSide - 1, y0 + kSide - 1);
    };
    std::vector<GapCells> gaps;
    GapCells members;
    auto flood = [&](int x0, int y0) {
        // Breadth first: a region too large is marked as a compact blob around the seed, which
        // the floods from the next seeds along the same rim meet at once.
        members.assign(1, {y0, x0});
        labelOf(x0, y0) = kFlooding;
        bool large = false;
        for (size_t head = 0; head < members.size() && !large; head++) {
            const auto [y, x] = members[head];
            const int nb[4][2] = {{x - 1, y}, {x + 1, y}, {x, y - 1}, {x, y + 1}};
            for (const auto& p : nb) {
                if (!w.contains(p[0], p[1]) || measured(p[0], p[1])) continue;
                if (inEmptyWholeTile(p[0], p[1])) {  // no label: its tile is not allocated
                    large = true;
                    continue;
                }
                int& l = labelOf(p[0], p[1]);
                if (l == kLarge) large = true;  // part of a region already found too large
                if (l != kUnvisited) continue;
                l = kFlooding;
                members.push_back({p[1], p[0]});
            }
            large |= members.size() > size_t(o.maxGapCells);
        }
        s.cellsVisited += members.size();
        s.gapComponents++;
        if (large) {  // stays Unknown; its cells stop the floods that reach them
            for (const auto& m : members) labelOf(m[1], m[0]) = kLarge;
            return;
        }
        for (const auto& m : members) labelOf(m[1], m[0]) = int(gaps.size());
        std::sort(members.begin(), members.end());
        gaps.push_back(members);
    };
    // Every gap touches a measured cell (the window is connected): seed from their neighbours.
    in.cells.forEachTile([&](int tx, int ty, const MeasuredCell* t) {
        for (size_t k = 0; k < TiledCells<MeasuredCell>::kTileCells; k++) {
            if (!measuredCell(t[k])) continue;
            const int x = tx * TiledCells<int>::kSide + int(k % TiledCells<int>::kSide);
            const int y = ty * TiledCells<int>::kSide + int(k / TiledCells<int>::kSide);
            if (!w.contains(x, y)) continue;
            const int nb[4][2] = {{x - 1, y}, {x + 1, y}, {x, y - 1}, {x, y + 1}};
            for (const auto& p : nb)
                if (w.contains(p[0], p[1]) && !measured(p[0], p[1]) &&
                    labelOf(p[0], p[1]) == kUnvisited)
                    flood(p[0], p[1]);
        }
    });
    std::sort(gaps.begin(), gaps.end(),
              [](const GapCells& a, const GapCells& b) { return a.front() < b.front(); });
    return gaps;
}

/** The raster around a gap that holds every cell the per-gap code (detail::fillGap) reads, clipped
 * to the window exactly as the whole-window raster is clipped. For the median alone
 * (`surface` false): the median window's half side. Otherwise also the support square (side =
 * the box's longer side + 2 supportMargin_cells, centred, slid inside the raster: it stays within
 * side - (box width) of the box on either axis), the shadow test (the rim's 5 x 5 planes and the
 * occluders' tops within shadowOccluders.reach_cells of the rim, ShadowOccluders.h) and the
 * biharmonic stencil (2 cells). */
CellWindow gapRaster(const GapCells& g, const CellWindow& w, const FillOptions& o, bool surface) {
    int x0 = INT_MAX, x1 = INT_MIN;
    const int y0 = g.front()[0], y1 = g.back()[0];
    for (const auto& c : g) x0 = std::min(x0, c[1]), x1 = std::max(x1, c[1]);
    const int bw = x1 - x0 + 1, bh = y1 - y0 + 1;
    const int side = std::max(bw, bh) + 2 * o.supportMargin_cells;
    const int reach =
        std::max(o.medianWindow_cells / 2, surface ? o.shadowOccluders.reach_cells + 4 : 0);
    const int mx = surface ? std::max(side - bw, reach) : reach;
    const int my = surface ? std::max(side - bh, reach) : reach;
    const int xa = std::max(x0 - mx, w.ix0), xb = std::min(x1 + mx + 1, w.ix0 + w.nx);
    const int ya = std::max(y0 - my, w.iy0), yb = std::min(y1 + my + 1, w.iy0 + w.ny);
    return CellWindow{xa, ya, xb - xa, yb - ya};
}

/** Gap `g`'s cells as indices of raster `rw`. */
Gap onRaster(const GapCells& g, const CellWindow& rw) {
    Gap gap;
    gap.cells.reserve(g.size());
    for (const auto& c : g) gap.cells.push_back((c[0] - rw.iy0) * rw.nx + (c[1] - rw.ix0));
    return gap;
}

/** Adds one gap's statistics (detail::fillGap's, on a raster of its own) to the run's. */
void addGapStats(FillResult::Stats& to, const FillResult::Stats& g) {
    to.supportAreas += g.supportAreas;
    to.termsChosen.insert(to.termsChosen.end(), g.termsChosen.begin(), g.termsChosen.end());
    to.movingNeighbourhoods += g.movingNeighbourhoods;
    to.rimCheckHarmonic += g.rimCheckHarmonic;
    to.rimCheckTerms.insert(to.rimCheckTerms.end(), g.rimCheckTerms.begin(), g.rimCheckTerms.end());
    to.shadowGaps += g.shadowGaps;
    to.shadowCells += g.shadowCells;
}

int saturated(size_t n) { return int(std::min<size_t>(n, INT_MAX)); }

}  // namespace

void SparseHeights::setMeasured(int ix, int iy, float h, float s, float c) {
    MeasuredCell& m = cells.at(ix, iy);
    m.height_m = h;
    m.sigma_m = s;
    m.certainty = c > 0 ? c : 1.0f;
}

bool SparseHeights::isMeasured(int ix, int iy) const {
    return lattice.window.contains(ix, iy) && measuredCell(cells.get(ix, iy));
}

HeightRaster SparseHeights::toRaster(const CellWindow& w) const {
    HeightRaster r(Lattice{lattice.cellSize_m, w});
    // Tile by tile: only the tiles that hold data are read.
    const int k = TiledCells<MeasuredCell>::kShift;
    for (int ty = w.iy0 >> k; ty <= (w.iy0 + w.ny - 1) >> k && w.nx > 0; ty++)
        for (int tx = w.ix0 >> k; tx <= (w.ix0 + w.nx - 1) >> k; tx++) {
            const auto* t = cells.findTile(tx, ty);
            if (!t) continue;
            // Multiplied, not shifted: tile indices are negative left of the origin.
            const int side = 1 << k;
            const int xa = std::max(tx * side, w.ix0), xb = std::min((tx + 1) * side, w.ix0 + w.nx);
            const int ya = std::max(ty * side, w.iy0), yb = std::min((ty + 1) * side, w.iy0 + w.ny);
            for (int iy = ya; iy < yb; iy++)
                for (int ix = xa; ix < xb; ix++) {
                    const MeasuredCell& c = t[TiledCells<MeasuredCell>::inTile(ix, iy)];
                    if (!lattice.window.contains(ix, iy)) continue;
                    const size_t q = r.index(ix - w.ix0, iy - w.iy0);
                    r.height_m[q] = c.height_m, r.sigma_m[q] = c.sigma_m;
                    r.certainty[q] = c.certainty;
                }
        }
    return r;
}

FillResult FilledCells::toResult(const SparseHeights& in) const {
    // In one pass over the window (no HeightRaster of it): the filled cells, then the measured
    // ones from in's tiles (disjoint after a fill; a cell measured since answers with its
    // measurement, as the queries do).
    FillResult out;
    out.lattice = lattice;
    out.height_m.assign(lattice.cellCount(), detail::kNaN);
    out.sigma_m.assign(lattice.cellCount(), detail::kNaN);
    out.source.assign(lattice.cellCount(), HeightSource::Unknown);
    const CellWindow& w = lattice.window;
    constexpr int kSide = TiledCells<MeasuredCell>::kSide;
    forEachFilled([&](int ix, int iy, const FilledCell& c) {
        const size_t k = out.index(ix - w.ix0, iy - w.iy0);
        out.height_m[k] = c.height_m, out.sigma_m[k] = c.sigma_m, out.source[k] = c.source;
    });
    in.cells.forEachTile([&](int tx, int ty, const MeasuredCell* t) {
        for (size_t k = 0; k < TiledCells<MeasuredCell>::kTileCells; k++) {
            const int ix = tx * kSide + int(k) % kSide, iy = ty * kSide + int(k) / kSide;
            if (!measuredCell(t[k]) || !w.contains(ix, iy)) continue;
            const size_t q = out.index(ix - w.ix0, iy - w.iy0);
            out.height_m[q] = t[k].height_m, out.sigma_m[q] = t[k].sigma_m;
            out.source[q] = HeightSource::Measured;
        }
    });
    out.stats = stats;
    return out;
}

FilledCells fillSparse(const SparseHeights& in, const FillOptions& o) {
    o.validate();
    if (!(in.lattice.cellSize_m > 0) || !std::isfinite(in.lattice.cellSize_m))
        throw std::invalid_argument("SparseHeights.lattice.cellSize_m: must be positive [m]");
    FilledCells out;
    out.lattice = in.lattice;
    const CellWindow& w = in.lattice.window;
    size_t measured = 0;
    constexpr int kSide = TiledCells<MeasuredCell>::kSide;
    in.cells.forEachTile([&](int tx, int ty, const MeasuredCell* t) {
        for (size_t k = 0; k < TiledCells<MeasuredCell>::kTileCells; k++)
            measured += measuredCell(t[k]) &&
                        w.contains(tx * kSide + int(k) % kSide, ty * kSide + int(k) / kSide);
    });
    size_t filled[5] = {};  // per HeightSource
    if (o.enabled)
        for (const GapCells& g : findGaps(in, o, out.stats)) {
            // The median's small raster first; the surface's larger one if the median does not
            // reach the whole gap.
            CellWindow rw = gapRaster(g, w, o, false);
            HeightRaster r = in.toRaster(rw);
            Gap gap = onRaster(g, rw);
            gap.medianReach = medianReaches(r, gap.cells, o);
            if (!gap.medianReach) {
                out.stats.cellsVisited += r.size();
                rw = gapRaster(g, w, o, true);
                r = in.toRaster(rw);
                gap.cells = onRaster(g, rw).cells;
            }
            out.stats.cellsVisited += r.size();
            std::vector<char> usable;
            FillResult local = detail::initResult(r, usable);
            detail::MedianFiller median(r, o);
            detail::fillGap(r, o, gap, usable, median, local);
            addGapStats(out.stats, local.stats);
            for (size_t c = 0; c < g.size(); c++) {
                const size_t k = size_t(gap.cells[c]);
                if (!local.isFilled(k)) continue;
                out.cells.at(g[c][1], g[c][0]) = {local.height_m[k], local.sigma_m[k],
                                                  local.source[k]};
                filled[size_t(local.source[k])]++;
            }
        }
    auto& s = out.stats;
    s.measured = saturated(measured);
    s.median = saturated(filled[size_t(HeightSource::FilledMedian)]);
    s.harmonic = saturated(filled[size_t(HeightSource::FilledHarmonic)]);
    s.gaussian = saturated(filled[size_t(HeightSource::FilledSurface)]) + s.harmonic;
    s.unfilled = saturated(w.cellCount() - measured - size_t(s.median) - size_t(s.gaussian));
    return out;
}

}  // namespace multibin::fill
