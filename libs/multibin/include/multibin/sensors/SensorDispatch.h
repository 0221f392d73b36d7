/* Part of the multibin elevation-mapping library. */
#pragma once

#include <mrpt/core/Clock.h>
#include <mrpt/obs/obs_frwds.h>
#include <mrpt/poses/CPose3D.h>
#include <mrpt/poses/CPose3DPDFGaussian.h>

#include <limits>
#include <map>
#include <memory>
#include <string>

#include "multibin/geometry/PointsWithCovariance.h"
#include "multibin/sensors/SensorModelOptions.h"
#include "multibin/sensors/SensorStats.h"

namespace multibin::sensors {

class StereoCovarianceTable;

/** State the sensor models keep between observations: the previous scan of each laser (eq 14),
 * the per-pixel stereo covariance table of the last calibration, and the sums of the models'
 * statistics that the map keeps. */
struct SensorModelState {
    struct PreviousScan {
        mrpt::poses::CPose3DPDFGaussian robotPose;
        mrpt::Clock::time_point time;
    };
    std::map<std::string, PreviousScan> previousScan;  //!< by sensor label
    /** Per-pixel covariance table of each stereo camera (by sensor label), rebuilt only when its
     * calibration changes. Read-only once built: copies of a map share them safely. */
    std::map<std::string, std::shared_ptr<const StereoCovarianceTable>> stereoTables;
    SensorModelStats stats;  //!< summed by the map over the observations it inserted

    /** Forgets the previous scans and the statistics (keeps the stereo tables: they depend only
     * on the calibration). */
    void reset() {
        previousScan.clear();
        stats = {};
    }
};

/** Points of one observation in its sensor frame, ready for pose propagation. */
struct SensorPoints {
    PointsWithCov points;             //!< sensor frame [m], covariances [m^2]
    mrpt::poses::CPose3D sensorPose;  //!< sensor on the robot
    /** Eq 14's Delta_zmax [m] for a laser scan with a previous scan; +infinity otherwise. */
    double continuityBound_m = std::numeric_limits<double>::infinity();
    /** A depth camera frame (CObservation3DRangeScan) whose points share an error
     * (DepthModelOptions::sharesFrameError()): the map adds it per cell
     * (addFrameSharedCovariance()). Point clouds, which may merge frames, get none. */
    bool depthFrameError = false;
    /** One camera frame (a stereo pair, a depth image): thousands of rays fanning over a
     * rectangle, not a scan's fan (the visibility constraint tests them differently). */
    bool cameraFrame = false;
    /** What the model did with this observation's readings (only its own kind is non-zero). */
    SensorModelStats stats;
};

/** The sensor-model step of CMultiBinElevationMap: observation -> sensor-frame points with 3x3
 * covariances, by the model its label is given in opts.modelByLabel (else its class's default):
 * CObservation2DRangeScan (laser, with eq 14's bound from the previous scan of the same label;
 * or lidar), CObservationStereoImages (stereo), CObservation3DRangeScan (depth),
 * CObservationPointCloud (depth, lidar or stereo), CObservationVelodyneScan and
 * CObservationRotatingScan (lidar). Invalid, NaN and out-of-range readings are counted in
 * out.stats; the caller adds them up. Returns false for observations that no model handles;
 * throws std::invalid_argument naming the key `sensor_models` for a model its observation class
 * cannot take. `robotPose` is the robot pose PDF of the observation. `threads` = 2 lets a stereo
 * pair's rows use the helper thread (StereoCovarianceTable::appendPoints). */
bool observationToSensorPoints(const mrpt::obs::CObservation& obs,
                               const mrpt::poses::CPose3DPDFGaussian& robotPose,
                               const SensorModelOptions& opts, double minRange_m, double maxRange_m,
                               SensorModelState& state, SensorPoints& out, int threads = 1);

}  // namespace multibin::sensors
