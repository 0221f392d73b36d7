/* The traversability layers' live update against the insertion it follows (doc/traversability.md,
 * "Live use"). Run from a Release build: build/tests/bench/bench_traversability. */
#include <benchmark/benchmark.h>
#include <mrpt/config/CConfigFile.h>
#include <mrpt/maps/CMultiBinElevationMap.h>
#include <mrpt/maps/CSimpleMap.h>
#include <mrpt/obs/CObservation2DRangeScan.h>

#include <ctime>
#include <string>
#include <vector>

namespace {
/** The shipped mock-up's keyframes (rawlogs/mockup.simplemap); false if missing. */
bool loadMockup(mrpt::maps::CSimpleMap& simplemap) {
    return simplemap.loadFromFile(std::string(MULTIBIN_REFERENCE_DATA_DIR) + "/mockup.simplemap");
}
bool isLaser(const mrpt::obs::CObservation& obs) {
    return dynamic_cast<const mrpt::obs::CObservation2DRangeScan*>(&obs) != nullptr;
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
// after each one (the hexapod defaults) or not (0), by Monte Carlo (arg 3 = 0) or the closed form
// (1, linear_uncertainty). The update's cost per observation is the difference of the two, divided
// by `observations`.
static void BM_MockupWithTraversability(benchmark::State& state) {
    mrpt::maps::CSimpleMap simplemap;
    if (!loadMockup(simplemap)) {
        state.SkipWithError("rawlogs/mockup.simplemap not found");
        return;
    }
    const bool lasers = state.range(0) != 0, update = state.range(1) != 0;
    const bool linear = state.range(2) != 0;
    state.SetLabel(std::string(lasers ? "laser" : "stereo") +
                   (update ? ", layers updated after each" : ", insertion only") +
                   (update ? (linear ? " (closed form)" : " (Monte Carlo)") : ""));
    size_t observations = 0;
    for (auto _ : state) {
        mrpt::maps::CMultiBinElevationMap map = mockupMap();
        map.traversabilityOptions.linear_uncertainty = linear;
        observations = 0;
        mrpt::maps::CMultiBinElevationMap::forEachObservationWithPosePdf(
            simplemap,
            [&](const mrpt::obs::CObservation& obs, const mrpt::poses::CPose3DPDFGaussian& pdf) {
                if (isLaser(obs) != lasers) return;
                map.insertObservation(obs, pdf);
                if (update) map.updateTraversability();
                observations++;
            });
        benchmark::DoNotOptimize(map);
    }
    state.counters["observations"] = double(observations);
}
BENCHMARK(BM_MockupWithTraversability)
    ->Args({1, 0, 0})
    ->Args({1, 1, 0})
    ->Args({1, 1, 1})
    ->Args({0, 0, 0})
    ->Args({0, 1, 0})
    ->Args({0, 1, 1})
    ->Unit(benchmark::kMillisecond);

// Issue 34's bound, one laser scan at a time: the mock-up mapped up to its last 20 laser scans
// with the layers up to date, then each of those scans inserted and the layers brought up to date
// after it, the two timed apart (CPU time of the thread) in the same run. Counters: the insertion
// and the update per scan [ms] and their ratio (issue 34's bound: update / insertion <= 0.2).
// Args: monte_carlo_draws (128 the default; 0 the features of the map's surface alone, no
// uncertainty: the floor of any design that computes the features of each dirty cell), and
// linear_uncertainty (1: the closed form instead of the draws).
static void BM_LaserScanUpdateOverInsertion(benchmark::State& state) {
    mrpt::maps::CSimpleMap simplemap;
    if (!loadMockup(simplemap)) {
        state.SkipWithError("rawlogs/mockup.simplemap not found");
        return;
    }
    // The thread's CPU time: the machine's other load does not enter the ratio.
    const auto cpu_ms = [] {
        timespec t;
        clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
        return double(t.tv_sec) * 1e3 + double(t.tv_nsec) * 1e-6;
    };
    constexpr size_t kTimedScans = 20;
    double insert_ms = 0, update_ms = 0;
    size_t timed = 0;
    for (auto _ : state) {
        state.PauseTiming();
        // The observations live in `simplemap`.
        std::vector<std::pair<const mrpt::obs::CObservation*, mrpt::poses::CPose3DPDFGaussian>> all;
        mrpt::maps::CMultiBinElevationMap::forEachObservationWithPosePdf(
            simplemap,
            [&](const mrpt::obs::CObservation& obs, const mrpt::poses::CPose3DPDFGaussian& pdf) {
                if (isLaser(obs)) all.emplace_back(&obs, pdf);
            });
        const size_t first = all.size() > kTimedScans ? all.size() - kTimedScans : 0;
        mrpt::maps::CMultiBinElevationMap map = mockupMap();
        map.traversabilityOptions.monte_carlo_draws = int(state.range(0));
        map.traversabilityOptions.linear_uncertainty = state.range(1) != 0;
        for (size_t i = 0; i < first; i++) map.insertObservation(*all[i].first, all[i].second);
        map.updateTraversability();
        state.ResumeTiming();
        for (size_t i = first; i < all.size(); i++) {
            const double t0 = cpu_ms();
            map.insertObservation(*all[i].first, all[i].second);
            const double t1 = cpu_ms();
            map.updateTraversability();
            const double t2 = cpu_ms();
            insert_ms += t1 - t0, update_ms += t2 - t1, timed++;
        }
    }
    state.counters["insert_ms_per_scan"] = insert_ms / double(timed);
    state.counters["update_ms_per_scan"] = update_ms / double(timed);
    state.counters["update_over_insert"] = update_ms / insert_ms;
}
BENCHMARK(BM_LaserScanUpdateOverInsertion)
    ->Args({128, 0})
    ->Args({128, 1})
    ->Args({0, 0})
    ->Iterations(3)
    ->Unit(benchmark::kMillisecond);

// The layers of the whole mock-up map computed once from nothing (what a batch run's export
// costs).
static void BM_MockupLayersFromScratch(benchmark::State& state) {
    mrpt::maps::CSimpleMap simplemap;
    if (!loadMockup(simplemap)) {
        state.SkipWithError("rawlogs/mockup.simplemap not found");
        return;
    }
    mrpt::maps::CMultiBinElevationMap map = mockupMap();
    map.insertSimpleMapWithPosePdfs(simplemap);
    for (auto _ : state) {
        const mrpt::maps::CMultiBinElevationMap copy = map;  // a copy recomputes everything
        copy.updateTraversability();
    }
}
BENCHMARK(BM_MockupLayersFromScratch)->Unit(benchmark::kMillisecond);

BENCHMARK_MAIN();
