/* Part of the multibin elevation-mapping library.
 * CMultiBinElevationMap: observation dispatch, pose PDFs and the insertion core. */
#include <mrpt/obs/CObservationRobotPose.h>
#include <mrpt/system/datetime.h>
#include "CMultiBinElevationMap_impl.h"
#include "multibin/sensors/ObservationChecks.h"
#include "multibin/util/Counters.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <limits>
#include <stdexcept>
#include <string>

#include "multibin/geometry/PosePropagation.h"
#include "multibin/grid/PointsPerCell.h"
#include "multibin/grid/VisibilityConstraint.h"
#include "multibin/sensors/DepthModel.h"
#include "multibin/sensors/SensorDispatch.h"
#include "multibin/util/VectorClones.h"

using namespace mrpt::maps;
using multibin::PointsWithCov;
using multibin::PointWithCov;

namespace {
/** The points growToCover() sizes the window by: within `half_m` (the sensors' range,
 * max_range_m) of the sensor on each axis (a stray far return must not stretch the map), within
 * `growthLimit_m` of the map origin (BinStore::kGrowthLimitCells) and passing the eq 13 gate
 * (nor may a stereo point 20 m away with sigma_z of metres). */
bool canGrowTheMap(const PointWithCov& p, const Eigen::Vector3d& sensor_m, double half_m,
                   double growthLimit_m, const multibin::BinUpdateParams& params) {
    return std::abs(p.point_m.x()) <= growthLimit_m && std::abs(p.point_m.y()) <= growthLimit_m &&
           std::abs(p.point_m.x() - sensor_m.x()) <= half_m &&
           std::abs(p.point_m.y() - sensor_m.y()) <= half_m && !std::isnan(p.cov_m2.zz) &&
           params.passesEq13(p.cov_m2.zz);
}

/** What growthNeeded's screen needs, by value: the window and the sensor-to-map transform. */
struct GrowthScreen {
    double rot[2][3];               //!< the first two rows of the sensor-to-map rotation
    double sensorX_m, sensorY_m;    //!< the sensor origin in the map
    double x0_m, x1_m, y0_m, y1_m;  //!< the window's edges
    double half_m;                  //!< the growth reach: max_range_m
    double originNorm_m;            //!< |x| + |y| + |z| of the sensor origin
};

/** growthNeeded's screen over n sensor-frame points: 1 where a point may grow the window and must
 * be tested exactly, 0 where it clearly cannot (clearly inside the window, or clearly farther
 * than half_m from the sensor); NaN coordinates give 1. The positions in double as
 * PosePropagator::horizontalInMap_m computes them. Branch-free, so it vectorises. */
MULTIBIN_VECTOR_CLONES
void screenForGrowth(const GrowthScreen& g, const float* xs, const float* ys, const float* zs,
                     size_t n, uint8_t* mayGrow) {
    for (size_t i = 0; i < n; i++) {
        const double px = xs[i], py = ys[i], pz = zs[i];
        const double qx = g.rot[0][0] * px + g.rot[0][1] * py + g.rot[0][2] * pz + g.sensorX_m;
        const double qy = g.rot[1][0] * px + g.rot[1][1] * py + g.rot[1][2] * pz + g.sensorY_m;
        // Far more than the single-precision propagation can differ from these [m].
        const double slack =
            1e-4 + 1e-5 * (std::abs(px) + std::abs(py) + std::abs(pz) + g.originNorm_m);
        const int inside = int(qx - slack >= g.x0_m) & int(qx + slack <= g.x1_m) &
                           int(qy - slack >= g.y0_m) & int(qy + slack <= g.y1_m);
        const int far = int(std::abs(qx - g.sensorX_m) > g.half_m + slack) |
                        int(std::abs(qy - g.sensorY_m) > g.half_m + slack);
        mayGrow[i] = uint8_t((1 - inside) & (1 - far));
    }
}

/** How many of the sensor-frame points lie along rays that point more than
 * InsertStats::kBelowHorizon_rad below the map's horizontal; `down` is the sensor-to-map
 * rotation's last row. */
size_t countSeenBelow(const PointsWithCov& sensorPoints, const Eigen::Vector3d& down) {
    // d < -sin(limit) |v|, without a square root per point: d < 0 and d^2 > sin^2 |v|^2.
    const double sin2 = std::pow(std::sin(multibin::InsertStats::kBelowHorizon_rad), 2);
    size_t n = 0;
    for (const PointWithCov& p : sensorPoints) {
        const Eigen::Vector3d v = p.point_m.cast<double>();
        const double d = down.dot(v);
        n += size_t(d < 0) & size_t(d * d > sin2 * v.squaredNorm());
    }
    return n;
}

/** Options may be set in code after construction: every insertion entry point checks them
 * before they reach the grid (a NaN certainty increment makes invalid bins). */
void validateOptions(const CMultiBinElevationMap& map) {
    map.creationOptions.validate();
    map.insertionOptions.validate();
}

/** t1 - t0 [s] as MRPT's timeDifference (whole microseconds), but +-inf where the int64 tick
 * difference would wrap (timestamps 2^63 ticks apart looked microseconds apart). */
double secondsBetween(mrpt::Clock::time_point t0, mrpt::Clock::time_point t1) {
    int64_t ticks = 0;
    if (__builtin_sub_overflow(int64_t(t1.time_since_epoch().count()),
                               int64_t(t0.time_since_epoch().count()), &ticks))
        return t1 > t0 ? std::numeric_limits<double>::infinity()
                       : -std::numeric_limits<double>::infinity();
    return 1e-6 * double(std::chrono::duration_cast<std::chrono::microseconds>(
                             mrpt::Clock::duration(ticks))
                             .count());
}
}  // namespace

bool CMultiBinElevationMap::acceptsLabel(const std::string& label) const {
    const auto& labels = insertionOptions.sensor_labels;
    return labels.empty() || std::find(labels.begin(), labels.end(), label) != labels.end();
}

bool CMultiBinElevationMap::internal_insertObservation(
    const mrpt::obs::CObservation& obs,
    const std::optional<const mrpt::poses::CPose3D>& robotPose) {
    const multibin::MapLock::Exclusive lock(m_impl->lock);
    validateOptions(*this);
    if (const auto* rp = dynamic_cast<const mrpt::obs::CObservationRobotPose*>(&obs)) {
        // Not inserted: kept as the pose PDF of the observations that follow.
        m_impl->lastRobotPose = rp->pose;
        m_impl->lastRobotPoseTime = rp->timestamp;
        return false;
    }
    mrpt::poses::CPose3DPDFGaussian pdf;
    bool haveCov = false;
    if (m_impl->lastRobotPose) {
        const bool timesKnown =
            obs.timestamp != INVALID_TIMESTAMP && m_impl->lastRobotPoseTime != INVALID_TIMESTAMP;
        const double dt = timesKnown
                              ? std::abs(secondsBetween(m_impl->lastRobotPoseTime, obs.timestamp))
                              : std::numeric_limits<double>::infinity();
        if (dt <= insertionOptions.robot_pose_max_dt_s) {
            pdf = *m_impl->lastRobotPose;
            haveCov = true;
        }
    }
    if (!haveCov) {
        pdf.cov = insertionOptions.defaultPoseCovariance();
        m_impl->poseFallbacks++;
    }
    if (robotPose)
        pdf.mean = *robotPose;  // the caller's mean wins; the covariance comes from the PDF
    else if (!haveCov)
        pdf.mean = mrpt::poses::CPose3D();
    return insertWithPosePdf(obs, pdf);
}

bool CMultiBinElevationMap::insertObservation(const mrpt::obs::CObservation& obs,
                                              const mrpt::poses::CPose3DPDFGaussian& robotPose) {
    const bool done = insertWithPosePdf(obs, robotPose);
    if (done) {
        publishEvent(mrptEventMetricMapInsert(this, &obs, robotPose.mean));
    }
    return done;
}

void CMultiBinElevationMap::forEachObservationWithPosePdf(
    const mrpt::maps::CSimpleMap& simplemap,
    const std::function<void(const mrpt::obs::CObservation&,
                             const mrpt::poses::CPose3DPDFGaussian&)>& visit,
    const std::function<void(size_t, size_t)>& progress) {
    // Every keyframe is checked before any is visited: a null pose, sensory frame or observation
    // (MRPT reads an object of the wrong class as null) is an error, not a silent skip.
    for (size_t i = 0; i < simplemap.size(); i++) {
        const auto& [posePdf, sf] = simplemap.get(i);
        const std::string where = "CMultiBinElevationMap: simplemap keyframe " + std::to_string(i);
        if (!posePdf) throw std::invalid_argument(where + " has no pose (null)");
        multibin::sensors::checkPosePdf(*posePdf, where + "'s pose");
        if (!sf) throw std::invalid_argument(where + " has no sensory frame (null)");
        for (const auto& obs : *sf)
            if (!obs) throw std::invalid_argument(where + " holds a null observation");
    }
    for (size_t i = 0; i < simplemap.size(); i++) {
        const auto& [posePdf, sf] = simplemap.get(i);
        {
            mrpt::poses::CPose3DPDFGaussian pdf;
            const auto [cov, mean] = posePdf->getCovarianceAndMean();
            pdf.mean = mean;
            pdf.cov = cov;
            for (const auto& obs : *sf) visit(*obs, pdf);
        }
        if (progress) progress(i + 1, simplemap.size());
    }
}

size_t CMultiBinElevationMap::insertSimpleMapWithPosePdfs(
    const mrpt::maps::CSimpleMap& simplemap, const std::function<void(size_t, size_t)>& progress) {
    size_t inserted = 0;
    forEachObservationWithPosePdf(
        simplemap,
        [&](const mrpt::obs::CObservation& obs, const mrpt::poses::CPose3DPDFGaussian& pdf) {
            if (insertObservation(obs, pdf)) inserted++;
        },
        progress);
    return inserted;
}

bool CMultiBinElevationMap::insertWithPosePdf(const mrpt::obs::CObservation& obs,
                                              const mrpt::poses::CPose3DPDFGaussian& posePdf) {
    const multibin::MapLock::Exclusive lock(m_impl->lock);
    validateOptions(*this);
    if (!acceptsLabel(obs.sensorLabel)) {
        m_impl->skippedByLabel++;
        return false;
    }
    for (int i = 0; i < 6; i++)
        if (!std::isfinite(posePdf.mean[i])) {
            multibin::util::addSaturating(m_impl->nonFinitePoses, size_t(1));
            throw std::invalid_argument("CMultiBinElevationMap: robot pose of observation '" +
                                        obs.sensorLabel + "' has a NaN or infinite component");
        }
    // From here on the pose is relative to the map origin (in double), so the single-precision
    // geometry after it stays small at any georeferenced coordinate.
    // An automatic origin is fixed once the observation is known good.
    const mrpt::math::TPoint2D origin = originFor(posePdf.mean.x(), posePdf.mean.y());
    mrpt::poses::CPose3DPDFGaussian robotPose = posePdf;
    robotPose.mean.x(posePdf.mean.x() - origin.x);
    robotPose.mean.y(posePdf.mean.y() - origin.y);
    obs.load();  // externally stored observations

    multibin::sensors::SensorPoints sensed;
    try {
        if (!multibin::sensors::observationToSensorPoints(
                obs, robotPose, insertionOptions.sensors, insertionOptions.min_range_m,
                insertionOptions.max_range_m, m_impl->sensorState, sensed,
                insertionOptions.insertion_threads))
            return false;  // not an observation this map models
    } catch (const std::invalid_argument&) {
        m_impl->sensorState.stats += sensed.stats;  // the refusal's counter (badAperture, ...)
        throw;
    }
    fixOriginNear(posePdf.mean.x(), posePdf.mean.y());
    const PointsWithCov& sensorPoints = sensed.points;
    const mrpt::poses::CPose3D& sensorPose = sensed.sensorPose;
    const double continuityBound_m = sensed.continuityBound_m;
    // Rejections before the insertion core: the model's own counts, added up here.
    m_impl->sensorState.stats += sensed.stats;
    m_impl->stats.outOfRange += sensed.stats.outOfRange();
    m_impl->stats.notFinite += sensed.stats.notFinite();
    if (sensorPoints.empty()) return false;

    // Eq 13's limit is the sensor model's (a lidar's far points may be kept with their sigma):
    // growth, the gate and the visibility constraint all see the same one.
    multibin::BinUpdateParams params = binUpdateParams();
    if (const auto model = sensed.stats.model())
        params.maxElevationUncertainty_m = insertionOptions.sensors.maxElevationUncertaintyFor(
            *model, params.maxElevationUncertainty_m);
    const multibin::PosePropagator propagator(robotPose, sensorPose);
    const Eigen::Vector3d& sensor_m = propagator.sensorOriginInMap_m();
    m_impl->stats.seenBelow +=
        countSeenBelow(sensorPoints, propagator.rotationSensorToMap().row(2).transpose());
    if (isDualGrid()) recenterRelative(robotPose.mean.x(), robotPose.mean.y());
    const bool grow = !isDualGrid() && growthNeeded(sensorPoints, propagator, params);
    if (grow || sensed.depthFrameError) {
        // Growth is sized by all map-frame points, and a depth frame's shared error is counted
        // per map cell: propagate them first.
        PointsWithCov mapPoints;
        multibin::PoseVariances pose;
        propagator.apply(sensorPoints, mapPoints, &pose);
        if (grow) growToCover(mapPoints, sensor_m, params);
        multibin::BinGrid& grid = gridFor(obs);
        size_t ownGateRejected = 0;
        if (sensed.depthFrameError) {
            // The gate is each point's own variance's; the frame's shared error comes after.
            ownGateRejected = multibin::removeFailingOwnGate(mapPoints, params);
            multibin::sensors::addFrameSharedCovariance(mapPoints, sensor_m,
                                                        insertionOptions.sensors.depth,
                                                        multibin::pointsPerCell(grid, mapPoints));
        }
        return insertIntoGrid(
                   grid, params,
                   [&](multibin::BinGrid& g, const multibin::BinUpdateParams& gridParams) {
                       if (!sensed.depthFrameError)
                           return g.insertPoints(mapPoints, gridParams, continuityBound_m, &pose);
                       // Eq 13 was applied to each point's own variance above.
                       multibin::BinUpdateParams shared = gridParams;
                       shared.maxElevationUncertainty_m = std::numeric_limits<double>::infinity();
                       multibin::InsertStats s =
                           g.insertPoints(mapPoints, shared, continuityBound_m, &pose);
                       s.tooUncertain += ownGateRejected;
                       return s;
                   },
                   sensor_m, sensed.cameraFrame)
                   .accepted > 0;
    }
    // The window stays as it is: propagate and fuse block by block (bit-identical result).
    return insertIntoGrid(
               gridFor(obs), params,
               [&](multibin::BinGrid& g, const multibin::BinUpdateParams& gridParams) {
                   return g.insertSensorPoints(propagator, sensorPoints, gridParams,
                                               continuityBound_m);
               },
               sensor_m, sensed.cameraFrame)
               .accepted > 0;
}

bool CMultiBinElevationMap::growthNeeded(const PointsWithCov& sensorPoints,
                                         const multibin::PosePropagator& propagator,
                                         const multibin::BinUpdateParams& params) const {
    const auto& c = creationOptions;
    if (!c.grow || c.dual_grid || sensorPoints.empty()) return false;
    const multibin::CellWindow& w = m_impl->grid.window();
    if (w.nx <= 0 || w.ny <= 0) return true;
    // growToCover() changes the window iff a point that canGrowTheMap() lies in a cell outside
    // it. The map-frame positions in double, from the same pose, differ from the propagator's
    // (single precision) by far less than `slack`: a point clearly inside the window, or clearly
    // farther than the reach from the sensor, cannot grow the map. The few others are
    // propagated exactly and tested as growToCover() would.
    const double cell = m_impl->grid.cellSize_m(), half = growthReach_m();
    const double x0 = w.ix0 * cell, x1 = (w.ix0 + w.nx) * cell;
    const double y0 = w.iy0 * cell, y1 = (w.iy0 + w.ny) * cell;
    const Eigen::Vector3d& s = propagator.sensorOriginInMap_m();
    GrowthScreen screen;
    const Eigen::Matrix3d& A = propagator.rotationSensorToMap();
    for (int r = 0; r < 2; r++)
        for (int k = 0; k < 3; k++) screen.rot[r][k] = A(r, k);
    screen.sensorX_m = s.x();
    screen.sensorY_m = s.y();
    screen.x0_m = x0;
    screen.x1_m = x1;
    screen.y0_m = y0;
    screen.y1_m = y1;
    screen.half_m = half;
    screen.originNorm_m = s.cwiseAbs().sum();
    constexpr size_t kBatch = 256;
    PointWithCov exact[kBatch];
    size_t pending = 0;
    auto anyGrows = [&]() {
        propagator.apply(exact, exact, pending);
        bool grows = false;
        for (size_t i = 0; i < pending; i++) {
            const PointWithCov& p = exact[i];
            grows = grows || (canGrowTheMap(p, s, half, growthLimit_m(), params) &&
                              !w.contains(m_impl->grid.cellIndex(p.point_m.x()),
                                          m_impl->grid.cellIndex(p.point_m.y())));
        }
        pending = 0;
        return grows;
    };
    // A block at a time: the screen (vectorised), then the few points it leaves, exactly.
    alignas(64) float bx[kBatch], by[kBatch], bz[kBatch];
    alignas(64) uint8_t mayGrow[kBatch];
    for (size_t begin = 0; begin < sensorPoints.size(); begin += kBatch) {
        const size_t n = std::min(kBatch, sensorPoints.size() - begin);
        gatherPositions(sensorPoints.data() + begin, n, bx, by, bz);
        screenForGrowth(screen, bx, by, bz, n, mayGrow);
        for (size_t i = 0; i < n; i++) {
            if (!mayGrow[i]) continue;
            exact[pending++] = sensorPoints[begin + i];
            if (pending == kBatch && anyGrows()) return true;
        }
    }
    return pending > 0 && anyGrows();
}

multibin::InsertStats CMultiBinElevationMap::insertPoints(
    const PointsWithCov& mapPoints, double continuityBound_m,
    const std::optional<Eigen::Vector3d>& sensorOrigin_m, const multibin::PoseVariances* pose) {
    const multibin::MapLock::Exclusive lock(m_impl->lock);
    validateOptions(*this);
    m_impl->originFixed = true;  // the points are relative to it
    return insertIntoGrid(
        isDualGrid() ? m_impl->local : m_impl->grid, binUpdateParams(),
        [&](multibin::BinGrid& g, const multibin::BinUpdateParams& params) {
            return g.insertPoints(mapPoints, params, continuityBound_m, pose);
        },
        sensorOrigin_m);
}

void CMultiBinElevationMap::growToCoverPoints(const PointsWithCov& mapPoints,
                                              const Eigen::Vector3d& sensor_m) {
    const multibin::MapLock::Exclusive lock(m_impl->lock);
    validateOptions(*this);
    growToCover(mapPoints, sensor_m, binUpdateParams());
}

multibin::InsertStats CMultiBinElevationMap::insertIntoGrid(
    multibin::BinGrid& grid, const multibin::BinUpdateParams& params, const FuseIntoGrid& fuse,
    const std::optional<Eigen::Vector3d>& sensorOrigin_m, bool cameraFrame) {
    if (sensorOrigin_m) reloadTilesInReach(grid, *sensorOrigin_m);
    grid.beginCycle();
    grid.setInsertionThreads(insertionOptions.insertion_threads);
    m_impl->fillStale = true;
    const multibin::InsertStats s = fuse(grid, params);
    m_impl->stats += s;
    if (sensorOrigin_m) {
        // The clearances bound the gap fill (fill::boundByClearance): kept only if it reads them.
        const multibin::fill::FillOptions& fill = insertionOptions.fill;
        if (insertionOptions.visibility.enabled && fill.enabled && fill.clearance.enabled)
            multibin::noteClearances(grid, *sensorOrigin_m, multibin::kClearanceRise_m);
        m_impl->visibilityStats += multibin::applyVisibilityConstraint(
            grid, *sensorOrigin_m, insertionOptions.visibility, params,
            cameraFrame ? multibin::RayFan::Skip : multibin::RayFan::Test);
        keepWithinMemoryBudget(*sensorOrigin_m);
    }
    return s;
}

double CMultiBinElevationMap::growthReach_m() const { return insertionOptions.max_range_m; }

double CMultiBinElevationMap::growthLimit_m() const {
    return multibin::BinStore::kGrowthLimitCells * m_impl->grid.cellSize_m();
}

void CMultiBinElevationMap::growToCover(const PointsWithCov& mapPoints,
                                        const Eigen::Vector3d& sensor_m,
                                        const multibin::BinUpdateParams& params) {
    const auto& c = creationOptions;
    if (!c.grow || c.dual_grid || mapPoints.empty()) return;
    const double half = growthReach_m();
    double xmin = std::numeric_limits<double>::infinity(), ymin = xmin, xmax = -xmin, ymax = -xmin;
    for (const PointWithCov& p : mapPoints) {
        const double x = p.point_m.x(), y = p.point_m.y();
        if (!canGrowTheMap(p, sensor_m, half, growthLimit_m(), params)) continue;
        xmin = std::min(xmin, x);
        xmax = std::max(xmax, x);
        ymin = std::min(ymin, y);
        ymax = std::max(ymax, y);
    }
    if (!(xmin <= xmax)) return;
    const multibin::CellWindow& cur = m_impl->grid.window();
    const int ixLo = m_impl->grid.cellIndex(xmin), ixHi = m_impl->grid.cellIndex(xmax);
    const int iyLo = m_impl->grid.cellIndex(ymin), iyHi = m_impl->grid.cellIndex(ymax);
    if (cur.nx > 0 && cur.ny > 0 && cur.contains(ixLo, iyLo) && cur.contains(ixHi, iyHi)) return;
    // Grow with a 1 m margin, so a moving sensor does not grow the window at every scan. Growing
    // costs nothing (the storage is tiled); the window bounds what queries and rasters cover.
    const int margin = std::max(1, static_cast<int>(std::ceil(1.0 / m_impl->grid.cellSize_m())));
    m_impl->grid.growToInclude(multibin::CellWindow{
        ixLo - margin, iyLo - margin, ixHi - ixLo + 1 + 2 * margin, iyHi - iyLo + 1 + 2 * margin});
}
