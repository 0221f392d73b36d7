/* Part of the multibin elevation-mapping library.
 * CMultiBinElevationMap::heights(): height() at many points, the work of a cell shared by the
 * points that read it (multibin::HeightAtCache) and the lock taken once. */
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "CMultiBinElevationMap_impl.h"
#include "multibin/grid/CellSurface.h"

using namespace mrpt::maps;

namespace {

/** Points sorted at a time: uint32 indices. */
constexpr size_t kChunk = size_t(1) << 20;

/** Cells of `lattice` along one axis. */
struct Range {
    int lo, hi;
};

/** The cells of `lattice` along x (or y) that cover `grid`'s window, and one more each side. */
Range coveringCells(const multibin::BinGrid& lattice, const multibin::BinGrid& grid, bool alongX) {
    const multibin::CellWindow& w = grid.window();
    const int first = alongX ? w.ix0 : w.iy0, count = alongX ? w.nx : w.ny;
    const double half_m = 0.5 * grid.cellSize_m();
    return {lattice.cellIndex(grid.cellCenter_m(first) - half_m) - 1,
            lattice.cellIndex(grid.cellCenter_m(first + count - 1) + half_m) + 1};
}

/** The points in the order that shares heightAt's cells most: by the lower-left one of the four
 * cells of `lattice` around them (whose centres they lie between), rows first, then columns,
 * the given order kept within a cell (two counting sorts). Cells beyond `x`, `y` (the grids'
 * windows) count as the edge: nothing is known there. `xSpan_m`: the columns' span [m]. */
std::vector<uint32_t> cellOrder(const multibin::BinGrid& lattice, Range x, Range y,
                                const double* x_m, const double* y_m, size_t n, double& xSpan_m) {
    const double half_m = 0.5 * lattice.cellSize_m();
    std::vector<int> column(n), row(n);
    Range used{x.hi, x.lo}, usedRows{y.hi, y.lo};
    for (size_t i = 0; i < n; i++) {
        column[i] = std::clamp(lattice.cellIndex(x_m[i] - half_m), x.lo, x.hi);
        row[i] = std::clamp(lattice.cellIndex(y_m[i] - half_m), y.lo, y.hi);
        used = {std::min(used.lo, column[i]), std::max(used.hi, column[i])};
        usedRows = {std::min(usedRows.lo, row[i]), std::max(usedRows.hi, row[i])};
    }
    xSpan_m = (used.hi - used.lo + 1) * lattice.cellSize_m();
    // Stable counting sort of `from` (null: 0 .. n - 1) by key into `to`.
    auto countingSort = [n](const std::vector<int>& key, Range r, const uint32_t* from,
                            uint32_t* to) {
        std::vector<size_t> start(size_t(r.hi - r.lo) + 2, 0);
        for (size_t i = 0; i < n; i++) start[size_t(key[i] - r.lo) + 1]++;
        for (size_t k = 1; k < start.size(); k++) start[k] += start[k - 1];
        for (size_t j = 0; j < n; j++) {
            const uint32_t i = from ? from[j] : uint32_t(j);
            to[start[size_t(key[i] - r.lo)]++] = i;
        }
    };
    std::vector<uint32_t> byColumn(n), order(n);
    countingSort(column, used, nullptr, byColumn.data());
    countingSort(row, usedRows, byColumn.data(), order.data());
    return order;
}

}  // namespace

void CMultiBinElevationMap::heights(const double* x_m, const double* y_m, size_t n,
                                    HeightAnswer* out) const {
    if (n > 0 && (!x_m || !y_m || !out))
        throw std::invalid_argument("CMultiBinElevationMap::heights: x_m, y_m and out must " +
                                    std::string("not be null (n = ") + std::to_string(n) + ")");
    if (n == 1) {  // nothing to share
        out[0] = height(x_m[0], y_m[0]);
        return;
    }
    prepareForReading();
    const multibin::MapLock::Shared lock(m_impl->lock);
    if (insertionOptions.query.height_query !=
        TInsertionOptions::TQueryOptions::HeightQuery::Plane) {
        for (size_t i = 0; i < n; i++) out[i] = height(x_m[i], y_m[i]);  // one cell each
        return;
    }
    const multibin::BinGrid& grid = m_impl->grid;
    const multibin::BinGrid* local = isDualGrid() ? &m_impl->local : nullptr;
    // Sorted by the finer lattice (a dual grid's local one), over both windows.
    const multibin::BinGrid& lattice =
        local && local->cellSize_m() < grid.cellSize_m() ? *local : grid;
    Range x = coveringCells(lattice, grid, true), y = coveringCells(lattice, grid, false);
    if (local) {
        const Range lx = coveringCells(lattice, *local, true);
        const Range ly = coveringCells(lattice, *local, false);
        x = {std::min(x.lo, lx.lo), std::max(x.hi, lx.hi)};
        y = {std::min(y.lo, ly.lo), std::max(y.hi, ly.hi)};
    }
    const Eigen::Vector2d& o = m_impl->origin_m;
    const bool reliefSigma = insertionOptions.query.relief_sigma;
    std::vector<double> xs, ys;  // relative to the origin, as the grids' cells are
    std::vector<std::pair<double, double>> sorted;
    for (size_t b = 0; b < n; b += kChunk) {
        const size_t m = std::min(kChunk, n - b);
        xs.resize(m);
        ys.resize(m);
        for (size_t i = 0; i < m; i++) xs[i] = x_m[b + i] - o.x(), ys[i] = y_m[b + i] - o.y();
        double xSpan_m = 0;
        const std::vector<uint32_t> order =
            cellOrder(lattice, x, y, xs.data(), ys.data(), m, xSpan_m);
        // Gathered in a loop of their own: the loads overlap there, not in the query loop.
        sorted.resize(m);
        for (size_t k = 0; k < m; k++) sorted[k] = {x_m[b + order[k]], y_m[b + order[k]]};
        multibin::HeightAtCache cache(grid, local, binUpdateParams(), xSpan_m);
        for (size_t k = 0; k < m; k++) {
            const auto [xk_m, yk_m] = sorted[k];
            HeightAnswer& a = out[b + order[k]];
            multibin::CellSurface c;
            // As height() answers: surfaceQuery's height and sigma where measured, else the
            // gap filling's (elevationQuery).
            if (cache.heightAt(xk_m - o.x(), yk_m - o.y(), reliefSigma, c)) {
                a = {c.height_m, std::sqrt(c.reportedVariance_m2()), HeightSource::Measured};
                continue;
            }
            double h = 0, s = 0;
            a = HeightAnswer{};
            if (insertionOptions.query.dem_return_filled) a.source = filledQuery(xk_m, yk_m, h, s);
            if (a.known()) a.height_m = h, a.sigma_m = s;
        }
    }
}
