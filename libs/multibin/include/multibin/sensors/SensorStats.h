/* Part of the multibin elevation-mapping library. */
#pragma once

#include <cstddef>
#include <optional>

#include "multibin/sensors/SensorModelOptions.h"

namespace multibin::sensors {

/** What the laser model did with the beams of the scans it was given. */
struct LaserStats {
    size_t beams = 0;         //!< beams seen
    size_t noReturn = 0;      //!< validity false or range >= the scan's maxRange
    size_t notFinite = 0;     //!< NaN or infinite range
    size_t outOfRange = 0;    //!< outside the map's [min_range, max_range]
    size_t lowIntensity = 0;  //!< restored intensity under the threshold within the check range
    size_t mixedPixel = 0;    //!< mixed measurement at a depth discontinuity
    size_t kept = 0;          //!< turned into points
    /** Beams of scans refused whole (an error) for their aperture: NaN, <= 0 or over a turn. */
    size_t badAperture = 0;
    LaserStats& operator+=(const LaserStats& o);
};

/** What the stereo model did with the pixels of the pairs it was given. */
struct StereoStats {
    size_t pairs = 0;        //!< observations processed
    size_t tableBuilds = 0;  //!< per-pixel covariance tables (re)built (calibration changed)
    size_t pixels = 0;       //!< pixels visited (after subsampling), or points of a stereo cloud
    size_t notFinite = 0;    //!< stereo cloud points with NaN or infinite coordinates
    size_t noDisparity = 0;  //!< no valid disparity (matching failed or invalid)
    size_t halo = 0;         //!< removed by the halo filter (full-resolution pixels)
    size_t nearCluster = 0;  //!< removed by the near-cluster filter (full-resolution pixels)
    size_t textureless = 0;  //!< SGBM pixels removed by the texture filter (full resolution)
    size_t tooNear = 0;      //!< depth under stereo_min_depth_m (out of the horopter)
    size_t outOfRange = 0;   //!< range outside [min_range, max_range]
    size_t kept = 0;         //!< turned into points
    /** Pairs refused whole (an error) for their calibration: sizes, non-finite or absurd
     * intrinsics (focal lengths, principal points), not a rectified pair. */
    size_t badCalibration = 0;
    StereoStats& operator+=(const StereoStats& o);
};

/** What the depth model did with the points it was given. */
struct DepthStats {
    size_t points = 0;       //!< points seen
    size_t notFinite = 0;    //!< NaN or infinite coordinates
    size_t outOfRange = 0;   //!< range outside [min_range, max_range] (0 = no return)
    size_t flyingPixel = 0;  //!< at a depth jump (depth_flying_pixel_*; DepthArtefacts.h)
    size_t frameBorder = 0;  //!< within depth_border_px of the frame's edge
    size_t kept = 0;         //!< turned into points with covariance
    DepthStats& operator+=(const DepthStats& o);
};

/** What the lidar model did with the returns it was given. */
struct LidarStats {
    size_t scans = 0;     //!< observations processed
    size_t returns = 0;   //!< readings seen (raw channels of a Velodyne scan)
    size_t noReturn = 0;  //!< no echo: invalid reading, range 0 or at the scan's maximum
    /** Velodyne echoes MRPT's calibrated point generation does not decode (for a VLP-16 in MRPT
     * 2.5: the second firing sequence of each data block) or drops by the scan's own range. */
    size_t notDecoded = 0;
    size_t notFinite = 0;   //!< NaN or infinite range or coordinates
    size_t outOfRange = 0;  //!< range outside [min_range, max_range]
    size_t kept = 0;        //!< turned into points with covariance
    LidarStats& operator+=(const LidarStats& o);
};

/** What the sensor models did, per sensor kind: of one observation, or summed by the map. */
struct SensorModelStats {
    LaserStats laser;
    StereoStats stereo;
    DepthStats depth;
    LidarStats lidar;
    SensorModelStats& operator+=(const SensorModelStats& o);

    /** Readings without a usable range: no return, not decoded, or outside the range the map
     * accepts (the map's InsertStats::outOfRange). */
    size_t outOfRange() const;
    /** Readings with NaN or infinite values (the map's InsertStats::notFinite). */
    size_t notFinite() const;
    /** The model that counted readings here (one observation's stats hold one model's counts);
     * none if nothing was counted. */
    std::optional<SensorModelKind> model() const;
};

}  // namespace multibin::sensors
