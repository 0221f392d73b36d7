/* Part of the multibin elevation-mapping library. */
#pragma once

#include <mrpt/poses/CPose3D.h>
#include <mrpt/poses/CPose3DPDFGaussian.h>

#include <Eigen/Core>

#include "multibin/PointsWithCovariance.h"

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
 * frame, so the per-point cost is a few 3x3 products: the rotation derivatives are computed once
 * per pose. */
class PosePropagator {
public:
    PosePropagator(const mrpt::poses::CPose3DPDFGaussian& robotPoseInMap,
                   const mrpt::poses::CPose3D& sensorPoseOnRobot);

    /** One point; `in.cov_m2` is the sensor-frame covariance. */
    PointWithCov apply(const PointWithCov& in) const;

    /** A batch; `out` is resized to match `in`. */
    void apply(const PointsWithCov& in, PointsWithCov& out) const;

    /** d p_map / d (x, y, z, yaw, pitch, roll) of the robot pose, at a point given in the robot
     * frame [m]. */
    Eigen::Matrix<double, 3, 6> jacobianWrtRobotPose(const Eigen::Vector3d& pointInRobot_m) const;

    /** Sensor origin in the map frame [m]. */
    const Eigen::Vector3d& sensorOriginInMap_m() const { return m_sensorOrigin_m; }

private:
    Eigen::Matrix3d m_rotSensorToRobot, m_rotSensorToMap, m_rotRobotToMap;
    Eigen::Vector3d m_tSensorOnRobot_m, m_tRobot_m, m_sensorOrigin_m;
    Eigen::Matrix3d m_dRot[3];  //!< dRot/dyaw, dRot/dpitch, dRot/droll of the robot pose
    Eigen::Matrix3d m_covTT, m_covTA, m_covAA;  //!< blocks of C_R: translation / angles
    // Single-precision copies for the per-point work (covariances need no more).
    Eigen::Matrix3f m_rotSensorToRobotF, m_rotRobotToMapF, m_rotSensorToMapF, m_covTTF, m_covATF,
        m_covAAF;
    Eigen::Vector3f m_tSensorOnRobotF, m_tRobotF;
    Eigen::Matrix3f m_dRotF[3];
};

}  // namespace multibin
