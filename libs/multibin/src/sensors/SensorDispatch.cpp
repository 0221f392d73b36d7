/* Part of the multibin elevation-mapping library. */
#include "multibin/sensors/SensorDispatch.h"

#include <mrpt/obs/CObservation2DRangeScan.h>
#include <mrpt/obs/CObservation3DRangeScan.h>
#include <mrpt/obs/CObservationPointCloud.h>
#include <mrpt/system/datetime.h>

#include <cmath>
#include <stdexcept>

#include "multibin/sensors/StereoDisparity.h"
#include "multibin/sensors/StereoModel.h"

namespace multibin::sensors {

StereoStats& StereoStats::operator+=(const StereoStats& o) {
    pairs += o.pairs;
    tableBuilds += o.tableBuilds;
    pixels += o.pixels;
    noDisparity += o.noDisparity;
    halo += o.halo;
    nearCluster += o.nearCluster;
    tooNear += o.tooNear;
    outOfRange += o.outOfRange;
    kept += o.kept;
    return *this;
}

void stereoToPoints(const mrpt::obs::CObservationStereoImages& obs, const StereoModelOptions& opts,
                    double minRange_m, double maxRange_m, SensorModelState& state,
                    PointsWithCov& out) {
    StereoStats& st = state.stats.stereo;
    const StereoGeometry g = StereoGeometry::fromObservation(obs);
    DisparityImage disp;
    if (obs.hasImageDisparity) {
        disp = decodeDisparityImage(obs.imageDisparity);
    } else {
        if (!obs.hasImageRight)
            throw std::invalid_argument(
                "CObservationStereoImages '" + obs.sensorLabel +
                "': neither a disparity image nor a right image (hasImageRight = false)");
        disp = computeDisparitySGBM(obs.imageLeft, obs.imageRight, opts);
    }
    if (disp.width != g.width || disp.height != g.height)
        throw std::invalid_argument("CObservationStereoImages '" + obs.sensorLabel +
                                    "': image size differs from leftCamera's ncols x nrows");
    if (opts.haloFilter) st.halo += removeHalos(disp, opts);
    if (opts.nearClusterFilter) st.nearCluster += removeNearClusters(disp, opts);

    auto& cached = state.stereoTables[obs.sensorLabel];
    if (!cached || !cached->matches(g, opts)) {
        cached = std::make_shared<const StereoCovarianceTable>(g, opts);
        st.tableBuilds++;
    }
    const StereoCovarianceTable& table = *cached;
    st.pairs++;
    out.clear();
    const StereoPixelCounts c =
        table.appendPoints(disp, opts.subsample, opts.minDepth_m, minRange_m, maxRange_m, out);
    st.pixels += c.pixels;
    st.noDisparity += c.noDisparity;
    st.tooNear += c.tooNear;
    st.outOfRange += c.outOfRange;
    st.kept += c.kept;
}

bool observationToSensorPoints(const mrpt::obs::CObservation& obs,
                               const mrpt::poses::CPose3DPDFGaussian& robotPose,
                               const SensorModelOptions& opts, double minRange_m, double maxRange_m,
                               SensorModelState& state, InsertStats& coreStats, SensorPoints& out) {
    out.points.clear();
    out.continuityBound_m = std::numeric_limits<double>::infinity();
    if (const auto* scan = dynamic_cast<const mrpt::obs::CObservation2DRangeScan*>(&obs)) {
        LaserStats ls;
        laserScanToPoints(*scan, opts.laser, minRange_m, maxRange_m, out.points, ls);
        state.stats.laser += ls;
        coreStats.outOfRange += ls.noReturn + ls.outOfRange;
        coreStats.notFinite += ls.notFinite;
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
        const size_t before = state.stats.stereo.tooNear + state.stats.stereo.outOfRange;
        stereoToPoints(*stereo, opts.stereo, minRange_m, maxRange_m, state, out.points);
        coreStats.outOfRange += state.stats.stereo.tooNear + state.stats.stereo.outOfRange - before;
        out.sensorPose = mrpt::poses::CPose3D(stereo->cameraPose);  // left camera on the robot
        return true;
    }
    DepthStats ds;
    if (const auto* depth = dynamic_cast<const mrpt::obs::CObservation3DRangeScan*>(&obs)) {
        depthScanToPoints(*depth, opts.depth, minRange_m, maxRange_m, out.points, ds);
        out.sensorPose = depth->sensorPose;
    } else if (const auto* cloud = dynamic_cast<const mrpt::obs::CObservationPointCloud*>(&obs)) {
        pointCloudToPoints(*cloud, opts.depth, minRange_m, maxRange_m, out.points, ds);
        out.sensorPose = cloud->sensorPose;
    } else {
        return false;
    }
    state.stats.depth += ds;
    coreStats.outOfRange += ds.outOfRange;
    coreStats.notFinite += ds.notFinite;
    return true;
}

}  // namespace multibin::sensors
