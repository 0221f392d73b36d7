/* Part of the multibin elevation-mapping library. */
#include "multibin/grid/VisibilityRule.h"

#include <algorithm>
#include <cmath>

#include "multibin/grid/CellSurface.h"

namespace multibin {

bool SightLine::setEnds(const BinGrid& grid, const BinGrid::UpdatedCell& u,
                        const Eigen::Vector3d& sensor_m) {
    tx_m = grid.cellCenter_m(u.ix);
    ty_m = grid.cellCenter_m(u.iy);
    tz_m = u.maxHeight_m;
    const double dx = sensor_m.x() - tx_m, dy = sensor_m.y() - ty_m;
    length_m = std::sqrt(dx * dx + dy * dy);  // libm hypot is several times slower
    return !(length_m < grid.cellSize_m());
}

void SightLine::setWalk(const BinGrid& grid, const Eigen::Vector3d& sensor_m) {
    const double cell = grid.cellSize_m();
    const double dx = sensor_m.x() - tx_m, dy = sensor_m.y() - ty_m;
    slope = (sensor_m.z() - tz_m) / length_m;
    inCellRise_m = std::abs(slope) * 0.7072 * cell;  // 0.7072: half a diagonal, rounded up
    ux = dx / length_m;
    uy = dy / length_m;
    invCell = 1.0 / cell;
    // Unless the sensor is absurdly far away, no sample reaches the range where
    // BinGrid::cellIndex() clamps, and its floor alone gives the same index.
    constexpr double kNoClamp = 1e8;  // [cells]; cellIndex() clamps beyond 5.3e8
    unclamped = std::abs(sensor_m.x() * invCell) < kNoClamp &&
                std::abs(sensor_m.y() * invCell) < kNoClamp &&
                std::abs(tx_m * invCell) < kNoClamp && std::abs(ty_m * invCell) < kNoClamp;
    // Past the point where the ray leaves the window no sample can touch a cell of the grid.
    // Without this, a sensor far from the map (a corrupt pose) costs 10^11 samples per cell.
    const CellWindow& w = grid.window();
    walk_m = length_m;
    auto clipAxis = [&](double origin, double dir, int i0, int n) {
        if (dir > 0) walk_m = std::min(walk_m, ((i0 + n) * cell - origin) / dir + cell);
        if (dir < 0) walk_m = std::min(walk_m, (i0 * cell - origin) / dir + cell);
    };
    clipAxis(tx_m, ux, w.ix0, w.nx);
    clipAxis(ty_m, uy, w.iy0, w.ny);
}

double targetCertainty(const BinGrid& grid, const BinGrid::UpdatedCell& u,
                       const BinUpdateParams& binParams) {
    CellSurface surface;
    return cellSurface(grid, u.ix, u.iy, binParams, surface) ? surface.certainty : 0.0;
}

void weakenBinsAboveMeasurements(BinGrid& grid, const BinGrid::UpdatedCell& u, double tz_m,
                                 const ConflictTest& conflicts, float decrement,
                                 VisibilityStats& stats) {
    grid.editBins(u.ix, u.iy, [&](Bin& b) {
        if (!conflicts(b, tz_m)) return true;
        b.certainty -= decrement;
        stats.binsWeakened++;
        if (b.certainty > 0) return true;
        stats.binsRemoved++;
        return false;
    });
}

VisibilityStats applyVisibilityRule(BinGrid& grid, const Eigen::Vector3d& sensor_m,
                                    const VisibilityParams& vis, const BinUpdateParams& binParams) {
    VisibilityStats stats;
    if (!vis.enabled) return stats;
    const ConflictTest conflicts(vis, binParams);
    // A rising ray stops once it clears the highest bin stored anywhere by the margin.
    const double stopHeight_m = grid.maxHeight_m() + vis.margin_m;
    for (const BinGrid::UpdatedCell& u : grid.updatedCells()) {
        // Taken before the cell's own edit: the surface the new points support.
        const double target = targetCertainty(grid, u, binParams);
        const float decrement = vis.certaintyDecrement * float(u.points);
        weakenBinsAboveMeasurements(grid, u, u.maxHeight_m, conflicts, decrement, stats);
        SightLine ray;
        if (!ray.set(grid, u, sensor_m)) continue;
        stats.raysCast++;
        forEachCellOnSightLine(grid, ray, u.ix, u.iy, stopHeight_m,
                               [&](int ix, int iy, double, double rayHigh_m) {
                                   stats.cellsVisited++;
                                   editOccluder(
                                       grid, ix, iy, rayHigh_m, conflicts,
                                       [target] { return target; }, decrement, stats);
                               });
    }
    return stats;
}

}  // namespace multibin
