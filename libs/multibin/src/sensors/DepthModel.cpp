/* Part of the multibin elevation-mapping library. */
#include "multibin/sensors/DepthModel.h"

#include <mrpt/maps/CPointsMap.h>
#include <mrpt/maps/CSimplePointsMap.h>

#include <algorithm>
#include <cmath>
#include <limits>
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
                                const std::function<Eigen::Vector2i(float x_m, float y_m)>& cellOf,
                                const std::function<bool(const PointWithCov&)>& failsOwnGate) {
    const size_t before = mapPoints.size();
    mapPoints.erase(std::remove_if(mapPoints.begin(), mapPoints.end(), failsOwnGate),
                    mapPoints.end());
    const size_t n = mapPoints.size();
    if (n == 0) return before;
    // Counting pass, then the covariance pass: scratch arrays, no allocation per point. The
    // counts live in a dense array over the frame's cells, or a hash map if that is too large.
    std::vector<Eigen::Vector2i> cell(n);
    Eigen::Vector2i lo = Eigen::Vector2i::Constant(std::numeric_limits<int>::max()), hi = -lo;
    for (size_t i = 0; i < n; i++) {
        cell[i] = cellOf(mapPoints[i].point_m.x(), mapPoints[i].point_m.y());
        lo = lo.cwiseMin(cell[i]);
        hi = hi.cwiseMax(cell[i]);
    }
    const int64_t nx = int64_t(hi.x()) - lo.x() + 1, ny = int64_t(hi.y()) - lo.y() + 1;
    std::vector<uint32_t> perPoint(n);
    if (nx * ny <= int64_t(4 * n + (1 << 20))) {
        std::vector<uint32_t> dense(size_t(nx * ny), 0);
        auto at = [&](const Eigen::Vector2i& c) -> uint32_t& {
            return dense[size_t((int64_t(c.y()) - lo.y()) * nx + (int64_t(c.x()) - lo.x()))];
        };
        for (size_t i = 0; i < n; i++) at(cell[i])++;
        for (size_t i = 0; i < n; i++) perPoint[i] = at(cell[i]);
    } else {
        std::unordered_map<int64_t, uint32_t> sparse;
        auto key = [](const Eigen::Vector2i& c) {
            return (int64_t(c.x()) << 32) ^ uint32_t(c.y());
        };
        for (size_t i = 0; i < n; i++) sparse[key(cell[i])]++;
        for (size_t i = 0; i < n; i++) perPoint[i] = sparse[key(cell[i])];
    }
    for (size_t i = 0; i < n; i++) {
        PointWithCov& p = mapPoints[i];
        const Eigen::Vector3d ray = p.point_m.cast<double>() - sensor_m;
        const double r = ray.norm();
        if (!(r > 0) || !std::isfinite(r)) continue;  // the map counts it as it is
        const Eigen::Vector3d v = ray / r;
        const double s = opts.frameSigma_m(r);
        const double a = double(perPoint[i]) * s * s;  // [m^2] along the ray
        SymmetricCov3& c = p.cov_m2;
        c.xx += float(a * v.x() * v.x());
        c.xy += float(a * v.x() * v.y());
        c.xz += float(a * v.x() * v.z());
        c.yy += float(a * v.y() * v.y());
        c.yz += float(a * v.y() * v.z());
        c.zz += float(a * v.z() * v.z());
    }
    return before - n;
}

}  // namespace multibin::sensors
