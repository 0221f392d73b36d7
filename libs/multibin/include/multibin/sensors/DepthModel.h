/* Part of the multibin elevation-mapping library. */
#pragma once

#include <mrpt/obs/CObservation3DRangeScan.h>

#include "multibin/geometry/PointsWithCovariance.h"
#include "multibin/sensors/SensorModelOptions.h"
#include "multibin/sensors/SensorStats.h"

namespace multibin::sensors {

/** Points of a depth camera observation in its sensor frame (MRPT's: +x forward), from its 3D
 * points if present, else from its range image unprojected with its own camera parameters, each
 * with the depth model's covariance (RayModel.h; point clouds: cloudToPoints()).
 * Throws std::invalid_argument if the three 3D point arrays differ in size. */
void depthScanToPoints(const mrpt::obs::CObservation3DRangeScan& scan,
                       const DepthModelOptions& opts, double minRange_m, double maxRange_m,
                       PointsWithCov& out, DepthStats& stats);

}  // namespace multibin::sensors
