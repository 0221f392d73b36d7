/* The stereo sensor model alone, before and after its optimisation in the same run: the library
 * path (arg 1) against the straightforward reference it replaced (arg 0,
 * tests/sensors/test_stereo_reference.h), on a real disparity image: OpenCV SGBM (the shipped
 * stereo_sgbm_* defaults) on a 640 x 480 crop of the Middlebury Aloe pair (rawlogs/stereo),
 * computed once before timing. Parts: halo filter, near-cluster filter, points with covariance
 * (every pixel), and the three together. Run e.g.:
 *   build/tests/bench/bench_stereo --benchmark_repetitions=5
 * --benchmark_report_aggregates_only=true Aloe has no calibration: the geometry below (f = 500 px,
 * 9 cm baseline, as bench_pipeline's frame) only sets the depths; the work per pixel does not
 * depend on it. */
#include <benchmark/benchmark.h>
#include <mrpt/img/CImage.h>

#include <limits>
#include <string>

#include "../sensors/test_stereo_reference.h"
#include "multibin/sensors/StereoDisparity.h"
#include "multibin/sensors/StereoModel.h"

using namespace multibin;
using namespace multibin::sensors;

namespace {
StereoGeometry geometry640x480() {
    StereoGeometry g;
    g.width = 640;
    g.height = 480;
    g.fx = g.fy = 500;
    g.cx = 319.5;
    g.cy = 239.5;
    g.cxRight = 319.5;
    g.baseline_m = 0.09;
    return g;
}

/** SGBM disparity of the 640 x 480 crop at (300, 300) of the Aloe pair (computed once), or an
 * empty image if the pair is missing. */
const DisparityImage& aloeCropDisparity() {
    static const DisparityImage d = [] {
        const std::string dir =
            std::string(MULTIBIN_REFERENCE_DATA_DIR) + "/stereo/middlebury-aloe/";
        mrpt::img::CImage left, right, l, r;
        if (!left.loadFromFile(dir + "aloeL.jpg") || !right.loadFromFile(dir + "aloeR.jpg"))
            return DisparityImage();
        left.extract_patch(l, 300, 300, 640, 480);
        right.extract_patch(r, 300, 300, 640, 480);
        return computeDisparitySGBM(l, r, StereoModelOptions());
    }();
    return d;
}

StereoModelOptions everyPixel() {
    StereoModelOptions o;
    o.subsample = 1;
    return o;
}

bool haveFrame(benchmark::State& state) {
    if (aloeCropDisparity().width != 640) {
        state.SkipWithError("Middlebury Aloe pair not found under rawlogs/stereo");
        return false;
    }
    state.SetLabel(state.range(0) ? "library" : "reference (before)");
    return true;
}

const double kInf = std::numeric_limits<double>::infinity();
}  // namespace

// Halo filter (9 x 9 minimum by OpenCV erosion) on the raw SGBM frame.
static void BM_StereoHaloFilter(benchmark::State& state) {
    if (!haveFrame(state)) return;
    const StereoModelOptions o = everyPixel();
    size_t removed = 0;
    for (auto _ : state) {
        state.PauseTiming();
        DisparityImage d = aloeCropDisparity();
        state.ResumeTiming();
        removed = state.range(0) ? removeHalos(d, o) : stereo_reference::removeHalos(d, o);
        benchmark::DoNotOptimize(d.disparity_px.data());
    }
    state.counters["removed_px"] = double(removed);
}
BENCHMARK(BM_StereoHaloFilter)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond);

// Near-cluster filter on the halo-filtered frame (as the model runs it).
static void BM_StereoNearClusterFilter(benchmark::State& state) {
    if (!haveFrame(state)) return;
    const StereoModelOptions o = everyPixel();
    DisparityImage afterHalo = aloeCropDisparity();
    removeHalos(afterHalo, o);
    size_t removed = 0;
    for (auto _ : state) {
        state.PauseTiming();
        DisparityImage d = afterHalo;
        state.ResumeTiming();
        removed =
            state.range(0) ? removeNearClusters(d, o) : stereo_reference::removeNearClusters(d, o);
        benchmark::DoNotOptimize(d.disparity_px.data());
    }
    state.counters["removed_px"] = double(removed);
}
BENCHMARK(BM_StereoNearClusterFilter)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond);

// Points with covariance (eqs 8-10) of every pixel of the filtered frame, table built once.
static void BM_StereoPointsWithCovariance(benchmark::State& state) {
    if (!haveFrame(state)) return;
    const StereoModelOptions o = everyPixel();
    DisparityImage filtered = aloeCropDisparity();
    removeHalos(filtered, o);
    removeNearClusters(filtered, o);
    const StereoGeometry g = geometry640x480();
    const StereoCovarianceTable table(g, o);
    const stereo_reference::Table refTable(g, o);
    PointsWithCov out;
    for (auto _ : state) {
        if (state.range(0)) {
            PointsWithCov fresh;  // as the map's insertion: a new vector per frame
            table.appendPoints(filtered, o.subsample, o.minDepth_m, 0, kInf, fresh);
            out = std::move(fresh);
        } else {
            // The reference loop without its filters (already applied).
            StereoModelOptions noFilters = o;
            noFilters.halo.enabled = noFilters.nearCluster.enabled = false;
            out = stereo_reference::framePoints(g, filtered, refTable, noFilters, 0, kInf).points;
        }
        benchmark::DoNotOptimize(out.data());
    }
    state.counters["points"] = double(out.size());
}
BENCHMARK(BM_StereoPointsWithCovariance)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond);

// The whole sensor model from a decoded disparity image: both filters, then every pixel's point.
static void BM_StereoModelFrame(benchmark::State& state) {
    if (!haveFrame(state)) return;
    const StereoModelOptions o = everyPixel();
    const StereoGeometry g = geometry640x480();
    const StereoCovarianceTable table(g, o);
    const stereo_reference::Table refTable(g, o);
    PointsWithCov out;
    for (auto _ : state) {
        state.PauseTiming();
        DisparityImage d = aloeCropDisparity();
        state.ResumeTiming();
        if (state.range(0)) {
            removeHalos(d, o);
            removeNearClusters(d, o);
            PointsWithCov fresh;
            table.appendPoints(d, o.subsample, o.minDepth_m, 0, kInf, fresh);
            out = std::move(fresh);
        } else {
            out = stereo_reference::framePoints(g, std::move(d), refTable, o, 0, kInf).points;
        }
        benchmark::DoNotOptimize(out.data());
    }
    state.counters["points"] = double(out.size());
}
BENCHMARK(BM_StereoModelFrame)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond);

BENCHMARK_MAIN();
