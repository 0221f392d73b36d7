/* Part of the multibin elevation-mapping library. */
#pragma once

#include <mrpt/poses/CPose3D.h>
#include <mrpt/poses/CPose3DPDFGaussian.h>

#include <Eigen/Core>

#include "multibin/geometry/PointsWithCovariance.h"

namespace multibin {

/** Moves points from a sensor frame into the map frame with their covariance (eqs 3, 11-12):
 *
 *   p_map = R (+) (S (+) p_sensor)
 *   C_map = J_R C_R J_R^T + J_S C_S J_S^T
 *
 * R is the robot pose in the map with its 6x6 covariance C_R over (x, y, z, yaw, pitch, roll)
 * [m, rad] (MRPT's CPose3DPDFGaussian convention); S the sensor pose on the robot, taken as exact
 * (rigid, calibrated off-line); C_S the point's covariance in the sensor frame.
 *
 * J_R = [I_3 | dRot/dyaw p_r, dRot/dpitch p_r, dRot/droll p_r] with p_r the point in the robot
 * frame. J_R is affine in the sensor-frame point, so every entry of J_R C_R J_R^T is a quadratic
 * polynomial in (x, y, z) of the sensor-frame point, and every entry of J_S C_S J_S^T (J_S the
 * sensor-to-map rotation) is linear in the six entries of C_S. The constructor folds the pose, its
 * covariance and the sensor pose into those polynomial coefficients (in double); per point what
 * is left is about a hundred single-precision multiply-adds, evaluated over blocks of points in
 * structure-of-arrays form so the compiler vectorises them. */
/** Points in structure-of-arrays form, a block at a time: the layout the propagation computes in
 * and the insertion core classifies from, so neither converts to PointWithCov and back. */
struct PointBlock {
    static constexpr size_t kCapacity = 256;
    /** x, y, z [m], then the covariance entries xx, xy, xz, yy, yz, zz [m^2]. */
    alignas(64) float v[9][kCapacity];
    /** The pose's part of each point's map-frame height variance and of its horizontal variance
     * (the mean of xx and yy) [m^2]: written by the propagation; NaN where not known. */
    alignas(64) float poseVariance_m2[2][kCapacity];

    /** Copies `in[0 .. n)`, n <= kCapacity (v only). */
    void gather(const PointWithCov* in, size_t n);
};

/** The pose's part of points' map-frame height and horizontal variance [m^2], a value per point
 * (PointBlock::poseVariance_m2's, for points that travel as PointWithCov). */
struct PoseVariances {
    std::vector<float> height_m2, horizontal_m2;
};

class PosePropagator {
public:
    PosePropagator(const mrpt::poses::CPose3DPDFGaussian& robotPoseInMap,
                   const mrpt::poses::CPose3D& sensorPoseOnRobot);

    /** One point; `in.cov_m2` is the sensor-frame covariance. */
    PointWithCov apply(const PointWithCov& in) const;

    /** A batch; `out` is resized to match `in` (no allocation once it has the capacity). With
     * `pose`, also the pose's part of each point's variances. */
    void apply(const PointsWithCov& in, PointsWithCov& out, PoseVariances* pose = nullptr) const;

    /** A batch from `in[0 .. n)` into `out[0 .. n)`; the ranges may be the same (in place) but
     * must not otherwise overlap. */
    void apply(const PointWithCov* in, PointWithCov* out, size_t n,
               PoseVariances* pose = nullptr) const;

    /** A block: `in[0 .. n)` (n <= PointBlock::kCapacity) into `out`, the same values as
     * apply(). */
    void applyBlock(const PointWithCov* in, size_t n, PointBlock& out) const;

    /** d p_map / d (x, y, z, yaw, pitch, roll) of the robot pose, at a point given in the robot
     * frame [m]. */
    Eigen::Matrix<double, 3, 6> jacobianWrtRobotPose(const Eigen::Vector3d& pointInRobot_m) const;

    /** The z-z entry of J_R C_R J_R^T at a sensor-frame point [m^2]: the robot pose's share of
     * the point's height variance, in double from the same polynomial apply() evaluates in single
     * precision (ten multiply-adds, no Jacobian). Clamped at 0 (rounding). */
    double poseHeightVariance_m2(double x_m, double y_m, double z_m) const {
        return heightVariancePolynomial(m_poseHeightVariance, x_m, y_m, z_m);
    }
    /** Its coefficients, of the monomials 1, x, y, z, xx, xy, xz, yy, yz, zz, for loops over
     * points that evaluate heightVariancePolynomial themselves. */
    const double* poseHeightVarianceCoefficients() const { return m_poseHeightVariance; }
    /** The polynomial of poseHeightVariance_m2 with coefficients `c`, clamped at 0; no branch. */
    static double heightVariancePolynomial(const double* c, double x, double y, double z) {
        const double v = c[0] + c[1] * x + c[2] * y + c[3] * z + c[4] * x * x + c[5] * x * y +
                         c[6] * x * z + c[7] * y * y + c[8] * y * z + c[9] * z * z;
        return v > 0 ? v : 0.0;
    }

    /** Sensor origin in the map frame [m]. */
    const Eigen::Vector3d& sensorOriginInMap_m() const { return m_sensorOrigin_m; }

    /** Sensor-to-map rotation. */
    const Eigen::Matrix3d& rotationSensorToMap() const { return m_rotSensorToMap; }

    /** Map-frame x and y of a sensor-frame point [m], in double from the same pose (apply()
     * evaluates in single precision): for tests that must bound apply()'s result cheaply. */
    Eigen::Vector2d horizontalInMap_m(const Eigen::Vector3f& p_m) const {
        const double px = p_m.x(), py = p_m.y(), pz = p_m.z();
        const Eigen::Matrix3d& A = m_rotSensorToMap;
        return {A(0, 0) * px + A(0, 1) * py + A(0, 2) * pz + m_sensorOrigin_m.x(),
                A(1, 0) * px + A(1, 1) * py + A(1, 2) * pz + m_sensorOrigin_m.y()};
    }

    /** Coefficients of the per-point evaluation (single precision), public for the kernel. */
    struct Coefficients {
        float rot[9];    //!< sensor-to-map rotation, row-major
        float trans[3];  //!< sensor origin in the map [m]
        /** Per covariance entry (xx, xy, xz, yy, yz, zz) of J_R C_R J_R^T: coefficients of the
         * monomials 1, x, y, z, xx, xy, xz, yy, yz, zz of the sensor-frame point [m^2 / m^k]. */
        float robot[6][10];
        /** Per covariance entry of J_S C_S J_S^T: coefficients of the six sensor-frame
         * covariance entries (xx, xy, xz, yy, yz, zz) [1]. */
        float sensor[6][6];
    };

private:
    Eigen::Vector3d m_sensorOrigin_m;
    Eigen::Matrix3d m_rotSensorToMap;  //!< sensor-to-map rotation
    Eigen::Matrix3d m_dRot[3];         //!< dRot/dyaw, dRot/dpitch, dRot/droll of the robot pose
    Coefficients m_k;
    /** m_k.robot's z-z row in double [m^2 / m^k]. */
    double m_poseHeightVariance[10];
};

}  // namespace multibin
