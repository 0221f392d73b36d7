/* Part of the multibin elevation-mapping library. */
#pragma once

#include <Eigen/Core>

#include "multibin/grid/BinGrid.h"
#include "multibin/grid/BinUpdate.h"
#include "multibin/grid/VisibilityParams.h"

namespace multibin {

/** The visibility rule of Belter, Łabęcki & Skrzypczyński 2012, as plainly as it reads: for each
 * cell updated in this cycle, its own bins above everything measured in it now lose
 * `certaintyDecrement` per new point; then the line of sight from the sensor to the highest new
 * point of the cell is sampled every half cell, from the cell back towards the sensor, until it
 * clears the highest bin stored anywhere (or leaves the window): in each cell it enters that was
 * not updated in this cycle, a bin above the line (ConflictTest) is stale. It is removed if it is
 * less certain than the updated cell's surface (CellSurface), otherwise it loses
 * `certaintyDecrement` per new point and then `certaintyShare` of what it keeps (and is removed
 * at 0; a share of 0 is the paper's fixed amount).
 *
 * This is the oracle: applyVisibilityConstraint (the fast path) must edit exactly the bins this
 * edits, bit for bit, with the same counts of rays, removals and weakenings. Its cost is rays x
 * length; it is not meant for production. */
VisibilityStats applyVisibilityRule(BinGrid& grid, const Eigen::Vector3d& sensor_m,
                                    const VisibilityParams& visibility,
                                    const BinUpdateParams& binParams);

/** Whether a bin lies above a line of sight by more than its conflict margin: the visibility
 * margin plus 3 sigma of the bin. */
class ConflictTest {
public:
    ConflictTest(const VisibilityParams& visibility, const BinUpdateParams& binParams)
        : m_visibility(visibility), m_binParams(binParams), m_minMargin_m(margin_m(Bin{})) {}
    /** The margin [m] by which `b` must lie above a line to conflict with it. */
    double margin_m(const Bin& b) const {
        return m_visibility.margin_m + 3.0 * BinGrid::sigma_m(b, m_binParams);
    }
    /** The smallest margin any bin can have (its variance at the floor): a bound no higher than
     * this above a line holds no conflicting bin. */
    double minMargin_m() const { return m_minMargin_m; }
    const VisibilityParams& visibility() const { return m_visibility; }
    bool operator()(const Bin& b, double lineHeight_m) const {
        const double above = b.height_m - lineHeight_m;
        return above > m_minMargin_m && above > margin_m(b);
    }

private:
    const VisibilityParams& m_visibility;
    const BinUpdateParams& m_binParams;
    double m_minMargin_m;
};

/** The line of sight from an updated cell's centre, at its highest new point, to the sensor, as
 * the rule samples it: at distances step, 2 step, ... (accumulated, d += step) from the cell,
 * each sample's cell tested at the ray's height there plus `inCellRise_m` (the most the ray
 * rises within half a cell diagonal), until `walk_m` (the sensor, or where the ray has left the
 * window, which is convex). */
struct SightLine {
    double tx_m = 0, ty_m = 0, tz_m = 0;  //!< the cell's centre and highest new point
    double length_m = 0;                  //!< horizontal distance to the sensor
    double slope = 0;                     //!< height gained per metre towards the sensor
    double inCellRise_m = 0;
    double ux = 0, uy = 0;  //!< unit horizontal direction towards the sensor
    double walk_m = 0;      //!< samples at d < walk_m
    bool unclamped = true;  //!< no sample reaches where BinGrid::cellIndex() clamps
    double invCell = 0;     //!< 1 / cell [1/m], as BinGrid computes it

    /** The line of `u`; false (no ray) if the sensor lies within a cell of its centre. */
    bool set(const BinGrid& grid, const BinGrid::UpdatedCell& u, const Eigen::Vector3d& sensor_m) {
        if (!setEnds(grid, u, sensor_m)) return false;
        setWalk(grid, sensor_m);
        return true;
    }
    /** set()'s first half: the ends and the length (the fast path's culling needs no more). */
    bool setEnds(const BinGrid& grid, const BinGrid::UpdatedCell& u,
                 const Eigen::Vector3d& sensor_m);
    /** set()'s second half: the slope, direction and extent of the walk. */
    void setWalk(const BinGrid& grid, const Eigen::Vector3d& sensor_m);
    /** The cell index of a sample's coordinate (as BinGrid::cellIndex, without the clamp where
     * none can apply). */
    int cellOf(const BinGrid& grid, double coord_m) const {
        return unclamped ? BinGrid::floorToInt(coord_m * invCell) : grid.cellIndex(coord_m);
    }
};

/** The cells the rule tests along `ray` from updated cell (startIx, startIy), in walking order,
 * each once: `visit(ix, iy, d_m, rayHigh_m)` with the sample's distance from the cell and the
 * line's height there (plus the in-cell rise). Cells outside the window or updated in this cycle
 * are left out; a rising ray ends where it clears `stopHeight_m`. Which cells a ray crosses,
 * apart from what the rule does to them. */
template <class Visit>
void forEachCellOnSightLine(const BinGrid& grid, const SightLine& ray, int startIx, int startIy,
                            double stopHeight_m, Visit&& visit) {
    const double step = 0.5 * grid.cellSize_m();
    int lastIx = startIx, lastIy = startIy;
    for (double d = step; d < ray.walk_m; d += step) {  // accumulated: the rule's rounding
        const double rayZ = ray.tz_m + ray.slope * d;
        if (ray.slope > 0 && rayZ - ray.inCellRise_m > stopHeight_m) break;
        const int ix = ray.cellOf(grid, ray.tx_m + ray.ux * d);
        const int iy = ray.cellOf(grid, ray.ty_m + ray.uy * d);
        if (ix == lastIx && iy == lastIy) continue;  // one test per cell entered
        lastIx = ix;
        lastIy = iy;
        if (!grid.window().contains(ix, iy) || grid.updatedThisCycle(ix, iy)) continue;
        visit(ix, iy, d, rayZ + ray.inCellRise_m);
    }
}

/** The certainty of the updated cell's surface as the map reports it (CellSurface), 0 if none. */
double targetCertainty(const BinGrid& grid, const BinGrid::UpdatedCell& u,
                       const BinUpdateParams& binParams);

/** targetCertainty, computed when first asked for (most updated cells edit nothing). Rays never
 * edit updated cells, so a late look-up gives the value the rule takes first, as long as it is
 * asked for before the cell's own edit (weakenBinsAboveMeasurements) when that runs. */
class LazyTargetCertainty {
public:
    LazyTargetCertainty(const BinGrid& grid, const BinGrid::UpdatedCell& u,
                        const BinUpdateParams& binParams)
        : m_grid(grid), m_u(u), m_binParams(binParams) {}
    double operator()() {
        if (!m_known) {
            m_value = targetCertainty(m_grid, m_u, m_binParams);
            m_known = true;
        }
        return m_value;
    }

private:
    const BinGrid& m_grid;
    const BinGrid::UpdatedCell& m_u;
    const BinUpdateParams& m_binParams;
    double m_value = 0;
    bool m_known = false;
};

/** The updated cell's own bins above `tz_m` (all it measured now) lose `decrement` each. */
void weakenBinsAboveMeasurements(BinGrid& grid, const BinGrid::UpdatedCell& u, double tz_m,
                                 const ConflictTest& conflicts, float decrement,
                                 VisibilityStats& stats);

/** Cell (ix, iy), crossed by a line of sight at `rayHigh_m`: its bins above the line are removed
 * if less certain than the target (`target()`: called only when a bin conflicts), otherwise
 * they lose `decrement` and then the share `certaintyShare` of the rest (removed at 0). */
template <class TargetCertainty>
void editOccluder(BinGrid& grid, int ix, int iy, double rayHigh_m, const ConflictTest& conflicts,
                  TargetCertainty&& target, float decrement, VisibilityStats& stats) {
    const float keep = 1.0f - conflicts.visibility().certaintyShare;
    grid.editBins(ix, iy, [&](Bin& b) {
        if (!conflicts(b, rayHigh_m)) return true;
        if (b.certainty < target()) {
            stats.binsRemoved++;
            return false;
        }
        b.certainty = (b.certainty - decrement) * keep;
        stats.binsWeakened++;
        if (b.certainty > 0) return true;
        stats.binsRemoved++;
        return false;
    });
}

}  // namespace multibin
