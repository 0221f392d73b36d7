/* End-to-end benchmarks through mrpt::maps::CMultiBinElevationMap: one 683-beam laser scan, the
 * laser scans of the shipped mock-up (rough terrain, the mapper's workload), one
 * 640 x 480 stereo frame from a disparity image, one 640 x 480 frame of map-frame points, each
 * with the visibility constraint on and off (its share of the observation's update), and OpenCV
 * SGBM on a 640 x 480 crop of the Middlebury Aloe pair, reported separately. Run e.g.:
 *   build/tests/bench/bench_pipeline --benchmark_repetitions=5
 * --benchmark_report_aggregates_only=true The sensor models (laser, stereo) are measured as they
 * are in the tree at build time. */
#include <benchmark/benchmark.h>
#include <mrpt/config/CConfigFile.h>
#include <mrpt/config/CConfigFileMemory.h>
#include <mrpt/maps/CMultiBinElevationMap.h>
#include <mrpt/maps/CSimpleMap.h>
#include <mrpt/obs/CObservation2DRangeScan.h>
#include <mrpt/obs/CObservationStereoImages.h>

#include <cmath>
#include <random>
#include <utility>
#include <vector>

#include "multibin/geometry/PosePropagation.h"
#include "multibin/grid/BinGrid.h"
#include "multibin/map/MapInternals.h"
#include "multibin/map/MapStatistics.h"
#include "multibin/sensors/StereoDisparity.h"

using namespace multibin;

namespace {

mrpt::poses::CPose3DPDFGaussian robotPosePdf() {
    mrpt::poses::CPose3DPDFGaussian pdf;
    pdf.mean = mrpt::poses::CPose3D(0, 0, 0, 0, 0, 0);
    pdf.cov.setZero();
    for (int i = 0; i < 3; i++) pdf.cov(i, i) = 1e-6;  // 1 mm
    for (int i = 3; i < 6; i++) pdf.cov(i, i) = 3e-6;  // ~0.1 deg
    return pdf;
}

/** The paper's laser: Hokuyo URG-04LX, 683 beams 0.352 deg apart, 0.26 m above a floor, pitched
 * 45 deg down; ranges are the floor's, with 2 mm noise; beams that miss the floor within 4 m
 * have no return. */
mrpt::obs::CObservation2DRangeScan pitchedLaserOverFloor() {
    mrpt::obs::CObservation2DRangeScan scan;
    scan.sensorLabel = "LASER";
    constexpr size_t kBeams = 683;
    const double pitch = mrpt::DEG2RAD(45.0), height = 0.26;
    scan.aperture = float(kBeams * mrpt::DEG2RAD(0.352));
    scan.rightToLeft = true;
    scan.maxRange = 4.0f;
    scan.sensorPose = mrpt::poses::CPose3D(0.1, 0, height, 0, pitch, 0);
    scan.resizeScan(kBeams);
    std::mt19937 rng(11);
    std::normal_distribution<float> noise(0.f, 0.002f);
    for (size_t i = 0; i < kBeams; i++) {
        const double a = scan.getScanAngle(i);
        const double down = std::cos(a) * std::sin(pitch);  // downward component of the beam
        const double r = down > 1e-3 ? height / down : 1e9;
        const bool valid = r < scan.maxRange;
        scan.setScanRange(i, valid ? float(r) + noise(rng) : scan.maxRange);
        scan.setScanRangeValidity(i, valid);
    }
    return scan;
}

/** A rectified 640 x 480 pair (the paper's STOC-like geometry: f = 500 px, 9 cm baseline), camera
 * 0.48 m up pitched 35 deg down over a floor with a 0.2 m box, given as a disparity image (with
 * 0.2 px noise); no right image, so no matching runs. */
mrpt::obs::CObservationStereoImages stereoFrameOverFloor() {
    const int w = 640, h = 480;
    const double fx = 500, fy = 500, cx = 319.5, cy = 239.5, baseline = 0.09;
    const mrpt::poses::CPose3D camera(0, 0, 0.48, mrpt::DEG2RAD(-90.0), 0,
                                      mrpt::DEG2RAD(-90.0 - 35.0));
    sensors::DisparityImage disp(w, h);
    std::mt19937 rng(13);
    std::normal_distribution<float> noise(0.f, 0.2f);
    for (int v = 0; v < h; v++)
        for (int u = 0; u < w; u++) {
            const mrpt::math::TVector3D rayMap =
                camera.rotateVector(mrpt::math::TVector3D((u - cx) / fx, (v - cy) / fy, 1.0));
            if (rayMap.z >= -1e-3) continue;
            double t = 0.48 / -rayMap.z;  // camera-frame depth of the floor
            // A box 0.2 m high on x in [1.2, 1.5] m, |y| < 0.2 m: its top face.
            const double tTop = (0.48 - 0.2) / -rayMap.z;
            const double xTop = tTop * rayMap.x, yTop = tTop * rayMap.y;
            if (xTop > 1.2 && xTop < 1.5 && std::abs(yTop) < 0.2) t = tTop;
            if (t > 4) continue;
            disp.at(u, v) = float(baseline * fx / t) + noise(rng);
        }
    mrpt::obs::CObservationStereoImages obs;
    obs.sensorLabel = "STEREO";
    for (auto* cam : {&obs.leftCamera, &obs.rightCamera}) {
        cam->ncols = uint32_t(w);
        cam->nrows = uint32_t(h);
        cam->setIntrinsicParamsFromValues(fx, fy, cx, cy);
    }
    obs.rightCameraPose = mrpt::poses::CPose3DQuat(mrpt::poses::CPose3D(baseline, 0, 0, 0, 0, 0));
    obs.cameraPose = mrpt::poses::CPose3DQuat(camera);
    obs.hasImageDisparity = true;
    obs.imageDisparity = sensors::encodeDisparityImage(disp);
    obs.hasImageRight = false;
    return obs;
}

/** Runs `insert` (one observation) per iteration on a map that has already seen it once, so the
 * grid has its size; counters: bins and what the last insertion accepted. */
template <typename Insert>
void runMap(benchmark::State& state, mrpt::maps::CMultiBinElevationMap& map, Insert&& insert) {
    insert();  // warm-up: grows the grid to cover the data
    const size_t before = map.statistics().insert.accepted;
    for (auto _ : state) insert();
    state.counters["points_per_update"] =
        double(map.statistics().insert.accepted - before) / double(state.iterations());
    state.counters["bins"] = double(multibin::MapInternals::grid(map).binCount());
}

void setVisibility(mrpt::maps::CMultiBinElevationMap& map, benchmark::State& state) {
    map.insertionOptions.visibility.enabled = state.range(0) != 0;
    state.SetLabel(map.insertionOptions.visibility.enabled ? "visibility on" : "visibility off");
}

/** The observations of the shipped mock-up (rawlogs/mockup.simplemap, loaded into memory) with
 * their keyframe pose PDFs, in order; only the laser scans if `lasersOnly`. */
using ObservationsWithPdf =
    std::vector<std::pair<mrpt::obs::CObservation::Ptr, mrpt::poses::CPose3DPDFGaussian>>;
bool loadMockup(ObservationsWithPdf& out, bool lasersOnly) {
    mrpt::maps::CSimpleMap simplemap;
    if (!simplemap.loadFromFile(std::string(MULTIBIN_REFERENCE_DATA_DIR) + "/mockup.simplemap"))
        return false;
    mrpt::maps::CMultiBinElevationMap::forEachObservationWithPosePdf(
        simplemap,
        [&](const mrpt::obs::CObservation& obs, const mrpt::poses::CPose3DPDFGaussian& pdf) {
            if (lasersOnly && !dynamic_cast<const mrpt::obs::CObservation2DRangeScan*>(&obs))
                return;
            obs.load();
            out.emplace_back(
                std::dynamic_pointer_cast<mrpt::obs::CObservation>(obs.duplicateGetSmartPtr()),
                pdf);
        });
    return true;
}

/** A fresh map with these options fed every observation, in order. */
mrpt::maps::CMultiBinElevationMap mapObservations(
    const mrpt::maps::CMultiBinElevationMap::TCreationOptions& creation,
    const mrpt::maps::CMultiBinElevationMap::TInsertionOptions& insertion,
    const ObservationsWithPdf& observations) {
    mrpt::maps::CMultiBinElevationMap map(creation);
    map.insertionOptions = insertion;
    for (const auto& [obs, pdf] : observations) map.insertObservation(*obs, pdf);
    return map;
}
}  // namespace

// One 683-beam pitched laser scan end to end: laser model (intensity, mixed pixels, range
// sigma), eq 14 bound, propagation, bin update, visibility constraint (arg 1) or not (arg 0).
static void BM_LaserScanEndToEnd(benchmark::State& state) {
    mrpt::maps::CMultiBinElevationMap map;
    setVisibility(map, state);
    const auto scan = pitchedLaserOverFloor();
    const auto pdf = robotPosePdf();
    runMap(state, map, [&] { map.insertObservation(scan, pdf); });
}
BENCHMARK(BM_LaserScanEndToEnd)->Arg(1)->Arg(0)->Unit(benchmark::kMicrosecond);

// The laser scans of the shipped mock-up (rawlogs/mockup.simplemap: rocks and boards up to
// 0.13 m, the robot driving over them) with their keyframe pose PDFs, through a map configured as
// ini/mockup.ini does (its laser keys) with sensor_labels = LASER: the mapper's own workload,
// rough terrain instead of the floor above. One iteration maps every scan into a fresh map;
// counter `scans_per_s` (CPU time; us per scan = 1e6 / it).
static void BM_LaserScansMockup(benchmark::State& state) {
    ObservationsWithPdf scans;
    if (!loadMockup(scans, /*lasersOnly=*/true)) {
        state.SkipWithError("rawlogs/mockup.simplemap not found");
        return;
    }
    const mrpt::config::CConfigFileMemory ini(
        "[c]\nresolution = 0.015\nbin_height = 0.05\n"
        "[i]\nlaser_agc = LASER:512\nsensor_labels = LASER\nvisibility_constraint = " +
        std::string(state.range(0) != 0 ? "true" : "false") + "\n");
    mrpt::maps::CMultiBinElevationMap::TCreationOptions creation;
    creation.loadFromConfigFile(ini, "c");
    mrpt::maps::CMultiBinElevationMap::TInsertionOptions insertion;
    insertion.loadFromConfigFile(ini, "i");
    state.SetLabel(insertion.visibility.enabled ? "visibility on" : "visibility off");
    size_t accepted = 0, cellsVisited = 0, rays = 0;
    for (auto _ : state) {
        const auto map = mapObservations(creation, insertion, scans);
        accepted = map.statistics().insert.accepted;
        cellsVisited = map.statistics().visibility.cellsVisited;
        rays = map.statistics().visibility.raysCast;
    }
    state.counters["scans"] = double(scans.size());
    state.counters["points_per_scan"] = double(accepted) / double(scans.size());
    state.counters["rays_per_scan"] = double(rays) / double(scans.size());
    state.counters["cells_tested_per_ray"] = rays ? double(cellsVisited) / double(rays) : 0.0;
    state.counters["scans_per_s"] = benchmark::Counter(
        double(scans.size()) * double(state.iterations()), benchmark::Counter::kIsRate);
}
BENCHMARK(BM_LaserScansMockup)->Arg(1)->Arg(0)->Unit(benchmark::kMillisecond);

// Every observation of the shipped mock-up (203 laser scans and 21 stereo frames of 320 x 240,
// with their pose PDFs) into a map configured by ini/mockup.ini: the default run of
// elevation-mapper, whose report.json gives the same work as multibin's insert_s. One iteration
// maps everything into a fresh map.
static void BM_MockupAllObservations(benchmark::State& state) {
    ObservationsWithPdf observations;
    if (!loadMockup(observations, /*lasersOnly=*/false)) {
        state.SkipWithError("rawlogs/mockup.simplemap not found");
        return;
    }
    const mrpt::config::CConfigFile ini(std::string(MULTIBIN_REFERENCE_DATA_DIR) +
                                        "/../ini/mockup.ini");
    const std::string section = "MappingApplication_multiBinElevationMap_00_";
    mrpt::maps::CMultiBinElevationMap::TCreationOptions creation;
    creation.loadFromConfigFile(ini, section + "creationOpts");
    mrpt::maps::CMultiBinElevationMap::TInsertionOptions insertion;
    insertion.loadFromConfigFile(ini, section + "insertOpts");
    size_t accepted = 0;
    for (auto _ : state)
        accepted = mapObservations(creation, insertion, observations).statistics().insert.accepted;
    state.counters["observations"] = double(observations.size());
    state.counters["points"] = double(accepted);
}
BENCHMARK(BM_MockupAllObservations)->Unit(benchmark::kMillisecond);

// One 640 x 480 stereo frame end to end from its disparity image: halo and near-cluster filters,
// triangulation with the calibration covariance table (eqs 4-10), propagation, bin update,
// visibility (arg 1) or not (arg 0). Every pixel is used (stereo_subsample = 1).
static void BM_StereoFrameEndToEnd(benchmark::State& state) {
    mrpt::maps::CMultiBinElevationMap map;
    setVisibility(map, state);
    map.insertionOptions.sensors.stereo.subsample = int(state.range(1));
    const auto obs = stereoFrameOverFloor();
    const auto pdf = robotPosePdf();
    runMap(state, map, [&] { map.insertObservation(obs, pdf); });
}
BENCHMARK(BM_StereoFrameEndToEnd)
    ->Args({1, 1})
    ->Args({0, 1})
    ->Args({1, 2})
    ->Unit(benchmark::kMillisecond);

// The same frame, every pixel, with visibility; arg: the insertion core's threads
// (insertion_threads), wall time: 1 (one core) against 2 (the two-stage pipeline).
static void BM_StereoFrameThreads(benchmark::State& state) {
    mrpt::maps::CMultiBinElevationMap map;
    map.insertionOptions.sensors.stereo.subsample = 1;
    map.insertionOptions.insertion_threads = int(state.range(0));
    const auto obs = stereoFrameOverFloor();
    const auto pdf = robotPosePdf();
    runMap(state, map, [&] { map.insertObservation(obs, pdf); });
}
BENCHMARK(BM_StereoFrameThreads)->Arg(1)->Arg(2)->UseRealTime()->Unit(benchmark::kMillisecond);

// A 640 x 480 frame of points already in the map frame (propagated once beforehand) through the
// map's own insertion: bin update and visibility (arg 1) or bin update only (arg 0).
static void BM_MapFrameFromMapPoints(benchmark::State& state) {
    mrpt::maps::CMultiBinElevationMap map;
    setVisibility(map, state);
    // The disparity frame's floor, as sensor-frame points with a range-proportional covariance.
    const mrpt::poses::CPose3D camera(0, 0, 0.48, mrpt::DEG2RAD(-90.0), 0,
                                      mrpt::DEG2RAD(-90.0 - 35.0));
    PointsWithCov sensorPts;
    for (int v = 0; v < 480; v++)
        for (int u = 0; u < 640; u++) {
            const Eigen::Vector3d ray((u - 319.5) / 500, (v - 239.5) / 500, 1.0);
            const mrpt::math::TVector3D rm =
                camera.rotateVector(mrpt::math::TVector3D(ray.x(), ray.y(), ray.z()));
            if (rm.z >= -1e-3 || 0.48 / -rm.z > 4) continue;
            const Eigen::Vector3f p = (ray * (0.48 / -rm.z)).cast<float>();
            const float s = 0.002f * p.z() * p.z();
            PointWithCov q{p, {1e-6f, 0, 0, 1e-6f, 0, 1e-6f}};
            q.cov_m2.zz += s * s;
            sensorPts.push_back(q);
        }
    const PosePropagator prop(robotPosePdf(), camera);
    PointsWithCov mapPts;
    prop.apply(sensorPts, mapPts);
    // Size the grid once through an observation-free path: insertPoints does not grow, so use a
    // fixed extent covering the frame.
    map.creationOptions.grow = false;
    map.creationOptions.min_x = -0.5;
    map.creationOptions.max_x = 4.5;
    map.creationOptions.min_y = -3.5;
    map.creationOptions.max_y = 3.5;
    map.clear();
    const Eigen::Vector3d origin = prop.sensorOriginInMap_m();
    runMap(state, map, [&] {
        benchmark::DoNotOptimize(
            map.insertPoints(mapPts, std::numeric_limits<double>::infinity(), origin));
    });
    state.counters["points_in_frame"] = double(mapPts.size());
}
BENCHMARK(BM_MapFrameFromMapPoints)->Arg(1)->Arg(0)->Unit(benchmark::kMillisecond);

// OpenCV StereoSGBM (the project's stereo_sgbm_* defaults) on a 640 x 480 crop of the Middlebury
// Aloe pair: the matching step, reported separately from the mapping pipeline.
static void BM_StereoSgbm640x480(benchmark::State& state) {
    const std::string dir = std::string(MULTIBIN_REFERENCE_DATA_DIR) + "/stereo/middlebury-aloe/";
    mrpt::img::CImage left, right;
    if (!left.loadFromFile(dir + "aloeL.jpg") || !right.loadFromFile(dir + "aloeR.jpg")) {
        state.SkipWithError("Middlebury Aloe pair not found under rawlogs/stereo");
        return;
    }
    mrpt::img::CImage l, r;
    left.extract_patch(l, 300, 300, 640, 480);
    right.extract_patch(r, 300, 300, 640, 480);
    const sensors::StereoModelOptions opts;
    for (auto _ : state) benchmark::DoNotOptimize(sensors::computeDisparitySGBM(l, r, opts));
}
BENCHMARK(BM_StereoSgbm640x480)->Unit(benchmark::kMillisecond);

BENCHMARK_MAIN();
