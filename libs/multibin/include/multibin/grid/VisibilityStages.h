/* Part of the multibin elevation-mapping library. */
#pragma once
/** The stages of the visibility constraint's fast path (applyVisibilityConstraint), each proven
 * against the rule (VisibilityRule.h) by its own test (tests/grid/test_VisibilityStages.cpp).
 * Internal: the library's and the tests' only. Each stage only rules out bins that cannot
 * conflict, from the grid's local height bounds (BinGrid::blockMaxHeight_m,
 * BinGrid::cellMaxHeight_m), so the bins edited are exactly the rule's:
 *
 * 1. Region: the blocks between the sensor and the updated cells, their bounds in a dense table;
 *    if no bound lies above the lowest line of sight, nothing can conflict (regionMayConflict).
 * 2. TowardsSensor: per block, the highest bound of the rectangle between it and the sensor's
 *    block: a ray whose rest lies above it edits nothing.
 * 3. FanTest: every ray of the update against the blocks within its angle from the sensor, then
 *    the squares of 4 x 4 cells and the cells of the blocks too high for it: rays proven clear.
 * 4. sweepColumns: a ray's stretches over block columns that may hold a conflicting bin.
 * 5. walkStretches: the rule's samples within those stretches, each cell tested and edited. */

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <utility>
#include <vector>

#include "multibin/grid/BinGrid.h"
#include "multibin/grid/VisibilityConstraint.h"
#include "multibin/grid/VisibilityParams.h"
#include "multibin/grid/VisibilityRule.h"

namespace multibin::visibility {

/** A local height bound (the highest bin below it, as a float) against a line of sight. */
struct BoundTest {
    double minConflictMargin_m = 0;  //!< ConflictTest::minMargin_m
    /** The bound widened for the rounding of bins' float heights: no bin lies above it. */
    static double tolerant_m(float max_m) {
        return double(max_m) + 1e-6 * (1.0 + std::abs(double(max_m)));
    }
    /** tolerant_m, -infinity for an empty bound: mayConflict(b, z) is limit_m(b) > z + margin. */
    static double limit_m(float max_m) {
        return max_m > -std::numeric_limits<float>::infinity()
                   ? tolerant_m(max_m)
                   : -std::numeric_limits<double>::infinity();
    }
    /** Whether a bin below the bound can lie above the line by the smallest conflict margin. */
    bool mayConflict(float max_m, double lineHeight_m) const {
        return max_m > -std::numeric_limits<float>::infinity() &&
               tolerant_m(max_m) > lineHeight_m + minConflictMargin_m;
    }
};

/** Stage 1: the blocks spanned by the updated cells and the sensor's cell (one cell wider for
 * rounding), clipped to the window; every sample of every ray lies over them. */
struct Region {
    int x0 = 0, y0 = 0;         //!< first block
    unsigned nx = 0, ny = 0;    //!< blocks; 0: no table (no update, or over 2^18 blocks)
    const float* bound_m = {};  //!< nx x ny exact copies of the block bounds, row by row
    float maxBound_m = -std::numeric_limits<float>::infinity();
    double lowestLine_m = std::numeric_limits<double>::infinity();  //!< lowest ray end, sensor

    bool empty() const { return nx == 0; }
    /** The block's bound, from the table where it holds it. */
    float blockBound(const BinGrid& grid, int bx, int by) const {
        const unsigned sx = unsigned(bx - x0), sy = unsigned(by - y0);
        return sx < nx && sy < ny ? bound_m[sx + sy * nx] : grid.blockMaxHeight_m(bx, by);
    }
};
Region buildRegion(const BinGrid& grid, const Eigen::Vector3d& sensor_m, std::vector<float>& table);
/** Whether any bin of the region can conflict with any line of sight (false: nothing to edit,
 * own bins included, as every line lies at or above lowestLine_m). */
inline bool regionMayConflict(const Region& region, const BoundTest& bounds) {
    return region.empty() || bounds.mayConflict(region.maxBound_m, region.lowestLine_m);
}
/** The rays of the update, counted as the rule counts them (one per updated cell a cell or
 * more from the sensor), without their walks. */
size_t countRays(const BinGrid& grid, const Eigen::Vector3d& sensor_m);

/** Stage 2: for each block of the region, the highest bound in the rectangle spanned by it and
 * the sensor's block. The rest of a ray from a point in a block lies in that rectangle (rounding
 * can move a sample across a block edge only within 1e-15 m of the sensor, where the ray is at
 * the sensor's height: hence the condition that the blocks around the sensor lie below it). */
struct TowardsSensor {
    const Region* region = nullptr;
    const float* bound_m = nullptr;  //!< null: not usable (sensor outside, or too low)
    bool usable() const { return bound_m != nullptr; }
    /** +infinity outside the region. */
    float restBound(int bx, int by) const {
        const unsigned sx = unsigned(bx - region->x0), sy = unsigned(by - region->y0);
        return sx < region->nx && sy < region->ny ? bound_m[sx + sy * region->nx]
                                                  : std::numeric_limits<float>::infinity();
    }
};
TowardsSensor buildTowardsSensor(const BinGrid& grid, const Region& region,
                                 const Eigen::Vector3d& sensor_m, const BoundTest& bounds,
                                 std::vector<float>& table);

/** Slack [m] along and across a ray between a sample's computed position and the exact line:
 * far above the rounding of the sample positions (~1e-15 of the coordinates). */
constexpr double kSlack_m = 1e-6;

/** Whether the ray of an updated cell at `tz_m`, starting in block (bx, by), passes above every
 * bound towards the sensor (its whole walk edits nothing). */
inline bool restOfRayClear(const TowardsSensor& towards, const BoundTest& bounds, int bx, int by,
                           double tz_m, double sensorZ_m) {
    return towards.usable() &&
           !bounds.mayConflict(towards.restBound(bx, by), std::min(tz_m, sensorZ_m) - kSlack_m);
}

/** A pseudo-angle of the direction (dx, dy) in [0, 4): increasing with the angle from +x,
 * counter-clockwise, one division instead of atan2 (not (0, 0)). */
inline double pseudoAngle(double dx, double dy) {
    if (dy >= 0) return dx >= 0 ? dy / (dx + dy) : 1 - dx / (dy - dx);
    return dx <= 0 ? 2 - dy / (-dx - dy) : 3 + dx / (dx - dy);
}

/** The nearest and farthest horizontal distances [m] from the sensor (sx, sy) to the square
 * [x0, x1] x [y0, y1], each widened by kSlack_m. */
struct SquareDistances {
    double near_m, far_m;
};
inline SquareDistances squareDistances(double x0, double x1, double y0, double y1, double sx,
                                       double sy) {
    const double gapX = std::max({x0 - sx, sx - x1, 0.0});
    const double gapY = std::max({y0 - sy, sy - y1, 0.0});
    const double farX = std::max(std::abs(x0 - sx), std::abs(x1 - sx));
    const double farY = std::max(std::abs(y0 - sy), std::abs(y1 - sy));
    return {std::sqrt(gapX * gapX + gapY * gapY) - kSlack_m,
            std::sqrt(farX * farX + farY * farY) + kSlack_m};
}

/** The pseudo-angles [lo, hi] (hi up to 6: past key 0 the keys continue from 4) within which
 * every direction from the sensor (sx, sy) to a point of the square [x0, x1] x [y0, y1] lies,
 * widened by 1e-6 (far above the keys' rounding for squares 1 mm or more from the sensor); false
 * if the square lies within 1 mm of the sensor or spans half a turn or more (any direction). */
inline bool squareKeys(double x0, double x1, double y0, double y1, double sx, double sy, double& lo,
                       double& hi) {
    constexpr double kKeySlack = 1e-6, kNearSensor_m = 1e-3;
    const double gapX = std::max({x0 - sx, sx - x1, 0.0});
    const double gapY = std::max({y0 - sy, sy - y1, 0.0});
    if (!(std::max(gapX, gapY) >= kNearSensor_m)) return false;
    const bool acrossZero = x1 > sx && y0 <= sy && sy <= y1;
    lo = std::numeric_limits<double>::infinity();
    hi = -lo;
    for (const double x : {x0, x1})
        for (const double y : {y0, y1}) {
            double k = pseudoAngle(x - sx, y - sy);
            if (acrossZero && k < 2) k += 4;
            lo = std::min(lo, k);
            hi = std::max(hi, k);
        }
    lo -= kKeySlack;
    hi += kKeySlack;
    return hi - lo < 2;  // less than half a turn, as a square away from the sensor
}

/** Stage 3's decision per updated cell. */
enum class RayState : uint8_t { Walk, Clear, NoRay };

/** A ray of the fan test. */
struct FanRay {
    double tx, ty, ux, uy, sumAbsU, length, slope, rise, tz;
    int ix, iy;
    uint32_t updatedIndex;
    bool clear;  // no square it passes over can conflict (so far)
};

/** A ray of the envelope test: its key (pseudoAngle from the sensor), length, slope (at least
 * 0) and the least height its samples can have, B (VisibilityEnvelope.cpp). */
struct EnvRay {
    double key, length, slope, low_m;
    uint32_t updatedIndex;
};

/** A set of rays summed up: their largest slope (at least 0) and least B. Each of them passes
 * over a square whose farthest point lies far_m from the sensor no lower than lowest_m(). */
struct RayEnvelope {
    double slope = 0;
    double low_m = std::numeric_limits<double>::infinity();
    void add(double s, double b) {
        slope = std::max(slope, s);
        low_m = std::min(low_m, b);
    }
    void add(const RayEnvelope& e) { add(e.slope, e.low_m); }
    /** 1e-9 m and 1e-15 of the drop cover the rounding of the walk's heights. */
    double lowest_m(double sensorZ_m, double far_m) const {
        const double drop_m = slope * far_m;
        return std::max(sensorZ_m - drop_m - 1e-15 * drop_m, low_m) - 1e-9;
    }
};

/** The arrays of the stages, kept between calls on each thread (a frame's thousands of rays
 * would otherwise take fresh pages from the system on every update). */
struct VisibilityScratch {
    std::vector<float> regionBound, towardsSensor, unitLimits;
    std::vector<RayState> rayState;
    std::vector<std::pair<double, uint32_t>> fan, bucketed;
    std::vector<uint32_t> start;
    std::vector<double> keys, lengths, fastSlopes, groupFastSlopes;
    std::vector<FanRay> rays;
    std::vector<int32_t> unitTableOf;
    std::vector<std::pair<double, double>> stretches;
    std::vector<double> sampleAt;
    std::vector<EnvRay> envRays, envSorted;
    std::vector<RayEnvelope> envGroups;
    std::vector<double> hotNear;
};

/** Stage 3 runs on sane extents only: heights below kMaxRayHeight_m and coordinates below
 * kMaxCoordinate_m, where its tests' slack (1e-9 m) covers the rounding of the walk's heights. */
constexpr double kMaxRayHeight_m = 1e4, kMaxCoordinate_m = 1e5;
/** Whether stage 3 can run on this update (a region of sane extent, a sane sensor height). */
bool rayTestsApply(const BinGrid& grid, const Region& region, const Eigen::Vector3d& sensor_m);

/** Stage 3's first look at every updated cell's ray, the same for both tests: shorter than a
 * cell (NoRay), clear by the rectangle towards the sensor (Clear), or passed to
 * `test(i, u, dx, dy, length_m)` (offsets to the sensor) if below kMaxRayHeight_m; the others stay
 * Walk. Returns the rays decided; `clear` counts the Clear ones. */
template <class Test>
size_t firstLook(const BinGrid& grid, const TowardsSensor& towards, const BoundTest& bounds,
                 const Eigen::Vector3d& sensor_m, std::vector<RayState>& state, size_t& clear,
                 Test&& test) {
    const std::vector<BinGrid::UpdatedCell>& updated = grid.updatedCells();
    state.assign(updated.size(), RayState::Walk);
    size_t decided = 0;
    for (size_t i = 0; i < updated.size(); i++) {
        const BinGrid::UpdatedCell& u = updated[i];
        const double dx = sensor_m.x() - grid.cellCenter_m(u.ix);
        const double dy = sensor_m.y() - grid.cellCenter_m(u.iy);
        const double length = std::sqrt(dx * dx + dy * dy);  // as SightLine's
        if (length < grid.cellSize_m()) {
            state[i] = RayState::NoRay;
            decided++;
        } else if (restOfRayClear(towards, bounds, BinGrid::blockOf(u.ix), BinGrid::blockOf(u.iy),
                                  u.maxHeight_m, sensor_m.z())) {
            state[i] = RayState::Clear;
            decided++;
            clear++;
        } else if (std::abs(u.maxHeight_m) < kMaxRayHeight_m) {
            test(i, u, dx, dy, length);
        }
    }
    return decided;
}

/** Stage 3's outcome: `state` (one per updated cell) when it ran. */
struct FanOutcome {
    bool ran = false;
    bool noWalk = false;   //!< every ray decided and none to walk
    size_t clearRays = 0;  //!< rays proven clear (counted as cast)
    /** After a test of `rays` rays: `decided` settled by firstLook, `clearFirst` of them clear,
     * and `clearByTest` proven clear by the test. */
    static FanOutcome after(size_t rays, size_t decided, size_t clearFirst, size_t clearByTest) {
        return {true, decided + clearByTest == rays, clearFirst + clearByTest};
    }
};
/** Stage 3's inputs for one update, and what its two tests (FanTest in VisibilityFan.cpp,
 * EnvelopeTest in VisibilityEnvelope.cpp, each derived from it) read of them. */
class RayTestInputs {
public:
    RayTestInputs(const BinGrid& grid, const Region& region, const TowardsSensor& towards,
                  const Eigen::Vector3d& sensor_m, const BoundTest& bounds,
                  VisibilityScratch& scratch)
        : m_grid(grid),
          m_region(region),
          m_towards(towards),
          m_sensor_m(sensor_m),
          m_bounds(bounds),
          m_s(scratch),
          m_cell(grid.cellSize_m()),
          m_step(0.5 * m_cell) {}

protected:
    /** f(bx, by) for every block of the region, row by row. */
    template <class F>
    void forEachBlock(F&& f) const {
        for (int by = m_region.y0; by < m_region.y0 + int(m_region.ny); by++)
            for (int bx = m_region.x0; bx < m_region.x0 + int(m_region.nx); bx++) f(bx, by);
    }

    const BinGrid& m_grid;
    const Region& m_region;
    const TowardsSensor& m_towards;
    const Eigen::Vector3d& m_sensor_m;
    const BoundTest& m_bounds;
    VisibilityScratch& m_s;
    const double m_cell;  //!< cell size [m]
    const double m_step;  //!< the rule's sample step: half a cell [m]
};

/** Stage 3: the fan of rays at once (every ray starts at the sensor). A ray is proven clear when
 * nothing it passes over can hold a bin above it by the smallest conflict margin: each block high
 * enough to matter against the rays within its angle from the sensor, at the ray's lowest height
 * over the block's range of distances; where a block is too high for a ray, its units of 4 x 4
 * cells, then their cells. Only where rayTestsApply holds (testRays checks it). `state` gets one
 * RayState per updated cell. */
FanOutcome testFan(const RayTestInputs& inputs, std::vector<RayState>& state);

/** Stage 3 for a camera frame's thousands of rays (RayFan::Skip): the rays' lower envelope by
 * direction (sectors of pseudo-angle, about one ray each), tested per block of the region, then
 * per cell of the blocks it does not settle, against the rays within the cell's directions long
 * enough to reach it. A ray is clear unless its sector holds a cell, within its reach, that may
 * hold a bin above the envelope there. Same precondition and outcome as testFan. */
FanOutcome testEnvelope(const RayTestInputs& inputs, std::vector<RayState>& state);

/** Stage 3 as the constraint runs it: `state` emptied, then, on a region of sane extent
 * (rayTestsApply: heights below 1e4 m, coordinates below 1e5 m), the fan test (RayFan::Test) or
 * the envelope test (RayFan::Skip); the outcome's `ran` says whether one ran. */
FanOutcome testRays(RayFan fan, const BinGrid& grid, const Region& region,
                    const TowardsSensor& towards, const Eigen::Vector3d& sensor_m,
                    const BoundTest& bounds, VisibilityScratch& scratch,
                    std::vector<RayState>& state);

/** Stage 4: the stretches [from, to] of distance from the target, in walking order, over block
 * columns (rows if the ray runs more along y) that may hold a bin conflicting with the ray;
 * returns the reach: past it no sample can meet a conflicting bin. `stopHeight_m`: a rising ray
 * ends where it clears it (the highest bin that can conflict, plus the margin). */
double sweepColumns(const BinGrid& grid, const Region& region, const TowardsSensor& towards,
                    const BinGrid::UpdatedCell& u, const Eigen::Vector3d& sensor_m, double length_m,
                    const BoundTest& bounds, double stopHeight_m,
                    std::vector<std::pair<double, double>>& stretches);

/** Stage 5: the rule's samples (SightLine) within the stretches, each taken exactly as the
 * rule takes it; each cell entered, unless its block's or its own bound rules it out, edited as
 * the rule edits it. `sampleAt`: the sample distances, shared by every ray (grown as needed). */
void walkStretches(BinGrid& grid, const Region& region, const SightLine& ray, int startIx,
                   int startIy, const std::vector<std::pair<double, double>>& stretches,
                   double reach_m, double stopHeight_m, const BoundTest& bounds,
                   const ConflictTest& conflicts, LazyTargetCertainty& target, float decrement,
                   std::vector<double>& sampleAt, VisibilityStats& stats);

}  // namespace multibin::visibility
