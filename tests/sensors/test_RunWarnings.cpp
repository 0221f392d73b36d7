/* The counts and the end-of-run warnings (apps/elevation-mapper/RunWarnings.h): a point too
 * uncertain to grow the map is counted as too uncertain; a dominant reason names its option; a
 * horizontal laser, an all-default pose covariance and a dominant gate each give one warning. */
#include <gtest/gtest.h>
#include <mrpt/config/CConfigFile.h>
#include <mrpt/maps/CMultiBinElevationMap.h>
#include <mrpt/obs/CObservation2DRangeScan.h>
#include <mrpt/obs/CObservationVelodyneScan.h>

#include <cmath>
#include <string>

#include "RunWarnings.h"
#include "mrpt_datasets.h"
#include "multibin/map/MapStatistics.h"

namespace {
using Map = mrpt::maps::CMultiBinElevationMap;

/** A 2D scan of 181 beams over 180 degrees, every beam `range_m`, the scanner `pitch_rad` down
 * at 0.3 m on the robot. */
mrpt::obs::CObservation2DRangeScan scanOf(double range_m, double pitch_rad) {
    mrpt::obs::CObservation2DRangeScan scan;
    scan.sensorLabel = "LASER";
    scan.aperture = float(M_PI);
    scan.maxRange = 30.f;
    scan.resizeScan(181);
    for (size_t i = 0; i < 181; i++) {
        scan.setScanRange(i, float(range_m));
        scan.setScanRangeValidity(i, true);
    }
    scan.sensorPose = mrpt::poses::CPose3D(0, 0, 0.3, 0, pitch_rad, 0);
    scan.timestamp = mrpt::Clock::now();
    return scan;
}

mrpt::poses::CPose3DPDFGaussian posePdf() {
    mrpt::poses::CPose3DPDFGaussian pdf;
    for (int i = 0; i < 6; i++) pdf.cov(i, i) = 1e-6;
    return pdf;
}

bool mentions(const std::vector<std::string>& lines, const std::string& what) {
    for (const auto& l : lines)
        if (l.find(what) != std::string::npos) return true;
    return false;
}

Map vlp16Map(double resolution_m) {
    Map::TCreationOptions c;
    c.resolution_m = resolution_m;
    Map map(c);
    map.insertionOptions.max_range_m = 130;
    map.insertionOptions.fill.enabled = false;
    const auto obs = multibin::test::datasetObservations("test_velodyne_VLP16.rawlog");
    map.insertObservation(*obs.at(0), mrpt::poses::CPose3D());  // default pose covariance
    return map;
}
}  // namespace

// MRPT's VLP-16 scan with the map's default eq 13 limit (0.1 m) and the default pose covariance:
// most points are too uncertain. They are counted as such, not "outside map" (a count that sent
// the user to an option that changes nothing), whatever the grid, and the report names the
// option.
TEST(RunWarnings, TooUncertainPointsAreCountedAsSuchAndTheReportNamesTheOption) {
    const Map small = vlp16Map(0.1), fine = vlp16Map(0.05);
    const multibin::InsertStats &a = small.statistics().insert, &b = fine.statistics().insert;
    EXPECT_EQ(a.accepted, b.accepted);
    EXPECT_EQ(a.tooUncertain, b.tooUncertain);
    EXPECT_EQ(a.outsideMap, 0u);
    EXPECT_EQ(b.outsideMap, 0u);
    EXPECT_GT(a.tooUncertain, a.accepted);
    const std::string gate = dominantRejection(small);
    EXPECT_NE(gate.find("eq 13"), std::string::npos) << gate;
    EXPECT_NE(gate.find("max_elevation_uncertainty_m"), std::string::npos) << gate;
    EXPECT_NE(gate.find("default_pose_sigmas"), std::string::npos) << gate;
    EXPECT_TRUE(mentions(runWarnings(small, {}), "most points rejected by one gate"));
}

// A fixed window beside the data: every point is outside the map, the report says so and
// names the extent keys.
TEST(RunWarnings, PointsOutsideAFixedWindowNameTheExtentOptions) {
    Map::TCreationOptions c;
    c.grow = false;
    c.min_x = 100, c.max_x = 101, c.min_y = 100, c.max_y = 101;
    Map map(c);
    map.insertionOptions.fill.enabled = false;
    map.insertObservation(scanOf(2.0, 0.5), posePdf());
    EXPECT_GT(map.statistics().insert.outsideMap, 100u);
    const std::string gate = dominantRejection(map);
    EXPECT_NE(gate.find("outside map"), std::string::npos) << gate;
    EXPECT_NE(gate.find("min_x"), std::string::npos) << gate;
}

// A horizontal laser sees walls at its own height: one warning. The same laser pitched 30
// degrees down sees the floor: none.
TEST(RunWarnings, AHorizontalLaserWarnsThatNoGroundWasSeen) {
    for (const double pitch_rad : {0.0, 30 * M_PI / 180}) {
        Map map;
        map.insertionOptions.fill.enabled = false;
        // Pitched, the 3 m beams reach the floor (0.3 m down) at about 0.52 m ahead: 0.6 m beams.
        map.insertObservation(scanOf(pitch_rad > 0 ? 0.6 : 3.0, pitch_rad), posePdf());
        ASSERT_GT(map.statistics().insert.accepted, 100u);
        const auto warnings = runWarnings(map, {1});
        EXPECT_EQ(mentions(warnings, "no surface below the sensors"), pitch_rad == 0)
            << "pitch " << pitch_rad;
        EXPECT_EQ(warnings.size(), pitch_rad == 0 ? 1u : 0u);
    }
}

// Every observation with the default pose covariance: one warning; with one pose covariance of
// the input's own, none.
TEST(RunWarnings, AllDefaultPoseCovariancesWarnOnce) {
    Map map;
    map.insertionOptions.fill.enabled = false;
    map.insertObservation(scanOf(0.6, 30 * M_PI / 180), mrpt::poses::CPose3D());
    ASSERT_EQ(map.statistics().poseFallbacks, 1u);
    EXPECT_TRUE(mentions(runWarnings(map, {0}), "default pose covariance"));
    EXPECT_TRUE(runWarnings(map, {1}).empty());
}
