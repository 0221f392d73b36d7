/* Part of the multibin elevation-mapping library: the elevation-mapper program. */
#pragma once

#include <mrpt/core/Clock.h>
#include <mrpt/poses/CPose3DPDFGaussian.h>

#include <cstddef>
#include <optional>
#include <string>

/** How the observations of a rawlog got their pose. */
struct PoseCounts {
    size_t robotPose = 0;               //!< the latest CObservationRobotPose, young enough
    size_t odometrySinceRobotPose = 0;  //!< that pose composed with the odometry since it
    size_t defaultCovariance = 0;       //!< no pose PDF: odometry's mean, default covariance
};

/** The pose PDF of each observation of a rawlog over time: the latest CObservationRobotPose
 * while no odometry arrived since it and it is at most `robotPoseMaxDt_s` older (or younger)
 * than the observation; the odometry composed since it, its covariance grown by the odometry's
 * (eq 3's composition, CPose3DPDFGaussian::operator+=); else the odometry's (or the last pose's)
 * mean without a covariance, which the map replaces with default_pose_sigmas. */
class PoseOverTime {
public:
    explicit PoseOverTime(double robotPoseMaxDt_s) : m_maxDt_s(robotPoseMaxDt_s) {}

    /** A CObservationRobotPose taken at `time`. */
    void robotPose(const mrpt::poses::CPose3DPDFGaussian& pdf, mrpt::Clock::time_point time);
    /** An odometry increment; a covariance with a NaN or infinite entry is unknown. */
    void odometry(const mrpt::poses::CPose3DPDFGaussian& step);

    struct Pose {
        mrpt::poses::CPose3DPDFGaussian pdf;
        bool hasCovariance = false;  //!< false: the mean only (the map's default covariance)
    };
    /** The pose of an observation taken at `time` (counted). */
    Pose at(mrpt::Clock::time_point time);
    const PoseCounts& counts() const { return m_counts; }

private:
    double m_maxDt_s;
    mrpt::poses::CPose3D m_odometry;                          //!< all odometry from the origin
    std::optional<mrpt::poses::CPose3DPDFGaussian> m_anchor;  //!< the latest robot pose
    mrpt::Clock::time_point m_anchorTime;
    mrpt::poses::CPose3DPDFGaussian m_sinceAnchor;  //!< odometry composed since it
    bool m_moved = false, m_sinceAnchorCovKnown = true;
    PoseCounts m_counts;
};

/** How far the robot poses of a run reach, against the coordinate range the map supports
 * (doc/frames.md): |x|, |y| <= kMaxAbsolute_m, and within kMaxFromOrigin_m of the map origin
 * (the map's geometry is single precision relative to it). A run whose poses lie beyond was
 * blamed on the map's window ("does not hold the data"), or mapped without a word. */
class PoseReach {
public:
    static constexpr double kMaxAbsolute_m = 1e7, kMaxFromOrigin_m = 2000;
    void add(const mrpt::poses::CPose3D& robotPose);
    /** Empty when every pose lies within the range; else what lies beyond it, e.g. "the robot
     * poses reach x 1e+12 m, beyond the supported range (|x|, |y| <= 1e7 m, within 2 km of the
     * map origin; doc/frames.md)". `originX_m`, `originY_m`: the map origin. */
    std::string beyondSupportedRange(double originX_m, double originY_m) const;

private:
    bool m_any = false;
    double m_minX_m = 0, m_maxX_m = 0, m_minY_m = 0, m_maxY_m = 0;
};
