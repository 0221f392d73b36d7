/* Part of the multibin elevation-mapping library: the elevation-mapper program. */
#include "PoseOverTime.h"

#include <mrpt/system/datetime.h>

#include <Eigen/Dense>

#include <cmath>

void PoseOverTime::robotPose(const mrpt::poses::CPose3DPDFGaussian& pdf,
                             mrpt::Clock::time_point time) {
    m_anchor = pdf;
    m_anchorTime = time;
    m_sinceAnchor = {};  // identity, zero covariance
    m_moved = false;
    m_sinceAnchorCovKnown = true;
}

void PoseOverTime::odometry(const mrpt::poses::CPose3DPDFGaussian& step) {
    m_odometry = m_odometry + step.mean;
    if (!m_anchor) return;
    const bool finite = step.cov.asEigen().allFinite();
    m_sinceAnchorCovKnown = m_sinceAnchorCovKnown && finite;
    mrpt::poses::CPose3DPDFGaussian s = step;
    if (!finite) s.cov.setZero();  // its mean still moves the pose
    m_sinceAnchor += s;
    m_moved = true;
}

PoseOverTime::Pose PoseOverTime::at(mrpt::Clock::time_point time) {
    Pose p;
    if (m_anchor && m_moved) {
        p.pdf = *m_anchor;
        p.pdf += m_sinceAnchor;
        p.hasCovariance = m_sinceAnchorCovKnown;
    } else if (m_anchor) {
        const bool timesKnown = time != INVALID_TIMESTAMP && m_anchorTime != INVALID_TIMESTAMP;
        p.pdf = *m_anchor;
        p.hasCovariance =
            timesKnown && std::abs(mrpt::system::timeDifference(m_anchorTime, time)) <= m_maxDt_s;
    } else {
        p.pdf.mean = m_odometry;
    }
    if (!p.hasCovariance)
        m_counts.defaultCovariance++;
    else if (m_moved)
        m_counts.odometrySinceRobotPose++;
    else
        m_counts.robotPose++;
    return p;
}
