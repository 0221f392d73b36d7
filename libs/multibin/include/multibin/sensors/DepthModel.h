/* Part of the multibin elevation-mapping library. */
#pragma once

#include <mrpt/obs/CObservation3DRangeScan.h>

#include <Eigen/Core>
#include <cstdint>
#include <vector>

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

/** The error the points of one depth frame share (DepthModelOptions::frameSigma_m()), in the map
 * frame: n points of a frame in one cell that share an error of sd s carry the information of
 * variance sigma^2 / n + s^2, not sigma^2 / n. Each point gets n s(r)^2 v v^T added to its
 * covariance, n the number of `mapPoints` in its cell (per cell, not per bin: the error is the
 * cell's, and the cell surface fuses adjacent bins of one surface as independent, which gives
 * back sigma^2 / n + s^2 only if each bin carries the cell's n), v its unit ray from `sensor_m`
 * and r its range: for equal sigmas the cell's fused variance is exactly sigma^2 / n + s^2 and
 * its weighted mean is unchanged; across frames the shared errors are independent, so more
 * frames still shrink it. `pointsInCell[i]`: n for point i (the grid's pointsPerCell()). The eq
 * 13 gate is a point's own: the insertion removes the points failing it first
 * (removeFailingOwnGate()) and fuses the rest with the gate off. Throws std::invalid_argument if
 * the counts are not one per point. */
void addFrameSharedCovariance(PointsWithCov& mapPoints, const Eigen::Vector3d& sensor_m,
                              const DepthModelOptions& opts,
                              const std::vector<uint32_t>& pointsInCell);

}  // namespace multibin::sensors
