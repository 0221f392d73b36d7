/* Part of the multibin elevation-mapping library: the elevation-mapper program. */
#include "ObservationTally.h"
#include "multibin/map/MapStatistics.h"

#include <mrpt/obs/CObservationRobotPose.h>

#include <cstdio>

using mrpt::maps::CMultiBinElevationMap;

void ObservationTally::before(const CMultiBinElevationMap& map) {
    m_accepted0 = map.statistics().insert.accepted;
    m_rejected0 = map.statistics().insert.rejected();
    m_byLabel0 = map.statistics().skippedByLabel;
}

void ObservationTally::after(const mrpt::obs::CObservation& obs, bool inserted,
                             const CMultiBinElevationMap& map) {
    Counts& c = m_byClass[obs.GetRuntimeClass()->className];
    const size_t fused = map.statistics().insert.accepted - m_accepted0;
    const size_t rejected = map.statistics().insert.rejected() - m_rejected0;
    c.pointsFused += fused;
    c.pointsRejected += rejected;
    if (dynamic_cast<const mrpt::obs::CObservationRobotPose*>(&obs))
        c.poses++;  // a pose PDF for the observations that follow, not data
    else if (map.statistics().skippedByLabel > m_byLabel0)
        c.byLabel++;
    else if (inserted || fused > 0)
        c.used++;
    else if (rejected > 0)
        c.rejected++;
    else
        c.nothing++;
}

size_t ObservationTally::observations() const {
    size_t n = 0;
    for (const auto& [name, c] : m_byClass)
        n += c.used + c.rejected + c.byLabel + c.nothing + c.poses;
    return n;
}

namespace {
/** A class none of whose observations reached the map's counters is one no model handles. */
bool unsupported(size_t used, size_t rejected, size_t pointsRejected) {
    return used == 0 && rejected == 0 && pointsRejected == 0;
}
}  // namespace

std::string ObservationTally::report() const {
    std::string s = "observations by class:\n";
    char buf[512];
    for (const auto& [name, c] : m_byClass) {
        std::string line = "  " + name + ":";
        auto add = [&](size_t n, const std::string& what) {
            if (n == 0) return;
            std::snprintf(buf, sizeof buf, " %zu %s;", n, what.c_str());
            line += buf;
        };
        if (c.poses) add(c.poses, "used as robot pose PDFs");
        std::snprintf(buf, sizeof buf, "used (%zu points fused, %zu rejected)", c.pointsFused,
                      c.pointsRejected);
        add(c.used, buf);
        add(c.rejected, "rejected (every point rejected)");
        add(c.byLabel, "skipped by label (sensor_labels)");
        add(c.nothing, unsupported(c.used, c.rejected, c.pointsRejected)
                           ? "skipped: unsupported class (no sensor model)"
                           : "skipped: empty");
        if (line.back() == ';') line.pop_back();
        s += line + "\n";
    }
    return s;
}

std::string ObservationTally::whyNothingFused(const multibin::InsertStats& t) const {
    if (m_byClass.empty())
        return "no point fused: the input holds no observation (only actions or odometry?); "
               "the map needs range data (laser scans, stereo or depth images, point clouds)";
    std::string why = "no point fused from " + std::to_string(observations()) + " observations:";
    char buf[512];
    for (const auto& [name, c] : m_byClass) {
        std::string part;
        if (c.poses) part += " " + std::to_string(c.poses) + " pose PDFs,";
        if (c.byLabel) part += " " + std::to_string(c.byLabel) + " skipped by sensor_labels,";
        if (c.rejected + c.used) part += " " + std::to_string(c.rejected + c.used) + " rejected,";
        if (c.nothing)
            part +=
                " " + std::to_string(c.nothing) +
                (unsupported(c.used, c.rejected, c.pointsRejected) ? " unsupported," : " empty,");
        part.pop_back();
        why += " " + name + ":" + part + ";";
    }
    if (t.rejected() > 0) {
        std::snprintf(buf, sizeof buf,
                      " points rejected: %zu (range %zu, non-finite %zu, covariance %zu, outside "
                      "map %zu, bin range %zu, eq 13 gate %zu, eq 14 gate %zu)",
                      t.rejected(), t.outOfRange, t.notFinite, t.badCovariance, t.outsideMap,
                      t.outsideBinRange, t.tooUncertain, t.continuityRejected);
        why += buf;
    } else {
        why.pop_back();
    }
    return why;
}
