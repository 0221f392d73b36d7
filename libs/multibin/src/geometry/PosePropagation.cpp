/* Part of the multibin elevation-mapping library. */
#include "multibin/geometry/PosePropagation.h"

#include "multibin/util/VectorClones.h"

#include <algorithm>
#include <cmath>
#include <cstdint>

namespace multibin {

namespace {
Eigen::Matrix3d toEigen(const mrpt::math::CMatrixDouble33& m) {
    Eigen::Matrix3d e;
    for (int r = 0; r < 3; r++)
        for (int c = 0; c < 3; c++) e(r, c) = m(r, c);
    return e;
}

/** Index pairs (r, c) of the stored upper triangle, in SymmetricCov3's order. */
constexpr int kEntryRow[6] = {0, 0, 0, 1, 1, 2};
constexpr int kEntryCol[6] = {0, 1, 2, 1, 2, 2};

constexpr size_t kBlock = PointBlock::kCapacity;

void scatter(const PointBlock& b, size_t n, PointWithCov* out) {
    for (size_t i = 0; i < n; i++) {
        out[i].point_m = Eigen::Vector3f(b.v[0][i], b.v[1][i], b.v[2][i]);
        out[i].cov_m2 =
            SymmetricCov3{b.v[3][i], b.v[4][i], b.v[5][i], b.v[6][i], b.v[7][i], b.v[8][i]};
    }
}

/** The per-point work over one block. Loops run over points innermost with loop-invariant
 * coefficients, so each is a plain vectorisable stream, built for AVX-512, AVX2 and the baseline
 * (MULTIBIN_VECTOR_CLONES: bit-identical whichever runs). */
MULTIBIN_VECTOR_CLONES
void propagateBlock(const PosePropagator::Coefficients& k, size_t n, const PointBlock& in,
                    PointBlock& out) {
    const float* __restrict x = in.v[0];
    const float* __restrict y = in.v[1];
    const float* __restrict z = in.v[2];
    alignas(64) float mono[6][kBlock];  // xx, xy, xz, yy, yz, zz
    for (size_t i = 0; i < n; i++) {
        mono[0][i] = x[i] * x[i];
        mono[1][i] = x[i] * y[i];
        mono[2][i] = x[i] * z[i];
        mono[3][i] = y[i] * y[i];
        mono[4][i] = y[i] * z[i];
        mono[5][i] = z[i] * z[i];
    }
    for (int r = 0; r < 3; r++) {
        const float a0 = k.rot[3 * r], a1 = k.rot[3 * r + 1], a2 = k.rot[3 * r + 2], t = k.trans[r];
        float* __restrict o = out.v[r];
        for (size_t i = 0; i < n; i++) o[i] = a0 * x[i] + a1 * y[i] + a2 * z[i] + t;
    }
    for (int e = 0; e < 6; e++) {
        const float* q = k.robot[e];
        const float* s = k.sensor[e];
        const float(*__restrict c)[kBlock] = in.v + 3;  // the covariance entries xx .. zz
        const float q0 = q[0], q1 = q[1], q2 = q[2], q3 = q[3], q4 = q[4], q5 = q[5], q6 = q[6],
                    q7 = q[7], q8 = q[8], q9 = q[9];
        const float s0 = s[0], s1 = s[1], s2 = s[2], s3 = s[3], s4 = s[4], s5 = s[5];
        float* __restrict o = out.v[3 + e];
        alignas(64) float robotPart[kBlock];
        for (size_t i = 0; i < n; i++) {
            const float robot = q0 + q1 * x[i] + q2 * y[i] + q3 * z[i] + q4 * mono[0][i] +
                                q5 * mono[1][i] + q6 * mono[2][i] + q7 * mono[3][i] +
                                q8 * mono[4][i] + q9 * mono[5][i];
            const float sensor = s0 * c[0][i] + s1 * c[1][i] + s2 * c[2][i] + s3 * c[3][i] +
                                 s4 * c[4][i] + s5 * c[5][i];
            robotPart[i] = robot;
            o[i] = robot + sensor;
        }
        // The pose's part of zz, and of the mean of xx and yy, kept apart too (separate loops:
        // a select in the loop above keeps GCC from vectorising it).
        float* __restrict height = out.poseVariance_m2[0];
        float* __restrict horizontal = out.poseVariance_m2[1];
        if (e == 5) std::copy_n(robotPart, n, height);
        if (e == 0)
            for (size_t i = 0; i < n; i++) horizontal[i] = 0.5f * robotPart[i];
        if (e == 3)
            for (size_t i = 0; i < n; i++) horizontal[i] += 0.5f * robotPart[i];
    }
}
}  // namespace

PosePropagator::PosePropagator(const mrpt::poses::CPose3DPDFGaussian& robotPoseInMap,
                               const mrpt::poses::CPose3D& sensorPoseOnRobot) {
    const mrpt::poses::CPose3D& R = robotPoseInMap.mean;
    const Eigen::Matrix3d rotRobotToMap = toEigen(R.getRotationMatrix());
    const Eigen::Matrix3d rotSensorToRobot = toEigen(sensorPoseOnRobot.getRotationMatrix());
    m_rotSensorToMap = rotRobotToMap * rotSensorToRobot;
    const Eigen::Matrix3d& rotSensorToMap = m_rotSensorToMap;
    const Eigen::Vector3d tRobot_m(R.x(), R.y(), R.z());
    const Eigen::Vector3d tSensorOnRobot_m(sensorPoseOnRobot.x(), sensorPoseOnRobot.y(),
                                           sensorPoseOnRobot.z());
    m_sensorOrigin_m = rotRobotToMap * tSensorOnRobot_m + tRobot_m;

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
    Eigen::Matrix3d covTT, covAT, covAA;  // translation / angle blocks of C_R
    for (int r = 0; r < 3; r++)
        for (int c = 0; c < 3; c++) {
            covTT(r, c) = C(r, c);
            covAT(r, c) = C(3 + r, c);
            covAA(r, c) = C(3 + r, 3 + c);
        }

    // M(r, k) = (dRot_k p_r)_r with p_r = Rs p_s + t_s is affine in q = (p_s, 1): M(r, k) = g_rk.q.
    Eigen::Vector4d g[3][3];
    for (int k = 0; k < 3; k++) {
        const Eigen::Matrix3d DRs = m_dRot[k] * rotSensorToRobot;
        const Eigen::Vector3d Dts = m_dRot[k] * tSensorOnRobot_m;
        for (int r = 0; r < 3; r++) g[r][k] << DRs(r, 0), DRs(r, 1), DRs(r, 2), Dts(r);
    }
    // Entry (r, c) of J_R C_R J_R^T = C_TT + M C_AT + (M C_AT)^T + M C_AA M^T, as q^T P q plus a
    // linear term; collected onto the monomials 1, x, y, z, xx, xy, xz, yy, yz, zz.
    // Monomial index of q_i q_j (i <= j; q_3 = 1).
    constexpr int kMono[4][4] = {{4, 5, 6, 1}, {5, 7, 8, 2}, {6, 8, 9, 3}, {1, 2, 3, 0}};
    for (int e = 0; e < 6; e++) {
        const int r = kEntryRow[e], c = kEntryCol[e];
        double coef[10] = {};
        coef[0] = covTT(r, c);
        Eigen::Vector4d lin = Eigen::Vector4d::Zero();
        Eigen::Matrix4d P = Eigen::Matrix4d::Zero();
        for (int k = 0; k < 3; k++) {
            lin += covAT(k, c) * g[r][k] + covAT(k, r) * g[c][k];
            for (int l = 0; l < 3; l++) P += covAA(k, l) * g[r][k] * g[c][l].transpose();
        }
        for (int i = 0; i < 4; i++) {
            coef[kMono[i][3]] += lin(i);  // q_i * q_3
            for (int j = 0; j < 4; j++) coef[kMono[std::min(i, j)][std::max(i, j)]] += P(i, j);
        }
        for (int m = 0; m < 10; m++) m_k.robot[e][m] = static_cast<float>(coef[m]);
        if (r == 2 && c == 2)
            for (int m = 0; m < 10; m++) m_poseHeightVariance[m] = coef[m];
    }
    // Entry (r, c) of A C_S A^T = sum_ij A(r, i) C_S(i, j) A(c, j), A the sensor-to-map rotation.
    const Eigen::Matrix3d& A = rotSensorToMap;
    for (int e = 0; e < 6; e++) {
        const int r = kEntryRow[e], c = kEntryCol[e];
        for (int f = 0; f < 6; f++) {
            const int i = kEntryRow[f], j = kEntryCol[f];
            const double v = i == j ? A(r, i) * A(c, i) : A(r, i) * A(c, j) + A(r, j) * A(c, i);
            m_k.sensor[e][f] = static_cast<float>(v);
        }
    }
    for (int r = 0; r < 3; r++) {
        for (int c = 0; c < 3; c++) m_k.rot[3 * r + c] = static_cast<float>(A(r, c));
        m_k.trans[r] = static_cast<float>(m_sensorOrigin_m(r));
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
    PointWithCov out;
    apply(&in, &out, 1);
    return out;
}

void PosePropagator::apply(const PointsWithCov& in, PointsWithCov& out, PoseVariances* pose) const {
    out.resize(in.size());
    apply(in.data(), out.data(), in.size(), pose);
}

void PointBlock::gather(const PointWithCov* in, size_t n) {
    for (size_t i = 0; i < n; i++) {
        // Ask for the input 32 points (1.1 kB) ahead: a frame's points stream from memory, and
        // this stride-9 copy issues loads too slowly for the hardware prefetcher to keep ahead
        // (the map's core 7-8 % faster on 2 M points). An address, not a pointer: it may lie past
        // the array, and prefetching never faults.
        __builtin_prefetch(
            reinterpret_cast<const void*>(reinterpret_cast<uintptr_t>(in + i) + 32 * sizeof *in));
        v[0][i] = in[i].point_m.x();
        v[1][i] = in[i].point_m.y();
        v[2][i] = in[i].point_m.z();
        v[3][i] = in[i].cov_m2.xx;
        v[4][i] = in[i].cov_m2.xy;
        v[5][i] = in[i].cov_m2.xz;
        v[6][i] = in[i].cov_m2.yy;
        v[7][i] = in[i].cov_m2.yz;
        v[8][i] = in[i].cov_m2.zz;
    }
}

void PosePropagator::applyBlock(const PointWithCov* in, size_t n, PointBlock& out) const {
    PointBlock src;
    src.gather(in, n);
    propagateBlock(m_k, n, src, out);
}

void PosePropagator::apply(const PointWithCov* in, PointWithCov* out, size_t n,
                           PoseVariances* pose) const {
    if (pose) {
        pose->height_m2.resize(n);
        pose->horizontal_m2.resize(n);
    }
    PointBlock dst;
    for (size_t begin = 0; begin < n; begin += kBlock) {
        const size_t m = std::min(kBlock, n - begin);
        applyBlock(in + begin, m, dst);  // reads in[begin ..) before out[begin ..) is written
        scatter(dst, m, out + begin);
        if (pose) {
            std::copy_n(dst.poseVariance_m2[0], m, pose->height_m2.data() + begin);
            std::copy_n(dst.poseVariance_m2[1], m, pose->horizontal_m2.data() + begin);
        }
    }
}

}  // namespace multibin
