/* Part of the multibin elevation-mapping library. Internal to gap filling. */
#pragma once

#include <limits>
#include <vector>

#include "multibin/fill/HeightRaster.h"

namespace multibin::fill::detail {

constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();

/** A result on the raster's lattice with its measured cells copied (source Measured) and every
 * other cell Unknown; `measured` receives 1 per measured cell, else 0. */
FillResult initResult(const HeightRaster& raster, std::vector<char>& measured);

/** Sets the cell counts of out.stats from out.source. */
void countSources(FillResult& out);

}  // namespace multibin::fill::detail
