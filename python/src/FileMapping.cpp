/* Part of the multibin elevation-mapping library: the Python module.
 * map_rawlog / map_simplemap: elevation-mapper's reading (RawlogSource, static library
 * rawlog_source) and its per-class report (ObservationTally), with the counts as a dict. */
#include <mrpt/maps/CSimpleMap.h>

#include <functional>
#include <stdexcept>

#include "ElevationMap.h"
#include "ObservationTally.h"
#include "RawlogSource.h"
#include "multibin/map/MapStatistics.h"

namespace py = pybind11;
using mrpt::maps::CMultiBinElevationMap;

namespace multibin::python {

namespace {
/** Feeds (observation, pose PDF, whether the PDF has a covariance) to a map. */
using Insert = std::function<void(const mrpt::obs::CObservation&,
                                  const mrpt::poses::CPose3DPDFGaussian&, bool)>;

/** Runs `read` (which calls insert for every observation) on `map` without the GIL, tallied as
 * elevation-mapper tallies it; an input of which no point was fused is an error, as there. */
py::dict mapTallied(CMultiBinElevationMap& map, const std::string& inputName,
                    const std::function<size_t(const Insert&)>& read) {
    ObservationTally tally;
    size_t entries = 0;
    const size_t fused0 = map.statistics().insert.accepted;
    {
        py::gil_scoped_release nogil;
        entries = read([&](const mrpt::obs::CObservation& obs,
                           const mrpt::poses::CPose3DPDFGaussian& pose, bool poseHasCov) {
            tally.before(map);
            const bool inserted = poseHasCov ? map.insertObservation(obs, pose)
                                             : map.insertObservation(obs, pose.mean);
            tally.after(obs, inserted, map);
        });
    }
    const multibin::MapStatistics stats = map.statistics();
    if (stats.insert.accepted == fused0)
        throw std::runtime_error(inputName + ": " + tally.whyNothingFused(stats.insert));
    py::dict byClass;
    for (const auto& [name, c] : tally.byClass()) {
        py::dict d;
        d["used"] = c.used;
        d["rejected"] = c.rejected;
        d["skipped_by_label"] = c.byLabel;
        d["skipped"] = c.nothing;
        d["pose_pdfs"] = c.poses;
        d["points_fused"] = c.pointsFused;
        d["points_rejected"] = c.pointsRejected;
        byClass[py::str(name)] = d;
    }
    py::dict out;
    out["entries"] = entries;
    out["observations"] = tally.observations();
    out["by_class"] = byClass;
    out["points"] = insertStatsDict(stats.insert);
    out["default_pose_covariance"] = stats.poseFallbacks;
    out["report"] = tally.report();
    return out;
}
}  // namespace

py::dict ElevationMap::mapRawlog(const std::string& path) {
    return mapTallied(*m_map, "rawlog '" + path + "'", [&](const Insert& insert) {
        return RawlogSource::forEachInRawlog(
            path,
            [&](const mrpt::obs::CObservation::Ptr& obs,
                const mrpt::poses::CPose3DPDFGaussian& pose,
                bool poseHasCov) { insert(*obs, pose, poseHasCov); },
            {});
    });
}

py::dict ElevationMap::mapSimplemap(const std::string& path) {
    return mapTallied(*m_map, "simplemap '" + path + "'", [&](const Insert& insert) {
        const mrpt::maps::CSimpleMap sm = RawlogSource::loadSimplemap(path);
        CMultiBinElevationMap::forEachObservationWithPosePdf(
            sm, [&](const mrpt::obs::CObservation& obs,
                    const mrpt::poses::CPose3DPDFGaussian& pdf) { insert(obs, pdf, true); });
        return sm.size();
    });
}

}  // namespace multibin::python
