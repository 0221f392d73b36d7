/* Part of the multibin elevation-mapping library. */
#pragma once

#include <Eigen/Core>
#include <cstddef>

#include "multibin/grid/BinGrid.h"
#include "multibin/grid/BinUpdate.h"
#include "multibin/grid/VisibilityParams.h"

namespace multibin {

/** The visibility constraint, applied after one observation updated `grid` (the cells of its
 * current update cycle), seen from `sensor_m` in the map frame:
 *
 * - along the line of sight from the sensor to the highest point accepted in each updated cell,
 *   a cell that was not updated in this cycle and holds a bin above the line is stale: the line
 *   passed through where it claims a surface. If the bin is less certain than the updated cell's
 *   surface (CellSurface: the certainty the map reports for that cell), it is removed; otherwise it
 *   loses `certaintyDecrement` per contradicting point (and is removed at 0);
 * - within an updated cell, a bin above everything measured in it now would have occluded those
 *   measurements: it loses `certaintyDecrement` per new point, so the next-best hypothesis wins.
 *
 * Heights can therefore go down as well as up. The bins edited are exactly those of the rule
 * (applyVisibilityRule, VisibilityRule.h: every ray sampled every half cell); this fast path
 * rules out, from the grid's block and cell height bounds, the places where no bin can conflict,
 * in five stages (VisibilityStages.h): the update's region, the rectangle towards the sensor, a
 * test of all the rays at once (the fan or the envelope test, below), a ray's block columns, and
 * the rule's samples over the columns left. The cost grows with the distinct updated cells, not
 * with the points, and with the relief near the lines of sight (doc/visibility.md). */
/** How the updated cells' lines of sight are tested before any walk: the fan test, each ray
 * against the blocks within its angle (a scan's few hundred rays: laser, lidar), or the envelope
 * test, the rays' lower envelope by direction against the cells near them (a camera frame's
 * thousands of rays, for which ordering and testing the fan measured slower than the walks it
 * saves). The bins edited are the same either way. */
enum class RayFan { Test, Skip };

VisibilityStats applyVisibilityConstraint(BinGrid& grid, const Eigen::Vector3d& sensor_m,
                                          const VisibilityParams& visibility,
                                          const BinUpdateParams& binParams,
                                          RayFan fan = RayFan::Test);

/** Notes the clearance (VisibilityIndex::noteClearance) of the cells each updated cell's line of
 * sight passes over, sampled once a cell from the cell towards the sensor until the line has
 * risen `maxRise_m` above its end or has crossed 16 cells (a shallow line's cost): the ground
 * there lies below the line, whose height at the sample is the cell's clearance. A line ends at
 * the highest bin its cell ever held, and only cells with two points or more of the update end
 * one (a lone point may be a range outlier beyond the surface). Edits no bin. The map calls it
 * (with kClearanceRise_m) before applyVisibilityConstraint when the constraint is enabled and the
 * fill reads clearances (fill_enabled, fill_clearance). */
void noteClearances(BinGrid& grid, const Eigen::Vector3d& sensor_m, double maxRise_m);
/** How far above its end a line of sight is followed for the clearance [m]: beyond, it is far
 * above any fill a gap's rim gives (0.14 m along a ray 30 deg below the horizontal; 0.15 m measured
 * no better on the tuning scenes). */
constexpr double kClearanceRise_m = 0.08;

}  // namespace multibin
