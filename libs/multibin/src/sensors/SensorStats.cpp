/* Part of the multibin elevation-mapping library. */
#include "multibin/sensors/SensorStats.h"

namespace multibin::sensors {

LaserStats& LaserStats::operator+=(const LaserStats& o) {
    beams += o.beams;
    noReturn += o.noReturn;
    notFinite += o.notFinite;
    outOfRange += o.outOfRange;
    lowIntensity += o.lowIntensity;
    mixedPixel += o.mixedPixel;
    kept += o.kept;
    return *this;
}

StereoStats& StereoStats::operator+=(const StereoStats& o) {
    pairs += o.pairs;
    tableBuilds += o.tableBuilds;
    pixels += o.pixels;
    notFinite += o.notFinite;
    noDisparity += o.noDisparity;
    halo += o.halo;
    nearCluster += o.nearCluster;
    tooNear += o.tooNear;
    outOfRange += o.outOfRange;
    kept += o.kept;
    return *this;
}

DepthStats& DepthStats::operator+=(const DepthStats& o) {
    points += o.points;
    notFinite += o.notFinite;
    outOfRange += o.outOfRange;
    kept += o.kept;
    return *this;
}

LidarStats& LidarStats::operator+=(const LidarStats& o) {
    scans += o.scans;
    returns += o.returns;
    noReturn += o.noReturn;
    notDecoded += o.notDecoded;
    notFinite += o.notFinite;
    outOfRange += o.outOfRange;
    kept += o.kept;
    return *this;
}

SensorModelStats& SensorModelStats::operator+=(const SensorModelStats& o) {
    laser += o.laser;
    stereo += o.stereo;
    depth += o.depth;
    lidar += o.lidar;
    return *this;
}

size_t SensorModelStats::outOfRange() const {
    return laser.noReturn + laser.outOfRange + stereo.tooNear + stereo.outOfRange +
           depth.outOfRange + lidar.noReturn + lidar.notDecoded + lidar.outOfRange;
}

size_t SensorModelStats::notFinite() const {
    return laser.notFinite + stereo.notFinite + depth.notFinite + lidar.notFinite;
}

}  // namespace multibin::sensors
