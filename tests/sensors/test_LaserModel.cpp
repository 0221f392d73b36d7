/* Laser model: eq 1 intensity rejection, mixed pixels, invalid beams, eq 14 continuity bound,
 * Monte Carlo consistency of the propagated covariance. */
#include <gtest/gtest.h>
#include <mrpt/core/bits_math.h>
#include <mrpt/maps/CMultiBinElevationMap.h>
#include <mrpt/obs/CObservation2DRangeScan.h>
#include <mrpt/system/datetime.h>

#include <cmath>
#include <limits>
#include <random>

#include "mc_check.h"
#include "multibin/geometry/PosePropagation.h"
#include "multibin/map/MapStatistics.h"
#include "multibin/sensors/LaserModel.h"

using namespace multibin;
using namespace multibin::sensors;

namespace {
/** A scan of `n` beams over `aperture_rad`, all with range `r_m` and valid. */
mrpt::obs::CObservation2DRangeScan makeScan(size_t n, double aperture_rad, float r_m) {
    mrpt::obs::CObservation2DRangeScan scan;
    scan.sensorLabel = "LASER";
    scan.aperture = float(aperture_rad);
    scan.rightToLeft = true;
    scan.maxRange = 4.0f;
    scan.resizeScan(n);
    for (size_t i = 0; i < n; i++) {
        scan.setScanRange(i, r_m);
        scan.setScanRangeValidity(i, true);
    }
    return scan;
}
}  // namespace

TEST(LaserModel, RestoredIntensityIsEquationOne) {
    // Ires = sqrt(I * 1023 / vAGC): I = 5000, vAGC = 512 -> sqrt(9990.234) = 99.951.
    EXPECT_NEAR(restoredIntensity(5000, 512), 99.9512, 1e-3);
    EXPECT_NEAR(restoredIntensity(1023, 1023), std::sqrt(1023.0), 1e-9);
}

TEST(LaserModel, LowIntensityRejectedOnlyWithinCheckRange) {
    LaserModelOptions opts;
    opts.agcByLabel["LASER"] = 512;
    opts.mixedPixelFilter = false;
    auto scan = makeScan(4, 0.1, 0.5f);
    scan.setScanHasIntensity(true);
    scan.setScanIntensity(0, 5000);  // Ires = 99.95 < 100 at 0.5 m: reject
    scan.setScanIntensity(1, 5100);  // Ires = 100.95: keep
    scan.setScanIntensity(2, 100);   // weak but beyond 1 m: keep
    scan.setScanRange(2, 1.5f);
    scan.setScanIntensity(3, 20000);  // strong: keep
    PointsWithCov pts;
    LaserStats st;
    laserScanToPoints(scan, opts, 0.02, 20, pts, st);
    EXPECT_EQ(st.lowIntensity, 1u);
    EXPECT_EQ(pts.size(), 3u);
    EXPECT_NEAR(pts[1].point_m.norm(), 1.5f, 1e-5);  // beam 2 kept

    // No AGC for the label: no intensity check at all.
    opts.agcByLabel.clear();
    LaserStats st2;
    laserScanToPoints(scan, opts, 0.02, 20, pts, st2);
    EXPECT_EQ(st2.lowIntensity, 0u);
    EXPECT_EQ(pts.size(), 4u);
}

TEST(LaserModel, InvalidNaNAndOutOfRangeBeamsAreSkippedAndCounted) {
    LaserModelOptions opts;
    auto scan = makeScan(8, 0.2, 1.0f);
    scan.setScanRangeValidity(1, false);                            // no return
    scan.setScanRange(2, 4.0f);                                     // >= maxRange
    scan.setScanRange(3, std::numeric_limits<float>::quiet_NaN());  // NaN
    scan.setScanRange(4, 0.01f);                                    // < min_range
    scan.setScanRange(5, 3.5f);                                     // > map max_range 3 m
    PointsWithCov pts;
    LaserStats st;
    laserScanToPoints(scan, opts, 0.02, 3.0, pts, st);
    EXPECT_EQ(st.beams, 8u);
    EXPECT_EQ(st.noReturn, 2u);
    EXPECT_EQ(st.notFinite, 1u);
    EXPECT_EQ(st.outOfRange, 2u);
    EXPECT_EQ(st.kept, 3u);
    EXPECT_EQ(pts.size(), 3u);
    for (const auto& p : pts) EXPECT_TRUE(p.point_m.allFinite());
}

TEST(LaserModel, MixedPixelBetweenForegroundAndBackgroundIsRejected) {
    LaserModelOptions opts;
    std::vector<float> r(41, 2.0f);
    for (size_t i = 0; i < 20; i++) r[i] = 1.0f;  // foreground edge at beam 20
    r[20] = 1.5f;                                 // straddles the edge: mixed
    auto mixed = findMixedPixels(r, opts);
    for (size_t i = 0; i < r.size(); i++) EXPECT_EQ(mixed[i], i == 20) << "beam " << i;

    // Two mixed beams, and a mixed beam against "no return" (infinitely far).
    r[21] = 1.8f;
    mixed = findMixedPixels(r, opts);
    EXPECT_TRUE(mixed[20] && mixed[21]);
    std::vector<float> veil(10, std::numeric_limits<float>::infinity());
    for (size_t i = 0; i < 5; i++) veil[i] = 1.0f;
    veil[5] = 2.5f;
    EXPECT_TRUE(findMixedPixels(veil, opts)[5]);
}

TEST(LaserModel, ThinObjectAndCleanEdgeAreKept) {
    LaserModelOptions opts;
    std::vector<float> r(41, 2.0f);
    for (size_t i = 0; i < 20; i++) r[i] = 1.0f;
    // A clean edge: nothing in between.
    for (bool m : findMixedPixels(r, opts)) EXPECT_FALSE(m);
    // A pole of one beam in front of both neighbours: a real object.
    r[30] = 0.7f;
    auto mixed = findMixedPixels(r, opts);
    EXPECT_FALSE(mixed[30]);
    // A three-beam cluster between the two sides is more than max_beams = 2: kept.
    r[19] = 1.3f;
    r[20] = 1.5f;
    r[21] = 1.7f;
    opts.mixedPixelJump_m = 0.25;
    mixed = findMixedPixels(r, opts);
    EXPECT_FALSE(mixed[19] || mixed[20] || mixed[21]);
    // Ground at a grazing angle: every step (5 cm) exceeds the jump, but the slope is steady.
    std::vector<float> grazing(30);
    for (size_t i = 0; i < grazing.size(); i++)
        grazing[i] = 1.0f + 0.05f * float(i) + 0.001f * float(i * i);
    for (bool m : findMixedPixels(grazing, LaserModelOptions())) EXPECT_FALSE(m);
    // ... while a mixed beam at the far end of such a slope, against a wall behind, is found.
    grazing[20] = grazing[19] + 0.5f;
    for (size_t i = 21; i < grazing.size(); i++) grazing[i] = grazing[19] + 1.0f;
    EXPECT_TRUE(findMixedPixels(grazing, LaserModelOptions())[20]);
    // Smooth ground (small steps) is one cluster.
    std::vector<float> ground(50);
    for (size_t i = 0; i < ground.size(); i++) ground[i] = 0.4f + 0.002f * float(i);
    for (bool m : findMixedPixels(ground, LaserModelOptions())) EXPECT_FALSE(m);
}

TEST(LaserModel, ScanMixedPixelCountedInStats) {
    LaserModelOptions opts;
    auto scan = makeScan(41, 0.3, 2.0f);
    for (size_t i = 0; i < 20; i++) scan.setScanRange(i, 1.0f);
    scan.setScanRange(20, 1.5f);
    PointsWithCov pts;
    LaserStats st;
    laserScanToPoints(scan, opts, 0.02, 20, pts, st);
    EXPECT_EQ(st.mixedPixel, 1u);
    EXPECT_EQ(pts.size(), 40u);
    opts.mixedPixelFilter = false;
    LaserStats st2;
    laserScanToPoints(scan, opts, 0.02, 20, pts, st2);
    EXPECT_EQ(pts.size(), 41u);
}

TEST(LaserModel, BeamDirectionsFollowEachScansGeometry) {
    // The beam directions are cached between scans; scans of other beam counts, apertures and
    // scanning directions, interleaved, must each get their own: every point is exactly
    // r_i (cos a_i, sin a_i, 0) with a_i = getScanAngle(i).
    LaserModelOptions opts;
    opts.mixedPixelFilter = false;
    struct Geometry {
        size_t beams;
        float aperture_rad;
        bool rightToLeft;
    };
    const Geometry geometries[] = {{683, 4.18879f, true},
                                   {683, 4.18879f, false},  // only the direction changes
                                   {181, float(M_PI), false},
                                   {683, 3.0f, false},
                                   {683, 4.18879f, false}};
    for (const Geometry& g : geometries) {
        mrpt::obs::CObservation2DRangeScan scan;
        scan.aperture = g.aperture_rad;
        scan.rightToLeft = g.rightToLeft;
        scan.maxRange = 5.0f;
        scan.resizeScan(g.beams);
        for (size_t i = 0; i < g.beams; i++) {
            scan.setScanRange(i, 0.5f + 0.001f * float(i));
            scan.setScanRangeValidity(i, true);
        }
        PointsWithCov pts;
        LaserStats stats;
        laserScanToPoints(scan, opts, 0.02, 20, pts, stats);
        ASSERT_EQ(pts.size(), g.beams);
        for (size_t i = 0; i < g.beams; i++) {
            const float a = scan.getScanAngle(i), r = scan.getScanRange(i);
            ASSERT_EQ(pts[i].point_m.x(), std::cos(a) * r) << g.beams << " beams, beam " << i;
            ASSERT_EQ(pts[i].point_m.y(), std::sin(a) * r) << g.beams << " beams, beam " << i;
        }
    }
}

TEST(LaserModel, ContinuityBoundHandComputed) {
    // Laser pointing straight down 0.5 m above the ground, exact poses: only the range term and
    // the allowance remain: 3 * sqrt(2) * sigma_r(0.5) + 0.01.
    LaserModelOptions opts;
    mrpt::poses::CPose3DPDFGaussian pose;  // zero covariance
    const mrpt::poses::CPose3D sensor(0, 0, 0.5, 0, mrpt::DEG2RAD(90.0), 0);
    PointsWithCov pts{{Eigen::Vector3f(0.5f, 0, 0), {}}};
    const double sr = opts.rangeSigma(0.5);
    EXPECT_NEAR(continuityBound_m(pts, sensor, pose, pose, opts), 3 * std::sqrt(2.0) * sr + 0.01,
                1e-9);

    // Pose height sigmas 1 cm and 2 cm, independent: sqrt(2 sr^2 + 1e-4 + 4e-4).
    auto a = pose, b = pose;
    a.cov(2, 2) = 1e-4;
    b.cov(2, 2) = 4e-4;
    EXPECT_NEAR(continuityBound_m(pts, sensor, a, b, opts),
                3 * std::sqrt(2 * sr * sr + 5e-4) + 0.01, 1e-9);
    // Fully correlated: the difference is 1 cm.
    opts.continuityPoseCorrelation = 1.0;
    EXPECT_NEAR(continuityBound_m(pts, sensor, a, b, opts),
                3 * std::sqrt(2 * sr * sr + 1e-4) + 0.01, 1e-9);
    // A pitch error moves a point 0.5 m ahead of the robot by 0.5 * sigma_pitch in height.
    opts.continuityPoseCorrelation = 0.0;
    const mrpt::poses::CPose3D forward(0, 0, 0.5, 0, mrpt::DEG2RAD(45.0), 0);
    PointsWithCov ahead{{Eigen::Vector3f(float(0.5 * std::sqrt(2.0)), 0, 0), {}}};
    auto c = pose;
    c.cov(4, 4) = 1e-4;  // pitch sigma 0.01 rad, previous pose exact
    const double srz = opts.rangeSigma(0.5 * std::sqrt(2.0)) * std::sqrt(0.5);
    EXPECT_NEAR(continuityBound_m(ahead, forward, pose, c, opts),
                3 * std::sqrt(2 * srz * srz + std::pow(0.5 * 0.01, 2)) + 0.01, 1e-9);
}

namespace {
/** A laser pointing straight down from `h_m` with beams across the scan plane; beam i at range
 * (h_m - rise_m[i]) / cos(a_i) hits the column below it at height rise_m[i]. */
mrpt::obs::CObservation2DRangeScan downwardScan(double h_m, const std::vector<double>& rise_m,
                                                double t_s) {
    auto scan = makeScan(rise_m.size(), 0.6, 1.0f);
    scan.sensorPose = mrpt::poses::CPose3D(0, 0, h_m, 0, mrpt::DEG2RAD(90.0), 0);
    scan.timestamp = mrpt::Clock::fromDouble(t_s);
    for (size_t i = 0; i < rise_m.size(); i++)
        scan.setScanRange(i, float((h_m - rise_m[i]) / std::cos(scan.getScanAngle(i))));
    return scan;
}
}  // namespace

TEST(LaserModel, ContinuityGateRejectsJumpAndKeepsSmallChangeInTheMap) {
    // Scan 1 sees flat ground; scan 2, 0.1 s later from the same pose, sees beam 3 3 cm higher
    // (beyond Delta_zmax ~ 1.7 cm: rejected) and beam 7 4 mm higher (within: kept). Both rises stay
    // inside bin 0, so only eq 14 can tell them apart.
    auto run = [](bool continuity) {
        mrpt::maps::CMultiBinElevationMap map;
        map.insertionOptions.sensors.laser.continuity = continuity;
        map.insertionOptions.visibility.enabled = false;
        mrpt::poses::CPose3DPDFGaussian pose;
        for (int i = 0; i < 6; i++) pose.cov(i, i) = 1e-8;
        std::vector<double> rise(11, 0.0);
        map.insertObservation(downwardScan(0.3, rise, 0.0), pose);
        rise[3] = 0.03;
        rise[7] = 0.004;
        map.insertObservation(downwardScan(0.3, rise, 0.1), pose);
        return map.statistics().insert;
    };
    const InsertStats on = run(true);
    EXPECT_EQ(on.continuityRejected, 1u);
    EXPECT_EQ(on.accepted, 21u);
    const InsertStats off = run(false);
    EXPECT_EQ(off.continuityRejected, 0u);
    EXPECT_EQ(off.accepted, 22u);
}

TEST(LaserModel, MonteCarloCovarianceMatchesPropagation) {
    // Range noise sigma_r(r) along the beam and robot pose noise C_R, pushed through the real
    // transform p_map = R (+) (S (+) r d); compared with the laser model + PosePropagator.
    LaserModelOptions opts;
    auto scan = makeScan(5, 0.8, 0.6f);
    scan.sensorPose = mrpt::poses::CPose3D(0.1, 0, 0.26, 0, mrpt::DEG2RAD(45.0), 0);
    PointsWithCov pts;
    LaserStats st;
    laserScanToPoints(scan, opts, 0.02, 20, pts, st);
    ASSERT_EQ(pts.size(), 5u);
    const size_t beam = 3;
    const auto pdf = mc::robotPosePdf();
    const PosePropagator prop(pdf, scan.sensorPose);
    const PointWithCov predicted = prop.apply(pts[beam]);

    std::mt19937 rng(7);
    std::normal_distribution<double> n01;
    const double a = scan.getScanAngle(beam), sr = opts.rangeSigma(0.6);
    std::vector<Eigen::Vector3d> samples;
    for (int k = 0; k < 4000; k++) {
        const double r = 0.6 + sr * n01(rng);
        const mrpt::poses::CPose3D R = mc::samplePose(pdf, rng);
        const mrpt::math::TPoint3D p =
            (R + scan.sensorPose)
                .composePoint(mrpt::math::TPoint3D(r * std::cos(a), r * std::sin(a), 0));
        samples.emplace_back(p.x, p.y, p.z);
    }
    mc::expectConsistent(samples, predicted.point_m.cast<double>(), predicted.cov_m2.toMatrix());
}
