/* Part of the multibin elevation-mapping library. */
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "multibin/geometry/PointsWithCovariance.h"
#include "multibin/grid/BinGrid.h"
#include "multibin/grid/BinUpdate.h"

namespace multibin {

/** Removes the points whose own height variance fails eq 13 (3 sigma_z > Delta_max), keeping the
 * order of the others; returns how many left. Points the grid refuses for another reason (not
 * finite) stay, for the grid to count. For an insertion whose points then get an error they
 * share added (a depth frame's, sensors::addFrameSharedCovariance()): the gate is a point's own,
 * and the grid then fuses them with the gate off. */
size_t removeFailingOwnGate(PointsWithCov& mapPoints, const BinUpdateParams& params);

/** For each point, how many of `mapPoints` fall in its cell of `grid` (inside the window or
 * not). */
std::vector<uint32_t> pointsPerCell(const BinGrid& grid, const PointsWithCov& mapPoints);

}  // namespace multibin
