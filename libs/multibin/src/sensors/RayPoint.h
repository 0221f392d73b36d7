/* Part of the multibin elevation-mapping library. Private to src/sensors. */
#pragma once

#include <mrpt/maps/CPointsMap.h>

#include <Eigen/Core>

#include "multibin/geometry/PointsWithCovariance.h"
#include "multibin/sensors/RayModel.h"

namespace multibin::sensors {

enum class RayPointFate { kept, notFinite, outOfRange };

/** Appends `p_m` with rayCovariance(p, sigmas(r)) if it is finite and its range r lies in
 * [minRange_m, maxRange_m] (a point at the origin is a missing return: out of range). `sigmas`
 * maps a range [m] to RaySigmas (a model's raySigmas()). */
template <class Sigmas>
RayPointFate appendRayPoint(const Eigen::Vector3f& p_m, double minRange_m, double maxRange_m,
                            const Sigmas& sigmas, PointsWithCov& out) {
    if (!p_m.allFinite()) return RayPointFate::notFinite;
    const float r = p_m.norm();
    if (!(r > 0) || r < minRange_m || r > maxRange_m) return RayPointFate::outOfRange;
    const RaySigmas s = sigmas(p_m.cast<double>().norm());
    out.push_back({p_m, rayCovariance(p_m, s.axial_m, s.lateral_m)});
    return RayPointFate::kept;
}

/** Counts a fate in a statistics struct with notFinite, outOfRange and kept counters. */
template <class Stats>
void count(RayPointFate fate, Stats& stats) {
    switch (fate) {
        case RayPointFate::kept:
            stats.kept++;
            break;
        case RayPointFate::notFinite:
            stats.notFinite++;
            break;
        case RayPointFate::outOfRange:
            stats.outOfRange++;
            break;
    }
}

/** Calls fn(Eigen::Vector3f) for each point of `pts`, after reserving room for them in `out`. */
template <class Fn>
void forEachCloudPoint(const mrpt::maps::CPointsMap& pts, PointsWithCov& out, const Fn& fn) {
    const auto& xs = pts.getPointsBufferRef_x();
    const auto& ys = pts.getPointsBufferRef_y();
    const auto& zs = pts.getPointsBufferRef_z();
    out.reserve(out.size() + xs.size());
    for (size_t i = 0; i < xs.size(); i++) fn(Eigen::Vector3f(xs[i], ys[i], zs[i]));
}

}  // namespace multibin::sensors
