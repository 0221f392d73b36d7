/* surface_accuracy: maps a simplemap with an ini's multiBinElevationMap and scores its heights at
 * random query points against a truth raster (bilinear in a finer raster than the map), as
 * doc/sub-cell-surface.md reports:
 *   surface_accuracy INI SIMPLEMAP TRUTH.asc XMIN,XMAX,YMIN,YMAX [POINTS [SEED]] */
#include <mrpt/config/CConfigFile.h>
#include <mrpt/maps/CMultiMetricMap.h>
#include <mrpt/maps/CSimpleMap.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <iostream>
#include <sstream>
#include <stdexcept>

#include "SurfaceAccuracy.h"
#include "multibin/io/EsriAsciiGrid.h"

using mrpt::maps::CMultiBinElevationMap;

int main(int argc, char** argv) try {
    if (argc < 5)
        throw std::invalid_argument(
            "usage: surface_accuracy INI SIMPLEMAP TRUTH.asc XMIN,XMAX,YMIN,YMAX [POINTS [SEED]]");
    mrpt::config::CConfigFile ini(argv[1]);
    mrpt::maps::TSetOfMetricMapInitializers inits;
    inits.loadFromConfigFile(ini, "MappingApplication");
    mrpt::maps::CMultiMetricMap maps(inits);
    const auto map = maps.mapByClass<CMultiBinElevationMap>();
    if (!map)
        throw std::runtime_error(std::string("ini '") + argv[1] + "' has no multiBinElevationMap");
    mrpt::maps::CSimpleMap sm;
    if (!sm.loadFromFile(argv[2]))
        throw std::runtime_error(std::string("cannot read simplemap '") + argv[2] + "'");
    map->insertSimpleMapWithPosePdfs(sm);
    map->flushLocalToGlobal();
    const multibin::EsriAsciiGrid truth = multibin::EsriAsciiGrid::load(argv[3]);
    double a[4];
    char c;
    std::istringstream area(argv[4]);
    if (!(area >> a[0] >> c >> a[1] >> c >> a[2] >> c >> a[3]))
        throw std::invalid_argument(std::string("area '") + argv[4] +
                                    "': want XMIN,XMAX,YMIN,YMAX [m]");
    const size_t points = argc > 5 ? std::stoul(argv[5]) : 20000;
    const unsigned seed = argc > 6 ? unsigned(std::stoul(argv[6])) : 1;
    std::vector<std::array<double, 4>> errors;
    const auto r = multibin::test::measureSurfaceAccuracy(
        *map, [&](double x, double y) { return truth.interpolate(x, y); }, a[0], a[1], a[2], a[3],
        points, seed, &errors);
    std::printf("cell %.3f m, %zu points (%zu drawn)\n", map->dem_get_resolution(), r.points,
                r.drawn);
    std::printf(
        "RMSE [mm]: floor (cell mean of the truth) %.2f | nearest (cell value) %.2f | "
        "bilinear of cell values %.2f | heightAt %.2f\n",
        1e3 * r.floor_m, 1e3 * r.nearest_m, 1e3 * r.bilinear_m, 1e3 * r.heightAt_m);
    std::printf(
        "heightAt / floor %.3f, heightAt / bilinear %.3f; within 3 sigma: heightAt %.4f, "
        "nearest %.4f\n",
        r.heightAt_m / r.floor_m, r.heightAt_m / r.bilinear_m, r.within3Sigma,
        r.nearestWithin3Sigma);
    // Where the error lies: percentiles of |error| per method.
    const char* names[4] = {"floor", "nearest", "bilinear", "heightAt"};
    for (int k = 0; k < 4; k++) {
        std::vector<double> a;
        for (const auto& e : errors) a.push_back(std::abs(e[k]));
        std::sort(a.begin(), a.end());
        auto q = [&](double f) { return 1e3 * a[size_t(f * (a.size() - 1))]; };
        std::printf("|error| [mm] %-9s median %.2f  p90 %.2f  p99 %.2f  max %.1f\n", names[k],
                    q(0.5), q(0.9), q(0.99), q(1.0));
    }
    return 0;
} catch (const std::exception& e) {
    std::cerr << "surface_accuracy: " << e.what() << "\n";
    return 1;
}
