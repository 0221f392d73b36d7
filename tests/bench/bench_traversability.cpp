/* The traversability layers' live update against the insertion it follows (doc/traversability.md,
 * "Live use"). Run from a Release build: build/tests/bench/bench_traversability. */
#include <benchmark/benchmark.h>
#include <mrpt/config/CConfigFile.h>
#include <mrpt/maps/CMultiBinElevationMap.h>
#include <mrpt/maps/CSimpleMap.h>
#include <mrpt/obs/CObservation2DRangeScan.h>

#include <string>
#include <utility>
#include <vector>

namespace {
using ObservationsWithPdf =
    std::vector<std::pair<mrpt::obs::CObservation::Ptr, mrpt::poses::CPose3DPDFGaussian>>;

/** The shipped mock-up's laser scans or stereo frames with their keyframe pose PDFs, in order. */
bool loadMockup(ObservationsWithPdf& out, bool lasers) {
    mrpt::maps::CSimpleMap simplemap;
    if (!simplemap.loadFromFile(std::string(MULTIBIN_REFERENCE_DATA_DIR) + "/mockup.simplemap"))
        return false;
    mrpt::maps::CMultiBinElevationMap::forEachObservationWithPosePdf(
        simplemap,
        [&](const mrpt::obs::CObservation& obs, const mrpt::poses::CPose3DPDFGaussian& pdf) {
            if (lasers !=
                (dynamic_cast<const mrpt::obs::CObservation2DRangeScan*>(&obs) != nullptr))
                return;
            obs.load();
            out.emplace_back(
                std::dynamic_pointer_cast<mrpt::obs::CObservation>(obs.duplicateGetSmartPtr()),
                pdf);
        });
    return true;
}

mrpt::maps::CMultiBinElevationMap mockupMap() {
    const mrpt::config::CConfigFile ini(std::string(MULTIBIN_REFERENCE_DATA_DIR) +
                                        "/../ini/mockup.ini");
    const std::string section = "MappingApplication_multiBinElevationMap_00_";
    mrpt::maps::CMultiBinElevationMap::TCreationOptions creation;
    creation.loadFromConfigFile(ini, section + "creationOpts");
    mrpt::maps::CMultiBinElevationMap map(creation);
    map.insertionOptions.loadFromConfigFile(ini, section + "insertOpts");
    return map;
}
}  // namespace

// Every laser scan (arg 1) or stereo frame (arg 0) of the shipped mock-up into a fresh map as
// ini/mockup.ini configures it, with (arg 2 = 1) the traversability layers brought up to date
// after each one (the hexapod defaults) or not (0). The update's cost per observation is the
// difference of the two, divided by `observations`.
static void BM_MockupWithTraversability(benchmark::State& state) {
    ObservationsWithPdf observations;
    if (!loadMockup(observations, state.range(0) != 0)) {
        state.SkipWithError("rawlogs/mockup.simplemap not found");
        return;
    }
    const bool update = state.range(1) != 0;
    state.SetLabel(std::string(state.range(0) ? "laser" : "stereo") +
                   (update ? ", layers updated after each" : ", insertion only"));
    for (auto _ : state) {
        mrpt::maps::CMultiBinElevationMap map = mockupMap();
        for (const auto& [obs, pdf] : observations) {
            map.insertObservation(*obs, pdf);
            if (update) map.updateTraversability();
        }
        benchmark::DoNotOptimize(map);
    }
    state.counters["observations"] = double(observations.size());
}
BENCHMARK(BM_MockupWithTraversability)
    ->Args({1, 0})
    ->Args({1, 1})
    ->Args({0, 0})
    ->Args({0, 1})
    ->Unit(benchmark::kMillisecond);

// The layers of the whole mock-up map computed once from nothing (what a batch run's export
// costs).
static void BM_MockupLayersFromScratch(benchmark::State& state) {
    ObservationsWithPdf lasers, stereo;
    if (!loadMockup(lasers, true) || !loadMockup(stereo, false)) {
        state.SkipWithError("rawlogs/mockup.simplemap not found");
        return;
    }
    mrpt::maps::CMultiBinElevationMap map = mockupMap();
    for (const auto* set : {&lasers, &stereo})
        for (const auto& [obs, pdf] : *set) map.insertObservation(*obs, pdf);
    for (auto _ : state) {
        const mrpt::maps::CMultiBinElevationMap copy = map;  // a copy recomputes everything
        copy.updateTraversability();
    }
}
BENCHMARK(BM_MockupLayersFromScratch)->Unit(benchmark::kMillisecond);

BENCHMARK_MAIN();
