/* Part of the multibin elevation-mapping library. */
#pragma once

#include <vector>

#include "multibin/fill/FillOptions.h"
#include "multibin/fill/HeightRaster.h"

namespace multibin::fill {

/** Fills the never-observed cells of a raster (DESIGN.md "Gap filling"):
 *  1. gaps = 4-connected components of cells that are not measured;
 *  2. a gap whose every cell has >= medianMinKnown measured cells in its window is filled by the
 *     weighted median (small gaps);
 *  3. a larger gap (<= maxGapCells) is filled by eq 16 fitted on a square support area around
 *     it (or by the repeated median if gaussianEnabled is false or the area has too little data);
 *  4. larger gaps stay Unfilled.
 * Only measured cells are ever used as data; measured cells are copied unchanged. With
 * options.enabled false every gap is Unfilled. Throws std::invalid_argument on a bad raster or
 * bad options. Deterministic for a given options.swarmSeed. */
FillResult fillGaps(const HeightRaster& raster, const FillOptions& options);

/** The weighted median alone: every gap cell whose window has >= medianMinKnown measured cells
 * is filled (source Median), others stay Unfilled. With `repeatUntilFilled`, further passes use
 * the cells filled by earlier passes as data too, until no cell changes (so a large gap is
 * filled from its rim inwards; used as the Gaussian fallback and as a baseline). */
FillResult weightedMedianFill(const HeightRaster& raster, const FillOptions& options,
                              bool repeatUntilFilled = false);

/** The weight of a window cell at offset (di, dj) from the centre: its distance
 * sqrt(di^2 + dj^2) [cells], larger away from the centre (the paper's skeleton). */
double medianSkeletonWeight(int di, int dj);

/** Labels of the 4-connected components of non-measured cells: -1 for measured cells, else
 * 0 .. count-1; `sizes` receives each component's cell count. */
std::vector<int> labelGaps(const HeightRaster& raster, std::vector<int>& sizes);

/** Empirical semivariogram gamma(h) = 0.5 mean (z(x) - z(x + h))^2 [m^2] of the measured cells
 * inside the box x0 <= ix < x0 + w, y0 <= iy < y0 + h (clipped to the raster), for lags
 * h = 1 .. maxLag cells along rows and columns; gamma[0] = 0. A lag with no pair takes the
 * previous lag's value. */
std::vector<double> semivariogram(const HeightRaster& raster, int x0, int y0, int w, int h,
                                  int maxLag);

}  // namespace multibin::fill
