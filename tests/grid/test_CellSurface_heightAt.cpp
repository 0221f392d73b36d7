/* The sub-cell surface (heightAt): heights at query points on no lattice, better than any one
 * height per cell, honest sigma, never across a step (doc/sub-cell-surface.md). */
#include <gtest/gtest.h>
#include <mrpt/maps/CMultiBinElevationMap.h>
#include <mrpt/math/TLine3D.h>
#include <mrpt/math/TObject3D.h>

#include <cmath>
#include <random>

#include "../common/test_scenes.h"
#include "SurfaceAccuracy.h"
#include "multibin/grid/BinUpdate.h"

using mrpt::maps::CMultiBinElevationMap;

namespace {
constexpr double kPi = 3.14159265358979323846;
constexpr double kCell_m = 0.02;
constexpr double kStepX_m = 0.311;  // inside a cell: that cell holds both sides
constexpr double kStep_m = 0.1;

/** Rock-like relief (slopes up to about 1.5) with a 10 cm step at x = kStepX_m. */
double terrain(double x, double y) {
    return 0.03 * std::sin(2 * kPi * x / 0.15) * std::cos(2 * kPi * y / 0.18) +
           0.008 * std::sin(2 * kPi * (x + 0.6 * y) / 0.05) + (x >= kStepX_m ? kStep_m : 0.0);
}

CMultiBinElevationMap fixedMap() { return test_scenes::fixedSquareMap(kCell_m, 0.6, 0.0005); }

/** `perCell` points per cell on average, uniformly placed, each displaced by its covariance
 * (1 mm horizontally, 2 mm vertically): the map is told the truth about its noise. */
multibin::PointsWithCov samplePoints(double perCell, unsigned seed,
                                     double (*surface)(double, double)) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> u(0.0, 0.6);
    std::normal_distribution<double> n(0.0, 1.0);
    const double sxy = 0.001, sz = 0.002;
    multibin::PointsWithCov pts;
    const size_t count = size_t(perCell * (0.6 / kCell_m) * (0.6 / kCell_m));
    for (size_t i = 0; i < count; i++) {
        const double x = u(rng), y = u(rng);
        multibin::PointWithCov p;
        p.point_m = Eigen::Vector3f(float(x + sxy * n(rng)), float(y + sxy * n(rng)),
                                    float(surface(x, y) + sz * n(rng)));
        p.cov_m2 = multibin::SymmetricCov3{};
        p.cov_m2.xx = p.cov_m2.yy = float(sxy * sxy);
        p.cov_m2.zz = float(sz * sz);
        pts.push_back(p);
    }
    return pts;
}
}  // namespace

TEST(SubCellSurface, BeatsTheOneHeightPerCellFloorAtRandomPoints) {
    CMultiBinElevationMap map = fixedMap();
    map.insertPoints(samplePoints(30, 1, terrain));
    // The inner area: every query point has four cell centres around it (bilinear).
    const auto r =
        multibin::test::measureSurfaceAccuracy(map, terrain, 0.02, 0.58, 0.02, 0.58, 20000, 2);
    ASSERT_EQ(r.points, 20000u);
    RecordProperty("floor_mm", std::to_string(1e3 * r.floor_m));
    RecordProperty("heightAt_mm", std::to_string(1e3 * r.heightAt_m));
    std::cout << "RMSE [mm]: floor " << 1e3 * r.floor_m << ", nearest " << 1e3 * r.nearest_m
              << ", bilinear " << 1e3 * r.bilinear_m << ", heightAt " << 1e3 * r.heightAt_m
              << "; within 3 sigma " << r.within3Sigma << " (nearest " << r.nearestWithin3Sigma
              << ")\n";
    EXPECT_GT(r.nearest_m, r.floor_m) << "no one height per cell beats the exact cell mean";
    EXPECT_LE(r.heightAt_m, 0.85 * r.floor_m);
    EXPECT_LT(r.heightAt_m, r.bilinear_m);
    EXPECT_GE(r.within3Sigma, 0.95);
}

TEST(SubCellSurface, SigmaGrowsTowardsTheCellEdgeOnASlope) {
    // A plane z = 0.5 x: exact at any point of a cell, its sigma least at the points' centroid.
    CMultiBinElevationMap map = fixedMap();
    map.insertPoints(samplePoints(30, 3, [](double x, double) { return 0.5 * x; }));
    const double cx = 0.31, cy = 0.31;  // a cell's centre
    double hc, sc, he, se;
    ASSERT_TRUE(map.heightAt(cx, cy, hc, sc));
    ASSERT_TRUE(map.heightAt(cx + 0.0099, cy + 0.0099, he, se));
    EXPECT_NEAR(hc, 0.5 * cx, 3 * sc);
    EXPECT_NEAR(he, 0.5 * (cx + 0.0099), 3 * se);
    // The slope inside the cell: the cell's constant would be 5 mm off at its corner. (Not
    // he - hc: the corner's answer blends the planes of the four cells around it, so the
    // difference carries the centre's noise too.)
    EXPECT_NEAR(he, 0.5 * (cx + 0.0099), 0.002) << "the slope inside the cell";
    EXPECT_GT(se, sc);
}

TEST(SubCellSurface, ContinuousAcrossCellEdgesOnOneSurface) {
    // A gentle noisy slope: each cell's plane carries its points' noise, so the planes of two
    // neighbouring cells disagree at their common edge by about a millimetre. heightAt blends the
    // planes of the four cells around the point, the same four on both sides of an edge, so its
    // answer does not jump there; the gap left is the slope over 2 um.
    CMultiBinElevationMap map = fixedMap();
    map.insertPoints(samplePoints(10, 6, [](double x, double y) { return 0.2 * x + 0.1 * y; }));
    double largestJump_m = 0, sum2 = 0;
    int edges = 0;
    for (int i = 3; i < 27; i++)
        for (const double y : {0.1049, 0.2131, 0.3877, 0.4513}) {
            const double edge = i * kCell_m;
            double hl, hr, sl, sr;
            ASSERT_TRUE(map.heightAt(edge - 1e-6, y, hl, sl));
            ASSERT_TRUE(map.heightAt(edge + 1e-6, y, hr, sr));
            largestJump_m = std::max(largestJump_m, std::abs(hr - hl));
            sum2 += (hr - hl) * (hr - hl);
            edges++;
            EXPECT_NEAR(sl, sr, 1e-4) << "x = " << edge << ", y = " << y;
        }
    std::cout << "largest jump at a cell edge " << 1e3 * largestJump_m << " mm, rms "
              << 1e3 * std::sqrt(sum2 / edges) << " mm\n";
    EXPECT_LT(largestJump_m, 1e-5);
}

TEST(SubCellSurface, NeverAcrossAStep) {
    // A 10 cm step on a cell boundary (x = 0.3) and one inside a cell (x = 0.511): queried up
    // to 3 mm (3 horizontal point sigmas) from the step, each side keeps its own surface, where
    // the cell's value mixes them or takes the wrong one.
    CMultiBinElevationMap map = fixedMap();
    const auto steps = [](double x, double) {
        return (x >= 0.3 ? 0.1 : 0.0) + (x >= 0.511 ? 0.1 : 0.0);
    };
    map.insertPoints(samplePoints(30, 4, steps));
    for (const double x : {0.261, 0.297, 0.303, 0.339, 0.5, 0.508, 0.514, 0.519}) {
        for (const double y : {0.305, 0.412}) {
            double h, s;
            ASSERT_TRUE(map.heightAt(x, y, h, s));
            EXPECT_NEAR(h, steps(x, y), 0.003) << "x = " << x << ", y = " << y;
            EXPECT_LE(std::abs(h - steps(x, y)), 3 * s) << "x = " << x << ", y = " << y;
        }
    }
}

TEST(SubCellSurface, NearestKeepsTheCellValue) {
    CMultiBinElevationMap map = fixedMap();
    map.insertPoints(samplePoints(10, 5, terrain));
    using Q = CMultiBinElevationMap::TInsertionOptions::TQueryOptions::HeightQuery;
    for (const double x : {0.101, 0.2345, 0.4567}) {
        for (const Q mode : {Q::Nearest, Q::Plane}) {
            map.insertionOptions.query.height_query = mode;
            double hg, sg, hWant, sWant, z;
            ASSERT_TRUE(map.getHeight(x, 0.3, hg, sg));
            ASSERT_TRUE(mode == Q::Nearest ? map.cellHeight(x, 0.3, hWant, sWant)
                                           : map.heightAt(x, 0.3, hWant, sWant));
            EXPECT_EQ(hg, hWant);
            EXPECT_EQ(sg, sWant);
            ASSERT_TRUE(map.dem_get_z(x, 0.3, z));
            EXPECT_EQ(z, hWant);
        }
    }
}

TEST(SubCellSurface, IntersectLine3DMeetsTheSubCellSurface) {
    // MRPT's intersectLine3D samples dem_get_z along the ray: a vertical ray at a cell's edge on
    // a slope meets the plane there, not the cell's value.
    CMultiBinElevationMap map = fixedMap();
    map.insertPoints(samplePoints(30, 6, [](double x, double) { return x; }));
    const double x = 0.3195, y = 0.305;
    double h, s, hCell, sCell;
    ASSERT_TRUE(map.heightAt(x, y, h, s));
    ASSERT_TRUE(map.cellHeight(x, y, hCell, sCell));
    ASSERT_GT(std::abs(h - hCell), 0.006) << "the test needs the two answers apart";
    mrpt::math::TObject3D hit;
    ASSERT_TRUE(map.intersectLine3D(
        mrpt::math::TLine3D(mrpt::math::TPoint3D(x, y, 1.0), mrpt::math::TPoint3D(x, y, 0.0)),
        hit));
    mrpt::math::TPoint3D p;
    ASSERT_TRUE(hit.getPoint(p));
    EXPECT_NEAR(p.z, h, 1e-6);
}

TEST(PoseSharedVariance, CodesRoundDownWithinAQuarterOctave) {
    // The byte a bin keeps per pose part (BinUpdate.h): never above the variance it stands for,
    // at most 19 % below it, monotone; NaN is "not known" and loses to any known code.
    using multibin::poseSigmaCode;
    using multibin::poseVariance_m2;
    EXPECT_EQ(poseSigmaCode(std::nanf("")), 0);
    EXPECT_EQ(poseVariance_m2(0), 0.0);
    EXPECT_EQ(poseSigmaCode(0.f), 1);
    EXPECT_EQ(poseSigmaCode(-1e-9f), 1);  // rounding below zero: the least code
    uint8_t previous = 0;
    for (double v = 1e-12; v < 1e6; v *= 1.01) {
        const uint8_t c = poseSigmaCode(float(v));
        ASSERT_GE(c, previous) << v;
        previous = c;
        EXPECT_LE(poseVariance_m2(c), float(v)) << v;
        EXPECT_GE(poseVariance_m2(c), 0.8 * v) << v;  // 2^-(1/4) = 0.84
    }
    EXPECT_EQ(multibin::leastPoseSigmaCode(0, 7), 7);
    EXPECT_EQ(multibin::leastPoseSigmaCode(9, 0), 9);
    EXPECT_EQ(multibin::leastPoseSigmaCode(9, 7), 7);
}

TEST(PoseSharedVariance, FramesSharingOnePoseErrorStayWithin3Sigma) {
    // Ten pitched laser scans of a slope from one drifting pose estimate: every frame's pose is
    // wrong by the same error, drawn from the pose PDF the map is given (as between two
    // corrections of a walking robot's odometry). Eq 15 fuses the ~100 points of a cell as
    // independent, so their fused sigma falls far below the pose error they share; the reported
    // sigma must keep the pose part (with the slope's share of its horizontal part for
    // heightAt). Without it the truth was inside 3 sigma at 49 % (heightAt) and 79 % (cell
    // value) of the query points.
    auto slope = [](double x, double y) { return 0.3 * x + 0.1 * y; };
    std::vector<mrpt::obs::CObservation2DRangeScan::Ptr> scans;
    std::vector<mrpt::poses::CPose3D> truePoses;
    for (int k = 0; k < 10; k++) {
        truePoses.emplace_back(0.1 + 0.005 * k, 0.6, slope(0.1 + 0.005 * k, 0.6), 0, 0, 0);
        scans.push_back(test_scenes::pitchedScanOver(slope, truePoses.back(), 0.26, 0.785));
    }
    const double sigmas[6] = {0.003, 0.003, 0.004, 0.004, 0.003, 0.003};  // x y z yaw pitch roll
    mrpt::math::CMatrixDouble66 cov;
    cov.setZero();
    for (int i = 0; i < 6; i++) cov(i, i) = sigmas[i] * sigmas[i];
    std::mt19937 rng(11);
    std::normal_distribution<double> n01;
    std::uniform_real_distribution<double> ux(0.30, 0.345), uy(0.45, 0.75);  // the scans' strip
    size_t queries = 0, cellInside = 0, planeInside = 0;
    double planeSigmaSum_m = 0;
    for (int trial = 0; trial < 60; trial++) {
        CMultiBinElevationMap map = test_scenes::fixedSquareMap(kCell_m, 1.2, 0.0005);
        double e[6];
        for (double& v : e) v = n01(rng);
        for (int k = 0; k < 10; k++) {
            const mrpt::poses::CPose3D& t = truePoses[size_t(k)];
            mrpt::poses::CPose3DPDFGaussian estimate;
            estimate.mean =
                mrpt::poses::CPose3D(t.x() + sigmas[0] * e[0], t.y() + sigmas[1] * e[1],
                                     t.z() + sigmas[2] * e[2], t.yaw() + sigmas[3] * e[3],
                                     t.pitch() + sigmas[4] * e[4], t.roll() + sigmas[5] * e[5]);
            estimate.cov = cov;
            mrpt::obs::CObservation2DRangeScan noisy = *scans[size_t(k)];
            for (size_t i = 0; i < noisy.getScanSize(); i++) {
                const float r = noisy.getScanRange(i);
                if (noisy.getScanRangeValidity(i))
                    noisy.setScanRange(i, float(r + (0.0006 + 0.0039 * r) * n01(rng)));
            }
            ASSERT_TRUE(map.insertObservation(noisy, estimate));
        }
        for (int q = 0; q < 20; q++) {
            const double x = ux(rng), y = uy(rng);
            double h, s, hc, sc;
            if (!map.heightAt(x, y, h, s) || !map.cellHeight(x, y, hc, sc)) continue;
            queries++;
            planeInside += std::abs(h - slope(x, y)) <= 3 * s;
            cellInside += std::abs(hc - slope(x, y)) <= 3 * sc;
            planeSigmaSum_m += s;
        }
    }
    ASSERT_GT(queries, 1000u);
    EXPECT_GE(double(planeInside) / double(queries), 0.95);
    EXPECT_GE(double(cellInside) / double(queries), 0.95);
    // Not by an absurd sigma: the pose part of a point's height here is about 4.2 mm.
    EXPECT_LT(planeSigmaSum_m / double(queries), 0.008);
}
