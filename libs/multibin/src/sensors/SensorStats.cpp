/* Part of the multibin elevation-mapping library. */
#include "multibin/sensors/SensorStats.h"
#include "multibin/util/Counters.h"

namespace multibin::sensors {

LaserStats& LaserStats::operator+=(const LaserStats& o) {
    return util::addMembers(*this, o, &LaserStats::beams, &LaserStats::noReturn,
                            &LaserStats::notFinite, &LaserStats::outOfRange,
                            &LaserStats::lowIntensity, &LaserStats::mixedPixel, &LaserStats::kept,
                            &LaserStats::badAperture);
}

StereoStats& StereoStats::operator+=(const StereoStats& o) {
    return util::addMembers(
        *this, o, &StereoStats::pairs, &StereoStats::tableBuilds, &StereoStats::pixels,
        &StereoStats::notFinite, &StereoStats::noDisparity, &StereoStats::halo,
        &StereoStats::nearCluster, &StereoStats::textureless, &StereoStats::tooNear,
        &StereoStats::outOfRange, &StereoStats::kept, &StereoStats::badCalibration);
}

DepthStats& DepthStats::operator+=(const DepthStats& o) {
    return util::addMembers(*this, o, &DepthStats::points, &DepthStats::notFinite,
                            &DepthStats::outOfRange, &DepthStats::flyingPixel,
                            &DepthStats::frameBorder, &DepthStats::kept);
}

LidarStats& LidarStats::operator+=(const LidarStats& o) {
    return util::addMembers(*this, o, &LidarStats::scans, &LidarStats::returns,
                            &LidarStats::noReturn, &LidarStats::notDecoded, &LidarStats::notFinite,
                            &LidarStats::outOfRange, &LidarStats::kept);
}

SensorModelStats& SensorModelStats::operator+=(const SensorModelStats& o) {
    return util::addMembers(*this, o, &SensorModelStats::laser, &SensorModelStats::stereo,
                            &SensorModelStats::depth, &SensorModelStats::lidar);
}

size_t SensorModelStats::outOfRange() const {
    return laser.noReturn + laser.outOfRange + stereo.tooNear + stereo.outOfRange +
           depth.outOfRange + lidar.noReturn + lidar.notDecoded + lidar.outOfRange;
}

size_t SensorModelStats::notFinite() const {
    return laser.notFinite + stereo.notFinite + depth.notFinite + lidar.notFinite;
}

std::optional<SensorModelKind> SensorModelStats::model() const {
    if (laser.beams > 0) return SensorModelKind::laser;
    if (lidar.returns > 0) return SensorModelKind::lidar;
    if (stereo.pixels > 0 || stereo.pairs > 0) return SensorModelKind::stereo;
    if (depth.points > 0) return SensorModelKind::depth;
    return std::nullopt;
}

}  // namespace multibin::sensors
