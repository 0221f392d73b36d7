/* The outputs of a long sparse route (doc/user-guide.md, "Long routes"): builds route_map's
 * diagonal route of LENGTH metres, fills it, writes saveMetricMapRepresentationToFile(PREFIX) and
 * prints each stage's time and each file's size beside the window's dense size:
 *   build/tests/io/route_outputs 200 /tmp/route200/o */
#include <cstdio>
#include <ctime>
#include <filesystem>
#include <string>

#include "route_map.h"

namespace fs = std::filesystem;

int main(int argc, char** argv) {
    if (argc != 3) {
        std::fprintf(stderr, "usage: route_outputs LENGTH_M PREFIX\n");
        return 1;
    }
    const double length_m = std::stod(argv[1]);
    const fs::path prefix = argv[2];
    fs::create_directories(prefix.parent_path().empty() ? "." : prefix.parent_path());
    // Processor time of this process: the machine may be shared (the insertion's helper thread
    // counts too).
    const auto seconds = [](std::clock_t t0) { return double(std::clock() - t0) / CLOCKS_PER_SEC; };
    auto t0 = std::clock();
    size_t points = 0;
    const auto map = route_map::routeMap(length_m, &points);
    const double insert_s = seconds(t0);
    t0 = std::clock();
    map->dem_update_map();
    const double fill_s = seconds(t0);
    t0 = std::clock();
    map->saveMetricMapRepresentationToFile(prefix.string());
    const double write_s = seconds(t0);
    const size_t window = map->dem_get_size_x() * map->dem_get_size_y();
    std::printf("route %.0f m: %zu points; window %zu x %zu cells (a float raster: %.1f MB)\n",
                length_m, points, map->dem_get_size_x(), map->dem_get_size_y(), window * 4e-6);
    std::printf(
        "processor time: insertion %.2f s, fill %.2f s, "
        "saveMetricMapRepresentationToFile %.2f s\n",
        insert_s, fill_s, write_s);
    const std::string stem = prefix.filename().string();
    for (const auto& e :
         fs::directory_iterator(prefix.parent_path().empty() ? "." : prefix.parent_path()))
        if (e.path().filename().string().rfind(stem, 0) == 0)
            std::printf("  %-24s %9.1f kB\n", e.path().filename().c_str(),
                        fs::file_size(e.path()) / 1e3);
    return 0;
}
