/* Part of the multibin elevation-mapping library. */
#include "multibin/PosePropagation.h"

#include <cmath>

namespace multibin {

namespace {
Eigen::Matrix3d toEigen(const mrpt::math::CMatrixDouble33& m) {
    Eigen::Matrix3d e;
    for (int r = 0; r < 3; r++)
        for (int c = 0; c < 3; c++) e(r, c) = m(r, c);
    return e;
}
}  // namespace

PosePropagator::PosePropagator(const mrpt::poses::CPose3DPDFGaussian& robotPoseInMap,
                               const mrpt::poses::CPose3D& sensorPoseOnRobot) {
    const mrpt::poses::CPose3D& R = robotPoseInMap.mean;
    m_rotRobotToMap = toEigen(R.getRotationMatrix());
    m_rotSensorToRobot = toEigen(sensorPoseOnRobot.getRotationMatrix());
    m_rotSensorToMap = m_rotRobotToMap * m_rotSensorToRobot;
    m_tRobot_m = Eigen::Vector3d(R.x(), R.y(), R.z());
    m_tSensorOnRobot_m =
        Eigen::Vector3d(sensorPoseOnRobot.x(), sensorPoseOnRobot.y(), sensorPoseOnRobot.z());
    m_sensorOrigin_m = m_rotRobotToMap * m_tSensorOnRobot_m + m_tRobot_m;

    // MRPT: Rot = Rz(yaw) Ry(pitch) Rx(roll).
    const double cy = std::cos(R.yaw()), sy = std::sin(R.yaw());
    const double cp = std::cos(R.pitch()), sp = std::sin(R.pitch());
    const double cr = std::cos(R.roll()), sr = std::sin(R.roll());
    Eigen::Matrix3d Rz, Ry, Rx, dRz, dRy, dRx;
    Rz << cy, -sy, 0, sy, cy, 0, 0, 0, 1;
    Ry << cp, 0, sp, 0, 1, 0, -sp, 0, cp;
    Rx << 1, 0, 0, 0, cr, -sr, 0, sr, cr;
    dRz << -sy, -cy, 0, cy, -sy, 0, 0, 0, 0;
    dRy << -sp, 0, cp, 0, 0, 0, -cp, 0, -sp;
    dRx << 0, 0, 0, 0, -sr, -cr, 0, cr, -sr;
    m_dRot[0] = dRz * Ry * Rx;
    m_dRot[1] = Rz * dRy * Rx;
    m_dRot[2] = Rz * Ry * dRx;

    const auto& C = robotPoseInMap.cov;
    for (int r = 0; r < 3; r++)
        for (int c = 0; c < 3; c++) {
            m_covTT(r, c) = C(r, c);
            m_covTA(r, c) = C(r, 3 + c);
            m_covAA(r, c) = C(3 + r, 3 + c);
        }
}

Eigen::Matrix<double, 3, 6> PosePropagator::jacobianWrtRobotPose(
    const Eigen::Vector3d& pointInRobot_m) const {
    Eigen::Matrix<double, 3, 6> J;
    J.leftCols<3>().setIdentity();
    for (int k = 0; k < 3; k++) J.col(3 + k) = m_dRot[k] * pointInRobot_m;
    return J;
}

PointWithCov PosePropagator::apply(const PointWithCov& in) const {
    const Eigen::Vector3d ps = in.point_m.cast<double>();
    const Eigen::Vector3d pr = m_rotSensorToRobot * ps + m_tSensorOnRobot_m;
    const Eigen::Vector3d pm = m_rotRobotToMap * pr + m_tRobot_m;

    // J_R C_R J_R^T with J_R = [I | M]: C_TT + M C_AT + C_TA M^T + M C_AA M^T.
    Eigen::Matrix3d M;
    for (int k = 0; k < 3; k++) M.col(k) = m_dRot[k] * pr;
    const Eigen::Matrix3d MCat = M * m_covTA.transpose();
    Eigen::Matrix3d cov = m_covTT + MCat + MCat.transpose() + M * m_covAA * M.transpose();
    // J_S C_S J_S^T with J_S the sensor-to-map rotation.
    cov += m_rotSensorToMap * in.cov_m2.toMatrix() * m_rotSensorToMap.transpose();

    return PointWithCov{pm.cast<float>(), SymmetricCov3::fromMatrix(cov)};
}

void PosePropagator::apply(const PointsWithCov& in, PointsWithCov& out) const {
    out.resize(in.size());
    for (size_t i = 0; i < in.size(); i++) out[i] = apply(in[i]);
}

}  // namespace multibin
