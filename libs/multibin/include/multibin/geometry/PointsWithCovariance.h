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

/** Whether `c`, not positive-definite, is still positive semi-definite: all principal minors
 * >= 0 to within single-precision rounding (see isCovariance). */
#if defined(__GNUC__)
__attribute__((cold))  // exact poses only: kept out of the insertion loop's hot code
#endif
bool isSingularCovariance(const SymmetricCov3& c);

/** Whether `c` is a covariance: finite and positive semi-definite. Zero and rank-deficient
 * covariances pass (an exact pose, a range-only sensor: the point is exactly known along some
 * directions); indefinite ones (a negative variance, |correlation| > 1) and NaN do not. */
/** Positive definite by Sylvester's criterion (leading minors), in double; no branch, so loops
 * over points vectorise. */
inline bool isPositiveDefinite(double xx, double xy, double xz, double yy, double yz, double zz) {
    const double m2 = xx * yy - xy * xy;
    const double m3 =
        xx * (yy * zz - yz * yz) - xy * (xy * zz - yz * xz) + xz * (xy * yz - yy * xz);
    return (xx > 0) & (m2 > 0) & (m3 > 0);
}

inline bool isCovariance(const SymmetricCov3& c) {
    if (__builtin_expect(isPositiveDefinite(c.xx, c.xy, c.xz, c.yy, c.yz, c.zz), 1))
        return true;  // the common case
    return isSingularCovariance(c);
}

/** One 3D point [m] with its full covariance [m^2]. */
struct PointWithCov {
    Eigen::Vector3f point_m;
    SymmetricCov3 cov_m2;
};

/** A batch of points, all in one frame (a sensor frame, or the map frame). */
using PointsWithCov = std::vector<PointWithCov>;

/** The positions of `in[0 .. n)` into three arrays (structure of arrays, for loops over a block of
 * points that the compiler vectorises); T float or double [m]. */
template <typename T>
void gatherPositions(const PointWithCov* in, size_t n, T* x, T* y, T* z) {
    for (size_t i = 0; i < n; i++) {
        x[i] = in[i].point_m.x();
        y[i] = in[i].point_m.y();
        z[i] = in[i].point_m.z();
    }
}

/** Covariance [m^2] of a point measured along the unit ray `dir` with range standard deviation
 * `sigmaRange_m` and perfectly known bearing: sigma^2 * dir * dir^T (eq 3's J_S C_S J_S^T). */
inline SymmetricCov3 rangeOnlyCovariance(const Eigen::Vector3f& dir, float sigmaRange_m) {
    const float s2 = sigmaRange_m * sigmaRange_m;
    return {s2 * dir.x() * dir.x(), s2 * dir.x() * dir.y(), s2 * dir.x() * dir.z(),
            s2 * dir.y() * dir.y(), s2 * dir.y() * dir.z(), s2 * dir.z() * dir.z()};
}

}  // namespace multibin
