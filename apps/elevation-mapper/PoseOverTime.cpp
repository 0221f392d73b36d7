/* Part of the multibin elevation-mapping library: the elevation-mapper program. */
#include "PoseOverTime.h"

#include <algorithm>
#include <cstdio>

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

void PoseReach::add(const mrpt::poses::CPose3D& p) {
    if (!m_any) {
        m_minX_m = m_maxX_m = p.x();
        m_minY_m = m_maxY_m = p.y();
        m_any = true;
    }
    m_minX_m = std::min(m_minX_m, p.x());
    m_maxX_m = std::max(m_maxX_m, p.x());
    m_minY_m = std::min(m_minY_m, p.y());
    m_maxY_m = std::max(m_maxY_m, p.y());
}

std::string PoseReach::beyondSupportedRange(double originX_m, double originY_m) const {
    if (!m_any) return {};
    const double absolute_m = std::max({-m_minX_m, m_maxX_m, -m_minY_m, m_maxY_m});
    const double fromOrigin_m = std::max(
        {originX_m - m_minX_m, m_maxX_m - originX_m, originY_m - m_minY_m, m_maxY_m - originY_m});
    if (absolute_m <= kMaxAbsolute_m && fromOrigin_m <= kMaxFromOrigin_m) return {};
    char b[320];
    std::snprintf(b, sizeof b,
                  "the robot poses reach x %.6g..%.6g m, y %.6g..%.6g m (%.3g m from the map "
                  "origin), beyond the supported range (|x|, |y| <= %.0e m, within %.0f km of the "
                  "map origin; doc/frames.md)",
                  m_minX_m, m_maxX_m, m_minY_m, m_maxY_m, fromOrigin_m, kMaxAbsolute_m,
                  kMaxFromOrigin_m / 1000);
    return b;
}
