/* Tests of CMultiBinElevationMap as an MRPT map: options, serialization, CMultiMetricMap
 * creation, pose PDFs from CObservationRobotPose, growth, the statistics snapshot. */
#include <gtest/gtest.h>
#include <mrpt/config/CConfigFileMemory.h>
#include <mrpt/io/CMemoryStream.h>
#include <mrpt/maps/CMultiBinElevationMap.h>
#include <mrpt/maps/CMultiMetricMap.h>
#include <mrpt/maps/CSimplePointsMap.h>
#include <mrpt/obs/CObservation2DRangeScan.h>
#include <mrpt/obs/CObservationPointCloud.h>
#include <mrpt/obs/CObservationRobotPose.h>
#include <mrpt/poses/CPose3DPDFGaussian.h>
#include <mrpt/serialization/CArchive.h>

#include <Eigen/Dense>
#include <cstring>
#include <random>

#include "../common/test_scenes.h"
#include "multibin/grid/BinGrid.h"
#include "multibin/map/MapInternals.h"
#include "multibin/map/MapStatistics.h"

using mrpt::maps::CMultiBinElevationMap;
using mrpt::poses::CPose3D;
using mrpt::poses::CPose3DPDFGaussian;

namespace {
std::vector<uint8_t> serialize(const mrpt::serialization::CSerializable& o) {
    mrpt::io::CMemoryStream buf;
    auto arch = mrpt::serialization::archiveFrom(buf);
    arch.WriteObject(&o);
    const auto* p = static_cast<const uint8_t*>(buf.getRawBufferData());
    return std::vector<uint8_t>(p, p + buf.getTotalBytesCount());
}
}  // namespace

TEST(CMultiBinElevationMap, PitchedLaserOverFloorGivesFlatMapWithHonestSigma) {
    CMultiBinElevationMap map;
    const auto scan = test_scenes::pitchedScanOverFloor(0.26, mrpt::DEG2RAD(45.0));
    CPose3DPDFGaussian pose =
        test_scenes::poseWithCov(CPose3D(0, 0, 0, 0, 0, 0), {1e-4, 1e-4, 1e-4, 1e-4, 1e-4, 1e-4});
    ASSERT_TRUE(map.insertObservation(*scan, pose));
    EXPECT_GT(map.statistics().insert.accepted, 300u);
    double h, s;
    ASSERT_TRUE(map.getHeight(0.26, 0.0, h, s));  // straight ahead, 0.26 m at 45 deg
    EXPECT_NEAR(h, 0.0, 0.001);
    EXPECT_GE(s, map.insertionOptions.height_sigma_floor_m - 1e-9);
    EXPECT_FALSE(map.getHeight(-0.5, 0.0, h, s));  // behind the robot: never seen
    EXPECT_EQ(map.statistics().poseFallbacks, 0u);
}

TEST(CMultiBinElevationMap, ExactAndPartlyExactPosesAreFusedIndefiniteOnesRejected) {
    // An icp-slam keyframe has an all-zero 6x6 covariance: an exact pose. With it (and with a
    // rank-deficient one: only the yaw uncertain) every floor point the pose with 1e-4 sigmas
    // fuses must be fused too, at the same height. An indefinite covariance (|correlation| of x
    // and y of 2) is no covariance: every point is rejected and counted as such.
    const auto scan = test_scenes::pitchedScanOverFloor(0.26, mrpt::DEG2RAD(45.0));
    auto fuse = [&](const mrpt::math::CMatrixDouble66& cov, multibin::InsertStats& stats) {
        CMultiBinElevationMap map;
        CPose3DPDFGaussian pose;
        pose.cov = cov;
        map.insertObservation(*scan, pose);
        stats = map.statistics().insert;
        double h = NAN, s;
        map.getHeight(0.26, 0.0, h, s);
        return h;
    };
    mrpt::math::CMatrixDouble66 uncertain, zero, yawOnly, indefinite;
    uncertain.setIdentity();
    uncertain *= 1e-8;
    zero.setZero();
    yawOnly.setZero();
    yawOnly(3, 3) = 1e-6;
    indefinite.setZero();
    indefinite(0, 0) = indefinite(1, 1) = 1e-4;
    indefinite(0, 1) = indefinite(1, 0) = 2e-4;
    multibin::InsertStats reference, stats;
    const double h0 = fuse(uncertain, reference);
    ASSERT_GT(reference.accepted, 300u);
    for (const auto* cov : {&zero, &yawOnly}) {
        const double h = fuse(*cov, stats);
        EXPECT_EQ(stats.accepted, reference.accepted);
        EXPECT_EQ(stats.badCovariance, 0u);
        EXPECT_NEAR(h, h0, 1e-4);
        EXPECT_NEAR(h, 0.0, 1e-3);
    }
    fuse(indefinite, stats);
    EXPECT_EQ(stats.accepted, 0u);
    EXPECT_EQ(stats.badCovariance, reference.accepted);
}

TEST(CMultiBinElevationMap, UsesLatestRobotPoseCovarianceWhileFresh) {
    CMultiBinElevationMap map;
    auto robotPose = mrpt::obs::CObservationRobotPose::Create();
    robotPose->pose =
        test_scenes::poseWithCov(CPose3D(), {0.001, 0.001, 0.02, 0.001, 0.001, 0.001});
    robotPose->timestamp = mrpt::Clock::fromDouble(100.0);
    auto scan = test_scenes::pitchedScanOverFloor(0.26, mrpt::DEG2RAD(45.0));
    map.insertionOptions.max_elevation_uncertainty_m = 1.0;

    scan->timestamp = mrpt::Clock::fromDouble(100.1);
    map.insertObservation(*robotPose);
    ASSERT_TRUE(map.insertObservation(*scan, CPose3D()));
    EXPECT_EQ(map.statistics().poseFallbacks, 0u);
    double h, sFresh;
    ASSERT_TRUE(map.cellHeight(0.26, 0.0, h, sFresh));
    // sigma_z of the robot pose is 20 mm; one scan's points are fused as independent, so the
    // cell's sigma is 20 mm / sqrt(points in the cell).
    EXPECT_GT(sFresh, 0.005);

    CMultiBinElevationMap map2;
    map2.insertionOptions = map.insertionOptions;
    scan->timestamp = mrpt::Clock::fromDouble(101.0);  // 0.9 s > robot_pose_max_dt
    map2.insertObservation(*robotPose);
    ASSERT_TRUE(map2.insertObservation(*scan, CPose3D()));
    EXPECT_EQ(map2.statistics().poseFallbacks, 1u);
    double sStale;
    ASSERT_TRUE(map2.cellHeight(0.26, 0.0, h, sStale));
    // sigma_z: about 10.4 mm with the default covariance against 20 mm with the robot pose's.
    EXPECT_NEAR(sStale / sFresh, 10.4 / 20.0, 0.05);
}

TEST(CMultiBinElevationMap, SerializationRoundTripIsBitExactThroughClassRegistry) {
    CMultiBinElevationMap map;
    map.insertionOptions.height_sigma_floor_m = 0.0031;
    map.insertionOptions.sensor_labels = {"LASER", "STEREO"};
    const auto scan = test_scenes::pitchedScanOverFloor(0.26, mrpt::DEG2RAD(45.0));
    for (int k = 0; k < 5; k++)
        map.insertObservation(
            *scan, test_scenes::poseWithCov(CPose3D(0.05 * k, 0, 0.01 * k, 0.1 * k, 0, 0),
                                            {1e-3, 1e-3, 1e-3, 1e-3, 1e-3, 1e-3}));
    ASSERT_GT(multibin::MapInternals::grid(map).binCount(), 100u);
    const std::vector<uint8_t> bytes = serialize(map);

    mrpt::io::CMemoryStream buf;
    buf.assignMemoryNotOwn(bytes.data(), bytes.size());
    auto arch = mrpt::serialization::archiveFrom(buf);
    const mrpt::serialization::CSerializable::Ptr obj = arch.ReadObject();  // via the registry
    const auto copy = std::dynamic_pointer_cast<CMultiBinElevationMap>(obj);
    ASSERT_TRUE(copy);
    EXPECT_EQ(serialize(*copy), bytes);
    EXPECT_EQ(multibin::MapInternals::grid(*copy).binCount(),
              multibin::MapInternals::grid(map).binCount());
    EXPECT_EQ(copy->insertionOptions.sensor_labels, map.insertionOptions.sensor_labels);
    const auto& w = multibin::MapInternals::grid(map).window();
    for (int iy = w.iy0; iy < w.iy0 + w.ny; iy++)
        for (int ix = w.ix0; ix < w.ix0 + w.nx; ix++) {
            const auto* a = multibin::MapInternals::grid(map).winningBin(ix, iy);
            const auto* b = multibin::MapInternals::grid(*copy).winningBin(ix, iy);
            ASSERT_EQ(a == nullptr, b == nullptr);
            if (a) {
                EXPECT_EQ(a->height_m, b->height_m);
                EXPECT_EQ(a->variance_m2, b->variance_m2);
                EXPECT_EQ(a->certainty, b->certainty);
                EXPECT_EQ(std::memcmp(&a->plane, &b->plane, sizeof a->plane), 0)
                    << "plane moments of cell " << ix << ", " << iy;
                // The pose parts (serialized since version 4): the reported sigma keeps them.
                EXPECT_NE(a->poseHeightSigmaCode, 0);
                EXPECT_EQ(a->poseHeightSigmaCode, b->poseHeightSigmaCode);
                EXPECT_EQ(a->poseHorizontalSigmaCode, b->poseHorizontalSigmaCode);
            }
        }
    // The sub-cell surface (from the plane moments, serialized since version 3) answers the same
    // at any point: before, a loaded map had no moments and answered with flat cells.
    std::mt19937 rng(3);
    std::uniform_real_distribution<double> x(0.2, 0.5), y(-0.3, 0.3);
    int answered = 0;
    for (int k = 0; k < 500; k++) {
        const double qx = x(rng), qy = y(rng);
        double h0, s0, h1, s1;
        const bool known = map.heightAt(qx, qy, h0, s0);
        ASSERT_EQ(copy->heightAt(qx, qy, h1, s1), known);
        if (!known) continue;
        answered++;
        EXPECT_EQ(h0, h1) << qx << ", " << qy;
        EXPECT_EQ(s0, s1) << qx << ", " << qy;
    }
    EXPECT_GT(answered, 100);
}

TEST(CMultiBinElevationMap, CorruptOrUnknownVersionSerializationIsRefused) {
    CMultiBinElevationMap map;
    map.insertObservation(*test_scenes::pitchedScanOverFloor(0.26, 0.78), CPose3D());
    std::vector<uint8_t> bytes = serialize(map);
    // Truncated stream.
    {
        mrpt::io::CMemoryStream buf;
        buf.assignMemoryNotOwn(bytes.data(), bytes.size() / 2);
        auto arch = mrpt::serialization::archiveFrom(buf);
        EXPECT_ANY_THROW(arch.ReadObject());
    }
    // Unknown version: the version byte follows the class name in MRPT's object header.
    const std::string name = "CMultiBinElevationMap";
    auto it = std::search(bytes.begin(), bytes.end(), name.begin(), name.end());
    ASSERT_NE(it, bytes.end());
    *(it + long(name.size())) = 77;
    {
        mrpt::io::CMemoryStream buf;
        buf.assignMemoryNotOwn(bytes.data(), bytes.size());
        auto arch = mrpt::serialization::archiveFrom(buf);
        EXPECT_ANY_THROW(arch.ReadObject());
    }
}

TEST(CMultiBinElevationMap, IniOptionsRoundTripAndMalformedValuesAreRefused) {
    CMultiBinElevationMap::TCreationOptions c;
    c.resolution_m = 0.015;
    c.bin_height_m = 0.04;
    c.grow = false;
    c.min_x = -1;
    c.max_x = 1;
    c.min_y = -2;
    c.max_y = 2.5;
    CMultiBinElevationMap::TInsertionOptions in;
    in.max_elevation_uncertainty_m = 0.0731;
    in.default_pose_sigmas = {0.1, 0.2, 0.3, 0.01, 0.02, 0.03};
    in.sensor_labels = {"STEREO"};
    in.render.colormap = mrpt::img::cmHOT;
    mrpt::config::CConfigFileMemory ini;
    c.saveToConfigFile(ini, "c");
    in.saveToConfigFile(ini, "i");
    CMultiBinElevationMap::TCreationOptions c2;
    CMultiBinElevationMap::TInsertionOptions in2;
    c2.loadFromConfigFile(ini, "c");
    in2.loadFromConfigFile(ini, "i");
    EXPECT_EQ(c2.resolution_m, c.resolution_m);
    EXPECT_EQ(c2.bin_height_m, c.bin_height_m);
    EXPECT_EQ(c2.grow, c.grow);
    EXPECT_EQ(c2.max_y, c.max_y);
    EXPECT_EQ(in2.max_elevation_uncertainty_m, in.max_elevation_uncertainty_m);
    EXPECT_EQ(in2.default_pose_sigmas, in.default_pose_sigmas);
    EXPECT_EQ(in2.sensor_labels, in.sensor_labels);
    EXPECT_EQ(in2.render.colormap, in.render.colormap);

    auto expectRefused = [](const std::string& text, const std::string& mention) {
        mrpt::config::CConfigFileMemory bad(text);
        CMultiBinElevationMap::TCreationOptions o;
        try {
            o.loadFromConfigFile(bad, "c");
            ADD_FAILURE() << "accepted: " << text;
        } catch (const std::invalid_argument& e) {
            EXPECT_NE(std::string(e.what()).find(mention), std::string::npos) << e.what();
        }
    };
    expectRefused("[c]\nresolution = 0.0x5\n", "resolution");
    expectRefused("[c]\nresoltion = 0.05\n", "resoltion");  // unknown key (typo)
    expectRefused("[c]\nresolution = -0.05\n", "resolution");
    expectRefused("[c]\ngrow = maybe\n", "grow");
    expectRefused("[c]\nresolution = 0.00001\n", "resolution");  // below 0.1 mm
    // The retired size limit is accepted (with a message on stderr) and changes nothing.
    mrpt::config::CConfigFileMemory retired("[c]\nmax_size_m = 40\n");
    EXPECT_NO_THROW(c2.loadFromConfigFile(retired, "c"));
    // MRPT's generic keys are accepted.
    mrpt::config::CConfigFileMemory generic("[c]\nenableSaveAs3DObject = false\n");
    EXPECT_NO_THROW(c2.loadFromConfigFile(generic, "c"));
}

TEST(CMultiBinElevationMap, CMultiMetricMapFromIniTextContainsTheMap) {
    const std::string ini =
        "[map]\n"
        "multiBinElevationMap_count = 1\n"
        "[map_multiBinElevationMap_00_creationOpts]\n"
        "resolution = 0.03\n"
        "enableSaveAs3DObject = true\n"
        "[map_multiBinElevationMap_00_insertOpts]\n"
        "max_elevation_uncertainty = 0.08\n";
    mrpt::config::CConfigFileMemory cfg(ini);
    mrpt::maps::TSetOfMetricMapInitializers inits;
    inits.loadFromConfigFile(cfg, "map");
    mrpt::maps::CMultiMetricMap mm(inits);
    const auto map = mm.mapByClass<CMultiBinElevationMap>();
    ASSERT_TRUE(map);
    EXPECT_DOUBLE_EQ(map->creationOptions.resolution_m, 0.03);
    EXPECT_DOUBLE_EQ(map->insertionOptions.max_elevation_uncertainty_m, 0.08);
    const auto scan = test_scenes::pitchedScanOverFloor(0.26, mrpt::DEG2RAD(45.0));
    mm.insertObservation(*scan, CPose3D());
    EXPECT_FALSE(map->isEmpty());

    mrpt::config::CConfigFileMemory bad(
        "[map]\nmultiBinElevationMap_count = 1\n[map_multiBinElevationMap_00_insertOpts]\n"
        "max_elevation_uncertainty = 8cm\n");
    mrpt::maps::TSetOfMetricMapInitializers badInits;
    EXPECT_THROW(badInits.loadFromConfigFile(bad, "map"), std::exception);
}

TEST(CMultiBinElevationMap, PointCloudObservationAndGrowth) {
    CMultiBinElevationMap map;
    auto obs = mrpt::obs::CObservationPointCloud::Create();
    auto pts = mrpt::maps::CSimplePointsMap::Create();
    // A plane z = -1 in the sensor frame, 3 x 3 m, plus far points.
    for (double x = -1.5; x <= 1.5; x += 0.05)
        for (double y = -1.5; y <= 1.5; y += 0.05) pts->insertPoint(float(x), float(y), -1.0f);
    pts->insertPoint(15.f, 0.f, -1.f);
    pts->insertPoint(50.f, 0.f, -1.f);  // beyond max_range
    obs->pointcloud = pts;
    obs->sensorPose = CPose3D(0, 0, 1.0, 0, 0, 0);
    ASSERT_TRUE(map.insertObservation(*obs, CPose3D(10, 5, 0, 0, 0, 0)));
    double h, s;
    ASSERT_TRUE(map.getHeight(10.0, 5.0, h, s));
    EXPECT_NEAR(h, 0.0, 1e-4);
    // The window: the 3 m plane and the 1 m growth margin on each side, not the 15 m point.
    EXPECT_NEAR(map.getXMax() - map.getXMin(), 5.0, 0.1);
    // 15 m away: with the default pose covariance too uncertain (3 sigma_z ~ 0.2 m > 0.1 m),
    // which is what it is counted as, wherever it lies; it does not grow the window.
    EXPECT_EQ(map.statistics().insert.tooUncertain, 1u);
    EXPECT_EQ(map.statistics().insert.outsideMap, 0u);
    EXPECT_EQ(map.statistics().insert.outOfRange, 1u);  // 50 m away: beyond max_range
}

// statistics(): one snapshot of every count, each part from its own counter (distinct counts, so
// that parts swapped or left out show), the deprecated accessors its parts, clear() zeroes it.
TEST(CMultiBinElevationMap, StatisticsSnapshotHoldsEveryCountOnce) {
    CMultiBinElevationMap map;
    map.insertionOptions.sensor_labels = {"CLOUD"};
    const auto cloud = [](const std::string& label) {
        auto obs = mrpt::obs::CObservationPointCloud::Create();
        auto pts = mrpt::maps::CSimplePointsMap::Create();
        for (int i = -10; i <= 10; i++)  // 21 x 21 points of a plane z = -1 in the sensor frame
            for (int j = -10; j <= 10; j++) pts->insertPoint(0.05f * i, 0.05f * j, -1.0f);
        pts->insertPoint(15.f, 0.f, -1.f);  // too uncertain with the default pose covariance
        pts->insertPoint(50.f, 0.f, -1.f);  // beyond max_range
        obs->pointcloud = pts;
        obs->sensorPose = CPose3D(0, 0, 1.0, 0, 0, 0);
        obs->sensorLabel = label;
        return obs;
    };
    EXPECT_EQ(map.statistics().insert.accepted + map.statistics().insert.rejected(), 0u);
    // Two insertions without a pose PDF: two fallbacks to the default pose covariance.
    ASSERT_TRUE(map.insertObservation(*cloud("CLOUD"), CPose3D(10, 5, 0, 0, 0, 0)));
    ASSERT_TRUE(map.insertObservation(*cloud("CLOUD"), CPose3D(10, 5, 0, 0, 0, 0)));
    // With a pose PDF (no fallback): one skipped by its label, three refused for a NaN pose.
    mrpt::poses::CPose3DPDFGaussian pdf(CPose3D(10, 5, 0, 0, 0, 0));
    pdf.cov.setIdentity();
    pdf.cov *= 1e-6;
    EXPECT_FALSE(map.insertObservation(*cloud("OTHER"), pdf));
    pdf.mean.x(std::numeric_limits<double>::quiet_NaN());
    for (int k = 0; k < 3; k++) EXPECT_ANY_THROW(map.insertObservation(*cloud("CLOUD"), pdf));

    const multibin::MapStatistics s = map.statistics();
    EXPECT_EQ(s.poseFallbacks, 2u);
    EXPECT_EQ(s.skippedByLabel, 1u);
    EXPECT_EQ(s.nonFinitePoses, 3u);
    EXPECT_EQ(s.insert.accepted + s.insert.rejected(), 2u * (21 * 21 + 2));  // every point once
    EXPECT_EQ(s.insert.tooUncertain, 2u);
    EXPECT_EQ(s.insert.outOfRange, 2u);
    EXPECT_EQ(s.sensorModels.depth.points, 2u * (21 * 21 + 2));  // a cloud: the depth model
    EXPECT_GT(s.visibility.raysCast, 0u);
    // The deprecated accessors: the snapshot's parts.
    EXPECT_EQ(map.statistics().insert.accepted, s.insert.accepted);
    EXPECT_EQ(map.statistics().visibility.raysCast, s.visibility.raysCast);
    EXPECT_EQ(map.statistics().sensorModels.depth.kept, s.sensorModels.depth.kept);
    EXPECT_EQ(map.statistics().poseFallbacks, 2u);
    EXPECT_EQ(map.statistics().skippedByLabel, 1u);
    EXPECT_EQ(map.statistics().nonFinitePoses, 3u);

    map.clear();
    const multibin::MapStatistics z = map.statistics();
    EXPECT_EQ(z.insert.accepted + z.insert.rejected() + z.visibility.raysCast, 0u);
    EXPECT_EQ(z.poseFallbacks + z.skippedByLabel + z.nonFinitePoses, 0u);
    EXPECT_EQ(z.sensorModels.depth.points, 0u);
}

TEST(CMultiBinElevationMap, GrowsForOnePointJustOutsideAmongManyInside) {
    // The growth check screens points (vectorised) and tests only those near the window's edge
    // exactly: one point a millimetre beyond the edge, in any of 600 positions of a block of
    // points well inside, must still grow the window, and a point beyond max_range_m (the growth
    // reach) must not.
    CMultiBinElevationMap map;
    map.insertionOptions.max_elevation_uncertainty_m = 1.0;  // the far point passes eq 13
    auto cloud = [](const std::vector<Eigen::Vector3f>& points) {
        auto obs = mrpt::obs::CObservationPointCloud::Create();
        auto pts = mrpt::maps::CSimplePointsMap::Create();
        for (const auto& p : points) pts->insertPoint(p.x(), p.y(), p.z());
        obs->pointcloud = pts;
        obs->sensorPose = CPose3D(0, 0, 1.0, 0, 0, 0);
        return obs;
    };
    std::vector<Eigen::Vector3f> first;
    for (int i = 0; i < 40; i++)
        for (int j = 0; j < 40; j++)
            first.emplace_back(-0.5f + 0.025f * i, -0.5f + 0.025f * j, -1.f);
    ASSERT_TRUE(map.insertObservation(*cloud(first), CPose3D()));
    for (int k = 0; k < 12; k++) {
        const double xMax = map.getXMax();
        std::vector<Eigen::Vector3f> points(600, Eigen::Vector3f(0.f, 0.f, -1.f));
        for (size_t i = 0; i < points.size(); i++) points[i].y() = -0.4f + 0.001f * float(i);
        const size_t at = size_t(k) * 50 + 7;
        const double robotX_m = xMax - 1.0;  // the edge 1 m ahead, well within the reach
        points[at].x() = float(xMax + 0.001 - robotX_m);  // just beyond the east edge
        const size_t outsideBefore = map.statistics().insert.outsideMap;
        ASSERT_TRUE(map.insertObservation(*cloud(points), CPose3D(robotX_m, 0, 0, 0, 0, 0)));
        EXPECT_GT(map.getXMax(), xMax) << "insertion " << k;
        EXPECT_EQ(map.statistics().insert.outsideMap, outsideBefore) << "insertion " << k;
    }
    const double xMax = map.getXMax();
    std::vector<Eigen::Vector3f> far(300, Eigen::Vector3f(0.f, 0.f, -1.f));
    far[150].x() = 30.5f;  // beyond max_range_m (20 m) from the sensor
    ASSERT_TRUE(map.insertObservation(*cloud(far), CPose3D(xMax - 1.0, 0, 0, 0, 0, 0)));
    EXPECT_EQ(map.getXMax(), xMax);
    // Within the reach, 19 m ahead: it grows the window, with no size limit.
    far[150].x() = 19.0f;
    ASSERT_TRUE(map.insertObservation(*cloud(far), CPose3D(xMax - 1.0, 0, 0, 0, 0, 0)));
    EXPECT_GT(map.getXMax(), xMax + 17.0);
}
