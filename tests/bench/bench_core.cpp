/* Benchmarks of the insertion core: covariance propagation, bin update, the ratio to MRPT's
 * CHeightGridMap2D in the same run, the visibility constraint's share of an update, moving the
 * window, memory per bin. Build in Release and run, e.g.:
 *   build/tests/bench/bench_core --benchmark_repetitions=5 --benchmark_report_aggregates_only=true
 * doc/performance.md has the figures and the exact commands. */
#include <benchmark/benchmark.h>
#include <mrpt/maps/CHeightGridMap2D.h>

#include <time.h>

#include <algorithm>
#include <cstring>
#include <limits>
#include <random>
#include <thread>

#include "multibin/geometry/PosePropagation.h"
#include "multibin/grid/BinGrid.h"
#include "multibin/grid/CellSurface.h"
#include "multibin/grid/VisibilityConstraint.h"

using namespace multibin;

namespace {
/** The calling thread's CPU time [s]: the parts timed inside one loop are compared in CPU time,
 * which other processes on the shared machine do not inflate (wall time does). */
struct Clock {
    static double now() {
        timespec t;
        clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
        return double(t.tv_sec) + 1e-9 * double(t.tv_nsec);
    }
};
double seconds(double a, double b) { return b - a; }

constexpr double kCell_m = 0.015;  // the paper's local-grid cell
constexpr double kCameraHeight_m = 0.48;

/** A stereo-frame-like cloud in the sensor frame: one point per pixel of a 640-wide image, in
 * image order, on a rough surface 1-3 m ahead (range noise 1 %, so neighbouring pixels land in
 * neighbouring, not always equal, cells and bins), with a range-only covariance plus 1 mm
 * isotropic. */
PointsWithCov makeSensorPoints(size_t n) {
    std::mt19937 rng(1);
    std::normal_distribution<float> rough(0.f, 0.01f);
    const int w = 640, h = int((n + w - 1) / w);
    PointsWithCov pts;
    pts.reserve(n);
    for (int v = 0; v < h; v++)
        for (int u = 0; u < w && pts.size() < n; u++) {
            // +x forward, +y left, +z up; rows look from far (top) to near (bottom).
            const Eigen::Vector3f dir =
                Eigen::Vector3f(1.f, 0.6f * (0.5f - float(u) / w), -0.2f - 0.4f * float(v) / h)
                    .normalized();
            const float range = float(kCameraHeight_m) / -dir.z() * (1.f + rough(rng));
            PointWithCov p;
            p.point_m = dir * range;
            p.cov_m2 = rangeOnlyCovariance(dir, 0.002f * range * range);
            p.cov_m2.xx += 1e-6f;
            p.cov_m2.yy += 1e-6f;
            p.cov_m2.zz += 1e-6f;
            pts.push_back(p);
        }
    return pts;
}

mrpt::poses::CPose3DPDFGaussian robotPose() {
    mrpt::poses::CPose3DPDFGaussian pdf;
    pdf.mean = mrpt::poses::CPose3D(0.3, -0.2, 0.1, 0.2, 0.05, -0.03);
    pdf.cov.setIdentity();
    pdf.cov *= 1e-6;
    return pdf;
}
const mrpt::poses::CPose3D kCameraOnRobot(0, 0, kCameraHeight_m, 0, 0, 0);

/** A grid covering every point of makeSensorPoints() seen from robotPose(). */
BinGrid frameGrid() {
    BinGrid grid(kCell_m);
    grid.reset(kCell_m, CellWindow{-100, -300, 400, 400});
    return grid;
}

/** Everything one frame needs, built once per benchmark. */
struct Frame {
    explicit Frame(size_t n)
        : sensorPoints(makeSensorPoints(n)), propagator(robotPose(), kCameraOnRobot) {
        propagator.apply(sensorPoints, mapPoints);
    }
    PointsWithCov sensorPoints, mapPoints;
    PosePropagator propagator;
};

mrpt::maps::CHeightGridMap2D mrptGridForFrame() {
    return mrpt::maps::CHeightGridMap2D(mrpt::maps::CHeightGridMap2D::mrSimpleAverage, -1.5, 4.5,
                                        -4.5, 1.5, kCell_m);
}

void mrptInsert(mrpt::maps::CHeightGridMap2D& grid, const PointsWithCov& mapPoints) {
    mrpt::maps::CHeightGridMap2D_Base::TPointInsertParams ip;
    ip.update_map_after_insertion = false;
    for (const auto& p : mapPoints)
        grid.insertIndividualPoint(p.point_m.x(), p.point_m.y(), p.point_m.z(), ip);
}
}  // namespace

// Covariance propagation alone (J_R C_R J_R^T + J_S C_S J_S^T for every point).
static void BM_Propagate(benchmark::State& state) {
    const Frame f(size_t(state.range(0)));
    PointsWithCov out;
    for (auto _ : state) {
        f.propagator.apply(f.sensorPoints, out);
        benchmark::DoNotOptimize(out.data());
        benchmark::ClobberMemory();
    }
    state.SetItemsProcessed(int64_t(state.iterations()) * state.range(0));
}
BENCHMARK(BM_Propagate)->Arg(307200)->Unit(benchmark::kMillisecond);

// Propagation on two threads, each taking half of the frame through the pointer-range apply():
// the per-point work is independent, so the output is bit-identical to one thread. Shows what a
// second core gives; the library itself stays single-threaded (callers choose).
static void BM_PropagateTwoThreads(benchmark::State& state) {
    const Frame f(size_t(state.range(0)));
    PointsWithCov out(f.sensorPoints.size());
    const size_t half = f.sensorPoints.size() / 2;
    for (auto _ : state) {
        std::thread second([&] {
            f.propagator.apply(f.sensorPoints.data() + half, out.data() + half,
                               f.sensorPoints.size() - half);
        });
        f.propagator.apply(f.sensorPoints.data(), out.data(), half);
        second.join();
        benchmark::DoNotOptimize(out.data());
        benchmark::ClobberMemory();
    }
    if (std::memcmp(out.data(), f.mapPoints.data(), out.size() * sizeof(PointWithCov)) != 0)
        state.SkipWithError("two-thread propagation differs from one thread");
    state.SetItemsProcessed(int64_t(state.iterations()) * state.range(0));
}
BENCHMARK(BM_PropagateTwoThreads)->Arg(307200)->UseRealTime()->Unit(benchmark::kMillisecond);

// The bin update alone (gates, eq 15 Kalman, update-cycle bookkeeping) of map-frame points.
static void BM_BinUpdate(benchmark::State& state) {
    const Frame f(size_t(state.range(0)));
    BinGrid grid = frameGrid();
    const BinUpdateParams params;
    for (auto _ : state) {
        grid.beginCycle();
        benchmark::DoNotOptimize(grid.insertPoints(f.mapPoints, params));
    }
    state.SetItemsProcessed(int64_t(state.iterations()) * state.range(0));
}
BENCHMARK(BM_BinUpdate)->Arg(307200)->Unit(benchmark::kMillisecond);

// Points with full covariance propagation (pose + sensor) and the bin update, one core: the
// headline throughput (a 640 x 480 frame's worth of points per iteration).
static void BM_InsertWithCovariancePropagation(benchmark::State& state) {
    const Frame f(size_t(state.range(0)));
    BinGrid grid = frameGrid();
    const BinUpdateParams params;
    PointsWithCov mapPts;
    for (auto _ : state) {
        f.propagator.apply(f.sensorPoints, mapPts);
        grid.beginCycle();
        benchmark::DoNotOptimize(grid.insertPoints(mapPts, params));
    }
    state.SetItemsProcessed(int64_t(state.iterations()) * state.range(0));
}
BENCHMARK(BM_InsertWithCovariancePropagation)->Arg(307200)->Unit(benchmark::kMillisecond);

// The same with BinGrid::insertSensorPoints: propagation and bin update fused block by block, so
// the 11 MB of map-frame points are never written out and read back.
static void BM_InsertSensorPointsFused(benchmark::State& state) {
    const Frame f(size_t(state.range(0)));
    BinGrid grid = frameGrid();
    const BinUpdateParams params;
    {  // The fused path must give the two-step result (bit-identical) before it is timed.
        BinGrid twoStep = frameGrid();
        twoStep.insertPoints(f.mapPoints, params);
        const InsertStats s = grid.insertSensorPoints(f.propagator, f.sensorPoints, params);
        const CellWindow& w = grid.window();
        size_t differ = grid.binCount() == twoStep.binCount() ? 0 : 1;
        for (int iy = w.iy0; iy < w.iy0 + w.ny; iy++)
            for (int ix = w.ix0; ix < w.ix0 + w.nx; ix++) {
                const Bin *a = grid.winningBin(ix, iy), *b = twoStep.winningBin(ix, iy);
                if (!a || !b) {
                    differ += (a != nullptr) != (b != nullptr);
                    continue;
                }
                differ += a->pointCount != b->pointCount || a->height_m != b->height_m ||
                          a->variance_m2 != b->variance_m2 || a->certainty != b->certainty;
            }
        if (differ != 0 || s.accepted == 0) {
            state.SkipWithError("fused insertion differs from apply() + insertPoints()");
            return;
        }
        grid = frameGrid();
    }
    for (auto _ : state) {
        grid.beginCycle();
        benchmark::DoNotOptimize(grid.insertSensorPoints(f.propagator, f.sensorPoints, params));
    }
    state.SetItemsProcessed(int64_t(state.iterations()) * state.range(0));
}
BENCHMARK(BM_InsertSensorPointsFused)->Arg(307200)->Unit(benchmark::kMillisecond);

// The same map-frame points into MRPT's CHeightGridMap2D (a plain running mean per cell).
static void BM_MrptHeightGridInsertIndividualPoint(benchmark::State& state) {
    const Frame f(size_t(state.range(0)));
    auto grid = mrptGridForFrame();
    for (auto _ : state) mrptInsert(grid, f.mapPoints);
    state.SetItemsProcessed(int64_t(state.iterations()) * state.range(0));
}
BENCHMARK(BM_MrptHeightGridInsertIndividualPoint)->Arg(307200)->Unit(benchmark::kMillisecond);

// The ratio in one loop: every iteration runs propagation + bin update (two steps, as the map
// does today), MRPT's insertion of the same points, and the fused path, each timed in thread CPU
// time, so machine noise hits all alike. Counters: throughput of each [points/s] and
// ratio = multibin / MRPT (target >= 0.3), ratio_fused likewise for the fused path.
static void BM_RatioToMrptSameLoop(benchmark::State& state) {
    const Frame f(size_t(state.range(0)));
    BinGrid grid = frameGrid();
    auto mrpt = mrptGridForFrame();
    const BinUpdateParams params;
    PointsWithCov mapPts;
    BinGrid fused = frameGrid();
    double tOurs = 0, tMrpt = 0, tFused = 0;
    for (auto _ : state) {
        const auto t0 = Clock::now();
        f.propagator.apply(f.sensorPoints, mapPts);
        grid.beginCycle();
        benchmark::DoNotOptimize(grid.insertPoints(mapPts, params));
        const auto t1 = Clock::now();
        mrptInsert(mrpt, f.mapPoints);
        const auto t2 = Clock::now();
        fused.beginCycle();
        benchmark::DoNotOptimize(fused.insertSensorPoints(f.propagator, f.sensorPoints, params));
        const auto t3 = Clock::now();
        tOurs += seconds(t0, t1);
        tMrpt += seconds(t1, t2);
        tFused += seconds(t2, t3);
    }
    const double n = double(state.iterations()) * double(state.range(0));
    state.counters["multibin_pts_per_s"] = n / tOurs;
    state.counters["mrpt_pts_per_s"] = n / tMrpt;
    state.counters["ratio"] = tMrpt / tOurs;
    state.counters["fused_pts_per_s"] = n / tFused;
    state.counters["ratio_fused"] = tMrpt / tFused;
}
BENCHMARK(BM_RatioToMrptSameLoop)->Arg(307200)->Unit(benchmark::kMillisecond);

// The visibility constraint's share of an update (bin update + constraint), timed separately in
// the same loop. Arg 0: a pitched-laser-like line of 683 points on a floor, sensor 0.26 m up;
// arg 1: the 640 x 480 frame, camera 0.48 m up; args 2 and 3: the same with one 0.25 m post
// stored far from every line of sight (before the local height bound, one tall bin anywhere
// made every ray walk until it cleared it). Counter `visibility_share` (target < 0.10).
static void BM_VisibilityShare(benchmark::State& state) {
    const bool frame = state.range(0) % 2 != 0, post = state.range(0) >= 2;
    BinGrid grid(kCell_m);
    BinUpdateParams params;
    const VisibilityParams vis;
    PointsWithCov pts;
    Eigen::Vector3d sensor;
    std::mt19937 rng(3);
    std::normal_distribution<float> noise(0.f, 0.002f);
    if (frame) {
        grid = frameGrid();
        const Frame f(640 * 480);
        pts = f.mapPoints;
        sensor = f.propagator.sensorOriginInMap_m();
    } else {
        grid.reset(kCell_m, CellWindow{-70, -70, 140, 140});
        pts.resize(683);
        for (size_t i = 0; i < pts.size(); i++) {
            const float a = -1.2f + 2.4f * float(i) / 682.f;
            pts[i].point_m = Eigen::Vector3f(0.26f * std::cos(a) + 0.3f, 0.6f * std::sin(a), 0.02f);
            pts[i].cov_m2 = {1e-6f, 0, 0, 1e-6f, 0, 4e-6f};
        }
        sensor = Eigen::Vector3d(0, 0, 0.26);
    }
    if (post) {
        InsertStats unused;
        const CellWindow& w = grid.window();
        grid.insertHeight(w.ix0 + 5, w.iy0 + 5, 0.25, 1e-6, params,
                          std::numeric_limits<double>::infinity(), unused);
    }
    double tUpdate = 0, tVis = 0;
    size_t cells = 0, cellsVisited = 0;
    for (auto _ : state) {
        if (!frame)
            for (auto& p : pts) p.point_m.z() = 0.02f + noise(rng);
        const auto t0 = Clock::now();
        grid.beginCycle();
        benchmark::DoNotOptimize(grid.insertPoints(pts, params));
        const auto t1 = Clock::now();
        const VisibilityStats vs = applyVisibilityConstraint(grid, sensor, vis, params);
        const auto t2 = Clock::now();
        cellsVisited = vs.cellsVisited;
        tUpdate += seconds(t0, t1);
        tVis += seconds(t1, t2);
        cells = grid.updatedCells().size();
    }
    state.counters["points"] = double(pts.size());
    state.counters["updated_cells"] = double(cells);
    state.counters["cells_visited"] = double(cellsVisited);
    state.counters["max_height_m"] = grid.maxHeight_m();
    state.counters["visibility_us"] = 1e6 * tVis / double(state.iterations());
    state.counters["bin_update_us"] = 1e6 * tUpdate / double(state.iterations());
    state.counters["visibility_share"] = tVis / (tUpdate + tVis);
}
BENCHMARK(BM_VisibilityShare)->DenseRange(0, 3)->Unit(benchmark::kMicrosecond);

// The visibility constraint's share of a dense camera frame over rocks (issue 32): a 2 x 2 m
// grid of 15 mm cells with 40 rocks (discs of 3-15 cm radius, 2-25 cm high) on a gently waving
// floor, seen by a camera 0.5 m up at one edge: four points in every cell of its 80-degree view
// that it sees (the line of sight from the camera passes above the terrain), 2 mm noise. The
// map is built from two such frames first; each iteration inserts the frame again and applies
// the constraint as the map does for a camera's frame (RayFan::Skip), timed apart in the same
// loop. Counter `visibility_share` (target <= 0.25).
static void BM_DenseFrameOverRocks(benchmark::State& state) {
    std::mt19937 rng(32);
    std::uniform_real_distribution<double> unit(0.0, 1.0);
    struct Rock {
        double x, y, r, h;
    };
    std::vector<Rock> rocks;
    for (int k = 0; k < 40; k++)
        rocks.push_back({0.3 + 1.6 * unit(rng), -0.9 + 1.8 * unit(rng), 0.03 + 0.12 * unit(rng),
                         0.02 + 0.23 * unit(rng)});
    auto ground = [&](double x, double y) {
        double z = 0.01 * std::sin(5 * x) * std::cos(4 * y);
        for (const Rock& r : rocks) {
            const double d = std::hypot(x - r.x, y - r.y);
            if (d < r.r) z = std::max(z, r.h * std::sqrt(1 - (d / r.r) * (d / r.r)));
        }
        return z;
    };
    // The terrain on a 5 mm raster over [-0.2, 2.2] x [-1.2, 1.2] m, for the lines of sight.
    constexpr double kRaster_m = 0.005, kX0_m = -0.2, kY0_m = -1.2;
    constexpr int kRasterN = 480;
    std::vector<float> raster(size_t(kRasterN) * kRasterN);
    for (int j = 0; j < kRasterN; j++)
        for (int i = 0; i < kRasterN; i++)
            raster[size_t(i + j * kRasterN)] =
                float(ground(kX0_m + (i + 0.5) * kRaster_m, kY0_m + (j + 0.5) * kRaster_m));
    auto rasterAt = [&](double x, double y) {
        const int i = std::clamp(int((x - kX0_m) / kRaster_m), 0, kRasterN - 1);
        const int j = std::clamp(int((y - kY0_m) / kRaster_m), 0, kRasterN - 1);
        return double(raster[size_t(i + j * kRasterN)]);
    };
    const Eigen::Vector3d camera(0.0, 0.0, 0.5);
    auto seen = [&](double x, double y, double z) {  // the line of sight above the terrain
        const double length = std::hypot(x - camera.x(), y - camera.y());
        for (double d = 0.01; d < length - 0.02; d += 0.005) {
            const double f = d / length;
            const double lx = x + (camera.x() - x) * f, ly = y + (camera.y() - y) * f;
            if (z + (camera.z() - z) * f < rasterAt(lx, ly) - 2e-3) return false;
        }
        return true;
    };
    BinGrid grid(kCell_m);
    grid.reset(kCell_m, CellWindow{-10, -67, 140, 134});
    PointsWithCov pts;
    std::normal_distribution<float> noise(0.f, 0.002f);
    const CellWindow& w = grid.window();
    for (int iy = w.iy0; iy < w.iy0 + w.ny; iy++)
        for (int ix = w.ix0; ix < w.ix0 + w.nx; ix++) {
            const double x = grid.cellCenter_m(ix), y = grid.cellCenter_m(iy);
            if (x < 0.2 || std::abs(std::atan2(y, x)) > 0.7) continue;
            for (int k = 0; k < 4; k++) {
                const double px = x + kCell_m * (unit(rng) - 0.5),
                             py = y + kCell_m * (unit(rng) - 0.5);
                const double pz = ground(px, py);
                if (!seen(px, py, pz)) continue;
                PointWithCov p;
                p.point_m = Eigen::Vector3f(float(px), float(py), float(pz) + noise(rng));
                p.cov_m2 = {1e-6f, 0, 0, 1e-6f, 0, 4e-6f};
                pts.push_back(p);
            }
        }
    BinUpdateParams params;
    VisibilityParams vis;
    vis.enabled = state.range(0) != 0;
    for (int k = 0; k < 2; k++) {  // the map so far
        grid.beginCycle();
        grid.insertPoints(pts, params);
        applyVisibilityConstraint(grid, camera, vis, params, RayFan::Skip);
    }
    double tUpdate = 0, tVis = 0;
    VisibilityStats vs;
    for (auto _ : state) {
        const auto t0 = Clock::now();
        grid.beginCycle();
        benchmark::DoNotOptimize(grid.insertPoints(pts, params));
        const auto t1 = Clock::now();
        vs = applyVisibilityConstraint(grid, camera, vis, params, RayFan::Skip);
        const auto t2 = Clock::now();
        tUpdate += seconds(t0, t1);
        tVis += seconds(t1, t2);
    }
    state.counters["points"] = double(pts.size());
    state.counters["updated_cells"] = double(grid.updatedCells().size());
    state.counters["rays"] = double(vs.raysCast);
    state.counters["bins_edited"] = double(vs.binsRemoved + vs.binsWeakened);
    state.counters["visibility_us"] = 1e6 * tVis / double(state.iterations());
    state.counters["bin_update_us"] = 1e6 * tUpdate / double(state.iterations());
    state.counters["visibility_share"] = tVis / (tUpdate + tVis);
}
BENCHMARK(BM_DenseFrameOverRocks)->Arg(1)->Arg(0)->Unit(benchmark::kMicrosecond);

// Moving the window by one cell on a full map of ny = 133 rows and nx columns (one bin per cell,
// refilled between moves outside the timing: manual time covers moveWindowTo only, with its
// leaver callback, the dual grid's write-back hook).
// - BM_MoveWindowOneCell/nx moves in x: 133 cells enter whatever nx is, so the time must stay
//   flat as the map grows 30-fold (nx 133 -> 4000);
// - BM_MoveWindowOneRow/nx moves in y: nx cells enter, so the time must grow with nx and the time
//   per entering cell stay flat.
static void moveWindowBenchmark(benchmark::State& state, bool alongX) {
    const int nx = int(state.range(0)), ny = 133;
    BinGrid grid(kCell_m);
    grid.reset(kCell_m, CellWindow{0, 0, nx, ny});
    const BinUpdateParams params;
    InsertStats stats;
    const double inf = std::numeric_limits<double>::infinity();
    for (int iy = 0; iy < ny; iy++)
        for (int ix = 0; ix < nx; ix++)
            grid.insertHeight(ix, iy, 0.01 * ((ix + iy) % 7), 1e-4, params, inf, stats);
    int x0 = 0, y0 = 0;
    size_t leavers = 0;
    for (auto _ : state) {
        (alongX ? x0 : y0) += 1;
        const auto t0 = Clock::now();
        grid.moveWindowTo(x0, y0, [&](int, int) { leavers++; });
        const auto t1 = Clock::now();
        state.SetIterationTime(seconds(t0, t1));
        // Refill the entering cells, so the next moves clear full cells again.
        if (alongX)
            for (int iy = y0; iy < y0 + ny; iy++)
                grid.insertHeight(x0 + nx - 1, iy, 0.01, 1e-4, params, inf, stats);
        else
            for (int ix = x0; ix < x0 + nx; ix++)
                grid.insertHeight(ix, y0 + ny - 1, 0.01, 1e-4, params, inf, stats);
    }
    const int entering = alongX ? ny : nx;
    state.counters["map_cells"] = double(nx) * ny;
    state.counters["entering_cells"] = entering;
    state.counters["leavers_per_move"] = double(leavers) / double(state.iterations());
    state.counters["ns_per_entering_cell"] =
        benchmark::Counter(double(entering) * double(state.iterations()) * 1e-9,
                           benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
}
static void BM_MoveWindowOneCell(benchmark::State& state) { moveWindowBenchmark(state, true); }
BENCHMARK(BM_MoveWindowOneCell)
    ->Arg(133)
    ->Arg(1000)
    ->Arg(4000)
    ->UseManualTime()
    ->Unit(benchmark::kMicrosecond);
static void BM_MoveWindowOneRow(benchmark::State& state) { moveWindowBenchmark(state, false); }
BENCHMARK(BM_MoveWindowOneRow)
    ->Arg(133)
    ->Arg(1000)
    ->Arg(4000)
    ->UseManualTime()
    ->Unit(benchmark::kMicrosecond);

// Memory of a 2 x 2 m grid at 15 mm (133 x 133 cells) after 200000 points. Arg 0: a floor, all
// points in one bin level; arg 1: the same points with each cell's height drawn from +-400 m
// (16000 bin levels spanned, one bin per cell as on the floor); arg 2: the floor plus a second
// bin in every cell (twice the observed bins). Memory must follow the observed bins (arg 2
// against 0) and ignore the vertical extent (arg 1 equal to 0). Counters [bytes]: total, per
// observed bin (including the 12 B per cell and the pool vector's spare capacity), per cell.
static void BM_Memory(benchmark::State& state) {
    const int mode = int(state.range(0));
    size_t bytes = 0, bins = 0, cells = 0;
    for (auto _ : state) {
        BinGrid grid(kCell_m);
        grid.reset(kCell_m, CellWindow{-66, -66, 133, 133});
        const BinUpdateParams params;
        std::mt19937 rng(5);
        std::uniform_real_distribution<float> u(-0.99f, 0.99f), z(0.0f, 0.04f);
        std::uniform_int_distribution<int> level(-8000, 7999);
        std::vector<int> cellLevel(grid.window().cellCount());
        for (int& l : cellLevel) l = level(rng);
        PointsWithCov pts;
        for (int i = 0; i < 200000; i++) {
            const float x = u(rng), y = u(rng);
            float h = z(rng);
            if (mode == 1) {  // this cell's own level, 5 cm bins
                const int ix = grid.cellIndex(x) + 66, iy = grid.cellIndex(y) + 66;
                h += 0.05f * float(cellLevel[size_t(ix) + 133 * size_t(iy)]);
            } else if (mode == 2 && i % 2) {
                h += 0.5f;  // a second bin, 0.5 m up
            }
            pts.push_back({Eigen::Vector3f(x, y, h), {1e-6f, 0, 0, 1e-6f, 0, 1e-6f}});
        }
        grid.insertPoints(pts, params);
        bytes = grid.memoryBytes();
        bins = grid.binCount();
        cells = grid.window().cellCount();
    }
    state.counters["sizeof_Bin"] = double(sizeof(Bin));
    state.counters["cells"] = double(cells);
    state.counters["bins"] = double(bins);
    state.counters["bytes"] = double(bytes);
    state.counters["bytes_per_bin"] = double(bytes) / double(bins);
}
BENCHMARK(BM_Memory)->Arg(0)->Arg(1)->Arg(2)->Iterations(1)->Unit(benchmark::kMillisecond);

/** Height queries at random points of a rough slope, 20 mm cells, 30 points a cell: /0 the cell's
 * value (surfaceAt, what cellHeight answers), /1 the sub-cell surface (heightAt, the planes of
 * the four cells around the point blended). Items: queries. */
static void BM_HeightQuery(benchmark::State& state) {
    const double cell_m = 0.02;
    BinGrid grid(cell_m);
    grid.reset(cell_m, CellWindow{0, 0, 50, 50});
    const BinUpdateParams params;
    std::mt19937 rng(9);
    std::uniform_real_distribution<double> u(0.0, 1.0);
    std::normal_distribution<double> n(0.0, 0.002);
    PointsWithCov pts;
    for (int i = 0; i < 30 * 2500; i++) {
        const double x = u(rng), y = u(rng);
        const double z = 0.3 * x + 0.02 * std::sin(20 * y) + n(rng);
        pts.push_back(
            {Eigen::Vector3f(float(x), float(y), float(z)), {1e-6f, 0, 0, 1e-6f, 0, 4e-6f}});
    }
    grid.insertPoints(pts, params);
    std::vector<std::pair<double, double>> queries(10000);
    for (auto& q : queries) q = {0.05 + 0.9 * u(rng), 0.05 + 0.9 * u(rng)};
    const bool subCell = state.range(0) == 1;
    for (auto _ : state) {
        double sum = 0;
        for (const auto& [x, y] : queries) {
            CellSurface s;
            const bool ok = subCell ? heightAt(grid, nullptr, x, y, params, true, s)
                                    : surfaceAt(grid, nullptr, x, y, params, true, s);
            sum += ok ? s.height_m : 0.0;
        }
        benchmark::DoNotOptimize(sum);
    }
    state.SetItemsProcessed(int64_t(state.iterations()) * int64_t(queries.size()));
}
BENCHMARK(BM_HeightQuery)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond);

BENCHMARK_MAIN();
