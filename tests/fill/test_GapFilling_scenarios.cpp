/* Honest sigma of filled cells on the shipped scenarios (issue: the mapper's filled-only cells
 * held the truth within 3 sigma in only 88.9 % (mock-up) and 88.6 % (walk) of cells, when the
 * rim check handed heights to the harmonic path but kept the kriging sigma and the kriging
 * variance ignored the steps hidden in the mapper's shadows). The scenarios' maps are built from
 * their simplemaps with the mapper's ini, filled with the default options, and the filled-only
 * cells compared with the ground truth averaged on the map's cells, as the evaluation does. The
 * sigma gains were calibrated on the LittleDog square-gap placements (compare_fill calibrate,
 * seed 1), not on these scenarios. */
#include <gtest/gtest.h>
#include <mrpt/config/CConfigFile.h>
#include <mrpt/io/CFileGZInputStream.h>
#include <mrpt/maps/CMultiBinElevationMap.h>
#include <mrpt/maps/CSimpleMap.h>
#include <mrpt/serialization/CArchive.h>

#include <cmath>
#include <cstdio>
#include <map>

#include "FillTestData.h"
#include "multibin/eval/Evaluation.h"
#include "multibin/fill/HeightRaster.h"
#include "multibin/io/EsriAsciiGrid.h"
#include "multibin/map/MapInternals.h"

namespace {

struct Coverage {
    size_t cells = 0, within3Sigma = 0;
    double share() const { return cells ? double(within3Sigma) / double(cells) : 0.0; }
};

/** Filled-only cells of the scenario's filled map within 3 sigma, per HeightSource and (key
 * Unknown) over all filled cells. */
std::map<multibin::HeightSource, Coverage> filledOnlyCoverage(const std::string& scenario) {
    const std::string dir = MULTIBIN_SOURCE_DIR;
    mrpt::config::CConfigFile ini(dir + "/ini/" + scenario + ".ini");
    const std::string prefix = "MappingApplication_multiBinElevationMap_00_";
    mrpt::maps::CMultiBinElevationMap::TCreationOptions creation;
    creation.loadFromConfigFile(ini, prefix + "creationOpts");
    mrpt::maps::CMultiBinElevationMap map(creation);
    map.insertionOptions.loadFromConfigFile(ini, prefix + "insertOpts");
    mrpt::maps::CSimpleMap sm;
    mrpt::io::CFileGZInputStream f(dir + "/rawlogs/" + scenario + ".simplemap");
    mrpt::serialization::archiveFrom(f) >> sm;
    map.insertSimpleMapWithPosePdfs(sm);
    map.dem_update_map();
    const multibin::fill::FillResult& fill = multibin::MapInternals::lastFill(map);

    std::map<multibin::HeightSource, Coverage> out;
    multibin::filltest::forEachFilledCellWithTruth(
        fill, dir + "/rawlogs/" + scenario + "_gt.asc", [&](size_t k, double t) {
            const bool inside = std::abs(fill.height_m[k] - t) <= 3 * fill.sigma_m[k];
            for (auto key : {fill.source[k], multibin::HeightSource::Unknown}) {
                out[key].cells++;
                out[key].within3Sigma += inside;
            }
        });
    for (const auto& [src, cov] : out)
        std::printf("%s: source %d (0 = all filled): %zu cells, %.1f %% within 3 sigma\n",
                    scenario.c_str(), int(src), cov.cells, 100 * cov.share());
    return out;
}

}  // namespace

TEST(FilledSigmaOnScenarios, FilledOnlyCellsHoldTheTruthWithin3SigmaOnMockupAndWalk) {
    for (const std::string scenario : {"mockup", "walk"}) {
        const auto cov = filledOnlyCoverage(scenario);
        ASSERT_GT(cov.at(multibin::HeightSource::Unknown).cells, 1000u) << scenario;
        EXPECT_GE(cov.at(multibin::HeightSource::Unknown).share(), 0.95) << scenario;
        // Each path its own sigma: the harmonic cells (the rim check's) are no longer the
        // kriging's (50.8 % on the walk, 82.7 % on the mock-up in the mapper's runs before).
        ASSERT_TRUE(cov.count(multibin::HeightSource::FilledHarmonic)) << scenario;
        EXPECT_GE(cov.at(multibin::HeightSource::FilledHarmonic).share(), 0.90) << scenario;
    }
}
