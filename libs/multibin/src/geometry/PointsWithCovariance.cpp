/* Part of the multibin elevation-mapping library. */
#include "multibin/geometry/PointsWithCovariance.h"

#include <cmath>

namespace multibin {

bool isSingularCovariance(const SymmetricCov3& c) {
    // Rounding: a covariance rotated into the map frame in single precision carries errors of
    // about 1e-7 of its largest entry in every entry, so an exactly singular one (an exact pose,
    // a range-only sensor) can show a variance or minor slightly below zero, by that much of its
    // scale (the trace t), not of its own size. 1e-6 t, 1e-5 t^2 and 1e-5 t^3 leave room; an
    // indefinite covariance (a negative variance, |correlation| > 1) misses them by far.
    constexpr double kVar = 1e-6, kMinor = 1e-5;
    const double xx = c.xx, xy = c.xy, xz = c.xz, yy = c.yy, yz = c.yz, zz = c.zz;
    const double t = xx + yy + zz;
    if (!(t >= 0) || !std::isfinite(t) || !std::isfinite(xy) || !std::isfinite(xz) ||
        !std::isfinite(yz))
        return false;  // also NaN
    if (!(xx >= -kVar * t && yy >= -kVar * t && zz >= -kVar * t)) return false;
    const double t2 = t * t, t3 = t2 * t;
    const double mxy = xx * yy - xy * xy, mxz = xx * zz - xz * xz, myz = yy * zz - yz * yz;
    if (!(mxy >= -kMinor * t2 && mxz >= -kMinor * t2 && myz >= -kMinor * t2)) return false;
    const double det = xx * myz - xy * (xy * zz - yz * xz) + xz * (xy * yz - yy * xz);
    return det >= -kMinor * t3;
}

}  // namespace multibin
