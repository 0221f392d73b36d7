/* Benchmarks of gap filling on the shared LittleDog boards at 15 mm cells. Build in Release (the
 * default) and run: build/tests/bench/bench_fill */
#include <benchmark/benchmark.h>

#include <random>

#include "../fill/FillTestData.h"
#include "multibin/fill/GapFilling.h"

using namespace multibin::fill;
using namespace multibin::filltest;

namespace {
const std::vector<Board>& boards() { return boardsAt15mm(MULTIBIN_REFERENCE_DATA_DIR); }

/** The 2 x 2 m local grid (133 x 133 cells) with four large gaps (sides 6, 10, 14, 18 cells)
 * and `holeFraction` of the other cells hidden as scattered 1- and 2-cell holes. */
HeightRaster localGrid(double holeFraction) {
    HeightRaster r = tiledRaster(boards(), 133, 1);
    hideBox(r, 10, 10, 6, 6);
    hideBox(r, 90, 15, 10, 10);
    hideBox(r, 20, 80, 14, 14);
    hideBox(r, 75, 75, 18, 18);
    std::mt19937 rng(2);
    std::uniform_int_distribution<int> pos(0, 131);
    std::uniform_int_distribution<int> side(1, 2);
    const int holes = int(holeFraction * 133 * 133 / 2.5);
    for (int h = 0; h < holes; h++) {
        const int s = side(rng);
        hideBox(r, pos(rng), pos(rng), s, s);
    }
    return r;
}

void report(benchmark::State& state, const FillResult& f) {
    state.counters["median_cells"] = f.stats.median;
    state.counters["gaussian_cells"] = f.stats.gaussian;
    state.counters["unfilled_cells"] = f.stats.unfilled;
    state.counters["support_areas"] = f.stats.supportAreas;
}
}  // namespace

// One support area: a 16 x 16-cell gap in a 24 x 24 crop (margin 4): 320 known cells.
static void BM_FillOneSupportArea(benchmark::State& state) {
    HeightRaster r = noisyCrop(boards()[size_t(state.range(0))], 8, 8, 24, 1);
    hideBox(r, 4, 4, 16, 16);
    const FillOptions o;
    FillResult f;
    for (auto _ : state) benchmark::DoNotOptimize(f = fillGaps(r, o));
    report(state, f);
    state.counters["known_cells"] = 24 * 24 - 16 * 16;
    state.counters["m_chosen"] = f.stats.termsChosen.empty() ? -1 : f.stats.termsChosen[0];
    state.SetLabel(boards()[size_t(state.range(0))].name);
}
BENCHMARK(BM_FillOneSupportArea)->DenseRange(0, 5)->Unit(benchmark::kMillisecond);

// The whole 2 x 2 m local grid at 15 mm: four large gaps and scattered small holes.
static void BM_FillLocalGrid133(benchmark::State& state) {
    const HeightRaster r = localGrid(double(state.range(0)) / 100.0);
    const FillOptions o;
    FillResult f;
    for (auto _ : state) benchmark::DoNotOptimize(f = fillGaps(r, o));
    report(state, f);
}
BENCHMARK(BM_FillLocalGrid133)->Arg(5)->Arg(20)->Unit(benchmark::kMillisecond);

// Weighted median alone over the whole 133 x 133 grid (state.range(0) % of cells hidden as
// scattered holes; no large gaps).
static void BM_WeightedMedian133(benchmark::State& state) {
    HeightRaster r = tiledRaster(boards(), 133, 1);
    std::mt19937 rng(3);
    std::bernoulli_distribution hideIt(double(state.range(0)) / 100.0);
    for (int iy = 0; iy < 133; iy++)
        for (int ix = 0; ix < 133; ix++)
            if (hideIt(rng)) r.setUnknown(ix, iy);
    const FillOptions o;
    FillResult f;
    for (auto _ : state) benchmark::DoNotOptimize(f = weightedMedianFill(r, o));
    report(state, f);
}
BENCHMARK(BM_WeightedMedian133)->Arg(10)->Arg(30)->Unit(benchmark::kMillisecond);

/** A long shadow on the 2 x 2 m grid of boards (133 x 133 cells, all measured but the gap): an 80
 * x 12-cell strip joined to 26 one-cell slits of 28 cells (1688 cells), whose rim fits in no single
 * kriging neighbourhood: moving neighbourhoods plus the rim check (the mapper's shadow gaps; test
 * FillGaps.LongShadowBesideAStepStaysWithinItsOwnRim has the same geometry). */
static void BM_FillLongShadow133(benchmark::State& state) {
    HeightRaster r = tiledRaster(boards(), 133, 1);
    hideBox(r, 26, 60, 80, 12);
    for (int ix = 28; ix <= 103; ix += 3) hideBox(r, ix, 32, 1, 28);
    const FillOptions o;
    FillResult f;
    for (auto _ : state) benchmark::DoNotOptimize(f = fillGaps(r, o));
    report(state, f);
    state.counters["moving"] = f.stats.movingNeighbourhoods;
    state.counters["rim_check_harmonic"] = f.stats.rimCheckHarmonic;
}
BENCHMARK(BM_FillLongShadow133)->Unit(benchmark::kMillisecond);

BENCHMARK_MAIN();
