/* The map's gap filling: lazy (dem_update_map only), measured vs filled, dem_return_filled. */
#include <gtest/gtest.h>
#include <mrpt/maps/CMultiBinElevationMap.h>
#include "multibin/io/EsriAsciiGrid.h"
#include "multibin/map/MapInternals.h"

using mrpt::maps::CMultiBinElevationMap;
using Source = CMultiBinElevationMap::HeightSource;

namespace {
/** A 1 x 1 m plane at 0.1 m in 2 cm cells with a hole of 3 x 3 cells around (0.5, 0.5). */
CMultiBinElevationMap planeWithHole() {
    CMultiBinElevationMap::TCreationOptions c;
    c.resolution_m = 0.02;
    c.grow = false;
    c.min_x = c.min_y = 0;
    c.max_x = c.max_y = 1;
    CMultiBinElevationMap map(c);
    CMultiBinElevationMap::TPointInsertParams ip;
    ip.pt_z_std = 0.003;
    for (int iy = 0; iy < 50; iy++)
        for (int ix = 0; ix < 50; ix++) {
            if (std::abs(ix - 25) <= 1 && std::abs(iy - 25) <= 1) continue;
            map.insertIndividualPoint(0.01 + 0.02 * ix, 0.01 + 0.02 * iy, 0.1, ip);
        }
    return map;
}
}  // namespace

TEST(MapFill, FillingIsLazyAndFilledCellsAreMarked) {
    CMultiBinElevationMap map = planeWithHole();
    const double hx = 0.51, hy = 0.51;  // the hole's centre cell
    double z, s;
    EXPECT_FALSE(map.dem_get_z(hx, hy, z)) << "nothing is filled before dem_update_map()";
    EXPECT_TRUE(multibin::MapInternals::fillIsStale(map));
    map.dem_update_map();
    EXPECT_FALSE(multibin::MapInternals::fillIsStale(map));
    ASSERT_TRUE(map.dem_get_z(hx, hy, z));
    EXPECT_NEAR(z, 0.1, 1e-4);
    EXPECT_EQ(map.getElevation(hx, hy, z, s), Source::FilledMedian);
    EXPECT_GT(s, 0.0);
    EXPECT_EQ(map.getElevation(0.11, 0.11, z, s), Source::Measured);
    EXPECT_EQ(map.getElevation(hx, hy, z, s, false), Source::Unknown);

    // Filled cells keep certainty 0 and are flagged in the source layer.
    const auto certainty = map.toRaster(CMultiBinElevationMap::RasterLayer::Certainty);
    const auto source = map.toRaster(CMultiBinElevationMap::RasterLayer::Source);
    EXPECT_EQ(certainty.heights_m(25, 25), 0.f);
    EXPECT_EQ(source.heights_m(25, 25), float(Source::FilledMedian));
    EXPECT_EQ(source.heights_m(0, 0), float(Source::Measured));
    EXPECT_GT(certainty.heights_m(0, 0), 0.f);

    // MRPT's documented behaviour on request: unobserved cells are not returned.
    map.insertionOptions.query.dem_return_filled = false;
    EXPECT_FALSE(map.dem_get_z(hx, hy, z));
    map.insertionOptions.query.dem_return_filled = true;

    // A new observation makes the fill stale; a cell measured since answers with its data.
    CMultiBinElevationMap::TPointInsertParams ip;
    ip.pt_z_std = 0.003;
    map.insertIndividualPoint(hx, hy, 0.3, ip);
    EXPECT_TRUE(multibin::MapInternals::fillIsStale(map));
    EXPECT_EQ(map.getElevation(hx, hy, z, s), Source::Measured);
    EXPECT_NEAR(z, 0.3, 1e-6);
}

TEST(MapFill, DisabledFillingLeavesGapsUnknown) {
    CMultiBinElevationMap map = planeWithHole();
    map.insertionOptions.fill.enabled = false;
    map.dem_update_map();
    double z;
    EXPECT_FALSE(map.dem_get_z(0.51, 0.51, z));
}
