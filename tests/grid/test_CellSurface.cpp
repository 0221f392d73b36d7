/* The reported surface of a cell: adjacent bins of one surface merged, relief in sigma. */
#include <gtest/gtest.h>
#include <mrpt/maps/CMultiBinElevationMap.h>

#include <cmath>

#include "../common/test_scenes.h"
#include "multibin/grid/BinGrid.h"
#include "multibin/io/EsriAsciiGrid.h"
#include "multibin/map/MapInternals.h"

using mrpt::maps::CMultiBinElevationMap;

namespace {
CMultiBinElevationMap fixedMap(double cell_m) {
    return test_scenes::fixedSquareMap(cell_m, 1.0, 0.001);
}
void insert(CMultiBinElevationMap& map, double x, double y, double z, double sigma) {
    CMultiBinElevationMap::TPointInsertParams ip;
    ip.pt_z_std = sigma;
    ASSERT_TRUE(map.insertIndividualPoint(x, y, z, ip));
}
}  // namespace

TEST(CellSurface, AdjacentBinsThatAgreeAreOneSurface) {
    // A surface at 0.05 m (a bin boundary) measured with sigma 3 mm: points fall in bins 0 and 1.
    CMultiBinElevationMap map = fixedMap(0.1);
    map.insertionOptions.query.relief_sigma = false;
    const double heights[] = {0.048, 0.052, 0.047, 0.053, 0.049, 0.051};
    for (double z : heights) insert(map, 0.55, 0.55, z, 0.003);
    double h, s;
    ASSERT_TRUE(map.cellHeight(0.55, 0.55, h, s));
    EXPECT_NEAR(h, 0.05, 1e-6) << "the mean of all six points, not of one bin's share";
    EXPECT_NEAR(s, 0.003 / std::sqrt(6.0), 1e-5);

    // Two surfaces 0.1 m apart stay two hypotheses: the more certain one wins alone.
    CMultiBinElevationMap two = fixedMap(0.1);
    two.insertionOptions.query.relief_sigma = false;
    for (int i = 0; i < 3; i++) insert(two, 0.55, 0.55, 0.01, 0.003);
    for (int i = 0; i < 2; i++) insert(two, 0.55, 0.55, 0.11, 0.003);
    ASSERT_TRUE(two.cellHeight(0.55, 0.55, h, s));
    EXPECT_NEAR(h, 0.01, 1e-6);
}

TEST(CellSurface, ReliefOfASlopeAddsItsHeightSpreadToSigma) {
    // A plane z = 0.2 x over 2 cm cells, one exact-ish point per cell at the cell centre.
    const double cell = 0.02, slope = 0.2, sigma = 0.001;
    CMultiBinElevationMap map = fixedMap(cell);
    for (int iy = 0; iy < 10; iy++)
        for (int ix = 0; ix < 10; ix++) {
            const double x = (ix + 0.5) * cell, y = (iy + 0.5) * cell;
            insert(map, x, y, 0.3 + slope * x, sigma);
        }
    double h, s;
    ASSERT_TRUE(map.cellHeight(0.05, 0.05, h, s));
    // sigma^2 = max(Kalman, floor) + (g s)^2 / 12; Kalman = floor = 1 mm here.
    EXPECT_NEAR(s, std::sqrt(sigma * sigma + std::pow(slope * cell, 2) / 12.0), 1e-6);
    map.insertionOptions.query.relief_sigma = false;
    ASSERT_TRUE(map.cellHeight(0.05, 0.05, h, s));
    EXPECT_NEAR(s, sigma, 1e-6);
}

TEST(CellSurface, OtherSurfacesInTheCellAddTheirCertaintyWeightedSpreadToSigma) {
    // One isolated cell (no neighbours: no slope term) holding a step: three points on its top at
    // 0.11 m and two on its foot at 0.01 m, 3 mm each. The top wins; the cell's truth, the mean
    // over its area, lies between the two, so sigma^2 gains (c_foot / (c_top + c_foot)) * 0.1^2.
    CMultiBinElevationMap map = fixedMap(0.1);
    for (int i = 0; i < 3; i++) insert(map, 0.55, 0.55, 0.11, 0.003);
    for (int i = 0; i < 2; i++) insert(map, 0.55, 0.55, 0.01, 0.003);
    double h, s;
    ASSERT_TRUE(map.cellHeight(0.55, 0.55, h, s));
    EXPECT_NEAR(h, 0.11, 1e-6);
    const double kalman2 = 0.003 * 0.003 / 3;  // the winning bin: 3 points of 3 mm
    EXPECT_NEAR(s * s, kalman2 + 2.0 / 5.0 * 0.1 * 0.1, 1e-9);
    map.insertionOptions.query.relief_sigma = false;  // the paper's sigma: the winning bin's alone
    ASSERT_TRUE(map.cellHeight(0.55, 0.55, h, s));
    EXPECT_NEAR(s * s, kalman2, 1e-9);
}

TEST(CellSurface, EveryLayerDescribesTheSameSurface) {
    // Six points of one surface at a bin boundary, three in bin 0 and three in bin 1: the height
    // and sigma layers report the merged surface, so the certainty layer must count all six
    // points' certainty (6), not the winning bin's share (3).
    CMultiBinElevationMap map = fixedMap(0.1);
    map.insertionOptions.query.relief_sigma = false;
    for (double z : {0.048, 0.052, 0.047, 0.053, 0.049, 0.051}) insert(map, 0.55, 0.55, z, 0.003);
    double h, s;
    ASSERT_TRUE(map.cellHeight(0.55, 0.55, h, s));
    using Layer = CMultiBinElevationMap::RasterLayer;
    EXPECT_FLOAT_EQ(map.toRaster(Layer::Height).heights_m(5, 5), float(h));
    EXPECT_FLOAT_EQ(map.toRaster(Layer::Sigma).heights_m(5, 5), float(s));
    EXPECT_FLOAT_EQ(map.toRaster(Layer::Certainty).heights_m(5, 5), 6.f);
    ASSERT_NE(multibin::MapInternals::grid(map).winningBin(5, 5), nullptr);
    EXPECT_FLOAT_EQ(multibin::MapInternals::grid(map).winningBin(5, 5)->certainty, 3.f)
        << "the case the test is about";
}
