/* Part of the multibin elevation-mapping library.
 * CMultiBinElevationMap: the dual grid (a precise local grid and a large global grid that move
 * with the robot).
 *
 * Each observation updates exactly one grid (global: stereo and global_sensor_labels; local: all
 * other sensors), so no datum is ever in both. The local grid is a window that moves with the
 * robot; the global one grows along the route (tiled storage: memory follows the ground seen).
 * Local cells that scroll out are fused into the global grid, which therefore holds everything
 * seen; a local cell that enters starts empty and queries combine it with the global estimate
 * (getHeight), so the same data are never counted twice. */
#include <mrpt/obs/CObservationStereoImages.h>
#include "CMultiBinElevationMap_impl.h"

#include <cmath>
#include <stdexcept>
#include <string>

#include <algorithm>
#include <cmath>

using namespace mrpt::maps;

multibin::BinGrid& CMultiBinElevationMap::gridFor(const mrpt::obs::CObservation& obs) {
    if (!isDualGrid()) return m_impl->grid;
    const auto& labels = insertionOptions.global_sensor_labels;
    const bool global = dynamic_cast<const mrpt::obs::CObservationStereoImages*>(&obs) != nullptr ||
                        std::find(labels.begin(), labels.end(), obs.sensorLabel) != labels.end();
    return global ? m_impl->grid : m_impl->local;
}

void CMultiBinElevationMap::writeBackLocalCell(int ix, int iy) {
    const double x = m_impl->local.cellCenter_m(ix), y = m_impl->local.cellCenter_m(iy);
    const int gx = m_impl->grid.cellIndex(x), gy = m_impl->grid.cellIndex(y);
    if (!m_impl->grid.window().contains(gx, gy)) return;  // beyond the global grid too
    const multibin::BinUpdateParams params = binUpdateParams();
    m_impl->local.forEachBin(ix, iy, [&](const multibin::Bin& b) {
        if (b.certainty > 0) m_impl->grid.fuseBin(gx, gy, b, params);
    });
}

void CMultiBinElevationMap::recenter(double x_m, double y_m) {
    const multibin::MapLock::Exclusive lock(m_impl->lock);
    if (!std::isfinite(x_m) || !std::isfinite(y_m))
        throw std::invalid_argument("CMultiBinElevationMap::recenter: the position (" +
                                    std::to_string(x_m) + ", " + std::to_string(y_m) +
                                    ") is not finite");
    if (!isDualGrid()) return;
    fixOriginNear(x_m, y_m);
    recenterRelative(x_m - m_impl->origin_m.x(), y_m - m_impl->origin_m.y());
}

void CMultiBinElevationMap::recenterRelative(double x_m, double y_m) {
    m_impl->fillStale = true;
    // The global grid first, so that local cells written back land inside it: it grows to cover
    // global_size_m around the robot and keeps everything seen; the local one moves.
    multibin::BinGrid& global = m_impl->grid;
    const int ng = globalSideCells();
    global.growToInclude(multibin::CellWindow{global.cellIndex(x_m) - ng / 2,
                                              global.cellIndex(y_m) - ng / 2, ng, ng});
    multibin::BinGrid& local = m_impl->local;
    const multibin::CellWindow& w = local.window();
    const int ix0 = local.cellIndex(x_m) - w.nx / 2, iy0 = local.cellIndex(y_m) - w.ny / 2;
    if (ix0 != w.ix0 || iy0 != w.iy0)
        local.moveWindowTo(ix0, iy0, [&](int ix, int iy) { writeBackLocalCell(ix, iy); });
}

void CMultiBinElevationMap::flushLocalToGlobal() {
    const multibin::MapLock::Exclusive lock(m_impl->lock);
    if (!isDualGrid()) return;
    const multibin::CellWindow w = m_impl->local.window();
    for (int iy = w.iy0; iy < w.iy0 + w.ny; iy++)
        for (int ix = w.ix0; ix < w.ix0 + w.nx; ix++) {
            writeBackLocalCell(ix, iy);
            m_impl->local.clearCell(ix, iy);
        }
}
