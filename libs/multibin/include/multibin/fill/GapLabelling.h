/* Part of the multibin elevation-mapping library. */
#pragma once

#include <vector>

#include "multibin/fill/FillOptions.h"
#include "multibin/fill/HeightRaster.h"

namespace multibin::fill {

/** Labels of the 4-connected components of non-measured cells: -1 for measured cells, else
 * 0 .. count-1; `sizes` receives each component's cell count. */
std::vector<int> labelGaps(const HeightRaster& raster, std::vector<int>& sizes);

/** One gap (a labelled component) as gap filling routes it. */
struct Gap {
    std::vector<int> cells;   //!< raster indices, ascending; empty if over maxGapCells
    bool medianReach = true;  //!< every cell's median window holds >= medianMinKnown measured cells
};

/** Whether every one of `cells` (raster indices) has >= options.medianMinKnown measured cells in
 * its medianWindow_cells window, clipped to the raster: the weighted median fills the gap. */
bool medianReaches(const HeightRaster& raster, const std::vector<int>& cells,
                   const FillOptions& options);

/** The gaps of labelGaps() in label order, each with its cells (none for a gap larger than
 * options.maxGapCells, which stays Unknown) and whether the median reaches all of them. */
std::vector<Gap> collectGaps(const HeightRaster& raster, const std::vector<int>& label,
                             const std::vector<int>& sizes, const FillOptions& options);

}  // namespace multibin::fill
