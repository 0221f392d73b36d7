/* Part of the multibin elevation-mapping library. */
#include "multibin/map/VisibilityConstraint.h"
#include <mrpt/config/CConfigFileBase.h>

#include "multibin/io/OptionKeys.h"
#include "multibin/map/CellSurface.h"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <vector>
#ifdef __SSE2__
#include <emmintrin.h>
#endif

namespace multibin {

namespace {
/** The visibility keys of `o` (a VisibilityParams or a const one), for the options protocol
 * (multibin/io/OptionKeys.h). */
template <class Params, class Visit>
void visitKeys(Params& o, Visit&& visit) {
    visit("visibility_constraint", o.enabled);
    visit({"visibility_margin_m", "visibility_margin"}, o.margin_m, atLeast(0, "m"));
    visit("visibility_certainty_decrement", o.certaintyDecrement, positive());
}

/** A pseudo-angle of the direction (dx, dy) in [0, 4): increasing with the angle from +x,
 * counter-clockwise, one division instead of atan2 (not (0, 0)). */
double pseudoAngle(double dx, double dy) {
    if (dy >= 0) return dx >= 0 ? dy / (dx + dy) : 1 - dx / (dy - dx);
    return dx <= 0 ? 2 - dy / (-dx - dy) : 3 + dx / (dx - dy);
}
}  // namespace

void VisibilityParams::read(StrictConfigSection& s) { visitKeys(*this, OptionReader{s}); }

void VisibilityParams::write(mrpt::config::CConfigFileBase& c, const std::string& section) const {
    visitKeys(*this, OptionWriter{c, section});
}

void VisibilityParams::validate() const {
    visitKeys(*this, OptionChecker("CMultiBinElevationMap insertion option"));
}

namespace {
/** A ray of the fan test (applyVisibilityConstraint). */
struct FanRay {
    double tx, ty, ux, uy, sumAbsU, length, slope, rise, tz;
    int ix, iy;
    uint32_t updatedIndex;
    bool clear;  // no square it passes over can conflict (so far)
};

/** applyVisibilityConstraint's arrays, kept between calls on each thread: a frame's thousands of
 * rays would otherwise take fresh pages from the system on every update. */
struct VisibilityScratch {
    std::vector<float> regionBound, towardsSensor, unitLimits;
    std::vector<uint8_t> rayState;
    std::vector<std::pair<double, uint32_t>> fan, bucketed;
    std::vector<uint32_t> start;
    std::vector<double> keys, lengths, fastSlopes, groupFastSlopes;
    std::vector<FanRay> rays;
    std::vector<int32_t> unitTableOf;
};

/** This thread's scratch arrays. Out of line so that the caller holds a plain reference: named
 * directly, a thread_local of this shared library is looked up again (__tls_get_addr) at almost
 * every use inside the constraint's lambdas (13 % of its instructions). */
__attribute__((noinline)) VisibilityScratch& threadScratch() {
    thread_local VisibilityScratch scratch;
    return scratch;
}
}  // namespace

VisibilityStats applyVisibilityConstraint(BinGrid& grid, const Eigen::Vector3d& sensor_m,
                                          const VisibilityParams& vis,
                                          const BinUpdateParams& binParams, RayFan fanTest) {
    VisibilityStats stats;
    if (!vis.enabled) return stats;
    const double cell = grid.cellSize_m();
    const double step = 0.5 * cell;
    // Rays stop once they clear every bin they could still meet by the margin: the highest
    // stored anywhere, or (below) the highest in the region of this update.
    double stopHeight = grid.maxHeight_m() + vis.margin_m;  // hoisted: editBins writes memory
    const double invCell = 1.0 / cell;                      // computed as BinGrid's own [1/m]
    constexpr double kNoClamp = 1e8;  // [cells]; cellIndex() clamps beyond 5.3e8
    auto conflictMargin = [&](const Bin& b) {
        return vis.margin_m + 3.0 * BinGrid::sigma_m(b, binParams);
    };
    // The smallest conflict margin any bin can have (its variance at the floor), computed the
    // same way: a bin no higher than this above the line is kept without the square root.
    const double minConflictMargin = conflictMargin(Bin{});
    auto conflicts = [&](const Bin& b, double lineHeight_m) {
        const double above = b.height_m - lineHeight_m;
        return above > minConflictMargin && above > conflictMargin(b);
    };
    // Local height bounds: a block or a cell whose bound lies no more than minConflictMargin
    // above the line holds no conflicting bin. The tolerance covers the rounding of bins' float
    // heights: no bin lies above tolerantBound_m(bound).
    auto tolerantBound_m = [](float max_m) {
        return double(max_m) + 1e-6 * (1.0 + std::abs(double(max_m)));
    };
    auto boundMayConflict = [&](float max_m, double lineHeight_m) {
        return max_m > -std::numeric_limits<float>::infinity() &&
               tolerantBound_m(max_m) > lineHeight_m + minConflictMargin;
    };
    const double block_m = BinGrid::kBlockCells * cell;
    const double invBlock = 1.0 / block_m;
    // Slack [m] along and across the ray between a sample's computed position and the exact
    // line: far above the rounding of the sample positions (~1e-15 of the coordinates).
    constexpr double kSlack_m = 1e-6;

    const CellWindow& w = grid.window();  // edits never change it
    // The window's block range: the sweep below ends where the ray leaves it.
    const int blockXLo = BinGrid::blockOf(w.ix0), blockXHi = BinGrid::blockOf(w.ix0 + w.nx - 1);
    const int blockYLo = BinGrid::blockOf(w.iy0), blockYHi = BinGrid::blockOf(w.iy0 + w.ny - 1);

    // The whole update at once: every line of sight runs between its updated cell and the
    // sensor, so no lower than the lowest of them, over cells within the box spanned by the
    // updated cells and the sensor's cell (one cell wider for rounding). If no block meeting that
    // box can hold a bin above that height by more than the smallest conflict margin, nothing
    // conflicts (a floor seen from above: most laser scans). Only the rays are counted.
    const std::vector<BinGrid::UpdatedCell>& updated = grid.updatedCells();
    // The region's block bounds copied into a dense table (exact copies; up to 1 MB): the walks
    // below look them up there, without the block table's wrap-around and tags.
    VisibilityScratch& scratch = threadScratch();
    std::vector<float>& regionBound = scratch.regionBound;
    regionBound.clear();
    int tableX0 = 0, tableY0 = 0;
    unsigned tableNx = 0, tableNy = 0;
    auto blockBound = [&](int bx, int by) {
        const unsigned sx = unsigned(bx - tableX0), sy = unsigned(by - tableY0);
        return sx < tableNx && sy < tableNy ? regionBound[sx + sy * tableNx]
                                            : grid.blockMaxHeight_m(bx, by);
    };
    // towardsSensor[b]: the highest bound of the table blocks in the rectangle spanned by block b
    // and the sensor's block. The rest of a ray from a point in block b lies in that rectangle
    // (the exact segment does; rounding can move a sample across a block edge only within
    // 1e-15 m of the sensor, where the ray is at the sensor's height: checked once, below), so
    // a ray, or the rest of its walk, ends where it passes above that bound. Empty when the
    // sensor's block is outside the table or blocks near it are higher than the sensor.
    std::vector<float>& towardsSensor = scratch.towardsSensor;
    towardsSensor.clear();
    auto restBound = [&](int bx, int by) {
        const unsigned sx = unsigned(bx - tableX0), sy = unsigned(by - tableY0);
        return sx < tableNx && sy < tableNy ? towardsSensor[sx + sy * tableNx]
                                            : std::numeric_limits<float>::infinity();
    };
    // The sensor's block, and whether the blocks around it lie below it (towardsSensor's
    // condition).
    int sensorBx = 0, sensorBy = 0;
    bool rectangleUsable = false;
    if (!updated.empty()) {
        int ixLo = grid.cellIndex(sensor_m.x()), ixHi = ixLo;
        int iyLo = grid.cellIndex(sensor_m.y()), iyHi = iyLo;
        // A NaN sensor height makes every ray comparison fail (no ray edits): leave it out.
        double lowest_m =
            std::isnan(sensor_m.z()) ? std::numeric_limits<double>::infinity() : sensor_m.z();
        for (const BinGrid::UpdatedCell& u : updated) {
            ixLo = std::min(ixLo, u.ix);
            ixHi = std::max(ixHi, u.ix);
            iyLo = std::min(iyLo, u.iy);
            iyHi = std::max(iyHi, u.iy);
            lowest_m = std::min(lowest_m, double(u.maxHeight_m));
        }
        const int bxLo = BinGrid::blockOf(std::max(ixLo - 1, w.ix0));
        const int bxHi = BinGrid::blockOf(std::min(ixHi + 1, w.ix0 + w.nx - 1));
        const int byLo = BinGrid::blockOf(std::max(iyLo - 1, w.iy0));
        const int byHi = BinGrid::blockOf(std::min(iyHi + 1, w.iy0 + w.ny - 1));
        if (bxHi >= bxLo && byHi >= byLo &&
            double(bxHi - bxLo + 1) * double(byHi - byLo + 1) <= double(1 << 18)) {
            // The region's table and its bound in one pass.
            tableX0 = bxLo;
            tableY0 = byLo;
            tableNx = unsigned(bxHi - bxLo + 1);
            tableNy = unsigned(byHi - byLo + 1);
            regionBound.resize(size_t(tableNx) * tableNy);
            float bound_m = -std::numeric_limits<float>::infinity();
            for (int by = byLo; by <= byHi; by++)
                for (int bx = bxLo; bx <= bxHi; bx++) {
                    const float b = grid.blockMaxHeight_m(bx, by);
                    regionBound[unsigned(bx - bxLo) + unsigned(by - byLo) * tableNx] = b;
                    bound_m = std::max(bound_m, b);
                }
            // Every sample lies in this region: its bound caps what a ray can meet.
            stopHeight = std::min(stopHeight, tolerantBound_m(bound_m) + vis.margin_m);
            if (!boundMayConflict(bound_m, lowest_m)) {
                // As the walk counts them (length >= cell), the square root only near the edge.
                const double cell2Lo = cell * cell * (1 - 1e-9), cell2Hi = cell * cell * (1 + 1e-9);
                for (const BinGrid::UpdatedCell& u : updated) {
                    const double dx = sensor_m.x() - grid.cellCenter_m(u.ix);
                    const double dy = sensor_m.y() - grid.cellCenter_m(u.iy);
                    const double d2 = dx * dx + dy * dy;
                    stats.raysCast += d2 > cell2Hi ? 1 : d2 < cell2Lo ? 0 : !(std::sqrt(d2) < cell);
                }
                return stats;
            }
            sensorBx = BinGrid::blockOf(grid.cellIndex(sensor_m.x()));
            sensorBy = BinGrid::blockOf(grid.cellIndex(sensor_m.y()));
            float nearSensor_m = -std::numeric_limits<float>::infinity();
            for (int by = sensorBy - 1; by <= sensorBy + 1; by++)
                for (int bx = sensorBx - 1; bx <= sensorBx + 1; bx++)
                    nearSensor_m = std::max(nearSensor_m, blockBound(bx, by));
            rectangleUsable = sensorBx >= bxLo && sensorBx <= bxHi && sensorBy >= byLo &&
                              sensorBy <= byHi &&
                              !boundMayConflict(nearSensor_m, sensor_m.z() - 1e-6);
        }
    }
    // towardsSensor: rows, then the blocks of a row, outwards from the sensor's: a block's
    // rectangle is itself and the rectangles of its neighbours towards the sensor (the same
    // maxima in any order of evaluation).
    if (rectangleUsable) {
        // In table indices (the sensor's block is in the table); toX / toY: the offset of the
        // neighbour towards the sensor's column / row, 0 in it.
        towardsSensor.resize(regionBound.size());
        const ptrdiff_t nx = ptrdiff_t(tableNx), ny = ptrdiff_t(tableNy);
        const ptrdiff_t sensorX = sensorBx - tableX0, sensorY = sensorBy - tableY0;
        auto row = [&](ptrdiff_t y, ptrdiff_t toY) {
            auto block = [&](ptrdiff_t x, ptrdiff_t toX) {
                const ptrdiff_t i = x + y * nx;
                float r = regionBound[size_t(i)];
                if (toX != 0) r = std::max(r, towardsSensor[size_t(i + toX)]);
                if (toY != 0) r = std::max(r, towardsSensor[size_t(i + toY * nx)]);
                towardsSensor[size_t(i)] = r;
            };
            for (ptrdiff_t x = sensorX; x >= 0; x--) block(x, x == sensorX ? 0 : 1);
            for (ptrdiff_t x = sensorX + 1; x < nx; x++) block(x, -1);
        };
        for (ptrdiff_t y = sensorY; y >= 0; y--) row(y, y == sensorY ? 0 : 1);
        for (ptrdiff_t y = sensorY + 1; y < ny; y++) row(y, -1);
    }

    // The fan of rays at once (every ray starts at the sensor): a ray is proven clear, and not
    // walked, when nothing it passes over can hold a bin above it by the smallest conflict
    // margin. Each block high enough to matter is tested against the rays within its angle as
    // seen from the sensor, at the ray's lowest height over the block's range of distances
    // from the sensor (the block's geometry computed once for all rays); where a block is too
    // high for a ray, its units of kUnitCells x kUnitCells cells, then their cells, at the
    // ray's lowest height over the distances along the ray where it can cross them. So a ray
    // passing high over rocks near the sensor while its end grazes flat ground needs no walk.
    // Conservative: every sample of the walk lies, to the slack, in the squares tested, its ray
    // height is no lower than the one tested (1e-9 m covers the rounding of heights below
    // 1e4 m), and the bounds only go up.
    // rayState[i] for updated cell i: kWalk, kClear (its ray edits nothing) or kNoRay (shorter
    // than a cell); empty: the test did not run.
    enum : uint8_t { kWalk, kClear, kNoRay };
    std::vector<uint8_t>& rayState = scratch.rayState;
    rayState.clear();
    // Set when the test decided every ray and none is to be walked (rayState is then not
    // read): the rays it proved clear.
    bool noWalk = false;
    size_t raysDecided = 0, raysClear = 0;
    constexpr double kMaxCoordinate_m = 1e5, kMaxHeight_m = 1e4, kHeightSlack_m = 1e-9;
    const double regionExtent_m = std::max(
        {std::abs(sensor_m.x()), std::abs(sensor_m.y()), std::abs(double(tableX0)) * block_m,
         std::abs(double(tableY0)) * block_m, std::abs(double(tableX0) + tableNx) * block_m,
         std::abs(double(tableY0) + tableNy) * block_m});
    if (fanTest == RayFan::Test && !regionBound.empty() && std::abs(sensor_m.z()) < kMaxHeight_m &&
        regionExtent_m < kMaxCoordinate_m) {
        // A bound as the tests below compare it: boundMayConflict(b, z) is limit(b) > z + margin.
        auto limit_m = [&](float max_m) {
            return max_m > -std::numeric_limits<float>::infinity()
                       ? tolerantBound_m(max_m)
                       : -std::numeric_limits<double>::infinity();
        };
        // The rays (in the order of the updated cells) and their keys: pseudoAngle from the
        // sensor, ray.
        std::vector<FanRay>& rays = scratch.rays;
        rays.clear();
        auto& fan = scratch.fan;
        fan.clear();
        rayState.assign(updated.size(), kWalk);
        double lowestRay_m = sensor_m.z();
        for (size_t i = 0; i < updated.size(); i++) {
            const BinGrid::UpdatedCell& u = updated[i];
            const double tz = u.maxHeight_m;
            const double tx = grid.cellCenter_m(u.ix), ty = grid.cellCenter_m(u.iy);
            const double dx = sensor_m.x() - tx, dy = sensor_m.y() - ty;
            const double length = std::sqrt(dx * dx + dy * dy);  // as the walk's
            if (length < cell) {
                rayState[i] = kNoRay;
                raysDecided++;
            } else if (!towardsSensor.empty() &&
                       !boundMayConflict(restBound(BinGrid::blockOf(u.ix), BinGrid::blockOf(u.iy)),
                                         std::min(tz, sensor_m.z()) - kSlack_m)) {
                rayState[i] = kClear;  // the rectangle towards the sensor, as the walk's test
                raysDecided++;
                raysClear++;
            } else if (std::abs(tz) < kMaxHeight_m) {
                fan.emplace_back(pseudoAngle(-dx, -dy), uint32_t(rays.size()));
                lowestRay_m = std::min(lowestRay_m, tz);
                // One division: the tests below allow far more than its rounding.
                const double invLength = 1.0 / length;
                const double slope = (sensor_m.z() - tz) * invLength, ux = dx * invLength,
                             uy = dy * invLength;
                rays.push_back({tx, ty, ux, uy, std::abs(ux) + std::abs(uy), length, slope,
                                std::abs(slope) * 0.7072 * cell, tz, u.ix, u.iy, uint32_t(i),
                                true});
            }
        }
        // The rays in key order, as the blocks below take them. A scan's come in beam order,
        // keys nearly sorted (up or down) from some angle round to it: reversed and rotated to
        // that order, insertion sort finishes in about linear time. Otherwise (a frame's rows)
        // a counting sort on buckets of keys, as many as rays, first.
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
        if (const size_t n = fan.size(); n > 1) {
            // One pass: the descents, and where the largest drop and the largest rise are (the
            // largest drop once reversed).
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
            if (largestDrop > 2) std::rotate(fan.begin(), fan.begin() + wrap, fan.end());
            if (!insertionSort(2 * n)) {
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
        }
        constexpr double kNoFastTest = std::numeric_limits<double>::infinity();
        constexpr size_t kGroup = 8;
        // In key order; lengths and slopes apart for the blocks' loop over rays.
        const size_t nRays = fan.size();
        // fastSlopes: the slope, or +infinity where the fast test below does not apply.
        std::vector<double>& keys = scratch.keys;
        std::vector<double>& lengths = scratch.lengths;
        std::vector<double>& fastSlopes = scratch.fastSlopes;
        keys.resize(nRays);
        lengths.resize(nRays);
        fastSlopes.resize(nRays);
        for (size_t j = 0; j < nRays; j++) {
            const FanRay& r = rays[fan[j].second];
            keys[j] = fan[j].first;
            lengths[j] = r.length;
            fastSlopes[j] = r.slope >= 0 ? r.slope : kNoFastTest;
        }
        const double longestRay_m =
            nRays > 0 ? *std::max_element(lengths.begin(), lengths.end()) : 0.0;
        // The steepest fastSlopes of each group of kGroup rays in key order (the last one
        // possibly shorter).
        std::vector<double>& groupFastSlopes = scratch.groupFastSlopes;
        groupFastSlopes.resize((nRays + kGroup - 1) / kGroup);
        for (size_t j = 0; j < nRays; j += kGroup)
            groupFastSlopes[j / kGroup] = *std::max_element(
                fastSlopes.begin() + j, fastSlopes.begin() + std::min(j + kGroup, nRays));
        // The ray's lowest height [m] over its samples at distances [from, to] from the target
        // (clipped to the walk's [step, length)), or NaN if there is none.
        auto lowestBetween = [&](const FanRay& r, double from, double to) {
            from = std::max(from, step);
            to = std::min(to, r.length);
            if (!(from <= to)) return std::numeric_limits<double>::quiet_NaN();
            return r.tz + std::min(r.slope * from, r.slope * to) + r.rise - kHeightSlack_m;
        };
        // The same over a square of centre (cx, cy) and half side h [m], widened by the slack:
        // where the line crosses it (its support across and along the ray).
        auto lowestOver = [&](const FanRay& r, double cx, double cy, double h) {
            const double ex = cx - r.tx, ey = cy - r.ty;
            const double reach = (h + kSlack_m) * r.sumAbsU;
            if (std::abs(r.ux * ey - r.uy * ex) > reach)
                return std::numeric_limits<double>::quiet_NaN();
            const double along = r.ux * ex + r.uy * ey;
            return lowestBetween(r, along - reach, along + reach);
        };
        constexpr int kUnitShift = 2, kUnitCells = 1 << kUnitShift;
        constexpr int kUnits = BinGrid::kBlockCells / kUnitCells;  // per side of a block
        // Per block, when first needed: limit_m of each unit's highest cell bound, rounded up
        // to a float (compared 16 at a time).
        std::vector<int32_t>& unitTableOf = scratch.unitTableOf;
        std::vector<float>& unitLimits = scratch.unitLimits;
        unitTableOf.clear();
        unitLimits.clear();
        auto roundUp = [](double v) {  // to within 1e-6 of v, far above float rounding
            return std::isfinite(v) ? float(v + 1e-6 * std::abs(v)) : float(v);
        };
        auto unitsOf = [&](unsigned blockSlot, int bx, int by) {
            if (unitTableOf.empty()) unitTableOf.assign(regionBound.size(), -1);
            int32_t& t = unitTableOf[blockSlot];
            if (t >= 0) return &unitLimits[size_t(t)];
            t = int32_t(unitLimits.size());
            float units[kUnits * kUnits];
            std::fill(units, units + kUnits * kUnits, -std::numeric_limits<float>::infinity());
            // The block's cells inside the window, a row at a time: its slots are one or two
            // contiguous runs.
            const VisibilityIndex& index = grid.visibilityIndex();
            const int ixLo = std::max(bx * BinGrid::kBlockCells, w.ix0);
            const int ixHi = std::min((bx + 1) * BinGrid::kBlockCells, w.ix0 + w.nx);
            const int iyLo = std::max(by * BinGrid::kBlockCells, w.iy0);
            const int iyHi = std::min((by + 1) * BinGrid::kBlockCells, w.iy0 + w.ny);
            int sx0 = ixLo - w.ix0 + grid.store().originSlotX();
            if (sx0 >= w.nx) sx0 -= w.nx;
            const int firstRun = std::min(ixHi - ixLo, w.nx - sx0);  // cells before the wrap
            const int originY = grid.store().originSlotY();
            const int column0 = ixLo - bx * BinGrid::kBlockCells;  // of the first cell read
            // Usually the block's rows lie whole in one run: a unit's row is 4 adjacent slots.
            const bool wholeRows = column0 == 0 && firstRun == BinGrid::kBlockCells;
            for (int iy = iyLo; iy < iyHi; iy++) {
                int sy = iy - w.iy0 + originY;
                if (sy >= w.ny) sy -= w.ny;
                const size_t base = size_t(sy) * size_t(w.nx), first = base + size_t(sx0);
                float* unitRow = units + ((iy - by * BinGrid::kBlockCells) >> kUnitShift) * kUnits;
                if (wholeRows) {
                    for (int c = 0; c < kUnits; c++) {
                        float m = unitRow[c];
                        for (int k = 0; k < kUnitCells; k++)
                            m = std::max(m,
                                         index.cellMaxHeight_m(first + size_t(c * kUnitCells + k)));
                        unitRow[c] = m;
                    }
                    continue;
                }
                for (int k = 0; k < ixHi - ixLo; k++) {
                    const size_t slot =
                        k < firstRun ? first + size_t(k) : base + size_t(k - firstRun);
                    float& u = unitRow[(column0 + k) >> kUnitShift];
                    u = std::max(u, index.cellMaxHeight_m(slot));
                }
            }
            unitLimits.resize(size_t(t) + kUnits * kUnits);
            for (int k = 0; k < kUnits * kUnits; k++)
                unitLimits[size_t(t) + size_t(k)] = roundUp(limit_m(units[k]));
            return &unitLimits[size_t(t)];
        };
        // Whether the ray may meet a conflicting bin in block (bx, by), over which it passes
        // no lower than blockLow_m: its units, then their cells (not the target's, nor updated
        // ones: the walk skips them).
        auto mayConflictInBlock = [&](const FanRay& r, unsigned blockSlot, int bx, int by,
                                      double blockLow_m) __attribute__((always_inline)) {
            const float* units = unitsOf(blockSlot, bx, by);
            // Rounded down, so a unit above the line in doubles is above it in floats.
            const double line_m = blockLow_m + minConflictMargin;
            const float lineF = float(line_m - 1e-6 * std::abs(line_m));
            uint32_t high = 0;  // the units above the ray's lowest height over the block
#ifdef __SSE2__
            const __m128 line4 = _mm_set1_ps(lineF);
            for (int k = 0; k < kUnits * kUnits; k += 4)
                high |= uint32_t(_mm_movemask_ps(_mm_cmpgt_ps(_mm_loadu_ps(units + k), line4)))
                        << k;
#else
            for (int k = 0; k < kUnits * kUnits; k++) high |= units[k] > lineF ? 1u << k : 0u;
#endif
            if (high == 0) return false;
            // lowestOver for each unit, from the first unit's offsets and a unit's steps.
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
                // The units the line passes within reach of, all 16 at once (the same
                // arithmetic as below, so the same ones): no branch per unit.
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
                if (!(units[k] > unitLow_m + minConflictMargin)) continue;
                const int ix0 = bx * BinGrid::kBlockCells + i * kUnitCells;
                const int iy0 = by * BinGrid::kBlockCells + j * kUnitCells;
                // Its cells likewise, from the unit's first cell.
                const double cellCross0 =
                    cross - (0.5 * kUnitCells - 0.5) * (stepX - stepY) / kUnitCells;
                const double cellAlong0 =
                    along - (0.5 * kUnitCells - 0.5) * (stepX + stepY) / kUnitCells;
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
                        if (boundMayConflict(grid.cellMaxHeight_m(ix, iy), cellLow_m) &&
                            !grid.updatedThisCycle(ix, iy))
                            return true;
                    }
            }
            return false;
        };
        // Keys are exact to far better than this for squares at least kNearSensor_m away.
        constexpr double kKeySlack = 1e-6, kNearSensor_m = 1e-3;
        const double sx = sensor_m.x(), sy = sensor_m.y(), sz = sensor_m.z();
        const double inCell_m = 0.7072 * cell;  // rise = |slope| inCell_m
        for (int by = tableY0; by < tableY0 + int(tableNy) && nRays > 0; by++)
            for (int bx = tableX0; bx < tableX0 + int(tableNx); bx++) {
                const unsigned slot = unsigned(bx - tableX0) + unsigned(by - tableY0) * tableNx;
                const double blockLimit_m = limit_m(regionBound[slot]);
                if (!(blockLimit_m > lowestRay_m - kHeightSlack_m + minConflictMargin))
                    continue;  // below every ray
                const double x0 = bx * block_m - kSlack_m, x1 = (bx + 1) * block_m + kSlack_m;
                const double y0 = by * block_m - kSlack_m, y1 = (by + 1) * block_m + kSlack_m;
                // Distances from the sensor to the (widened) block: nearest and farthest.
                const double gapX = std::max({x0 - sx, sx - x1, 0.0});
                const double gapY = std::max({y0 - sy, sy - y1, 0.0});
                const double farX = std::max(std::abs(x0 - sx), std::abs(x1 - sx));
                const double farY = std::max(std::abs(y0 - sy), std::abs(y1 - sy));
                const double near_m = std::sqrt(gapX * gapX + gapY * gapY) - kSlack_m;
                const double far_m = std::sqrt(farX * farX + farY * farY) + kSlack_m;
                // A ray rising towards the sensor passes over the block no lower than
                // sz - slope far_m + slope inCell_m (its samples there lie at most far_m from
                // the sensor, and tz + slope length is sz), wherever it ends: clear if its slope
                // is at most maxSlope (1e-8 m spare for the rounding of the quotient and of
                // tz + slope d).
                const double maxSlope =
                    (sz - blockLimit_m + minConflictMargin - 1e-8) / (far_m - inCell_m);
                // No sample of a ray shorter than this lies in the block (1e-9 m spare).
                const double nearStep_m = near_m + step - 1e-9;
                if (longestRay_m < nearStep_m) continue;  // beyond every ray
                const double cx = (bx + 0.5) * block_m, cy = (by + 0.5) * block_m;
                // The rays within the block's angle: keys in [lo, hi], which may pass key 0 (the
                // +x direction) on either side; all of them near the sensor.
                size_t ranges[2][2] = {{0, nRays}, {0, 0}};
                if (std::max(gapX, gapY) >= kNearSensor_m) {
                    const bool acrossZero = x1 > sx && y0 <= sy && sy <= y1;
                    double lo = std::numeric_limits<double>::infinity(), hi = -lo;
                    for (const double x : {x0, x1})
                        for (const double y : {y0, y1}) {
                            double k = pseudoAngle(x - sx, y - sy);
                            if (acrossZero && k < 2) k += 4;
                            lo = std::min(lo, k);
                            hi = std::max(hi, k);
                        }
                    lo -= kKeySlack;
                    hi += kKeySlack;
                    if (hi - lo < 2) {  // less than half a turn, as a square away from the sensor
                        // Binary searches without a branch on the keys (conditional moves):
                        // the keys' order is no pattern a branch predictor learns.
                        // The number of leading keys for which `before(key)` holds (the keys
                        // are sorted, so they are a prefix).
                        auto prefix = [&](auto before) {
                            const double* base = keys.data();
                            size_t n = nRays;
                            while (n > 1) {
                                const size_t half = n / 2;
                                base = before(base[half - 1]) ? base + half : base;
                                n -= half;
                            }
                            return size_t(base - keys.data()) + size_t(n == 1 && before(*base));
                        };
                        auto first = [&](double k) {  // the first ray of key >= k
                            return prefix([k](double key) { return key < k; });
                        };
                        auto after = [&](double k) {  // the first ray of key > k
                            return prefix([k](double key) { return !(k < key); });
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
                }
                for (const auto& range : ranges)
                    for (size_t j = range[0]; j < range[1]; j++) {
                        // The rest of j's group at once where none of the group is steeper
                        // than maxSlope (at a range's ends, part of a group: a subset).
                        if (j % kGroup == 0 || j == range[0]) {
                            const size_t g = j / kGroup;
                            if (groupFastSlopes[g] <= maxSlope) {
                                j = std::min((g + 1) * kGroup, range[1]) - 1;
                                continue;
                            }
                        }
                        // On the line, a sample at distance d from the target lies length - d
                        // from the sensor: none in the block if length < nearStep_m.
                        const double length = lengths[j];
                        if (length < nearStep_m) continue;
                        if (fastSlopes[j] <= maxSlope) continue;
                        FanRay& r = rays[fan[j].second];
                        if (!r.clear) continue;  // already to be walked
                        // Both bounds hold: the larger one, the second only where the first
                        // does not clear the ray (a NaN first one: no sample in the block).
                        const double between_m = lowestBetween(r, length - far_m, length - near_m);
                        if (!(blockLimit_m > between_m + minConflictMargin)) continue;
                        const double low_m =
                            std::max(between_m, lowestOver(r, cx, cy, 0.5 * block_m));
                        if (blockLimit_m > low_m + minConflictMargin &&
                            mayConflictInBlock(r, slot, bx, by, low_m))
                            r.clear = false;
                    }
            }
        size_t fanClear = 0;
        for (const FanRay& r : rays) {
            rayState[r.updatedIndex] = r.clear ? kClear : kWalk;
            fanClear += r.clear;
        }
        // The rays left out of the fan (heights beyond kMaxHeight_m) are walked.
        noWalk = raysDecided + fanClear == updated.size();
        if (noWalk) stats.raysCast += raysClear + fanClear;
    }

    // The sample distances along a ray, as the walk accumulates them (d += step, not k step,
    // whose rounding differs): the same for every ray, so computed once, as far as a ray needs.
    std::vector<double> sampleAt{0.0, step};
    // Per ray: the stretches [from, to] of distance over block columns that may hold a
    // conflicting bin, in walking order; samples elsewhere are skipped (see below).
    std::vector<std::pair<double, double>> stretches;

    for (size_t i = 0; i < updated.size(); i++) {
        const BinGrid::UpdatedCell& u = updated[i];
        const double tz = u.maxHeight_m;
        // Computed where used: most updated cells edit nothing.
        auto decrement = [&]() { return vis.certaintyDecrement * float(u.points); };
        // The certainty of the cell's surface (CellSurface) before its own edit (below); needed
        // only when a ray meets a conflicting bin. Rays never edit updated cells, so a late
        // look-up gives the same value unless the cell's own edit ran: then it is taken first.
        double targetCertainty = 0;
        bool haveTarget = false;
        auto target = [&]() {
            if (!haveTarget) {
                CellSurface surface;
                targetCertainty =
                    cellSurface(grid, u.ix, u.iy, binParams, surface) ? surface.certainty : 0.0;
                haveTarget = true;
            }
            return targetCertainty;
        };

        // Bins of the updated cell above all that was measured in it now.
        if (boundMayConflict(grid.cellMaxHeight_m(u.ix, u.iy), tz)) {
            target();
            grid.editBins(u.ix, u.iy, [&](Bin& b) {
                if (!conflicts(b, tz)) return true;
                b.certainty -= decrement();
                stats.binsWeakened++;
                if (b.certainty > 0) return true;
                stats.binsRemoved++;
                return false;
            });
        }

        // Walk the line of sight from the updated cell back to the sensor.
        if (noWalk) continue;                             // counted above
        if (!rayState.empty() && rayState[i] != kWalk) {  // decided by the fan test above
            stats.raysCast += rayState[i] == kClear;
            continue;
        }
        const double tx = grid.cellCenter_m(u.ix), ty = grid.cellCenter_m(u.iy);
        const double dx = sensor_m.x() - tx, dy = sensor_m.y() - ty;
        const double length = std::sqrt(dx * dx + dy * dy);  // libm hypot is several times slower
        if (length < cell) continue;
        stats.raysCast++;
        // The whole ray at once: no lower than its lower end, over the rectangle between its
        // cell's block and the sensor's. If no block there can conflict, the walk below would
        // edit nothing (most floor rays of a lidar revolution in a room).
        if (!towardsSensor.empty() &&
            !boundMayConflict(restBound(BinGrid::blockOf(u.ix), BinGrid::blockOf(u.iy)),
                              std::min(tz, sensor_m.z()) - kSlack_m))
            continue;

        // Sweep the ray's block columns (rows if it runs more along y), with its direction and
        // slope to rounding (the slack covers it): over each, the blocks the line can touch and
        // the ray's lowest height there. `reach` ends the last stretch of the ray below some
        // block's bound: no sample beyond it can meet a conflicting bin.
        double reach = 0;
        stretches.clear();
        {
            const bool xMajor = std::abs(dx) >= std::abs(dy);
            const double da0 = xMajor ? dx : dy, db0 = xMajor ? dy : dx;
            // One division for 1 / length and 1 / ua (ua = da0 / length, |ua| >= 0.707).
            const double r = 1.0 / (length * da0);
            const double invLength = da0 * r, invUa = length * length * r;
            const double ub = db0 * invLength;
            const double aSlope = (sensor_m.z() - tz) * invLength;
            const double aRise = std::abs(aSlope) * 0.7072 * cell;
            const double a0 = xMajor ? tx : ty, b0 = xMajor ? ty : tx;
            const int stepA = da0 > 0 ? 1 : -1;
            const int endA =
                da0 > 0 ? (xMajor ? blockXHi : blockYHi) + 1 : (xMajor ? blockXLo : blockYLo) - 1;
            int ka = BinGrid::blockOf(xMajor ? u.ix : u.iy);
            for (double da = 0; da < length && ka != endA; ka += stepA) {
                // A rising ray is lowest where the stretch starts.
                const double startZ_m = tz + aSlope * (da - kSlack_m) - kSlack_m;
                // Past here the samples stop: the ray clears the highest stored bin (below).
                if (aSlope > 0 && startZ_m - aRise > stopHeight) break;
                const double exit = ((da0 > 0 ? ka + 1 : ka) * block_m - a0) * invUa;
                const double db = std::min(exit, length);
                const double bLo = b0 + ub * (ub > 0 ? da - kSlack_m : db + kSlack_m) - kSlack_m;
                const double bHi = b0 + ub * (ub > 0 ? db + kSlack_m : da - kSlack_m) + kSlack_m;
                float bound_m = -std::numeric_limits<float>::infinity();
                float rest_m = -std::numeric_limits<float>::infinity();
                for (int kb = BinGrid::floorToInt(bLo * invBlock),
                         kbEnd = BinGrid::floorToInt(bHi * invBlock);
                     kb <= kbEnd; kb++) {
                    const int bx = xMajor ? ka : kb, by = xMajor ? kb : ka;
                    bound_m = std::max(bound_m, blockBound(bx, by));
                    if (!towardsSensor.empty()) rest_m = std::max(rest_m, restBound(bx, by));
                }
                // The rest of the ray, this column included: no lower than its ends.
                if (!towardsSensor.empty() &&
                    !boundMayConflict(
                        rest_m, std::min(startZ_m, tz + aSlope * (length + kSlack_m) - kSlack_m)))
                    break;
                const double lowest_m =
                    aSlope > 0 ? startZ_m : tz + aSlope * (db + kSlack_m) - kSlack_m;
                if (boundMayConflict(bound_m, lowest_m + aRise)) {
                    // A rising ray clears the column's bound part-way (rocks: mostly within a
                    // few cells): past that distance every sample's ray, at least
                    // tz + slope d + inCellRise, lies above the bound by the smallest conflict
                    // margin (1e-6 m spare for rounding), so the stretch ends there.
                    double end = db;
                    if (aSlope > 0) {
                        const double clearHeight_m =
                            tolerantBound_m(bound_m) - minConflictMargin - aRise + 1e-6;
                        end = std::min(db, std::max(da, (clearHeight_m - tz) / aSlope));
                    }
                    reach = end + kSlack_m;
                    if (!stretches.empty() && stretches.back().second >= da - kSlack_m)
                        stretches.back().second = reach;  // joins the previous column's
                    else
                        stretches.emplace_back(da - kSlack_m, reach);
                }
                da = exit;
            }
        }
        if (!(reach >= step)) continue;  // the first sample lies beyond it

        // The samples, exactly as the global-bound walk takes them.
        const double slope = (sensor_m.z() - tz) / length;  // ray height gained per metre back
        // The ray's highest point within a cell lies at most half a diagonal from a sample.
        const double inCellRise = std::abs(slope) * 0.7072 * cell;
        const double ux = dx / length, uy = dy / length;  // unit direction towards the sensor
        // Every sample lies between the cell centre and the sensor; unless the sensor is absurdly
        // far away, no sample reaches the range where BinGrid::cellIndex() clamps, and its floor
        // alone gives the same index.
        const bool unclamped = std::abs(sensor_m.x() * invCell) < kNoClamp &&
                               std::abs(sensor_m.y() * invCell) < kNoClamp &&
                               std::abs(tx * invCell) < kNoClamp &&
                               std::abs(ty * invCell) < kNoClamp;
        auto cellOf = [&](double coord_m) {
            return unclamped ? BinGrid::floorToInt(coord_m * invCell) : grid.cellIndex(coord_m);
        };
        // The ray starts inside the window, which is convex: past the point where it leaves the
        // window no sample can touch a cell of the grid. Without this, a sensor far from the map
        // (a corrupt pose) costs 10^11 samples per updated cell.
        double walk = length;
        auto clipAxis = [&](double origin, double dir, int i0, int n) {
            if (dir > 0) walk = std::min(walk, ((i0 + n) * cell - origin) / dir + cell);
            if (dir < 0) walk = std::min(walk, (i0 * cell - origin) / dir + cell);
        };
        clipAxis(tx, ux, w.ix0, w.nx);
        clipAxis(ty, uy, w.iy0, w.ny);
        // Only the samples within the stretches, each taken exactly as the full walk takes it:
        // a sample outside them lies over blocks whose bound is too low to conflict, so it edits
        // nothing, and it lies in another cell than the next sample taken (cells of a column
        // that cannot conflict, or, within the slack of a column edge, a cell the block test
        // below rejects as the full walk's would): the one-test-per-cell rule is kept.
        const double last = std::min(walk, reach);
        while (sampleAt.back() < last) sampleAt.push_back(sampleAt.back() + step);
        int lastIx = u.ix, lastIy = u.iy;
        size_t k = 1;
        bool done = false;
        for (const auto& [from, to] : stretches) {
            // sampleAt[k] is k step to within far less than a step: start two samples early.
            const double guess = std::floor(from / step) - 2;
            if (guess > double(k)) k = size_t(guess);
            for (; k < sampleAt.size(); k++) {
                const double d = sampleAt[k];
                if (d < from) continue;
                if (!(d < walk) || d > reach) {
                    done = true;
                    break;
                }
                if (d > to) break;
                const double rayZ = tz + slope * d;
                if (slope > 0 && rayZ - inCellRise > stopHeight) {
                    done = true;
                    break;
                }
                const int ix = cellOf(tx + ux * d);
                const int iy = cellOf(ty + uy * d);
                if (ix == lastIx && iy == lastIy) continue;
                lastIx = ix;
                lastIy = iy;
                const double rayHigh = rayZ + inCellRise;
                // The block bound first: a small table, and most cells stop here.
                if (!boundMayConflict(blockBound(BinGrid::blockOf(ix), BinGrid::blockOf(iy)),
                                      rayHigh))
                    continue;
                // Then the cell's own bound (outside the window: -infinity), before its bins.
                if (!boundMayConflict(grid.cellMaxHeight_m(ix, iy), rayHigh) ||
                    grid.updatedThisCycle(ix, iy))
                    continue;
                stats.cellsVisited++;
                grid.editBins(ix, iy, [&](Bin& b) {
                    if (!conflicts(b, rayHigh)) return true;
                    if (b.certainty < target()) {
                        stats.binsRemoved++;
                        return false;
                    }
                    b.certainty -= decrement();
                    stats.binsWeakened++;
                    if (b.certainty > 0) return true;
                    stats.binsRemoved++;
                    return false;
                });
            }
            if (done) break;
        }
    }
    return stats;
}

}  // namespace multibin
