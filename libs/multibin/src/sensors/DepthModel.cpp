/* Part of the multibin elevation-mapping library. */
#include "multibin/sensors/DepthModel.h"

#include <mrpt/maps/CPointsMap.h>
#include <mrpt/maps/CSimplePointsMap.h>

#include <cmath>
#include <stdexcept>
#include <string>
#include <utility>

#include "RayPoint.h"

namespace multibin::sensors {

namespace {
void appendDepthPoint(const Eigen::Vector3f& p_m, const DepthModelOptions& opts, double minRange_m,
                      double maxRange_m, PointsWithCov& out, DepthStats& stats) {
    stats.points++;
    count(appendRayPoint(p_m, minRange_m, maxRange_m, opts.raySigmas(), out), stats);
}
}  // namespace

namespace {
void appendPointsMap(const mrpt::maps::CPointsMap& pts, const DepthModelOptions& opts,
                     double minRange_m, double maxRange_m, PointsWithCov& out, DepthStats& stats) {
    forEachCloudPoint(pts, out, [&](const Eigen::Vector3f& p) {
        appendDepthPoint(p, opts, minRange_m, maxRange_m, out, stats);
    });
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
        out.reserve(nx);
        for (size_t i = 0; i < scan.points3D_x.size(); i++)
            appendDepthPoint(
                Eigen::Vector3f(scan.points3D_x[i], scan.points3D_y[i], scan.points3D_z[i]), opts,
                minRange_m, maxRange_m, out, stats);
    } else if (scan.hasRangeImage) {
        mrpt::maps::CSimplePointsMap local;
        mrpt::obs::T3DPointsProjectionParams pp;
        pp.takeIntoAccountSensorPoseOnRobot = false;  // sensor frame (+x forward)
        // unprojectInto() only fills caches of the observation; the data are not changed.
        const_cast<mrpt::obs::CObservation3DRangeScan&>(scan).unprojectInto(local, pp);
        appendPointsMap(local, opts, minRange_m, maxRange_m, out, stats);
    }
}

}  // namespace multibin::sensors
