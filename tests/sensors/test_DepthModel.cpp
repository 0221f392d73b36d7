/* Depth-camera model: Nguyen 2012 curve, covariance along the ray, Monte Carlo consistency, the
 * real MRPT depth frame through the map. */
#include <gtest/gtest.h>
#include <mrpt/maps/CMultiBinElevationMap.h>
#include <mrpt/maps/CSimplePointsMap.h>
#include <mrpt/obs/CObservation3DRangeScan.h>
#include <mrpt/obs/CObservationPointCloud.h>
#include <mrpt/obs/CRawlog.h>

#include <cmath>
#include <random>

#include "mc_check.h"
#include "multibin/geometry/PosePropagation.h"
#include "multibin/grid/BinGrid.h"
#include "multibin/map/MapInternals.h"
#include "multibin/map/MapStatistics.h"
#include "multibin/sensors/DepthModel.h"
#include "multibin/sensors/RayModel.h"
#include "multibin/sensors/SensorDispatch.h"

using namespace multibin;
using namespace multibin::sensors;

TEST(DepthModel, AxialAndLateralSigmasFollowTheModel) {
    DepthModelOptions o;
    // Nguyen 2012: 0.0012 + 0.0019 (z - 0.4)^2: 1.2 mm at 0.4 m, 4.24 mm at 1.65 m.
    EXPECT_NEAR(o.axialSigma_m(0.4), 0.0012, 1e-12);
    EXPECT_NEAR(o.axialSigma_m(1.65), 0.0012 + 0.0019 * 1.5625, 1e-12);
    const Eigen::Vector3f p(2.0f, 1.0f, -0.5f);
    const Eigen::Matrix3d C = rayPointCovariance(p, o).toMatrix();
    const double r = p.cast<double>().norm();
    const Eigen::Vector3d d = p.cast<double>() / r;
    EXPECT_NEAR(d.dot(C * d), std::pow(o.axialSigma_m(r), 2), 1e-9);
    // Any direction across the ray: (lateral sigma * r)^2.
    const Eigen::Vector3d across = d.cross(Eigen::Vector3d::UnitZ()).normalized();
    EXPECT_NEAR(across.dot(C * across), std::pow(o.lateralSigma_rad * r, 2), 1e-9);
    EXPECT_NEAR(across.dot(C * d), 0.0, 1e-9);
}

TEST(DepthModel, InvalidPointsSkippedAndCounted) {
    DepthModelOptions o;
    PointsWithCov out;
    DepthStats st;
    mrpt::obs::CObservationPointCloud cloud;
    auto pts = mrpt::maps::CSimplePointsMap::Create();
    pts->insertPoint(NAN, 0, 0);
    pts->insertPoint(0, 0, 0);  // no return
    pts->insertPoint(6, 0, 0);
    pts->insertPoint(1, 0, 0);
    cloud.pointcloud = pts;
    cloudToPoints(cloud, o, 0.1, 5, out, st);
    EXPECT_EQ(st.points, 4u);
    EXPECT_EQ(st.notFinite, 1u);
    EXPECT_EQ(st.outOfRange, 2u);
    EXPECT_EQ(st.kept, 1u);
    EXPECT_EQ(out.size(), 1u);
}

TEST(DepthModel, MonteCarloCovarianceMatchesPropagation) {
    // Axial and lateral noise of the stated model, plus robot pose noise, through the real
    // transform; compared with the depth covariance + PosePropagator.
    DepthModelOptions o;
    std::normal_distribution<double> n01;
    mc::expectRayModelConsistent(
        o, mrpt::poses::CPose3D(0.2, 0.0, 0.6, 0.1, 0.4, 0.0), Eigen::Vector3d(2.5, 0.4, -0.3), 5,
        [&](const Eigen::Vector3d& p, double r, const Eigen::Vector3d& d, const Eigen::Vector3d& e1,
            const Eigen::Vector3d& e2, std::mt19937& rng) {
            return Eigen::Vector3d(p + o.axialSigma_m(r) * n01(rng) * d +
                                   o.lateralSigma_rad * r * (n01(rng) * e1 + n01(rng) * e2));
        });
}

TEST(DepthModel, PointArraysOfDifferentSizesAreRefused) {
    mrpt::obs::CObservation3DRangeScan scan;
    scan.sensorLabel = "DEPTH";
    scan.hasPoints3D = true;
    scan.points3D_x.assign(10, 1.0f);
    scan.points3D_y.assign(3, 0.0f);
    scan.points3D_z.assign(10, 0.0f);
    PointsWithCov out;
    DepthStats st;
    try {
        depthScanToPoints(scan, DepthModelOptions(), 0.02, 20, out, st);
        ADD_FAILURE() << "accepted";
    } catch (const std::invalid_argument& e) {
        EXPECT_NE(std::string(e.what()).find("DEPTH"), std::string::npos);
        EXPECT_NE(std::string(e.what()).find("points3D"), std::string::npos);
    }
    scan.points3D_y.assign(10, 0.0f);
    depthScanToPoints(scan, DepthModelOptions(), 0.02, 20, out, st);
    EXPECT_EQ(out.size(), 10u);
}

TEST(DepthModel, PointCloudObservationUsesTheModel) {
    mrpt::obs::CObservationPointCloud cloud;
    auto pts = mrpt::maps::CSimplePointsMap::Create();
    pts->insertPoint(1.0f, 0.0f, 0.0f);
    pts->insertPoint(3.0f, 1.0f, -1.0f);
    cloud.pointcloud = pts;
    SensorModelOptions opts;
    SensorModelState state;
    SensorPoints sp;
    ASSERT_TRUE(observationToSensorPoints(cloud, mrpt::poses::CPose3DPDFGaussian(), opts, 0.02, 20,
                                          state, sp));
    ASSERT_EQ(sp.points.size(), 2u);
    const Eigen::Matrix3d C = sp.points[1].cov_m2.toMatrix();
    const Eigen::Vector3d d = Eigen::Vector3d(3, 1, -1).normalized();
    EXPECT_NEAR(d.dot(C * d), std::pow(opts.depth.axialSigma_m(std::sqrt(11.0)), 2), 1e-8);
}

TEST(DepthModel, RealMrptDepthFrameInsertsWithoutNaN) {
    mrpt::obs::CRawlog rawlog;
    ASSERT_TRUE(rawlog.loadFromRawLogFile(MULTIBIN_SOURCE_DIR "/rawlogs/mrpt_tests_rgbd.rawlog"));
    mrpt::maps::CMultiBinElevationMap map;
    map.insertionOptions.max_range_m = 6.0;
    map.insertionOptions.max_elevation_uncertainty_m = 0.15;
    SensorModelOptions opts = map.insertionOptions.sensors;
    size_t frames = 0;
    for (size_t i = 0; i < rawlog.size(); i++) {
        mrpt::obs::CObservation::Ptr obs;
        if (rawlog.getType(i) == mrpt::obs::CRawlog::etObservation)
            obs = rawlog.getAsObservation(i);
        else if (rawlog.getType(i) == mrpt::obs::CRawlog::etSensoryFrame)
            obs = rawlog.getAsObservations(i)
                      ->getObservationByClass<mrpt::obs::CObservation3DRangeScan>();
        auto depth = std::dynamic_pointer_cast<mrpt::obs::CObservation3DRangeScan>(obs);
        if (!depth) continue;
        frames++;
        // The points carry the depth model's covariance.
        SensorModelState state;
        SensorPoints sp;
        ASSERT_TRUE(observationToSensorPoints(*depth, mrpt::poses::CPose3DPDFGaussian(), opts, 0.02,
                                              6.0, state, sp));
        ASSERT_GT(sp.points.size(), 1000u);
        for (const auto& p : sp.points) {
            const Eigen::Matrix3d C = p.cov_m2.toMatrix();
            const Eigen::Vector3d d = p.point_m.cast<double>().normalized();
            const double r = p.point_m.cast<double>().norm();
            ASSERT_NEAR(std::sqrt(d.dot(C * d)), opts.depth.axialSigma_m(r), 1e-5);
        }
        EXPECT_TRUE(map.insertObservation(*depth, mrpt::poses::CPose3DPDFGaussian()));
    }
    ASSERT_EQ(frames, 1u);
    EXPECT_GT(map.statistics().sensorModels.depth.kept, 1000u);
    EXPECT_GT(map.statistics().insert.accepted, 1000u);
    // No NaN anywhere: every bin of every cell has a finite height, variance and certainty.
    const auto& g = multibin::MapInternals::grid(map);
    size_t bins = 0;
    for (int iy = g.window().iy0; iy < g.window().iy0 + g.window().ny; iy++)
        for (int ix = g.window().ix0; ix < g.window().ix0 + g.window().nx; ix++)
            g.forEachBin(ix, iy, [&](const multibin::Bin& b) {
                bins++;
                EXPECT_TRUE(std::isfinite(b.height_m) && std::isfinite(b.variance_m2) &&
                            std::isfinite(b.certainty));
                EXPECT_GT(b.variance_m2, 0.f);
            });
    EXPECT_GT(bins, 100u);
}

// The frame-shared error (doc/sensor-models.md, "Frame-shared error"): 16 points of one frame in
// one 2 cm cell, 1 m straight below the camera. Independent points fuse to sigma^2 / 16; with the
// shared error s they fuse to sigma^2 / 16 + s^2 (hand-computed), at the same height. A point too
// uncertain on its own (8 m away) is rejected by eq 13 either way, counted once.
TEST(DepthModel, FrameSharedErrorFusesToSigmaSquaredOverNPlusShared) {
    mrpt::obs::CObservation3DRangeScan scan;
    scan.sensorLabel = "DEPTH";
    scan.hasPoints3D = true;
    for (int i = 0; i < 4; i++)
        for (int j = 0; j < 4; j++) {
            scan.points3D_x.push_back(1.0f);  // +x forward: straight down once pitched
            scan.points3D_y.push_back(0.003f * float(i) - 0.0045f);
            scan.points3D_z.push_back(0.003f * float(j) - 0.0045f);
        }
    scan.points3D_x.push_back(8.0f);
    scan.points3D_y.push_back(0.0f);
    scan.points3D_z.push_back(0.0f);
    mrpt::poses::CPose3DPDFGaussian pose;  // exact
    pose.mean = mrpt::poses::CPose3D(0.01, 0.01, 1.0, 0, M_PI / 2, 0);

    double h[2], sigma[2];
    const DepthModelOptions shared;
    for (const bool on : {false, true}) {
        mrpt::maps::CMultiBinElevationMap map;
        map.insertionOptions.fill.enabled = false;
        map.insertionOptions.height_sigma_floor_m = 1e-5;
        if (!on) {
            map.insertionOptions.sensors.depth.quantisationStep_per_m = 0;
            map.insertionOptions.sensors.depth.frameSigmaRelative = 0;
        }
        ASSERT_TRUE(map.insertObservation(scan, pose));
        EXPECT_EQ(map.statistics().insert.accepted, 16u);
        EXPECT_EQ(map.statistics().insert.tooUncertain, 1u);
        ASSERT_TRUE(map.cellHeight(0.01, 0.01, h[on], sigma[on]));
    }
    const double sa = shared.axialSigma_m(1.0), s = shared.frameSigma_m(1.0);
    EXPECT_NEAR(s, std::sqrt(0.003 * 0.003 / 12 + 0.005 * 0.005), 1e-12);
    EXPECT_NEAR(sigma[0], sa / 4, 0.02 * sa / 4);
    EXPECT_NEAR(sigma[1], std::sqrt(sa * sa / 16 + s * s), 0.02 * s);
    EXPECT_NEAR(h[0], 0.0, 1e-4);
    EXPECT_NEAR(h[1], h[0], 1e-6);
}

TEST(MonteCarloCheck, DetectsACovarianceTwentyPercentOff) {
    // The consistency check itself: samples of N(0, I) pass against I and fail against 1.2 I
    // (NEES too small) and 0.8 I (NEES too large).
    std::mt19937 rng(9);
    std::normal_distribution<double> n01;
    std::vector<Eigen::Vector3d> s;
    for (int k = 0; k < 4000; k++) s.emplace_back(n01(rng), n01(rng), n01(rng));
    const Eigen::Matrix3d I = Eigen::Matrix3d::Identity();
    const mc::Consistency ok = mc::consistency(s, Eigen::Vector3d::Zero(), I);
    EXPECT_LT(ok.worstEntry, 0.1);
    EXPECT_TRUE(ok.meanNees > ok.neesLo && ok.meanNees < ok.neesHi) << ok.meanNees;
    const mc::Consistency big = mc::consistency(s, Eigen::Vector3d::Zero(), 1.2 * I);
    EXPECT_LT(big.meanNees, big.neesLo);
    EXPECT_GT(big.worstEntry, 0.1);
    const mc::Consistency small = mc::consistency(s, Eigen::Vector3d::Zero(), 0.8 * I);
    EXPECT_GT(small.meanNees, small.neesHi);
    EXPECT_GT(small.shareAbove, 0.01 + small.shareTol);
}
