/* Part of the multibin elevation-mapping library. */
#include "multibin/VisibilityConstraint.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace multibin {

VisibilityStats applyVisibilityConstraint(BinGrid& grid, const Eigen::Vector3d& sensor_m,
                                          const VisibilityParams& vis,
                                          const BinUpdateParams& binParams) {
    VisibilityStats stats;
    if (!vis.enabled) return stats;
    const double cell = grid.cellSize_m();
    const double step = 0.5 * cell;
    const double maxStoredHeight = grid.maxHeight_m();
    const double stopHeight = maxStoredHeight + vis.margin_m;  // hoisted: editBins writes memory
    const double invCell = 1.0 / cell;                         // computed as BinGrid's own [1/m]
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
    // Local height bound: a block whose bound lies no more than minConflictMargin above the line
    // holds no conflicting bin. The tolerance covers the rounding of bins' float heights.
    auto blockMayConflict = [&](float blockMax_m, double lineHeight_m) {
        return blockMax_m > -std::numeric_limits<float>::infinity() &&
               double(blockMax_m) + 1e-6 * (1.0 + std::abs(double(blockMax_m))) >
                   lineHeight_m + minConflictMargin;
    };
    const double block_m = BinGrid::kBlockCells * cell;
    const double invBlock = 1.0 / block_m;
    // Slack [m] along and across the ray between a sample's computed position and the exact
    // line: far above the rounding of the sample positions (~1e-15 of the coordinates).
    constexpr double kSlack_m = 1e-6;

    for (const BinGrid::UpdatedCell& u : grid.updatedCells()) {
        const Bin* winner = grid.winningBin(u.ix, u.iy);
        const float targetCertainty = winner ? winner->certainty : 0.f;
        const double tz = u.maxHeight_m;
        const float decrement = vis.certaintyDecrement * float(u.points);

        // Bins of the updated cell above all that was measured in it now.
        grid.editBins(u.ix, u.iy, [&](Bin& b) {
            if (!conflicts(b, tz)) return true;
            b.certainty -= decrement;
            stats.binsWeakened++;
            if (b.certainty > 0) return true;
            stats.binsRemoved++;
            return false;
        });

        // Walk the line of sight from the updated cell back to the sensor.
        const double tx = grid.cellCenter_m(u.ix), ty = grid.cellCenter_m(u.iy);
        const double dx = sensor_m.x() - tx, dy = sensor_m.y() - ty;
        const double length = std::sqrt(dx * dx + dy * dy);  // libm hypot is several times slower
        if (length < cell) continue;
        stats.raysCast++;
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
        const CellWindow& w = grid.window();
        double walk = length;
        auto clipAxis = [&](double origin, double dir, int i0, int n) {
            if (dir > 0) walk = std::min(walk, ((i0 + n) * cell - origin) / dir + cell);
            if (dir < 0) walk = std::min(walk, (i0 * cell - origin) / dir + cell);
        };
        clipAxis(tx, ux, w.ix0, w.nx);
        clipAxis(ty, uy, w.iy0, w.ny);
        // The samples never go past the global bound (below) or the window.
        const double globalReach =
            slope > 0 ? (stopHeight + inCellRise - tz) / slope + kSlack_m : walk;
        // Walk the ray's block columns (rows if it runs more along y): over each, the blocks the
        // line can touch, and the lowest ray height there. `reach` ends the last stretch of the
        // ray below some block's bound: no sample beyond it can meet a conflicting bin.
        double reach = 0;
        {
            const bool xMajor = std::abs(ux) >= std::abs(uy);
            const double a0 = xMajor ? tx : ty, b0 = xMajor ? ty : tx;
            const double ua = xMajor ? ux : uy, ub = xMajor ? uy : ux;  // |ua| >= 0.707
            const double invUa = 1.0 / ua;
            const double limit = std::min(walk, globalReach);
            int ka = BinGrid::blockOf(xMajor ? u.ix : u.iy);
            for (double da = 0; da<limit; ka += ua> 0 ? 1 : -1) {
                const double exit = ((ua > 0 ? ka + 1 : ka) * block_m - a0) * invUa;
                const double db = std::min(exit, limit);
                const double bLo = b0 + ub * (ub > 0 ? da - kSlack_m : db + kSlack_m) - kSlack_m;
                const double bHi = b0 + ub * (ub > 0 ? db + kSlack_m : da - kSlack_m) + kSlack_m;
                float bound_m = -std::numeric_limits<float>::infinity();
                for (int kb = BinGrid::floorToInt(bLo * invBlock),
                         kbEnd = BinGrid::floorToInt(bHi * invBlock);
                     kb <= kbEnd; kb++)
                    bound_m = std::max(bound_m, xMajor ? grid.blockMaxHeight_m(ka, kb)
                                                       : grid.blockMaxHeight_m(kb, ka));
                const double lowest_m = tz + slope * (slope > 0 ? da - kSlack_m : db + kSlack_m);
                if (blockMayConflict(bound_m, lowest_m + inCellRise)) reach = db + kSlack_m;
                da = exit;
            }
        }
        int lastIx = u.ix, lastIy = u.iy;
        for (double d = step; d < walk; d += step) {
            if (d > reach) break;
            const double rayZ = tz + slope * d;
            if (slope > 0 && rayZ - inCellRise > stopHeight) break;
            const int ix = cellOf(tx + ux * d);
            const int iy = cellOf(ty + uy * d);
            if (ix == lastIx && iy == lastIy) continue;
            lastIx = ix;
            lastIy = iy;
            if (!grid.window().contains(ix, iy) || grid.updatedThisCycle(ix, iy)) continue;
            const double rayHigh = rayZ + inCellRise;
            if (!blockMayConflict(grid.blockMaxHeight_m(BinGrid::blockOf(ix), BinGrid::blockOf(iy)),
                                  rayHigh))
                continue;
            stats.cellsVisited++;
            grid.editBins(ix, iy, [&](Bin& b) {
                if (!conflicts(b, rayHigh)) return true;
                if (b.certainty < targetCertainty) {
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
    }
    return stats;
}

}  // namespace multibin
