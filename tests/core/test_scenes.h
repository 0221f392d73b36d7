/* Synthetic observations shared by the core tests. */
#pragma once

#include <mrpt/core/bits_math.h>
#include <mrpt/obs/CObservation2DRangeScan.h>
#include <mrpt/poses/CPose3D.h>

#include <cmath>

namespace test_scenes {

/** A pitched 2D laser seeing the plane z = 0 from 0.26 m, like the paper's URG-04LX. */
inline mrpt::obs::CObservation2DRangeScan::Ptr pitchedScanOverFloor(double height_m,
                                                                    double pitch_rad) {
    auto scan = mrpt::obs::CObservation2DRangeScan::Create();
    scan->sensorLabel = "LASER";
    scan->aperture = float(mrpt::DEG2RAD(240.0));
    scan->maxRange = 4.0f;
    scan->sensorPose = mrpt::poses::CPose3D(0, 0, height_m, 0, pitch_rad, 0);
    const size_t N = 683;
    scan->resizeScan(N);
    for (size_t i = 0; i < N; i++) {
        const double a = -0.5 * scan->aperture + scan->aperture * double(i) / (N - 1);
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

}  // namespace test_scenes
