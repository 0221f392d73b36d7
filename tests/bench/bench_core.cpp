/* Benchmarks of the insertion core, the moving window and the visibility constraint.
 * Build in Release (the default) and run: build/tests/bench/bench_core */
#include <benchmark/benchmark.h>
#include <mrpt/maps/CHeightGridMap2D.h>
#include <mrpt/maps/CMultiBinElevationMap.h>

#include <random>

#include "multibin/BinGrid.h"
#include "multibin/PosePropagation.h"
#include "multibin/VisibilityConstraint.h"

using namespace multibin;

namespace {
/** A stereo-frame-like cloud in the sensor frame: one point per pixel of a w x h image, in
 * image order, on a rough surface 1-3 m ahead (neighbouring pixels land in neighbouring cells,
 * as in real frames). */
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
            const float range = 0.48f / -dir.z() * (1.f + rough(rng));
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
}  // namespace

// Points with full covariance propagation (pose + sensor) and the bin update, one core.
static void BM_InsertWithCovariancePropagation(benchmark::State& state) {
    const PointsWithCov sensorPts = makeSensorPoints(size_t(state.range(0)));
    const PosePropagator prop(robotPose(), mrpt::poses::CPose3D(0, 0, 0.48, 0, 0, 0));
    BinGrid grid(0.015);
    grid.reset(0.015, CellWindow{-100, -300, 400, 400});
    BinUpdateParams params;
    PointsWithCov mapPts;
    for (auto _ : state) {
        prop.apply(sensorPts, mapPts);
        grid.beginCycle();
        benchmark::DoNotOptimize(grid.insertPoints(mapPts, params));
    }
    state.SetItemsProcessed(int64_t(state.iterations()) * state.range(0));
}
BENCHMARK(BM_InsertWithCovariancePropagation)->Arg(307200)->Unit(benchmark::kMillisecond);

// The same map-frame points into MRPT's CHeightGridMap2D (a plain running mean per cell).
static void BM_MrptHeightGridInsertIndividualPoint(benchmark::State& state) {
    const PointsWithCov sensorPts = makeSensorPoints(size_t(state.range(0)));
    const PosePropagator prop(robotPose(), mrpt::poses::CPose3D(0, 0, 0.48, 0, 0, 0));
    PointsWithCov mapPts;
    prop.apply(sensorPts, mapPts);
    mrpt::maps::CHeightGridMap2D grid(mrpt::maps::CHeightGridMap2D::mrSimpleAverage, -1.5, 4.5,
                                      -4.5, 1.5, 0.015);
    mrpt::maps::CHeightGridMap2D_Base::TPointInsertParams ip;
    ip.update_map_after_insertion = false;
    for (auto _ : state)
        for (const auto& p : mapPts)
            grid.insertIndividualPoint(p.point_m.x(), p.point_m.y(), p.point_m.z(), ip);
    state.SetItemsProcessed(int64_t(state.iterations()) * state.range(0));
}
BENCHMARK(BM_MrptHeightGridInsertIndividualPoint)->Arg(307200)->Unit(benchmark::kMillisecond);

// Moving a full N x N map by one cell: the cost follows the N entering cells, not the N^2 cells.
static void BM_MoveWindowOneCell(benchmark::State& state) {
    const int n = int(state.range(0));
    BinGrid grid(0.015);
    grid.reset(0.015, CellWindow{0, 0, n, n});
    BinUpdateParams params;
    InsertStats stats;
    for (int iy = 0; iy < n; iy++)
        for (int ix = 0; ix < n; ix++)
            grid.insertHeight(ix, iy, 0.01 * ((ix + iy) % 7), 1e-4, params,
                              std::numeric_limits<double>::infinity(), stats);
    int x0 = 0;
    for (auto _ : state) {
        x0 += 1;
        grid.moveWindowTo(x0, 0);
    }
    state.counters["entering_cells"] = n;
    state.counters["ns_per_entering_cell"] =
        benchmark::Counter(double(n) * double(state.iterations()) * 1e-9,
                           benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
}
BENCHMARK(BM_MoveWindowOneCell)->Arg(133)->Arg(400)->Arg(1600)->Unit(benchmark::kMicrosecond);

// One pitched-laser-like cycle (683 points on a line across the grid) with and without the
// visibility constraint: the constraint's share of the update.
static void BM_LaserCycle(benchmark::State& state) {
    const bool visibility = state.range(0) != 0;
    BinGrid grid(0.015);
    grid.reset(0.015, CellWindow{-70, -70, 140, 140});
    BinUpdateParams params;
    VisibilityParams vis;
    std::mt19937 rng(3);
    std::normal_distribution<float> noise(0.f, 0.002f);
    PointsWithCov scan(683);
    for (size_t i = 0; i < scan.size(); i++) {
        const float a = -1.2f + 2.4f * float(i) / 682.f;
        scan[i].point_m = Eigen::Vector3f(0.26f * std::cos(a) + 0.3f, 0.6f * std::sin(a), 0.02f);
        scan[i].cov_m2 = {1e-6f, 0, 0, 1e-6f, 0, 4e-6f};
    }
    const Eigen::Vector3d sensor(0, 0, 0.26);
    for (auto _ : state) {
        for (auto& p : scan) p.point_m.z() = 0.02f + noise(rng);
        grid.beginCycle();
        grid.insertPoints(scan, params);
        if (visibility)
            benchmark::DoNotOptimize(applyVisibilityConstraint(grid, sensor, vis, params));
    }
    state.SetItemsProcessed(int64_t(state.iterations()) * 683);
}
BENCHMARK(BM_LaserCycle)->Arg(0)->Arg(1)->Unit(benchmark::kMicrosecond);

BENCHMARK_MAIN();
