/* Part of the multibin elevation-mapping library. */
#include "multibin/sensors/DepthModel.h"

#include <mrpt/maps/CPointsMap.h>
#include <mrpt/maps/CSimplePointsMap.h>

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>
#include <unordered_map>
#include <utility>
#include <vector>

#include "RayPoint.h"

namespace multibin::sensors {

namespace {
void appendPointsMap(const mrpt::maps::CPointsMap& pts, const DepthModelOptions& opts,
                     double minRange_m, double maxRange_m, PointsWithCov& out, DepthStats& stats) {
    stats.points += pts.size();
    count(appendCloudPoints(pts, minRange_m, maxRange_m, opts.raySigmas(), out), stats);
}
}  // namespace

void depthScanToPoints(const mrpt::obs::CObservation3DRangeScan& scan,
                       const DepthModelOptions& opts, double minRange_m, double maxRange_m,
                       PointsWithCov& out, DepthStats& stats) {
    out.clear();
    if (scan.hasPoints3D) {
        const size_t nx = scan.points3D_x.size(), ny = scan.points3D_y.size(),
                     nz = scan.points3D_z.size();
        if (nx != ny || nx != nz)
            throw std::invalid_argument(
                "CObservation3DRangeScan '" + scan.sensorLabel +
                "': points3D_x, points3D_y and points3D_z have different sizes (" +
                std::to_string(nx) + ", " + std::to_string(ny) + ", " + std::to_string(nz) + ")");
        stats.points += nx;
        count(
            appendRayPoints(scan.points3D_x.data(), scan.points3D_y.data(), scan.points3D_z.data(),
                            nx, minRange_m, maxRange_m, opts.raySigmas(), out),
            stats);
    } else if (scan.hasRangeImage) {
        mrpt::maps::CSimplePointsMap local;
        mrpt::obs::T3DPointsProjectionParams pp;
        pp.takeIntoAccountSensorPoseOnRobot = false;  // sensor frame (+x forward)
        // unprojectInto() only fills caches of the observation; the data are not changed.
        const_cast<mrpt::obs::CObservation3DRangeScan&>(scan).unprojectInto(local, pp);
        appendPointsMap(local, opts, minRange_m, maxRange_m, out, stats);
    }
}

size_t addFrameSharedCovariance(PointsWithCov& mapPoints, const Eigen::Vector3d& sensor_m,
                                const DepthModelOptions& opts,
                                const std::function<int64_t(float x_m, float y_m)>& cellOf,
                                const std::function<bool(const PointWithCov&)>& failsOwnGate) {
    const size_t before = mapPoints.size();
    mapPoints.erase(std::remove_if(mapPoints.begin(), mapPoints.end(), failsOwnGate),
                    mapPoints.end());
    // Counting pass, then the covariance pass: two scratch arrays, no allocation per point.
    std::vector<int64_t> cell(mapPoints.size());
    std::unordered_map<int64_t, uint32_t> count;
    count.reserve(mapPoints.size() / 8 + 16);
    for (size_t i = 0; i < mapPoints.size(); i++) {
        cell[i] = cellOf(mapPoints[i].point_m.x(), mapPoints[i].point_m.y());
        count[cell[i]]++;
    }
    for (size_t i = 0; i < mapPoints.size(); i++) {
        PointWithCov& p = mapPoints[i];
        const Eigen::Vector3d ray = p.point_m.cast<double>() - sensor_m;
        const double r = ray.norm();
        if (!(r > 0) || !std::isfinite(r)) continue;  // the map counts it as it is
        const Eigen::Vector3d v = ray / r;
        const double s = opts.frameSigma_m(r);
        const double add = double(count[cell[i]]) * s * s;  // [m^2] along the ray
        p.cov_m2 = SymmetricCov3::fromMatrix(p.cov_m2.toMatrix() + add * v * v.transpose());
    }
    return before - mapPoints.size();
}

}  // namespace multibin::sensors
