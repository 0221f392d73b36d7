/* The map on stereo alone against the pipeline a user would write without it: OpenCV StereoSGBM
 * with the library's default parameters, every pixel triangulated, the points averaged in MRPT's
 * CHeightGridMap2D (mrSimpleAverage) at the map's cell size. Both scored against the ground truth
 * of a terrain-sim scenario on the cells both hold. Used by tests/bench/compare_stereo_naive (the
 * table in doc/sensor-models.md) and by the CI guard in test_StereoNaive.cpp. */
#pragma once

#include <mrpt/config/CConfigFile.h>
#include <mrpt/io/CFileGZInputStream.h>
#include <mrpt/maps/CHeightGridMap2D.h>
#include <mrpt/maps/CMultiBinElevationMap.h>
#include <mrpt/maps/CSimpleMap.h>
#include <mrpt/obs/CObservationStereoImages.h>
#include <mrpt/poses/CPose3DPDF.h>
#include <mrpt/serialization/CArchive.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>

#include "NaiveStereo.h"
#include "multibin/io/EsriAsciiGrid.h"

namespace stereo_naive {

struct Score {
    size_t truthCells = 0;     //!< cells with a finite truth
    size_t naiveCells = 0;     //!< of those, held by the naive grid
    size_t mapCells = 0;       //!< of those, held by the map
    size_t commonCells = 0;    //!< held by both
    double naiveSumSq_m2 = 0;  //!< on the common cells
    double mapSumSq_m2 = 0;
    size_t mapWithin3Sigma = 0;         //!< common cells whose truth is within 3 sigma of the map
    size_t naiveGood = 0, mapGood = 0;  //!< cells held within kGood_m of the truth (all held)
    static constexpr double kGood_m = 0.03;
    double naiveRmse_m() const { return std::sqrt(naiveSumSq_m2 / double(commonCells)); }
    double mapRmse_m() const { return std::sqrt(mapSumSq_m2 / double(commonCells)); }
    double naiveCoverage() const { return double(naiveCells) / double(truthCells); }
    double mapCoverage() const { return double(mapCells) / double(truthCells); }
    double naiveGoodCoverage() const { return double(naiveGood) / double(truthCells); }
    double mapGoodCoverage() const { return double(mapGood) / double(truthCells); }
    double mapWithin3() const { return double(mapWithin3Sigma) / double(commonCells); }
};

/** Scores scenario `prefix` (terrain-sim output: PREFIX.simplemap, PREFIX.ini, PREFIX_gt.asc); the
 * map takes the scenario's ini with `edit` applied to its insertion options. Disparity images in
 * the simplemap are dropped: both sides match the rendered pairs with SGBM. */
/** Scored area [m, map frame]; the default takes every cell of the ground truth. */
struct Area {
    double xMin_m = -1e9, xMax_m = 1e9, yMin_m = -1e9, yMax_m = 1e9;
    bool contains(double x, double y) const {
        return x >= xMin_m && x <= xMax_m && y >= yMin_m && y <= yMax_m;
    }
};

template <class EditOptions>
Score compare(const std::string& prefix, EditOptions edit, const Area& area = {}) {
    mrpt::maps::CSimpleMap sm;
    {
        mrpt::io::CFileGZInputStream f(prefix + ".simplemap");
        mrpt::serialization::archiveFrom(f) >> sm;
    }
    const auto gt = multibin::EsriAsciiGrid::load(prefix + "_gt.asc");
    const double cell_m = gt.cellsize_m;

    // (a) naive: OpenCV's SGBM call with the library's default parameters (so without the
    // library's left-border padding), triangulate, plain mean.
    multibin::sensors::StereoModelOptions defaults;
    defaults.sgbmFullWidth = std::getenv("NAIVE_FULL") != nullptr;  // an experiment
    mrpt::maps::CHeightGridMap2D naive(
        mrpt::maps::CHeightGridMap2D::mrSimpleAverage, gt.xllcenter_m - cell_m / 2,
        gt.xMax_m() + cell_m / 2, gt.yllcenter_m - cell_m / 2, gt.yMax_m() + cell_m / 2, cell_m);
    for (size_t i = 0; i < sm.size(); i++) {
        const auto& [posePdf, sf] = sm.get(i);
        const mrpt::poses::CPose3D robot = posePdf->getMeanVal();
        for (const auto& obs : *sf) {
            auto st = std::dynamic_pointer_cast<mrpt::obs::CObservationStereoImages>(obs);
            if (!st) continue;
            st->hasImageDisparity = false;
            terrain_sim::insertNaiveStereo(naive, *st, robot, defaults);
        }
    }

    // (b) the map, stereo only.
    mrpt::maps::CMultiBinElevationMap::TCreationOptions c;
    c.resolution_m = cell_m;
    mrpt::maps::CMultiBinElevationMap map(c);
    mrpt::config::CConfigFile ini(prefix + ".ini");
    map.insertionOptions.loadFromConfigFile(
        ini, "MappingApplication_multiBinElevationMap_00_insertOpts");
    map.insertionOptions.sensor_labels = {"STEREO"};
    edit(map.insertionOptions);
    map.insertSimpleMapWithPosePdfs(sm);
    const bool dem = std::getenv("DEM") != nullptr;
    if (dem) map.dem_update_map();

    Score s;
    FILE* dump = std::getenv("DUMP") ? std::fopen(std::getenv("DUMP"), "w") : nullptr;
    for (int r = 0; r < gt.rows(); r++)
        for (int k = 0; k < gt.cols(); k++) {
            const double truth = gt.heights_m(r, k);
            const double x = gt.xllcenter_m + k * cell_m, y = gt.yllcenter_m + r * cell_m;
            if (!std::isfinite(truth) || !area.contains(x, y)) continue;
            s.truthCells++;
            const auto* nc = naive.cellByPos(x, y);
            const bool hasNaive = nc && nc->w > 0;
            double h, sigma;
            const bool hasMap = dem ? map.getElevation(x, y, h, sigma) !=
                                          mrpt::maps::CMultiBinElevationMap::HeightSource::Unknown
                                    : map.getHeight(x, y, h, sigma);
            s.naiveCells += hasNaive;
            s.mapCells += hasMap;
            s.naiveGood += hasNaive && std::abs(nc->h - truth) <= Score::kGood_m;
            s.mapGood += hasMap && std::abs(h - truth) <= Score::kGood_m;
            if (dump && hasNaive != hasMap)
                std::fprintf(dump, "X %g %g %g %d %g %u\n", x, y, truth, int(hasNaive),
                             hasNaive ? double(nc->h) : h, hasNaive ? nc->w : 0u);
            if (!hasNaive || !hasMap) continue;
            s.commonCells++;
            if (dump)
                std::fprintf(dump, "%g %g %g %g %g %g %u\n", x, y, truth, nc->h, h, sigma, nc->w);
            s.naiveSumSq_m2 += (nc->h - truth) * (nc->h - truth);
            s.mapSumSq_m2 += (h - truth) * (h - truth);
            s.mapWithin3Sigma += std::abs(h - truth) <= 3 * sigma;
        }
    if (dump) std::fclose(dump);
    return s;
}

}  // namespace stereo_naive
