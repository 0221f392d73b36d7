/* A VLP-16 revolution through the map: the lidar sensor model alone, and sensor model plus
 * insertion (propagation, bin update, visibility constraint) through
 * CMultiBinElevationMap::insertObservation, on one core. The revolution is simulated: 16 rings
 * (elevations -15 to +15 deg in 2 deg steps) x 1875 azimuths = 30 000 returns from a sensor
 * 0.9 m above a flat floor inside a 16 x 16 m room with 3 m walls, as a CObservationPointCloud
 * labelled VELO with the lidar model. The map is grown by one insertion before timing (the steady
 * state of a run). Also MRPT's recorded VLP-16 scan (mrpt-common, 11 305 points), including
 * MRPT's point generation. Run e.g.:
 *   taskset -c 0 build/tests/bench/bench_lidar --benchmark_repetitions=5
 *       --benchmark_report_aggregates_only=true */
#include <benchmark/benchmark.h>
#include <mrpt/config/CConfigFileMemory.h>
#include <mrpt/maps/CMultiBinElevationMap.h>
#include <mrpt/maps/CSimplePointsMap.h>
#include <mrpt/obs/CObservationPointCloud.h>
#include <mrpt/obs/CObservationVelodyneScan.h>
#include <mrpt/obs/CRawlog.h>

#include <algorithm>
#include <cmath>
#include <limits>

#include "multibin/map/MapStatistics.h"
#include "multibin/sensors/LidarModel.h"
#include "multibin/sensors/RayModel.h"

using namespace multibin;
using namespace multibin::sensors;

namespace {
constexpr int kRings = 16, kAzimuths = 1875;
constexpr double kSensorHeight_m = 0.9, kHalfRoom_m = 8.0, kWall_m = 3.0;

/** The simulated revolution (sensor frame; +x forward, +z up). */
mrpt::obs::CObservationPointCloud vlp16Revolution() {
    mrpt::obs::CObservationPointCloud cloud;
    cloud.sensorLabel = "VELO";
    cloud.sensorPose = mrpt::poses::CPose3D(0, 0, kSensorHeight_m, 0, 0, 0);
    auto pts = mrpt::maps::CSimplePointsMap::Create();
    pts->reserve(kRings * kAzimuths);
    for (int ring = 0; ring < kRings; ring++) {
        const double el = (-15.0 + 2.0 * ring) * M_PI / 180.0;
        for (int k = 0; k < kAzimuths; k++) {
            const double az = 2 * M_PI * k / kAzimuths;
            const double dx = std::cos(el) * std::cos(az), dy = std::cos(el) * std::sin(az);
            const double dz = std::sin(el);
            // First hit: the floor (z = -height), a wall (|x| or |y| = half room), or the
            // ceiling height of the walls (no return: the point at the origin).
            double t = std::numeric_limits<double>::infinity();
            if (dz < 0) t = kSensorHeight_m / -dz;
            const double tWall = kHalfRoom_m / std::max(std::abs(dx), std::abs(dy));
            if (tWall < t && dz * tWall <= kWall_m - kSensorHeight_m) t = tWall;
            if (!std::isfinite(t)) t = 0;
            pts->insertPoint(float(t * dx), float(t * dy), float(t * dz));
        }
    }
    cloud.pointcloud = pts;
    return cloud;
}

mrpt::poses::CPose3DPDFGaussian robotPose() {
    mrpt::poses::CPose3DPDFGaussian pdf;
    const double s[6] = {0.02, 0.02, 0.01, 0.005, 0.003, 0.003};
    for (int i = 0; i < 6; i++) pdf.cov(i, i) = s[i] * s[i];
    return pdf;
}

std::unique_ptr<mrpt::maps::CMultiBinElevationMap> lidarMap() {
    mrpt::maps::CMultiBinElevationMap::TCreationOptions c;
    c.resolution_m = 0.05;
    auto map = std::make_unique<mrpt::maps::CMultiBinElevationMap>(c);
    mrpt::config::CConfigFileMemory ini("[s]\nsensor_models = VELO:lidar\n");
    map->insertionOptions.loadFromConfigFile(ini, "s");
    map->insertionOptions.max_elevation_uncertainty_m = 0.3;
    map->insertionOptions.fill.enabled = false;
    return map;
}

void BM_LidarModelVlp16Revolution(benchmark::State& state) {
    const auto cloud = vlp16Revolution();
    const LidarModelOptions opts;
    PointsWithCov out;
    for (auto _ : state) {
        LidarStats st;
        cloudToPoints(cloud, opts, 0.02, 20.0, out, st);
        benchmark::DoNotOptimize(out.data());
    }
    state.counters["points"] = double(out.size());
}
BENCHMARK(BM_LidarModelVlp16Revolution)->Unit(benchmark::kMillisecond);

/** Arg 1: with the visibility constraint (the default), arg 0: without. */
void BM_MapInsertVlp16Revolution(benchmark::State& state) {
    const auto cloud = vlp16Revolution();
    const auto pose = robotPose();
    auto map = lidarMap();
    map->insertionOptions.visibility.enabled = state.range(0) != 0;
    map->insertObservation(cloud, pose);  // grows the map: not timed
    const size_t before = map->statistics().insert.accepted;
    const VisibilityStats visBefore = map->statistics().visibility;
    for (auto _ : state) benchmark::DoNotOptimize(map->insertObservation(cloud, pose));
    const double n = double(state.iterations());
    const VisibilityStats& vis = map->statistics().visibility;
    state.counters["returns"] = double(cloud.pointcloud->size());
    state.counters["fused_per_scan"] = double(map->statistics().insert.accepted - before) / n;
    state.counters["rays"] = double(vis.raysCast - visBefore.raysCast) / n;
    state.counters["cells_tested"] = double(vis.cellsVisited - visBefore.cellsVisited) / n;
    state.counters["bins_removed"] = double(vis.binsRemoved - visBefore.binsRemoved) / n;
    state.counters["bins_weakened"] = double(vis.binsWeakened - visBefore.binsWeakened) / n;
}
BENCHMARK(BM_MapInsertVlp16Revolution)->Arg(1)->Arg(0)->Unit(benchmark::kMillisecond);

/** The same with visibility, arg: the insertion core's threads (insertion_threads), wall time:
 * 1 (on one core) against 2 (the two-stage pipeline; run on two free cores). */
void BM_MapInsertVlp16RevolutionThreads(benchmark::State& state) {
    const auto cloud = vlp16Revolution();
    const auto pose = robotPose();
    auto map = lidarMap();
    map->insertionOptions.insertion_threads = int(state.range(0));
    map->insertObservation(cloud, pose);  // grows the map: not timed
    for (auto _ : state) benchmark::DoNotOptimize(map->insertObservation(cloud, pose));
}
BENCHMARK(BM_MapInsertVlp16RevolutionThreads)
    ->Arg(1)
    ->Arg(2)
    ->UseRealTime()
    ->Unit(benchmark::kMillisecond);

/** MRPT's recorded VLP-16 scan, or null if mrpt-common is missing. */
mrpt::obs::CObservation::Ptr mrptVlp16Scan() {
    mrpt::obs::CRawlog rawlog;
    if (!rawlog.loadFromRawLogFile("/usr/share/mrpt/datasets/test_velodyne_VLP16.rawlog"))
        return {};
    auto scan = rawlog.getAsObservation(0);
    scan->sensorLabel = "VELO";
    return scan;
}

/** Arg 0: the lidar model alone (with MRPT's point generation); arg 1: through the map; arg 2:
 * through the map without the visibility constraint. */
void BM_MrptVlp16Scan(benchmark::State& state) {
    const auto scan = mrptVlp16Scan();
    if (!scan) {
        state.SkipWithError("mrpt-common's test_velodyne_VLP16.rawlog is missing");
        return;
    }
    const auto pose = robotPose();
    auto map = lidarMap();
    map->insertionOptions.max_range_m = 130.0;
    map->insertionOptions.visibility.enabled = state.range(0) != 2;
    map->insertObservation(*scan, pose);
    const auto& velodyne = dynamic_cast<const mrpt::obs::CObservationVelodyneScan&>(*scan);
    PointsWithCov out;
    for (auto _ : state) {
        if (state.range(0) == 0) {
            LidarStats st;
            velodyneScanToPoints(velodyne, LidarModelOptions(), 0.02, 130.0, out, st);
            benchmark::DoNotOptimize(out.data());
        } else {
            benchmark::DoNotOptimize(map->insertObservation(*scan, pose));
        }
    }
}
BENCHMARK(BM_MrptVlp16Scan)->Arg(0)->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond);

/** MRPT's recorded depth frame (mrpt-common's tests_rgbd.rawlog: 273 225 points of a wall and a
 * bookshelf, 1.6-2.6 m) through the map, the camera looking down from 1.5 m as in the test
 * MrptDatasets.RgbdFrameAsFloorHoldsThePlaneWithinThreeSigma, with a small pose covariance:
 * depth model, the frame-shared error per cell, propagation, bin update, visibility. Arg: the
 * insertion's threads (insertion_threads), wall time. */
void BM_MrptRgbdFrame(benchmark::State& state) {
    mrpt::obs::CRawlog rawlog;
    if (!rawlog.loadFromRawLogFile("/usr/share/mrpt/datasets/tests_rgbd.rawlog")) {
        state.SkipWithError("mrpt-common's tests_rgbd.rawlog is missing");
        return;
    }
    mrpt::obs::CObservation::Ptr frame;
    for (size_t i = 0; i < rawlog.size() && !frame; i++)
        if (rawlog.getType(i) == mrpt::obs::CRawlog::etObservation)
            frame = rawlog.getAsObservation(i);
    if (!frame) {
        state.SkipWithError("tests_rgbd.rawlog holds no observation");
        return;
    }
    frame->load();
    mrpt::maps::CMultiBinElevationMap map;
    map.insertionOptions.insertion_threads = int(state.range(0));
    mrpt::poses::CPose3DPDFGaussian pose = robotPose();
    pose.mean = mrpt::poses::CPose3D(0, 0, 1.5, 0, M_PI / 2, 0);
    map.insertObservation(*frame, pose);  // grows the map: not timed
    for (auto _ : state) benchmark::DoNotOptimize(map.insertObservation(*frame, pose));
    state.counters["fused"] =
        double(map.statistics().insert.accepted) / double(state.iterations() + 1);
}
BENCHMARK(BM_MrptRgbdFrame)->Arg(1)->Arg(2)->UseRealTime()->Unit(benchmark::kMillisecond);
}  // namespace

BENCHMARK_MAIN();
