/* Part of the multibin elevation-mapping library. */
#include "multibin/fill/SparseFill.h"

#include <algorithm>
#include <array>
#include <climits>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <ctime>
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

/** The numbers of the tiles of a TiledCells by cell, through a small cache of the tiles found
 * last: a flood stays in a few tiles (along a tile border it steps between two at every cell),
 * where a hash lookup per step would cost much of the flood. Tile numbers never change, so the
 * cache holds while tiles are added. */
template <typename Lookup>
class TileNumbers {
public:
    explicit TileNumbers(Lookup lookup) : m_lookup(std::move(lookup)) {}
    /** The number of cell (ix, iy)'s tile: what Lookup(tx, ty) answers (-1: none). */
    long of(int ix, int iy) {
        const int tx = ix >> TiledCells<int>::kShift, ty = iy >> TiledCells<int>::kShift;
        Entry& e = m_cache[(unsigned(tx) * 3u + unsigned(ty)) & (kEntries - 1)];
        if (!e.valid || e.tx != tx || e.ty != ty) e = {tx, ty, m_lookup(tx, ty), true};
        return e.number;
    }

private:
    static constexpr unsigned kEntries = 16;
    struct Entry {
        int tx = 0, ty = 0;
        long number = -1;
        bool valid = false;
    };
    Lookup m_lookup;
    std::array<Entry, kEntries> m_cache{};
};

/** Which cells of a tile are measured, a bit a cell (row iy % kSide, bit ix % kSide). */
using TileBits = std::array<uint64_t, TiledCells<int>::kSide>;

/** The measured cells of in's tiles, by tile number: read once (512 B a tile against the cells'
 * 48 kB) for the count and the floods, which test every neighbour they reach. */
std::vector<TileBits> measuredBits(const SparseHeights& in) {
    constexpr size_t kSide = TiledCells<int>::kSide;
    std::vector<TileBits> bits(in.cells.tileCount());
    size_t number = 0;
    in.cells.forEachTile([&](int, int, const MeasuredCell* t) {
        TileBits& b = bits[number++];
        for (size_t k = 0; k < TiledCells<MeasuredCell>::kTileCells; k++)
            b[k / kSide] |= uint64_t(measuredCell(t[k])) << (k % kSide);
    });
    return bits;
}

/** The measured cells inside in's window. */
size_t measuredInWindow(const SparseHeights& in, const std::vector<TileBits>& bits) {
    constexpr int kSide = TiledCells<int>::kSide;
    const CellWindow& w = in.lattice.window;
    size_t measured = 0, number = 0;
    in.cells.forEachTile([&](int tx, int ty, const MeasuredCell*) {
        const TileBits& b = bits[number++];
        const int x0 = tx * kSide, y0 = ty * kSide;
        const bool inside = w.contains(x0, y0) && w.contains(x0 + kSide - 1, y0 + kSide - 1);
        for (int r = 0; r < kSide; r++)
            if (inside)
                measured += size_t(__builtin_popcountll(b[size_t(r)]));
            else
                for (uint64_t row = b[size_t(r)]; row != 0; row &= row - 1)
                    measured += w.contains(x0 + __builtin_ctzll(row), y0 + r);
    });
    return measured;
}

/** What the floods know of an unmeasured cell, a byte a cell (a tile of labels is 4 kB). */
enum class Label : int8_t { Unvisited, Flooding, Large, InAGap };

/** One gap: its cells (absolute), row by row. */
using GapCells = std::vector<std::array<int, 2>>;  // (iy, ix): sorts row-major

/** The gaps of at most o.maxGapCells cells, in the whole-window path's label order (by first
 * cell, row-major), each sorted row-major. Counts the floods' cells and the larger regions. */
std::vector<GapCells> findGaps(const SparseHeights& in, const std::vector<TileBits>& measuredBits,
                               const FillOptions& o, FillResult::Stats& s) {
    const CellWindow& w = in.lattice.window;
    constexpr int kSide = TiledCells<int>::kSide;
    TiledCells<Label> label(Label::Unvisited);
    // Room for the data's tiles and as many around them (reserved, not touched: a tile added
    // beyond it would copy every label tile into fresh pages).
    label.reserve(2 * in.cells.tileCount() + 16);
    TileNumbers dataTiles([&](int tx, int ty) { return in.cells.findTileNumber(tx, ty); });
    TileNumbers labelTiles([&](int tx, int ty) { return long(label.tileNumber(tx, ty)); });
    // Cell (ix, iy), in the data's tile number n (-1: none), is measured.
    auto measuredIn = [&](long n, int ix, int iy) {
        return n >= 0 &&
               (measuredBits[size_t(n)][size_t(iy & (kSide - 1))] >> (ix & (kSide - 1)) & 1) != 0;
    };
    auto measured = [&](int ix, int iy) { return measuredIn(dataTiles.of(ix, iy), ix, iy); };
    auto labelOf = [&](int ix, int iy) -> Label& {
        return label.tileCells(size_t(labelTiles.of(ix, iy)))[TiledCells<Label>::inTile(ix, iy)];
    };
    // A tile without data whole inside the window is kTileCells connected unmeasured cells: a
    // flood that enters one is in a region larger than maxGapCells when kTileCells is, and stops
    // there instead of flooding maxGapCells cells first (the open sides of a wall).
    const bool emptyTileIsLarge = TiledCells<int>::kTileCells > size_t(o.maxGapCells);
    auto inEmptyWholeTile = [&](int ix, int iy) {
        if (!emptyTileIsLarge || dataTiles.of(ix, iy) >= 0) return false;
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
        labelOf(x0, y0) = Label::Flooding;
        bool large = false;
        for (size_t head = 0; head < members.size() && !large; head++) {
            const auto [y, x] = members[head];
            // A neighbour in the cell's own tile (most) reuses what was found of the tile.
            const long dataNumber = dataTiles.of(x, y);
            const size_t labelNumber = size_t(labelTiles.of(x, y));
            const bool ownTileEmptyWhole = inEmptyWholeTile(x, y);
            const int cx = x & (kSide - 1), cy = y & (kSide - 1);
            const int nb[4][2] = {{x - 1, y}, {x + 1, y}, {x, y - 1}, {x, y + 1}};
            const bool ownTile[4] = {(cx > 0), (cx < kSide - 1), (cy > 0), (cy < kSide - 1)};
            for (int k = 0; k < 4; k++) {
                const int px = nb[k][0], py = nb[k][1];
                if (!w.contains(px, py)) continue;
                if (measuredIn(ownTile[k] ? dataNumber : dataTiles.of(px, py), px, py)) continue;
                if (ownTile[k] ? ownTileEmptyWhole : inEmptyWholeTile(px, py)) {
                    large = true;  // no label: its tile is not allocated
                    continue;
                }
                const size_t n = ownTile[k] ? labelNumber : size_t(labelTiles.of(px, py));
                Label& l = label.tileCells(n)[TiledCells<Label>::inTile(px, py)];
                if (l == Label::Large) large = true;  // part of a region already found too large
                if (l != Label::Unvisited) continue;
                l = Label::Flooding;
                members.push_back({py, px});
            }
            large |= members.size() > size_t(o.maxGapCells);
        }
        s.cellsVisited += members.size();
        s.gapComponents++;
        if (large) {  // stays Unknown; its cells stop the floods that reach them
            for (const auto& m : members) labelOf(m[1], m[0]) = Label::Large;
            return;
        }
        for (const auto& m : members) labelOf(m[1], m[0]) = Label::InAGap;
        std::sort(members.begin(), members.end());
        gaps.push_back(members);
    };
    // Every gap touches a measured cell (the window is connected): seed from their neighbours.
    size_t number = 0;
    in.cells.forEachTile([&](int tx, int ty, const MeasuredCell*) {
        const std::array<uint64_t, kSide>& bits = measuredBits[number++];
        for (int r = 0; r < kSide; r++)  // the measured cells row by row, west to east
            for (uint64_t row = bits[size_t(r)]; row != 0; row &= row - 1) {
                const int x = tx * kSide + __builtin_ctzll(row), y = ty * kSide + r;
                if (!w.contains(x, y)) continue;
                const int nb[4][2] = {{x - 1, y}, {x + 1, y}, {x, y - 1}, {x, y + 1}};
                for (const auto& p : nb)
                    if (w.contains(p[0], p[1]) && !measured(p[0], p[1]) &&
                        labelOf(p[0], p[1]) == Label::Unvisited)
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
    const std::vector<TileBits> bits = measuredBits(in);
    const size_t measured = measuredInWindow(in, bits);
    size_t filled[5] = {};  // per HeightSource
    if (o.enabled)
        for (const GapCells& g : findGaps(in, bits, o, out.stats)) {
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
