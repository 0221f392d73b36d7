/* Part of the multibin elevation-mapping library. */
#pragma once

#include <Eigen/Core>
#include <cstddef>
#include <vector>

namespace multibin {

/** Upper triangle of a symmetric 3x3 covariance [m^2]. */
struct SymmetricCov3 {
    float xx = 0, xy = 0, xz = 0, yy = 0, yz = 0, zz = 0;

    Eigen::Matrix3d toMatrix() const {
        Eigen::Matrix3d m;
        m << xx, xy, xz, xy, yy, yz, xz, yz, zz;
        return m;
    }
    /** Takes the upper triangle of `m` (assumed symmetric). */
    static SymmetricCov3 fromMatrix(const Eigen::Matrix3d& m) {
        return {float(m(0, 0)), float(m(0, 1)), float(m(0, 2)),
                float(m(1, 1)), float(m(1, 2)), float(m(2, 2))};
    }
};

/** Whether `c` is a covariance: finite and positive semi-definite, all principal minors >= 0
 * to within single-precision rounding. Zero and rank-deficient covariances pass (an exact pose,
 * a range-only sensor: the point is exactly known along some directions); indefinite ones (a
 * negative variance, |correlation| > 1) do not. */
inline bool isCovariance(const SymmetricCov3& c) {
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

/** One 3D point [m] with its full covariance [m^2]. */
struct PointWithCov {
    Eigen::Vector3f point_m;
    SymmetricCov3 cov_m2;
};

/** A batch of points, all in one frame (a sensor frame, or the map frame). */
using PointsWithCov = std::vector<PointWithCov>;

/** Covariance [m^2] of a point measured along the unit ray `dir` with range standard deviation
 * `sigmaRange_m` and perfectly known bearing: sigma^2 * dir * dir^T (eq 3's J_S C_S J_S^T). */
inline SymmetricCov3 rangeOnlyCovariance(const Eigen::Vector3f& dir, float sigmaRange_m) {
    const float s2 = sigmaRange_m * sigmaRange_m;
    return {s2 * dir.x() * dir.x(), s2 * dir.x() * dir.y(), s2 * dir.x() * dir.z(),
            s2 * dir.y() * dir.y(), s2 * dir.y() * dir.z(), s2 * dir.z() * dir.z()};
}

}  // namespace multibin
