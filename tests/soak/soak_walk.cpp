/* Soak: a long simulated walk over tiled LittleDog boards with the dual grid scrolling.
 *
 * Benchmark-style program (not a ctest test, not in CI; see doc/reliability.md). terrain-sim's
 * classes simulate one pass of the hexapod walk over the boards (laser at 10 Hz, stereo with a
 * disparity image at 1 Hz); the pass is then repeated end to end, each repetition shifted forward
 * by the pass length in the map frame, so the robot walks on and on in +x over an endless row of
 * boards while the local (2 m) and global (10 m) grids follow it. Every observation is inserted
 * with its estimated pose PDF.
 *
 * Each minute of robot time it prints: observations, points fused, CPU and wall time spent in
 * insertObservation(), points per CPU second, resident memory, the grids' own memory and bin
 * counts; every `--check-every` seconds of robot time it scans every bin of both grids for a
 * non-finite height, a negative or non-finite variance or certainty. At the end it checks:
 *   - memory flat once full: resident memory and grid memory over the last minutes within 5 % of
 *     their value when the global grid first filled (minute 3, after 18 m of walk at 0.1 m/s);
 *   - no invalid cell ever;
 *   - throughput (points per CPU second) in the last minute within 20 % of the first.
 * Exit code 0 if all hold, 2 otherwise.
 *
 *   soak_walk [--minutes 10] [--speed 0.1] [--tiles 6x2] [--seed 1] [--check-every 10]
 *             [--boards DIR]   (default the source tree's rawlogs/terrain/littledog) */
#include <mrpt/config/CConfigFileMemory.h>
#include <mrpt/maps/CMultiBinElevationMap.h>

#include <unistd.h>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "LaserSim.h"
#include "Scenario.h"
#include "StereoSim.h"
#include "SurfaceTexture.h"
#include "Terrain.h"
#include "Trajectory.h"
#include "multibin/grid/BinGrid.h"
#include "multibin/map/MapInternals.h"
#include "multibin/map/MapStatistics.h"

namespace fs = std::filesystem;
using mrpt::maps::CMultiBinElevationMap;

namespace {

double threadCpu_s() {
    timespec ts{};
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
    return double(ts.tv_sec) + 1e-9 * double(ts.tv_nsec);
}

double residentMemory_MB() {
    std::ifstream f("/proc/self/statm");
    long pages = 0, resident = 0;
    f >> pages >> resident;
    return double(resident) * double(sysconf(_SC_PAGESIZE)) / 1e6;
}

struct CellCheck {
    size_t bins = 0, invalid = 0;
};

/** Every bin of both grids: finite height, finite variance >= 0, finite certainty >= 0. */
CellCheck checkCells(const CMultiBinElevationMap& map) {
    CellCheck c;
    for (const multibin::BinGrid* g :
         {&multibin::MapInternals::grid(map), &multibin::MapInternals::localGrid(map)}) {
        const multibin::CellWindow& w = g->window();
        for (int iy = w.iy0; iy < w.iy0 + w.ny; iy++)
            for (int ix = w.ix0; ix < w.ix0 + w.nx; ix++)
                g->forEachBin(ix, iy, [&](const multibin::Bin& b) {
                    c.bins++;
                    const bool ok = std::isfinite(b.height_m) && std::isfinite(b.variance_m2) &&
                                    b.variance_m2 >= 0 && std::isfinite(b.certainty) &&
                                    b.certainty >= 0;
                    c.invalid += !ok;
                });
    }
    return c;
}

struct Minute {
    size_t observations = 0, points = 0;
    double cpu_s = 0, wall_s = 0;
    double rss_MB = 0, grid_MB = 0;
    size_t localBins = 0, globalBins = 0;
};

/** One pass of the walk, simulated once: per frame the estimated pose and its observations. */
struct PassFrame {
    double t_s;
    mrpt::poses::CPose3DPDFGaussian estimate;
    mrpt::obs::CObservation::Ptr laser, stereo;
};

}  // namespace

int main(int argc, char** argv) {
    double minutes = 10, speed_mps = 0.1, checkEvery_s = 10;
    int tilesX = 6, tilesY = 2;
    uint64_t seed = 1;
    std::string boardsDir =
        (fs::path(MULTIBIN_REFERENCE_DATA_DIR) / "terrain" / "littledog").string();
    for (int i = 1; i + 1 < argc; i += 2) {
        const std::string a = argv[i], v = argv[i + 1];
        if (a == "--minutes")
            minutes = std::stod(v);
        else if (a == "--speed")
            speed_mps = std::stod(v);
        else if (a == "--check-every")
            checkEvery_s = std::stod(v);
        else if (a == "--seed")
            seed = std::stoull(v);
        else if (a == "--boards")
            boardsDir = v;
        else if (a == "--tiles" && std::sscanf(v.c_str(), "%dx%d", &tilesX, &tilesY) == 2)
            continue;
        else {
            std::fprintf(stderr, "soak_walk: unknown argument '%s'\n", a.c_str());
            return 1;
        }
    }

    // --- One pass of the walk, simulated with terrain-sim's classes -------------------------
    terrain_sim::ScenarioConfig cfg;
    for (const char* b : {"B", "X1", "W", "AC", "CC", "CD"})
        cfg.terrainFiles.push_back((fs::path(boardsDir) / (std::string(b) + ".asc")).string());
    cfg.tilesX = tilesX;
    cfg.tilesY = tilesY;
    cfg.seed = seed;
    cfg.scenario = "walk";
    cfg.trajectory.walkSpeed_mps = speed_mps;
    std::vector<multibin::EsriAsciiGrid> boards;
    for (const auto& f : cfg.terrainFiles) boards.push_back(multibin::EsriAsciiGrid::load(f));
    const auto terrain = terrain_sim::Terrain::fromBoards(boards, tilesX, tilesY, cfg.margin_m);
    const terrain_sim::SurfaceTexture texture(terrain, seed, cfg.darkPatches);
    const terrain_sim::LaserSim laser(cfg.laser, terrain, texture, seed);
    const terrain_sim::StereoSim stereo(cfg.stereo, terrain, texture);
    std::mt19937_64 poseRng(terrain_sim::hash64(seed * 3 + 1)),
        laserRng(terrain_sim::hash64(seed * 3 + 2)), stereoRng(terrain_sim::hash64(seed * 3 + 3));
    const auto frames = terrain_sim::walkTrajectory(terrain, cfg.trajectory, poseRng);
    std::vector<PassFrame> pass;
    const auto simStart = std::chrono::steady_clock::now();
    for (const auto& f : frames) {
        PassFrame p{f.t_s, f.estimate, nullptr, nullptr};
        p.laser = laser.scan(f.truth, terrain_sim::syntheticStamp(f.t_s), laserRng);
        if (f.stereo)
            p.stereo = stereo.observation(stereo.render(f.truth, stereoRng),
                                          terrain_sim::syntheticStamp(f.t_s));
        pass.push_back(p);
    }
    const double period_s = 1.0 / cfg.trajectory.laserRate_hz;
    const double passDuration_s = pass.back().t_s - pass.front().t_s + period_s;
    const double passLength_m = speed_mps * passDuration_s;
    std::printf(
        "soak_walk: %dx%d boards (%.2f m tiles), one pass %.1f s / %.2f m, %zu frames, simulated "
        "in %.1f s; walking %.1f min of robot time at %.2f m/s with the dual grid\n",
        tilesX, tilesY, terrain.tileSide_m(), passDuration_s, passLength_m, pass.size(),
        std::chrono::duration<double>(std::chrono::steady_clock::now() - simStart).count(), minutes,
        speed_mps);

    // --- The map: the scenario's sensor options, dual grid with the paper's sizes ------------
    CMultiBinElevationMap::TCreationOptions creation;
    creation.dual_grid = true;  // local 2 m at 15 mm, global 10 m at 50 mm (defaults)
    CMultiBinElevationMap map(creation);
    {
        mrpt::config::CConfigFileMemory ini(terrain_sim::mapperIni(cfg));
        map.insertionOptions.loadFromConfigFile(
            ini, "MappingApplication_multiBinElevationMap_00_insertOpts");
    }

    // --- Walk --------------------------------------------------------------------------------
    const double total_s = minutes * 60.0;
    std::vector<Minute> perMinute(size_t(std::ceil(minutes)));
    size_t invalidEver = 0, checks = 0, maxBins = 0;
    double nextCheck_s = 0;
    std::printf("%6s %6s %9s %8s %8s %10s %8s %8s %9s %9s\n", "minute", "obs", "points", "cpu_s",
                "wall_s", "points/cpu", "rss_MB", "grid_MB", "local_bins", "glob_bins");
    for (size_t rep = 0;; rep++) {
        const double dt_s = double(rep) * passDuration_s;
        const double dx_m = double(rep) * passLength_m;
        bool done = false;
        for (const PassFrame& f : pass) {
            const double t_s = f.t_s - pass.front().t_s + dt_s;
            if (t_s >= total_s) {
                done = true;
                break;
            }
            Minute& m = perMinute[size_t(t_s / 60.0)];
            mrpt::poses::CPose3DPDFGaussian pdf = f.estimate;
            pdf.mean.x(pdf.mean.x() + dx_m);
            const auto stamp = terrain_sim::syntheticStamp(t_s);
            for (const auto& obs : {f.laser, f.stereo}) {
                if (!obs) continue;
                obs->timestamp = stamp;
                const size_t before = map.statistics().insert.accepted;
                const double c0 = threadCpu_s();
                const auto w0 = std::chrono::steady_clock::now();
                map.insertObservation(*obs, pdf);
                m.cpu_s += threadCpu_s() - c0;
                m.wall_s +=
                    std::chrono::duration<double>(std::chrono::steady_clock::now() - w0).count();
                m.points += map.statistics().insert.accepted - before;
                m.observations++;
            }
            if (t_s >= nextCheck_s) {
                const CellCheck c = checkCells(map);
                invalidEver += c.invalid;
                maxBins = std::max(maxBins, c.bins);
                checks++;
                nextCheck_s += checkEvery_s;
            }
            m.rss_MB = residentMemory_MB();
            m.grid_MB = double(multibin::MapInternals::grid(map).memoryBytes() +
                               multibin::MapInternals::localGrid(map).memoryBytes()) /
                        1e6;
            m.localBins = multibin::MapInternals::localGrid(map).binCount();
            m.globalBins = multibin::MapInternals::grid(map).binCount();
        }
        if (done) break;
    }
    for (size_t i = 0; i < perMinute.size(); i++) {
        const Minute& m = perMinute[i];
        std::printf("%6zu %6zu %9zu %8.2f %8.2f %10.0f %8.1f %8.1f %9zu %9zu\n", i + 1,
                    m.observations, m.points, m.cpu_s, m.wall_s, m.points / m.cpu_s, m.rss_MB,
                    m.grid_MB, m.localBins, m.globalBins);
    }
    const CellCheck last = checkCells(map);
    invalidEver += last.invalid;
    checks++;

    // --- Verdicts ----------------------------------------------------------------------------
    bool ok = true;
    const size_t full = std::min<size_t>(2, perMinute.size() - 1);  // minute 3: global grid full
    double rssMax = 0, gridMax = 0;
    for (size_t i = full; i < perMinute.size(); i++) {
        rssMax = std::max(rssMax, perMinute[i].rss_MB);
        gridMax = std::max(gridMax, perMinute[i].grid_MB);
    }
    const double rssGrowth = rssMax / perMinute[full].rss_MB - 1;
    const double gridGrowth = gridMax / perMinute[full].grid_MB - 1;
    const bool memFlat = rssGrowth <= 0.05 && gridGrowth <= 0.05;
    std::printf(
        "memory: resident %.1f MB at minute %zu, max %.1f MB after (%+.1f %%); grids %.1f "
        "MB, max %.1f MB (%+.1f %%): %s\n",
        perMinute[full].rss_MB, full + 1, rssMax, 100 * rssGrowth, perMinute[full].grid_MB, gridMax,
        100 * gridGrowth, memFlat ? "flat" : "GROWING");
    ok &= memFlat;
    std::printf(
        "cells: %zu checks (every %.0f s of robot time, up to %zu bins), invalid bins "
        "(NaN height, negative or NaN variance/certainty): %zu\n",
        checks, checkEvery_s, maxBins, invalidEver);
    ok &= invalidEver == 0;
    const Minute &first = perMinute.front(), &lastMin = perMinute.back();
    const double tFirst = first.points / first.cpu_s, tLast = lastMin.points / lastMin.cpu_s;
    const double change = tLast / tFirst - 1;
    const bool steady = std::abs(change) <= 0.20;
    std::printf(
        "throughput: first minute %.0f points/cpu-s (%.0f obs/cpu-s), last minute %.0f "
        "points/cpu-s (%.0f obs/cpu-s): %+.1f %% %s\n",
        tFirst, first.observations / first.cpu_s, tLast, lastMin.observations / lastMin.cpu_s,
        100 * change, steady ? "(within 20 %)" : "(OUTSIDE 20 %)");
    ok &= steady;
    const auto& s = map.statistics().insert;
    std::printf(
        "map: %zu points fused, %zu rejected; visibility constraint removed %zu bins, "
        "weakened %zu\n",
        s.accepted, s.rejected(), map.statistics().visibility.binsRemoved,
        map.statistics().visibility.binsWeakened);
    std::printf("soak_walk: %s\n", ok ? "PASS" : "FAIL");
    return ok ? 0 : 2;
}
