/* Part of the multibin elevation-mapping library. */
#include "multibin/sensors/LidarModel.h"

#include <mrpt/obs/CObservation2DRangeScan.h>
#include <mrpt/obs/CObservationPointCloud.h>
#include <mrpt/obs/CObservationRotatingScan.h>
#include <mrpt/obs/CObservationVelodyneScan.h>

#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <stdexcept>
#include <utility>

#include "RayPoint.h"

namespace multibin::sensors {

namespace {
/** A beam of a scan in the sensor's xy plane: no return, NaN, or a point. */
void appendPlanarBeam(float range_m, bool valid, double scanMaxRange_m, double azimuth_rad,
                      const LidarModelOptions& opts, double minRange_m, double maxRange_m,
                      PointsWithCov& out, LidarStats& stats) {
    stats.returns++;
    if (std::isnan(range_m) || std::isinf(range_m)) {
        stats.notFinite++;
    } else if (!valid || range_m <= 0 || range_m >= scanMaxRange_m) {
        stats.noReturn++;
    } else {
        const Eigen::Vector3f p(float(std::cos(azimuth_rad)) * range_m,
                                float(std::sin(azimuth_rad)) * range_m, 0.f);
        count(appendRayPoint(p, minRange_m, maxRange_m, opts.raySigmas(), out), stats);
    }
}

/** Receives the points of MRPT's Velodyne point generation. */
struct Collector : mrpt::obs::CObservationVelodyneScan::PointCloudStorageWrapper {
    const LidarModelOptions& opts;
    double minRange_m, maxRange_m;
    PointsWithCov& out;
    LidarStats& stats;
    size_t generated = 0;
    Collector(const LidarModelOptions& o, double lo, double hi, PointsWithCov& p, LidarStats& s)
        : opts(o), minRange_m(lo), maxRange_m(hi), out(p), stats(s) {}
    void reserve(std::size_t n) override { out.reserve(out.size() + n); }
    void add_point(float x, float y, float z, uint8_t, const mrpt::system::TTimeStamp&, const float,
                   uint16_t) override {
        generated++;
        count(
            appendRayPoint(Eigen::Vector3f(x, y, z), minRange_m, maxRange_m, opts.raySigmas(), out),
            stats);
    }
};
}  // namespace

void velodyneScanToPoints(const mrpt::obs::CObservationVelodyneScan& scan,
                          const LidarModelOptions& opts, double minRange_m, double maxRange_m,
                          PointsWithCov& out, LidarStats& stats) {
    out.clear();
    stats.scans++;
    size_t echoes = 0;
    for (const auto& packet : scan.scan_packets)
        for (const auto& block : packet.blocks)
            for (const auto& packed : block.laser_returns) {
                stats.returns++;
                // MRPT's accessor binds a uint16_t reference to a field of a packed struct, which
                // is misaligned in the packet (undefined behaviour): read an aligned copy.
                alignas(alignof(uint16_t)) mrpt::obs::CObservationVelodyneScan::laser_return_t ret;
                std::memcpy(&ret, &packed, sizeof ret);
                if (ret.distance() == 0)
                    stats.noReturn++;
                else
                    echoes++;
            }
    mrpt::obs::CObservationVelodyneScan::TGeneratePointCloudParameters params;
    params.minDistance = 0.f;  // the map's min_range applies, not MRPT's 1 m default
    Collector collector(opts, minRange_m, maxRange_m, out, stats);
    // generatePointCloud() with a storage wrapper writes only to the wrapper.
    const_cast<mrpt::obs::CObservationVelodyneScan&>(scan).generatePointCloud(collector, params);
    stats.notDecoded += echoes >= collector.generated ? echoes - collector.generated : 0;
}

void lidarScanToPoints(const mrpt::obs::CObservation2DRangeScan& scan,
                       const LidarModelOptions& opts, double minRange_m, double maxRange_m,
                       PointsWithCov& out, LidarStats& stats) {
    out.clear();
    stats.scans++;
    const size_t n = scan.getScanSize();
    out.reserve(n);
    for (size_t i = 0; i < n; i++)
        appendPlanarBeam(scan.getScanRange(i), scan.getScanRangeValidity(i), scan.maxRange,
                         scan.getScanAngle(i), opts, minRange_m, maxRange_m, out, stats);
}

void rotatingScanToPoints(const mrpt::obs::CObservationRotatingScan& scan,
                          const LidarModelOptions& opts, double minRange_m, double maxRange_m,
                          PointsWithCov& out, LidarStats& stats) {
    out.clear();
    if (scan.rowCount != 1)
        throw std::invalid_argument(
            "CObservationRotatingScan '" + scan.sensorLabel + "' (" + scan.lidarModel + ", " +
            std::to_string(scan.rowCount) +
            " rows): MRPT 2.5 stores no beam elevations for it; only single-row (2D) rotating "
            "scans can be mapped (insert the CObservationVelodyneScan instead)");
    if (scan.rangeImage.rows() != 1 || size_t(scan.rangeImage.cols()) != scan.columnCount)
        throw std::invalid_argument("CObservationRotatingScan '" + scan.sensorLabel +
                                    "': rangeImage is not rowCount x columnCount");
    stats.scans++;
    const size_t n = scan.columnCount;
    out.reserve(n);
    const double step = scan.azimuthSpan / double(n);
    for (size_t i = 0; i < n; i++) {
        const uint16_t raw = scan.rangeImage(0, i);
        appendPlanarBeam(float(raw * scan.rangeResolution), raw != 0, scan.maxRange,
                         scan.startAzimuth + double(i) * step, opts, minRange_m, maxRange_m, out,
                         stats);
    }
}

}  // namespace multibin::sensors
