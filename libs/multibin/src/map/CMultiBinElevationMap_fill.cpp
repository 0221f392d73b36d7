/* Part of the multibin elevation-mapping library.
 * CMultiBinElevationMap: gap filling and the DEM queries that return filled heights.
 *
 * Filling is lazy: insertions only mark the last fill stale, and dem_update_map() (MRPT's hook
 * for "make every observation count") refills the whole window once. A map read from a file
 * fills itself on its first query (fillIfLoaded()), so it answers as the map that wrote it. Filled
 * cells keep certainty 0; a cell measured after the fill answers with its measurement. */
#include "CMultiBinElevationMap_impl.h"

#include <cmath>
#include <iostream>

#include "multibin/fill/GapFilling.h"

using namespace mrpt::maps;

void CMultiBinElevationMap::dem_update_map() {
    const multibin::MapLock::Exclusive lock(m_impl->lock);
    m_impl->grid.reloadTilesNear(0, 0, std::numeric_limits<double>::infinity());
    if (m_impl->fillStale) fillNow();
}

void CMultiBinElevationMap::fillNow() const {
    const multibin::CellWindow w = m_impl->grid.window();
    if (w.cellCount() > kMaxWholeWindowCells) {
        // One raster of the whole window: beyond this, GBs for a route's mostly empty box.
        std::cerr << "CMultiBinElevationMap: gap filling skipped: the window of " << w.nx << " x "
                  << w.ny << " cells is beyond the " << kMaxWholeWindowCells
                  << " cells filled as one raster (long routes); set fill_enabled = false to "
                     "skip it without this message\n";
        m_impl->fill = {};
        m_impl->fillWindow = {};
        m_impl->fillStale = false;
        return;
    }
    multibin::fill::HeightRaster raster(multibin::Lattice{m_impl->grid.cellSize_m(), w});
    const Eigen::Vector2d& o = m_impl->origin_m;  // getHeight() takes pose-frame coordinates
    for (int r = 0; r < w.ny; r++)
        for (int c = 0; c < w.nx; c++) {
            double h, s;
            // Without the pose part the cells share (CellSurface::poseVariance_m2): it moves a
            // gap's neighbours together, so it does not weigh one against another.
            if (surfaceQuery(false, o.x() + m_impl->grid.cellCenter_m(w.ix0 + c),
                             o.y() + m_impl->grid.cellCenter_m(w.iy0 + r), h, s, false))
                raster.setMeasured(c, r, float(h), float(s));
        }
    m_impl->fill = multibin::fill::fillGaps(raster, insertionOptions.fill);
    m_impl->fillWindow = w;
    m_impl->fillStale = false;
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
    return elevationQuery(insertionOptions.height_query == TInsertionOptions::HeightQuery::Plane,
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
    if (m_impl->fill.source.empty()) return HeightSource::Unknown;
    const int ix = m_impl->grid.cellIndex(x_m - m_impl->origin_m.x()),
              iy = m_impl->grid.cellIndex(y_m - m_impl->origin_m.y());
    if (!m_impl->fillWindow.contains(ix, iy)) return HeightSource::Unknown;
    const size_t k = m_impl->fill.index(ix - m_impl->fillWindow.ix0, iy - m_impl->fillWindow.iy0);
    if (!m_impl->fill.isFilled(k)) return HeightSource::Unknown;
    height_m = m_impl->fill.height_m[k];
    sigma_m = m_impl->fill.sigma_m[k];
    // FilledHarmonic is a surface fill too (eq 16 plus harmonic rim residuals): one value of
    // the source layer for both surface paths.
    return m_impl->fill.source[k] == multibin::HeightSource::FilledMedian
               ? HeightSource::FilledMedian
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
    a.source =
        elevationQuery(insertionOptions.height_query == TInsertionOptions::HeightQuery::Plane, x_m,
                       y_m, h, s, insertionOptions.dem_return_filled);
    if (a.known()) a.height_m = h, a.sigma_m = s;
    return a;
}

bool CMultiBinElevationMap::dem_get_z(const double x, const double y, double& z_out) const {
    const HeightAnswer a = height(x, y);
    if (a.known()) z_out = a.height_m;
    return a.known();
}
