/* Observation fields checked at the boundary (issue 37, kind 2): every field a model reads is
 * checked once before any model runs, with the observation's class, label and field in the
 * error, and the map unchanged. Before, the laser model checked its aperture and the others
 * read what they were given. */
#include <gtest/gtest.h>
#include <mrpt/maps/CSimpleMap.h>
#include <mrpt/maps/CSimplePointsMap.h>
#include <mrpt/math/CMatrixFixed.h>
#include <mrpt/obs/CObservation3DRangeScan.h>
#include <mrpt/obs/CObservationPointCloud.h>
#include <mrpt/obs/CObservationRotatingScan.h>
#include <mrpt/obs/CObservationStereoImages.h>
#include <mrpt/obs/CSensoryFrame.h>
#include <mrpt/poses/CPose3DPDFParticles.h>
#include <mrpt/poses/CPose3DPDFSOG.h>

#include <cmath>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "../common/reliability_helpers.h"
#include "multibin/io/ErrorMessage.h"

using namespace reliability;

namespace {

/** A pose with translation (x, y, z) and rotation matrix `scale` * I (0: the zero matrix):
 * what MRPT builds from a stored quaternion it does not normalise. */
mrpt::poses::CPose3D scaledPose(double scale, double z_m = 0.3) {
    mrpt::math::CMatrixDouble44 hm;
    hm.setIdentity();
    for (int i = 0; i < 3; i++) hm(i, i) = scale;
    hm(2, 3) = z_m;
    return mrpt::poses::CPose3D(hm);
}

/** insert() throws a message holding every word; the map holding data (with `model` as the
 * model of the label LASER, if given) is unchanged. */
void expectRefused(const std::function<void(Map&)>& insert, const std::vector<std::string>& words,
                   std::optional<multibin::sensors::SensorModelKind> model = std::nullopt) {
    Map map = mapWithData();
    if (model) map.insertionOptions.sensors.modelByLabel["LASER"] = *model;
    const auto before = serialize(map);
    try {
        insert(map);
        ADD_FAILURE() << "accepted; expected an error mentioning '" << words.front() << "'";
    } catch (const std::exception& e) {
        const std::string msg = multibin::oneLineMessage(e);
        for (const std::string& w : words)
            EXPECT_NE(msg.find(w), std::string::npos) << "'" << w << "' not in: " << msg;
    }
    EXPECT_EQ(serialize(map), before);
}

/** A depth camera 4 x 3 px looking down from 0.5 m, every pixel 0.5 m away. */
mrpt::obs::CObservation3DRangeScan::Ptr depthScan() {
    auto obs = mrpt::obs::CObservation3DRangeScan::Create();
    obs->sensorLabel = "DEPTH";
    obs->hasRangeImage = true;
    obs->rangeImage_setSize(3, 4);
    obs->rangeImage.fill(500);  // 0.5 m at the default 1 mm unit
    obs->cameraParams.ncols = 4;
    obs->cameraParams.nrows = 3;
    obs->cameraParams.setIntrinsicParamsFromValues(4, 4, 2, 1.5);
    obs->cameraParamsIntensity = obs->cameraParams;
    obs->sensorPose = mrpt::poses::CPose3D(0, 0, 0.5, 0, M_PI / 2, 0);
    return obs;
}

/** A single-row rotating scan of 100 beams over a half turn, 1 m each. */
mrpt::obs::CObservationRotatingScan::Ptr rotatingScan() {
    auto obs = mrpt::obs::CObservationRotatingScan::Create();
    obs->sensorLabel = "LIDAR";
    obs->rowCount = 1;
    obs->columnCount = 100;
    obs->rangeImage.setConstant(1, 100, 100);
    obs->rangeResolution = 0.01;
    obs->startAzimuth = -M_PI / 2;
    obs->azimuthSpan = M_PI;
    obs->sensorPose = mrpt::poses::CPose3D(0, 0, 0.3, 0, 0.3, 0);
    return obs;
}

}  // namespace

// A scaled or zero rotation in a sensor pose was read as it was.
TEST(ObservationChecks, SensorPosesThatAreNotRotationsAreErrors) {
    for (const double scale : {2.0, 0.0}) {
        SCOPED_TRACE(scale);
        auto scan = floorScan(50);
        scan->sensorLabel = "LASER";
        scan->sensorPose = scaledPose(scale);
        expectRefused([&](Map& m) { m.insertObservation(*scan, posePdf()); },
                      {"CObservation2DRangeScan 'LASER': sensorPose", "not a rotation"});
        auto cloud = mrpt::obs::CObservationPointCloud::Create();
        cloud->sensorLabel = "CLOUD";
        cloud->pointcloud = mrpt::maps::CSimplePointsMap::Create();
        cloud->pointcloud->insertPoint(0.5, 0, -0.3);
        cloud->sensorPose = scaledPose(scale);
        expectRefused([&](Map& m) { m.insertObservation(*cloud, posePdf()); },
                      {"CObservationPointCloud 'CLOUD': sensorPose", "not a rotation"});
    }
}

// The robot pose given with an observation: the same.
TEST(ObservationChecks, RobotPosesThatAreNotRotationsAreErrors) {
    for (const double scale : {3.0, 0.0}) {
        SCOPED_TRACE(scale);
        auto scan = floorScan(50);
        scan->sensorLabel = "LASER";
        mrpt::poses::CPose3DPDFGaussian pdf = posePdf();
        pdf.mean = scaledPose(scale, 0);
        expectRefused([&](Map& m) { m.insertObservation(*scan, pdf); },
                      {"robot pose of", "CObservation2DRangeScan 'LASER'", "not a rotation"});
    }
}

// A keyframe whose PDF holds no pose was mapped as an exact pose at the origin.
TEST(ObservationChecks, KeyframePdfsWithNoParticlesOrModesAreErrors) {
    auto scan = floorScan(50);
    scan->sensorLabel = "LASER";
    auto sf = mrpt::obs::CSensoryFrame::Create();
    sf->insert(scan);
    for (const auto& [pdf, what] :
         {std::pair<mrpt::poses::CPose3DPDF::Ptr, std::string>{
              std::make_shared<mrpt::poses::CPose3DPDFParticles>(0), "no particles"},
          {std::make_shared<mrpt::poses::CPose3DPDFSOG>(0), "no mode"}}) {
        SCOPED_TRACE(what);
        mrpt::maps::CSimpleMap sm;
        sm.insert(pdf, sf);
        expectRefused([&, &sm = sm](Map& m) { m.insertSimpleMapWithPosePdfs(sm); },
                      {"keyframe 0", what});
    }
}

// A negative focal length, a negative range unit: values the class cannot hold.
TEST(ObservationChecks, DepthCalibrationsAndRangeUnitsOutOfTheirRangeAreErrors) {
    auto negativeFocal = depthScan();
    negativeFocal->cameraParams.setIntrinsicParamsFromValues(-4, 4, 2, 1.5);
    expectRefused([&](Map& m) { m.insertObservation(*negativeFocal, posePdf()); },
                  {"CObservation3DRangeScan 'DEPTH'", "cameraParams.fx"});
    auto negativeUnit = depthScan();
    negativeUnit->rangeUnits = -0.001f;
    expectRefused([&](Map& m) { m.insertObservation(*negativeUnit, posePdf()); },
                  {"CObservation3DRangeScan 'DEPTH'", "rangeUnits"});
}

// Azimuth spans beyond a turn and negative range resolutions in the rotating-scan path.
TEST(ObservationChecks, RotatingScanSpansAndResolutionsOutOfTheirRangeAreErrors) {
    for (const double span : {100.0, std::nan("")}) {
        auto s = rotatingScan();
        s->azimuthSpan = span;
        expectRefused([&](Map& m) { m.insertObservation(*s, posePdf()); },
                      {"CObservationRotatingScan 'LIDAR'", "azimuthSpan"});
    }
    auto negative = rotatingScan();
    negative->rangeResolution = -0.01;
    expectRefused([&](Map& m) { m.insertObservation(*negative, posePdf()); },
                  {"CObservationRotatingScan 'LIDAR'", "rangeResolution"});
}

// The aperture the laser model checks, in the lidar model's path too.
TEST(ObservationChecks, AScanApertureOutOfRangeIsAnErrorInTheLidarPath) {
    for (const float aperture : {std::nanf(""), 20.f}) {
        auto scan = floorScan(50);
        scan->sensorLabel = "LASER";
        scan->aperture = aperture;
        expectRefused([&](Map& m) { m.insertObservation(*scan, posePdf()); },
                      {"CObservation2DRangeScan 'LASER'", "aperture"},
                      multibin::sensors::SensorModelKind::lidar);
    }
}

// A negative focal length and an absurd baseline in a stereo pair.
TEST(ObservationChecks, StereoFocalLengthsAndBaselinesOutOfTheirRangeAreErrors) {
    auto focal = stereoPair(32, 24);
    focal->leftCamera.setIntrinsicParamsFromValues(-300, 300, 16, 12);
    expectRefused([&](Map& m) { m.insertObservation(*focal, posePdf()); },
                  {"CObservationStereoImages 'STEREO'", "leftCamera.fx", "negative"});
    auto baseline = stereoPair(32, 24);
    baseline->rightCameraPose = mrpt::math::TPose3DQuat(1e6, 0, 0, 1, 0, 0, 0);
    expectRefused([&](Map& m) { m.insertObservation(*baseline, posePdf()); },
                  {"CObservationStereoImages 'STEREO'", "baseline"});
}
