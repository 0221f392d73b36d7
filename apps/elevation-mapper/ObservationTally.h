/* Part of the multibin elevation-mapping library: the elevation-mapper program. */
#pragma once

#include <mrpt/maps/CMultiBinElevationMap.h>
#include <mrpt/obs/CObservation.h>

#include <cstddef>
#include <map>
#include <string>

/** What the map did with each observation, per observation class: used (a point fused), rejected
 * (points reached the map, none fused), skipped by sensor label, or nothing taken (a class no
 * sensor model handles, or an empty observation). Fed around each insertion with the map's own
 * counters, so the mapper never maps nothing silently. */
class ObservationTally {
public:
    /** Snapshot of the map's counters before an insertion. */
    void before(const mrpt::maps::CMultiBinElevationMap& map);
    /** Classifies `obs` from the counters' change since before(). */
    void after(const mrpt::obs::CObservation& obs, bool inserted,
               const mrpt::maps::CMultiBinElevationMap& map);

    size_t observations() const;
    /** One line per class, e.g. "CObservation2DRangeScan: 112 used (61 234 points fused, ...)". */
    std::string report() const;
    /** One line saying why no point was fused (call when the map fused none). */
    std::string whyNothingFused(const multibin::InsertStats& totals) const;

    /** What report() prints for one class (the Python module returns them as a dict). */
    struct Counts {
        size_t used = 0, rejected = 0, byLabel = 0, nothing = 0, poses = 0;
        size_t pointsFused = 0, pointsRejected = 0;
    };
    const std::map<std::string, Counts>& byClass() const { return m_byClass; }

private:
    std::map<std::string, Counts> m_byClass;
    size_t m_accepted0 = 0, m_rejected0 = 0, m_byLabel0 = 0;
};
