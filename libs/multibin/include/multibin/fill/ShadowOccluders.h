/* Part of the multibin elevation-mapping library. */
#pragma once

#include <vector>

#include "multibin/fill/FillOptions.h"
#include "multibin/fill/HeightRaster.h"

namespace multibin::fill {

/** The occluders of one gap's hidden surface (doc/gap-filling.md, "Shadows behind a step").
 *
 * A range sensor's shadow lies behind a raised edge: its rim holds the edge's top (the occluder)
 * on one side and the hidden surface's continuation on the far side, and the terrain in the
 * shadow lies below the lines of sight that grazed the edge. Interpolating between both rims
 * builds a ramp from the edge's top down to the far rim, i.e. on that bound, not below it. The
 * occluder's cells are not data of the hidden surface.
 *
 * A measured cell o touching the gap is an occluder rim cell when, looking across the gap along
 * its inward normal (a fan of five directions within +-30 degrees; eight directions all round
 * for a cell with the gap all round it), the first measured cells beyond the gap (the median of
 * at least three) lie lower than o by a step that neither the sigmas nor the visible surfaces'
 * slopes explain: drop > shadowOccluders.stepSigmas * sqrt(sigma_o^2 + sigma_f^2 + (d s)^2), d the
 * distance across [cells] and s the larger slope along the crossing of the planes fitted to the
 * 5 x 5 windows of o and of the far cell. The gap is a shadow only if there are at least
 * sqrt(gap cells) such rim cells (a strip behind its edge is at least as long as it is wide).
 * Then the fill ignores:
 *  - each occluder's top: measured cells joined to an occluder rim cell through cells above
 *    halfway down its step, within shadowOccluders.reach_cells of it;
 *  - stray returns inside the shadow: measured islands of one or two cells with nothing but the
 *    gap around them (mixed pixels between the edge and the far ground, outliers);
 *  - stray returns on the rim: rim cells off the median of their measured 8-neighbours by more
 *    than shadowOccluders.stepSigmas times what the sigmas and the neighbours' spread explain. */
struct ShadowOccluders {
    /** Raster indices of the measured cells the hidden surface's fill ignores (above); empty when
     * the gap is not a shadow behind a step. They stay measured in the map. */
    std::vector<int> cells;
    int rimCells = 0;  //!< occluder rim cells found (0 when the gap is not a shadow)
};

/** Finds the occluders of gap `cells` (raster indices of one 4-connected gap of `raster`), with
 * options.shadowOccluders.stepSigmas and options.shadowOccluders.reach_cells. */
ShadowOccluders findShadowOccluders(const HeightRaster& raster, const std::vector<int>& cells,
                                    const FillOptions& options);

/** A copy of `raster` in which `occluders.cells` are unknown: the hidden surface is filled from
 * the rest. */
HeightRaster withoutOccluders(const HeightRaster& raster, const ShadowOccluders& occluders);

}  // namespace multibin::fill
