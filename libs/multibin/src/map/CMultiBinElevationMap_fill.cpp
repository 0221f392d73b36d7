/* Part of the multibin elevation-mapping library.
 * CMultiBinElevationMap: gap filling and the DEM queries that return filled heights.
 *
 * Filling is lazy: insertions only mark the last fill stale, and dem_update_map() (MRPT's hook
 * for "make every observation count") refills the window once, tile by tile (fill::fillSparse:
 * the cost follows the cells near data, not the window). A map read from a file
 * fills itself on its first query (fillIfLoaded()), so it answers as the map that wrote it. Filled
 * cells keep certainty 0; a cell measured after the fill answers with its measurement. */
#include "CMultiBinElevationMap_impl.h"

#include <cmath>
#include <set>
#include <utility>

#include "multibin/fill/BoundedByClearance.h"
#include "multibin/fill/SparseFill.h"
#include "multibin/grid/BinStore.h"

using namespace mrpt::maps;

void CMultiBinElevationMap::dem_update_map() {
    const multibin::MapLock::Exclusive lock(m_impl->lock);
    m_impl->grid.reloadAllTiles();
    if (m_impl->fillStale) fillNow();
}

multibin::fill::SparseHeights CMultiBinElevationMap::fillInput() const {
    prepareForReading();
    const multibin::MapLock::Shared lock(m_impl->lock);
    const multibin::BinGrid& grid = m_impl->grid;
    multibin::fill::SparseHeights in;
    in.lattice = grid.lattice();
    // A cell is measured only where a bin of either grid is: the global grid's tiles, and with
    // the dual grid the global tiles under the local grid's tiles.
    constexpr int kTile = multibin::BinStore::kTileCells;
    std::set<std::pair<int, int>> tiles;  // (ty, tx): row by row
    grid.store().forEachTile([&](int tx, int ty) { tiles.emplace(ty, tx); });
    if (isDualGrid())
        m_impl->local.store().forEachTile([&](int tx, int ty) {
            const multibin::BinGrid& l = m_impl->local;
            const int gx0 = grid.cellIndex(l.cellCenter_m(tx * kTile)),
                      gx1 = grid.cellIndex(l.cellCenter_m(tx * kTile + kTile - 1));
            const int gy0 = grid.cellIndex(l.cellCenter_m(ty * kTile)),
                      gy1 = grid.cellIndex(l.cellCenter_m(ty * kTile + kTile - 1));
            for (int y = multibin::BinStore::tileOf(gy0); y <= multibin::BinStore::tileOf(gy1); y++)
                for (int x = multibin::BinStore::tileOf(gx0); x <= multibin::BinStore::tileOf(gx1);
                     x++)
                    tiles.emplace(y, x);
        });
    in.cells.reserve(tiles.size());               // at most one input tile per tile read
    const Eigen::Vector2d& o = m_impl->origin_m;  // surfaceQuery() takes pose-frame coordinates
    const multibin::CellWindow& w = in.lattice.window;
    for (const auto& [ty, tx] : tiles) {
        const Impl::TileBins bins(*m_impl, tx, ty, isDualGrid());
        const bool inside = Impl::TileBins::wholeInside(w, tx, ty);  // no test per cell then
        bins.forEachHeld(
            tx * kTile, (tx + 1) * kTile, ty * kTile, (ty + 1) * kTile, false,
            [](int, int) { return false; },
            [&](int ix, int iy) {
                double h, s;
                // Without the pose part the cells share (CellSurface::poseVariance_m2): it moves
                // a gap's neighbours together, so it does not weigh one against another.
                if ((inside || w.contains(ix, iy)) &&
                    surfaceQuery(false, o.x() + grid.cellCenter_m(ix),
                                 o.y() + grid.cellCenter_m(iy), h, s, false))
                    in.setMeasured(ix, iy, float(h), float(s));
            });
    }
    return in;
}

void CMultiBinElevationMap::fillNow() const {
    // Tiled: the cost follows the cells near data, not the window (a long route's box).
    const multibin::fill::SparseHeights in = fillInput();
    m_impl->filled = multibin::fill::fillSparse(in, insertionOptions.fill);
    // The lines of sight bound the fill from above; a map read from a file has no clearances.
    const multibin::BinGrid& grid = m_impl->grid;
    multibin::fill::boundByClearance(m_impl->filled, insertionOptions.fill,
                                     [&](int ix, int iy) { return grid.clearance_m(ix, iy); });
    m_impl->fillWindow = in.lattice.window;
    // lastFill()'s raster of the window is built when first asked for: the statistics now.
    m_impl->fill = {};
    m_impl->fill.stats = m_impl->filled.stats;
    m_impl->fillRasterBuilt = false;
    m_impl->fillStale = false;
}

const multibin::fill::FillResult& CMultiBinElevationMap::lastFill() const {
    prepareForReading();
    const multibin::MapLock::Shared lock(m_impl->lock);
    const std::lock_guard<std::mutex> build(m_impl->fillRasterMutex.m);
    if (!m_impl->fillRasterBuilt && m_impl->fillWindow.cellCount() > 0 &&
        m_impl->fillWindow.cellCount() <= kMaxWholeWindowCells) {
        // The measured cells as the queries answer them now (the same as at the fill unless
        // observations came since), the filled ones of the fill.
        m_impl->fill = m_impl->filled.toResult(fillInput());
    }
    m_impl->fillRasterBuilt = true;
    return m_impl->fill;
}

const multibin::fill::FilledCells& CMultiBinElevationMap::lastFilledCells() const {
    prepareForReading();
    return m_impl->filled;
}

void CMultiBinElevationMap::fillIfLoaded() const {
    // Inside another entry point the lock is held: the outermost one has filled, or skipped.
    if (m_impl->lock.heldByThisThread()) return;
    // Bins that no insertion put there came from a file (serialization clears the counts):
    // the map that wrote them had filled its gaps, so this one fills once, on first query.
    auto loadedAndUnfilled = [&] {
        return m_impl->fillStale && m_impl->stats.accepted == 0 && m_impl->grid.binCount() > 0;
    };
    {
        const multibin::MapLock::Shared lock(m_impl->lock);
        if (!loadedAndUnfilled()) return;
    }
    const multibin::MapLock::Exclusive lock(m_impl->lock);
    if (loadedAndUnfilled()) fillNow();
}

CMultiBinElevationMap::HeightSource CMultiBinElevationMap::getElevation(double x_m, double y_m,
                                                                        double& height_m,
                                                                        double& sigma_m,
                                                                        bool includeFilled) const {
    prepareForReading();
    return elevationQuery(
        insertionOptions.query.height_query == TInsertionOptions::TQueryOptions::HeightQuery::Plane,
        x_m, y_m, height_m, sigma_m, includeFilled);
}

CMultiBinElevationMap::HeightSource CMultiBinElevationMap::cellElevation(double x_m, double y_m,
                                                                         double& height_m,
                                                                         double& sigma_m,
                                                                         bool includeFilled) const {
    prepareForReading();
    return elevationQuery(false, x_m, y_m, height_m, sigma_m, includeFilled);
}

CMultiBinElevationMap::HeightSource CMultiBinElevationMap::elevationQuery(
    bool subCell, double x_m, double y_m, double& height_m, double& sigma_m,
    bool includeFilled) const {
    const multibin::MapLock::Shared lock(m_impl->lock);
    const bool measured = surfaceQuery(subCell, x_m, y_m, height_m, sigma_m);
    if (measured) return HeightSource::Measured;
    return includeFilled ? filledQuery(x_m, y_m, height_m, sigma_m) : HeightSource::Unknown;
}

CMultiBinElevationMap::HeightSource CMultiBinElevationMap::filledQuery(double x_m, double y_m,
                                                                       double& height_m,
                                                                       double& sigma_m) const {
    const int ix = m_impl->grid.cellIndex(x_m - m_impl->origin_m.x()),
              iy = m_impl->grid.cellIndex(y_m - m_impl->origin_m.y());
    if (!m_impl->fillWindow.contains(ix, iy)) return HeightSource::Unknown;
    const multibin::fill::FilledCell* f = m_impl->filled.find(ix, iy);
    if (!f) return HeightSource::Unknown;
    height_m = f->height_m;
    sigma_m = f->sigma_m;
    // FilledHarmonic is a surface fill too (eq 16 plus harmonic rim residuals): one value of
    // the source layer for both surface paths.
    return f->source == multibin::HeightSource::FilledMedian ? HeightSource::FilledMedian
                                                             : HeightSource::FilledSurface;
}

bool CMultiBinElevationMap::dem_get_z_by_cell(const size_t cx, const size_t cy,
                                              double& z_out) const {
    prepareForReading();
    const multibin::MapLock::Shared lock(m_impl->lock);
    if (cx >= dem_get_size_x() || cy >= dem_get_size_y()) return false;
    const multibin::CellWindow& w = m_impl->grid.window();
    return dem_get_z(m_impl->origin_m.x() + m_impl->grid.cellCenter_m(w.ix0 + int(cx)),
                     m_impl->origin_m.y() + m_impl->grid.cellCenter_m(w.iy0 + int(cy)), z_out);
}

CMultiBinElevationMap::HeightAnswer CMultiBinElevationMap::height(double x_m, double y_m) const {
    prepareForReading();
    HeightAnswer a;
    double h = 0, s = 0;
    a.source = elevationQuery(
        insertionOptions.query.height_query == TInsertionOptions::TQueryOptions::HeightQuery::Plane,
        x_m, y_m, h, s, insertionOptions.query.dem_return_filled);
    if (a.known()) a.height_m = h, a.sigma_m = s;
    return a;
}

bool CMultiBinElevationMap::dem_get_z(const double x, const double y, double& z_out) const {
    const HeightAnswer a = height(x, y);
    if (a.known()) z_out = a.height_m;
    return a.known();
}
