/* Part of the multibin elevation-mapping library. */
#pragma once

#include "multibin/fill/FillOptions.h"
#include "multibin/fill/HeightRaster.h"

namespace multibin::fill {

/** The weighted median alone: every gap cell whose window has >= medianMinKnown measured cells
 * is filled (source FilledMedian), others stay Unknown. With `repeatUntilFilled`, further passes
 * use the cells filled by earlier passes as data too, until no cell changes (so a large gap is
 * filled from its rim inwards; used as the Gaussian fallback and as a baseline). */
FillResult weightedMedianFill(const HeightRaster& raster, const FillOptions& options,
                              bool repeatUntilFilled = false);

/** The weight of a window cell at offset (di, dj) from the centre: its distance
 * sqrt(di^2 + dj^2) [cells], larger away from the centre (the paper's skeleton). */
double medianSkeletonWeight(int di, int dj);

}  // namespace multibin::fill
