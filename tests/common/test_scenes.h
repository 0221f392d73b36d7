/* Synthetic observations and pose PDFs shared by the tests of several folders. */
#pragma once

#include <mrpt/core/bits_math.h>
#include <mrpt/maps/CMultiBinElevationMap.h>
#include <mrpt/obs/CObservation2DRangeScan.h>
#include <mrpt/poses/CPose3D.h>
#include <mrpt/poses/CPose3DPDFGaussian.h>

#include <array>
#include <cmath>

namespace test_scenes {

/** A robot pose PDF: `sigmas` (x, y, z [m], yaw, pitch, roll [rad]) on the diagonal, and x
 * correlated with pitch. */
inline mrpt::poses::CPose3DPDFGaussian poseWithCov(const mrpt::poses::CPose3D& mean,
                                                   const std::array<double, 6>& sigmas) {
    mrpt::poses::CPose3DPDFGaussian pdf;
    pdf.mean = mean;
    pdf.cov.setZero();
    for (int i = 0; i < 6; i++) pdf.cov(i, i) = sigmas[size_t(i)] * sigmas[size_t(i)];
    pdf.cov(0, 4) = pdf.cov(4, 0) = 0.3 * sigmas[0] * sigmas[4];  // some correlation
    return pdf;
}

/** A pitched 2D laser (240 deg, `beams` beams) seeing the plane z = 0 from `height_m`, like the
 * paper's URG-04LX (683 beams, 0.26 m, 45 deg). */
inline mrpt::obs::CObservation2DRangeScan::Ptr pitchedScanOverFloor(double height_m,
                                                                    double pitch_rad,
                                                                    size_t beams = 683) {
    auto scan = mrpt::obs::CObservation2DRangeScan::Create();
    scan->sensorLabel = "LASER";
    scan->aperture = float(mrpt::DEG2RAD(240.0));
    scan->maxRange = 4.0f;
    scan->sensorPose = mrpt::poses::CPose3D(0, 0, height_m, 0, pitch_rad, 0);
    scan->resizeScan(beams);
    for (size_t i = 0; i < beams; i++) {
        const double a =
            beams > 1 ? -0.5 * scan->aperture + scan->aperture * double(i) / double(beams - 1) : 0;
        // Ray direction in the robot frame; hits z = 0 at t = h / -dz.
        const mrpt::math::TVector3D d =
            scan->sensorPose.rotateVector(mrpt::math::TVector3D(std::cos(a), std::sin(a), 0));
        const double t = d.z < -1e-3 ? height_m / -d.z : 100.0;
        const bool valid = t < scan->maxRange;
        scan->setScanRange(i, valid ? float(t) : 0.f);
        scan->setScanRangeValidity(i, valid);
    }
    return scan;
}
/** A pitched 2D laser scan of a height field `terrain(x, y)` [m], found by ray marching,
 * with the robot at `robot` and the laser `height_m` above it, pitched down by `pitch_rad`. */
template <typename Terrain>
mrpt::obs::CObservation2DRangeScan::Ptr pitchedScanOver(const Terrain& terrain,
                                                        const mrpt::poses::CPose3D& robot,
                                                        double height_m, double pitch_rad) {
    auto scan = mrpt::obs::CObservation2DRangeScan::Create();
    scan->sensorLabel = "LASER";
    scan->aperture = float(mrpt::DEG2RAD(240.0));
    scan->maxRange = 4.0f;
    scan->sensorPose = mrpt::poses::CPose3D(0, 0, height_m, 0, pitch_rad, 0);
    const size_t N = 683;
    scan->resizeScan(N);
    const mrpt::poses::CPose3D sensorInMap = robot + scan->sensorPose;
    for (size_t i = 0; i < N; i++) {
        const double a = -0.5 * scan->aperture + scan->aperture * double(i) / (N - 1);
        const mrpt::math::TVector3D d =
            sensorInMap.rotateVector(mrpt::math::TVector3D(std::cos(a), std::sin(a), 0));
        float range = 0;
        auto below = [&](double t) {
            return sensorInMap.z() + t * d.z <=
                   terrain(sensorInMap.x() + t * d.x, sensorInMap.y() + t * d.y);
        };
        // The terrain is below the sensor: upward beams never hit. March in 4 mm steps, then
        // bisect to 0.01 mm.
        for (double t = 0.02; d.z < 0 && t < scan->maxRange; t += 0.004) {
            if (!below(t)) continue;
            double lo = t - 0.004, hi = t;
            while (hi - lo > 1e-5) (below(0.5 * (lo + hi)) ? hi : lo) = 0.5 * (lo + hi);
            range = float(hi);
            break;
        }
        scan->setScanRange(i, range);
        scan->setScanRangeValidity(i, range > 0);
    }
    return scan;
}

/** A map of fixed extent [0, side_m] x [0, side_m] (no growth) with cells of `cell_m` and a
 * height sigma floor of `sigmaFloor_m`. */
inline mrpt::maps::CMultiBinElevationMap fixedSquareMap(double cell_m, double side_m,
                                                        double sigmaFloor_m) {
    mrpt::maps::CMultiBinElevationMap::TCreationOptions c;
    c.resolution_m = cell_m;
    c.grow = false;
    c.min_x = c.min_y = 0;
    c.max_x = c.max_y = side_m;
    mrpt::maps::CMultiBinElevationMap map(c);
    map.insertionOptions.height_sigma_floor_m = sigmaFloor_m;
    return map;
}

}  // namespace test_scenes
