/* Part of the multibin elevation-mapping library's tests.
 * route-scale: maps one route of RouteScene.h through CMultiBinElevationMap::insertObservation
 * (5 cm cells, defaults otherwise) and prints what scaling asks: points seen and fused, what was
 * refused and why, insertion time per point, peak memory of the process and the map's own, tiles,
 * and the serialized map's size. One route per process, so the peak memory is the route's.
 *
 *   route-scale LENGTH_M [SPACING_M [BUDGET_MB]]      e.g. route-scale 1000
 *
 * BUDGET_MB: memory_budget_mb (0: none); the peak while mapping is printed apart from the
 * process's peak, which includes saving the map (a read: every tile back in memory).
 *
 * scripts/evaluate-route-scale.sh runs it for 50, 200 and 1000 m (doc/route-scale.md). */
#include <mrpt/io/CFileGZOutputStream.h>
#include <mrpt/maps/CMultiBinElevationMap.h>
#include <mrpt/serialization/CArchive.h>
#include "multibin/grid/BinGrid.h"

#include <chrono>
#include <cstdio>
#include <fstream>
#include <iostream>
#include <stdexcept>
#include <string>

#include "RouteScene.h"
#include "multibin/map/MapInternals.h"
#include "multibin/map/MapStatistics.h"

namespace {
/** The process's peak resident memory [MB] (VmHWM). */
double peakResidentMB() {
    std::ifstream status("/proc/self/status");
    std::string line;
    while (std::getline(status, line))
        if (line.rfind("VmHWM:", 0) == 0) return std::stod(line.substr(6)) / 1024.0;
    return -1;
}
}  // namespace

int main(int argc, char** argv) {
    try {
        if (argc < 2)
            throw std::invalid_argument("usage: route-scale LENGTH_M [SPACING_M [BUDGET_MB]]");
        multibin::test::RouteOptions o;
        o.length_m = std::stod(argv[1]);
        if (argc > 2) o.spacing_m = std::stod(argv[2]);
        if (!(o.length_m > 0) || !(o.spacing_m > 0.005))
            throw std::invalid_argument("route-scale: LENGTH_M > 0 and SPACING_M > 0.005 m");
        mrpt::maps::CMultiBinElevationMap::TCreationOptions c;
        c.resolution_m = 0.05;
        if (argc > 3) c.memory_budget_mb = std::stod(argv[3]);
        mrpt::maps::CMultiBinElevationMap map(c);
        size_t seen = 0;
        double insert_s = 0;
        multibin::test::forEachRouteCloud(o, [&](const mrpt::obs::CObservationPointCloud& cloud,
                                                 const mrpt::poses::CPose3D& pose, size_t points) {
            const auto t0 = std::chrono::steady_clock::now();
            map.insertObservation(cloud, pose);
            insert_s +=
                std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
            seen += points;
        });
        const double mappingPeak_mb = peakResidentMB();
        const mrpt::maps::CMultiBinElevationMap::TileStoreStats tiles = map.tileStoreStats();
        const multibin::InsertStats& s = map.statistics().insert;
        const std::string file = "route-scale-" + std::string(argv[1]) + "m.mbmap.gz";
        {
            mrpt::io::CFileGZOutputStream out(file);
            mrpt::serialization::archiveFrom(out) << map;
        }
        std::ifstream written(file, std::ios::binary | std::ios::ate);
        const multibin::CellWindow& w = multibin::MapInternals::grid(map).window();
        std::printf(
            "route %.0f m: %zu clouds, %zu points; fused %zu, outside map %zu, too uncertain %zu, "
            "out of range %zu\n",
            o.length_m, multibin::test::routeCloudCount(o), seen, size_t(s.accepted),
            size_t(s.outsideMap), size_t(s.tooUncertain), size_t(s.outOfRange));
        std::printf("insertion %.3f s, %.1f ns per point\n", insert_s,
                    1e9 * insert_s / double(seen));
        std::printf(
            "window %d x %d cells (%.0f M), %zu tiles (%.1f M cells), %zu bins; map %.1f MB, "
            "process peak %.1f MB; file %.1f MB (%s)\n",
            w.nx, w.ny, double(w.cellCount()) / 1e6,
            multibin::MapInternals::grid(map).store().tileCount(),
            double(multibin::MapInternals::grid(map).store().tileCount() *
                   multibin::BinStore::kTileSlots) /
                1e6,
            multibin::MapInternals::grid(map).binCount(),
            double(multibin::MapInternals::grid(map).memoryBytes()) / 1e6, peakResidentMB(),
            double(written.tellg()) / 1e6, file.c_str());
        std::printf(
            "while mapping: process peak %.1f MB, grid peak %.1f MB; tiles written to disk %zu, "
            "read back %zu\n",
            mappingPeak_mb, double(tiles.peakResidentBytes) / 1e6, tiles.tilesWritten,
            tiles.tilesRead);
        std::remove(file.c_str());
        return 0;
    } catch (const std::exception& e) {
        std::cerr << "route-scale: " << e.what() << "\n";
        return 1;
    }
}
