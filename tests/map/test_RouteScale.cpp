/* Part of the multibin elevation-mapping library's tests.
 * Routes of 50, 200 and 1000 m (RouteScene.h, 5 cm cells, defaults otherwise): every point the
 * sensor model keeps is fused, none "outside map"; the map's memory and the gap filling's work
 * grow with the ground seen, not with the route's bounding box. Timing and peak process memory:
 * route-scale (doc/route-scale.md). */
#include <gtest/gtest.h>
#include <mrpt/maps/CMultiBinElevationMap.h>
#include "multibin/grid/BinGrid.h"

#include "RouteScene.h"
#include "multibin/fill/GapFilling.h"
#include "multibin/fill/SparseFill.h"
#include "multibin/map/MapInternals.h"
#include "multibin/map/MapStatistics.h"
#include "multibin/traversability/TerrainFeatures.h"

namespace {
struct RouteResult {
    size_t points = 0, fused = 0, outsideMap = 0, tooUncertain = 0, tiles = 0, bytes = 0;
    size_t windowCells = 0;
    bool filled = false;              //!< dem_update_map() filled some cell
    size_t fillVisited = 0;           //!< cells the fill's gap search and per-gap rasters read
    std::string traversabilityError;  //!< what traversabilityLayers() threw, if it did
};

RouteResult mapRoute(double length_m) {
    multibin::test::RouteOptions o;
    o.length_m = length_m;
    o.spacing_m = 0.1;  // sparse clouds: the extent matters here, not the density
    o.step_m = 0.4;
    mrpt::maps::CMultiBinElevationMap::TCreationOptions c;
    c.resolution_m = 0.05;
    mrpt::maps::CMultiBinElevationMap map(c);
    map.insertionOptions.fill.enabled = false;
    RouteResult r;
    multibin::test::forEachRouteCloud(o, [&](const mrpt::obs::CObservationPointCloud& cloud,
                                             const mrpt::poses::CPose3D& pose, size_t points) {
        map.insertObservation(cloud, pose);
        r.points += points;
    });
    r.fused = map.statistics().insert.accepted;
    r.outsideMap = map.statistics().insert.outsideMap;
    r.tooUncertain = map.statistics().insert.tooUncertain;
    r.tiles = multibin::MapInternals::grid(map).store().tileCount();
    r.bytes = multibin::MapInternals::grid(map).memoryBytes();
    r.windowCells = multibin::MapInternals::grid(map).window().cellCount();
    map.insertionOptions.fill.enabled = true;
    map.dem_update_map();
    const multibin::fill::FillResult::Stats& fs = map.lastFilledCells().stats;
    r.filled = fs.median + fs.gaussian > 0;
    r.fillVisited = fs.cellsVisited;
    try {
        map.traversabilityLayers();
    } catch (const std::exception& e) {
        r.traversabilityError = e.what();
    }
    return r;
}
}  // namespace

TEST(RouteScale, EveryPointIsFusedAndMemoryFollowsTheGroundSeen) {
    const RouteResult r50 = mapRoute(50), r200 = mapRoute(200), r1000 = mapRoute(1000);
    for (const RouteResult* r : {&r50, &r200, &r1000}) {
        EXPECT_EQ(r->outsideMap, 0u);
        // The footprint is 1 .. 3.3 m from the sensor: the default pose covariance keeps all.
        EXPECT_EQ(r->fused + r->tooUncertain, r->points);
        EXPECT_GT(r->fused, r->points * 99 / 100);
    }
    // The 1000 m route's window (its bounding box: 14 000 x 14 000 cells) is 5 x 5 = 25 times the
    // 200 m one's; its tiles and memory are 5 times, as the ground seen.
    EXPECT_GT(double(r1000.windowCells) / double(r200.windowCells), 20.0);
    const double tiles = double(r1000.tiles) / double(r200.tiles);
    const double bytes = double(r1000.bytes) / double(r200.bytes);
    EXPECT_GT(tiles, 4.5);
    EXPECT_LT(tiles, 5.5);
    EXPECT_LT(bytes, 6.0);
    EXPECT_LT(double(r1000.bytes), 1.5e9);
    // Filling is tiled: done on every route, its work 5 times the 200 m route's, as the ground
    // seen. The traversability layers are one raster over the window: done up to 8192 x 8192
    // cells, beyond it (the 1000 m route) they refuse, by name.
    EXPECT_TRUE(r200.filled);
    EXPECT_TRUE(r1000.filled);
    const double visited = double(r1000.fillVisited) / double(r200.fillVisited);
    EXPECT_GT(visited, 4.0) << r200.fillVisited << " " << r1000.fillVisited;
    EXPECT_LT(visited, 6.0) << r200.fillVisited << " " << r1000.fillVisited;
    EXPECT_TRUE(r200.traversabilityError.empty()) << r200.traversabilityError;
    EXPECT_NE(r1000.traversabilityError.find("14"), std::string::npos) << r1000.traversabilityError;
    // The 50 m route: a quarter of the 200 m one, give or take the ends.
    EXPECT_LT(double(r200.tiles) / double(r50.tiles), 4.6);
}
