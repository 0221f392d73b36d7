/* MRPT's PlannerSimple2D on the occupancy grid the map exports (getAsOccupancyGrid): paths that
 * cross no cell the truth calls untraversable, found wherever the truth's own grid has one, and
 * no longer than 1.15 x the truth's. */
#include <gtest/gtest.h>
#include <mrpt/maps/CMultiBinElevationMap.h>

#include <cmath>
#include <random>

#include "PlanningCheck.h"
#include "multibin/traversability/TerrainFeatures.h"

using mrpt::maps::CMultiBinElevationMap;
using namespace multibin;

namespace {
constexpr double kCell = 0.02, kSideX = 1.6, kSideY = 1.0;

/** Flat ground with a 0.15 m wall across y < 0.7 at x in [0.5, 0.6], a 40 deg ramp at x in
 * [0.9, 1.05] for y > 0.45, a 0.04 m step (traversable) beyond x = 1.2, and a rough patch
 * (waves of 4 cm amplitude every 4 cm: RMS 2.8 cm) at x in [0.2, 0.4], y in [0.3, 0.6]. */
double terrain(double x, double y) {
    double z = 0;
    if (x >= 0.5 && x < 0.6 && y < 0.7) z = 0.15;
    if (x >= 0.9 && x < 1.05 && y > 0.45) z = std::tan(40 * M_PI / 180) * (x - 0.9);
    if (x >= 1.2) z += 0.04;
    if (x >= 0.2 && x < 0.4 && y >= 0.3 && y < 0.6) z += 0.04 * std::sin(2 * M_PI * x / 0.04);
    return z;
}

CMultiBinElevationMap mapOfTerrain(unsigned seed) {
    CMultiBinElevationMap::TCreationOptions c;
    c.resolution_m = kCell;
    c.grow = false;
    c.min_x = c.min_y = 0;
    c.max_x = kSideX, c.max_y = kSideY;
    c.origin_auto = false;
    CMultiBinElevationMap map(c);
    PointsWithCov pts;
    std::mt19937 rng(seed);
    std::normal_distribution<double> n01;
    const double sigma = 0.002;
    for (double y = 0.0025; y < kSideY; y += 0.005)
        for (double x = 0.0025; x < kSideX; x += 0.005) {
            PointWithCov p;
            p.point_m =
                Eigen::Vector3f(float(x), float(y), float(terrain(x, y) + sigma * n01(rng)));
            p.cov_m2 = {1e-8f, 0, 0, 1e-8f, 0, float(sigma * sigma)};
            pts.push_back(p);
        }
    map.insertPoints(pts);
    return map;
}

/** The truth's classes on `lattice`'s cells: the features of the terrain sampled every 2 mm over
 * each cell's disc. */
planning::TruthCells truthCells(const traversability::TraversabilityOptions& o,
                                const mrpt::maps::COccupancyGridMap2D& lattice) {
    planning::TruthCells t;
    t.nx = lattice.getSizeX(), t.ny = lattice.getSizeY();
    t.cls.assign(size_t(t.nx) * t.ny, 0);
    for (unsigned cy = 0; cy < t.ny; cy++)
        for (unsigned cx = 0; cx < t.nx; cx++) {
            const double x0 = lattice.idx2x(cx), y0 = lattice.idx2y(cy);
            traversability::DiscAccumulator acc;
            for (double dy = -o.radius_m; dy <= o.radius_m; dy += 0.002)
                for (double dx = -o.radius_m; dx <= o.radius_m; dx += 0.002)
                    if (dx * dx + dy * dy <= o.radius_m * o.radius_m)
                        acc.add(dx, dy, terrain(x0 + dx, y0 + dy));
            traversability::DiscFeatures f;
            acc.features(f);
            t.cls[size_t(cy) * t.nx + cx] = f.step_m > o.max_step_m ||
                                            f.slope_deg > o.max_slope_deg ||
                                            f.roughness_m > o.max_roughness_m;
        }
    return t;
}
}  // namespace

TEST(TraversabilityPlanning, PlannerSimple2DOnTheExportedGridMatchesTheTruths) {
    CMultiBinElevationMap map = mapOfTerrain(3);
    mrpt::maps::COccupancyGridMap2D grid;
    map.getAsOccupancyGrid(grid);
    const planning::TruthCells truth = truthCells(map.traversabilityOptions, grid);
    const mrpt::maps::COccupancyGridMap2D truthGrid = truth.grid(grid);

    mrpt::nav::PlannerSimple2D planner;
    planner.robotRadius = 0.0f;  // the layer's disc is the robot's footprint already
    planner.minStepInReturnedPath = 0.0f;
    // Start and goal pairs across the obstacles, and one the wall and ramp shut off with the step
    // side (y in 0.7..1.0 is open at the wall but the ramp blocks y > 0.45 beyond it).
    const std::vector<std::pair<planning::Pose, planning::Pose>> pairs = {
        {{0.1, 0.1, 0}, {1.5, 0.1, 0}},  {{0.1, 0.9, 0}, {1.5, 0.9, 0}},
        {{0.1, 0.5, 0}, {0.8, 0.2, 0}},  {{0.7, 0.9, 0}, {1.4, 0.3, 0}},
        {{0.1, 0.2, 0}, {0.45, 0.5, 0}}, {{1.3, 0.1, 0}, {0.05, 0.95, 0}}};
    const planning::PlanningScore s =
        planning::comparePlans(grid, truthGrid, truth, pairs, planner);
    EXPECT_EQ(s.foundWhereTruth, s.truthFound);  // a path wherever the truth has one
    EXPECT_EQ(s.foundWhereNone, 0);              // and none where it has none
    EXPECT_EQ(s.unsafeCells, 0) << "of " << s.pathCells << " path cells";
    EXPECT_EQ(s.ratiosWithin(1.15), int(s.lengthRatios.size())) << "longest " << s.maxRatio();
    EXPECT_GE(s.truthFound, 4);  // most pairs have a path (the test is not vacuous)
}

namespace {
/** A 3 m x 1 m lattice of 0.1 m cells, every cell free. */
mrpt::maps::COccupancyGridMap2D openGrid() {
    mrpt::maps::COccupancyGridMap2D g(0, 3.0f, 0, 1.0f, 0.1f);
    for (unsigned cy = 0; cy < g.getSizeY(); cy++)
        for (unsigned cx = 0; cx < g.getSizeX(); cx++) g.setCell(int(cx), int(cy), 1.f);
    return g;
}
}  // namespace

// The comparison itself, on a hand-made case: the truth walls the lattice off at x in [1.5, 1.6]
// where the map sees open ground; the map's straight path along its row crosses the wall in
// exactly one cell and is counted as found where the truth has none.
TEST(TraversabilityPlanning, ComparePlansCountsAPathThroughATruthWall) {
    const mrpt::maps::COccupancyGridMap2D map = openGrid();
    planning::TruthCells truth;
    truth.nx = map.getSizeX(), truth.ny = map.getSizeY();
    truth.cls.assign(size_t(truth.nx) * truth.ny, 0);
    for (unsigned cy = 0; cy < truth.ny; cy++)
        truth.cls[cy * truth.nx + unsigned(map.x2idx(1.55))] = 1;
    mrpt::nav::PlannerSimple2D planner;
    planner.robotRadius = 0, planner.minStepInReturnedPath = 0;
    const planning::PlanningScore s = planning::comparePlans(
        map, truth.grid(map), truth, {{{0.25, 0.55, 0}, {2.75, 0.55, 0}}}, planner);
    EXPECT_EQ(s.truthFound, 0);
    EXPECT_EQ(s.foundWhereNone, 1);
    EXPECT_EQ(s.unsafePaths, 1);
    EXPECT_EQ(s.unsafeCells, 1);
    EXPECT_EQ(s.pathCells, 25);  // cells 3..26 of the row, then the goal point
}

// The pairs' rule: starts and goals on truth-traversable cells of opposite bands (the westmost and
// eastmost tenth of the known cells' x range, then the southmost and northmost tenth of y).
TEST(TraversabilityPlanning, OppositeSidePairsLieInOppositeBandsOnTraversableCells) {
    const mrpt::maps::COccupancyGridMap2D g = openGrid();
    planning::TruthCells truth;
    truth.nx = g.getSizeX(), truth.ny = g.getSizeY();
    truth.cls.assign(size_t(truth.nx) * truth.ny, 0);
    truth.cls[0] = 1;  // an untraversable cell in the west band: never a start
    const auto pairs = planning::oppositeSidePairs(g, truth, 40, 5);
    ASSERT_EQ(pairs.size(), 40u);
    for (size_t k = 0; k < pairs.size(); k++) {
        const auto& [s, e] = pairs[k];
        EXPECT_EQ(truth.at(g, s.x(), s.y()), 0);
        if (k % 2 == 0) {  // 30 columns: bands of 3
            EXPECT_LT(s.x(), 0.3);
            EXPECT_GT(e.x(), 2.7);
        } else {  // 10 rows: bands of 1
            EXPECT_LT(s.y(), 0.1);
            EXPECT_GT(e.y(), 0.9);
        }
    }
}

// MRPT's planner keeps a cell free only where its P(free) is above occupancyThreshold: at the
// default 0.5, an unknown cell (0.5) is an obstacle; below 0.5 it is passable.
TEST(TraversabilityPlanning, UnknownCellsBlockPlannerSimple2DAtItsDefaultThreshold) {
    mrpt::maps::COccupancyGridMap2D g = openGrid();
    for (unsigned cy = 0; cy < g.getSizeY(); cy++) g.setCell(g.x2idx(1.55), int(cy), 0.5f);
    mrpt::nav::PlannerSimple2D planner;
    planner.robotRadius = 0, planner.minStepInReturnedPath = 0;
    planning::Path path;
    bool notFound = false;
    planner.computePath(g, {0.25, 0.55, 0}, {2.75, 0.55, 0}, path, notFound);
    EXPECT_TRUE(notFound);
    planner.occupancyThreshold = 0.49f;
    planner.computePath(g, {0.25, 0.55, 0}, {2.75, 0.55, 0}, path, notFound);
    EXPECT_FALSE(notFound);
}
