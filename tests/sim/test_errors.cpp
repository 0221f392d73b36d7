/* Sensor errors of terrain-sim that the library's models do not describe (--noise independent):
 * each error measured against the ray-cast truth has the stated shape. */
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include "LaserSim.h"
#include "Scenario.h"
#include "StereoSim.h"
#include "sim_fixtures.h"

using namespace terrain_sim;

namespace {

Terrain flatGround() {
    return Terrain::fromSamples(Eigen::MatrixXf::Zero(201, 201), -1.0, -1.0, 0.01);
}

/** Two-sided tail P(|X| > k) of a Student-t with 4 dof scaled to unit variance (closed form of
 * the t4 CDF, F(t) = 1/2 + 3/8 s (1 - t^2 / (12 q)) with q = 1 + t^2 / 4, s = t / sqrt(q)). */
double studentT4Tail(double k) {
    const double t = k / std::sqrt(0.5);  // unit variance: t4 scaled by sqrt((4 - 2) / 4)
    const double q = 1.0 + t * t / 4.0;
    const double F = 0.5 + 0.375 * t / std::sqrt(q) * (1.0 - t * t / (12.0 * q));
    return 2.0 * (1.0 - F);
}

/** |measured - expected| within 4.5 binomial standard deviations of n trials. */
void expectFraction(size_t hits, size_t n, double p, const char* what) {
    const double sd = std::sqrt(p * (1 - p) / n);
    EXPECT_NEAR(double(hits) / n, p, 4.5 * sd) << what << ": " << hits << " of " << n;
}

/** Laser residuals (r - r_true - surface bias) / sigma_r(r_true) over flat ground. */
struct LaserResiduals {
    std::vector<double> z, res_m, range_m;
    /** Every valid return's r - r_true, dark returns and surface bias included [m]. */
    std::vector<double> rangeError_m;
    size_t beams = 0, outliers = 0;
    std::vector<double> outlierFactors;
};

LaserResiduals laserResiduals(const LaserConfig& cfg, int scans, uint64_t seed) {
    const Terrain t = flatGround();
    const SurfaceTexture tex(t, seed, 0);
    const LaserSim laser(cfg, t, tex, seed);
    std::mt19937_64 rng(seed + 100);
    std::vector<BeamTruth> truth;
    LaserResiduals out;
    for (int s = 0; s < scans; ++s) {
        const auto scan = laser.scan(mrpt::poses::CPose3D(0.001 * s, 0, 0, 0.01 * s, 0, 0),
                                     syntheticStamp(0), rng, &truth);
        for (int k = 0; k < 683; ++k) {
            const auto& b = truth[k];
            if (b.surface >= 0 && !b.dropout && scan->getScanRangeValidity(k))
                out.rangeError_m.push_back(scan->getScanRange(k) - b.trueRange_m);
            if (b.surface < 0 || b.dropout || b.dark || b.mixed) continue;
            ++out.beams;
            const double r = b.trueRange_m;
            if (b.outlier) {
                ++out.outliers;
                out.outlierFactors.push_back(scan->getScanRange(k) / r);
                continue;
            }
            if (!scan->getScanRangeValidity(k)) continue;
            const double res = scan->getScanRange(k) - r - laser.surfaceBias_m(b.surface);
            out.res_m.push_back(res);
            out.range_m.push_back(r);
            out.z.push_back(res / cfg.sigma(r));
        }
    }
    return out;
}

}  // namespace

// Student-t range noise with 4 dof at the model's sigma: the tails are those of the scaled t4
// (1.3 % beyond 3 sigma, 0.21 % beyond 5 sigma, against 0.27 % and 6e-7 for the Gaussian), and
// the normalised residuals still have unit variance.
TEST(SensorErrors, LaserStudentTailsAtTheStatedSigma) {
    LaserConfig cfg;
    cfg.errors.tailDof = 4;
    const auto r = laserResiduals(cfg, 120, 5);
    const size_t n = r.z.size();
    ASSERT_GT(n, 30000u);
    size_t beyond1 = 0, beyond3 = 0, beyond5 = 0;
    double ss = 0;
    for (double z : r.z) {
        beyond1 += std::abs(z) > 1;
        beyond3 += std::abs(z) > 3;
        beyond5 += std::abs(z) > 5;
        ss += z * z;
    }
    expectFraction(beyond1, n, studentT4Tail(1), "beyond 1 sigma");
    expectFraction(beyond3, n, studentT4Tail(3), "beyond 3 sigma");
    expectFraction(beyond5, n, studentT4Tail(5), "beyond 5 sigma");
    EXPECT_GT(double(beyond3) / n, 3 * 0.0027);  // clearly not Gaussian
    EXPECT_NEAR(std::sqrt(ss / n), 1.0, 0.1);    // same sigma (t4 has no 4th moment: loose)
    EXPECT_EQ(r.outliers, 0u);
}

// Range-dependent bias b0 + b1 r, the same on every surface: the mean residual per range band
// follows it, and a straight-line fit of the residuals on the true range recovers b0 and b1.
TEST(SensorErrors, LaserRangeBiasFollowsTheStatedLine) {
    LaserConfig cfg;
    cfg.rangeBias0_m = -0.002;
    cfg.rangeBiasSlope = 0.01;
    const auto r = laserResiduals(cfg, 60, 6);
    const size_t n = r.res_m.size();
    ASSERT_GT(n, 10000u);
    double sx = 0, sy = 0, sxx = 0, sxy = 0, sw = 0;
    for (size_t i = 0; i < n; ++i) {
        const double w = 1.0 / std::pow(cfg.sigma(r.range_m[i]), 2);  // weighted least squares
        sw += w, sx += w * r.range_m[i], sy += w * r.res_m[i];
        sxx += w * r.range_m[i] * r.range_m[i], sxy += w * r.range_m[i] * r.res_m[i];
    }
    const double det = sw * sxx - sx * sx;
    const double b1 = (sw * sxy - sx * sy) / det, b0 = (sxx * sy - sx * sxy) / det;
    const double sdB1 = std::sqrt(sw / det), sdB0 = std::sqrt(sxx / det);
    EXPECT_NEAR(b1, 0.01, 4 * sdB1);
    EXPECT_NEAR(b0, -0.002, 4 * sdB0);
    EXPECT_LT(sdB1, 0.001);  // the fit is precise enough to tell the bias from none
    // Without the option, no such bias.
    const auto r0 = laserResiduals(LaserConfig(), 20, 6);
    double m0 = 0;
    for (double x : r0.res_m) m0 += x;
    EXPECT_LT(std::abs(m0 / r0.res_m.size()), 0.0003);
}

// About 1 % outliers: the share of returns that are gross errors matches, their range is the
// truth times U(0.5, 1.5) (mean 1, standard deviation 0.5 / sqrt(3)), and the other returns keep
// Gaussian noise (none beyond 5.5 sigma).
TEST(SensorErrors, LaserOutlierFractionAndSpread) {
    LaserConfig cfg;
    cfg.errors.outlierFraction = 0.01;
    const auto r = laserResiduals(cfg, 120, 7);
    ASSERT_GT(r.beams, 30000u);
    expectFraction(r.outliers, r.beams, 0.01, "outliers");
    double m = 0, v = 0;
    for (double f : r.outlierFactors) {
        EXPECT_GE(f, 0.5 - 1e-6);
        EXPECT_LE(f, 1.5 + 1e-6);
        m += f;
    }
    m /= r.outlierFactors.size();
    for (double f : r.outlierFactors) v += (f - m) * (f - m);
    const double sd = std::sqrt(v / (r.outlierFactors.size() - 1));
    EXPECT_NEAR(m, 1.0, 4 * 0.2887 / std::sqrt(double(r.outlierFactors.size())));
    EXPECT_NEAR(sd, 0.5 / std::sqrt(3.0), 0.04);
    for (double z : r.z) ASSERT_LT(std::abs(z), 5.5);
}

// A mounting pitch error the map is not told: the beams are cast 0.3 deg steeper (the true range
// of each beam is that of the true pitch), while the scan's sensorPose stays the nominal one, so
// the points the map computes from it lie off the flat ground by the predicted amount.
TEST(SensorErrors, LaserPitchErrorIsCastButNotWritten) {
    LaserConfig cfg;
    cfg.sigma = {0.0, 0.0, 0.0};
    cfg.surfaceBiasMax_m = 0.0;
    cfg.pitchError_rad = 0.3 * M_PI / 180;
    const Terrain t = flatGround();
    const SurfaceTexture tex(t, 1, 0);
    const LaserSim laser(cfg, t, tex, 1);
    std::mt19937_64 rng(1);
    std::vector<BeamTruth> truth;
    const auto scan = laser.scan(mrpt::poses::CPose3D(), syntheticStamp(0), rng, &truth);
    EXPECT_EQ(scan->sensorPose, LaserConfig().pose);  // the written pose is the nominal one
    const double pitch = (45.0 + 0.3) * M_PI / 180;   // the stated true pitch
    int checked = 0;
    for (int k = 200; k < 483; k += 7) {
        ASSERT_TRUE(scan->getScanRangeValidity(k)) << k;
        const double a = std::atan2(laser.beamDirection(k).y(), laser.beamDirection(k).x());
        const double rTrue = 0.26 / (std::cos(a) * std::sin(pitch));
        EXPECT_NEAR(scan->getScanRange(k), rTrue, 1e-6) << k;
        // Where the map puts the point: nominal 45 deg, height 0.26 - r cos(a) sin(45 deg).
        const double zMap = 0.26 - scan->getScanRange(k) * std::cos(a) * std::sin(M_PI / 4);
        EXPECT_NEAR(zMap, 0.26 * (1 - std::sin(M_PI / 4) / std::sin(pitch)), 1e-6) << k;
        EXPECT_GT(zMap, 0.001) << k;  // the flat ground seen 1 mm and more too high
        ++checked;
    }
    EXPECT_GT(checked, 30);
}

namespace {
/** Textured flat ground: 6 x 6 flat boards of 0.6 m. */
Terrain texturedPlane() {
    return Terrain::fromBoards({sim_test::flatBoard(61, 0.01, 0.0)}, 6, 6, 0.0);
}
}  // namespace

// Stereo matching noise with Student-t tails (4 dof at 0.25 px) and 1 % outliers (the true
// disparity times U(0.5, 1.5)), measured on the written disparity image against the true
// disparity of the render.
TEST(SensorErrors, StereoStudentTailsAndOutliers) {
    const Terrain t = texturedPlane();
    const SurfaceTexture tex(t, 2, 0);
    StereoConfig cfg;
    cfg.errors.tailDof = 4;
    cfg.errors.outlierFraction = 0.01;
    const StereoSim stereo(cfg, t, tex);
    std::mt19937_64 rng(8);
    size_t n = 0, beyond1 = 0, beyond3 = 0, beyond5 = 0, matched = 0, outliers = 0;
    for (int f = 0; f < 2; ++f) {
        const StereoRender r =
            stereo.render(mrpt::poses::CPose3D(0.1 + 0.2 * f, 0, 0, 0, 0, 0), rng);
        for (int v = 0; v < cfg.height_px; ++v)
            for (int u = 0; u < cfg.width_px; ++u) {
                const int kind = r.matchKind.at<uint8_t>(v, u);
                const double d = r.disparity16.at<uint16_t>(v, u) / 16.0;
                const double dt = r.trueDisparity.at<float>(v, u);
                if (kind == StereoRender::kOutlier) {
                    ++outliers, ++matched;
                    if (d > 0) {
                        EXPECT_GE(d / dt, 0.5 - 0.04 / dt) << u << "," << v;
                        EXPECT_LE(d / dt, 1.5 + 0.04 / dt) << u << "," << v;
                    }
                    continue;
                }
                if (kind != StereoRender::kNoise) continue;
                ++matched;
                if (d <= 0) continue;
                const double z = (d - dt) / cfg.matchingSigma_px;
                ++n;
                beyond1 += std::abs(z) > 1;
                beyond3 += std::abs(z) > 3;
                beyond5 += std::abs(z) > 5;
            }
    }
    ASSERT_GT(n, 40000u);
    // The 1/16 px rounding adds 0.5 % to the variance: within the tolerances below.
    expectFraction(beyond1, n, studentT4Tail(1), "beyond 1 sigma");
    expectFraction(beyond3, n, studentT4Tail(3), "beyond 3 sigma");
    expectFraction(beyond5, n, studentT4Tail(5), "beyond 5 sigma");
    expectFraction(outliers, matched, 0.01, "outliers");
}

// Mixed pixels at depth edges: in front of a 0.15 m block, pixels next to a disparity jump over
// 2 px match a blend of both sides with the stated chance, and their disparity lies between.
TEST(SensorErrors, StereoMixedPixelsBlendBothSidesOfAnEdge) {
    const Terrain t = sim_test::raisedCentreBoard();
    const SurfaceTexture tex(t, 4, 0);
    StereoConfig cfg;
    cfg.mixedProbability = 0.5;
    cfg.matchingSigma_px = 0.0;
    cfg.blobsPerFrame = 0;
    const StereoSim stereo(cfg, t, tex);
    std::mt19937_64 rng(9);
    const StereoRender r = stereo.render(mrpt::poses::CPose3D(0.0, 0, 0, 0, 0, 0), rng);
    const cv::Mat& dt = r.trueDisparity;
    size_t edge = 0, mixed = 0;
    for (int v = 1; v + 1 < cfg.height_px; ++v)
        for (int u = 1; u + 1 < cfg.width_px; ++u) {
            const int kind = r.matchKind.at<uint8_t>(v, u);
            if (kind == StereoRender::kNone || kind == StereoRender::kBlob) continue;
            const double d0 = dt.at<float>(v, u);
            double dn = d0;
            for (const auto& o :
                 {cv::Point(-1, 0), cv::Point(1, 0), cv::Point(0, -1), cv::Point(0, 1)}) {
                const double x = dt.at<float>(v + o.y, u + o.x);
                if (x > 0 && std::abs(x - d0) > std::abs(dn - d0)) dn = x;
            }
            if (std::abs(dn - d0) <= cfg.haloJump_px) {
                EXPECT_NE(kind, StereoRender::kMixed) << u << "," << v;
                continue;
            }
            ++edge;
            if (kind != StereoRender::kMixed) continue;
            ++mixed;
            const double d = r.disparity16.at<uint16_t>(v, u) / 16.0;
            if (d == 0) continue;  // u - d < 0: no match
            EXPECT_GE(d, std::min(d0, dn) - 1.0 / 32) << u << "," << v;
            EXPECT_LE(d, std::max(d0, dn) + 1.0 / 32) << u << "," << v;
        }
    ASSERT_GT(edge, 200u);
    expectFraction(mixed, edge, 0.5, "mixed pixels at edges");
}

// Calibration errors the map is not told: the pair is rendered with the true baseline and
// principal point, the observation carries the nominal ones. A principal point off by (2, 3) px
// shifts the image by exactly that; a baseline 0.3 mm longer scales every disparity by 0.0903 /
// 0.09.
TEST(SensorErrors, StereoCalibrationErrorsAreRenderedButNotWritten) {
    const Terrain t = texturedPlane();
    const SurfaceTexture tex(t, 2, 0);
    StereoConfig nominal;
    nominal.disparity = false;
    StereoConfig off = nominal;
    off.cxError_px = 2;
    off.cyError_px = 3;
    off.baselineError_m = 0.0003;
    const StereoSim a(nominal, t, tex), b(off, t, tex);
    std::mt19937_64 rngA(1), rngB(1);
    const mrpt::poses::CPose3D robot(0.1, 0, 0, 0, 0, 0);
    const StereoRender ra = a.render(robot, rngA), rb = b.render(robot, rngB);
    int checked = 0;
    for (int v = 3; v < nominal.height_px; v += 5)
        for (int u = 2; u < nominal.width_px; u += 5) {
            const double da = ra.trueDisparity.at<float>(v - 3, u - 2);
            const double db = rb.trueDisparity.at<float>(v, u);
            if (da <= 0) continue;
            ASSERT_NEAR(db / da, 0.0903 / 0.09, 1e-5) << u << "," << v;
            ++checked;
        }
    EXPECT_GT(checked, 2000);
    const auto obs = b.observation(rb, syntheticStamp(0));
    EXPECT_DOUBLE_EQ(obs->rightCameraPose.x(), 0.09);
    EXPECT_DOUBLE_EQ(obs->leftCamera.cx(), nominal.cx_px());
    EXPECT_DOUBLE_EQ(obs->leftCamera.cy(), nominal.cy_px());
}

// --noise independent turns every error on with the stated values and leaves the written ini
// (calibration and sigmas) exactly the matched one: the map is not told.
TEST(SensorErrors, IndependentNoiseKeepsTheWrittenIni) {
    ScenarioConfig matched;
    matched.terrainFiles = {"x.asc"};
    ScenarioConfig independent = matched;
    applyIndependentNoise(independent);
    EXPECT_EQ(mapperIni(matched), mapperIni(independent));
    EXPECT_EQ(independent.laser.errors.tailDof, 4);
    EXPECT_EQ(independent.stereo.errors.tailDof, 4);
    EXPECT_DOUBLE_EQ(independent.laser.errors.outlierFraction, 0.01);
    EXPECT_DOUBLE_EQ(independent.stereo.errors.outlierFraction, 0.01);
    EXPECT_DOUBLE_EQ(independent.laser.rangeBiasSlope, 0.01);
    EXPECT_DOUBLE_EQ(independent.laser.pitchError_rad, 0.3 * M_PI / 180);
    EXPECT_DOUBLE_EQ(independent.stereo.baselineError_m, 0.0003);
    EXPECT_EQ(matched.laser.errors.tailDof, 0);  // the default draws the model's Gaussian
}

// --noise exact: the same ini, every laser range exactly the ray-cast one (no noise, no surface
// or dark-return bias), and the estimated poses equal to the true ones with the matched run's
// covariances; the matched run's ranges and poses are off by their noise.
TEST(SensorErrors, ExactMeasurementsKeepTheIniAndTheirErrorsAreZero) {
    ScenarioConfig matched;
    matched.terrainFiles = {"x.asc"};
    ScenarioConfig exact = matched;
    applyExactMeasurements(exact);
    EXPECT_EQ(mapperIni(matched), mapperIni(exact));

    auto largestRangeError_m = [](const LaserConfig& cfg) {
        double largest = 0;
        for (const double e : laserResiduals(cfg, 20, 3).rangeError_m)
            largest = std::max(largest, std::abs(e));
        return largest;
    };
    EXPECT_LT(largestRangeError_m(exact.laser), 1e-6);  // float ranges
    EXPECT_GT(largestRangeError_m(matched.laser), 1e-3);

    const Terrain t = flatGround();
    for (const ScenarioConfig* c : {&matched, &exact}) {
        TrajectoryOptions o = c->trajectory;
        o.maxFrames = 40;
        std::mt19937_64 rng(5);
        const auto frames = walkTrajectory(t, o, rng);
        ASSERT_EQ(frames.size(), 40u);
        double largest = 0;
        for (const Frame& f : frames) {
            const auto d = f.estimate.mean.asVectorVal() - f.truth.asVectorVal();
            largest = std::max(largest, d.array().abs().maxCoeff());
            EXPECT_GT(f.estimate.cov(0, 0), 0.0);  // the written covariance stays
        }
        if (c == &exact)
            EXPECT_LT(largest, 1e-12);
        else
            EXPECT_GT(largest, 1e-3);
    }
}
