/* Part of the multibin elevation-mapping library: the elevation-mapper program. */
#pragma once

#include <mrpt/maps/CSimpleMap.h>
#include <mrpt/obs/CObservation.h>
#include <mrpt/poses/CPose3DPDFGaussian.h>

#include <functional>
#include <memory>
#include <string>

/** Streams the observations of a rawlog (either format: actions + sensory frames, or
 * observations only), each with the robot pose PDF it was taken at: the latest
 * CObservationRobotPose (mean and covariance), else the odometry of the actions composed from the
 * origin (mean only). */
class RawlogSource {
public:
    /** obs, the pose PDF, whether the PDF carries a covariance (false: mean only). */
    using Visitor = std::function<void(const mrpt::obs::CObservation::Ptr& obs,
                                       const mrpt::poses::CPose3DPDFGaussian& robotPose,
                                       bool poseHasCovariance)>;
    /** Progress: fraction of the input read [0, 1], entries read so far. */
    using Progress = std::function<void(double fraction, size_t entries)>;

    /** Reads the whole rawlog; throws std::runtime_error naming the file and the entry on a
     * truncated or corrupt file. Returns the number of entries read. */
    static size_t forEachInRawlog(const std::string& path, const Visitor& visit,
                                  const Progress& progress);
    /** Loads a simplemap file (gz-compressed or not); throws std::runtime_error naming the file
     * if it is missing, truncated or corrupt. */
    static mrpt::maps::CSimpleMap loadSimplemap(const std::string& path);
};
