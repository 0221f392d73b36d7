/* Part of the multibin elevation-mapping library. */
#pragma once

#include <Eigen/Core>
#include <cstddef>

#include "multibin/map/BinGrid.h"

namespace multibin {

/** Parameters of the visibility constraint. */
struct VisibilityParams {
    bool enabled = true;
    /** A bin conflicts with a line of sight when it lies above it by more than this plus 3 sigma
     * of the bin [m]: cell-size relief and the ray's own uncertainty live in this margin. */
    double margin_m = 0.02;
    /** The fixed amount of certainty a conflicting bin loses for each new point it contradicts
     * (each point whose line of sight it blocks, or which lies below it in its own cell): with
     * the default equal to the certainty increment, a moved object is forgotten as fast as the
     * new surface is learnt. */
    float certaintyDecrement = 1.0f;
};

/** What one application of the constraint did. */
struct VisibilityStats {
    size_t raysCast = 0;      //!< one per distinct updated cell
    size_t cellsVisited = 0;  //!< cells tested along the rays
    size_t binsRemoved = 0;   //!< stale bins removed
    size_t binsWeakened = 0;  //!< conflicting bins that lost certainty
};

/** The visibility constraint, applied after one observation updated `grid` (the cells of its
 * current update cycle), seen from `sensor_m` in the map frame:
 *
 * - along the line of sight from the sensor to the highest point accepted in each updated cell,
 *   a cell that was not updated in this cycle and holds a bin above the line is stale: the line
 *   passed through where it claims a surface. If the bin is less certain than the updated cell's
 *   winning bin, it is removed; otherwise it loses `certaintyDecrement` per contradicting point
 *   (and is removed at 0);
 * - within an updated cell, a bin above everything measured in it now would have occluded those
 *   measurements: it loses `certaintyDecrement` per new point, so the next-best hypothesis wins.
 *
 * Heights can therefore go down as well as up. The rays are sampled every half cell from the
 * updated cell back towards the sensor. BinGrid's block height bounds (BinGrid::blockMaxHeight_m)
 * decide where a bin can conflict at all: a ray is walked only as far as the last block it
 * passes too low over, a cell is tested only if its block's bound lies above the ray by the
 * smallest conflict margin, and an update whose whole region (the blocks between the sensor and
 * the updated cells) lies below every line of sight costs no walk at all. The bins edited are
 * exactly those of a walk to the highest bin stored anywhere; the cost grows with the distinct
 * updated cells, not with the points, and with the relief near the lines of sight. */
VisibilityStats applyVisibilityConstraint(BinGrid& grid, const Eigen::Vector3d& sensor_m,
                                          const VisibilityParams& visibility,
                                          const BinUpdateParams& binParams);

}  // namespace multibin
