/* Part of the multibin elevation-mapping library. */
#include "multibin/map/VisibilityConstraint.h"
#include <mrpt/config/CConfigFileBase.h>

#include "multibin/io/OptionKeys.h"
#include "multibin/map/CellSurface.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

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
}  // namespace

void VisibilityParams::read(StrictConfigSection& s) { visitKeys(*this, OptionReader{s}); }

void VisibilityParams::write(mrpt::config::CConfigFileBase& c, const std::string& section) const {
    visitKeys(*this, OptionWriter{c, section});
}

void VisibilityParams::validate() const {
    visitKeys(*this, OptionChecker("CMultiBinElevationMap insertion option"));
}

VisibilityStats applyVisibilityConstraint(BinGrid& grid, const Eigen::Vector3d& sensor_m,
                                          const VisibilityParams& vis,
                                          const BinUpdateParams& binParams) {
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
    std::vector<float> regionBound;
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
    std::vector<float> towardsSensor;
    auto restBound = [&](int bx, int by) {
        const unsigned sx = unsigned(bx - tableX0), sy = unsigned(by - tableY0);
        return sx < tableNx && sy < tableNy ? towardsSensor[sx + sy * tableNx]
                                            : std::numeric_limits<float>::infinity();
    };
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
            float bound_m = -std::numeric_limits<float>::infinity();
            for (int by = byLo; by <= byHi; by++)
                for (int bx = bxLo; bx <= bxHi; bx++)
                    bound_m = std::max(bound_m, grid.blockMaxHeight_m(bx, by));
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
            // Rays to walk: the region's tables (a second pass, which the common case above
            // never needs).
            tableX0 = bxLo;
            tableY0 = byLo;
            tableNx = unsigned(bxHi - bxLo + 1);
            tableNy = unsigned(byHi - byLo + 1);
            regionBound.resize(size_t(tableNx) * tableNy);
            for (int by = byLo; by <= byHi; by++)
                for (int bx = bxLo; bx <= bxHi; bx++)
                    regionBound[unsigned(bx - bxLo) + unsigned(by - byLo) * tableNx] =
                        grid.blockMaxHeight_m(bx, by);
            const int sbx = BinGrid::blockOf(grid.cellIndex(sensor_m.x()));
            const int sby = BinGrid::blockOf(grid.cellIndex(sensor_m.y()));
            float nearSensor_m = -std::numeric_limits<float>::infinity();
            for (int by = sby - 1; by <= sby + 1; by++)
                for (int bx = sbx - 1; bx <= sbx + 1; bx++)
                    nearSensor_m = std::max(nearSensor_m, blockBound(bx, by));
            if (sbx >= bxLo && sbx <= bxHi && sby >= byLo && sby <= byHi &&
                !boundMayConflict(nearSensor_m, sensor_m.z() - 1e-6)) {
                // Rows, then the blocks of a row, outwards from the sensor's: a block's
                // rectangle is itself and the rectangles of its neighbours towards the sensor.
                auto outwards = [](int from, int lo, int hi) {
                    std::vector<int> order{from};
                    for (int k = 1; from - k >= lo || from + k <= hi; k++) {
                        if (from - k >= lo) order.push_back(from - k);
                        if (from + k <= hi) order.push_back(from + k);
                    }
                    return order;
                };
                towardsSensor.resize(regionBound.size());
                const std::vector<int> columns = outwards(sbx, bxLo, bxHi);
                for (int by : outwards(sby, byLo, byHi))
                    for (int bx : columns) {
                        float r = blockBound(bx, by);
                        if (bx != sbx) r = std::max(r, restBound(bx + (bx < sbx ? 1 : -1), by));
                        if (by != sby) r = std::max(r, restBound(bx, by + (by < sby ? 1 : -1)));
                        towardsSensor[unsigned(bx - bxLo) + unsigned(by - byLo) * tableNx] = r;
                    }
            }
        }
    }

    // The sample distances along a ray, as the walk accumulates them (d += step, not k step,
    // whose rounding differs): the same for every ray, so computed once, as far as a ray needs.
    std::vector<double> sampleAt{0.0, step};
    // Per ray: the stretches [from, to] of distance over block columns that may hold a
    // conflicting bin, in walking order; samples elsewhere are skipped (see below).
    std::vector<std::pair<double, double>> stretches;

    for (const BinGrid::UpdatedCell& u : updated) {
        const double tz = u.maxHeight_m;
        const float decrement = vis.certaintyDecrement * float(u.points);
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
                b.certainty -= decrement;
                stats.binsWeakened++;
                if (b.certainty > 0) return true;
                stats.binsRemoved++;
                return false;
            });
        }

        // Walk the line of sight from the updated cell back to the sensor.
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
                    b.certainty -= decrement;
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
