/* Part of the multibin elevation-mapping library. */
#pragma once

#include <mrpt/obs/CObservation3DRangeScan.h>
#include <mrpt/obs/CObservationPointCloud.h>

#include "multibin/geometry/PointsWithCovariance.h"
#include "multibin/sensors/SensorModelOptions.h"
#include "multibin/sensors/SensorStats.h"

namespace multibin::sensors {

/** Sensor-frame covariance [m^2] of a structured-light depth point at `p_m` (sensor origin at 0):
 * sigma_axial(r)^2 d d^T + (sigma_lateral r)^2 (I - d d^T), with r = |p|, d = p / r, sigma_axial
 * the Nguyen 2012 curve of `opts` and sigma_lateral = opts.lateralSigma_rad. */
SymmetricCov3 depthPointCovariance(const Eigen::Vector3f& p_m, const DepthModelOptions& opts);

/** Appends the point (sensor frame) with its depth-model covariance, or counts it as not finite /
 * out of range. */
void appendDepthPoint(const Eigen::Vector3f& p_m, const DepthModelOptions& opts, double minRange_m,
                      double maxRange_m, PointsWithCov& out, DepthStats& stats);

/** Points of a depth camera observation in its sensor frame (MRPT's: +x forward), from its 3D
 * points if present, else from its range image unprojected with its own camera parameters.
 * Throws std::invalid_argument if the three 3D point arrays differ in size. */
void depthScanToPoints(const mrpt::obs::CObservation3DRangeScan& scan,
                       const DepthModelOptions& opts, double minRange_m, double maxRange_m,
                       PointsWithCov& out, DepthStats& stats);

/** Points of a point cloud observation in its sensor frame, with the depth model. */
void pointCloudToPoints(const mrpt::obs::CObservationPointCloud& cloud,
                        const DepthModelOptions& opts, double minRange_m, double maxRange_m,
                        PointsWithCov& out, DepthStats& stats);

}  // namespace multibin::sensors
