/* Part of the multibin elevation-mapping library. */
#include <mrpt/config/CConfigFile.h>
#include <mrpt/maps/TMetricMapTypesRegistry.h>
#include <mrpt/rtti/CObject.h>
#include "CMultiBinElevationMap_impl.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <iostream>
#include <optional>
#include <sstream>
#include <stdexcept>
#include <tuple>
#include <utility>

#include "multibin/map/MapStatistics.h"

using namespace mrpt::maps;

// "multiBinElevationMap" is the name used in CMultiMetricMap ini files
// (multiBinElevationMap_count).
MAP_DEFINITION_REGISTER("mrpt::maps::CMultiBinElevationMap,multiBinElevationMap",
                        mrpt::maps::CMultiBinElevationMap)

IMPLEMENTS_SERIALIZABLE(CMultiBinElevationMap, CMetricMap, mrpt::maps)

// Register with MRPT's class registry when the library loads, so polymorphic deserialization
// (CArchive::ReadObject) finds the class in any program that loads the library. A C++ dynamic
// initialiser placed after IMPLEMENTS_SERIALIZABLE runs after the class id it reads (same
// translation unit, in order); MRPT_INITIALIZER (a constructor attribute) may run before it with
// clang, which then registers a null class name.
namespace {
const bool kClassRegistered =
    (mrpt::rtti::registerClass(CLASS_ID(mrpt::maps::CMultiBinElevationMap)), true);
}  // namespace

namespace multibin {
void registerMultiBinElevationMap() {
    // Registration happens at load time; naming this function forces the library to be linked.
    mrpt::rtti::registerClass(CLASS_ID(mrpt::maps::CMultiBinElevationMap));
}
}  // namespace multibin

// ---------------------------------------------------------------------------------------------
// Construction, statistics, clearing
// ---------------------------------------------------------------------------------------------
CMultiBinElevationMap::CMultiBinElevationMap() : m_impl(std::make_unique<Impl>()) {
    setCreationOptions(TCreationOptions());
}

CMultiBinElevationMap::CMultiBinElevationMap(const TCreationOptions& creation)
    : m_impl(std::make_unique<Impl>()) {
    setCreationOptions(creation);
}

CMultiBinElevationMap::CMultiBinElevationMap(const CMultiBinElevationMap& other)
    : CMetricMap(other),
      CHeightGridMap2D_Base(other),
      creationOptions(other.creationOptions),
      insertionOptions(other.insertionOptions),
      traversabilityOptions(other.traversabilityOptions),
      m_impl(std::make_unique<Impl>(*other.m_impl)) {}

CMultiBinElevationMap& CMultiBinElevationMap::operator=(const CMultiBinElevationMap& other) {
    if (this == &other) return *this;
    CMetricMap::operator=(other);
    CHeightGridMap2D_Base::operator=(other);
    creationOptions = other.creationOptions;
    insertionOptions = other.insertionOptions;
    traversabilityOptions = other.traversabilityOptions;
    *m_impl = *other.m_impl;
    return *this;
}

CMultiBinElevationMap::~CMultiBinElevationMap() = default;

const multibin::BinGrid& CMultiBinElevationMap::grid() const {
    prepareForReading();
    return m_impl->grid;
}
const multibin::BinGrid& CMultiBinElevationMap::localGrid() const {
    prepareForReading();
    return m_impl->local;
}
bool CMultiBinElevationMap::fillIsStale() const { return m_impl->fillStale; }
multibin::MapStatistics CMultiBinElevationMap::statistics() const {
    const multibin::MapLock::Shared lock(m_impl->lock);
    return {m_impl->stats,         m_impl->visibilityStats, m_impl->sensorState.stats,
            m_impl->poseFallbacks, m_impl->skippedByLabel,  m_impl->nonFinitePoses};
}
void CMultiBinElevationMap::setCreationOptions(const TCreationOptions& creation) {
    const multibin::MapLock::Exclusive lock(m_impl->lock);
    creation.validate();
    creationOptions = creation;
    internal_clear();
}

int CMultiBinElevationMap::globalSideCells() const {
    const auto& c = creationOptions;
    return std::max(1, static_cast<int>(std::lround(c.global_size_m / c.global_resolution_m)));
}

void CMultiBinElevationMap::internal_clear() {
    const multibin::MapLock::Exclusive lock(m_impl->lock);
    const auto& c = creationOptions;
    const std::optional<mrpt::math::TPoint2D> origin = c.originBeforeData();
    m_impl->originFixed = origin.has_value();
    m_impl->origin_m = origin ? Eigen::Vector2d(origin->x, origin->y) : Eigen::Vector2d(0, 0);
    const Eigen::Vector2d& o = m_impl->origin_m;
    multibin::CellWindow w;
    const double res = c.resolution_m;
    if (c.max_x > c.min_x && c.max_y > c.min_y) {
        w.ix0 = static_cast<int>(std::floor((c.min_x - o.x()) / res));
        w.iy0 = static_cast<int>(std::floor((c.min_y - o.y()) / res));
        w.nx = static_cast<int>(std::ceil((c.max_x - o.x()) / res)) - w.ix0;
        w.ny = static_cast<int>(std::ceil((c.max_y - o.y()) / res)) - w.iy0;
    }
    if (c.dual_grid) {
        // Robot-centred windows, placed by recenter() at the first observation.
        auto side = [](double size_m, double res_m) {
            return std::max(1, static_cast<int>(std::lround(size_m / res_m)));
        };
        const int nl = side(c.local_size_m, c.local_resolution_m);
        const int ng = globalSideCells();
        m_impl->local.reset(c.local_resolution_m, multibin::CellWindow{-nl / 2, -nl / 2, nl, nl});
        m_impl->grid.reset(c.global_resolution_m, multibin::CellWindow{-ng / 2, -ng / 2, ng, ng});
    } else {
        m_impl->grid.reset(res, w);
        m_impl->local.reset(res, multibin::CellWindow{});
    }
    m_impl->stats = {};
    m_impl->visibilityStats = {};
    m_impl->poseFallbacks = 0;
    m_impl->skippedByLabel = 0;
    m_impl->nonFinitePoses = 0;
    m_impl->lastRobotPose.reset();
    m_impl->sensorState.reset();
    m_impl->fill = {};
    m_impl->fillRasterBuilt = false;
    m_impl->filled = {};
    m_impl->fillWindow = {};
    m_impl->fillStale = true;
}

multibin::BinUpdateParams CMultiBinElevationMap::binUpdateParams() const {
    multibin::BinUpdateParams p;
    p.binHeight_m = creationOptions.bin_height_m;
    p.certaintyIncrement = insertionOptions.certainty_increment;
    p.maxElevationUncertainty_m = insertionOptions.max_elevation_uncertainty_m;
    p.varianceFloor_m2 =
        insertionOptions.height_sigma_floor_m * insertionOptions.height_sigma_floor_m;
    return p;
}

bool CMultiBinElevationMap::isEmpty() const {
    const multibin::MapLock::Shared lock(m_impl->lock);
    return m_impl->grid.empty() && m_impl->local.empty();
}

std::string CMultiBinElevationMap::asString() const {
    const multibin::MapLock::Shared lock(m_impl->lock);
    std::ostringstream os;
    os << "CMultiBinElevationMap: " << m_impl->grid.window().nx << " x " << m_impl->grid.window().ny
       << " cells of " << m_impl->grid.cellSize_m() << " m, x in [" << m_impl->windowEdge_m(0)
       << ", " << m_impl->windowEdge_m(1) << "], y in [" << m_impl->windowEdge_m(2) << ", "
       << m_impl->windowEdge_m(3) << "] m, " << m_impl->grid.binCount() << " bins of "
       << creationOptions.bin_height_m << " m";
    return os.str();
}

mrpt::math::TPoint2D CMultiBinElevationMap::mapOrigin() const {
    const multibin::MapLock::Shared lock(m_impl->lock);
    return {m_impl->origin_m.x(), m_impl->origin_m.y()};
}

mrpt::math::TPoint2D CMultiBinElevationMap::originFor(double x_m, double y_m) const {
    if (m_impl->originFixed) return {m_impl->origin_m.x(), m_impl->origin_m.y()};
    return creationOptions.originNear(x_m, y_m);
}

void CMultiBinElevationMap::fixOriginNear(double x_m, double y_m) {
    const mrpt::math::TPoint2D o = originFor(x_m, y_m);
    m_impl->origin_m = {o.x, o.y};
    m_impl->originFixed = true;
}

float CMultiBinElevationMap::compute3DMatchingRatio(const mrpt::maps::CMetricMap*,
                                                    const mrpt::poses::CPose3D&,
                                                    const TMatchingRatioParams&) const {
    return 0;  // not a map used for registration
}

double CMultiBinElevationMap::internal_computeObservationLikelihood(
    const mrpt::obs::CObservation&, const mrpt::poses::CPose3D&) const {
    return 0;  // see internal_canComputeObservationLikelihood()
}

bool CMultiBinElevationMap::internal_canComputeObservationLikelihood(
    const mrpt::obs::CObservation&) const {
    return false;  // a terrain map, not a localisation map: no likelihood model
}

// ---------------------------------------------------------------------------------------------
// DEM interface
// ---------------------------------------------------------------------------------------------
bool CMultiBinElevationMap::insertIndividualPoint(const double x, const double y, const double z,
                                                  const TPointInsertParams& params) {
    const multibin::MapLock::Exclusive lock(m_impl->lock);
    creationOptions.validate();
    insertionOptions.validate();
    const double sigma = params.pt_z_std > 0 ? params.pt_z_std : insertionOptions.range_sigma_m;
    if (std::isfinite(x) && std::isfinite(y)) fixOriginNear(x, y);
    const double xr = x - m_impl->origin_m.x(), yr = y - m_impl->origin_m.y();
    multibin::PointsWithCov pts(1);
    pts[0].point_m = Eigen::Vector3f(float(xr), float(yr), float(z));
    // Horizontal position taken as exact to the cell; only the height variance matters here.
    const float tiny = static_cast<float>(1e-12);
    pts[0].cov_m2 = {tiny, 0, 0, tiny, 0, float(sigma * sigma)};
    growToCover(pts, Eigen::Vector3d(xr, yr, z), binUpdateParams());
    return insertPoints(pts).accepted == 1;
}
