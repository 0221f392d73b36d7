/* Part of the multibin elevation-mapping library. */
#pragma once

#include <mrpt/obs/obs_frwds.h>

namespace mrpt::obs {
class CObservationPointCloud;  // in mrpt::maps, not in obs_frwds.h
}

#include <Eigen/Core>

#include "multibin/geometry/PointsWithCovariance.h"
#include "multibin/sensors/SensorModelOptions.h"
#include "multibin/sensors/SensorStats.h"

namespace multibin::sensors {

/** Points of a Velodyne scan in its sensor frame, from MRPT's calibrated point generation
 * (CObservationVelodyneScan::generatePointCloud with no distance filter of its own). Every raw
 * channel of the scan's packets is counted: no echo, not decoded by MRPT, or
 * out of range or not finite, like any ray point (RayModel.h). */
void velodyneScanToPoints(const mrpt::obs::CObservationVelodyneScan& scan,
                          const LidarModelOptions& opts, double minRange_m, double maxRange_m,
                          PointsWithCov& out, LidarStats& stats);

/** Points of a 2D lidar scan (any scanner: CObservation2DRangeScan with the lidar model) in its
 * sensor frame. Beams without a return (invalid, <= 0, >= the scan's maxRange) are counted as
 * such. */
void lidarScanToPoints(const mrpt::obs::CObservation2DRangeScan& scan,
                       const LidarModelOptions& opts, double minRange_m, double maxRange_m,
                       PointsWithCov& out, LidarStats& stats);

/** Points of a rotating scan in its sensor frame. MRPT 2.5's CObservationRotatingScan carries no
 * beam geometry (no calibration, no per-point directions), so only a single-row scan (a 2D
 * scanner: column i at azimuth startAzimuth + i azimuthSpan / columnCount, in the sensor's xy
 * plane) can be turned into points; a multi-row scan throws std::invalid_argument naming it. */
void rotatingScanToPoints(const mrpt::obs::CObservationRotatingScan& scan,
                          const LidarModelOptions& opts, double minRange_m, double maxRange_m,
                          PointsWithCov& out, LidarStats& stats);

}  // namespace multibin::sensors
