/* Pose propagation (PosePropagation.h): the Jacobian with respect to the robot pose against
 * finite differences and MRPT, the pose part of a height's variance, and the propagated
 * covariance against Monte Carlo. */
#include <gtest/gtest.h>
#include <mrpt/poses/CPose3DPDFGaussian.h>
#include <mrpt/random/RandomGenerators.h>

#include <Eigen/Dense>
#include <random>

#include "../common/test_scenes.h"
#include "multibin/geometry/PosePropagation.h"

using mrpt::poses::CPose3D;
using mrpt::poses::CPose3DPDFGaussian;
using test_scenes::poseWithCov;

TEST(PosePropagation, JacobianMatchesFiniteDifferencesAndMrpt) {
    const CPose3DPDFGaussian robot =
        poseWithCov(CPose3D(1.0, -2.0, 0.3, 0.7, -0.2, 0.15), {0.01, 0.01, 0.01, 0.01, 0.01, 0.01});
    const CPose3D sensor(0.1, 0.0, 0.26, 0.0, mrpt::DEG2RAD(45.0), 0.0);
    const multibin::PosePropagator prop(robot, sensor);
    const Eigen::Vector3d pr(0.8, 0.3, -0.1);  // point in the robot frame
    const Eigen::Matrix<double, 3, 6> J = prop.jacobianWrtRobotPose(pr);
    const double h = 1e-6;
    for (int k = 0; k < 6; k++) {
        double vp[6], vm[6];
        for (int i = 0; i < 6; i++) vp[i] = vm[i] = robot.mean[i];
        vp[k] += h;
        vm[k] -= h;
        const CPose3D plus(vp[0], vp[1], vp[2], vp[3], vp[4], vp[5]);
        const CPose3D minus(vm[0], vm[1], vm[2], vm[3], vm[4], vm[5]);
        const auto gp = plus.composePoint(mrpt::math::TPoint3D(pr.x(), pr.y(), pr.z()));
        const auto gm = minus.composePoint(mrpt::math::TPoint3D(pr.x(), pr.y(), pr.z()));
        EXPECT_NEAR(J(0, k), (gp.x - gm.x) / (2 * h), 1e-6) << "column " << k;
        EXPECT_NEAR(J(1, k), (gp.y - gm.y) / (2 * h), 1e-6) << "column " << k;
        EXPECT_NEAR(J(2, k), (gp.z - gm.z) / (2 * h), 1e-6) << "column " << k;
    }
    mrpt::math::CMatrixDouble36 Jmrpt;
    double gx, gy, gz;
    robot.mean.composePoint(pr.x(), pr.y(), pr.z(), gx, gy, gz, std::nullopt, Jmrpt);
    for (int r = 0; r < 3; r++)
        for (int c = 0; c < 6; c++) EXPECT_NEAR(J(r, c), Jmrpt(r, c), 1e-9);
}

TEST(PosePropagation, PoseHeightVarianceIsTheJacobiansQuadraticForm) {
    // The double-precision polynomial the continuity bound (eq 14) evaluates against
    // (J_R C_R J_R^T)_zz from the Jacobian, with a full correlated covariance, at random points.
    std::mt19937 rng(3);
    std::uniform_real_distribution<double> unit(-1.0, 1.0);
    for (int trial = 0; trial < 20; trial++) {
        CPose3DPDFGaussian robot;
        robot.mean = CPose3D(unit(rng), unit(rng), 0.3 * unit(rng), 3 * unit(rng), 0.5 * unit(rng),
                             0.5 * unit(rng));
        Eigen::Matrix<double, 6, 6> A;
        for (int r = 0; r < 6; r++)
            for (int c = 0; c < 6; c++) A(r, c) = 0.01 * unit(rng);
        const Eigen::Matrix<double, 6, 6> C = A * A.transpose();  // positive semi-definite
        for (int r = 0; r < 6; r++)
            for (int c = 0; c < 6; c++) robot.cov(r, c) = C(r, c);
        const CPose3D sensor(0.1, 0.05, 0.26, 0.2, mrpt::DEG2RAD(40.0), 0.1);
        const multibin::PosePropagator prop(robot, sensor);
        for (int k = 0; k < 50; k++) {
            const Eigen::Vector3d ps(3 * unit(rng), 3 * unit(rng), 3 * unit(rng));
            Eigen::Vector3d pr;
            sensor.composePoint(ps.x(), ps.y(), ps.z(), pr.x(), pr.y(), pr.z());
            const Eigen::Matrix<double, 1, 6> j = prop.jacobianWrtRobotPose(pr).row(2);
            const double expected = (j * C * j.transpose())(0, 0);
            EXPECT_NEAR(prop.poseHeightVariance_m2(ps.x(), ps.y(), ps.z()), expected,
                        1e-12 + 1e-9 * expected);
        }
    }
}

TEST(PosePropagation, CovarianceMatchesMonteCarlo) {
    const CPose3DPDFGaussian robot = poseWithCov(CPose3D(0.5, 0.2, 0.1, 0.3, 0.05, -0.04),
                                                 {0.02, 0.015, 0.01, 0.02, 0.01, 0.015});
    const CPose3D sensor(0.1, 0.0, 0.26, 0.0, mrpt::DEG2RAD(45.0), 0.0);
    const multibin::PosePropagator prop(robot, sensor);
    multibin::PointWithCov ps;
    ps.point_m = Eigen::Vector3f(0.6f, 0.2f, 0.0f);
    const Eigen::Vector3f dir = ps.point_m.normalized();
    ps.cov_m2 = multibin::rangeOnlyCovariance(dir, 0.005f);
    const multibin::PointWithCov pm = prop.apply(ps);
    const Eigen::Matrix3d C = pm.cov_m2.toMatrix();

    mrpt::random::CRandomGenerator rng(1234);
    std::mt19937 gen(99);
    std::normal_distribution<double> n01;
    const int N = 20000;
    std::vector<mrpt::math::CVectorDouble> poses;
    rng.drawGaussianMultivariateMany(poses, N, robot.cov);
    Eigen::Vector3d mean = Eigen::Vector3d::Zero();
    Eigen::Matrix3d M2 = Eigen::Matrix3d::Zero();
    std::vector<Eigen::Vector3d> samples;
    double nees = 0;
    const Eigen::Matrix3d Cinv = C.inverse();
    for (int s = 0; s < N; s++) {
        double v[6];
        for (int i = 0; i < 6; i++) v[i] = robot.mean[i] + poses[size_t(s)][i];
        const CPose3D R(v[0], v[1], v[2], v[3], v[4], v[5]);
        const Eigen::Vector3d local = (ps.point_m + dir * float(0.005 * n01(gen))).cast<double>();
        const auto g =
            (R + sensor).composePoint(mrpt::math::TPoint3D(local.x(), local.y(), local.z()));
        const Eigen::Vector3d e = Eigen::Vector3d(g.x, g.y, g.z) - pm.point_m.cast<double>();
        M2 += e * e.transpose();
        nees += e.dot(Cinv * e);
    }
    M2 /= N;
    for (int r = 0; r < 3; r++)
        for (int c = 0; c < 3; c++)
            EXPECT_NEAR(M2(r, c), C(r, c), 0.05 * std::sqrt(C(r, r) * C(c, c)))
                << "entry " << r << "," << c;
    // Mean NEES of N samples of a 3-dof chi-square: 3 +- 99 % bounds (normal approx., 6/N var).
    const double meanNees = nees / N, halfWidth = 2.576 * std::sqrt(6.0 / N);
    EXPECT_GT(meanNees, 3 - halfWidth);
    EXPECT_LT(meanNees, 3 + halfWidth);
}
