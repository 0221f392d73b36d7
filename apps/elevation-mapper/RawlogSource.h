/* Part of the multibin elevation-mapping library: the elevation-mapper program. */
#pragma once

#include <mrpt/io/CStream.h>
#include <mrpt/maps/CSimpleMap.h>
#include <mrpt/obs/CObservation.h>
#include <mrpt/poses/CPose3DPDFGaussian.h>

#include <cstdint>
#include <functional>
#include <memory>
#include <string>

#include "PoseOverTime.h"
#include "RawlogSourceWarnings.h"

/** Streams the observations of a rawlog (either format: actions + sensory frames, or
 * observations only), each with the robot pose PDF it was taken at (PoseOverTime): the latest
 * CObservationRobotPose within robot_pose_max_dt_s, else that pose composed with the odometry
 * since it (covariance grown by the odometry's), else the odometry composed from the origin
 * (mean only: the map's default covariance).
 *
 * Every entry is checked before use: a null entry, an object of another class, a null action or
 * odometry PDF, a non-finite odometry are errors naming the file and the entry. Reading an entry
 * may request at most ReadBudget::limitFor(bytes left in the file) in one allocation
 * (RawlogSourceGuard.h), so a file that declares more objects or beams than it holds is refused
 * before the memory is taken. */
class RawlogSource {
public:
    /** obs (never null), the pose PDF, whether the PDF carries a covariance (false: mean only). */
    using Visitor = std::function<void(const mrpt::obs::CObservation::Ptr& obs,
                                       const mrpt::poses::CPose3DPDFGaussian& robotPose,
                                       bool poseHasCovariance)>;
    /** Progress: fraction of the input read [0, 1], entries read so far. */
    using Progress = std::function<void(double fraction, size_t entries)>;

    /** Reads the whole rawlog; throws std::runtime_error naming the file and the entry on a
     * truncated, corrupt or hostile file, and on an error of `visit` (prefixed with the file and
     * the entry). Returns the number of entries read. `robotPoseMaxDt_s`: how long a
     * CObservationRobotPose stays valid without odometry (the map's robot_pose_max_dt_s);
     * `counts`, if given, receives how the observations got their pose; `warnings`, if given,
     * what MRPT prints on std::cerr while an entry is read (else it reaches std::cerr). */
    static size_t forEachInRawlog(const std::string& path, const Visitor& visit,
                                  const Progress& progress, double robotPoseMaxDt_s = 0.5,
                                  PoseCounts* counts = nullptr, MrptWarnings* warnings = nullptr);
    /** The same on an open stream of uncompressed rawlog bytes; `name` names it in errors,
     * `sizeBound_bytes` bounds the bytes it holds from its current position. */
    static size_t forEachInStream(mrpt::io::CStream& in, const std::string& name,
                                  uint64_t sizeBound_bytes, const Visitor& visit,
                                  const Progress& progress, double robotPoseMaxDt_s = 0.5,
                                  PoseCounts* counts = nullptr, MrptWarnings* warnings = nullptr);

    /** Loads a simplemap file (gz-compressed or not); throws std::runtime_error naming the file
     * (and the keyframe) if it is missing, truncated, corrupt or holds a null keyframe pose,
     * sensory frame or observation; `warnings` as for forEachInRawlog. */
    static mrpt::maps::CSimpleMap loadSimplemap(const std::string& path,
                                                MrptWarnings* warnings = nullptr);
    /** The same on an open stream (see forEachInStream). */
    static mrpt::maps::CSimpleMap readSimplemap(mrpt::io::CStream& in, const std::string& name,
                                                uint64_t sizeBound_bytes,
                                                MrptWarnings* warnings = nullptr);
};
