/* Tests of the visibility constraint: stale heights are removed, consistent ones kept. */
#include <gtest/gtest.h>
#include <mrpt/maps/CMultiBinElevationMap.h>

#include <array>
#include <cstring>
#include <limits>
#include <random>

#include "../common/test_scenes.h"
#include "multibin/grid/CellSurface.h"
#include "multibin/grid/VisibilityConstraint.h"
#include "multibin/grid/VisibilityRule.h"
#include "multibin/map/MapStatistics.h"
#include "visibility_test_util.h"

using namespace multibin;
using multibin::test::binsOf;
using multibin::test::pointAt;

TEST(Visibility, StaleOccluderLessCertainThanTheTargetIsRemoved) {
    BinGrid g(0.1);
    g.reset(0.1, CellWindow{-5, -5, 30, 10});
    BinUpdateParams p;
    VisibilityParams v;
    // A stale 0.35 m reading at x = 1.05 (certainty 1) and a 0 m target at x = 2.05.
    g.beginCycle();
    g.insertPoints({pointAt(1.05, 0.05, 0.35, 0.005)}, p);
    // Sensor at (0, 0, 0.5): the line of sight to (2.05, 0) passes x = 1.05 at about 0.25 m, below
    // the stale 0.35 m: it must go once the target is more certain.
    g.beginCycle();
    g.insertPoints({pointAt(2.05, 0.05, 0.0, 0.005), pointAt(2.05, 0.05, 0.0, 0.005)}, p);
    const VisibilityStats s = applyVisibilityConstraint(g, {0.05, 0.05, 0.5}, v, p);
    EXPECT_EQ(s.raysCast, 1u);
    EXPECT_EQ(s.binsRemoved, 1u);
    EXPECT_EQ(g.winningBin(10, 0), nullptr);
    ASSERT_NE(g.winningBin(20, 0), nullptr);
}

TEST(Visibility, RuleEditsABinJustAboveTheConflictHeightAndKeepsOneJustBelow) {
    // By hand: sensor at (0.05, 0.05, 0.5), target cell centre (2.05, 0.05) at 0 m. The sample
    // at d = 1.0 m from the target lies in cell 10 (x = 1.05): the ray is at 0.25 m there (slope
    // 0.5 / 2.0), plus the in-cell rise 0.25 * 0.7072 * 0.1 m; a bin conflicts above that by the
    // margin plus 3 sigma of the bin (ConflictTest). 2 mm above: removed; 2 mm below: kept.
    BinUpdateParams p;
    VisibilityParams v;
    const double rayHigh_m = 0.25 + 0.25 * 0.7072 * 0.1;
    for (const double offset_m : {0.002, -0.002}) {
        BinGrid g(0.1);
        g.reset(0.1, CellWindow{-5, -5, 30, 10});
        g.beginCycle();
        g.insertPoints({pointAt(1.05, 0.05, 0.3, 0.005)}, p);  // any height: for its sigma
        const double conflictAt_m = rayHigh_m + ConflictTest(v, p).margin_m(*g.winningBin(10, 0));
        g.reset(0.1, CellWindow{-5, -5, 30, 10});
        g.beginCycle();
        g.insertPoints({pointAt(1.05, 0.05, conflictAt_m + offset_m, 0.005)}, p);
        g.beginCycle();
        g.insertPoints({pointAt(2.05, 0.05, 0.0, 0.005), pointAt(2.05, 0.05, 0.0, 0.005)}, p);
        const VisibilityStats s = applyVisibilityRule(g, {0.05, 0.05, 0.5}, v, p);
        EXPECT_EQ(s.raysCast, 1u);
        EXPECT_EQ(s.binsRemoved, offset_m > 0 ? 1u : 0u) << offset_m;
        EXPECT_EQ(g.winningBin(10, 0) == nullptr, offset_m > 0) << offset_m;
    }
}

TEST(Visibility, OccluderIsWeighedAgainstTheCellSurfaceNotItsWinningBin) {
    // The target cell's surface lies at a bin boundary: two points in bin 0 and two in bin 1, one
    // surface of certainty 4 whose winning bin alone has 2. A stale occluder of certainty 3 is
    // less certain than the surface the map reports there: it goes, not merely weakened.
    BinGrid g(0.1);
    g.reset(0.1, CellWindow{-5, -5, 30, 10});
    BinUpdateParams p;
    VisibilityParams v;
    g.beginCycle();
    for (int i = 0; i < 3; i++) g.insertPoints({pointAt(1.05, 0.05, 0.35, 0.005)}, p);
    g.insertPoints({pointAt(2.05, 0.05, 0.048, 0.005), pointAt(2.05, 0.05, 0.048, 0.005),
                    pointAt(2.05, 0.05, 0.052, 0.005)},
                   p);
    g.beginCycle();
    g.insertPoints({pointAt(2.05, 0.05, 0.052, 0.005)}, p);
    CellSurface surface;
    ASSERT_TRUE(cellSurface(g, 20, 0, p, surface));
    EXPECT_DOUBLE_EQ(surface.certainty, 4.0);
    EXPECT_FLOAT_EQ(g.winningBin(20, 0)->certainty, 2.f);
    const VisibilityStats s = applyVisibilityConstraint(g, {0.05, 0.05, 0.5}, v, p);
    EXPECT_EQ(s.binsRemoved, 1u);
    EXPECT_EQ(s.binsWeakened, 0u);
    EXPECT_EQ(g.winningBin(10, 0), nullptr);
}

TEST(Visibility, MoreCertainOccluderOnlyLosesCertainty) {
    // One contradicting point: the decrement (1), then the share of the rest: (5 - 1) x 0.5 by
    // default; the paper's fixed amount with share 0.
    for (const float share : {0.5f, 0.0f}) {
        SCOPED_TRACE(share);
        BinGrid g(0.1);
        g.reset(0.1, CellWindow{-5, -5, 30, 10});
        BinUpdateParams p;
        VisibilityParams v;
        v.certaintyShare = share;
        g.beginCycle();
        for (int i = 0; i < 5; i++) g.insertPoints({pointAt(1.05, 0.05, 0.30, 0.005)}, p);
        g.beginCycle();
        g.insertPoints({pointAt(2.05, 0.05, 0.0, 0.005)}, p);
        const VisibilityStats s = applyVisibilityConstraint(g, {0.05, 0.05, 0.5}, v, p);
        EXPECT_EQ(s.binsRemoved, 0u);
        EXPECT_EQ(s.binsWeakened, 1u);
        ASSERT_NE(g.winningBin(10, 0), nullptr);
        EXPECT_FLOAT_EQ(g.winningBin(10, 0)->certainty, share > 0 ? 2.f : 4.f);
    }
}

TEST(Visibility, ConsistentTerrainIsUntouched) {
    // A slope rising away from the sensor: every cell is visible, nothing is stale. The same
    // slope with one cell raised 5 cm into the line of sight: exactly that bin is edited.
    for (const bool raised : {false, true}) {
        BinGrid g(0.1);
        g.reset(0.1, CellWindow{-5, -5, 30, 10});
        BinUpdateParams p;
        VisibilityParams v;
        g.beginCycle();
        for (int i = 3; i < 20; i++) {
            // The line of sight from (0.05, 0.25) to (2.05, 0.2) passes x = 1.25 at 0.22 m.
            const double z = raised && i == 12 ? 0.27 : 0.01 * i;
            g.insertPoints({pointAt(0.1 * i + 0.05, 0.05, z, 0.005)}, p);
        }
        g.beginCycle();
        g.insertPoints({pointAt(2.05, 0.05, 0.2, 0.005)}, p);
        BinGrid reference = g;
        // Sensor 0.25 m up: the line of sight runs low over the slope for a while.
        const VisibilityStats s = applyVisibilityConstraint(g, {0.05, 0.05, 0.25}, v, p);
        const VisibilityStats r = applyVisibilityRule(reference, {0.05, 0.05, 0.25}, v, p);
        // Raised: weakened by the contradicting point to certainty 0, hence also removed.
        EXPECT_EQ(s.binsWeakened, raised ? 1u : 0u);
        EXPECT_EQ(s.binsRemoved, raised ? 1u : 0u);
        EXPECT_EQ(s.binsRemoved, r.binsRemoved);
        EXPECT_EQ(s.binsWeakened, r.binsWeakened);
        EXPECT_EQ(binsOf(g), binsOf(reference));
        if (raised) EXPECT_EQ(g.winningBin(12, 0), nullptr) << "less certain than the target";
        // The rule walks every cell under the line; the local bound only those near it.
        EXPECT_LE(s.cellsVisited, r.cellsVisited);
        EXPECT_GT(r.cellsVisited, 5u);
    }
}

TEST(Visibility, LocalHeightBoundEditsTheSameBinsAsTheGlobalWalk) {
    // Random terrains with spikes and stale layers, random updates and sensor positions (above,
    // below, on a cell-centre line so samples fall on cell edges, far outside the window), on
    // windows that were moved and grown (block slots reused): the library's constraint must
    // leave every bin bit-identical to the rule (applyVisibilityRule), with the same counts.
    std::mt19937 rng(20261122);
    std::uniform_real_distribution<double> unit(0.0, 1.0);
    size_t edits = 0, visited = 0, visitedReference = 0, scenes = 0;
    for (int scene = 0; scene < 300; scene++) {
        const double cell = unit(rng) < 0.5 ? 0.015 : 0.1;
        const int nx = 8 + int(unit(rng) * 60), ny = 8 + int(unit(rng) * 60);
        const int ix0 = int(unit(rng) * 40) - 20, iy0 = int(unit(rng) * 40) - 20;
        BinGrid g(cell);
        g.reset(cell, CellWindow{ix0, iy0, nx, ny});
        BinUpdateParams p;
        VisibilityParams v;
        const double slopeX = (unit(rng) - 0.5) * 0.4, slopeY = (unit(rng) - 0.5) * 0.4;
        auto ground = [&](int ix, int iy) {
            return slopeX * ix * cell + slopeY * iy * cell + 0.01 * std::sin(ix * 0.7 + iy * 1.3);
        };
        auto fill = [&](const CellWindow& w) {
            for (int iy = w.iy0; iy < w.iy0 + w.ny; iy++)
                for (int ix = w.ix0; ix < w.ix0 + w.nx; ix++) {
                    if (unit(rng) < 0.15) continue;  // unobserved
                    double z = ground(ix, iy);
                    if (unit(rng) < 0.03) z += 0.05 + unit(rng) * 0.8;  // spikes, stale objects
                    const int reps = 1 + int(unit(rng) * 4);
                    PointsWithCov pts;
                    for (int k = 0; k < reps; k++)
                        pts.push_back(pointAt(g.cellCenter_m(ix), g.cellCenter_m(iy),
                                              z + 0.002 * unit(rng), 0.002 + 0.01 * unit(rng)));
                    if (unit(rng) < 0.2)  // a second layer
                        pts.push_back(pointAt(g.cellCenter_m(ix), g.cellCenter_m(iy),
                                              z + 0.1 + 0.3 * unit(rng), 0.005));
                    g.beginCycle();
                    g.insertPoints(pts, p);
                }
        };
        fill(g.window());
        if (unit(rng) < 0.4) {  // move: entering cells reuse the slots of leaving blocks
            const int mx = int(unit(rng) * 2 * nx) - nx, my = int(unit(rng) * 2 * ny) - ny;
            g.moveWindowTo(ix0 + mx, iy0 + my);
            fill(g.window());
        }
        if (unit(rng) < 0.2) {  // grow: the block table is rebuilt
            const CellWindow w = g.window();
            g.growToInclude(CellWindow{w.ix0 - 5, w.iy0 - 3, w.nx + 9, w.ny + 4});
            fill(CellWindow{w.ix0 - 5, w.iy0 - 3, 5, 3});
        }
        // The update: a random subset of cells seen lower than stored (objects gone) or at
        // the ground.
        const CellWindow w = g.window();
        g.beginCycle();
        PointsWithCov update;
        const int n = 1 + int(unit(rng) * 40);
        for (int k = 0; k < n; k++) {
            const int ix = w.ix0 + int(unit(rng) * w.nx), iy = w.iy0 + int(unit(rng) * w.ny);
            const double z = ground(ix, iy) - (unit(rng) < 0.3 ? 0.1 * unit(rng) : 0.0);
            for (int r = int(unit(rng) * 3); r >= 0; r--)
                update.push_back(pointAt(g.cellCenter_m(ix), g.cellCenter_m(iy), z, 0.003));
        }
        g.insertPoints(update, p);
        Eigen::Vector3d sensor((w.ix0 + unit(rng) * w.nx) * cell, (w.iy0 + unit(rng) * w.ny) * cell,
                               unit(rng) < 0.8 ? 0.2 + unit(rng) * 1.0 : -0.3 - unit(rng) * 0.5);
        const double kind = unit(rng);
        if (kind < 0.2) sensor.y() = g.cellCenter_m(w.iy0 + int(unit(rng) * w.ny));
        if (kind > 0.2 && kind < 0.3) sensor.x() = g.cellCenter_m(w.ix0 + int(unit(rng) * w.nx));
        if (kind > 0.95) sensor.x() += 50.0;  // far outside the window
        if (kind > 0.93 && kind < 0.95) sensor.z() = std::numeric_limits<double>::quiet_NaN();
        BinGrid reference = g;
        // Every other scene without the fan test (a camera frame's rays): the walk's own tests.
        const RayFan fan = scene % 2 ? RayFan::Skip : RayFan::Test;
        const VisibilityStats s = applyVisibilityConstraint(g, sensor, v, p, fan);
        const VisibilityStats r = applyVisibilityRule(reference, sensor, v, p);
        ASSERT_EQ(s.raysCast, r.raysCast) << "scene " << scene;
        ASSERT_EQ(s.binsRemoved, r.binsRemoved) << "scene " << scene;
        ASSERT_EQ(s.binsWeakened, r.binsWeakened) << "scene " << scene;
        ASSERT_EQ(g.binCount(), reference.binCount()) << "scene " << scene;
        ASSERT_TRUE(binsOf(g) == binsOf(reference)) << "scene " << scene;
        edits += r.binsRemoved + r.binsWeakened;
        visited += s.cellsVisited;
        visitedReference += r.cellsVisited;
        scenes++;
    }
    std::cout << scenes << " scenes, " << edits << " bins edited; cells tested " << visited
              << " against the rule's " << visitedReference << "\n";
    EXPECT_GT(edits, 300u) << "the scenes must exercise the constraint";
    EXPECT_LT(visited, visitedReference);
}

namespace {
/** Laser-like fans over rough ground: a sensor 0.15-0.8 m up (sometimes below the ground or
 * near a window edge), its rays ending on an arc of updated cells, rocks (discs up to 0.3 m) and
 * stale spikes near the sensor and beside the targets, so that rays pass just above or just
 * below blocks, units and cells. The library's fan test clears a ray only if no square it passes
 * over can conflict: every bin must stay bit-identical to the rule. With
 * `farCornerTargets`, some rays also end in the cell of their block farthest from the sensor,
 * with a stale bin a cell or so towards the sensor within a centimetre of the conflict height:
 * there a ray's samples in its own block reach almost the block's farthest distance from the
 * sensor, where the slope test bounds the ray's height. Returns the bins edited and the rays. */
std::pair<size_t, size_t> checkFansOverRocks(uint32_t seed, int sceneCount, bool farCornerTargets) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> unit(0.0, 1.0);
    size_t edits = 0, rays = 0;
    for (int scene = 0; scene < sceneCount; scene++) {
        const double cell = unit(rng) < 0.7 ? 0.015 : 0.05;
        const int n = 60 + int(unit(rng) * 80);
        const int ix0 = int(unit(rng) * 200) - 100, iy0 = int(unit(rng) * 200) - 100;
        BinGrid g(cell);
        g.reset(cell, CellWindow{ix0, iy0, n, n});
        BinUpdateParams p;
        VisibilityParams v;
        struct Rock {
            double x, y, r, h;
        };
        std::vector<Rock> rocks;
        const CellWindow w = g.window();
        for (int k = int(unit(rng) * 12); k > 0; k--)
            rocks.push_back({(w.ix0 + unit(rng) * w.nx) * cell, (w.iy0 + unit(rng) * w.ny) * cell,
                             (2 + unit(rng) * 8) * cell, 0.02 + unit(rng) * 0.28});
        const double tilt = (unit(rng) - 0.5) * 0.2;
        auto ground = [&](double x, double y) {
            double z = tilt * x + 0.004 * std::sin(x * 40) * std::cos(y * 30);
            for (const Rock& r : rocks)
                if (std::hypot(x - r.x, y - r.y) < r.r) z = std::max(z, r.h);
            return z;
        };
        for (int iy = w.iy0; iy < w.iy0 + w.ny; iy++)
            for (int ix = w.ix0; ix < w.ix0 + w.nx; ix++) {
                if (unit(rng) < 0.1) continue;
                const double x = g.cellCenter_m(ix), y = g.cellCenter_m(iy);
                double z = ground(x, y);
                if (unit(rng) < 0.01) z += 0.03 + unit(rng) * 0.3;  // stale spikes
                PointsWithCov pts{pointAt(x, y, z, 0.002 + 0.004 * unit(rng))};
                if (unit(rng) < 0.3) pts.push_back(pointAt(x, y, z + 0.001, 0.003));
                g.beginCycle();
                g.insertPoints(pts, p);
            }
        // The sensor and its fan: targets on an arc, seen at the ground or lower (objects gone).
        const double sx = (w.ix0 + (0.1 + 0.8 * unit(rng)) * w.nx) * cell;
        const double sy = (w.iy0 + (0.1 + 0.8 * unit(rng)) * w.ny) * cell;
        const double kind = unit(rng);
        const double sz = kind < 0.1 ? -0.2 : ground(sx, sy) + 0.15 + unit(rng) * 0.65;
        const double heading = unit(rng) * 2 * M_PI, aperture = 0.5 + unit(rng) * 4.0;
        const double range = (0.2 + unit(rng) * 0.6) * n * cell;
        PointsWithCov update;
        for (int b = 0; b < 200; b++) {
            const double a = heading - 0.5 * aperture + aperture * b / 199.0;
            const double r = range * (0.5 + 0.5 * unit(rng));
            const double x = sx + r * std::cos(a), y = sy + r * std::sin(a);
            const int ix = g.cellIndex(x), iy = g.cellIndex(y);
            if (!w.contains(ix, iy)) continue;
            const double z = ground(g.cellCenter_m(ix), g.cellCenter_m(iy)) -
                             (unit(rng) < 0.2 ? 0.1 * unit(rng) : 0.0);
            update.push_back(pointAt(g.cellCenter_m(ix), g.cellCenter_m(iy), z, 0.003));
        }
        // Rays ending in their block's farthest cell from the sensor, or a cell or so inside its
        // nearest corner (so the ray's first samples lie barely inside the block), a near miss
        // beside them.
        PointsWithCov nearMisses;
        for (size_t k = 0, n0 = update.size(); farCornerTargets && k < n0; k++) {
            const double kind = unit(rng);
            if (kind < 0.5) continue;
            const bool far = kind < 0.85;
            const int bx = BinGrid::blockOf(g.cellIndex(update[k].point_m.x()));
            const int by = BinGrid::blockOf(g.cellIndex(update[k].point_m.y()));
            // The block's first row or column faces away from the sensor or towards it.
            const bool lowX = g.cellCenter_m(bx * BinGrid::kBlockCells) < sx;
            const bool lowY = g.cellCenter_m(by * BinGrid::kBlockCells) < sy;
            const int inX = far ? 0 : int(unit(rng) * 2.99), inY = far ? 0 : int(unit(rng) * 2.99);
            const int ix =
                bx * BinGrid::kBlockCells + (lowX == far ? inX : BinGrid::kBlockCells - 1 - inX);
            const int iy =
                by * BinGrid::kBlockCells + (lowY == far ? inY : BinGrid::kBlockCells - 1 - inY);
            if (!w.contains(ix, iy)) continue;
            const double tx = g.cellCenter_m(ix), ty = g.cellCenter_m(iy), tz = ground(tx, ty);
            const double dx = sx - tx, dy = sy - ty, length = std::hypot(dx, dy);
            if (length < 4 * cell) continue;
            update.push_back(pointAt(tx, ty, tz, 0.003));
            // Just past the target's cell: there the slope test's bound is tightest.
            const double d =
                (0.5 + 0.6 * unit(rng)) * cell / std::max(std::abs(dx), std::abs(dy)) * length;
            const double slope = (sz - tz) / length;
            const double x = tx + dx / length * d, y = ty + dy / length * d;
            if (g.cellIndex(x) == ix && g.cellIndex(y) == iy) continue;
            const double conflictAt = tz + slope * d + std::abs(slope) * 0.7072 * cell + 0.026;
            nearMisses.push_back(pointAt(x, y, conflictAt + (unit(rng) - 0.4) * 0.02, 0.001));
        }
        for (const PointWithCov& m : nearMisses) {
            g.beginCycle();
            g.insertPoints({m}, p);
        }
        // Near misses: on some rays, a stale bin in the cell where the ray leaves a block or a
        // unit towards its target (where it is lowest over that square), within a centimetre
        // of the conflict height there (the walk's ray height, cell rise and margin).
        for (const PointWithCov& t : update) {
            if (unit(rng) < 0.6) continue;
            const double tx = t.point_m.x(), ty = t.point_m.y(), tz = t.point_m.z();
            const double dx = sx - tx, dy = sy - ty, length = std::hypot(dx, dy);
            if (length < 4 * cell) continue;
            const double slope = (sz - tz) / length;
            const double square_m = (unit(rng) < 0.5 ? 16 : 4) * cell;
            // The first crossing of a square's edge going from the target towards the sensor.
            double d = length;
            for (const auto& [from, towards] : {std::pair{tx, dx}, std::pair{ty, dy}}) {
                if (towards == 0) continue;
                const double edge = towards > 0 ? std::ceil(from / square_m) * square_m
                                                : std::floor(from / square_m) * square_m;
                d = std::min(d, (edge - from) / towards * length);
            }
            d += 0.25 * cell * unit(rng);  // just inside the square
            if (d >= length - cell) continue;
            const double x = tx + dx / length * d, y = ty + dy / length * d;
            const double conflictAt = tz + slope * d + std::abs(slope) * 0.7072 * cell + 0.026;
            g.beginCycle();
            g.insertPoints({pointAt(x, y, conflictAt + (unit(rng) - 0.4) * 0.02, 0.001)}, p);
        }
        g.beginCycle();
        g.insertPoints(update, p);
        const Eigen::Vector3d sensor(sx, sy, sz);
        BinGrid reference = g;
        const VisibilityStats s = applyVisibilityConstraint(g, sensor, v, p);
        const VisibilityStats r = applyVisibilityRule(reference, sensor, v, p);
        EXPECT_EQ(s.raysCast, r.raysCast) << "scene " << scene;
        EXPECT_EQ(s.binsRemoved, r.binsRemoved) << "scene " << scene;
        EXPECT_EQ(s.binsWeakened, r.binsWeakened) << "scene " << scene;
        EXPECT_TRUE(binsOf(g) == binsOf(reference)) << "scene " << scene;
        if (::testing::Test::HasFailure()) break;  // the first failing scene only
        edits += r.binsRemoved + r.binsWeakened;
        rays += r.raysCast;
    }
    return {edits, rays};
}
}  // namespace

TEST(Visibility, FanTestEditsTheSameBinsAsTheGlobalWalkOverRocks) {
    const auto [edits, rays] = checkFansOverRocks(20261124, 120, false);
    std::cout << rays << " rays, " << edits << " bins edited\n";
    EXPECT_GT(edits, 500u) << "the scenes must exercise the constraint";
}

TEST(Visibility, FanTestEditsTheSameBinsAsTheGlobalWalkForRaysEndingAtABlocksFarCorner) {
    // The slope test bounds a ray over a block by its height at the block's farthest distance
    // from the sensor, whether or not the ray reaches that far (its samples never lie farther).
    const auto [edits, rays] = checkFansOverRocks(20261125, 300, true);
    std::cout << rays << " rays, " << edits << " bins edited\n";
    EXPECT_GT(edits, 500u) << "the scenes must exercise the constraint";
}

TEST(Visibility, UpdatedCellBinAboveTheNewMeasurementsLosesCertainty) {
    BinGrid g(0.1);
    g.reset(0.1, CellWindow{-5, -5, 30, 10});
    BinUpdateParams p;
    VisibilityParams v;
    g.beginCycle();
    g.insertPoints({pointAt(1.05, 0.05, 0.30, 0.005), pointAt(1.05, 0.05, 0.30, 0.005)}, p);
    for (int cycle = 0; cycle < 2; cycle++) {
        g.beginCycle();
        g.insertPoints({pointAt(1.05, 0.05, 0.0, 0.005)}, p);
        applyVisibilityConstraint(g, {0.05, 0.05, 0.5}, v, p);
    }
    // The 0.3 m bin lost 1 per contradicting point and vanished after two; the ground bin wins.
    size_t bins = 0;
    g.forEachBin(10, 0, [&](const Bin&) { bins++; });
    EXPECT_EQ(bins, 1u);
    EXPECT_NEAR(g.winningBin(10, 0)->height_m, 0.0, 1e-6);
}

namespace {
struct BoxTerrain {
    bool boxPresent = true;
    double operator()(double x, double y) const {
        const double ground = 0.01 * std::sin(3 * x) * std::cos(2 * y);
        const bool inBox = x > 0.60 && x < 0.75 && y > -0.10 && y < 0.10;
        return boxPresent && inBox ? 0.12 : ground;
    }
};

/** Drives the pitched laser from x = -0.3 to 0.9 in 10 mm steps. */
void drive(mrpt::maps::CMultiBinElevationMap& map, const BoxTerrain& terrain) {
    mrpt::poses::CPose3DPDFGaussian pose;
    pose.cov.setIdentity();
    pose.cov *= 1e-8;
    for (double x = -0.3; x <= 0.9; x += 0.01) {
        pose.mean = mrpt::poses::CPose3D(x, 0, 0, 0, 0, 0);
        map.insertObservation(
            *test_scenes::pitchedScanOver(terrain, pose.mean, 0.26, mrpt::DEG2RAD(45.0)), pose);
    }
}
}  // namespace

TEST(Visibility, MovedObjectIsForgottenAndItsSurroundingsKept) {
    mrpt::maps::CMultiBinElevationMap::TCreationOptions c;
    c.resolution_m = 0.015;
    BoxTerrain terrain;
    for (const bool constraint : {true, false}) {
        mrpt::maps::CMultiBinElevationMap map(c);
        map.insertionOptions.visibility.enabled = constraint;
        // Judged on the winning surface and its Kalman sigma: with relief_sigma, box bins left
        // in a cell raise that cell's sigma (their honest effect on the reported uncertainty),
        // which would hide whether the surface itself came back to the ground.
        map.insertionOptions.query.relief_sigma = false;
        terrain.boxPresent = true;
        drive(map, terrain);
        double h, s;
        ASSERT_TRUE(map.getHeight(0.70, 0.0, h, s));
        EXPECT_NEAR(h, 0.12, 0.01) << "the box is mapped in the first pass";
        terrain.boxPresent = false;
        drive(map, terrain);
        // Inside the old footprint and around it: height within 2 sigma of the true ground; and
        // over every cell, those the faces cross included, the RMSE from the ground.
        size_t cells = 0, within2Sigma = 0, around = 0, aroundOk = 0, all = 0;
        double sumSquares_m2 = 0;
        for (double x = 0.55; x < 0.80; x += 0.015)
            for (double y = -0.15; y < 0.15; y += 0.015) {
                if (!map.getHeight(x, y, h, s)) continue;
                const double truth = terrain(x, y);
                all++;
                sumSquares_m2 += (h - truth) * (h - truth);
                // The 2 sigma test on cells wholly inside the box's footprint. The cells its
                // faces cross also fused the faces' low points into their ground bin: they are
                // judged by the RMSE above (tests/sim/test_moved_object.cpp: with noise).
                const bool onFaces = (x > 0.585 && x < 0.615) || (x > 0.735 && x < 0.765) ||
                                     std::abs(std::abs(y) - 0.10) < 0.015;
                const bool inFootprint = x > 0.615 && x < 0.735 && std::abs(y) < 0.085;
                if (onFaces) continue;
                const bool ok = std::abs(h - truth) <= 2 * s + 0.003;  // + within-cell relief
                if (inFootprint) {
                    cells++;
                    within2Sigma += ok;
                } else {
                    around++;
                    aroundOk += ok;
                }
            }
        const double rmse_m = std::sqrt(sumSquares_m2 / double(std::max<size_t>(all, 1)));
        if (constraint) {
            EXPECT_LE(rmse_m, 0.015) << "faces included (issue 18's bound)";
            EXPECT_GT(cells, 50u);
            EXPECT_EQ(within2Sigma, cells) << "footprint cells back on the ground";
            EXPECT_GE(double(aroundOk), 0.95 * double(around)) << "surroundings unharmed";
            EXPECT_GT(
                map.statistics().visibility.binsRemoved + map.statistics().visibility.binsWeakened,
                0u);
        } else {
            // Without the constraint the box lingers: this is what the constraint fixes.
            EXPECT_LT(within2Sigma, cells);
            EXPECT_GT(rmse_m, 0.015);
        }
        std::cout << (constraint ? "with" : "without") << " visibility constraint: " << within2Sigma
                  << " / " << cells << " footprint cells within 2 sigma, " << aroundOk << " / "
                  << around << " around; RMSE over all " << all << " cells " << 1e3 * rmse_m
                  << " mm\n";
    }
}

TEST(Visibility, SubCellAnswerWeighsWhatTheConstraintTookFromAFace) {
    // A 20 mm cell crossed by a box's face: 12 ground points over the cell, 40 face points in a
    // strip 4 mm from its left edge (the scan line swept up the face). While the face stands,
    // heightAt answers it over the part of the cell its points cover; once the constraint has
    // taken 32 of its certainty (newer rays saw through it), over less (with the points as the
    // prior: as much), and the cell value is the ground.
    BinGrid g(0.02);
    g.reset(0.02, CellWindow{-5, -5, 10, 10});
    BinUpdateParams p;
    g.beginCycle();
    PointsWithCov pts;
    for (int i = 0; i < 4; i++)
        for (int j = 0; j < 3; j++)
            pts.push_back(pointAt(0.0025 + 0.005 * i, 0.004 + 0.006 * j, 0.01, 0.002));
    for (int k = 0; k < 40; k++)
        pts.push_back(pointAt(0.004, 0.001 + 0.00045 * k, 0.055 + 0.001 * k, 0.002));
    g.insertPoints(pts, p);
    // The share of a 10 x 10 lattice over the cell where heightAt answers the face.
    auto faceShare = [&]() {
        int face = 0;
        for (int i = 0; i < 10; i++)
            for (int j = 0; j < 10; j++) {
                CellSurface s;
                EXPECT_TRUE(
                    heightAt(g, nullptr, 0.001 + 0.002 * i, 0.001 + 0.002 * j, p, false, s));
                face += s.height_m > 0.04;
            }
        return face / 100.0;
    };
    const double standing = faceShare();
    g.editBins(0, 0, [](Bin& b) {
        if (b.index == 1) b.certainty -= 32;  // as applyVisibilityConstraint's decrement does
        return true;
    });
    const double weakened = faceShare();
    CellSurface cell;
    ASSERT_TRUE(cellSurface(g, 0, 0, p, cell));
    EXPECT_NEAR(cell.height_m, 0.01, 0.002) << "the cell value: the most certain surface";
    std::cout << "the face answers heightAt over " << standing << " of the cell while it stands, "
              << weakened << " once weakened\n";
    EXPECT_GE(standing, 0.2);
    EXPECT_LT(weakened, standing);
}

TEST(Visibility, ClearanceIsTheLowestLineOfSightOverACellWithinTheRiseLimit) {
    // By hand: sensor at (0.05, 0.05, 0.5), target cell 20 (centre x = 2.05) at 0 m: the line
    // towards the sensor rises 0.25 m per m, so over cell k (x from 0.1 k to 0.1 k + 0.1) it lies
    // between 0.25 (2.05 - 0.1 k - 0.1) and 0.25 (2.05 - 0.1 k) m. The walk stops once the line
    // is kClearanceRise_m above the target (d = 0.32 m), so cells 19, 18, 17 (samples at
    // d = 0.1, 0.2, 0.3 m) get one and cell 16 (d = 0.4 m) none. No bin changes.
    ASSERT_DOUBLE_EQ(kClearanceRise_m, 0.08);  // the hand computation's limit
    BinUpdateParams p;
    BinGrid g(0.1);
    g.reset(0.1, CellWindow{-5, -5, 30, 10});
    auto lineOver = [](int k, double tz_m) {  // the line's lowest and highest over cell k
        return std::make_pair(tz_m + 0.25 * (2.05 - 0.1 * k - 0.1), tz_m + 0.25 * (2.05 - 0.1 * k));
    };
    g.beginCycle();
    g.insertPoints({pointAt(2.05, 0.05, 0.0, 0.005), pointAt(2.05, 0.05, 0.0, 0.005)}, p);
    const auto before = binsOf(g);
    noteClearances(g, {0.05, 0.05, 0.5}, kClearanceRise_m);
    EXPECT_EQ(binsOf(g), before);
    for (int k = 17; k <= 19; k++) {
        const auto [low, high] = lineOver(k, 0.0);
        EXPECT_GE(g.clearance_m(k, 0), low - 1e-6) << k;
        EXPECT_LE(g.clearance_m(k, 0), high + 1e-6) << k;
    }
    EXPECT_EQ(g.clearance_m(16, 0), std::numeric_limits<float>::infinity());
    EXPECT_EQ(g.clearance_m(20, 0), std::numeric_limits<float>::infinity());  // the target
    EXPECT_EQ(g.clearance_m(21, 0), std::numeric_limits<float>::infinity());  // beyond it
    EXPECT_EQ(g.clearance_m(19, 1), std::numeric_limits<float>::infinity());  // beside the line
    // A lower sensor's line (0.3 / 2.0 m per m) lowers it; points below the cell's surface
    // (0.2 m under it) do not: the line ends at the highest bin the cell held.
    g.beginCycle();
    g.insertPoints({pointAt(2.05, 0.05, 0.0, 0.005), pointAt(2.05, 0.05, 0.0, 0.005)}, p);
    noteClearances(g, {0.05, 0.05, 0.3}, kClearanceRise_m);
    const float lowered_m = g.clearance_m(19, 0);
    EXPECT_GE(lowered_m, 0.15 * 0.05 - 1e-6);
    EXPECT_LE(lowered_m, 0.15 * 0.15 + 1e-6);
    g.beginCycle();
    g.insertPoints({pointAt(2.05, 0.05, -0.2, 0.005), pointAt(2.05, 0.05, -0.2, 0.005)}, p);
    noteClearances(g, {0.05, 0.05, 0.5}, kClearanceRise_m);
    EXPECT_EQ(g.clearance_m(19, 0), lowered_m);
    // A lone point of an update (a range outlier, maybe) ends no line: cell 23 holds it.
    g.beginCycle();
    g.insertPoints({pointAt(2.35, 0.05, 0.0, 0.005)}, p);
    noteClearances(g, {0.05, 0.05, 0.5}, kClearanceRise_m);
    ASSERT_NE(g.winningBin(23, 0), nullptr);
    EXPECT_EQ(g.clearance_m(22, 0), std::numeric_limits<float>::infinity());
}
