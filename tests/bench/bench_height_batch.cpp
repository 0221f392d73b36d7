/* The batch height query (CMultiBinElevationMap::heights) against a loop of height() over the
 * same points, on the shipped mock-up map (rawlogs/mockup.simplemap mapped as elevation-mapper
 * maps it, gaps filled). Both are timed in the same iteration in thread CPU time, so a shared
 * machine's load hits both alike; counter `ratio` = loop time / batch time.
 *
 *   ninja -C build bench_height_batch && build/tests/bench/bench_height_batch
 *
 * /0: 100 000 points uniform over the map's window (about a fifth known; as
 *     python/bench/bench_height.py's blocks); /1: 316 x 316 points half a cell apart, row by row,
 *     around the middle of the measured places (a raster at twice the map's resolution); /2, /3,
 *     /4: 100 000 uniform points where the map answers measured, unknown, filled. */
#include <benchmark/benchmark.h>
#include <mrpt/maps/CMultiBinElevationMap.h>
#include <time.h>

#include <random>
#include <vector>

#include "../common/mockup_map.h"

using mrpt::maps::CMultiBinElevationMap;

namespace {

double threadCpu_s() {
    timespec t;
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
    return double(t.tv_sec) + 1e-9 * double(t.tv_nsec);
}

/** The mock-up map, mapped once, its gaps filled. */
const CMultiBinElevationMap& mockupMap() {
    static const auto maps = test_maps::mockupMaps();
    return *maps->mapByClass<CMultiBinElevationMap>();
}

/** The points of case `which` (see the file's comment). */
void queryPoints(const CMultiBinElevationMap& map, int which, std::vector<double>& x,
                 std::vector<double>& y) {
    constexpr size_t kPoints = 100000;
    const double x0 = map.getXMin(), x1 = map.getXMax(), y0 = map.getYMin(), y1 = map.getYMax();
    x.clear();
    y.clear();
    if (which == 1) {  // 316 x 316 points half a cell apart, row by row, around the middle
        std::vector<double> mx, my;  // of the measured places
        queryPoints(map, 2, mx, my);
        double cx = 0, cy = 0;
        for (size_t i = 0; i < mx.size(); i++) cx += mx[i] / double(mx.size());
        for (size_t i = 0; i < my.size(); i++) cy += my[i] / double(my.size());
        const double step_m = 0.5 * map.creationOptions.resolution_m;
        const int side = 316;
        for (int r = 0; r < side; r++)
            for (int c = 0; c < side; c++) {
                x.push_back(cx + (c - side / 2 + 0.25) * step_m);
                y.push_back(cy + (r - side / 2 + 0.25) * step_m);
            }
        return;
    }
    std::mt19937 rng(7);
    std::uniform_real_distribution<double> ux(x0, x1), uy(y0, y1);
    while (x.size() < kPoints) {
        const double xi = ux(rng), yi = uy(rng);
        const auto source = map.height(xi, yi).source;
        using Source = CMultiBinElevationMap::HeightSource;
        if ((which == 2 && source != Source::Measured) ||
            (which == 3 && source != Source::Unknown) ||
            (which == 4 && source != Source::FilledMedian && source != Source::FilledSurface))
            continue;
        x.push_back(xi);
        y.push_back(yi);
    }
}

void BM_HeightsBatchVsLoop(benchmark::State& state) {
    const CMultiBinElevationMap& map = mockupMap();
    std::vector<double> x, y;
    queryPoints(map, int(state.range(0)), x, y);
    const size_t n = x.size();
    std::vector<CMultiBinElevationMap::HeightAnswer> batch(n), loop(n);
    double batch_s = 0, loop_s = 0;
    for (auto _ : state) {
        const double t0 = threadCpu_s();
        map.heights(x.data(), y.data(), n, batch.data());
        const double t1 = threadCpu_s();
        for (size_t i = 0; i < n; i++) loop[i] = map.height(x[i], y[i]);
        const double t2 = threadCpu_s();
        batch_s += t1 - t0;
        loop_s += t2 - t1;
        benchmark::DoNotOptimize(batch.data());
        benchmark::DoNotOptimize(loop.data());
    }
    size_t known = 0;
    for (const auto& a : batch) known += a.known();
    const double queries = double(state.iterations()) * double(n);
    state.counters["batch_ns_per_point"] = 1e9 * batch_s / queries;
    state.counters["loop_ns_per_point"] = 1e9 * loop_s / queries;
    state.counters["ratio"] = loop_s / batch_s;
    state.counters["known"] = double(known) / double(n);
}
BENCHMARK(BM_HeightsBatchVsLoop)->DenseRange(0, 4)->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
