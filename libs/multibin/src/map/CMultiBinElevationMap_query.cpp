/* Part of the multibin elevation-mapping library. */
// mrpt::maps::CMultiBinElevationMap: height queries (the map's surface at a point or a cell) and
// the extent of its window (CHeightGridMap2D_Base's DEM interface).
#include "CMultiBinElevationMap_impl.h"

#include <cmath>

#include "multibin/grid/CellSurface.h"

using namespace mrpt::maps;

bool CMultiBinElevationMap::getHeight(double x_m, double y_m, double& height_m,
                                      double& sigma_m) const {
    const HeightAnswer a = height(x_m, y_m);
    if (a.source != HeightSource::Measured) return false;
    height_m = a.height_m;
    sigma_m = a.sigma_m;
    return true;
}

bool CMultiBinElevationMap::surfaceQuery(bool subCell, double x_m, double y_m, double& height_m,
                                         double& sigma_m, bool sharedPosePart) const {
    const multibin::MapLock::Shared lock(m_impl->lock);
    const Eigen::Vector2d& o = m_impl->origin_m;
    const auto estimate = subCell ? multibin::heightAt : multibin::surfaceAt;
    multibin::CellSurface c;
    if (!estimate(m_impl->grid, isDualGrid() ? &m_impl->local : nullptr, x_m - o.x(), y_m - o.y(),
                  binUpdateParams(), insertionOptions.query.relief_sigma, c))
        return false;
    height_m = c.height_m;
    sigma_m = std::sqrt(sharedPosePart ? c.reportedVariance_m2() : c.variance_m2);
    return true;
}

bool CMultiBinElevationMap::heightAt(double x_m, double y_m, double& height_m,
                                     double& sigma_m) const {
    prepareForReading();
    return surfaceQuery(true, x_m, y_m, height_m, sigma_m);
}

bool CMultiBinElevationMap::cellHeight(double x_m, double y_m, double& height_m,
                                       double& sigma_m) const {
    prepareForReading();
    return surfaceQuery(false, x_m, y_m, height_m, sigma_m);
}

namespace {
// Under the lock: growth moves the window. (A template: Impl is the map's private type.)
template <class Impl>
double lockedWindowEdge_m(Impl& impl, int edge) {
    const multibin::MapLock::Shared lock(impl.lock);
    return impl.windowEdge_m(edge);
}
}  // namespace

double CMultiBinElevationMap::getXMin() const { return lockedWindowEdge_m(*m_impl, 0); }
double CMultiBinElevationMap::getXMax() const { return lockedWindowEdge_m(*m_impl, 1); }
double CMultiBinElevationMap::getYMin() const { return lockedWindowEdge_m(*m_impl, 2); }
double CMultiBinElevationMap::getYMax() const { return lockedWindowEdge_m(*m_impl, 3); }

double CMultiBinElevationMap::dem_get_resolution() const { return m_impl->grid.cellSize_m(); }
size_t CMultiBinElevationMap::dem_get_size_x() const { return size_t(m_impl->grid.window().nx); }
size_t CMultiBinElevationMap::dem_get_size_y() const { return size_t(m_impl->grid.window().ny); }
