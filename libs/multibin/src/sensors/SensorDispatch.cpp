/* Part of the multibin elevation-mapping library. */
#include "multibin/sensors/SensorDispatch.h"

#include <mrpt/obs/CObservation2DRangeScan.h>
#include <mrpt/obs/CObservation3DRangeScan.h>
#include <mrpt/obs/CObservationPointCloud.h>
#include <mrpt/obs/CObservationStereoImages.h>
#include <mrpt/system/datetime.h>

#include <cmath>

#include "multibin/sensors/DepthModel.h"
#include "multibin/sensors/LaserModel.h"
#include "multibin/sensors/StereoModel.h"

namespace multibin::sensors {

bool observationToSensorPoints(const mrpt::obs::CObservation& obs,
                               const mrpt::poses::CPose3DPDFGaussian& robotPose,
                               const SensorModelOptions& opts, double minRange_m, double maxRange_m,
                               SensorModelState& state, SensorPoints& out) {
    out.points.clear();
    out.continuityBound_m = std::numeric_limits<double>::infinity();
    out.stats = {};
    if (const auto* scan = dynamic_cast<const mrpt::obs::CObservation2DRangeScan*>(&obs)) {
        laserScanToPoints(*scan, opts.laser, minRange_m, maxRange_m, out.points, out.stats.laser);
        out.sensorPose = scan->sensorPose;
        if (opts.laser.continuity) {
            const auto prev = state.previousScan.find(scan->sensorLabel);
            const bool timesKnown = prev != state.previousScan.end() &&
                                    scan->timestamp != INVALID_TIMESTAMP &&
                                    prev->second.time != INVALID_TIMESTAMP;
            if (timesKnown &&
                std::abs(mrpt::system::timeDifference(prev->second.time, scan->timestamp)) <=
                    opts.laser.continuityMaxDt_s)
                out.continuityBound_m = continuityBound_m(
                    out.points, out.sensorPose, prev->second.robotPose, robotPose, opts.laser);
            state.previousScan[scan->sensorLabel] = {robotPose, scan->timestamp};
        }
        return true;
    }
    if (const auto* stereo = dynamic_cast<const mrpt::obs::CObservationStereoImages*>(&obs)) {
        stereoToPoints(*stereo, opts.stereo, minRange_m, maxRange_m,
                       state.stereoTables[stereo->sensorLabel], out.points, out.stats.stereo);
        out.sensorPose = mrpt::poses::CPose3D(stereo->cameraPose);  // left camera on the robot
        return true;
    }
    if (const auto* depth = dynamic_cast<const mrpt::obs::CObservation3DRangeScan*>(&obs)) {
        depthScanToPoints(*depth, opts.depth, minRange_m, maxRange_m, out.points, out.stats.depth);
        out.sensorPose = depth->sensorPose;
        return true;
    }
    if (const auto* cloud = dynamic_cast<const mrpt::obs::CObservationPointCloud*>(&obs)) {
        pointCloudToPoints(*cloud, opts.depth, minRange_m, maxRange_m, out.points, out.stats.depth);
        out.sensorPose = cloud->sensorPose;
        return true;
    }
    return false;
}

}  // namespace multibin::sensors
