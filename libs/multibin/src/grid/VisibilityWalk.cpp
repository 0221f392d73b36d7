/* Part of the multibin elevation-mapping library. */
/* Stages 4 and 5 of the visibility constraint (VisibilityStages.h): a ray's stretches over
 * block columns that may conflict, and the rule's samples within them. */
#include <algorithm>
#include <cmath>

#include "multibin/grid/VisibilityStages.h"

namespace multibin::visibility {

double sweepColumns(const BinGrid& grid, const Region& region, const TowardsSensor& towards,
                    const BinGrid::UpdatedCell& u, const Eigen::Vector3d& sensor_m, double length,
                    const BoundTest& bounds, double stopHeight_m,
                    std::vector<std::pair<double, double>>& stretches) {
    // The ray's direction and slope to rounding (the slack covers it): over each column, the
    // blocks the line can touch and the ray's lowest height there. `reach` ends the last
    // stretch of the ray below some block's bound.
    stretches.clear();
    double reach = 0;
    const double cell = grid.cellSize_m(), block_m = BinGrid::kBlockCells * cell;
    const double invBlock = 1.0 / block_m;
    const CellWindow& w = grid.window();
    const double tx = grid.cellCenter_m(u.ix), ty = grid.cellCenter_m(u.iy), tz = u.maxHeight_m;
    const double dx = sensor_m.x() - tx, dy = sensor_m.y() - ty;
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
    // The window's block range: the sweep ends where the ray leaves it.
    const int lo = BinGrid::blockOf(xMajor ? w.ix0 : w.iy0);
    const int hi = BinGrid::blockOf(xMajor ? w.ix0 + w.nx - 1 : w.iy0 + w.ny - 1);
    const int endA = da0 > 0 ? hi + 1 : lo - 1;
    int ka = BinGrid::blockOf(xMajor ? u.ix : u.iy);
    for (double da = 0; da < length && ka != endA; ka += stepA) {
        // A rising ray is lowest where the stretch starts.
        const double startZ_m = tz + aSlope * (da - kSlack_m) - kSlack_m;
        // Past here the samples stop: the ray clears the highest bin that can conflict.
        if (aSlope > 0 && startZ_m - aRise > stopHeight_m) break;
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
            bound_m = std::max(bound_m, region.blockBound(grid, bx, by));
            if (towards.usable()) rest_m = std::max(rest_m, towards.restBound(bx, by));
        }
        // The rest of the ray, this column included: no lower than its ends.
        if (towards.usable() &&
            !bounds.mayConflict(rest_m,
                                std::min(startZ_m, tz + aSlope * (length + kSlack_m) - kSlack_m)))
            break;
        const double lowest_m = aSlope > 0 ? startZ_m : tz + aSlope * (db + kSlack_m) - kSlack_m;
        if (bounds.mayConflict(bound_m, lowest_m + aRise)) {
            // A rising ray clears the column's bound part-way (rocks: mostly within a few
            // cells): past that distance every sample's ray, at least tz + slope d +
            // inCellRise, lies above the bound by the smallest conflict margin (1e-6 m spare
            // for rounding), so the stretch ends there.
            double end = db;
            if (aSlope > 0) {
                const double clearHeight_m =
                    BoundTest::tolerant_m(bound_m) - bounds.minConflictMargin_m - aRise + 1e-6;
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
    return reach;
}

void walkStretches(BinGrid& grid, const Region& region, const SightLine& ray, int startIx,
                   int startIy, const std::vector<std::pair<double, double>>& stretches,
                   double reach_m, double stopHeight_m, const BoundTest& bounds,
                   const ConflictTest& conflicts, LazyTargetCertainty& target, float decrement,
                   std::vector<double>& sampleAt, VisibilityStats& stats) {
    // The sample distances as the rule accumulates them (d += step, not k step, whose rounding
    // differs): the same for every ray, so computed once, as far as a ray needs.
    const double step = 0.5 * grid.cellSize_m();
    if (sampleAt.empty()) sampleAt = {0.0, step};
    // A sample outside the stretches lies over blocks whose bound is too low to conflict, so it
    // edits nothing, and in another cell than the next sample taken (cells of a column that
    // cannot conflict, or, within the slack of a column edge, a cell the block test below
    // rejects as the rule's would): the one-test-per-cell rule is kept.
    const double last = std::min(ray.walk_m, reach_m);
    while (sampleAt.back() < last) sampleAt.push_back(sampleAt.back() + step);
    int lastIx = startIx, lastIy = startIy;
    size_t k = 1;
    for (const auto& [from, to] : stretches) {
        // sampleAt[k] is k step to within far less than a step: start two samples early.
        const double guess = std::floor(from / step) - 2;
        if (guess > double(k)) k = size_t(guess);
        for (; k < sampleAt.size(); k++) {
            const double d = sampleAt[k];
            if (d < from) continue;
            if (!(d < ray.walk_m) || d > reach_m) return;
            if (d > to) break;
            const double rayZ = ray.tz_m + ray.slope * d;
            if (ray.slope > 0 && rayZ - ray.inCellRise_m > stopHeight_m) return;
            const int ix = ray.cellOf(grid, ray.tx_m + ray.ux * d);
            const int iy = ray.cellOf(grid, ray.ty_m + ray.uy * d);
            if (ix == lastIx && iy == lastIy) continue;
            lastIx = ix;
            lastIy = iy;
            const double rayHigh = rayZ + ray.inCellRise_m;
            // The block bound first: a small table, and most cells stop here.
            if (!bounds.mayConflict(
                    region.blockBound(grid, BinGrid::blockOf(ix), BinGrid::blockOf(iy)), rayHigh))
                continue;
            // Then the cell's own bound (outside the window: -infinity), before its bins.
            if (!bounds.mayConflict(grid.cellMaxHeight_m(ix, iy), rayHigh) ||
                grid.updatedThisCycle(ix, iy))
                continue;
            stats.cellsVisited++;
            editOccluder(grid, ix, iy, rayHigh, conflicts, target, decrement, stats);
        }
    }
}

}  // namespace multibin::visibility
