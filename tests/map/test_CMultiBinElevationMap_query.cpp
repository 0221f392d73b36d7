/* A map read from a file answers as the map that wrote it: filled cells included, without the
 * caller running dem_update_map(). */
#include <gtest/gtest.h>
#include <mrpt/io/CMemoryStream.h>
#include <mrpt/maps/CMultiBinElevationMap.h>
#include <mrpt/serialization/CArchive.h>

#include <cmath>
#include "multibin/map/MapInternals.h"

namespace {
using Map = mrpt::maps::CMultiBinElevationMap;

/** A 1 m x 1 m tilted plane (z = 0.1 x) of 5 cm cells measured everywhere but a 3 x 3-cell hole
 * around (0.5, 0.5), filled by dem_update_map(). */
Map mapWithAFilledHole() {
    Map::TCreationOptions c;
    c.resolution_m = 0.05;
    c.grow = false;
    c.max_x = c.max_y = 1.0;
    Map map(c);
    for (int i = 0; i < 20; i++)
        for (int j = 0; j < 20; j++) {
            if (std::abs(i - 10) <= 1 && std::abs(j - 10) <= 1) continue;
            const double x = 0.025 + 0.05 * i, y = 0.025 + 0.05 * j;
            mrpt::maps::CHeightGridMap2D_Base::TPointInsertParams p;
            p.pt_z_std = 0.005;
            map.insertIndividualPoint(x, y, 0.1 * x, p);
        }
    map.dem_update_map();
    return map;
}

Map roundTrip(const Map& map) {
    mrpt::io::CMemoryStream mem;
    auto out = mrpt::serialization::archiveFrom(mem);
    out << map;
    mem.Seek(0);
    auto in = mrpt::serialization::archiveFrom(mem);
    Map loaded;
    in >> loaded;
    return loaded;
}
}  // namespace

// The hole's centre is filled in the map that wrote the file; the loaded map answers the same
// source, height and sigma from getElevation, cellElevation, dem_get_z and dem_get_z_by_cell,
// with no dem_update_map() (it answered "unknown" before).
TEST(LoadedMap, AnswersFilledCellsWithoutDemUpdateMap) {
    const Map written = mapWithAFilledHole();
    const double x = 0.525, y = 0.525;
    double h0 = 0, s0 = 0;
    const auto src0 = written.getElevation(x, y, h0, s0);
    ASSERT_NE(src0, Map::HeightSource::Unknown);
    ASSERT_NE(src0, Map::HeightSource::Measured);
    EXPECT_NEAR(h0, 0.0525, 0.01);

    const Map loaded = roundTrip(written);
    double h = NAN, s = NAN, z = NAN, zc = NAN;
    EXPECT_EQ(loaded.getElevation(x, y, h, s), src0);
    EXPECT_DOUBLE_EQ(h, h0);
    EXPECT_DOUBLE_EQ(s, s0);
    EXPECT_EQ(loaded.cellElevation(x, y, h, s), src0);
    ASSERT_TRUE(loaded.dem_get_z(x, y, z));
    EXPECT_DOUBLE_EQ(z, h0);
    ASSERT_TRUE(loaded.dem_get_z_by_cell(10, 10, zc));
    EXPECT_DOUBLE_EQ(zc, h0);
    EXPECT_FALSE(multibin::MapInternals::fillIsStale(loaded));
}

// A loaded map that then receives data is an ordinary map again: its fill follows
// dem_update_map() (no refill per query).
TEST(LoadedMap, AfterAnInsertionTheFillIsExplicitAgain) {
    Map loaded = roundTrip(mapWithAFilledHole());
    mrpt::maps::CHeightGridMap2D_Base::TPointInsertParams p;
    p.pt_z_std = 0.005;
    ASSERT_TRUE(loaded.insertIndividualPoint(0.025, 0.025, 0.0025, p));
    double h, s;
    EXPECT_EQ(loaded.getElevation(0.525, 0.525, h, s), Map::HeightSource::Unknown);
    EXPECT_TRUE(multibin::MapInternals::fillIsStale(loaded));
    loaded.dem_update_map();
    EXPECT_NE(loaded.getElevation(0.525, 0.525, h, s), Map::HeightSource::Unknown);
}

// The recommended query answers height, sigma and source in one call: measured where measured
// (what getHeight() says), filled in the hole (what dem_get_z() says), NaN and Unknown outside
// the map, where the old queries left their outputs untouched.
TEST(HeightQuery, OneAnswerWithSourceAndNaNWhereUnknown) {
    const Map map = mapWithAFilledHole();
    const Map::HeightAnswer measured = map.height(0.2, 0.3);
    ASSERT_EQ(measured.source, Map::HeightSource::Measured);
    double h = NAN, s = NAN;
    ASSERT_TRUE(map.getHeight(0.2, 0.3, h, s));
    EXPECT_EQ(measured.height_m, h);
    EXPECT_EQ(measured.sigma_m, s);
    EXPECT_NEAR(measured.height_m, 0.02, 0.005);  // the plane z = 0.1 x

    const Map::HeightAnswer filled = map.height(0.525, 0.525);
    EXPECT_TRUE(filled.known());
    EXPECT_NE(filled.source, Map::HeightSource::Measured);
    double z = NAN;
    ASSERT_TRUE(map.dem_get_z(0.525, 0.525, z));
    EXPECT_EQ(filled.height_m, z);
    EXPECT_FALSE(map.getHeight(0.525, 0.525, h, s));  // measured only

    const Map::HeightAnswer outside = map.height(5.0, 5.0);
    EXPECT_FALSE(outside.known());
    EXPECT_EQ(outside.source, Map::HeightSource::Unknown);
    EXPECT_TRUE(std::isnan(outside.height_m) && std::isnan(outside.sigma_m));
    EXPECT_FALSE(map.dem_get_z(5.0, 5.0, z));
}
