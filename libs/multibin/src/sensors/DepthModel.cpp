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

}  // namespace multibin::sensors
