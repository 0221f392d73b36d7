/* Part of the multibin elevation-mapping library: the elevation-mapper program. */
#include "RunWarnings.h"

#include <cstdio>

#include "multibin/map/MapStatistics.h"
#include "multibin/sensors/SensorStats.h"

namespace {
/** A reason points are dropped, its count and the options that govern it. */
struct Gate {
    const char* name;
    size_t count;
    const char* governedBy;
};

std::vector<Gate> gatesOf(const mrpt::maps::CMultiBinElevationMap& map) {
    const multibin::InsertStats& s = map.statistics().insert;
    const multibin::sensors::SensorModelStats& m = map.statistics().sensorModels;
    // Readings without an echo (no return, not decoded) are not a gate: no option brings them.
    const size_t range =
        m.laser.outOfRange + m.stereo.outOfRange + m.depth.outOfRange + m.lidar.outOfRange;
    return {
        {"range gate", range, "min_range_m and max_range_m"},
        {"outside map", s.outsideMap,
         "grow and min_x_m .. max_y_m for a fixed window; local_size_m, global_size_m for the "
         "dual grid; max_range_m bounds how far from its sensor a point grows the map"},
        {"eq 13 gate (too uncertain: 3 sigma_z > the limit)", s.tooUncertain,
         "max_elevation_uncertainty_m or the sensor's *_max_elevation_uncertainty_m; the pose "
         "covariance (default_pose_sigmas when the input gives none) sets sigma_z at range "
         "(doc/sensor-reach.md)"},
        {"eq 14 gate (laser continuity)", s.continuityRejected, "laser_continuity_*"},
        {"bin range", s.outsideBinRange, "bin_height_m"},
        {"indefinite covariance", s.badCovariance, "the input's pose covariance"},
        {"laser low intensity", m.laser.lowIntensity,
         "laser_agc, laser_min_restored_intensity, laser_intensity_check_range_m"},
        {"laser mixed pixels", m.laser.mixedPixel, "laser_mixed_pixel_*"},
        {"depth flying pixels", m.depth.flyingPixel, "depth_flying_pixel_*"},
        {"depth frame border", m.depth.frameBorder, "depth_border_px"},
    };
}
}  // namespace

std::string dominantRejection(const mrpt::maps::CMultiBinElevationMap& map) {
    const std::vector<Gate> gates = gatesOf(map);
    size_t total = map.statistics().insert.accepted;
    const Gate* top = nullptr;
    for (const Gate& g : gates) {
        total += g.count;
        if (!top || g.count > top->count) top = &g;
    }
    if (!top || 2 * top->count <= total) return {};
    char buf[512];
    std::snprintf(buf, sizeof buf,
                  "most points rejected by one gate, %s: %zu of %zu (%.0f %%); "
                  "governed by %s",
                  top->name, top->count, total, 100.0 * double(top->count) / double(total),
                  top->governedBy);
    return buf;
}

std::vector<std::string> runWarnings(const mrpt::maps::CMultiBinElevationMap& map,
                                     const RunFacts& facts) {
    std::vector<std::string> out;
    const multibin::InsertStats& s = map.statistics().insert;
    const size_t handed = s.accepted + s.tooUncertain + s.outsideMap + s.outsideBinRange +
                          s.continuityRejected + s.badCovariance;
    // Under 1 % of the points looked down: the map holds what stands at the sensors' height.
    if (handed > 0 && 100 * s.seenBelow < handed)
        out.push_back(
            "no surface below the sensors was seen: " + std::to_string(s.seenBelow) + " of " +
            std::to_string(handed) +
            " points lie more than 5 degrees below a sensor's horizontal (a horizontal laser "
            "maps walls, not terrain: pitch it down, or add a sensor that sees the ground)");
    if (map.statistics().poseFallbacks > 0 && facts.observationsWithPoseCovariance == 0)
        out.push_back("every observation (" + std::to_string(map.statistics().poseFallbacks) +
                      ") was mapped with the default pose covariance (default_pose_sigmas): the "
                      "input gives none (no CObservationRobotPose, no simplemap covariance), so "
                      "the map's sigmas rest on that guess");
    const std::string gate = dominantRejection(map);
    if (!gate.empty()) out.push_back(gate);
    return out;
}
