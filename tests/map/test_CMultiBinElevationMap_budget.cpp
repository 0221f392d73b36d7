/* Part of the multibin elevation-mapping library's tests.
 * The memory budget (TCreationOptions::memory_budget_mb): a route mapped out and back within a
 * budget a fraction of what it needs holds the same bins, bit for bit, as without one; the tiles
 * written to disk came back when the route returned to them; the scratch file leaves nothing in
 * its directory; an unusable directory is a one-line error naming it. */
#include <gtest/gtest.h>
#include <mrpt/maps/CMultiBinElevationMap.h>

#include <cstring>
#include <filesystem>
#include <tuple>
#include <vector>

#include "RouteScene.h"
#include "multibin/grid/BinGrid.h"
#include "multibin/map/MapInternals.h"

namespace {
using Map = mrpt::maps::CMultiBinElevationMap;

struct Cloud {
    mrpt::obs::CObservationPointCloud cloud;
    mrpt::poses::CPose3D robot;
};

/** An 80 m route out and back (the way back re-observes the tiles written to disk). */
std::vector<Cloud> outAndBack() {
    multibin::test::RouteOptions o;
    o.length_m = 80;
    o.step_m = 0.4;
    o.spacing_m = 0.1;
    std::vector<Cloud> clouds;
    multibin::test::forEachRouteCloud(o, [&](const mrpt::obs::CObservationPointCloud& c,
                                             const mrpt::poses::CPose3D& pose, size_t) {
        clouds.push_back({c, pose});
    });
    for (size_t k = clouds.size(); k-- > 0;) clouds.push_back(clouds[k]);
    return clouds;
}

Map::TCreationOptions creation(double budget_mb, const std::string& dir = "") {
    Map::TCreationOptions c;
    c.resolution_m = 0.05;
    c.memory_budget_mb = budget_mb;
    c.tile_store_dir = dir;
    return c;
}

void mapClouds(Map& map, const std::vector<Cloud>& clouds) {
    map.insertionOptions.max_range_m = 4;  // the footprint is 1 .. 3.4 m from the sensor
    for (const Cloud& c : clouds) map.insertObservation(c.cloud, c.robot);
}

/** Every bin of the map with its cell, every byte of its estimate, in cell and chain order. */
using BinRecord = std::tuple<int, int, std::vector<unsigned char>>;
std::vector<BinRecord> allBins(const Map& map) {
    std::vector<BinRecord> bins;
    multibin::MapInternals::grid(map).store().forEachStoredBin(
        [&](int ix, int iy, const multibin::Bin& b) {
            const multibin::BinEstimate& e = b;
            std::vector<unsigned char> bytes(sizeof e);
            std::memcpy(bytes.data(), &e, sizeof e);
            bins.emplace_back(ix, iy, bytes);
        });
    // Tiles come back in another order than they were allocated: sort by cell, keeping each
    // cell's chain order (stable).
    std::stable_sort(bins.begin(), bins.end(), [](const BinRecord& a, const BinRecord& b) {
        return std::tie(std::get<1>(a), std::get<0>(a)) < std::tie(std::get<1>(b), std::get<0>(b));
    });
    return bins;
}
}  // namespace

TEST(MemoryBudget, ARouteOverItsBudgetHoldsTheSameBinsAsWithoutOne) {
    const std::vector<Cloud> clouds = outAndBack();
    Map unbounded(creation(0));
    mapClouds(unbounded, clouds);
    const size_t needed = multibin::MapInternals::grid(unbounded).residentBytes();

    const double budget_mb = 1.5;
    ASSERT_GT(double(needed), 3 * budget_mb * 1e6) << "the route must need well over the budget";
    const std::filesystem::path dir =
        std::filesystem::temp_directory_path() / ("multibin-budget-" + std::to_string(getpid()));
    std::filesystem::create_directories(dir);
    Map budgeted(creation(budget_mb, dir.string()));
    mapClouds(budgeted, clouds);
    const Map::TileStoreStats s = budgeted.tileStoreStats();
    std::printf("needed %.2f MB; budget %.2f MB: peak %.2f MB, tiles written %zu, read back %zu\n",
                double(needed) / 1e6, budget_mb, double(s.peakResidentBytes) / 1e6, s.tilesWritten,
                s.tilesRead);
    EXPECT_GT(s.tilesWritten, 10u);
    EXPECT_GT(s.tilesRead, 5u) << "the way back re-observes tiles on disk";
    EXPECT_GT(s.tilesOnDisk, 0u);
    // Within the budget, give or take one observation's growth.
    EXPECT_LT(double(s.peakResidentBytes), 1.25 * budget_mb * 1e6);
    // The scratch file has no name: nothing in its directory.
    EXPECT_TRUE(std::filesystem::is_empty(dir));
    std::filesystem::remove_all(dir);

    // Reading brings every tile back: the same bins, bit for bit, cell by cell.
    EXPECT_EQ(multibin::MapInternals::grid(budgeted).binCount(),
              multibin::MapInternals::grid(unbounded).binCount());
    EXPECT_EQ(budgeted.tileStoreStats().tilesOnDisk, 0u);
    EXPECT_TRUE(allBins(budgeted) == allBins(unbounded));
    // And the same heights where the route was.
    for (double along = 0; along < 80; along += 0.37) {
        const double x = along * std::cos(M_PI / 4) + 1.5, y = along * std::sin(M_PI / 4) + 1.5;
        const Map::HeightAnswer a = budgeted.height(x, y), b = unbounded.height(x, y);
        EXPECT_EQ(a.source, b.source);
        if (a.known()) EXPECT_EQ(a.height_m, b.height_m);
    }
}

TEST(MemoryBudget, AnUnusableTileStoreDirectoryIsAnErrorNamingIt) {
    const std::vector<Cloud> clouds = outAndBack();
    Map map(creation(0.5, "/nonexistent/multibin-tiles"));
    try {
        mapClouds(map, clouds);
        FAIL() << "a budget that needs the disk with no usable directory must not map silently";
    } catch (const std::runtime_error& e) {
        EXPECT_NE(std::string(e.what()).find("/nonexistent/multibin-tiles"), std::string::npos)
            << e.what();
        EXPECT_NE(std::string(e.what()).find("tile_store_dir"), std::string::npos) << e.what();
    }
}
