/* Writing a sparse map's outputs against inserting it (issue 35: "no stage costs more than
 * insertion on a sparse map"). The map: a straight diagonal route of ROUTE m over rough ground,
 * a 4 m wide swath of 5 cm cells seen every 0.2 m (two points a cell per frame), inserted
 * through growToCoverPoints + insertPoints. Then each output on its own, and the dense path it
 * replaced (the four layers over the whole window), all in one run:
 *   build/tests/io/bench_outputs --benchmark_min_time=1x
 * The route's length is the benchmark's argument (metres). */
#include <benchmark/benchmark.h>
#include <mrpt/maps/CMultiBinElevationMap.h>
#include <mrpt/opengl/CSetOfObjects.h>

#include <cmath>
#include <filesystem>
#include <map>
#include <memory>

#include "multibin/geometry/Lattice.h"
#include "multibin/io/GeoTiff.h"
#include "multibin/io/MapLayerFiles.h"
#include "multibin/io/OutputFile.h"
#include "route_map.h"

namespace fs = std::filesystem;
using Map = mrpt::maps::CMultiBinElevationMap;

namespace {

using route_map::routeMap;

/** The map of each length, built once (after BM_Insert measured building it). */
Map& cachedMap(double length_m) {
    static std::map<double, std::unique_ptr<Map>> maps;
    auto& m = maps[length_m];
    if (!m) {
        m = routeMap(length_m);
        m->dem_update_map();
    }
    return *m;
}

fs::path scratch() {
    const fs::path d = fs::temp_directory_path() / "multibin_bench_outputs";
    fs::create_directories(d);
    return d;
}

void BM_Insert(benchmark::State& state) {
    size_t points = 0;
    for (auto _ : state) {
        auto map = routeMap(double(state.range(0)), &points);
        benchmark::DoNotOptimize(map.get());
    }
    state.counters["points"] = double(points);
}

void BM_Fill(benchmark::State& state) {
    for (auto _ : state) {
        state.PauseTiming();
        auto map = routeMap(double(state.range(0)));
        state.ResumeTiming();
        map->dem_update_map();
    }
}

void BM_OccupiedTiles(benchmark::State& state) {
    const Map& map = cachedMap(double(state.range(0)));
    size_t tiles = 0;
    for (auto _ : state) tiles = map.occupiedTiles(multibin::kGeoTiffTile).size();
    state.counters["tiles"] = double(tiles);
    state.counters["window_cells"] = double(map.dem_get_size_x() * map.dem_get_size_y());
}

void BM_GeoTiffFourLayers(benchmark::State& state) {
    const Map& map = cachedMap(double(state.range(0)));
    uintmax_t bytes = 0;
    const std::vector<multibin::MapLayer> all{multibin::MapLayer::Height, multibin::MapLayer::Sigma,
                                              multibin::MapLayer::Certainty,
                                              multibin::MapLayer::Source};
    std::vector<std::string> paths;
    for (const auto layer : all)
        paths.push_back(
            (scratch() / (std::string(multibin::mapLayerName(layer)) + ".tif")).string());
    for (auto _ : state)
        multibin::writeSparseGeoTiffs(
            multibin::tiledLayers(map, all), paths, std::vector<multibin::GeoTiffOptions>(4),
            [&](size_t k, const std::function<bool(const std::string&)>& write) {
                multibin::writeFileAtomically(paths[k], write);
            });
    for (const std::string& p : paths) bytes += fs::file_size(p);
    state.counters["bytes"] = double(bytes);
}

void BM_PreviewsThree(benchmark::State& state) {
    const Map& map = cachedMap(double(state.range(0)));
    size_t bytes = 0;
    for (auto _ : state) {
        const multibin::TiledRaster h = multibin::tiledLayer(map, multibin::MapLayer::Height);
        const std::vector<multibin::MapLayer> shown{
            multibin::MapLayer::Height, multibin::MapLayer::Sigma, multibin::MapLayer::Source};
        bytes = 0;
        for (const auto& png : multibin::layerPreviewPngs(
                 multibin::tiledLayers(map, shown, &h.tiles), shown, multibin::knownWindow(h, 5)))
            bytes += png.size();
    }
    state.counters["bytes"] = double(bytes);
}

void BM_Scene(benchmark::State& state) {
    const Map& map = cachedMap(double(state.range(0)));
    for (auto _ : state) {
        mrpt::opengl::CSetOfObjects scene;
        map.getVisualizationInto(scene);
        benchmark::DoNotOptimize(&scene);
    }
}

/** What the outputs did before: each layer over the whole window, then cropped. */
void BM_DenseLayersOverTheWindow(benchmark::State& state) {
    const Map& map = cachedMap(double(state.range(0)));
    for (auto _ : state)
        for (const auto layer : {multibin::MapLayer::Height, multibin::MapLayer::Sigma,
                                 multibin::MapLayer::Certainty, multibin::MapLayer::Source})
            benchmark::DoNotOptimize(map.toRaster(layer).heights_m.data());
}

}  // namespace

#define ROUTES ->Arg(50)->Arg(200)->Unit(benchmark::kMillisecond)->Iterations(1)
BENCHMARK(BM_Insert) ROUTES;
BENCHMARK(BM_Fill) ROUTES;
BENCHMARK(BM_OccupiedTiles) ROUTES;
BENCHMARK(BM_GeoTiffFourLayers) ROUTES;
BENCHMARK(BM_PreviewsThree) ROUTES;
BENCHMARK(BM_Scene) ROUTES;
BENCHMARK(BM_DenseLayersOverTheWindow) ROUTES;
BENCHMARK_MAIN();
