/* Part of the multibin elevation-mapping library. */
#include "multibin/sensors/SensorDispatch.h"

#include <mrpt/obs/CObservation2DRangeScan.h>
#include <mrpt/obs/CObservation3DRangeScan.h>
#include <mrpt/obs/CObservationPointCloud.h>
#include <mrpt/obs/CObservationRotatingScan.h>
#include <mrpt/obs/CObservationStereoImages.h>
#include <mrpt/obs/CObservationVelodyneScan.h>
#include <mrpt/system/datetime.h>

#include <cmath>
#include <initializer_list>
#include <stdexcept>
#include <string>

#include "multibin/sensors/DepthModel.h"
#include "multibin/sensors/LaserModel.h"
#include "multibin/sensors/LidarModel.h"
#include "multibin/sensors/ObservationChecks.h"
#include "multibin/sensors/RayModel.h"
#include "multibin/sensors/StereoModel.h"

namespace multibin::sensors {

namespace {
/** The model chosen for `obs` (its label's entry in sensor_models, else `classDefault`), which must
 * be one of `allowed`. */
SensorModelKind chooseModel(const mrpt::obs::CObservation& obs, const SensorModelOptions& opts,
                            SensorModelKind classDefault,
                            std::initializer_list<SensorModelKind> allowed) {
    const SensorModelKind kind = opts.modelFor(obs.sensorLabel, classDefault);
    for (SensorModelKind k : allowed)
        if (k == kind) return kind;
    std::string names;
    for (SensorModelKind k : allowed)
        names += std::string(names.empty() ? "" : " or ") + sensorModelName(k);
    throw std::invalid_argument("CMultiBinElevationMap insertion option 'sensor_models': label '" +
                                obs.sensorLabel + "' is given the " + sensorModelName(kind) +
                                " model, but its observation is a " +
                                obs.GetRuntimeClass()->className + ", which takes " + names);
}
}  // namespace

bool observationToSensorPoints(const mrpt::obs::CObservation& obs,
                               const mrpt::poses::CPose3DPDFGaussian& robotPose,
                               const SensorModelOptions& opts, double minRange_m, double maxRange_m,
                               SensorModelState& state, SensorPoints& out, int threads) {
    using K = SensorModelKind;
    out.points.clear();
    out.continuityBound_m = std::numeric_limits<double>::infinity();
    out.stats = {};
    out.depthFrameError = false;
    out.cameraFrame = false;
    // Every field a model reads, once, before any model reads it.
    checkObservationFields(obs);
    checkPose(robotPose.mean, "the robot pose of " + std::string(obs.GetRuntimeClass()->className) +
                                  " '" + obs.sensorLabel + "'");
    if (const auto* scan = dynamic_cast<const mrpt::obs::CObservation2DRangeScan*>(&obs)) {
        out.sensorPose = scan->sensorPose;
        if (chooseModel(obs, opts, K::laser, {K::laser, K::lidar}) == K::lidar) {
            if (const std::string why = apertureProblem(*scan); !why.empty())
                throw std::invalid_argument(why);
            lidarScanToPoints(*scan, opts.lidar, minRange_m, maxRange_m, out.points,
                              out.stats.lidar);
            return true;
        }
        laserScanToPoints(*scan, opts.laser, minRange_m, maxRange_m, out.points, out.stats.laser);
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
        chooseModel(obs, opts, K::stereo, {K::stereo});
        out.cameraFrame = true;
        stereoToPoints(*stereo, opts.stereo, minRange_m, maxRange_m,
                       state.stereoTables[stereo->sensorLabel], out.points, out.stats.stereo,
                       threads);
        out.sensorPose = mrpt::poses::CPose3D(stereo->cameraPose);  // left camera on the robot
        return true;
    }
    // A class that takes one model only: its points by `toPoints` with that model.
    const auto onlyModel = [&](const auto& scan, K kind, auto toPoints, const auto& model,
                               auto& stats) {
        chooseModel(obs, opts, kind, {kind});
        toPoints(scan, model, minRange_m, maxRange_m, out.points, stats);
        out.sensorPose = scan.sensorPose;
        return true;
    };
    if (const auto* depth = dynamic_cast<const mrpt::obs::CObservation3DRangeScan*>(&obs)) {
        // One frame of one camera. A point cloud may merge frames or sensors: no term.
        out.depthFrameError = opts.depth.sharesFrameError();
        out.cameraFrame = true;
        return onlyModel(*depth, K::depth, depthScanToPoints, opts.depth, out.stats.depth);
    }
    if (const auto* cloud = dynamic_cast<const mrpt::obs::CObservationPointCloud*>(&obs)) {
        out.sensorPose = cloud->sensorPose;
        switch (chooseModel(obs, opts, K::depth, {K::depth, K::lidar, K::stereo})) {
            case K::lidar:
                cloudToPoints(*cloud, opts.lidar, minRange_m, maxRange_m, out.points,
                              out.stats.lidar);
                break;
            case K::stereo:
                cloudToPoints(*cloud, opts.stereo, minRange_m, maxRange_m, out.points,
                              out.stats.stereo);
                break;
            default:
                cloudToPoints(*cloud, opts.depth, minRange_m, maxRange_m, out.points,
                              out.stats.depth);
        }
        return true;
    }
    if (const auto* velodyne = dynamic_cast<const mrpt::obs::CObservationVelodyneScan*>(&obs))
        return onlyModel(*velodyne, K::lidar, velodyneScanToPoints, opts.lidar, out.stats.lidar);
    if (const auto* rotating = dynamic_cast<const mrpt::obs::CObservationRotatingScan*>(&obs))
        return onlyModel(*rotating, K::lidar, rotatingScanToPoints, opts.lidar, out.stats.lidar);
    return false;
}

}  // namespace multibin::sensors
