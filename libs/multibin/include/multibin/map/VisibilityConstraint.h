/* Part of the multibin elevation-mapping library. */
#pragma once

#include <Eigen/Core>
#include <cstddef>

#include "multibin/map/BinGrid.h"
#include "multibin/map/MapTypes.h"

namespace multibin {

/** The visibility constraint, applied after one observation updated `grid` (the cells of its
 * current update cycle), seen from `sensor_m` in the map frame:
 *
 * - along the line of sight from the sensor to the highest point accepted in each updated cell,
 *   a cell that was not updated in this cycle and holds a bin above the line is stale: the line
 *   passed through where it claims a surface. If the bin is less certain than the updated cell's
 *   surface (CellSurface: the certainty the map reports for that cell), it is removed; otherwise it
 * loses `certaintyDecrement` per contradicting point (and is removed at 0);
 * - within an updated cell, a bin above everything measured in it now would have occluded those
 *   measurements: it loses `certaintyDecrement` per new point, so the next-best hypothesis wins.
 *
 * Heights can therefore go down as well as up. The rays are sampled every half cell from the
 * updated cell back towards the sensor. BinGrid's block height bounds (BinGrid::blockMaxHeight_m)
 * decide where a bin can conflict at all: a ray is walked only as far as the last block it
 * passes too low over, and only over the block columns it passes too low over (its other
 * samples are skipped, the rest taken at the same distances), a ray's sweep of block columns
 * ends where the rest of the ray passes above every block that near the sensor, a cell is tested
 * only if its block's bound lies above the ray by the smallest conflict margin, and an update
 * whose whole region (the blocks between the sensor and the updated cells) lies below every line
 * of sight costs no walk at all. Before any walk, the fan of rays is tested at once: each block
 * against the rays within its angle from the sensor, then, where a block is too high for a ray,
 * its squares of 4 x 4 cells and their cells; a ray that passes above all of them by the
 * smallest conflict margin is not walked (on rough terrain, most rays). The bins edited are
 * exactly those of a walk to the highest bin stored anywhere; the cost grows with the distinct
 * updated cells, not with the points, and with the relief near the lines of sight. */
/** How the updated cells' lines of sight are tested before any walk: the fan test (a scan's
 * rays: laser, lidar), or the walk's own tests alone (a camera frame's thousands of rays over
 * rough ground, where ordering and testing the fan measured slower than the walks it saves).
 * The bins edited are the same either way. */
enum class RayFan { Test, Skip };

VisibilityStats applyVisibilityConstraint(BinGrid& grid, const Eigen::Vector3d& sensor_m,
                                          const VisibilityParams& visibility,
                                          const BinUpdateParams& binParams,
                                          RayFan fan = RayFan::Test);

}  // namespace multibin
