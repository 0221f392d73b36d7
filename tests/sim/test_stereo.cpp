/* Stereo of terrain-sim: camera geometry, rendering against the analytic disparity of a plane
 * (checked by OpenCV's StereoSGBM on the rendered pair), STOC-style disparity artefacts. */
#include <gtest/gtest.h>

#include <opencv2/calib3d.hpp>

#include <algorithm>
#include <cmath>

#include "Scenario.h"
#include "StereoSim.h"
#include "sim_fixtures.h"

using namespace terrain_sim;

namespace {
/** Textured flat ground: 6 x 6 flat boards of 0.6 m (x in [0, 3.6], y in [-1.8, 1.8]). */
Terrain texturedPlane() {
    return Terrain::fromBoards({sim_test::flatBoard(61, 0.01, 0.0)}, 6, 6, 0.0);
}

/** Disparity [px] of left pixel (u, v) over the plane z = 0, from the camera geometry alone. */
double analyticDisparity(const StereoConfig& cfg, const mrpt::poses::CPose3D& robot, int u, int v) {
    const mrpt::poses::CPose3D cam = robot + cfg.leftPose();
    const Eigen::Vector3d dc((u - cfg.cx_px()) / cfg.fx_px(), (v - cfg.cy_px()) / cfg.fx_px(), 1.0);
    const Eigen::Vector3d d = cam.getRotationMatrix().asEigen() * dc;  // z_cam = 1 per unit
    const double zcam = -cam.z() / d.z();                              // along the ray
    return cfg.fx_px() * cfg.baseline_m / zcam;
}
}  // namespace

TEST(StereoSim, LeftCameraPitched35DegAt48cmWithMrptAxes) {
    StereoConfig cfg;
    const auto p = cfg.leftPose();
    const Eigen::Matrix3d R = p.getRotationMatrix().asEigen();
    const double c = std::cos(35 * M_PI / 180), s = std::sin(35 * M_PI / 180);
    EXPECT_TRUE(R.col(2).isApprox(Eigen::Vector3d(c, 0, -s), 1e-12));  // +z: forward, down
    EXPECT_TRUE(R.col(0).isApprox(Eigen::Vector3d(0, -1, 0), 1e-12));  // +x: right
    EXPECT_LT(R.col(1).z(), 0);                                        // +y: down
    EXPECT_NEAR(R.determinant(), 1.0, 1e-12);
    EXPECT_NEAR(p.z(), 0.48, 1e-12);
    // The right camera sits baseline_m to the right of the left one.
    const auto right = p + mrpt::poses::CPose3D(cfg.baseline_m, 0, 0, 0, 0, 0);
    EXPECT_NEAR(p.y() - right.y(), cfg.baseline_m, 1e-12);
}

// Rendering geometry: the true disparity of the render equals the plane's analytic one, and
// OpenCV's SGBM matching the rendered pair recovers it within 0.5 px.
TEST(StereoSim, RenderedPlaneGivesAnalyticDisparity) {
    const Terrain t = texturedPlane();
    const SurfaceTexture tex(t, 2, 0);
    StereoConfig cfg;
    cfg.disparity = false;
    const StereoSim stereo(cfg, t, tex);
    const mrpt::poses::CPose3D robot(0.1, 0.0, 0.0, 0.0, 0.0, 0.0);
    std::mt19937_64 rng(3);
    const StereoRender r = stereo.render(robot, rng);
    for (int v = 0; v < cfg.height_px; v += 7)
        for (int u = 0; u < cfg.width_px; u += 7)
            ASSERT_NEAR(r.trueDisparity.at<float>(v, u), analyticDisparity(cfg, robot, u, v), 1e-3);

    const int numDisp = 64;
    auto sgbm = cv::StereoSGBM::create(0, numDisp, 5, 8 * 25, 32 * 25, 1, 0, 10, 0, 0,
                                       cv::StereoSGBM::MODE_HH);
    cv::Mat d16;
    sgbm->compute(r.left, r.right, d16);
    std::vector<double> err;
    for (int v = 4; v < cfg.height_px - 4; ++v)
        for (int u = numDisp + 4; u < cfg.width_px - 4; ++u) {
            const short raw = d16.at<short>(v, u);
            if (raw <= 0) continue;
            err.push_back(raw / 16.0 - analyticDisparity(cfg, robot, u, v));
        }
    ASSERT_GT(err.size(), size_t(0.8 * (cfg.height_px - 8) * (cfg.width_px - numDisp - 8)));
    double mean = 0;
    size_t within = 0;
    for (double e : err) {
        mean += e;
        within += std::abs(e) <= 0.5;
    }
    mean /= err.size();
    std::nth_element(err.begin(), err.begin() + err.size() / 2, err.end(),
                     [](double a, double b) { return std::abs(a) < std::abs(b); });
    const double medianAbs = std::abs(err[err.size() / 2]);
    RecordProperty("sgbm_mean_error_px", std::to_string(mean));
    RecordProperty("sgbm_within_half_px", std::to_string(double(within) / err.size()));
    std::cout << "SGBM vs analytic over the plane: mean " << mean << " px, median |e| " << medianAbs
              << " px, " << 100.0 * within / err.size() << " % within 0.5 px of " << err.size()
              << " matched pixels\n";
    EXPECT_LT(std::abs(mean), 0.1);
    EXPECT_LT(medianAbs, 0.25);
    EXPECT_GT(double(within) / err.size(), 0.9);
}

// The simulated STOC disparity: the truth plus matching noise on texture, nothing on textureless
// flat ground except near-camera blobs (disparity larger than the truth).
TEST(StereoSim, DisparityImageNoiseAndTexturelessBlobs) {
    StereoConfig cfg;
    cfg.blobsPerFrame = 6;
    std::mt19937_64 rng(9);
    {
        const Terrain t = texturedPlane();
        const SurfaceTexture tex(t, 2, 0);
        const StereoSim stereo(cfg, t, tex);
        const StereoRender r = stereo.render(mrpt::poses::CPose3D(0.1, 0, 0, 0, 0, 0), rng);
        ASSERT_EQ(r.disparity16.type(), CV_16U);
        double chi2 = 0;
        size_t n = 0;
        for (int v = 0; v < cfg.height_px; ++v)
            for (int u = 0; u < cfg.width_px; ++u) {
                const uint16_t raw = r.disparity16.at<uint16_t>(v, u);
                if (raw == 0) continue;
                // 1/16 px quantisation adds (1/16)^2 / 12 to the variance.
                const double z = (raw / 16.0 - r.trueDisparity.at<float>(v, u)) /
                                 std::sqrt(std::pow(cfg.matchingSigma_px, 2) + 1.0 / (256 * 12));
                chi2 += z * z;
                ++n;
            }
        ASSERT_GT(n, size_t(0.7 * cfg.width_px * cfg.height_px));
        EXPECT_NEAR(chi2, double(n), 3.29 * std::sqrt(2.0 * n));
    }
    {
        const Terrain flat = Terrain::fromSamples(Eigen::MatrixXf::Zero(401, 401), -1, -2, 0.01);
        const SurfaceTexture tex(flat, 2, 0);
        const StereoSim stereo(cfg, flat, tex);
        const StereoRender r = stereo.render(mrpt::poses::CPose3D(), rng);
        size_t valid = 0;
        for (int v = 0; v < cfg.height_px; ++v)
            for (int u = 0; u < cfg.width_px; ++u) {
                const uint16_t raw = r.disparity16.at<uint16_t>(v, u);
                if (raw == 0) continue;
                ++valid;
                EXPECT_GT(raw / 16.0, 1.15 * r.trueDisparity.at<float>(v, u));  // nearer
                EXPECT_GE(v, cfg.height_px / 2 - 10);  // blobs sit in the near half
            }
        EXPECT_GT(valid, 20u);
        EXPECT_LT(valid, size_t(0.05 * cfg.width_px * cfg.height_px));
    }
}

// Halos: next to a depth edge the background takes the foreground's disparity, within the halo
// width, and only there.
TEST(StereoSim, HalosFattenTheForegroundAtDepthEdges) {
    // Textured ground with a 0.15 m high textured block in front of the camera.
    const Terrain t = sim_test::raisedCentreBoard();
    const SurfaceTexture tex(t, 4, 0);
    StereoConfig cfg;
    cfg.blobsPerFrame = 0;
    const StereoSim stereo(cfg, t, tex);
    std::mt19937_64 rng(8);
    const StereoRender r = stereo.render(mrpt::poses::CPose3D(0.0, 0, 0, 0, 0, 0), rng);
    size_t halo = 0;
    for (int v = 0; v < cfg.height_px; ++v)
        for (int u = 0; u < cfg.width_px; ++u) {
            const uint16_t raw = r.disparity16.at<uint16_t>(v, u);
            if (raw == 0) continue;
            const double d = raw / 16.0, dt = r.trueDisparity.at<float>(v, u);
            double dmax = dt;  // the nearest surface within the halo width
            for (int k = std::max(0, u - cfg.haloWidth_px);
                 k <= std::min(cfg.width_px - 1, u + cfg.haloWidth_px); ++k)
                dmax = std::max(dmax, double(r.trueDisparity.at<float>(v, k)));
            if (dmax - dt > cfg.haloJump_px) {
                ++halo;  // background next to a nearer surface: takes the foreground's disparity
                EXPECT_NEAR(d, dmax, 5 * cfg.matchingSigma_px) << u << "," << v;
            } else {
                EXPECT_NEAR(d, dt, 5 * cfg.matchingSigma_px) << u << "," << v;
            }
        }
    EXPECT_GT(halo, 50u);
}
