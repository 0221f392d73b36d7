/* Stereo model: Jacobians against finite differences, per-pixel table, Monte Carlo consistency
 * of eqs 4-12, artefact filters, disparity image format, frames through the map. */
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

TEST(StereoModel, DisparityImageFormatRoundTrip) {
    DisparityImage d(4, 2);
    d.at(0, 0) = 12.5f;
    d.at(3, 1) = 0.0625f;
    const mrpt::img::CImage img = encodeDisparityImage(d);
    EXPECT_EQ(img.asCvMatRef().type(), CV_16UC1);
    EXPECT_EQ(img.asCvMatRef().at<uint16_t>(0, 0), 200);  // 12.5 * 16
    const DisparityImage back = decodeDisparityImage(img);
    EXPECT_FLOAT_EQ(back.at(0, 0), 12.5f);
    EXPECT_FLOAT_EQ(back.at(3, 1), 0.0625f);
    EXPECT_FALSE(back.valid(1, 0));  // 0 = invalid
    mrpt::img::CImage grey(4, 2, mrpt::img::CH_GRAY);
    EXPECT_THROW(decodeDisparityImage(grey), std::invalid_argument);
}

TEST(StereoArtefacts, HaloOnTheNearSideOfAnEdgeIsRemovedFarSideKept) {
    // Background 10 px; a foreground square (30 px) whose matching window fattened it by 2 px:
    // the halo ring carries the foreground disparity over the background.
    DisparityImage d(60, 60);
    for (auto& x : d.disparity_px) x = 10.f;
    for (int v = 18; v < 42; v++)
        for (int u = 18; u < 42; u++)
            d.at(u, v) = 30.f;  // true square: 20..39, halo 18..19, 40..41
    StereoModelOptions o;
    o.haloRadius_px = 2;
    const size_t removed = removeHalos(d, o);
    EXPECT_FALSE(d.valid(18, 30));  // halo pixel: reject
    EXPECT_FALSE(d.valid(41, 30));
    EXPECT_TRUE(d.valid(30, 30));  // foreground interior: keep
    EXPECT_TRUE(d.valid(17, 30));  // background next to the edge: keep
    EXPECT_TRUE(d.valid(5, 5));
    EXPECT_EQ(removed, size_t(24 * 24 - 20 * 20));  // a 2 px band inside the edge
    // A smooth slope (1 px per pixel) is not an edge.
    DisparityImage slope(40, 10);
    for (int v = 0; v < 10; v++)
        for (int u = 0; u < 40; u++) slope.at(u, v) = 5.f + 1.f * float(u);
    EXPECT_EQ(removeHalos(slope, o), 0u);
}

TEST(StereoArtefacts, TexturelessPixelsRemovedTexturedKept) {
    // Left half: alternating 0/255 columns (grey std 127.5); right half: uniform 100 with a
    // +-1 checkerboard (std exactly 1 in any 5 x 5 window: 13 of one sign and 12 of the other
    // give a variance of 1 - (1/25)^2 = 0.9984).
    const int W = 40, H = 20;
    cv::Mat img(H, W, CV_8UC1);
    for (int v = 0; v < H; v++)
        for (int u = 0; u < W; u++)
            img.at<uint8_t>(v, u) =
                u < W / 2 ? uint8_t(u % 2 ? 255 : 0) : uint8_t((u + v) % 2 ? 101 : 99);
    const mrpt::img::CImage left(img, mrpt::img::SHALLOW_COPY);
    DisparityImage d(W, H);
    for (float& x : d.disparity_px) x = 10.f;
    d.at(35, 10) = std::numeric_limits<float>::quiet_NaN();  // already invalid: not counted
    StereoModelOptions o;
    o.textureMinStd_grey = 1.5;
    DisparityImage out = d;
    // Windows reaching a textured column (u <= W/2 - 1 + 2) keep their pixels.
    const size_t expected = size_t(H) * size_t(W / 2 - 2) - 1;
    EXPECT_EQ(removeTextureless(out, left, o), expected);
    for (int v = 0; v < H; v++)
        for (int u = 0; u < W; u++) EXPECT_EQ(out.valid(u, v), u < W / 2 + 2) << u << "," << v;
    o.textureMinStd_grey = 0.9;  // below the checkerboard's std: nothing removed
    out = d;
    EXPECT_EQ(removeTextureless(out, left, o), 0u);
    o.textureMinStd_grey = 0;  // off
    EXPECT_EQ(removeTextureless(out, left, o), 0u);
    o.textureMinStd_grey = 1.5;
    DisparityImage small(W - 1, H);
    EXPECT_THROW(removeTextureless(small, left, o), std::invalid_argument);
}

TEST(StereoArtefacts, SmallNearClusterRemovedLargeOrFarKept) {
    StereoModelOptions o;
    o.nearClusterMaxArea_px = 50;
    DisparityImage d(80, 80);
    for (auto& x : d.disparity_px) x = 10.f;
    for (int v = 5; v < 10; v++)
        for (int u = 5; u < 10; u++) d.at(u, v) = 40.f;  // 25 px blob floating near: reject
    for (int v = 30; v < 40; v++)
        for (int u = 30; u < 40; u++) d.at(u, v) = 40.f;  // 100 px near object: keep
    for (int v = 60; v < 65; v++)
        for (int u = 60; u < 65; u++) d.at(u, v) = 4.f;  // 25 px farther than around: keep
    const size_t removed = removeNearClusters(d, o);
    EXPECT_EQ(removed, 25u);
    EXPECT_FALSE(d.valid(7, 7));
    EXPECT_TRUE(d.valid(35, 35));
    EXPECT_TRUE(d.valid(62, 62));
    EXPECT_TRUE(d.valid(20, 20));
    // An isolated speck in an invalid area is removed too.
    DisparityImage e(20, 20);
    for (int v = 2; v < 4; v++)
        for (int u = 2; u < 4; u++) e.at(u, v) = 12.f;
    EXPECT_EQ(removeNearClusters(e, o), 4u);
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
