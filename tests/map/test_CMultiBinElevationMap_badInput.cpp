/* Bad input through the public API of CMultiBinElevationMap: every case ends in a clear
 * exception (naming the input and the problem) or a skip counted in the statistics, and nothing
 * already in the map is lost (doc/reliability.md lists the cases and their outcomes). */
#include <gtest/gtest.h>
#include <mrpt/config/CConfigFileMemory.h>
#include <mrpt/maps/CMultiMetricMap.h>
#include <mrpt/maps/CSimplePointsMap.h>
#include <mrpt/obs/CObservation3DRangeScan.h>
#include <mrpt/obs/CObservationPointCloud.h>
#include <mrpt/obs/CObservationStereoImages.h>

#include <chrono>
#include <functional>
#include <limits>
#include <string>
#include <tuple>

#include "../common/reliability_helpers.h"
#include "multibin/grid/BinGrid.h"
#include "multibin/map/MapInternals.h"
#include "multibin/map/MapStatistics.h"
#include "multibin/sensors/SensorDispatch.h"
#include "multibin/sensors/StereoDisparity.h"

using namespace reliability;

namespace {
constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();
constexpr float kInf = std::numeric_limits<float>::infinity();
/** Beams of floorScan() that hit the floor within 4 m (683 beams over 240 deg, 45 deg pitch). */
constexpr size_t kFloorReturns = 481;

/** A scan of `beams` beams, all with range `r`, marked valid. */
mrpt::obs::CObservation2DRangeScan::Ptr scanOfRanges(float r, size_t beams = 50) {
    auto scan = floorScan(beams);
    for (size_t i = 0; i < beams; i++) {
        scan->setScanRange(i, r);
        scan->setScanRangeValidity(i, true);
    }
    return scan;
}

/** What one rejected observation added to the map's statistics. */
struct Counted {
    multibin::InsertStats core;
    multibin::sensors::LaserStats laser;
    multibin::sensors::DepthStats depth;
};

/** Inserts `obs` into a map that holds data, checks the map's bytes do not change, and returns
 * what the insertion added to the statistics. */
Counted insertIntoMapWithData(const mrpt::obs::CObservation& obs) {
    Map map = mapWithData();
    const auto before = serialize(map);
    const auto core0 = map.statistics().insert;
    const auto sensors0 = map.statistics().sensorModels;
    EXPECT_FALSE(map.insertObservation(obs, posePdf()));
    EXPECT_EQ(serialize(map), before) << "a rejected observation changed the map";
    const auto& c = map.statistics().insert;
    const auto& l = map.statistics().sensorModels.laser;
    const auto& d = map.statistics().sensorModels.depth;
    Counted out;
    out.core.accepted = c.accepted - core0.accepted;
    out.core.outOfRange = c.outOfRange - core0.outOfRange;
    out.core.notFinite = c.notFinite - core0.notFinite;
    out.core.badCovariance = c.badCovariance - core0.badCovariance;
    out.core.outsideMap = c.outsideMap - core0.outsideMap;
    out.core.outsideBinRange = c.outsideBinRange - core0.outsideBinRange;
    out.core.tooUncertain = c.tooUncertain - core0.tooUncertain;
    out.core.continuityRejected = c.continuityRejected - core0.continuityRejected;
    out.laser.notFinite = l.notFinite - sensors0.laser.notFinite;
    out.laser.noReturn = l.noReturn - sensors0.laser.noReturn;
    out.depth.notFinite = d.notFinite - sensors0.depth.notFinite;
    out.depth.outOfRange = d.outOfRange - sensors0.depth.outOfRange;
    EXPECT_EQ(out.core.accepted, 0u);
    return out;
}

/** The floor height the good scan gave: its beams all land on the line x = 0.26 m ahead of the
 * robot (45 deg pitch, 0.26 m high), i.e. on a cell border; either side may hold it. */
bool floorHeightAt(const Map& map, double xRobot_m, double y_m, double& h_m) {
    double s;
    return map.getHeight(xRobot_m + 0.2599, y_m, h_m, s) ||
           map.getHeight(xRobot_m + 0.2601, y_m, h_m, s);
}

mrpt::maps::CMultiMetricMap mapsFromIni(const std::string& iniText) {
    mrpt::config::CConfigFileMemory ini(iniText);
    mrpt::maps::TSetOfMetricMapInitializers inits;
    inits.loadFromConfigFile(ini, "map");
    return mrpt::maps::CMultiMetricMap(inits);
}

std::string iniWith(const std::string& creation, const std::string& insertion = "") {
    return "[map]\nmultiBinElevationMap_count = 1\n[map_multiBinElevationMap_00_creationOpts]\n" +
           creation + "\n[map_multiBinElevationMap_00_insertOpts]\n" + insertion + "\n";
}
}  // namespace

// ---------------------------------------------------------------------------------------------
// Ranges: each beam is a skip counted in InsertStats (notFinite / outOfRange) and LaserStats.
// ---------------------------------------------------------------------------------------------
TEST(BadInputRanges, NaNRangesAreCountedAndSkipped) {
    const Counted n = insertIntoMapWithData(*scanOfRanges(kNaN, 50));
    EXPECT_EQ(n.core.notFinite, 50u);
    EXPECT_EQ(n.laser.notFinite, 50u);
}

TEST(BadInputRanges, InfiniteRangesAreCountedAndSkipped) {
    auto scan = scanOfRanges(kInf, 50);
    for (size_t i = 0; i < 25; i++) scan->setScanRange(i, -kInf);
    const Counted n = insertIntoMapWithData(*scan);
    EXPECT_EQ(n.core.notFinite, 50u);
    EXPECT_EQ(n.laser.notFinite, 50u);
}

TEST(BadInputRanges, NegativeAndZeroRangesAreNoReturns) {
    auto scan = scanOfRanges(-1.0f, 50);
    for (size_t i = 0; i < 25; i++) scan->setScanRange(i, 0.f);
    const Counted n = insertIntoMapWithData(*scan);
    EXPECT_EQ(n.laser.noReturn, 50u);
    EXPECT_EQ(n.core.outOfRange, 50u);
}

TEST(BadInputRanges, BadBeamsAmongGoodOnesLeaveTheGoodOnes) {
    // Every 3rd beam NaN, inf, negative: the others land on the floor as usual.
    auto scan = floorScan();
    const size_t noReturnBefore = [] {
        Map m;
        m.insertObservation(*floorScan(), posePdf());
        return m.statistics().sensorModels.laser.noReturn;
    }();
    size_t nonFinite = 0, negative = 0;
    for (size_t i = 0, k = 0; i < scan->getScanSize(); i += 3, k++) {
        const bool wasReturn = scan->getScanRangeValidity(i);
        scan->setScanRange(i, k % 3 == 0 ? kNaN : k % 3 == 1 ? kInf : -0.5f);
        scan->setScanRangeValidity(i, true);
        if (k % 3 == 2)
            negative += wasReturn;  // a beam that had no return stays a no-return
        else
            nonFinite++;
        if (k % 3 != 2 && !wasReturn) negative--;  // ... and is now non-finite instead
    }
    Map map;
    EXPECT_TRUE(map.insertObservation(*scan, posePdf()));
    EXPECT_EQ(map.statistics().sensorModels.laser.notFinite, nonFinite);
    EXPECT_EQ(map.statistics().sensorModels.laser.noReturn, noReturnBefore + negative);
    double h;
    ASSERT_TRUE(floorHeightAt(map, 0, 0, h));
    EXPECT_NEAR(h, 0.0, 0.01);  // the floor, from the good beams
}

TEST(BadInputRanges, NonFinitePointCloudPointsAreCounted) {
    auto obs = mrpt::obs::CObservationPointCloud::Create();
    obs->sensorLabel = "CLOUD";
    auto pts = mrpt::maps::CSimplePointsMap::Create();
    pts->insertPoint(kNaN, 0, 0);
    pts->insertPoint(1, kInf, 0);
    pts->insertPoint(0, 0, 0);  // zero range
    obs->pointcloud = pts;
    const Counted n = insertIntoMapWithData(*obs);
    EXPECT_EQ(n.depth.notFinite, 2u);
    EXPECT_EQ(n.depth.outOfRange, 1u);
    EXPECT_EQ(n.core.notFinite + n.core.outOfRange, 3u);
}

// ---------------------------------------------------------------------------------------------
// Scans
// ---------------------------------------------------------------------------------------------
TEST(BadInputScans, EmptyScanInsertsNothing) {
    auto scan = floorScan(0);
    EXPECT_EQ(insertIntoMapWithData(*scan).core.rejected(), 0u);
}

TEST(BadInputScans, EmptyPointCloudAndMissingCloudInsertNothing) {
    auto obs = mrpt::obs::CObservationPointCloud::Create();
    insertIntoMapWithData(*obs);  // pointcloud == nullptr
    obs->pointcloud = mrpt::maps::CSimplePointsMap::Create();
    insertIntoMapWithData(*obs);
}

TEST(BadInputScans, SingleBeamScanWithApertureIsHandled) {
    // One beam: MRPT's beam spacing aperture / (N - 1) divides by zero.
    // MRPT's getScanAngle() gives NaN: the one point is counted as non-finite.
    auto scan = floorScan(1);
    scan->setScanRange(0, 0.5f);
    scan->setScanRangeValidity(0, true);
    EXPECT_EQ(insertIntoMapWithData(*scan).core.notFinite, 1u);
}

// The beam angles derive from the aperture: NaN made every beam NaN (counted as notFinite),
// 0 put every beam on one line, 100 rad wrapped the beams round 16 times; both were used.
TEST(BadInputScans, AnApertureThatIsNaNZeroOrOverATurnIsAnErrorAndCounted) {
    for (const double aperture : {double(kNaN), 0.0, -1.0, 100.0}) {
        SCOPED_TRACE(aperture);
        auto scan = scanOfRanges(0.5f, 50);
        scan->sensorLabel = "LASER";
        scan->aperture = float(aperture);
        Map map = mapWithData();
        const auto before = serialize(map);
        const size_t refused0 = map.statistics().sensorModels.laser.badAperture;
        expectErrorMentioning([&] { map.insertObservation(*scan, posePdf()); },
                              {"LASER", "aperture"});
        EXPECT_EQ(map.statistics().sensorModels.laser.badAperture - refused0, 50u);
        EXPECT_EQ(serialize(map), before);
    }
    // A full turn is a valid aperture.
    auto scan = scanOfRanges(0.5f, 50);
    scan->aperture = float(2 * M_PI);
    Map map = mapWithData();
    EXPECT_NO_THROW(map.insertObservation(*scan, posePdf()));
    EXPECT_EQ(map.statistics().sensorModels.laser.badAperture, 0u);
}

// Found by this test (was an out-of-bounds read of points3D_y/z); fixed in DepthModel.cpp.
TEST(BadInputScans, DepthScanPointArraysOfDifferentSizesAreAnError) {
    // hasPoints3D with points3D_y / points3D_z shorter than points3D_x.
    auto obs = mrpt::obs::CObservation3DRangeScan::Create();
    obs->sensorLabel = "DEPTH";
    obs->hasPoints3D = true;
    obs->points3D_x.assign(1000, 1.0f);
    obs->points3D_y.assign(3, 0.0f);
    obs->points3D_z.assign(3, 0.0f);
    Map map = mapWithData();
    const auto before = serialize(map);
    expectErrorMentioning([&] { map.insertObservation(*obs, posePdf()); }, {"DEPTH", "points3D"});
    EXPECT_EQ(serialize(map), before);
}

TEST(BadInputScans, DepthRangeImageSizeDifferentFromCalibrationIsAnError) {
    // A 4 x 3 px range image whose camera parameters claim 640 x 480 px.
    auto obs = mrpt::obs::CObservation3DRangeScan::Create();
    obs->sensorLabel = "DEPTH";
    obs->hasRangeImage = true;
    obs->rangeImage_setSize(3, 4);
    obs->rangeImage.fill(1.0f);
    obs->cameraParams.ncols = 640;
    obs->cameraParams.nrows = 480;
    obs->cameraParams.setIntrinsicParamsFromValues(500, 500, 320, 240);
    obs->cameraParamsIntensity = obs->cameraParams;
    // MRPT's unprojection asserts the sizes; its exception names both fields.
    Map map = mapWithData();
    const auto before = serialize(map);
    expectErrorMentioning([&] { map.insertObservation(*obs, posePdf()); },
                          {"rangeImage.cols()", "cameraParams.ncols"});
    EXPECT_EQ(serialize(map), before);
}

// ---------------------------------------------------------------------------------------------
// Covariances and poses
// ---------------------------------------------------------------------------------------------
TEST(BadInputPose, NaNInThePoseMeanIsAnErrorNamingTheObservation) {
    Map map = mapWithData();
    const auto before = serialize(map);
    auto pdf = posePdf();
    pdf.mean.x(std::numeric_limits<double>::quiet_NaN());
    expectErrorMentioning([&] { map.insertObservation(*floorScan(), pdf); }, {"LASER", "NaN"});
    expectErrorMentioning([&] { map.insertObservation(*floorScan(), pdf.mean); }, {"LASER", "NaN"});
    EXPECT_EQ(serialize(map), before);
    EXPECT_EQ(map.statistics().nonFinitePoses, 2u);  // refused and counted
}

TEST(BadInputPose, NaNInThePoseCovarianceRejectsEveryPoint) {
    auto pdf = posePdf();
    pdf.cov(2, 2) = std::numeric_limits<double>::quiet_NaN();
    Map map = mapWithData();
    const auto before = serialize(map);
    const size_t notFinite0 = map.statistics().insert.notFinite;
    // Every point's covariance is NaN: each is counted as non-finite, none reaches a bin.
    EXPECT_FALSE(map.insertObservation(*floorScan(), pdf));
    EXPECT_EQ(map.statistics().insert.notFinite - notFinite0, kFloorReturns);
    EXPECT_EQ(serialize(map), before);
}

TEST(BadInputPose, NonPositiveDefinitePoseCovarianceRejectsEveryPoint) {
    auto pdf = posePdf();
    pdf.cov(2, 2) = -1e-2;  // negative z variance
    Map map = mapWithData();
    const auto before = serialize(map);
    EXPECT_FALSE(map.insertObservation(*floorScan(), pdf));
    EXPECT_EQ(map.statistics().insert.badCovariance, kFloorReturns);
    EXPECT_EQ(serialize(map), before);
}

TEST(BadInputPose, NonSymmetricPoseCovarianceIsRejected) {
    // Symmetric part positive-definite, antisymmetric part large: not a covariance.
    auto pdf = posePdf();
    pdf.cov(0, 2) = 0.5;
    pdf.cov(2, 0) = -0.5;
    Map map = mapWithData();
    const auto before = serialize(map);
    EXPECT_FALSE(map.insertObservation(*floorScan(), pdf));
    EXPECT_EQ(map.statistics().insert.badCovariance, kFloorReturns);
    EXPECT_EQ(serialize(map), before);
}

TEST(BadInputPose, NonPositiveDefinitePointCovarianceIsCounted) {
    const Map::TCreationOptions c = fixedTwoMetreMap();
    Map map = mapWithData(c);
    const auto before = serialize(map);
    multibin::PointsWithCov pts(3);
    for (auto& p : pts) p.point_m = Eigen::Vector3f(0.5f, 0.f, 0.f);
    pts[0].cov_m2 = {-1e-4f, 0, 0, 1e-4f, 0, 1e-4f};     // negative variance
    pts[1].cov_m2 = {1e-4f, 1e-3f, 0, 1e-4f, 0, 1e-4f};  // |rho| > 1
    pts[2].cov_m2 = {1e-4f, 0, 0, 1e-4f, 0, kNaN};       // NaN
    const multibin::InsertStats s = map.insertPoints(pts);
    EXPECT_EQ(s.accepted, 0u);
    EXPECT_EQ(s.badCovariance + s.notFinite, 3u);
    EXPECT_EQ(serialize(map), before);
}

// ---------------------------------------------------------------------------------------------
// Points far outside the map, heights beyond the bin range
// ---------------------------------------------------------------------------------------------
TEST(BadInputExtent, PointsFarOutsideAFixedMapAreCounted) {
    const Map::TCreationOptions c = fixedTwoMetreMap();
    Map map = mapWithData(c);
    const auto before = serialize(map);
    multibin::PointsWithCov pts(4);
    const float far[4][2] = {{1e7f, 0}, {0, -1e7f}, {3e38f, 3e38f}, {1.5f, 0}};
    for (int i = 0; i < 4; i++) {
        pts[size_t(i)].point_m = Eigen::Vector3f(far[i][0], far[i][1], 0.f);
        pts[size_t(i)].cov_m2 = {1e-6f, 0, 0, 1e-6f, 0, 1e-6f};
    }
    EXPECT_EQ(map.insertPoints(pts).outsideMap, 4u);
    EXPECT_EQ(serialize(map), before);
}

// A window that cannot hold the data is never a silent empty map. A growing map holds every
// point within range, at any cell size (before the tiled storage, a growth limit smaller than its
// margin put the window beside the data); a fixed window far away fuses nothing and counts every
// point as outsideMap.
TEST(BadInputExtent, AGrowingMapHoldsEveryPointAndAFixedWindowCountsTheRest) {
    for (const double resolution_m : {0.02, 30.0}) {
        SCOPED_TRACE(std::to_string(resolution_m) + " m");
        Map::TCreationOptions c;
        c.resolution_m = resolution_m;
        Map map(c);
        map.insertObservation(*floorScan(), posePdf());
        const multibin::InsertStats& s = map.statistics().insert;
        EXPECT_GT(s.accepted, 0u);
        EXPECT_EQ(s.outsideMap, 0u);
        EXPECT_EQ(s.accepted, map.statistics().sensorModels.laser.kept);
    }
    Map::TCreationOptions far = fixedTwoMetreMap();
    far.resolution_m = 30;
    far.min_x = 5e7, far.max_x = 5e7 + 1;  // within the +-1e8 m of map coordinates
    Map map(far);
    map.insertObservation(*floorScan(), posePdf());
    EXPECT_EQ(map.statistics().insert.accepted, 0u);
    EXPECT_EQ(map.statistics().insert.outsideMap, map.statistics().sensorModels.laser.kept);
    EXPECT_GT(map.statistics().insert.outsideMap, 0u);
}

// A stray return 1000 km ahead: beyond max_range_m it is counted out of range and the window
// stays; with a range that admits it, it is fused, and the storage grows by a tile and the
// directory's entries, not by the 1000 km (a dense grid of that window: 5e10 cells).
TEST(BadInputExtent, AStrayFarPointCostsATileNotItsDistance) {
    Map map = mapWithData();
    const multibin::CellWindow w = multibin::MapInternals::grid(map).window();
    const size_t bytes0 = multibin::MapInternals::grid(map).memoryBytes();
    auto obs = mrpt::obs::CObservationPointCloud::Create();
    obs->sensorLabel = "CLOUD";
    auto pts = mrpt::maps::CSimplePointsMap::Create();
    pts->insertPoint(1e6f, 0, -0.3f);
    obs->pointcloud = pts;
    const size_t outOfRange0 = map.statistics().insert.outOfRange;
    map.insertObservation(*obs, posePdf());
    EXPECT_TRUE(multibin::MapInternals::grid(map).window() == w);
    EXPECT_EQ(map.statistics().insert.outOfRange - outOfRange0, 1u);
    map.insertionOptions.max_range_m = 1e7;                  // the point passes the sensor model
    map.insertionOptions.max_elevation_uncertainty_m = 1e5;  // and eq 13: sigma_z is ~1 km
    map.insertionOptions.default_pose_sigmas = {0, 0, 0, 0, 0, 0};
    const size_t accepted0 = map.statistics().insert.accepted;
    map.insertObservation(*obs, mrpt::poses::CPose3D());
    EXPECT_EQ(map.statistics().insert.accepted - accepted0, 1u)
        << "too uncertain " << map.statistics().insert.tooUncertain << ", outside map "
        << map.statistics().insert.outsideMap << ", not finite "
        << map.statistics().insert.notFinite << ", bad covariance "
        << map.statistics().insert.badCovariance << ", out of range "
        << map.statistics().insert.outOfRange;
    EXPECT_GT(multibin::MapInternals::grid(map).window().ix0 +
                  multibin::MapInternals::grid(map).window().nx,
              w.ix0 + w.nx + 1000000);
    EXPECT_LT(multibin::MapInternals::grid(map).memoryBytes() - bytes0, size_t(1) << 20);
}

TEST(BadInputExtent, ARobotPoseFarAwayKeepsTheDataAlreadyMapped) {
    // A finite but absurd pose (10^12 m): the grid may not follow it beyond its growth limit
    // (BinStore::kGrowthLimitCells from the map origin), and the floor mapped near the origin
    // must stay.
    Map map = mapWithData();
    const auto before = serialize(map);
    const size_t outside0 = map.statistics().insert.outsideMap;
    EXPECT_FALSE(map.insertObservation(*floorScan(), posePdf(1e12, -1e12)));
    EXPECT_EQ(serialize(map), before);  // window included: the grid did not jump there
    EXPECT_EQ(map.statistics().insert.outsideMap - outside0, kFloorReturns);
    double h;
    EXPECT_TRUE(floorHeightAt(map, 0, 0, h));
}

// Found by fuzz_observation_insert: applyVisibilityConstraint() walked each line of sight over its
// whole length; a sensor 10^9 m from the map (a corrupt sensorPose, a pose jump) meant ~10^11
// steps per updated cell. The walk now stops where the ray leaves the grid window.
TEST(BadInputExtent, ASensorFarFromTheMapDoesNotHangTheVisibilityConstraint) {
    const Map::TCreationOptions c = fixedTwoMetreMap();
    Map map(c);
    multibin::PointsWithCov pts(3);
    for (int i = 0; i < 3; i++) {
        pts[size_t(i)].point_m = Eigen::Vector3f(0.1f * float(i), 0.f, 0.f);
        pts[size_t(i)].cov_m2 = {1e-6f, 0, 0, 1e-6f, 0, 1e-6f};
    }
    const auto t0 = std::chrono::steady_clock::now();
    map.insertPoints(pts, std::numeric_limits<double>::infinity(), Eigen::Vector3d(1e9, 0.0, 1.0));
    const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    EXPECT_LT(s, 1.0) << "3 points took " << s << " s";
}

TEST(BadInputExtent, HeightsBeyondTheBinRangeAreCounted) {
    // int16 bin indices with 0.05 m bins cover +-1638 m.
    const Map::TCreationOptions c = fixedTwoMetreMap();
    Map map = mapWithData(c);
    const auto before = serialize(map);
    multibin::PointsWithCov pts(3);
    const float z[3] = {5000.f, -5000.f, 3e38f};
    for (int i = 0; i < 3; i++) {
        pts[size_t(i)].point_m = Eigen::Vector3f(0.5f, 0.f, z[i]);
        pts[size_t(i)].cov_m2 = {1e-6f, 0, 0, 1e-6f, 0, 1e-6f};
    }
    EXPECT_EQ(map.insertPoints(pts).outsideBinRange, 3u);
    EXPECT_EQ(serialize(map), before);
}

TEST(BadInputExtent, DualGridSurvivesAPoseJumpOfAThousandKilometres) {
    Map::TCreationOptions c;
    c.dual_grid = true;
    c.local_size_m = 1.0;
    c.local_resolution_m = 0.05;
    c.global_size_m = 4.0;
    c.global_resolution_m = 0.1;
    Map map(c);
    map.insertObservation(*floorScan(), posePdf());
    map.insertObservation(*floorScan(), posePdf(1e6, 1e6));
    map.insertObservation(*floorScan(), posePdf(-1e6, 0));
    for (const auto& b : content(map)) {
        EXPECT_TRUE(std::isfinite(std::get<4>(b)));
        EXPECT_GE(std::get<5>(b), 0.f);
    }
    double h;
    ASSERT_TRUE(floorHeightAt(map, -1e6, 0, h));
    EXPECT_NEAR(h, 0.0, 0.02);
}

// ---------------------------------------------------------------------------------------------
// Stereo: image sizes against the calibration
// ---------------------------------------------------------------------------------------------
TEST(BadInputStereo, DisparityImageSizeDifferentFromCalibrationIsAnError) {
    Map map = mapWithData();
    const auto before = serialize(map);
    expectErrorMentioning([&] { map.insertObservation(*stereoPair(16, 12), posePdf()); },
                          {"STEREO", "size"});
    EXPECT_EQ(serialize(map), before);
}

TEST(BadInputStereo, LeftAndRightCalibrationSizesDifferentIsAnError) {
    auto obs = stereoPair(32, 24);
    obs->rightCamera.ncols = 64;
    Map map = mapWithData();
    const auto before = serialize(map);
    expectErrorMentioning([&] { map.insertObservation(*obs, posePdf()); }, {"rightCamera", "size"});
    EXPECT_EQ(serialize(map), before);
}

TEST(BadInputStereo, ZeroCalibrationSizeIsAnError) {
    auto obs = stereoPair(32, 24);
    obs->leftCamera.ncols = obs->rightCamera.ncols = 0;
    Map map = mapWithData();
    const auto before = serialize(map);
    expectErrorMentioning([&] { map.insertObservation(*obs, posePdf()); }, {"leftCamera", "zero"});
    EXPECT_EQ(serialize(map), before);
}

// A NaN principal point turned every pixel's ray to NaN: the pair was processed and its pixels
// lost without a count. Non-finite or absurd intrinsics are an error, counted per pair.
TEST(BadInputStereo, NonFiniteOrAbsurdIntrinsicsAreAnErrorAndCounted) {
    const double inf = std::numeric_limits<double>::infinity();
    const std::vector<
        std::tuple<std::string, std::function<void(mrpt::img::TCamera&)>, std::string>>
        cases = {{"NaN cx", [](mrpt::img::TCamera& c) { c.cx(kNaN); }, "principal point"},
                 {"NaN cy", [](mrpt::img::TCamera& c) { c.cy(kNaN); }, "principal point"},
                 {"cx 1e9 px", [](mrpt::img::TCamera& c) { c.cx(1e9); }, "principal point"},
                 {"inf fx", [&](mrpt::img::TCamera& c) { c.fx(inf); }, "focal"},
                 {"NaN fy", [](mrpt::img::TCamera& c) { c.fy(kNaN); }, "focal"}};
    for (const auto& [name, spoil, what] : cases) {
        SCOPED_TRACE(name);
        auto obs = stereoPair(32, 24);
        spoil(obs->leftCamera);
        spoil(obs->rightCamera);
        Map map = mapWithData();
        const auto before = serialize(map);
        expectErrorMentioning([&] { map.insertObservation(*obs, posePdf()); }, {what});
        EXPECT_EQ(map.statistics().sensorModels.stereo.badCalibration, 1u);
        EXPECT_EQ(map.statistics().sensorModels.stereo.pixels, 0u) << "no pixel is visited";
        EXPECT_EQ(serialize(map), before);
    }
    auto obs = stereoPair(32, 24);
    obs->rightCamera.cx(kNaN);
    Map map = mapWithData();
    expectErrorMentioning([&] { map.insertObservation(*obs, posePdf()); },
                          {"rightCamera", "principal point"});
}

TEST(BadInputStereo, MatchingSizesAreInserted) {
    // The control case: the same pair with matching sizes does reach the map.
    Map map;
    EXPECT_TRUE(map.insertObservation(*stereoPair(32, 24), posePdf()));
    const auto& st = map.statistics().sensorModels.stereo;
    EXPECT_GT(map.statistics().insert.accepted, 0u)
        << "pixels " << st.pixels << " noDisparity " << st.noDisparity << " halo " << st.halo
        << " near " << st.nearCluster << " tooNear " << st.tooNear << " outOfRange "
        << st.outOfRange << " kept " << st.kept << "; core rejected "
        << map.statistics().insert.rejected() << " too uncertain "
        << map.statistics().insert.tooUncertain;
}

// ---------------------------------------------------------------------------------------------
// ini files
// ---------------------------------------------------------------------------------------------
TEST(BadInputIni, UnknownKeyIsAnErrorNamingSectionAndKey) {
    expectErrorMentioning([] { mapsFromIni(iniWith("resolutoin = 0.02")); },
                          {"map_multiBinElevationMap_00_creationOpts", "resolutoin"});
    expectErrorMentioning([] { mapsFromIni(iniWith("", "max_elevation_uncertanty = 0.1")); },
                          {"map_multiBinElevationMap_00_insertOpts", "max_elevation_uncertanty"});
}

TEST(BadInputIni, WrongTypeIsAnErrorNamingTheKey) {
    expectErrorMentioning([] { mapsFromIni(iniWith("resolution = two cm")); },
                          {"resolution", "two cm"});
    expectErrorMentioning([] { mapsFromIni(iniWith("grow = maybe")); }, {"grow", "maybe"});
    expectErrorMentioning([] { mapsFromIni(iniWith("", "default_pose_sigmas = 0.1 0.1")); },
                          {"default_pose_sigmas"});
    expectErrorMentioning([] { mapsFromIni(iniWith("", "laser_mixed_pixel_max_beams = 2.5")); },
                          {"laser_mixed_pixel_max_beams"});
}

// MRPT's ini writer takes a trailing backslash for a line continuation: such a value would not
// load back the same from saved options, so it is refused when read (reliability finding 8).
TEST(BadInputIni, AValueEndingInABackslashIsAnErrorNamingTheKey) {
    // Written through the API: in ini text MRPT's reader itself joins such a line with the next
    // (the fuzzer reached it with a line cut by a NUL byte).
    const auto loadLabels = [](const std::string& value) {
        mrpt::config::CConfigFileMemory ini;
        ini.write("s", "sensor_labels", value);
        Map::TInsertionOptions o;
        o.loadFromConfigFile(ini, "s");
        return o.sensor_labels;
    };
    EXPECT_EQ(loadLabels("LASER\\STEREO"), std::vector<std::string>{"LASER\\STEREO"});
    expectErrorMentioning([&] { loadLabels("LASER\\"); }, {"sensor_labels", "backslash"});
    expectErrorMentioning([&] { loadLabels("LASER\x01"); }, {"sensor_labels", "control character"});
}

TEST(BadInputIni, NegativeOrZeroSizesAreErrors) {
    for (const std::string key : {"resolution", "bin_height"})
        for (const std::string v : {"-0.02", "0", "nan", "inf"})
            expectErrorMentioning([&] { mapsFromIni(iniWith(key + " = " + v)); }, {key});
    for (const std::string key :
         {"local_size_m", "local_resolution", "global_size_m", "global_resolution"})
        expectErrorMentioning([&] { mapsFromIni(iniWith("dual_grid = true\n" + key + " = -1")); },
                              {key});
    expectErrorMentioning(
        [] { mapsFromIni(iniWith("grow = false\nmin_x = 1\nmax_x = -1\nmin_y = 0\nmax_y = 1")); },
        {"max"});
    expectErrorMentioning([] { mapsFromIni(iniWith("", "height_sigma_floor = -0.001")); },
                          {"height_sigma_floor"});
}

// Cells below 0.1 mm are refused: the growth limit (2^28 cells) would then reach less than 26 km
// from the map origin. A vast map at a sane cell size is not refused: it is stored in tiles.
TEST(BadInputIni, ACellTooSmallIsRefusedAndAVastExtentIsNot) {
    expectErrorMentioning([] { mapsFromIni(iniWith("resolution = 0.00001")); }, {"resolution"});
    expectErrorMentioning(
        [] { mapsFromIni(iniWith("dual_grid = true\nglobal_resolution = 1e-6")); },
        {"global_resolution"});
    EXPECT_NO_THROW(
        mapsFromIni(iniWith("grow = false\nresolution = 0.01\nmin_x = 0\nmax_x = 1e4\n"
                            "min_y = 0\nmax_y = 1e4")));
}

// A 300 m local grid at 15 mm (4e8 cells, 4.8 GB of cell slots) is refused by validate(), before
// anything is allocated.
TEST(BadInputIni, ADualGridTooLargeForMemoryIsRefusedBeforeAllocating) {
    Map::TCreationOptions c;
    c.dual_grid = true;
    c.local_size_m = 300;
    c.local_resolution_m = 0.015;
    expectErrorMentioning([&] { c.validate(); }, {"local_size_m"});
}
