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
#include "multibin/grid/BinGrid.h"
#include "multibin/io/EsriAsciiGrid.h"
#include "multibin/map/MapInternals.h"

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
    std::vector<multibin::test::QueryPointErrors> errors;
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
        for (const auto& e : errors) a.push_back(std::abs(e.error_m[k]));
        std::sort(a.begin(), a.end());
        auto q = [&](double f) { return 1e3 * a[size_t(f * (a.size() - 1))]; };
        std::printf("|error| [mm] %-9s median %.2f  p90 %.2f  p99 %.2f  max %.1f\n", names[k],
                    q(0.5), q(0.9), q(0.99), q(1.0));
    }
    // Where the squared error lies: by the truth's relief inside the point's cell (a cell on a
    // step holds two surfaces, and no height measured in the cell says where the step runs
    // where its foot was not seen).
    const double kReliefBounds_m[] = {0.01, 0.03, 0.1, INFINITY};
    double total[4] = {0, 0, 0, 0};
    for (const auto& e : errors)
        for (int k = 0; k < 4; k++) total[k] += e.error_m[k] * e.error_m[k];
    double lower_m = 0;
    for (double upper_m : kReliefBounds_m) {
        double se[4] = {0, 0, 0, 0};
        size_t n = 0;
        for (const auto& e : errors) {
            if (!(e.cellRelief_m >= lower_m && e.cellRelief_m < upper_m)) continue;
            n++;
            for (int k = 0; k < 4; k++) se[k] += e.error_m[k] * e.error_m[k];
        }
        std::printf(
            "cell relief %3.0f-%3.0f mm: %5.1f %% of points; RMSE [mm] (share of the "
            "squared error)",
            1e3 * lower_m, 1e3 * upper_m, 100.0 * n / errors.size());
        for (int k = 0; k < 4; k++)
            std::printf(" %s %.2f (%.0f %%)", names[k], n ? 1e3 * std::sqrt(se[k] / n) : 0.0,
                        100.0 * se[k] / total[k]);
        std::printf("\n");
        lower_m = upper_m;
    }
    // The cells of large relief (a step, a rock's flank): does heightAt take the right surface,
    // and where it is far off, was the true height measured in the cell at all (a bin of the
    // cell within 20 mm of the truth)? Where not, the surface there was hidden from the sensors.
    for (const double lower_m : {0.03, 0.1}) {
        const double upper_m = lower_m < 0.1 ? 0.1 : INFINITY;
        size_t n = 0, right = 0, far = 0, tooHigh = 0, measured = 0;
        for (const auto& e : errors) {
            if (!(e.cellRelief_m >= lower_m && e.cellRelief_m < upper_m)) continue;
            n++;
            right += std::abs(e.error_m[3]) < 0.01;
            if (std::abs(e.error_m[3]) <= 0.03) continue;
            far++;
            tooHigh += e.error_m[3] > 0;
            bool seen = false;
            for (const multibin::BinGrid* g :
                 {&multibin::MapInternals::grid(*map), &multibin::MapInternals::localGrid(*map)})
                g->forEachBin(g->cellIndex(e.x_m), g->cellIndex(e.y_m),
                              [&](const multibin::Bin& b) {
                                  seen |= std::abs(b.height_m - e.truth_m) < 0.02;
                              });
            measured += seen;
        }
        std::printf(
            "cells of relief %3.0f-%3.0f mm: %zu points; heightAt within 10 mm %zu, off by "
            "more than 30 mm %zu (%zu too high; %zu with a bin of their cell within 20 mm "
            "of the truth)\n",
            1e3 * lower_m, 1e3 * upper_m, n, right, far, tooHigh, measured);
    }
    // What heightAt would score if it matched the floor wherever the cell holds 30 mm of relief
    // or more (the steps and flanks that the sensors see from one side only).
    double mixed = 0;
    for (const auto& e : errors) {
        const double v = e.cellRelief_m >= 0.03 ? e.error_m[0] : e.error_m[3];
        mixed += v * v;
    }
    const double mixed_m = std::sqrt(mixed / errors.size());
    std::printf(
        "heightAt with the floor's error in cells of relief >= 30 mm: %.2f mm (%.3f x the "
        "floor)\n",
        1e3 * mixed_m, mixed_m / r.floor_m);
    return 0;
} catch (const std::exception& e) {
    std::cerr << "surface_accuracy: " << e.what() << "\n";
    return 1;
}
