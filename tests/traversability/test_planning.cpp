/* MRPT's PlannerSimple2D on the occupancy grid the map exports (getAsOccupancyGrid): paths that
 * cross no cell the truth calls untraversable, found wherever the truth's own grid has one, and
 * no longer than 1.15 x the truth's. */
#include <gtest/gtest.h>
#include <mrpt/maps/CMultiBinElevationMap.h>
#include <mrpt/maps/COccupancyGridMap2D.h>
#include <mrpt/nav/planners/PlannerSimple2D.h>

#include <cmath>
#include <deque>
#include <random>

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

/** The truth's grid: the features of the terrain sampled every 2 mm over each cell's disc. */
mrpt::maps::COccupancyGridMap2D truthGrid(const traversability::TraversabilityOptions& o,
                                          std::vector<uint8_t>& untraversable) {
    mrpt::maps::COccupancyGridMap2D g(0, float(kSideX), 0, float(kSideY), float(kCell));
    untraversable.assign(g.getSizeX() * g.getSizeY(), 0);
    for (unsigned cy = 0; cy < g.getSizeY(); cy++)
        for (unsigned cx = 0; cx < g.getSizeX(); cx++) {
            const double x0 = g.idx2x(cx), y0 = g.idx2y(cy);
            traversability::DiscAccumulator acc;
            for (double dy = -o.radius_m; dy <= o.radius_m; dy += 0.002)
                for (double dx = -o.radius_m; dx <= o.radius_m; dx += 0.002)
                    if (dx * dx + dy * dy <= o.radius_m * o.radius_m)
                        acc.add(dx, dy, terrain(x0 + dx, y0 + dy));
            traversability::DiscFeatures f;
            acc.features(f);
            const bool bad = f.step_m > o.max_step_m || f.slope_deg > o.max_slope_deg ||
                             f.roughness_m > o.max_roughness_m;
            untraversable[cy * g.getSizeX() + cx] = bad;
            g.setCell(int(cx), int(cy), bad ? 0.f : 1.f);
        }
    return g;
}

double lengthOf(const std::deque<mrpt::math::TPoint2D>& path) {
    double l = 0;
    for (size_t i = 1; i < path.size(); i++) l += (path[i] - path[i - 1]).norm();
    return l;
}
}  // namespace

TEST(TraversabilityPlanning, PlannerSimple2DOnTheExportedGridMatchesTheTruths) {
    CMultiBinElevationMap map = mapOfTerrain(3);
    mrpt::maps::COccupancyGridMap2D grid;
    map.getAsOccupancyGrid(grid);
    std::vector<uint8_t> truthBad;
    const mrpt::maps::COccupancyGridMap2D truth = truthGrid(map.traversabilityOptions, truthBad);
    ASSERT_EQ(grid.getSizeX(), truth.getSizeX());
    ASSERT_EQ(grid.getSizeY(), truth.getSizeY());

    mrpt::nav::PlannerSimple2D planner;
    planner.robotRadius = 0.0f;  // the layer's disc is the robot's footprint already
    planner.minStepInReturnedPath = 0.0f;
    // Start and goal pairs across the obstacles, and one the wall and ramp shut off with the step
    // side (y in 0.7..1.0 is open at the wall but the ramp blocks y > 0.45 beyond it).
    const std::vector<std::pair<mrpt::poses::CPose2D, mrpt::poses::CPose2D>> pairs = {
        {{0.1, 0.1, 0}, {1.5, 0.1, 0}},  {{0.1, 0.9, 0}, {1.5, 0.9, 0}},
        {{0.1, 0.5, 0}, {0.8, 0.2, 0}},  {{0.7, 0.9, 0}, {1.4, 0.3, 0}},
        {{0.1, 0.2, 0}, {0.45, 0.5, 0}}, {{1.3, 0.1, 0}, {0.05, 0.95, 0}}};
    int found = 0;
    for (const auto& [start, goal] : pairs) {
        std::deque<mrpt::math::TPoint2D> truthPath, path;
        bool truthNotFound = true, notFound = true;
        planner.computePath(truth, start, goal, truthPath, truthNotFound);
        planner.computePath(grid, start, goal, path, notFound);
        EXPECT_EQ(notFound, truthNotFound) << start << " -> " << goal;
        if (notFound || truthNotFound) continue;
        found++;
        for (const auto& p : path) {
            const int cx = truth.x2idx(p.x), cy = truth.y2idx(p.y);
            EXPECT_FALSE(truthBad[size_t(cy) * truth.getSizeX() + size_t(cx)])
                << "the path " << start << " -> " << goal << " crosses (" << p.x << ", " << p.y
                << "), untraversable in truth";
        }
        EXPECT_LE(lengthOf(path), 1.15 * lengthOf(truthPath)) << start << " -> " << goal;
    }
    EXPECT_GE(found, 4);  // most pairs have a path (the test is not vacuous)
}
