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
    m_rotSensorToRobotF = m_rotSensorToRobot.cast<float>();
    m_rotRobotToMapF = m_rotRobotToMap.cast<float>();
    m_rotSensorToMapF = m_rotSensorToMap.cast<float>();
    m_covTTF = m_covTT.cast<float>();
    m_covATF = m_covTA.transpose().cast<float>();
    m_covAAF = m_covAA.cast<float>();
    m_tSensorOnRobotF = m_tSensorOnRobot_m.cast<float>();
    m_tRobotF = m_tRobot_m.cast<float>();
    for (int k = 0; k < 3; k++) m_dRotF[k] = m_dRot[k].cast<float>();
}

Eigen::Matrix<double, 3, 6> PosePropagator::jacobianWrtRobotPose(
    const Eigen::Vector3d& pointInRobot_m) const {
    Eigen::Matrix<double, 3, 6> J;
    J.leftCols<3>().setIdentity();
    for (int k = 0; k < 3; k++) J.col(3 + k) = m_dRot[k] * pointInRobot_m;
    return J;
}

PointWithCov PosePropagator::apply(const PointWithCov& in) const {
    const Eigen::Vector3f pr = m_rotSensorToRobotF * in.point_m + m_tSensorOnRobotF;
    const Eigen::Vector3f pm = m_rotRobotToMapF * pr + m_tRobotF;

    // J_R C_R J_R^T with J_R = [I | M]: C_TT + M C_AT + (M C_AT)^T + M C_AA M^T.
    Eigen::Matrix3f M;
    M.col(0) = m_dRotF[0] * pr;
    M.col(1) = m_dRotF[1] * pr;
    M.col(2) = m_dRotF[2] * pr;
    const Eigen::Matrix3f MCat = M * m_covATF;
    const Eigen::Matrix3f MCaa = M * m_covAAF;
    // J_S C_S J_S^T with J_S the sensor-to-map rotation.
    const SymmetricCov3& s = in.cov_m2;
    Eigen::Matrix3f Cs;
    Cs << s.xx, s.xy, s.xz, s.xy, s.yy, s.yz, s.xz, s.yz, s.zz;
    const Eigen::Matrix3f RCs = m_rotSensorToMapF * Cs;

    // Only the upper triangle of the symmetric sum is needed.
    auto entry = [&](int r, int c) {
        return m_covTTF(r, c) + MCat(r, c) + MCat(c, r) + MCaa.row(r).dot(M.row(c)) +
               RCs.row(r).dot(m_rotSensorToMapF.row(c));
    };
    return PointWithCov{pm, SymmetricCov3{entry(0, 0), entry(0, 1), entry(0, 2), entry(1, 1),
                                          entry(1, 2), entry(2, 2)}};
}

void PosePropagator::apply(const PointsWithCov& in, PointsWithCov& out) const {
    out.resize(in.size());
    for (size_t i = 0; i < in.size(); i++) out[i] = apply(in[i]);
}

}  // namespace multibin
