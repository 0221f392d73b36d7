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

SensorModelStats& SensorModelStats::operator+=(const SensorModelStats& o) {
    laser += o.laser;
    stereo += o.stereo;
    depth += o.depth;
    return *this;
}

size_t SensorModelStats::outOfRange() const {
    return laser.noReturn + laser.outOfRange + stereo.tooNear + stereo.outOfRange +
           depth.outOfRange;
}

size_t SensorModelStats::notFinite() const { return laser.notFinite + depth.notFinite; }

}  // namespace multibin::sensors
