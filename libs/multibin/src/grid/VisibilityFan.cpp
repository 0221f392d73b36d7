/* Part of the multibin elevation-mapping library. */
/* Stage 3 of the visibility constraint (VisibilityStages.h): the fan test. Conservative: every
 * sample of a walk lies, to the slack, in the squares tested, its ray height is no lower than the
 * one tested (1e-9 m covers the rounding of heights below 1e4 m), and the bounds only go up. */
#include <algorithm>
#include <cmath>
#include <cstddef>
#ifdef __SSE2__
#include <emmintrin.h>
#endif

#include "multibin/grid/VisibilityStages.h"

namespace multibin::visibility {

namespace {
constexpr double kHeightSlack_m = 1e-9;
constexpr size_t kGroup = 8;  // rays whose steepest slope is tested at once
constexpr int kUnitShift = 2, kUnitCells = 1 << kUnitShift;
constexpr int kUnits = BinGrid::kBlockCells / kUnitCells;  // per side of a block

/** Sorts a fan's (key, ray) entries by key. A scan's come in beam order, keys nearly sorted (up
 * or down) from some angle round to it: reversed and rotated to that order, insertion sort
 * finishes in about linear time. Otherwise (a frame's rows) a counting sort on buckets of keys,
 * as many as rays, first. */
void sortByAngle(std::vector<std::pair<double, uint32_t>>& fan, VisibilityScratch& scratch) {
    auto insertionSort = [&](size_t maxMoves) {  // false if it gave up
        size_t moves = 0;
        for (size_t a = 1; a < fan.size(); a++) {
            const auto entry = fan[a];
            size_t k = a;
            for (; k > 0 && entry < fan[k - 1]; k--) fan[k] = fan[k - 1];
            fan[k] = entry;
            if ((moves += a - k) > maxMoves) return false;
        }
        return true;
    };
    const size_t n = fan.size();
    if (n <= 1) return;
    // One pass: the descents, and where the largest drop and the largest rise are (the largest
    // drop once reversed).
    size_t descents = 0, drop = 0, rise = 0;
    double largestDrop = 0, largestRise = 0;
    for (size_t j = 1; j < n; j++) {
        const double change = fan[j].first - fan[j - 1].first;
        descents += change < 0;
        if (-change > largestDrop) largestDrop = -change, drop = j;
        if (change > largestRise) largestRise = change, rise = j;
    }
    size_t wrap = drop;      // after the largest drop
    if (2 * descents > n) {  // mostly clockwise
        std::reverse(fan.begin(), fan.end());
        largestDrop = largestRise;
        wrap = n - rise;
    }
    if (largestDrop > 2) std::rotate(fan.begin(), fan.begin() + ptrdiff_t(wrap), fan.end());
    if (insertionSort(2 * n)) return;
    std::vector<uint32_t>& start = scratch.start;
    start.assign(n + 1, 0);
    auto bucketOf = [&](double key) {  // keys lie in [0, 4)
        return std::min(size_t(std::max(key, 0.0) * (0.25 * double(n))), n - 1);
    };
    for (const auto& entry : fan) start[bucketOf(entry.first) + 1]++;
    for (size_t b = 1; b <= n; b++) start[b] += start[b - 1];
    auto& bucketed = scratch.bucketed;
    bucketed.resize(n);
    for (const auto& entry : fan) bucketed[start[bucketOf(entry.first)]++] = entry;
    fan.swap(bucketed);
    if (!insertionSort(8 * n)) std::sort(fan.begin(), fan.end());
}

/** The number of leading keys for which `before(key)` holds (the keys are sorted, so they are a
 * prefix); branch-free (conditional moves): the keys' order is no pattern a predictor learns. */
template <class Before>
size_t prefix(const std::vector<double>& keys, Before before) {
    const double* base = keys.data();
    size_t n = keys.size();
    while (n > 1) {
        const size_t half = n / 2;
        base = before(base[half - 1]) ? base + half : base;
        n -= half;
    }
    return size_t(base - keys.data()) + size_t(n == 1 && before(*base));
}

/** The fan test's state for one update: its inputs, and its arrays in the scratch. */
class FanTest : RayTestInputs {
public:
    explicit FanTest(const RayTestInputs& inputs)
        : RayTestInputs(inputs), m_block_m(BinGrid::kBlockCells * m_cell) {}

    FanOutcome run(std::vector<RayState>& state);

private:
    size_t collectRays(std::vector<RayState>& state, size_t& raysClear);
    void orderByKey();
    double lowestBetween(const FanRay& r, double from, double to) const;
    double lowestOver(const FanRay& r, double cx, double cy, double h) const;
    const float* unitsOf(unsigned blockSlot, int bx, int by);
    bool mayConflictInBlock(const FanRay& r, unsigned blockSlot, int bx, int by, double blockLow_m);
    void testBlock(int bx, int by);

    const double m_block_m;
    double m_lowestRay_m = 0, m_longestRay_m = 0;
};

/** The rays (in the order of the updated cells) and their keys: pseudoAngle from the sensor.
 * Returns the rays firstLook decided. */
size_t FanTest::collectRays(std::vector<RayState>& state, size_t& raysClear) {
    m_s.rays.clear();
    m_s.fan.clear();
    m_lowestRay_m = m_sensor_m.z();
    auto add = [&](size_t i, const BinGrid::UpdatedCell& u, double dx, double dy, double length) {
        const double tz = u.maxHeight_m;
        m_s.fan.emplace_back(pseudoAngle(-dx, -dy), uint32_t(m_s.rays.size()));
        m_lowestRay_m = std::min(m_lowestRay_m, tz);
        // One division: the tests allow far more than its rounding.
        const double invLength = 1.0 / length;
        const double slope = (m_sensor_m.z() - tz) * invLength, ux = dx * invLength,
                     uy = dy * invLength;
        m_s.rays.push_back({m_grid.cellCenter_m(u.ix), m_grid.cellCenter_m(u.iy), ux, uy,
                            std::abs(ux) + std::abs(uy), length, slope,
                            std::abs(slope) * 0.7072 * m_cell, tz, u.ix, u.iy, uint32_t(i), true});
    };
    return firstLook(m_grid, m_towards, m_bounds, m_sensor_m, state, raysClear, add);
}

/** The keys, lengths and "fast slopes" (the slope, or +infinity where the slope test does not
 * apply: falling rays) in key order, and the steepest fast slope of each group of kGroup. */
void FanTest::orderByKey() {
    sortByAngle(m_s.fan, m_s);
    const size_t nRays = m_s.fan.size();
    m_s.keys.resize(nRays);
    m_s.lengths.resize(nRays);
    m_s.fastSlopes.resize(nRays);
    for (size_t j = 0; j < nRays; j++) {
        const FanRay& r = m_s.rays[m_s.fan[j].second];
        m_s.keys[j] = m_s.fan[j].first;
        m_s.lengths[j] = r.length;
        m_s.fastSlopes[j] = r.slope >= 0 ? r.slope : std::numeric_limits<double>::infinity();
    }
    m_longestRay_m = nRays > 0 ? *std::max_element(m_s.lengths.begin(), m_s.lengths.end()) : 0.0;
    m_s.groupFastSlopes.resize((nRays + kGroup - 1) / kGroup);
    for (size_t j = 0; j < nRays; j += kGroup)
        m_s.groupFastSlopes[j / kGroup] =
            *std::max_element(m_s.fastSlopes.begin() + ptrdiff_t(j),
                              m_s.fastSlopes.begin() + ptrdiff_t(std::min(j + kGroup, nRays)));
}

/** The ray's lowest height [m] over its samples at distances [from, to] from the target
 * (clipped to the walk's [step, length)), or NaN if there is none. */
double FanTest::lowestBetween(const FanRay& r, double from, double to) const {
    from = std::max(from, m_step);
    to = std::min(to, r.length);
    if (!(from <= to)) return std::numeric_limits<double>::quiet_NaN();
    return r.tz + std::min(r.slope * from, r.slope * to) + r.rise - kHeightSlack_m;
}

/** The same over a square of centre (cx, cy) and half side h [m], widened by the slack: where
 * the line crosses it (its support across and along the ray). */
double FanTest::lowestOver(const FanRay& r, double cx, double cy, double h) const {
    const double ex = cx - r.tx, ey = cy - r.ty;
    const double reach = (h + kSlack_m) * r.sumAbsU;
    if (std::abs(r.ux * ey - r.uy * ex) > reach) return std::numeric_limits<double>::quiet_NaN();
    const double along = r.ux * ex + r.uy * ey;
    return lowestBetween(r, along - reach, along + reach);
}

/** Per block, when first needed: BoundTest::limit_m of each unit's highest cell bound, rounded
 * up to a float (compared 16 at a time). */
const float* FanTest::unitsOf(unsigned blockSlot, int bx, int by) {
    std::vector<int32_t>& tableOf = m_s.unitTableOf;
    if (tableOf.empty()) tableOf.assign(size_t(m_region.nx) * m_region.ny, -1);
    int32_t& t = tableOf[blockSlot];
    if (t >= 0) return &m_s.unitLimits[size_t(t)];
    t = int32_t(m_s.unitLimits.size());
    float units[kUnits * kUnits];
    std::fill(units, units + kUnits * kUnits, -std::numeric_limits<float>::infinity());
    // The block's cells inside the window, a row at a time: a block lies in one tile of the
    // store, so a row's slots are contiguous.
    const CellWindow& w = m_grid.window();
    const VisibilityIndex& index = m_grid.visibilityIndex();
    const int ixLo = std::max(bx * BinGrid::kBlockCells, w.ix0);
    const int ixHi = std::min((bx + 1) * BinGrid::kBlockCells, w.ix0 + w.nx);
    const int iyLo = std::max(by * BinGrid::kBlockCells, w.iy0);
    const int iyHi = std::min((by + 1) * BinGrid::kBlockCells, w.iy0 + w.ny);
    const int column0 = ixLo - bx * BinGrid::kBlockCells;  // of the first cell read
    // Usually the block's rows lie whole in the window: a unit's row is 4 adjacent slots.
    const bool wholeRows = column0 == 0 && ixHi - ixLo == BinGrid::kBlockCells;
    for (int iy = iyLo; iy < iyHi; iy++) {
        const size_t first = m_grid.store().slot(ixLo, iy);
        float* unitRow = units + ((iy - by * BinGrid::kBlockCells) >> kUnitShift) * kUnits;
        if (wholeRows) {
            for (int c = 0; c < kUnits; c++) {
                float m = unitRow[c];
                for (int k = 0; k < kUnitCells; k++)
                    m = std::max(m, index.cellMaxHeight_m(first + size_t(c * kUnitCells + k)));
                unitRow[c] = m;
            }
            continue;
        }
        for (int k = 0; k < ixHi - ixLo; k++) {
            float& u = unitRow[(column0 + k) >> kUnitShift];
            u = std::max(u, index.cellMaxHeight_m(first + size_t(k)));
        }
    }
    auto roundUp = [](double v) {  // to within 1e-6 of v, far above float rounding
        return std::isfinite(v) ? float(v + 1e-6 * std::abs(v)) : float(v);
    };
    m_s.unitLimits.resize(size_t(t) + kUnits * kUnits);
    for (int k = 0; k < kUnits * kUnits; k++)
        m_s.unitLimits[size_t(t) + size_t(k)] = roundUp(BoundTest::limit_m(units[k]));
    return &m_s.unitLimits[size_t(t)];
}

/** Whether the ray may meet a conflicting bin in block (bx, by), over which it passes no lower
 * than blockLow_m: its units, then their cells (not the target's, nor updated ones: the walk
 * skips them). */
__attribute__((always_inline)) inline bool FanTest::mayConflictInBlock(const FanRay& r,
                                                                       unsigned blockSlot, int bx,
                                                                       int by, double blockLow_m) {
    const float* units = unitsOf(blockSlot, bx, by);
    // Rounded down, so a unit above the line in doubles is above it in floats.
    const double line_m = blockLow_m + m_bounds.minConflictMargin_m;
    const float lineF = float(line_m - 1e-6 * std::abs(line_m));
    uint32_t high = 0;  // the units above the ray's lowest height over the block
#ifdef __SSE2__
    const __m128 line4 = _mm_set1_ps(lineF);
    for (int k = 0; k < kUnits * kUnits; k += 4)
        high |= uint32_t(_mm_movemask_ps(_mm_cmpgt_ps(_mm_loadu_ps(units + k), line4))) << k;
#else
    for (int k = 0; k < kUnits * kUnits; k++) high |= units[k] > lineF ? 1u << k : 0u;
#endif
    if (high == 0) return false;
    // lowestOver for each unit, from the first unit's offsets and a unit's steps.
    const double cell = m_cell;
    const double unit_m = kUnitCells * cell;
    const double ex = (bx * BinGrid::kBlockCells + 0.5 * kUnitCells) * cell - r.tx;
    const double ey = (by * BinGrid::kBlockCells + 0.5 * kUnitCells) * cell - r.ty;
    const double cross0 = r.ux * ey - r.uy * ex, along0 = r.ux * ex + r.uy * ey;
    const double stepX = r.ux * unit_m, stepY = r.uy * unit_m;
    const double reach = (0.5 * unit_m + kSlack_m) * r.sumAbsU;
#ifdef __SSE2__
    static_assert(kUnits == 4, "one row of units is two pairs of doubles");
    // Where one or two units are high, their own test below is cheaper than this one.
    if (const uint32_t rest = high & (high - 1); (rest & (rest - 1)) != 0) {
        // The units the line passes within reach of, all 16 at once (the same arithmetic as
        // below, so the same ones): no branch per unit.
        const __m128d reach2 = _mm_set1_pd(reach);
        const __m128d absMask = _mm_castsi128_pd(_mm_set1_epi64x(0x7fffffffffffffff));
        const __m128d across01 = _mm_mul_pd(_mm_set_pd(1.0, 0.0), _mm_set1_pd(stepY));
        const __m128d across23 = _mm_mul_pd(_mm_set_pd(3.0, 2.0), _mm_set1_pd(stepY));
        uint32_t onLine = 0;
        for (int j = 0; j < kUnits; j++) {
            const __m128d row = _mm_set1_pd(cross0 + j * stepX);
            const __m128d c01 = _mm_and_pd(_mm_sub_pd(row, across01), absMask);
            const __m128d c23 = _mm_and_pd(_mm_sub_pd(row, across23), absMask);
            onLine |= uint32_t(_mm_movemask_pd(_mm_cmpngt_pd(c01, reach2)) |
                               (_mm_movemask_pd(_mm_cmpngt_pd(c23, reach2)) << 2))
                      << (kUnits * j);
        }
        high &= onLine;
    }
#endif
    for (; high != 0; high &= high - 1) {
        const int k = __builtin_ctz(high), i = k % kUnits, j = k / kUnits;
        const double cross = cross0 + j * stepX - i * stepY;
        if (std::abs(cross) > reach) continue;
        const double along = along0 + i * stepX + j * stepY;
        const double unitLow_m = lowestBetween(r, along - reach, along + reach);
        if (!(units[k] > unitLow_m + m_bounds.minConflictMargin_m)) continue;
        const int ix0 = bx * BinGrid::kBlockCells + i * kUnitCells;
        const int iy0 = by * BinGrid::kBlockCells + j * kUnitCells;
        // Its cells likewise, from the unit's first cell.
        const double cellCross0 = cross - (0.5 * kUnitCells - 0.5) * (stepX - stepY) / kUnitCells;
        const double cellAlong0 = along - (0.5 * kUnitCells - 0.5) * (stepX + stepY) / kUnitCells;
        const double cellStepX = stepX / kUnitCells, cellStepY = stepY / kUnitCells;
        const double cellReach = (0.5 * cell + kSlack_m) * r.sumAbsU;
        for (int cy = 0; cy < kUnitCells; cy++)
            for (int cx = 0; cx < kUnitCells; cx++) {
                const int ix = ix0 + cx, iy = iy0 + cy;
                const double cellCross = cellCross0 + cy * cellStepX - cx * cellStepY;
                if (std::abs(cellCross) > cellReach || (ix == r.ix && iy == r.iy)) continue;
                const double cellAlong = cellAlong0 + cx * cellStepX + cy * cellStepY;
                const double cellLow_m =
                    lowestBetween(r, cellAlong - cellReach, cellAlong + cellReach);
                if (m_bounds.mayConflict(m_grid.cellMaxHeight_m(ix, iy), cellLow_m) &&
                    !m_grid.updatedThisCycle(ix, iy))
                    return true;
            }
    }
    return false;
}

/** Block (bx, by) of the region against the rays within its angle from the sensor, at the
 * ray's lowest height over the block's range of distances from the sensor (the block's
 * geometry computed once for all rays): a ray it may conflict with is no longer clear. */
void FanTest::testBlock(int bx, int by) {
    const unsigned slot = unsigned(bx - m_region.x0) + unsigned(by - m_region.y0) * m_region.nx;
    const double blockLimit_m = BoundTest::limit_m(m_region.bound_m[slot]);
    const double margin_m = m_bounds.minConflictMargin_m;
    if (!(blockLimit_m > m_lowestRay_m - kHeightSlack_m + margin_m)) return;  // below every ray
    const double sx = m_sensor_m.x(), sy = m_sensor_m.y(), sz = m_sensor_m.z();
    const double x0 = bx * m_block_m - kSlack_m, x1 = (bx + 1) * m_block_m + kSlack_m;
    const double y0 = by * m_block_m - kSlack_m, y1 = (by + 1) * m_block_m + kSlack_m;
    // Distances from the sensor to the (widened) block: nearest and farthest.
    const SquareDistances distances = squareDistances(x0, x1, y0, y1, sx, sy);
    const double near_m = distances.near_m, far_m = distances.far_m;
    // A ray rising towards the sensor passes over the block no lower than
    // sz - slope far_m + slope inCell_m (its samples there lie at most far_m from the sensor,
    // and tz + slope length is sz), wherever it ends: clear if its slope is at most maxSlope
    // (1e-8 m spare for the rounding of the quotient and of tz + slope d).
    const double inCell_m = 0.7072 * m_cell;  // rise = |slope| inCell_m
    const double maxSlope = (sz - blockLimit_m + margin_m - 1e-8) / (far_m - inCell_m);
    // No sample of a ray shorter than this lies in the block (1e-9 m spare).
    const double nearStep_m = near_m + m_step - 1e-9;
    if (m_longestRay_m < nearStep_m) return;  // beyond every ray
    const double cx = (bx + 0.5) * m_block_m, cy = (by + 0.5) * m_block_m;
    // The rays within the block's angle: keys in [lo, hi], which may pass key 0 (the +x
    // direction) on either side; all of them near the sensor.
    const size_t nRays = m_s.keys.size();
    size_t ranges[2][2] = {{0, nRays}, {0, 0}};
    if (double lo, hi; squareKeys(x0, x1, y0, y1, sx, sy, lo, hi)) {
        auto first = [&](double k) {  // the first ray of key >= k
            return prefix(m_s.keys, [k](double key) { return key < k; });
        };
        auto after = [&](double k) {  // the first ray of key > k
            return prefix(m_s.keys, [k](double key) { return !(k < key); });
        };
        ranges[0][0] = first(lo);
        ranges[0][1] = after(hi);
        if (lo < 0) {  // and from lo + 4 to the end
            ranges[1][0] = first(lo + 4);
            ranges[1][1] = nRays;
        } else if (hi >= 4) {  // and from the start to hi - 4
            ranges[1][1] = after(hi - 4);
        }
    }
    for (const auto& range : ranges)
        for (size_t j = range[0]; j < range[1]; j++) {
            // The rest of j's group at once where none of the group is steeper than maxSlope
            // (at a range's ends, part of a group: a subset).
            if (j % kGroup == 0 || j == range[0]) {
                const size_t g = j / kGroup;
                if (m_s.groupFastSlopes[g] <= maxSlope) {
                    j = std::min((g + 1) * kGroup, range[1]) - 1;
                    continue;
                }
            }
            // On the line, a sample at distance d from the target lies length - d from the
            // sensor: none in the block if length < nearStep_m.
            const double length = m_s.lengths[j];
            if (length < nearStep_m) continue;
            if (m_s.fastSlopes[j] <= maxSlope) continue;
            FanRay& r = m_s.rays[m_s.fan[j].second];
            if (!r.clear) continue;  // already to be walked
            // Both bounds hold: the larger one, the second only where the first does not clear
            // the ray (a NaN first one: no sample in the block).
            const double between_m = lowestBetween(r, length - far_m, length - near_m);
            if (!(blockLimit_m > between_m + margin_m)) continue;
            const double low_m = std::max(between_m, lowestOver(r, cx, cy, 0.5 * m_block_m));
            if (blockLimit_m > low_m + margin_m && mayConflictInBlock(r, slot, bx, by, low_m))
                r.clear = false;
        }
}

FanOutcome FanTest::run(std::vector<RayState>& state) {
    size_t raysClear = 0;
    const size_t decided = collectRays(state, raysClear);
    orderByKey();
    m_s.unitTableOf.clear();
    m_s.unitLimits.clear();
    if (!m_s.fan.empty()) forEachBlock([&](int bx, int by) { testBlock(bx, by); });
    size_t fanClear = 0;
    for (const FanRay& r : m_s.rays) {
        state[r.updatedIndex] = r.clear ? RayState::Clear : RayState::Walk;
        fanClear += r.clear;
    }
    // The rays left out of the fan (heights beyond kMaxRayHeight_m) are walked.
    return FanOutcome::after(state.size(), decided, raysClear, fanClear);
}
}  // namespace

FanOutcome testFan(const RayTestInputs& inputs, std::vector<RayState>& state) {
    return FanTest(inputs).run(state);
}

}  // namespace multibin::visibility
