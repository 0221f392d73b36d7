/* Tests of each stage of the visibility constraint's fast path against the rule
 * (VisibilityStages.h, VisibilityRule.h), on random scenes of six kinds: steps, overhangs, thin
 * posts, grazing rays, dense frames and sparse lidar revolutions. Edits only lower certainties or
 * remove bins, so a stage that rules a ray out in the unedited grid rules out what the rule would
 * do there after earlier rays' edits too: each stage is checked against the conflicts the rule's
 * sight lines meet in the unedited grid. */
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cstring>
#include <random>

#include "multibin/grid/VisibilityConstraint.h"
#include "multibin/grid/VisibilityRule.h"
#include "multibin/grid/VisibilityStages.h"
#include "visibility_test_util.h"

using namespace multibin;
using multibin::test::binsOf;
using multibin::test::pointAt;
using namespace multibin::visibility;

namespace {
/** Floor: a level floor, nothing stale, seen from above (most laser scans). */
enum class Kind { Steps, Overhangs, Posts, Grazing, DenseFrame, SparseLidar, Floor };
constexpr Kind kKinds[] = {Kind::Steps,      Kind::Overhangs,   Kind::Posts, Kind::Grazing,
                           Kind::DenseFrame, Kind::SparseLidar, Kind::Floor};

struct Scene {
    BinGrid grid;
    Eigen::Vector3d sensor_m;
};

/** A mapped terrain of the given kind, then one update (the current cycle) seen from a sensor:
 * objects gone (cells seen at the ground under where they stood) and ground seen again. */
Scene randomScene(std::mt19937& rng, Kind kind) {
    std::uniform_real_distribution<double> unit(0.0, 1.0);
    const double cell = kind == Kind::SparseLidar ? 0.1 : (unit(rng) < 0.5 ? 0.015 : 0.05);
    const int n = kind == Kind::SparseLidar ? 80 + int(unit(rng) * 60) : 40 + int(unit(rng) * 60);
    const int ix0 = int(unit(rng) * 60) - 30, iy0 = int(unit(rng) * 60) - 30;
    Scene s{BinGrid(cell), Eigen::Vector3d::Zero()};
    BinGrid& g = s.grid;
    g.reset(cell, CellWindow{ix0, iy0, n, n});
    const CellWindow w = g.window();
    const bool floor = kind == Kind::Floor;
    const double tilt = floor ? 0.0 : (unit(rng) - 0.5) * 0.2,
                 stepAt = (ix0 + unit(rng) * n) * cell;
    const double stepHeight = kind == Kind::Steps ? (unit(rng) - 0.3) * 0.4 : 0.0;
    auto ground = [&](double x, double y) {
        return tilt * x + 0.005 * std::sin(x * 30) * std::cos(y * 20) +
               (x > stepAt ? stepHeight : 0);
    };
    BinUpdateParams p;
    PointsWithCov mapped;
    for (int iy = w.iy0; iy < w.iy0 + w.ny; iy++)
        for (int ix = w.ix0; ix < w.ix0 + w.nx; ix++) {
            if (unit(rng) < 0.1) continue;  // unobserved
            const double x = g.cellCenter_m(ix), y = g.cellCenter_m(iy);
            double z = ground(x, y);
            if (kind == Kind::Posts && unit(rng) < 0.01) z += 0.1 + unit(rng) * 0.6;
            if (!floor && unit(rng) < 0.01) z += 0.03 + unit(rng) * 0.3;  // stale spikes
            for (int k = 1 + int(unit(rng) * 3); k > 0; k--)
                mapped.push_back(pointAt(x, y, z + 0.001 * unit(rng), 0.002 + 0.006 * unit(rng)));
            if (kind == Kind::Overhangs && unit(rng) < 0.15)  // a table top or a branch
                mapped.push_back(pointAt(x, y, z + 0.2 + 0.6 * unit(rng), 0.003));
        }
    g.beginCycle();
    g.insertPoints(mapped, p);
    // The sensor, and the cells it sees now.
    const double span = n * cell;
    double sx = (w.ix0 + (0.1 + 0.8 * unit(rng)) * n) * cell;
    double sy = (w.iy0 + (0.1 + 0.8 * unit(rng)) * n) * cell;
    if (kind == Kind::Grazing) {  // on a cell corner or a cell-centre line
        sx = (w.ix0 + int(unit(rng) * n)) * cell + (unit(rng) < 0.5 ? 0.0 : 0.5 * cell);
        sy = (w.iy0 + int(unit(rng) * n)) * cell + (unit(rng) < 0.5 ? 0.0 : 0.5 * cell);
    }
    const double up = kind == Kind::SparseLidar ? 0.8 + unit(rng) * 1.2 : 0.15 + unit(rng) * 0.8;
    s.sensor_m = {sx, sy, ground(sx, sy) + (!floor && unit(rng) < 0.05 ? -0.3 : up)};
    std::vector<std::pair<int, int>> seen;
    if (kind == Kind::DenseFrame) {  // every cell of a sector ahead
        const double heading = unit(rng) * 2 * M_PI, half = 0.3 + unit(rng) * 0.5;
        for (int iy = w.iy0; iy < w.iy0 + w.ny; iy++)
            for (int ix = w.ix0; ix < w.ix0 + w.nx; ix++) {
                const double dx = g.cellCenter_m(ix) - sx, dy = g.cellCenter_m(iy) - sy;
                const double off = std::remainder(std::atan2(dy, dx) - heading, 2 * M_PI);
                if (std::abs(off) < half && std::hypot(dx, dy) < 0.7 * span)
                    seen.push_back({ix, iy});
            }
    } else if (kind == Kind::Grazing) {  // along the cell row, column or diagonal of the sensor
        const int cx = g.cellIndex(sx), cy = g.cellIndex(sy);
        for (int k = 0; k < 120; k++) {
            const int dir = int(unit(rng) * 8), r = 2 + int(unit(rng) * n);
            const int ddx[] = {1, -1, 0, 0, 1, 1, -1, -1}, ddy[] = {0, 0, 1, -1, 1, -1, 1, -1};
            seen.push_back({cx + ddx[dir] * r, cy + ddy[dir] * r});
        }
    } else {  // a fan (laser) or a ring (lidar) of beams
        const bool ring = kind == Kind::SparseLidar;
        const double heading = unit(rng) * 2 * M_PI,
                     aperture = ring ? 2 * M_PI : 0.5 + 3 * unit(rng);
        for (int b = 0; b < 300; b++) {
            const double a = heading + aperture * (b / 299.0 - 0.5);
            const double r = span * (ring ? 0.1 + 0.6 * unit(rng) : 0.2 + 0.4 * unit(rng));
            seen.push_back({g.cellIndex(sx + r * std::cos(a)), g.cellIndex(sy + r * std::sin(a))});
        }
    }
    PointsWithCov update;
    for (const auto& [ix, iy] : seen) {
        if (!w.contains(ix, iy)) continue;
        const double x = g.cellCenter_m(ix), y = g.cellCenter_m(iy);
        update.push_back(pointAt(
            x, y, ground(x, y) - (!floor && unit(rng) < 0.2 ? 0.05 * unit(rng) : 0), 0.003));
    }
    g.beginCycle();
    g.insertPoints(update, p);
    return s;
}

/** The distances from the updated cell at which the rule's sight line meets a conflicting bin in
 * the unedited grid (empty: its ray edits nothing). */
std::vector<double> conflictsOnLine(const BinGrid& g, const BinGrid::UpdatedCell& u,
                                    const Eigen::Vector3d& sensor_m, const VisibilityParams& v,
                                    const BinUpdateParams& p) {
    std::vector<double> at;
    SightLine ray;
    if (!ray.set(g, u, sensor_m)) return at;
    const ConflictTest conflicts(v, p);
    forEachCellOnSightLine(g, ray, u.ix, u.iy, g.maxHeight_m() + v.margin_m,
                           [&](int ix, int iy, double d, double rayHigh_m) {
                               bool any = false;
                               g.forEachBin(ix, iy,
                                            [&](const Bin& b) { any |= conflicts(b, rayHigh_m); });
                               if (any) at.push_back(d);
                           });
    return at;
}

bool ownBinsConflict(const BinGrid& g, const BinGrid::UpdatedCell& u, const VisibilityParams& v,
                     const BinUpdateParams& p) {
    const ConflictTest conflicts(v, p);
    bool any = false;
    g.forEachBin(u.ix, u.iy, [&](const Bin& b) { any |= conflicts(b, u.maxHeight_m); });
    return any;
}

/** Stages 1 and 2 of a scene's update, with the default parameters, as the constraint builds
 * them. */
struct FirstStages {
    const VisibilityParams v;
    const BinUpdateParams p;
    const ConflictTest conflicts{v, p};
    const BoundTest bounds{conflicts.minMargin_m()};
    VisibilityScratch scratch;
    const Region region;
    const TowardsSensor towards;
    explicit FirstStages(const Scene& s)
        : region(buildRegion(s.grid, s.sensor_m, scratch.regionBound)),
          towards(buildTowardsSensor(s.grid, region, s.sensor_m, bounds, scratch.towardsSensor)) {}
    FirstStages(const FirstStages&) = delete;  // towards points into region
};

/** Runs `check(scene, kind)` on `perKind` scenes of each kind. */
template <class Check>
void onRandomScenes(uint32_t seed, int perKind, Check&& check) {
    std::mt19937 rng(seed);
    for (const Kind kind : kKinds)
        for (int k = 0; k < perKind; k++) {
            Scene scene = randomScene(rng, kind);
            check(scene, int(kind) * 1000 + k);
            if (::testing::Test::HasFatalFailure()) return;
        }
}
}  // namespace

TEST(VisibilityStages, TheFastPathEditsTheRulesBinsOnEveryKindOfScene) {
    size_t edits = 0, rays = 0;
    onRandomScenes(20261127, 25, [&](Scene& s, int id) {
        const VisibilityParams v;
        const BinUpdateParams p;
        for (const RayFan fan : {RayFan::Test, RayFan::Skip}) {
            BinGrid fast = s.grid, rule = s.grid;
            const VisibilityStats f = applyVisibilityConstraint(fast, s.sensor_m, v, p, fan);
            const VisibilityStats r = applyVisibilityRule(rule, s.sensor_m, v, p);
            ASSERT_EQ(f.raysCast, r.raysCast) << id;
            ASSERT_EQ(f.binsRemoved, r.binsRemoved) << id;
            ASSERT_EQ(f.binsWeakened, r.binsWeakened) << id;
            ASSERT_TRUE(binsOf(fast) == binsOf(rule)) << id;
            if (fan == RayFan::Test) edits += r.binsRemoved + r.binsWeakened, rays += r.raysCast;
        }
    });
    std::cout << rays << " rays, " << edits << " bins edited\n";
    EXPECT_GT(edits, 1000u) << "the scenes must exercise the constraint";
}

TEST(VisibilityStages, RegionRulesOutOnlyUpdatesWithoutAnyConflict) {
    size_t ruledOut = 0, scenes = 0;
    onRandomScenes(20261128, 25, [&](Scene& s, int id) {
        const VisibilityParams v;
        const BinUpdateParams p;
        const BoundTest bounds{ConflictTest(v, p).minMargin_m()};
        std::vector<float> table;
        // Also the same update seen from far above: most of those are ruled out.
        for (const double lift_m : {0.0, 3.0}) {
            const Eigen::Vector3d sensor = s.sensor_m + Eigen::Vector3d(0, 0, lift_m);
            const Region region = buildRegion(s.grid, sensor, table);
            if (region.empty()) continue;  // no cell seen
            scenes++;
            if (regionMayConflict(region, bounds)) continue;
            ruledOut++;
            EXPECT_EQ(countRays(s.grid, sensor),
                      applyVisibilityRule(s.grid, sensor, v, p).raysCast);
            for (const BinGrid::UpdatedCell& u : s.grid.updatedCells()) {
                ASSERT_FALSE(ownBinsConflict(s.grid, u, v, p)) << id;
                ASSERT_TRUE(conflictsOnLine(s.grid, u, sensor, v, p).empty()) << id;
            }
        }
    });
    std::cout << ruledOut << " of " << scenes << " updates ruled out whole\n";
    EXPECT_GT(ruledOut, 10u);
    EXPECT_LT(ruledOut, scenes);
}

TEST(VisibilityStages, RaysClearTowardsTheSensorOrByTheFanTestMeetNoConflict) {
    size_t clearByRectangle = 0, clearByFan = 0, walked = 0;
    onRandomScenes(20261129, 25, [&](Scene& s, int id) {
        FirstStages st(s);
        [[maybe_unused]] auto& [v, p, conflictTest, bounds, scratch, region, towards] = st;
        std::vector<RayState> state;
        const FanOutcome fan =
            testRays(RayFan::Test, s.grid, region, towards, s.sensor_m, bounds, scratch, state);
        const auto& updated = s.grid.updatedCells();
        for (size_t i = 0; i < updated.size(); i++) {
            const BinGrid::UpdatedCell& u = updated[i];
            SightLine ray;
            const bool isRay = ray.setEnds(s.grid, u, s.sensor_m);
            const bool clear = conflictsOnLine(s.grid, u, s.sensor_m, v, p).empty();
            if (isRay && restOfRayClear(towards, bounds, BinGrid::blockOf(u.ix),
                                        BinGrid::blockOf(u.iy), u.maxHeight_m, s.sensor_m.z())) {
                ASSERT_TRUE(clear) << id << " ray " << i << " (rectangle towards the sensor)";
                clearByRectangle++;
            }
            if (!fan.ran) continue;
            ASSERT_EQ(state[i] == RayState::NoRay, !isRay) << id << " ray " << i;
            if (state[i] == RayState::Clear) {
                ASSERT_TRUE(clear) << id << " ray " << i << " (fan test)";
                clearByFan++;
            }
            walked += state[i] == RayState::Walk;
        }
    });
    std::cout << clearByRectangle << " rays clear by the rectangle, " << clearByFan
              << " by the fan test (rectangle included), " << walked << " to walk\n";
    EXPECT_GT(clearByRectangle, 100u);
    EXPECT_GT(clearByFan, clearByRectangle);
    EXPECT_GT(walked, 1000u);
}

TEST(VisibilityStages, RaysClearByTheEnvelopeTestMeetNoConflict) {
    size_t clear = 0, walk = 0;
    onRandomScenes(20261131, 25, [&](Scene& s, int id) {
        FirstStages st(s);
        [[maybe_unused]] auto& [v, p, conflictTest, bounds, scratch, region, towards] = st;
        std::vector<RayState> state;
        const FanOutcome out =
            testRays(RayFan::Skip, s.grid, region, towards, s.sensor_m, bounds, scratch, state);
        if (!out.ran) return;
        const auto& updated = s.grid.updatedCells();
        size_t sceneClear = 0;
        for (size_t i = 0; i < updated.size(); i++) {
            SightLine ray;
            ASSERT_EQ(state[i] == RayState::NoRay, !ray.setEnds(s.grid, updated[i], s.sensor_m))
                << id << " ray " << i;
            if (state[i] == RayState::Clear) {
                ASSERT_TRUE(conflictsOnLine(s.grid, updated[i], s.sensor_m, v, p).empty())
                    << id << " ray " << i;
                sceneClear++;
            }
            walk += state[i] == RayState::Walk;
        }
        clear += sceneClear;
        EXPECT_EQ(out.noWalk, std::count(state.begin(), state.end(), RayState::Walk) == 0) << id;
    });
    std::cout << clear << " rays clear by the envelope test, " << walk << " to walk\n";
    EXPECT_GT(clear, 10000u);
    EXPECT_GT(walk, 1000u);
}

// Stage 3 runs only where its slack covers the rounding of heights (rayTestsApply): from a sensor
// 2e4 m up (the limit is 1e4 m) neither test runs and every ray is left to the walk, state
// emptied of an earlier update's; from the scene's own sensor both run, a state per ray.
TEST(VisibilityStages, RayTestsRunOnlyWhereTheirSlackHolds) {
    size_t ran = 0;
    onRandomScenes(20261132, 3, [&](Scene& s, int id) {
        const Eigen::Vector3d sensor_m = s.sensor_m;
        for (const double lift_m : {0.0, 2e4})
            for (const RayFan fan : {RayFan::Test, RayFan::Skip}) {
                s.sensor_m = sensor_m + Eigen::Vector3d(0, 0, lift_m);
                FirstStages st(s);
                std::vector<RayState> state(7, RayState::Clear);  // an earlier update's
                const FanOutcome out = testRays(fan, s.grid, st.region, st.towards, s.sensor_m,
                                                st.bounds, st.scratch, state);
                const bool sane = lift_m == 0.0 && !st.region.empty();
                ASSERT_EQ(out.ran, sane) << id << " lifted " << lift_m << " m";
                EXPECT_EQ(state.size(), sane ? s.grid.updatedCells().size() : 0u) << id;
                ran += out.ran;
            }
    });
    EXPECT_GT(ran, 20u);
}

TEST(VisibilityStages, ColumnStretchesHoldEveryConflictAndTheirWalkEditsAsTheRule) {
    size_t conflicts = 0, rays = 0;
    onRandomScenes(20261130, 25, [&](Scene& s, int id) {
        FirstStages st(s);
        [[maybe_unused]] auto& [v, p, conflictTest, bounds, scratch, region, towards] = st;
        const double stopHeight_m =
            std::min(s.grid.maxHeight_m(), BoundTest::tolerant_m(region.maxBound_m)) + v.margin_m;
        const double step = 0.5 * s.grid.cellSize_m();
        scratch.sampleAt = {0.0, step};
        const auto& updated = s.grid.updatedCells();
        for (size_t i = 0; i < updated.size(); i++) {
            const BinGrid::UpdatedCell& u = updated[i];
            SightLine ray;
            if (!ray.set(s.grid, u, s.sensor_m)) continue;
            const double reach = sweepColumns(s.grid, region, towards, u, s.sensor_m, ray.length_m,
                                              bounds, stopHeight_m, scratch.stretches);
            for (const double d : conflictsOnLine(s.grid, u, s.sensor_m, v, p)) {
                bool inside = false;
                for (const auto& [from, to] : scratch.stretches) inside |= d >= from && d <= to;
                ASSERT_TRUE(inside && d <= reach) << id << " ray " << i << " conflict at " << d;
                conflicts++;
            }
            // This ray alone: its stretches' walk edits what the rule's walk edits (nothing, on
            // the scene itself, where the rule's line meets no conflict).
            const bool edits = !conflictsOnLine(s.grid, u, s.sensor_m, v, p).empty();
            BinGrid walked = edits ? s.grid : BinGrid(s.grid.cellSize_m());
            BinGrid& walkedGrid = edits ? walked : s.grid;
            VisibilityStats ws, rs;
            LazyTargetCertainty target(walkedGrid, u, p);
            if (reach >= step)
                walkStretches(walkedGrid, region, ray, u.ix, u.iy, scratch.stretches, reach,
                              stopHeight_m, bounds, conflictTest, target, 1.0f, scratch.sampleAt,
                              ws);
            if (!edits) {
                ASSERT_EQ(ws.binsRemoved + ws.binsWeakened, 0u) << id << " ray " << i;
                rays++;
                continue;
            }
            BinGrid rule = s.grid;
            const double ruleTarget = targetCertainty(rule, u, p);
            forEachCellOnSightLine(rule, ray, u.ix, u.iy, s.grid.maxHeight_m() + v.margin_m,
                                   [&](int ix, int iy, double, double rayHigh_m) {
                                       editOccluder(  // st: a lambda captures no binding
                                           rule, ix, iy, rayHigh_m, st.conflicts,
                                           [&] { return ruleTarget; }, 1.0f, rs);
                                   });
            ASSERT_EQ(ws.binsRemoved, rs.binsRemoved) << id << " ray " << i;
            ASSERT_EQ(ws.binsWeakened, rs.binsWeakened) << id << " ray " << i;
            ASSERT_TRUE(binsOf(walked) == binsOf(rule)) << id << " ray " << i;
            rays++;
        }
    });
    std::cout << rays << " rays, " << conflicts << " conflicts on their lines\n";
    EXPECT_GT(conflicts, 1000u);
}
