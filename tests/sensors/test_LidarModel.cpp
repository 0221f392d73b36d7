/* Lidar model (3D and 2D lidars): published defaults, Monte Carlo consistency of the propagated
 * covariance, counting of every beam, the model chosen per sensor label. */
#include <gtest/gtest.h>
#include <mrpt/config/CConfigFileMemory.h>
#include <mrpt/maps/CMultiBinElevationMap.h>
#include <mrpt/maps/CSimplePointsMap.h>
#include <mrpt/obs/CObservation2DRangeScan.h>
#include <mrpt/obs/CObservationPointCloud.h>
#include <mrpt/obs/CObservationRotatingScan.h>

#include <cmath>
#include <cstring>
#include <limits>
#include <random>

#include "mc_check.h"
#include "multibin/geometry/PosePropagation.h"
#include "multibin/io/StrictConfigSection.h"
#include "multibin/sensors/DepthModel.h"
#include "multibin/sensors/LidarModel.h"
#include "multibin/sensors/RayModel.h"
#include "multibin/sensors/SensorDispatch.h"

using namespace multibin;
using namespace multibin::sensors;

namespace {
/** Variance along the unit direction of `p` of the covariance `c` [m^2]. */
double alongRay(const PointWithCov& p) {
    const Eigen::Vector3d d = p.point_m.cast<double>().normalized();
    return d.dot(p.cov_m2.toMatrix() * d);
}
/** Variance across the ray of `p` (along a unit vector orthogonal to it) [m^2]. */
double acrossRay(const PointWithCov& p) {
    const Eigen::Vector3d d = p.point_m.cast<double>().normalized();
    const Eigen::Vector3d e = d.cross(Eigen::Vector3d::UnitZ()).normalized();
    return e.dot(p.cov_m2.toMatrix() * e);
}

/** Monte Carlo of one lidar return at `p` (sensor frame): range noise, angular noise and a
 * uniformly random spot in the divergence footprint, and robot pose noise, through the real
 * transform; compared with rayPointCovariance() + PosePropagator. */
void expectLidarModelConsistent(const LidarModelOptions& o, const Eigen::Vector3d& p) {
    std::normal_distribution<double> n01;
    std::uniform_real_distribution<double> u01;
    mc::expectRayModelConsistent(
        o, mrpt::poses::CPose3D(0.1, 0.0, 0.9, 0.05, 0.1, 0.0), p, 11,
        [&](const Eigen::Vector3d&, double r, const Eigen::Vector3d& d, const Eigen::Vector3d& e1,
            const Eigen::Vector3d& e2, std::mt19937& rng) {
            // Spot uniform in a disc of angular radius delta / 2.
            const double rho = 0.5 * o.beamDivergence_rad * std::sqrt(u01(rng));
            const double phi = 2 * M_PI * u01(rng);
            const double a1 = o.angularSigma_rad * n01(rng) + rho * std::cos(phi);
            const double a2 = o.angularSigma_rad * n01(rng) + rho * std::sin(phi);
            const Eigen::Vector3d dir = (d + a1 * e1 + a2 * e2).normalized();
            return Eigen::Vector3d((r + o.rangeSigma(r) * n01(rng)) * dir);
        });
}

mrpt::obs::CObservationPointCloud cloudOf(const std::vector<Eigen::Vector3f>& pts,
                                          const std::string& label) {
    mrpt::obs::CObservationPointCloud cloud;
    cloud.sensorLabel = label;
    auto map = mrpt::maps::CSimplePointsMap::Create();
    for (const auto& p : pts) map->insertPoint(p.x(), p.y(), p.z());
    cloud.pointcloud = map;
    return cloud;
}

/** A 2D scan of `n` beams over 180 deg (maximum range 30 m) labelled UTM, with these ranges. */
mrpt::obs::CObservation2DRangeScan utmScan(const std::vector<float>& ranges_m) {
    mrpt::obs::CObservation2DRangeScan scan;
    scan.sensorLabel = "UTM";
    scan.aperture = M_PI;
    scan.maxRange = 30.f;
    scan.resizeScan(ranges_m.size());
    for (size_t i = 0; i < ranges_m.size(); i++) {
        scan.setScanRange(i, ranges_m[i]);
        scan.setScanRangeValidity(i, true);
    }
    return scan;
}

SensorModelOptions loadOptions(const std::string& body) {
    mrpt::config::CConfigFileMemory ini("[s]\n" + body);
    StrictConfigSection s(ini, "s");
    SensorModelOptions o;
    o.read(s);
    s.finish();
    return o;
}
}  // namespace

TEST(LidarModel, PresetsAreThePublishedFiguresAndTheLateralSigmaAddsTheFootprint) {
    // doc/sensor-models.md gives the datasheet figures; these are them, converted as stated there.
    const auto vlp = LidarModelOptions::forSensor("vlp16");
    EXPECT_DOUBLE_EQ(vlp.rangeSigma(10.0), 0.03);
    EXPECT_DOUBLE_EQ(vlp.beamDivergence_rad, 0.003);
    const auto os1 = LidarModelOptions::forSensor("os1");
    EXPECT_DOUBLE_EQ(os1.rangeSigma(50.0), 0.03);
    const auto utm = LidarModelOptions::forSensor("utm30lx");
    EXPECT_NEAR(utm.rangeSigma(10.0), 0.0367, 1e-12);  // >= 30 mm up to 10 m
    EXPECT_NEAR(utm.rangeSigma(30.0), 0.0501, 1e-12);  // >= 50 mm at 30 m
    EXPECT_THROW(LidarModelOptions::forSensor("hdl64"), std::invalid_argument);
    // Across the beam at 10 m: 10 * sqrt(0.001^2 + 0.003^2 / 16) = 12.5 mm.
    EXPECT_NEAR(vlp.lateralSigma_m(10.0), 0.0125, 1e-12);
    const PointWithCov p{Eigen::Vector3f(6, 8, 0), rayPointCovariance({6, 8, 0}, vlp)};
    EXPECT_NEAR(alongRay(p), 0.03 * 0.03, 1e-9);
    EXPECT_NEAR(acrossRay(p), 0.0125 * 0.0125, 1e-9);
}

TEST(LidarModel, MonteCarloCovarianceMatchesPropagationForVlp16AndOs1) {
    // Angular noise dominated (VLP-16) and divergence dominated (OS1) footprints, a return 6 m
    // away and below the sensor (a floor point), and the shared pose-noise fixture.
    expectLidarModelConsistent(LidarModelOptions::forSensor("vlp16"), {5.0, 3.0, -1.2});
    expectLidarModelConsistent(LidarModelOptions::forSensor("os1"), {5.0, 3.0, -1.2});
}

TEST(LidarModel, TwoDimensionalScanCountsEveryBeam) {
    // A 2D scanner with the lidar model: each beam is a point or one counted reason.
    auto scan = utmScan({2.f, 0.f, NAN, 31.f, 25.f, 3.f});
    scan.setScanRangeValidity(5, false);
    const LidarModelOptions o = LidarModelOptions::forSensor("utm30lx");
    PointsWithCov out;
    LidarStats st;
    lidarScanToPoints(scan, o, 0.1, 20.0, out, st);
    EXPECT_EQ(st.returns, 6u);
    EXPECT_EQ(st.kept, 1u);        // 2 m
    EXPECT_EQ(st.noReturn, 3u);    // 0 m, >= maxRange, invalid flag
    EXPECT_EQ(st.notFinite, 1u);   // NaN
    EXPECT_EQ(st.outOfRange, 1u);  // 25 m > the map's 20 m
    ASSERT_EQ(out.size(), 1u);
    EXPECT_NEAR(out[0].point_m.norm(), 2.0, 1e-6);
    EXPECT_NEAR(alongRay(out[0]), std::pow(o.rangeSigma(2.0), 2), 1e-10);
}

TEST(LidarModel, SingleRowRotatingScanFollowsMrptsColumnAzimuthsAndMultiRowIsRefused) {
    // MRPT's own conversion of a 2D scan: column i at startAzimuth + i azimuthSpan / columnCount
    // (CObservationRotatingScan::fromScan2D), range to its 1 cm resolution. Each point must be
    // there, and within one beam step of the 2D scan's own beam (whose step is
    // aperture / (N - 1)).
    std::vector<float> ranges(181);
    for (int i = 0; i < 181; i++) ranges[i] = 1.0f + 0.01f * float(i);
    const auto scan = utmScan(ranges);
    mrpt::obs::CObservationRotatingScan rot;
    rot.fromScan2D(scan);
    const LidarModelOptions o;
    PointsWithCov a, b;
    LidarStats sa, sb;
    lidarScanToPoints(scan, o, 0.1, 20.0, a, sa);
    rotatingScanToPoints(rot, o, 0.1, 20.0, b, sb);
    ASSERT_EQ(a.size(), 181u);
    ASSERT_EQ(b.size(), a.size());
    for (size_t i = 0; i < b.size(); i++) {
        const double az = rot.startAzimuth + double(i) * rot.azimuthSpan / rot.columnCount;
        const double r = rot.rangeImage(0, i) * rot.rangeResolution;
        EXPECT_NEAR(b[i].point_m.x(), r * std::cos(az), 1e-5) << "column " << i;
        EXPECT_NEAR(b[i].point_m.y(), r * std::sin(az), 1e-5) << "column " << i;
        EXPECT_NEAR(b[i].point_m.norm(), a[i].point_m.norm(), 0.0051) << "column " << i;
        const double step = M_PI / 180.0;
        EXPECT_LT(std::acos(std::min(
                      1.0, double(a[i].point_m.normalized().dot(b[i].point_m.normalized())))),
                  step)
            << "column " << i;
    }
    rot.rowCount = 16;
    EXPECT_THROW(rotatingScanToPoints(rot, o, 0.1, 20.0, b, sb), std::invalid_argument);
}

TEST(SensorModels, PointCloudGetsTheModelOfItsLabel) {
    // The same cloud from a depth camera, a lidar and a stereo rig: each label gets its model's
    // sigma along the ray; an unlabelled cloud gets the documented default, the depth model.
    const SensorModelOptions opts =
        loadOptions("sensor_models = VELO:lidar, RIG:stereo, KINECT:depth\n");
    const Eigen::Vector3f p(3.0f, 0.0f, -0.5f);
    const double r = p.cast<double>().norm();
    const double sDepth = opts.depth.axialSigma_m(r), sLidar = opts.lidar.rangeSigma(r);
    const double sStereo = std::sqrt(2.0) * opts.stereo.matchingSigma_px * r * r /
                           (opts.stereo.cloudFocalLength_px * opts.stereo.cloudBaseline_m);
    const std::pair<std::string, double> cases[] = {
        {"KINECT", sDepth}, {"", sDepth}, {"OTHER", sDepth}, {"VELO", sLidar}, {"RIG", sStereo}};
    for (const auto& [label, sigma] : cases) {
        SensorModelState state;
        SensorPoints sp;
        ASSERT_TRUE(observationToSensorPoints(cloudOf({p}, label), {}, opts, 0.02, 20, state, sp));
        ASSERT_EQ(sp.points.size(), 1u) << label;
        EXPECT_NEAR(std::sqrt(alongRay(sp.points[0])), sigma, 1e-6) << "label '" << label << "'";
    }
    EXPECT_EQ(SensorModelOptions().modelFor("", SensorModelKind::depth), SensorModelKind::depth);
}

TEST(LidarModel, CloudPointsInBlocksEqualThePerPointModelBitForBit) {
    // cloudToPoints runs the model over blocks of points (vectorised): every kept point must carry
    // exactly rayPointCovariance's covariance, and every point be counted once by its fate, across
    // block boundaries (1000 points: 3 full blocks of 256 and a partial one).
    std::mt19937 rng(5);
    std::uniform_real_distribution<float> coord(-40.f, 40.f);
    std::vector<Eigen::Vector3f> pts;
    size_t notFinite = 0, outOfRange = 0;
    const float nan = std::numeric_limits<float>::quiet_NaN(), inf = INFINITY;
    for (int i = 0; i < 1000; i++) {
        Eigen::Vector3f p(coord(rng), coord(rng), coord(rng));
        if (i % 97 == 3)
            p.y() = nan, notFinite++;
        else if (i % 89 == 5)
            p.z() = -inf, notFinite++;
        else if (i % 83 == 7)
            p.setZero(), outOfRange++;  // a missing return
        else if (p.norm() > 50.f)
            outOfRange++;
        pts.push_back(p);
    }
    const LidarModelOptions model = LidarModelOptions::forSensor("os1");
    PointsWithCov out;
    LidarStats stats;
    cloudToPoints(cloudOf(pts, "VELO"), model, 0.02, 50.0, out, stats);
    EXPECT_EQ(stats.returns, pts.size());
    EXPECT_EQ(stats.notFinite, notFinite);
    EXPECT_EQ(stats.outOfRange, outOfRange);
    ASSERT_EQ(stats.kept, pts.size() - notFinite - outOfRange);
    ASSERT_EQ(out.size(), stats.kept);
    size_t k = 0;
    for (const auto& p : pts) {
        if (!p.allFinite() || !(p.norm() > 0) || p.norm() > 50.f) continue;
        ASSERT_EQ(out[k].point_m, p);
        const SymmetricCov3 expected = rayPointCovariance(p, model);
        EXPECT_EQ(std::memcmp(&out[k].cov_m2, &expected, sizeof expected), 0) << "point " << k;
        k++;
    }
}

TEST(SensorModels, UnknownOrMismatchedModelIsAnErrorNamingTheKey) {
    try {
        loadOptions("sensor_models = VELO:velodyne\n");
        FAIL() << "unknown model accepted";
    } catch (const std::invalid_argument& e) {
        EXPECT_NE(std::string(e.what()).find("sensor_models"), std::string::npos) << e.what();
        EXPECT_NE(std::string(e.what()).find("velodyne"), std::string::npos) << e.what();
    }
    EXPECT_THROW(loadOptions("lidar_sensor = hdl64\n"), std::invalid_argument);
    // A 2D scan cannot take the stereo model: refused when the scan arrives, naming the key.
    const SensorModelOptions opts = loadOptions("sensor_models = LASER:stereo\n");
    mrpt::obs::CObservation2DRangeScan scan;
    scan.sensorLabel = "LASER";
    SensorModelState state;
    SensorPoints sp;
    try {
        observationToSensorPoints(scan, {}, opts, 0.02, 20, state, sp);
        FAIL() << "stereo model accepted for a 2D scan";
    } catch (const std::invalid_argument& e) {
        EXPECT_NE(std::string(e.what()).find("sensor_models"), std::string::npos) << e.what();
    }
}

TEST(SensorModels, LidarAndModelKeysRoundTrip) {
    SensorModelOptions o = loadOptions(
        "lidar_sensor = os1\nlidar_angular_sigma = 0.0004\nsensor_models = A:lidar,B:stereo\n"
        "stereo_cloud_focal_length_px = 700\nstereo_cloud_baseline = 0.12\n");
    EXPECT_EQ(o.lidar.sensor, "os1");
    EXPECT_DOUBLE_EQ(o.lidar.angularSigma_rad, 0.0004);  // the key overrides the preset
    EXPECT_DOUBLE_EQ(o.lidar.beamDivergence_rad,
                     LidarModelOptions::forSensor("os1").beamDivergence_rad);
    mrpt::config::CConfigFileMemory saved;
    o.write(saved, "s");
    StrictConfigSection s(saved, "s");
    SensorModelOptions back;
    back.read(s);
    s.finish();
    EXPECT_EQ(back.lidar.sensor, "os1");
    EXPECT_DOUBLE_EQ(back.lidar.angularSigma_rad, 0.0004);
    EXPECT_DOUBLE_EQ(back.lidar.rangeSigma(5.0), o.lidar.rangeSigma(5.0));
    EXPECT_EQ(back.modelByLabel, o.modelByLabel);
    EXPECT_DOUBLE_EQ(back.stereo.cloudFocalLength_px, 700);
    EXPECT_DOUBLE_EQ(back.stereo.cloudBaseline_m, 0.12);
}
