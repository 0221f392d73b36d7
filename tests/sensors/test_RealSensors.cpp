/* Real sensors with the shipped ini presets (ini/): MRPT's recorded VLP-16 scan with the default
 * pose covariance, the reach the pose covariance and eq 13 allow, and the counts. */
#include <gtest/gtest.h>
#include <mrpt/config/CConfigFile.h>
#include <mrpt/maps/CMultiBinElevationMap.h>
#include <mrpt/maps/CSimplePointsMap.h>
#include <mrpt/obs/CObservationVelodyneScan.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <string>
#include <vector>

#include "mrpt_datasets.h"
#include "multibin/geometry/PosePropagation.h"
#include "multibin/map/MapStatistics.h"
#include "multibin/sensors/RayModel.h"
#include "multibin/sensors/SensorStats.h"

namespace {
using Map = mrpt::maps::CMultiBinElevationMap;

/** A map with the options of a shipped preset (ini/NAME), as elevation-mapper reads them. */
Map mapFromPreset(const std::string& name) {
    const mrpt::config::CConfigFile ini(std::string(MULTIBIN_SOURCE_DIR) + "/ini/" + name);
    const std::string prefix = "MappingApplication_multiBinElevationMap_00_";
    Map::TCreationOptions c;
    c.loadFromConfigFile(ini, prefix + "creationOpts");
    Map map(c);
    map.insertionOptions.loadFromConfigFile(ini, prefix + "insertOpts");
    map.insertionOptions.fill.enabled = false;  // the measured cells are scored
    return map;
}

double median(std::vector<double> v) {
    if (v.empty()) return NAN;
    std::nth_element(v.begin(), v.begin() + v.size() / 2, v.end());
    return v[v.size() / 2];
}

mrpt::obs::CObservationVelodyneScan::Ptr vlp16Scan() {
    const auto obs = multibin::test::datasetObservations("test_velodyne_VLP16.rawlog");
    EXPECT_EQ(obs.size(), 1u);
    return std::dynamic_pointer_cast<mrpt::obs::CObservationVelodyneScan>(obs.at(0));
}
}  // namespace

// MRPT's recorded VLP-16 scan, the shipped ini/lidar-vlp16.ini and no pose covariance given (the
// default's 5 mrad attitude sigma): at least 90 % of the 11 305 points MRPT's CSimplePointsMap
// takes are fused, and the ground ring is in the map: of the 0.1 m cells where MRPT's points show
// bare ground (a point within 5 cm of their floor plane, none 0.3 m above it), >= 90 % are
// measured, >= 80 % of those beyond 10 m (with the map's 0.1 m eq 13 limit the ground beyond
// about 7 m was refused), and the least-squares plane through the map's heights of those cells
// lies on MRPT's floor plane: within 3 cm below the sensor and 0.2 degrees of tilt.
TEST(RealSensors, Vlp16PresetWithDefaultPoseCovarianceKeepsTheGroundRing) {
    const auto scan = vlp16Scan();
    ASSERT_TRUE(scan);
    mrpt::maps::CSimplePointsMap mrptPoints;
    mrptPoints.insertObservation(*scan);
    ASSERT_EQ(mrptPoints.size(), 11305u);
    const auto P = multibin::test::pointsOf(mrptPoints);
    const multibin::test::FloorPlane floor = multibin::test::fitFloorPlane(P);
    ASSERT_GT(floor.inliers, 1000u);

    Map map = mapFromPreset("lidar-vlp16.ini");
    map.insertObservation(*scan, mrpt::poses::CPose3D());  // no PDF: the default covariance
    EXPECT_EQ(map.statistics().poseFallbacks, 1u);
    const multibin::InsertStats& s = map.statistics().insert;
    std::printf("  fused %zu of 11305 (too uncertain %zu, outside map %zu)\n", s.accepted,
                s.tooUncertain, s.outsideMap);
    EXPECT_GE(double(s.accepted), 0.9 * 11305);

    const double res = map.creationOptions.resolution_m;
    std::map<std::pair<int, int>, std::pair<int, bool>> cells;  // floor inliers, clutter
    for (const auto& p : P) {
        auto& cell = cells[{int(std::floor(p.x() / res)), int(std::floor(p.y() / res))}];
        const double above = p.z() - floor.z(p.x(), p.y());
        cell.first += std::abs(above) < 0.05;
        cell.second = cell.second || above > 0.3;
    }
    size_t floorCells = 0, measured = 0, farCells = 0, farMeasured = 0;
    Eigen::MatrixXd A(0, 3);
    std::vector<Eigen::Vector3d> rows;
    std::vector<double> nearSigmas, farSigmas;  // what the wider limit costs: the far sigma
    for (const auto& [ij, v] : cells) {
        if (v.first < 1 || v.second) continue;
        const double x = (ij.first + 0.5) * res, y = (ij.second + 0.5) * res;
        const bool far = std::hypot(x, y) > 10.0;
        floorCells++;
        farCells += far;
        double h = 0, sigma = 0;
        if (!map.cellHeight(x, y, h, sigma)) continue;
        measured++;
        farMeasured += far;
        (far ? farSigmas : nearSigmas).push_back(sigma);
        rows.emplace_back(x, y, h);
    }
    A.resize(Eigen::Index(rows.size()), 3);
    Eigen::VectorXd z(A.rows());
    for (size_t i = 0; i < rows.size(); i++) {
        A.row(Eigen::Index(i)) << rows[i].x(), rows[i].y(), 1.0;
        z(Eigen::Index(i)) = rows[i].z();
    }
    ASSERT_GT(rows.size(), 100u);
    const Eigen::Vector3d plane = A.colPivHouseholderQr().solve(z);  // z = a x + b y + c
    const Eigen::Vector3d mapNormal = Eigen::Vector3d(-plane(0), -plane(1), 1.0).normalized();
    const double tilt_deg = std::acos(std::min(1.0, mapNormal.dot(floor.normal))) * 180 / M_PI;
    const double offset_m = plane(2) - floor.z(0, 0);
    std::printf(
        "  floor cells %zu, measured %zu; beyond 10 m %zu, measured %zu; map plane %.4f m "
        "from MRPT's below the sensor, %.3f deg apart\n",
        floorCells, measured, farCells, farMeasured, offset_m, tilt_deg);
    std::printf("  median cell sigma: %.3f m within 10 m, %.3f m beyond\n", median(nearSigmas),
                median(farSigmas));
    EXPECT_GE(double(measured), 0.9 * double(floorCells));
    ASSERT_GT(farCells, 500u);
    EXPECT_GE(double(farMeasured), 0.8 * double(farCells));
    EXPECT_LT(std::abs(offset_m), 0.03);
    EXPECT_LT(tilt_deg, 0.2);
}

namespace {
/** 3 sigma of the map-frame height [m] of a ground point `d_m` ahead of a VLP-16 mounted
 * `height_m` above the ground, with the default pose sigmas but an attitude sigma of
 * `attitude_rad` on yaw, pitch and roll. */
double threeSigmaHeight(double d_m, double height_m, double attitude_rad) {
    mrpt::poses::CPose3DPDFGaussian robot;
    const Map::TInsertionOptions defaults;
    for (int i = 0; i < 3; i++) robot.cov(i, i) = std::pow(defaults.default_pose_sigmas[i], 2);
    for (int i = 3; i < 6; i++) robot.cov(i, i) = attitude_rad * attitude_rad;
    const multibin::PosePropagator propagator(robot, mrpt::poses::CPose3D(0, 0, height_m, 0, 0, 0));
    multibin::PointWithCov p;
    p.point_m = Eigen::Vector3f(float(d_m), 0.f, float(-height_m));
    p.cov_m2 = multibin::sensors::rayPointCovariance(p.point_m, defaults.sensors.lidar);
    return 3.0 * std::sqrt(double(propagator.apply(p).cov_m2.zz));
}
}  // namespace

// The reach eq 13 leaves a sensor (doc/sensor-reach.md): a ground point d metres away has a height
// sigma of about d x the attitude sigma (and the beam's angular sigma), so it counts only out to
// about Delta_max / (3 sigma_att), exactly sqrt((Delta_max / 3)^2 - sigma_z^2) /
// sqrt(sigma_att^2 + sigma_across^2). The
// figures from the library's own propagation (VLP-16 model, 2 m above the ground), checked against
// that rule within 5 %, written to sensor_reach.csv in the build folder for
// doc/figures/sensor_reach.py, and the table of the reach printed.
TEST(RealSensors, ReachIsTheEq13LimitOverThreeAttitudeSigmas) {
    const double height_m = 2.0;
    const std::vector<double> attitudes_rad{0.001, 0.002, 0.005, 0.01};
    const std::vector<double> limits_m{0.1, 0.3, 0.5, 1.0};
    std::FILE* csv =
        std::fopen((std::string(MULTIBIN_BINARY_DIR) + "/sensor_reach.csv").c_str(), "w");
    ASSERT_TRUE(csv);
    std::fprintf(csv, "distance_m");
    for (double a : attitudes_rad) std::fprintf(csv, ",three_sigma_m_at_%g_rad", a);
    std::fprintf(csv, "\n");
    for (double d = 0.5; d <= 100.0; d += 0.5) {
        std::fprintf(csv, "%g", d);
        for (double a : attitudes_rad) std::fprintf(csv, ",%.5f", threeSigmaHeight(d, height_m, a));
        std::fprintf(csv, "\n");
    }
    std::fclose(csv);
    std::printf(
        "  reach [m] on the ground (VLP-16 2 m up, default x y z sigmas):\n  attitude sigma");
    for (double lim : limits_m) std::printf(" | Delta_max %.1f m", lim);
    std::printf("\n");
    for (double a : attitudes_rad) {
        std::printf("  %.0f mrad        ", 1000 * a);
        for (double lim : limits_m) {
            double reach = 0;
            for (double d = 0.1; d <= 300 && threeSigmaHeight(d, height_m, a) <= lim; d += 0.1)
                reach = d;
            std::printf(" | %15.1f", reach);
            // sigma_z^2 = sigma_z,pose^2 + d^2 (sigma_att^2 + sigma_across^2): the pose's height
            // sigma, then the attitude's and the beam's angular sigma at distance d.
            const Map::TInsertionOptions defaults;
            const double zPose_m = defaults.default_pose_sigmas[2];
            const double across = defaults.sensors.lidar.lateralSigma_m(1.0);
            const double rule =
                std::sqrt(lim * lim / 9 - zPose_m * zPose_m) / std::hypot(a, across);
            // Nearer, the range sigma along steep beams adds to it: the rule is the far field.
            if (rule > 10 && rule < 250) EXPECT_NEAR(reach, rule, 0.05 * rule) << a << " " << lim;
        }
        std::printf("\n");
    }
}
