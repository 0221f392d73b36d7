/* Part of the multibin elevation-mapping library. */
#pragma once

#include <mrpt/core/Clock.h>
#include <mrpt/obs/CObservation.h>
#include <mrpt/obs/CObservationStereoImages.h>
#include <mrpt/poses/CPose3D.h>
#include <mrpt/poses/CPose3DPDFGaussian.h>

#include <limits>
#include <map>
#include <memory>
#include <string>

#include "multibin/map/BinGrid.h"
#include "multibin/geometry/PointsWithCovariance.h"
#include "multibin/sensors/DepthModel.h"
#include "multibin/sensors/LaserModel.h"
#include "multibin/sensors/SensorModelOptions.h"

namespace multibin::sensors {

class StereoCovarianceTable;

/** What the stereo model did with the pixels of the pairs it was given. */
struct StereoStats {
    size_t pairs = 0;        //!< observations processed
    size_t tableBuilds = 0;  //!< per-pixel covariance tables (re)built (calibration changed)
    size_t pixels = 0;       //!< pixels visited (after subsampling)
    size_t noDisparity = 0;  //!< no valid disparity (matching failed or invalid)
    size_t halo = 0;         //!< removed by the halo filter (full-resolution pixels)
    size_t nearCluster = 0;  //!< removed by the near-cluster filter (full-resolution pixels)
    size_t tooNear = 0;      //!< depth under stereo_min_depth (out of the horopter)
    size_t outOfRange = 0;   //!< range outside [min_range, max_range]
    size_t kept = 0;         //!< turned into points
    StereoStats& operator+=(const StereoStats& o);
};

/** Sums of what the sensor models did, per sensor kind. */
struct SensorModelStats {
    LaserStats laser;
    StereoStats stereo;
    DepthStats depth;
};

/** State the sensor models keep between observations: the previous scan of each laser (eq 14),
 * the per-pixel stereo covariance table of the last calibration, and statistics. */
struct SensorModelState {
    struct PreviousScan {
        mrpt::poses::CPose3DPDFGaussian robotPose;
        mrpt::Clock::time_point time;
    };
    std::map<std::string, PreviousScan> previousScan;  //!< by sensor label
    /** Per-pixel covariance table of each stereo camera (by sensor label), rebuilt only when its
     * calibration changes. Read-only once built: copies of a map share them safely. */
    std::map<std::string, std::shared_ptr<const StereoCovarianceTable>> stereoTables;
    SensorModelStats stats;

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
};

/** Points with covariance of a stereo pair in the LEFT camera frame (MRPT camera frame): disparity
 * from the observation's disparity image if present (see decodeDisparityImage()), else OpenCV
 * StereoSGBM; halo and near-cluster filters; every `subsample`-th pixel; eqs 4-10 for the
 * covariance, through the per-pixel table kept in `state`. */
void stereoToPoints(const mrpt::obs::CObservationStereoImages& obs, const StereoModelOptions& opts,
                    double minRange_m, double maxRange_m, SensorModelState& state,
                    PointsWithCov& out);

/** The sensor-model step of CMultiBinElevationMap: observation -> sensor-frame points with 3x3
 * covariances. Handles CObservation2DRangeScan (laser model and eq 14 bound from the previous scan
 * of the same label), CObservationStereoImages, CObservation3DRangeScan and
 * CObservationPointCloud (depth model). Invalid, NaN and out-of-range readings are counted in
 * coreStats.outOfRange / notFinite as well as in state.stats(). Returns false for observations
 * that no model handles. `robotPose` is the robot pose PDF of the observation. */
bool observationToSensorPoints(const mrpt::obs::CObservation& obs,
                               const mrpt::poses::CPose3DPDFGaussian& robotPose,
                               const SensorModelOptions& opts, double minRange_m, double maxRange_m,
                               SensorModelState& state, InsertStats& coreStats, SensorPoints& out);

}  // namespace multibin::sensors
