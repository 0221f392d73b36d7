/* Tests of grid/PointsPerCell.h: the eq 13 gate on each point's own variance and the points per
 * cell, counted by hand. */
#include <gtest/gtest.h>

#include <limits>

#include "multibin/grid/PointsPerCell.h"

using namespace multibin;

namespace {
PointWithCov pointAt(double x, double y, double sigmaZ_m) {
    PointWithCov p;
    p.point_m = Eigen::Vector3f(float(x), float(y), 0.f);
    p.cov_m2 = {1e-6f, 0, 0, 1e-6f, 0, float(sigmaZ_m * sigmaZ_m)};
    return p;
}
}  // namespace

TEST(PointsPerCell, CountsThePointsOfEachCellInsideAndOutsideTheWindow) {
    BinGrid grid(0.1);
    grid.reset(0.1, CellWindow{0, 0, 10, 10});
    // Cells (0,0): 3 points, (5,2): 1, (-3,0) outside the window: 2.
    const PointsWithCov pts{pointAt(0.01, 0.02, 0.01), pointAt(0.55, 0.25, 0.01),
                            pointAt(0.09, 0.09, 0.01), pointAt(-0.25, 0.05, 0.01),
                            pointAt(0.05, 0.05, 0.01), pointAt(-0.21, 0.01, 0.01)};
    const std::vector<uint32_t> expected{3, 1, 3, 2, 3, 2};
    EXPECT_EQ(pointsPerCell(grid, pts), expected);
}

TEST(PointsPerCell, PointsScatteredFarApartAreCountedTheSame) {
    // Cells 10^6 apart: the counts take the hash map, not a dense array over their box.
    BinGrid grid(0.1);
    grid.reset(0.1, CellWindow{0, 0, 10, 10});
    const PointsWithCov pts{pointAt(0.01, 0.01, 0.01), pointAt(1e5, 1e5, 0.01),
                            pointAt(0.02, 0.02, 0.01), pointAt(-1e5, 1e5, 0.01),
                            pointAt(1e5 + 0.01, 1e5 + 0.01, 0.01)};
    const std::vector<uint32_t> expected{2, 2, 2, 1, 2};
    EXPECT_EQ(pointsPerCell(grid, pts), expected);
    EXPECT_TRUE(pointsPerCell(grid, {}).empty());
}

TEST(PointsPerCell, TheGateRemovesOnlyFinitePointsTooUncertainOnTheirOwn) {
    BinUpdateParams params;
    params.maxElevationUncertainty_m = 0.09;  // 3 sigma <= 0.09: sigma <= 0.03 passes
    PointsWithCov pts{pointAt(0, 0, 0.01), pointAt(1, 0, 0.031), pointAt(2, 0, 0.029),
                      pointAt(3, 0, 0.5)};
    PointWithCov notFinite = pointAt(4, 0, 0.5);
    notFinite.point_m.x() = std::numeric_limits<float>::quiet_NaN();
    pts.push_back(notFinite);  // the grid's to count (notFinite), not the gate's
    EXPECT_EQ(removeFailingOwnGate(pts, params), 2u);
    ASSERT_EQ(pts.size(), 3u);
    EXPECT_EQ(pts[0].point_m.x(), 0.f);
    EXPECT_EQ(pts[1].point_m.x(), 2.f);
    EXPECT_TRUE(std::isnan(pts[2].point_m.x()));
}
