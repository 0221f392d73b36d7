/* MRPT's own recorded datasets (Debian package mrpt-common, MRPT_DATASETS_DIR) through the map:
 * the VLP-16 scan, the rotating scans and the RGB-D frame. */
#include <gtest/gtest.h>
#include <mrpt/config/CConfigFileMemory.h>
#include <mrpt/maps/CMultiBinElevationMap.h>
#include <mrpt/maps/CSimpleMap.h>
#include <mrpt/maps/CSimplePointsMap.h>
#include <mrpt/obs/CObservation3DRangeScan.h>
#include <mrpt/obs/CObservationPointCloud.h>
#include <mrpt/obs/CObservationRotatingScan.h>
#include <mrpt/obs/CObservationVelodyneScan.h>
#include <mrpt/obs/CRawlog.h>
#include <mrpt/obs/CSensoryFrame.h>

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <map>
#include <random>
#include <string>

#include "mrpt_datasets.h"
#include "multibin/io/EsriAsciiGrid.h"
#include "multibin/map/MapStatistics.h"
#include "multibin/sensors/SensorDispatch.h"

using namespace multibin::sensors;

namespace {
using multibin::test::datasetObservations;
using multibin::test::depthFramePoints;
using multibin::test::FramePoint;
using multibin::test::originPose;

/** Every cell of the map with a measured height has a finite height and sigma; returns how many
 * cells are measured. */
size_t expectFiniteCells(const mrpt::maps::CMultiBinElevationMap& map) {
    const auto layout = map.toRaster(mrpt::maps::CMultiBinElevationMap::RasterLayer::Source);
    size_t measured = 0;
    for (int row = 0; row < layout.rows(); row++)
        for (int col = 0; col < layout.cols(); col++) {
            const double x = layout.xllcenter_m + col * layout.cellsize_m;
            const double y = layout.yllcenter_m + row * layout.cellsize_m;
            double h = 0, s = 0;
            if (!map.getHeight(x, y, h, s)) continue;
            measured++;
            EXPECT_TRUE(std::isfinite(h) && std::isfinite(s) && s > 0)
                << "cell at (" << x << ", " << y << "): height " << h << ", sigma " << s;
        }
    return measured;
}
}  // namespace

// The VLP-16 scan: MRPT's CSimplePointsMap takes 11 305 points from it and so must the map (it
// was refused before: 0 points). Its floor, the largest near-horizontal plane of MRPT's own
// points, must come out of the map at the height MRPT gives it: both use MRPT's calibrated point
// generation and the same sensor pose, so any offset would be a frame or decoding error of ours.
// Every raw return must be a fused point or a counted rejection (none lost silently), and no cell
// may hold a NaN.
TEST(MrptDatasets, Vlp16ScanFloorIsMrptsPlaneAndEveryReturnIsAccountedFor) {
    const auto obs = datasetObservations("test_velodyne_VLP16.rawlog");
    ASSERT_EQ(obs.size(), 1u);
    const auto velodyne = std::dynamic_pointer_cast<mrpt::obs::CObservationVelodyneScan>(obs[0]);
    ASSERT_TRUE(velodyne);

    // MRPT's points and the floor plane n.p = d (RANSAC, inliers within 5 cm, |n_z| > 0.8).
    mrpt::maps::CSimplePointsMap mrptPoints;
    mrptPoints.insertObservation(*velodyne);
    ASSERT_EQ(mrptPoints.size(), 11305u);
    const std::vector<Eigen::Vector3d> P = multibin::test::pointsOf(mrptPoints);
    const multibin::test::FloorPlane floor = multibin::test::fitFloorPlane(P);
    ASSERT_GT(floor.inliers, 1000u);
    const Eigen::Vector3d n = floor.normal;
    const size_t bestInliers = floor.inliers;
    auto floorZ = [&](double x, double y) { return floor.z(x, y); };

    mrpt::maps::CMultiBinElevationMap::TCreationOptions c;
    c.resolution_m = 0.25;
    mrpt::maps::CMultiBinElevationMap map(c);
    map.insertionOptions.max_range_m = 130.0;
    map.insertionOptions.fill.enabled = false;
    ASSERT_TRUE(map.insertObservation(*velodyne, originPose()));

    // Accounting: 75 packets x 12 blocks x 32 channels, each counted once by the model, and each
    // kept point fused or rejected by the map for a named reason.
    const LidarStats& ls = map.statistics().sensorModels.lidar;
    EXPECT_EQ(ls.returns, 75u * 12u * 32u);
    EXPECT_EQ(ls.returns, ls.noReturn + ls.notDecoded + ls.notFinite + ls.outOfRange + ls.kept);
    EXPECT_EQ(ls.kept, 11305u);  // what MRPT's CSimplePointsMap takes
    const multibin::InsertStats& is = map.statistics().insert;
    EXPECT_EQ(is.outOfRange, ls.noReturn + ls.notDecoded + ls.outOfRange);
    EXPECT_EQ(is.notFinite, ls.notFinite);
    EXPECT_EQ(is.accepted + is.rejected() - is.outOfRange - is.notFinite, ls.kept);
    EXPECT_GT(is.accepted, 10000u);

    // The floor: each cell holding at least 3 of MRPT's floor inliers, and no point of MRPT's
    // more than 0.3 m above the plane (a cell with a wall or an object in it reports that), has
    // its height on the plane within 3 sigma of the cell plus the plane's own spread (the 5 cm
    // inlier band) and its relief across the cell (slope x half a diagonal).
    std::map<std::pair<int, int>, std::pair<int, bool>> cells;  // inliers, clutter
    const double res = c.resolution_m;
    for (const auto& p : P) {
        auto& cell = cells[{int(std::floor(p.x() / res)), int(std::floor(p.y() / res))}];
        const double above = p.z() - floorZ(p.x(), p.y());
        if (std::abs(above) < 0.05) cell.first++;
        if (above > 0.3) cell.second = true;
    }
    const double relief = std::hypot(n.x(), n.y()) / n.z() * res * M_SQRT1_2;
    size_t floorCells = 0, onPlane = 0, within3Sigma = 0;  // the latter without the 5 cm band
    double sumOffset = 0;
    for (const auto& [ij, v] : cells) {
        if (v.first < 3 || v.second) continue;
        const double x = (ij.first + 0.5) * res, y = (ij.second + 0.5) * res;
        double h = 0, s = 0;
        if (!map.getHeight(x, y, h, s)) continue;
        floorCells++;
        const double offset = h - floorZ(x, y);
        sumOffset += offset;
        onPlane += std::abs(offset) <= 3 * s + 0.05 + relief;
        within3Sigma += std::abs(offset) <= 3 * s + relief;
    }
    std::printf(
        "  floor plane n = (%.4f %.4f %.4f), %zu MRPT inliers; %zu floor cells, %zu on the "
        "plane, %zu within 3 sigma + relief alone, mean offset %.4f m\n",
        n.x(), n.y(), n.z(), bestInliers, floorCells, onPlane, within3Sigma,
        sumOffset / floorCells);
    ASSERT_GT(floorCells, 30u);
    EXPECT_GE(double(onPlane), 0.95 * double(floorCells));
    EXPECT_LT(std::abs(sumOffset / double(floorCells)), 0.02);
    EXPECT_GT(expectFiniteCells(map), 500u);
}

// MRPT 2.5's CObservationRotatingScan stores no beam elevations (no calibration, no point
// directions), so the VLP-16 rotating scan cannot be turned into points by anyone: MRPT's own
// CSimplePointsMap takes 0 points from it. The map must say so, naming the observation, instead
// of mapping nothing in silence. The single-row rotating scan (a 2D scanner) has its geometry and
// must map every echo.
TEST(MrptDatasets, RotatingScansMapWhenTheyHaveGeometryAndAreRefusedByNameOtherwise) {
    const auto velo = datasetObservations("rot_scan_velodyne.rawlog");
    ASSERT_EQ(velo.size(), 1u);
    mrpt::maps::CMultiBinElevationMap map;
    map.insertionOptions.fill.enabled = false;
    try {
        map.insertObservation(*velo[0], originPose());
        FAIL() << "a 16-row rotating scan was accepted without beam geometry";
    } catch (const std::invalid_argument& e) {
        EXPECT_NE(std::string(e.what()).find("CObservationRotatingScan"), std::string::npos);
    }

    const auto planar = datasetObservations("rot_scan_2d.rawlog");
    ASSERT_EQ(planar.size(), 1u);
    const auto rot = std::dynamic_pointer_cast<mrpt::obs::CObservationRotatingScan>(planar[0]);
    ASSERT_TRUE(rot);
    size_t echoes = 0;
    for (int i = 0; i < rot->columnCount; i++) echoes += rot->rangeImage(0, i) != 0;
    map.insertionOptions.max_range_m = 80.0;
    map.insertObservation(*rot, originPose());
    const LidarStats& ls = map.statistics().sensorModels.lidar;
    EXPECT_EQ(ls.returns, size_t(rot->columnCount));
    EXPECT_EQ(ls.noReturn + ls.notFinite, size_t(rot->columnCount) - echoes);
    EXPECT_EQ(ls.kept + ls.outOfRange, echoes);
    EXPECT_GT(ls.kept, 0u);
    expectFiniteCells(map);
}

// The RGB-D frame of MRPT's tests as a point cloud: by default (no label entry) it gets the depth
// camera model, as every CObservationPointCloud did before; with `sensor_models = LABEL:lidar` the
// same points get the lidar's sigma along the ray instead, and both maps hold only finite cells.
TEST(MrptDatasets, RgbdFramePointCloudGetsTheModelOfItsLabel) {
    const auto obs = datasetObservations("tests_rgbd.rawlog");
    mrpt::obs::CObservation3DRangeScan::Ptr depth;
    for (const auto& o : obs)
        if (auto d = std::dynamic_pointer_cast<mrpt::obs::CObservation3DRangeScan>(o)) depth = d;
    ASSERT_TRUE(depth);
    mrpt::obs::CObservationPointCloud cloud;
    cloud.sensorLabel = depth->sensorLabel;
    cloud.sensorPose = depth->sensorPose;
    auto pts = mrpt::maps::CSimplePointsMap::Create();
    mrpt::obs::T3DPointsProjectionParams pp;
    pp.takeIntoAccountSensorPoseOnRobot = false;
    depth->unprojectInto(*pts, pp);
    cloud.pointcloud = pts;
    ASSERT_GT(pts->size(), 1000u);

    for (const std::string model : {"", "lidar"}) {
        mrpt::config::CConfigFileMemory ini(
            "[s]\nsensor_models = " +
            (model.empty() ? std::string() : cloud.sensorLabel + ":" + model) + "\n");
        mrpt::maps::CMultiBinElevationMap map;
        map.insertionOptions.loadFromConfigFile(ini, "s");
        map.insertionOptions.max_range_m = 6.0;
        map.insertionOptions.fill.enabled = false;
        const SensorModelOptions& opts = map.insertionOptions.sensors;
        SensorModelState state;
        SensorPoints sp;
        ASSERT_TRUE(observationToSensorPoints(cloud, originPose(), opts, 0.02, 6.0, state, sp));
        ASSERT_GT(sp.points.size(), 1000u);
        for (size_t i = 0; i < sp.points.size(); i += 97) {
            const auto& p = sp.points[i];
            const double r = p.point_m.cast<double>().norm();
            const Eigen::Vector3d d = p.point_m.cast<double>() / r;
            const double along = std::sqrt(d.dot(p.cov_m2.toMatrix() * d));
            const double expected =
                model.empty() ? opts.depth.axialSigma_m(r) : opts.lidar.rangeSigma(r);
            ASSERT_NEAR(along, expected, 1e-5) << "model '" << model << "', point " << i;
        }
        EXPECT_TRUE(map.insertObservation(cloud, originPose()));
        EXPECT_GT(expectFiniteCells(map), 100u);
    }
}

// MRPT's icp-slam map of the Malaga CS faculty building: its keyframes carry an all-zero 6x6
// covariance (icp-slam's poses are exact by construction). An exact pose is not an error: the
// points must be fused as with a near-exact (1 mm) pose, none rejected as "covariance", and every
// reading fused or counted by reason. Before exact poses were accepted, every point of this map
// was rejected as "covariance" and the map stayed empty.
TEST(MrptDatasets, IcpSlamSimplemapWithExactPosesIsMapped) {
    const std::string path =
        std::string(MRPT_DATASETS_DIR) + "/malaga-cs-fac-building.simplemap.gz";
    mrpt::maps::CSimpleMap simplemap;
    ASSERT_TRUE(simplemap.loadFromFile(path)) << path << " (Debian package mrpt-common)";
    ASSERT_GT(simplemap.size(), 10u);
    size_t exactKeyframes = 0;
    for (const auto& kf : simplemap) {
        const auto [cov, mean] = kf.pose->getCovarianceAndMean();
        exactKeyframes += cov.asEigen().cwiseAbs().maxCoeff() == 0.0;
    }
    EXPECT_EQ(exactKeyframes, simplemap.size()) << "the dataset's keyframes are exact poses";

    // The same keyframes with a 1 mm / 1 mrad covariance: the reference count.
    mrpt::maps::CSimpleMap nearExact = simplemap;
    for (auto& kf : nearExact) {
        auto pdf = mrpt::poses::CPose3DPDFGaussian::Create();
        pdf->mean = kf.pose->getMeanVal();
        for (int i = 0; i < 6; i++) pdf->cov(i, i) = 1e-6;
        kf.pose = pdf;
    }
    mrpt::maps::CMultiBinElevationMap::TCreationOptions creation;
    creation.resolution_m = 0.1;  // a building floor: 10 cm cells
    mrpt::maps::CMultiBinElevationMap exact(creation), reference(creation);
    exact.insertSimpleMapWithPosePdfs(simplemap);
    reference.insertSimpleMapWithPosePdfs(nearExact);

    const multibin::InsertStats& s = exact.statistics().insert;
    EXPECT_EQ(s.badCovariance, 0u);
    EXPECT_EQ(s.notFinite, 0u);
    EXPECT_GT(s.accepted, 1000u);
    EXPECT_GE(double(s.accepted), 0.99 * double(reference.statistics().insert.accepted))
        << "exact " << s.accepted << ", 1 mm " << reference.statistics().insert.accepted;
    EXPECT_GT(expectFiniteCells(exact), 100u);
}

namespace {
/** Sigma check of the real depth frame read as a floor (doc/sensor-models.md, "Frame-shared
 * error"): the frame of tests_rgbd.rawlog (a wall behind a bookshelf, 1.6-2.6 m) inserted as if
 * the camera looked straight down from 1.5 m, with an exact pose; the wall is the floor. The
 * floor plane is the least-squares plane of the points of the clean wall (image rows 20-130,
 * columns 30-589); a floor cell holds at least 5 of the frame's points, 95 % of them within 4 cm
 * of the plane. Cells with y >= 0 (the image's left half, `calibrationHalf`) calibrated
 * depth_frame_sigma_relative; the figures are of the other half. */
struct FloorSigmaCheck {
    size_t cells = 0, within3Sigma = 0;
    double rms_m = 0, medianSigma_m = 0;
};
FloorSigmaCheck depthFloorSigma(const mrpt::obs::CObservation3DRangeScan& frame,
                                const multibin::sensors::DepthModelOptions& depth,
                                bool calibrationHalf = false) {
    mrpt::maps::CMultiBinElevationMap map;  // default options: 2 cm cells
    map.insertionOptions.fill.enabled = false;
    map.insertionOptions.sensors.depth = depth;
    mrpt::poses::CPose3DPDFGaussian pose;  // exact
    pose.mean = mrpt::poses::CPose3D(0, 0, 1.5, 0, M_PI / 2, 0);
    EXPECT_TRUE(map.insertObservation(frame, pose));

    std::vector<Eigen::Vector3d> P;
    Eigen::MatrixXd A(0, 3);
    std::vector<Eigen::Vector3d> wall;
    for (const FramePoint& f : depthFramePoints(frame, pose.mean)) {
        P.push_back(f.p_m);
        if (f.row >= 20 && f.row <= 130 && f.col >= 30 && f.col < 590) wall.push_back(f.p_m);
    }
    A.resize(Eigen::Index(wall.size()), 3);
    Eigen::VectorXd h(A.rows());
    for (size_t i = 0; i < wall.size(); i++) {
        A.row(Eigen::Index(i)) << wall[i].x(), wall[i].y(), 1.0;
        h(Eigen::Index(i)) = wall[i].z();
    }
    const Eigen::Vector3d plane = A.colPivHouseholderQr().solve(h);
    auto floorZ = [&](double x, double y) { return plane(0) * x + plane(1) * y + plane(2); };

    const double res = map.creationOptions.resolution_m;
    std::map<std::pair<int, int>, std::pair<int, int>> perCell;  // points, within 4 cm
    for (const auto& p : P) {
        auto& c = perCell[{int(std::floor(p.x() / res)), int(std::floor(p.y() / res))}];
        c.first++;
        c.second += std::abs(p.z() - floorZ(p.x(), p.y())) < 0.04;
    }
    FloorSigmaCheck out;
    std::vector<double> sigmas;
    double sum2 = 0;
    for (const auto& [ij, n] : perCell) {
        const double x = (ij.first + 0.5) * res, y = (ij.second + 0.5) * res;
        double hm = 0, s = 0;
        if ((y >= 0) != calibrationHalf || n.first < 5 || n.second < 0.95 * n.first ||
            !map.cellHeight(x, y, hm, s))
            continue;
        const double e = hm - floorZ(x, y);
        out.cells++;
        out.within3Sigma += std::abs(e) <= 3 * s;
        sum2 += e * e;
        sigmas.push_back(s);
    }
    if (out.cells == 0) return out;
    out.rms_m = std::sqrt(sum2 / double(out.cells));
    std::nth_element(sigmas.begin(), sigmas.begin() + sigmas.size() / 2, sigmas.end());
    out.medianSigma_m = sigmas[sigmas.size() / 2];
    return out;
}
}  // namespace

// A real depth frame's errors are shared by neighbouring points (depth quantisation, the
// camera's depth distortion): the cell heights of one frame lie 17 mm RMS from the floor plane.
// With the frame-shared term (the defaults) >= 95 % of the scored floor cells hold the plane
// within 3 sigma; with the term off (points independent) the Kalman sigma shrinks with the number
// of points and only about a third do.
TEST(MrptDatasets, RgbdFrameAsFloorHoldsThePlaneWithinThreeSigma) {
    const auto obs = datasetObservations("tests_rgbd.rawlog");
    ASSERT_EQ(obs.size(), 1u);
    const auto frame = std::dynamic_pointer_cast<mrpt::obs::CObservation3DRangeScan>(obs[0]);
    ASSERT_TRUE(frame && frame->hasPoints3D);
    ASSERT_EQ(frame->points3D_idxs_x.size(), frame->points3D_x.size());

    const DepthModelOptions withTerm;
    DepthModelOptions independent;
    independent.quantisationStep_per_m = 0;
    independent.frameSigmaRelative = 0;
    // The calibration of depth_frame_sigma_relative (printed only): the smallest c in steps of
    // 0.0005 that puts 99.7 % of the calibration half's cells within 3 sigma.
    for (const double c : {0.004, 0.0045, 0.005, 0.0055}) {
        DepthModelOptions o;
        o.frameSigmaRelative = c;
        const FloorSigmaCheck f = depthFloorSigma(*frame, o, true);
        std::printf(
            "  calibration half, c = %.4f: %zu cells, median sigma %.1f mm, %.1f %% within "
            "3 sigma\n",
            c, f.cells, 1000 * f.medianSigma_m, 100.0 * double(f.within3Sigma) / double(f.cells));
    }
    for (const bool shared : {true, false}) {
        const FloorSigmaCheck f = depthFloorSigma(*frame, shared ? withTerm : independent);
        std::printf(
            "  %s: %zu floor cells, RMS %.1f mm, median sigma %.1f mm, %.1f %% within 3 "
            "sigma\n",
            shared ? "frame-shared term" : "points independent", f.cells, 1000 * f.rms_m,
            1000 * f.medianSigma_m, 100.0 * double(f.within3Sigma) / double(f.cells));
        ASSERT_GT(f.cells, 1500u);
        const double share = double(f.within3Sigma) / double(f.cells);
        if (shared)
            EXPECT_GE(share, 0.95);
        else
            EXPECT_LT(share, 0.6);
    }
}
