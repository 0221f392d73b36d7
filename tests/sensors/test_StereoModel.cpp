/* Stereo model: Jacobians against finite differences, per-pixel table, Monte Carlo consistency
 * of eqs 4-12, SGBM, frames through the map. The disparity format and the artefact filters:
 * test_StereoDisparity.cpp. */
#include <gtest/gtest.h>
#include <mrpt/core/bits_math.h>
#include <mrpt/maps/CMultiBinElevationMap.h>
#include <mrpt/obs/CObservationStereoImages.h>

#include <cmath>
#include <cstring>
#include <limits>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>
#include <random>

#include "mc_check.h"
#include "multibin/geometry/PosePropagation.h"
#include "multibin/map/MapStatistics.h"
#include "multibin/sensors/SensorDispatch.h"
#include "multibin/sensors/StereoDisparity.h"
#include "multibin/sensors/StereoModel.h"

using namespace multibin;
using namespace multibin::sensors;

namespace {
StereoGeometry stocGeometry() {
    StereoGeometry g;
    g.width = 640;
    g.height = 480;
    g.fx = 500;
    g.fy = 505;
    g.cx = 321.5;
    g.cy = 238.0;
    g.cxRight = 321.5;
    g.baseline_m = 0.09;
    return g;
}

/** Options with a non-trivial calibration uncertainty in every parameter. */
StereoModelOptions uncertainOptions() {
    StereoModelOptions o;
    o.leftIntrinsicsSigma = {0.8, 0.7, 0.6, 0.5, 0.004, 0.003, 0.0004, 0.0003, 0.002};
    o.rightIntrinsicsSigma = {0.6, 0.9, 0.5, 0.7, 0.003, 0.004, 0.0003, 0.0004, 0.001};
    o.extrinsicsSigma = {0.0008, 0.0006, 0.0005, 0.0004, 0.0003, 0.0006};
    o.matchingSigma_px = 0.25;
    return o;
}

/** An observation of a rectified pair with the geometry of `g` and a disparity image. */
mrpt::obs::CObservationStereoImages makeObservation(const StereoGeometry& g,
                                                    const DisparityImage& disp) {
    mrpt::obs::CObservationStereoImages obs;
    obs.sensorLabel = "STEREO";
    for (auto* cam : {&obs.leftCamera, &obs.rightCamera}) {
        cam->ncols = uint32_t(g.width);
        cam->nrows = uint32_t(g.height);
        cam->setIntrinsicParamsFromValues(g.fx, g.fy, g.cx, g.cy);
    }
    obs.rightCamera.setIntrinsicParamsFromValues(g.fx, g.fy, g.cxRight, g.cy);
    obs.rightCameraPose =
        mrpt::poses::CPose3DQuat(mrpt::poses::CPose3D(g.baseline_m, 0, 0, 0, 0, 0));
    obs.hasImageDisparity = true;
    obs.imageDisparity = encodeDisparityImage(disp);
    obs.hasImageRight = false;
    return obs;
}
}  // namespace

TEST(StereoModel, TriangulationJacobianMatchesFiniteDifferences) {
    const StereoGeometry g = stocGeometry();
    for (const Eigen::Vector3d q : {Eigen::Vector3d(100, 50, 20), Eigen::Vector3d(600, 400, 7.5),
                                    Eigen::Vector3d(321, 240, 60)}) {
        const Eigen::Matrix3d J = g.triangulationJacobian(q[0], q[1], q[2]);
        for (int k = 0; k < 3; k++) {
            Eigen::Vector3d a = q, b = q;
            a[k] += 1e-4;
            b[k] -= 1e-4;
            const Eigen::Vector3d fd =
                (g.triangulate(a[0], a[1], a[2]) - g.triangulate(b[0], b[1], b[2])) / 2e-4;
            EXPECT_LT((J.col(k) - fd).norm(), 1e-6 * (1 + fd.norm())) << "column " << k;
        }
    }
    // Eq 8: z = b f / d.
    EXPECT_NEAR(g.triangulate(400, 300, 20).z(), 0.09 * 500 / 20, 1e-12);
}

TEST(StereoModel, CalibrationJacobianMatchesFiniteDifferencesOfTheRealModel) {
    const StereoGeometry g = stocGeometry();
    for (const Eigen::Vector3d q : {Eigen::Vector3d(50, 40, 30), Eigen::Vector3d(600, 420, 12),
                                    Eigen::Vector3d(330, 250, 45)}) {
        const auto J = g.calibrationJacobian(q[0], q[1], q[2]);
        const Eigen::Vector3d P = g.triangulate(q[0], q[1], q[2]);
        const CalibrationVector zero = CalibrationVector::Zero();
        // observe() at zero error reproduces the pixel.
        EXPECT_LT((g.observe(P, zero) - q).norm(), 1e-9);
        for (int k = 0; k < kCalibrationParams; k++) {
            const double h = (k % 9 < 4 && k < 18) ? 1e-3 : 1e-6;
            CalibrationVector a = zero, b = zero;
            a[k] = h;
            b[k] = -h;
            const Eigen::Vector3d fd = (g.observe(P, a) - g.observe(P, b)) / (2 * h);
            EXPECT_LT((J.col(k) - fd).norm(), 1e-5 * (1 + fd.norm()))
                << "parameter " << k << " analytic " << J.col(k).transpose() << " fd "
                << fd.transpose();
        }
    }
}

TEST(StereoModel, TableEqualsDirectPropagation) {
    const StereoGeometry g = stocGeometry();
    const StereoModelOptions o = uncertainOptions();
    const StereoCovarianceTable table(g, o);
    const CalibrationVector var = calibrationVariances(o);
    for (const Eigen::Vector3i q : {Eigen::Vector3i(50, 40, 30), Eigen::Vector3i(600, 420, 12),
                                    Eigen::Vector3i(330, 250, 45)}) {
        const auto J = g.calibrationJacobian(q[0], q[1], q[2]);
        Eigen::Matrix3d direct = J * var.asDiagonal() * J.transpose();
        direct(2, 2) += 2 * o.matchingSigma_px * o.matchingSigma_px;
        const Eigen::Matrix3d fromTable = table.pixelCovariance(q[0], q[1], q[2]);
        EXPECT_LT((direct - fromTable).norm(), 1e-5 * direct.norm()) << direct << "\n" << fromTable;
    }
    EXPECT_TRUE(table.matches(g, o));
    StereoModelOptions other = o;
    other.matchingSigma_px = 0.3;
    EXPECT_FALSE(table.matches(g, other));
}

TEST(StereoModel, MonteCarloCovarianceMatchesPropagation) {
    // Calibration errors (24 parameters) and matching noise pushed through the real projection
    // with distortion and the true right-camera pose, then triangulated with the nominal
    // calibration (what the mapper does); then robot pose noise through the real composition.
    const StereoGeometry g = stocGeometry();
    const StereoModelOptions o = uncertainOptions();
    const StereoCovarianceTable table(g, o);
    const CalibrationVector sd = calibrationVariances(o).cwiseSqrt();
    const mrpt::poses::CPose3D camera(0.05, 0, 0.48, mrpt::DEG2RAD(-90.0), 0,
                                      mrpt::DEG2RAD(-90.0 - 35.0));
    const auto pdf = mc::robotPosePdf();
    std::mt19937 rng(11);
    std::normal_distribution<double> n01;
    for (const Eigen::Vector3i q : {Eigen::Vector3i(400, 300, 40), Eigen::Vector3i(80, 420, 25)}) {
        const Eigen::Vector3d P = g.triangulate(q[0], q[1], q[2]);
        const Eigen::Matrix3d Cs = table.pointCovariance(q[0], q[1], q[2]);
        std::vector<Eigen::Vector3d> sensorSamples, mapSamples;
        for (int k = 0; k < 4000; k++) {
            CalibrationVector delta;
            for (int i = 0; i < kCalibrationParams; i++) delta[i] = sd[i] * n01(rng);
            Eigen::Vector3d obs = g.observe(P, delta);
            obs[2] += std::sqrt(2.0) * o.matchingSigma_px * n01(rng);  // noise in each image
            const Eigen::Vector3d Pc = g.triangulate(obs[0], obs[1], obs[2]);
            sensorSamples.push_back(Pc);
            const mrpt::math::TPoint3D pm =
                (mc::samplePose(pdf, rng) + camera)
                    .composePoint(mrpt::math::TPoint3D(Pc.x(), Pc.y(), Pc.z()));
            mapSamples.emplace_back(pm.x, pm.y, pm.z);
        }
        mc::expectConsistent(sensorSamples, P, Cs);
        const PointWithCov pred =
            PosePropagator(pdf, camera)
                .apply(PointWithCov{P.cast<float>(), SymmetricCov3::fromMatrix(Cs)});
        mc::expectConsistent(mapSamples, pred.point_m.cast<double>(), pred.cov_m2.toMatrix());
    }
}

TEST(StereoModel, WallInFrontOfTheRobotLandsAtItsDistance) {
    // Camera looking along the robot's +x (MRPT camera frame: +z forward, +x right, +y down), a
    // fronto-parallel wall at d = 15 px -> z = 0.09 * 500 / 15 = 3 m: map points at x = 3 m, and
    // image rows above the centre are higher (+z in the map).
    const StereoGeometry g = stocGeometry();
    DisparityImage disp(g.width, g.height);
    for (auto& x : disp.disparity_px) x = 15.f;
    auto obs = makeObservation(g, disp);
    obs.cameraPose = mrpt::poses::CPose3DQuat(
        mrpt::poses::CPose3D(0, 0, 0.5, mrpt::DEG2RAD(-90.0), 0, mrpt::DEG2RAD(-90.0)));
    SensorModelOptions opts;
    opts.stereo = uncertainOptions();
    opts.stereo.subsample = 8;
    SensorModelState state;
    SensorPoints sp;
    mrpt::poses::CPose3DPDFGaussian pose;
    StereoStats sum;  // the model's counts of each pair, added up as the map does
    auto sense = [&](const mrpt::obs::CObservationStereoImages& o) {
        const bool handled = observationToSensorPoints(o, pose, opts, 0.02, 20, state, sp);
        sum += sp.stats.stereo;
        return handled;
    };
    ASSERT_TRUE(sense(obs));
    EXPECT_EQ(sum.tableBuilds, 1u);
    ASSERT_GT(sp.points.size(), 1000u);
    const PosePropagator prop(pose, sp.sensorPose);
    for (const auto& p : sp.points) {
        const PointWithCov m = prop.apply(p);
        EXPECT_NEAR(m.point_m.x(), 3.0, 1e-4);
    }
    const PointWithCov top = prop.apply(sp.points.front());  // row 0, column 0: up and left
    EXPECT_GT(top.point_m.z(), 0.5);
    EXPECT_GT(top.point_m.y(), 0.0);
    // Depth sigma grows as z^2: ~ z/d * sigma_d at the centre.
    EXPECT_GT(top.cov_m2.xx, 0.f);
    // Second frame with the same calibration: no new table.
    ASSERT_TRUE(sense(obs));
    EXPECT_EQ(sum.tableBuilds, 1u);
    // A second camera with another calibration gets its own table; alternating frames of the
    // two cameras build nothing more.
    StereoGeometry g2 = g;
    g2.fx = g2.fy = 400;
    auto obs2 = makeObservation(g2, disp);
    obs2.sensorLabel = "STEREO_REAR";
    for (int k = 0; k < 2; k++) {
        ASSERT_TRUE(sense(obs2));
        ASSERT_TRUE(sense(obs));
    }
    EXPECT_EQ(sum.tableBuilds, 2u);
    // A changed sigma rebuilds.
    opts.stereo.matchingSigma_px = 0.5;
    ASSERT_TRUE(sense(obs));
    EXPECT_EQ(sum.tableBuilds, 3u);
}

TEST(StereoModel, GroundSeenByPitchedCameraIsMappedFlat) {
    // Camera 0.48 m high pitched 35 deg down (the paper's STOC mount) over flat ground z = 0; the
    // disparity image is computed from the geometry and the map must come out flat at 0 within
    // 3 sigma. The right image is absent: the disparity image is used.
    const StereoGeometry g = stocGeometry();
    const mrpt::poses::CPose3D camera(0, 0, 0.48, mrpt::DEG2RAD(-90.0), 0,
                                      mrpt::DEG2RAD(-90.0 - 35.0));
    DisparityImage disp(g.width, g.height);
    for (int v = 0; v < g.height; v++)
        for (int u = 0; u < g.width; u++) {
            const mrpt::math::TVector3D ray = camera.rotateVector(
                mrpt::math::TVector3D((u - g.cx) / g.fx, (v - g.cy) / g.fy, 1.0));
            if (ray.z >= -1e-3) continue;
            const double t = 0.48 / -ray.z;  // camera-frame depth of the ground
            if (t > 4) continue;
            disp.at(u, v) = float(g.baseline_m * g.fx / t);
        }
    auto obs = makeObservation(g, disp);
    obs.cameraPose = mrpt::poses::CPose3DQuat(camera);
    mrpt::maps::CMultiBinElevationMap map;
    map.insertionOptions.sensors.stereo = uncertainOptions();
    map.insertionOptions.sensors.stereo.subsample = 4;
    mrpt::poses::CPose3DPDFGaussian pose;
    for (int i = 0; i < 6; i++) pose.cov(i, i) = 1e-8;
    ASSERT_TRUE(map.insertObservation(obs, pose));
    const auto& st = map.statistics().sensorModels.stereo;
    EXPECT_EQ(st.halo + st.nearCluster, 0u);  // a smooth plane has no artefacts
    EXPECT_GT(st.kept, 5000u);
    size_t checked = 0;
    for (double x = 0.5; x < 2.0; x += 0.1)
        for (double y = -0.3; y <= 0.3; y += 0.1) {
            double h, s;
            if (!map.getHeight(x, y, h, s)) continue;
            EXPECT_LT(std::abs(h), 3 * s + 1e-3) << "at " << x << ", " << y;
            checked++;
        }
    EXPECT_GT(checked, 50u);
}

TEST(StereoModel, SgbmOnATexturedPairRecoversTheDisparity) {
    // Random texture shifted by 12 px: a fronto-parallel plane. Without a disparity image, the
    // model runs StereoSGBM on the pair.
    StereoGeometry g = stocGeometry();
    g.width = 320;
    g.height = 240;
    g.cx = 160;
    g.cxRight = 160;
    g.cy = 120;
    cv::Mat left(g.height, g.width, CV_8UC1), right(g.height, g.width, CV_8UC1);
    cv::RNG rng(3);
    cv::Mat big(g.height, g.width + 12, CV_8UC1);
    rng.fill(big, cv::RNG::UNIFORM, 0, 255);
    cv::GaussianBlur(big, big, cv::Size(3, 3), 0.8);
    big(cv::Rect(0, 0, g.width, g.height)).copyTo(left);
    big(cv::Rect(12, 0, g.width, g.height)).copyTo(right);  // right(u) = left(u + 12)?
    // A point at left column u appears in the right image at u - 12: right(u) = big(u + 12) =
    // left(u + 12), so right = left shifted by -12 columns, i.e. disparity +12.
    StereoModelOptions o;
    o.sgbmNumDisparities = 32;
    const DisparityImage d =
        computeDisparitySGBM(mrpt::img::CImage(left, mrpt::img::DEEP_COPY),
                             mrpt::img::CImage(right, mrpt::img::DEEP_COPY), o);
    size_t good = 0, valid = 0;
    for (int v = 0; v < g.height; v++)
        for (int u = 40; u < g.width; u++)
            if (d.valid(u, v)) {
                valid++;
                if (std::abs(d.at(u, v) - 12.f) <= 0.5f) good++;
            }
    EXPECT_GT(valid, size_t(0.9 * 280 * 240));
    EXPECT_GT(good, size_t(0.98 * double(valid)));

    // Through the observation: no disparity image, both images present.
    DisparityImage empty(g.width, g.height);
    auto obs = makeObservation(g, empty);
    obs.hasImageDisparity = false;
    obs.hasImageRight = true;
    obs.imageLeft = mrpt::img::CImage(left, mrpt::img::DEEP_COPY);
    obs.imageRight = mrpt::img::CImage(right, mrpt::img::DEEP_COPY);
    SensorModelOptions opts;
    opts.stereo.sgbmNumDisparities = 32;
    SensorModelState state;
    SensorPoints sp;
    ASSERT_TRUE(observationToSensorPoints(obs, mrpt::poses::CPose3DPDFGaussian(), opts, 0.02, 20,
                                          state, sp));
    ASSERT_GT(sp.points.size(), 10000u);
    size_t atDepth = 0;
    for (const auto& p : sp.points)
        if (std::abs(p.point_m.z() - 0.09 * 500 / 12) < 0.05) atDepth++;
    EXPECT_GT(atDepth, size_t(0.95 * double(sp.points.size())));

    obs.hasImageRight = false;
    EXPECT_THROW(observationToSensorPoints(obs, mrpt::poses::CPose3DPDFGaussian(), opts, 0.02, 20,
                                           state, sp),
                 std::invalid_argument);
}

TEST(StereoModel, SgbmFullWidthMatchesTheLeftmostColumns) {
    // The textured plane at disparity 12 again, 32 disparities searched: OpenCV leaves columns
    // 0-31 without disparity; with stereo_sgbm_full_width, columns 12-31 (right pixel u - 12 >= 0
    // inside the right image) get the true disparity, and no pixel gets a match whose right pixel
    // falls left of the right image.
    const int W = 320, H = 240, trueD = 12;
    cv::Mat big(H, W + trueD, CV_8UC1);
    cv::RNG rng(3);
    rng.fill(big, cv::RNG::UNIFORM, 0, 255);
    cv::GaussianBlur(big, big, cv::Size(3, 3), 0.8);
    const mrpt::img::CImage left(cv::Mat(big(cv::Rect(0, 0, W, H))), mrpt::img::DEEP_COPY);
    const mrpt::img::CImage right(cv::Mat(big(cv::Rect(trueD, 0, W, H))), mrpt::img::DEEP_COPY);
    StereoModelOptions o;
    o.sgbmNumDisparities = 32;
    o.sgbmFullWidth = false;
    const DisparityImage narrow = computeDisparitySGBM(left, right, o);
    o.sgbmFullWidth = true;
    const DisparityImage full = computeDisparitySGBM(left, right, o);
    size_t narrowBand = 0, band = 0, bandGood = 0, outside = 0, differ = 0;
    for (int v = 0; v < H; v++)
        for (int u = 0; u < W; u++) {
            if (u < 32) narrowBand += narrow.valid(u, v);
            if (full.valid(u, v) && u - full.at(u, v) < 0) outside++;
            if (u >= trueD + 2 && u < 32 && full.valid(u, v)) {  // 2 px: half the block
                band++;
                bandGood += std::abs(full.at(u, v) - trueD) <= 0.5f;
            }
            // Beyond the band the padding changes nothing but SGBM's paths from the left edge.
            if (u >= 64 && narrow.valid(u, v) && full.valid(u, v))
                differ += std::abs(narrow.at(u, v) - full.at(u, v)) > 0.5f;
        }
    EXPECT_EQ(narrowBand, 0u);
    EXPECT_GT(band, size_t(0.9 * 18 * H));
    EXPECT_GT(bandGood, size_t(0.98 * double(band)));
    EXPECT_EQ(outside, 0u);
    EXPECT_LT(differ, size_t(0.001 * 256 * H));
}

TEST(StereoModel, RowsOnTwoCoresGiveTheSamePointsInTheSameOrder) {
    // threads = 2: the helper thread does the lower half of the rows into its own array,
    // appended after the upper half. Every point, covariance and count must equal one thread's,
    // for steps 1 to 3 (odd row counts too); an image already in `out` stays in front.
    const StereoGeometry g = stocGeometry();
    const StereoCovarianceTable table(g, uncertainOptions());
    DisparityImage disp(g.width, g.height);
    std::mt19937 rng(4);
    std::uniform_real_distribution<float> d(0.f, 120.f);
    for (int v = 0; v < g.height; v++)
        for (int u = 0; u < g.width; u++) disp.at(u, v) = (u * 7 + v * 3) % 5 == 0 ? 0.f : d(rng);
    for (int step = 1; step <= 3; step++) {
        PointsWithCov one, two;
        one.push_back({Eigen::Vector3f(1, 2, 3), {}});
        two = one;
        const StereoPixelCounts a = table.appendPoints(disp, step, 0.2, 0.5, 10.0, one, 1);
        const StereoPixelCounts b = table.appendPoints(disp, step, 0.2, 0.5, 10.0, two, 2);
        EXPECT_GT(a.kept, 1000u);
        EXPECT_GT(a.noDisparity, 1000u);
        EXPECT_GT(a.outOfRange + a.tooNear, 100u);
        EXPECT_EQ(a.pixels, b.pixels);
        EXPECT_EQ(a.kept, b.kept);
        EXPECT_EQ(a.noDisparity, b.noDisparity);
        EXPECT_EQ(a.tooNear, b.tooNear);
        EXPECT_EQ(a.outOfRange, b.outOfRange);
        ASSERT_EQ(one.size(), two.size());
        EXPECT_EQ(std::memcmp(one.data(), two.data(), one.size() * sizeof(PointWithCov)), 0)
            << "step " << step;
    }
}

TEST(StereoModel, UnrectifiedPairIsRefused) {
    const StereoGeometry g = stocGeometry();
    DisparityImage disp(g.width, g.height);
    auto obs = makeObservation(g, disp);
    obs.leftCamera.dist[0] = 0.1;
    EXPECT_THROW(StereoGeometry::fromObservation(obs), std::invalid_argument);
    obs = makeObservation(g, disp);
    obs.rightCameraPose = mrpt::poses::CPose3DQuat(mrpt::poses::CPose3D(0.09, 0, 0, 0.01, 0, 0));
    EXPECT_THROW(StereoGeometry::fromObservation(obs), std::invalid_argument);
}

TEST(StereoModel, AppendPointsGivesPointCovarianceAndRefusesBadArguments) {
    const StereoGeometry g = stocGeometry();
    const StereoModelOptions o = uncertainOptions();
    const StereoCovarianceTable table(g, o);
    DisparityImage disp(g.width, g.height);
    disp.at(400, 300) = 40.f;  // z = 1.1 m: kept
    disp.at(80, 420) = 2.f;    // z = 22.5 m: beyond the 10 m range
    disp.at(10, 10) = 400.f;   // z = 0.11 m: nearer than 0.2 m
    PointsWithCov out;
    const StereoPixelCounts c = table.appendPoints(disp, 1, 0.2, 0.5, 10.0, out);
    EXPECT_EQ(c.pixels, size_t(g.width) * size_t(g.height));
    EXPECT_EQ(c.kept, 1u);
    EXPECT_EQ(c.tooNear, 1u);
    EXPECT_EQ(c.outOfRange, 1u);
    EXPECT_EQ(c.noDisparity, c.pixels - 3);
    ASSERT_EQ(out.size(), 1u);
    const Eigen::Vector3d p = g.triangulate(400, 300, 40.0);
    EXPECT_EQ(out[0].point_m, p.cast<float>());  // exactly eqs 8-9
    const Eigen::Matrix3d C = table.pointCovariance(400, 300, 40.0);
    EXPECT_EQ(out[0].cov_m2.toMatrix(), SymmetricCov3::fromMatrix(C).toMatrix());
    // Every other pixel with step 2: (400, 300) is visited, (80, 420) too, (10, 10) too.
    out.clear();
    EXPECT_EQ(table.appendPoints(disp, 2, 0.2, 0.5, 10.0, out).pixels, size_t(320 * 240));
    EXPECT_EQ(out.size(), 1u);
    EXPECT_THROW(table.appendPoints(disp, 0, 0.2, 0.5, 10.0, out), std::invalid_argument);
    EXPECT_THROW(table.appendPoints(DisparityImage(g.width - 1, g.height), 1, 0.2, 0.5, 10.0, out),
                 std::invalid_argument);
}
