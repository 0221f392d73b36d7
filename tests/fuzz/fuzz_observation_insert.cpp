/* libFuzzer target: bytes -> up to 4 observations (2D laser scan, point cloud, stereo pair with a
 * disparity image, or a CObservationRobotPose) each with a robot pose PDF -> insertObservation()
 * into a growing or a dual-grid map.
 * Properties: no crash or sanitizer report; an observation that throws leaves the map's bytes
 * unchanged; after every observation every bin holds a finite height, a finite variance >= 0 and
 * a certainty >= 0. Values come either bounded (plausible) or as raw float bit patterns (NaN,
 * inf, huge), chosen per field by the input. */
#include <mrpt/maps/CSimplePointsMap.h>
#include <mrpt/obs/CObservation2DRangeScan.h>
#include <mrpt/obs/CObservationPointCloud.h>
#include <mrpt/obs/CObservationRobotPose.h>
#include <mrpt/obs/CObservationStereoImages.h>

#include "fuzz_common.h"
#include "multibin/sensors/StereoDisparity.h"

namespace {
using Map = mrpt::maps::CMultiBinElevationMap;

mrpt::poses::CPose3DPDFGaussian takePosePdf(fuzz::ByteReader& in) {
    const uint8_t mode = in.take<uint8_t>();
    const bool raw = mode & 1;
    mrpt::poses::CPose3DPDFGaussian pdf;
    const float x = in.takeFloat(-20, 20, raw), y = in.takeFloat(-20, 20, raw),
                z = in.takeFloat(-1, 1, raw);
    const float yaw = in.takeFloat(-4, 4, raw), pitch = in.takeFloat(-1, 1, raw),
                roll = in.takeFloat(-1, 1, raw);
    pdf.mean = mrpt::poses::CPose3D(x, y, z, yaw, pitch, roll);
    if (mode & 2) {
        // Any 6x6 matrix: not symmetric, not positive-definite, NaN ...
        for (int r = 0; r < 6; r++)
            for (int c = 0; c < 6; c++) pdf.cov(r, c) = in.take<float>();
    } else {
        pdf.cov.setZero();
        for (int i = 0; i < 6; i++) pdf.cov(i, i) = std::pow(in.takeFloat(0, 0.05f, false), 2.f);
    }
    return pdf;
}

mrpt::poses::CPose3D takeSensorPose(fuzz::ByteReader& in) {
    const bool raw = in.take<uint8_t>() & 1;
    return mrpt::poses::CPose3D(in.takeFloat(-0.5, 0.5, raw), in.takeFloat(-0.5, 0.5, raw),
                                in.takeFloat(0, 0.6f, raw), in.takeFloat(-3, 3, raw),
                                in.takeFloat(-1.5, 1.5, raw), in.takeFloat(-0.5, 0.5, raw));
}

mrpt::obs::CObservation::Ptr takeScan(fuzz::ByteReader& in) {
    auto scan = mrpt::obs::CObservation2DRangeScan::Create();
    scan->sensorLabel = (in.take<uint8_t>() & 1) ? "LASER" : "LASER2";
    const uint8_t flags = in.take<uint8_t>();
    scan->aperture = in.takeFloat(0, 6.3f, flags & 1);
    scan->maxRange = in.takeFloat(0, 6, flags & 2);
    scan->sensorPose = takeSensorPose(in);
    const size_t n = size_t(in.takeInt(0, 96));
    scan->resizeScan(n);
    scan->setScanHasIntensity(flags & 4);
    for (size_t i = 0; i < n; i++) {
        scan->setScanRange(i, in.takeFloat(-0.5, 5, flags & 8));
        scan->setScanRangeValidity(i, in.take<uint8_t>() & 1);
        if (flags & 4) scan->setScanIntensity(i, in.take<int16_t>());
    }
    return scan;
}

mrpt::obs::CObservation::Ptr takeCloud(fuzz::ByteReader& in) {
    auto obs = mrpt::obs::CObservationPointCloud::Create();
    obs->sensorLabel = "CLOUD";
    obs->sensorPose = takeSensorPose(in);
    auto pts = mrpt::maps::CSimplePointsMap::Create();
    const bool raw = in.take<uint8_t>() & 1;
    const int n = in.takeInt(0, 96);
    for (int i = 0; i < n; i++)
        pts->insertPoint(in.takeFloat(-3, 3, raw), in.takeFloat(-3, 3, raw),
                         in.takeFloat(-3, 3, raw));
    obs->pointcloud = pts;
    return obs;
}

mrpt::obs::CObservation::Ptr takeStereo(fuzz::ByteReader& in) {
    auto obs = mrpt::obs::CObservationStereoImages::Create();
    obs->sensorLabel = "STEREO";
    // Image and calibration sizes chosen separately: they may disagree.
    const int w = in.takeInt(1, 24), h = in.takeInt(1, 24);
    const uint8_t flags = in.take<uint8_t>();
    const uint32_t cw = (flags & 1) ? uint32_t(in.takeInt(0, 32)) : uint32_t(w);
    const uint32_t ch = (flags & 2) ? uint32_t(in.takeInt(0, 32)) : uint32_t(h);
    const double f = in.takeFloat(-5, 60, flags & 4);
    for (auto* cam : {&obs->leftCamera, &obs->rightCamera}) {
        cam->ncols = cw;
        cam->nrows = ch;
        cam->setIntrinsicParamsFromValues(f, f, 0.5 * w, 0.5 * h);
    }
    if (flags & 8) obs->rightCamera.setIntrinsicParamsFromValues(f, f + 1, 0.5 * w, 0.5 * h);
    obs->rightCameraPose =
        mrpt::math::TPose3DQuat(in.takeFloat(-0.1f, 0.2f, flags & 16), 0, 0, 1, 0, 0, 0);
    // Left camera on the robot as a raw quaternion pose: with raw values it may be NaN or not of
    // unit norm. MRPT's quaternion constructor refuses such values by throwing through a noexcept
    // path (std::terminate), so the raw values are written into the pose's storage directly: the
    // map must cope with what a corrupt observation can hold.
    const bool rawQ = in.take<uint8_t>() & 1;
    if (rawQ) {
        obs->cameraPose = mrpt::poses::CPose3DQuat();
        for (int i = 0; i < 3; i++) obs->cameraPose[i] = double(in.take<float>());
        for (int i = 0; i < 4; i++) obs->cameraPose.quat()[i] = double(in.take<float>());
    } else {
        obs->cameraPose = mrpt::poses::CPose3DQuat(
            mrpt::poses::CPose3D(in.takeFloat(-0.5, 0.5, false), 0, in.takeFloat(0, 0.6f, false),
                                 in.takeFloat(-3, 3, false), in.takeFloat(-1.5, 1.5, false), 0));
    }
    multibin::sensors::DisparityImage d(w, h);
    for (float& v : d.disparity_px) v = in.takeFloat(0, 40, flags & 32);
    obs->imageDisparity = multibin::sensors::encodeDisparityImage(d);
    obs->hasImageDisparity = true;
    obs->hasImageRight = false;
    return obs;
}

mrpt::obs::CObservation::Ptr takeRobotPose(fuzz::ByteReader& in) {
    auto obs = mrpt::obs::CObservationRobotPose::Create();
    obs->pose = takePosePdf(in);
    obs->timestamp = mrpt::Clock::fromDouble(1.0 + in.take<uint8_t>() * 0.1);
    return obs;
}
}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    fuzz::ByteReader in(data, size);
    const uint8_t setup = in.take<uint8_t>();
    Map::TCreationOptions c;
    if (setup & 1) {
        c.dual_grid = true;
        c.local_size_m = 1.0;
        c.local_resolution_m = 0.05;
        c.global_size_m = 4.0;
        c.global_resolution_m = 0.1;
    }
    Map map(c);
    map.insertionOptions.sensors.stereo.subsample = 1;
    for (int k = 0; k < 4 && in.remaining() > 0; k++) {
        const uint8_t kind = in.take<uint8_t>() % 4;
        mrpt::obs::CObservation::Ptr obs;
        try {
            switch (kind) {
                case 0:
                    obs = takeScan(in);
                    break;
                case 1:
                    obs = takeCloud(in);
                    break;
                case 2:
                    obs = takeStereo(in);
                    break;
                default:
                    obs = takeRobotPose(in);
                    break;
            }
        } catch (const std::exception& e) {
            // MRPT itself refuses to build some observations (e.g. a pose whose quaternion is not
            // of unit norm); they never reach the map.
            fuzz::debugRejected(e);
            return 0;
        }
        obs->timestamp = mrpt::Clock::fromDouble(1.0 + 0.1 * k);
        const bool withPdf = in.take<uint8_t>() & 1;
        const mrpt::poses::CPose3DPDFGaussian pdf = takePosePdf(in);
        const std::vector<uint8_t> before = fuzz::serialize(map);
        try {
            if (withPdf)
                map.insertObservation(*obs, pdf);
            else
                map.insertObservation(*obs, pdf.mean);
        } catch (const std::exception& e) {
            fuzz::debugRejected(e);
            if (fuzz::serialize(map) != before)
                fuzz::fail("a rejected observation changed the map");
        }
        fuzz::checkInvariants(map);
    }
    double h, s;
    if (map.getHeight(0, 0, h, s) && !(std::isfinite(h) && s >= 0)) fuzz::fail("getHeight");
    return 0;
}
