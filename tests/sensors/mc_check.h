/* Monte Carlo consistency checks shared by the sensor tests. */
#pragma once

#include <gtest/gtest.h>
#include <mrpt/poses/CPose3D.h>
#include <mrpt/poses/CPose3DPDFGaussian.h>

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>
#include <vector>

#include "multibin/geometry/PosePropagation.h"
#include "multibin/sensors/RayModel.h"

namespace mc {

/** A robot pose PDF with correlated 6x6 covariance (x y z yaw pitch roll). */
inline mrpt::poses::CPose3DPDFGaussian robotPosePdf() {
    mrpt::poses::CPose3DPDFGaussian pdf;
    pdf.mean = mrpt::poses::CPose3D(1.0, 2.0, 0.1, 0.3, 0.02, -0.01);
    Eigen::Matrix<double, 6, 1> s;
    s << 0.01, 0.012, 0.008, 0.004, 0.003, 0.003;
    Eigen::Matrix<double, 6, 6> C =
        (s * s.transpose()).cwiseProduct(Eigen::Matrix<double, 6, 6>::Identity());
    C(0, 1) = C(1, 0) = 0.3 * s[0] * s[1];
    C(2, 4) = C(4, 2) = -0.4 * s[2] * s[4];
    C(0, 3) = C(3, 0) = 0.2 * s[0] * s[3];
    for (int r = 0; r < 6; r++)
        for (int c = 0; c < 6; c++) pdf.cov(r, c) = C(r, c);
    return pdf;
}

/** Draws a pose from the PDF: mean + L n in (x y z yaw pitch roll). */
inline mrpt::poses::CPose3D samplePose(const mrpt::poses::CPose3DPDFGaussian& pdf,
                                       std::mt19937& rng) {
    Eigen::Matrix<double, 6, 6> C;
    for (int r = 0; r < 6; r++)
        for (int c = 0; c < 6; c++) C(r, c) = pdf.cov(r, c);
    const Eigen::Matrix<double, 6, 6> L = C.llt().matrixL();
    std::normal_distribution<double> n01;
    Eigen::Matrix<double, 6, 1> n;
    for (int i = 0; i < 6; i++) n[i] = n01(rng);
    const Eigen::Matrix<double, 6, 1> d = L * n;
    const auto& m = pdf.mean;
    return mrpt::poses::CPose3D(m.x() + d[0], m.y() + d[1], m.z() + d[2], m.yaw() + d[3],
                                m.pitch() + d[4], m.roll() + d[5]);
}

/** 0.5 % and 99.5 % quantiles of chi^2 with k degrees of freedom (Wilson-Hilferty). */
inline std::pair<double, double> chi2Bounds99(double k) {
    const double z = 2.5758293035489;  // two-sided 99 %
    auto q = [&](double zz) {
        const double a = 2.0 / (9.0 * k);
        return k * std::pow(1 - a + zz * std::sqrt(a), 3);
    };
    return {q(-z), q(z)};
}

/** Result of comparing samples with a predicted mean and covariance. */
struct Consistency {
    Eigen::Matrix3d empirical;
    double worstEntry = 0;  //!< max |E_rc - P_rc| / sqrt(P_rr P_cc)
    double meanNees = 0;
    double neesLo = 0, neesHi = 0;  //!< 99 % bounds of the mean NEES (chi^2 with 3N dof / N)
    double shareAbove = 0;          //!< share of samples with NEES > chi^2_3(0.99) = 11.345
    double shareTol = 0;            //!< 99 % binomial tolerance around 1 %
};

inline Consistency consistency(const std::vector<Eigen::Vector3d>& samples,
                               const Eigen::Vector3d& mean, const Eigen::Matrix3d& P) {
    Consistency c;
    const size_t N = samples.size();
    Eigen::Vector3d m = Eigen::Vector3d::Zero();
    for (const auto& s : samples) m += s;
    m /= double(N);
    Eigen::Matrix3d E = Eigen::Matrix3d::Zero();
    for (const auto& s : samples) E += (s - m) * (s - m).transpose();
    c.empirical = E / double(N - 1);
    for (int r = 0; r < 3; r++)
        for (int k = 0; k < 3; k++)
            c.worstEntry = std::max(
                c.worstEntry, std::abs(c.empirical(r, k) - P(r, k)) / std::sqrt(P(r, r) * P(k, k)));
    const Eigen::Matrix3d Pinv = P.inverse();
    double sum = 0;
    size_t above = 0;
    for (const auto& s : samples) {
        const double e = (s - mean).dot(Pinv * (s - mean));
        sum += e;
        if (e > 11.3449) above++;
    }
    const auto [lo, hi] = chi2Bounds99(3.0 * double(N));
    c.meanNees = sum / double(N);
    c.neesLo = lo / double(N);
    c.neesHi = hi / double(N);
    c.shareAbove = double(above) / double(N);
    c.shareTol = 2.5758 * std::sqrt(0.01 * 0.99 / double(N)) + 1.0 / double(N);
    return c;
}

/** Expects samples consistent with a predicted mean and covariance: every covariance entry within
 * `tol` of sqrt(P_ii P_jj) (the sampling error of 4000 samples is ~ 0.02-0.03 of it), the mean
 * NEES inside the 99 % chi-square bounds of 3N degrees of freedom, and the share of samples with
 * NEES above chi^2_3(0.99) consistent with 1 % (binomial, 99 %). */
inline void expectConsistent(const std::vector<Eigen::Vector3d>& samples,
                             const Eigen::Vector3d& mean, const Eigen::Matrix3d& P,
                             double tol = 0.1) {
    const Consistency c = consistency(samples, mean, P);
    std::printf(
        "  MC %zu samples: worst covariance entry off by %.3f sqrt(PiiPjj), mean NEES %.3f "
        "in [%.3f, %.3f], NEES > 11.34: %.2f %%\n",
        samples.size(), c.worstEntry, c.meanNees, c.neesLo, c.neesHi, 100.0 * c.shareAbove);
    EXPECT_LT(c.worstEntry, tol) << "empirical\n" << c.empirical << "\npropagated\n" << P;
    EXPECT_GT(c.meanNees, c.neesLo) << "covariance too large";
    EXPECT_LT(c.meanNees, c.neesHi) << "covariance too small";
    EXPECT_NEAR(c.shareAbove, 0.01, c.shareTol) << "share of samples with NEES > 11.34";
}

/** Monte Carlo of a ray model (depth, lidar): 4000 draws of the point `p` (sensor frame) moved by
 * `perturb(p, r, d, e1, e2, rng)` (the model's own noise: r = |p|, d = p / r, e1 and e2 across the
 * ray) and of the robot pose, through the real transform of `sensor` on the robot; expected
 * consistent with rayPointCovariance() + PosePropagator. */
template <class Model, class Perturb>
void expectRayModelConsistent(const Model& model, const mrpt::poses::CPose3D& sensor,
                              const Eigen::Vector3d& p, unsigned seed, Perturb&& perturb) {
    const auto pdf = robotPosePdf();
    const double r = p.norm();
    const Eigen::Vector3d d = p / r;
    const Eigen::Vector3d e1 = d.cross(Eigen::Vector3d::UnitZ()).normalized(), e2 = d.cross(e1);
    const multibin::PointWithCov pred =
        multibin::PosePropagator(pdf, sensor)
            .apply(multibin::PointWithCov{
                p.cast<float>(), multibin::sensors::rayPointCovariance(p.cast<float>(), model)});
    std::mt19937 rng(seed);
    std::vector<Eigen::Vector3d> samples;
    for (int k = 0; k < 4000; k++) {
        const Eigen::Vector3d q = perturb(p, r, d, e1, e2, rng);
        const auto m =
            (samplePose(pdf, rng) + sensor).composePoint(mrpt::math::TPoint3D(q.x(), q.y(), q.z()));
        samples.emplace_back(m.x, m.y, m.z);
    }
    expectConsistent(samples, pred.point_m.cast<double>(), pred.cov_m2.toMatrix());
}

}  // namespace mc
