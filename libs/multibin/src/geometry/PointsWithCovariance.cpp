/* Part of the multibin elevation-mapping library. */
#include "multibin/geometry/PointsWithCovariance.h"

namespace multibin {

bool isSingularCovariance(const SymmetricCov3& c) {
    // Rounding: float entries carry a relative error of 6e-8, so a singular covariance can show
    // minors of -1e-7 of their scale; 1e-5 leaves room. The absolute terms cover entries that
    // rounded to zero (variances below (1e-12 m)^2 are exact for any purpose).
    constexpr double kRel = 1e-5, kAbs2 = 1e-48, kAbs3 = 1e-72;
    const double xx = c.xx, xy = c.xy, xz = c.xz, yy = c.yy, yz = c.yz, zz = c.zz;
    if (!(xx >= 0 && yy >= 0 && zz >= 0)) return false;  // also NaN
    const double mxy = xx * yy - xy * xy, mxz = xx * zz - xz * xz, myz = yy * zz - yz * yz;
    if (!(mxy >= -kRel * xx * yy - kAbs2 && mxz >= -kRel * xx * zz - kAbs2 &&
          myz >= -kRel * yy * zz - kAbs2))
        return false;
    const double det = xx * myz - xy * (xy * zz - yz * xz) + xz * (xy * yz - yy * xz);
    return det >= -kRel * xx * yy * zz - kAbs3;
}

}  // namespace multibin
