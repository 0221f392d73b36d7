/* Part of the multibin elevation-mapping library. */
#pragma once

#include "multibin/fill/FillOptions.h"
#include "multibin/fill/GapLabelling.h"
#include "multibin/fill/HeightRaster.h"
#include "multibin/fill/SupportArea.h"
#include "multibin/fill/WeightedMedianFill.h"

namespace multibin::fill {

/** Fills the never-observed cells of a raster (DESIGN.md "Gap filling", doc/gap-filling.md),
 * one strategy per gap:
 *  1. gaps = 4-connected components of cells that are not measured (GapLabelling.h);
 *  2. a gap whose every cell has >= medianMinKnown measured cells in its window is filled by the
 *     weighted median (small gaps; WeightedMedianFill.h);
 *  3. a larger gap (<= maxGapCells) that is a shadow behind a step (ShadowOccluders.h) is
 *     filled from its hidden side only: harmonic interpolation of the rim without the occluder;
 *     another larger gap (<= maxGapCells) gets a square support area (SupportArea.h) and is filled
 * by eq 16 fitted there: as the trend of a universal kriging (KrigingFill.h, default) or plus
 *     harmonic / biharmonic rim residuals (HarmonicFill.h), m chosen as in ModelSelection.h; by
 *     the repeated median if gaussianEnabled is false or the area has too little data;
 *  4. larger gaps stay Unknown.
 * Only measured cells are ever used as data; measured cells are copied unchanged. With
 * options.enabled false every gap is Unknown. Throws std::invalid_argument on a bad raster or
 * bad options. Deterministic for a given options.swarmSeed. */
FillResult fillGaps(const HeightRaster& raster, const FillOptions& options);

}  // namespace multibin::fill
