/* Part of the multibin elevation-mapping library. Private to src/sensors. */
#pragma once

#include <mrpt/maps/CPointsMap.h>

#include <Eigen/Core>

#include <algorithm>
#include <cmath>
#include <cstdint>

#include "multibin/geometry/PointsWithCovariance.h"
#include "multibin/sensors/RayModel.h"

namespace multibin::sensors {

enum class RayPointFate { kept, notFinite, outOfRange };

/** The arithmetic of one ray point, without a branch (loops over points vectorise): the
 * covariance rayCovariance(p, sigmas(|p|)) of p = (x, y, z) [m] into `cov` (meaningless unless
 * kept) and the point's fate: not finite, or out of range if |p| is 0 or outside
 * [minRange_m, maxRange_m] (a point at the origin is a missing return). `sigmas` maps a range [m]
 * to RaySigmas (a model's raySigmas()). The same operations in the same order as Eigen's
 * allFinite(), norm() and rayCovariance(), so the results are bit-identical to them. */
template <class Sigmas>
inline RayPointFate rayPoint(float x, float y, float z, double minRange_m, double maxRange_m,
                             const Sigmas& sigmas, SymmetricCov3& cov) {
    const int finite = (x - x == x - x) & (y - y == y - y) & (z - z == z - z);
    const float r = std::sqrt(x * x + y * y + z * z);
    const int inRange = (r > 0) & !(r < minRange_m) & !(r > maxRange_m);
    const double xd = x, yd = y, zd = z;
    const double n = std::sqrt(xd * xd + yd * yd + zd * zd);
    const RaySigmas s = sigmas(n);
    cov = rayCovarianceAlong(xd / n, yd / n, zd / n, s.axial_m, s.lateral_m);
    return RayPointFate((finite ^ 1) * int(RayPointFate::notFinite) |
                        (finite & (inRange ^ 1)) * int(RayPointFate::outOfRange));
}

/** Appends `p_m` with its covariance if rayPoint() keeps it. */
template <class Sigmas>
RayPointFate appendRayPoint(const Eigen::Vector3f& p_m, double minRange_m, double maxRange_m,
                            const Sigmas& sigmas, PointsWithCov& out) {
    SymmetricCov3 cov;
    const RayPointFate fate =
        rayPoint(p_m.x(), p_m.y(), p_m.z(), minRange_m, maxRange_m, sigmas, cov);
    if (fate == RayPointFate::kept) out.push_back({p_m, cov});
    return fate;
}

/** How many points of a batch met each fate. */
struct RayPointCounts {
    size_t kept = 0, notFinite = 0, outOfRange = 0;
};

/** appendRayPoint() over the n points (xs[i], ys[i], zs[i]), a block of points at a time:
 * rayPoint() over the block in structure-of-arrays form (vectorised), then the kept points packed
 * into `out`. */
template <class Sigmas>
RayPointCounts appendRayPoints(const float* xs, const float* ys, const float* zs, size_t n,
                               double minRange_m, double maxRange_m, const Sigmas& sigmas,
                               PointsWithCov& out) {
    constexpr size_t kBlock = 256;
    float c[6][kBlock];
    int32_t fate[kBlock];
    RayPointCounts counts;
    for (size_t begin = 0; begin < n; begin += kBlock) {
        const size_t m = std::min(kBlock, n - begin);
        const float *x = xs + begin, *y = ys + begin, *z = zs + begin;
        for (size_t i = 0; i < m; i++) {
            SymmetricCov3 cov;
            fate[i] = int32_t(rayPoint(x[i], y[i], z[i], minRange_m, maxRange_m, sigmas, cov));
            c[0][i] = cov.xx;
            c[1][i] = cov.xy;
            c[2][i] = cov.xz;
            c[3][i] = cov.yy;
            c[4][i] = cov.yz;
            c[5][i] = cov.zz;
        }
        // Zero-filled first, then packed in place (as the stereo rows are).
        const size_t base = out.size();
        out.resize(base + m);
        PointWithCov* kept = out.data() + base;
        size_t k = 0;
        for (size_t i = 0; i < m; i++) {
            counts.notFinite += fate[i] == int32_t(RayPointFate::notFinite);
            counts.outOfRange += fate[i] == int32_t(RayPointFate::outOfRange);
            if (fate[i] != int32_t(RayPointFate::kept)) continue;
            kept[k].point_m = Eigen::Vector3f(x[i], y[i], z[i]);
            kept[k++].cov_m2 = {c[0][i], c[1][i], c[2][i], c[3][i], c[4][i], c[5][i]};
        }
        out.resize(base + k);
        counts.kept += k;
    }
    return counts;
}

/** appendRayPoints() over every point of `pts`. */
template <class Sigmas>
RayPointCounts appendCloudPoints(const mrpt::maps::CPointsMap& pts, double minRange_m,
                                 double maxRange_m, const Sigmas& sigmas, PointsWithCov& out) {
    return appendRayPoints(pts.getPointsBufferRef_x().data(), pts.getPointsBufferRef_y().data(),
                           pts.getPointsBufferRef_z().data(), pts.size(), minRange_m, maxRange_m,
                           sigmas, out);
}

/** Adds a batch's counts to a statistics struct with notFinite, outOfRange and kept counters. */
template <class Stats>
void count(const RayPointCounts& c, Stats& stats) {
    stats.kept += c.kept;
    stats.notFinite += c.notFinite;
    stats.outOfRange += c.outOfRange;
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

}  // namespace multibin::sensors
